"""A torque-free asymmetric rigid body: integrate on SE(3) and check the invariants.

Run: python examples/free_rigid_body.py
"""

import numpy as np

import gmuk
from gmuk.dynamics import kinetic_energy, spatial_momentum


def main() -> dict[str, float]:
    body = gmuk.RigidBody("box", mass=2.0, inertia=np.diag([1.0, 2.0, 3.0]))  # kg, kg·m²
    system = gmuk.System([body])
    V0 = np.array([0.3, 1.0, 0.2, 0.5, 0.0, 0.1])  # [ω (rad/s); v (m/s)] in the body frame
    state = system.state(g={"box": np.eye(4)}, V={"box": V0})
    traj = system.simulate(state, (0.0, 60.0), rtol=1e-12, atol=1e-12)
    I = system.mass_matrix
    E = kinetic_energy(traj.V_B[:, 0], I)
    h = spatial_momentum(traj.g_NB[:, 0], traj.V_B[:, 0], I)
    R = traj.body("box").R
    result = {
        "steps": float(traj.stats["n_steps"]),
        "energy_drift": float(np.abs(E / E[0] - 1).max()),
        "momentum_drift": float(np.abs(h - h[0]).max() / np.linalg.norm(h[0])),
        "orthogonality": float(np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3)).max()),
    }
    for k, v in result.items():
        print(f"{k:>15}: {v:.3g}")
    return result


if __name__ == "__main__":
    main()
