"""Tutorial 7: a spacecraft on reaction wheels under MRP feedback, in both wheel forms.

Three HR16-class wheels (50 N·m·s at 6000 rpm, 0.2 N·m) on the body axes of a spacecraft of
locked inertia I_B = diag(900, 800, 600) kg·m², spinning at 100, 200, 300 rpm; Basilisk's
MRP feedback L = −K σ − P ω + ω × H turns the spacecraft from σ_BN = (0.1, 0.2, −0.3) to
inertial pointing (the setup of ``gmuk run rw-pointing``).

1. The internal-momentum form: the bus alone (inertia I_B − Σ J_s g gᵀ) and the wheel momenta
   as the controller's states. Fast: the whole slew in a few hundredths of a second.
2. The Udwadia–Kalaba form: each wheel a rigid body on a bearing (a RelativeConstraint free
   about its spin axis), the motor a torque pair. The two forms fly the same slew, and the
   bearing's torque on each wheel has no component about the spin axis.

Run: python examples/tutorials/t7_gnc_wheels.py [--quick]
"""

from __future__ import annotations

import argparse

import numpy as np

import gmuk
from gmuk.actuators import ReactionWheel, WheelArray, WheelMotors
from gmuk.attitude import R_NB_from_mrp, mrp_from_R_NB

RPM = 2.0 * np.pi / 60.0


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a shorter UK comparison")
    args = parser.parse_args(argv)
    compare = 10.0 if args.quick else 60.0  # s of the slew flown in both forms

    I_B = np.diag([900.0, 800.0, 600.0])  # kg·m², wheels locked
    J_s = 50.0 / (6000.0 * RPM)  # kg·m²
    wheels = WheelArray(
        [ReactionWheel(g, J_s, max_torque=0.2, max_speed=6000 * RPM) for g in np.eye(3)]
    )
    speeds0 = np.array([100.0, 200.0, 300.0]) * RPM  # rad/s, relative to the bus
    omega0 = np.array([0.001, -0.01, 0.03])  # rad/s, body frame
    g0 = np.eye(4)
    g0[:3, :3] = R_NB_from_mrp([0.1, 0.2, -0.3])
    V0 = np.r_[omega0, 0.0, 0.0, 0.0]

    # 1. internal-momentum form: the wheel command is the controller's output
    bus = gmuk.RigidBody("bus", 750.0, wheels.spun_down_inertia(I_B))
    law = gmuk.MRPFeedback(bus, wheels, K=3.5, P=30.0, inertia_B=I_B)
    fast = gmuk.System([bus], controllers=[law])
    state = fast.state(g={"bus": g0}, V={"bus": V0}, z=law.states(omega0, speeds0))
    traj = fast.simulate(state, (0.0, 600.0), rtol=1e-12, atol=1e-12)
    final = traj.body("bus")
    h = traj.z[:, :3]  # the wheels' absolute spin momenta (N·m·s)
    H_N = np.einsum("kij,kj->ki", final.R, final.omega @ bus.inertia.T + h @ wheels.G.T)

    # 2. Udwadia–Kalaba form: wheel bodies on bearings, the same law drives the motors
    bus_uk = gmuk.RigidBody("bus", 750.0, wheels.uk_bus_inertia(I_B))
    wheel_bodies, bearings = wheels.uk_parts(bus_uk)
    motors = WheelMotors(bus_uk, wheel_bodies, wheels, law.wheel_command)
    exact = gmuk.System([bus_uk, *wheel_bodies], constraints=bearings, forces=[motors])
    g_w, V_w = wheels.uk_state(wheel_bodies, g0, V0, speeds0)
    state_uk = exact.state(g={"bus": g0, **g_w}, V={"bus": V0, **V_w})
    t = np.linspace(0.0, compare, 11)
    uk = exact.simulate(state_uk, (0.0, compare), rtol=1e-12, atol=1e-12, t_eval=t)
    im = fast.simulate(state, (0.0, compare), rtol=1e-12, atol=1e-12, t_eval=t)
    R_uk, R_im = uk.body("bus").R[-1], im.body("bus").R[-1]
    speeds_uk = motors.wheel_speeds(uk.state(len(t) - 1))
    speeds_im = wheels.speeds(im.body("bus").omega[-1], im.z[-1, :3])
    bearing_spin = max(np.abs(uk.body(b.name).constraint_force[:, 0]).max() for b in wheel_bodies)
    bearing = max(np.abs(uk.body(b.name).constraint_force[:, :3]).max() for b in wheel_bodies)

    result = {
        "final_sigma_norm": float(np.linalg.norm(mrp_from_R_NB(final.R[-1]))),
        "final_omega_norm_rad_s": float(np.linalg.norm(final.omega[-1])),
        "final_wheel_speed_max_rpm": float(np.abs(wheels.speeds(final.omega[-1], h[-1])).max())
        / RPM,
        "momentum_rel_change": float(np.abs(H_N - H_N[0]).max() / np.linalg.norm(H_N[0])),
        "steps_600s": float(traj.stats["n_steps"]),
        "forms_attitude_difference_rad": float(np.linalg.norm(gmuk.lie.so3.log(R_uk.T @ R_im))),
        "forms_wheel_speed_difference_rad_s": float(np.abs(speeds_uk - speeds_im).max()),
        "bearing_torque_max_Nm": float(bearing),
        "bearing_spin_torque_max_Nm": float(bearing_spin),
    }
    for k, v in result.items():
        print(f"{k:>36}: {v:.3g}")
    return result


if __name__ == "__main__":
    main()
