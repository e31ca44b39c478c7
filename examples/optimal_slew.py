"""Minimum-effort rest-to-rest slew of a rigid body by direct collocation (gmuk.optimize),
then flown open loop by the simulator. Needs ``pip install "gmuk[optimize]"``.

Run: python examples/optimal_slew.py
"""

import numpy as np

import gmuk
from gmuk.lie import so3
from gmuk.optimize import Mesh, OptimalControlProblem


def main() -> dict[str, float]:
    J = np.array([[10.0, 1.0, -0.5], [1.0, 12.0, 0.3], [-0.5, 0.3, 15.0]])  # kg·m²
    body = gmuk.RigidBody("sat", mass=100.0, inertia=J)
    system = gmuk.System([body])
    start = system.state(g={"sat": np.eye(4)}, V={"sat": np.zeros(6)})
    target = np.eye(4)
    target[:3, :3] = so3.exp(0.5 * np.pi * np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0))  # 90°

    # minimise ∫ uᵀ𝕀⁻¹u dt over 60 s, at rest at both ends, 12 elements of degree 4
    problem = OptimalControlProblem(
        system, start, 60.0, final={"g": {"sat": target}, "V": {"sat": np.zeros(6)}}
    )
    plan = problem.solve(Mesh.uniform(0.0, 60.0, n_elements=12, degree=4))

    # fly the planned torque open loop and compare attitudes at the nodes
    flown = gmuk.System([body], controllers=[plan.controller()])
    traj = flown.simulate(start, (0.0, 60.0), t_eval=plan.t, rtol=1e-11, atol=1e-12)
    R_plan, R_flown = plan.R_NB[:, 0], traj.g_NB[:, 0, :3, :3]
    result = {
        "objective": plan.objective,
        "peak_torque_N_m": float(np.abs(plan.u[:, :3]).max()),
        "final_attitude_error_rad": float(np.linalg.norm(so3.log(R_plan[-1].T @ target[:3, :3]))),
        "orthogonality": float(np.abs(np.swapaxes(R_plan, 1, 2) @ R_plan - np.eye(3)).max()),
        "flown_vs_plan_rad": float(
            np.linalg.norm(so3.log(np.swapaxes(R_flown, 1, 2) @ R_plan), axis=1).max()
        ),
    }
    for k, v in result.items():
        print(f"{k:>25}: {v:.3g}")
    return result


if __name__ == "__main__":
    main()
