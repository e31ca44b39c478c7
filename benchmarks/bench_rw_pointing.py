"""rw-pointing: gmuk beside Basilisk 2.12, the same reaction-wheel slew (issue #29, item 7).

Run on demand (not a test; Basilisk is a benchmark-only peer, never a gmuk dependency):

    pip install bsk==2.12.1
    python benchmarks/bench_rw_pointing.py [--repeat N]

The script pins OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1 before numpy is imported.

Setup (gmuk/scenarios/rw_pointing.py states it): I_B = diag(900, 800, 600) kg·m² with the
wheels locked, three balanced HR16-class wheels on the body axes (J_s = 50/(6000 rpm),
0.2 N·m, 6000 rpm, no friction) at 100, 200, 300 rpm, σ_BN(0) = (0.1, 0.2, −0.3),
ω_BN(0) = (0.001, −0.01, 0.03) rad/s, 600 s, L = −K σ − P ω + ω × H (K = 3.5, P = 30),
u = −Gᵀ L saturated. Basilisk: ``spacecraft.Spacecraft`` with ``hub.IHubPntBc_B = I_B``
(balanced wheels subtract J_s g gᵀ themselves: ``matrixD −= Js g gᵀ``), no gravity body,
``ReactionWheelStateEffector`` with ``rwFactory.create('Honeywell_HR16', g, maxMomentum=50.,
Omega=…, rWB_B=0)``, ``simpleNav`` → ``attTrackingError`` (``inertial3D``, σ_R0N = 0) →
``mrpFeedback`` (K, P, Ki = −1, **controlLawType = 1**: its ω × H term uses ω_BN as the
issue's law does; the example's default 0 uses ω_RN = 0 and drops it) → ``rwMotorTorque``
(control axes = I) → the wheels; vehicle configuration I_B. Everything in one task at step
dt with Basilisk's default RK4 integrator.

Control in time. Basilisk's flight software runs once per task step: its wheel command is
held for dt (zero-order hold). gmuk's MRPFeedback is continuous. Basilisk is made
continuous-equivalent by shrinking dt: its error against the continuous law is O(dt)
(the hold) plus O(dt⁴) (RK4). Its own convergence is the change of its final state when dt
halves; gmuk's own convergence is the change of its final state from rtol = atol = 1e-12 to
1e-13 (DOP853). Agreement is measured on the final σ_BN (as the rotation angle between the
two attitudes), ω_BN and the wheel speeds.

Timing: the whole run (build the simulation, run 600 s, read the final state) after one
warm-up, median of ``--repeat`` runs; imports and gmuk's one-time loop compile excluded.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import itertools
import statistics
import time
from typing import Any

import numpy as np

from gmuk.attitude import R_NB_from_mrp
from gmuk.lie import so3
from gmuk.scenarios import rw_pointing as rw

DURATION = 600.0


def gmuk_run(tol: float) -> dict[str, Any]:
    """The whole gmuk run (internal-momentum form) at rtol = atol = tol."""
    system, state, law = rw.build("internal")
    traj = system.simulate(state, (0.0, DURATION), rtol=tol, atol=tol, t_eval=[DURATION])
    bus = traj.body("bus")
    omega = bus.omega[-1]
    speeds = traj.z[-1, :3] / law.wheels.J_s - law.wheels.G.T @ omega
    return {"R": bus.R[-1], "omega": omega, "speeds": speeds, "steps": traj.stats["n_steps"]}


def basilisk_run(dt: float) -> dict[str, Any]:
    """The whole Basilisk run at task step dt (s)."""
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import attTrackingError, inertial3D, mrpFeedback, rwMotorTorque
    from Basilisk.simulation import reactionWheelStateEffector, simpleNav, spacecraft
    from Basilisk.utilities import SimulationBaseClass, macros, simIncludeRW
    from Basilisk.utilities import unitTestSupport as sh

    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("p")
    proc.addTask(sim.CreateNewTask("t", macros.sec2nano(dt)))
    sc = spacecraft.Spacecraft()
    sc.hub.mHub = rw.MASS
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = sh.np2EigenMatrix3d(rw.INERTIA_B.ravel().tolist())
    sc.hub.sigma_BNInit = [[x] for x in rw.SIGMA0]
    sc.hub.omega_BN_BInit = [[x] for x in rw.OMEGA0]
    sim.AddModelToTask("t", sc, 1)
    factory = simIncludeRW.rwFactory()
    for g, rpm in zip(np.eye(3), (100.0, 200.0, 300.0), strict=True):
        factory.create(
            "Honeywell_HR16", g.tolist(), maxMomentum=50.0, Omega=rpm, rWB_B=[0.0, 0.0, 0.0]
        )
    wheels = reactionWheelStateEffector.ReactionWheelStateEffector()
    factory.addToSpacecraft("rw", wheels, sc)
    sim.AddModelToTask("t", wheels, 2)
    nav = simpleNav.SimpleNav()
    sim.AddModelToTask("t", nav)
    ref = inertial3D.inertial3D()
    ref.sigma_R0N = [0.0, 0.0, 0.0]
    sim.AddModelToTask("t", ref)
    err = attTrackingError.attTrackingError()
    sim.AddModelToTask("t", err)
    ctl = mrpFeedback.mrpFeedback()
    ctl.K, ctl.Ki, ctl.P = rw.K, -1.0, rw.P
    ctl.integralLimit = 2.0 / ctl.Ki * 0.1
    ctl.controlLawType = 1
    sim.AddModelToTask("t", ctl)
    mot = rwMotorTorque.rwMotorTorque()
    mot.controlAxes_B = [1, 0, 0, 0, 1, 0, 0, 0, 1]
    sim.AddModelToTask("t", mot)
    vc = messaging.VehicleConfigMsg().write(
        messaging.VehicleConfigMsgPayload(ISCPntB_B=rw.INERTIA_B.ravel().tolist())
    )
    params = factory.getConfigMessage()
    nav.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    err.attNavInMsg.subscribeTo(nav.attOutMsg)
    err.attRefInMsg.subscribeTo(ref.attRefOutMsg)
    ctl.guidInMsg.subscribeTo(err.attGuidOutMsg)
    ctl.vehConfigInMsg.subscribeTo(vc)
    ctl.rwParamsInMsg.subscribeTo(params)
    ctl.rwSpeedsInMsg.subscribeTo(wheels.rwSpeedOutMsg)
    mot.rwParamsInMsg.subscribeTo(params)
    mot.vehControlInMsg.subscribeTo(ctl.cmdTorqueOutMsg)
    wheels.rwMotorCmdInMsg.subscribeTo(mot.rwMotorTorqueOutMsg)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(DURATION))
    sim.ExecuteSimulation()
    state = sc.scStateOutMsg.read()
    return {
        "R": R_NB_from_mrp(np.asarray(state.sigma_BN)),
        "omega": np.asarray(state.omega_BN_B),
        "speeds": np.asarray(wheels.rwSpeedOutMsg.read().wheelSpeeds[:3]),
    }


def distance(a: dict[str, Any], b: dict[str, Any]) -> tuple[float, float, float]:
    """(attitude angle (rad), |Δω| (rad/s), max |ΔΩ| (rad/s)) between two final states."""
    angle = float(np.linalg.norm(so3.log(a["R"].T @ b["R"])))
    return (
        angle,
        float(np.linalg.norm(a["omega"] - b["omega"])),
        float(np.abs(a["speeds"] - b["speeds"]).max()),
    )


def richardson(coarse: dict[str, Any], fine: dict[str, Any]) -> dict[str, Any]:
    """First-order Richardson extrapolation of two runs at dt and dt/2: 2·fine − coarse (on
    SO(3): fine moved on by the rotation from coarse to fine)."""
    step = so3.log(coarse["R"].T @ fine["R"])
    return {
        "R": fine["R"] @ so3.exp(step),
        "omega": 2.0 * fine["omega"] - coarse["omega"],
        "speeds": 2.0 * fine["speeds"] - coarse["speeds"],
    }


def timed(fn: Any, arg: Any, repeat: int) -> float:
    fn(arg)  # warm-up
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(arg)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    fmt = "{:>26}  {:>10.2e} rad  {:>10.2e} rad/s  {:>10.2e} rad/s"
    ref = gmuk_run(1e-13)
    print("gmuk (DOP853, continuous law); final state against gmuk at 1e-13:")
    for tol in (1e-8, 1e-10, 1e-12):
        print(fmt.format(f"rtol = atol = {tol:g}", *distance(gmuk_run(tol), ref)))
    print("Basilisk 2.12 (RK4, FSW held for dt); final state against gmuk at 1e-13,")
    print("and [against itself at dt/2]:")
    runs = {dt: basilisk_run(dt) for dt in (0.1, 0.05, 0.025, 0.0125, 0.00625)}
    dts = sorted(runs, reverse=True)
    for a, b in itertools.pairwise(dts):
        print(fmt.format(f"dt = {a:g} s", *distance(runs[a], ref)))
        print(fmt.format(f"[dt = {a:g} vs {b:g} s]", *distance(runs[a], runs[b])))
    print(fmt.format(f"dt = {dts[-1]:g} s", *distance(runs[dts[-1]], ref)))
    print("Basilisk extrapolated to dt → 0 (Richardson, first order) against gmuk at 1e-13:")
    for a, b in itertools.pairwise(dts):
        print(fmt.format(f"from dt = {a:g}, {b:g} s", *distance(richardson(runs[a], runs[b]), ref)))
    print(f"\nwhole-run time, median of {args.repeat}:")
    t_g = {tol: timed(gmuk_run, tol, args.repeat) for tol in (1e-8, 1e-12)}
    t_b = {dt: timed(basilisk_run, dt, args.repeat) for dt in (0.1, 0.0125)}
    for tol, t in t_g.items():
        print(f"  gmuk     rtol = atol = {tol:g}: {t * 1e3:9.1f} ms")
    for dt, t in t_b.items():
        print(f"  Basilisk dt = {dt:g} s:         {t * 1e3:9.1f} ms")
    print(
        f"  ratio gmuk(1e-8) / Basilisk(dt 0.1 s) = {t_g[1e-8] / t_b[0.1]:.3f}; "
        f"gmuk(1e-12) / Basilisk(dt 0.0125 s) = {t_g[1e-12] / t_b[0.0125]:.3f}"
    )


if __name__ == "__main__":
    main()
