"""Links with a singular mass block: no mass, no rotational inertia, or a rod's.

Robot descriptions put massless "virtual" links between the revolute joints of a hip or a
shoulder (human.urdf) and point masses on others (iCub). Such a link has no acceleration of
its own (M has no inverse there); its joints determine it. gmuk takes it as a
``RigidBody(allow_singular=True)`` under the tree solve, which eliminates the link with the
joint to its parent (the null-space method on that joint's rows), and its joints'
accelerations must equal Pinocchio's ABA, which handles such links in reduced coordinates.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pinocchio as pin
import pytest
from helpers import aba_random_state, joint_space_condition, worst_aba_difference
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import gmuk
from gmuk.dynamics import inertia_pinv, singular_mass, zero_moments
from gmuk.errors import ConstraintError, DefinitionError, InertiaError
from gmuk.robots import JointEffort, RevoluteJoint, Robot, SphericalJoint, example_robot_data

RTOL = 1e-10

#: A gimbal (three revolutes with crossing axes through two massless links) carrying a
#: point mass (no rotational inertia) on an arm, then a rod (one zero moment) on a hinge
#: whose axis is not the rod's.
GIMBAL_URDF = """<robot name="gimbal">
  <link name="ground"/>
  <link name="yaw"/>
  <link name="pitch"><inertial><mass value="0"/>
    <inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.3 0.1 -0.2"/><mass value="1.5"/>
    <inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0.001" ixz="0" iyz="0.002"/></inertial></link>
  <link name="bob"><inertial><origin xyz="0.2 0 0"/><mass value="0.7"/>
    <inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="rod"><inertial><origin xyz="0 0 -0.25"/><mass value="0.4"/>
    <inertia ixx="0.008" iyy="0.008" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j_yaw" type="revolute"><parent link="ground"/><child link="yaw"/>
    <origin xyz="0 0 1"/><axis xyz="0 0 1"/>{LIMIT}</joint>
  <joint name="j_pitch" type="revolute"><parent link="yaw"/><child link="pitch"/>
    <axis xyz="0 1 0"/>{LIMIT}</joint>
  <joint name="j_roll" type="revolute"><parent link="pitch"/><child link="arm"/>
    <axis xyz="1 0 0"/>{LIMIT}</joint>
  <joint name="j_bob" type="revolute"><parent link="arm"/><child link="bob"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>{LIMIT}</joint>
  <joint name="j_rod" type="revolute"><parent link="bob"/><child link="rod"/>
    <origin xyz="0.2 0 0"/><axis xyz="0 1 0"/>{LIMIT}</joint>
</robot>
""".replace("{LIMIT}", '<limit lower="-9" upper="9" effort="1" velocity="9"/>')


_random_state = aba_random_state


def _worst(robot: Robot, n: int, seed: int) -> float:
    return worst_aba_difference(robot, n, seed)


@pytest.fixture(scope="module")
def gimbal(tmp_path_factory):
    path = tmp_path_factory.mktemp("gimbal") / "gimbal.urdf"
    path.write_text(GIMBAL_URDF)
    return Robot.from_urdf(path)


def test_the_gimbals_links_are_singular_and_it_follows_aba_at_100_states(gimbal):
    singular = {b.name for b in gimbal.bodies if b.singular}
    assert singular == {"yaw", "pitch", "bob", "rod"}
    assert gimbal.system.solver.name == "tree"
    assert _worst(gimbal, 100, seed=0) <= RTOL


@pytest.mark.parametrize(
    ("relative", "base"),
    [
        ("human_description/robots/human.urdf", "fixed"),
        ("human_description/robots/human.urdf", "floating"),
        ("icub_description/robots/icub.urdf", "floating"),
        ("icub_description/robots/icub_reduced.urdf", "fixed"),
    ],
)
def test_human_and_icub_follow_aba_at_100_random_states(relative, base):
    robot = Robot.from_urdf(example_robot_data(relative), base=base)
    assert any(b.singular for b in robot.bodies)
    assert _worst(robot, 100, seed=2) <= RTOL


@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_icub_at_ill_conditioned_states_is_as_close_to_a_50_digit_solve_as_aba(base):
    """Where cond(M) > 1e8 neither method keeps 1e-10 (both reach 1e-8 at 1e11): against
    Pinocchio's M and nonlinear effects solved to 50 digits, gmuk's error stays below a
    hundredth of the worst case cond(M)·ε, as ABA's does (both measured up to 1.1e-3 of it
    over 30 states), and on the same order as ABA's own."""
    robot = Robot.from_urdf(example_robot_data("icub_description/robots/icub.urdf"), base=base)
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(11)
    checked = 0
    worst_ratio = 0.0
    while checked < 8:
        q, v, tau = aba_random_state(model, rng)
        cond = joint_space_condition(model, data, q)
        if cond <= 1e8:
            continue
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        rhs = tau - pin.nle(model, data, q, v)
        with mpmath.workdps(50):
            exact = np.array(
                mpmath.lu_solve(mpmath.matrix(M.tolist()), mpmath.matrix(rhs.tolist())).tolist(),
                dtype=float,
            ).ravel()
        size = max(1.0, float(np.linalg.norm(exact)))
        ours = np.linalg.norm(robot.forward_dynamics(q, v, tau) - exact) / size
        aba = np.linalg.norm(pin.aba(model, data, q, v, tau) - exact) / size
        assert ours <= 1e-2 * cond * np.finfo(float).eps
        worst_ratio = max(worst_ratio, ours / aba)
        checked += 1
    assert worst_ratio <= 20.0


def test_the_tree_solve_equals_the_dense_kkt_solve(gimbal):
    """The merged elimination against the dense KKT system it stands for, at random states
    with joint torques (loads on the massless links themselves)."""
    efforts = [JointEffort(gimbal.joint(n), [t]) for n, t in (("j_pitch", 0.7), ("j_roll", -0.4))]
    system = gimbal.with_forces(efforts).system
    solver = system.solver
    rng = np.random.default_rng(3)
    for _ in range(20):
        q, v, _ = _random_state(gimbal.model, rng)
        state = gimbal.state(q, v, system=system)
        acc = system.accelerations(state)
        A, b = solver._blocks(state)
        A_full = solver._dense(A)
        r = solver._rhs(state, acc.free)
        ac, lam, _, _, _ = solver._singular_kkt(state, acc.free, A_full, b, r)
        scale = max(1.0, float(np.abs(acc.constraint).max()))
        assert np.abs(acc.constraint - ac).max() <= 1e-11 * scale
        np.testing.assert_allclose(
            acc.multipliers, lam, rtol=0, atol=1e-10 * max(1.0, np.abs(lam).max())
        )


def test_constraint_wrench_is_a_transpose_lambda_on_every_path(gimbal):
    """Accelerations.constraint_force is Aᵀλ, also on a link without mass (where it is not
    M ν̇_c), from the compiled call and from the general path alike."""
    efforts = [JointEffort(gimbal.joint("j_pitch"), [0.3])]
    system = gimbal.with_forces(efforts).system
    solver = system.solver
    rng = np.random.default_rng(5)
    q, v, _ = _random_state(gimbal.model, rng)
    state = gimbal.state(q, v, system=system)
    compiled = system.accelerations(state)
    modeled, unmodeled = solver._loads(state)
    general = solver._general(state, modeled, unmodeled, None)
    A, _ = solver._blocks(state)
    A_full = solver._dense(A)
    for acc in (compiled, general):
        expected = A_full.T @ acc.multipliers
        assert np.abs(acc.constraint_force - expected).max() <= 1e-12 * np.abs(expected).max()
    np.testing.assert_allclose(
        general.total, compiled.total, rtol=0, atol=1e-12 * np.abs(compiled.total).max()
    )


def test_a_gimbal_second_agrees_with_aba_integrated_by_dop853(gimbal):
    """The compiled step loop with the merged elimination: 1 s of the gimbal falling under
    gravity against Pinocchio's ABA driven by scipy's DOP853, both at tight tolerances."""
    model, data = gimbal.model, gimbal.model.createData()
    rng = np.random.default_rng(7)
    q0, v0, _ = _random_state(model, rng)
    t = np.linspace(0.0, 1.0, 101)
    traj = gimbal.system.simulate(
        gimbal.state(q0, v0), (0.0, 1.0), t_eval=t, rtol=1e-12, atol=1e-12
    )
    assert traj.success, traj.message
    nq = model.nq

    def rhs(_t, y):
        return np.concatenate([y[nq:], pin.aba(model, data, y[:nq], y[nq:], np.zeros(model.nv))])

    ref = solve_ivp(rhs, (0.0, 1.0), np.concatenate([q0, v0]), method="DOP853", t_eval=t,
                    rtol=1e-13, atol=1e-13)  # fmt: skip
    assert np.abs(gimbal.configuration(traj) - ref.y[:nq].T).max() <= 1e-7
    assert np.abs(gimbal.velocity(traj) - ref.y[nq:].T).max() <= 1e-6


# ----------------------------------------------------------------------------- refusals
def _massless(name):
    return gmuk.RigidBody(name, 0.0, np.zeros((3, 3)), allow_singular=True)


def _heavy(name):
    return gmuk.RigidBody(name, 2.0, np.diag([0.1, 0.2, 0.25]))


def test_a_massless_link_at_the_end_of_a_chain_is_undetermined_and_says_so():
    """A point mass on a hinge whose axis runs through it: nothing fixes its spin, and the
    solve says so instead of choosing one (Pinocchio's ABA divides by zero there)."""
    base = _heavy("base")
    bob = gmuk.RigidBody("bob", 1.0, np.zeros((3, 3)), allow_singular=True)
    joints = [
        RevoluteJoint(None, base, axis=(0, 0, 1)),
        RevoluteJoint(base, bob, axis=(1, 0, 0)),  # through the bob's centre of mass
    ]
    system = gmuk.System([base, bob], joints)
    state = system.state(
        {"base": np.eye(4), "bob": np.eye(4)}, {"base": np.zeros(6), "bob": np.zeros(6)}
    )
    with pytest.raises(ConstraintError, match="singular"):
        system.accelerations(state)


def test_a_singular_link_outside_a_joint_tree_is_refused():
    a, b = _heavy("a"), _massless("b")
    loop = [
        SphericalJoint(None, a),
        SphericalJoint(a, b),
        SphericalJoint(None, b, parent_frame=np.diag([1.0, 1.0, 1.0, 1.0])),  # closes a loop
    ]
    with pytest.raises(DefinitionError, match=r"singular mass block.*only the tree solve"):
        gmuk.System([a, b], loop)
    with pytest.raises(DefinitionError, match="only the tree solve"):
        gmuk.System([a, b], loop[:2], solver="dense")


def test_loads_the_solve_does_not_see_are_refused_on_a_singular_link():
    a, b = _heavy("a"), _massless("b")
    joints = [SphericalJoint(None, a), SphericalJoint(a, b)]
    push = gmuk.AppliedWrench("b", [0.0, 0.0, 0.0, 1.0, 0.0, 0.0], modeled=False)
    with pytest.raises(DefinitionError, match="unmodeled"):
        gmuk.System([a, b], joints, forces=[push])


@pytest.mark.parametrize(
    ("mass", "J", "words"),
    [
        (0.0, np.eye(3), "J must be zero when m = 0"),
        (1.0, np.diag([-1e-3, 1.0, 1.0]), "positive semidefinite"),
        (1.0, np.diag([0.0, 1.0, 3.0]), "triangle inequality"),
        (-1.0, np.zeros((3, 3)), "mass must be"),
    ],
)
def test_allow_singular_still_refuses_what_is_not_physical(mass, J, words):
    with pytest.raises(InertiaError, match=words):
        gmuk.RigidBody("x", mass, J, allow_singular=True)


def test_allow_singular_takes_a_bool_only():
    with pytest.raises(DefinitionError, match="allow_singular must be True or False"):
        gmuk.RigidBody("x", 0.0, np.zeros((3, 3)), allow_singular="yes")


def test_a_massless_floating_link_is_undetermined_and_says_so():
    """A massless body with no joint to hold it: nothing determines its motion."""
    base = _heavy("base")
    ghost = _massless("ghost")
    system = gmuk.System([base, ghost], [RevoluteJoint(None, base)], solver="tree")
    state = system.state(
        {"base": np.eye(4), "ghost": np.eye(4)}, {"base": np.zeros(6), "ghost": np.zeros(6)}
    )
    with pytest.raises(ConstraintError, match="singular"):
        system.accelerations(state)


def test_a_singular_body_is_refused_by_default():
    with pytest.raises(InertiaError, match="mass must be"):
        gmuk.RigidBody("x", 0.0, np.zeros((3, 3)))
    with pytest.raises(InertiaError, match="positive definite"):
        gmuk.RigidBody("x", 1.0, np.zeros((3, 3)))
    assert not gmuk.RigidBody("x", 1.0, np.eye(3), allow_singular=True).singular


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.one_of(st.just(0.0), st.floats(1e-3, 10.0)), min_size=3, max_size=3),
    st.integers(0, 3),
    st.integers(0, 2**31),
)
def test_inertia_pinv_is_the_moore_penrose_inverse(moments, zeros, seed):
    w = np.sort(np.array(moments))
    w[:zeros] = 0.0
    U = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))[0]
    J = (U * w) @ U.T
    P = inertia_pinv(J)
    scale = max(1.0, float(np.abs(P).max()))
    assert np.abs(J @ P @ J - J).max() <= 1e-12 * max(1.0, w.max()) * scale
    assert np.abs(P @ J @ P - P).max() <= 1e-12 * scale * scale
    assert np.abs(J @ P - (J @ P).T).max() <= 1e-12 * scale
    clean = zero_moments(J)[0]
    assert singular_mass(1.0, J) == bool(clean[0] == 0.0)
