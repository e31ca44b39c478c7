"""Inequality constraints by slack and excess coordinates (McCann 2020, §6.3, Eqs. 94–110):
rows against finite differences and hand-written formulas, the initial slack, rigid bodies
held by a position- and a velocity-level bound, bad input, and the singular point where the
gradient of h vanishes on its bound.

Notation: σ = +1 for a slack (``h ≤ u``: ``h − u + w² = 0``), −1 for an excess (``h ≥ l``:
``h − l − w² = 0``). Position level: ``A = [A_h, 2σw]``, ``b = b_h − 2σẇ²``; velocity level:
``A = [A_h, 2σẇ]``, ``b = b_h``; ``b_h = −(ḣ' − A_h ν̇)`` (ḣ' = ḧ or ḣ).
"""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gmuk
from gmuk.errors import (
    ConstraintError,
    DefinitionError,
    GmukError,
    InconsistentConstraintsWarning,
)
from gmuk.lie import so3
from gmuk.state import State

SETTINGS = settings(max_examples=30, deadline=None)
FD_RTOL = 1e-7  # finite-difference rows against analytic ones, relative to the row's norm
EXACT_RTOL = 1e-12  # analytic rows against the same formulas written here


# ---------------------------------------------------------------------------- helpers
def raw_state(system, t=0.0, *, r=None, v=None, g=None, V=None, w=None, w_dot=None):
    """A State of ``system`` with every coordinate given, slack ones included (System.state
    would compute those): for rows at arbitrary (w, ẇ)."""
    lay = system.layout
    r, v, g, V = r or {}, v or {}, g or {}, V or {}
    w, w_dot = w or {}, w_dot or {}
    G = np.zeros((lay.n_rigid, 4, 4))
    Vs = np.zeros((lay.n_rigid, 6))
    x = np.zeros(lay.n_euclid)
    xd = np.zeros(lay.n_euclid)
    for b in system.bodies:
        sl = lay.slot(b)
        if sl.kind == "rigid":
            G[sl.index] = g[b.name]
            Vs[sl.index] = V[b.name]
        elif sl.kind == "point":
            x[sl.index : sl.index + 3] = r[b.name]
            xd[sl.index : sl.index + 3] = v[b.name]
        else:
            x[sl.index] = w[b.name]
            xd[sl.index] = w_dot[b.name]
    return State(float(t), G, Vs, x, xd, np.zeros(lay.n_control), lay)


def expected_rows(A_h, b_h, h, h_dot, level, bounds, w, w_dot, alpha=0.0, beta=0.0):
    """The rows of ``h − bound + σw² = 0`` (position) or ``h − bound + σẇ² = 0`` (velocity),
    written out: ``bounds`` is a list of (value, σ), ``w``/``w_dot`` the coordinates."""
    n, k = A_h.size, len(bounds)
    A = np.zeros((k, n + k))
    b = np.zeros(k)
    for i, (value, sigma) in enumerate(bounds):
        A[i, :n] = A_h
        if level == "position":
            A[i, n + i] = 2.0 * sigma * w[i]
            phi = h - value + sigma * w[i] ** 2
            phi_dot = h_dot + 2.0 * sigma * w[i] * w_dot[i]
            b[i] = b_h - 2.0 * sigma * w_dot[i] ** 2 - alpha * phi_dot - beta * phi
        else:
            A[i, n + i] = 2.0 * sigma * w_dot[i]
            b[i] = b_h - alpha * (h - value + sigma * w_dot[i] ** 2)
    return A, b


def row_error(rows, ref):
    """‖[A b] − [A_ref b_ref]‖ / ‖[A_ref b_ref]‖."""
    got = np.hstack([rows[0], rows[1][:, None]])
    want = np.hstack([ref[0], ref[1][:, None]])
    return float(np.linalg.norm(got - want) / np.linalg.norm(want))


class ValueOnlyPlane(gmuk.InequalityConstraint):
    """n̂ · r_N written as ``value()`` only: rows by finite differences."""

    def __init__(self, body, normal, **kw):
        super().__init__([body], **kw)
        self.n = np.asarray(normal, float) / np.linalg.norm(normal)

    def value(self, q, nu, t):
        qb = q[0]
        return float(self.n @ (qb[:3, 3] if qb.shape == (4, 4) else qb))


class Helix:
    """A reference motion with closed-form position, velocity and acceleration."""

    def __init__(self, radius, rate, climb):
        self.a, self.w, self.c = float(radius), float(rate), float(climb)

    def position(self, t):
        a, w = self.a, self.w
        return np.array([a * math.cos(w * t), a * math.sin(w * t), self.c * t])

    def velocity(self, t):
        a, w = self.a, self.w
        return np.array([-a * w * math.sin(w * t), a * w * math.cos(w * t), self.c])

    def acceleration(self, t):
        a, w = self.a, self.w
        return np.array([-a * w * w * math.cos(w * t), -a * w * w * math.sin(w * t), 0.0])


def breathing_bound(t):
    """δ(t) = 2 + ½ sin 1.3t with its two rates."""
    return 2.0 + 0.5 * math.sin(1.3 * t), 0.65 * math.cos(1.3 * t), -0.845 * math.sin(1.3 * t)


class ValueOnlyTracking(gmuk.InequalityConstraint):
    """‖e‖ − δ or ½(‖e‖² − δ²) ≤ 0 written as ``value()`` only."""

    def __init__(self, body, reference, bound, quantity, form, **kw):
        super().__init__([body], upper=0.0, level=quantity, **kw)
        self.reference, self.bound, self.quantity, self.form = reference, bound, quantity, form

    def value(self, q, nu, t):
        ref = self.reference
        e = q[0] - ref.position(t) if self.quantity == "position" else nu[0] - ref.velocity(t)
        d = self.bound(t)[0]
        return float(np.linalg.norm(e)) - d if self.form == "norm" else 0.5 * (e @ e - d * d)


def tracking_by_hand(quantity, form, r, v, t, reference, bound):
    """(A_h, b_h, h, ḣ) of Eqs. 101–110 (corrected) and of the squared form, by hand."""
    e, e_dot = r - reference.position(t), v - reference.velocity(t)
    a_r = reference.acceleration(t)
    d, d1, d2 = bound(t)
    if quantity == "position":
        n = np.linalg.norm(e)
        if form == "norm":
            # ḧ = (ėᵀė + eᵀë)/‖e‖ − (eᵀė)²/‖e‖³ − δ̈ with ë = ν̇ − r̈_r
            b_h = (a_r @ e - e_dot @ e_dot) / n + (e @ e_dot) ** 2 / n**3 + d2
            return e / n, b_h, n - d, e @ e_dot / n - d1
        b_h = a_r @ e - e_dot @ e_dot + d1 * d1 + d * d2
        return e.copy(), b_h, 0.5 * (e @ e - d * d), e @ e_dot - d * d1
    n = np.linalg.norm(e_dot)
    if form == "norm":
        return e_dot / n, a_r @ e_dot / n + d1, n - d, None
    return e_dot.copy(), a_r @ e_dot + d * d1, 0.5 * (e_dot @ e_dot - d * d), None


def coords(lo=-2.0, hi=2.0):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


vec3 = st.tuples(coords(), coords(), coords()).map(np.array)
directions = vec3.filter(lambda n: np.linalg.norm(n) > 0.2)
gains = st.one_of(st.just((0.0, 0.0)), st.tuples(st.floats(0.0, 20.0), st.floats(0.0, 100.0)))


# ---------------------------------------------------------------------------- 1. rows
@SETTINGS
@given(
    rigid=st.booleans(),
    normal=directions,
    position=vec3,
    velocity=st.tuples(vec3, vec3),
    rotation=vec3,
    slack=st.tuples(coords(-3, 3), coords(-3, 3)),
    slack_rate=st.tuples(coords(-3, 3), coords(-3, 3)),
    ab=gains,
)
def test_plane_bound_rows_match_finite_differences_and_hand_formulas(
    rigid, normal, position, velocity, rotation, slack, slack_rate, ab
):
    body = gmuk.RigidBody("b", 3.0, np.diag([1.0, 2.0, 3.0])) if rigid else gmuk.PointMass("b", 2.0)
    gains = gmuk.Baumgarte(alpha=ab[0], beta=ab[1])
    kw = {"lower": -1.0, "upper": 1.5, "baumgarte": gains, "name": "h"}
    analytic = gmuk.PlaneBound(body, normal, **kw)
    fd = ValueOnlyPlane(body, normal, **kw)
    system = gmuk.System([body], [analytic])
    assert gmuk.System([body], [fd]).layout == system.layout  # same slack names: one State
    w = {"h.upper": slack[0], "h.lower": slack[1]}
    w_dot = {"h.upper": slack_rate[0], "h.lower": slack_rate[1]}
    n_hat = normal / np.linalg.norm(normal)
    if rigid:
        R = so3.exp(rotation)
        g = np.eye(4)
        g[:3, :3], g[:3, 3] = R, position
        omega, v = velocity
        state = raw_state(system, 0.7, g={"b": g}, V={"b": np.r_[omega, v]}, w=w, w_dot=w_dot)
        A_h = np.r_[np.zeros(3), R.T @ n_hat]
        b_h = -n_hat @ R @ np.cross(omega, v)  # r̈_N = R(v̇ + ω × v)
        h, h_dot = n_hat @ position, n_hat @ R @ v
    else:
        state = raw_state(system, 0.7, r={"b": position}, v={"b": velocity[0]}, w=w, w_dot=w_dot)
        A_h, b_h, h, h_dot = n_hat, 0.0, n_hat @ position, n_hat @ velocity[0]
    ref = expected_rows(
        A_h, b_h, h, h_dot, "position", [(1.5, 1.0), (-1.0, -1.0)], slack, slack_rate, *ab
    )
    assert row_error(analytic.rows(state), ref) <= EXACT_RTOL
    assert row_error(fd.rows(state), ref) <= FD_RTOL
    q, nu, t = analytic._configs(state)[0], analytic._configs(state)[1], 0.7
    assert analytic.rate(q, nu, t) == pytest.approx(h_dot, rel=EXACT_RTOL, abs=EXACT_RTOL)
    assert abs(fd.rate(q, nu, t) - h_dot) <= FD_RTOL * max(1.0, abs(h_dot))
    assert analytic.h(state) == pytest.approx(h, rel=EXACT_RTOL, abs=EXACT_RTOL)


@pytest.mark.parametrize("form", ["norm", "squared"])
@pytest.mark.parametrize("quantity", ["position", "velocity"])
@SETTINGS
@given(
    radius=st.floats(0.5, 2.0),
    rate=st.floats(0.3, 1.5),
    climb=st.floats(-0.5, 0.5),
    t=st.floats(0.0, 5.0),
    error=directions,
    other=vec3,
    slack=coords(-3, 3),
    slack_rate=coords(-3, 3),
    constant=st.booleans(),
    ab=gains,
)
def test_tracking_error_bound_rows_match_finite_differences_and_hand_formulas(
    quantity, form, radius, rate, climb, t, error, other, slack, slack_rate, constant, ab
):
    reference = Helix(radius, rate, climb)
    bound = (lambda t: (1.7, 0.0, 0.0)) if constant else breathing_bound
    body = gmuk.PointMass("p", 2.0)
    kw = {"baumgarte": gmuk.Baumgarte(alpha=ab[0], beta=ab[1]), "name": "h"}
    analytic = gmuk.TrackingErrorBound(
        body, reference, 1.7 if constant else bound, quantity=quantity, form=form, **kw
    )
    fd = ValueOnlyTracking(body, reference, bound, quantity, form, **kw)
    system = gmuk.System([body], [analytic])
    # the error whose norm is taken is `error` (‖·‖ ≥ 0.2: the norm form is smooth there)
    if quantity == "position":
        r, v = reference.position(t) + error, reference.velocity(t) + other
    else:
        r, v = reference.position(t) + other, reference.velocity(t) + error
    state = raw_state(
        system, t, r={"p": r}, v={"p": v}, w={"h.upper": slack}, w_dot={"h.upper": slack_rate}
    )
    A_h, b_h, h, h_dot = tracking_by_hand(quantity, form, r, v, t, reference, bound)
    ref = expected_rows(A_h, b_h, h, h_dot, quantity, [(0.0, 1.0)], [slack], [slack_rate], *ab)
    assert analytic.h(state) == pytest.approx(h, rel=EXACT_RTOL, abs=EXACT_RTOL)
    assert fd.h(state) == pytest.approx(h, rel=EXACT_RTOL, abs=EXACT_RTOL)
    assert row_error(analytic.rows(state), ref) <= EXACT_RTOL
    assert row_error(fd.rows(state), ref) <= FD_RTOL
    if quantity == "position":
        q, nu = (r,), (v,)
        assert analytic.rate(q, nu, t) == pytest.approx(h_dot, rel=EXACT_RTOL, abs=EXACT_RTOL)
        assert abs(fd.rate(q, nu, t) - h_dot) <= FD_RTOL * max(1.0, abs(h_dot))


def test_both_bounds_give_one_row_each_with_their_own_slack_column():
    body = gmuk.PointMass("p", 2.0)
    c = gmuk.PlaneBound(body, [0.0, 0.0, 2.0], lower=-1.0, upper=2.0, name="z")
    system = gmuk.System([body], [c])
    assert [b.name for b in system.bodies] == ["p", "z.upper", "z.lower"]
    assert [(b.side, b.value, b.sign) for b in c.bounds] == [
        ("upper", 2.0, 1.0),
        ("lower", -1.0, -1.0),
    ]
    state = raw_state(
        system,
        r={"p": [0.0, 0.0, 0.5]},
        v={"p": [0.0, 0.0, 0.0]},
        w={"z.upper": 0.7, "z.lower": 1.1},
        w_dot={"z.upper": 0.3, "z.lower": -0.2},
    )
    A, b = c.rows(state)
    np.testing.assert_array_equal(A, [[0, 0, 1, 1.4, 0], [0, 0, 1, 0, -2.2]])
    np.testing.assert_allclose(b, [-2 * 0.3**2, 2 * 0.2**2], rtol=1e-15)


# ---------------------------------------------------------------------------- 5. initial slack
@SETTINGS
@given(
    normal=directions,
    h=st.floats(-0.99, 1.99),
    velocity=vec3,
    other=vec3,
)
def test_initial_slack_inside_the_bounds_is_the_square_root_of_the_margin(
    normal, h, velocity, other
):
    body = gmuk.PointMass("p", 2.0)
    c = gmuk.PlaneBound(body, normal, lower=-1.0, upper=2.0, name="x")
    n_hat = normal / np.linalg.norm(normal)
    r = h * n_hat + np.cross(n_hat, other)  # n̂ · r = h
    system = gmuk.System([body], [c], [gmuk.LinearSpringDamper(10.0, 5.0)])
    state = system.state(r={"p": r}, v={"p": velocity})
    h_dot = n_hat @ velocity
    w_u, w_l = math.sqrt(2.0 - h), math.sqrt(h + 1.0)
    iu, il = (system.layout.slot(n).index for n in ("x.upper", "x.lower"))
    assert state.x[iu] == pytest.approx(w_u, rel=1e-12)
    assert state.x[il] == pytest.approx(w_l, rel=1e-12)
    assert state.xdot[iu] == pytest.approx(-h_dot / (2 * w_u), rel=1e-12, abs=1e-12)
    assert state.xdot[il] == pytest.approx(h_dot / (2 * w_l), rel=1e-12, abs=1e-12)
    # φ = 0 and φ̇ = 0 for both equalities
    for w, wd, bound, sigma in ((w_u, state.xdot[iu], 2.0, 1.0), (w_l, state.xdot[il], -1.0, -1.0)):
        assert abs(h - bound + sigma * w * w) <= 1e-12 * 4
        assert abs(h_dot + 2 * sigma * w * wd) <= 1e-12 * max(1.0, abs(h_dot))


class SpeedUp(gmuk.InequalityConstraint):
    """v_z ≤ u or ≥ l: a velocity-level h of a point mass."""

    def value(self, q, nu, t):
        return nu[0][2]


def test_velocity_level_initial_slack_rate_is_the_square_root_of_the_margin():
    body = gmuk.PointMass("p", 1.0)
    c = SpeedUp([body], lower=-0.5, upper=0.5, level="velocity", name="vz")
    system = gmuk.System([body], [c])
    state = system.state(r={"p": [0.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.3]})
    iu, il = (system.layout.slot(n).index for n in ("vz.upper", "vz.lower"))
    assert state.x[iu] == 0.0 and state.x[il] == 0.0
    assert state.xdot[iu] == pytest.approx(math.sqrt(0.2), rel=1e-14)
    assert state.xdot[il] == pytest.approx(math.sqrt(0.8), rel=1e-14)


@pytest.mark.parametrize("side", ["lower", "upper"])
def test_on_the_bound_pressed_outward_starts_with_zero_slack_and_the_bound_holds(side):
    # lower: z ≥ 0 with a force −z; upper: z ≤ 0 with a force +z (both push out)
    sign = -1.0 if side == "lower" else 1.0
    body = gmuk.PointMass("p", 2.0)
    c = gmuk.PlaneBound(body, [0.0, 0.0, 1.0], **{side: 0.0}, name="z")
    push = gmuk.AppliedWrench(body, [0.3, 0.0, 6.0 * sign])
    system = gmuk.System([body], [c], [push])
    state = system.state(r={"p": [1.0, 2.0, 0.0]}, v={"p": [0.5, 0.0, 0.0]})
    i = system.layout.slot(f"z.{side}").index
    assert (state.x[i], state.xdot[i]) == (0.0, 0.0)
    acc = system.accelerations(state)
    f_c = acc.of(body, "constraint_force")
    np.testing.assert_allclose(f_c, [0.0, 0.0, -6.0 * sign], rtol=0, atol=1e-12)
    np.testing.assert_allclose(acc.of(body), [0.15, 0.0, 0.0], rtol=0, atol=1e-12)
    traj = system.simulate(state, (0.0, 2.0), t_eval=np.linspace(0.0, 2.0, 41), rtol=1e-10)
    z = traj.r_N[:, 0, 2]
    assert np.abs(z).max() <= 1e-9
    assert traj.r_N[-1, 0, 0] == pytest.approx(1.0 + 0.5 * 2.0 + 0.5 * 0.15 * 4.0, rel=1e-9)


@pytest.mark.parametrize("side", ["lower", "upper"])
def test_on_the_bound_moving_inward_starts_with_the_free_slack_rate_and_no_force(side):
    sigma = -1.0 if side == "lower" else 1.0
    mass, force = 2.0, 6.0
    body = gmuk.PointMass("p", mass)
    c = gmuk.PlaneBound(body, [0.0, 0.0, 1.0], **{side: 0.0}, name="z")
    # the force points inside: +z for z ≥ 0, −z for z ≤ 0
    system = gmuk.System([body], [c], [gmuk.AppliedWrench(body, [0.0, 0.0, -sigma * force])])
    state = system.state(r={"p": [0.0, 0.0, 0.0]}, v={"p": [1.0, 0.0, 0.0]})
    i = system.layout.slot(f"z.{side}").index
    h_ddot_free = -sigma * force / mass
    assert state.x[i] == 0.0
    assert state.xdot[i] == pytest.approx(math.sqrt(-sigma * h_ddot_free / 2.0), rel=1e-14)
    acc = system.accelerations(state)
    assert np.abs(acc.of(body, "constraint_force")).max() <= 1e-12 * force
    assert acc.of(body)[2] == pytest.approx(h_ddot_free, rel=1e-12)


@pytest.mark.parametrize(("z_dot", "direction"), [(0.5, "out of"), (-0.5, "into")])
def test_on_a_position_bound_with_a_rate_is_an_error_saying_it_is_moving(z_dot, direction):
    body = gmuk.PointMass("p", 1.0)
    system = gmuk.System([body], [gmuk.PlaneBound(body, [0, 0, 1], upper=1.0, name="top")])
    with pytest.raises(ConstraintError, match="moving") as info:
        system.state(r={"p": [0.0, 0.0, 1.0]}, v={"p": [0.0, 0.0, z_dot]})
    assert f"moving {direction} it" in str(info.value)
    assert "'top'" in str(info.value) and f"{z_dot:g}" in str(info.value)


def test_on_a_velocity_bound_with_the_free_motion_leaving_it_is_an_error():
    body = gmuk.PointMass("p", 1.0)
    c = SpeedUp([body], upper=0.5, level="velocity", name="vz")
    leaving = gmuk.System([body], [c], [gmuk.AppliedWrench(body, [0.0, 0.0, -1.0])])
    with pytest.raises(ConstraintError, match="free motion leaves it") as info:
        leaving.state(r={"p": [0.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.5]})
    assert "'vz'" in str(info.value)
    # pressing outward instead: (0, 0), and the bound holds v_z at 0.5
    c2 = SpeedUp([body], upper=0.5, level="velocity", name="vz")
    pressing = gmuk.System([body], [c2], [gmuk.AppliedWrench(body, [0.0, 0.0, 1.0])])
    state = pressing.state(r={"p": [0.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.5]})
    assert (state.x[3], state.xdot[3]) == (0.0, 0.0)
    acc = pressing.accelerations(state)
    assert abs(acc.of(body)[2]) <= 1e-12
    assert acc.of(body, "constraint_force")[2] == pytest.approx(-1.0, rel=1e-12)


# ---------------------------------------------------------------------------- 4. rigid bodies
class SpinRate(gmuk.InequalityConstraint):
    """ω₃ (body z rate) of a rigid body: a velocity-level h in rad/s."""

    def value(self, q, nu, t):
        return nu[0][2]


def test_rigid_body_held_above_a_plane_and_below_a_spin_rate():
    body = gmuk.RigidBody("box", 3.0, np.diag([1.0, 2.0, 3.0]))
    floor = gmuk.PlaneBound(body, [0.0, 0.0, 1.0], lower=0.0, name="floor")
    spin = SpinRate([body], upper=0.5, level="velocity", unit="rad/s", name="spin")
    push = gmuk.AppliedWrench(body, [0, 0, 0, 0, 0, -6.0], frame="inertial")  # 2 m/s² down
    torque = gmuk.AppliedWrench(body, [0, 0, 1.5, 0, 0, 0])  # spins ω₃ up at 0.5 rad/s²
    system = gmuk.System([body], [floor, spin], [push, torque])
    g0 = np.eye(4)
    g0[:3, :3], g0[:3, 3] = so3.exp([0.05, -0.03, 0.2]), [0.0, 0.0, 1.0]
    state = system.state(g={"box": g0}, V={"box": [0.05, -0.04, 0.0, 0.2, 0.0, 0.0]})
    t = np.linspace(0.0, 4.0, 401)
    traj = system.simulate(state, (0.0, 4.0), t_eval=t, rtol=1e-10, atol=1e-12)
    assert traj.success
    z, w3 = traj.g_NB[:, 0, 2, 3], traj.V_B[:, 0, 2]
    # held: never beyond the bound by more than 1e-9
    assert z.min() >= -1e-9
    assert w3.max() <= 0.5 + 1e-9
    # and meaningful: each bound becomes active (free motion would cross both by t = 1.1 s)
    assert z.min() < 1e-3 * z[0]
    assert (0.5 - w3).min() < 1e-3 * (0.5 - w3[0])
    kkt = gmuk.kkt.kkt_diagnostics(system, traj)
    assert kkt["floor.lower"].primal_violation.max() <= 1e-9
    assert kkt["spin.upper"].primal_violation.max() <= 1e-9
    assert kkt["spin.upper"].multiplier_unit == "J/(rad/s·s)"
    assert kkt.stationarity.max() <= 1e-12


# ---------------------------------------------------------------------------- 6. bad input
class Scripted(gmuk.InequalityConstraint):
    """h = make(x), x the first coordinate of a point mass: a value() of any form."""

    def __init__(self, bodies, make, **kw):
        super().__init__(bodies, **kw)
        self.make = make

    def value(self, q, nu, t):
        return self.make(q[0][0])


def scripted_system(make, **kw):
    body = gmuk.PointMass("p", 1.0)
    c = Scripted([body], make, name="bad", **kw)
    system = gmuk.System([body], [c])
    state = raw_state(
        system,
        r={"p": [0.2, 0.0, 0.0]},
        v={"p": [1.0, 0.0, 0.0]},
        w={"bad.upper": 1.0},
        w_dot={"bad.upper": -0.5},
    )
    return system, c, state


@pytest.mark.parametrize("level", ["position", "velocity"])
def test_value_of_the_wrong_shape_is_a_constraint_error_saying_scalar(level):
    system, c, state = scripted_system(lambda x: np.array([x, 1.0]), upper=5.0, level=level)
    with pytest.raises(ConstraintError, match="scalar") as info:
        system.state(r={"p": [0.2, 0.0, 0.0]}, v={"p": [1.0, 0.0, 0.0]})
    assert "'bad'" in str(info.value) and "(2,)" in str(info.value)
    # at rows time (the slack given): the same clear error, not a TypeError from float()
    with pytest.raises(ConstraintError, match="scalar") as info:
        c.rows(state)
    assert "'bad'" in str(info.value) and "(2,)" in str(info.value)


@pytest.mark.parametrize("shape", [(), (1,), (1, 1)])
def test_value_as_a_size_one_array_gives_the_rows_of_a_float(shape):
    _, plain, state = scripted_system(lambda x: x * x, upper=5.0)
    system, shaped, _ = scripted_system(lambda x: np.full(shape, x * x), upper=5.0)
    ref = plain.rows(state)
    got = shaped.rows(state)
    np.testing.assert_array_equal(got[0], ref[0])
    np.testing.assert_array_equal(got[1], ref[1])
    s = system.state(r={"p": [0.2, 0.0, 0.0]}, v={"p": [1.0, 0.0, 0.0]})
    assert s.x[3] == pytest.approx(math.sqrt(5.0 - 0.04), rel=1e-14)


def test_value_not_finite_is_a_constraint_error_naming_the_constraint():
    system, c, state = scripted_system(lambda x: float("nan"), upper=5.0)
    with pytest.raises(ConstraintError, match="not finite") as info:
        system.state(r={"p": [0.2, 0.0, 0.0]}, v={"p": [1.0, 0.0, 0.0]})
    assert "'bad'" in str(info.value) and "nan" in str(info.value)
    with pytest.raises(ConstraintError, match="not finite") as info:
        c.rows(state)
    assert "'bad'" in str(info.value)


@pytest.mark.parametrize(
    ("kw", "needles"),
    [
        ({"lower": 2.0, "upper": 1.0}, ["lower < upper", "2.0", "1.0"]),
        ({"lower": 1.5, "upper": 1.5}, ["lower < upper", "1.5", "HolonomicConstraint"]),
        ({}, ["upper=", "lower="]),
        ({"upper": float("inf")}, ["upper", "finite", "inf"]),
        ({"lower": float("nan")}, ["lower", "finite", "nan"]),
        ({"upper": "one"}, ["upper", "number", "'one'"]),
        ({"upper": 1.0, "level": "acceleration"}, ["level", "'acceleration'"]),
    ],
)
def test_bad_definitions_are_definition_errors_with_the_values(kw, needles):
    with pytest.raises(DefinitionError) as info:
        Scripted(["p"], lambda x: x, name="bad", **kw)
    msg = str(info.value)
    assert isinstance(info.value, GmukError)
    assert "'bad'" in msg
    for needle in needles:
        assert needle in msg


@pytest.mark.parametrize(
    ("make", "needle"),
    [
        (lambda p: gmuk.PlaneBound(p, [0.0, 0.0, 0.0], upper=1.0), "normal"),
        (lambda p: gmuk.TrackingErrorBound(p, Helix(1, 1, 0), 0.0, name="t"), "bound must be > 0"),
        (lambda p: gmuk.TrackingErrorBound(p, Helix(1, 1, 0), 1.0, form="cubed"), "'cubed'"),
        (lambda p: gmuk.TrackingErrorBound(p, Helix(1, 1, 0), 1.0, quantity="jerk"), "'jerk'"),
        (lambda p: gmuk.TrackingErrorBound(p, object(), 1.0), "position(t)"),
    ],
)
def test_bad_built_in_inequalities_are_definition_errors(make, needle):
    with pytest.raises(DefinitionError) as info:
        make(gmuk.PointMass("p", 1.0))
    assert needle in str(info.value)


def test_an_infeasible_start_says_by_how_much():
    body = gmuk.PointMass("p", 1.0)
    system = gmuk.System([body], [gmuk.PlaneBound(body, [1, 0, 0], lower=5.0, name="x_min")])
    with pytest.raises(ConstraintError, match="violates") as info:
        system.state(r={"p": [4.75, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]})
    msg = str(info.value)
    assert "'x_min'" in msg and "h ≥ 5" in msg and "outside by 0.25 m" in msg and "4.75" in msg


def test_giving_an_owned_slack_to_system_state_is_a_definition_error():
    body = gmuk.PointMass("p", 1.0)
    system = gmuk.System([body], [gmuk.PlaneBound(body, [1, 0, 0], upper=1.0, name="x")])
    with pytest.raises(DefinitionError, match="belongs to a constraint") as info:
        system.state(r={"p": [0.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]}, s={"x.upper": 1.0})
    assert "s['x.upper']" in str(info.value)
    with pytest.raises(DefinitionError, match=re.escape("s_dot['x.upper']")):
        system.state(r={"p": [0.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]}, s_dot={"x.upper": 0.0})


def test_two_inequalities_with_one_name_are_a_duplicate_body_name():
    body = gmuk.PointMass("p", 1.0)
    a = gmuk.PlaneBound(body, [1, 0, 0], upper=1.0, name="box")
    b = gmuk.PlaneBound(body, [0, 1, 0], upper=1.0, name="box")
    with pytest.raises(DefinitionError, match=re.escape("duplicate body name 'box.upper'")):
        gmuk.System([body], [a, b])


def norm_tracking_on_its_reference():
    body = gmuk.PointMass("p", 1.0)
    ref = Helix(1.0, 1.0, 0.0)
    c = gmuk.TrackingErrorBound(body, ref, 1.0, name="trk")
    system = gmuk.System([body], [c])
    on_reference = {
        "r": {"p": ref.position(0.0)},
        "v": {"p": ref.velocity(0.0) + np.array([0, 0, 0.1])},
    }
    return c, system, on_reference


def test_norm_tracking_bound_starting_at_zero_error_is_a_constraint_error():
    """The docstring: at zero error the norm form's rows are undefined, "an error, not a
    NaN". A start on the reference is the natural start of a tracking run."""
    _, system, on_reference = norm_tracking_on_its_reference()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ConstraintError, match="'trk'"):
            system.state(**on_reference)


def test_norm_tracking_bound_rows_at_zero_error_are_a_constraint_error_without_warning():
    c, system, on_reference = norm_tracking_on_its_reference()
    state = raw_state(system, **on_reference, w={"trk.upper": 1.0}, w_dot={"trk.upper": 0.0})
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ConstraintError, match="'trk'"):
            c.rows(state)


def test_squared_tracking_bound_is_defined_at_zero_error():
    body = gmuk.PointMass("p", 1.0)
    ref = Helix(1.0, 1.0, 0.0)
    c = gmuk.TrackingErrorBound(body, ref, 2.0, form="squared", name="trk")
    system = gmuk.System([body], [c])
    state = system.state(r={"p": ref.position(0.0)}, v={"p": ref.velocity(0.0)})
    assert state.x[3] == pytest.approx(math.sqrt(2.0), rel=1e-14)  # h = −δ²/2 = −2
    A, b = c.rows(state)
    np.testing.assert_array_equal(A, [[0.0, 0.0, 0.0, 2.0 * math.sqrt(2.0)]])
    assert np.isfinite(b).all()


# ---------------------------------------------------------------------------- 8. singular point
class Cubic(gmuk.InequalityConstraint):
    """h = x³ ≤ 0: the gradient 3x² vanishes on the bound."""

    def value(self, q, nu, t):
        return q[0][0] ** 3


def cubic_system():
    body = gmuk.PointMass("p", 1.0)
    c = Cubic([body], upper=0.0, name="cubic")
    pull = gmuk.AppliedWrench(body, [0.5, -1.0, 0.25])
    return body, c, gmuk.System([body], [c], [pull])


def test_on_the_bound_with_zero_gradient_and_zero_slack_rate_the_row_is_void():
    _, c, system = cubic_system()
    state = raw_state(
        system,
        r={"p": [0, 0, 0]},
        v={"p": [1.0, 0.2, 0]},
        w={"cubic.upper": 0.0},
        w_dot={"cubic.upper": 0.0},
    )
    A, b = c.rows(state)
    np.testing.assert_array_equal(A, np.zeros((1, 4)))
    np.testing.assert_array_equal(b, [0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        acc = system.accelerations(state)
    # the row is 0 = 0: no constraint force, the free motion, rank 0
    assert acc.rank == 0 and acc.residual == 0.0
    np.testing.assert_array_equal(acc.constraint, np.zeros(4))
    np.testing.assert_array_equal(acc.multipliers, [0.0])
    np.testing.assert_allclose(acc.total, [0.5, -1.0, 0.25, 0.0], rtol=0, atol=1e-15)


@pytest.mark.parametrize("w_dot", [1.0, 1e-3])
def test_on_the_bound_with_zero_gradient_and_a_slack_rate_warns_inconsistent(w_dot):
    _, _, system = cubic_system()
    state = raw_state(
        system,
        r={"p": [0, 0, 0]},
        v={"p": [1.0, 0.2, 0]},
        w={"cubic.upper": 0.0},
        w_dot={"cubic.upper": w_dot},
    )
    with pytest.warns(InconsistentConstraintsWarning, match="inconsistent"):
        acc = system.accelerations(state)
    # 0 · ν̇ = −2ẇ² has no solution: least squares keeps the free motion, finite numbers
    for field in ("free", "constraint", "total", "constraint_force", "multipliers"):
        assert np.isfinite(getattr(acc, field)).all()
    assert acc.rank == 0
    assert acc.residual == pytest.approx(2.0 * w_dot**2, rel=1e-15)
    np.testing.assert_array_equal(acc.constraint, np.zeros(4))
    np.testing.assert_allclose(acc.total, [0.5, -1.0, 0.25, 0.0], rtol=0, atol=1e-15)


def test_moving_onto_a_bound_with_zero_gradient_reflects_at_the_cusp():
    """x³ + w² = 0 is the cusp x = −|w|^(2/3): the run passes w = 0 (measured: no warning,
    the mass turns back, energy kept to 3.3e-4 relative, φ drift 6e-10)."""
    body = gmuk.PointMass("p", 1.0)
    c = Cubic([body], upper=0.0, name="cubic")
    system = gmuk.System([body], [c])
    state = system.state(r={"p": [-1.0, 0.0, 0.0]}, v={"p": [1.0, 0.0, 0.0]})
    assert state.x[3] == 1.0 and state.xdot[3] == pytest.approx(-1.5, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error", InconsistentConstraintsWarning)
        traj = system.simulate(
            state, (0.0, 3.0), t_eval=np.linspace(0.0, 3.0, 301), rtol=1e-10, atol=1e-12
        )
    x, w = traj.r_N[:, 0, 0], traj.x[:, 3]
    assert traj.success
    assert x.max() <= 1e-9  # held
    assert w.min() < -3.0 and traj.xdot[-1, 0] < -0.7  # through w = 0 and back
    assert np.abs(x**3 + w**2).max() <= 1e-9
    energy = 0.5 * (traj.v_N[:, 0] ** 2).sum(axis=1) + 0.5 * traj.xdot[:, 3] ** 2
    assert np.abs(energy / energy[0] - 1.0).max() <= 1e-3
