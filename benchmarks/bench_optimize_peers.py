"""gmuk.optimize against peer transcriptions of the same problems: a hand-written, mapped
CasADi + IPOPT transcription (benchmarks/hand_transcriptions.py) and GEKKO
(benchmarks/gekko_smd.py, the SMD only).

Cases (meshes uniform):

* bounded spring–mass–damper (tests/optimize/handwritten_lobatto.py's problem; gmuk solves
  the ``smd-bi`` System, a 3-D point mass with the spring–damper and the PlaneBound), 150
  elements of degree 3 and of degree 4. The hand transcription twice: of the 1-D problem,
  and of the NLP gmuk poses (the point mass in R³, three times the variables; the same
  optimum). GEKKO twice: on the same elements and nodes
  (``NODES = degree + 1``) and with ``NODES = 2`` on as many time points as the mesh has
  nodes (gekko_smd.py's docstring says why both, and why ``NODES = 5`` is not a usable
  discretisation of this problem);
* the rigid-body rest-to-rest slew of docs/optimize.rst (benchmarks/bench_optimize.py's
  slew_rows, without its re-simulation), 40 elements of degree 4. The hand transcription
  (unit quaternions) twice: the attitude alone, and with the translational part gmuk's
  rigid body carries (its NLP's variables, the same optimum).

All in one process: per case, one warm-up run of every solver, then ``--repeat`` rounds in
which the solvers take turns, so that the load of the (shared) machine falls on all alike.
The table gives medians. Times (wall, s):

* gmuk: "total" is the call ``OptimalControlProblem(...).solve(mesh)`` (the System and its
  State are the user's, built before the clock starts), "solve" its ``timings["solve_s"]``
  (the IPOPT call), "build" the rest (transcription, solver creation, starting point, the
  result's assembly);
* hand-written: "build" up to and including ``nlpsol`` and the starting point, "solve" the
  solver call;
* GEKKO: "build" the Python model, "solve" ``m.solve`` (writing the model files, APMonitor's
  own compile of them, IPOPT, reading the results); GEKKO's own SOLVETIME is printed
  below the table.

The last column is gmuk's median total divided by the row's median total (below 1: gmuk is
faster).

Run from the repository's root:
    python benchmarks/bench_optimize_peers.py [--repeat 7]
(OMP_NUM_THREADS and OPENBLAS_NUM_THREADS are set to 1 below, before numpy is imported.)
"""

from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_optimize import slew_setup
from gekko_smd import gekko_smd
from hand_transcriptions import HandResult, slew_mapped, smd_mapped

from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.scenarios import smd


@dataclass
class Run:
    """One solve's figures, common to every solver."""

    build_s: float
    solve_s: float
    objective: float
    iterations: int
    status: str
    solver_s: float = float("nan")  # GEKKO's own SOLVETIME

    @property
    def total_s(self) -> float:
        return self.build_s + self.solve_s


Runner = Callable[[], Run]


# ---------------------------------------------------------------------- gmuk
def gmuk_smd(n_elements: int, degree: int) -> Runner:
    """gmuk on the ``smd-bi`` System (built once, outside the timing)."""
    system, state = smd.build("smd-bi")

    def run() -> Run:
        tic = time.perf_counter()
        r = OptimalControlProblem(system, state, 30.0).solve(
            Mesh.uniform(0.0, 30.0, n_elements, degree)
        )
        total = time.perf_counter() - tic
        solve = r.timings["solve_s"]
        return Run(total - solve, solve, r.objective, r.iterations, r.status)

    return run


def gmuk_slew(n_elements: int, degree: int) -> Runner:
    """gmuk on bench_optimize.slew_rows's slew (System, State and final state built once)."""
    system, state, final = slew_setup()

    def run() -> Run:
        tic = time.perf_counter()
        r = OptimalControlProblem(system, state, 60.0, final=final).solve(
            Mesh.uniform(0.0, 60.0, n_elements, degree)
        )
        total = time.perf_counter() - tic
        solve = r.timings["solve_s"]
        return Run(total - solve, solve, r.objective, r.iterations, r.status)

    return run


# ---------------------------------------------------------------------- peers
def hand(solve: Callable[[int, int], HandResult], n_elements: int, degree: int) -> Runner:
    """A mapped hand-written transcription (smd_mapped or slew_mapped)."""

    def run() -> Run:
        r = solve(n_elements, degree)
        return Run(r.build_s, r.solve_s, r.objective, r.iterations, r.status)

    return run


def smd_3d(n_elements: int, degree: int) -> HandResult:
    """The hand-written SMD on the NLP gmuk poses: a point mass in R³ (``dim=3``)."""
    return smd_mapped(n_elements, degree, dim=3)


def slew_with_translation(n_elements: int, degree: int) -> HandResult:
    """The hand-written slew with the translational part gmuk carries (``translation``)."""
    return slew_mapped(n_elements, degree, translation=True)


def gekko(n_elements: int, degree: int, same_nodes: bool) -> Runner:
    """GEKKO on the SMD."""

    def run() -> Run:
        r = gekko_smd(n_elements, degree, same_nodes=same_nodes)
        return Run(r.build_s, r.solve_s, r.objective, r.iterations, r.status, r.solver_s)

    return run


# ---------------------------------------------------------------------- driver
def cases() -> list[tuple[str, dict[str, Runner]]]:
    """The benchmark's cases: a title and its solvers (gmuk first)."""
    out = []
    for p in (3, 4):
        n = 150
        out.append(
            (
                f"bounded SMD, {n} elements of degree {p} ({n * p + 1} nodes)",
                {
                    "gmuk": gmuk_smd(n, p),
                    "hand-written CasADi, mapped, 1-D": hand(smd_mapped, n, p),
                    "hand-written CasADi, mapped, 3-D (gmuk's NLP)": hand(smd_3d, n, p),
                    f"GEKKO, same nodes (NODES={p + 1})": gekko(n, p, True),
                    f"GEKKO, NODES=2 on {n * p + 1} points": gekko(n, p, False),
                },
            )
        )
    out.append(
        (
            "rigid-body slew, 40 elements of degree 4 (161 nodes)",
            {
                "gmuk": gmuk_slew(40, 4),
                "hand-written CasADi, mapped, attitude only": hand(slew_mapped, 40, 4),
                "hand-written CasADi, mapped, with translation (gmuk's NLP)": hand(
                    slew_with_translation, 40, 4
                ),
            },
        )
    )
    return out


def measure(solvers: dict[str, Runner], repeat: int) -> dict[str, list[Run]]:
    """One warm-up of each solver, then ``repeat`` rounds, the solvers taking turns."""
    for run in solvers.values():
        run()
    runs: dict[str, list[Run]] = {name: [] for name in solvers}
    for _ in range(repeat):
        for name, run in solvers.items():
            runs[name].append(run())
    return runs


def report(title: str, runs: dict[str, list[Run]], repeat: int) -> None:
    """Print one case's markdown table of medians."""

    def med(rows: list[Run], key: str) -> float:
        return statistics.median(getattr(r, key) for r in rows)

    print(f"\n{title}; medians of {repeat} runs")
    print(
        "| solver | build (s) | solve (s) | total (s) | objective | iterations | status "
        "| gmuk / this, total |"
    )
    print("|---|---:|---:|---:|---:|---:|---|---:|")
    gmuk_total = med(runs["gmuk"], "total_s")
    for name, rows in runs.items():
        statuses = sorted({r.status for r in rows})
        print(
            f"| {name} | {med(rows, 'build_s'):.3f} | {med(rows, 'solve_s'):.3f} | "
            f"{med(rows, 'total_s'):.3f} | {rows[-1].objective:.10g} | "
            f"{med(rows, 'iterations'):.0f} | {', '.join(statuses)} | "
            f"{gmuk_total / med(rows, 'total_s'):.2f} |"
        )
    for name, rows in runs.items():
        if name.startswith("GEKKO"):
            print(f"{name}: GEKKO's SOLVETIME, median {med(rows, 'solver_s'):.3f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="timed rounds per case")
    args = parser.parse_args()
    for title, solvers in cases():
        report(title, measure(solvers, args.repeat), args.repeat)


if __name__ == "__main__":
    main()
