"""The contact solve: Gauss's principle with unilateral rows, and impacts.

:class:`ContactSolver` is the strategy a System takes when one of its constraints is a
:class:`~gmuk.constraints.unilateral.UnilateralConstraint`. At each right-hand-side evaluation
it solves

``min ½ (ν̇ − ν̇_a)ᵀ M (ν̇ − ν̇_a)``  s.t.  ``A ν̇ = b`` (bilateral rows),
``a_k ν̇ ≥ b_k`` (the closed unilateral rows)

as a least-distance program solved by one non-negative least-squares problem
(:func:`solve_with_inequalities`: Lawson and Hanson's finite active-set method, exact and
indifferent to redundant rows such as four corners of a face on a plane). The row count of
the System stays the same whatever is active (inactive rows get the multiplier 0).

:func:`impulse` applies the same problem at the velocity level for an impact (impulsive
Udwadia–Kalaba): ``min ½ (ν⁺ − ν⁻)ᵀ M (ν⁺ − ν⁻)`` subject to the bilateral rows keeping their
velocity, ``A ν⁺ = A ν⁻``, and each closed gap leaving with at least −e times its approach
rate (Newton's law of restitution), ``a_k ν⁺ ≥ −e a_k ν⁻``. :func:`simulate_with_impacts` runs a
System with events on its unilateral gaps and applies an impulse at each.

Coulomb friction (:class:`~gmuk.constraints.unilateral.PointPlaneContact` with ``friction=μ``)
makes the problem a complementarity problem that is no longer Gauss's principle;
:func:`solve_with_friction` solves it by staggered projections (Kaufman et al. 2008) at the
acceleration level: the normal problem above with the friction forces held as applied forces,
then the friction problem with the normal forces held, alternated to a fixed point.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.constraints.unilateral import CLOSED_GAP, SLIP_SPEED, UnilateralConstraint
from gmuk.engine import segments
from gmuk.engine.events import Event
from gmuk.engine.solvers import DenseSolver, Solution
from gmuk.errors import ConstraintError, DefinitionError, SimulationError
from gmuk.state import State
from gmuk.trajectory import EventRecord, Trajectory

if TYPE_CHECKING:
    from gmuk.engine.system import System

__all__ = [
    "FRICTION_TOL",
    "ContactKKT",
    "ContactSolver",
    "FrictionRows",
    "contact_kkt",
    "impulse",
    "project",
    "simulate_with_impacts",
    "solve_with_friction",
    "solve_with_inequalities",
]


_EPS = float(np.finfo(float).eps)


def solve_with_inequalities(
    a: FloatArray,
    Minv_sqrt: FloatArray,
    A: FloatArray,
    b: FloatArray,
    equal: np.ndarray,
    candidates: np.ndarray,
    rcond: float | None = None,
) -> tuple[FloatArray, FloatArray, int, float]:
    """The KKT point of Gauss's principle with rows ``equal`` of ``A ν̇ = b`` as equalities
    and rows ``candidates`` as inequalities ``A_k ν̇ ≥ b_k`` (module docstring).

    In ``x = M^{1/2} (ν̇ − ν̇_a)`` the problem is a least-distance program (Lawson and Hanson
    1974, Ch. 23): ``min ‖x‖`` s.t. ``G_e x = h_e``, ``G_u x ≥ h_u`` with ``G = A M^{-1/2}``,
    ``h = b − A ν̇_a``. The equalities give ``x = x₀ + N y`` (x₀ the minimum-norm solution,
    the Udwadia–Kalaba one; N an orthonormal basis of the null space of G_e, from its SVD),
    and the inequalities in y are solved through one non-negative least-squares problem,
    ``min ‖E u − f‖, u ≥ 0`` with ``E = [(G_u N)ᵀ; (h_u − G_u x₀)ᵀ]``, ``f = e_last``
    (scipy's ``nnls``, Lawson–Hanson's active-set method: finite, exact, and indifferent
    to redundant rows). Then ``y = −r[:-1]/r[-1]`` and ``λ_u = u/(−r[-1])`` for
    ``r = E u − f``, and λ_e solves ``G_eᵀ λ_e = x − G_uᵀ λ_u`` (minimum norm).

    Returns
    -------
    ac : ndarray (n,)
        ν̇_c.
    lam : ndarray (s,)
        Multipliers of every row (0 for rows in neither set); λ ≥ 0 on the inequalities.
    rank : int
        Rank of the equality rows.
    residual : float
        ‖A_e ν̇ − b_e‖₂.

    Raises
    ------
    SimulationError
        When the inequalities cannot all hold together with the equalities.
    """
    from scipy.optimize import nnls

    n = a.size
    G = A @ Minv_sqrt
    h = b - A @ a
    G_e, h_e = G[equal], h[equal]
    if equal.size:
        U, sv, Vt = np.linalg.svd(G_e, full_matrices=True)
        cut = (rcond if rcond is not None else max(G_e.shape) * _EPS) * (sv[0] if sv.size else 0)
        rank = int((sv > cut).sum())
        x0 = Vt[:rank].T @ ((U[:, :rank].T @ h_e) / sv[:rank])
        N = Vt[rank:].T
    else:
        rank, x0, N = 0, np.zeros(n), np.eye(n)
    lam = np.zeros(b.size)
    x = x0
    if candidates.size:
        G_u = G[candidates]
        GN = G_u @ N
        hy = h[candidates] - G_u @ x0
        # scaled so that the rows and the right-hand side are of one size: y = σ y'
        sigma = float(np.abs(hy).max())
        if sigma > 0.0:
            E = np.vstack([GN.T, (hy / sigma)[None, :]])
            f = np.zeros(E.shape[0])
            f[-1] = 1.0
            u, _ = nnls(E, f, maxiter=50 * max(E.shape))
            r = E @ u - f
            if not -r[-1] > 1e-12:
                raise SimulationError(
                    "the unilateral rows cannot all hold with the bilateral ones (the "
                    f"least-distance program is infeasible; 1 − hᵀu = {-r[-1]:.3g})"
                )
            x = x0 + N @ (sigma * (-r[:-1] / r[-1]))
            lam[candidates] = sigma * u / -r[-1]
    if equal.size:
        rhs = x - G[candidates].T @ lam[candidates] if candidates.size else x
        lam[equal] = np.linalg.lstsq(G_e.T, rhs, rcond=None)[0]
    ac = Minv_sqrt @ x
    residual = float(np.linalg.norm(A[equal] @ (a + ac) - b[equal])) if equal.size else 0.0
    return ac, lam, rank, residual


#: The friction iteration (:func:`solve_with_friction`) has converged when no friction force
#: changes by more than this times the largest cone radius μ f_n between two rounds.
FRICTION_TOL = 1e-10
#: Rounds of the staggered iteration before it gives up (SimulationError).
FRICTION_MAX_ROUNDS = 1000
#: Sweeps of the friction problem's block descent within one round (round-off can keep the
#: last digits of a redundant set of points moving; the rounds' test decides convergence).
_MAX_SWEEPS = 200


@dataclasses.dataclass(frozen=True)
class FrictionRows:
    """The m closed points with friction in a stack of rows (:func:`solve_with_friction`).

    Attributes
    ----------
    normal : ndarray (m,) of int
        Each point's normal row.
    tangent : ndarray (m, 2) of int
        Its two tangential rows (the tangential acceleration along t₁, t₂ held at the row's
        right-hand side when it sticks; the multipliers are the friction force, N).
    mu : ndarray (m,)
        Coulomb's coefficient of each point.
    velocity : ndarray (m, 2)
        Each point's tangential velocity along t₁, t₂ (m/s): above
        :data:`~gmuk.constraints.unilateral.SLIP_SPEED` it slides.
    """

    normal: np.ndarray
    tangent: np.ndarray
    mu: FloatArray
    velocity: FloatArray


def solve_with_friction(
    a: FloatArray,
    Minv_sqrt: FloatArray,
    A: FloatArray,
    b: FloatArray,
    equal: np.ndarray,
    candidates: np.ndarray,
    friction: FrictionRows,
    rcond: float | None = None,
) -> tuple[FloatArray, FloatArray, int, float]:
    """:func:`solve_with_inequalities` with Coulomb friction at the points ``friction``.

    The contact force at a closed point is ``f_n n + f_t`` with ``f_n ≥ 0`` complementary to
    the normal row (as without friction) and ``‖f_t‖ ≤ μ f_n`` (Coulomb's circular cone).
    A point sliding with tangential velocity u (``‖u‖ >`` :data:`SLIP_SPEED`) gets the kinetic
    force ``f_t = −μ f_n u/‖u‖``. A point at rest gets the force of maximal dissipation at
    the acceleration level: the minimiser of ``½ f_tᵀ W f_t + r₀ᵀ f_t`` over the cones, where
    ``r(f_t) = r₀ + W f_t`` is the sticking points' tangential-row residual
    ``T ν̇ − b_T`` and ``W = T M^{-1/2} P M^{-1/2} Tᵀ`` their Delassus matrix (P: the projector
    on the null space of the bilateral rows, which respond to the friction): it holds the
    point (``r = 0``) when the cone allows, and otherwise opposes its tangential acceleration
    with the whole ``μ f_n`` (Moreau's and Glocker's sticking law; Pfeiffer and Glocker 1996,
    Ch. 5).

    When no point slides, every point held is tried first: Gauss's principle with the
    tangential rows as equalities, then the least-norm contact forces giving its constraint
    force with each friction force in the polygon of 16 sides inscribed in its cone (two
    least-distance programs); if there are none, the iteration below decides.

    The coupled problem is solved by staggered projections (Kaufman, Sueda, James and Pai
    2008, at the acceleration level instead of the velocity level): the normal problem —
    Gauss's principle with the friction forces applied, :func:`solve_with_inequalities` —
    then the friction problem with the normal forces held — the kinetic forces set, the
    sticking ones by block coordinate descent over the points (each point's two-dimensional
    problem on its disk solved exactly, a secular equation; Jourdan, Alart and Jean 1998) —
    alternated from zero friction until no friction force changes by more than
    :data:`FRICTION_TOL` times the largest ``μ f_n``. The accelerations returned are those of
    the last normal problem with the last friction forces, so ``M ν̇_c = Aᵀλ`` and the normal
    rows' KKT conditions hold to round-off; the cone and the sticking rows hold to the
    iteration's tolerance. The fixed point exists and the iteration converges for the
    moderate μ of common contacts; with large μ the acceleration-level problem may have no
    solution (Painlevé's paradox), and then the iteration stops with a SimulationError.

    Parameters
    ----------
    a, Minv_sqrt, A, b, equal, candidates, rcond
        As for :func:`solve_with_inequalities`.
    friction : FrictionRows
        The closed points with friction (their normal rows among ``candidates``).

    Returns
    -------
    As :func:`solve_with_inequalities`; the multipliers of the tangential rows are the
    friction forces (N, along t₁, t₂).

    Raises
    ------
    SimulationError
        When the inequalities cannot hold, or the iteration does not converge in
        :data:`FRICTION_MAX_ROUNDS` rounds.

    References
    ----------
    Kaufman, D. M., Sueda, S., James, D. L. and Pai, D. K. (2008), Staggered projections for
    frictional contact in multibody systems, ACM Trans. Graph. 27(5), 164.
    Jourdan, F., Alart, P. and Jean, M. (1998), A Gauss–Seidel like algorithm to solve
    frictional contact problems, Comput. Methods Appl. Mech. Engrg. 155, 31–47.
    Pfeiffer, F. and Glocker, C. (1996), Multibody Dynamics with Unilateral Contacts, Wiley.
    """
    m = friction.mu.size
    speed = np.linalg.norm(friction.velocity, axis=1)
    sliding = speed > SLIP_SPEED
    direction = np.zeros((m, 2))
    direction[sliding] = friction.velocity[sliding] / speed[sliding, None]
    stick = np.flatnonzero(~sliding)
    tangent_rows = friction.tangent.reshape(-1)
    G_T = A[tangent_rows] @ Minv_sqrt
    stick_rows = friction.tangent[stick].reshape(-1)
    W = np.zeros((0, 0))
    if stick.size:
        G_s = A[stick_rows] @ Minv_sqrt
        if equal.size:  # the bilateral rows respond: W = G_s P G_sᵀ, P = N Nᵀ
            G_e = A[equal] @ Minv_sqrt
            _, sv, Vt = np.linalg.svd(G_e, full_matrices=True)
            cut = (rcond if rcond is not None else max(G_e.shape) * _EPS) * (
                sv[0] if sv.size else 0.0
            )
            G_s = G_s @ Vt[int((sv > cut).sum()) :].T
        W = G_s @ G_s.T
    if not sliding.any():  # every point sticks, if the cones can hold them all
        held = _all_sticking(a, Minv_sqrt, A, b, equal, candidates, friction, rcond)
        if held is not None:
            return held
    f = np.zeros((m, 2))
    for _ in range(FRICTION_MAX_ROUNDS):
        shift = Minv_sqrt @ (G_T.T @ f.reshape(-1))  # M⁻¹ Tᵀ f_t
        ac_n, lam, rank, residual = solve_with_inequalities(
            a + shift, Minv_sqrt, A, b, equal, candidates, rcond
        )
        ac = shift + ac_n
        lam = _least_norm_normals(A, b, a + ac, a, lam, equal, candidates)
        radius = friction.mu * np.maximum(lam[friction.normal], 0.0)
        new = np.zeros((m, 2))
        new[sliding] = -radius[sliding, None] * direction[sliding]
        scale = float(radius.max(initial=0.0))
        if stick.size:
            r = A[stick_rows] @ (a + ac) - b[stick_rows]
            new[stick] = _disk_descent(W, r, f[stick], radius[stick], FRICTION_TOL * scale)
        converged = float(np.abs(new - f).max(initial=0.0)) <= FRICTION_TOL * scale
        if converged:
            break
        f = new
    else:
        raise SimulationError(
            f"the friction iteration did not converge in {FRICTION_MAX_ROUNDS} rounds (a "
            "coefficient too large for the acceleration-level problem: Painlevé's paradox?)"
        )
    lam[tangent_rows] = f.reshape(-1)
    return ac, lam, rank, residual


#: Sides of the polygon inscribed in each cone within which :func:`_all_sticking` looks for
#: the friction forces (a polygon, so that the search is a least-distance program).
_CONE_SIDES = 16


def _all_sticking(
    a: FloatArray,
    Minv_sqrt: FloatArray,
    A: FloatArray,
    b: FloatArray,
    equal: np.ndarray,
    candidates: np.ndarray,
    friction: FrictionRows,
    rcond: float | None,
) -> tuple[FloatArray, FloatArray, int, float] | None:
    """Every friction point held: Gauss's principle with the tangential rows as equalities,
    then the least-norm contact forces giving the same constraint force with each friction
    force within the polygon of :data:`_CONE_SIDES` sides inscribed in its cone
    (``d_j·f_t ≤ μ cos(π/K) f_n``), both least-distance programs. None when no such forces
    exist (some point must slip, or lies near its cone's edge): the staggered iteration
    then decides."""
    stick_rows = friction.tangent.reshape(-1)
    held = np.concatenate([equal, stick_rows])
    try:
        ac, lam0, rank, _ = solve_with_inequalities(a, Minv_sqrt, A, b, held, candidates, rcond)
    except SimulationError:
        return None
    acc = a + ac
    slack = A[candidates] @ acc - b[candidates]
    size = float(np.abs(b[candidates]).max(initial=0.0)) + float(
        np.abs(A[candidates]).max(initial=0.0)
    ) * (float(np.abs(acc).max(initial=0.0)) + float(np.abs(a).max(initial=0.0)))
    shut = (lam0[candidates] > 0.0) | (slack <= 1e-10 * size)
    rows = np.concatenate([candidates, stick_rows])  # the unknowns: normal, then tangential
    p, m = candidates.size, friction.mu.size
    G = A[rows].T  # (n, p + 2m)
    Q0 = G @ lam0[rows]
    n = G.shape[0]
    Q = Q0
    if equal.size:
        proj = np.eye(n) - np.linalg.pinv(A[equal]) @ A[equal]
        G, Q = proj @ G, proj @ Q
    where = {int(r): j for j, r in enumerate(candidates)}
    angles = 2.0 * np.pi * np.arange(_CONE_SIDES) / _CONE_SIDES
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (K, 2)
    ineq = np.zeros((p + _CONE_SIDES * m, p + 2 * m))
    ineq[:p, :p] = np.eye(p)
    for i in range(m):
        block = slice(p + _CONE_SIDES * i, p + _CONE_SIDES * (i + 1))
        ineq[block, where[int(friction.normal[i])]] = friction.mu[i] * np.cos(np.pi / _CONE_SIDES)
        ineq[block, p + 2 * i : p + 2 * i + 2] = -d
    off = np.flatnonzero(~shut)  # normal rows with slack: no force there
    eq_rows = np.vstack([G, np.eye(p + 2 * m)[off]])
    stacked = np.vstack([eq_rows, ineq])
    rhs = np.concatenate([Q, np.zeros(off.size), np.zeros(ineq.shape[0])])
    n_eq = eq_rows.shape[0]
    try:
        z, _, _, residual = solve_with_inequalities(
            np.zeros(p + 2 * m),
            np.eye(p + 2 * m),
            stacked,
            rhs,
            np.arange(n_eq),
            n_eq + np.arange(ineq.shape[0]),
        )
    except SimulationError:
        return None
    if residual > 1e-10 * (float(np.linalg.norm(Q)) + 1e-300):
        return None
    lam = lam0.copy()
    lam[rows] = z
    if equal.size:
        moved = Q0 - A[rows].T @ z  # in the bilateral rows' span
        lam[equal] = lam0[equal] + np.linalg.lstsq(A[equal].T, moved, rcond=None)[0]
    residual_e = float(np.linalg.norm(A[equal] @ acc - b[equal])) if equal.size else 0.0
    return ac, lam, rank, residual_e


def _least_norm_normals(
    A: FloatArray,
    b: FloatArray,
    acc: FloatArray,
    free: FloatArray,
    lam: FloatArray,
    equal: np.ndarray,
    candidates: np.ndarray,
) -> FloatArray:
    """The multipliers ``lam`` with the unilateral ones replaced by the least-norm
    non-negative ones that give the same constraint force on the rows at zero slack.

    Redundant contact rows (four corners of a face on a plane) leave the normal forces free
    within a polytope, and the non-negative least squares of the normal problem returns one
    of its vertices, which may jump from one evaluation to the next; the friction cones
    depend on these forces, so the friction solve takes the unique least-norm ones instead
    (a least-distance program: ``min ‖λ_u‖`` s.t. ``Π A_uᵀ λ_u = Π Q``, ``λ_u ≥ 0``, Q the
    constraint force and Π the projector off the bilateral rows' span)."""
    if not candidates.size:
        return lam
    slack = A[candidates] @ acc - b[candidates]
    size = float(np.abs(b[candidates]).max(initial=0.0)) + float(
        np.abs(A[candidates]).max(initial=0.0)
    ) * (float(np.abs(acc).max(initial=0.0)) + float(np.abs(free).max(initial=0.0)))
    active = candidates[(lam[candidates] > 0.0) | (slack <= 1e-10 * size)]
    if not active.size:
        return lam
    Q0 = A[candidates].T @ lam[candidates]  # the unilateral rows' share of M ν̇_c
    Q = Q0
    A_u = A[active].T  # (n, p)
    n, p = A_u.shape
    if equal.size:
        A_e = A[equal]
        proj = np.eye(n) - np.linalg.pinv(A_e) @ A_e
        A_u, Q = proj @ A_u, proj @ Q
    rows = np.vstack([A_u, np.eye(p)])
    rhs = np.concatenate([Q, np.zeros(p)])
    least, _, _, _ = solve_with_inequalities(
        np.zeros(p), np.eye(p), rows, rhs, np.arange(n), n + np.arange(p)
    )
    out = lam.copy()
    out[candidates] = 0.0
    out[active] = np.maximum(least, 0.0)
    if equal.size:
        moved = Q0 - A[candidates].T @ out[candidates]  # in the bilateral rows' span
        out[equal] = lam[equal] + np.linalg.lstsq(A[equal].T, moved, rcond=None)[0]
    return out


def _disk_descent(
    W: FloatArray, r: FloatArray, f0: FloatArray, radius: FloatArray, tol: float
) -> FloatArray:
    """Block coordinate descent on ``min ½ fᵀ W f + (r − W f₀)ᵀ f`` over the disks
    ``‖f_i‖ ≤ radius_i`` (f (p, 2)), from f₀ whose residual ``W f₀ + (r − W f₀)`` is r: each
    block minimised exactly in turn, sweeps until no block moves by more than ``tol``."""
    f = f0.astype(float).reshape(-1)
    res = np.array(r, dtype=float)
    p = radius.size
    blocks = [np.linalg.eigh(W[2 * i : 2 * i + 2, 2 * i : 2 * i + 2]) for i in range(p)]
    for _ in range(_MAX_SWEEPS):
        moved = 0.0
        for i in range(p):
            sl = slice(2 * i, 2 * i + 2)
            w, U = blocks[i]
            g = res[sl] - W[sl, sl] @ f[sl]
            step = _disk_minimiser(w, U, g, float(radius[i])) - f[sl]
            if step.any():
                res += W[:, sl] @ step
                f[sl] += step
                moved = max(moved, float(np.abs(step).max()))
        if moved <= tol:
            break
    return f.reshape(p, 2)  # at the cap, the staggered iteration's test decides


def _disk_minimiser(w: FloatArray, U: FloatArray, g: FloatArray, rho: float) -> FloatArray:
    """``argmin ½ fᵀ W f + gᵀ f`` over ``‖f‖ ≤ ρ`` for a 2×2 PSD ``W = U diag(w) Uᵀ``: the
    unconstrained minimiser if it lies in the disk, else ``f = −(W + ν I)⁻¹ g`` on the circle,
    ν > 0 the root of the secular equation ``1/‖f(ν)‖ = 1/ρ`` (Newton's method from the left,
    monotone for this concave function; Moré and Sorensen 1983)."""
    if not rho > 0.0:
        return np.zeros(2)
    gp = U.T @ g
    w = np.maximum(w, 0.0)
    floor = 8.0 * _EPS * float(w.max(initial=0.0))
    free = w > floor
    if not np.any(np.abs(gp[~free]) > 0.0):  # a minimiser exists; the least-norm one
        fp = np.where(free, -gp / np.where(free, w, 1.0), 0.0)
        if float(np.hypot(*fp)) <= rho:
            return np.asarray(U @ fp, dtype=float)
    g_norm = float(np.hypot(*gp))
    nu = 0.0 if bool(free.all()) else 1e-12 * g_norm / rho
    for _ in range(100):
        d = w + nu
        n2 = float(np.sum((gp / d) ** 2))
        n = np.sqrt(n2)
        psi = 1.0 / n - 1.0 / rho
        dpsi = float(np.sum(gp**2 / d**3)) / (n2 * n)
        step = -psi / dpsi
        nu += step
        if abs(step) <= 4.0 * _EPS * nu:
            break
    fp = -gp / (w + nu)
    fp *= min(1.0, rho / float(np.hypot(*fp)))
    return np.asarray(U @ fp, dtype=float)


class ContactSolver(DenseSolver):
    """Dense rows with unilateral constraints: the active-set KKT solve (module docstring)."""

    name = "contact"

    @classmethod
    def problems(cls, system: System) -> list[str]:
        """Dense rows only (the contact solve stacks them densely)."""
        return []

    def _row_ranges(self, state: State) -> list[tuple[Any, int, int]]:
        """(constraint, first row, end row) of each constraint, rows counted once, at the first
        state (a constraint's row count does not change along a run)."""
        ranges: list[tuple[Any, int, int]] | None = self.__dict__.get("_ranges")
        if ranges is None:
            ranges, r = [], 0
            for c in self.system.constraints:
                n = int(np.asarray(c.rows(state)[1]).reshape(-1).size)
                ranges.append((c, r, r + n))
                r += n
            self._ranges = ranges
        return ranges

    def solve(self, state: State, a: FloatArray, rows: Any = None) -> Solution:
        """The KKT point with the closed unilateral rows as inequalities."""
        A, b = self._rows(state, rows)
        A = np.asarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)
        equal, candidates = [], []
        ranges = self._row_ranges(state)
        if ranges and ranges[-1][2] != b.size:
            raise ConstraintError(
                f"the constraints gave {b.size} rows at t = {state.t:.9g} s and "
                f"{ranges[-1][2]} at the start: a constraint's row count may not change"
            )
        normal, tangent, mu, velocity = [], [], [], []
        for c, r0, r1 in ranges:
            if isinstance(c, UnilateralConstraint):
                shut = c.closed(state)
                closed = np.flatnonzero(shut)
                candidates += [r0 + k for k in closed]
                if c.friction > 0.0 and closed.size:
                    k = shut.size
                    normal += [r0 + i for i in closed]
                    tangent += [(r0 + k + 2 * i, r0 + k + 2 * i + 1) for i in closed]
                    mu += [c.friction] * closed.size
                    velocity.append(c.tangential_velocities(state)[closed])  # type: ignore[attr-defined]
            else:
                equal += list(range(r0, r1))
        if normal:
            ac, lam, rank, residual = solve_with_friction(
                a,
                self._Minv_sqrt,
                A,
                b,
                np.array(equal, dtype=np.int64),
                np.array(candidates, dtype=np.int64),
                FrictionRows(
                    np.array(normal, dtype=np.int64),
                    np.array(tangent, dtype=np.int64),
                    np.array(mu),
                    np.concatenate(velocity),
                ),
                self.system.rcond,
            )
        else:
            ac, lam, rank, residual = solve_with_inequalities(
                a,
                self._Minv_sqrt,
                A,
                b,
                np.array(equal, dtype=np.int64),
                np.array(candidates, dtype=np.int64),
                self.system.rcond,
            )
        scale = float(np.linalg.norm(b)) + float(np.linalg.norm(A)) * (
            float(np.linalg.norm(a)) + float(np.linalg.norm(ac))
        )
        self.check_consistency(state, residual, scale)
        return ac, lam, rank, residual, 0.0


def _with_velocity(state: State, nu: FloatArray) -> State:
    """``state`` with the generalised velocity ν (the inverse of :meth:`State.nu`)."""
    lay = state.layout
    V = nu[(lay.rigid_offsets[:, None] + np.arange(6)).ravel()].reshape(state.V.shape)
    xdot = nu[lay.euclid_offsets] if lay.n_euclid else state.xdot
    return State(state.t, state.g, V, state.x, xdot, state.z, lay)


def _unilaterals(system: System) -> list[UnilateralConstraint]:
    return [c for c in system.constraints if isinstance(c, UnilateralConstraint)]


def impulse(system: System, state: State, *, plastic: bool = False) -> tuple[State, FloatArray]:
    """The state just after an impact at ``state`` (impulsive Udwadia–Kalaba, module
    docstring), and the impulse multipliers (N·s per row; 0 for rows not in contact).

    Every gap that is closed (φ ≤ :data:`CLOSED_GAP`) and closing (φ̇ < 0) leaves with at
    least ``−e φ̇`` (its constraint's restitution e; 0 when ``plastic``); every other closed gap
    with at least 0;
    the bilateral rows keep their velocity-level values. The rows are the constraints'
    acceleration rows, whose coefficients are the velocity Jacobians of their gaps and
    joints."""
    solver = system.solver
    if not isinstance(solver, DenseSolver):
        raise DefinitionError("impulse needs a System with dense rows")
    A, _ = system.constraint_rows(state)
    A = np.asarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)
    nu = state.nu()
    target = A @ nu
    equal, candidates, r = [], [], 0
    for c in system.constraints:
        n = int(np.asarray(c.rows(state)[1]).reshape(-1).size)
        if isinstance(c, UnilateralConstraint):
            g, gd = c.gaps(state)
            for k in range(g.size):  # the normal rows (tangential ones, if any, follow)
                if g[k] <= CLOSED_GAP:
                    candidates.append(r + k)
                    e = 0.0 if plastic else c.restitution
                    target[r + k] = -e * gd[k] if gd[k] < 0.0 else 0.0
        else:
            equal += list(range(r, r + n))
        r += n
    dnu, lam, _, _ = solve_with_inequalities(
        nu,
        system._Minv_sqrt,
        A,
        target,
        np.array(equal, dtype=np.int64),
        np.array(candidates, dtype=np.int64),
        system.rcond,
    )
    return _with_velocity(state, nu + dnu), lam


class _Gaps:
    """A unilateral constraint's gaps at the last state asked for (the events of its gaps
    share one evaluation per state)."""

    def __init__(self, constraint: UnilateralConstraint) -> None:
        self.constraint = constraint
        self._key: tuple[float, int] | None = None
        self._gaps = np.zeros(0)

    def at(self, t: float, state: State) -> FloatArray:
        key = (t, id(state))
        if key != self._key:
            self._gaps = self.constraint.gaps(state)[0]
            self._key = key
        return self._gaps


#: A gap at zero when a segment starts (just struck, or resting) is watched IMPACT_DEPTH (m or
#: rad) below where it starts: its value starts positive, so that leaving zero and coming back
#: within one step is still a sign change, and a resting gap (held at zero by its row) never
#: gets there.
IMPACT_DEPTH = 1e-10


class _GapEvent(Event):
    """Gap k of a unilateral constraint closing: one event per gap (a minimum over gaps
    would hide a gap that closes in the step where another one opens from zero), watched at
    zero, or at −IMPACT_DEPTH when it starts at zero (``g₀ ≤ CLOSED_GAP``)."""

    def __init__(self, gaps: _Gaps, k: int, g0: float) -> None:
        super().__init__(terminal=True, direction=-1, name=f"{gaps.constraint.name} impact {k}")
        self.gaps = gaps
        self.k = k
        self.offset = IMPACT_DEPTH if g0 <= CLOSED_GAP else 0.0

    def value(self, t: float, state: State) -> float:
        return float(self.gaps.at(t, state)[self.k]) + self.offset


def _join(parts: Sequence[Trajectory], impacts: list[EventRecord]) -> Trajectory:
    """One trajectory of consecutive segments, with the impacts counted and last in its
    events: recorded, not terminal (each ended a segment, not the run)."""
    events = tuple(e for p in parts for e in p.events if e not in impacts) + tuple(
        dataclasses.replace(e, terminal=False) for e in impacts
    )
    return segments.join(parts, stats={"impacts": len(impacts)}, events=events)


def simulate_with_impacts(
    system: System,
    state0: State,
    t_span: tuple[float, float],
    *,
    t_eval: Any = None,
    rest_speed: float = 1e-3,
    max_impacts: int = 10_000,
    **options: Any,
) -> Trajectory:
    """Integrate a System with unilateral constraints through their impacts.

    The run goes on until a gap that was open closes (a terminal event on the smallest open
    gap of each unilateral constraint, located on the step's continuous extension); there
    :func:`impulse` gives the velocities after the impact, and the run starts again from
    them, and :func:`project` closes what the impact left penetrating (to second order). An
    impact slower than ``rest_speed`` (m/s or rad/s) is plastic (e = 0), so that a
    bouncing body comes to rest after finitely many impacts instead of infinitely many in
    finite time. The returned trajectory holds each segment's outputs (the state just
    after an impact is the first output of the next segment when ``t_eval`` is None) and an
    :class:`~gmuk.trajectory.EventRecord` per impact (name ``"<constraint> impact <k>"`` for
    gap k, its state the one just before); ``stats["impacts"]`` counts them.

    Parameters
    ----------
    system, state0, t_span
        As for :meth:`gmuk.System.simulate`.
    t_eval : array_like, optional
        Output times; default every accepted step.
    rest_speed : float
        Impacts slower than this (m/s or rad/s) are plastic (default 1e-3).
    max_impacts : int
        Give up (SimulationError) after this many impacts.
    **options
        Passed to :meth:`gmuk.System.simulate` (rtol, atol, method …; not ``events``).
    """
    if "events" in options:
        raise DefinitionError("simulate_with_impacts sets its own events; give no events=")
    unilateral = _unilaterals(system)
    t, t1 = float(t_span[0]), float(t_span[1])
    times = None if t_eval is None else np.asarray(t_eval, dtype=float)
    state = state0
    parts: list[Trajectory] = []
    impacts: list[EventRecord] = []
    while True:
        events: list[Event] = []
        for c in unilateral:
            shared = _Gaps(c)
            events += [
                _GapEvent(shared, k, float(g0))
                for k, g0 in enumerate(c.gaps(state)[0])
                if np.isfinite(g0)  # a stop at infinity never closes
            ]
        seg_eval = segments.segment_times(times, t, t1, first=True)
        traj = system.simulate(state, (t, t1), t_eval=seg_eval, events=events, **options)
        if traj.status != "terminated":
            parts.append(segments.trimmed(traj, times, drop_last=False))
            break
        hit = traj.events[-1]
        state, _ = impulse(system, hit.state, plastic=_slow(hit.state, unilateral, rest_speed))
        state = project(system, state)
        impacts.append(hit)
        parts.append(segments.trimmed(traj, times, drop_last=True))
        if len(impacts) > max_impacts:
            raise SimulationError(f"more than {max_impacts} impacts by t = {hit.t:.9g} s")
        t = hit.t
    from gmuk.engine.integrate import check_drift

    joined = _join(parts, impacts)
    return check_drift(system, joined, options.get("drift_tol", 1e-6))


def project(system: System, state: State) -> State:
    """``state`` with its penetrating gaps closed: the smallest mass-weighted displacement
    ``δν`` (``min ½ δνᵀ M δν``) with ``a_k δν ≥ −φ_k`` for every gap below zero and the
    bilateral rows' ``A δν = 0``, applied on the group (``g ← g exp(δξ)`` for a rigid body).
    The gaps after it are of the order of φ² (the rows are the gaps' first-order change)."""
    from gmuk.lie import se3

    gaps = [(c, c.gaps(state)[0]) for c in _unilaterals(system)]
    if all(float(g.min(initial=0.0)) >= 0.0 for _, g in gaps):
        return state
    A, _ = system.constraint_rows(state)
    A = np.asarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)
    target = np.zeros(A.shape[0])
    equal, candidates, r = [], [], 0
    by_name = dict(gaps)
    for c in system.constraints:
        n = int(np.asarray(c.rows(state)[1]).reshape(-1).size)
        if isinstance(c, UnilateralConstraint):
            g = by_name[c]
            for k in np.flatnonzero(g < 0.0):
                candidates.append(r + int(k))
                target[r + int(k)] = -g[k]
        else:
            equal += list(range(r, r + n))
        r += n
    move, _, _, _ = solve_with_inequalities(
        np.zeros(A.shape[1]),
        system._Minv_sqrt,
        A,
        target,
        np.array(equal, dtype=np.int64),
        np.array(candidates, dtype=np.int64),
        system.rcond,
    )
    lay = state.layout
    G, x = state.g.copy(), state.x.copy()
    for name in lay.names:
        sl = lay.slot(name)
        if sl.kind == "rigid":
            G[sl.index] = G[sl.index] @ se3.exp(move[sl.offset : sl.offset + 6])
        else:
            x[sl.index : sl.index + sl.dof] += move[sl.offset : sl.offset + sl.dof]
    return State(state.t, G, state.V, x, state.xdot, state.z, lay)


def _slow(state: State, unilateral: list[UnilateralConstraint], rest_speed: float) -> bool:
    """Whether every gap closing at ``state`` approaches slower than ``rest_speed``."""
    for c in unilateral:
        g, gd = c.gaps(state)
        closing = (g <= CLOSED_GAP) & (gd < 0.0)
        if closing.any() and float((-gd[closing]).max()) >= rest_speed:
            return False
    return True


@dataclasses.dataclass(frozen=True)
class ContactKKT:
    """The KKT conditions of one unilateral constraint along a trajectory (arrays (N, k)).

    Attributes
    ----------
    gap : ndarray
        φ (primal feasibility: φ ≥ 0), m or rad.
    multiplier : ndarray
        λ (dual feasibility: λ ≥ 0), N or N·m.
    row_slack : ndarray
        ``a ν̇ − b`` of the row (≥ 0 where closed).
    complementarity : ndarray
        ``λ (a ν̇ − b)``: zero at a KKT point.
    """

    name: str
    gap: FloatArray
    multiplier: FloatArray
    row_slack: FloatArray
    complementarity: FloatArray

    def summary(self) -> dict[str, float]:
        """Largest violation of each condition over the run."""
        return {
            "penetration": float(np.maximum(-self.gap, 0.0).max(initial=0.0)),
            "negative_multiplier": float(np.maximum(-self.multiplier, 0.0).max(initial=0.0)),
            "complementarity": float(np.abs(self.complementarity).max(initial=0.0)),
        }


def contact_kkt(system: System, trajectory: Trajectory) -> dict[str, ContactKKT]:
    """The KKT conditions of every unilateral constraint of ``system`` at each output of
    ``trajectory`` (the System that produced it), by constraint name."""
    states = [trajectory.state(i) for i in range(len(trajectory))]
    out: dict[str, ContactKKT] = {}
    r = 0
    first = states[0]
    for c in system.constraints:
        n = int(np.asarray(c.rows(first)[1]).reshape(-1).size)
        if isinstance(c, UnilateralConstraint):
            gaps, slack = [], []
            cols = system.layout.columns(c.bodies)
            k = c.gaps(first)[0].size  # the normal rows (tangential ones, if any, follow)
            for i, s in enumerate(states):
                A, b = c.rows(s)
                gaps.append(c.gaps(s)[0])
                slack.append(np.asarray(A)[:k] @ trajectory.acceleration[i][cols] - b[:k])
            lam = trajectory.multipliers[:, r : r + k]
            sl = np.array(slack)
            out[c.name] = ContactKKT(c.name, np.array(gaps), lam, sl, lam * sl)
        r += n
    return out
