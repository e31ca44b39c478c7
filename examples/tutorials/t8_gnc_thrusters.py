"""Tutorial 8: an attitude slew on pulsed thrusters, through the Earth's shadow.

A 150 kg spacecraft (I_B = diag(20, 18, 12) kg·m²) in a 500 km circular orbit at the epoch
2026-03-20T12:00:00 UTC, its orbit plane tilted β = 67.5° from the Sun so that the Earth's
shadow lasts minutes, not half an hour. It feels the Earth's gravity (a point mass, with its
gravity-gradient torque: McCann 2020, Eq. 23) and cannonball solar radiation pressure. Twelve
1 N hydrazine thrusters in six pure couples (0.5 m arms, I_sp = 220 s, minimum impulse bit
5 mN·s, on-time quantum 1 ms) fly an MRP PD slew of 90° towards inertial pointing, commanded
once a second. An EclipseEvent records the umbra's entry and exit, and a second one, terminal,
ends the run when the spacecraft is back in full sunlight.

1. The thrusters spend propellant: :class:`gmuk.actuators.Thrusters` carries the mass as its
   first internal state. The radiation pressure, a force that does not scale with the mass,
   is named in its ``scaled_forces``; left out, the System refuses to be built.
2. :func:`gmuk.actuators.simulate_pulsed` turns each command into valve on-times and
   integrates between the switching times. The script checks that every on-time is a whole
   number of quanta, no firing is below the minimum impulse bit and every thrust is 0 or
   F_max, and that the mass spent is the firings' propellant.

Run: python examples/tutorials/t8_gnc_thrusters.py [--quick]
(--quick: the first 150 s only, the slew and the shadow's entry.)
"""

from __future__ import annotations

import argparse

import numpy as np

import gmuk
from gmuk.actuators import Thrusters, couple_thrusters, simulate_pulsed
from gmuk.attitude import R_NB_from_mrp, mrp_from_R_NB
from gmuk.environment import EARTH_MU, EARTH_RADIUS, CannonballSRP, EclipseEvent, Epoch, position
from gmuk.errors import DefinitionError
from gmuk.lie import so3

EPOCH = "2026-03-20T12:00:00"  # UTC; t = 0 of the run (t in TDB seconds)
ALTITUDE = 500e3  # m, circular
BETA = np.radians(67.5)  # the Sun's elevation above the orbit plane
U0 = np.radians(-16.0)  # where the run starts: the angle from the orbit's midnight point
ARM = 0.5  # m, of each thruster from the centre of mass
K, P = 1.0, 6.0  # N·m, N·m·s: the PD gains on σ_BN and ω_BN
PERIOD = 1.0  # s, the control period


def circular_orbit(epoch: Epoch, altitude: float, beta: float, u: float) -> tuple:
    """r_N (m) and v_N (m/s), GCRS axes, on a circular orbit whose plane has the Sun at the
    elevation ``beta`` (rad) at ``epoch``, at the angle ``u`` (rad, along the motion) from its
    midnight point, the point farthest from the Sun."""
    s = position("sun", epoch)
    s /= np.linalg.norm(s)
    p = np.cross(s, [0.0, 0.0, 1.0])
    p /= np.linalg.norm(p)
    h = np.sin(beta) * s + np.cos(beta) * p  # the orbit's normal: h·s = sin β
    e1 = -s + np.sin(beta) * h  # in the plane, away from the Sun
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(h, e1)
    a = EARTH_RADIUS + altitude
    r_N = a * (np.cos(u) * e1 + np.sin(u) * e2)
    v_N = np.sqrt(EARTH_MU / a) * (-np.sin(u) * e1 + np.cos(u) * e2)
    return r_N, v_N


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the first 150 s only")
    args = parser.parse_args(argv)
    span = 150.0 if args.quick else 1000.0  # s; the full run ends at the terminal event

    epoch = Epoch.from_iso(EPOCH)
    sc = gmuk.RigidBody("sc", 150.0, np.diag([20.0, 18.0, 12.0]))  # kg, kg·m²
    gravity = gmuk.GravityGradient(EARTH_MU)  # the Earth as a point mass, Eq. 23
    srp = CannonballSRP(epoch, area=1.5, C_R=1.3, occulters=("earth",))  # m²
    rcs = couple_thrusters(
        ARM, 1.0, 220.0, min_impulse_bit=0.005, on_time_quantum=0.001
    )  # F_max (N), I_sp (s), minimum impulse bit (N·s), on-time quantum (s)

    # The radiation pressure does not scale with the mass: without scaled_forces it would act
    # on the initial mass, and the System refuses.
    try:
        gmuk.System([sc], forces=[gravity, srp], controllers=[Thrusters(sc, rcs)])
        refused = False
    except DefinitionError as error:
        refused = "not proportional to its mass" in str(error)
    thrusters = Thrusters(sc, rcs, dry_mass=140.0, scaled_forces=[srp])
    system = gmuk.System([sc], forces=[gravity, srp], controllers=[thrusters])

    r_N, v_N = circular_orbit(epoch, ALTITUDE, BETA, U0)
    g0 = np.eye(4)
    g0[:3, :3] = R_NB_from_mrp([np.tan(np.pi / 8), 0.0, 0.0])  # 90° about the x axis
    g0[:3, 3] = r_N
    V0 = np.r_[0.0, 0.0, 0.0, g0[:3, :3].T @ v_N]  # [ω; v] (rad/s, m/s), body frame
    state = system.state(g={"sc": g0}, V={"sc": V0})

    def slew(t: float, state: gmuk.State, mass: float) -> np.ndarray:
        """The commanded wrench [L; F]: L = −K σ_BN − P ω_BN (N·m, body frame), no force."""
        sigma = mrp_from_R_NB(state.pose("sc")[:3, :3])
        return np.r_[-K * sigma - P * state.twist("sc")[:3], 0.0, 0.0, 0.0]

    umbra = EclipseEvent(sc, epoch, kind="umbra", direction=0)  # recorded: entry and exit
    sunlight = EclipseEvent(sc, epoch, kind="penumbra", direction=1, terminal=True, name="sunlight")
    traj = simulate_pulsed(
        system,
        state,
        (0.0, span),
        thrusters,
        slew,
        PERIOD,
        events=[umbra, sunlight],
        rtol=1e-10,
        atol=1e-10,
    )

    # The valves' limits, from the firings simulate_pulsed commanded.
    on = np.array(traj.stats["firings"]["on_times"])  # s, (periods, 12)
    quanta = on / rcs.on_time_quantum
    whole_quanta = bool(np.all(np.abs(quanta - np.round(quanta)) < 1e-9))
    above_bit = bool(np.all((on == 0.0) | (rcs.max_thrust * on >= rcs.min_impulse_bit - 1e-12)))
    all_or_nothing = bool(set(np.unique(traj.z[:, 1:])) <= {0.0, 1.0})
    if not (whole_quanta and above_bit and all_or_nothing):
        raise RuntimeError("a firing broke the valves' limits")
    spent = traj.stats["propellant"]  # kg: the mass state's change
    from_firings = float(np.sum(on @ rcs.mass_flow))  # kg: Σ t_on ṁ

    final = traj.body("sc")
    error = np.linalg.norm(so3.log(final.R), axis=-1)  # rad, from inertial pointing
    # The law's dead band: a command below 2 · arm · (minimum impulse bit) / Δt (one couple's
    # smallest firing) is dropped, i.e. K‖σ‖ below it, an angle θ = 4 arctan ‖σ‖.
    smallest = 2.0 * ARM * rcs.min_impulse_bit[0] / PERIOD  # N·m
    last = traj.state(len(traj) - 1)
    mu = last.z[0] / sc.mass  # m / m₀
    srp_final = np.linalg.norm(srp.wrenches(last, [sc])[0])  # N
    result = {
        "refused_without_scaled_forces": float(refused),
        "propellant_kg": spent,
        "propellant_minus_firings_kg": abs(spent - from_firings),
        "firings": float(np.count_nonzero(on)),
        "within_2deg_from_s": float(traj.t[np.nonzero(error > np.radians(2.0))[0][-1] + 1]),
        "final_attitude_error_rad": float(error[-1]),
        "final_rate_rad_s": float(np.linalg.norm(final.omega[-1])),
        "dead_band_rad": float(4.0 * np.arctan(smallest / K)),
        "srp_force_final_N": float(srp_final),
        "srp_correction_final_N": float((1.0 / mu - 1.0) * srp_final),
        "t_final_s": float(traj.t[-1]),
    }
    for e in traj.events:
        if e.name == "sunlight":
            what, key = "is back in full sunlight", "sunlight_s"
        elif e.direction < 0:
            what, key = f"enters the {e.name}", "umbra_entry_s"
        else:
            what, key = f"leaves the {e.name}", "umbra_exit_s"
        print(f"{what:>26} at t = {e.t:7.2f} s, {(epoch + e.t).iso('utc', 0)} UTC")
        result[key] = e.t
    for k, v in result.items():
        print(f"{k:>32}: {v:.6g}")
    return result


if __name__ == "__main__":
    main()
