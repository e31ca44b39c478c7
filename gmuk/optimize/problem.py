"""Direct Lobatto (LGL) collocation of a gmuk System: transcription, solve, mesh refinement.

The continuous problem, for the physical bodies of a :class:`gmuk.System` (point masses and
rigid bodies; the slack coordinates of its inequality constraints are not used), is::

    minimise  J = ∫ uᵀ M⁻¹ u dt   (or ∫ L(t, q, ν, u) dt)
    subject to  M ν̇ = Q(t, q, ν) + u            (rigid bodies: + ad*_V 𝕀V, Eq. 10b)
                q̇ from ν                        (ṙ = v; Ṙ = R ω^, ṙ_N = R v_B)
                l ≤ h(q, ν, t) ≤ u                every InequalityConstraint
                φ(q, t) = 0, ψ(q, ν, t) = 0       holonomic / nonholonomic constraints
                the initial state, and any given part of the final state,

with u the generalized control force of every degree of freedom (N for a point mass,
[L; f] in the body frame for a rigid body) and M the System's mass matrix, so that J is the
Gauss-principle cost of McCann (2020) §6.4.

Transcription
-------------
Every element ``[t_k, t_{k+1}]`` of the :class:`~gmuk.optimize.Mesh` carries the p_k + 1 LGL
nodes; states and controls are unknowns at every distinct node (boundary nodes shared, so
states and controls are continuous there). The dynamics ``ẏ = F(t, y, u)`` are imposed in
integral form (Lobatto IIIA collocation, order 2p at the element ends)::

    y_j = y_0 + (h/2) Σ_l A_jl F_l,   j = 1 … p,

with A the LGL integration matrix (:func:`~gmuk.optimize.lgl.lgl_integration_matrix`); the
cost is the LGL quadrature ``Σ_i W_i uᵢᵀ M⁻¹ uᵢ``; path constraints are imposed at every node
after the first (the initial state is fixed and checked before solving).

A rigid body's attitude is kept on SO(3) by local exponential coordinates about each
element's start: ``R(t) = R_k exp(θ(t)^)`` with ``θ(t_k) = 0`` and ``θ̇ = J_r(θ)⁻¹ ω``, and
the start itself ``R_k = R̄_k exp(φ_k^)`` about a constant reference R̄_k taken from the
starting guess (an NLP parameter; φ_0 = 0). Three rows per element boundary,
``vee(skew(R_{k+1}ᵀ R_k exp(θ_p^))) = 0``, join the elements; the same form fixes a final
attitude. The unknowns are θ (3 per node after the first of each element), φ (3 per
element), ω, v_B and r_N; ``ṙ_N = R v_B``. Every attitude gmuk reports is a product of
exponentials, so it is a rotation to rounding error whatever the solver's iterates; no
unit-norm or orthogonality constraint is needed, and θ and φ stay small (bounded per
element), away from the chart's singularity at ‖θ‖ = 2π. Unknown start attitudes, rather
than the chain ``R_{k+1} = R_k exp(θ_p)``, keep the NLP sparse: with the chain every element
depends on all earlier ones. Translation is in inertial
coordinates: SE(3) and SO(3) × R³ are the same manifold, and the exponential chart of SE(3)
would only couple position into the attitude's chart for no gain.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._casadi import casadi
from gmuk._validation import FloatArray, as_array, check_se3, real_number, strict_integer
from gmuk.bodies import Body, BodyKind, RigidBody
from gmuk.constraints.inequality import InequalityConstraint
from gmuk.errors import DefinitionError, OptimizationError
from gmuk.lie import so3
from gmuk.optimize import _blocks, _so3, parts
from gmuk.optimize.lgl import lgl_integration_matrix, lgl_nodes
from gmuk.optimize.mesh import Mesh, split_counts
from gmuk.optimize.result import OptimalControlResult, PathConstraintResult, RefinementStep
from gmuk.state import State

if TYPE_CHECKING:
    from gmuk.engine.system import System

__all__ = ["OptimalControlProblem"]

#: Relative tolerance of the checks of boundary conditions against the path constraints.
BOUNDARY_TOL = 1e-9

#: Sizes (elements) of the partial meshes on which :meth:`OptimalControlProblem.solve` times
#: the build of a larger mesh before building it (see ``_check_build_time``).
CALIBRATION_ELEMENTS = (16, 64)

#: Factor on the build time extrapolated from the partial meshes (see above).
BUILD_MARGIN = 1.5

#: IPOPT's options for a warm start from a previous solution's point and multipliers: start
#: from them, close to the solution (barrier parameter and bound pushes small).
WARM_START_OPTIONS = {
    "ipopt.warm_start_init_point": "yes",
    "ipopt.mu_init": 1e-6,
    "ipopt.warm_start_bound_push": 1e-3,
    "ipopt.warm_start_bound_frac": 1e-3,
    "ipopt.warm_start_slack_bound_push": 1e-3,
    "ipopt.warm_start_slack_bound_frac": 1e-3,
    "ipopt.warm_start_mult_bound_push": 1e-3,
}

#: Points per element, equally spaced between its ends, at which the path inequalities are
#: evaluated between the nodes (``OptimalControlResult.violation_between_nodes``).
BETWEEN_NODE_SAMPLES = 20

#: Meshes of one degree and at most this many elements are built without timing a part
#: first: their build is one element's symbolic work and then, per element, only index
#: arithmetic and sparse assembly (``_blocks``), small beside any budget (under a second at
#: this size: ``benchmarks/README.md``), and the build checks the clock as it goes.
UNTIMED_ELEMENTS = 1000

#: IPOPT options set by :meth:`OptimalControlProblem.solve`'s own arguments.
_RESERVED_OPTIONS = {
    "max_iter": "max_iter",
    "max_cpu_time": "max_cpu_time",
    "max_wall_time": "max_cpu_time",
    "tol": "tol",
}

CostFunction = Callable[[float, tuple[Any, ...], tuple[Any, ...], tuple[Any, ...]], Any]


@dataclass(frozen=True)
class _BodyPlan:
    body: Body
    rigid: bool
    y: int  # first row in Y: point mass [r(3) v(3)], rigid [r_N(3) ω(3) v_B(3)]
    u: int  # first row in U: 3 (point mass) or 6 (rigid)
    th: int  # first row in Θ (rigid only; −1 otherwise)


class OptimalControlProblem:
    """The optimal control of a System's bodies from a given start, transcribed by LGL
    collocation and solved with IPOPT through CasADi.

    Parameters
    ----------
    system : System
        Point masses and rigid bodies; forces with a CasADi form (see
        :mod:`gmuk.optimize.parts`); constraints that are inequalities (their bounds become
        path constraints, not their slack form), holonomic or nonholonomic. Unmodeled forces
        are left out (the plan, like the Udwadia–Kalaba solve, knows only the modeled ones);
        controllers are refused (the optimum is the control).
    initial : State
        The start (its time is t0); only the physical bodies' entries are used.
    t_final : float
        End time tf > t0 (s).
    final : State or mapping, optional
        Final conditions: a State (every physical body's configuration and velocity fixed),
        or a mapping with any of the keys of :meth:`gmuk.System.state` — ``"g"``, ``"V"``
        (rigid), ``"r"``, ``"v"`` (point masses), each a mapping body name → value — fixing
        just those. Default: free.
    cost : callable, optional
        A running cost ``L(t, q, nu, u)`` (CasADi scalar) replacing ``uᵀM⁻¹u``: q, nu as
        for constraints (per physical body), u per body (3×1 or 6×1 CasADi columns).
    max_element_rotation : float
        Bound (rad) on each component of the local exponential coordinates: θ within an
        element and φ, an element's start against its reference attitude from the guess
        (≤ 1.5; default 1.5). Refine the mesh if a body turns faster than that per element,
        and start from a closer guess (``guess=``) if the optimum turns that far from it.
    control_bounds : mapping, optional
        Body name → ``(lower, upper)``: bounds on that body's control at every node, each a
        number or one per component (a point mass's f_N, N; a rigid body's [L; f] in the
        body frame, N·m and N); ``None`` or ±inf for no bound on a side. Default: none.
    free_final_time : (float, float), optional
        ``(t_min, t_max)`` (s): the final time is an unknown in this interval, ``t_final``
        its starting guess (``t_min ≤ t_final ≤ t_max``). The mesh is laid on
        [t0, t_final] and scaled with the final time (its elements keep their proportions).
        Default: the final time is ``t_final``.
    time_cost : float
        Weight (cost units per s, ≥ 0) of the elapsed time ``t_f − t0`` added to the cost;
        with ``cost=lambda t, q, nu, u: 0`` and bounded controls, a minimum-time problem.
        Needs ``free_final_time``. Default 0.
    eliminate_idle : bool
        Hold at zero, rather than solve for, the state and control components that the
        problem's structure proves zero at an optimum (:attr:`idle`: a point mass moved
        along one axis, the translation of a body that only turns): the same optimum with a
        smaller NLP. Default True.

    Raises
    ------
    MissingDependencyError
        When CasADi is not installed.
    DefinitionError
        For a part gmuk cannot transcribe (naming it), controllers, a bad time span or bad
        boundary conditions.
    OptimizationError
        With status ``"Infeasible_Bounds"`` when the initial state or the given final state
        violates a path constraint (checked before solving).
    """

    def __init__(
        self,
        system: System,
        initial: State,
        t_final: float,
        *,
        final: State | Mapping[str, Any] | None = None,
        cost: CostFunction | None = None,
        max_element_rotation: float = 1.5,
        control_bounds: Mapping[str, Any] | None = None,
        free_final_time: tuple[float, float] | None = None,
        time_cost: float = 0.0,
        eliminate_idle: bool = True,
    ) -> None:
        from gmuk.engine.system import System

        casadi()  # CasADi is installed, or a MissingDependencyError with the pip command
        if not isinstance(system, System):
            raise DefinitionError(f"system must be a gmuk.System; got {type(system).__name__}")
        if not isinstance(initial, State) or initial.layout != system.layout:
            raise DefinitionError("initial must be a State of this System (system.state(...))")
        self.system = system
        self.t0 = float(initial.t)
        self.tf = real_number(t_final, "t_final (s)")
        if not self.tf > self.t0:
            raise DefinitionError(f"t_final must be > the initial time {self.t0}; got {self.tf}")
        if cost is not None and not callable(cost):
            raise DefinitionError(f"cost must be a callable L(t, q, nu, u); got {cost!r:.60}")
        self.cost = cost
        rot = real_number(max_element_rotation, "max_element_rotation (rad)", positive=True)
        if rot > 1.5:
            raise DefinitionError(f"max_element_rotation must be in (0, 1.5] rad; got {rot}")
        self.max_element_rotation = rot
        if system.controllers:
            raise DefinitionError(
                "the System has controllers "
                f"{[c.name for c in system.controllers]}; gmuk.optimize computes the control "
                "itself: build the System without them"
            )
        owned = {b.name for c in system.constraints for b in c.owned_bodies}
        self.bodies: tuple[Body, ...] = tuple(b for b in system.bodies if b.name not in owned)
        plans, y, u, th = [], 0, 0, 0
        for b in self.bodies:
            if b.kind is BodyKind.SLACK:
                raise DefinitionError(
                    f"body {b.name!r} is a SlackCoordinate of no inequality constraint; "
                    "gmuk.optimize transcribes point masses and rigid bodies"
                )
            rigid = b.kind is BodyKind.RIGID
            plans.append(_BodyPlan(b, rigid, y, u, th if rigid else -1))
            y += 9 if rigid else 6
            u += 6 if rigid else 3
            th += 3 if rigid else 0
        self._plans = plans
        self._by_name = {p.body.name: p for p in plans}
        self.n_y, self.n_u, self.n_th = y, u, th
        self._forces = self._force_plan()
        self._constraints = [
            (c, parts.constraint_kind(c), self._constraint_plans(c)) for c in system.constraints
        ]
        self._M_inv = np.zeros((u, u))
        for p in plans:
            Minv = np.linalg.inv(p.body.mass_matrix())
            d = p.body.dof
            self._M_inv[p.u : p.u + d, p.u : p.u + d] = Minv
        self.y0, self.R0 = self._initial_values(initial)
        self._final_y, self._final_R = self._final_values(final)
        self.u_lower, self.u_upper = self._control_bounds(control_bounds)
        self.tf_bounds = self._free_final_time(free_final_time)
        if not isinstance(eliminate_idle, (bool, np.bool_)):
            raise DefinitionError(
                f"eliminate_idle must be True or False; got {eliminate_idle!r:.40}"
            )
        self.eliminate_idle = bool(eliminate_idle)
        self.time_cost = real_number(time_cost, "time_cost")
        if self.time_cost < 0.0:
            raise DefinitionError(f"time_cost must be ≥ 0; got {self.time_cost}")
        if self.time_cost and self.tf_bounds is None:
            raise DefinitionError(
                "time_cost weighs the final time, which is fixed: give free_final_time="
                "(t_min, t_max) too"
            )
        self._check_boundaries()

    # ------------------------------------------------------------------ set-up
    def _plan_named(self, name: Any, where: str) -> _BodyPlan:
        """The plan of the physical body ``name``; a DefinitionError naming ``where`` and the
        problem's bodies otherwise."""
        plan = self._by_name.get(name) if isinstance(name, str) else None
        if plan is None:
            raise DefinitionError(
                f"{where} names unknown body {name!r}; the problem's bodies are "
                f"{sorted(self._by_name)}"
            )
        return plan

    def _control_bounds(self, bounds: Any) -> tuple[FloatArray, FloatArray]:
        """Per control component: lower and upper bound (−inf/inf where none)."""
        lower, upper = np.full(self.n_u, -np.inf), np.full(self.n_u, np.inf)
        if bounds is None:
            return lower, upper
        if not isinstance(bounds, Mapping):
            raise DefinitionError(
                "control_bounds must map body names to (lower, upper), e.g. "
                f"{{'sat': (-0.1, 0.1)}}; got {type(bounds).__name__}"
            )
        for name, pair in bounds.items():
            plan = self._plan_named(name, "control_bounds")
            if not isinstance(pair, (tuple, list)) or len(pair) != 2:
                raise DefinitionError(
                    f"control_bounds[{name!r}] must be (lower, upper); got {pair!r:.60}"
                )
            d = plan.body.dof
            sides = []
            for side, value, default in (("lower", pair[0], -np.inf), ("upper", pair[1], np.inf)):
                try:
                    v = np.array(
                        [default if e is None else e for e in value]
                        if isinstance(value, (list, tuple))
                        else (default if value is None else value),
                        dtype=float,
                    )
                except (TypeError, ValueError):
                    v = np.full(0, np.nan)
                if v.ndim == 0:
                    v = np.full(d, float(v))
                if v.shape != (d,) or np.isnan(v).any():
                    raise DefinitionError(
                        f"control_bounds[{name!r}] {side}: a number or {d} numbers (not NaN) "
                        f"for its {d} control components; got {value!r:.60}"
                    )
                sides.append(v)
            if np.any(sides[0] > sides[1]):
                raise DefinitionError(
                    f"control_bounds[{name!r}]: lower {sides[0]} exceeds upper {sides[1]}"
                )
            lower[plan.u : plan.u + d], upper[plan.u : plan.u + d] = sides
        return lower, upper

    def _free_final_time(self, bounds: Any) -> tuple[float, float] | None:
        """(t_min, t_max) of a free final time, checked against t0 and the guess t_final."""
        if bounds is None:
            return None
        if not isinstance(bounds, (tuple, list)) or len(bounds) != 2:
            raise DefinitionError(
                f"free_final_time must be (t_min, t_max) in s; got {bounds!r:.60}"
            )
        lo = real_number(bounds[0], "free_final_time t_min (s)")
        hi = real_number(bounds[1], "free_final_time t_max (s)")
        if not self.t0 < lo <= self.tf <= hi:
            raise DefinitionError(
                f"free_final_time: need t0 ({self.t0:g}) < t_min ≤ t_final ≤ t_max; got "
                f"t_min {lo:g}, t_final {self.tf:g} (the guess), t_max {hi:g}"
            )
        return lo, hi

    def _force_plan(self) -> list[tuple[Any, list[_BodyPlan]]]:
        out = []
        for f in self.system.forces:
            if not f.modeled:
                continue
            if f.bodies is None:
                bodies = [p for p in self._plans if p.body.kind in f.acts_on]
            else:
                names = [b if isinstance(b, str) else b.name for b in f.bodies]
                if not all(n in self._by_name for n in names):  # acts on slack coordinates
                    if all(n not in self._by_name for n in names):
                        continue
                    raise DefinitionError(
                        f"force model {f.name!r} acts on slack coordinates and bodies together"
                    )
                bodies = [self._by_name[n] for n in names]
            if bodies:
                out.append((f, bodies))
        return out

    def _constraint_plans(self, c: Any) -> list[_BodyPlan]:
        refs = c.physical_bodies if isinstance(c, InequalityConstraint) else c.bodies
        return [self._by_name[b if isinstance(b, str) else b.name] for b in refs]

    def _initial_values(self, state: State) -> tuple[FloatArray, list[FloatArray]]:
        y = np.zeros(self.n_y)
        Rs = []
        for p in self._plans:
            if p.rigid:
                g, V = state.pose(p.body), state.twist(p.body)
                y[p.y : p.y + 3] = g[:3, 3]
                y[p.y + 3 : p.y + 9] = V
                Rs.append(g[:3, :3].copy())
            else:
                y[p.y : p.y + 3] = state.position(p.body)
                y[p.y + 3 : p.y + 6] = state.velocity(p.body)
        return y, Rs

    def _final_values(
        self, final: State | Mapping[str, Any] | None
    ) -> tuple[dict[int, float], dict[str, FloatArray]]:
        """Fixed final entries of Y (row → value) and final attitudes (rigid name → R)."""
        fixed: dict[int, float] = {}
        Rf: dict[str, FloatArray] = {}
        if final is None:
            return fixed, Rf
        if isinstance(final, State):
            if final.layout != self.system.layout:
                raise DefinitionError("final must be a State of this System or a mapping")
            spec: dict[str, dict[str, Any]] = {"g": {}, "V": {}, "r": {}, "v": {}}
            for p in self._plans:
                if p.rigid:
                    spec["g"][p.body.name] = final.pose(p.body)
                    spec["V"][p.body.name] = final.twist(p.body)
                else:
                    spec["r"][p.body.name] = final.position(p.body)
                    spec["v"][p.body.name] = final.velocity(p.body)
        elif isinstance(final, Mapping):
            unknown = set(final) - {"g", "V", "r", "v"}
            if unknown:
                raise DefinitionError(
                    f"final conditions take the keys 'g', 'V', 'r', 'v'; got {sorted(unknown)}"
                )
            spec = {}
            for k in ("g", "V", "r", "v"):
                entry = final.get(k)
                if entry is not None and not isinstance(entry, Mapping):
                    raise DefinitionError(
                        f"final[{k!r}] must be a mapping body name → value (or None); got "
                        f"{type(entry).__name__} {entry!r:.60}"
                    )
                spec[k] = dict(entry or {})
        else:
            raise DefinitionError(
                f"final must be a State, a mapping or None; got {type(final).__name__}"
            )
        for key, values in spec.items():
            for name, value in values.items():
                plan = self._plan_named(name, f"final[{key!r}]")
                if plan.rigid != (key in ("g", "V")):
                    raise DefinitionError(
                        f"final[{key!r}][{name!r}]: {key!r} is for "
                        f"{'rigid bodies' if key in ('g', 'V') else 'point masses'}; "
                        f"{name!r} is a {plan.body.kind} body"
                    )
                if key == "g":
                    g = check_se3(value, f"final['g'][{name!r}]")
                    Rf[name] = g[:3, :3].copy()
                    rows, vals = range(plan.y, plan.y + 3), g[:3, 3]
                elif key == "V":
                    vals = as_array(value, (6,), f"final['V'][{name!r}]", batch=False)
                    rows = range(plan.y + 3, plan.y + 9)
                else:
                    vals = as_array(value, (3,), f"final[{key!r}][{name!r}]", batch=False)
                    rows = range(
                        plan.y + (0 if key == "r" else 3), plan.y + (3 if key == "r" else 6)
                    )
                fixed.update({r: float(v) for r, v in zip(rows, vals, strict=True)})
        return fixed, Rf

    def _body_qv(self, plans: Sequence[_BodyPlan], y: FloatArray, Rs: Sequence[Any]) -> Any:
        """Numeric q, ν tuples of ``plans`` from a Y column and the rigid attitudes."""
        q, nu = [], []
        for p in plans:
            if p.rigid:
                g = np.eye(4)
                g[:3, :3] = Rs[p.th // 3]
                g[:3, 3] = y[p.y : p.y + 3]
                q.append(g)
                nu.append(y[p.y + 3 : p.y + 9].copy())
            else:
                q.append(y[p.y : p.y + 3].copy())
                nu.append(y[p.y + 3 : p.y + 6].copy())
        return tuple(q), tuple(nu)

    def _check_boundaries(self) -> None:
        """Path constraints at t0 (and at tf where the final state fixes their bodies)."""
        problems = []
        ends = [("initial", self.t0, self.y0, self.R0, self._plans)]
        complete = [p for p in self._plans if self._final_fixes(p)]
        if complete:
            yf = self.y0.copy()
            for r, v in self._final_y.items():
                yf[r] = v
            Rf = [self._final_R.get(p.body.name, np.eye(3)) for p in self._plans if p.rigid]
            ends.append(("final", self.tf, yf, Rf, complete))
        for label, t, y, Rs, known in ends:
            for c, kind, plans in self._constraints:
                if not all(p in known for p in plans):
                    continue
                q, nu = self._body_qv(plans, y, Rs)
                if kind == "inequality":
                    h = float(np.asarray(c.value(q, nu, t), dtype=float).reshape(-1)[0])
                    for bd in c.bounds:
                        margin = bd.margin(h)
                        if margin < -BOUNDARY_TOL * max(1.0, abs(bd.value)):
                            problems.append(
                                f"the {label} state violates {c.name!r}: {bd.label} "
                                f"{c.unit} with h = {h:.9g} (outside by {-margin:.3g})"
                            )
                else:
                    args = (q, t) if kind == "holonomic" else (q, nu, t)
                    res = np.asarray(c.residual(*args), dtype=float).reshape(-1)
                    if np.abs(res).max(initial=0.0) > 1e-8:
                        problems.append(
                            f"the {label} state violates the {kind} constraint {c.name!r}: "
                            f"max abs residual {np.abs(res).max():.3g}"
                        )
        if problems:
            raise OptimizationError(
                "infeasible before solving: " + "; ".join(problems), "Infeasible_Bounds"
            )

    def _final_fixes(self, p: _BodyPlan) -> bool:
        rows = range(p.y, p.y + (9 if p.rigid else 6))
        return all(r in self._final_y for r in rows) and (
            not p.rigid or p.body.name in self._final_R
        )

    # ------------------------------------------------------------------ dynamics
    def _rhs(self, t: Any, y: Any, u: Any, Rs: Sequence[Any]) -> Any:
        """F(t, y, u) (n_y × 1) for CasADi SX or DM columns y, u and attitudes Rs."""
        import casadi as ca

        q, nu = self._casadi_qv(self._plans, y, Rs)
        gen = [ca.DM.zeros(p.body.dof, 1) for p in self._plans]
        for f, plans in self._forces:
            idx = [self._plans.index(p) for p in plans]
            terms = parts.force_terms(
                f, t, [q[i] for i in idx], [nu[i] for i in idx], [p.body for p in plans]
            )
            for i, w in zip(idx, terms, strict=True):
                gen[i] = gen[i] + w
        blocks = []
        for i, p in enumerate(self._plans):
            Q = gen[i] + u[p.u : p.u + p.body.dof]
            if p.rigid:
                body = p.body
                assert isinstance(body, RigidBody)
                J = ca.DM(body.inertia)
                w, v = y[p.y + 3 : p.y + 6], y[p.y + 6 : p.y + 9]
                w_dot = ca.DM(np.linalg.inv(body.inertia)) @ (ca.cross(J @ w, w) + Q[:3])
                v_dot = ca.cross(v, w) + Q[3:] / body.mass
                blocks += [Rs[p.th // 3] @ v, w_dot, v_dot]
            else:
                blocks += [y[p.y + 3 : p.y + 6], Q / p.body.mass]
        return ca.vertcat(*blocks)

    @functools.cached_property
    def idle(self) -> tuple[np.ndarray, np.ndarray]:
        """The state and control components (indices into y and u) that are zero at the
        optimum by the problem's structure, so that the transcription holds them at zero
        instead of solving for them: a point mass moved along one axis only, say, or the
        translation of a body that only slews.

        A set Z of components qualifies when, with every component in Z held at zero, any
        feasible trajectory stays feasible and costs no more — so an optimum of the problem
        restricted to Z = 0 is an optimum of the whole. Checked symbolically, on CasADi's
        expressions of the parts, and only what is proved is used:

        * every state in Z starts at zero, and ends at zero or free; every control in Z may
          be zero (its bounds admit 0);
        * the dynamics of a state in Z vanish identically when Z is zero (CasADi simplifies
          them to a structural zero), so Z = 0 is a solution;
        * the dynamics of the other states, the attitude charts' rates, every path
          constraint and a user's running cost do not depend on Z at all;
        * the default cost uᵀM⁻¹u has no cross term between controls in Z and the others
          (M⁻¹ is block-diagonal there), so zeroing them lowers it.

        Z starts as every component allowed by the first rule and shrinks to a fixed point.
        """
        import casadi as ca

        n_y, n_u = self.n_y, self.n_u
        y, u = ca.SX.sym("y", n_y), ca.SX.sym("u", n_u)
        t: Any = ca.SX.sym("t")
        Rs = [ca.SX.sym("R", 3, 3) for _ in range(self.n_th // 3)]
        theta = ca.SX.sym("theta", self.n_th)
        try:
            F = self._rhs(t, y, u, Rs)
            others = [self._theta_rate(theta, y)] if self.n_th else []
            for c, kind, plans in self._constraints:
                q, nu = self._casadi_qv(plans, y, Rs)
                if kind == "inequality":
                    others.append(parts.inequality_value(c, q, nu, t))
                else:
                    others.append(parts.equality_residual(c, q, nu, t))
            if self.cost is not None:
                q, nu = self._casadi_qv(self._plans, y, Rs)
                us = tuple(u[p.u : p.u + p.body.dof] for p in self._plans)
                others.append(parts._as_column(self.cost(t, q, nu, us), "cost", 1))
        except (DefinitionError, RuntimeError, TypeError, ValueError, NotImplementedError):
            return np.zeros(0, dtype=int), np.zeros(0, dtype=int)  # not analysed: none
        final = self._final_y
        states = {i for i in range(n_y) if self.y0[i] == 0.0 and final.get(i, 0.0) == 0.0}
        controls = {i for i in range(n_u) if self.u_lower[i] <= 0.0 <= self.u_upper[i]}
        rest = ca.vertcat(*others) if others else ca.SX(0, 1)
        while True:
            zs, zu = sorted(states), sorted(controls)
            Z = ca.vertcat(*[y[i] for i in zs], *[u[i] for i in zu])
            at_zero = ca.substitute(F, Z, ca.SX.zeros(Z.shape[0])) if zs or zu else F
            drop_s = {i for i in zs if not at_zero[i].is_zero()}
            # a state outside Z, or anything else, that depends on a component of Z
            needed = ca.vertcat(*[F[i] for i in range(n_y) if i not in states], rest)
            used = np.zeros(n_y + n_u, dtype=bool)
            if needed.shape[0]:
                pattern = ca.jacobian_sparsity(needed, ca.vertcat(y, u))
                used[np.unique(np.asarray(pattern.get_col(), dtype=int))] = True
            drop_s |= {i for i in zs if used[i]}
            drop_u = {i for i in zu if used[n_y + i]}
            if self.cost is None:  # uᵀM⁻¹u: no cross term between Z and the other controls
                outside = [j for j in range(n_u) if j not in controls]
                drop_u |= {i for i in zu if np.any(self._M_inv[i, outside] != 0.0)}
            if not drop_s and not drop_u:
                return np.array(zs, dtype=int), np.array(zu, dtype=int)
            states -= drop_s
            controls -= drop_u

    def _casadi_qv(self, plans: Sequence[_BodyPlan], y: Any, Rs: Sequence[Any]) -> Any:
        import casadi as ca

        q, nu = [], []
        for p in plans:
            if p.rigid:
                top = ca.horzcat(Rs[p.th // 3], y[p.y : p.y + 3])
                q.append(ca.vertcat(top, ca.DM([[0.0, 0.0, 0.0, 1.0]])))
                nu.append(y[p.y + 3 : p.y + 9])
            else:
                q.append(y[p.y : p.y + 3])
                nu.append(y[p.y + 3 : p.y + 6])
        return tuple(q), tuple(nu)

    def _theta_rate(self, theta: Any, y: Any) -> Any:
        import casadi as ca

        rates = []
        for p in self._plans:
            if p.rigid:
                rates.append(_so3.theta_rate_casadi(theta[p.th : p.th + 3], y[p.y + 3 : p.y + 6]))
        return ca.vertcat(*rates)

    def _attitudes(self, R_start: Sequence[Any], theta: Any) -> list[Any]:
        return [
            R_start[p.th // 3] @ _so3.exp_casadi(theta[p.th : p.th + 3])
            for p in self._plans
            if p.rigid
        ]

    def solve(
        self,
        mesh: Mesh | None = None,
        *,
        n_elements: int = 50,
        degree: int = 3,
        guess: OptimalControlResult | None = None,
        warm_start: bool = False,
        max_iter: int = 3000,
        max_cpu_time: float = 120.0,
        tol: float = 1e-8,
        log: bool = False,
        ipopt_options: Mapping[str, Any] | None = None,
    ) -> OptimalControlResult:
        """Transcribe on ``mesh`` and solve with IPOPT, within ``max_cpu_time``.

        Parameters
        ----------
        mesh : Mesh, optional
            Default ``Mesh.uniform(t0, tf, n_elements, degree)``.
        n_elements, degree : int
            Used when ``mesh`` is not given.
        guess : OptimalControlResult, optional
            A previous solution of a problem with the same bodies (any mesh covering
            [t0, tf]) to start from; default: the initial state held (moved linearly, and
            rotated about one axis, towards given final conditions).
        warm_start : bool
            With a ``guess`` solved on this same mesh (a changed parameter, say: a bound, a
            mass, a final condition), start IPOPT from the guess's own point and
            multipliers with its warm-start options (:data:`WARM_START_OPTIONS`) instead of
            the guess's interpolated states alone; ``result.stats["warm_started"]`` says
            whether it could. Default False.
        max_iter : int
            IPOPT's iteration limit, an integer in [0, 2³¹ − 1].
        max_cpu_time : float
            The time budget (s) of the whole call, building the NLP and solving it: IPOPT
            gets what the build left as its CPU- and wall-time limits. A mesh of more than
            1000 elements (64 if its elements' degrees differ) is first timed on 16 (and 64)
            of its elements, and refused up front when building it all would not fit in the
            budget; the build checks the clock as it goes. The call returns or raises within
            about ``max_cpu_time``.
        tol : float
            IPOPT's convergence tolerance (> 0).
        log : bool
            Keep IPOPT's iteration log in ``result.log`` (it is never printed).
        ipopt_options : mapping, optional
            Further IPOPT options, name → str, int or float (``{"mu_strategy":
            "adaptive"}``, ...). The limits above are set by their own arguments, not here.

        Returns
        -------
        OptimalControlResult

        Raises
        ------
        DefinitionError
            For arguments not as above (checked before anything is built).
        OptimizationError
            When IPOPT does not converge; ``status`` is its return status and ``result``
            the last iterate. With status ``"Maximum_CpuTime_Exceeded"`` and no result
            when the budget is spent (or would be) building the NLP.
        """
        budget = _Budget(real_number(max_cpu_time, "max_cpu_time (s)", positive=True))
        settings = _solver_settings(max_iter, tol, log, ipopt_options)
        if mesh is None:
            mesh = Mesh.uniform(self.t0, self.tf, n_elements, degree)
        if not isinstance(mesh, Mesh):
            raise DefinitionError(f"mesh must be a gmuk.optimize.Mesh; got {type(mesh).__name__}")
        self._check_guess(guess)
        if not isinstance(warm_start, (bool, np.bool_)):
            raise DefinitionError(f"warm_start must be True or False; got {warm_start!r:.40}")
        self._check_build_time(mesh, budget)
        tr = _Transcription(self, mesh, budget=budget)
        budget.built = budget.elapsed()
        result = tr.solve(guess=guess, budget=budget, warm_start=bool(warm_start), **settings)
        if not result.success:
            raise OptimizationError(
                f"IPOPT did not solve the problem: {result.status} after {result.iterations} "
                f"iterations (objective {result.objective:.6g}, max constraint violation "
                f"{result.stats.get('constraint_violation', float('nan')):.3g}); "
                + ("see result.log" if log else "solve with log=True for IPOPT's log"),
                result.status,
                result,
            )
        return result

    def _check_guess(self, guess: Any) -> None:
        """A guess is None or the result of a problem with these bodies, finite, covering
        [t0, tf]."""
        if guess is None:
            return
        if not isinstance(guess, OptimalControlResult):
            raise DefinitionError(
                "guess must be an OptimalControlResult (a previous solve of a problem with "
                f"the same bodies) or None; got {type(guess).__name__}"
            )
        mine = [(p.body.name, str(p.body.kind), p.body.dof) for p in self._plans]
        theirs = list(zip(guess.body_names, guess.body_kinds, guess.body_dofs, strict=False))
        nr = self.n_th // 3
        if (
            theirs != mine
            or guess.y.shape[1:] != (self.n_y,)
            or guess.u.shape[1:] != (self.n_u,)
            or guess.R_NB.shape[1:] != (nr, 3, 3)
        ):
            raise DefinitionError(
                "guess is the result of a problem with other bodies: its bodies (name, kind, "
                f"dof) are {theirs}; this problem's are {mine}"
            )
        lo = self.t0 + 1e-9 * max(1.0, abs(self.t0))
        hi = self.tf - 1e-9 * max(1.0, abs(self.tf))
        if self.tf_bounds is not None:  # read at the same fractions of its own span
            hi = guess.mesh.t0
        if guess.mesh.t0 > lo or guess.mesh.tf < hi:
            raise DefinitionError(
                f"guess spans [{guess.mesh.t0:g}, {guess.mesh.tf:g}] s; it must cover the "
                f"problem's span [{self.t0:g}, {self.tf:g}] s"
            )
        arrays = (guess.y, guess.u, guess.theta, guess.element_R)
        if not all(np.all(np.isfinite(a)) for a in arrays):
            raise DefinitionError(
                f"guess holds NaN or inf (its solve ended with status {guess.status!r}); "
                "start from a finite result or from the default guess"
            )

    def _check_build_time(self, mesh: Mesh, budget: _Budget) -> None:
        """Refuse up front a mesh whose NLP would not be built within the budget.

        Building the NLP (CasADi's derivatives and IPOPT's set-up, one call each that
        cannot be interrupted) costs about the same per element; it is timed on the first
        16 elements and, if those suggest the whole might not fit, on the first 64, and
        the mean cost per element extrapolated to the mesh. Not for meshes of one degree
        up to :data:`UNTIMED_ELEMENTS` elements, whose build is cheap (its note)."""
        K = mesh.n_elements
        if K <= CALIBRATION_ELEMENTS[-1] or (K <= UNTIMED_ELEMENTS and len(set(mesh.degrees)) == 1):
            return
        small, large = CALIBRATION_ELEMENTS
        t_small, nlp_small = _time_build(self, mesh, small)
        estimate = t_small / small * K  # an over-estimate: fixed costs counted per element
        budget.reserve = nlp_small / small * K
        timed_on = small
        if estimate <= 0.5 * budget.remaining():
            return
        if 4.0 * t_small < 0.5 * budget.remaining():
            t_large, nlp_large = _time_build(self, mesh, large)
            # the mean cost per element, not the slope between the two, and a margin: the
            # cost per element still grows with the mesh (measured for one point mass:
            # 1.2 ms at 64 elements, 1.3 ms at 10⁴, 1.6 ms or more at 5·10⁴)
            estimate = BUILD_MARGIN * t_large / large * K
            budget.reserve = BUILD_MARGIN * nlp_large / large * K
            timed_on = large
        if estimate > budget.remaining():
            raise OptimizationError(
                f"a mesh of {K} elements would take about {estimate:.3g} s to build (timed "
                f"on its first {timed_on} elements), more than the time budget "
                f"max_cpu_time = {budget.total:g} s "
                f"leaves ({max(budget.remaining(), 0.0):.3g} s): use fewer elements or raise "
                "max_cpu_time",
                "Maximum_CpuTime_Exceeded",
            )

    # ------------------------------------------------------------------ transcription
    def transcribe(self, mesh: Mesh) -> _Transcription:
        """Build the NLP on ``mesh`` (no solve, no time budget); see :meth:`solve`."""
        return _Transcription(self, mesh)

    def solve_adaptive(
        self,
        mesh: Mesh | None = None,
        *,
        tol: float = 1e-6,
        max_rounds: int = 6,
        max_elements: int = 2000,
        n_elements: int = 20,
        degree: int = 3,
        bound_tol: float | None = None,
        **options: Any,
    ) -> OptimalControlResult:
        """Solve, estimate each element's error, split the elements above ``tol`` and
        solve again from the previous solution, until every element is below ``tol`` (and,
        with ``bound_tol``, the path inequalities hold between the nodes to ``bound_tol``).

        The error estimate of element k is the collocation defect between the nodes:
        at 2p + 1 Gauss points inside the element the state polynomial
        ``y(τ) = y_0 + (h/2) ∫ F̃`` (F̃ the interpolant of the nodal F) and the control
        interpolant give ``d = F̃ − F(t, y(τ), u(τ))``; the estimate is
        ``(h/2) ∫ |d| dτ`` per state component, relative to ``1 + max |y|`` over the
        element, the largest over the components. Elements above ``tol`` are split into
        ``⌈(e/tol)^(1/(p+1))⌉`` (2 to 4) equal parts.

        Parameters
        ----------
        mesh : Mesh, optional
            The first mesh (default ``n_elements`` uniform elements of ``degree``).
        tol : float
            Target relative error per element.
        max_rounds : int
            Solves at most, ≥ 1 (the last result is returned even if above ``tol``; its
            ``refinement`` history says so).
        max_elements : int
            Stop refining before a mesh would exceed this many elements.
        bound_tol : float, optional
            Largest violation of a path inequality between the nodes (in its own unit:
            :meth:`~gmuk.optimize.OptimalControlResult.violation_between_nodes`) to accept;
            an element where it is larger is split in two at least. Default: not checked.
        options
            Passed to :meth:`solve`; ``max_cpu_time`` is the budget of each solve.

        Returns
        -------
        OptimalControlResult
            The last solve's, with ``refinement`` the list of :class:`RefinementStep`.
        """
        tol = real_number(tol, "tol", positive=True)
        rounds = strict_integer(max_rounds, "max_rounds", minimum=1)
        most = strict_integer(max_elements, "max_elements", minimum=1)
        b_tol = None if bound_tol is None else real_number(bound_tol, "bound_tol", positive=True)
        if mesh is None:
            mesh = Mesh.uniform(self.t0, self.tf, n_elements, degree)
        history: list[RefinementStep] = []
        guess = options.pop("guess", None)
        result = None
        for rnd in range(rounds):
            result = self.solve(mesh, guess=guess, **options)
            # with a free final time the estimates are of the result's mesh (scaled to its
            # final time); the split applies to the same elements of the unscaled one
            free = self.tf_bounds is not None
            tr = _Transcription(self, result.mesh if free else mesh, build=False, part=free)
            errors = tr.element_errors(result)
            emax = float(errors.max())
            violations = np.zeros(mesh.n_elements)
            if b_tol is not None:
                violations = tr.bound_violations(result)[0]
            history.append(
                RefinementStep(
                    rnd,
                    mesh.n_elements,
                    mesh.n_nodes,
                    result.objective,
                    emax,
                    result.iterations,
                    result.timings["total_s"],
                    float(violations.max()) if b_tol is not None else float("nan"),
                )
            )
            outside = violations > (b_tol if b_tol is not None else np.inf)
            if emax <= tol and not outside.any():
                break
            counts = [
                max(c, 2 if out else 1)
                for c, out in zip(split_counts(errors, tol, mesh.degrees), outside, strict=True)
            ]
            if mesh.n_elements + sum(c - 1 for c in counts) > most:
                break
            mesh, guess = mesh.split(counts), result
        assert result is not None
        return dataclasses.replace(result, refinement=history)


class _Transcription:
    """The NLP of a problem on one mesh (CasADi symbols, bounds, index maps)."""

    def __init__(
        self,
        problem: OptimalControlProblem,
        mesh: Mesh,
        build: bool = True,
        *,
        budget: _Budget | None = None,
        part: bool = False,
    ) -> None:
        """``part``: a mesh that need not span the problem (the first elements only, to time
        the build, see :meth:`OptimalControlProblem._check_build_time`; a result's mesh
        scaled to its free final time, for its error estimates); ``budget``: the clock to
        check."""
        if not isinstance(mesh, Mesh):
            raise DefinitionError(f"mesh must be a gmuk.optimize.Mesh; got {type(mesh).__name__}")
        self.budget = budget or _Budget(float("inf"))
        off = abs(mesh.t0 - problem.t0) > 1e-12 * max(1.0, abs(problem.t0)) or abs(
            mesh.tf - problem.tf
        ) > 1e-12 * max(1.0, abs(problem.tf))
        if off and not part:
            raise DefinitionError(
                f"the mesh spans [{mesh.t0:g}, {mesh.tf:g}] s; the problem [{problem.t0:g}, "
                f"{problem.tf:g}] s"
            )
        self.problem = problem
        self.mesh = mesh
        self.times = mesh.times
        self.W = mesh.quadrature_weights
        self.n_th_cols = sum(mesh.degrees)
        if build:
            self._build()

    # layout of the decision vector: vec(Y) (n_y × N), vec(U) (n_u × N), vec(Θ) (n_th × Σp)
    def _build(self) -> None:
        pb, mesh = self.problem, self.mesh
        N, K, ny, nu_, nth = mesh.n_nodes, mesh.n_elements, pb.n_y, pb.n_u, pb.n_th
        # x = vec(Y), vec(U), vec(Θ), vec(Φ)[, t_f when it is free]
        self.free = pb.tf_bounds is not None
        self.n_x = (ny + nu_) * N + nth * self.n_th_cols + nth * K + int(self.free)
        # path constraints at nodes 1 … N−1 (the last skipped where the final state fixes
        # the constraint's bodies: it was checked before solving)
        self._path_nodes = [
            np.arange(1, N - 1 if all(pb._final_fixes(p) for p in plans) else N)
            for _, _, plans in pb._constraints
        ]
        self.idle_states, self.idle_controls = (
            pb.idle
            if pb.eliminate_idle
            else (
                np.zeros(0, dtype=int),
                np.zeros(0, dtype=int),
            )
        )
        self.bounds = self._simple_bounds()
        # grad_f, jac_g and hess_lag assembled from the blocks' (mapped build), else CasADi's
        self.derivatives: dict[str, Any] = {}
        self.x: Any = None  # the NLP's variables, parameters, cost and rows (CasADi)
        self.p: Any = None
        self.f: Any = None
        self.g: Any = None
        self.mapped = False
        if len(set(mesh.degrees)) == 1:
            try:
                self._build_mapped()
                self.mapped = True
            except DefinitionError:
                self.mapped = False  # a part needs a numeric time: one expression per node
        self.budget.check("transcribing")
        if not self.mapped:
            self._build_unrolled()
            self._check_finite()
            self.budget.check("transcribing")
        # variable bounds: initial state, given final entries, θ and φ per element (φ₀ = 0)
        lbx = np.full(self.n_x, -np.inf)
        ubx = np.full(self.n_x, np.inf)
        lbx[:ny] = ubx[:ny] = pb.y0
        for r, v in pb._final_y.items():
            lbx[(N - 1) * ny + r] = ubx[(N - 1) * ny + r] = v
        th0 = (ny + nu_) * N
        lbx[th0:] = -pb.max_element_rotation
        ubx[th0:] = pb.max_element_rotation
        phi0 = th0 + nth * self.n_th_cols
        lbx[phi0 : phi0 + nth] = ubx[phi0 : phi0 + nth] = 0.0
        lbx[ny * N : th0] = np.tile(pb.u_lower, N)
        ubx[ny * N : th0] = np.tile(pb.u_upper, N)
        nodes = np.arange(N)[:, None]
        for base, size, idle in ((0, ny, self.idle_states), (ny * N, nu_, self.idle_controls)):
            held = (base + nodes * size + idle[None, :]).reshape(-1)
            lbx[held] = ubx[held] = 0.0
        if self.free:
            assert pb.tf_bounds is not None
            lbx[-1], ubx[-1] = pb.tf_bounds
        for i, (r, a, d) in self.bounds.items():
            c, _, _ = pb._constraints[i]
            idx = self._path_nodes[i] * ny + r
            lo, hi = self._path_bounds(c, "inequality")
            lo_y, hi_y = sorted(((lo - d) / a, (hi - d) / a))
            lbx[idx], ubx[idx] = lo_y, hi_y
        self.lbx, self.ubx = lbx, ubx

    def _simple_bounds(self) -> dict[int, tuple[int, float, float]]:
        """The inequalities that bound one state variable, ``l ≤ a y_r + d ≤ u`` with
        constants a ≠ 0 and d (a :class:`~gmuk.PlaneBound` along an axis, say): constraint
        index → (r, a, d). They become bounds on the variables y_r at the path nodes rather
        than rows of the NLP, as one would write them by hand: no rows, no slacks, no
        derivatives to evaluate. Only where nothing else bounds y_r (the initial state and
        given final entries are not path nodes; a second such inequality on the same y_r
        keeps its rows)."""
        import casadi as ca

        pb = self.problem
        y = ca.SX.sym("y", pb.n_y)
        Rs = [ca.SX.sym("R", 3, 3) for _ in range(pb.n_th // 3)]
        t = ca.SX.sym("t")
        found: dict[int, tuple[int, float, float]] = {}
        taken: set[int] = set()
        for i, (c, kind, plans) in enumerate(pb._constraints):
            if kind != "inequality" or self._path_nodes[i].size == 0:
                continue
            q, nu = pb._casadi_qv(plans, y, Rs)
            try:
                h = parts.inequality_value(c, q, nu, t)
            except DefinitionError:
                continue  # needs a numeric time: checked and reported with the rows
            others = ca.vertcat(t, *[ca.vec(R) for R in Rs])
            if ca.depends_on(h, others):
                continue
            J = ca.jacobian(h, y)
            if J.nnz() != 1 or ca.depends_on(J, y):
                continue
            r = int(J.sparsity().get_col()[0])
            a = float(ca.evalf(J)[0, r])
            d = float(ca.evalf(ca.substitute(h, y, ca.DM.zeros(pb.n_y))))
            if not (np.isfinite(a) and np.isfinite(d)) or a == 0.0 or r in taken:
                continue
            if any(r == f for f in pb._final_y) and self._path_nodes[i][-1] == (
                self.mesh.n_nodes - 1
            ):
                continue  # a given final value: keep the row, whose check reports a conflict
            taken.add(r)
            found[i] = (r, a, d)
        return found

    def _path_bounds(self, c: Any, kind: str) -> tuple[float, float]:
        if kind != "inequality":
            return 0.0, 0.0
        lo = next((b.value for b in c.bounds if b.side == "lower"), -np.inf)
        hi = next((b.value for b in c.bounds if b.side == "upper"), np.inf)
        return lo, hi

    def _node_terms(self, t: Any, y: Any, u: Any, Rs: Sequence[Any]) -> tuple[Any, list[Any], Any]:
        """F, the path-constraint values (one column per constraint) and the running cost
        at one node, for symbolic or numeric t."""
        import casadi as ca

        pb = self.problem
        F = pb._rhs(t, y, u, Rs)
        values = []
        for i, (c, kind, plans) in enumerate(pb._constraints):
            if i in self.bounds:
                values.append(ca.DM(0, 1))
                continue
            q, nu = pb._casadi_qv(plans, y, Rs)
            if kind == "inequality":
                values.append(parts.inequality_value(c, q, nu, t))
            else:
                values.append(parts.equality_residual(c, q, nu, t))
        if pb.cost is None:
            L = u.T @ (_dm(pb._M_inv) @ u)
        else:
            q, nu = pb._casadi_qv(pb._plans, y, Rs)
            us = tuple(u[p.u : p.u + p.body.dof] for p in pb._plans)
            L = parts._as_column(pb.cost(t, q, nu, us), "cost", 1)
        return F, values, L

    def _element(
        self, p: int, Rbar: Any, phi: Any, Yk: Any, Uk: Any, THk: Any, tk: Sequence[Any]
    ) -> tuple[Any, Any, Any, Any, list[Any]]:
        """One element's expressions: start and end attitudes (3 × 3 n_rigid), the
        collocation residuals (column), the cost (∫ L over the element) and each
        constraint's values at nodes 1 … p (columns). ``tk`` numeric or symbolic."""
        import casadi as ca

        pb = self.problem
        nth, nr = pb.n_th, pb.n_th // 3
        starts = _element_starts(Rbar, phi)
        thetas = [ca.SX.zeros(nth, 1)] + [THk[:, j] for j in range(p)]
        node_R = [starts] + [pb._attitudes(starts, thetas[j]) for j in range(1, p + 1)]
        Fs, Ls = [], []
        values: list[list[Any]] = [[] for _ in pb._constraints]
        for j in range(p + 1):
            F, vals, L = self._node_terms(tk[j], Yk[:, j], Uk[:, j], node_R[j])
            Fs.append(F)
            Ls.append(L)
            if j > 0:
                for c_vals, v in zip(values, vals, strict=True):
                    c_vals.append(v)
        _x_nodes, w = lgl_nodes(p)
        h = tk[p] - tk[0]
        A = ca.DM(0.5 * np.asarray(lgl_integration_matrix(p))[1:].T)  # (p+1) × p
        dyn = Yk[:, 1:] - ca.repmat(Yk[:, 0], 1, p) - h * (ca.horzcat(*Fs) @ A)
        idle = self.idle_states
        if idle.size:  # states held at zero (OptimalControlProblem.idle): no rows
            dyn = dyn[[i for i in range(pb.n_y) if i not in set(idle.tolist())], :]
        res = [ca.vec(dyn)]
        if nth:
            rates = ca.horzcat(*[pb._theta_rate(thetas[j], Yk[:, j]) for j in range(p + 1)])
            res.append(ca.vec(THk - h * (rates @ A)))
        cost = 0.5 * h * (ca.horzcat(*Ls) @ ca.DM(w))
        R_start = ca.horzcat(*starts) if nr else ca.SX(3, 0)
        R_end = ca.horzcat(*node_R[p]) if nr else ca.SX(3, 0)
        return R_start, R_end, ca.vertcat(*res), cost, [ca.vertcat(*v) for v in values]

    def _symbols(self, kind: Any) -> tuple[Any, Any, Any, Any, Any, Any, Any]:
        """x, p and their views: Y (n_y × N), U (n_u × N), Θ (n_th × Σp), Φ (n_th × K),
        R̄ (3 × 3 n_rigid K)."""
        import casadi as ca

        pb, mesh = self.problem, self.mesh
        N, K, ny, nu_, nth = mesh.n_nodes, mesh.n_elements, pb.n_y, pb.n_u, pb.n_th
        X = kind.sym("x", self.n_x)
        P = kind.sym("p", 9 * (nth // 3) * K)
        o1, o2, o3 = ny * N, (ny + nu_) * N, (ny + nu_) * N + nth * self.n_th_cols
        Y = ca.reshape(X[:o1], ny, N)
        U = ca.reshape(X[o1:o2], nu_, N)
        TH = ca.reshape(X[o2:o3], nth, self.n_th_cols)
        PHI = ca.reshape(X[o3 : o3 + nth * K], nth, K)
        RBAR = ca.reshape(P, 3, 3 * (nth // 3) * K)
        return X, P, Y, U, TH, PHI, RBAR

    def _build_mapped(self) -> None:
        """The NLP as blocks (:mod:`gmuk.optimize._blocks`): one SX function of an element
        (its collocation residuals, path-constraint values and cost), one of the attitude
        continuity between two elements and one of the final attitude, each mapped over its
        instances with the node times as an input. CasADi differentiates one element, not
        every node's copy, so the cost of building the NLP hardly grows with the mesh, and
        the NLP's derivatives are the blocks' own, summed."""
        import casadi as ca

        pb, mesh = self.problem, self.mesh
        K, p, N = mesh.n_elements, mesh.degrees[0], mesh.n_nodes
        ny, nu_, nth, nr = pb.n_y, pb.n_u, pb.n_th, pb.n_th // 3
        # the element's inputs: w = (φ, y₀, Y, u₀, U, Θ[, t_f]) are NLP variables, a = (R̄,
        # the node times) not; with a free final time a holds the nodes' fractions s of the
        # span instead, and the times are t0 + (t_f − t0) s
        free = int(self.free)
        w = ca.SX.sym("w", nth + ny * (p + 1) + nu_ * (p + 1) + nth * p + free)
        a = ca.SX.sym("a", 9 * nr + p + 1)
        cut = np.cumsum([0, nth, ny * (p + 1), nu_ * (p + 1), nth * p])
        phi = w[cut[0] : cut[1]]
        Yk = ca.reshape(w[cut[1] : cut[2]], ny, p + 1)
        Uk = ca.reshape(w[cut[2] : cut[3]], nu_, p + 1)
        THk = ca.reshape(w[cut[3] : cut[4]], nth, p)
        # components held at zero enter as zeros: no derivatives are formed for them
        for M, idle in ((Yk, self.idle_states), (Uk, self.idle_controls)):
            for i in idle.tolist():
                M[i, :] = 0.0
        Rbar = ca.reshape(a[: 9 * nr], 3, 3 * nr)
        node = [a[9 * nr + j] for j in range(p + 1)]
        if self.free:
            node = [pb.t0 + (w[-1] - pb.t0) * sj for sj in node]
        _, _, res, cost, path = self._element(p, Rbar, phi, Yk, Uk, THk, node)
        rows_of = [i for i in range(len(pb._constraints)) if i not in self.bounds]
        element = ca.Function(
            "element", [w, a], [ca.vertcat(res, *[path[i] for i in rows_of]), cost]
        )
        # float() or math.* on a symbol gives NaN silently (CasADi's SX.__float__): a part
        # that needs a numeric time shows it here, at the start, and goes node by node
        x0, p0 = self._sample_point()
        w0 = np.concatenate(
            [np.zeros(nth), x0[: ny * (p + 1)], np.zeros(nu_ * (p + 1)), np.zeros(nth * p)]
            + ([[pb.tf]] if self.free else [])
        )
        a0 = np.concatenate([p0[: 9 * nr], self._node_inputs()[: p + 1]])
        if not all(np.all(np.isfinite(np.asarray(v))) for v in element(w0, a0)):
            raise DefinitionError("a part is not finite with a symbolic time")
        self.budget.check("transcribing")

        # where each element's w sits in x (x = vec(Y), vec(U), vec(Θ), vec(Φ))
        o1, o2 = ny * N, (ny + nu_) * N
        o3 = o2 + nth * self.n_th_cols
        nodes = np.arange(K)[:, None] * p + np.arange(p + 1)[None, :]  # (K, p + 1)

        def entries(base: int, size: int, columns: np.ndarray) -> np.ndarray:
            return (base + columns[..., None] * size + np.arange(size)).reshape(len(columns), -1)

        cols_th = np.arange(K)[:, None] * p + np.arange(p)[None, :]
        w_index = np.hstack(
            [
                entries(o3, nth, np.arange(K)[:, None]),
                entries(0, ny, nodes),
                entries(o1, nu_, nodes),
                entries(o2, nth, cols_th),
            ]
            + ([np.full((K, 1), self.n_x - 1)] if self.free else [])
        )
        P = ca.MX.sym("p", 9 * nr * K)
        T = ca.DM(self._node_inputs()[nodes].T)
        a_el = ca.vertcat(ca.reshape(P, 9 * nr, K), T)

        # the rows: collocation residuals, continuity, each path constraint's, final attitude
        n_res = int(res.shape[0])
        sizes = [int(path[i].shape[0]) // p for i in range(len(pb._constraints))]
        n_cont = 3 * nr * (K - 1) if nr else 0
        n_final = 3 * sum(1 for q in pb._plans if q.rigid and q.body.name in pb._final_R)
        starts = self._row_layout(K * n_res, n_cont, sizes, n_final)
        el_rows = [np.arange(K)[:, None] * n_res + np.arange(n_res)[None, :]]
        for i in rows_of:
            s, r0 = sizes[i], starts[i]
            # node k p + j (j = 1 … p) is path row r0 + (k p + j − 1) s + component, if kept
            n = (nodes[:, 1:] - 1)[:, :, None] * s + np.arange(s)[None, None, :]
            n = n.reshape(K, -1)
            kept = self._path_nodes[i].size * s
            el_rows.append(np.where((n < kept) & (r0 >= 0), r0 + n, -1))
        blocks = [_blocks.Block(element, w_index, a_el, np.hstack(el_rows))]

        if nr:
            # continuity between elements k and k + 1, and the final attitude: functions of
            # (φ_k, θ_k at its last node, φ_k+1) and of (φ_K, θ_K at its last node)
            phi_a, th_a, phi_b = (ca.SX.sym(n, nth) for n in ("phi_a", "theta_a", "phi_b"))
            Ra, Rb = ca.SX.sym("Ra", 9 * nr), ca.SX.sym("Rb", 9 * nr)

            end_a = pb._attitudes(_element_starts(ca.reshape(Ra, 3, 3 * nr), phi_a), th_a)
            start_b = _element_starts(ca.reshape(Rb, 3, 3 * nr), phi_b)
            last = entries(o2, nth, cols_th[:, -1:])  # θ at each element's last node
            phis = entries(o3, nth, np.arange(K)[:, None])
            Rbars = ca.reshape(P, 9 * nr, K)
            if K > 1:
                cont = ca.Function(
                    "continuity",
                    [ca.vertcat(phi_a, th_a, phi_b), ca.vertcat(Ra, Rb)],
                    [_continuity_rows(start_b, end_a), ca.SX(1, 1)],
                )
                blocks.append(
                    _blocks.Block(
                        cont,
                        np.hstack([phis[:-1], last[:-1], phis[1:]]),
                        ca.vertcat(Rbars[:, :-1], Rbars[:, 1:]),
                        K * n_res + np.arange(n_cont).reshape(K - 1, 3 * nr),
                    )
                )
            if n_final:
                final = ca.Function(
                    "final_attitude",
                    [ca.vertcat(phi_a, th_a), Ra],
                    [self._final_attitude_rows(end_a), ca.SX(1, 1)],
                )
                blocks.append(
                    _blocks.Block(
                        final,
                        np.hstack([phis[-1:], last[-1:]]),
                        Rbars[:, -1],
                        (starts[-1] + np.arange(n_final))[None, :],
                    )
                )
        if pb.time_cost:  # time_cost (t_f − t0): a block of its own, no rows
            tf_sym = ca.SX.sym("tf")
            elapsed = ca.Function(
                "elapsed_time",
                [tf_sym, ca.SX.sym("a", 0)],
                [ca.SX(0, 1), pb.time_cost * (tf_sym - pb.t0)],
            )
            blocks.append(
                _blocks.Block(
                    elapsed, np.array([[self.n_x - 1]]), ca.DM(0, 1), np.zeros((1, 0), dtype=int)
                )
            )
        X = ca.MX.sym("x", self.n_x)
        self.budget.check("transcribing")
        self.f, self.g, self.derivatives = _blocks.derivative_functions(
            blocks, X, P, int(self.lbg.size)
        )
        self.x, self.p = X, P

    def _build_unrolled(self) -> None:
        """One expression per element, each part called with the nodes' numeric times."""
        import casadi as ca

        pb, mesh = self.problem, self.mesh
        nr = pb.n_th // 3
        X, P, Y, U, TH, PHI, RBAR = self._symbols(ca.SX)
        outs = []
        col = 0
        i0 = 0
        for k, p in enumerate(mesh.degrees):
            self.budget.check(f"transcribing element {k} of {mesh.n_elements}")
            outs.append(
                self._element(
                    p,
                    RBAR[:, 3 * nr * k : 3 * nr * (k + 1)],
                    PHI[:, k],
                    Y[:, i0 : i0 + p + 1],
                    U[:, i0 : i0 + p + 1],
                    TH[:, col : col + p],
                    [
                        pb.t0 + (X[-1] - pb.t0) * float(s) if self.free else float(s)
                        for s in self._node_inputs()[i0 : i0 + p + 1]
                    ],
                )
            )
            col += p
            i0 += p
        self._assemble(
            X,
            P,
            ca.horzcat(*[o[0] for o in outs]),
            ca.horzcat(*[o[1] for o in outs]),
            ca.vertcat(*[o[2] for o in outs]),
            ca.horzcat(*[o[3] for o in outs]),
            [ca.vertcat(*[o[4][c] for o in outs]) for c in range(len(pb._constraints))],
        )

    def _assemble(
        self,
        X: Any,
        P: Any,
        R_start: Any,
        R_end: Any,
        dyn: Any,
        costs: Any,
        path: list[Any],
    ) -> None:
        """The NLP from the elements' outputs: collocation residuals, attitude continuity
        between elements, path constraints (element-major: nodes 1 … N−1 in order), final
        attitudes, and the cost."""
        import casadi as ca

        pb, K = self.problem, self.mesh.n_elements
        nr = pb.n_th // 3
        g_blocks = [dyn]
        if nr and K > 1:
            Ra, Rb = ca.SX.sym("Ra", 3, 3 * nr), ca.SX.sym("Rb", 3, 3 * nr)
            blocks3 = [slice(3 * b, 3 * b + 3) for b in range(nr)]
            rows = _continuity_rows([Ra[:, c] for c in blocks3], [Rb[:, c] for c in blocks3])
            cont = ca.Function("continuity", [Ra, Rb], [rows])
            g_blocks.append(
                ca.vec(cont.map(K - 1)(R_start[:, 3 * nr :], R_end[:, : 3 * nr * (K - 1)]))
            )
        R_last = R_end[:, R_end.shape[1] - 3 * nr :]
        att = self._final_attitude_rows([R_last[:, 3 * b : 3 * b + 3] for b in range(nr)])
        sizes = [v.shape[0] // (self.mesh.n_nodes - 1) for v in path]
        n_eq = sum(b.shape[0] for b in g_blocks)
        starts = self._row_layout(dyn.shape[0], n_eq - dyn.shape[0], sizes, att.shape[0])
        for i, (values, r0) in enumerate(zip(path, starts, strict=False)):
            if r0 >= 0:
                g_blocks.append(values[: sizes[i] * self._path_nodes[i].size])
        self.x, self.p = X, P
        self.g = ca.vertcat(*g_blocks, att)
        self.f = ca.sum2(costs)
        if pb.time_cost:
            self.f = self.f + pb.time_cost * (X[-1] - pb.t0)

    def _row_layout(self, n_dyn: int, n_cont: int, sizes: list[int], n_final: int) -> list[int]:
        """Lay out the rows of g: the collocation residuals (``n_dyn``), the attitude
        continuity (``n_cont``), each path constraint's values at its nodes (``sizes``: its
        values per node) and the final attitudes (``n_final``). Sets ``lbg``, ``ubg`` and
        ``path_rows``; returns each constraint's first row (−1 for one without rows) and,
        last, the first final-attitude row."""
        pb = self.problem
        lbg, ubg = [0.0] * (n_dyn + n_cont), [0.0] * (n_dyn + n_cont)
        # (constraint, kind, nodes, first row, values per node); for an inequality imposed
        # as variable bounds: (constraint, "bound", nodes, its index in _constraints, 1)
        self.path_rows: list[tuple[Any, str, np.ndarray, int, int]] = []
        starts = []
        for i, ((c, kind, _), nodes, s) in enumerate(
            zip(pb._constraints, self._path_nodes, sizes, strict=True)
        ):
            if i in self.bounds:  # variable bounds (_simple_bounds), no rows
                self.path_rows.append((c, "bound", nodes, i, 1))
                starts.append(-1)
                continue
            if nodes.size == 0:
                starts.append(-1)
                continue
            lo, hi = self._path_bounds(c, kind)
            starts.append(len(lbg))
            self.path_rows.append((c, kind, nodes, len(lbg), s))
            lbg += [lo] * (s * nodes.size)
            ubg += [hi] * (s * nodes.size)
        starts.append(len(lbg))
        lbg += [0.0] * n_final
        ubg += [0.0] * n_final
        self.lbg, self.ubg = np.array(lbg), np.array(ubg)
        return starts

    def _node_inputs(self) -> FloatArray:
        """The node times (s), or with a free final time their fractions of the span."""
        if self.free:
            return (self.times - self.problem.t0) / (self.problem.tf - self.problem.t0)
        return np.asarray(self.times, dtype=float)

    def _sample_point(self) -> tuple[FloatArray, FloatArray]:
        """x with the initial state at every node and zero controls and charts, and p with
        the initial attitudes as every element's reference."""
        pb, mesh = self.problem, self.mesh
        x = np.zeros(self.n_x)
        x[: pb.n_y * mesh.n_nodes] = np.tile(pb.y0, mesh.n_nodes)
        if self.free:
            x[-1] = pb.tf
        Rbar = np.tile(np.array(pb.R0).reshape(1, -1, 3, 3), (mesh.n_elements, 1, 1, 1))
        p = np.transpose(Rbar, (2, 0, 1, 3)).reshape(3, -1).reshape(-1, order="F")
        return x, p

    def _check_finite(self) -> None:
        """Refuse an NLP that is not finite at the sample point, naming the part that
        returns NaN there (a numeric method called with CasADi symbols)."""
        import casadi as ca

        x, p = self._sample_point()
        fg = ca.Function("fg", [self.x, self.p], [self.f, self.g])
        if all(np.all(np.isfinite(np.asarray(v))) for v in fg(x, p)):
            return
        pb = self.problem
        y = ca.SX.sym("y", pb.n_y)
        Rs = [ca.SX.sym("R", 3, 3) for _ in pb.R0]
        args = [y, *Rs]
        values = [np.asarray(pb.y0), *[np.asarray(R) for R in pb.R0]]
        q, nu = pb._casadi_qv(pb._plans, y, Rs)
        index = {p_.body.name: i for i, p_ in enumerate(pb._plans)}
        t = float(self.times[0])
        suspects: list[tuple[str, Any]] = []
        for f, plans in pb._forces:
            ids = [index[p_.body.name] for p_ in plans]
            suspects.append(
                (
                    f"force model {f.name!r} ({type(f).__name__})",
                    lambda f=f, ids=ids, plans=plans: ca.vertcat(
                        *parts.force_terms(
                            f,
                            t,
                            [q[i] for i in ids],
                            [nu[i] for i in ids],
                            [p_.body for p_ in plans],
                        )
                    ),
                )
            )
        for c, kind, plans in pb._constraints:
            ids = [index[p_.body.name] for p_ in plans]
            fn = parts.inequality_value if kind == "inequality" else parts.equality_residual
            suspects.append(
                (
                    f"constraint {c.name!r} ({type(c).__name__})",
                    lambda c=c, fn=fn, ids=ids: fn(
                        c, tuple(q[i] for i in ids), tuple(nu[i] for i in ids), t
                    ),
                )
            )
        for who, build in suspects:
            value = np.asarray(ca.Function("part", args, [build()])(*values))
            if not np.all(np.isfinite(value)):
                raise DefinitionError(
                    f"{who} returns NaN or inf at the initial state when evaluated with "
                    "CasADi symbols: does its CasADi form call float(), math.* or numpy on a "
                    "symbol (CasADi turns those into NaN silently)? Write it with casadi "
                    "operations"
                )
        raise DefinitionError(
            "the transcribed problem is not finite at the initial state (NaN or inf in the "
            "dynamics, constraints or cost there)"
        )

    def _final_attitude_rows(self, R_final: Sequence[Any]) -> Any:
        """vee(skew(R_fᵀ R(tf))) = 0 for every rigid body with a given final attitude."""
        import casadi as ca

        pb = self.problem
        rows = []
        for p in pb._plans:
            if p.rigid and p.body.name in pb._final_R:
                rows.append(_skew_vee(ca.DM(pb._final_R[p.body.name]).T @ R_final[p.th // 3]))
        return ca.vertcat(*rows) if rows else ca.DM(0, 1)

    # ------------------------------------------------------------------ guess
    def initial_guess(self, guess: OptimalControlResult | None) -> tuple[FloatArray, FloatArray]:
        """The starting point x₀ and the reference attitudes R̄ (the parameters p)."""
        pb, mesh = self.problem, self.mesh
        N, t = mesh.n_nodes, self.times
        nr = pb.n_th // 3
        s = (t - pb.t0) / (pb.tf - pb.t0)
        if guess is not None:
            # with a free final time the guess is read at the same fraction of its span
            tg = pb.t0 + s * (float(guess.t[-1]) - pb.t0) if self.free else t
            Yg = guess.states_at(tg)
            Ug = guess.control(tg)
            Rg = guess.attitudes_at(tg)
        else:
            yf = pb.y0.copy()
            for r, v in pb._final_y.items():
                yf[r] = v
            Yg = pb.y0[None, :] + s[:, None] * (yf - pb.y0)[None, :]
            Ug = np.zeros((N, pb.n_u))
            rigid = [p for p in pb._plans if p.rigid]
            Rg = np.zeros((N, len(rigid), 3, 3))
            for j, p in enumerate(rigid):
                R0 = pb.R0[j]
                Rf = pb._final_R.get(p.body.name, R0)
                phi = so3.log(R0.T @ Rf)
                Rg[:, j] = R0 @ so3.exp(s[:, None] * phi[None, :])
                if p.body.name in pb._final_R and not any(
                    r in pb._final_y for r in range(p.y + 3, p.y + 6)
                ):
                    Yg[:, p.y + 3 : p.y + 6] = phi / (pb.tf - pb.t0)
        if nr:
            Rg[0] = np.array(pb.R0)  # the start is given
        # element k's reference R̄_k: the guess at its first node; θ at its other nodes:
        # log(R̄_kᵀ R), all elements at once
        starts = np.array([mesh.first_node(k) for k in range(mesh.n_elements)], dtype=int)
        Rbar = np.zeros((mesh.n_elements, 0, 3, 3))
        TH = np.zeros((0, self.n_th_cols))
        if nr:
            Rbar = _orthonormal(Rg[starts])  # (K, n_rigid, 3, 3)
            owner = np.repeat(np.arange(mesh.n_elements), mesh.degrees)  # θ column → element
            later = np.concatenate(
                [starts[k] + np.arange(1, p + 1) for k, p in enumerate(mesh.degrees)]
            )
            self.budget.check("computing the starting point")
            d = so3.log(_orthonormal(np.swapaxes(Rbar[owner], -1, -2) @ Rg[later]))
            rot = pb.max_element_rotation
            TH = np.clip(d, -rot, rot).reshape(-1, pb.n_th).T  # (n_th, Σp)
        x0 = np.concatenate(
            [
                Yg.reshape(-1),
                Ug.reshape(-1),
                TH.reshape(-1, order="F"),
                np.zeros(pb.n_th * mesh.n_elements),
                [pb.tf if guess is None else float(guess.t[-1])] if self.free else [],
            ]
        )
        # p = vec(R̄) with R̄ (3, 3 n_rigid K): element k, body b in columns 3(n_r k + b) …
        params = np.transpose(Rbar, (2, 0, 1, 3)).reshape(3, -1).reshape(-1, order="F")
        return x0, params

    # ------------------------------------------------------------------ solve
    def solve(
        self,
        *,
        guess: OptimalControlResult | None,
        budget: _Budget,
        warm_start: bool = False,
        max_iter: int,
        tol: float,
        log: bool,
        ipopt_options: Mapping[str, Any],
    ) -> OptimalControlResult:
        """Solve with arguments checked by :func:`_solver_settings`; IPOPT gets what is left
        of ``budget`` (less the expected cost of building the solver)."""
        import casadi as ca

        x0, pbar = self.initial_guess(guess)
        warm = self._warm_start(guess) if warm_start else None
        multipliers: dict[str, Any] = {}
        if warm is not None:  # the guess's own NLP point and multipliers
            x0, pbar, lam_x0, lam_g0 = warm
            multipliers = {"lam_x0": lam_x0, "lam_g0": lam_g0}
        x0 = np.clip(x0, self.lbx, self.ubx)
        tic = time.perf_counter()
        left = budget.remaining() - budget.reserve
        budget.check("computing the starting point")
        cpu = max(left, 1e-3 * budget.total)
        log_path = None
        opts: dict[str, Any] = {
            "print_time": False,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.max_iter": int(max_iter),
            "ipopt.max_cpu_time": cpu,
            "ipopt.max_wall_time": cpu,
            "ipopt.tol": tol,
        }
        if log:
            fd, log_path = tempfile.mkstemp(prefix="gmuk-ipopt-", suffix=".log")
            os.close(fd)
            opts["ipopt.output_file"] = log_path
            opts["ipopt.file_print_level"] = 5
        if warm is not None:
            opts.update(WARM_START_OPTIONS)
        opts.update(ipopt_options)
        opts.update(self.derivatives)
        nlp = {"x": self.x, "p": self.p, "f": self.f, "g": self.g}
        try:
            solver = ca.nlpsol("gmuk", "ipopt", nlp, opts)
        except (RuntimeError, TypeError, NotImplementedError) as exc:
            if log_path is not None:
                os.unlink(log_path)
            raise DefinitionError(f"CasADi refused the IPOPT options: {exc}") from None
        setup = time.perf_counter() - tic
        try:
            budget.check("building the solver (CasADi's derivatives)")
        except OptimizationError:
            if log_path is not None:
                os.unlink(log_path)
            raise
        tic = time.perf_counter()
        out = solver(
            x0=x0, p=pbar, lbx=self.lbx, ubx=self.ubx, lbg=self.lbg, ubg=self.ubg, **multipliers
        )
        solve_s = time.perf_counter() - tic
        stats = solver.stats()
        text = None
        if log_path is not None:
            with open(log_path, encoding="utf-8", errors="replace") as fh:
                text = fh.read()
            os.unlink(log_path)
        x = np.asarray(out["x"]).reshape(-1)
        lam_g = np.asarray(out["lam_g"]).reshape(-1)
        lam_x = np.asarray(out["lam_x"]).reshape(-1)
        gval = np.asarray(out["g"]).reshape(-1)
        viol = float(np.maximum(np.maximum(self.lbg - gval, gval - self.ubg), 0.0).max(initial=0))
        iters = stats.get("iterations") or {}
        history = {
            k: np.asarray(iters.get(k, []), dtype=float) for k in ("obj", "inf_pr", "inf_du", "mu")
        }
        evaluations = sum(
            float(v) for k, v in stats.items() if k.startswith("t_wall_nlp_") and v == v
        )
        timings = {
            "transcription_s": budget.built + setup,
            "solve_s": solve_s,
            # of solve_s: the NLP's functions and derivatives, and IPOPT's own work
            "evaluations_s": evaluations,
            "ipopt_s": max(solve_s - evaluations, 0.0),
            "total_s": budget.built + setup + solve_s,
        }
        return self._result(
            x,
            pbar,
            lam_g,
            lam_x,
            gval,
            float(out["f"]),
            stats,
            history,
            text,
            timings,
            viol,
            warm_started=warm is not None,
        )

    def _warm_start(
        self, guess: OptimalControlResult | None
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray] | None:
        """The guess's own NLP point, parameters and multipliers, when it was solved on this
        mesh with an NLP of this layout (same variables and rows); None otherwise."""
        nlp = None if guess is None else guess._nlp
        if nlp is None or guess is None:
            return None
        x, p, lam_x, lam_g = nlp
        same_mesh = guess.mesh.degrees == self.mesh.degrees and np.array_equal(
            guess.mesh.breaks, self.mesh.breaks
        )
        if self.free:  # the guess's mesh is scaled to its final time: compare fractions
            span = guess.mesh.tf - guess.mesh.t0
            mine = (self.mesh.breaks - self.mesh.t0) / (self.mesh.tf - self.mesh.t0)
            same_mesh = guess.mesh.degrees == self.mesh.degrees and np.allclose(
                (guess.mesh.breaks - guess.mesh.t0) / span, mine, rtol=0.0, atol=1e-14
            )
        if not same_mesh or x.size != self.n_x or lam_g.size != self.lbg.size:
            return None
        if p.size != 9 * (self.problem.n_th // 3) * self.mesh.n_elements:
            return None
        return x.copy(), p.copy(), lam_x.copy(), lam_g.copy()

    def path_values(
        self, x: FloatArray, gval: FloatArray, lam_g: FloatArray, lam_x: FloatArray
    ) -> list[tuple[Any, str, np.ndarray, FloatArray, FloatArray, float, float]]:
        """Per path constraint: (constraint, "inequality" or the equality's kind, its nodes,
        its values (n_nodes, m), the NLP's multipliers of them (n_nodes, m, not divided by
        the quadrature weights), lower and upper bound). An inequality imposed as variable
        bounds has the value a y_r + d and the multiplier λ_x / a of the row it replaces."""
        out = []
        ny = self.problem.n_y
        for c, kind, nodes, r0, m in self.path_rows:
            if kind == "bound":
                r, a, d = self.bounds[r0]
                idx = nodes * ny + r
                lo, hi = self._path_bounds(c, "inequality")
                vals = (a * x[idx] + d)[:, None]
                out.append((c, "inequality", nodes, vals, (lam_x[idx] / a)[:, None], lo, hi))
                continue
            n = nodes.size
            rows = np.arange(r0, r0 + n * m)
            out.append(
                (
                    c,
                    kind,
                    nodes,
                    gval[rows].reshape(n, m),
                    lam_g[rows].reshape(n, m),
                    float(self.lbg[rows[0]]),
                    float(self.ubg[rows[0]]),
                )
            )
        return out

    def _unpack(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        pb, N, K = self.problem, self.mesh.n_nodes, self.mesh.n_elements
        ny, nu_, nth = pb.n_y, pb.n_u, pb.n_th
        o1, o2, o3 = ny * N, (ny + nu_) * N, (ny + nu_) * N + nth * self.n_th_cols
        Y = x[:o1].reshape(N, ny)
        U = x[o1:o2].reshape(N, nu_)
        TH = x[o2:o3].reshape(self.n_th_cols, nth)
        PHI = x[o3 : o3 + nth * K].reshape(K, nth)
        return Y, U, TH, PHI

    def _attitudes_numeric(
        self, TH: FloatArray, PHI: FloatArray, pbar: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """Node attitudes (N, n_rigid, 3, 3) and element-start attitudes (K, n_rigid, 3, 3),
        ``R̄_k exp(φ_k) exp(θ)``: products of exponentials. A node shared by two elements
        takes the end of the earlier one (the start of the next equals it to the solver's
        tolerance on the continuity rows)."""
        pb, mesh = self.problem, self.mesh
        nr, K = pb.n_th // 3, mesh.n_elements
        Rbar = pbar.reshape(3, -1, order="F").reshape(3, K, nr, 3).transpose(1, 2, 0, 3)
        starts = Rbar @ so3.exp(PHI.reshape(K, nr, 3))
        R = np.zeros((mesh.n_nodes, nr, 3, 3))
        if nr:
            R[0] = starts[0]
        col = 0
        for k, p in enumerate(mesh.degrees):
            i0 = mesh.first_node(k)
            th = TH[col : col + p].reshape(p, nr, 3)
            R[i0 + 1 : i0 + p + 1] = starts[k][None] @ so3.exp(th)
            col += p
        return R, starts

    def _result(
        self,
        x: FloatArray,
        pbar: FloatArray,
        lam_g: FloatArray,
        lam_x: FloatArray,
        gval: FloatArray,
        objective: float,
        stats: Mapping[str, Any],
        history: dict[str, FloatArray],
        text: str | None,
        timings: dict[str, float],
        violation: float,
        warm_started: bool = False,
    ) -> OptimalControlResult:
        pb, mesh = self.problem, self.mesh
        Y, U, TH, PHI = self._unpack(x)
        R, starts = self._attitudes_numeric(TH, PHI, pbar)
        times, W = self.times, self.W
        if self.free:  # the mesh scaled to the optimal final time
            scale = (float(x[-1]) - pb.t0) / (pb.tf - pb.t0)
            times, W = pb.t0 + (self.times - pb.t0) * scale, self.W * scale
            mesh = Mesh(pb.t0 + (mesh.breaks - pb.t0) * scale, mesh.degrees, max_nodes=mesh.n_nodes)
        paths = {}
        for c, kind, nodes, vals, lam_raw, lo, hi in self.path_values(x, gval, lam_g, lam_x):
            lam = lam_raw / W[nodes][:, None]
            paths[c.name] = PathConstraintResult(
                name=c.name,
                kind=kind,
                t=times[nodes],
                value=vals[:, 0] if kind == "inequality" else vals,
                lower=lo if kind == "inequality" else 0.0,
                upper=hi if kind == "inequality" else 0.0,
                multiplier=lam[:, 0] if kind == "inequality" else lam,
                unit=getattr(c, "unit", "") if kind == "inequality" else "",
                cost_unit="N²·s/kg" if pb.cost is None else "cost",
            )
        return OptimalControlResult(
            t=np.array(times, dtype=float),
            mesh=mesh,
            body_names=tuple(p.body.name for p in pb._plans),
            body_kinds=tuple(str(p.body.kind) for p in pb._plans),
            body_dofs=tuple(p.body.dof for p in pb._plans),
            y=Y.copy(),
            u=U.copy(),
            R_NB=R,
            theta=TH.copy(),
            element_R=starts,
            objective=objective,
            status=str(stats.get("return_status", "unknown")),
            success=bool(stats.get("success", False)),
            iterations=int(stats.get("iter_count", 0)),
            iteration_history=history,
            log=text,
            path=paths,
            timings=timings,
            stats={
                "constraint_violation": violation,
                "n_variables": int(x.size),
                "n_constraints": int(gval.size),
                "t_final": float(times[-1]),
                "idle_states": int(self.idle_states.size),
                "idle_controls": int(self.idle_controls.size),
                "warm_started": bool(warm_started),
            },
            _kkt=_KKTEvaluator(self, x, pbar, lam_g, lam_x),
            _between=lambda res: self.bound_violations(res)[1],
            _nlp=(x.copy(), np.asarray(pbar, dtype=float).copy(), lam_x.copy(), lam_g.copy()),
        )

    # ------------------------------------------------------------------ between the nodes
    def bound_violations(
        self, result: OptimalControlResult, samples: int = BETWEEN_NODE_SAMPLES
    ) -> tuple[FloatArray, dict[str, float]]:
        """How far the path inequalities are violated between the nodes: per element of
        ``result.mesh`` the largest violation of any of them (in each one's own unit), and
        per inequality its largest. The state between the nodes is the result's
        interpolant (:meth:`~gmuk.optimize.OptimalControlResult.states_at`,
        :meth:`~gmuk.optimize.OptimalControlResult.attitudes_at`), evaluated at ``samples``
        equally spaced points inside each element."""
        pb, mesh = self.problem, result.mesh
        K = mesh.n_elements
        frac = np.arange(1, samples + 1) / (samples + 1)
        breaks = np.asarray(mesh.breaks)
        t = (breaks[:-1, None] + np.diff(breaks)[:, None] * frac[None, :]).reshape(-1)
        Y = result.states_at(t)
        R = result.attitudes_at(t)
        per_element = np.zeros(K)
        per_constraint: dict[str, float] = {}
        for c, kind, plans in pb._constraints:
            if kind != "inequality":
                continue
            worst = np.zeros(t.size)
            for i in range(t.size):
                q, nu = pb._body_qv(plans, Y[i], R[i])
                h = float(np.asarray(c.value(q, nu, float(t[i])), dtype=float).reshape(-1)[0])
                worst[i] = max(0.0, *(-bd.margin(h) for bd in c.bounds))
            per_element = np.maximum(per_element, worst.reshape(K, samples).max(axis=1))
            per_constraint[c.name] = float(worst.max(initial=0.0))
        return per_element, per_constraint

    # ------------------------------------------------------------------ error estimate
    def element_errors(self, result: OptimalControlResult) -> FloatArray:
        """Relative collocation-defect estimate of each element (see solve_adaptive)."""
        pb, mesh = self.problem, self.mesh
        nr = pb.n_th // 3
        # the nodal F and θ̇, in one batch
        R_nodes = result.R_NB
        F_nodes = self._rhs_batch(result.t, result.y, result.u, R_nodes)
        per_element = []
        pts_t, pts_y, pts_u, pts_R, pts_T = [], [], [], [], []
        col = 0
        for k, p in enumerate(mesh.degrees):
            i0 = mesh.first_node(k)
            a, b = mesh.breaks[k], mesh.breaks[k + 1]
            h = b - a
            x_nodes, _ = lgl_nodes(p)
            z, wz = np.polynomial.legendre.leggauss(2 * p + 1)
            Ainteg = _integration_at(x_nodes, z)  # (m, p+1)
            L = _interp(x_nodes, z)
            Yk, Uk, Fk = (
                result.y[i0 : i0 + p + 1],
                result.u[i0 : i0 + p + 1],
                F_nodes[i0 : i0 + p + 1],
            )
            th_nodes = np.zeros((p + 1, pb.n_th))
            th_nodes[1:] = result.theta[col : col + p]
            col += p
            Tk = np.array([self._theta_rate_num(th_nodes[j], Yk[j]) for j in range(p + 1)])
            Yz = Yk[0][None, :] + 0.5 * h * Ainteg @ Fk
            Tz = 0.5 * h * Ainteg @ Tk
            Rz = np.array(
                [
                    [
                        result.element_R[k][b_] @ _so3.exp_numeric(Tz[m, 3 * b_ : 3 * b_ + 3])
                        for b_ in range(nr)
                    ]
                    for m in range(z.size)
                ]
            ).reshape(z.size, nr, 3, 3)
            pts_t.append(a + 0.5 * h * (z + 1.0))
            pts_y.append(Yz)
            pts_u.append(L @ Uk)
            pts_R.append(Rz)
            pts_T.append(np.array([self._theta_rate_num(Tz[m], Yz[m]) for m in range(z.size)]))
            scale = 1.0 + np.abs(np.concatenate([Yk, th_nodes], axis=1)).max(axis=0)
            per_element.append((h, wz, L @ Fk, L @ Tk, scale))
        F_pts = self._rhs_batch(
            np.concatenate(pts_t),
            np.concatenate(pts_y),
            np.concatenate(pts_u),
            np.concatenate(pts_R),
        )
        errors = np.zeros(mesh.n_elements)
        m0 = 0
        for k, (h, wz, F_interp, T_interp, scale) in enumerate(per_element):
            m = wz.size
            d = np.concatenate([F_interp - F_pts[m0 : m0 + m], T_interp - pts_T[k]], axis=1)
            m0 += m
            errors[k] = float((0.5 * h * (wz @ np.abs(d)) / scale).max())
        return errors

    def _rhs_batch(self, t: FloatArray, y: FloatArray, u: FloatArray, R: FloatArray) -> FloatArray:
        """F at many points (n, n_y): one mapped CasADi call when the parts take a symbolic
        time, else point by point."""
        import casadi as ca

        pb = self.problem
        n, nr = t.size, pb.n_th // 3
        try:
            ts, ys, us = ca.SX.sym("t"), ca.SX.sym("y", pb.n_y), ca.SX.sym("u", pb.n_u)
            Rs = ca.SX.sym("R", 3, 3 * nr)
            fn = ca.Function(
                "rhs",
                [ts, ys, us, Rs],
                [pb._rhs(ts, ys, us, [Rs[:, 3 * b : 3 * b + 3] for b in range(nr)])],
            )
        except DefinitionError:
            return np.array([self._rhs_num(float(t[i]), y[i], u[i], list(R[i])) for i in range(n)])
        Rflat = np.transpose(R, (2, 0, 1, 3)).reshape(3, 3 * nr * n) if nr else np.zeros((3, 0))
        out = fn.map(n)(t[None, :], y.T, u.T, Rflat)
        return np.asarray(out).T

    def _rhs_num(self, t: float, y: FloatArray, u: FloatArray, Rs: Sequence[FloatArray]) -> Any:
        import casadi as ca

        out = self.problem._rhs(t, ca.DM(y), ca.DM(u), [ca.DM(R) for R in Rs])
        return np.asarray(ca.DM(out)).reshape(-1)

    def _theta_rate_num(self, theta: FloatArray, y: FloatArray) -> FloatArray:
        pb = self.problem
        out = np.zeros(pb.n_th)
        for p in pb._plans:
            if p.rigid:
                out[p.th : p.th + 3] = _so3.theta_rate_numeric(
                    theta[p.th : p.th + 3], y[p.y + 3 : p.y + 6]
                )
        return out


class _KKTEvaluator:
    """The NLP's KKT residuals at the solution, computed on request (builds the gradient of
    the Lagrangian only then)."""

    def __init__(
        self,
        tr: _Transcription,
        x: FloatArray,
        p: FloatArray,
        lam_g: FloatArray,
        lam_x: FloatArray,
    ) -> None:
        self.tr, self.x, self.p, self.lam_g, self.lam_x = tr, x, p, lam_g, lam_x

    def __call__(self) -> dict[str, float]:
        import casadi as ca

        tr = self.tr
        lam = type(tr.x).sym("lam", tr.g.shape[0])
        grad = ca.Function(
            "grad_L", [tr.x, tr.p, lam], [ca.gradient(tr.f + ca.dot(lam, tr.g), tr.x)]
        )
        gL = np.asarray(grad(self.x, self.p, self.lam_g)).reshape(-1) + self.lam_x
        grad_f = ca.Function("grad_f", [tr.x, tr.p], [ca.gradient(tr.f, tr.x)])
        grad_f_val = np.asarray(grad_f(self.x, self.p))
        gval = np.asarray(ca.Function("g", [tr.x, tr.p], [tr.g])(self.x, self.p)).reshape(-1)
        primal = np.maximum(np.maximum(tr.lbg - gval, gval - tr.ubg), 0.0)
        primal_x = np.maximum(np.maximum(tr.lbx - self.x, self.x - tr.ubx), 0.0)
        # complementarity of the inequality rows: λ times the distance to the bound it pushes
        comp = 0.0
        dual = 0.0
        paths = tr.path_values(self.x, gval, self.lam_g, self.lam_x)
        for _c, kind, _nodes, vals, lam_n, lower, upper in paths:
            if kind != "inequality":
                continue
            lam_i, g_i = lam_n[:, 0], vals[:, 0]
            up = upper - g_i if np.isfinite(upper) else np.full_like(g_i, np.inf)
            lo = g_i - lower if np.isfinite(lower) else np.full_like(g_i, np.inf)
            dist = np.where(lam_i > 0, up, lo)
            dist = np.where(np.isfinite(dist), dist, 0.0)
            comp = max(comp, float(np.abs(lam_i * dist).max(initial=0.0)))
            # a multiplier pushing from a side with no bound is dual-infeasible
            wrong = np.where(lam_i > 0, not np.isfinite(upper), not np.isfinite(lower))
            dual = max(dual, float(np.abs(lam_i[wrong]).max(initial=0.0)))
        return {
            "stationarity": float(np.abs(gL).max(initial=0.0)),
            "stationarity_relative": float(
                np.abs(gL).max(initial=0.0) / max(1.0, float(np.abs(grad_f_val).max(initial=0.0)))
            ),
            "primal_violation": float(max(primal.max(initial=0.0), primal_x.max(initial=0.0))),
            "complementarity": comp,
            "dual_violation": dual,
        }


class _Budget:
    """The wall-clock budget of one :meth:`OptimalControlProblem.solve` (s), from its
    start: ``reserve`` is the expected cost of building the solver, ``built`` the time the
    transcription took."""

    def __init__(self, total: float) -> None:
        self.total = total
        self.start = time.perf_counter()
        self.reserve = 0.0
        self.built = 0.0

    def elapsed(self) -> float:
        return time.perf_counter() - self.start

    def remaining(self) -> float:
        return self.total - self.elapsed()

    def check(self, stage: str) -> None:
        """An :class:`OptimizationError` if the budget is spent (while ``stage``)."""
        if self.remaining() <= 0.0:
            raise OptimizationError(
                f"the time budget max_cpu_time = {self.total:g} s was spent building the NLP "
                f"({self.elapsed():.3g} s, {stage}) before IPOPT started: use fewer elements "
                "or raise max_cpu_time",
                "Maximum_CpuTime_Exceeded",
            )


def _solver_settings(max_iter: Any, tol: Any, log: Any, ipopt_options: Any) -> dict[str, Any]:
    """The solver arguments of :meth:`OptimalControlProblem.solve`, checked."""
    n_iter = strict_integer(
        max_iter, "max_iter", minimum=0, maximum=2**31 - 1, integral_floats=True
    )
    tol_ = real_number(tol, "tol", positive=True)
    if not isinstance(log, (bool, np.bool_)):
        raise DefinitionError(f"log must be True or False; got {type(log).__name__} {log!r:.40}")
    if ipopt_options is None:
        ipopt_options = {}
    if not isinstance(ipopt_options, Mapping):
        raise DefinitionError(
            "ipopt_options must be a mapping of IPOPT option names to values, e.g. "
            f'{{"mu_strategy": "adaptive"}}; got {type(ipopt_options).__name__} '
            f"{ipopt_options!r:.60}"
        )
    opts: dict[str, Any] = {}
    for key, value in ipopt_options.items():
        if not isinstance(key, str) or not key.removeprefix("ipopt."):
            raise DefinitionError(f"IPOPT option names must be non-empty strings; got {key!r:.40}")
        name = key.removeprefix("ipopt.")
        if name in _RESERVED_OPTIONS:
            raise DefinitionError(
                f"IPOPT's {name!r} is set by solve's own argument "
                f"{_RESERVED_OPTIONS[name]}=, not through ipopt_options"
            )
        if isinstance(value, (bool, np.bool_)) or not isinstance(
            value, (str, int, float, np.integer, np.floating)
        ):
            raise DefinitionError(
                f"IPOPT option {name!r} must be a string, an integer or a number (IPOPT "
                f'spells yes/no as "yes"/"no"); got {type(value).__name__} {value!r:.40}'
            )
        if isinstance(value, (float, np.floating)):
            if value != value:
                raise DefinitionError(f"IPOPT option {name!r} must not be NaN")
            value = float(value)
        elif isinstance(value, np.integer):
            value = int(value)
        opts[f"ipopt.{name}"] = value
    return {"max_iter": n_iter, "tol": tol_, "log": bool(log), "ipopt_options": opts}


def _time_build(problem: OptimalControlProblem, mesh: Mesh, n: int) -> tuple[float, float]:
    """Seconds to build the NLP, the starting point, the solver and IPOPT's set-up (no
    iteration) on the first ``n`` elements of ``mesh``; and the part of it spent building
    the solver and setting IPOPT up."""
    import casadi as ca

    tic = time.perf_counter()
    part = Mesh(mesh.breaks[: n + 1], mesh.degrees[:n], max_nodes=mesh.n_nodes)
    tr = _Transcription(problem, part, part=True)
    x0, p = tr.initial_guess(None)
    mid = time.perf_counter()
    opts: dict[str, Any] = {
        "print_time": False,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.max_iter": 0,
        **tr.derivatives,
    }
    solver = ca.nlpsol("timing", "ipopt", {"x": tr.x, "p": tr.p, "f": tr.f, "g": tr.g}, opts)
    solver(x0=np.clip(x0, tr.lbx, tr.ubx), p=p, lbx=tr.lbx, ubx=tr.ubx, lbg=tr.lbg, ubg=tr.ubg)
    end = time.perf_counter()
    return end - tic, end - mid


def _element_starts(Rbar: Any, phi: Any) -> list[Any]:
    """The attitudes at an element's start, ``R̄ exp(φ^)`` per rigid body: R̄ (3 × 3 n_rigid,
    the reference attitudes side by side) and φ (3 n_rigid) CasADi."""
    return [
        Rbar[:, 3 * b : 3 * b + 3] @ _so3.exp_casadi(phi[3 * b : 3 * b + 3])
        for b in range(phi.shape[0] // 3)
    ]


def _continuity_rows(starts_next: Sequence[Any], ends: Sequence[Any]) -> Any:
    """The rows joining two elements, per rigid body ``vee(skew(R_{k+1}ᵀ R_k exp(θ_p)))``:
    the next element's start attitudes and this element's end attitudes."""
    import casadi as ca

    return ca.vertcat(*[_skew_vee(a.T @ e) for a, e in zip(starts_next, ends, strict=True)])


def _skew_vee(E: Any) -> Any:
    """vee of the skew part of a 3 × 3 CasADi matrix: sin(angle) times the axis of a
    rotation E, zero iff E = I (or a half turn)."""
    import casadi as ca

    return 0.5 * ca.vertcat(E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1])


def _dm(a: FloatArray) -> Any:
    import casadi as ca

    return ca.DM(a)


def _orthonormal(R: FloatArray) -> FloatArray:
    """The nearest rotations (..., 3, 3) (a product of rotations drifts by rounding only)."""
    u, _, vt = np.linalg.svd(R)
    flip = np.linalg.det(u @ vt) < 0
    u[..., :, -1] *= np.where(flip, -1.0, 1.0)[..., None]
    out: FloatArray = u @ vt
    return out


def _interp(x: FloatArray, y: FloatArray) -> FloatArray:
    from gmuk.optimize.lgl import interpolation_matrix

    return interpolation_matrix(x, y)


def _integration_at(x: FloatArray, y: FloatArray) -> FloatArray:
    """B (len(y), len(x)): ``B_mj = ∫_{−1}^{y_m} ℓ_j``, ℓ_j the Lagrange basis of nodes x,
    by exact integration of the interpolant in the Legendre basis (Vandermonde solve;
    used only for the error estimate, at modest degree)."""
    n = x.size
    V = np.polynomial.legendre.legvander(x, n - 1)  # (n, n)
    coef = np.linalg.solve(V, np.eye(n))  # Legendre coefficients of each ℓ_j (column j)
    out = np.zeros((y.size, n))
    for j in range(n):
        integ = np.polynomial.legendre.legint(coef[:, j], lbnd=-1.0)
        out[:, j] = np.polynomial.legendre.legval(y, integ)
    return out
