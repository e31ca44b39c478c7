"""Sparse assembly of many small constraints: ``System.accelerations`` for a chain of n rigid
bodies with one constraint per link returning dense (5, 12) blocks (5 rows on the twists of
two neighbours), so s = 5(n − 1) rows. Reports the median time per call and the time spent
stacking the rows (``System.constraint_rows``).

Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_assembly.py [--n 1000 10000]
"""

from __future__ import annotations

import argparse
import statistics
import time
import tracemalloc

import numpy as np

import gmuk


class Link(gmuk.Constraint):
    """Five fixed rows coupling two bodies (a dense (5, 12) block)."""

    def __init__(self, a, b, A, rhs):
        super().__init__([a, b])
        self.A, self.b = A, rhs

    def rows(self, state):
        return self.A, self.b


def chain(n: int, rng: np.random.Generator) -> tuple[gmuk.System, gmuk.State]:
    bodies = [
        gmuk.RigidBody(f"b{i}", rng.uniform(1, 5), np.diag(rng.uniform(1, 2, 3))) for i in range(n)
    ]
    links = [
        Link(bodies[i], bodies[i + 1], rng.normal(size=(5, 12)), rng.normal(size=5))
        for i in range(n - 1)
    ]
    system = gmuk.System(bodies, links, sparse=True)
    names = [b.name for b in bodies]
    state = system.state(g={k: np.eye(4) for k in names}, V={k: rng.normal(size=6) for k in names})
    return system, state


def median_time(fn, repeat: int = 7) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[100, 1000, 10000])
    args = ap.parse_args()
    rng = np.random.default_rng(3)
    print("| bodies | rows | accelerations (ms) | stacking the rows (ms) | peak memory (MB) |")
    print("|---:|---:|---:|---:|---:|")
    for n in args.n:
        system, state = chain(n, rng)
        t_acc = median_time(lambda: system.accelerations(state))  # noqa: B023
        t_rows = median_time(lambda: system.constraint_rows(state))  # noqa: B023
        tracemalloc.start()
        system.accelerations(state)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(
            f"| {n} | {5 * (n - 1)} | {t_acc * 1e3:.1f} | {t_rows * 1e3:.1f} | {peak / 1e6:.1f} |"
        )


if __name__ == "__main__":
    main()
