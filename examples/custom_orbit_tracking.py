"""Hold a spacecraft in the modified-LVLH attitude on an orbit of your choosing.

The Chapter 4 set-up (McCann 2020, Section 4.1.2) in a few lines: pick the orbit, the body and
the constraint; gmuk supplies the corrected reference (g_d, V_d, V̇_d) and the Udwadia–Kalaba
constraint wrench. Run: python examples/custom_orbit_tracking.py
"""

import numpy as np

import gmuk
from gmuk.orbits import KeplerOrbit, LVLHReference

MU_MOON = 4.9028e12  # m³/s²


def main() -> dict[str, float]:
    # A frozen-orbit-like lunar orbit: a = 2100 km, e = 0.05, i = 85°, ω = 90°.
    orbit = KeplerOrbit.from_elements(2.1e6, 0.05, np.radians(85.0), 0.0, np.radians(90.0), MU_MOON)
    craft = gmuk.RigidBody("spacecraft", 1200.0, np.diag([800.0, 900.0, 1000.0]))
    reference = LVLHReference(orbit)
    system = gmuk.System(
        [craft], [gmuk.ConfigurationTracking(craft, reference)], [gmuk.GravityGradient(MU_MOON)]
    )
    start = reference.evaluate(0.0)  # at periapsis, on the reference
    state = system.state(g={"spacecraft": start.g}, V={"spacecraft": start.V})
    t = np.linspace(0.0, orbit.period, 361)
    traj = system.simulate(state, (0.0, orbit.period), t_eval=t, rtol=1e-13, atol=1e-12)

    view = traj.body("spacecraft")
    expected = reference.evaluate_many(t)
    torque = np.linalg.norm(view.constraint_force[:, :3], axis=1)  # N·m, body frame
    result = {
        "period_s": float(orbit.period),
        "max_position_error_m": float(
            np.linalg.norm(view.position - expected.g[:, :3, 3], axis=1).max()
        ),
        "max_constraint_torque_N_m": float(torque.max()),
        "mean_constraint_torque_N_m": float(torque.mean()),
    }
    for k, v in result.items():
        print(f"{k:>26}: {v:.4g}")
    return result


if __name__ == "__main__":
    main()
