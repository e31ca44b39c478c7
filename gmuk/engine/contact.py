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
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.constraints.unilateral import CLOSED_GAP, UnilateralConstraint
from gmuk.engine import segments
from gmuk.engine.events import Event
from gmuk.engine.solvers import DenseSolver, Solution
from gmuk.errors import ConstraintError, DefinitionError, SimulationError
from gmuk.state import State
from gmuk.trajectory import EventRecord, Trajectory

if TYPE_CHECKING:
    from gmuk.engine.system import System

__all__ = [
    "ContactKKT",
    "ContactSolver",
    "contact_kkt",
    "impulse",
    "project",
    "simulate_with_impacts",
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
        for c, r0, r1 in ranges:
            if isinstance(c, UnilateralConstraint):
                closed = c.closed(state)
                candidates += [r0 + k for k in np.flatnonzero(closed)]
            else:
                equal += list(range(r0, r1))
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
            for k in range(n):
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
            for i, s in enumerate(states):
                A, b = c.rows(s)
                gaps.append(c.gaps(s)[0])
                slack.append(np.asarray(A) @ trajectory.acceleration[i][cols] - b)
            lam = trajectory.multipliers[:, r : r + n]
            sl = np.array(slack)
            out[c.name] = ContactKKT(c.name, np.array(gaps), lam, sl, lam * sl)
        r += n
    return out
