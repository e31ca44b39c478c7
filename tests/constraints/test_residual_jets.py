"""Rows of residual-defined constraints from derivative jets (issue #26 item 7).

The rows of :class:`gmuk.HolonomicConstraint` and :class:`gmuk.NonholonomicConstraint` come
from one call of the residual on jets (``gmuk/constraints/_jet.py``): they must equal the
analytic rows to round-off (rigid body, point mass, two bodies, explicit time, velocity
level), the jet arithmetic must be the chain rule (hypothesis, against mpmath's derivatives
and against finite differences), and a residual that jets cannot trace must fall back to the
finite differences, visibly, never giving wrong rows.
"""

from __future__ import annotations

import warnings

import mpmath
import numpy as np
import pytest
from helpers import Distance, random_rigid_bodies, random_state
from hypothesis import given, settings
from hypothesis import strategies as st

import gmuk
from gmuk.constraints import _jet
from gmuk.errors import GmukWarning
from gmuk.lie import se3, so3

TOL = 1e-12  # relative to the rows' scale: round-off, not truncation


def close(x, ref, tol=TOL):
    x, ref = np.asarray(x, dtype=float), np.asarray(ref, dtype=float)
    assert x.shape == ref.shape, (x.shape, ref.shape)
    assert np.abs(x - ref).max(initial=0.0) <= tol * max(1.0, np.abs(ref).max(initial=0.0))


def random_pose(rng):
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = so3.exp(rng.normal(size=3)), rng.normal(size=3)
    return g


def point_velocity_rows(g, V, p):
    """x = R p + r: (∂x/∂V (3, 6), velocity-product part of ẍ (3,)), with ẋ = R(ω × p + v)."""
    R, w, v = g[:3, :3], V[:3], V[3:]
    return R @ np.hstack([-so3.hat(p), np.eye(3)]), R @ np.cross(w, np.cross(w, p) + v)


# --------------------------------------------------------------------------------------
# constraints written by a user, and their rows by hand


class Pinned(gmuk.HolonomicConstraint):
    """The README's pin: φ = R_NB p_B + r_N (m), p_B = 0.5 m along axis 3."""

    def residual(self, q, t):
        (g_NB,) = q
        return g_NB[:3, :3] @ [0.0, 0.0, 0.5] + g_NB[:3, 3]


def pinned_rows(g, V):
    J, acc = point_velocity_rows(g, V, np.array([0.0, 0.0, 0.5]))
    return J, -acc


def distance_rows(g_a, g_b, V_a, V_b, p_a, p_b):
    e = g_a[:3, :3] @ p_a + g_a[:3, 3] - g_b[:3, :3] @ p_b - g_b[:3, 3]
    Ja, acc_a = point_velocity_rows(g_a, V_a, p_a)
    Jb, acc_b = point_velocity_rows(g_b, V_b, p_b)
    ed = Ja @ V_a - Jb @ V_b
    A = 2.0 * e @ np.hstack([Ja, -Jb])
    return A[None, :], np.array([-2.0 * (ed @ ed + e @ (acc_a - acc_b))])


class Tether(gmuk.HolonomicConstraint):
    """|x − r| = L between a rigid body's point p_B and a point mass (norm, not squared)."""

    def residual(self, q, t):
        g, r = q
        return np.array([np.linalg.norm(g[:3, :3] @ [0.2, -0.1, 0.3] + g[:3, 3] - r) - 1.5])


def tether_rows(g, V, r, v):
    p = np.array([0.2, -0.1, 0.3])
    J, acc = point_velocity_rows(g, V, p)
    e = g[:3, :3] @ p + g[:3, 3] - r
    n = np.linalg.norm(e)
    u = e / n
    ed = J @ V - v
    A = np.concatenate([u @ J, -u])[None, :]
    # d²|e|/dt² = u·ë + (|ė|² − (u·ė)²)/|e|, ë's velocity part = acc
    return A, np.array([-(u @ acc + (ed @ ed - (u @ ed) ** 2) / n)])


class Circling(gmuk.HolonomicConstraint):
    """A point mass on a moving target c(t) = (cos t, sin t, t²/2) m: explicit time."""

    def residual(self, q, t):
        (r,) = q
        return r - np.array([np.cos(t), np.sin(t), 0.5 * t**2])


class SpinningPin(gmuk.HolonomicConstraint):
    """A rigid body's point p_B held on a rotating arm: R_NB p_B + r_N = R_z(t) a (m)."""

    def residual(self, q, t):
        (g,) = q
        c, s = np.cos(2.0 * t), np.sin(2.0 * t)
        target = np.stack([0.7 * c, 0.7 * s, 0.1 * t + 0.0 * c])
        return g[:3, :3] @ np.array([0.1, 0.2, 0.3]) + g[:3, 3] - target


def spinning_pin_rows(g, V, t):
    J, acc = point_velocity_rows(g, V, np.array([0.1, 0.2, 0.3]))
    # target'' = −4 · 0.7 (cos 2t, sin 2t, 0)
    target_dd = -4.0 * 0.7 * np.array([np.cos(2.0 * t), np.sin(2.0 * t), 0.0])
    return J, target_dd - acc


class NoSink(gmuk.NonholonomicConstraint):
    """ψ = e₃ᵀ R_NB v_B − sin t (m/s) of a rigid body, and x · ẋ of a point mass."""

    def residual(self, q, nu, t):
        (g, x), (V, xdot) = q, nu
        return np.array([(g[:3, :3] @ V[3:])[2] - np.sin(t), x @ xdot])


def no_sink_rows(g, V, x, xdot, t):
    R = g[:3, :3]
    A = np.zeros((2, 9))
    A[0, 3:6] = R[2]  # e₃ᵀ R
    A[1, 6:] = x
    # dψ/dτ with ν held: e₃ᵀ R (ω × v) − cos t, and ẋ · ẋ
    b = -np.array([R[2] @ np.cross(V[:3], V[3:]) - np.cos(t), xdot @ xdot])
    return A, b


# --------------------------------------------------------------------------------------
# the rows against the hand-derived ones


@pytest.mark.parametrize("seed", range(10))
def test_rigid_pin_rows_are_the_analytic_ones(seed):
    rng = np.random.default_rng(seed)
    g, V = random_pose(rng), rng.normal(size=6)
    con = Pinned(["bob"])
    A_ref, b_ref = pinned_rows(g, V)
    close(con.jacobian((g,), 0.3), A_ref)
    close(con.bias((g,), (V,), 0.3), b_ref)
    close(con.rate((g,), (V,), 0.3), A_ref @ V)
    assert con.jet_fallback is None


@pytest.mark.parametrize("seed", range(10))
def test_rigid_pair_distance_rows_are_the_analytic_ones(seed):
    rng = np.random.default_rng(100 + seed)
    g_a, g_b, V_a, V_b = random_pose(rng), random_pose(rng), rng.normal(size=6), rng.normal(size=6)
    p_a, p_b = rng.normal(size=3), rng.normal(size=3)
    con = Distance("a", "b", p_a, p_b, 1.0)
    A_ref, b_ref = distance_rows(g_a, g_b, V_a, V_b, p_a, p_b)
    close(con.jacobian((g_a, g_b), 0.0), A_ref)
    close(con.bias((g_a, g_b), (V_a, V_b), 0.0), b_ref)


@pytest.mark.parametrize("seed", range(10))
def test_rigid_and_point_mass_tether_rows_are_the_analytic_ones(seed):
    rng = np.random.default_rng(200 + seed)
    g, V, r, v = random_pose(rng), rng.normal(size=6), rng.normal(size=3), rng.normal(size=3)
    con = Tether(["body", "ball"])
    A_ref, b_ref = tether_rows(g, V, r, v)
    close(con.jacobian((g, r), 0.0), A_ref)
    close(con.bias((g, r), (V, v), 0.0), b_ref)


@pytest.mark.parametrize("t", [0.0, 0.7, -2.5, 40.0])
def test_explicitly_time_dependent_rows_are_the_analytic_ones(t):
    rng = np.random.default_rng(3)
    r, v = rng.normal(size=3), rng.normal(size=3)
    con = Circling(["ball"])
    close(con.jacobian((r,), t), np.eye(3))
    close(con.rate((r,), (v,), t), v - np.array([-np.sin(t), np.cos(t), t]))
    close(con.bias((r,), (v,), t), np.array([-np.cos(t), -np.sin(t), 1.0]))
    g, V = random_pose(rng), rng.normal(size=6)
    A_ref, b_ref = spinning_pin_rows(g, V, t)
    spin = SpinningPin(["bob"])
    close(spin.jacobian((g,), t), A_ref)
    close(spin.bias((g,), (V,), t), b_ref)


@pytest.mark.parametrize("seed", range(10))
def test_nonholonomic_rows_are_the_analytic_ones(seed):
    rng = np.random.default_rng(300 + seed)
    g, V, x, xdot = random_pose(rng), rng.normal(size=6), rng.normal(size=3), rng.normal(size=3)
    t = float(rng.normal())
    con = NoSink(["body", "ball"])
    A_ref, b_ref = no_sink_rows(g, V, x, xdot, t)
    close(con.jacobian((g, x), (V, xdot), t), A_ref)
    close(con.bias((g, x), (V, xdot), t), b_ref)


def test_rows_and_baumgarte_terms_from_a_state_are_the_analytic_ones():
    rng = np.random.default_rng(4)
    a, b = random_rigid_bodies(rng, 2)
    p_a, p_b = rng.normal(size=3), rng.normal(size=3)
    gains = gmuk.Baumgarte(alpha=3.0, beta=2.0)
    con = Distance(a, b, p_a, p_b, 1.0, baumgarte=gains)
    system = gmuk.System([a, b], [con])
    for _ in range(5):
        state = random_state(system, rng)
        g_a, g_b, V_a, V_b = state.pose(a), state.pose(b), state.twist(a), state.twist(b)
        A_ref, b_ref = distance_rows(g_a, g_b, V_a, V_b, p_a, p_b)
        phi = con.residual((g_a, g_b), state.t)
        A, bb = con.rows(state)
        close(A, A_ref)
        close(bb, b_ref - 3.0 * (A_ref @ np.r_[V_a, V_b]) - 2.0 * phi)
        close(con.violation(state)[1], A_ref @ np.r_[V_a, V_b])


def test_finite_differences_stay_available_and_agree_to_their_accuracy():
    rng = np.random.default_rng(5)
    g_a, g_b, V_a, V_b = random_pose(rng), random_pose(rng), rng.normal(size=6), rng.normal(size=6)
    p_a, p_b = rng.normal(size=3), rng.normal(size=3)
    exact = Distance("a", "b", p_a, p_b, 1.0)
    fd = Distance("a", "b", p_a, p_b, 1.0, derivatives="fd")
    A_ref, b_ref = distance_rows(g_a, g_b, V_a, V_b, p_a, p_b)
    calls = []
    fd_residual = fd.residual
    object.__setattr__(fd, "residual", lambda q, t: calls.append(1) or fd_residual(q, t))
    close(fd.jacobian((g_a, g_b), 0.0), A_ref, 1e-7)
    close(fd.bias((g_a, g_b), (V_a, V_b), 0.0), b_ref, 1e-6)
    assert len(calls) > 40  # four per degree of freedom and the path: differences, not jets
    close(exact.jacobian((g_a, g_b), 0.0), A_ref)
    with pytest.raises(gmuk.errors.ConstraintError, match="derivatives must be"):
        Distance("a", "b", p_a, p_b, 1.0, derivatives="exact")


def test_analytic_overrides_take_precedence():
    class PinnedHalf(Pinned):
        def jacobian(self, q, t):
            return np.full((3, 6), 7.0)

    rng = np.random.default_rng(6)
    system = gmuk.System([gmuk.RigidBody("bob", 1.0, np.eye(3))], [con := PinnedHalf(["bob"])])
    state = random_state(system, rng)
    A, b = con.rows(state)
    assert np.all(A == 7.0)
    close(b, pinned_rows(state.pose("bob"), state.twist("bob"))[1])  # bias still exact


def test_one_residual_call_per_rows():
    calls = []

    class Counted(Pinned):
        def residual(self, q, t):
            calls.append(type(q[0]).__name__)
            return super().residual(q, t)

    system = gmuk.System([gmuk.RigidBody("bob", 1.0, np.eye(3))], [con := Counted(["bob"])])
    con.rows(random_state(system, np.random.default_rng(7)))
    assert calls == ["Jet"]


def test_the_readme_pendulum_holds_its_pin_to_round_off():
    bob = gmuk.RigidBody("bob", mass=2.0, inertia=np.diag([0.10, 0.12, 0.05]))
    system = gmuk.System([bob], [Pinned([bob])], [gmuk.UniformGravity()])
    g0 = np.eye(4)
    g0[:3, 3] = [0.0, 0.0, -0.5]
    w0 = np.array([2.0, 0.0, 5.0])
    state = system.state(g={"bob": g0}, V={"bob": np.r_[w0, -np.cross(w0, [0.0, 0.0, 0.5])]})
    traj = system.simulate(state, (0.0, 2.0), t_eval=np.linspace(0.0, 2.0, 51))
    pin_N = traj.body("bob").R @ [0.0, 0.0, 0.5] + traj.body("bob").position
    assert np.abs(pin_N).max() < 1e-12  # finite-difference rows drift ~1e-9 m here


# --------------------------------------------------------------------------------------
# the fallback to finite differences


class Inverted(gmuk.HolonomicConstraint):
    """A residual through np.linalg.inv, which jets do not support."""

    def residual(self, q, t):
        (g,) = q
        return np.linalg.inv(g)[:3, 3]


def inverted_rows(g, V):
    """φ = −Rᵀ r; its rows through the same finite differences (the reference here)."""
    return Inverted(["bob"], derivatives="fd").jacobian((g,), 0.0), Inverted(
        ["bob"], derivatives="fd"
    ).bias((g,), (V,), 0.0)


def test_an_unsupported_operation_falls_back_once_and_says_so():
    rng = np.random.default_rng(8)
    g, V = random_pose(rng), rng.normal(size=6)
    con = Inverted(["bob"])
    with pytest.warns(GmukWarning, match=r"numpy\.linalg\.inv"):
        A = con.jacobian((g,), 0.0)
    assert "numpy.linalg.inv" in con.jet_fallback
    assert "in residual, test_residual_jets.py" in con.jet_fallback  # the line that stopped it
    A_fd, b_fd = inverted_rows(g, V)
    np.testing.assert_array_equal(A, A_fd)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once: no second warning
        np.testing.assert_array_equal(con.bias((g,), (V,), 0.0), b_fd)

    # the finite differences are right: φ = −Rᵀ r, A = [−[Rᵀr]×... checked against jets of
    # the same φ written with supported operations
    class Supported(gmuk.HolonomicConstraint):
        def residual(self, q, t):
            (g,) = q
            return -(g[:3, :3].T @ g[:3, 3])

    close(A, Supported(["bob"]).jacobian((g,), 0.0), 1e-8)


@pytest.mark.parametrize(
    "residual, what",
    [
        (lambda g: np.array([float(g[0, 3])]), "float()"),
        (lambda g: np.array([g[0, 3] + 0.0]).astype(float), "ValueError"),
        (lambda g: np.zeros(2), "a result without derivatives"),
        (lambda g: np.einsum("ij,j->i", g[:3, :3], [1.0, 2.0, 3.0]), "numpy.einsum"),
        (lambda g: np.add.reduce(g[:3, 3]), "numpy.add.reduce"),
    ],
    ids=["float", "astype", "constant", "einsum", "reduce"],
)
def test_what_jets_cannot_trace_falls_back_to_finite_differences(residual, what):
    class User(gmuk.HolonomicConstraint):
        def residual(self, q, t):
            return residual(q[0])

    rng = np.random.default_rng(9)
    g, V = random_pose(rng), rng.normal(size=6)
    con, fd = User(["bob"]), User(["bob"], derivatives="fd")
    with pytest.warns(GmukWarning):
        A = con.jacobian((g,), 0.0)
    assert what in con.jet_fallback
    np.testing.assert_array_equal(A, fd.jacobian((g,), 0.0))
    np.testing.assert_array_equal(con.bias((g,), (V,), 0.0), fd.bias((g,), (V,), 0.0))


def test_a_residual_that_fails_on_floats_too_keeps_its_own_error_and_the_jets():
    class Broken(gmuk.HolonomicConstraint):
        def residual(self, q, t):
            raise ValueError("the user's own message")

    con = Broken(["bob"])
    g = np.eye(4)
    with pytest.raises(ValueError, match="the user's own message"):
        con.jacobian((g,), 0.0)
    assert con.jet_fallback is None  # the residual failed, not the jets


def test_a_singular_derivative_uses_finite_differences_for_that_state_only():
    class Length(gmuk.HolonomicConstraint):
        def residual(self, q, t):
            (r,) = q
            return np.array([np.linalg.norm(r)])

    con = Length(["ball"])
    A0 = con.jacobian((np.zeros(3),), 0.0)  # |r| at r = 0: no derivative; differences give 0
    assert np.all(np.isfinite(A0)) and con.jet_fallback is None
    r = np.array([3.0, 4.0, 0.0])
    close(con.jacobian((r,), 0.0), (r / 5.0)[None, :])


def test_branches_on_values_and_object_arrays_are_traced():
    class Piecewise(gmuk.HolonomicConstraint):
        def residual(self, q, t):
            (r,) = q
            z = r[2]
            lift = z**3 if z > 0 else -(z**2)  # a branch on the value
            items = [r[0] * r[1], lift, 2.0]  # a list of jets and a number
            return np.array(items) + np.sum(r)

    con = Piecewise(["ball"])
    r, v = np.array([0.5, -1.5, 2.0]), np.array([0.1, 0.2, 0.3])
    A = con.jacobian((r,), 0.0)
    close(A, [[1 + r[1], 1 + r[0], 1.0], [1.0, 1.0, 1 + 3 * r[2] ** 2], [1.0, 1.0, 1.0]])
    close(con.bias((r,), (v,), 0.0), -np.array([2 * v[0] * v[1], 6 * r[2] * v[2] ** 2, 0.0]))
    assert con.jet_fallback is None


# --------------------------------------------------------------------------------------
# the jet arithmetic: the chain rule


def path_jet(x0, x1, x2, n_eps=0):
    """x(ε, τ) = x0 + Σ εₖ eₖ + τ x1 + τ² x2 / 2 as a jet (ε over the entries of x0)."""
    x0 = np.asarray(x0, dtype=float)
    n_parts = n_eps + 3
    data = np.zeros((n_parts, *x0.shape))
    data[0], data[-2], data[-1] = x0, x1, x2
    for k in range(n_eps):
        data[(1 + k, *np.unravel_index(k, x0.shape))] = 1.0
    return _jet.Jet(data)


MP_UNARY = {
    np.sin: (mpmath.sin, (-4.0, 4.0)),
    np.cos: (mpmath.cos, (-4.0, 4.0)),
    np.tan: (mpmath.tan, (-1.4, 1.4)),
    np.arcsin: (mpmath.asin, (-0.95, 0.95)),
    np.arccos: (mpmath.acos, (-0.95, 0.95)),
    np.arctan: (mpmath.atan, (-5.0, 5.0)),
    np.sinh: (mpmath.sinh, (-3.0, 3.0)),
    np.cosh: (mpmath.cosh, (-3.0, 3.0)),
    np.tanh: (mpmath.tanh, (-3.0, 3.0)),
    np.exp: (mpmath.exp, (-3.0, 3.0)),
    np.expm1: (mpmath.expm1, (-3.0, 3.0)),
    np.log: (mpmath.log, (0.1, 10.0)),
    np.log1p: (lambda x: mpmath.log(1 + x), (-0.9, 10.0)),
    np.log10: (mpmath.log10, (0.1, 10.0)),
    np.log2: (lambda x: mpmath.log(x, 2), (0.1, 10.0)),
    np.sqrt: (mpmath.sqrt, (0.1, 10.0)),
    np.cbrt: (mpmath.cbrt, (0.1, 10.0)),
    np.square: (lambda x: x * x, (-5.0, 5.0)),
    np.reciprocal: (lambda x: 1 / x, (0.2, 5.0)),
    np.absolute: (abs, (0.1, 5.0)),
    np.deg2rad: (mpmath.radians, (-5.0, 5.0)),
}


def mp_path_derivatives(f, x0, x1, x2):
    """First and second τ-derivatives of f(x0 + τ x1 + τ² x2/2) at 0, to 30 digits."""
    with mpmath.workdps(30):
        h = lambda tau: f(mpmath.mpf(x0) + tau * x1 + tau * tau * x2 / 2)  # noqa: E731
        return float(mpmath.diff(h, 0, 1)), float(mpmath.diff(h, 0, 2))


def assert_rel(x, ref, tol=1e-12):
    assert abs(x - ref) <= tol * max(1.0, abs(ref)), (x, ref)


unit = st.floats(-1.0, 1.0)


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(sorted(MP_UNARY, key=lambda u: u.__name__)), unit, unit, unit, unit)
def test_functions_of_one_argument_follow_the_chain_rule(ufunc, s, x1, x2, neg):
    f_mp, (lo, hi) = MP_UNARY[ufunc]
    x0 = lo + (hi - lo) * (s + 1.0) / 2.0
    jet = ufunc(path_jet(x0, x1, x2, n_eps=1))
    d1, d2 = mp_path_derivatives(f_mp, x0, x1, x2)
    assert_rel(jet.data[0], float(f_mp(mpmath.mpf(x0))))
    assert_rel(jet.data[-2], d1, 1e-11)
    assert_rel(jet.data[-1], d2, 1e-10)
    assert_rel(jet.data[1], float(mpmath.diff(f_mp, x0)), 1e-11)  # ∂/∂ε: f'(x0)


@settings(max_examples=200, deadline=None)
@given(
    st.sampled_from(["mul", "div", "pow", "rpow", "atan2", "hypot", "sub", "powc"]),
    st.floats(0.2, 3.0), st.floats(0.2, 3.0), unit, unit, unit, unit,
)  # fmt: skip
def test_functions_of_two_arguments_follow_the_chain_rule(op, a0, b0, a1, b1, a2, b2):
    ops = {
        "mul": (lambda a, b: a * b, lambda a, b: a * b),
        "div": (lambda a, b: a / b, lambda a, b: a / b),
        "pow": (lambda a, b: a**b, lambda a, b: a**b),
        "rpow": (lambda a, b: 2.5**b + a, lambda a, b: mpmath.mpf(2.5) ** b + a),
        "powc": (lambda a, b: a**2.7 - b**0.5, lambda a, b: a ** mpmath.mpf(2.7) - mpmath.sqrt(b)),
        "atan2": (np.arctan2, mpmath.atan2),
        "hypot": (np.hypot, mpmath.hypot),
        "sub": (lambda a, b: np.subtract(a, b) - 1.0, lambda a, b: a - b - 1),
    }
    f_np, f_mp = ops[op]
    jet = f_np(path_jet(a0, a1, a2), path_jet(b0, b1, b2))
    with mpmath.workdps(30):

        def h(tau):
            return f_mp(a0 + tau * a1 + tau * tau * a2 / 2, b0 + tau * b1 + tau * tau * b2 / 2)

        d1, d2 = float(mpmath.diff(h, 0, 1)), float(mpmath.diff(h, 0, 2))
    assert_rel(jet.data[-2], d1, 1e-11)
    assert_rel(jet.data[-1], d2, 1e-10)


def fd_derivatives(f, x0, x1, x2, step=1e-3):
    """Jacobian in x0's entries and τ-derivatives along x0 + τ x1 + τ² x2/2 of the float
    function f, by five-point differences (the reference for expressions of arrays)."""

    def stencil1(h, s):
        return (h(-2 * s) - 8 * h(-s) + 8 * h(s) - h(2 * s)) / (12 * s)

    cols = []
    for k in range(x0.size):
        e = np.zeros(x0.size)
        e[k] = 1.0
        e = e.reshape(x0.shape)
        cols.append(stencil1(lambda s, e=e: np.asarray(f(x0 + s * e)), step))
    path = lambda s: np.asarray(f(x0 + s * x1 + s * s * x2 / 2))  # noqa: E731
    d2 = (
        -path(-2 * step) + 16 * path(-step) - 30 * path(0.0) + 16 * path(step) - path(2 * step)
    ) / (12 * step * step)
    return np.stack(cols, axis=-1), stencil1(path, step), d2


M = np.array([[1.0, 2.0, 0.5], [-0.3, 0.7, 1.1], [0.2, -1.0, 0.4]])
EXPRESSIONS = {
    "matvec": lambda x: M @ x + x @ M,
    "matrix": lambda x: (np.outer(x, x) @ M.T).T[1:, ::2],
    "cross": lambda x: np.cross(x, M[0]) + np.cross(M[1], x) + np.cross(x, x[::-1]),
    "norm": lambda x: np.linalg.norm(x) * np.sum(x**2) + np.linalg.norm(np.outer(x, x)),
    "dot": lambda x: np.dot(x, M @ x) - x.dot(x) / (1.0 + x[0] ** 2),
    "trace": lambda x: np.trace(np.outer(x, M @ x)) + np.outer(x, x).trace(),
    "stack": lambda x: np.stack([x, 2 * x**2]).ravel() - np.concatenate([x, x[:2]])[1:4].sum(),
    "hstack": lambda x: np.hstack([x[:1], np.array([3.0]), np.sin(x)]) * np.vstack([x, x])[1, 0],
    "trig": lambda x: np.arctan2(x[0], 2.0 + x[1]) * np.cos(x) - np.tan(x / 4) + np.exp(x) / 3,
    "inverse trig": lambda x: np.arcsin(x / 5.0) + np.arccos(x / 6.0) * np.abs(x[2] + 5.0),
    "log sqrt": lambda x: np.log(2.0 + x**2) + np.sqrt(1.0 + x * x) ** 3 - (2.0 + x) ** -1.5,
    "rmatmul list": lambda x: [1.0, 2.0, 3.0] @ np.outer(x, x) - (x @ [0.5, 0.1, 0.2]),
    "transpose reshape": lambda x: np.outer(x, M[2]).T.reshape(9)[::4] / (x[1] + 4.0),
    "where max": lambda x: np.where(x > 0.0, x**2, -x) + np.maximum(x, 0.3) - np.minimum(x, x[0]),
    "setitem": lambda x: _setitem_expression(x),
    "mean clip": lambda x: np.mean(np.outer(x, x), axis=0) + np.clip(x, -0.5, 0.5) * 3.0,
}


def _setitem_expression(x):
    y = x * 2.0
    y[1] = x[0] * x[2]
    y[::2] = y[::2] + 1.0
    return y


@settings(max_examples=150, deadline=None)
@given(
    st.sampled_from(sorted(EXPRESSIONS)),
    st.lists(st.floats(-1.5, 1.5), min_size=9, max_size=9),
)
def test_array_expressions_match_finite_differences(name, numbers):
    f = EXPRESSIONS[name]
    x0, x1, x2 = (np.array(numbers[i : i + 3]) for i in (0, 3, 6))
    # keep clear of the kinks of where/maximum/minimum/clip/abs, where differences fail
    if name in ("where max", "mean clip") and (
        min(np.abs(x0).min(), np.abs(x0 - 0.3).min(), np.abs(np.abs(x0) - 0.5).min()) < 0.05
        or np.abs(x0 - x0[0])[1:].min() < 0.05
    ):
        return
    if name == "norm" and np.linalg.norm(x0) < 0.1:
        return  # |x| has no derivative at 0 (gmuk takes differences there: the test above)
    jet = _jet.as_jet(f(path_jet(x0, x1, x2, n_eps=3)), 6)
    A, d1, d2 = fd_derivatives(f, x0, x1, x2)
    value = np.asarray(f(x0))
    np.testing.assert_allclose(jet.data[0], value, rtol=1e-13, atol=1e-13)
    scale = max(1.0, np.abs(value).max())
    np.testing.assert_allclose(np.moveaxis(jet.data[1:4], 0, -1), A, atol=1e-6 * scale)
    np.testing.assert_allclose(jet.data[-2], d1, atol=1e-6 * scale)
    np.testing.assert_allclose(jet.data[-1], d2, atol=1e-4 * scale)


def test_a_pose_seed_is_the_series_of_g_exp():
    rng = np.random.default_rng(10)
    g, V, xi = random_pose(rng), rng.normal(size=6), rng.normal(size=6)
    jet = _jet.seed_pose(g, V, 9, 0)
    s = 1e-4
    # ∂/∂εₖ of g exp(ε eₖ^), ∂/∂τ and ∂²/∂τ² of g exp(τ V^), by central differences
    for k in range(6):
        e = np.eye(6)[k]
        d = (g @ se3.exp(s * e) - g @ se3.exp(-s * e)) / (2 * s)
        np.testing.assert_allclose(jet.data[1 + k], d, atol=1e-7)
    d1 = (g @ se3.exp(s * V) - g @ se3.exp(-s * V)) / (2 * s)
    d2 = (g @ se3.exp(s * V) - 2 * g + g @ se3.exp(-s * V)) / s**2
    np.testing.assert_allclose(jet.data[-2], d1, atol=1e-7)
    np.testing.assert_allclose(jet.data[-1], d2, atol=1e-5)
    np.testing.assert_array_equal(jet.data[0], g)
    del xi


def test_jets_refuse_to_become_floats_and_compare_by_value():
    x = path_jet(np.array([1.0, -2.0]), np.ones(2), np.zeros(2), n_eps=2)
    for convert in (float, int, complex):
        with pytest.raises(_jet.JetUnsupported, match=convert.__name__):
            convert(x[0])
    with pytest.raises((TypeError, ValueError)):
        np.zeros(2)[0] = x[0]
    np.testing.assert_array_equal(x > 0, [True, False])
    np.testing.assert_array_equal(0 < x, [True, False])
    np.testing.assert_array_equal(np.less(x, [2.0, -3.0]), [True, False])
    assert x.shape == (2,) and x.ndim == 1 and len(x) == 2 and x.T.shape == (2,)
    a, b = x  # iteration
    assert a.shape == () and bool(b < 0)
    with pytest.raises(_jet.JetUnsupported, match=r"numpy\.linalg\.inv"):
        np.linalg.inv(np.outer(x, x))


POSE_EXPRESSIONS = {
    "rotation product": lambda g, t: (g[:3, :3].T @ g[:3, :3] @ M).ravel() * (1.0 + t),
    "angle": lambda g, t: np.array([np.arccos(0.999 * (np.trace(g[:3, :3]) - 1.0) / 2.0)]),
    "axes": lambda g, t: np.array([g[:3, 0] @ g[:3, 1] + np.cross(g[:3, 0], g[:3, 2])[1]]),
    "homogeneous": lambda g, t: (g @ np.array([0.1, -0.2, 0.3, 1.0]))[:3] - np.sin(t),
    "pose product": lambda g, t: (g @ g)[:3, 3] + np.linalg.norm(g[:3, 3]) * np.cos(2.0 * t),
    "euler-like": lambda g, t: np.array(
        [np.arctan2(g[2, 1], g[2, 2]), np.arcsin(np.clip(-g[2, 0], -1.0, 1.0)), t**2 * g[0, 3]]
    ),
    "columns": lambda g, t: np.concatenate([g[:3, 3], np.hstack([g[0, :3], 1.0])]) / (2.0 + t),
    "advanced index": lambda g, t: g[[0, 2], 3] * g[:3, :3][np.array([1, 0]), [2, 1]],
}


@pytest.mark.parametrize("name", sorted(POSE_EXPRESSIONS))
def test_residuals_of_a_pose_match_finite_differences(name):
    f = POSE_EXPRESSIONS[name]

    class User(gmuk.HolonomicConstraint):
        def residual(self, q, t):
            return f(q[0], t)

    rng = np.random.default_rng(11)
    exact, fd = User(["bob"]), User(["bob"], derivatives="fd")
    for _ in range(5):
        g = np.eye(4)
        g[:3, :3], g[:3, 3] = so3.exp(0.5 * rng.normal(size=3)), rng.normal(size=3)
        V, t = rng.normal(size=6), float(rng.uniform(0.1, 1.0))
        close(exact.jacobian((g,), t), fd.jacobian((g,), t), 1e-7)
        close(exact.rate((g,), (V,), t), fd.rate((g,), (V,), t), 1e-7)
        close(exact.bias((g,), (V,), t), fd.bias((g,), (V,), t), 1e-6)
    assert exact.jet_fallback is None
