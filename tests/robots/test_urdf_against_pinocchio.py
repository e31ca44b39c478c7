"""Robots from URDF (gmuk.robots.Robot) against Pinocchio's articulated-body algorithm.

gmuk builds each robot in maximal coordinates (one rigid body per link, joints as constraint
rows) and solves the Udwadia–Kalaba equation; Pinocchio runs ABA in reduced coordinates on the
same URDF. The joint accelerations must agree to round-off at random states, for every robot
that example-robot-data ships and gmuk builds; the robots gmuk refuses are refused for a reason
it names.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from helpers import aba_random_state, worst_aba_difference
from scipy.integrate import solve_ivp

import gmuk
from gmuk.errors import DefinitionError, MissingDependencyError
from gmuk.robots import Robot, example_robot_data, example_robot_urdfs

RTOL = 1e-10

#: URDFs gmuk refuses, with the words its error must say. (human, icub and icub_reduced,
#: whose links without mass or rotational inertia sit between joints, are built: their
#: mass blocks are singular, and the tree solve eliminates such a link with its joint.)
REFUSED = {
    "romeo.urdf": "moves only links without mass",  # massless finger tips: ABA gives NaN
    "romeo_laas_small.urdf": "positive semidefinite",  # negative principal moments
    "romeo_small.urdf": "triangle inequality",  # not a physical inertia
    "ur3.urdf": "Pinocchio could not read",  # the file names no robot
}
#: URDFs whose links include singular mass blocks (no mass, or no rotational inertia).
SINGULAR = {"human.urdf", "icub.urdf", "icub_reduced.urdf"}
#: URDFs with no moving joint: a fixed base leaves nothing to simulate.
NO_JOINTS = {"quadrotor_base.urdf", "iris_simple.urdf"}


_random_state = aba_random_state


def _worst(robot: Robot, n: int, seed: int) -> float:
    return worst_aba_difference(robot, n, seed)


URDFS = [p for p in example_robot_urdfs()]


@pytest.mark.parametrize("base", ["fixed", "floating"])
@pytest.mark.parametrize("path", URDFS, ids=[f"{p.parent.parent.name}/{p.name}" for p in URDFS])
def test_every_example_robot_builds_and_agrees_with_aba_or_is_refused(path, base):
    if path.name in REFUSED:
        with pytest.raises(DefinitionError, match=REFUSED[path.name]):
            Robot.from_urdf(path, base=base)
        return
    if path.name in NO_JOINTS and base == "fixed":
        with pytest.raises(DefinitionError, match="nothing moves"):
            Robot.from_urdf(path, base=base)
        return
    robot = Robot.from_urdf(path, base=base)
    assert robot.nv == robot.model.nv
    assert _worst(robot, 3, seed=len(path.name)) <= RTOL


@pytest.mark.parametrize(
    ("relative", "base"),
    [
        ("panda_description/urdf/panda.urdf", "fixed"),
        ("solo_description/robots/solo12.urdf", "floating"),
        ("ur_description/urdf/ur5_robot.urdf", "fixed"),
    ],
)
def test_panda_solo12_and_ur5_agree_with_aba_at_100_random_states(relative, base):
    robot = Robot.from_urdf(example_robot_data(relative), base=base)
    assert _worst(robot, 100, seed=0) <= RTOL


#: The (URDF, base) pairs gmuk builds.
BUILT = [
    (p, base)
    for p in URDFS
    for base in ("fixed", "floating")
    if p.name not in REFUSED and not (p.name in NO_JOINTS and base == "fixed")
]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("path", "base"), BUILT, ids=[f"{p.parent.parent.name}/{p.name}-{b}" for p, b in BUILT]
)
def test_every_example_robot_agrees_with_aba_at_100_random_states(path, base):
    assert _worst(Robot.from_urdf(path, base=base), 100, seed=1) <= RTOL


@pytest.mark.parametrize(
    ("relative", "base"),
    [
        ("kinova_description/robots/kinova.urdf", "fixed"),  # continuous joints: cos, sin
        ("solo_description/robots/solo12.urdf", "floating"),  # free-flyer: x, y, z, quaternion
        ("panda_description/urdf/panda.urdf", "fixed"),  # prismatic fingers, one unaligned
    ],
)
def test_state_and_back_gives_pinocchios_q_and_v(relative, base):
    robot = Robot.from_urdf(example_robot_data(relative), base=base)
    rng = np.random.default_rng(4)
    for _ in range(10):
        q, v, _ = _random_state(robot.model, rng)
        state = robot.state(q, v)
        q2, v2 = robot._q_v(state)
        np.testing.assert_allclose(pin.difference(robot.model, q, q2), 0.0, atol=1e-12)
        np.testing.assert_allclose(v2, v, atol=1e-12)


PLANAR_URDF = """<robot name="sled">
  <link name="ground"/>
  <link name="sled">
    <inertial><origin xyz="0.1 -0.05 0.02" rpy="0.1 0.2 0.3"/><mass value="2.0"/>
      <inertia ixx="0.3" iyy="0.4" izz="0.5" ixy="0.01" ixz="0.0" iyz="0.02"/></inertial>
  </link>
  <link name="arm">
    <inertial><origin xyz="0.3 0 0"/><mass value="0.5"/>
      <inertia ixx="0.01" iyy="0.02" izz="0.025" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="slide" type="planar">
    <parent link="ground"/><child link="sled"/><origin xyz="0 0 1" rpy="0.3 0 0"/>
  </joint>
  <joint name="hinge" type="continuous">
    <parent link="sled"/><child link="arm"/><origin xyz="0.2 0.1 0" rpy="0 0.4 0"/>
    <axis xyz="0.6 0 0.8"/>
  </joint>
</robot>
"""


def test_a_planar_joint_and_an_unaligned_continuous_joint_follow_pinocchio(tmp_path):
    path = tmp_path / "sled.urdf"
    path.write_text(PLANAR_URDF)
    robot = Robot.from_urdf(path)
    assert robot.joint("slide").kind == "planar"
    assert _worst(robot, 50, seed=3) <= RTOL
    rng = np.random.default_rng(8)
    q, v, _ = _random_state(robot.model, rng)
    q2, v2 = robot._q_v(robot.state(q, v))
    np.testing.assert_allclose(pin.difference(robot.model, q, q2), 0.0, atol=1e-12)
    np.testing.assert_allclose(v2, v, atol=1e-12)


def test_locked_joints_give_pinocchios_reduced_model():
    path = example_robot_data("panda_description/urdf/panda.urdf")
    fingers = {"panda_finger_joint1": [0.02], "panda_finger_joint2": [0.03]}
    robot = Robot.from_urdf(path, locked_joints=fingers)
    assert (robot.nq, robot.nv, len(robot.bodies)) == (7, 7, 7)
    assert "panda_finger_joint1" not in robot.joints
    assert _worst(robot, 20, seed=5) <= RTOL
    by_name = Robot.from_urdf(path, locked_joints=list(fingers))
    assert by_name.nv == 7


def test_a_panda_second_agrees_with_aba_integrated_by_dop853():
    """1 s of the Panda (fingers locked) falling from a random state under gravity: gmuk's
    run against Pinocchio's ABA integrated by scipy's DOP853, both at tight tolerances."""
    path = example_robot_data("panda_description/urdf/panda.urdf")
    robot = Robot.from_urdf(path, locked_joints=["panda_finger_joint1", "panda_finger_joint2"])
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(12)
    q0, v0, _ = _random_state(model, rng)
    t = np.linspace(0.0, 1.0, 101)  # dense enough that the rates unwrap every angle
    traj = robot.system.simulate(robot.state(q0, v0), (0.0, 1.0), t_eval=t, rtol=1e-12, atol=1e-12)
    assert traj.success, traj.message

    def rhs(_t, y):
        return np.concatenate([y[7:], pin.aba(model, data, y[:7], y[7:], np.zeros(7))])

    ref = solve_ivp(rhs, (0.0, 1.0), np.concatenate([q0, v0]), method="DOP853", t_eval=t,
                    rtol=1e-13, atol=1e-13)  # fmt: skip
    q = robot.configuration(traj)
    v = robot.velocity(traj)
    assert np.abs(q - ref.y[:7].T).max() <= 1e-7
    assert np.abs(v - ref.y[7:].T).max() <= 1e-6


def test_configuration_unwraps_revolute_angles_along_a_run():
    path = example_robot_data("double_pendulum_description/urdf/double_pendulum_simple.urdf")
    robot = Robot.from_urdf(path, gravity=(0.0, 0.0, 0.0))
    # spin the first joint at 10 rad/s for 1 s: its angle passes π
    state = robot.state([0.0, 0.0], [10.0, 0.0])
    traj = robot.system.simulate(state, (0.0, 1.0), t_eval=np.linspace(0.0, 1.0, 101))
    q = robot.configuration(traj)
    assert np.all(np.diff(q[:, 0]) > 0.0)
    assert q[-1, 0] > 2.0 * math.pi


def test_joint_names_and_bad_input_are_reported():
    path = example_robot_data("ur_description/urdf/ur5_robot.urdf")
    robot = Robot.from_urdf(path)
    assert isinstance(robot.joint("elbow_joint"), gmuk.robots.RevoluteJoint)
    with pytest.raises(DefinitionError, match=r"no joint named 'elbow'.*elbow_joint"):
        robot.joint("elbow")
    with pytest.raises(DefinitionError, match="no URDF file"):
        Robot.from_urdf(path.with_name("nothing.urdf"))
    with pytest.raises(DefinitionError, match="base must be"):
        Robot.from_urdf(path, base="mobile")
    with pytest.raises(DefinitionError, match="locked_joints: no joint named 'wrist'"):
        Robot.from_urdf(path, locked_joints=["wrist"])
    with pytest.raises(gmuk.errors.ShapeError):
        robot.state(np.zeros(5), np.zeros(6))
    assert "ur5_robot.urdf" in repr(robot)


def test_missing_example_robot_data_says_how_to_install(monkeypatch):
    import importlib.metadata as md

    from gmuk.robots import data

    def missing(name):
        raise md.PackageNotFoundError(name)

    data._robots_dir.cache_clear()
    monkeypatch.setattr(data.metadata, "distribution", missing)
    try:
        with pytest.raises(MissingDependencyError, match="pip install example-robot-data"):
            example_robot_data("panda_description/urdf/panda.urdf")
    finally:
        monkeypatch.undo()
        data._robots_dir.cache_clear()
