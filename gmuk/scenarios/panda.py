"""The Franka Emika Panda arm falling under gravity with joint damping (issue #28).

The Panda of example-robot-data's URDF (fingers locked at their neutral opening), released at
rest from its "ready" configuration, falls under gravity (g = 9.81 m/s² along −z, Pinocchio's
default) with a viscous damper of ``damping`` N·m·s/rad on each of its seven joints. gmuk runs it
in maximal coordinates (seven rigid bodies, seven revolute joints: 35 constraint rows);
Pinocchio's articulated-body algorithm integrated by scipy's DOP853 runs the same robot in
reduced coordinates as the reference. The summary gives the final joint angles, the largest
difference from the reference, the mechanical energy dissipated (it may only decrease) and the
joints' constraint residuals.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmuk.scenarios import Option, Scenario, ScenarioResult, non_negative_float, positive_float
from gmuk.view import with_joint_frames

NAME = "panda"
DESCRIPTION = "Panda arm (URDF) falling under gravity with joint damping, against Pinocchio ABA"

#: The arm's "ready" configuration (rad), example-robot-data's reference posture.
READY = np.array([0.0, -0.785398163, 0.0, -2.35619449, 0.0, 1.57079632679, 0.785398163])
URDF = "panda_description/urdf/panda.urdf"
FINGERS = ("panda_finger_joint1", "panda_finger_joint2")


def build(damping: float = 0.5) -> Any:
    """The Panda Robot with a JointSpringDamper of ``damping`` (N·m·s/rad) on each joint."""
    from gmuk.robots import Robot, example_robot_data

    return Robot.from_urdf(example_robot_data(URDF), locked_joints=FINGERS, damping=damping)


def mechanical_energy(robot: Any, traj: Any) -> np.ndarray:
    """Kinetic plus gravitational potential energy (J) of the robot's bodies at each output."""
    g_N = np.array(robot.model.gravity.linear, dtype=float)
    out = np.zeros(len(traj))
    for body in robot.bodies:
        view = traj.body(body.name)
        w, v, r = view.omega, view.v, view.position
        J, m = body.inertia, body.mass
        out += 0.5 * np.einsum("ni,ij,nj->n", w, J, w)
        out += 0.5 * m * np.einsum("ni,ni->n", v, v) - m * r @ g_N
    return out


def pinocchio_reference(
    robot: Any, q0: np.ndarray, v0: np.ndarray, t: np.ndarray, damping: float
) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's ABA with τ = −c v, integrated by scipy's DOP853 at rtol = atol = 1e-12:
    (q (N, 7), v (N, 7))."""
    import pinocchio as pin
    from scipy.integrate import solve_ivp

    model = robot.model
    data = model.createData()
    n = model.nv

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        return np.concatenate([y[n:], pin.aba(model, data, y[:n], y[n:], -damping * y[n:])])

    y0 = np.concatenate([q0, v0])
    sol = solve_ivp(rhs, (t[0], t[-1]), y0, method="DOP853", t_eval=t, rtol=1e-12, atol=1e-12)
    return sol.y[:n].T, sol.y[n:].T


def run(duration: float = 2.0, damping: float = 0.5) -> ScenarioResult:
    """Simulate ``duration`` s of the falling arm."""
    robot = build(damping)
    v0 = np.zeros(robot.nv)
    t = np.linspace(0.0, duration, round(200 * duration) + 1)
    traj = robot.system.simulate(robot.state(READY, v0), (0.0, duration), t_eval=t)
    traj = with_joint_frames(traj, robot.system)  # the 3-D view draws the links and joints
    q = robot.configuration(traj)
    v = robot.velocity(traj)
    q_ref, v_ref = pinocchio_reference(robot, READY, v0, t, damping)
    energy = mechanical_energy(robot, traj)
    summary = {
        "duration_s": duration,
        "damping_N_m_s_per_rad": damping,
        "q_final_rad": q[-1].tolist(),
        "pinocchio_max_q_difference_rad": float(np.abs(q - q_ref).max()),
        "pinocchio_max_v_difference_rad_s": float(np.abs(v - v_ref).max()),
        "energy_dissipated_J": float(energy[0] - energy[-1]),
        "energy_largest_increase_J": float(max(np.diff(energy).max(initial=0.0), 0.0)),
        "rhs_evaluations": int(traj.stats.get("n_rhs", 0)),
    }
    return ScenarioResult(
        NAME,
        {NAME: traj},
        NAME,
        summary,
        data={"robot": robot, "q": q, "v": v, "q_ref": q_ref, "energy": energy},
    )


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Joint angles, their difference from Pinocchio's, and the mechanical energy."""
    from gmuk.plotting import plot_panels

    traj = result.trajectories[NAME]
    q, q_ref, energy = result.data["q"], result.data["q_ref"], result.data["energy"]
    names = list(result.data["robot"].joints)
    none: dict[str, Any] = {}
    angles = [(f"joint {k + 1}", np.degrees(q[:, k]), none) for k in range(q.shape[1])]
    diffs = [(f"_joint {k + 1}", q[:, k] - q_ref[:, k], none) for k in range(q.shape[1])]
    paths = plot_panels(
        traj.t,
        [
            ("q (deg)", angles),
            ("q − q_Pinocchio (rad)", diffs),
            ("E − E₀ (J)", [("mechanical energy", energy - energy[0], {"color": "k"})]),
        ],
        f"Panda falling with joint damping ({', '.join(names[:1])} … {names[-1]})",
        out / "panda_joints",
        formats,
    )
    return paths


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("duration", positive_float, 2.0, "simulated time (s)"),
        Option("damping", non_negative_float, 0.5, "viscous damping on each joint (N·m·s/rad)"),
    ),
)
