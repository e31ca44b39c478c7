"""lunar-rcs: the thesis's spacecraft tracking its lunar reference on reaction-control
thrusters instead of the ideal wrench, through the Moon's shadow (issue #29, item 7).

Setup
-----
The spacecraft of Chapters 3–5 (the Lunar Module's mass properties, 7063 kg) on the FCEI
orbit (a = 4000 km, e = 0.2, i = 35°, Ω = ω = 0, axes ICRF-aligned, Moon-centred), with the
modified-LVLH reference of :mod:`gmuk.scenarios.fccl`. It starts near the reference at
periselene: 6.16 m off in position, 0.02, −0.01, 0.01 m/s off in inertial velocity, rotated
by the rotation vector (1°, −1.5°, 0.5°) (0.0327 rad) in the body frame and off by
(1, −0.5, 0.2) mrad/s in inertial angular velocity.

The command is FCCL's: at the start of each control period (0.5 s) the wrench that the
Udwadia–Kalaba solve of the tracking constraint (:class:`gmuk.ConfigurationTracking`, the
gravity gradient modeled) and the Morse–Lyapunov law (default gains) would apply — the
*ideal* wrench of Section 5.1 — evaluated at the current state. Twelve thrusters in six pure
couples (:func:`gmuk.actuators.couple_thrusters`: 2 m arms, 445 N each, like the Apollo LM's
RCS; I_sp = 290 s, minimum impulse bit F_max × 14 ms, on-time quantum 2 ms) deliver it
(:meth:`~gmuk.actuators.ThrusterSet.allocate`, then pulse-width modulation;
:func:`gmuk.actuators.simulate_pulsed`). The plant feels only the gravity gradient of the
point-mass Moon (Eq. 23) and the thrust, with the mass the thrusters spend
(:class:`gmuk.actuators.Thrusters`).

At the epoch 2027-11-01T00:00:00 UTC (t = 0 at periselene) the orbit enters the Moon's umbra
about 230 s later: an :class:`gmuk.environment.EclipseEvent` (recorded, not terminal) marks
the entry, with the Sun and Moon from the ERFA series (:mod:`gmuk.environment.ephemeris`).

Summary (``summary.json``): the eclipse entry time (s), the final attitude and position
errors from the reference (rad, m), the propellant spent (kg), the number of firings, and the
limit checks: every on-time a whole number of quanta, no firing below the minimum impulse
bit, every thrust 0 or F_max.

Figures: attitude and position errors (log scale, eclipse entry marked), the thrusters'
on-times per period, and the spacecraft's mass.

Command line: ``gmuk run lunar-rcs``, ``gmuk run lunar-rcs --duration 60 --period 0.25``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.actuators import Thrusters, couple_thrusters, simulate_pulsed
from gmuk.environment import EclipseEvent, Epoch
from gmuk.lie import so3
from gmuk.orbits import LVLHReference
from gmuk.scenarios import Option, Scenario, ScenarioResult, _lvlh, fccl, positive_float

NAME = "lunar-rcs"
DESCRIPTION = "the thesis's spacecraft tracking its lunar reference on RCS thrusters (eclipse)"

BODY = "spacecraft"
EPOCH = "2027-11-01T00:00:00"
ARM = 2.0
MAX_THRUST = 445.0
ISP = 290.0
ON_TIME_QUANTUM = 0.002
MIN_ON_TIME = 0.014  # s: the minimum impulse bit is F_max × 14 ms
PROPELLANT = 500.0
POSITION_OFFSET = np.array([5.0, -3.0, 2.0])
VELOCITY_OFFSET = np.array([0.02, -0.01, 0.01])
ROTATION_OFFSET = np.deg2rad([1.0, -1.5, 0.5])
RATE_OFFSET = np.array([1e-3, -5e-4, 2e-4])
RTOL = ATOL = 1e-9


def build(max_thrust: float = MAX_THRUST) -> dict[str, Any]:
    """The plant (gravity gradient and thrusters), the FCCL command System, the reference,
    the thrusters' controller and the initial state."""
    command, _, orbit = fccl.build()
    reference = LVLHReference(orbit)
    sc = _lvlh.spacecraft(BODY)
    thrusters = Thrusters(
        sc,
        couple_thrusters(
            ARM,
            max_thrust,
            ISP,
            min_impulse_bit=max_thrust * MIN_ON_TIME,
            on_time_quantum=ON_TIME_QUANTUM,
        ),
        dry_mass=sc.mass - PROPELLANT,
    )
    plant = gmuk.System([sc], forces=[gmuk.GravityGradient(orbit.mu)], controllers=[thrusters])
    r0 = reference.evaluate(0.0)
    g = r0.g.copy()
    g[:3, :3] = r0.g[:3, :3] @ Rotation.from_rotvec(ROTATION_OFFSET).as_matrix()
    g[:3, 3] += POSITION_OFFSET
    R_ref = r0.g[:3, :3]
    omega_N = R_ref @ r0.V[:3] + RATE_OFFSET
    v_N = R_ref @ r0.V[3:] + VELOCITY_OFFSET
    V = np.r_[g[:3, :3].T @ omega_N, g[:3, :3].T @ v_N]
    state = plant.state({BODY: g}, {BODY: V})
    return {
        "plant": plant,
        "command": command,
        "reference": reference,
        "thrusters": thrusters,
        "state": state,
    }


def ideal_wrench(command: gmuk.System) -> Any:
    """The law: FCCL's ideal wrench (UK constraint wrench plus Morse–Lyapunov wrench, N·m
    and N, body frame) at the plant's pose and twist."""
    z = np.zeros(command.layout.n_control)  # the law's integral term is off (k_I = 0)

    def law(t: float, state: gmuk.State, mass: float) -> FloatArray:
        s = command.state({BODY: state.pose(BODY)}, {BODY: state.twist(BODY)}, z=z, t=t)
        acc = command.accelerations(s)
        return np.asarray(acc.constraint_force + acc.control_force)

    return law


def errors(traj: gmuk.Trajectory, reference: LVLHReference) -> tuple[FloatArray, FloatArray]:
    """Attitude error ‖log(R_refᵀ R)‖ (rad) and position error (m) at each output."""
    ref = reference.evaluate_many(traj.t)
    R, r = traj.g_NB[:, 0, :3, :3], traj.g_NB[:, 0, :3, 3]
    rot = np.linalg.norm(so3.log(np.einsum("kji,kjl->kil", ref.g[:, :3, :3], R)), axis=-1)
    return rot, np.linalg.norm(r - ref.g[:, :3, 3], axis=-1)


def run(
    duration: float = 300.0, period: float = 0.5, max_thrust: float = MAX_THRUST
) -> ScenarioResult:
    """Fly ``duration`` seconds at control period ``period`` (s) with thrusters of
    ``max_thrust`` (N)."""
    parts = build(max_thrust)
    thrusters: Thrusters = parts["thrusters"]
    eclipse = EclipseEvent(BODY, Epoch.from_iso(EPOCH), "moon", "umbra", centre="moon")
    t_eval = np.linspace(0.0, duration, int(np.ceil(duration / 0.5)) + 1)
    traj = simulate_pulsed(
        parts["plant"],
        parts["state"],
        (0.0, duration),
        thrusters,
        ideal_wrench(parts["command"]),
        period,
        t_eval=t_eval,
        events=[eclipse],
        rtol=RTOL,
        atol=ATOL,
    )
    rot, pos = errors(traj, parts["reference"])
    firings = traj.stats["firings"]
    on = np.array(firings["on_times"])
    ts = thrusters.thrusters
    quanta = on / ts.on_time_quantum
    entries = [e.t for e in traj.events if e.name == eclipse.name]
    summary = {
        "duration_s": float(duration),
        "period_s": float(period),
        "epoch_utc": EPOCH,
        "eclipse_entry_s": entries[0] if entries else None,
        "attitude_error_initial_rad": float(rot[0]),
        "attitude_error_final_rad": float(rot[-1]),
        "position_error_initial_m": float(pos[0]),
        "position_error_final_m": float(pos[-1]),
        "propellant_kg": float(traj.stats["propellant"]),
        "firings": int(np.count_nonzero(on)),
        "largest_commanded_force_N": float(np.abs(np.array(firings["commanded"])[:, 3:]).max()),
        "largest_commanded_torque_Nm": float(np.abs(np.array(firings["commanded"])[:, :3]).max()),
        "on_times_whole_quanta": bool(np.all(np.abs(quanta - np.round(quanta)) < 1e-9)),
        "no_firing_below_minimum_impulse_bit": bool(
            np.all((on == 0.0) | (ts.max_thrust * on >= ts.min_impulse_bit - 1e-12))
        ),
        "thrusts_all_or_nothing": bool(set(np.unique(traj.z[:, 1:])) <= {0.0, 1.0}),
        "rtol": RTOL,
        "atol": ATOL,
    }
    data = {"attitude_error": rot, "position_error": pos, "firings": firings, "thrusters": ts}
    return ScenarioResult(NAME, {NAME: traj}, NAME, summary, data)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Tracking errors and mass, and the thrusters' on-times, against time."""
    plt = plotting._pyplot()
    out.mkdir(parents=True, exist_ok=True)
    traj = result.trajectories[result.primary]
    entry = result.summary["eclipse_entry_s"]
    period = result.summary["period_s"]

    def mark(ax: Any, color: str = "k") -> None:
        if entry is not None:
            ax.axvline(entry, color=color, ls="--", lw=1.0, label="umbra entry")

    fig, axes = plt.subplots(3, 1, figsize=(7.5, 7.0), sharex=True, layout="constrained")
    for ax, key, label in (
        (axes[0], "attitude_error", "attitude error ‖log R_refᵀR‖ (rad)"),
        (axes[1], "position_error", "position error ‖r − r_ref‖ (m)"),
    ):
        ax.semilogy(traj.t, result.data[key], lw=1.2)
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        mark(ax)
    axes[0].legend(loc="best", fontsize=8)
    axes[2].plot(traj.t, traj.z[:, 0], lw=1.2)
    axes[2].set_ylabel("mass (kg)")
    axes[2].set_xlabel("t (s)")
    axes[2].grid(True, alpha=0.3)
    mark(axes[2])
    fig.suptitle("lunar-rcs: FCCL's command on 12 RCS thrusters")
    paths = plotting._save(plt, fig, out / "tracking", formats)

    t_k = np.array(result.data["firings"]["t"])
    on = np.array(result.data["firings"]["on_times"])
    fig, ax = plt.subplots(figsize=(8.0, 3.8), layout="constrained")
    k, i = np.nonzero(on)
    dots = ax.scatter(
        t_k[k],
        i,
        c=1e3 * on[k, i],
        s=14,
        marker="|",
        cmap="viridis",
        norm=plt.matplotlib.colors.LogNorm(),
    )
    mark(ax)
    ax.set_yticks(range(on.shape[1]), [t.name for t in result.data["thrusters"]])
    ax.set_xlabel("t (s)")
    ax.set_ylabel("thruster")
    ax.set_title(f"firings: one tick per period a thruster fires (Δt = {period:g} s)")
    fig.colorbar(dots, ax=ax, label="on-time (ms)")
    return paths + plotting._save(plt, fig, out / "on_times", formats)


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("duration", positive_float, 300.0, "simulated time (s)"),
        Option("period", positive_float, 0.5, "control period (s)"),
        Option("max_thrust", positive_float, MAX_THRUST, "thrust of each of the 12 thrusters (N)"),
    ),
)
