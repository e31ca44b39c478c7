"""Tutorial 6: a robot from its URDF — load it, check it, simulate it, read its joints.

gmuk reads the URDF with Pinocchio's parser and builds one rigid body per link and one joint
(a constraint) per URDF joint. The script loads the Panda arm of example-robot-data with its
fingers locked, checks gmuk's joint accelerations against Pinocchio's articulated-body
algorithm, lets the arm fall under gravity with damped joints and a torque on its elbow, and
reads the joint angles back — from the robot (Pinocchio's q) and from one named joint.

    python examples/tutorials/t6_robot_from_urdf.py [--quick]
"""

from __future__ import annotations

import argparse

import numpy as np
import pinocchio as pin

from gmuk.robots import JointEffort, Robot, example_robot_data


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a short run (for the tests)")
    args = parser.parse_args(argv)
    duration = 0.5 if args.quick else 2.0

    # 1. Load: a fixed base, the two finger joints locked at their neutral opening, and a
    #    viscous damper of 0.5 N·m·s/rad on each of the seven arm joints.
    urdf = example_robot_data("panda_description/urdf/panda.urdf")
    fingers = ["panda_finger_joint1", "panda_finger_joint2"]
    robot = Robot.from_urdf(urdf, locked_joints=fingers, damping=0.5)
    print(robot)

    # 2. Check: gmuk's joint accelerations against pin.aba at random states (Pinocchio's
    #    q, v and τ; the damping is a force model of the robot, so Pinocchio gets it in τ).
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(0)
    pin.seed(0)  # Pinocchio's generator too: the same states on every run
    worst = 0.0
    for _ in range(10):
        q = pin.randomConfiguration(model)
        v, tau = rng.normal(size=7), rng.normal(size=7)
        expected = pin.aba(model, data, q, v, tau - 0.5 * v)
        worst = max(worst, float(np.abs(robot.forward_dynamics(q, v, tau) - expected).max()))
    print(f"largest difference from pin.aba: {worst:.1e} rad/s²")

    # 3. Simulate: add a constant 5 N·m on the elbow (panda_joint4) and release the arm at
    #    rest from its ready posture.
    elbow = robot.joint("panda_joint4")
    driven = robot.with_forces([JointEffort(elbow, [5.0])])
    q0 = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    state = driven.state(q0, np.zeros(7))
    t = np.linspace(0.0, duration, 101)
    traj = driven.system.simulate(state, (0.0, duration), t_eval=t)
    print(traj.summary())

    # 4. Read the joints: Pinocchio's q for the whole arm, or one joint's angle (unwrapped)
    q = driven.configuration(traj)
    q4 = elbow.coordinates_along(traj)[:, 0]
    print(f"elbow: {np.degrees(q4[0]):.1f}° → {np.degrees(q4[-1]):.1f}°")
    residual = max(float(np.abs(r).max()) for j in driven.joints.values()
                   for r in j.violation(traj.state(-1)))  # fmt: skip
    print(f"largest joint residual at the end: {residual:.1e}")
    return {
        "aba_difference": worst,
        "elbow_column_matches": float(np.abs(q[:, 3] - q4).max()),
        "elbow_turn_rad": float(q4[-1] - q4[0]),
        "joint_residual": residual,
        "success": float(traj.success),
    }


if __name__ == "__main__":
    main()
