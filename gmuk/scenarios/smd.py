"""SMD-GT, SMD-LT, SMD-BI: a spring–mass–damper under inequality constraints (McCann 2020,
§6.5.1).

``m ẍ + b ẋ + k x = 0`` with m = 2 kg, b = 5 N·s/m, k = 10 N/m: a :class:`gmuk.PointMass`
moving along the inertial x axis on a :class:`gmuk.LinearSpringDamper` anchored at the
origin, kept by a :class:`gmuk.PlaneBound` on x:

==========  ==============  ==================  =======================================
scenario    inequality      coordinates         initial state (chosen here)
==========  ==============  ==================  =======================================
``smd-gt``  x ≥ 5 m         excess p            x₀ = 8 m, ẋ₀ = 0 (released above)
``smd-lt``  x ≤ 1 m         slack s             x₀ = 0, ẋ₀ = 5 m/s (would reach 1.16 m)
``smd-bi``  1 m ≤ x ≤ 2 m   slack s, excess p   x₀ = 1.5 m, ẋ₀ = 6 m/s (hits 2 m, then 1 m)
==========  ==============  ==================  =======================================

The thesis does not print its initial conditions; these make every bound active during the
run. The slack coordinates have mass 1 kg·m (Gauss's weight of the slack), their initial
values come from the state (``p₀ = √(x₀ − 5)``, ``ṗ₀ = ẋ₀/(2p₀)``, …), and each equality
``x − bound ± w² = 0`` has Baumgarte gains α = 10 s⁻¹, β = 25 s⁻² so that its drift stays
at round-off. Thirty seconds (the span of the thesis's Figure 6.20), DOP853 at rtol = 1e-10,
atol = 1e-12, outputs every 0.01 s.

Steady states
-------------
The analytic ones: GT x → 5 m with the control acceleration k·5/m = 25 m/s² holding it; LT
x → 0 with no control (the bound is inactive at rest); BI x → 1 m with k·1/m = 5 m/s².
LT gets there exponentially. GT and BI, as the thesis formulates them, get there slowly: the
slack has no dynamics of its own, so the contact with the bound is elastic — the mass keeps
bouncing off it, handing its energy to the slack and taking it back, and only the physical
damper, whose rate ``b ẋ² = 4b w² ẇ²`` vanishes at the bound, removes it. The bounce
amplitude decays like t^(−1/2), so x − bound like 1/t. ``--slack-damping C`` adds a damper
``−C ẇ`` on the slack coordinates (:class:`gmuk.SlackDamping`, a choice of slack dynamics the
thesis leaves open in §6.3.3): the contact becomes inelastic and the steady state is reached
exponentially (C = 20 kg·m/s is critical at the GT bound, where μ = 50 N).

Figures
-------
Per run (thesis Figures 6.1–6.6, 6.7–6.12, 6.13–6.19): position with the constraint value
x ∓ w², velocity, control acceleration (the constraint force over m), control effort
∫ abs(u) dt, the multipliers λ, and the KKT conditions of each bound
(:func:`gmuk.kkt.kkt_diagnostics`).

Command line
------------
``gmuk run smd-gt``, ``gmuk run smd-bi --slack-damping 20``, ``gmuk run smd-lt --help``.

References
----------
McCann (2020), §6.3, Eqs. (94)–(97), §6.5.1, Figures 6.1–6.19.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.kkt import KKTDiagnostics, kkt_diagnostics
from gmuk.scenarios import Option, Scenario, ScenarioResult, non_negative_float, positive_float

MASS = 2.0  # kg
DAMPING = 5.0  # N·s/m
STIFFNESS = 10.0  # N/m
BODY = "mass"
RTOL, ATOL = 1e-10, 1e-12
BAUMGARTE = gmuk.Baumgarte(alpha=10.0, beta=25.0)

#: name → (bounds (lower, upper), x₀ (m), ẋ₀ (m/s), thesis figure numbers, description)
CASES: dict[str, tuple[tuple[float | None, float | None], float, float, str, str]] = {
    "smd-gt": ((5.0, None), 8.0, 0.0, "6.1–6.6", "x ≥ 5 m"),
    "smd-lt": ((None, 1.0), 0.0, 5.0, "6.7–6.12", "x ≤ 1 m"),
    "smd-bi": ((1.0, 2.0), 1.5, 6.0, "6.13–6.19", "1 m ≤ x ≤ 2 m"),
}


def steady_state(case: str) -> tuple[float, float]:
    """The analytic steady state (x (m), control acceleration (m/s²)) of a case: the point of
    the feasible interval nearest the spring's rest point, held by k·x/m."""
    (lower, upper), *_ = CASES[case]
    x = min(
        max(0.0, lower if lower is not None else -np.inf), upper if upper is not None else np.inf
    )
    return float(x), STIFFNESS * float(x) / MASS


def build(
    case: str, slack_mass: float = 1.0, slack_damping: float = 0.0
) -> tuple[gmuk.System, gmuk.State]:
    """The System and initial State of ``case`` ("smd-gt", "smd-lt" or "smd-bi")."""
    (lower, upper), x0, v0, *_ = CASES[case]
    mass = gmuk.PointMass(BODY, MASS)
    bound = gmuk.PlaneBound(
        mass,
        [1.0, 0.0, 0.0],
        lower=lower,
        upper=upper,
        slack_mass=slack_mass,
        baumgarte=BAUMGARTE,
        name="x",
    )
    forces: list[gmuk.ForceModel] = [gmuk.LinearSpringDamper(STIFFNESS, DAMPING, bodies=[mass])]
    if slack_damping > 0.0:
        forces.append(gmuk.SlackDamping(slack_damping))
    system = gmuk.System([mass], [bound], forces)
    state = system.state(r={BODY: [x0, 0.0, 0.0]}, v={BODY: [v0, 0.0, 0.0]})
    return system, state


def simulate(
    case: str, duration: float = 30.0, slack_mass: float = 1.0, slack_damping: float = 0.0
) -> tuple[gmuk.System, gmuk.Trajectory]:
    """Run ``case`` for ``duration`` seconds; outputs every 0.01 s."""
    system, state = build(case, slack_mass, slack_damping)
    n = round(duration / 0.01) + 1
    t_eval = np.linspace(0.0, duration, n)
    traj = system.simulate(state, (0.0, duration), t_eval=t_eval, rtol=RTOL, atol=ATOL)
    return system, traj


def control_acceleration(traj: gmuk.Trajectory) -> FloatArray:
    """u = f_c,x / m (m/s²): the constraint force on the mass along x over its mass."""
    return traj.body(BODY).constraint_force[:, 0] / MASS


def control_effort(traj: gmuk.Trajectory) -> FloatArray:
    """∫₀ᵗ abs(u) dt (m/s), trapezoidal over the outputs."""
    u = np.abs(control_acceleration(traj))
    steps = 0.5 * (u[1:] + u[:-1]) * np.diff(traj.t)
    return np.concatenate([[0.0], np.cumsum(steps)])


def summarise(case: str, traj: gmuk.Trajectory, kkt: KKTDiagnostics) -> dict[str, Any]:
    """The summary.json figures of a run."""
    x = traj.r_N[:, 0, 0]
    u = control_acceleration(traj)
    x_ss, u_ss = steady_state(case)
    bounds = kkt.summary()["bounds"]
    return {
        "inequality": CASES[case][4],
        "x0_m": CASES[case][1],
        "v0_m_per_s": CASES[case][2],
        "duration_s": float(traj.t[-1]),
        "x_min": float(x.min()),
        "x_max": float(x.max()),
        "x_final": float(x[-1]),
        "v_final": float(traj.v_N[-1, 0, 0]),
        "control_accel_final": float(u[-1]),
        "control_effort_final": float(control_effort(traj)[-1]),
        "steady_state_x_m": x_ss,
        "steady_state_control_accel": u_ss,
        "primal_violation_max": max(b["primal_violation_max"] for b in bounds.values()),
        "dual_violation_max": max(b["dual_violation_max"] for b in bounds.values()),
        "complementarity_abs_max": max(b["complementarity_abs_max"] for b in bounds.values()),
        "stationarity_max": kkt.summary()["stationarity_max"],
        "n_rhs": int(traj.stats.get("n_rhs", 0)),
    }


def _runner(case: str) -> Any:
    def run(
        duration: float = 30.0, slack_mass: float = 1.0, slack_damping: float = 0.0
    ) -> ScenarioResult:
        system, traj = simulate(case, duration, slack_mass, slack_damping)
        kkt = kkt_diagnostics(system, traj)
        return ScenarioResult(
            case,
            {case: traj},
            case,
            summarise(case, traj, kkt),
            data={"system": system, "kkt": kkt},
        )

    run.__doc__ = f"Simulate {case} ({CASES[case][4]}) for ``duration`` seconds."
    return run


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Position, velocity, control acceleration, control effort, multipliers, KKT."""
    out.mkdir(parents=True, exist_ok=True)
    case = result.name
    traj = result.trajectories[result.primary]
    kkt: KKTDiagnostics = result.data["kkt"]
    label = f"{case.upper()} ({CASES[case][4]}), thesis Figs. {CASES[case][3]}"
    t = traj.t
    x = traj.r_N[:, 0, 0]
    paths: list[Path] = []
    constraint_lines = []
    for k, b in enumerate(kkt.inequalities.values()):
        sign = 1.0 if b.side == "upper" else -1.0
        constraint_lines.append(
            (
                f"x {'+' if sign > 0 else '−'} w² ({b.side} bound {b.bound:g} m)",
                x + sign * b.slack**2,
                {"color": f"C{k + 1}", "linestyle": "--"},
            )
        )
    paths += plotting.plot_panels(
        t,
        [("x (m)", [("position x", x, {"color": "C0"}), *constraint_lines])],
        f"{label}: position and constraint value",
        out / "position",
        formats,
    )
    panels: list[tuple[str, str, FloatArray]] = [
        ("velocity", "ẋ (m/s)", traj.v_N[:, 0, 0]),
        ("control", "u (m/s²)", control_acceleration(traj)),
        ("effort", "∫|u| dt (m/s)", control_effort(traj)),
    ]
    for key, ylabel, y in panels:
        paths += plotting.plot_panels(
            t, [(ylabel, [(key, y, {"color": "C0"})])], f"{label}: {key}", out / key, formats
        )
    lines = [
        (f"μ of {b.side} bound ({b.multiplier_unit})", b.mu, {"color": f"C{k}"})
        for k, b in enumerate(kkt.inequalities.values())
    ]
    paths += plotting.plot_panels(
        t, [("μ (N)", lines)], f"{label}: KKT multipliers", out / "multipliers", formats
    )
    for b in kkt.inequalities.values():
        paths += plotting.plot_kkt(b, out / f"kkt_{b.side}", formats)
    return paths


_OPTIONS = (
    Option("duration", positive_float, 30.0, "simulated time (s)"),
    Option("slack_mass", positive_float, 1.0, "Gauss's weight of each slack coordinate (kg·m)"),
    Option(
        "slack_damping",
        non_negative_float,
        0.0,
        "viscous damping of the slack coordinates (kg·m/s); 0 is the thesis's formulation",
    ),
)


def _scenario(case: str) -> Scenario:
    return Scenario(
        case,
        f"spring–mass–damper kept at {CASES[case][4]} by slack/excess variables (§6.5.1)",
        _runner(case),
        figures,
        options=_OPTIONS,
    )


GT = _scenario("smd-gt")
LT = _scenario("smd-lt")
BI = _scenario("smd-bi")
