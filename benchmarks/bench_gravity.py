"""Spherical-harmonic gravity: gmuk.gravity beside pyshtools' MakeGravGridPoint, same run.

Run on demand (not a test):

    python benchmarks/bench_gravity.py [--quick]

The script sets OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1 itself, before numpy is
imported, so that neither numpy nor pyshtools starts BLAS threads.

Fields: GRGM660PRIM truncated to degrees 10 and 50, and to 150 (the whole file shipped
with gmuk, ``gmuk.gravity.load("GRGM660PRIM")``); degree 660 is synthetic (Kaula rule
C̄, S̄ ~ N(0, (10⁻⁵/n²)²), seeded). Points lie 50-500 km above the Moon (reference radius 1738 km).

Single point, at one fixed position 200 km up:

* gmuk ``field.acceleration(r_F)`` (a float64 array of shape (3,));
* gmuk ``field.acceleration_hessian(r_F)`` (acceleration and Hessian in one pass; the
  ``acc + Hessian`` column and the ratio), and the same request through
  ``field.evaluate(r_F, potential=False, hessian=True)`` (which calls it);
* pyshtools ``pyshtools.gravmag.MakeGravGridPoint(cilm, gm, r0, r, lat, lon)`` with the
  spherical coordinates computed outside the timing, twice: with ``cilm`` a C-ordered
  array (``np.array([C, S])``, what ``SHCoeffs.coeffs`` is; f2py copies it into Fortran
  order on every call) and with a Fortran-ordered copy made once (no per-call copy). The
  faster of the two is the one the targets are judged against.

Batch: 1000 random points at degree 150: one gmuk call on a (1000, 3) array against a
Python loop of 1000 pyshtools calls (spherical coordinates precomputed).

Per-call floor: what a compiled call from Python costs on this machine whatever the
degree (an empty numba function with the signature of gmuk's single-point kernel, through
numba's dispatcher and through the compiled entry gmuk uses; the allocation of the result
array; ``np.array(r_F)``, an input copy the single-point path avoids, for comparison),
gmuk's compiled acceleration entry alone and the whole method at degrees 0 and 10, and
pyshtools at degree 0.

Agreement: every row's gmuk acceleration is compared with pyshtools' (converted from
(r, θ, φ) components to Cartesian, same sign convention a = +∇U) at 20 random points; the
largest relative difference is printed.

Timing: each case's number of calls is chosen by ``timeit``'s ``autorange`` (≥ 0.2 s per
run); then ``repeat`` rounds run every case once in turn (interleaved, so that a change of
load on a busy machine hits every case alike), and each figure is the median over the
rounds. numba kernels are loaded (compiled if need be) and called once before timing.
"""

from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import platform
import statistics
import subprocess
import timeit
from pathlib import Path

import numba
import numpy as np
import pyshtools as pysh
from numba import njit, types

from gmuk.gravity import MOON_MU, MOON_RADIUS, SphericalHarmonicField, _kernels, load

BATCH = 1000
DEGREES = (10, 50, 150, 660)
#: Basilisk's spherical-harmonic model on this machine, as quoted in the issue (not run here).
BASILISK = {10: 3e-6, 50: 15e-6, 150: 145e-6, 660: 3.4e-3}


def fmt(seconds: float) -> str:
    if seconds < 1e-6:
        return f"{seconds * 1e9:.0f} ns"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.2f} µs"
    return f"{seconds * 1e3:.2f} ms"


def kaula_field(N: int, seed: int = 0, amplitude: float = 1e-5) -> SphericalHarmonicField:
    """Synthetic lunar field: C̄, S̄ ~ N(0, (amplitude/n²)²) for 2 ≤ n ≤ N, C̄₀₀ = 1."""
    rng = np.random.default_rng(seed)
    C = np.zeros((N + 1, N + 1))
    S = np.zeros((N + 1, N + 1))
    n, m = np.tril_indices(N + 1)
    keep = n >= 2
    sd = amplitude / n[keep] ** 2
    C[n[keep], m[keep]] = rng.normal(0.0, sd)
    S[n[keep], m[keep]] = np.where(m[keep] > 0, rng.normal(0.0, sd), 0.0)
    C[0, 0] = 1.0
    return SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S, name=f"Kaula-{N}-{seed}")


def spherical(r: np.ndarray) -> tuple[float, float, float]:
    """(|r| in m, latitude in degrees, longitude in degrees) of a Cartesian point."""
    x, y, z = (float(v) for v in r)
    rn = float(np.sqrt(x * x + y * y + z * z))
    return rn, float(np.degrees(np.arcsin(z / rn))), float(np.degrees(np.arctan2(y, x)))


def pysh_cartesian(g: np.ndarray, lat: float, lon: float) -> np.ndarray:
    """pyshtools' (g_r, g_θ, g_φ) (θ colatitude) as Cartesian components."""
    th, ph = np.radians(90.0 - lat), np.radians(lon)
    e_r = np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
    e_th = np.array([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)])
    e_ph = np.array([-np.sin(ph), np.cos(ph), 0.0])
    return g[0] * e_r + g[1] * e_th + g[2] * e_ph


def points(rng: np.random.Generator, k: int) -> np.ndarray:
    """k random body-fixed points 50-500 km above the reference sphere (m), shape (k, 3)."""
    u = rng.normal(size=(k, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    return u * (MOON_RADIUS + rng.uniform(50e3, 500e3, size=k))[:, None]


def agreement(field: SphericalHarmonicField, cilm: np.ndarray, pts: np.ndarray) -> float:
    """Largest |a_gmuk − a_pyshtools| / |a| over the points."""
    worst = 0.0
    for r in pts:
        rn, lat, lon = spherical(r)
        g = pysh.gravmag.MakeGravGridPoint(cilm, field.mu, field.radius, rn, lat, lon)
        a = field.acceleration(r)
        worst = max(
            worst, float(np.linalg.norm(a - pysh_cartesian(g, lat, lon))) / float(np.linalg.norm(a))
        )
    return worst


def measure(cases: dict[str, object], repeat: int) -> dict[str, float]:
    """Median seconds per call of each case, rounds interleaved across the cases."""
    timers = {}
    for name, fn in cases.items():
        timer = timeit.Timer(fn)  # type: ignore[arg-type]
        number, _ = timer.autorange()  # enough calls for ≥ 0.2 s per run
        timers[name] = (timer, number)
    samples: dict[str, list[float]] = {name: [] for name in cases}
    for _ in range(repeat):
        for name, (timer, number) in timers.items():
            samples[name].append(timer.timeit(number) / number)
    return {name: statistics.median(v) for name, v in samples.items()}


_RO = types.Array(types.float64, 1, "C", readonly=True)
_RA = types.Array(types.float64, 1, "A", readonly=True)
_RW = types.Array(types.float64, 1, "C")


@njit(types.int64(_RO, _RA, _RW, types.boolean))
def _empty_kernel(d, r, out, central):  # type: ignore[no-untyped-def]
    """Does nothing; same signature as gmuk's single-point acceleration kernel."""
    return 0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 rounds instead of 9")
    args = parser.parse_args()
    repeat = 3 if args.quick else 9

    grail = load("GRGM660PRIM")
    fields = {N: (grail.truncate(N) if N < grail.degree else grail) for N in DEGREES[:3]}
    fields[660] = kaula_field(660, seed=0)
    rng = np.random.default_rng(0)
    r1 = np.array([0.6, -0.5, 0.62])
    r1 *= (MOON_RADIUS + 200e3) / np.linalg.norm(r1)  # 200 km up, latitude ≈ 38°
    rn1, lat1, lon1 = spherical(r1)
    check_pts = points(rng, 20)
    batch_pts = points(rng, BATCH)
    batch_sph = [spherical(r) for r in batch_pts]

    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
            cwd=Path(__file__).resolve().parent,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    print(
        f"numpy {np.__version__}, numba {numba.__version__}, pyshtools {pysh.__version__}, "
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs, commit {commit}"
    )
    print("OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 (set by this script)")
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    print(f"median of {repeat} interleaved timeit rounds\n")

    # ------------------------------------------------------------------ single point
    rows = []
    for N in DEGREES:
        f = fields[N]
        cilm_c = np.array([f.C, f.S])
        cilm_f = np.asfortranarray(cilm_c)
        mu, R = f.mu, f.radius
        # warm up (loads the compiled kernels) and check both libraries agree
        f.acceleration(r1)
        f.acceleration_hessian(r1)
        err = agreement(f, cilm_f, check_pts)
        t = measure(
            {
                "acc": lambda f=f: f.acceleration(r1),
                "acc+H": lambda f=f: f.acceleration_hessian(r1),
                "evaluate acc+H": lambda f=f: f.evaluate(r1, potential=False, hessian=True),
                "pysh C": lambda c=cilm_c, mu=mu, R=R: pysh.gravmag.MakeGravGridPoint(
                    c, mu, R, rn1, lat1, lon1
                ),
                "pysh F": lambda c=cilm_f, mu=mu, R=R: pysh.gravmag.MakeGravGridPoint(
                    c, mu, R, rn1, lat1, lon1
                ),
            },
            repeat,
        )
        rows.append((N, t, err))
        print(f"degree {N}: measured", flush=True)

    # ------------------------------------------------------------------ batch of 1000
    f = fields[150]
    cilm_c = np.array([f.C, f.S])
    cilm_f = np.asfortranarray(cilm_c)
    mu, R = f.mu, f.radius
    f.acceleration(batch_pts)
    tb = measure(
        {
            "acc": lambda: f.acceleration(batch_pts),
            "acc+H": lambda: f.acceleration_hessian(batch_pts),
            "pysh C": lambda: [
                pysh.gravmag.MakeGravGridPoint(cilm_c, mu, R, rn, la, lo)
                for rn, la, lo in batch_sph
            ],
            "pysh F": lambda: [
                pysh.gravmag.MakeGravGridPoint(cilm_f, mu, R, rn, la, lo)
                for rn, la, lo in batch_sph
            ],
        },
        repeat,
    )
    print("batch: measured", flush=True)

    # ------------------------------------------------------------------ per-call floor
    f0 = grail.truncate(0)
    d0 = np.zeros(8)  # any read-only float64 vector: the empty kernel does not read it
    d0.setflags(write=False)
    cilm0 = np.asfortranarray(np.array([f0.C, f0.S]))
    # (``entry`` is absent before gmuk's single-point fast path; the row is then skipped)
    entry = getattr(_kernels, "entry", None)
    buf = np.empty(3)
    _empty_kernel(d0, r1, buf, True)
    f0.acceleration(r1)
    floor = {
        "np.array(r_F)": lambda: np.array(r1),
        "np.empty(3)": lambda: np.empty(3),
        "empty compiled call, numba dispatcher": lambda: _empty_kernel(d0, r1, buf, True),
    }
    if entry is not None:
        empty_entry = entry(_empty_kernel)
        floor["empty compiled call, compiled entry"] = lambda: empty_entry(d0, r1, buf, True)
        acc_entry = _kernels.ENTRIES.acceleration_at
        d10 = fields[10]._data
        floor["gmuk's compiled acceleration entry alone, degree 0"] = lambda: acc_entry(
            f0._data, r1, buf, True
        )
        floor["gmuk's compiled acceleration entry alone, degree 10"] = lambda: acc_entry(
            d10, r1, buf, True
        )
    floor["gmuk acceleration, degree 0"] = lambda: f0.acceleration(r1)
    floor["gmuk acceleration, degree 10"] = lambda: fields[10].acceleration(r1)
    floor["pyshtools MakeGravGridPoint, degree 0"] = lambda: pysh.gravmag.MakeGravGridPoint(
        cilm0, mu, R, rn1, lat1, lon1
    )
    tf = measure(floor, repeat)
    print(f"load average at end: {os.getloadavg()[0]:.2f}\n")

    print(
        "| degree | gmuk acceleration | gmuk acc + Hessian | (acc+H) / acc | same via evaluate "
        "| pyshtools, C-ordered cilm | pyshtools, Fortran-ordered cilm "
        "| gmuk / faster pyshtools | Basilisk (issue) | max rel. diff. vs pyshtools |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for N, t, err in rows:
        fast = min(t["pysh C"], t["pysh F"])
        print(
            f"| {N} | {fmt(t['acc'])} | {fmt(t['acc+H'])} | {t['acc+H'] / t['acc']:.2f} "
            f"| {fmt(t['evaluate acc+H'])} "
            f"| {fmt(t['pysh C'])} | {fmt(t['pysh F'])} | {t['acc'] / fast:.2f} "
            f"| {fmt(BASILISK[N])} | {err:.1e} |"
        )
    fast = min(tb["pysh C"], tb["pysh F"])
    print(
        f"| 150, ×{BATCH} | {fmt(tb['acc'])} | {fmt(tb['acc+H'])} "
        f"| {tb['acc+H'] / tb['acc']:.2f} | — | {fmt(tb['pysh C'])} (loop) "
        f"| {fmt(tb['pysh F'])} (loop) | {tb['acc'] / fast:.2f} | — | — |"
    )
    print("\nPer-call floor (same run):\n")
    print("| call | median |")
    print("|---|---:|")
    for name, v in tf.items():
        print(f"| {name} | {fmt(v)} |")


if __name__ == "__main__":
    main()
