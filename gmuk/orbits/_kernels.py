"""Compiled kernels of the orbit references: the anomaly and its rates at one time, and the
modified-LVLH pose, twist and twist rate (the closed forms of
:meth:`gmuk.orbits.LVLHReference.evaluate`), for the integrator's hot path."""

from __future__ import annotations

import math

import numpy as np

from gmuk._numba import njit
from gmuk.orbits import kepler

__all__ = ["anomaly_rates", "lvlh_state"]


@njit(cache=True)
def anomaly_rates(t, mean_motion, e, mu, p):  # type: ignore[no-untyped-def]
    """(f, ḟ, f̈) at time t (s since periapsis) of a conic with mean motion n, eccentricity
    e, gravitational parameter μ and semi-latus rectum p (McCann 2020, Section 4.1.2)."""
    M = mean_motion * t
    if e < 1.0:
        f = kepler.true_from_eccentric_scalar(kepler.eccentric_from_mean_scalar(M, e), e)
    elif e == 1.0:
        f = 2.0 * math.atan(kepler.parabolic_from_mean_scalar(M))
    else:
        f = kepler.true_from_hyperbolic_scalar(kepler.hyperbolic_from_mean_scalar(M, e), e)
    k2 = mu / p**3
    w = 1.0 + e * math.cos(f)
    return f, math.sqrt(k2) * w * w, -2.0 * k2 * w**3 * e * math.sin(f)


@njit(cache=True)
def lvlh_state(t, mean_motion, e, mu, p, R, g, V, V_dot):  # type: ignore[no-untyped-def]
    """Fill the desired pose g (4, 4), twist V (6,) and twist rate V̇ (6,) of the
    modified-LVLH frame at time t: ``g = g_P g_{d/P}`` with R = R_NP the perifocal frame,
    ``R_{d/P} = [[−cos f, sin f, 0], [−sin f, −cos f, 0], [0, 0, 1]]`` (Eq. 69 corrected),
    ``V = [0, 0, ḟ, v₁, v₂, 0]``, ``V̇ = [0, 0, f̈, μ/r² + ḟ v₂, −ḟ v₁, 0]``."""
    f, fd, fdd = anomaly_rates(t, mean_motion, e, mu, p)
    c, s = math.cos(f), math.sin(f)
    w = 1.0 + e * c
    r = p / w
    k = math.sqrt(mu / p)
    v1, v2 = -k * e * s, -k * w
    rel = np.array(((-c, s, 0.0), (-s, -c, 0.0), (0.0, 0.0, 1.0)))
    pos = np.array((r * c, r * s, 0.0))
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for m in range(3):
                acc += R[i, m] * rel[m, j]
            g[i, j] = acc
        acc = 0.0
        for m in range(3):
            acc += R[i, m] * pos[m]
        g[i, 3] = acc
    g[3, 0] = 0.0
    g[3, 1] = 0.0
    g[3, 2] = 0.0
    g[3, 3] = 1.0
    V[0] = 0.0
    V[1] = 0.0
    V[2] = fd
    V[3] = v1
    V[4] = v2
    V[5] = 0.0
    V_dot[0] = 0.0
    V_dot[1] = 0.0
    V_dot[2] = fdd
    V_dot[3] = mu / (r * r) + fd * v2
    V_dot[4] = -fd * v1
    V_dot[5] = 0.0


@njit(cache=True)
def lvlh_state_packed(t, p, g, V, V_dot):  # type: ignore[no-untyped-def]
    """:func:`lvlh_state` with the reference packed as the compiled parts pack it (what
    :meth:`gmuk.orbits.LVLHReference._compiled_orbit` gives): p = (n, e, μ, p, R_NP row by
    row, ...)."""
    R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R[i, j] = p[4 + 3 * i + j]
    lvlh_state(t, p[0], p[1], p[2], p[3], R, g, V, V_dot)
