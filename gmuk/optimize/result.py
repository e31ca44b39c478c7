"""The result of a direct-collocation solve: nodal states and controls, path-constraint
multipliers, KKT residuals, IPOPT's status and log, and an open-loop controller."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._validation import FloatArray
from gmuk.control.base import Controller
from gmuk.errors import DefinitionError
from gmuk.kkt import BoundConditions
from gmuk.lie import so3
from gmuk.optimize.lgl import interpolation_matrix
from gmuk.optimize.mesh import Mesh

if TYPE_CHECKING:
    from gmuk.state import State

__all__ = [
    "BoundKKT",
    "OpenLoopControl",
    "OptimalControlResult",
    "PathConstraintResult",
    "RefinementStep",
]


@dataclass(frozen=True, eq=False)
class BoundKKT(BoundConditions):
    """KKT quantities of one side of a path inequality at the nodes (arrays (n,)).

    The same names as :class:`gmuk.kkt.InequalityKKT`, so that
    :func:`gmuk.plotting.plot_kkt` draws either; there is no slack coordinate here.

    Attributes
    ----------
    constraint, side : str
    bound : float
    t : ndarray
        Node times (s).
    h, g : ndarray
        h and its KKT form g ≤ 0 (``h − u`` or ``l − h``), in ``unit``.
    mu : ndarray
        The multiplier density of this side, ≥ 0 at a KKT point (``multiplier_unit``).
    """

    constraint: str
    side: str
    bound: float
    t: FloatArray
    h: FloatArray
    g: FloatArray
    mu: FloatArray
    unit: str
    multiplier_unit: str


@dataclass(frozen=True, eq=False)
class PathConstraintResult:
    """One constraint of the System at the nodes where it was imposed.

    Attributes
    ----------
    name : str
    kind : {"inequality", "holonomic", "nonholonomic"}
    t : ndarray (n,)
        Node times (s) (every node after the first; the last too unless the final state
        fixes the constraint's bodies).
    value : ndarray (n,) or (n, s)
        h (inequalities, ``unit``) or the residual (equalities).
    lower, upper : float
        The bounds of h (±inf when absent; 0 for equalities).
    multiplier : ndarray (n,) or (n, s)
        IPOPT's multiplier of each row divided by the node's quadrature weight: a density
        in time, the multiplier function of the continuous problem (cost unit per unit of h
        per second). CasADi's sign: > 0 where the upper bound pushes, < 0 the lower.
    unit, cost_unit : str
    """

    name: str
    kind: str
    t: FloatArray
    value: FloatArray
    lower: float
    upper: float
    multiplier: FloatArray
    unit: str
    cost_unit: str

    def kkt(self) -> list[BoundKKT]:
        """The KKT form of each bound of an inequality (an empty list for equalities)."""
        if self.kind != "inequality":
            return []
        out = []
        unit = self.unit or "unit of h"
        mu_unit = (
            f"N²/(kg·{unit})" if self.cost_unit == "N²·s/kg" else f"{self.cost_unit}/({unit}·s)"
        )
        for side, bound, sign in (("lower", self.lower, -1.0), ("upper", self.upper, 1.0)):
            if not np.isfinite(bound):
                continue
            other = self.upper if side == "lower" else self.lower
            lam = sign * self.multiplier
            # with both bounds one row carries both multipliers: each side takes its sign
            mu = np.maximum(lam, 0.0) if np.isfinite(other) else lam
            out.append(
                BoundKKT(
                    self.name,
                    side,
                    float(bound),
                    self.t,
                    self.value,
                    sign * (self.value - bound),
                    mu,
                    self.unit,
                    mu_unit,
                )
            )
        return out


@dataclass(frozen=True)
class RefinementStep:
    """One solve of :meth:`OptimalControlProblem.solve_adaptive`."""

    round: int
    n_elements: int
    n_nodes: int
    objective: float
    max_error: float
    iterations: int
    total_s: float
    #: the largest path-inequality violation between the nodes (``bound_tol`` given), or nan
    max_bound_violation: float = float("nan")


@dataclass(frozen=True, eq=False)
class OptimalControlResult:
    """The optimum at the mesh's nodes.

    Attributes
    ----------
    t : ndarray (N,)
        Distinct node times (s).
    mesh : Mesh
    body_names : tuple of str
        The physical bodies, in System order.
    body_kinds : tuple of str
        "point" or "rigid", per body.
    body_dofs : tuple of int
        3 or 6, per body.
    y : ndarray (N, n_y)
        Nodal states, per body: point mass [r_N (3), v_N (3)] (m, m/s); rigid body
        [r_N (3), ω (3), v_B (3)] (m, rad/s, m/s). See :attr:`r_N`, :attr:`g_NB` …
    u : ndarray (N, n_u)
        Nodal controls, per body: f_N (3) (N) or [L; f] (6) in the body frame (N·m, N).
    R_NB : ndarray (N, n_rigid, 3, 3)
        Attitudes, products of exponentials (rotations to rounding error).
    theta : ndarray (Σ p_k, 3 n_rigid)
        Local exponential coordinates at each element's nodes after its first (rad).
    element_R : ndarray (K, n_rigid, 3, 3)
        Attitude at each element's start.
    objective : float
        J at the optimum (N²·s/kg for the default cost ∫uᵀM⁻¹u dt).
    status : str
        IPOPT's return status; ``success`` whether it converged.
    iterations : int
    iteration_history : dict of str → ndarray
        Per IPOPT iteration: "obj", "inf_pr", "inf_du", "mu".
    log : str or None
        IPOPT's iteration log, when the solve was asked for it (``log=True``).
    path : dict of str → PathConstraintResult
    timings : dict
        "transcription_s" (building the NLP and the solver), "solve_s" (IPOPT's call), of
        it "evaluations_s" (the NLP's functions and derivatives) and "ipopt_s" (IPOPT's own
        work), "total_s" (s).
    stats : dict
        "constraint_violation" (largest violation of the NLP's constraints),
        "n_variables", "n_constraints", "t_final" (s; the optimum's with a free final
        time), "idle_states" and "idle_controls" (components held at zero:
        :attr:`OptimalControlProblem.idle`), "warm_started" (the solve started from the
        guess's own NLP point and multipliers).
    refinement : list of RefinementStep or None
        The history of :meth:`OptimalControlProblem.solve_adaptive`.
    """

    t: FloatArray
    mesh: Mesh
    body_names: tuple[str, ...]
    body_kinds: tuple[str, ...]
    body_dofs: tuple[int, ...]
    y: FloatArray
    u: FloatArray
    R_NB: FloatArray
    theta: FloatArray
    element_R: FloatArray
    objective: float
    status: str
    success: bool
    iterations: int
    iteration_history: dict[str, FloatArray]
    log: str | None
    path: dict[str, PathConstraintResult]
    timings: dict[str, float]
    stats: dict[str, Any]
    _kkt: Callable[[], dict[str, float]] = field(repr=False)
    refinement: list[RefinementStep] | None = None
    _between: Callable[[OptimalControlResult], dict[str, float]] | None = field(
        default=None, repr=False
    )
    #: the NLP's solution x, parameters p and multipliers λ_x, λ_g (a warm start's)
    _nlp: tuple[FloatArray, FloatArray, FloatArray, FloatArray] | None = field(
        default=None, repr=False
    )

    def __repr__(self) -> str:
        return (
            f"OptimalControlResult(status={self.status!r}, objective={self.objective:.10g}, "
            f"iterations={self.iterations}, {self.mesh!r}, bodies={list(self.body_names)})"
        )

    # ------------------------------------------------------------------ layout
    def _slots(self) -> dict[str, tuple[str, int, int, int]]:
        """name → (kind, first state row, first control row, rigid index or point index)."""
        out, y, u, nr, npm = {}, 0, 0, 0, 0
        for name, kind in zip(self.body_names, self.body_kinds, strict=True):
            if kind == "rigid":
                out[name] = (kind, y, u, nr)
                y, u, nr = y + 9, u + 6, nr + 1
            else:
                out[name] = (kind, y, u, npm)
                y, u, npm = y + 6, u + 3, npm + 1
        return out

    def _rows(self, kind: str, lo: int, hi: int) -> list[int]:
        return [
            y + k for (kd, y, _, _) in self._slots().values() if kd == kind for k in range(lo, hi)
        ]

    @property
    def r_N(self) -> FloatArray:
        """Point-mass positions (N, n_point, 3) (m)."""
        return self.y[:, self._rows("point", 0, 3)].reshape(len(self.t), -1, 3)

    @property
    def v_N(self) -> FloatArray:
        """Point-mass velocities (N, n_point, 3) (m/s)."""
        return self.y[:, self._rows("point", 3, 6)].reshape(len(self.t), -1, 3)

    @property
    def g_NB(self) -> FloatArray:
        """Rigid-body poses (N, n_rigid, 4, 4)."""
        n = self.R_NB.shape[1]
        g = np.zeros((len(self.t), n, 4, 4))
        g[..., :3, :3] = self.R_NB
        g[..., :3, 3] = self.y[:, self._rows("rigid", 0, 3)].reshape(len(self.t), n, 3)
        g[..., 3, 3] = 1.0
        return g

    @property
    def V_B(self) -> FloatArray:
        """Rigid-body twists [ω; v] (N, n_rigid, 6) (rad/s, m/s)."""
        return self.y[:, self._rows("rigid", 3, 9)].reshape(len(self.t), -1, 6)

    def body(self, name: str) -> dict[str, FloatArray]:
        """One body's nodal arrays: ``r_N``, ``v_N`` (point mass) or ``g_NB``, ``V_B``
        (rigid), and its control ``u``."""
        slots = self._slots()
        if name not in slots:
            raise DefinitionError(f"no body {name!r}; bodies are {list(self.body_names)}")
        kind, y, u, i = slots[name]
        if kind == "rigid":
            return {
                "g_NB": self.g_NB[:, i],
                "V_B": self.y[:, y + 3 : y + 9],
                "u": self.u[:, u : u + 6],
            }
        return {
            "r_N": self.y[:, y : y + 3],
            "v_N": self.y[:, y + 3 : y + 6],
            "u": self.u[:, u : u + 3],
        }

    # ------------------------------------------------------------------ interpolation
    def _per_element(self, t: Any, values: FloatArray) -> FloatArray:
        """The degree-p interpolant of nodal ``values`` (N, m) in each element, at t."""
        mesh = self.mesh
        tt = mesh.check_times(t)
        out = np.zeros((tt.size, values.shape[1]))
        elements = mesh.element_of(tt)
        for k in np.unique(elements):
            sel = elements == k
            i0 = mesh.first_node(int(k))
            nodes = mesh.element_times(int(k))
            out[sel] = interpolation_matrix(nodes, tt[sel]) @ values[i0 : i0 + len(nodes)]
        return out

    def control(self, t: Any) -> FloatArray:
        """u at times t: (n_u,) for a scalar t, (len(t), n_u) otherwise; the degree-p
        interpolant of the nodal controls in the element holding each time. Times must be
        finite and within the mesh's span (else :class:`DefinitionError`)."""
        out = self._per_element(t, self.u)
        return out[0] if np.ndim(t) == 0 else out

    def states_at(self, t: Any) -> FloatArray:
        """The state rows y (len(t), n_y) at times t: the degree-p interpolant of the nodal
        states in each element (the method's own state polynomial, the integral of the
        interpolated F, has degree p + 1; they agree at the nodes and differ between them
        by the discretisation error)."""
        return self._per_element(t, self.y)

    def attitudes_at(self, t: Any) -> FloatArray:
        """Attitudes (len(t), n_rigid, 3, 3) at times t: the element's θ interpolated,
        then ``R_k exp(θ^)``. Times must be finite and within the mesh's span."""
        tt = self.mesh.check_times(t)
        nr = self.R_NB.shape[1]
        if nr == 0:
            return np.zeros((tt.size, 0, 3, 3))
        mesh = self.mesh
        out = np.zeros((tt.size, nr, 3, 3))
        elements = mesh.element_of(tt)
        for k in np.unique(elements):
            sel = elements == k
            p = mesh.degrees[int(k)]
            c0 = mesh.first_node(int(k))
            th = np.zeros((p + 1, 3 * nr))
            th[1:] = self.theta[c0 : c0 + p]
            th_t = interpolation_matrix(mesh.element_times(int(k)), tt[sel]) @ th
            out[sel] = self.element_R[int(k)][None] @ so3.exp(th_t.reshape(-1, nr, 3))
        return out

    def controller(self, name: str = "optimal control") -> OpenLoopControl:
        """A :class:`gmuk.Controller` applying this control open loop (for re-simulating the
        optimum with :meth:`gmuk.System.simulate` on a System of the same bodies, without
        the path constraints)."""
        return OpenLoopControl(self, name=name)

    # ------------------------------------------------------------------ KKT
    def kkt(self) -> dict[str, BoundKKT]:
        """Every bound of every path inequality, keyed ``"<constraint>.<side>"``."""
        return {f"{b.constraint}.{b.side}": b for pc in self.path.values() for b in pc.kkt()}

    def kkt_residuals(self) -> dict[str, float]:
        """The NLP's first-order optimality residuals at the solution.

        Returns
        -------
        dict
            ``stationarity`` (max abs of ∇f + J_gᵀλ_g + λ_x), ``stationarity_relative``
            (over max(1, max abs ∇f)), ``primal_violation`` (largest violation of a
            constraint or variable bound), ``complementarity`` (largest abs λ times the
            distance to the bound it pushes, path inequalities), ``dual_violation`` (largest
            multiplier pushing from a side with no bound).
        """
        return self._kkt()

    def violation_between_nodes(self) -> dict[str, float]:
        """The largest violation of each path inequality between the nodes, in its own
        unit (0 where it holds): the constraints hold at the nodes only, and the state's
        interpolant (:meth:`states_at`, :meth:`attitudes_at`) can leave the bounds between
        them. Evaluated on request at 20 equally spaced points inside every element;
        :meth:`OptimalControlProblem.solve_adaptive` with ``bound_tol`` refines until it is
        below a tolerance."""
        if self._between is None:
            return {}
        return self._between(self)

    def summary(self) -> dict[str, Any]:
        """JSON-serialisable headline figures."""
        return {
            "objective": self.objective,
            "status": self.status,
            "iterations": self.iterations,
            "n_elements": self.mesh.n_elements,
            "n_nodes": self.mesh.n_nodes,
            "degrees": sorted(set(self.mesh.degrees)),
            **{k: float(v) for k, v in self.timings.items()},
        }


class OpenLoopControl(Controller):
    """The control of an :class:`OptimalControlResult` as a function of time.

    Each body gets the interpolated nodal control: f_N (N) on a point mass, [L; f] in the
    body frame (N·m, N) on a rigid body. Time outside the solved span is an error.

    Parameters
    ----------
    result : OptimalControlResult
    name : str
    """

    _forms = Forms(
        compiled="an interpolated table in Python: called back from the compiled loop",
        symbolic="gmuk.optimize transcribes no controller (this is its output)",
    )

    def __init__(self, result: OptimalControlResult, *, name: str = "optimal control") -> None:
        if not isinstance(result, OptimalControlResult):
            raise DefinitionError(
                "OpenLoopControl needs an OptimalControlResult (OptimalControlProblem.solve's "
                f"result); got {type(result).__name__}"
            )
        if not isinstance(name, str) or not name:
            raise DefinitionError(f"a controller's name must be a non-empty str; got {name!r:.60}")
        super().__init__(list(result.body_names), name=name)
        self.result = result
        offsets = np.concatenate([[0], np.cumsum(result.body_dofs)])
        self._slices = [slice(int(a), int(b)) for a, b in itertools.pairwise(offsets)]

    def control(
        self, state: State, z: FloatArray, *modeled: FloatArray
    ) -> tuple[Sequence[Any], Any]:
        """The interpolated controls at ``state.t``, one array per body."""
        u = self.result.control(state.t)
        return [u[s] for s in self._slices], np.zeros(0)
