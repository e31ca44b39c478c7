"""An inequality of your own: a probe dropped onto a floor, z ≥ 0 (McCann 2020, §6.3).

Only h = z is written; gmuk takes its derivatives, adds the excess coordinate p
(h − 0 − p² = 0), sets p from the initial state and solves the equality with the rest.
A damper on the excess coordinate makes the contact inelastic, so the probe comes to rest
on the floor, where the multiplier is the floor's normal force.
Run: python examples/inequality_floor.py
"""

import numpy as np

import gmuk
from gmuk.kkt import kkt_diagnostics


class AboveFloor(gmuk.InequalityConstraint):
    """h = z, the height of a point mass above the plane z = 0 (m)."""

    def value(self, q, nu, t):
        (r,) = q
        return r[2]


def main() -> dict[str, float]:
    probe = gmuk.PointMass("probe", mass=1.5)
    floor = AboveFloor([probe], lower=0.0, unit="m", name="floor")
    system = gmuk.System([probe], [floor], [gmuk.UniformGravity(), gmuk.SlackDamping(8.0)])
    state = system.state(r={"probe": [0.0, 0.0, 2.0]}, v={"probe": [0.5, 0.0, 0.0]})
    traj = system.simulate(
        state, (0.0, 15.0), t_eval=np.linspace(0, 15, 1501), rtol=1e-10, atol=1e-12
    )
    kkt = kkt_diagnostics(system, traj)["floor.lower"]
    z = traj.body("probe").position[:, 2]
    weight = probe.mass * 9.80665
    result = {
        "min_height_m": float(z.min()),
        "primal_violation_max_m": float(kkt.primal_violation.max()),
        "final_normal_force_N": float(kkt.mu[-1]),
        "normal_force_vs_weight": float(kkt.mu[-1] / weight - 1.0),
        "final_horizontal_speed_m_s": float(traj.body("probe").velocity[-1, 0]),
    }
    for k, v in result.items():
        print(f"{k:>28}: {v:.4g}")
    return result


if __name__ == "__main__":
    main()
