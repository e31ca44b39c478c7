"""The joint library (gmuk.robots.joints): kinematics, rows, residuals, analytic checks.

Every joint kind is held to what defines it: a relative motion along its motion subspace S is
free (zero residuals), its constrained rows hold along a run, the joint forces do no work (a
free chain keeps its energy), and its coordinates and rates read back what built the state.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ellipk

import gmuk
from gmuk.constraints.relative import relative_rows
from gmuk.errors import DefinitionError, NotOnGroupError
from gmuk.lie import se3, so3
from gmuk.robots import (
    CylindricalJoint,
    FixedJoint,
    JointEffort,
    JointSpringDamper,
    PlanarJoint,
    PrismaticJoint,
    RevoluteJoint,
    ScrewJoint,
    SphericalJoint,
    UniversalJoint,
)
from gmuk.robots.joints import _HEAD, _SCREW, _UNIVERSAL, joint_residuals, joint_rows


def _inertia(rng: np.random.Generator) -> np.ndarray:
    R = so3.exp(rng.uniform(-np.pi, np.pi, 3))
    a, b = rng.uniform(0.5, 2.0, 2)
    c = rng.uniform(abs(a - b) + 0.05, a + b)
    return R @ np.diag([a, b, c]) @ R.T


def _pose(rng: np.random.Generator, scale: float = 1.0) -> np.ndarray:
    g = np.eye(4)
    g[:3, :3] = so3.exp(rng.uniform(-np.pi, np.pi, 3))
    g[:3, 3] = scale * rng.normal(size=3)
    return g


def _make(kind: str, parent: gmuk.RigidBody | None, child: gmuk.RigidBody, rng, **kw):
    frames = {"parent_frame": _pose(rng), "child_frame": _pose(rng, 0.3)}
    axis = rng.normal(size=3)
    if kind == "fixed":
        return FixedJoint(parent, child, **frames, **kw)
    if kind == "revolute":
        return RevoluteJoint(parent, child, axis=axis, **frames, **kw)
    if kind == "prismatic":
        return PrismaticJoint(parent, child, axis=axis, **frames, **kw)
    if kind == "cylindrical":
        return CylindricalJoint(parent, child, axis=axis, **frames, **kw)
    if kind == "screw":
        return ScrewJoint(parent, child, axis=axis, pitch=0.05, **frames, **kw)
    if kind == "spherical":
        return SphericalJoint(parent, child, **frames, **kw)
    if kind == "planar":
        return PlanarJoint(parent, child, normal=axis, **frames, **kw)
    if kind == "universal":
        a1 = axis / np.linalg.norm(axis)
        a2 = np.cross(a1, rng.normal(size=3))
        return UniversalJoint(
            parent, child, axis1=a1, axis2=a2 / np.linalg.norm(a2), **frames, **kw
        )
    raise AssertionError(kind)


KINDS = (
    "fixed",
    "revolute",
    "prismatic",
    "cylindrical",
    "screw",
    "spherical",
    "planar",
    "universal",
)


def _relative_motion(joint, rng) -> tuple[np.ndarray, np.ndarray]:
    """A relative pose h (4, 4) on the joint's manifold and a relative twist V_rel (6,) in
    its motion subspace there."""
    if isinstance(joint, UniversalJoint):
        q1, q2 = rng.uniform(-2.0, 2.0, 2)
        R = so3.exp(q1 * joint.axis1) @ so3.exp(q2 * joint.axis2)
        h = np.eye(4)
        h[:3, :3] = R
        rates = rng.normal(size=2)
        w = rates[0] * (R.T @ joint.axis1) + rates[1] * joint.axis2
        return h, np.concatenate([w, np.zeros(3)])
    S = joint.motion_subspace
    q = rng.uniform(-2.5, 2.5, S.shape[1])
    h = se3.exp(S @ q) if S.shape[1] else np.eye(4)
    return h, S @ rng.normal(size=S.shape[1])


def _state_on_joint(joint, parent, child, rng):
    """A System of the joint, and a state that satisfies it at position and velocity level."""
    bodies = [b for b in (parent, child) if b is not None]
    system = gmuk.System(bodies, [joint])
    h, V_rel = _relative_motion(joint, rng)
    g_P = _pose(rng) if parent is not None else np.eye(4)
    V_P = rng.normal(size=6) if parent is not None else np.zeros(6)
    g_Jp = g_P @ joint.parent_frame if parent is not None else joint.parent_frame
    V_Jp = se3.Ad(se3.inverse(joint.parent_frame)) @ V_P if parent is not None else np.zeros(6)
    g_Jc = g_Jp @ h
    V_Jc = V_rel + se3.Ad(se3.inverse(h)) @ V_Jp
    g_C = g_Jc @ se3.inverse(joint.child_frame)
    V_C = se3.Ad(joint.child_frame) @ V_Jc
    g = {child.name: g_C}
    V = {child.name: V_C}
    if parent is not None:
        g[parent.name], V[parent.name] = g_P, V_P
    return system, system.state(g=g, V=V), h, V_rel


@pytest.mark.parametrize("grounded", [False, True])
@pytest.mark.parametrize("kind", KINDS)
def test_motion_along_the_subspace_leaves_zero_residuals(kind, grounded):
    rng = np.random.default_rng(hash((kind, grounded)) % 2**32)
    for _ in range(10):
        parent = None if grounded else gmuk.RigidBody("P", 2.0, _inertia(rng))
        child = gmuk.RigidBody("C", 1.0, _inertia(rng))
        joint = _make(kind, parent, child, rng)
        _, state, h, V_rel = _state_on_joint(joint, parent, child, rng)
        pos, vel = joint.violation(state)
        np.testing.assert_allclose(pos, 0.0, atol=1e-12)
        np.testing.assert_allclose(vel, 0.0, atol=1e-12)
        np.testing.assert_allclose(joint.relative_pose(state), h, atol=1e-12)
        np.testing.assert_allclose(joint.relative_twist(state), V_rel, atol=1e-12)


@pytest.mark.parametrize("kind", [k for k in KINDS if k not in ("fixed",)])
def test_motion_off_the_subspace_shows_in_the_residuals(kind):
    rng = np.random.default_rng(7)
    parent = gmuk.RigidBody("P", 2.0, _inertia(rng))
    child = gmuk.RigidBody("C", 1.0, _inertia(rng))
    joint = _make(kind, parent, child, rng)
    system, state, _, _ = _state_on_joint(joint, parent, child, rng)
    # a small displacement of the child along a constrained direction
    T = joint._T if kind != "universal" else np.eye(6)[3:]
    xi = 1e-4 * T[0]
    g = {n: state.pose(n) for n in ("P", "C")}
    V = {n: state.twist(n) for n in ("P", "C")}
    g["C"] = g["C"] @ joint.child_frame @ se3.exp(xi) @ se3.inverse(joint.child_frame)
    V["C"] = V["C"] + se3.Ad(joint.child_frame) @ xi
    pos, vel = joint.violation(system.state(g=g, V=V))
    assert np.abs(pos).max() > 5e-5
    assert np.abs(vel).max() > 5e-5


@pytest.mark.parametrize("kind", KINDS)
def test_a_free_chain_keeps_its_energy_and_its_joint(kind):
    """No gravity, no load: the joint's constraint forces do no work."""
    rng = np.random.default_rng(sum(map(ord, kind)))
    parent = gmuk.RigidBody("P", 2.0, _inertia(rng))
    child = gmuk.RigidBody("C", 1.0, _inertia(rng))
    joint = _make(kind, parent, child, rng)
    system, state, _, _ = _state_on_joint(joint, parent, child, rng)
    traj = system.simulate(state, (0.0, 3.0), rtol=1e-12, atol=1e-12)
    assert traj.success, traj.message

    def energy(s):
        out = 0.0
        for b in (parent, child):
            V = s.twist(b.name)
            out += 0.5 * V[:3] @ b.inertia @ V[:3] + 0.5 * b.mass * V[3:] @ V[3:]
        return out

    E0, E1 = energy(traj.state(0)), energy(traj.state(-1))
    assert abs(E1 - E0) <= 1e-9 * E0
    pos, vel = joint.violation(traj.state(-1))
    assert np.abs(pos).max() < 1e-8 and np.abs(vel).max() < 1e-8


def test_compound_pendulum_period_is_the_elliptic_integral():
    """A rod on a revolute joint to the ground, released from rest at θ₀ = 2 rad: period
    T = 4 √(I_O / (m g l)) K(sin²(θ₀/2)) (K with parameter m = k²)."""
    m, l, g0 = 2.0, 0.7, 9.81
    J = np.diag([m * (2 * l) ** 2 / 12, m * (2 * l) ** 2 / 12, 1e-3])
    rod = gmuk.RigidBody("rod", m, J)
    # pivot on the rod's x axis at distance l from its centre of mass; joint axis z
    X_CJ = np.eye(4)
    X_CJ[:3, 3] = (l, 0.0, 0.0)
    hinge = RevoluteJoint(None, rod, axis=(0, 0, 1), child_frame=X_CJ)
    weight = gmuk.UniformGravity((-g0, 0.0, 0.0))
    system = gmuk.System([rod], [hinge], [weight])
    theta0 = 2.0
    # the rod hangs along −x from the pivot at the origin: centre of mass at −l (Rz θ e_x)
    h = se3.exp(np.array([0, 0, theta0, 0, 0, 0]))
    g_rod = h @ se3.inverse(X_CJ)
    state = system.state(g={"rod": g_rod}, V={"rod": np.zeros(6)})
    I_O = J[2, 2] + m * l**2
    period = 4.0 * math.sqrt(I_O / (m * g0 * l)) * ellipk(math.sin(theta0 / 2) ** 2)
    traj = system.simulate(
        state, (0.0, period), t_eval=np.linspace(0.0, period, 401), rtol=1e-12, atol=1e-12
    )
    q = hinge.coordinates_along(traj)[:, 0]
    assert q[0] == pytest.approx(theta0, abs=1e-12)
    assert q[-1] == pytest.approx(theta0, abs=1e-8)
    assert q[200] == pytest.approx(-theta0, abs=1e-8)  # half a period: the other side
    assert q.min() == pytest.approx(-theta0, abs=1e-6)


def test_screw_joint_slides_pitch_per_radian_past_half_a_turn():
    nut = gmuk.RigidBody("nut", 1.0, np.diag([0.01, 0.01, 0.02]))
    screw = ScrewJoint(None, nut, axis=(0, 0, 1), pitch=0.01)
    system = gmuk.System([nut], [screw], [gmuk.UniformGravity((0, 0, -9.81))])
    state = system.state(g={"nut": np.eye(4)}, V={"nut": np.zeros(6)})
    traj = system.simulate(state, (0.0, 2.0), rtol=1e-12, atol=1e-12, t_eval=np.linspace(0, 2, 51))
    theta = screw.coordinates_along(traj)[:, 0]
    z = np.array([traj.state(i).pose("nut")[2, 3] for i in range(len(traj))])
    assert abs(theta[-1]) > 3 * math.pi  # past one and a half turns
    np.testing.assert_allclose(z, 0.01 * theta, atol=1e-10)
    # the nut falls as a point mass m on an effective inertia m + I/p²: z = −½ a t²
    a = 9.81 * 1.0 / (1.0 + 0.02 / 0.01**2)
    np.testing.assert_allclose(z, -0.5 * a * traj.t**2, atol=1e-9)


def test_universal_joint_coordinates_and_rates_read_back():
    rng = np.random.default_rng(11)
    P = gmuk.RigidBody("P", 2.0, _inertia(rng))
    C = gmuk.RigidBody("C", 1.0, _inertia(rng))
    for _ in range(20):
        joint = _make("universal", P, C, rng)
        _, state, h, V_rel = _state_on_joint(joint, P, C, rng)
        q1, q2 = joint.coordinates(state)
        R = so3.exp(q1 * joint.axis1) @ so3.exp(q2 * joint.axis2)
        np.testing.assert_allclose(R, h[:3, :3], atol=1e-12)
        rates = joint.rates(state)
        w = rates[0] * (h[:3, :3].T @ joint.axis1) + rates[1] * joint.axis2
        np.testing.assert_allclose(w, V_rel[:3], atol=1e-12)


@pytest.mark.parametrize("kind", ["revolute", "prismatic", "cylindrical", "planar", "spherical"])
def test_coordinates_and_rates_read_back_the_motion(kind):
    rng = np.random.default_rng(5)
    P = gmuk.RigidBody("P", 2.0, _inertia(rng))
    C = gmuk.RigidBody("C", 1.0, _inertia(rng))
    joint = _make(kind, P, C, rng)
    S = joint.motion_subspace
    q = rng.uniform(-1.0, 1.0, S.shape[1])
    qd = rng.normal(size=S.shape[1])
    system = gmuk.System([P, C], [joint])
    h = se3.exp(S @ q)
    g_Jc = joint.parent_frame @ h
    V_Jc = S @ qd
    state = system.state(
        g={"P": np.eye(4), "C": g_Jc @ se3.inverse(joint.child_frame)},
        V={"P": np.zeros(6), "C": se3.Ad(joint.child_frame) @ V_Jc},
    )
    np.testing.assert_allclose(joint.rates(state), qd, atol=1e-12)
    if kind in ("revolute", "prismatic", "spherical"):
        np.testing.assert_allclose(joint.coordinates(state), q, atol=1e-12)


def test_baumgarte_gains_pull_a_displaced_joint_back():
    rng = np.random.default_rng(2)
    P = gmuk.RigidBody("P", 2.0, _inertia(rng))
    C = gmuk.RigidBody("C", 1.0, _inertia(rng))
    joint = RevoluteJoint(P, C, axis=(0, 0, 1), baumgarte=gmuk.Baumgarte.critical(20.0))
    system = gmuk.System([P, C], [joint])
    off = np.eye(4)
    off[:3, 3] = (1e-3, -2e-3, 1e-3)
    off[:3, :3] = so3.exp(np.array([2e-3, 0.0, 0.0]))
    state = system.state(g={"P": np.eye(4), "C": off}, V={"P": np.zeros(6), "C": np.zeros(6)})
    pos0, _ = joint.violation(state)
    traj = system.simulate(state, (0.0, 1.5), rtol=1e-11, atol=1e-11, drift_tol=None)
    pos1, vel1 = joint.violation(traj.state(-1))
    assert np.abs(pos0).max() > 1e-3
    assert np.abs(pos1).max() < 1e-8 and np.abs(vel1).max() < 1e-7


def test_joint_effort_does_the_work_tau_times_angle():
    """A constant torque τ on a revolute joint to the ground spins the child up:
    ½ I θ̇² = τ θ (no gravity)."""
    wheel = gmuk.RigidBody("w", 3.0, np.diag([0.3, 0.3, 0.5]))
    axle = RevoluteJoint(None, wheel, axis=(0, 0, 1))
    tau = 0.7
    system = gmuk.System([wheel], [axle], [JointEffort(axle, [tau])])
    state = system.state(g={"w": np.eye(4)}, V={"w": np.zeros(6)})
    traj = system.simulate(state, (0.0, 2.0), rtol=1e-12, atol=1e-12)
    theta = axle.coordinates_along(traj)[-1, 0]
    rate = axle.rates(traj.state(-1))[0]
    assert theta == pytest.approx(0.5 * tau / 0.5 * 4.0, rel=1e-10)
    assert 0.5 * 0.5 * rate**2 == pytest.approx(tau * theta, rel=1e-10)


def test_joint_spring_damper_is_a_damped_oscillator():
    """k, c on a prismatic joint: x(t) of m ẍ + c ẋ + k x = 0."""
    m, k, c = 2.0, 50.0, 1.5
    block = gmuk.RigidBody("b", m, np.eye(3) * 0.1)
    rail = PrismaticJoint(None, block, axis=(1, 0, 0))
    system = gmuk.System([block], [rail], [JointSpringDamper(rail, stiffness=k, damping=c)])
    g0 = np.eye(4)
    g0[0, 3] = 0.1
    state = system.state(g={"b": g0}, V={"b": np.zeros(6)})
    t = np.linspace(0.0, 3.0, 31)
    traj = system.simulate(state, (0.0, 3.0), t_eval=t, rtol=1e-12, atol=1e-12)
    wn, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)
    x = 0.1 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    np.testing.assert_allclose(rail.coordinates_along(traj)[:, 0], x, atol=1e-10)


def test_bad_joint_definitions_say_what_is_wrong():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    b = gmuk.RigidBody("b", 1.0, np.eye(3))
    with pytest.raises(DefinitionError, match="nonzero"):
        RevoluteJoint(a, b, axis=(0, 0, 0))
    with pytest.raises(DefinitionError, match="perpendicular"):
        UniversalJoint(a, b, axis1=(1, 0, 0), axis2=(1, 1, 0))
    with pytest.raises(DefinitionError, match="pitch"):
        ScrewJoint(a, b, pitch=0.0)
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(NotOnGroupError):
        RevoluteJoint(a, b, parent_frame=bad)
    with pytest.raises(DefinitionError, match="one per row"):
        RevoluteJoint(a, b, baumgarte=gmuk.Baumgarte(alpha=[1.0, 2.0]))
    with pytest.raises(DefinitionError, match=r"more than once|twice"):
        RevoluteJoint(a, a)
    with pytest.raises(DefinitionError, match="Joint"):
        JointEffort("not a joint", [1.0])  # type: ignore[arg-type]
    hinge = RevoluteJoint(a, b)
    with pytest.raises(DefinitionError, match="stiffness"):
        JointSpringDamper(hinge, stiffness=-1.0)
    with pytest.raises(DefinitionError, match=r"1 numbers|number"):
        JointSpringDamper(hinge, damping=[1.0, 2.0])


# -- the compiled row kernel against a straightforward reference: the joint frames' poses and
# twists by matrix products, the rows of a relative constraint between them (relative_rows),
# mapped to the bodies' twists, the universal joint's moving row and the Baumgarte terms with
# the position residual by se3.log


def _reference(g1, V1, g2, V2, p):
    """(A (s, 12), b (s,), Φ (s,), T V_rel (s,)) by the matrix products of the joint's math."""
    s = int(p[2])
    XP, XC = p[3:19].reshape(4, 4), p[19:35].reshape(4, 4)
    AdP, AdC = p[35:71].reshape(6, 6), p[71:107].reshape(6, 6)
    if p[0] != 0.0:
        gJp, VJp, gJc, VJc = XP, np.zeros(6), g1 @ XC, AdC @ V1
    else:
        gJp, VJp, gJc, VJc = g1 @ XP, AdP @ V1, g2 @ XC, AdC @ V2
    h = np.linalg.inv(gJp) @ gJc
    T = p[_HEAD : _HEAD + 6 * s].reshape(s, 6).copy()
    e = _HEAD + 8 * s
    a1 = h[:3, :3].T @ p[e : e + 3]
    if p[1] == _UNIVERSAL:
        T[-1] = np.concatenate([np.cross(a1, p[e + 3 : e + 6]), np.zeros(3)])
    At, bt, Vr = np.empty((s, 12)), np.empty(s), np.empty(6)
    relative_rows(gJp, VJp, gJc, VJc, T, np.zeros(6), At, bt, Vr)
    A = np.zeros((s, 12))
    if p[0] != 0.0:
        A[:, :6] = At[:, 6:] @ AdC
    else:
        A[:, :6], A[:, 6:] = At[:, :6] @ AdP, At[:, 6:] @ AdC
    if p[1] == _UNIVERSAL:
        n_dot = np.cross(-np.cross(Vr[:3], a1), p[e + 3 : e + 6])
        bt[-1] -= n_dot @ Vr[:3]
    hh = h
    if p[1] == _SCREW:
        axis, pitch = p[e : e + 3], p[e + 3]
        theta = axis @ h[:3, 3] / pitch
        hh = h @ se3.exp(-theta * np.concatenate([axis, pitch * axis])[None])[0]
    phi = T @ se3.log(hh[None])[0]
    if p[1] == _UNIVERSAL:
        phi[-1] = -(a1 @ p[e + 3 : e + 6])
    vel = T @ Vr
    alpha, beta = p[_HEAD + 6 * s : _HEAD + 7 * s], p[_HEAD + 7 * s : _HEAD + 8 * s]
    return A, bt - alpha * vel - beta * phi, phi, vel


def _close(new, ref):
    """Each row equal to round-off: within 1e-13 of the row's largest entry."""
    scale = np.maximum(np.abs(ref).max(axis=-1, keepdims=True), 1e-300)
    assert np.all(np.abs(new - ref) <= 1e-13 * scale), np.abs(new - ref).max()


@pytest.mark.parametrize("stabilised", [False, True])
@pytest.mark.parametrize("grounded", [False, True])
@pytest.mark.parametrize("kind", KINDS)
def test_joint_rows_equal_the_matrix_product_reference(kind, grounded, stabilised):
    rng = np.random.default_rng([KINDS.index(kind), grounded, stabilised])
    for _ in range(20):
        parent = None if grounded else gmuk.RigidBody("P", 1.0, _inertia(rng))
        child = gmuk.RigidBody("C", 2.0, _inertia(rng))
        gains = (
            gmuk.Baumgarte(alpha=rng.uniform(1, 10), beta=rng.uniform(1, 50))
            if stabilised
            else None
        )
        joint = _make(kind, parent, child, rng, baumgarte=gains)
        p = joint._params
        s = joint._T.shape[0]
        g1, g2 = _pose(rng, 2.0), _pose(rng, 2.0)
        V1, V2 = rng.normal(size=6), rng.normal(size=6)
        A, b = np.full((s, 12), np.nan), np.full(s, np.nan)
        assert joint_rows(0.0, g1, V1, g2, V2, p, A, b) == 0
        A_ref, b_ref, phi_ref, vel_ref = _reference(g1, V1, g2, V2, p)
        _close(A, A_ref)
        _close(b[None], b_ref[None])
        pos, vel = np.empty(s), np.empty(s)
        joint_residuals(g1, V1, g2, V2, p, pos, vel)
        _close(pos[None], phi_ref[None])
        _close(vel[None], vel_ref[None])


@pytest.mark.parametrize("grounded", [False, True])
@pytest.mark.parametrize("kind", KINDS)
def test_residuals_at_many_states_equal_one_state_at_a_time(kind, grounded):
    """The drift check of a run evaluates the residuals at all its sampled outputs in one
    compiled loop: the numbers of :meth:`Joint.violation` at each state, bit for bit."""
    rng = np.random.default_rng([KINDS.index(kind), grounded])
    parent = None if grounded else gmuk.RigidBody("P", 2.0, _inertia(rng))
    child = gmuk.RigidBody("C", 1.0, _inertia(rng))
    joint = _make(kind, parent, child, rng, baumgarte=gmuk.Baumgarte(alpha=1.0, beta=1.0))
    system = gmuk.System([b for b in (parent, child) if b is not None], [joint])
    states = [
        system.state(
            g={b.name: _pose(rng, 2.0) for b in system.bodies},
            V={b.name: rng.normal(size=6) for b in system.bodies},
        )
        for _ in range(7)
    ]
    along = joint._violation_along(states)
    assert along is not None
    for n, state in enumerate(states):
        pos, vel = joint.violation(state)
        np.testing.assert_array_equal(along[0][n], pos)
        np.testing.assert_array_equal(along[1][n], vel)


class _OwnViolation(RevoluteJoint):
    def violation(self, state):
        pos, vel = super().violation(state)
        return 2.0 * pos, vel


def test_a_joint_with_its_own_violation_is_checked_one_state_at_a_time():
    """A subclass's ``violation`` is what the drift check reports, not the kernel's."""
    body = gmuk.RigidBody("C", 1.0, np.diag([1.0, 2.0, 3.0]))
    joint = _OwnViolation(None, body)
    system = gmuk.System([body], [joint])
    state = system.state(g={"C": se3.exp(np.full(6, 0.1))}, V={"C": np.zeros(6)})
    assert joint._violation_along([state]) is None
    traj = system.simulate(state, (0.0, 0.01), t_eval=[0.0, 0.01], drift_tol=None)
    (entry,) = traj.stats["constraint_violation"]["constraints"]
    assert entry["initial_position"] == pytest.approx(
        float(np.linalg.norm(joint.violation(state)[0])), rel=1e-12
    )
