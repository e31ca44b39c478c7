"""Shared orbits and an eighth-order central difference for the tests of gmuk.orbits."""

from __future__ import annotations

import math

import numpy as np

from gmuk.orbits import MU_MOON_THESIS_CONSISTENT, KeplerOrbit, fcei_orbit

MU = MU_MOON_THESIS_CONSISTENT

#: Orbits the reference and the two-body motion are checked on (all around the Moon, with
#: periapsis above its 1737 km radius).
ORBITS = {
    "circular_equatorial": KeplerOrbit.from_elements(4.0e6, 0.0, 0.0, 0.0, 0.0, MU),
    "fcei_thesis": fcei_orbit(),
    "high_e_0.9": KeplerOrbit.from_elements(
        2.0e7, 0.9, math.radians(60.0), math.radians(30.0), math.radians(120.0), MU
    ),
    "retrograde_inclined": KeplerOrbit.from_elements(
        5.0e6, 0.3, math.radians(150.0), math.radians(40.0), math.radians(250.0), MU
    ),
    "hyperbola": KeplerOrbit.from_elements(
        -3.0e6, 1.8, math.radians(20.0), math.radians(300.0), math.radians(45.0), MU
    ),
    "parabola": KeplerOrbit.from_elements(
        None, 1.0, math.radians(80.0), math.radians(10.0), math.radians(200.0), MU, p=5.0e6
    ),
}
CLOSED = [k for k, o in ORBITS.items() if o.kind == "ellipse"]

# Eighth-order central-difference weights for the first derivative, offsets −4..4.
_W = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])


def sample_times(orbit: KeplerOrbit, n: int = 201) -> np.ndarray:
    """n times (odd n): one period [0, T] for an ellipse, so that periapsis (t = 0) and
    apoapsis (t = T/2) are samples; for open conics a symmetric window about periapsis out to
    80 % of the asymptotic true anomaly."""
    if orbit.kind == "ellipse":
        return np.linspace(0.0, orbit.period, n)
    f_inf = math.pi if orbit.kind == "parabola" else math.acos(-1.0 / orbit.e)
    t_max = float(orbit.time_from_true_anomaly(0.8 * f_inf))
    return np.linspace(-t_max, t_max, n)


def central_difference(fun, t: np.ndarray, h: np.ndarray) -> np.ndarray:
    """d/dt fun at times t (N,) with steps h (N,); fun maps (N,) times to (N, ...) arrays.
    Truncation error O(h⁸)."""
    out = None
    for k, w in zip(range(-4, 5), _W, strict=True):
        if w == 0.0:
            continue
        val = fun(t + k * h)
        hb = h.reshape(h.shape + (1,) * (val.ndim - 1))
        term = w * val / hb
        out = term if out is None else out + term
    return out


def local_step(orbit: KeplerOrbit, t: np.ndarray, fraction: float = 0.01) -> np.ndarray:
    """A time step of ``fraction`` of the local time scale of the motion: ``r/|v|``, capped
    for an ellipse at ``1/n`` (at apoapsis of an eccentric orbit r/|v| exceeds the period)."""
    r, v = orbit.state(t)
    tau = np.linalg.norm(r, axis=-1) / np.linalg.norm(v, axis=-1)
    if orbit.kind == "ellipse":
        tau = np.minimum(tau, 1.0 / orbit.mean_motion)
    return fraction * tau
