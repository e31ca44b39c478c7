"""gmuk.environment.EclipseEvent: umbra and penumbra crossings located by gmuk.simulate."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import gmuk
from gmuk.environment import EARTH_MU, RADIUS, EclipseEvent, Epoch, position
from gmuk.errors import DefinitionError

EPOCH = Epoch("2024-03-20T03:06:00")  # the March equinox: the Sun in the equatorial plane
A = 7.0e6  # circular orbit radius (m)
N = math.sqrt(EARTH_MU / A**3)  # mean motion (rad/s)
INCLINATION = 0.3  # rad
P_HAT = np.array([1.0, 0.0, 0.0])
Q_HAT = np.array([0.0, math.cos(INCLINATION), math.sin(INCLINATION)])


def circular(t: float) -> np.ndarray:
    """The orbit in closed form: r(t) = a (cos nt p̂ + sin nt q̂) (m)."""
    return A * (math.cos(N * t) * P_HAT + math.sin(N * t) * Q_HAT)


def cone_margin(t: float, kind: str) -> float:
    """Signed angle (rad) of the orbit's point at t outside the shadow cone, computed from the
    cones themselves (an apex and a half-angle), not from apparent radii: the umbra cone is
    tangent to the Sun and the Earth on the same side, apex V_u = −ŝ R_E |s|/(R_S − R_E)
    behind the Earth, half-angle asin((R_S − R_E)/|s|) about ŝ; the penumbra cone is tangent
    on opposite sides, apex V_p = +ŝ R_E |s|/(R_S + R_E) between them, half-angle
    asin((R_S + R_E)/|s|) about −ŝ. Positive outside, negative inside (behind the Earth)."""
    s = position("sun", EPOCH + t)
    d = float(np.linalg.norm(s))
    s_hat = s / d
    r = circular(t)
    R_S, R_E = RADIUS["sun"], RADIUS["earth"]
    if kind == "umbra":
        apex, axis, half = -s_hat * R_E * d / (R_S - R_E), s_hat, math.asin((R_S - R_E) / d)
    else:
        apex, axis, half = s_hat * R_E * d / (R_S + R_E), -s_hat, math.asin((R_S + R_E) / d)
    u = r - apex
    angle = math.atan2(float(np.linalg.norm(np.cross(u, axis))), float(u @ axis))
    return angle - half


def crossings(kind: str, t_end: float) -> list[float]:
    """Zeros of cone_margin on the shadowed side, by Brent's method to 1e-12 s."""
    ts = np.linspace(0.0, t_end, 4001)
    m = [cone_margin(t, kind) for t in ts]
    out = []
    for i in range(len(ts) - 1):
        if np.sign(m[i]) != np.sign(m[i + 1]) and circular(ts[i]) @ position("sun", EPOCH) < 0:
            out.append(brentq(cone_margin, ts[i], ts[i + 1], args=(kind,), xtol=1e-12))
    return out


def test_entry_and_exit_times_agree_with_the_shadow_cones_to_a_microsecond():
    sat = gmuk.PointMass("sat", 100.0)
    system = gmuk.System([sat], forces=[gmuk.PointMassGravity(EARTH_MU)])
    state = system.state(r={"sat": circular(0.0)}, v={"sat": A * N * Q_HAT})
    period = 2.0 * math.pi / N
    events = [
        EclipseEvent(sat, EPOCH, kind="umbra", direction=0),
        EclipseEvent(sat, EPOCH, kind="penumbra", direction=0),
    ]
    traj = system.simulate(state, (0.0, period), rtol=1e-13, atol=1e-8, events=events)
    for kind in ("umbra", "penumbra"):
        found = [e for e in traj.events if e.name == f"earth {kind}"]
        expected = crossings(kind, period)
        assert len(found) == len(expected) == 2
        assert [e.direction for e in found] == [-1, 1]  # entry falls, exit rises
        for e, t in zip(found, expected, strict=True):
            assert abs(e.t - t) < 1e-6
    pen_in, umb_in = (next(e.t for e in traj.events if e.name == n) for n in
                      ("earth penumbra", "earth umbra"))  # fmt: skip
    assert 0.0 < umb_in - pen_in < 20.0  # ~8 s of penumbra at 7000 km


def test_margin_is_smooth_through_the_crossing_where_the_fraction_has_a_kink():
    event = EclipseEvent("sat", EPOCH)
    t0 = crossings("umbra", 2.0 * math.pi / N)[0]
    h = 1e-2
    m = [event.margin(t0 + k * h, circular(t0 + k * h)) for k in (-2, -1, 0, 1, 2)]
    # equal steps of a smooth function: second differences tiny beside first differences
    d1 = np.diff(m)
    assert (d1 < 0).all()
    assert np.abs(np.diff(d1)).max() < 1e-4 * np.abs(d1).min()
    assert abs(m[2]) < 1e-9


def test_direction_keeps_entries_only_by_default():
    event = EclipseEvent("sat", EPOCH, occulter="moon", kind="penumbra")
    assert (event.direction, event.terminal, event.name) == (-1, False, "moon penumbra")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"occulter": "sun"}, "occulter"),
        ({"kind": "antumbra"}, "kind"),
        ({"centre": "sun"}, "centre"),
    ],
)
def test_bad_events_are_refused(kwargs, match):
    with pytest.raises(DefinitionError, match=match):
        EclipseEvent("sat", EPOCH, **kwargs)
    with pytest.raises(DefinitionError, match="Epoch"):
        EclipseEvent("sat", "2024-03-20")  # type: ignore[arg-type]
