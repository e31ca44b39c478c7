"""10 s of ``simulate`` for a chain of n rigid bodies (issue #14: report it, growth ≤ n^1.2).

Each link is a constraint returning fixed dense (5, 12) rows on the twists of two
neighbours with b = 0 (so A ν stays at its initial value), on the sparse path, bodies
spinning freely under no force; DOP853 at rtol = atol = 1e-8, outputs every second.
Reports wall time, right-hand-side evaluations, time per evaluation, and the growth exponent
between successive sizes.

Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_chain_sim.py
(``--n 100 300 1000`` by default).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import gmuk


class Link(gmuk.Constraint):
    def __init__(self, a, b, A):
        super().__init__([a, b])
        self.A, self.b = A, np.zeros(A.shape[0])

    def rows(self, state):
        return self.A, self.b


def run(n: int, rng: np.random.Generator) -> tuple[float, int]:
    bodies = [
        gmuk.RigidBody(f"b{i}", rng.uniform(1, 5), np.diag(rng.uniform(1, 2, 3))) for i in range(n)
    ]
    links = [Link(bodies[i], bodies[i + 1], rng.normal(size=(5, 12))) for i in range(n - 1)]
    system = gmuk.System(bodies, links, sparse=True)
    names = [b.name for b in bodies]
    state = system.state(
        g={k: np.eye(4) for k in names}, V={k: 0.1 * rng.normal(size=6) for k in names}
    )
    t0 = time.perf_counter()
    traj = system.simulate(state, (0.0, 10.0), t_eval=np.arange(11.0), rtol=1e-8, atol=1e-8)
    elapsed = time.perf_counter() - t0
    assert traj.success, traj.message
    return elapsed, int(traj.stats["n_rhs"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[100, 300, 1000])
    args = ap.parse_args()
    rng = np.random.default_rng(4)
    print("| bodies | wall (s) | RHS | ms per RHS | growth exponent: wall | per RHS |")
    print("|---:|---:|---:|---:|---:|---:|")
    previous: tuple[int, float, float] | None = None
    for n in args.n:
        wall, n_rhs = run(n, rng)
        per = wall / n_rhs
        if previous is None:
            growth = "— | —"
        else:
            scale = math.log(n / previous[0])
            growth = (
                f"{math.log(wall / previous[1]) / scale:.2f} | "
                f"{math.log(per / previous[2]) / scale:.2f}"
            )
        print(f"| {n} | {wall:.2f} | {n_rhs} | {per * 1e3:.2f} | {growth} |")
        previous = (n, wall, per)


if __name__ == "__main__":
    main()
