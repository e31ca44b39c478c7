"""gmuk.optimize against a hand-written CasADi + IPOPT Lobatto transcription (issue #17).

The bounded spring–mass–damper (m = 2 kg, b = 5 N·s/m, k = 10 N/m, 1 m ≤ x ≤ 2 m,
x₀ = 1.5 m, ẋ₀ = 6 m/s, 30 s, final state free, cost ∫u²/m dt) on 150 elements of degree 3
(451 nodes), transcribed and solved

* by gmuk: ``OptimalControlProblem(system, state, 30).solve(Mesh.uniform(0, 30, 150, 3))``
  on the ``smd-bi`` System (a 3-D point mass, the spring–damper, the PlaneBound);
* by ``tests/optimize/handwritten_lobatto.py``: the same discretisation written directly in
  CasADi for the 1-D problem, as one would by hand.

Both in the same process, alternating, after one warm-up each; medians of ``--repeat`` runs of
the total (building the NLP and the solver, and IPOPT's solve), with the split. ``--table``
also prints the objective under uniform and adaptive mesh refinement (docs/optimize.rst).

``--slew`` adds the rigid-body table (a 90° rest-to-rest slew; docs/optimize.rst).

Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_optimize.py [--table] [--slew]
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import statistics
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "optimize"))

from handwritten_lobatto import solve_smd

from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.scenarios import smd


def gmuk_once(n_elements: int, degree: int) -> dict[str, float]:
    system, state = smd.build("smd-bi")  # the System is the user's: not timed
    tic = time.perf_counter()
    result = OptimalControlProblem(system, state, 30.0).solve(
        Mesh.uniform(0.0, 30.0, n_elements, degree)
    )
    total = time.perf_counter() - tic
    return {
        "objective": result.objective,
        "total_s": total,
        "solve_s": result.timings["solve_s"],
        "transcription_s": total - result.timings["solve_s"],
    }


def handwritten_once(n_elements: int, degree: int) -> dict[str, float]:
    tic = time.perf_counter()
    out = solve_smd(n_elements=n_elements, degree=degree)
    total = time.perf_counter() - tic
    return {
        "objective": out["objective"],
        "total_s": total,
        "solve_s": out["solve_s"],
        "transcription_s": total - out["solve_s"],
    }


def compare(n_elements: int, degree: int, repeat: int) -> None:
    gmuk_once(n_elements, degree)
    handwritten_once(n_elements, degree)
    runs: dict[str, list[dict[str, float]]] = {"gmuk": [], "hand-written CasADi": []}
    for _ in range(repeat):
        runs["gmuk"].append(gmuk_once(n_elements, degree))
        runs["hand-written CasADi"].append(handwritten_once(n_elements, degree))
    print(f"bounded SMD, {n_elements} elements of degree {degree}, medians of {repeat} runs")
    print(
        "| transcription | objective | transcription + solver set-up (s) | IPOPT (s) | total (s) |"
    )
    print("|---|---:|---:|---:|---:|")
    med = {}
    for name, rows in runs.items():
        med[name] = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
        m = med[name]
        print(
            f"| {name} | {m['objective']:.10f} | {m['transcription_s']:.3f} | "
            f"{m['solve_s']:.3f} | {m['total_s']:.3f} |"
        )
    g, h = med["gmuk"], med["hand-written CasADi"]
    print(
        f"ratio gmuk / hand-written, total: {g['total_s'] / h['total_s']:.2f}; objectives "
        f"differ by {abs(g['objective'] - h['objective']) / h['objective']:.1e} relative"
    )


def table() -> None:
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    print("uniform meshes, degree 3")
    print("| elements | nodes | objective | IPOPT iterations | transcription (s) | total (s) |")
    print("|---:|---:|---:|---:|---:|---:|")
    for n in (10, 20, 40, 80, 150, 300, 600):
        r = problem.solve(Mesh.uniform(0.0, 30.0, n, 3))
        print(
            f"| {n} | {r.mesh.n_nodes} | {r.objective:.6f} | {r.iterations} | "
            f"{r.timings['transcription_s']:.3f} | {r.timings['total_s']:.2f} |"
        )
    r = problem.solve_adaptive(Mesh.uniform(0.0, 30.0, 10, 3), tol=1e-6)
    print("adaptive refinement from 10 elements of degree 3, tol = 1e-6")
    print("| round | elements | nodes | objective | max error estimate |")
    print("|---:|---:|---:|---:|---:|")
    for s in r.refinement or []:
        print(
            f"| {s.round} | {s.n_elements} | {s.n_nodes} | {s.objective:.6f} | {s.max_error:.1e} |"
        )


def slew_setup() -> tuple[Any, Any, dict[str, Any]]:
    """docs/optimize.rst's slew, as the user builds it before timing starts: the System of
    one free body "sat" (100 kg, J = [[10, 1, −0.5], [1, 12, 0.3], [−0.5, 0.3, 15]] kg·m²),
    its State at rest at the identity, and the final conditions (at rest, turned 90° about
    (1, 1, 1)/√3)."""
    import numpy as np

    import gmuk
    from gmuk.lie import so3

    J = np.array([[10.0, 1.0, -0.5], [1.0, 12.0, 0.3], [-0.5, 0.3, 15.0]])
    system = gmuk.System([gmuk.RigidBody("sat", 100.0, J)])
    state = system.state(g={"sat": np.eye(4)}, V={"sat": np.zeros(6)})
    gf = np.eye(4)
    gf[:3, :3] = so3.exp(0.5 * np.pi * np.ones(3) / np.sqrt(3.0))
    return system, state, {"g": {"sat": gf}, "V": {"sat": np.zeros(6)}}


def slew_rows(elements: tuple[int, ...] = (6, 12, 24, 48)) -> list[dict[str, float]]:
    """Minimum-effort rest-to-rest slew of one rigid body, 90° about (1, 1, 1)/√3 in 60 s,
    degree 4, on each number of ``elements``: per mesh the objective, the largest
    orthogonality error max(|RᵀR − I|, |det R − 1|), the final attitude error (rad), the
    largest error of its re-simulation by System.simulate at the nodes (rad; DOP853, rtol
    1e-11), IPOPT's iterations and the wall time (s). docs/optimize.rst's table; its figures
    are checked by tests/docs_figures.py, which calls this."""
    import numpy as np

    import gmuk
    from gmuk.lie import so3

    system, state, final = slew_setup()
    body = system.bodies[0]
    gf = final["g"]["sat"]
    rows = []
    for n in elements:
        tic = time.perf_counter()
        r = OptimalControlProblem(system, state, 60.0, final=final).solve(
            Mesh.uniform(0.0, 60.0, n, 4)
        )
        total = time.perf_counter() - tic
        R = r.R_NB[:, 0]
        driven = gmuk.System([body], controllers=[r.controller()])
        traj = driven.simulate(state, (0.0, 60.0), t_eval=r.t, rtol=1e-11, atol=1e-12)
        rows.append(
            {
                "elements": n,
                "objective": r.objective,
                "orthogonality": max(
                    np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(),
                    np.abs(np.linalg.det(R) - 1.0).max(),
                ),
                "final_error": float(np.linalg.norm(so3.log(R[-1].T @ gf[:3, :3]))),
                "resimulated_error": float(
                    np.linalg.norm(
                        so3.log(np.swapaxes(traj.g_NB[:, 0, :3, :3], -1, -2) @ R), axis=-1
                    ).max()
                ),
                "iterations": r.iterations,
                "total_s": total,
            }
        )
    return rows


def slew() -> None:
    """Print :func:`slew_rows` as docs/optimize.rst's table."""
    print("rigid-body slew, degree 4; re-simulated with System.simulate (DOP853, rtol 1e-11)")
    print(
        "| elements | objective | max(|RᵀR − I|, |det R − 1|) | final attitude error (rad) | "
        "re-simulated, max error at the nodes (rad) | IPOPT iterations | total (s) |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for row in slew_rows():
        print(
            f"| {row['elements']} | {row['objective']:.10e} | {row['orthogonality']:.1e} | "
            f"{row['final_error']:.1e} | {row['resimulated_error']:.1e} | "
            f"{row['iterations']} | {row['total_s']:.2f} |"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=150)
    parser.add_argument("--degree", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--table", action="store_true", help="also the refinement tables")
    parser.add_argument("--slew", action="store_true", help="also the rigid-body slew table")
    parser.add_argument("--slew-only", action="store_true", help="only the slew table")
    args = parser.parse_args()
    if not args.slew_only:
        compare(args.elements, args.degree, args.repeat)
    if args.table and not args.slew_only:
        table()
    if args.slew or args.slew_only:
        slew()


if __name__ == "__main__":
    main()
