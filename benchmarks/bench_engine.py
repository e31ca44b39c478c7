"""Per-call cost of System.accelerations beside Pinocchio's constrained forward dynamics.

Run on demand (not a test):

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_engine.py [--quick]

Cases (issue #3): one body with a tracking constraint; the virtual-spacecraft pair
(6 tracking rows + 5 relative rows); n = 10, 100, 1000 free bodies with 5n sparse constraint
rows, each coupling two bodies: along a chain (the typical multibody structure) or between
random pairs (a random graph, the worst case for sparse LU, also solved by CG).
Pinocchio: ``pin.forwardDynamics(model, data, q, v, tau, J, gamma)`` with n free-flyer joints
(the same KKT problem), timed in the same run; it cannot build n = 1000 here.
Medians over repeats; prints a Markdown table.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import statistics
import time

import numpy as np
import scipy.sparse as sp

import gmuk
from gmuk.lie import se3
from gmuk.reference import ReferenceState, ReferenceTrajectory


class Screw(ReferenceTrajectory):
    """g_d(t) = exp(t ξ): constant twist, zero acceleration (a read-only constant)."""

    def __init__(self, xi):
        self.xi = np.asarray(xi, float)
        self.zero = np.zeros(6)
        self.zero.setflags(write=False)

    def evaluate(self, t):
        return ReferenceState(se3.exp(t * self.xi), self.xi, self.zero)


class SparseRows(gmuk.Constraint):
    def __init__(self, bodies, A, b):
        super().__init__(bodies)
        self.A, self.b = A, b

    def rows(self, state):
        return self.A, self.b


def per_call(fn, min_time=0.2, repeat=7):
    """Median seconds per call over ``repeat`` batches of about ``min_time`` each."""
    fn()
    n, t0 = 1, time.perf_counter()
    fn()
    dt = time.perf_counter() - t0
    n = max(1, int(min_time / max(dt, 1e-9)))
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        samples.append((time.perf_counter() - t0) / n)
    return statistics.median(samples)


def perm6():
    P = np.zeros((6, 6))
    P[:3, 3:] = P[3:, :3] = np.eye(3)  # [ω; v] ↔ [v; ω]
    return P


def pin_case(bodies, A, b, V):
    """Pinocchio forwardDynamics for free-flyers at the identity pose, twists V (n, 6)."""
    import pinocchio as pin

    model = pin.Model()
    for i, body in enumerate(bodies):
        j = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), f"ff{i}")
        model.appendBodyToJoint(
            j, pin.Inertia(body.mass, np.zeros(3), body.inertia), pin.SE3.Identity()
        )
    data = model.createData()
    n = len(bodies)
    P = np.kron(np.eye(n), perm6())
    q = pin.neutral(model)
    v = P @ V.ravel()
    tau = np.zeros(6 * n)
    J = A @ P  # columns reordered to Pinocchio's [v; ω]
    gamma = -b  # Pinocchio solves J a = −γ
    return per_call(lambda: pin.forwardDynamics(model, data, q, v, tau, J, gamma))


def chain_rows(rng, n, s):
    """Row r couples body r // 5 with the next one (a chain, as in linked multibody systems)."""
    return _rows(rng, n, s, lambda r: (min(r // 5, n - 2), min(r // 5, n - 2) + 1))


def random_rows(rng, n, s):
    """Row r couples two random bodies (a random graph: the worst case for sparse LU)."""
    return _rows(rng, n, s, lambda r: tuple(rng.choice(n, 2, replace=False)))


def _rows(rng, n, s, pair):
    rows, cols, vals = [], [], []
    for r in range(s):
        i, j = pair(r)
        idx = np.concatenate([np.arange(6 * i, 6 * i + 6), np.arange(6 * j, 6 * j + 6)])
        rows.extend([r] * 12)
        cols.extend(idx)
        vals.extend(rng.normal(size=12))
    return sp.csr_matrix((vals, (rows, cols)), shape=(s, 6 * n)), rng.normal(size=s)


def breakdown() -> None:
    """Where one call of the one-body tracking case goes (best of 9 batches of 5000)."""
    import timeit

    from gmuk.engine import _uk_kernels

    J = np.diag([3.0e4, 3.2e4, 3.4e4])
    body = gmuk.RigidBody("a", 15103.0, J)
    ref = Screw([0, 0, 1e-3, 1600.0, 0, 0])
    c = gmuk.ConfigurationTracking(body, ref)
    S = gmuk.System([body], [c])
    st = S.state(g={"a": np.eye(4)}, V={"a": ref.xi})
    A, b = S._stack_rows(st, check_finite=False)
    z = S._zero_loads
    args = (st.V, z, A, b, S.solver._params, np.empty(4 * 6 + 6 + 3))
    compiled = gmuk.engine.solvers._fused_entry()
    parts = [
        ("System.accelerations (whole call)", lambda: S.accelerations(st)),
        ("reference.evaluate (the user's)", lambda: ref.evaluate(0.3)),
        ("ConfigurationTracking.rows (incl. evaluate)", lambda: c.rows(st)),
        ("rows + checks (System._stack_rows)", lambda: S._stack_rows(st, check_finite=False)),
        ("compiled solve, numba dispatcher (uk_rigid)", lambda: _uk_kernels.uk_rigid(*args)),
        ("compiled solve, compiled entry (no dispatch)", lambda: compiled(*args)),
    ]
    for label, fn in parts:
        t = min(timeit.repeat(fn, number=5000, repeat=9)) / 5000
        print(f"{label:45s} {t * 1e6:7.2f} µs")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="skip n = 1000")
    ap.add_argument("--breakdown", action="store_true", help="time the one-body call's parts")
    args = ap.parse_args()
    if args.breakdown:
        breakdown()
        return
    rng = np.random.default_rng(0)
    J = np.diag([3.0e4, 3.2e4, 3.4e4])
    out = []

    body = gmuk.RigidBody("a", 15103.0, J)
    ref = Screw([0, 0, 1e-3, 1600.0, 0, 0])
    sys1 = gmuk.System([body], [gmuk.ConfigurationTracking(body, ref)])
    st1 = sys1.state(g={"a": np.eye(4)}, V={"a": ref.xi})
    A1, b1 = sys1.constraint_rows(st1)
    out.append(
        (
            "1 body, tracking (6 rows)",
            per_call(lambda: sys1.accelerations(st1)),
            pin_case([body], A1, b1, st1.V),
        )
    )

    L, B = gmuk.RigidBody("virtual", 15103.0, J), gmuk.RigidBody("spacecraft", 15103.0, J)
    sys2 = gmuk.System(
        [L, B], [gmuk.ConfigurationTracking(L, ref), gmuk.RelativeConstraint(B, L, free_axes=[0])]
    )
    st2 = sys2.state(
        g={"virtual": np.eye(4), "spacecraft": np.eye(4)},
        V={"virtual": ref.xi, "spacecraft": ref.xi},
    )
    A2, b2 = sys2.constraint_rows(st2)
    out.append(
        (
            "virtual pair (11 rows)",
            per_call(lambda: sys2.accelerations(st2)),
            pin_case([L, B], A2, b2, st2.V),
        )
    )

    cases = [
        (10, "chain", False),
        (10, "chain", True),
        (100, "chain", False),
        (100, "chain", True),
        (100, "random", True),
        (100, "random", True, "cg"),
    ]
    if not args.quick:
        cases += [(1000, "chain", True), (1000, "random", True, "cg")]
    for n, kind, path, *solver in cases:
        bodies = [
            gmuk.RigidBody(f"b{i}", rng.uniform(1, 5), np.diag(rng.uniform(1, 2, 3)))
            for i in range(n)
        ]
        A, b = (chain_rows if kind == "chain" else random_rows)(rng, n, 5 * n)
        names = [bd.name for bd in bodies]
        how = solver[0] if solver else "lu"
        system = gmuk.System(bodies, [SparseRows(bodies, A, b)], sparse=path, sparse_solver=how)
        st = system.state(g={k: np.eye(4) for k in names}, V={k: rng.normal(size=6) for k in names})
        t_gmuk = per_call(lambda: system.accelerations(st), repeat=5)  # noqa: B023
        t_pin = pin_case(bodies, A.toarray(), b, st.V) if (n <= 100 and path) else None
        label = f"{n} bodies, {5 * n} rows, {kind}, {'sparse ' + how if path else 'dense'}"
        out.append((label, t_gmuk, t_pin))

    print("| case | gmuk (µs) | Pinocchio (µs) | gmuk / Pinocchio |")
    print("|---|---:|---:|---:|")
    for name, tg, tp in out:
        ratio = f"{tg / tp:.2f}" if tp else "—"
        tp_s = f"{tp * 1e6:.1f}" if tp else "—"
        print(f"| {name} | {tg * 1e6:.1f} | {tp_s} | {ratio} |")


if __name__ == "__main__":
    main()
