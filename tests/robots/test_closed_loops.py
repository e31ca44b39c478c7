"""Closed kinematic loops built from gmuk.robots joints (issue #28, item 3).

A loop is more joints than a tree needs; the Udwadia–Kalaba solve takes the redundant rows.
Each mechanism is held to an independent reference: Freudenstein's equation and the
one-degree-of-freedom energy integral for the four-bar, the closed-form piston position for
the slider-crank, and Pinocchio's constrained dynamics (loop-closure constraint models) for
the Stewart–Gough platform.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gmuk
from gmuk.lie import so3
from gmuk.robots import PrismaticJoint, RevoluteJoint
from gmuk.scenarios import four_bar as fb


class CrankDrive(gmuk.NonholonomicConstraint):
    """ψ = ω_z − Ω: the crank's body rate about z (its joint axis) held at Ω (rad/s)."""

    def __init__(self, crank: gmuk.RigidBody, rate: float) -> None:
        super().__init__([crank], name="drive")
        self.rate = rate

    def residual(self, q, nu, t):
        return nu[0][2:3] - self.rate


def _dense(A):
    return A.toarray() if hasattr(A, "toarray") else np.asarray(A)


# ----------------------------------------------------------------------------- four-bar


def test_four_bar_rows_are_rank_deficient_and_the_minimum_norm_solve_is_consistent():
    """20 rows, rank 17 (a planar loop of 3-D revolute joints repeats three out-of-plane rows);
    the accelerations satisfy every row, and equal those of 17 independent rows alone."""
    system, state, _ = fb.build(0.7, 5.0)
    A, b = system.constraint_rows(state)
    A = _dense(A)
    assert A.shape == (20, 18)
    sv = np.linalg.svd(A, compute_uv=False)
    assert np.linalg.matrix_rank(A, tol=1e-10 * sv[0]) == 17
    assert sv[16] > 1e-2 * sv[0] and sv[17] < 1e-14 * sv[0]  # clearly 17, not nearly 18
    acc = system.accelerations(state)
    np.testing.assert_allclose(A @ acc.total, b, atol=1e-12 * np.abs(b).max())
    assert acc.residual < 1e-12
    # the same motion from independent rows only: Gauss's principle by hand with the
    # rows that QR with pivoting keeps, (A M⁻¹ᐟ²)⁺ with no redundancy to resolve
    import scipy.linalg

    _, _, piv = scipy.linalg.qr(A.T, pivoting=True)
    keep = np.sort(piv[:17])
    M = system.mass_matrix
    Mh = scipy.linalg.sqrtm(M).real
    Mih = np.linalg.inv(Mh)
    a_free = acc.free
    Ak, bk = A[keep], b[keep]
    a_ind = a_free + Mih @ np.linalg.pinv(Ak @ Mih) @ (bk - Ak @ a_free)
    np.testing.assert_allclose(acc.total, a_ind, rtol=0, atol=1e-11 * np.abs(a_ind).max())
    # the multipliers are the minimum-norm ones: orthogonal to the null space of Aᵀ
    null = scipy.linalg.null_space(A.T)
    assert null.shape[1] == 3
    lam = acc.multipliers
    assert np.abs(null.T @ lam).max() < 1e-10 * np.abs(lam).max()


def test_driven_four_bar_rocker_follows_freudenstein():
    """Gravity off, crank driven at Ω = 3 rad/s through more than a turn: the rocker angle is
    the root of Freudenstein's equation at θ₂ = θ₂₀ + Ω t, to 1e-9 rad."""
    omega, theta0 = 3.0, 0.3
    system0, _, joints = fb.build(theta0, omega, gravity=False)
    drive = CrankDrive(system0.bodies[0], omega)
    system = gmuk.System(list(system0.bodies), [*joints.values(), drive])
    state = fb.state_at(system, theta0, omega)
    t = np.linspace(0.0, 2.5, 51)
    traj = system.simulate(state, (0.0, 2.5), t_eval=t, rtol=1e-12, atol=1e-12)
    assert traj.success, traj.message
    theta2 = joints["O2"].coordinates_along(traj)[:, 0]
    theta4 = joints["O4"].coordinates_along(traj)[:, 0]
    np.testing.assert_allclose(theta2, theta0 + omega * t, rtol=0, atol=1e-9)
    _, theta4_exact = fb.angles(theta0 + omega * t)
    np.testing.assert_allclose(theta4, theta4_exact, rtol=0, atol=1e-9)
    assert np.abs(fb.freudenstein_residual(theta2, theta4)).max() < 1e-9
    # it swings: Freudenstein's rocker range is covered
    assert np.ptp(theta4) > 0.5


def test_free_four_bar_under_gravity_keeps_its_energy_and_follows_the_energy_integral():
    """Free under gravity: energy constant to 1e-11, the loop closed, and the crank reaches
    each angle at the time the one-DoF energy integral gives (quadrature of dθ/θ̇(θ))."""
    system, joints, traj = fb.simulate(duration=1.0, rate=8.0)
    assert traj.success, traj.message
    E = fb.energy(system, traj)
    assert np.abs(E - E[0]).max() < 1e-11 * abs(E[0])
    pos, vel = fb.loop_residuals(joints, traj)
    assert pos < 1e-10 and vel < 1e-10
    theta2 = joints["O2"].coordinates_along(traj)[:, 0]
    assert theta2[-1] > 2 * math.pi  # more than a turn
    k = np.arange(5, len(traj), 5)
    t_ref = fb.crank_time(theta2[k], 0.0, 8.0)
    np.testing.assert_allclose(t_ref, traj.t[k], rtol=0, atol=1e-10)
    # the reference is converged: twice the panels change it by less than the tolerance
    assert np.abs(fb.crank_time(theta2[k], 0.0, 8.0, panels_per_rad=80) - t_ref).max() < 1e-12


def test_energy_integral_reference_sees_gravity_and_not_a_uniform_mass_scale():
    """The reference is not blind: scaling every bar's mass leaves the times alone (weight and
    inertia scale together), while 1 % more gravity moves them by far more than the 1e-10 s
    the test above holds."""
    theta = np.array([1.0, 3.0, 6.0])
    base = fb.crank_time(theta, 0.0, 8.0)
    original = fb.DENSITY
    try:
        fb.DENSITY = original * 1.01
        scaled = fb.crank_time(theta, 0.0, 8.0)
    finally:
        fb.DENSITY = original
    np.testing.assert_allclose(scaled, base, rtol=1e-12)
    g0 = fb.GRAVITY
    try:
        fb.GRAVITY = g0 * 1.01
        moved = fb.crank_time(theta, 0.0, 8.0)
    finally:
        fb.GRAVITY = g0
    assert np.abs(moved - base).max() > 1e-4


# -------------------------------------------------------------------------- slider-crank

R_CRANK, L_ROD = 0.1, 0.35


def slider_crank(theta0: float, omega: float):
    """Crank (r) on a revolute joint at the origin, rod (l) on revolute joints at both ends,
    piston on a prismatic joint along x: 20 rows for 18 coordinates, rank 17; with the
    drive 21 rows of rank 18."""
    crank, rod = fb.bar("crank", R_CRANK), fb.bar("rod", L_ROD)
    piston = gmuk.RigidBody("piston", 0.5, np.diag([1e-3, 1e-3, 1e-3]))
    at = fb._at
    joints = {
        "O": RevoluteJoint(None, crank, child_frame=at(-R_CRANK / 2), name="O"),
        "A": RevoluteJoint(
            crank, rod, parent_frame=at(R_CRANK / 2), child_frame=at(-L_ROD / 2), name="A"
        ),
        "B": RevoluteJoint(rod, piston, parent_frame=at(L_ROD / 2), name="B"),
        "slide": PrismaticJoint(None, piston, axis=(1, 0, 0), name="slide"),
    }
    system = gmuk.System([crank, rod, piston], [*joints.values(), CrankDrive(crank, omega)])
    # the state at θ₀: A = r e^{iθ}, B = (x, 0), rod angle φ with sin φ = −r sin θ / l
    s, c = math.sin(theta0), math.cos(theta0)
    phi = math.asin(-R_CRANK * s / L_ROD)
    x = R_CRANK * c + L_ROD * math.cos(phi)
    phidot = -R_CRANK * c * omega / (L_ROD * math.cos(phi))
    xdot = -R_CRANK * s * omega - L_ROD * math.sin(phi) * phidot
    A = np.array([R_CRANK * c, R_CRANK * s, 0.0])
    vA = R_CRANK * omega * np.array([-s, c, 0.0])
    g, V = {}, {}
    for name, th, r, v, w in (
        ("crank", theta0, A / 2, vA / 2, omega),
        (
            "rod",
            phi,
            A + L_ROD / 2 * np.array([math.cos(phi), math.sin(phi), 0]),
            vA + L_ROD / 2 * phidot * np.array([-math.sin(phi), math.cos(phi), 0]),
            phidot,
        ),
        ("piston", 0.0, np.array([x, 0, 0]), np.array([xdot, 0, 0]), 0.0),
    ):
        R = so3.exp(np.array([0, 0, th]))
        g[name] = fb._pose(R, r)
        V[name] = np.concatenate([[0, 0, w], R.T @ v])
    return system, system.state(g=g, V=V), joints


def test_slider_crank_piston_follows_the_closed_form():
    """Driven crank (Ω = 4 rad/s, more than a turn): x(θ) = r cos θ + √(l² − r² sin² θ) to
    1e-10 m, its rate to 1e-9 m/s; the loop's rows are rank-deficient and stay satisfied."""
    omega, theta0 = 4.0, 0.2
    system, state, joints = slider_crank(theta0, omega)
    A = _dense(system.constraint_rows(state)[0])
    assert A.shape == (21, 18) and np.linalg.matrix_rank(A, tol=1e-10) == 18
    t = np.linspace(0.0, 2.0, 41)
    traj = system.simulate(state, (0.0, 2.0), t_eval=t, rtol=1e-12, atol=1e-12)
    assert traj.success, traj.message
    theta = theta0 + omega * t
    x_exact = R_CRANK * np.cos(theta) + np.sqrt(L_ROD**2 - R_CRANK**2 * np.sin(theta) ** 2)
    xdot_exact = (
        -R_CRANK
        * omega
        * np.sin(theta)
        * (1 + R_CRANK * np.cos(theta) / np.sqrt(L_ROD**2 - R_CRANK**2 * np.sin(theta) ** 2))
    )
    slide = joints["slide"]
    np.testing.assert_allclose(slide.coordinates_along(traj)[:, 0], x_exact, atol=1e-10)
    np.testing.assert_allclose(slide.rates_along(traj)[:, 0], xdot_exact, atol=1e-9)
    np.testing.assert_allclose(traj.body("piston").position[:, 0], x_exact, atol=1e-10)
    np.testing.assert_allclose(joints["O"].coordinates_along(traj)[:, 0], theta, rtol=0, atol=1e-9)
    for j in joints.values():
        p, v = j.violation(traj.state(-1))
        assert np.abs(p).max() < 1e-10 and np.abs(v).max() < 1e-10


# ------------------------------------------------------------------ Stewart–Gough platform


def _pin_stewart(st, pin):
    """The same platform as a Pinocchio tree with the loops cut at the spherical joints: per
    leg RX (massless) → RY (lower leg) → PZ (upper leg), the platform on a free-flyer, and a
    CONTACT_3D loop-closure model between each upper leg's tip and its platform point."""
    model = pin.Model()
    model.gravity.linear = np.array([0.0, 0.0, -st.GRAVITY])
    legs = []
    for i, b in enumerate(st.base_points()):
        jx = model.addJoint(0, pin.JointModelRX(), pin.SE3(np.eye(3), b), f"U{i}x")
        jy = model.addJoint(jx, pin.JointModelRY(), pin.SE3.Identity(), f"U{i}y")
        lever = np.array([0.0, 0.0, st.LOWER_LENGTH / 2])
        model.appendBodyToJoint(
            jy,
            pin.Inertia(st.LOWER_MASS, lever, st.rod_inertia(st.LOWER_MASS, st.LOWER_LENGTH)),
            pin.SE3.Identity(),
        )
        jp = model.addJoint(jy, pin.JointModelPZ(), pin.SE3(np.eye(3), lever), f"P{i}")
        model.appendBodyToJoint(
            jp,
            pin.Inertia(st.UPPER_MASS, np.zeros(3), st.rod_inertia(st.UPPER_MASS, st.UPPER_LENGTH)),
            pin.SE3.Identity(),
        )
        legs.append((jx, jy, jp))
    jf = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "platform")
    model.appendBodyToJoint(
        jf, pin.Inertia(st.PLATFORM_MASS, np.zeros(3), st.PLATFORM_INERTIA), pin.SE3.Identity()
    )
    tip = pin.SE3(np.eye(3), np.array([0.0, 0.0, st.UPPER_LENGTH / 2]))
    constraints = [
        pin.RigidConstraintModel(
            pin.ContactType.CONTACT_3D, model, jp, tip, jf, pin.SE3(np.eye(3), p),
            pin.ReferenceFrame.LOCAL,
        )
        for (_, _, jp), p in zip(legs, st.platform_points(), strict=True)
    ]  # fmt: skip
    return model, legs, jf, constraints


def _pin_state(pin, model, legs, jf, g_NP, V_P, q_legs, qd_legs):
    q, v = np.zeros(model.nq), np.zeros(model.nv)
    for (jx, jy, jp), qi, qdi in zip(legs, q_legs, qd_legs, strict=True):
        for j, value, rate in zip((jx, jy, jp), qi, qdi, strict=True):
            q[model.idx_qs[j]], v[model.idx_vs[j]] = value, rate
    iq, iv = model.idx_qs[jf], model.idx_vs[jf]
    q[iq : iq + 7] = pin.SE3ToXYZQUAT(pin.SE3(g_NP[:3, :3], g_NP[:3, 3]))
    v[iv : iv + 6] = np.concatenate([V_P[3:], V_P[:3]])  # Pinocchio's [v; ω]
    return q, v


def _universal_accelerations(joint, state, Vdot_C):
    """(q̈₁, q̈₂) of a universal joint from its child's V̇: ω_rel = q̇₁ R_hᵀa₁ + q̇₂ a₂, so
    [R_hᵀa₁, a₂] q̈ = ω̇_rel + q̇₁ ω_rel × R_hᵀa₁."""
    Rh = joint.relative_pose(state)[:3, :3]
    a1 = Rh.T @ joint.axis1
    w = joint.relative_twist(state)[:3]
    wdot = joint.relative_acceleration(state, np.zeros(6), Vdot_C)[:3]
    qd1 = joint.rates(state)[0]
    rhs = wdot + qd1 * np.cross(w, a1)
    sol, *_ = np.linalg.lstsq(np.column_stack([a1, joint.axis2]), rhs, rcond=None)
    return sol


def test_stewart_platform_matches_pinocchio_constraint_dynamics():
    """At random consistent states (platform pose and twist, legs from the closed-form inverse
    kinematics) gmuk's accelerations of the tree joints (universal, prismatic, the platform's
    free motion) equal Pinocchio's constraintDynamics with the loops cut at the spherical
    joints, to 1e-12 relative (measured: 1.2e-14 on the platform).

    Pinocchio's constraint dynamics is a proximal method with Baumgarte terms; it is the exact
    KKT solution here with: Baumgarte gains Kp = Kd = 0 (their defaults; checked), zero
    compliance (checked), and ProximalSettings(mu=0, max_iter=1): with μ = 0 the first
    proximal iterate is the plain KKT solve of [[M, Jᵀ], [J, 0]] [q̈; −λ] = [τ − C; −γ],
    which is well posed because the six loops' 18 rows are independent."""
    pin = pytest.importorskip("pinocchio")
    from gmuk.scenarios import stewart as st

    model, legs, jf, constraints = _pin_stewart(st, pin)
    for c in constraints:
        assert c.m_baumgarte_parameters.Kp == 0.0 and c.m_baumgarte_parameters.Kd == 0.0
        assert not np.asarray(c.retrieveCompliance()).any()
    datas = [c.createData() for c in constraints]
    data = model.createData()
    pin.initConstraintDynamics(model, data, constraints, datas)
    prox = pin.ProximalSettings(1e-14, 0.0, 1)

    system, parts = st.build(stiffness=0.0, damping=0.0, gravity=True)  # no leg effort
    assert not parts["legs"]
    rng = np.random.default_rng(28)
    for _ in range(8):
        xi = np.concatenate([rng.uniform(-0.15, 0.15, 3), rng.uniform(-0.05, 0.05, 3)])
        g_NP = st.nominal_pose() @ gmuk.lie.se3.exp(xi)
        V_P = np.concatenate([rng.normal(0, 0.5, 3), rng.normal(0, 0.2, 3)])
        state = st.state_at(system, g_NP, V_P)
        q_legs, qd_legs = st.leg_coordinates(g_NP, V_P)
        q, v = _pin_state(pin, model, legs, jf, g_NP, V_P, q_legs, qd_legs)
        # the same state: Pinocchio's placements of the platform and upper legs are gmuk's
        pin.forwardKinematics(model, data, q, v)
        np.testing.assert_allclose(data.oMi[jf].homogeneous, g_NP, atol=1e-14)
        for i, (_, _, jp) in enumerate(legs):
            np.testing.assert_allclose(
                data.oMi[jp].homogeneous, state.pose(f"upper{i}"), atol=1e-14
            )
            np.testing.assert_allclose(
                np.concatenate([data.v[jp].angular, data.v[jp].linear]),
                state.twist(f"upper{i}"),
                atol=1e-13,
            )
        # zero joint effort: ddq from the KKT system
        tau = np.zeros(model.nv)
        ddq = pin.constraintDynamics(model, data, q, v, tau, constraints, datas, prox)
        acc = system.accelerations(state)
        Vdot = acc.total.reshape(-1, 6)
        names = [b.name for b in system.bodies]
        scale = np.abs(ddq).max()
        for i, (jx, jy, jp) in enumerate(legs):
            U, P = parts["universal"][i], parts["prismatic"][i]
            lower, upper = names.index(f"lower{i}"), names.index(f"upper{i}")
            q12 = _universal_accelerations(U, state, Vdot[lower])
            s_dd = P.axis @ P.relative_acceleration(state, Vdot[lower], Vdot[upper])[3:]
            mine = np.array([*q12, s_dd])
            theirs = ddq[[model.idx_vs[jx], model.idx_vs[jy], model.idx_vs[jp]]]
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12 * scale)
        iv = model.idx_vs[jf]
        plat = Vdot[names.index("platform")]
        np.testing.assert_allclose(
            np.concatenate([plat[3:], plat[:3]]), ddq[iv : iv + 6], rtol=0, atol=1e-12 * scale
        )
