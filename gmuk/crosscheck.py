"""Cross-check gmuk's hand-written SE(3) operators and dynamics against Pinocchio.

gmuk writes its Lie-group operators and rigid-body dynamics by hand (McCann 2020, Chapter 2);
Pinocchio (``import pinocchio as pin``, a runtime dependency) implements the same quantities
independently. :func:`check` evaluates both on seeded random inputs and reports, per
quantity, the worst disagreement against a tolerance; ``gmuk check`` prints that table and
exits 1 if any quantity fails. Run it after installing gmuk on a new machine, or after
changing an operator.

>>> import gmuk
>>> report = gmuk.check(seed=0, n=20)  # doctest: +SKIP
>>> report.ok  # doctest: +SKIP
True

Orderings
---------
gmuk orders twists ``V = [ω; v]``, wrenches ``τ = [L; f]`` and exponential coordinates
``ξ = [θ; ρ]`` angular first (McCann 2020, Eq. 9); Pinocchio orders motions and forces linear
first. Every conversion between the two goes through :func:`_swap_vec` and :func:`_swap_op`
(the permutation ``P = [[0, I₃], [I₃, 0]]``, symmetric and its own inverse), here and in
the test suite's cross-checks (``tests/cross_checks/pin_helpers.py`` imports them).

What is compared
----------------
=====================  =====================================================================
gmuk                   Pinocchio
=====================  =====================================================================
``so3.hat``            ``pin.skew``
``so3.exp``, ``log``   ``pin.exp3``, ``pin.log3``
``se3.hat``, ``vee``   ``pin.Motion.homogeneous``; ``pin.unSkew`` and the last column
``se3.exp``, ``log``   ``pin.exp6``, ``pin.log6``
``se3.inverse``        ``pin.SE3.inverse``
``se3.Ad``             ``pin.SE3.action``
``se3.ad``             ``pin.Motion.action``
``se3.ad_star``        ``−pin.Motion.dualAction`` (gmuk's ad*_V = +ad_Vᵀ, Eq. 15;
                       Pinocchio's dual action is the force cross product −ad_Vᵀ)
``se3.dexp``           ``pin.Jexp6`` at ξ (right Jacobian: exp(ξ + δ) ≈ exp(ξ) exp(Jδ))
``se3.dexp_inv``       ``pin.Jlog6`` at exp(ξ) (its inverse, ξ̇ = dexp_inv(ξ) V)
``free_acceleration``  ``pin.aba`` of one free-flyer body with its centre of mass at the joint
                       (Eq. 10b; joint velocity = body twist, joint torque = body wrench)
``System`` (UK)        ``pin.forwardDynamics(model, data, q, v, τ, J, γ)`` of 1–3 free-flyer
                       bodies with random rows ``A ν̇ = b``: J = A reordered, γ = −b (Eq. 64);
                       the multipliers λ of Eq. 3 against ``data.lambda_c``
=====================  =====================================================================

The error of one sample is ``max|gmuk − Pinocchio| / max(1, max|Pinocchio|)`` over the
entries: absolute for values below 1, relative above. A row reports the worst sample.

Samples. Rotation angles θ = ‖θ‖ are drawn from [0, 1e-6] (one sample in five) and
[0.2, 3.0]; translations have magnitudes 0.1–1000 m, twists 0.01–100. Pinocchio 4.1 is
itself inaccurate outside those ranges: its ``Jexp6`` and ``Jlog6`` err by up to 2e-5 for
θ ∈ [1e-4, 1e-2] and still 2e-12 at θ ≈ 0.05 (gmuk's ``dexp`` there agrees with a 40-digit
series to 2e-16), its ``log6``, ``log3`` and ``Jlog6`` by up to 3e-11 for θ ∈ [3.0, π);
gmuk's accuracy at every angle is tested against multi-precision references in ``tests/``.
Within the ranges the two agree to round-off: over 20 seeds of 1000 samples the worst
Lie-group error is 3e-14, a three-hundredth of their tolerance 1e-11. The dynamics rows have
1e-10: the constrained solves (1e-11 worst over the same seeds) go through factorisations
of KKT systems whose bodies' masses differ by up to 1e4.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.errors import DefinitionError

if TYPE_CHECKING:
    import pinocchio as pin

__all__ = ["CheckReport", "CheckRow", "check"]

#: Tolerance of the Lie-group rows and of the dynamics rows (error as defined above).
LIE_TOL = 1e-11
DYNAMICS_TOL = 1e-10

#: The most samples :func:`check` takes per quantity (its inputs and Pinocchio's objects
#: are held in memory: about 1 KiB a sample).
MAX_SAMPLES = 1_000_000

#: Permutation [ω; v] ↔ [v; ω] as an index array (applied on the last axis).
_SWAP = np.array([3, 4, 5, 0, 1, 2])


def _swap_vec(x: Any) -> FloatArray:
    """Reorder 6-vectors between [angular; linear] (gmuk) and [linear; angular] (Pinocchio),
    on the last axis; the same call converts either way."""
    return np.asarray(x, dtype=float)[..., _SWAP]


def _swap_op(A: Any) -> FloatArray:
    """Reorder a 6×6 operator between the two orderings: ``P A P`` with P the swap."""
    return np.asarray(A, dtype=float)[..., _SWAP, :][..., :, _SWAP]


def _to_pin_se3(g: Any) -> pin.SE3:
    """A 4×4 homogeneous matrix as a ``pin.SE3`` (no reordering is involved)."""
    import pinocchio as pin

    g = np.asarray(g, dtype=float)
    return pin.SE3(g[:3, :3].copy(), g[:3, 3].copy())


def _from_pin_se3(M: pin.SE3) -> FloatArray:
    """A ``pin.SE3`` as a 4×4 homogeneous matrix."""
    return np.array(M.homogeneous)


def _q_from_g(g: Any) -> FloatArray:
    """Free-flyer configuration ``[translation; quaternion (x, y, z, w)]`` of a pose g_NB."""
    import pinocchio as pin

    g = np.asarray(g, dtype=float)
    quat = pin.Quaternion(g[:3, :3].copy())
    return np.concatenate([g[:3, 3], quat.coeffs()])


def _free_flyer_model(
    bodies: Sequence[tuple[float, FloatArray]],
) -> tuple[pin.Model, pin.Data]:
    """A Pinocchio model of rigid bodies, each on its own free-flyer joint, without gravity.

    ``bodies`` gives (mass (kg), inertia J (kg·m²) about the centre of mass, body axes). The
    centre of mass is at the joint origin, so each joint frame is gmuk's body frame B and
    its joint velocity ``[v; ω]`` is the body twist in Pinocchio's order.
    """
    import pinocchio as pin

    model = pin.Model()
    model.gravity = pin.Motion.Zero()
    for i, (mass, J) in enumerate(bodies):
        jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), f"free_flyer_{i}")
        inertia = pin.Inertia(float(mass), np.zeros(3), np.asarray(J, dtype=float))
        model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
    return model, model.createData()


@dataclass(frozen=True)
class CheckRow:
    """One compared quantity.

    Attributes
    ----------
    quantity : str
        The gmuk function, e.g. ``"se3.Ad"``.
    reference : str
        The Pinocchio function it is compared with.
    samples : int
    error : float
        Worst ``max|gmuk − Pinocchio| / max(1, max|Pinocchio|)`` over the samples
        (``inf`` if gmuk raised).
    tolerance : float
    worst_sample : int
        Index of the sample with that error (−1 if gmuk raised).
    note : str
        Why the row failed when the error is not a number (the exception gmuk raised).
    """

    quantity: str
    reference: str
    samples: int
    error: float
    tolerance: float
    worst_sample: int = -1
    note: str = ""

    @property
    def ok(self) -> bool:
        """Whether the worst error is within the tolerance (NaN fails)."""
        return bool(self.error <= self.tolerance)


@dataclass(frozen=True)
class CheckReport:
    """Result of :func:`check`: one :class:`CheckRow` per quantity.

    ``report.ok`` is True when every row passes; ``str(report)`` is the table that
    ``gmuk check`` prints.
    """

    rows: tuple[CheckRow, ...]
    seed: int
    n: int
    pinocchio_version: str
    elapsed_s: float

    @property
    def ok(self) -> bool:
        """Whether every quantity agrees with Pinocchio within its tolerance."""
        return all(row.ok for row in self.rows)

    @property
    def failed(self) -> tuple[CheckRow, ...]:
        """The rows that fail."""
        return tuple(row for row in self.rows if not row.ok)

    def __str__(self) -> str:
        head = ("quantity", "Pinocchio reference", "samples", "worst error", "tolerance", "")
        body = [
            (
                r.quantity,
                r.reference,
                str(r.samples),
                f"{r.error:.2e}",
                f"{r.tolerance:.0e}",
                "pass" if r.ok else "FAIL" + (f" ({r.note})" if r.note else ""),
            )
            for r in self.rows
        ]
        widths = [max(len(line[i]) for line in (head, *body)) for i in range(len(head) - 1)]

        def fmt(line: tuple[str, ...]) -> str:
            cells = [
                c.ljust(w) if i < 2 else c.rjust(w)
                for i, (c, w) in enumerate(zip(line, widths, strict=False))
            ]
            return "  ".join([*cells, line[-1]]).rstrip()

        rule = "  ".join("-" * w for w in widths) + "  ----"
        verdict = (
            f"all {len(self.rows)} quantities agree with Pinocchio"
            if self.ok
            else f"{len(self.failed)} of {len(self.rows)} quantities FAIL: "
            + ", ".join(r.quantity for r in self.failed)
        )
        lines = [
            f"gmuk against Pinocchio {self.pinocchio_version}, seed {self.seed}, "
            f"{self.n} samples per quantity ({self.elapsed_s:.2f} s)",
            "worst error: max |gmuk - Pinocchio| / max(1, max |Pinocchio|) over the samples",
            "",
            fmt(head),
            rule,
            *(fmt(line) for line in body),
            "",
            verdict,
        ]
        return "\n".join(lines)


def _error(ours: Any, theirs: Any) -> float:
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    if ours.shape != theirs.shape:
        return math.inf
    return float(np.abs(ours - theirs).max() / max(1.0, float(np.abs(theirs).max())))


def _unit_vectors(rng: np.random.Generator, n: int) -> FloatArray:
    e = rng.normal(size=(n, 3))
    return e / np.linalg.norm(e, axis=1, keepdims=True)


def _rotation_vectors(rng: np.random.Generator, n: int) -> FloatArray:
    """θ e with θ in [0, 1e-6] for one sample in five, else in [0.2, 3.0] (module doc)."""
    small = rng.uniform(size=n) < 0.2
    theta = np.where(small, rng.uniform(0.0, 1e-6, n), rng.uniform(0.2, 3.0, n))
    return theta[:, None] * _unit_vectors(rng, n)


def _exp_coords(rng: np.random.Generator, n: int) -> FloatArray:
    """[θ; ρ] with θ as in :func:`_rotation_vectors` and |ρ| log-uniform in [0.1, 1000] m."""
    rho = _unit_vectors(rng, n) * 10.0 ** rng.uniform(-1.0, 3.0, (n, 1))
    return np.concatenate([_rotation_vectors(rng, n), rho], axis=1)


def _twists(rng: np.random.Generator, n: int) -> FloatArray:
    return rng.normal(size=(n, 6)) * 10.0 ** rng.uniform(-2.0, 2.0, (n, 1))


def _random_body(rng: np.random.Generator) -> tuple[float, FloatArray]:
    """Mass 0.1–1000 kg; principal moments m k² (k² ∈ [0.01, 9] m²) meeting the triangle
    inequality, on random axes."""
    import pinocchio as pin

    m = float(10.0 ** rng.uniform(-1.0, 3.0))
    a, b = m * rng.uniform(0.01, 9.0, size=2)
    c = max(rng.uniform(abs(a - b), a + b), 1e-2 * m)
    R = pin.exp3(_rotation_vectors(rng, 1)[0])
    return m, R @ np.diag([a, b, c]) @ R.T


def _lie_cases(rng: np.random.Generator, n: int) -> list[tuple[str, str, Callable[[int], Any]]]:
    """(quantity, reference, function of the sample index → (gmuk value, Pinocchio value))."""
    import pinocchio as pin

    from gmuk.lie import se3, so3

    w = _rotation_vectors(rng, n)
    xi = _exp_coords(rng, n)
    V, W = _twists(rng, n), _twists(rng, n)
    G = [_from_pin_se3(pin.exp6(pin.Motion(_swap_vec(x)))) for x in xi]
    Rs = [pin.exp3(x) for x in w]

    def motion(k: int) -> pin.Motion:
        return pin.Motion(_swap_vec(V[k]))

    def vee_reference(k: int) -> FloatArray:
        X = motion(k).homogeneous
        return np.concatenate([pin.unSkew(X[:3, :3]), X[:3, 3]])

    return [
        ("so3.hat", "pin.skew", lambda k: (so3.hat(w[k]), pin.skew(w[k]))),
        ("so3.exp", "pin.exp3", lambda k: (so3.exp(w[k]), pin.exp3(w[k]))),
        ("so3.log", "pin.log3", lambda k: (so3.log(Rs[k]), pin.log3(Rs[k]))),
        ("se3.hat", "pin.Motion.homogeneous", lambda k: (se3.hat(V[k]), motion(k).homogeneous)),
        (
            "se3.vee",
            "pin.unSkew, last column",
            lambda k: (se3.vee(motion(k).homogeneous), vee_reference(k)),
        ),
        (
            "se3.exp",
            "pin.exp6",
            lambda k: (se3.exp(xi[k]), pin.exp6(pin.Motion(_swap_vec(xi[k]))).homogeneous),
        ),
        ("se3.log", "pin.log6", lambda k: (se3.log(G[k]), _swap_vec(pin.log6(G[k]).vector))),
        (
            "se3.inverse",
            "pin.SE3.inverse",
            lambda k: (se3.inverse(G[k]), _to_pin_se3(G[k]).inverse().homogeneous),
        ),
        ("se3.Ad", "pin.SE3.action", lambda k: (se3.Ad(G[k]), _swap_op(_to_pin_se3(G[k]).action))),
        ("se3.ad", "pin.Motion.action", lambda k: (se3.ad(V[k]), _swap_op(motion(k).action))),
        (
            "se3.ad_star",
            "-pin.Motion.dualAction",
            lambda k: (se3.ad_star(V[k]), -_swap_op(motion(k).dualAction)),
        ),
        (
            "se3.ad applied",
            "pin.Motion.cross",
            lambda k: (
                se3.ad(V[k]) @ W[k],
                _swap_vec(motion(k).cross(pin.Motion(_swap_vec(W[k]))).vector),
            ),
        ),
        (
            "se3.dexp",
            "pin.Jexp6",
            lambda k: (se3.dexp(xi[k]), _swap_op(pin.Jexp6(pin.Motion(_swap_vec(xi[k]))))),
        ),
        (
            "se3.dexp_inv",
            "pin.Jlog6",
            lambda k: (se3.dexp_inv(xi[k]), _swap_op(pin.Jlog6(_to_pin_se3(G[k])))),
        ),
    ]


def _free_acceleration_case(rng: np.random.Generator, n: int) -> Callable[[int], Any]:
    import pinocchio as pin

    from gmuk.dynamics import free_acceleration, spatial_inertia

    model, data = _free_flyer_model([(1.0, np.eye(3))])
    bodies = [_random_body(rng) for _ in range(n)]
    V = np.concatenate([rng.normal(size=(n, 3)), 10.0 * rng.normal(size=(n, 3))], axis=1)
    tau = np.array([m for m, _ in bodies])[:, None] * rng.normal(size=(n, 6))
    xi = _exp_coords(rng, n)

    def case(k: int) -> tuple[FloatArray, FloatArray]:
        m, J = bodies[k]
        model.inertias[1] = pin.Inertia(m, np.zeros(3), J)
        q = _q_from_g(pin.exp6(pin.Motion(_swap_vec(xi[k]))).homogeneous)
        ddq = pin.aba(model, data, q, _swap_vec(V[k]), _swap_vec(tau[k]))
        return free_acceleration(V[k], spatial_inertia(m, J), tau[k]), _swap_vec(ddq)

    return case


def _constrained_cases(
    rng: np.random.Generator, n: int
) -> tuple[Callable[[int], Any], Callable[[int], Any]]:
    """UK accelerations and multipliers of 1–3 free bodies with s random rows A ν̇ = b,
    s < 6·bodies (full row rank), against Pinocchio's KKT solve. One solve serves both."""
    import pinocchio as pin

    import gmuk

    class _Rows(gmuk.Constraint):
        def __init__(self, bodies: Sequence[gmuk.RigidBody], A: FloatArray, b: FloatArray):
            super().__init__(bodies)
            self.A, self.b = A, b

        def rows(self, state: gmuk.State) -> tuple[FloatArray, FloatArray]:
            return self.A, self.b

    cache: dict[int, tuple[tuple[FloatArray, FloatArray], tuple[FloatArray, FloatArray]]] = {}
    setups = []
    for _ in range(n):
        nb = int(rng.integers(1, 4))
        inertias = [_random_body(rng) for _ in range(nb)]
        s = int(rng.integers(1, 6 * nb))
        # singular values in [0.5, 2]: the comparison measures the solvers, not cond(A)
        U = np.linalg.qr(rng.normal(size=(s, s)))[0]
        Vt = np.linalg.qr(rng.normal(size=(6 * nb, 6 * nb)))[0][:s]
        A = U @ (rng.uniform(0.5, 2.0, s)[:, None] * Vt)
        b = rng.normal(size=s)
        g = [_from_pin_se3(pin.exp6(pin.Motion(_swap_vec(x)))) for x in _exp_coords(rng, nb)]
        V = rng.normal(size=(nb, 6))
        setups.append((inertias, A, b, g, V))

    def solve(k: int) -> tuple[tuple[FloatArray, FloatArray], tuple[FloatArray, FloatArray]]:
        if k not in cache:
            inertias, A, b, g, V = setups[k]
            nb = len(inertias)
            bodies = [gmuk.RigidBody(f"b{i}", m, J) for i, (m, J) in enumerate(inertias)]
            system = gmuk.System(bodies, [_Rows(bodies, A, b)])
            state = system.state(
                g={bd.name: gi for bd, gi in zip(bodies, g, strict=True)},
                V={bd.name: Vi for bd, Vi in zip(bodies, V, strict=True)},
            )
            acc = system.accelerations(state)
            model, data = _free_flyer_model(inertias)
            q = np.concatenate([_q_from_g(gi) for gi in g])
            J = _swap_vec(A.reshape(len(b), nb, 6)).reshape(len(b), 6 * nb)
            ddq = pin.forwardDynamics(model, data, q, _swap_vec(V).ravel(), np.zeros(6 * nb), J, -b)
            total = _swap_vec(np.asarray(ddq).reshape(nb, 6)).ravel()
            cache[k] = ((acc.total, total), (acc.multipliers, np.array(data.lambda_c)))
        return cache[k]

    return (lambda k: solve(k)[0]), (lambda k: solve(k)[1])


def _row(quantity: str, reference: str, case: Callable[[int], Any], n: int, tol: float) -> CheckRow:
    worst, where = -1.0, -1
    try:
        for k in range(n):
            err = _error(*case(k))
            if not err <= worst:  # NaN included: it becomes the worst and stays
                worst, where = err, k
                if math.isnan(err):
                    break
    except Exception as exc:  # a broken operator is a failed row, not a crashed check
        return CheckRow(quantity, reference, n, math.inf, tol, -1, f"{type(exc).__name__}: {exc}")
    return CheckRow(quantity, reference, n, worst, tol, where)


def check(seed: int = 0, n: int = 1000, verbose: bool = False) -> CheckReport:
    """Compare gmuk's SE(3) operators and dynamics with Pinocchio on random inputs.

    Parameters
    ----------
    seed : int
        Seed of the random inputs (:func:`numpy.random.default_rng`).
    n : int
        Samples per Lie-group quantity and for the free-body dynamics (≥ 1); the constrained
        dynamics, which builds a :class:`gmuk.System` per sample, uses ``max(1, n // 10)``.
    verbose : bool
        Print each row as soon as it is computed.

    Returns
    -------
    CheckReport
        ``report.ok`` tells whether every quantity passed; ``str(report)`` is the table.

    Raises
    ------
    DefinitionError
        ``n`` or ``seed`` is not a non-negative integer (``n`` ≥ 1), or ``n`` is more than
        :data:`MAX_SAMPLES`.

    Notes
    -----
    The quantities, the error measure, the sampled ranges and the tolerances are in the
    module docstring (:mod:`gmuk.crosscheck`). Takes about 0.3 s at the default ``n`` (once
    gmuk's compiled kernels are cached), linear in ``n``.
    """
    for label, value, low in (("n", n, 1), ("seed", seed, 0)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise DefinitionError(f"check: {label} must be an integer ≥ {low}; got {value!r}")
    if n > MAX_SAMPLES:  # refused before allocating n samples (10**400 cannot be)
        raise DefinitionError(
            f"check: n must be at most {MAX_SAMPLES:,} (gmuk.crosscheck.MAX_SAMPLES, about "
            f"{MAX_SAMPLES // 1000 * 0.3 / 60:.0f} min and 1 GiB); got "
            + (f"{int(n):,}" if n < 10**20 else f"an integer of {len(str(int(n)))} digits")
        )
    import pinocchio as pin

    t0 = time.perf_counter()
    rng = np.random.default_rng(int(seed))
    n = int(n)
    n_uk = max(1, n // 10)
    plan: list[tuple[str, str, Callable[[int], Any], int, float]] = [
        (q, ref, case, n, LIE_TOL) for q, ref, case in _lie_cases(rng, n)
    ]
    plan.append(
        (
            "free_acceleration (Eq. 10b)",
            "pin.aba, free flyer",
            _free_acceleration_case(rng, n),
            n,
            DYNAMICS_TOL,
        )
    )
    total, multipliers = _constrained_cases(rng, n_uk)
    plan.append(
        ("System UK acceleration (Eq. 64)", "pin.forwardDynamics", total, n_uk, DYNAMICS_TOL)
    )
    plan.append(
        (
            "System UK multipliers (Eq. 3)",
            "forwardDynamics lambda_c",
            multipliers,
            n_uk,
            DYNAMICS_TOL,
        )
    )
    rows = []
    for quantity, reference, case, count, tol in plan:
        row = _row(quantity, reference, case, count, tol)
        rows.append(row)
        if verbose:
            status = "pass" if row.ok else "FAIL"
            print(f"{quantity:<32} {row.error:.2e} (tolerance {tol:.0e}) {status}", flush=True)
    return CheckReport(tuple(rows), int(seed), n, str(pin.__version__), time.perf_counter() - t0)
