"""SMD-COMPARE: the Udwadia–Kalaba slack answer of the spring–mass–damper beside the direct
optimum of the same model (McCann 2020, §6.4, Figures 6.20–6.27).

For each of the SMD cases (:mod:`gmuk.scenarios.smd`: x ≥ 5 m, x ≤ 1 m, 1 m ≤ x ≤ 2 m; same
m, b, k, initial state and 30 s) two answers of the same System:

* **UK with slack/excess variables** — ``gmuk run smd-gt`` etc.: the constraint force of the
  Udwadia–Kalaba solve is the control;
* **direct optimum** — :class:`gmuk.optimize.OptimalControlProblem` on the same System: the
  control force u minimising ``∫ u²/m dt`` subject to the dynamics and the bounds on x at every
  node (path constraints, not the slack form), final state free; Lobatto IIIA collocation on
  ``--elements`` elements of degree ``--degree`` (``--elements 1 --degree 4``: gmuk's scheme
  on the thesis's five nodes, not the thesis's Eqs. 98–100; docs/scenarios/smd_compare.rst),
  or adaptively refined to ``--refine-tol``.

Both are compared on the UK run's output grid (every 0.01 s; the optimum interpolated in its
elements): position, velocity, control acceleration u/m, control effort ``∫|u|/m dt``, the
objective ``∫u²/m dt`` (trapezoidal for both), multipliers and the KKT conditions of each
bound. The multipliers are different objects: UK's μ is the force (N) of the bound's row in
the Gauss problem at each instant; the direct optimum's is the multiplier density of the
path constraint of the whole-horizon problem (N²/(kg·m), see
:class:`gmuk.optimize.PathConstraintResult`). They are drawn on separate axes.

Command line
------------
``gmuk run smd-compare``, ``gmuk run smd-compare --cases smd-bi --refine-tol 1e-6``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.kkt import kkt_diagnostics
from gmuk.scenarios import (
    Option,
    OptionError,
    Scenario,
    ScenarioResult,
    comma_separated,
    non_negative_float,
    positive_float,
    smd,
)

NAME = "smd-compare"
DESCRIPTION = "SMD: the UK slack answer beside the direct LGL optimum of the same model (§6.4)"
#: The thesis's figure for each panel.
FIGURES = {
    "position": "6.20",
    "velocity": "6.21",
    "control": "6.22",
    "effort": "6.23",
    "multipliers": "6.24–6.25",
    "kkt": "6.26–6.27",
}


def _trapezoid(y: FloatArray, t: FloatArray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def _cumulative(y: FloatArray, t: FloatArray) -> FloatArray:
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))])


def collocated_x(direct: Any, t: FloatArray) -> FloatArray:
    """x (m) at times t of the collocation method's own state polynomial: in each element, x
    at its first node plus the integral of the degree-p interpolant of ẋ = v at its nodes
    (degree p + 1, Lobatto IIIA). It equals the nodal x at the nodes; between them it is what
    the NLP's dynamics describe, and can leave bounds that hold at every node (the degree-p
    interpolant of the nodal x, ``states_at``, is another curve)."""
    mesh = direct.mesh
    x, v = direct.r_N[:, 0, 0], direct.v_N[:, 0, 0]
    out = np.empty(t.shape)
    elements = mesh.element_of(t)
    for k in np.unique(elements):
        sel = elements == k
        i0, p = mesh.first_node(int(k)), mesh.degrees[int(k)]
        t_k = mesh.element_times(int(k))
        v_poly = np.polynomial.Polynomial.fit(t_k, v[i0 : i0 + p + 1], p)
        integral = v_poly.integ()
        out[sel] = x[i0] + integral(t[sel]) - integral(t_k[0])
    return out


def compare_case(
    case: str,
    duration: float = 30.0,
    elements: int = 150,
    degree: int = 3,
    refine_tol: float = 0.0,
) -> dict[str, Any]:
    """Run one case both ways; returns the UK trajectory and KKT, the direct result, the
    comparison arrays on the UK grid and the summary figures."""
    from gmuk.optimize import Mesh, OptimalControlProblem

    system, traj = smd.simulate(case, duration)
    kkt_uk = kkt_diagnostics(system, traj)
    state0 = traj.state(0)
    problem = OptimalControlProblem(system, state0, duration)
    mesh = Mesh.uniform(0.0, duration, elements, degree)
    if refine_tol > 0.0:
        direct = problem.solve_adaptive(mesh, tol=refine_tol)
    else:
        direct = problem.solve(mesh)
    t = traj.t
    x_uk, v_uk = traj.r_N[:, 0, 0], traj.v_N[:, 0, 0]
    u_uk = smd.control_acceleration(traj)
    y_d = direct.states_at(t)
    x_d, v_d = y_d[:, 0], y_d[:, 3]
    u_d = direct.control(t)[:, 0] / smd.MASS
    J_uk = _trapezoid(smd.MASS * u_uk**2, t)  # ∫ f²/m dt with f = m u
    J_d = _trapezoid(smd.MASS * u_d**2, t)
    kkt_d = direct.kkt()
    residuals = direct.kkt_residuals()
    summary = {
        "inequality": smd.CASES[case][4],
        "objective_uk": J_uk,
        "objective_direct": J_d,
        "objective_direct_quadrature": direct.objective,
        "objective_ratio_uk_over_direct": J_uk / J_d if J_d > 0 else float("inf"),
        "control_effort_uk": _trapezoid(np.abs(u_uk), t),
        "control_effort_direct": _trapezoid(np.abs(u_d), t),
        "x_max_abs_difference_m": float(np.abs(x_uk - x_d).max()),
        "x_rms_difference_m": float(np.sqrt(np.mean((x_uk - x_d) ** 2))),
        "v_max_abs_difference_m_s": float(np.abs(v_uk - v_d).max()),
        "u_rms_difference_m_s2": float(np.sqrt(np.mean((u_uk - u_d) ** 2))),
        "x_direct_min_on_grid_m": float(x_d.min()),
        "x_direct_max_on_grid_m": float(x_d.max()),
        "x_direct_collocation_min_m": float(collocated_x(direct, t).min()),
        "x_direct_collocation_max_m": float(collocated_x(direct, t).max()),
        "x_final_uk": float(x_uk[-1]),
        "x_final_direct": float(x_d[-1]),
        "u_final_uk": float(u_uk[-1]),
        "u_final_direct": float(u_d[-1]),
        "uk_dual_violation_max": max(
            b.summary()["dual_violation_max"] for b in kkt_uk.inequalities.values()
        ),
        "uk_complementarity_abs_max": max(
            b.summary()["complementarity_abs_max"] for b in kkt_uk.inequalities.values()
        ),
        "direct_primal_violation_max": max(
            b.summary()["primal_violation_max"] for b in kkt_d.values()
        ),
        "direct_dual_violation_max": max(b.summary()["dual_violation_max"] for b in kkt_d.values()),
        "direct_kkt_stationarity_relative": residuals["stationarity_relative"],
        "direct_status": direct.status,
        "direct_iterations": direct.iterations,
        "direct_elements": direct.mesh.n_elements,
        "direct_nodes": direct.mesh.n_nodes,
        "direct_total_s": direct.timings["total_s"],
    }
    if direct.refinement:
        summary["direct_refinement"] = [
            {"elements": s.n_elements, "objective": s.objective, "max_error": s.max_error}
            for s in direct.refinement
        ]
    return {
        "system": system,
        "trajectory": traj,
        "kkt_uk": kkt_uk,
        "direct": direct,
        "grid": {
            "t": t,
            "x_uk": x_uk,
            "x_direct": x_d,
            "v_uk": v_uk,
            "v_direct": v_d,
            "u_uk": u_uk,
            "u_direct": u_d,
        },
        "summary": summary,
    }


def run(
    cases: tuple[str, ...] = ("smd-gt", "smd-lt", "smd-bi"),
    duration: float = 30.0,
    elements: int = 150,
    degree: int = 3,
    refine_tol: float = 0.0,
) -> ScenarioResult:
    """Compare the UK slack runs with the direct optimum for each case."""
    unknown = [c for c in cases if c not in smd.CASES]
    if unknown or not cases:
        raise OptionError(f"--cases takes names from {sorted(smd.CASES)}; got {list(cases)}")
    if elements < 1 or not 1 <= degree <= 40:
        raise OptionError(
            f"--elements must be ≥ 1 and --degree in [1, 40]; got {elements}, {degree}"
        )
    data = {c: compare_case(c, duration, elements, degree, refine_tol) for c in cases}
    summary = {c: d["summary"] for c, d in data.items()}
    primary = "smd-bi" if "smd-bi" in data else cases[0]
    return ScenarioResult(
        NAME, {c: d["trajectory"] for c, d in data.items()}, primary, summary, data=data
    )


def write_data(result: ScenarioResult, out: Path) -> list[Path]:
    """``direct_<case>.npz``: the optimum's nodes (t, x, v, u, multipliers of the bounds)."""
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for case, d in result.data.items():
        direct = d["direct"]
        arrays = {"t": direct.t, "r_N": direct.r_N[:, 0], "v_N": direct.v_N[:, 0], "u": direct.u}
        for name, b in direct.kkt().items():
            arrays[f"mu_{name}_t"] = b.t
            arrays[f"mu_{name}"] = b.mu
        path = out / f"direct_{case}.npz"
        np.savez_compressed(path, **arrays)
        paths.append(path)
    return paths


def _panels(
    panels: list[tuple[str, list[tuple[str, FloatArray, FloatArray, dict[str, Any]]]]],
    title: str,
    out: Path,
    formats: tuple[str, ...],
) -> list[Path]:
    """A figure with a row per panel; each line has its own time axis."""
    from gmuk import plotting

    plt = plotting._pyplot()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(
        len(panels),
        1,
        sharex=True,
        squeeze=False,
        figsize=(7.0, 1.7 * len(panels) + 0.9),
        constrained_layout=True,
    )
    for ax, (ylabel, lines) in zip(axes[:, 0], panels, strict=True):
        for label, t, y, style in lines:
            ax.plot(t, y, label=label, **{"lw": 1.1, **style})
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=7)
    axes[-1, 0].set_xlabel("t (s)")
    fig.suptitle(title, fontsize=10)
    return plotting._save(plt, fig, out, formats)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Per case: position, velocity, control, control effort, multipliers, KKT (thesis
    Figures 6.20–6.27), UK slack (C0) against the direct optimum (C1)."""
    paths: list[Path] = []
    uk: dict[str, Any] = {"color": "C0"}
    dr: dict[str, Any] = {"color": "C1", "linestyle": "--"}
    bound: dict[str, Any] = {"color": "0.4", "linestyle": ":", "lw": 0.9}
    for case, d in result.data.items():
        g = d["grid"]
        t = g["t"]
        direct = d["direct"]
        label = f"{case.upper()} ({smd.CASES[case][4]})"
        where = out / case
        lines: list[tuple[str, Any, Any, dict[str, Any]]] = [
            ("UK slack", t, g["x_uk"], uk),
            ("direct optimum", t, g["x_direct"], dr),
        ]
        lines += [
            (f"bound {b.bound:g} m", t, np.full_like(t, b.bound), bound)
            for b in direct.kkt().values()
        ]
        paths += _panels(
            [("x (m)", lines)],
            f"{label}: position (cf. thesis Fig. {FIGURES['position']})",
            where / "position",
            formats,
        )
        # the UK-slack run beside the optimum: (y label, UK values, optimum's, title, file)
        effort_uk, effort_d = (_cumulative(np.abs(g[k]), t) for k in ("u_uk", "u_direct"))
        for ylabel, y_uk, y_d, title, stem in (
            ("ẋ (m/s)", g["v_uk"], g["v_direct"], "velocity", "velocity"),
            ("u (m/s²)", g["u_uk"], g["u_direct"], "control acceleration", "control"),
            ("∫|u| dt (m/s)", effort_uk, effort_d, "control effort", "effort"),
        ):
            paths += _panels(
                [(ylabel, [("UK slack", t, y_uk, uk), ("direct optimum", t, y_d, dr)])],
                f"{label}: {title} (cf. Fig. {FIGURES[stem]})",
                where / stem,
                formats,
            )
        kkt_uk = d["kkt_uk"].inequalities
        side_color = {"lower": "C2", "upper": "C3"}
        mu_uk = [
            (f"UK μ, {b.side} bound", t, b.mu, {"color": side_color[b.side]})
            for b in kkt_uk.values()
        ]
        kd = direct.kkt()
        mu_d = [
            (
                f"direct μ, {b.side} bound",
                b.t,
                b.mu,
                {"color": side_color[b.side], "linestyle": "--"},
            )
            for b in kd.values()
        ]
        unit_d = next(iter(kd.values())).multiplier_unit if kd else ""
        paths += _panels(
            [("UK μ (N)", mu_uk), (f"direct μ ({unit_d})", mu_d)],
            f"{label}: multipliers (cf. Figs. {FIGURES['multipliers']})",
            where / "multipliers",
            formats,
        )
        panels = []
        direct_by_side = {b.side: b for b in kd.values()}
        for b_uk in kkt_uk.values():
            b_d = direct_by_side[b_uk.side]
            panels.append(
                (f"g, {b_uk.side} (m)", [("UK", t, b_uk.g, uk), ("direct", b_d.t, b_d.g, dr)])
            )
            panels.append(
                (
                    f"μ g, {b_uk.side}",
                    [
                        ("UK (N·m)", t, b_uk.complementarity, uk),
                        ("direct", b_d.t, b_d.complementarity, dr),
                    ],
                )
            )
        paths += _panels(
            panels, f"{label}: KKT conditions (cf. Figs. {FIGURES['kkt']})", where / "kkt", formats
        )
    return paths


def _degree(text: str) -> int:
    value = int(text)
    if not 1 <= value <= 40:
        raise ValueError("must be an integer in [1, 40]")
    return value


def _elements(text: str) -> int:
    value = int(text)
    if value < 1:
        raise ValueError("must be an integer ≥ 1")
    return value


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option(
            "cases",
            comma_separated(str),
            ("smd-gt", "smd-lt", "smd-bi"),
            "the SMD cases, comma-separated",
        ),
        Option("duration", positive_float, 30.0, "simulated and optimised time (s)"),
        Option("elements", _elements, 150, "collocation elements of the direct optimum"),
        Option("degree", _degree, 3, "LGL degree p of each element (p + 1 nodes)"),
        Option(
            "refine_tol",
            non_negative_float,
            0.0,
            "refine the mesh adaptively to this relative error per element (0: do not)",
        ),
    ),
    write_data=write_data,
)
