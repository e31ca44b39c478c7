"""Constraint kinds: automatic rows of user residuals, relative (virtual pair), tracking,
T²SE(3), Baumgarte (McCann 2020, Eqs. 1, 4, 65–67, 73–74, 79–80, Section 4.1.3)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import Distance, ScrewReference, random_rigid_bodies, random_state

import gmuk
from gmuk.lie import se3, so3


def distance_rows_by_hand(state, a, b, p_a, p_b):
    """Analytic A, b of φ = |e|², e = x_a − x_b, with ẋ = R(v + ω × p)."""
    g_a, g_b, V_a, V_b = state.pose(a), state.pose(b), state.twist(a), state.twist(b)
    R_a, R_b = g_a[:3, :3], g_b[:3, :3]
    e = R_a @ p_a + g_a[:3, 3] - R_b @ p_b - g_b[:3, 3]
    # ẋ = R(v + ω × p) = R v − R p^× ω  →  ∂ẋ/∂V = R [−p^×, I]
    Ja = R_a @ np.hstack([-so3.hat(p_a), np.eye(3)])
    Jb = R_b @ np.hstack([-so3.hat(p_b), np.eye(3)])
    A = 2.0 * e @ np.hstack([Ja, -Jb])
    ed = Ja @ V_a - Jb @ V_b
    # ẍ = R(v̇ + ω̇ × p) + R ω × (v + ω × p): velocity-product part of ẍ_a − ẍ_b
    wa, wb = V_a[:3], V_b[:3]
    acc_a = R_a @ np.cross(wa, V_a[3:] + np.cross(wa, p_a))
    acc_b = R_b @ np.cross(wb, V_b[3:] + np.cross(wb, p_b))
    bias = -2.0 * (ed @ ed + e @ (acc_a - acc_b))
    return A[None, :], np.array([bias])


def test_automatic_rows_of_a_user_holonomic_constraint_match_hand_derived():
    rng = np.random.default_rng(20)
    a, b = random_rigid_bodies(rng, 2)
    p_a, p_b = np.array([0.3, -0.1, 0.2]), np.array([-0.2, 0.4, 0.1])
    con = Distance(a, b, p_a, p_b, 1.0)
    system = gmuk.System([a, b], [con])
    for _ in range(20):
        state = random_state(system, rng)
        A, bb = con.rows(state)
        A_ref, b_ref = distance_rows_by_hand(state, a, b, p_a, p_b)
        assert np.abs(A - A_ref).max() <= 1e-7 * np.abs(A_ref).max()
        assert abs(bb[0] - b_ref[0]) <= 1e-7 * max(abs(b_ref[0]), np.abs(A_ref).max())


def test_user_distance_constraint_holds_along_a_simulation():
    rng = np.random.default_rng(21)
    a, b = random_rigid_bodies(rng, 2)
    p_a, p_b = np.array([0.5, 0.0, 0.0]), np.array([-0.5, 0.0, 0.0])
    system = gmuk.System([a, b], [Distance(a, b, p_a, p_b, 1.0)], [gmuk.UniformGravity(bodies=[b])])
    # Start consistent: points 1 m apart, relative velocity orthogonal to the link.
    g_b = np.eye(4)
    g_b[:3, 3] = [2.0, 0.0, 0.0]
    V_b = np.array([0.0, 0.0, 0.3, 0.0, 0.5, 0.0])
    state = system.state(g={a.name: np.eye(4), b.name: g_b}, V={a.name: np.zeros(6), b.name: V_b})
    traj = system.simulate(state, (0.0, 3.0), rtol=1e-11, atol=1e-11)
    x_a = traj.g_NB[:, 0, :3, :3] @ p_a + traj.g_NB[:, 0, :3, 3]
    x_b = traj.g_NB[:, 1, :3, :3] @ p_b + traj.g_NB[:, 1, :3, 3]
    dist = np.linalg.norm(x_a - x_b, axis=1)
    assert np.abs(dist - 1.0).max() < 1e-7
    assert np.abs(traj.g_NB[-1, 1, :3, 3] - g_b[:3, 3]).max() > 0.1  # it really moved


class Sleigh(gmuk.NonholonomicConstraint):
    """Planar knife edge at the centre of mass: ω₁ = ω₂ = 0, v₂ = v₃ = 0 (body frame)."""

    def residual(self, q, nu, t):
        (V,) = nu
        return np.array([V[0], V[1], V[4], V[5]])


def test_nonholonomic_knife_edge_moves_on_the_analytic_circle():
    body = gmuk.RigidBody("sleigh", 2.0, np.diag([1.0, 2.0, 2.5]))
    system = gmuk.System([body], [Sleigh([body])])
    u, w = 1.5, 0.3  # forward speed (m/s), yaw rate (rad/s)
    state = system.state(g={"sleigh": np.eye(4)}, V={"sleigh": [0, 0, w, u, 0, 0]})
    con = system.constraints[0]
    A, b = con.rows(state)
    assert np.allclose(A, np.eye(6)[[0, 1, 4, 5]], atol=1e-9)
    assert np.allclose(b, 0.0, atol=1e-9)
    t = np.linspace(0.0, 20.0, 41)
    traj = system.simulate(state, (0.0, 20.0), t_eval=t, rtol=1e-11, atol=1e-11)
    radius = u / w
    expected = np.stack([radius * np.sin(w * t), radius * (1 - np.cos(w * t)), 0 * t], axis=1)
    assert np.abs(traj.body("sleigh").position - expected).max() < 1e-7
    assert (
        np.abs(traj.body("sleigh").euler("321")[:, 0] - np.angle(np.exp(1j * w * t))).max() < 1e-9
    )


def test_relative_constraint_rows_match_section_4_1_3():
    rng = np.random.default_rng(22)
    L, B = random_rigid_bodies(rng, 2, prefix="x")
    con = gmuk.RelativeConstraint(B, L, free_axes=[0])
    system = gmuk.System([L, B], [con])
    state = random_state(system, rng)
    A, b = con.rows(state)
    S = np.eye(6)[1:]
    g_BL = se3.inverse(state.pose(L)) @ state.pose(B)
    Ad_inv = se3.Ad(se3.inverse(g_BL))
    V_BL = state.twist(B) - Ad_inv @ state.twist(L)
    assert np.allclose(A, np.hstack([-S @ Ad_inv, S]))
    assert np.allclose(b, -S @ se3.ad(V_BL) @ Ad_inv @ state.twist(L))


def _virtual_pair(torque):
    J = np.diag([4.0, 5.0, 5.0])  # axisymmetric about the free axis: J₁φ̈ = L₁ exactly
    L, B = gmuk.RigidBody("virtual", 10.0, J), gmuk.RigidBody("spacecraft", 10.0, J)
    xi = np.array([0.0, 0.0, 0.05, 1.0, 0.0, 0.0])
    ref = ScrewReference(np.eye(4), xi)
    forces = [gmuk.AppliedWrench(B, torque)]
    system = gmuk.System(
        [L, B],
        [gmuk.ConfigurationTracking(L, ref), gmuk.RelativeConstraint(B, L, free_axes=[0])],
        forces,
    )
    state = system.state(
        g={"virtual": np.eye(4), "spacecraft": np.eye(4)}, V={"virtual": xi, "spacecraft": xi}
    )
    return system, state, ref


def test_virtual_pair_free_axis_moves_under_torque_and_others_stay_locked():
    torque = lambda t: np.array([0.2 * np.sin(t), 0, 0, 0, 0, 0])  # noqa: E731
    system, state, ref = _virtual_pair(torque)
    t = np.linspace(0.0, 10.0, 51)
    traj = system.simulate(state, (0.0, 10.0), t_eval=t, rtol=1e-11, atol=1e-12)
    g_L, g_B = traj.g_NB[:, 0], traj.g_NB[:, 1]
    rel = se3.log(se3.inverse(g_L) @ g_B)  # relative pose of B in L
    # L follows the reference exactly.
    g_ref = np.array([ref.evaluate(tt).g for tt in t])
    assert np.abs(se3.log(se3.inverse(g_ref) @ g_L)).max() < 1e-9
    # B rotates about its first axis only: roll grows, the five other components stay zero.
    assert np.abs(rel[:, 1:]).max() < 1e-9
    assert np.abs(rel[:, 0]).max() > 0.01
    # Roll obeys J₁ φ̈ = L₁ ((J₂ − J₃)ω₂ω₃ = 0): φ = 0.2/J₁ (t − sin t).
    assert np.abs(rel[:, 0] - 0.2 / 4.0 * (t - np.sin(t))).max() < 1e-8
    assert traj.multipliers.shape == (51, 11)


def test_tracking_constraint_b_is_eq_67_on_the_constraint_and_projected_off_it():
    rng = np.random.default_rng(23)
    (body,) = random_rigid_bodies(rng, 1)
    xi = rng.normal(size=6)
    ref = ScrewReference(se3.exp(rng.normal(size=6)), xi)
    con = gmuk.ConfigurationTracking(body, ref)
    system = gmuk.System([body], [con])
    r0 = ref.evaluate(0.7)
    on = system.state(g={body.name: r0.g}, V={body.name: r0.V}, t=0.7)
    A, b = con.rows(on)
    assert np.array_equal(A, np.eye(6))
    assert np.allclose(b, 0.0, atol=1e-12)  # constant twist: V̇ = 0 on the constraint
    off = random_state(system, rng)
    X = se3.inverse(off.pose(body)) @ ref.evaluate(0.0).g @ (se3.hat(xi) @ se3.hat(xi)) - se3.hat(
        off.twist(body)
    ) @ se3.hat(off.twist(body))
    _, b_off = con.rows(off)
    W = 0.5 * (X[:3, :3] - X[:3, :3].T)
    assert np.allclose(b_off, np.concatenate([so3.vee(W), X[:3, 3]]), atol=1e-12)


def test_tracking_calls_its_kernels_with_the_compiled_loops_types_from_a_read_only_state():
    """A State's arrays are read-only; the Python forms of tracking pass its kernels writable
    copies, so numba compiles each kernel for one type only, the compiled loop's (a read-only
    array type would be a second compilation on a fresh machine, seconds each)."""
    import numba

    from gmuk.constraints import tracking

    rng = np.random.default_rng(5)
    (body,) = random_rigid_bodies(rng, 1)
    con = gmuk.ConfigurationTracking(body, ScrewReference(np.eye(4), rng.normal(size=6)))
    state = random_state(gmuk.System([body], [con]), rng)
    assert not state.g.flags.writeable
    con.rows(state)
    con.violation(state)
    for kernel in (tracking.tracking_rows, tracking.tracking_b, tracking._errors):
        arrays = [a for sig in kernel.signatures for a in sig if isinstance(a, numba.types.Array)]
        assert all(a.mutable for a in arrays), (kernel.__name__, kernel.signatures)
    assert tracking.tracking_rows.signatures and tracking._errors.signatures  # both were called


def test_eq80_takes_exactly_one_constraint_while_reachable_rows_stack():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    ref = ScrewReference(np.eye(4), np.array([0.01, 0.02, -0.03, 1.0, 0.0, 0.5]))
    both = [gmuk.ConfigurationTrackingT2(a, ref), gmuk.ConfigurationTracking(a, ref)]
    with pytest.raises(gmuk.errors.DefinitionError, match="exactly one TangentBundleConstraint"):
        gmuk.System([a], both, tangent_bundle_method="eq80")
    with pytest.raises(gmuk.errors.DefinitionError, match="exactly one TangentBundleConstraint"):
        gmuk.System([a], [gmuk.ConfigurationTracking(a, ref)], tangent_bundle_method="eq80")
    # On R⁶ the T²SE(3) rows stack with the tracking rows (consistent, redundant).
    stacked = gmuk.System([a], both)
    alone = gmuk.System([a], both[1:])
    state = stacked.state(g={"a": ref.evaluate(0.0).g}, V={"a": ref.evaluate(0.0).V})
    A, b = stacked.constraint_rows(state)
    assert A.shape == (16 + 6, 6) and b.shape == (22,)  # A g̈ B = C: 4 × 4 rows
    x, y = stacked.accelerations(state), alone.accelerations(state)
    assert np.allclose(x.total, y.total, rtol=0, atol=1e-12)
    assert x.residual <= 1e-12


def test_baumgarte_drives_an_initial_tracking_error_to_zero():
    body = gmuk.RigidBody("a", 3.0, np.diag([1.0, 1.5, 2.0]))
    ref = ScrewReference(np.eye(4), np.array([0.0, 0.1, 0.0, 0.5, 0.0, 0.0]))
    con = gmuk.ConfigurationTracking(body, ref, baumgarte=gmuk.Baumgarte.critical(2.0))
    system = gmuk.System([body], [con])
    g0 = se3.exp(np.array([0.05, -0.03, 0.02, 0.1, -0.2, 0.05]))
    state = system.state(g={"a": g0}, V={"a": np.zeros(6)})
    traj = system.simulate(state, (0.0, 10.0), t_eval=[0.0, 10.0], rtol=1e-10, atol=1e-12)
    err = [
        np.abs(se3.log(se3.inverse(ref.evaluate(t).g) @ g)).max()
        for t, g in zip(traj.t, traj.g_NB[:, 0], strict=True)
    ]
    assert err[0] > 0.1 and err[1] < 1e-6  # e^{-ωt}(1 + ωt) at ωt = 20: 4e-8


def test_baumgarte_on_a_holonomic_residual_restores_the_constraint():
    rng = np.random.default_rng(25)
    a, b = random_rigid_bodies(rng, 2)
    p = np.zeros(3)
    con = Distance(a, b, p, p, 1.0, baumgarte=gmuk.Baumgarte.critical(3.0))
    system = gmuk.System([a, b], [con])
    g_b = np.eye(4)
    g_b[:3, 3] = [1.2, 0, 0]  # violates |x_a − x_b| = 1 by 0.2 m
    state = system.state(
        g={a.name: np.eye(4), b.name: g_b}, V={a.name: np.zeros(6), b.name: np.zeros(6)}
    )
    traj = system.simulate(state, (0.0, 8.0), t_eval=[8.0], rtol=1e-10, atol=1e-12)
    assert abs(np.linalg.norm(traj.g_NB[-1, 1, :3, 3] - traj.g_NB[-1, 0, :3, 3]) - 1.0) < 1e-6


def test_baumgarte_rejects_negative_gains():
    with pytest.raises(gmuk.errors.DefinitionError, match="≥ 0"):
        gmuk.Baumgarte(alpha=-1.0)


def _pair_systems(rng):
    from gmuk.constraints import VirtualPairT2

    J = np.array([[4.0, 0.2, 0.3], [0.2, 5.0, 0.1], [0.3, 0.1, 6.0]])  # not principal
    L, B = gmuk.RigidBody("virtual", 10.0, J), gmuk.RigidBody("spacecraft", 10.0, J)
    ref = ScrewReference(se3.exp(rng.normal(size=6)), np.array([0.01, 0.02, 0.05, 1, 0, 0.1]))
    forces = [gmuk.AppliedWrench(B, rng.normal(size=6))]
    r6 = gmuk.System(
        [L, B],
        [gmuk.ConfigurationTracking(L, ref), gmuk.RelativeConstraint(B, L, free_axes=[0])],
        forces,
    )
    reach = gmuk.System([L, B], [VirtualPairT2(B, L, ref)], forces)
    eq80 = gmuk.System([L, B], [VirtualPairT2(B, L, ref)], forces, tangent_bundle_method="eq80")
    return r6, reach, eq80, ref


def test_virtual_pair_on_t2se3_restricted_to_reachable_equals_r6():
    rng = np.random.default_rng(26)
    r6, reach, eq80, ref = _pair_systems(rng)
    for t in (0.0, 1.3, 7.0):
        r = ref.evaluate(t)
        h = se3.exp(np.array([rng.uniform(-1, 1), 0, 0, 0, 0, 0]))  # on the constraint
        V_B = np.array([rng.normal(), 0, 0, 0, 0, 0]) + se3.Ad(se3.inverse(h)) @ r.V
        state = r6.state(
            g={"virtual": r.g, "spacecraft": r.g @ h}, V={"virtual": r.V, "spacecraft": V_B}, t=t
        )
        a6, ar, ae = (s.accelerations(state) for s in (r6, reach, eq80))
        scale = np.abs(a6.constraint).max()
        assert np.abs(ar.total - a6.total).max() <= 1e-12 * scale
        assert ar.rank == 11
        # Eq. 80 as printed: much of its g̈_c is unreachable, and its projection is not the
        # Gauss-optimal constraint acceleration.
        assert ae.unreachable > 0.05
        assert np.abs(ae.total - a6.total).max() > 1e-6 * scale


def test_full_tracking_on_t2se3_agrees_with_r6_for_both_methods():
    rng = np.random.default_rng(27)
    (body,) = random_rigid_bodies(rng, 1)
    ref = ScrewReference(se3.exp(rng.normal(size=6)), rng.normal(size=6))
    forces = [gmuk.AppliedWrench(body, rng.normal(size=6))]
    r6 = gmuk.System([body], [gmuk.ConfigurationTracking(body, ref)], forces)
    reach, eq80 = (
        gmuk.System(
            [body], [gmuk.ConfigurationTrackingT2(body, ref)], forces, tangent_bundle_method=m
        )
        for m in ("reachable", "eq80")
    )
    # On the constraint all three agree and nothing is unreachable.
    r = ref.evaluate(0.4)
    on = r6.state(g={body.name: r.g}, V={body.name: r.V}, t=0.4)
    acc6 = r6.accelerations(on)
    scale = np.abs(acc6.constraint).max()  # total is V̇_d = 0 here; the forces are cancelled
    for system in (reach, eq80):
        acc = system.accelerations(on)
        assert np.abs(acc.total - acc6.total).max() <= 1e-12 * scale
        assert acc.unreachable < 1e-12
    # Off it, g̈ = g̈_d is unreachable: Eq. 67's projection (R⁶), Eq. 80 plus projection, and
    # the least-squares reachable solve all give the Frobenius-closest g(V^² + V̇^); only the
    # reachable solve says the rows are inconsistent.
    for _ in range(5):
        off = random_state(r6, rng)
        a6 = r6.accelerations(off).total
        scale = max(1.0, np.abs(a6).max())
        assert np.abs(eq80.accelerations(off).total - a6).max() <= 1e-12 * scale
        with pytest.warns(gmuk.errors.InconsistentConstraintsWarning):
            a_r = reach.accelerations(off).total
        assert np.abs(a_r - a6).max() <= 1e-12 * scale
