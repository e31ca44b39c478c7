"""Cost per right-hand side of the compiled loop on one rigid body (bench_peers.py's case 4:
point-mass Moon plus gravity gradient, 7200 s, DOP853 at 1e-11), median of 9 runs after a
warm-up, in µs per evaluation.

To compare two commits, alternate the tree (a clone at each commit) in one session:

    export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
    for i in 1 2 3 4 5; do
        (cd /tmp/base && PYTHONPATH=/tmp/base python /path/to/bench_rigid_rhs.py)
        (cd /tmp/head && PYTHONPATH=/tmp/head python /path/to/bench_rigid_rhs.py)
    done
"""

from __future__ import annotations

import statistics
import time

import numpy as np

import gmuk


def case() -> tuple[gmuk.System, gmuk.State]:
    """The System (one rigid body, point-mass Moon plus gravity gradient) and its state at
    periselene of a 1838 km circular orbit inclined at 80°."""
    mu, r0 = 4.9028e12, 1838e3
    sc = gmuk.RigidBody("sc", 500.0, np.diag([100.0, 200.0, 300.0]))
    system = gmuk.System([sc], [], [gmuk.GravityGradient(mu)])
    g = np.eye(4)
    g[0, 3] = r0
    v = np.sqrt(mu / r0) * np.array([0.0, np.cos(np.radians(80)), np.sin(np.radians(80))])
    return system, system.state(g={"sc": g}, V={"sc": [0.001, 0.002, 0.003, *v]})


def main() -> None:
    system, state = case()
    options = {"rtol": 1e-11, "atol": 1e-11}
    traj = system.simulate(state, (0.0, 7200.0), **options)
    walls = []
    for _ in range(9):
        t0 = time.perf_counter()
        system.simulate(state, (0.0, 7200.0), **options)
        walls.append(time.perf_counter() - t0)
    n = traj.stats["n_rhs"]
    print(f"{statistics.median(walls) / n * 1e6:.2f} us per RHS ({n} evaluations)")


if __name__ == "__main__":
    main()
