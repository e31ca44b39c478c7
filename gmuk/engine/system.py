"""The System: parts in, accelerations out.

A :class:`System` takes bodies, constraints, force models and controllers once, validates
them (reporting every problem in one :class:`gmuk.errors.DefinitionError`), freezes them,
and builds the constant block-diagonal mass matrix. :meth:`System.accelerations` then maps a
:class:`gmuk.State` to the free, constraint and total accelerations with the multipliers and
diagnostics, and :meth:`System.simulate` integrates on SE(3)ⁿ × Rᵏ. The System stores no State.

References
----------
McCann (2020), Eqs. (2)–(3) (point masses), (63)–(64) (rigid bodies on R⁶), (79)–(80) (T²SE(3)).
"""

from __future__ import annotations

import difflib
import functools
import inspect
import itertools
import math
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal, ParamSpec, TypeVar

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from gmuk._validation import (
    FloatArray,
    all_finite,
    as_array,
    check_se3,
    check_sequence,
    real_number,
)
from gmuk.bodies import Body, BodyKind, RigidBody
from gmuk.constraints.base import Constraint, as_rows
from gmuk.control.base import Controller
from gmuk.dynamics import inertia_pinv
from gmuk.engine import _uk_kernels, solvers, uk
from gmuk.engine.events import Event
from gmuk.engine.integrate import simulate as _simulate
from gmuk.engine.integrators import _program
from gmuk.engine.solvers import QR_COND_LIMIT, QR_MAX_ROWS, Accelerations, UKSolver
from gmuk.engine.tree import TREE, TreeSolver
from gmuk.errors import ConstraintError, DefinitionError, GmukError, NonFiniteError
from gmuk.forces.base import ForceModel
from gmuk.state import Layout, State

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from gmuk.engine.integrators import RungeKuttaMethod
    from gmuk.engine.integrators._program import Program
    from gmuk.trajectory import Trajectory

__all__ = ["QR_COND_LIMIT", "QR_MAX_ROWS", "SPARSE_THRESHOLD", "Accelerations", "System"]

_P = ParamSpec("_P")
_R = TypeVar("_R")


def _names_its_options(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """``func``, whose keyword-only parameters are its options, refusing an unknown keyword
    with a TypeError that lists them (and suggests the closest) instead of Python's bare
    "unexpected keyword argument". ``inspect.signature`` still shows ``func``'s own."""
    params = inspect.signature(func).parameters
    options = [k for k, p in params.items() if p.kind is inspect.Parameter.KEYWORD_ONLY]
    owner = func.__qualname__

    @functools.wraps(func)
    def checked(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        for key in kwargs:
            if key not in params:
                close = difflib.get_close_matches(key, options, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                raise TypeError(
                    f"{owner}() got an unexpected keyword argument {key!r}{hint}; its options "
                    f"are {', '.join(options)}"
                )
        return func(*args, **kwargs)

    return checked


#: Above this many degrees of freedom, ``sparse="auto"`` selects the sparse solve.
SPARSE_THRESHOLD = 300


def _pinv_block(body: Any) -> FloatArray:
    """M⁺ = blkdiag(J⁺, m⁺ I₃) of a rigid body with a singular mass block."""
    out = np.zeros((6, 6))
    out[:3, :3] = inertia_pinv(body.inertia)
    out[3:, 3:] = (1.0 / body.mass if body.mass > 0.0 else 0.0) * np.eye(3)
    return out


def _sqrt_psd(B: FloatArray) -> FloatArray:
    """B^½ of a symmetric positive-semidefinite B (for M⁺^½ from M⁺)."""
    w, U = np.linalg.eigh(B)
    return np.asarray((U * np.sqrt(np.clip(w, 0.0, None))) @ U.T)


class System:
    """Bodies, constraints, forces and controllers, assembled once.

    Parameters
    ----------
    bodies : sequence of Body
        Unique names. Their order is the order of ν, of A's columns and of the results.
    constraints : sequence of Constraint
    forces : sequence of ForceModel
    controllers : sequence of Controller
    solver : str or UKSolver subclass, optional
        The Udwadia–Kalaba solve strategy (:mod:`gmuk.engine.solvers`): "fused", "dense",
        "sparse", "tree", "eq80", or any registered name or subclass. Default: chosen from
        ``sparse`` and ``tangent_bundle_method`` — "eq80" when asked for, "tree" (linear
        time, :mod:`gmuk.engine.tree`) when ``sparse`` is "auto" and every constraint is a
        :mod:`gmuk.robots` joint, the joints forming a tree or forest with the ground,
        "sparse" when ``sparse`` is True (or "auto" above ``SPARSE_THRESHOLD`` dof), else
        "fused" when the System allows it (rigid bodies only, every load modeled), else
        "dense".
    sparse : {"auto", True, False}
        Sparse or dense rows and mass blocks when ``solver`` is not given.
    sparse_solver : {"lu", "cg"}
        Sparse solve of A M⁻¹ Aᵀ λ = r: direct LU (exact; best for chain- or mesh-like
        coupling) or conjugate gradients (best for large, randomly coupled systems); see
        :func:`gmuk.engine.uk.solve_sparse`.
    tangent_bundle_method : {"reachable", "eq80"}
        How a :class:`~gmuk.constraints.TangentBundleConstraint` is solved. "reachable"
        (default): its rows restrict ``A g̈ B = C`` to reachable accelerations
        ``g(V^² + V̇^)`` (:func:`gmuk.engine.uk.reachable_rows`) and stack with any other
        constraint's rows. "eq80": McCann (2020) Eq. 80 as printed, each body's block of
        g̈_c projected onto g·se(3) (``Accelerations.unreachable`` says how much it
        discarded); the System then takes that one constraint only. They agree for full
        tracking (A = B = I₄).
    strict : bool
        Raise :class:`gmuk.errors.InconsistentConstraintsError` on inconsistent constraints
        instead of warning.
    consistency_tol : float
        Constraints count as inconsistent when ‖A ν̇ − b‖₂ > tol · (‖b‖₂ + ‖A‖_F (‖ν̇_a‖₂ +
        ‖ν̇_c‖₂)): relative to the size of the rows, so scaling them (and b) by any factor
        does not change the decision.
    rcond : float, optional
        Relative singular-value cut-off for the rank of A M^{-1/2} (dense solves).

    Attributes
    ----------
    solver : UKSolver
        The strategy chosen for this System.

    Raises
    ------
    DefinitionError
        Listing every problem found (duplicate names, unknown bodies, a part given a body
        of a kind it does not act on, a solver that cannot take these parts …).

    Notes
    -----
    Each part declares what it needs, and the System checks it here, once: constraints their
    ``body_kinds``, force models their ``acts_on``, solve strategies their ``problems``. A
    new kind of part needs no change to the System.
    """

    def __init__(
        self,
        bodies: Sequence[Body],
        constraints: Sequence[Constraint] = (),
        forces: Sequence[ForceModel] = (),
        controllers: Sequence[Controller] = (),
        *,
        solver: str | type[UKSolver] | None = None,
        sparse: bool | str = "auto",
        sparse_solver: str = "lu",
        tangent_bundle_method: str = "reachable",
        strict: bool = False,
        consistency_tol: float = 1e-8,
        rcond: float | None = None,
    ) -> None:
        bodies = check_sequence(bodies, "bodies")
        self.constraints = check_sequence(constraints, "constraints")
        forces = check_sequence(forces, "forces")
        controllers = check_sequence(controllers, "controllers")
        # Bodies the constraints bring (an inequality's slack coordinates) come last.
        owned = [b for c in self.constraints if isinstance(c, Constraint) for b in c.owned_bodies]
        self.bodies = (*bodies, *owned)
        self._owned_names = frozenset(b.name for b in owned)
        self.forces = tuple(forces)
        self.controllers = tuple(controllers)
        problems = self._validate()
        if not problems:  # what a controller asks of the rest of the System
            problems = [p for ctl in self.controllers for p in ctl._system_problems(self)]
        if problems:
            raise DefinitionError(problems)
        if sparse not in ("auto", True, False):
            raise DefinitionError(f"sparse must be 'auto', True or False; got {sparse!r}")
        if sparse_solver not in ("lu", "cg"):
            raise DefinitionError(f"sparse_solver must be 'lu' or 'cg'; got {sparse_solver!r}")
        if tangent_bundle_method not in ("reachable", "eq80"):
            raise DefinitionError(
                f"tangent_bundle_method must be 'reachable' or 'eq80'; got "
                f"{tangent_bundle_method!r}"
            )
        self.tangent_bundle_method = tangent_bundle_method
        self.sparse_solver = sparse_solver
        parts: list[Constraint | ForceModel | Controller] = [
            *self.constraints,
            *self.forces,
            *self.controllers,
        ]
        for part in parts:
            part._freeze()
        if not isinstance(strict, (bool, np.bool_)):
            raise DefinitionError(f"strict must be True or False; got {strict!r}")
        self.strict = bool(strict)
        self.consistency_tol = real_number(consistency_tol, "consistency_tol", positive=True)
        if rcond is not None:
            rcond = real_number(rcond, "rcond", positive=True)
            if not rcond < 1.0:
                raise DefinitionError(f"rcond must be in (0, 1) or None; got {rcond!r}")
        self.rcond = rcond
        n_ctrl = sum(c.n_states for c in self.controllers)
        self.layout = Layout(
            tuple(b.name for b in self.bodies),
            tuple(b.kind for b in self.bodies),
            tuple(b.dof for b in self.bodies),
            n_ctrl,
        )
        self._by_name = {b.name: b for b in self.bodies}
        # Whether anything acts on the plant that the UK solve does not see.
        self._plant_only_loads = bool(self.controllers) or any(not f.modeled for f in self.forces)
        self._zero_loads = np.zeros(self.layout.n_dof)
        self._zero_loads.setflags(write=False)
        self._zero_z = self._zero_loads[:0]
        solver_cls = self._choose_solver(solver, sparse)
        if problems := self._singular_problems(solver_cls):
            raise DefinitionError(problems)
        self.sparse = solver_cls.wants_sparse(self)
        self._build_mass()
        self._build_index()
        self.solver: UKSolver = solver_cls(self)
        self._accelerations = self.solver.accelerations

    def _choose_solver(self, solver: object, sparse: bool | str) -> type[UKSolver]:
        """The solve strategy: given, or chosen from the options and the parts."""
        if solver is not None:
            if sparse != "auto" or self.tangent_bundle_method != "reachable":
                raise DefinitionError(
                    "give either solver= or the sparse= / tangent_bundle_method= options, "
                    f"not both; got solver={solver!r}, sparse={sparse!r}, "
                    f"tangent_bundle_method={self.tangent_bundle_method!r}"
                )
            cls = solvers.resolve(solver)
        elif self.tangent_bundle_method == "eq80":
            cls = solvers.TangentBundleEq80Solver
        elif any(getattr(c, "unilateral", False) for c in self.constraints):
            from gmuk.engine.contact import ContactSolver  # the contact solve (its own module)

            cls = ContactSolver
        elif sparse == "auto" and self._joint_tree():
            cls = TreeSolver
        elif sparse is True or (sparse == "auto" and self.layout.n_dof > SPARSE_THRESHOLD):
            cls = solvers.SparseSolver
        elif not solvers.FusedRigidSolver.problems(self):
            cls = solvers.FusedRigidSolver
        else:
            cls = solvers.DenseSolver
        problems = cls.problems(self)
        if problems:
            raise DefinitionError(problems)
        return cls

    def _singular_problems(self, solver_cls: type[UKSolver]) -> list[str]:
        """Why the bodies with a singular mass block (``RigidBody(allow_singular=True)``)
        cannot be solved here: they have no M⁻¹, so only the tree solve, which determines
        their motion through their joints, takes them, and only with every load on them
        going through that solve."""
        singular = [b.name for b in self.bodies if getattr(b, "singular", False)]
        if not singular:
            return []
        shown = ", ".join(repr(n) for n in singular[:5]) + (" …" if len(singular) > 5 else "")
        out = []
        if not issubclass(solver_cls, TreeSolver):
            out.append(
                f"bodies {shown} have a singular mass block (allow_singular): only the tree "
                "solve takes them (every constraint an equality on one or two rigid bodies, "
                f"forming a tree or forest with the ground); this System's solver is "
                f"{solver_cls.name!r}"
            )
        names = set(singular)

        def acts_on_singular(bodies: Any) -> bool:
            if bodies is None:
                return True
            return any((b if isinstance(b, str) else b.name) in names for b in bodies)

        for f in self.forces:
            if not f.modeled and acts_on_singular(f.bodies):
                out.append(
                    f"force {f.name!r} is unmodeled and acts on bodies with a singular mass "
                    f"block ({shown}): a load the solve does not see needs M⁻¹"
                )
        for ctl in self.controllers:
            if acts_on_singular(ctl.bodies):
                out.append(
                    f"controller {ctl.name!r} acts on bodies with a singular mass block "
                    f"({shown}): a controller's load is applied after the solve, through M⁻¹"
                )
        return out

    def _joint_tree(self) -> bool:
        """Whether every constraint is a joint of :mod:`gmuk.robots` and they form a tree or
        forest with the ground (what the tree solve takes, :class:`TreeSolver`)."""
        joints = sys.modules.get("gmuk.robots.joints")  # no joint unless that is imported
        if joints is None or not self.constraints:
            return False
        if not all(isinstance(c, joints.Joint) for c in self.constraints):
            return False
        return not TreeSolver.problems(self)

    @property
    def tangent_bundle(self) -> bool:
        """Whether the System is solved by McCann (2020) Eq. 80 on T²SE(3)."""
        return isinstance(self.solver, solvers.TangentBundleEq80Solver)

    # ------------------------------------------------------------------ validation
    def _validate(self) -> list[str]:
        problems: list[str] = []
        names: dict[str, int] = {}
        for i, b in enumerate(self.bodies):
            if not isinstance(b, Body):
                problems.append(f"bodies[{i}] must be a gmuk.Body; got {type(b).__name__}")
                continue
            if b.name in names:
                problems.append(
                    f"duplicate body name {b.name!r} (bodies[{names[b.name]}] and bodies[{i}])"
                )
            names.setdefault(b.name, i)
        if not self.bodies:
            problems.append("a System needs at least one body")
        kinds = {b.name: b.kind for b in self.bodies if isinstance(b, Body)}

        def check_refs(label: str, refs: Iterable[Body | str], allowed: Iterable[str]) -> None:
            allowed = frozenset(allowed)
            for ref in refs:
                name = ref if isinstance(ref, str) else getattr(ref, "name", None)
                if name not in kinds:
                    problems.append(
                        f"{label} refers to unknown body {name!r}; bodies are {sorted(kinds)}"
                    )
                elif not isinstance(ref, str) and self.bodies[names[name]] is not ref:
                    problems.append(f"{label} refers to a different body object named {name!r}")
                elif kinds[name] not in allowed:
                    problems.append(
                        f"{label} acts on {' and '.join(sorted(map(str, allowed)))} bodies; "
                        f"{name!r} is a {kinds[name]} body"
                    )

        for i, c in enumerate(self.constraints):
            if not isinstance(c, Constraint):
                problems.append(
                    f"constraints[{i}] must be a gmuk.Constraint; got {type(c).__name__}"
                )
            else:
                own = c.owned_bodies
                refs = [b for b in c.bodies if not any(b is o for o in own)]
                check_refs(f"constraint {c.name!r}", refs, c.body_kinds)
        for i, f in enumerate(self.forces):
            if not isinstance(f, ForceModel):
                problems.append(f"forces[{i}] must be a gmuk.ForceModel; got {type(f).__name__}")
            elif f.bodies is not None:
                check_refs(f"force {f.name!r}", f.bodies, f.acts_on)
        for i, ctl in enumerate(self.controllers):
            if not isinstance(ctl, Controller):
                problems.append(
                    f"controllers[{i}] must be a gmuk.Controller; got {type(ctl).__name__}"
                )
            else:
                check_refs(f"controller {ctl.name!r}", ctl.bodies, ctl.body_kinds)
        return problems

    # ------------------------------------------------------------------ set-up
    def _build_mass(self) -> None:
        blocks = [b.mass_matrix() for b in self.bodies]
        self._M_blocks = blocks
        rigid = [b for b in self.bodies if isinstance(b, RigidBody)]
        self._J = np.array([b.inertia for b in rigid]).reshape(-1, 3, 3)
        #: each rigid body's singular mass block (allow_singular): J⁺ and 1/m → 0 for it
        self._singular = np.array([getattr(b, "singular", False) for b in rigid], dtype=bool)
        if self._singular.any():
            self._Jinv = np.array(
                [inertia_pinv(J) if sing else np.linalg.inv(J)
                 for J, sing in zip(self._J, self._singular, strict=True)]
            ).reshape(-1, 3, 3)  # fmt: skip
        else:
            self._Jinv = np.linalg.inv(self._J) if rigid else self._J.copy()
        self._m_rigid = np.array([b.mass for b in rigid])
        euclid = [b for b in self.bodies if b.kind is not BodyKind.RIGID]
        self._m_euclid = (
            np.concatenate([np.full(b.dof, b.mass) for b in euclid]) if euclid else np.zeros(0)
        )
        singular = [getattr(b, "singular", False) for b in self.bodies]
        # M⁺ = blkdiag(J⁺, m⁺ I) for a singular block: no strategy that reads it takes one
        inv = [
            _pinv_block(body) if sing else np.linalg.inv(B)
            for body, B, sing in zip(self.bodies, blocks, singular, strict=True)
        ]
        inv_sqrt = [
            _sqrt_psd(Bi) if sing else uk.matrix_power_spd(B, -0.5)
            for B, Bi, sing in zip(blocks, inv, singular, strict=True)
        ]
        if self.sparse:  # never form n_dof × n_dof dense matrices on the sparse path
            self._Minv_sp = sp.block_diag(inv, format="csr")
            self._Minv_sqrt_sp = sp.block_diag(inv_sqrt, format="csr")
        else:
            self._M_dense = scipy.linalg.block_diag(*self._M_blocks)
            self._Minv_dense = scipy.linalg.block_diag(*inv)
            self._Minv_sqrt = scipy.linalg.block_diag(*inv_sqrt)

    @property
    def mass_matrix(self) -> FloatArray:
        """The block-diagonal mass matrix M = 𝕀̄ (n_dof, n_dof), dense (SI units)."""
        if self.sparse:
            return scipy.linalg.block_diag(*self._M_blocks)
        return self._M_dense

    def _build_index(self) -> None:
        lay = self.layout
        self._rigid_idx = (lay.rigid_offsets[:, None] + np.arange(6)).reshape(-1, 6)
        self._constraint_cols = [lay.columns(c.bodies) for c in self.constraints]
        # A constraint's columns as a slice when contiguous (basic indexing is ~10× cheaper).
        self._constraint_where: list[slice | np.ndarray] = [
            slice(int(c[0]), int(c[-1]) + 1)
            if c.size and np.array_equal(c, np.arange(c[0], c[-1] + 1))
            else c
            for c in self._constraint_cols
        ]
        # One constraint spanning every dof in order: its A is the System's A as it stands.
        self._single_full_width = len(self._constraint_cols) == 1 and np.array_equal(
            self._constraint_cols[0], np.arange(lay.n_dof)
        )
        self._single_dense = self._single_full_width and not self.sparse
        self._force_bodies: list[list[Body]] = []
        for f in self.forces:
            if f.bodies is None:
                bs = [b for b in self.bodies if b.kind in f.acts_on]
            else:
                bs = [self._resolve(r) for r in f.bodies]
            self._force_bodies.append(bs)
        # Force models that keep ForceModel.wrenches are called per body directly, with each
        # body's slot looked up here once: (model, [(body, rigid?, index, offset, dof)]);
        # the others through their wrenches() (slots None). In the models' order.
        self._force_plan = [
            (f, bs, [self._force_slot(b) for b in bs] if direct else None)
            for f, bs in zip(self.forces, self._force_bodies, strict=True)
            for direct in [type(f).wrenches is ForceModel.wrenches]
        ]
        self._ctrl_bodies = [[self._resolve(r) for r in c.bodies] for c in self.controllers]
        # The CSR pattern of the stacked rows when every constraint gives dense blocks.
        self._csr_pattern: tuple[Any, np.ndarray, np.ndarray, np.ndarray | None] | None = None
        offs = np.cumsum([0] + [c.n_states for c in self.controllers])
        self._ctrl_slices = [slice(int(a), int(b)) for a, b in itertools.pairwise(offs)]

    def _resolve(self, ref: Body | str) -> Body:
        return self._by_name[ref if isinstance(ref, str) else ref.name]

    # ------------------------------------------------------------------ states
    def state(
        self,
        g: Mapping[str, Any] | None = None,
        V: Mapping[str, Any] | None = None,
        *,
        r: Mapping[str, Any] | None = None,
        v: Mapping[str, Any] | None = None,
        s: Mapping[str, Any] | None = None,
        s_dot: Mapping[str, Any] | None = None,
        z: Any = None,
        t: float = 0.0,
    ) -> State:
        """Build a validated State.

        Parameters
        ----------
        g, V : mapping name → array
            Pose g_NB (4, 4) and body twist [ω; v] (6,) of every rigid body.
        r, v : mapping name → array
            Position r_N and velocity v_N (3,) of every point mass (m, m/s).
        s, s_dot : mapping name → float
            Value and rate of every slack coordinate.
        z : array_like, optional
            Controllers' internal states, concatenated in controller order; their
            ``initial_state()`` if omitted.
        t : float
            Time (s).

        Every body's configuration and velocity must be given (nothing is defaulted
        silently); unknown names are an error.
        """
        lay = self.layout
        problems: list[str] = []
        given: dict[str, dict[Any, Any]] = {}
        for key, mapping in (("g", g), ("V", V), ("r", r), ("v", v), ("s", s), ("s_dot", s_dot)):
            if mapping is not None and not isinstance(mapping, Mapping):
                raise DefinitionError(
                    f"{key} must be a mapping of body name to value (a dict); got "
                    f"{type(mapping).__name__} {mapping!r:.60}"
                )
            given[key] = dict(mapping or {})
        need = {
            BodyKind.RIGID: ("g", "V"),
            BodyKind.POINT: ("r", "v"),
            BodyKind.SLACK: ("s", "s_dot"),
        }
        for key, mapping in given.items():
            for name in mapping:
                if name not in self._by_name:
                    problems.append(
                        f"{key}[{name!r}]: no body of that name; bodies are {list(lay.names)}"
                    )
                elif key not in need[self._by_name[name].kind]:
                    problems.append(
                        f"{key}[{name!r}]: {name!r} is a "
                        f"{self._by_name[name].kind} body; give "
                        f"{' and '.join(need[self._by_name[name].kind])}"
                    )
        for b in self.bodies:
            for key in need[b.kind]:
                if b.name in self._owned_names:
                    if b.name in given[key]:
                        problems.append(
                            f"{key}[{b.name!r}]: {b.name!r} belongs to a constraint, which sets "
                            "it from the other bodies' state; do not give it"
                        )
                elif b.name not in given[key]:
                    problems.append(f"missing {key}[{b.name!r}]")
        if problems:
            raise DefinitionError(problems)
        G = np.zeros((lay.n_rigid, 4, 4))
        Vs = np.zeros((lay.n_rigid, 6))
        x = np.zeros(lay.n_euclid)
        xd = np.zeros(lay.n_euclid)
        for b in self.bodies:
            sl = lay.slot(b)
            if b.kind is BodyKind.RIGID:
                pose = as_array(given["g"][b.name], (4, 4), f"g[{b.name!r}]", batch=False)
                G[sl.index] = check_se3(pose, f"g[{b.name!r}]")
                Vs[sl.index] = as_array(given["V"][b.name], (6,), f"V[{b.name!r}]", batch=False)
            elif b.name not in self._owned_names:  # owned ones are set below
                kq, kv = need[b.kind]
                shape = (sl.dof,)
                x[sl.index : sl.index + sl.dof] = as_array(
                    np.reshape(given[kq][b.name], -1), shape, f"{kq}[{b.name!r}]", batch=False
                )
                xd[sl.index : sl.index + sl.dof] = as_array(
                    np.reshape(given[kv][b.name], -1), shape, f"{kv}[{b.name!r}]", batch=False
                )
        if z is None:
            zz = np.concatenate([c.initial_state() for c in self.controllers] or [np.zeros(0)])
        else:
            zz = as_array(np.reshape(z, -1), (lay.n_control,), "z", batch=False)
        tt = real_number(t, "t")
        state = State._adopt(tt, G, Vs, x, xd, np.array(zz, dtype=float), lay)
        if self._owned_names:
            state = self._set_owned(state)
        return state

    def _set_owned(self, state: State) -> State:
        """``state`` with the bodies the constraints own (slack coordinates) filled in from
        the others (a new State: a State's arrays are read-only)."""
        free = self._free(state, self._generalized_forces(state)[0])
        x, xd = state.x.copy(), state.xdot.copy()
        for c, cols in zip(self.constraints, self._constraint_cols, strict=True):
            if not c.owned_bodies:
                continue
            values = c.initial_owned_state(state, free[cols])
            for body, (w, w_dot) in zip(c.owned_bodies, values, strict=True):
                i = self.layout.slot(body).index
                x[i], xd[i] = w, w_dot
        return state.replace(x=x, xdot=xd)

    # ------------------------------------------------------------------ dynamics
    def _apply_Minv(self, Q: FloatArray) -> FloatArray:
        if not self.sparse:
            return self._Minv_dense @ Q
        out = np.empty_like(Q)
        if self.layout.n_rigid:
            Qr = Q[self._rigid_idx]
            ar = np.empty_like(Qr)
            ar[:, :3] = np.einsum("nij,nj->ni", self._Jinv, Qr[:, :3])
            ar[:, 3:] = Qr[:, 3:] / self._m_rigid[:, None]
            out[self._rigid_idx] = ar
        if self.layout.n_euclid:
            e = self.layout.euclid_offsets
            out[e] = Q[e] / self._m_euclid
        return out

    def _apply_M(self, a: FloatArray) -> FloatArray:
        if not self.sparse:
            return self._M_dense @ a
        out = np.empty_like(a)
        if self.layout.n_rigid:
            ar = a[self._rigid_idx]
            Qr = np.empty_like(ar)
            Qr[:, :3] = np.einsum("nij,nj->ni", self._J, ar[:, :3])
            Qr[:, 3:] = ar[:, 3:] * self._m_rigid[:, None]
            out[self._rigid_idx] = Qr
        if self.layout.n_euclid:
            e = self.layout.euclid_offsets
            out[e] = a[e] * self._m_euclid
        return out

    def _free(self, state: State, Q: FloatArray) -> FloatArray:
        """ν̇_a = M⁻¹(ad*_V 𝕀V + Q) (Eq. 10b for rigid bodies, Q/m for the others)."""
        if not self.layout.n_euclid:  # rigid bodies only: ν is the stacked twists
            return _uk_kernels.rigid_free_accel(
                state.V, self._J, self._Jinv, self._m_rigid, Q.reshape(-1, 6)
            ).reshape(-1)
        a = np.empty(self.layout.n_dof)
        if self.layout.n_rigid:
            a[self._rigid_idx] = _uk_kernels.rigid_free_accel(
                state.V, self._J, self._Jinv, self._m_rigid, Q[self._rigid_idx]
            )
        if self.layout.n_euclid:
            e = self.layout.euclid_offsets
            a[e] = Q[e] / self._m_euclid
        return a

    def _generalized_forces(self, state: State) -> tuple[FloatArray, FloatArray]:
        """The modeled and the unmodeled generalized forces (n_dof,) of the force models."""
        if not self.forces:  # shared, read-only zeros
            return self._zero_loads, self._zero_loads
        n = self.layout.n_dof
        modeled, unmodeled = np.zeros(n), np.zeros(n)
        self._add_loads(self._force_plan, state, modeled, unmodeled)
        return modeled, unmodeled

    def _add_loads(
        self, plan: list[Any], state: State, modeled: FloatArray, unmodeled: FloatArray
    ) -> None:
        """Add the generalized forces of the force models of ``plan`` (entries of
        ``_force_plan``) at ``state`` to ``modeled`` and ``unmodeled`` (n_dof,).

        Each model's return values are checked (:func:`_part_output`): arrays of real numbers
        (not booleans, complex numbers, strings or objects) of exactly the body's dof, and,
        once per model, finite. Raises DefinitionError or NonFiniteError naming the model,
        the body and the time."""
        t = state.t
        for f, bodies, slots in plan:
            target = modeled if f.modeled else unmodeled
            try:
                if slots is None:
                    for body, w in zip(bodies, f.wrenches(state, bodies), strict=True):
                        self._add(target, body, w, f, t)
                else:
                    for body, rigid, i, offset, dof in slots:
                        if rigid:
                            w = f.wrench(t, state.g[i], state.V[i], body)
                        else:
                            w = f.force(t, state.x[i : i + dof], state.xdot[i : i + dof], body)
                        if type(w) is not np.ndarray or w.shape != (dof,) or w.dtype != np.float64:
                            w = _part_output(w, (dof,), f, body, t)
                        target[offset : offset + dof] += w
            except ValueError as exc:
                _raise_if_read_only(exc, f, t)
                raise
            if not all_finite(target):  # once per model: it added NaN or inf
                self._not_finite(target, bodies, f, t)

    def _not_finite(self, target: FloatArray, bodies: Iterable[Body], part: Any, t: float) -> None:
        """Raise NonFiniteError naming the first of ``bodies`` whose entries of ``target``
        (n_dof,) are not finite (the load a part just added)."""
        for body in bodies:
            s = self.layout.slot(body)
            if not all_finite(target[s.offset : s.offset + s.dof]):
                raise NonFiniteError(
                    f"{_who(part)} returned a non-finite load (NaN or inf) for {body.kind} body "
                    f"{body.name!r} at t = {t:.9g} s (or loads whose sum is beyond float64)"
                )
        raise NonFiniteError(
            f"{_who(part)} returned a non-finite load (NaN or inf) at t = {t:.9g} s"
        )

    def _force_slot(self, body: Body) -> tuple[Body, bool, int, int, int]:
        s = self.layout.slot(body)
        return body, body.kind is BodyKind.RIGID, s.index, s.offset, s.dof

    def _controls(self, state: State, modeled: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The controllers' generalized forces (n_dof,) and internal-state rates, given the
        modeled acceleration ν̇_a + ν̇_c (n_dof,), which controllers may ask for."""
        if not self.controllers:
            return self._zero_loads, self._zero_z
        return self._controls_of(range(len(self.controllers)), state, modeled)

    def _controls_of(
        self, which: Iterable[int], state: State, modeled: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """:meth:`_controls` of the controllers numbered ``which`` only (ż zero elsewhere).

        Each controller's return values are checked: one wrench per body as in
        :meth:`_add_loads`, and ż an array of real numbers with exactly ``n_states`` entries
        (a scalar or another length is not broadcast), finite. Raises DefinitionError or
        NonFiniteError naming the controller (and the body) and the time."""
        control = np.zeros(self.layout.n_dof)
        z_dot = np.zeros(self.layout.n_control)
        modeled.setflags(write=False)
        t = state.t
        for k in which:
            c, bodies, sl = self.controllers[k], self._ctrl_bodies[k], self._ctrl_slices[k]
            try:
                if c.uses_modeled_acceleration:
                    out = c.control(state, state.z[sl], modeled)
                else:
                    out = c.control(state, state.z[sl])
            except ValueError as exc:
                _raise_if_read_only(exc, c, t)
                raise
            if not (isinstance(out, (tuple, list)) and len(out) == 2):
                raise DefinitionError(
                    f"{_who(c)}: control() must return a pair (u, z_dot); got "
                    f"{type(out).__name__} {out!r:.60}"
                )
            u, zd = out
            try:
                for body, w in zip(bodies, u, strict=True):
                    self._add(control, body, w, c, t)
            except (TypeError, ValueError) as exc:
                if isinstance(exc, GmukError):
                    raise
                raise DefinitionError(
                    f"{_who(c)}: control() must return one load per body ({len(bodies)}) as a "
                    f"sequence; got {type(u).__name__} {u!r:.60}"
                ) from None
            n = sl.stop - sl.start
            if type(zd) is not np.ndarray or zd.shape != (n,) or zd.dtype != np.float64:
                zd = _part_output(zd, (n,), c, None, t)
            z_dot[sl] = zd
            if not all_finite(control):
                self._not_finite(control, bodies, c, t)
            if not all_finite(zd):
                raise NonFiniteError(
                    f"{_who(c)} returned a non-finite z_dot (NaN or inf) at t = {t:.9g} s: "
                    f"{zd!r:.80}"
                )
        return control, z_dot

    def _add(self, target: FloatArray, body: Body, w: Any, part: Any, t: float) -> None:
        """Add a part's load ``w`` for ``body`` into ``target`` (n_dof,), checked as
        :func:`_part_output` checks it (finiteness is the caller's, once per part)."""
        s = self.layout.slot(body)
        if type(w) is not np.ndarray or w.shape != (s.dof,) or w.dtype != np.float64:
            w = _part_output(w, (s.dof,), part, body, t)
        target[s.offset : s.offset + s.dof] += w

    def constraint_rows(self, state: State) -> tuple[FloatArray | sp.csr_matrix, FloatArray]:
        """The stacked rows (A (s, n_dof), b (s,)) of all R⁶ constraints at ``state``
        (a sparse CSR A on the sparse path)."""
        return self._stack_rows(state, check_finite=True)

    def _stack_rows(
        self, state: State, check_finite: bool
    ) -> tuple[FloatArray | sp.csr_matrix, FloatArray]:
        """Stacked rows; with ``check_finite=False`` float64 ndarrays of the right shapes are
        taken as they are and the caller checks finiteness of the stacked A and b (then
        :meth:`constraint_rows` names the culprit)."""
        if self._single_dense and not check_finite:
            # The common small case: one dense constraint on every dof, in order.
            Ai, bi = _pair(self.constraints[0], state)
            if (
                type(Ai) is np.ndarray
                and type(bi) is np.ndarray
                and Ai.dtype == np.float64
                and bi.dtype == np.float64
                and bi.ndim == 1
                and Ai.shape == (bi.shape[0], self.layout.n_dof)
            ):
                return Ai, bi
            Ai, bi = as_rows(Ai, bi, self.layout.n_dof, f"constraint {self.constraints[0].name!r}")
            return (Ai.toarray() if sp.issparse(Ai) else Ai), bi
        blocks = []
        for c, cols in zip(self.constraints, self._constraint_cols, strict=True):
            Ai, bi = _pair(c, state)
            if not (
                not check_finite
                and type(Ai) is np.ndarray
                and type(bi) is np.ndarray
                and Ai.dtype == np.float64
                and bi.dtype == np.float64
                and bi.ndim == 1
                and Ai.shape == (bi.shape[0], cols.size)
            ):
                Ai, bi = as_rows(Ai, bi, cols.size, f"constraint {c.name!r}")
            blocks.append((Ai, bi, cols))
        n = self.layout.n_dof
        s = sum(bi.size for _, bi, _ in blocks)
        b = np.concatenate([bi for _, bi, _ in blocks]) if blocks else np.zeros(0)
        if self.sparse:
            if not blocks:
                return sp.csr_matrix((0, n)), b
            if all(type(Ai) is np.ndarray for Ai, _, _ in blocks):
                return self._csr_from_dense(blocks, s), b
            rows, cols_all, data = [], [], []
            r0 = 0
            for Ai, bi, cols in blocks:
                coo = sp.coo_matrix(Ai)
                rows.append(coo.row + r0)
                cols_all.append(cols[coo.col])
                data.append(coo.data)
                r0 += bi.size
            A_sp = sp.csr_matrix(
                (np.concatenate(data), (np.concatenate(rows), np.concatenate(cols_all))),
                shape=(s, n),
            )
            return A_sp, b
        if self._single_full_width and not sp.issparse(blocks[0][0]):
            return np.ascontiguousarray(blocks[0][0]), b
        A = np.zeros((s, n))
        r0 = 0
        for (Ai, bi, _), where in zip(blocks, self._constraint_where, strict=True):
            A[r0 : r0 + bi.size, where] = Ai.toarray() if sp.issparse(Ai) else Ai
            r0 += bi.size
        return A, b

    def _csr_from_dense(
        self, blocks: list[tuple[Any, FloatArray, np.ndarray]], s: int
    ) -> sp.csr_matrix:
        """The stacked A (s, n_dof) in CSR from dense blocks, by a pattern made once.

        The pattern (column indices, row pointers and the order that sorts each block's
        columns) depends only on the blocks' shapes; it is built on the first call and again
        only when a shape changes. Each call then concatenates the blocks' values: no sparse
        matrix per constraint. Entries that are zero in a block are kept as stored zeros.
        """
        shapes = tuple(Ai.shape for Ai, _, _ in blocks)
        pattern = self._csr_pattern
        if pattern is None or pattern[0] != shapes:
            pattern = self._make_csr_pattern(shapes, [cols for _, _, cols in blocks])
            self._csr_pattern = pattern
        _, indices, indptr, gather = pattern
        data = np.concatenate([Ai.ravel() for Ai, _, _ in blocks])
        if gather is not None:
            data = data[gather]
        # copies: scipy may sort or prune a matrix's index arrays in place
        return sp.csr_matrix(
            (data, indices.copy(), indptr.copy()), shape=(s, self.layout.n_dof), copy=False
        )

    @staticmethod
    def _make_csr_pattern(
        shapes: tuple[tuple[int, ...], ...], columns: list[np.ndarray]
    ) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray | None]:
        indices, gather, counts = [], [], []
        base = 0
        for (rows, width), cols in zip(shapes, columns, strict=True):
            order = np.argsort(cols, kind="stable")
            indices.append(np.tile(cols[order], rows))
            gather.append(base + (np.arange(rows)[:, None] * width + order[None, :]).ravel())
            counts.append(np.full(rows, width))
            base += rows * width
        index = np.concatenate(indices).astype(np.int32)
        take = np.concatenate(gather)
        indptr = np.concatenate([[0], np.cumsum(np.concatenate(counts))]).astype(np.int32)
        identity = bool(np.array_equal(take, np.arange(take.size)))
        return shapes, index, indptr, None if identity else take

    def accelerations(self, state: State) -> Accelerations:
        """Free, constraint and total accelerations at ``state``, with multipliers.

        Parameters
        ----------
        state : State

        Returns
        -------
        Accelerations

        Raises
        ------
        NonFiniteError
            When the accelerations overflow (loads or constraint rows too large for float64).

        Warns
        -----
        InconsistentConstraintsWarning
            When A ν̇ = b has no solution (residual above tolerance); raises
            InconsistentConstraintsError instead in strict mode.
        """
        if state.layout is not self.layout and state.layout != self.layout:
            raise DefinitionError("state belongs to another System (layouts differ)")
        try:
            acc = self._accelerations(state)
        except (RuntimeWarning, FloatingPointError) as exc:  # warnings or errstate as errors
            raise NonFiniteError(
                f"the accelerations at t = {state.t:.9g} s overflow ({exc}; constraint rows or "
                "loads too large for float64?)"
            ) from None
        if not acc._finite_checked and not (
            all_finite(acc.total)
            and all_finite(acc.constraint_force)
            and all_finite(acc.multipliers)
            and math.isfinite(acc.residual)
        ):
            raise NonFiniteError(
                f"non-finite accelerations (NaN or inf) at t = {state.t:.9g} s: the free "
                f"acceleration is {'finite' if all_finite(acc.free) else 'not finite'}; are "
                "the state, the loads or the constraint rows too large for float64?"
            )
        return acc

    # ------------------------------------------------------------------ compiled form
    def compiled_program(self, method: RungeKuttaMethod, state: State) -> Program:
        """This System's compiled form with ``method`` for a run from ``state``: the arrays
        and the Python callback the compiled loop runs (:mod:`gmuk.engine.integrators._program`).

        Each part contributes what it declares (its ``_compiled_term``; parts without one are
        called back in Python), and the solve runs compiled under the ``"fused"``, ``"dense"``
        and ``"tree"`` strategies, in Python otherwise (:attr:`compiled_solve`). The row counts
        of constraints evaluated in Python are read at ``state``.

        Raises
        ------
        DefinitionError
            When the method replaces the tableau's step with its own Python.
        Exception
            Whatever a part raises when its rows are evaluated at ``state``.
        """
        solve, _ = self.compiled_solve
        if solve == _program.FUSED:
            constants = np.array(self.solver._params)  # type: ignore[attr-defined]
        elif solve == _program.DENSE:
            constants = self._Minv_sqrt
        elif solve == TREE:  # the packed tree after its first two entries (build() adds them)
            constants = self.solver.loop_constants(state)  # type: ignore[attr-defined]
        else:
            constants = np.zeros(1)
        view = _program.SystemView(
            layout=self.layout,
            bodies=self.bodies,
            constraints=self.constraints,
            constraint_bodies=[[self._resolve(b) for b in c.bodies] for c in self.constraints],
            constraint_cols=self._constraint_cols,
            constraint_where=self._constraint_where,
            force_plan=self._force_plan,
            controllers=self.controllers,
            controller_bodies=self._ctrl_bodies,
            controller_slices=self._ctrl_slices,
            J=self._J,
            Jinv=self._Jinv,
            m_rigid=self._m_rigid,
            m_euclid=self._m_euclid,
            plant_only=self._plant_only_loads,
            solve=solve,
            solve_constants=constants,
            consistency_tol=self.consistency_tol,
            rcond=self.rcond,
            accelerations=(
                self.accelerations
                if type(self).accelerations is not System.accelerations
                else self._accelerations
            ),
            add_loads=self._add_loads,
            controls_of=self._controls_of,
            rows_of=_pair,
        )
        return _program.build(view, method, state)

    @property
    def compiled_solve(self) -> tuple[int, str]:
        """How the compiled loop solves this System (``gmuk.engine.integrators._program``'s FREE,
        FUSED, DENSE or PYTHON_SOLVE, or :data:`gmuk.engine.tree.TREE`) and, for PYTHON_SOLVE,
        why."""
        if type(self).accelerations is not System.accelerations:
            return _program.PYTHON_SOLVE, "the System subclass has its own accelerations"
        if not self.constraints:
            return _program.FREE, ""
        if type(self.solver) is solvers.FusedRigidSolver:
            return _program.FUSED, ""
        if type(self.solver) is solvers.DenseSolver:
            return _program.DENSE, ""
        if type(self.solver) is TreeSolver:
            return TREE, ""
        return _program.PYTHON_SOLVE, f"the constraints are solved by {type(self.solver).__name__}"

    # ------------------------------------------------------------------ simulation
    @_names_its_options
    def simulate(
        self,
        state0: State,
        t_span: tuple[float, float],
        *,
        t_eval: ArrayLike | None = None,
        method: str | type[RungeKuttaMethod] | RungeKuttaMethod = "DOP853",
        rtol: float = 1e-10,
        atol: float = 1e-10,
        step: float | None = None,
        first_step: float | None = None,
        max_step: float = np.inf,
        max_steps: int = 1_000_000,
        progress: bool | None = None,
        on_failure: Literal["raise", "return"] = "raise",
        compiled: bool | None = None,
        drift_tol: float | None = 1e-6,
        events: Event | Sequence[Event] | None = None,
    ) -> Trajectory:
        """Integrate from ``state0`` over ``t_span`` on SE(3)ⁿ × Rᵏ.

        The options are those of :func:`gmuk.engine.integrate.simulate`, which this calls
        and whose docstring gives the details (error weights, the drift check, checkpoints).
        An unknown keyword is a TypeError that lists them.

        Parameters
        ----------
        state0 : State
            Initial state (from :meth:`state`); its ``t`` is replaced by ``t_span[0]``.
        t_span : (float, float)
            Start and end times (s), end > start.
        t_eval : array_like, shape (k,), optional
            Output times (s), increasing, within ``t_span``. Default: every accepted step.
        method : str, RungeKuttaMethod subclass or instance
            The Runge–Kutta method: a registered name, case-insensitive — ``"DOP853"``
            (default, adaptive, 8th order), ``"DOPRI5"``, ``"RK4"`` (fixed step) or a name a
            user subclass registered (:data:`gmuk.engine.integrate.METHODS`) — or a class or
            an instance.
        rtol, atol : float
            Relative and absolute tolerances of the adaptive methods (default 1e-10 each);
            each 3-vector of the state (ω in rad/s, v in m/s, positions in m, the step's
            rotation in rad) is weighed by its norm: ``w = atol + rtol · ‖u‖``.
        step : float, optional
            Step size (s) of a fixed-step method such as RK4 (required there); ignored by the
            adaptive ones.
        first_step : float, optional
            First step (s) of an adaptive method; chosen automatically by default.
        max_step : float
            Largest step (s) of an adaptive method (default: no limit).
        max_steps : int
            Give up (status "failed") after this many steps (default 1 000 000).
        progress : bool, optional
            Progress bar: True always, False never, None (default) only on a terminal once
            the run has taken more than 2 s.
        on_failure : {"raise", "return"}
            On a failure (step-size underflow, NaN, too many steps, an inconsistent solve in
            strict mode): raise :class:`gmuk.errors.SimulationError` carrying the trajectory
            so far (default), or return that trajectory with ``status="failed"``.
        compiled : bool, optional
            Deprecated and ignored (every run takes the compiled loop); False is an error.
        drift_tol : float or None
            How far (in each residual's units; default 1e-6) a constraint may drift from where
            it started before the run ends with ``status="drifted"``; None records the
            violations without judging them.
        events : Event or sequence of Event, optional
            Functions of (t, state) whose sign changes are located to 1e-13 s
            (:class:`gmuk.Event`, docs/events.rst): recorded in ``traj.events``, or
            terminal (the run ends there, ``status="terminated"``).

        Returns
        -------
        Trajectory
            Time-major record of the run; ``print(traj)`` summarises it.

        Raises
        ------
        DefinitionError
            For an unknown method name or a bad option value (as
            :func:`gmuk.engine.integrate.simulate`).
        SimulationError
            When the run fails and ``on_failure="raise"``.
        TypeError
            For a keyword that is not an option (the message lists the options).
        """
        return _simulate(
            self, state0, t_span, t_eval=t_eval, method=method, rtol=rtol, atol=atol,
            step=step, first_step=first_step, max_step=max_step, max_steps=max_steps,
            progress=progress, on_failure=on_failure, compiled=compiled, drift_tol=drift_tol,
            events=events,
        )  # fmt: skip

    def __repr__(self) -> str:
        return (
            f"System(bodies={list(self.layout.names)}, constraints={len(self.constraints)}, "
            f"forces={len(self.forces)}, controllers={len(self.controllers)}, "
            f"solver={self.solver.name!r})"
        )


def _part_output(
    w: Any, shape: tuple[int, ...], part: Any, body: Body | None, t: float
) -> FloatArray:
    """A part's return value ``w`` as a float64 array of ``shape``, refusing what is not an
    array of real numbers (booleans, complex numbers, strings, objects: dtype kinds other
    than f, i, u) and a load of another shape. ``body`` None: ``w`` is a controller's ż,
    which may have any shape with exactly ``shape[0]`` entries (never broadcast).

    The slow path of the System's checks: a float64 ndarray of ``shape`` never comes here.
    Finiteness is checked by the caller, once per part.
    """
    what = f"for {body.kind} body {body.name!r}" if body is not None else "as z_dot"
    arr: Any = None
    if not isinstance(w, (bool, np.bool_, str, bytes, complex)):
        try:
            arr = np.asarray(w)
        except (TypeError, ValueError):  # ragged sequences
            arr = None
    if arr is None or arr.dtype.kind not in "fiu":
        got = f"{type(w).__name__}" if arr is None else f"dtype {arr.dtype}"
        raise DefinitionError(
            f"{_who(part)} returned {got} {w!r:.60} {what} at t = {t:.9g} s; expected an array of "
            f"real numbers (float or int; not bool, complex or str) of shape {shape}"
        )
    if arr.shape != shape and not (body is None and arr.size == shape[0]):
        expected = f"{shape[0]} entries" if body is None else f"shape {shape}"
        raise DefinitionError(
            f"{_who(part)} returned shape {arr.shape} {what} at t = {t:.9g} s; expected {expected}"
        )
    return arr.astype(np.float64).reshape(shape)


def _pair(c: Constraint, state: State) -> tuple[Any, Any]:
    """A constraint's ``rows(state)``, checked to be a pair (A, b); A and b that are not
    float64 ndarrays must hold real numbers of kinds f, i, u (booleans are refused here;
    complex numbers, strings and objects by ``as_rows``)."""
    try:
        out = c.rows(state)
    except ValueError as exc:
        _raise_if_read_only(exc, c, state.t)
        raise
    if type(out) is tuple and len(out) == 2:
        A, b = out
    elif isinstance(out, (tuple, list)) and len(out) == 2:
        A, b = out[0], out[1]
    else:
        A = b = None
    if A is not None:
        if not (type(A) is np.ndarray and A.dtype == np.float64):
            _not_bool(A, c, state, "A")
        if not (type(b) is np.ndarray and b.dtype == np.float64):
            _not_bool(b, c, state, "b")
        return A, b
    raise ConstraintError(
        f"constraint {c.name!r}: rows() must return a pair (A, b); got {type(out).__name__}"
        + (f" of length {len(out)}" if isinstance(out, (tuple, list)) else f" {out!r:.60}")
    )


def _not_bool(x: Any, c: Constraint, state: State, name: str) -> None:
    """Refuse booleans as a constraint's A or b (numpy would read True as 1.0)."""
    dtype = getattr(x, "dtype", None)
    if dtype is None:
        if isinstance(x, (bool, np.bool_)):
            kind = "b"
        else:
            try:
                kind = np.asarray(x).dtype.kind
            except (TypeError, ValueError):
                return  # as_rows names what is wrong
    else:
        kind = np.dtype(dtype).kind
    if kind == "b":
        raise ConstraintError(
            f"constraint {c.name!r}: rows() returned booleans as {name} at t = {state.t:.9g} s; "
            "expected real numbers (float or int)"
        )


def _raise_if_read_only(exc: ValueError, part: Any, t: float) -> None:
    """Raise a DefinitionError naming the part when ``exc`` is numpy's refusal to write into
    a read-only array: the part wrote into the State (or the modeled acceleration) it was
    given, which are read-only so that no part can change the caller's data."""
    if "read-only" in str(exc):
        raise DefinitionError(
            f"{_who(part)} tried to write into the arrays it was given at t = {t:.9g} s ({exc}): a "
            "State and the modeled acceleration are read-only; copy them "
            "(e.g. state.V.copy()) to compute in place"
        ) from exc


def _who(part: Any) -> str:
    """How messages name a part: "force 'Drag'", "controller 'PD'", "constraint 'Rows'"
    (built only when a message is, not on every call)."""
    kind = (
        "force"
        if isinstance(part, ForceModel)
        else "controller"
        if isinstance(part, Controller)
        else "constraint"
    )
    return f"{kind} {part.name!r}"
