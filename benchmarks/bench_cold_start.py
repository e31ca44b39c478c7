"""The first ``gmuk run`` of a scenario on an empty numba cache, and where its CPU goes.

Runs the scenario in this process with ``NUMBA_CACHE_DIR`` set to a fresh folder (so every
kernel compiles), records numba's compile events (``numba.core.event``) and prints the CPU
time of the run, of the loop's compilation and of each compiled function (exclusive of the
functions it compiled in turn), and the compile's CPU by phase: numba's lowering to LLVM IR,
its CPython and C wrappers, LLVM's function and module passes, machine code (exclusive of one
another; typing and numba's other passes are the rest). Usage::

    OMP_NUM_THREADS=1 python benchmarks/bench_cold_start.py [fcei]

Run it in a fresh process: numba reads ``NUMBA_CACHE_DIR`` when it is imported, so the script
sets it before importing gmuk.
"""

from __future__ import annotations

import functools
import os
import sys
import tempfile
import time
from collections import defaultdict
from typing import Any

os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="gmuk-cold-")

from numba.core import event


class CompileTimes(event.Listener):
    """CPU seconds per compiled function, exclusive of the compilations nested in it."""

    def __init__(self) -> None:
        self.stack: list[list[object]] = []
        self.exclusive: dict[str, float] = defaultdict(float)

    def on_start(self, ev: event.Event) -> None:
        d = ev.data["dispatcher"]
        self.stack.append([getattr(d, "__qualname__", "?"), time.process_time(), 0.0])

    def on_end(self, ev: event.Event) -> None:
        name, t0, nested = self.stack.pop()
        spent = time.process_time() - float(t0)  # type: ignore[arg-type]
        self.exclusive[str(name)] += spent - float(nested)  # type: ignore[arg-type]
        if self.stack:
            self.stack[-1][2] = float(self.stack[-1][2]) + spent  # type: ignore[arg-type]


class Phases:
    """CPU seconds per phase of numba's compilation, each exclusive of the others nested in
    it (a wrapper's module goes through the function passes, for instance)."""

    def __init__(self) -> None:
        self.stack: list[list[float]] = []
        self.seconds: dict[str, float] = defaultdict(float)

    def wrap(self, owner: Any, method: str, phase: str) -> None:
        original = getattr(owner, method)

        @functools.wraps(original)
        def timed(*args: Any, **kwargs: Any) -> Any:
            self.stack.append([time.process_time(), 0.0])
            try:
                return original(*args, **kwargs)
            finally:
                t0, nested = self.stack.pop()
                spent = time.process_time() - t0
                self.seconds[phase] += spent - nested
                if self.stack:
                    self.stack[-1][1] += spent

        setattr(owner, method, timed)

    def install(self) -> None:
        from numba.core import codegen, lowering

        self.wrap(lowering.Lower, "lower_normal_function", "lowering to LLVM IR")
        self.wrap(lowering.Lower, "create_cpython_wrapper", "CPython wrappers")
        self.wrap(lowering.Lower, "create_cfunc_wrapper", "C wrappers")
        self.wrap(codegen.CPUCodeLibrary, "_optimize_functions", "LLVM function passes")
        self.wrap(codegen.CPUCodeLibrary, "_optimize_final_module", "LLVM module passes")
        self.wrap(codegen.JITCodeLibrary, "_finalize_specific", "machine code")


def main() -> None:
    scenario = sys.argv[1] if len(sys.argv) > 1 else "fcei"
    times = CompileTimes()
    event.register("numba:compile", times)
    phases = Phases()
    phases.install()
    start = time.process_time()
    import gmuk.cli
    from gmuk.engine.integrators import _compiled

    compile_now = _compiled._compile_now
    loop_s = [0.0]

    def timed() -> None:
        t0 = time.process_time()
        compile_now()
        loop_s[0] = time.process_time() - t0

    _compiled._compile_now = timed
    out = tempfile.mkdtemp(prefix="gmuk-cold-out-")
    try:
        gmuk.cli.main(["run", scenario, "--out", out, "--no-plots"])
    except SystemExit:
        pass
    total = time.process_time() - start
    compiled = sum(times.exclusive.values())
    print(
        f"\n{scenario}: {total:.1f} s of CPU in all, {compiled:.1f} s compiling "
        f"({loop_s[0]:.1f} s of it the loop's compile_loop)"
    )
    for phase, seconds in sorted(phases.seconds.items(), key=lambda kv: -kv[1]):
        print(f"  {seconds:6.2f} s  {phase}")
    rest = compiled - sum(phases.seconds.values())
    print(f"  {rest:6.2f} s  typing and numba's other passes (the rest)\nby function:")
    for name, seconds in sorted(times.exclusive.items(), key=lambda kv: -kv[1])[:25]:
        print(f"  {seconds:6.2f} s  {name}")


if __name__ == "__main__":
    main()
