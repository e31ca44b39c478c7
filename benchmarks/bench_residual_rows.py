"""Residual-defined constraints against hand-written rows: whole-run wall time (issue #26).

Two Systems, each run with the constraint written as a residual only (gmuk derives A and b)
and with analytic ``jacobian`` / ``bias`` overrides (the same physics, the same tolerances):

* ``readme``: the README's pendulum (``Pinned``, a rigid body hanging from a pin 0.5 m along
  its axis 3, uniform gravity), 10 s, 501 output times, default tolerances;
* ``tutorial1``: tutorial 1's System (``examples/tutorials/t1_holonomic_constraint.py``),
  20 s, 101 output times, ``rtol=1e-10, atol=1e-12``.

The variants run alternately, ``--repeats`` times each, after one warm-up run each; the
medians are printed with the ratio residual/analytic. When the installed gmuk offers
``derivatives="fd"`` (the finite differences), that variant is timed too. Usage::

    python benchmarks/bench_residual_rows.py             # 7 alternating repeats
    python benchmarks/bench_residual_rows.py --quick     # 3 repeats, runs of a tenth

The thread counts are pinned to one at the top of this file, before numpy is imported.
"""

from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import inspect
import runpy
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk.lie import so3

ROOT = Path(__file__).resolve().parents[1]
P_B = np.array([0.0, 0.0, 0.5])  # m, body frame: the pin of both Systems


class Pinned(gmuk.HolonomicConstraint):
    """The README's residual, as it stands: φ = R_NB p_B + r_N (m)."""

    def residual(self, q: Any, t: float) -> Any:
        (g_NB,) = q
        return g_NB[:3, :3] @ [0.0, 0.0, 0.5] + g_NB[:3, 3]


class PinnedAnalytic(Pinned):
    """The same constraint with exact rows: A = R_NB [−[p_B]×, I₃], b = −R_NB ω × (ω × p_B + v)."""

    def jacobian(self, q: Any, t: float) -> Any:
        (g,) = q
        return g[:3, :3] @ np.hstack([-so3.hat(P_B), np.eye(3)])

    def bias(self, q: Any, nu: Any, t: float) -> Any:
        (g,), (V,) = q, nu
        return -g[:3, :3] @ np.cross(V[:3], np.cross(V[:3], P_B) + V[3:])


def _has_fd_option() -> bool:
    return "derivatives" in inspect.signature(gmuk.HolonomicConstraint.__init__).parameters


def readme_case(variant: str, duration: float) -> Callable[[], object]:
    """The README pendulum with the constraint of ``variant``; returns the timed call."""
    bob = gmuk.RigidBody("bob", mass=2.0, inertia=np.diag([0.10, 0.12, 0.05]))
    if variant == "analytic":
        pin = PinnedAnalytic([bob])
    elif variant == "fd":
        pin = Pinned([bob], derivatives="fd")  # type: ignore[call-arg]
    else:
        pin = Pinned([bob])
    system = gmuk.System([bob], [pin], [gmuk.UniformGravity()])
    g0 = np.eye(4)
    g0[:3, 3] = [0.0, 0.0, -0.5]
    w0 = np.array([2.0, 0.0, 5.0])
    state = system.state(g={"bob": g0}, V={"bob": np.r_[w0, -np.cross(w0, P_B)]})
    t_eval = np.linspace(0.0, duration, 501)
    return lambda: system.simulate(state, (0.0, duration), t_eval=t_eval)


def tutorial1_case(variant: str, duration: float) -> Callable[[], object]:
    """Tutorial 1's System with the constraint of ``variant``; returns the timed call."""
    t1 = runpy.run_path(str(ROOT / "examples" / "tutorials" / "t1_holonomic_constraint.py"))
    if variant == "analytic":
        cls = t1["PinnedAnalytic"]
    elif variant == "fd":
        base = t1["Pinned"]

        class PinnedFD(base):  # type: ignore[valid-type, misc]
            def __init__(self, body: Any, p_B: Any) -> None:
                gmuk.HolonomicConstraint.__init__(self, [body], derivatives="fd")  # type: ignore[call-arg]
                self.p_B = np.asarray(p_B, dtype=float)

        cls = PinnedFD
    else:
        cls = t1["Pinned"]
    system, state = t1["pendulum"](cls)
    t_eval = np.linspace(0.0, duration, 101)
    return lambda: system.simulate(state, (0.0, duration), t_eval=t_eval, rtol=1e-10, atol=1e-12)


def measure(
    case: Callable[[str, float], Callable[[], object]],
    variants: list[str],
    duration: float,
    repeats: int,
) -> dict[str, float]:
    """Median wall time (s) of each variant, run alternately ``repeats`` times."""
    calls = {v: case(v, duration) for v in variants}
    for call in calls.values():
        call()  # warm-up: compiled loop loaded, caches filled
    times: dict[str, list[float]] = {v: [] for v in variants}
    for _ in range(repeats):
        for v in variants:
            t0 = time.perf_counter()
            calls[v]()
            times[v].append(time.perf_counter() - t0)
    return {v: statistics.median(ts) for v, ts in times.items()}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 repeats of runs a tenth long")
    parser.add_argument("--repeats", type=int, default=None)
    args = parser.parse_args(argv)
    repeats = args.repeats or (3 if args.quick else 7)
    scale = 0.1 if args.quick else 1.0
    variants = ["residual", "analytic"] + (["fd"] if _has_fd_option() else [])
    for label, case, duration in (
        ("readme", readme_case, 10.0 * scale),
        ("tutorial1", tutorial1_case, 20.0 * scale),
    ):
        med = measure(case, variants, duration, repeats)
        parts = ", ".join(f"{v} {med[v]:.3f} s" for v in variants)
        ratio = med["residual"] / med["analytic"]
        extra = f", fd/analytic {med['fd'] / med['analytic']:.2f}" if "fd" in med else ""
        print(
            f"{label} ({duration:g} s, medians of {repeats}): {parts}; "
            f"residual/analytic {ratio:.2f}{extra}"
        )


if __name__ == "__main__":
    main()
