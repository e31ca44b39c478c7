"""rw-pointing: inertial pointing on three reaction wheels under MRP feedback (issue #29,
item 7), the setup of Basilisk's ``scenarioAttitudeFeedbackRW`` with its physics stated.

Physics
-------
* I_B = diag(900, 800, 600) kg·m²: the whole spacecraft's inertia about its centre of mass
  with the wheels locked (each wheel's spin inertia included); mass 750 kg (it does not
  enter: no force acts).
* Three balanced wheels with spin axes g_i on the body axes, spin inertia
  J_s = 50 / (6000·2π/60) kg·m² (an HR16-class wheel: 50 N·m·s at 6000 rpm), motor torque
  limit 0.2 N·m, speed limit 6000 rpm, no friction; initial speeds relative to the bus
  100, 200, 300 rpm. Total angular momentum H = I_B ω + J_s Σ Ω_i g_i.
* σ_BN(0) = (0.1, 0.2, −0.3), ω_BN(0) = (0.001, −0.01, 0.03) rad/s; inertial pointing
  (σ_RN = 0).
* Commanded body torque L = −K σ_BN − P ω + ω × H, K = 3.5 N·m, P = 30 N·m·s; wheel motor
  torques u_i = −g_iᵀ L, saturated at 0.2 N·m (:class:`gmuk.MRPFeedback`, continuous in
  time). No external torque.

The spacecraft flies in the internal-momentum form (``--form internal``, the default: the bus
of inertia I_B − Σ J_s g gᵀ and the wheel momenta as the controller's states) or in the
Udwadia–Kalaba form (``--form uk``: three wheel bodies on bearing constraints,
:class:`gmuk.actuators.WheelMotors`). DOP853 at rtol = atol = 1e-12, outputs every second.

Summary (``summary.json``): the final ``sigma_BN``, ``omega_BN_B`` (rad/s, body frame) and
``wheel_speeds`` (rad/s, relative to the bus), and the relative change of the inertial
angular momentum over the run.

Figures: attitude σ_BN, rates ω_BN, wheel speeds (rpm), motor torques (N·m).

Command line: ``gmuk run rw-pointing``, ``gmuk run rw-pointing --duration 60 --form uk``.

References
----------
Basilisk ``examples/scenarioAttitudeFeedbackRW.py`` (the setup; its FSW runs at 0.1 s, the
comparison is in ``benchmarks/bench_rw_pointing.py``); Schaub and Junkins (2018), §8.4.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk.actuators import ReactionWheel, WheelArray, WheelMotors
from gmuk.attitude import R_NB_from_mrp, mrp_from_R_NB
from gmuk.scenarios import Option, Scenario, ScenarioResult, positive_float

NAME = "rw-pointing"
DESCRIPTION = "inertial pointing on three reaction wheels, MRP feedback (Basilisk's RW example)"

RPM = 2.0 * np.pi / 60.0
INERTIA_B = np.diag([900.0, 800.0, 600.0])
MASS = 750.0
SPIN_INERTIA = 50.0 / (6000.0 * RPM)
MAX_TORQUE = 0.2
MAX_SPEED = 6000.0 * RPM
SPEEDS0 = np.array([100.0, 200.0, 300.0]) * RPM
SIGMA0 = np.array([0.1, 0.2, -0.3])
OMEGA0 = np.array([0.001, -0.01, 0.03])
K, P = 3.5, 30.0
RTOL = ATOL = 1e-12


def wheels() -> WheelArray:
    """The three HR16-class wheels on the body axes."""
    return WheelArray(
        [
            ReactionWheel(g, SPIN_INERTIA, max_torque=MAX_TORQUE, max_speed=MAX_SPEED)
            for g in np.eye(3)
        ]
    )


def build(form: str = "internal") -> tuple[gmuk.System, gmuk.State, gmuk.MRPFeedback]:
    """The System, its initial State and the control law, in either wheel form."""
    w = wheels()
    g0 = np.eye(4)
    g0[:3, :3] = R_NB_from_mrp(SIGMA0)
    V0 = np.r_[OMEGA0, 0.0, 0.0, 0.0]
    if form == "internal":
        bus = gmuk.RigidBody("bus", MASS, w.spun_down_inertia(INERTIA_B))
        law = gmuk.MRPFeedback(bus, w, K=K, P=P, inertia_B=INERTIA_B)
        system = gmuk.System([bus], controllers=[law])
        state = system.state(g={"bus": g0}, V={"bus": V0}, z=law.states(OMEGA0, SPEEDS0))
        return system, state, law
    if form == "uk":
        bus = gmuk.RigidBody("bus", MASS, w.uk_bus_inertia(INERTIA_B))
        bodies, constraints = w.uk_parts(bus)
        law = gmuk.MRPFeedback("bus", w, K=K, P=P, inertia_B=INERTIA_B)
        motors = WheelMotors(bus, bodies, w, law.wheel_command)
        system = gmuk.System([bus, *bodies], constraints=constraints, forces=[motors])
        g_w, V_w = w.uk_state(bodies, g0, V0, SPEEDS0)
        state = system.state(g={"bus": g0, **g_w}, V={"bus": V0, **V_w})
        return system, state, law
    raise gmuk.errors.DefinitionError(f"form must be 'internal' or 'uk'; got {form!r}")


def histories(traj: gmuk.Trajectory, law: gmuk.MRPFeedback) -> dict[str, Any]:
    """σ_BN (k, 3), ω_BN_B (k, 3), wheel speeds Ω (k, 3) (rad/s), motor torques (k, 3)
    (N·m, after the limits) and the inertial angular momentum H_N (k, 3) of a run in either
    form."""
    w = law.wheels
    bus = traj.body("bus")
    R, omega = bus.R, bus.omega
    if traj.z.shape[1]:  # internal-momentum form: h in the controller's states
        h = traj.z[:, : len(w)]
        speeds = h / w.J_s - omega @ w.G
    else:  # UK form: the wheel bodies' spin relative to the bus
        speeds = np.empty((len(traj.t), len(w)))
        for i in range(len(w)):
            wheel = traj.body(f"bus.wheel{i}")
            axis_B = np.einsum("kji,kj->ki", R, wheel.R[:, :, 0])
            speeds[:, i] = wheel.omega[:, 0] - np.einsum("ki,ki->k", axis_B, omega)
        h = w.J_s * (omega @ w.G + speeds)
    torques = np.empty_like(speeds)
    for k in range(len(traj.t)):
        u_cmd = law.command(R[k], omega[k], h[k])[2]
        torques[k] = [w[i].spin_torque(u_cmd[i], speeds[k, i]) for i in range(len(w))]
    H_B = omega @ INERTIA_B.T + (speeds * w.J_s) @ w.G.T
    return {
        "sigma_BN": mrp_from_R_NB(R),
        "omega_BN_B": omega,
        "wheel_speeds": speeds,
        "motor_torques": torques,
        "H_N": np.einsum("kij,kj->ki", R, H_B),
    }


def run(duration: float = 600.0, form: str = "internal") -> ScenarioResult:
    """Fly the slew for ``duration`` seconds in the given wheel form."""
    system, state, law = build(form)
    t_eval = np.linspace(0.0, duration, max(int(np.ceil(duration)), 1) + 1)
    traj = system.simulate(state, (0.0, duration), rtol=RTOL, atol=ATOL, t_eval=t_eval)
    hist = histories(traj, law)
    H = hist["H_N"]
    summary = {
        "form": form,
        "duration_s": float(duration),
        "sigma_BN": hist["sigma_BN"][-1].tolist(),
        "omega_BN_B": hist["omega_BN_B"][-1].tolist(),
        "wheel_speeds": hist["wheel_speeds"][-1].tolist(),
        "wheel_speeds_rpm": (hist["wheel_speeds"][-1] / RPM).tolist(),
        "max_abs_motor_torque_Nm": float(np.abs(hist["motor_torques"]).max()),
        "momentum_rel_change": float(np.abs(H - H[0]).max() / np.linalg.norm(H[0])),
        "rtol": RTOL,
        "atol": ATOL,
    }
    return ScenarioResult(NAME, {NAME: traj}, NAME, summary, {"histories": hist, "law": law})


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Attitude, rates, wheel speeds and motor torques against time."""
    out.mkdir(parents=True, exist_ok=True)
    t = result.trajectories[result.primary].t
    hist = result.data["histories"]
    label = f"rw-pointing ({result.summary['form']} form)"
    series = [
        ("attitude", "σ_BN", hist["sigma_BN"], 1.0, "σ_BN"),
        ("rates", "ω_BN (rad/s)", hist["omega_BN_B"], 1.0, "ω"),
        ("wheel_speeds", "Ω (rpm)", hist["wheel_speeds"], 1.0 / RPM, "Ω"),
        ("motor_torques", "u (N·m)", hist["motor_torques"], 1.0, "u"),
    ]
    paths: list[Path] = []
    for key, ylabel, y, scale, sym in series:
        lines = [(f"{sym}{i + 1}", y[:, i] * scale, {"color": f"C{i}"}) for i in range(3)]
        paths += plotting.plot_panels(t, [(ylabel, lines)], f"{label}: {key}", out / key, formats)
    return paths


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("duration", positive_float, 600.0, "simulated time (s)"),
        Option(
            "form",
            str,
            "internal",
            "wheel form: internal (momentum states) or uk (wheel bodies on constraints)",
            choices=("internal", "uk"),
        ),
    ),
)
