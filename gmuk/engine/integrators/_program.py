"""A System's compiled form: the arrays and the Python callback the compiled loop runs.

:meth:`gmuk.System.compiled_program` describes itself to :func:`build` as a :class:`SystemView`
(its parts, masses, solve and callbacks) and :func:`build` packs it, with the method's
:class:`MethodTable`, into a :class:`Program`: named records of arrays that the loop
(:mod:`gmuk.engine.integrators._compiled`) reads, and :class:`PythonParts`, the C callback
through which the loop evaluates what has no compiled form. Each part contributes what it
declares (a force model's ``_compiled_term``, a constraint's, a controller's;
``docs/architecture.rst``); nothing here tests a part's class.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from gmuk._numba import kernel_address
from gmuk.bodies import Body, BodyKind
from gmuk.constraints.base import ROWS_KERNEL, as_rows
from gmuk.control.base import CONTROL_KERNEL
from gmuk.engine.integrators._base import RungeKuttaMethod
from gmuk.engine.integrators.dop853 import DOP853
from gmuk.errors import ConstraintError, DefinitionError
from gmuk.forces.base import FORCE_KERNEL

if TYPE_CHECKING:
    from gmuk.state import Layout, State

__all__ = [
    "MethodTable",
    "Parts",
    "Program",
    "PythonParts",
    "SystemView",
    "build",
    "method_table",
    "reference_records",
]

# How the right-hand side solves (Dims.solve).
FREE = 0  #: no constraints: the free acceleration
FUSED = 1  #: FusedRigidSolver: free acceleration, QR solve and wrenches in one call
DENSE = 2  #: DenseSolver: the free acceleration, then the certified QR solve
PYTHON_SOLVE = 3  #: the System's own Python accelerations at every evaluation

# The phases of the Python callback (PythonParts).
PHASE_LOADS = 0  #: loads and rows of the parts without a compiled form
PHASE_CONTROLS = 1  #: the controllers without a compiled form
PHASE_ACCELERATIONS = 2  #: the whole acceleration in Python (System._accelerations)


#: The constraint table's kind of a constraint whose rows come from Python (PythonParts, at
#: io[p0:]); the others hold their kernel's address (gmuk._numba.kernel_address).
PYTHON = -1


class SystemView(NamedTuple):
    """What a System hands :func:`build`: its parts, masses, solve and callbacks."""

    layout: Layout
    #: every body, in the order of ν
    bodies: tuple[Body, ...]
    constraints: tuple[Any, ...]
    #: each constraint's bodies (resolved), its columns of A, and those as a slice if contiguous
    constraint_bodies: list[list[Body]]
    constraint_cols: list[np.ndarray]
    constraint_where: list[slice | np.ndarray]
    #: (model, bodies, slots or None) per force model, as the System evaluates them
    force_plan: list[Any]
    controllers: tuple[Any, ...]
    controller_bodies: list[list[Body]]
    controller_slices: list[slice]
    #: central inertias (n_r, 3, 3), their inverses, rigid masses, Euclidean masses per entry
    J: np.ndarray
    Jinv: np.ndarray
    m_rigid: np.ndarray
    m_euclid: np.ndarray
    #: unmodeled loads or controllers act on the plant beyond the solve
    plant_only: bool
    #: FREE, FUSED, DENSE or PYTHON_SOLVE
    solve: int
    #: FUSED: the fused solve's packed constants; DENSE: M^(−1/2) (n_dof, n_dof)
    solve_constants: np.ndarray
    consistency_tol: float
    rcond: float | None
    #: the System's accelerations at a state (the whole solve in Python)
    accelerations: Callable[[State], Any]
    #: add the generalized forces of force-plan entries at a state to (modeled, unmodeled)
    add_loads: Callable[[list[Any], State, np.ndarray, np.ndarray], None]
    #: the controls and ż of the controllers numbered in a sequence, given ν̇ modeled
    controls_of: Callable[[Sequence[int], State, np.ndarray], tuple[np.ndarray, np.ndarray]]
    #: a constraint's rows (A, b) at a state, checked to be a pair
    rows_of: Callable[[Any, State], tuple[Any, Any]]


class Dims(NamedTuple):
    """Sizes and switches of a program (all int)."""

    n_rigid: int
    n_euclid: int
    n_dof: int
    #: unmodeled loads or controllers act on the plant beyond the solve (1) or not (0)
    plant_only: int
    #: constraint rows s
    n_rows: int
    #: address of the Python callback (PythonParts)
    callback: int
    n_control: int
    #: where the controllers' phase reads and writes ``io`` (0: no controller in Python)
    controls_at: int
    #: FREE, FUSED, DENSE or PYTHON_SOLVE
    solve: int
    #: where the Python loads start in ``io``
    loads_at: int
    #: where the Python accelerations (the layout of rhs's outputs) start in ``io``
    accel_at: int
    #: whether any force model, constraint row or controller is evaluated in Python
    python_parts: int
    #: the rank reported without constraints (the solve's own, −1 for none)
    free_rank: int
    #: whether any compiled force term acts on a point mass
    point_terms: int


class Parts(NamedTuple):
    """A System's compiled form, as the kernels take it."""

    #: (n_terms, 8) int64: kernel address, rigid, body index, ν offset, modeled, parameter start,
    #: field start, field end
    terms: np.ndarray
    params: np.ndarray
    field_data: np.ndarray
    J: np.ndarray  #: (n_r, 3, 3) central inertias (kg·m², body frame)
    Jinv: np.ndarray
    m_rigid: np.ndarray
    m_euclid: np.ndarray  #: per Euclidean coordinate
    rigid_offsets: np.ndarray  #: each rigid body's first entry of ν
    euclid_offsets: np.ndarray  #: each Euclidean coordinate's entry of ν
    dims: Dims
    #: (n_c, 6) int64: kind, body, other body, first row, rows, parameter start
    cons: np.ndarray
    cparams: np.ndarray
    #: the solve's packed constants (FusedRigidSolver's, or the dense solve's)
    uk_params: np.ndarray
    #: the buffer shared with the Python callback
    io: np.ndarray
    #: (n_ctrl, 5) int64: kernel address, body index, ν offset, z offset, parameter start
    ctrls: np.ndarray
    ctrl_params: np.ndarray
    #: where the point masses' 3-vectors start in Y (positions, then velocities)
    point_starts: np.ndarray


class MethodTable(NamedTuple):
    """A Runge–Kutta method as the loop reads it, from the method object."""

    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    E: np.ndarray
    E3: np.ndarray  #: DOP853's order-3 estimate (zeros otherwise)
    A_ext: np.ndarray  #: DOP853's extended stages (the full tableau)
    c_ext: np.ndarray
    D: np.ndarray  #: DOP853's continuous-extension coefficients
    n_stages: int
    n_rows: int
    fsal: bool
    adaptive: bool
    order: int
    dop853: bool
    dense: bool
    safety: float
    min_factor: float
    max_factor: float
    max_factor_rejected: float
    error_floor: float
    e3_weight: float
    defect_node: float
    defect_gain: float


@dataclass(frozen=True)
class Program:
    """The compiled form of a System and a method (see the module docstring)."""

    parts: Parts
    method: MethodTable
    #: length of the integrator's state Y
    n: int
    #: rows of the stacked constraints
    s: int
    #: the Python callback (force models, constraints, controllers or the solve)
    python: PythonParts

    @property
    def n_aux(self) -> int:
        """Length of :func:`rhs`'s other outputs (:func:`aux_layout`)."""
        return aux_size(self.parts.dims.n_dof, self.s, self.parts.dims.n_control)


def aux_size(n_dof: int, s: int, n_control: int) -> int:
    """Length of :func:`rhs`'s other outputs: the total acceleration, the unmodeled generalized
    forces, the constraint acceleration and the constraint forces M ν̇_c (n_dof each), λ (s),
    the residual, the controls (n_dof), ż (n_c) and the rank of A (−1: none)."""
    return 5 * n_dof + s + 2 + n_control


def aux_layout(n_dof: int, s: int, n_control: int) -> dict[str, slice | int]:
    """Where each of :func:`rhs`'s other outputs sits (see :func:`aux_size`)."""
    nd = n_dof
    return {
        "acceleration": slice(0, nd),
        "unmodeled_force": slice(nd, 2 * nd),
        "constraint_acceleration": slice(2 * nd, 3 * nd),
        "constraint_force": slice(3 * nd, 4 * nd),
        "multipliers": slice(4 * nd, 4 * nd + s),
        "residual": 4 * nd + s,
        "control_force": slice(4 * nd + s + 1, 5 * nd + s + 1),
        "z_dot": slice(5 * nd + s + 1, 5 * nd + s + 1 + n_control),
        "rank": 5 * nd + s + 1 + n_control,
    }


def own_step_methods(method: RungeKuttaMethod) -> list[str]:
    """The step methods a method class replaces with its own Python (empty for a tableau
    method and for DOP853 itself)."""
    cls = type(method)
    if cls is DOP853:
        return []
    names = ("stages", "error_norm", "interpolant", "interpolant_error")
    return [n for n in names if getattr(cls, n) is not getattr(RungeKuttaMethod, n)]


def method_table(method: RungeKuttaMethod) -> MethodTable:
    """The loop's view of ``method`` (writable copies: every program has the same types)."""
    own = own_step_methods(method)
    if own:
        raise DefinitionError(
            f"the method {type(method).__qualname__} replaces {', '.join(own)} with its own "
            "Python; gmuk's loop runs explicit Runge–Kutta tableaus (A, b, c, E) and DOP853"
        )
    dop853 = isinstance(method, DOP853)
    n_rows = method._n_rows
    E = np.zeros(n_rows) if method.E is None else np.array(method.E, dtype=float)
    zeros = np.zeros(n_rows)
    return MethodTable(
        A=np.array(method.A, dtype=float, order="C"),
        b=np.array(method.b, dtype=float),
        c=np.array(method.c, dtype=float),
        E=E,
        E3=np.array(DOP853.E3 if dop853 else zeros, dtype=float),
        A_ext=np.array(DOP853.A_extended, dtype=float, order="C"),
        c_ext=np.array(DOP853.c_extended, dtype=float),
        D=np.array(DOP853.D, dtype=float, order="C"),
        n_stages=int(method.n_stages),
        n_rows=int(n_rows),
        fsal=bool(method.fsal),
        adaptive=bool(method.adaptive),
        order=int(method.order),
        dop853=dop853,
        dense=bool(method.dense_output and dop853),
        safety=float(method.safety),
        min_factor=float(method.min_factor),
        max_factor=float(method.max_factor),
        max_factor_rejected=float(method.max_factor_rejected),
        error_floor=float(method.error_floor),
        e3_weight=float(DOP853.e3_weight),
        defect_node=float(DOP853.defect_node),
        defect_gain=float(DOP853.defect_gain),
    )


def build(view: SystemView, method: RungeKuttaMethod, state: State) -> Program:
    """The compiled form of a System (its :class:`SystemView`) with ``method``, for a run from
    ``state``.

    Parts without a compiled form are called back in Python (:class:`PythonParts`); the row
    counts of such constraints (and of a solve done in Python) are read at ``state``.

    Raises
    ------
    DefinitionError
        When the method replaces the tableau's step with its own Python.
    Exception
        Whatever a part raises when its rows are evaluated at ``state`` (the caller reports
        it as the run's failure at the start).
    """
    from gmuk.engine.solvers import QR_COND_LIMIT, QR_MAX_ROWS

    meth = method_table(method)
    lay = view.layout
    nr, ne, nd, nc = lay.n_rigid, lay.n_euclid, lay.n_dof, lay.n_control
    solve = view.solve
    kinds = (BodyKind.RIGID, BodyKind.POINT, BodyKind.SLACK)
    if any(b.kind not in kinds for b in view.bodies):
        solve = PYTHON_SOLVE
    free_rank = -1
    cons = np.zeros((0, 6), dtype=np.int64)
    cparams, uk_params = np.zeros(1), np.zeros(1)
    py_constraints: list[int] = []
    if solve != PYTHON_SOLVE:
        cons, cparams, uk_params = _constraint_program(view, solve)
        py_constraints = [k for k in range(cons.shape[0]) if cons[k, 0] == PYTHON]
        row = 0
        for k in range(cons.shape[0]):
            cons[k, 3] = row
            if cons[k, 0] == PYTHON:  # its rows at the start, checked as at every stage
                c = view.constraints[k]
                A, b = view.rows_of(c, state)
                _, b = as_rows(A, b, view.constraint_cols[k].size, f"constraint {c.name!r}")
                cons[k, 4] = b.size
            row += cons[k, 4]
        n_rows = int(cons[:, 4].sum())
        if solve == DENSE and n_rows > QR_MAX_ROWS:  # more than the certified QR takes
            solve = PYTHON_SOLVE
    if solve == PYTHON_SOLVE:
        n_rows = int(view.accelerations(state).multipliers.size)
        cons = np.zeros((0, 6), dtype=np.int64)
        cparams, uk_params = np.zeros(1), np.zeros(1)
        terms_plan: list[Any] = []
        py_forces: list[Any] = []
        py_constraints = []
        ctrl_plan: list[tuple[int, Any]] = []
        py_controllers: list[int] = []
    else:
        if solve == FREE:
            rank = view.accelerations(state).rank
            free_rank = -1 if rank is None else int(rank)
        terms_plan, py_forces = force_terms(view.force_plan)
        ctrl_plan, py_controllers = _controller_plan(view)
    terms, params, field_data = pack_terms(terms_plan)
    if solve == DENSE:  # DenseSolver.solve_rows: the QR's condition limit for these rows
        rcond = view.rcond
        if rcond is None:
            rcond = max(n_rows, nd) * float(np.finfo(float).eps)
        uk_params[0] = min(QR_COND_LIMIT, 0.1 / rcond)
    ctrl_rows: list[list[int]] = []
    ctrl_params: list[float] = []
    for k, (kernel, values) in ctrl_plan:
        body = view.controller_bodies[k][0]
        slot = lay.slot(body)
        z0 = int(view.controller_slices[k].start)
        address = kernel_address(kernel, CONTROL_KERNEL)
        ctrl_rows.append([address, slot.index, slot.offset, z0, len(ctrl_params)])
        ctrl_params.extend(np.asarray(values, dtype=float).tolist())
    python = PythonParts(view, py_forces, cons, py_constraints, py_controllers, n_rows)
    points = [lay.slot(b).index for b in view.bodies if b.kind is BodyKind.POINT]
    point_starts = [12 * nr + half * ne + i for half in (0, 1) for i in points]
    dims = Dims(
        n_rigid=nr,
        n_euclid=ne,
        n_dof=nd,
        plant_only=int(view.plant_only),
        n_rows=n_rows,
        callback=python.address,
        n_control=nc,
        controls_at=python.controls_at if py_controllers else 0,
        solve=solve,
        loads_at=python.loads_at,
        accel_at=python.accel_at,
        python_parts=int(bool(py_forces or py_constraints or py_controllers)),
        free_rank=free_rank,
        point_terms=int(bool(terms.shape[0]) and not terms[:, 1].all()),
    )
    parts = Parts(
        terms=terms,
        params=params,
        field_data=field_data,
        J=np.ascontiguousarray(view.J, dtype=float).reshape(nr, 3, 3),
        Jinv=np.ascontiguousarray(view.Jinv, dtype=float).reshape(nr, 3, 3),
        m_rigid=np.ascontiguousarray(view.m_rigid, dtype=float).reshape(nr),
        m_euclid=np.ascontiguousarray(view.m_euclid, dtype=float).reshape(ne),
        rigid_offsets=np.asarray(lay.rigid_offsets, dtype=np.int64),
        euclid_offsets=np.asarray(lay.euclid_offsets, dtype=np.int64),
        dims=dims,
        cons=cons,
        cparams=cparams,
        uk_params=uk_params,
        io=python.io,
        ctrls=np.array(ctrl_rows, dtype=np.int64).reshape(-1, 5),
        ctrl_params=np.array([*ctrl_params, 0.0], dtype=float),
        point_starts=np.array(point_starts, dtype=np.int64),
    )
    return Program(parts, meth, 12 * nr + 2 * ne + nc, n_rows, python)


def force_terms(force_plan: list[Any]) -> tuple[list[tuple[Any, ...]], list[Any]]:
    """The compiled terms ``(kernel, values, data, rigid, index, offset, modeled)`` of the force
    models of a System's ``_force_plan`` that have a compiled form on every body they act
    on, and the other models' entries (evaluated in Python)."""
    terms: list[tuple[Any, ...]] = []
    py_forces = []
    for entry in force_plan:
        f, _bodies, slots = entry
        compiled_terms = [] if slots is None else [f._compiled_term(b) for b, *_ in slots]
        if slots is None or any(term is None for term in compiled_terms):
            py_forces.append(entry)  # the whole model in Python
            continue
        for (_body, rigid, index, offset, _dof), term in zip(slots, compiled_terms, strict=True):
            assert term is not None
            kernel, values, data = term
            terms.append((kernel, values, data, rigid, index, offset, f.modeled))
    return terms, py_forces


def pack_terms(plan: list[tuple[Any, ...]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The term table, parameters and shared field data of :func:`_force_plan`'s terms."""
    terms: list[list[int]] = []
    params: list[float] = []
    fields: list[np.ndarray] = []
    field_at: dict[int, tuple[int, int]] = {}
    n_field = 0
    for kernel, values, data, rigid, index, offset, modeled in plan:
        f0 = f1 = 0
        if data is not None:
            if id(data) not in field_at:
                field_at[id(data)] = (n_field, n_field + data.size)
                fields.append(np.asarray(data, dtype=float))
                n_field += data.size
            f0, f1 = field_at[id(data)]
        address = kernel_address(kernel, FORCE_KERNEL)
        terms.append([address, int(rigid), index, offset, int(modeled), len(params), f0, f1])
        params.extend(float(v) for v in values)
    field_data = np.concatenate(fields) if fields else np.zeros(1)
    field_data.setflags(write=False)
    return (
        np.array(terms, dtype=np.int64).reshape(-1, 8),
        np.array([*params, 0.0], dtype=float),
        field_data,
    )


def _controller_plan(view: SystemView) -> tuple[list[tuple[int, Any]], list[int]]:
    """The controllers with a compiled term on one rigid body ``(k, (kernel, values))``, and
    the numbers of the others (called back in Python)."""
    compiled: list[tuple[int, Any]] = []
    python: list[int] = []
    for k, ctl in enumerate(view.controllers):
        term = ctl._compiled_term()
        bodies = view.controller_bodies[k]
        if term is None or len(bodies) != 1 or bodies[0].kind is not BodyKind.RIGID:
            python.append(k)
        else:
            compiled.append((k, term))
    return compiled, python


#: The C signature of PythonParts' callback: int64 f(int64 phase), 0 on success.
_CALLBACK_TYPE = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_int64)


class PythonParts:
    """What a program evaluates in Python when the compiled right-hand side calls back.

    The compiled loop writes the stage's state into ``io`` and calls a C function (a ctypes
    callback to :meth:`_call`) with a phase:

    * :data:`PHASE_LOADS`: builds the :class:`~gmuk.State`, calls the force models and
      constraints without a compiled form as the System does (``System._add_loads``, each
      constraint's ``rows``) and writes their generalized forces and rows into ``io``;
    * :data:`PHASE_CONTROLS`, after the solve: the controllers without a compiled form, given
      the modeled acceleration (``System._controls_of``);
    * :data:`PHASE_ACCELERATIONS`: the whole acceleration, ``System._accelerations`` (or a
      System subclass's own ``accelerations``), written in the layout of :func:`rhs`'s
      outputs (:func:`aux_layout`).

    Layout of ``io``: t, g (16 n_r), V (6 n_r), x (n_e), ẋ (n_e), z (n_c); from ``loads_at``
    the modeled and unmodeled generalized forces (2 n_dof); from ``controls_at`` the modeled
    acceleration (n_dof, in), the controls (n_dof) and ż (n_c); from ``accel_at`` the
    accelerations of :data:`PHASE_ACCELERATIONS`; then for each constraint in Python its
    rows A (rows, n_dof) and b (rows), at the offset the constraint table holds. A part that
    raises makes the loop stop with :data:`CALLBACK` and leaves the exception in ``error``.
    """

    def __init__(
        self,
        view: SystemView,
        forces: list[Any],
        cons: np.ndarray,
        constraints: list[int],
        controllers: list[int],
        n_rows: int,
    ) -> None:
        lay = view.layout
        nr, ne, nd, nc = lay.n_rigid, lay.n_euclid, lay.n_dof, lay.n_control
        self.view, self.forces, self.layout = view, forces, lay
        self.controllers = controllers
        self.n_rows = n_rows
        self._accelerations = view.accelerations
        self._g = slice(1, 1 + 16 * nr)
        self._V = slice(1 + 16 * nr, 1 + 22 * nr)
        self._x = slice(1 + 22 * nr, 1 + 22 * nr + ne)
        self._xd = slice(1 + 22 * nr + ne, 1 + 22 * nr + 2 * ne)
        self._z = slice(1 + 22 * nr + 2 * ne, 1 + 22 * nr + 2 * ne + nc)
        self.loads_at = 1 + 22 * nr + 2 * ne + nc
        self.controls_at = self.loads_at + 2 * nd
        ca = self.controls_at
        self._acc, self._control = slice(ca, ca + nd), slice(ca + nd, ca + 2 * nd)
        self._z_dot = slice(ca + 2 * nd, ca + 2 * nd + nc)
        self.accel_at = ca + 2 * nd + nc
        self._layout = aux_layout(nd, n_rows, nc)
        at = self.accel_at + aux_size(nd, n_rows, nc)
        self.constraints = []
        for k in constraints:
            rows = int(cons[k, 4])
            cons[k, 5] = at
            self.constraints.append(
                (view.constraints[k], view.constraint_cols[k].size,
                 view.constraint_where[k], rows, at)
            )  # fmt: skip
            at += rows * (nd + 1)
        self.io = np.zeros(at)
        self._modeled = self.io[self.loads_at : self.loads_at + nd]
        self._unmodeled = self.io[self.loads_at + nd : self.loads_at + 2 * nd]
        self._state: State | None = None
        self.error: BaseException | None = None
        # resolved once: the callback runs at every evaluation
        from gmuk.state import State as _State

        self._as_rows, self._make_state, self._pair = as_rows, _State._adopt, view.rows_of
        self._c_function = _CALLBACK_TYPE(self._call)  # kept alive with the program
        self.address = int(ctypes.cast(self._c_function, ctypes.c_void_p).value or 0)

    def _call(self, phase: int) -> int:
        try:
            if phase == PHASE_LOADS:
                self.evaluate()
            elif phase == PHASE_CONTROLS:
                self.control()
            else:
                self.accelerations()
        except BaseException as exc:  # a C caller cannot take an exception: keep it
            self.error = exc
            return 1
        return 0

    def state(self) -> State:
        """The state the loop wrote into ``io``: one read-only copy of it, viewed as the
        State's arrays (:meth:`State._adopt`), so a part that writes into it fails instead
        of changing the loop's state."""
        io, lay = self.io, self.layout
        block = io[1 : self.loads_at].copy()  # g, V, x, ẋ, z: one copy, frozen once
        block.setflags(write=False)
        g, V, x, xd, z = self._g, self._V, self._x, self._xd, self._z
        return self._make_state(
            float(io[0]),
            block[g.start - 1 : g.stop - 1].reshape(lay.n_rigid, 4, 4),
            block[V.start - 1 : V.stop - 1].reshape(lay.n_rigid, 6),
            block[x.start - 1 : x.stop - 1],
            block[xd.start - 1 : xd.stop - 1],
            block[z.start - 1 : z.stop - 1],
            lay,
        )

    def accelerations(self) -> None:
        """The System's accelerations at the state in ``io``, into ``io`` from
        ``accel_at`` in the layout of :func:`rhs`'s outputs."""
        state = self.state()
        acc = self._accelerations(state)
        if acc.multipliers.size != self.n_rows:
            raise ConstraintError(
                f"the constraints gave {acc.multipliers.size} rows at t = {state.t:.9g} s and "
                f"{self.n_rows} at the start; a run keeps its number of constraint rows"
            )
        out = self.io[self.accel_at :]
        for name, where in self._layout.items():
            if name == "rank":
                out[where] = -1 if acc.rank is None else acc.rank
            else:
                out[where] = getattr(acc, _ACCELERATION_FIELDS.get(name, name))

    def control(self) -> None:
        """The controllers' generalized forces and internal-state rates at the state of the
        last :meth:`evaluate`, given the modeled acceleration in ``io``, into ``io``."""
        assert self._state is not None
        io = self.io
        control, z_dot = self.view.controls_of(self.controllers, self._state, io[self._acc].copy())
        io[self._control] = control
        io[self._z_dot] = z_dot

    def evaluate(self) -> None:
        """The parts' loads and rows at the state in ``io``, into ``io``."""
        io, lay = self.io, self.layout
        self._state = state = self.state()
        if self.forces:
            self._modeled[:] = 0.0
            self._unmodeled[:] = 0.0
            self.view.add_loads(self.forces, state, self._modeled, self._unmodeled)
        nd = lay.n_dof
        for c, width, where, rows, at in self.constraints:
            Ai, bi = self._pair(c, state)
            Ai, bi = self._as_rows(Ai, bi, width, f"constraint {c.name!r}")
            if bi.size != rows:
                raise ConstraintError(
                    f"constraint {c.name!r} gave {bi.size} rows at t = {state.t:.9g} s and "
                    f"{rows} at the start; a run keeps its number of constraint rows"
                )
            block = io[at : at + rows * nd].reshape(rows, nd)
            block[:] = 0.0
            block[:, where] = Ai.toarray() if hasattr(Ai, "toarray") else Ai
            io[at + rows * nd : at + rows * (nd + 1)] = bi


#: Accelerations' fields under the names of rhs's outputs (where they differ).
_ACCELERATION_FIELDS = {"acceleration": "total", "constraint_acceleration": "constraint"}


def _constraint_program(view: SystemView, solve: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(cons (n_c, 6) int64 — kind, body, other body, first row, rows, parameter start —,
    parameters, the solve's packed constants) for the FREE, FUSED or DENSE solve. The row
    counts of PYTHON constraints and every constraint's first row are left to
    :func:`program`."""
    from gmuk.engine.solvers import QR_COND_LIMIT

    if solve == FREE:
        return np.zeros((0, 6), dtype=np.int64), np.zeros(1), np.zeros(1)
    rows: list[list[int]] = []
    params: list[float] = []
    for c, bodies in zip(view.constraints, view.constraint_bodies, strict=True):
        term = c._compiled_term()
        if term is None or len(bodies) > 2 or any(b.kind is not BodyKind.RIGID for b in bodies):
            # rows from Python; program() sets their count and place
            rows.append([PYTHON, 0, -1, 0, 0, 0])
            continue
        kernel, values, n_rows = term
        address = kernel_address(kernel, ROWS_KERNEL)
        idx = [view.layout.slot(b).index for b in bodies]
        rows.append([address, idx[0], idx[1] if len(idx) == 2 else -1, 0, n_rows, len(params)])
        params += values
    cons = np.array(rows, dtype=np.int64).reshape(-1, 6)
    if solve == FUSED:  # a writable copy: every program has the same argument types
        return cons, np.array([*params, 0.0]), np.array(view.solve_constants, dtype=float)
    # P[0], the condition limit, depends on the row count: build() sets it
    P = [QR_COND_LIMIT, view.consistency_tol, *np.ravel(view.solve_constants)]
    return cons, np.array([*params, 0.0]), np.array(P, dtype=float)


def reference_records() -> tuple[Parts, MethodTable]:
    """Records with the argument types of every program (empty arrays of each field's dtype,
    dimensions and flags, as :func:`build` makes them): what the loop is compiled for."""
    ints = np.zeros((0, 8), dtype=np.int64)
    field = np.zeros(1)
    field.setflags(write=False)
    return (
        Parts(
            terms=ints,
            params=np.zeros(1),
            field_data=field,
            J=np.zeros((0, 3, 3)),
            Jinv=np.zeros((0, 3, 3)),
            m_rigid=np.zeros(0),
            m_euclid=np.zeros(0),
            rigid_offsets=np.zeros(0, dtype=np.int64),
            euclid_offsets=np.zeros(0, dtype=np.int64),
            dims=Dims(*([0] * len(Dims._fields))),
            cons=np.zeros((0, 6), dtype=np.int64),
            cparams=np.zeros(1),
            uk_params=np.zeros(1),
            io=np.zeros(1),
            ctrls=np.zeros((0, 5), dtype=np.int64),
            ctrl_params=np.zeros(1),
            point_starts=np.zeros(0, dtype=np.int64),
        ),
        method_table(DOP853()),
    )
