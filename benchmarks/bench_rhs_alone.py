"""The compiled right-hand side alone, called from a compiled loop: ns per call.

The case of ``bench_rigid_rhs.py`` (one rigid body, point-mass Moon plus gravity gradient).
The loop calls :func:`gmuk.engine.integrators._compiled.rhs` 200 000 times at a state with a
nonzero ξ; the minimum of seven repetitions is printed. Usage::

    OMP_NUM_THREADS=1 python benchmarks/bench_rhs_alone.py

(Before issue #24 the same measurement needs the old API: ``_compiled.program(system, method,
state)`` and ``rhs`` without its ``ints`` argument.)
"""

from __future__ import annotations

import time

import numba
import numpy as np
from bench_rigid_rhs import case

from gmuk.engine.integrators import _compiled, get_method


@numba.njit
def _calls(n, Y, G0, parts, dY, aux, ints):  # type: ignore[no-untyped-def]
    s = 0
    for i in range(n):
        s += _compiled.rhs(0.1 * i, Y, G0, parts, dY, aux, ints)
    return s


def main() -> None:
    system, state = case()
    prog = system.compiled_program(get_method("DOP853"), state)
    _compiled.compile_loop()
    Y = np.zeros(12)
    Y[:6] = 1e-3
    Y[6:] = state.V[0]
    args = (Y, state.g.copy(), prog.parts, np.empty(12), np.empty(prog.n_aux))
    ints = np.zeros(_compiled.N_INTS, np.int64)
    _calls(10, *args, ints)
    n, best = 200_000, float("inf")
    for _ in range(7):
        t0 = time.perf_counter()
        _calls(n, *args, ints)
        best = min(best, time.perf_counter() - t0)
    print(f"rhs alone: {best / n * 1e9:.0f} ns per call (minimum of 7 x {n})")


if __name__ == "__main__":
    main()
