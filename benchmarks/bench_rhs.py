"""Where a right-hand side goes: one FCEI orbit end to end and the per-call cost of its
parts, and a point mass in the GRAIL field (issue #14's per-RHS overhead).

Rows: ``gmuk.scenarios.fcei.run()`` (median of 7 runs after one warm-up); its ``simulate``
call alone with the compiled and with the Python step loop, and the wall time per
right-hand side evaluation of each (everything the loop does, divided by its evaluations);
for the FCEI
System (built as ``gmuk.scenarios._lvlh.fully_constrained`` builds it) one right-hand side
``_Problem.rhs`` at a new time per call, ``LVLHReference.evaluate`` at a new time and
``GravityGradient.wrench``; for a 300 kg point mass in GRGM660PRIM to degree 50 one
right-hand side and the field's acceleration alone. Medians of 7 batches (µs per call).

Systems with parts in Python (issue #14's mixed systems): a rigid body and a point mass under
point-mass gravity and a user's Python drag model (3000 s, DOP853 at 1e-11), called back
from the compiled loop; and the FCCL scenario (``gmuk.scenarios.fccl.run()``, its
Morse–Lyapunov controller compiled). Each with the compiled loop and with the reference Python
loop of ``gmuk.testing`` (the scenario's ``simulate`` calls sent to it for that timing).

Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_rhs.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import contextlib
import itertools
import math
import statistics
import time
import timeit
from typing import Any

import numpy as np

import gmuk
from gmuk.orbits import KeplerOrbit, LVLHReference, fcei_orbit
from gmuk.scenarios import _lvlh as common
from gmuk.scenarios import fcei
from gmuk.testing import _ReferenceProblem as _Problem


def per_call_us(fn, number: int = 5000, repeat: int = 7) -> float:
    """Median over ``repeat`` batches of the time per call (µs)."""
    fn()
    return statistics.median(timeit.repeat(fn, number=number, repeat=repeat)) / number * 1e6


def fcei_orbit_run(compiled: bool | None) -> tuple[float, float]:
    """Median wall time (s) of one FCEI orbit as the scenario runs it, and µs per RHS."""
    orbit = fcei_orbit(common.MU)
    craft, ref = common.spacecraft(), LVLHReference(orbit)
    system = gmuk.System(
        [craft], [gmuk.ConfigurationTracking(craft, ref)], [gmuk.GravityGradient(orbit.mu)]
    )
    r0 = ref.evaluate(0.0)
    state = system.state(g={craft.name: r0.g}, V={craft.name: r0.V})
    t = common.time_grid(orbit, 1.0)
    options = {"t_eval": t, "rtol": common.RTOL, "atol": common.ATOL}
    run = _simulate if compiled else _reference
    traj = run(system, state, (0.0, t[-1]), **options)
    walls = []
    for _ in range(7):
        t0 = time.perf_counter()
        run(system, state, (0.0, t[-1]), **options)
        walls.append(time.perf_counter() - t0)
    wall = statistics.median(walls)
    return wall, wall / traj.stats["n_rhs"] * 1e6


class Drag(gmuk.ForceModel):
    """A user's force model in Python: linear drag on the twist and on the velocity."""

    def wrench(self, t, g, V, body):  # type: ignore[no-untyped-def]
        return np.r_[-1e-3 * V[:3], -1e-4 * V[3:]]

    def force(self, t, x, xdot, body):  # type: ignore[no-untyped-def]
        return -1e-4 * xdot


def mixed_run(compiled: bool) -> tuple[float, float]:
    """Median wall time (s) of the rigid body and point mass with the Python drag model,
    and µs per RHS."""
    mu, r0 = 4.9028e12, 1838e3
    v0 = math.sqrt(mu / r0)
    sc = gmuk.RigidBody("sc", 500.0, np.diag([150.0, 200.0, 300.0]))
    p = gmuk.PointMass("p", 3.0)
    system = gmuk.System([sc, p], [], [gmuk.PointMassGravity(mu), Drag()])
    g = np.eye(4)
    g[0, 3] = r0
    state = system.state(
        g={"sc": g},
        V={"sc": [0.01, -0.02, 0.005, 0.0, v0, 0.0]},
        r={"p": [0.0, r0 + 30e3, 1e3]},
        v={"p": [-v0, 0.0, 20.0]},
    )
    options = {"rtol": 1e-11, "atol": 1e-11}
    run = _simulate if compiled else _reference
    traj = run(system, state, (0.0, 3000.0), **options)
    walls = []
    for _ in range(7):
        t0 = time.perf_counter()
        run(system, state, (0.0, 3000.0), **options)
        walls.append(time.perf_counter() - t0)
    wall = statistics.median(walls)
    return wall, wall / traj.stats["n_rhs"] * 1e6


def _simulate(system: Any, state: Any, span: Any, **options: Any) -> Any:
    """gmuk's one loop, compiled."""
    return system.simulate(state, span, **options)


def _reference(system: Any, state: Any, span: Any, **options: Any) -> Any:
    """The reference Python loop (gmuk.testing), which has no progress bar."""
    from gmuk.testing import reference_simulate

    options.pop("progress", None)
    return reference_simulate(system, state, span, **options)


def fccl_run(python_loop: bool) -> float:
    """Median wall time (s) of ``gmuk.scenarios.fccl.run()`` (3 runs after a warm-up)."""
    from unittest import mock

    from gmuk.scenarios import fccl

    force = mock.patch("gmuk.engine.system._simulate", _reference)
    walls = []
    with force if python_loop else contextlib.nullcontext():
        fccl.run()
        for _ in range(3):
            t0 = time.perf_counter()
            fccl.run()
            walls.append(time.perf_counter() - t0)
    return statistics.median(walls)


def main() -> None:
    gmuk.compile_loop()  # timings of the compiled loop, not of its one-time compilation
    fcei.run()
    runs = []
    for _ in range(7):
        t0 = time.perf_counter()
        fcei.run()
        runs.append(time.perf_counter() - t0)
    rows = [("gmuk.scenarios.fcei.run(), one orbit (s)", statistics.median(runs))]
    for compiled, name in ((True, "compiled loop"), (False, "Python reference loop")):
        wall, per_rhs = fcei_orbit_run(compiled)
        rows += [
            (f"FCEI orbit, simulate only, {name} (s)", wall),
            (f"FCEI orbit, {name}: µs per right-hand side, whole run", per_rhs),
        ]

    for compiled, name in ((True, "compiled loop"), (False, "Python reference loop")):
        wall, per_rhs = mixed_run(compiled)
        rows += [
            (f"rigid body + point mass, Python drag model, {name} (s)", wall),
            (f"same, {name}: µs per right-hand side, whole run", per_rhs),
        ]
    rows += [
        ("gmuk.scenarios.fccl.run(), compiled loop (s)", fccl_run(False)),
        ("gmuk.scenarios.fccl.run(), Python reference loop (s)", fccl_run(True)),
    ]

    orbit = fcei_orbit(common.MU)
    craft, ref = common.spacecraft(), LVLHReference(orbit)
    gg = gmuk.GravityGradient(orbit.mu)
    system = gmuk.System([craft], [gmuk.ConfigurationTracking(craft, ref)], [gg])
    r0 = ref.evaluate(0.0)
    state = system.state(g={craft.name: r0.g}, V={craft.name: r0.V})
    prob = _Problem(system)
    prob.G0 = state.g.copy()
    Y = prob.pack(state)
    times = itertools.count(1.0, 0.37)  # a new time at every call
    rows += [
        ("FCEI: one right-hand side (µs)", per_call_us(lambda: prob.rhs(next(times), Y))),
        ("FCEI: LVLHReference.evaluate (µs)", per_call_us(lambda: ref.evaluate(next(times)))),
        (
            "FCEI: GravityGradient.wrench (µs)",
            per_call_us(lambda: gg.wrench(1.0, state.g[0], state.V[0], craft)),
        ),
    ]

    gravity = gmuk.SphericalHarmonicGravity("GRGM660PRIM", degree=50)
    ellipse = KeplerOrbit.from_elements(1838e3, 0.0, math.radians(80), 0, 0, gravity.field.mu)
    mass = gmuk.PointMass("sc", 300.0)
    free = gmuk.System([mass], [], [gravity])
    r, v = ellipse.state(0.0)
    point = free.state(r={"sc": r}, v={"sc": v})
    prob2 = _Problem(free)
    Y2 = prob2.pack(point)
    rows += [
        (
            "point mass, degree 50: one right-hand side (µs)",
            per_call_us(lambda: prob2.rhs(1.0, Y2)),
        ),
        (
            "point mass, degree 50: the field's acceleration alone (µs)",
            per_call_us(lambda: gravity.field.acceleration(np.asarray(r))),
        ),
    ]
    print("| quantity | median |")
    print("|---|---:|")
    for label, value in rows:
        print(f"| {label} | {value:.3g} |")


if __name__ == "__main__":
    main()
