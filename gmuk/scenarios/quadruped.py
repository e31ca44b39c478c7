"""Solo12 standing on the ground: a floating-base quadruped with exact contacts (issue #28).

The Solo12 of example-robot-data's URDF (floating base, twelve revolute joints) is released
1 mm above a flat floor in a standing posture (hips straight, thighs ±0.8 rad, knees ∓1.6 rad),
its joints held by spring–dampers about that posture (5 N·m/rad, 0.3 N·m·s/rad). Each foot is a
:class:`~gmuk.constraints.unilateral.PointPlaneContact` on its lower leg; the run goes through
the landing impact (:func:`gmuk.engine.contact.simulate_with_impacts`) and the robot settles on
its four feet. The summary gives the feet's normal forces at the end (their sum is the weight),
the base height, the number of impacts and the contacts' KKT conditions along the run
(:func:`gmuk.engine.contact.contact_kkt`): penetration, negative multipliers, complementarity.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmuk.scenarios import Option, Scenario, ScenarioResult, positive_float
from gmuk.view import with_joint_frames

NAME = "quadruped"
DESCRIPTION = "Solo12 (URDF, floating base) landing and standing on four exact contacts"

URDF = "solo_description/robots/solo12.urdf"
LEGS = ("FL", "FR", "HL", "HR")
#: Standing posture (rad) of each leg's hip abduction, hip flexion and knee.
POSTURE = {"FL": (0.0, 0.8, -1.6), "FR": (0.0, 0.8, -1.6), "HL": (0.0, -0.8, 1.6),
           "HR": (0.0, -0.8, 1.6)}  # fmt: skip
DROP = 1e-3  # m: the lowest foot's height at release
STIFFNESS, DAMPING = 5.0, 0.3  # N·m/rad, N·m·s/rad


def build() -> tuple[Any, Any, Any, list[Any]]:
    """(robot, System with feet and joint springs, initial State, the foot contacts)."""
    import pinocchio as pin

    from gmuk.constraints.unilateral import PointPlaneContact
    from gmuk.robots import JointSpringDamper, Robot, example_robot_data

    robot = Robot.from_urdf(example_robot_data(URDF), base="floating")
    model = robot.model
    q0 = pin.neutral(model)
    for leg, angles in POSTURE.items():
        for joint, value in zip(("HAA", "HFE", "KFE"), angles, strict=True):
            q0[model.joints[model.getJointId(f"{leg}_{joint}")].idx_q] = value
    data = model.createData()
    pin.framesForwardKinematics(model, data, q0)
    feet = [model.getFrameId(f"{leg}_FOOT") for leg in LEGS]
    q0[2] += DROP - min(float(data.oMf[f].translation[2]) for f in feet)
    contacts = []
    for leg, fid in zip(LEGS, feet, strict=True):
        frame = model.frames[fid]
        i = frame.parentJoint  # the foot in its lower leg's body frame (at its centre of mass)
        point = np.array(frame.placement.translation) - robot._com[i]
        contacts.append(PointPlaneContact(robot.bodies[i - 1], point, name=f"{leg} foot"))
    rest = robot.state(q0, np.zeros(model.nv))
    springs = [
        JointSpringDamper(j, stiffness=STIFFNESS, damping=DAMPING, rest=j.coordinates(rest))
        for j in robot.joints.values()
    ]
    system = robot.with_parts(constraints=contacts, forces=springs)
    return robot, system, robot.state(q0, np.zeros(model.nv), system=system), contacts


def run(duration: float = 0.5) -> ScenarioResult:
    """Simulate ``duration`` s from the release."""
    from gmuk.engine.contact import contact_kkt, simulate_with_impacts

    robot, system, state, contacts = build()
    t = np.linspace(0.0, duration, round(100 * duration) + 1)
    traj = simulate_with_impacts(system, state, (0.0, duration), t_eval=t, rtol=1e-8, atol=1e-8)
    traj = with_joint_frames(traj, system)  # the 3-D view draws the links and joints
    kkt = contact_kkt(system, traj)
    weight = -float(robot.model.gravity.linear[2]) * sum(b.mass for b in robot.bodies)
    forces = np.column_stack([kkt[c.name].multiplier[:, 0] for c in contacts])
    summary = {
        "duration_s": duration,
        "impacts": int(traj.stats.get("impacts", 0)),
        "foot_forces_end_N": forces[-1].tolist(),
        "weight_N": weight,
        "support_minus_weight_end_N": float(forces[-1].sum() - weight),
        "base_height_end_m": float(traj.state(-1).pose(robot.bodies[0].name)[2, 3]),
        "max_penetration_m": max(k.summary()["penetration"] for k in kkt.values()),
        "max_negative_multiplier_N": max(k.summary()["negative_multiplier"] for k in kkt.values()),
        "max_complementarity": max(k.summary()["complementarity"] for k in kkt.values()),
        "rhs_evaluations": int(traj.stats.get("n_rhs", 0)),
    }
    return ScenarioResult(
        NAME, {NAME: traj}, NAME, summary, data={"forces": forces, "robot": robot, "kkt": kkt}
    )


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Base height, the feet's normal forces and the contacts' complementarity."""
    from gmuk.plotting import plot_panels

    traj = result.trajectories[NAME]
    robot, forces, kkt = result.data["robot"], result.data["forces"], result.data["kkt"]
    base = traj.body(robot.bodies[0].name).position[:, 2]
    none: dict[str, Any] = {}
    return plot_panels(
        traj.t,
        [
            ("base height (m)", [("base", base, {"color": "k"})]),
            (
                "normal force (N)",
                [(f"{leg} foot", forces[:, k], none) for k, leg in enumerate(LEGS)],
            ),
            (
                "|λ (a ν̇ − b)|",
                [(f"_{name}", np.abs(k.complementarity[:, 0]), none) for name, k in kkt.items()],
            ),
        ],
        "Solo12 landing and standing on four frictionless contacts",
        out / "quadruped_contacts",
        formats,
    )


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(Option("duration", positive_float, 0.5, "simulated time (s)"),),
)
