"""FCCL: the fully constrained closed loop from a disturbed state (McCann 2020, Section 5.1).

The FCEI orbit (a = 4000 km, e = 0.2, i = 35°, Ω = ω = 0; :func:`gmuk.orbits.fcei_orbit`
with the Chapter 4 μ) and its modified-LVLH reference, but the spacecraft starts *off* the
constraint, at the disturbed state printed in Section 5.1. The Udwadia–Kalaba solve
(:class:`gmuk.ConfigurationTracking`, Eq. 67 rows, no Baumgarte terms) computes its wrench
from the modeled dynamics (the uniform-field gravity gradient, Eq. 23) at the actual state;
the :class:`gmuk.control.MorseLyapunovController` (the corrected law, default gains) adds its
own wrench and drives the spacecraft onto the nominal motion. A second run starts on the
constraint (the reference's own state at periselene) without a controller: the *nominal*,
drawn dashed in the figures as in the thesis (kept on the constraint against integration
drift by Baumgarte terms that vanish there; see :func:`simulate_nominal`).

Initial state
-------------
Position r = (3.201e6, 163.150, 4997.447) m in N and body twist
V = (0.05, 0.07, 0.01044, −569.501, −1178.17, 328.89840) (rad/s, m/s), as printed. The
printed rotation block ::

    [[-0.88728, 0.35421, -0.29541], [-0.25042, -0.90782, -0.33637], [-0.38733, -0.22448, 0.89420]]

is *not* a rotation to its printed precision (largest entry of RᵀR − I: 6.85e-6,
det R = 0.99999957), so gmuk uses the nearest rotation in the Frobenius norm, U Vᵀ of its
singular-value decomposition (:func:`initial_pose`); no entry changes by more than 3.9e-6.
Against the nominal at t = 0 the position error is 5.10 km, the attitude error 0.569 rad, the
angular-velocity error 0.087 rad/s and the inertial velocity error 13.2 m/s.

Span
----
With the default gains (integral term off) the slow translational error decays as
e^{−(κ/k₁₂ + k₂₂)t} ≈ e^{−2.1e-4 t}: the 5.1 km fall below 1 m at 4.15e4 s (1.83 orbits), and
the default span, :data:`ORBITS` = 2, covers that. The attitude error falls below 1e-3 rad
after 21 s. With the integral gain k_I = 1e-8 s⁻² (``k_integral=1e-8``) the slow dynamics
``ψ̇ ≈ −(k₂₂ + κ/k₁₂) ψ − k_I z``, ``ż = ψ`` are a (nearly) critically damped pair at
λ ≈ 1e-4 s⁻¹; from z(0) = 0 the position error behaves as (1 − λt) e^{−λt}: it passes close to
zero (14 m) near t = 1/λ ≈ 1e4 s, overshoots to ≈ 660 m near 2e4 s and stays above 1 m until
1.165e5 s (5.13 orbits).

Integration
-----------
The closed loop has fast stable modes (rates ≈ 1 s⁻¹: k₂₁ = 1.1 s⁻¹ and k₁₂ ≈ 1 s⁻¹) beside
the slow translational ones, so explicit steps are limited by stability to ≈ 2.5 s whatever
the tolerance. DOPRI5 at rtol = atol = 1e-8 (:data:`RTOL`) with steps ≤ 2 s
(:data:`MAX_STEP`) is the cheapest setting measured that keeps the step control off the edge
of the stability interval: without the bound the steps oscillate there (191 rejected steps in
the first 5000 s) and the Morse–Lyapunov torque after the transient carries 1e-3 N·m of noise;
with it, none are rejected and the noise is 6e-5 N·m (3.8e-6 N·m at rtol 1e-10 for 1.5 times
the evaluations). Output times (:func:`time_grid`): 11 points on [0, 1] s, then geometric to
the end, merged with :data:`SAMPLES_PER_ORBIT` uniform points per orbit; DOPRI5 steps exactly
onto them. The nominal runs at the Chapter 4 tolerances (DOP853, rtol 3e-15, atol 1e-12).

With k_I = 1e-8 the attitude error levels off at 6.1e-9 rad, at every tolerance from 1e-8 to
1e-11: not integration error but the integral term's rotational mode, ψ_ω ≈ −(k_I/k₂₁) z_ω,
which decays at k_I/k₂₁ ≈ 9e-9 s⁻¹; without the integral term it ends at 4.5e-13 rad.

Outputs
-------
``run`` returns the trajectories ``"fccl"`` (primary) and ``"nominal"`` — with
``baumgarte=True`` also one per :data:`BAUMGARTE_DESIGNS` entry, ``"baumgarte_<label>"`` —
and a summary (:func:`summarize`). ``figures`` writes Figures 5.1–5.10 (``fig5_01_position``
… ``fig5_10_rotational_control_error``) on a time axis linear on [0, 1] s and logarithmic
beyond, the Lyapunov function, and with Baumgarte runs the error norms of every run.

Quantities
----------
* UK wrench: the constraint wrench ``M ν̇_c`` [L; f] of the run (body frame, N·m and N).
* M–L wrench u: the controller's wrench [u_L; u_f] (body frame).
* Corrective wrench Δ: the run's total control wrench (UK + M–L) minus the nominal UK wrench
  at the same time, the latter rotated into the run's body frame (``E_Rᵀ``, E_R = R_nᵀR) so
  that both are components of the same physical vector (:func:`corrective_wrench`). It is
  what the disturbed start costs beyond holding the nominal; for a UK + Baumgarte run
  (no controller) it is the UK wrench minus the nominal one.
* Settling time of an error: the earliest output time from which on the error stays at or
  below its threshold (:data:`ATTITUDE_THRESHOLD`, :data:`POSITION_THRESHOLD`); ``None``
  when the last output is above it (:func:`settling_time`).
* Efforts: ``∫‖·‖ dt`` by the trapezoid rule over the outputs (N·s, N·m·s).

Command line
------------
``gmuk run fccl`` (two orbits, ``--orbits``; ``--k-integral 1e-8`` for the loop with an
integral term), ``gmuk run fccl --baumgarte true`` to add the
UK + Baumgarte runs, ``gmuk run fccl --help``.

References
----------
McCann (2020), Section 5.1, Eqs. (81)–(89), Figures 5.1–5.10; the errata (``docs/errata.rst``,
"Section 5.1 controller") and :mod:`gmuk.control.morse_lyapunov` for the corrected law.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.constraints.tracking import tracking_errors
from gmuk.control import MorseLyapunovController
from gmuk.lie import so3
from gmuk.orbits import KeplerOrbit, LVLHReference, fcei_orbit
from gmuk.scenarios import (
    Option,
    Scenario,
    ScenarioResult,
    boolean,
    non_negative_float,
    positive_float,
)
from gmuk.scenarios import _lvlh as common
from gmuk.trajectory import Trajectory

__all__ = [
    "ATTITUDE_THRESHOLD",
    "BAUMGARTE_DESIGNS",
    "DESCRIPTION",
    "K_INTEGRAL",
    "MAX_STEP",
    "NAME",
    "NOMINAL_BAUMGARTE",
    "ORBITS",
    "POSITION_THRESHOLD",
    "PRINTED_POSITION",
    "PRINTED_ROTATION",
    "PRINTED_TWIST",
    "RTOL",
    "SCENARIO",
    "build",
    "compare_baumgarte",
    "corrective_wrench",
    "euler_degrees",
    "figures",
    "initial_pose",
    "integral_norm",
    "non_negative_float",
    "run",
    "settling_time",
    "simulate_nominal",
    "summarize",
    "time_grid",
    "tracking_norms",
]

NAME = "fccl"
DESCRIPTION = (
    "Ch. 5: FCEI from the disturbed state of §5.1, UK + Morse-Lyapunov control (Figs 5.1-5.10)"
)
BODY = "spacecraft"

#: The disturbed initial state of Section 5.1 as printed: rotation block of g (not a rotation
#: to its printed precision; see :func:`initial_pose`), position (m, N), body twist [ω; v]
#: (rad/s, m/s).
PRINTED_ROTATION = np.array(
    [
        [-0.88728, 0.35421, -0.29541],
        [-0.25042, -0.90782, -0.33637],
        [-0.38733, -0.22448, 0.89420],
    ]
)
PRINTED_POSITION = np.array([3.201e6, 163.150, 4997.447])
PRINTED_TWIST = np.array([0.05, 0.07, 0.01044, -5.69501e2, -1.17817e3, 328.89840])

#: Closed-loop integration: method and tolerance (rtol = atol); see the module docstring.
METHOD = "DOPRI5"
RTOL = 1e-8
#: Largest closed-loop step (s): inside DOPRI5's stability interval for the fast modes, so
#: that the step-size control does not oscillate at its edge (module docstring).
MAX_STEP = 2.0
#: Default span, in periods of the FCEI orbit.
ORBITS = 2.0
#: Stabilisation of the nominal run against integration drift (:func:`simulate_nominal`):
#: critically damped at ω_n = 1e-3 rad/s, well above the orbit rate (≤ 4.2e-4 rad/s).
NOMINAL_BAUMGARTE = gmuk.Baumgarte.critical(1e-3)
#: The controller's integral gain k_I (1/s²): its default (off).
K_INTEGRAL = 0.0
#: Uniform output points per orbit, beside the geometric ones of the transient.
SAMPLES_PER_ORBIT = 361
#: Geometric output points from 1 s to the end (the transient is resolved to ≈ 2 %).
GEOMETRIC_SAMPLES = 600
#: Settling thresholds: attitude error (rad) and position error (m).
ATTITUDE_THRESHOLD = 1e-3
POSITION_THRESHOLD = 1.0
#: UK + Baumgarte designs compared with the controller: (label, ω_n of the three rotation
#: rows, ω_n of the three translation rows), rad/s, critically damped (α = 2ω_n, β = ω_n²).
#: "matched" settles attitude and position about when the controller (default gains) does,
#: "slow" about when the controller with k_I = 1e-8 does; "orbit_rate" has a translational
#: ω_n near the orbit rate (1.9e-4 to 4.2e-4 rad/s), where the rotating-frame coupling of the
#: body-frame errors keeps the in-plane position error from converging (see
#: docs/scenarios/chapter5.rst).
BAUMGARTE_DESIGNS: tuple[tuple[str, float, float], ...] = (
    ("matched", 0.43, 6e-4),
    ("slow", 0.43, 4e-4),
    ("orbit_rate", 0.43, 3e-4),
)


def initial_pose() -> FloatArray:
    """The disturbed pose g (4, 4) of Section 5.1: the printed position and the rotation
    nearest (Frobenius norm) to the printed block, U Vᵀ of its SVD."""
    U, _, Vt = np.linalg.svd(PRINTED_ROTATION)
    R = U @ Vt
    if np.linalg.det(R) < 0:  # not the case here; kept for a block of the other handedness
        R = U @ np.diag([1.0, 1.0, -1.0]) @ Vt
    g = np.eye(4)
    g[:3, :3] = R
    g[:3, 3] = PRINTED_POSITION
    return g


def time_grid(orbit: KeplerOrbit, orbits: float) -> FloatArray:
    """Output times (s): 0, 0.1, …, 1 s, geometric from 1 s to the end, and
    :data:`SAMPLES_PER_ORBIT` uniform points per orbit, merged (all within the span)."""
    end = orbits * orbit.period
    n = common.output_count(orbits, SAMPLES_PER_ORBIT) + 1
    parts = [np.linspace(0.0, end, n), np.linspace(0.0, min(1.0, end), 11)]
    if end > 1.0:
        parts.append(np.geomspace(1.0, end, GEOMETRIC_SAMPLES))
    t = np.unique(np.concatenate(parts))
    # drop points closer than 1 ms to their predecessor (coincident up to round-off)
    keep = np.concatenate([[True], np.diff(t) > 1e-3])
    t = t[keep]
    t[-1] = end
    return t


def build(
    *,
    controller: bool = True,
    baumgarte: gmuk.Baumgarte | None = None,
    k_integral: float = K_INTEGRAL,
) -> tuple[gmuk.System, MorseLyapunovController | None, KeplerOrbit]:
    """The FCCL System: the spacecraft on the FCEI reference with the gravity gradient modeled,
    with or without the controller (default gains but the integral gain ``k_integral``,
    1/s²) and Baumgarte terms."""
    orbit = fcei_orbit(common.MU)
    sc = common.spacecraft(BODY)
    ref = LVLHReference(orbit)
    ctl = MorseLyapunovController(sc, ref, k_integral=k_integral) if controller else None
    system = gmuk.System(
        [sc],
        [gmuk.ConfigurationTracking(sc, ref, baumgarte=baumgarte)],
        [gmuk.GravityGradient(orbit.mu)],
        [ctl] if ctl is not None else [],
    )
    return system, ctl, orbit


def _simulate_disturbed(
    system: gmuk.System, t: FloatArray, rtol: float, max_step: float = np.inf
) -> Trajectory:
    state = system.state(g={BODY: initial_pose()}, V={BODY: PRINTED_TWIST})
    return system.simulate(
        state,
        (0.0, float(t[-1])),
        t_eval=t,
        rtol=rtol,
        atol=rtol,
        method=METHOD,
        max_step=max_step,
    )


def simulate_nominal(orbit: KeplerOrbit, t: FloatArray) -> Trajectory:
    """The nominal: the spacecraft starting on the constraint, UK only (no controller), at the
    Chapter 4 tolerances, sampled at ``t`` (s).

    The Eq. 67 rows alone do not hold a run on the constraint for long: integration error
    grows by ≈ 10³ per orbit (attitude error 4.6e-14 rad after one orbit, 2.6e-11 after two,
    2.5 rad after six; measured with :func:`time_grid`). Baumgarte terms
    (:data:`NOMINAL_BAUMGARTE`) vanish on the constraint, so they leave the nominal motion
    and its UK wrench unchanged while damping that drift: over six orbits the run then stays
    within 3e-14 rad and 1e-7 m of the reference, and its UK wrench within 1e-15 N·m and
    1e-9 N of the wrench evaluated on the reference states.
    """
    system, _, _ = build(controller=False, baumgarte=NOMINAL_BAUMGARTE)
    r0 = LVLHReference(orbit).evaluate(0.0)
    state = system.state(g={BODY: r0.g}, V={BODY: r0.V})
    return system.simulate(state, (0.0, float(t[-1])), t_eval=t, rtol=common.RTOL, atol=common.ATOL)


# --- measures ----------------------------------------------------------------------------------


def settling_time(t: FloatArray, error: FloatArray, threshold: float) -> float | None:
    """The earliest output time from which on ``error`` stays ≤ ``threshold`` (same unit);
    ``t[0]`` if it never exceeds it, None if the last output exceeds it."""
    above = np.flatnonzero(np.asarray(error) > threshold)
    if above.size == 0:
        return float(t[0])
    k = int(above[-1]) + 1
    return float(t[k]) if k < len(t) else None


def integral_norm(t: FloatArray, values: FloatArray) -> float:
    """``∫‖values‖ dt`` by the trapezoid rule over the outputs; values (N, k)."""
    n = np.linalg.norm(values, axis=1)
    return float(np.sum(0.5 * (n[1:] + n[:-1]) * np.diff(t)))


def tracking_norms(traj: Trajectory, orbit: KeplerOrbit) -> dict[str, FloatArray]:
    """Errors against the reference at every output time.

    Returns
    -------
    dict
        ``position_m``: ‖r − r_n‖ (m); ``attitude_rad``: rotation angle of R_nᵀR (rad);
        ``velocity_m_s``: ‖ṙ − ṙ_n‖ in N (m/s); ``omega_rad_s``: ‖E_ω‖, the angular velocity
        of R_nᵀR in the body frame (rad/s); ``twist_v_m_s``: ‖E_v‖, the translational part of
        the body twist of g_n⁻¹g (m/s).
    """
    ref = LVLHReference(orbit).evaluate_many(traj.t)
    view = traj.body(BODY)
    i = traj.body_names.index(BODY)
    E = np.array(
        [
            np.concatenate(tracking_errors(traj.g_NB[k, i], traj.V_B[k, i], ref.g[k], ref.V[k]))
            for k in range(len(traj.t))
        ]
    )
    v_n = np.einsum("kij,kj->ki", ref.g[:, :3, :3], ref.V[:, 3:])
    R_err = np.swapaxes(ref.g[:, :3, :3], 1, 2) @ view.R
    return {
        "position_m": np.linalg.norm(view.position - ref.g[:, :3, 3], axis=1),
        "attitude_rad": np.linalg.norm(so3.log(R_err), axis=1),
        "velocity_m_s": np.linalg.norm(view.velocity - v_n, axis=1),
        "omega_rad_s": np.linalg.norm(E[:, 6:9], axis=1),
        "twist_v_m_s": np.linalg.norm(E[:, 9:], axis=1),
    }


def euler_degrees(traj: Trajectory, nominal: Trajectory) -> tuple[FloatArray, FloatArray]:
    """3-2-1 Euler angles (deg) of R_NB of a run and of the nominal, each unwrapped in time,
    the run's shifted by whole turns to start within 180° of the nominal's (no ±180° jumps
    in a figure)."""
    a = np.unwrap(traj.body(BODY).euler("321"), axis=0)
    n = np.unwrap(nominal.body(BODY).euler("321"), axis=0)
    a -= 2.0 * np.pi * np.round((a[0] - n[0]) / (2.0 * np.pi))
    return np.degrees(a), np.degrees(n)


def corrective_wrench(traj: Trajectory, nominal: Trajectory) -> FloatArray:
    """Δ (N, 6) = UK + M–L wrench of ``traj`` minus the nominal UK wrench rotated into the
    run's body frame, [Δ_L; Δ_f] (N·m, N); both sampled at the same times."""
    run, nom = traj.body(BODY), nominal.body(BODY)
    E_Rt = np.swapaxes(run.R, 1, 2) @ nom.R  # Rᵀ R_n: nominal body → run body components
    w_n = nom.constraint_force
    rotated = np.concatenate(
        [
            np.einsum("kij,kj->ki", E_Rt, w_n[:, :3]),
            np.einsum("kij,kj->ki", E_Rt, w_n[:, 3:]),
        ],
        axis=1,
    )
    return np.asarray(run.constraint_force + run.control_force - rotated)


def summarize(
    traj: Trajectory,
    nominal: Trajectory,
    orbit: KeplerOrbit,
    controller: MorseLyapunovController | None = None,
) -> dict[str, Any]:
    """Headline figures of a disturbed run (with or without the controller); see the keys."""
    t = traj.t
    e = tracking_norms(traj, orbit)
    view = traj.body(BODY)
    u = view.control_force
    uk = view.constraint_force
    d = corrective_wrench(traj, nominal)
    u_f, u_L = np.linalg.norm(u[:, 3:], axis=1), np.linalg.norm(u[:, :3], axis=1)
    d_f, d_L = np.linalg.norm(d[:, 3:], axis=1), np.linalg.norm(d[:, :3], axis=1)
    out: dict[str, Any] = {
        "settling_criterion": (
            "earliest output time from which on the error stays <= the threshold"
        ),
        "attitude_threshold_rad": ATTITUDE_THRESHOLD,
        "position_threshold_m": POSITION_THRESHOLD,
        "attitude_settling_time_s": settling_time(t, e["attitude_rad"], ATTITUDE_THRESHOLD),
        "position_settling_time_s": settling_time(t, e["position_m"], POSITION_THRESHOLD),
        "initial_position_error_m": float(e["position_m"][0]),
        "initial_attitude_error_rad": float(e["attitude_rad"][0]),
        "final_position_error_m": float(e["position_m"][-1]),
        "max_position_error_m": float(e["position_m"].max()),
        "final_attitude_error_rad": float(e["attitude_rad"][-1]),
        "max_attitude_error_rad": float(e["attitude_rad"].max()),
        "max_velocity_error_m_s": float(e["velocity_m_s"].max()),
        "final_velocity_error_m_s": float(e["velocity_m_s"][-1]),
        "peak_uk_force_N": float(np.linalg.norm(uk[:, 3:], axis=1).max()),
        "peak_uk_torque_N_m": float(np.linalg.norm(uk[:, :3], axis=1).max()),
        "peak_corrective_force_N": float(d_f.max()),
        "peak_corrective_torque_N_m": float(d_L.max()),
        "final_corrective_force_N": float(d_f[-1]),
        "final_corrective_torque_N_m": float(d_L[-1]),
        "corrective_effort_force_N_s": integral_norm(t, d[:, 3:]),
        "corrective_effort_torque_N_m_s": integral_norm(t, d[:, :3]),
    }
    if controller is not None:
        W, W_dot = controller.lyapunov(traj)
        out |= {
            "peak_control_force_N": float(u_f.max()),
            "peak_control_torque_N_m": float(u_L.max()),
            "final_control_force_N": float(u_f[-1]),
            "final_control_torque_N_m": float(u_L[-1]),
            "control_effort_force_N_s": integral_norm(t, u[:, 3:]),
            "control_effort_torque_N_m_s": integral_norm(t, u[:, :3]),
            "lyapunov_W0": float(W[0]),
            "lyapunov_W_final_over_W0": float(W[-1] / W[0]),
            "max_lyapunov_W_dot": float(W_dot.max()),
            "max_lyapunov_W_increase_over_W0": float(np.diff(W).max() / W[0]),
        }
    out |= {
        "rhs_evaluations": int(traj.stats["n_rhs"]),
        "steps": int(traj.stats["n_steps"]),
    }
    return out


# --- runs --------------------------------------------------------------------------------------


def _baumgarte(omega_rotation: float, omega_translation: float) -> gmuk.Baumgarte:
    w = np.repeat([omega_rotation, omega_translation], 3)
    return gmuk.Baumgarte(alpha=2.0 * w, beta=w**2)


def compare_baumgarte(
    orbits: float = ORBITS,
    designs: Sequence[tuple[str, float, float]] = BAUMGARTE_DESIGNS,
    rtol: float = RTOL,
    *,
    nominal: Trajectory | None = None,
) -> tuple[dict[str, Trajectory], dict[str, dict[str, Any]]]:
    """UK + Baumgarte stabilisation alone (no controller) from the disturbed start.

    Parameters
    ----------
    orbits : float
        Span, in periods of the FCEI orbit.
    designs : sequence of (label, ω_rotation, ω_translation)
        Critically damped gains per design (rad/s): α = 2ω_n, β = ω_n² on the three rotation
        and the three translation rows of :class:`gmuk.ConfigurationTracking`.
    rtol : float
        rtol = atol of the DOPRI5 runs.
    nominal : Trajectory, optional
        The nominal sampled at :func:`time_grid` (simulated when not given).

    Returns
    -------
    trajectories : dict
        ``"baumgarte_<label>"`` → Trajectory.
    summaries : dict
        label → :func:`summarize` of that run, plus ``omega_rotation_rad_s`` and
        ``omega_translation_rad_s``.
    """
    orbit = fcei_orbit(common.MU)
    t = time_grid(orbit, orbits)
    nominal = simulate_nominal(orbit, t) if nominal is None else nominal
    trajs: dict[str, Trajectory] = {}
    rows: dict[str, dict[str, Any]] = {}
    for label, w_rot, w_tr in designs:
        system, _, _ = build(controller=False, baumgarte=_baumgarte(w_rot, w_tr))
        traj = _simulate_disturbed(system, t, rtol)
        trajs[f"baumgarte_{label}"] = traj
        rows[label] = {
            "omega_rotation_rad_s": float(w_rot),
            "omega_translation_rad_s": float(w_tr),
            **summarize(traj, nominal, orbit),
        }
    return trajs, rows


#: Keys of a Baumgarte run's summary copied, prefixed, into the scenario's summary.
_BAUMGARTE_KEYS = (
    "omega_rotation_rad_s",
    "omega_translation_rad_s",
    "attitude_settling_time_s",
    "position_settling_time_s",
    "final_position_error_m",
    "max_position_error_m",
    "final_attitude_error_rad",
    "peak_corrective_force_N",
    "peak_corrective_torque_N_m",
    "corrective_effort_force_N_s",
    "corrective_effort_torque_N_m_s",
    "rhs_evaluations",
)


def run(
    orbits: float = ORBITS,
    baumgarte: bool = False,
    rtol: float = RTOL,
    k_integral: float = K_INTEGRAL,
) -> ScenarioResult:
    """Simulate the closed loop and the nominal over ``orbits`` orbits from periselene.

    Parameters
    ----------
    orbits : float
        Span, in periods of the FCEI orbit (22 696 s); two by default (with the default
        gains the position error stays below 1 m from 1.83 orbits on; module docstring).
    baumgarte : bool
        Also run the UK + Baumgarte designs of :data:`BAUMGARTE_DESIGNS` (no controller)
        and add their figures to the summary as ``baumgarte_<label>_<key>``.
    rtol : float
        rtol = atol of the closed-loop DOPRI5 runs.
    k_integral : float
        The controller's integral gain k_I (1/s², ≥ 0); default its own, 0 (off).
    """
    system, ctl, orbit = build(k_integral=k_integral)
    assert ctl is not None
    t = time_grid(orbit, orbits)
    traj = _simulate_disturbed(system, t, rtol, MAX_STEP)
    nominal = simulate_nominal(orbit, t)
    summary = summarize(traj, nominal, orbit, ctl)
    summary["k_integral_1_s2"] = ctl.k_integral
    summary["nominal_max_position_error_m"] = float(
        tracking_norms(nominal, orbit)["position_m"].max()
    )
    trajs = {NAME: traj, "nominal": nominal}
    if baumgarte:
        extra, rows = compare_baumgarte(orbits, rtol=rtol, nominal=nominal)
        trajs |= extra
        for label, row in rows.items():
            summary |= {f"baumgarte_{label}_{k}": row[k] for k in _BAUMGARTE_KEYS}
    return ScenarioResult(NAME, trajs, NAME, summary)


# --- figures -----------------------------------------------------------------------------------


def state_figures(
    fig: Callable[..., None],
    traj: Trajectory,
    nominal: Trajectory,
    norms: dict[str, FloatArray],
    *,
    first: int,
    titles: tuple[str, str, str, str],
    attitude_label: str,
) -> None:
    """Position, velocity, attitude and angular velocity of a run against the nominal, with
    their error norms (:func:`tracking_norms`), as figures ``first`` … ``first + 3`` of
    Chapter 5 through a scenario's ``fig(key, y, y_n, ylabels, title, norm)``."""
    a, n = traj.body(BODY), nominal.body(BODY)
    axes = ("1", "2", "3")
    specs = (
        ("position", a.position / 1e3, n.position / 1e3, "r{} (km)", "‖r − r_n‖ (m)", "position_m"),
        ("velocity", a.velocity, n.velocity, "v{} (m/s)", "‖v − v_n‖ (m/s)", "velocity_m_s"),
        ("attitude", *euler_degrees(traj, nominal), "", attitude_label, "attitude_rad"),
        ("angular_velocity", a.omega, n.omega, "ω{} (rad/s)", "‖E_ω‖ (rad/s)", "omega_rad_s"),
    )
    for k, (stem, y, y_n, unit, norm_label, key) in enumerate(specs):
        ylabels = (
            ["ψ (deg)", "θ (deg)", "φ (deg)"]
            if stem == "attitude"
            else [unit.format(i) for i in axes]
        )
        fig(f"fig5_{first + k:02d}_{stem}", y, y_n, ylabels, titles[k], (norm_label, norms[key]))


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Figures 5.1–5.10, the Lyapunov function and, with Baumgarte runs, the error norms of
    every run (time axis linear on [0, 1] s, logarithmic beyond)."""
    out.mkdir(parents=True, exist_ok=True)
    traj, nominal = result.trajectories[NAME], result.trajectories["nominal"]
    orbit = fcei_orbit(common.MU)
    t = traj.t
    a, n = traj.body(BODY), nominal.body(BODY)
    e = tracking_norms(traj, orbit)
    d = corrective_wrench(traj, nominal)
    axes = ("1", "2", "3")
    paths: list[Path] = []

    def fig(
        key: str,
        y: FloatArray,
        y_n: FloatArray | None,
        ylabels: list[str],
        title: str,
        norm: tuple[str, FloatArray] | None,
    ) -> None:
        paths.extend(
            plotting.plot_against_nominal(
                t,
                y,
                y_n,
                ylabels,
                title,
                out / key,
                formats,
                label="FCCL",
                norm=norm,
                t_scale="symlog",
            )
        )

    state_figures(
        fig,
        traj,
        nominal,
        e,
        first=1,
        titles=(
            "Fig. 5.1 FCCL position in N",
            "Fig. 5.2 FCCL velocity in N",
            "Fig. 5.3 FCCL attitude: 3-2-1 Euler angles of R_NB",
            "Fig. 5.4 FCCL angular velocity, body frame",
        ),
        attitude_label="attitude error (rad)",
    )
    fig(
        "fig5_05_uk_translational_control",
        a.constraint_force[:, 3:],
        n.constraint_force[:, 3:],
        [f"f{i} (N)" for i in axes],
        "Fig. 5.5 FCCL translational control: UK constraint force, body frame",
        None,
    )
    fig(
        "fig5_06_uk_rotational_control",
        a.constraint_force[:, :3],
        n.constraint_force[:, :3],
        [f"L{i} (N·m)" for i in axes],
        "Fig. 5.6 FCCL rotational control: UK constraint torque, body frame",
        None,
    )
    u = a.control_force
    fig(
        "fig5_07_ml_translational_control",
        u[:, 3:],
        None,
        [f"u_f{i} (N)" for i in axes],
        "Fig. 5.7 FCCL translational Morse–Lyapunov control, body frame",
        ("‖u_f‖ (N)", np.linalg.norm(u[:, 3:], axis=1)),
    )
    fig(
        "fig5_08_ml_rotational_control",
        u[:, :3],
        None,
        [f"u_L{i} (N·m)" for i in axes],
        "Fig. 5.8 FCCL rotational Morse–Lyapunov control, body frame",
        ("‖u_L‖ (N·m)", np.linalg.norm(u[:, :3], axis=1)),
    )
    fig(
        "fig5_09_translational_control_error",
        d[:, 3:],
        None,
        [f"Δf{i} (N)" for i in axes],
        "Fig. 5.9 FCCL translational control error: UK + M–L − nominal UK force",
        ("‖Δf‖ (N)", np.linalg.norm(d[:, 3:], axis=1)),
    )
    fig(
        "fig5_10_rotational_control_error",
        d[:, :3],
        None,
        [f"ΔL{i} (N·m)" for i in axes],
        "Fig. 5.10 FCCL rotational control error: UK + M–L − nominal UK torque",
        ("‖ΔL‖ (N·m)", np.linalg.norm(d[:, :3], axis=1)),
    )
    _, ctl, _ = build(k_integral=float(result.summary.get("k_integral_1_s2", K_INTEGRAL)))
    assert ctl is not None
    W, W_dot = ctl.lyapunov(traj)
    paths += plotting.plot_log_lines(
        t,
        [("W / W(0)", W / W[0], {}), ("−Ẇ / W(0) (1/s)", -W_dot / W[0], {"ls": "--"})],
        "W / W(0), −Ẇ / W(0) (1/s)",
        "FCCL Lyapunov function W and its rate (corrected law)",
        out / "fccl_lyapunov",
        formats,
        t_scale="symlog",
    )
    runs = {k: v for k, v in result.trajectories.items() if k.startswith("baumgarte_")}
    if runs:
        for key, unit, title in (
            ("position_m", "position error (m)", "Position error"),
            ("attitude_rad", "attitude error (rad)", "Attitude error"),
        ):
            lines = [("UK + Morse–Lyapunov", e[key], {"color": "k", "lw": 2.0})]
            lines += [
                (
                    f"UK + Baumgarte, {k.removeprefix('baumgarte_')}",
                    tracking_norms(v, orbit)[key],
                    {},
                )
                for k, v in runs.items()
            ]
            paths += plotting.plot_log_lines(
                t,
                lines,
                unit,
                f"{title}: Morse–Lyapunov control vs UK + Baumgarte alone",
                out / f"fccl_baumgarte_{key}",
                formats,
                t_scale="symlog",
            )
    paths += common.orbit_figure(result, BODY, out, formats)
    return paths


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("orbits", positive_float, ORBITS, "span, in periods of the FCEI orbit (22696 s)"),
        Option(
            "baumgarte",
            boolean,
            False,
            "also run UK + Baumgarte stabilisation alone (no controller) for comparison",
        ),
        Option("rtol", positive_float, RTOL, "closed-loop DOPRI5 tolerance, rtol = atol"),
        Option(
            "k_integral",
            non_negative_float,
            K_INTEGRAL,
            "integral gain k_I of the controller (1/s²); 0 removes the integral term",
        ),
    ),
    central_radius=common.CENTRAL_RADIUS,
)
