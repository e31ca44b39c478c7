"""What events cost in a whole run, and that a run without them is unchanged.

Run on demand (not a test):

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_events.py [--repeats 5]
        [--orbits 20] [--no-events] [--first-event]

A point mass on a Keplerian orbit (e = 0.3, a = 7000 km, point-mass gravity, compiled) over
20 orbits, DOP853 at rtol = atol = 1e-10, every step an output or 2001 output times: without
events, with one recorded ApsisEvent (both apsides: 40 crossings), and with a Python event
that never crosses (the cost of handing back every step). Prints the best wall time of
``--repeats`` runs, the steps, the time per step and the evaluations spent locating events,
and checks that the runs with recorded events have the same bits as the run without. The
SHA-256 of the no-event run's arrays (``digest``) compares checkouts: the same digest before
and after a change means the no-event path computes the same bits.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import hashlib
import inspect
import time

import numpy as np

import gmuk
from gmuk.orbits import KeplerOrbit
from gmuk.trajectory import _ARRAYS

MU = 3.986004418e14


def kepler():
    orbit = KeplerOrbit.from_elements(7.0e6, 0.3, 0.4, 0.2, 1.1, MU)
    r_N, v_N = orbit.state(-0.3 * orbit.period)
    sat = gmuk.PointMass("sat", mass=10.0)
    system = gmuk.System(bodies=[sat], forces=[gmuk.PointMassGravity(MU)])
    return system, system.state(r={"sat": r_N}, v={"sat": v_N}), orbit.period


def digest(traj) -> str:
    h = hashlib.sha256()
    for name in _ARRAYS:
        h.update(np.ascontiguousarray(getattr(traj, name)).tobytes())
    return h.hexdigest()[:16]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--orbits", type=float, default=20.0)
    ap.add_argument("--no-events", action="store_true", help="time the run without events only")
    ap.add_argument(
        "--first-event",
        action="store_true",
        help="time only the first located event of this process (its helpers compiled, or "
        "loaded from numba's cache); remove gmuk/engine/integrators/__pycache__/_event_step.* "
        "first for the cold figure",
    )
    args = ap.parse_args()
    system, state, period = kepler()
    if args.first_event:
        system.simulate(state, (0.0, 0.1 * period))  # the loop loaded first
        t0 = time.perf_counter()
        traj = system.simulate(state, (0.0, period), events=[gmuk.ApsisEvent("sat")])
        print(f"first located event: {time.perf_counter() - t0:.2f} s ({len(traj.events)} event)")
        return
    span = (0.0, args.orbits * period)
    has_events = "events" in inspect.signature(system.simulate).parameters
    never = None
    if has_events:
        never = gmuk.Event(lambda t, s: 1.0, name="never")
    print(f"| outputs | events | best of {args.repeats} (s) | steps | µs/step | n_event_rhs | "
          "events | same bits | digest |")  # fmt: skip
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for outputs in ("every step", "2001 times"):
        t_eval = None if outputs == "every step" else np.linspace(*span, 2001)
        cases = [("none", None)]
        if has_events and not args.no_events:
            cases += [("ApsisEvent both", gmuk.ApsisEvent("sat", kind="both")),
                      ("never crosses", never)]  # fmt: skip
        ref = None
        for label, event in cases:
            kw = {} if event is None else {"events": [event]}
            best = np.inf
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                traj = system.simulate(state, span, t_eval=t_eval, **kw)
                best = min(best, time.perf_counter() - t0)
            ref = ref or traj
            same = all(getattr(ref, k).tobytes() == getattr(traj, k).tobytes() for k in _ARRAYS)
            steps = traj.stats["n_steps"]
            print(
                f"| {outputs} | {label} | {best:.4f} | {steps} | {1e6 * best / steps:.1f} | "
                f"{traj.stats.get('n_event_rhs', '')} | {len(getattr(traj, 'events', ()))} | "
                f"{same} | {digest(traj)} |"
            )


if __name__ == "__main__":
    main()
