"""Per-call cost of gmuk.lie.se3 and Eq. 10b beside the same operations in Pinocchio.

Run on demand (not a test):

    python benchmarks/bench_lie.py [--quick]

The script sets OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1 itself, before numpy is
imported, so that neither numpy nor Pinocchio starts BLAS threads.

Single calls: ``se3.exp``, ``se3.log``, ``se3.Ad``, ``se3.dexp_inv`` and
``dynamics.free_acceleration`` (one body) against ``pin.exp6``, ``pin.log6``,
``SE3.action``, ``pin.Jlog6`` and ``pin.aba`` on a one-body free-flyer model, each called the
ordinary way from Python (numpy arrays in for gmuk; ndarray or ``pin.SE3`` in for Pinocchio,
built once outside the timing). Batches: one gmuk call on 1000 elements against a Python loop
of 1000 Pinocchio calls. Each figure is the median over ``repeat`` runs of ``timeit`` with an
automatically chosen number of calls. Prints a Markdown table; the ratio is gmuk / Pinocchio
(above 1: gmuk is slower).
"""

from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import platform
import statistics
import timeit

import numpy as np
import pinocchio as pin

from gmuk.dynamics import free_acceleration, spatial_inertia
from gmuk.lie import se3

BATCH = 1000
SWAP = np.array([3, 4, 5, 0, 1, 2])  # [ω; v] ↔ [v; ω]


def per_call(fn, repeat):
    """Median seconds per call of ``fn`` over ``repeat`` timeit runs."""
    timer = timeit.Timer(fn)
    number, _ = timer.autorange()  # enough calls for ≥ 0.2 s per run
    return statistics.median(t / number for t in timer.repeat(repeat=repeat, number=number))


def fmt(seconds):
    if seconds < 1e-6:
        return f"{seconds * 1e9:.0f} ns"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.2f} µs"
    return f"{seconds * 1e3:.2f} ms"


def free_flyer(mass, J):
    model = pin.Model()
    model.gravity = pin.Motion.Zero()
    jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "body")
    model.appendBodyToJoint(jid, pin.Inertia(mass, np.zeros(3), J), pin.SE3.Identity())
    return model, model.createData()


def cases(rng):
    """(name, gmuk callable, Pinocchio callable) for single calls and 1000-element batches."""
    xi = np.concatenate([rng.normal(size=3), 10.0 * rng.normal(size=3)])
    g = se3.exp(xi)
    M = pin.SE3(g[:3, :3].copy(), g[:3, 3].copy())
    xi_pin = xi[SWAP].copy()

    m, J = 500.0, np.diag([100.0, 200.0, 250.0])
    I = spatial_inertia(m, J)
    V = rng.normal(size=6)
    tau = rng.normal(size=6)
    model, data = free_flyer(m, J)
    q = np.concatenate([g[:3, 3], pin.Quaternion(g[:3, :3].copy()).coeffs()])
    v_pin, tau_pin = V[SWAP].copy(), tau[SWAP].copy()

    Xi = np.concatenate([rng.normal(size=(BATCH, 3)), 10.0 * rng.normal(size=(BATCH, 3))], 1)
    G = se3.exp(Xi)
    Ms = [pin.SE3(Gk[:3, :3].copy(), Gk[:3, 3].copy()) for Gk in G]
    Xi_pin = [x[SWAP].copy() for x in Xi]
    Vs = rng.normal(size=(BATCH, 6))
    Taus = rng.normal(size=(BATCH, 6))
    Vs_pin = [x[SWAP].copy() for x in Vs]
    Taus_pin = [x[SWAP].copy() for x in Taus]

    single = [
        ("exp", lambda: se3.exp(xi), lambda: pin.exp6(xi_pin)),
        ("log", lambda: se3.log(g), lambda: pin.log6(M)),
        ("Ad", lambda: se3.Ad(g), lambda: M.action),
        ("dexp_inv / Jlog6", lambda: se3.dexp_inv(xi), lambda: pin.Jlog6(M)),
        (
            "Eq. 10b / aba",
            lambda: free_acceleration(V, I, tau),
            lambda: pin.aba(model, data, q, v_pin, tau_pin),
        ),
    ]
    batch = [
        ("exp", lambda: se3.exp(Xi), lambda: [pin.exp6(x) for x in Xi_pin]),
        ("log", lambda: se3.log(G), lambda: [pin.log6(Mk) for Mk in Ms]),
        ("Ad", lambda: se3.Ad(G), lambda: [Mk.action for Mk in Ms]),
        ("dexp_inv / Jlog6", lambda: se3.dexp_inv(Xi), lambda: [pin.Jlog6(Mk) for Mk in Ms]),
        (
            "Eq. 10b / aba",
            lambda: free_acceleration(Vs, I, Taus),
            lambda: [
                pin.aba(model, data, q, vk, tk) for vk, tk in zip(Vs_pin, Taus_pin, strict=True)
            ],
        ),
    ]
    return single, batch


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 repeats instead of 9")
    args = parser.parse_args()
    repeat = 3 if args.quick else 9

    rng = np.random.default_rng(0)
    single, batch = cases(rng)
    for _, ours, theirs in single + batch:  # warm-up: load the compiled kernels
        ours()
        theirs()

    py = platform.python_version()
    print(f"numpy {np.__version__}, pinocchio {pin.__version__}, Python {py}")
    print("OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 (set by this script)")
    print(f"median of {repeat} timeit runs\n")
    print("| operation | gmuk | Pinocchio | ratio gmuk/pin |")
    print("|---|---:|---:|---:|")
    rows = [(name, "", ours, theirs) for name, ours, theirs in single]
    rows += [(name, f" ×{BATCH}", ours, theirs) for name, ours, theirs in batch]
    for name, suffix, ours, theirs in rows:
        t_ours, t_theirs = per_call(ours, repeat), per_call(theirs, repeat)
        print(f"| {name}{suffix} | {fmt(t_ours)} | {fmt(t_theirs)} | {t_ours / t_theirs:.2f} |")


if __name__ == "__main__":
    main()
