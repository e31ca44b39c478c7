"""The compiled step loop: the RKMK integrator of :mod:`gmuk.integrate`, run in machine code
for a System of rigid bodies, point masses and slack coordinates.

The parts that have compiled forms run compiled: the built-in gravity, uniform-gravity and
linear spring–damper models (``ForceModel._compiled_term``, unless a subclass overrides
their methods), LVLH configuration tracking and relative constraints on rigid bodies, the
corrected Morse–Lyapunov law on an LVLH reference (``Controller._compiled_term``), the
free acceleration and the Udwadia–Kalaba solve of the ``"fused"`` and ``"dense"`` strategies
(the certified QR solve; a state whose rows it cannot certify is handed to the Python
loop). Every other force model, constraint and controller is called in Python from inside
the loop through a C callback (:class:`PythonParts`): only those parts cost Python time.
Systems with constraints under another solve strategy (sparse, Eq. 80, a user's) or a
System subclass that overrides ``accelerations`` run the Python loop. The
method must be one whose step is its tableau (every
:class:`~gmuk.integrators.RungeKuttaMethod` that keeps the base class's ``stages``,
``error_norm`` and has no continuous extension of its own) or DOP853 itself.
:func:`program` derives the compiled form from the parts once per call of ``simulate``; the
parts stay the objects the user built.

The loop is the Python loop of :class:`gmuk.integrate._Stepper` statement for statement (step
control, landing on output times, the continuous extension and its error control, the base
pose update with its Newton–Schulz step, the reuse of the last evaluation's accelerations at
the step end). It runs a chunk of steps and returns, so that Python can see stop requests,
write checkpoints and drain the output buffers between chunks; the results agree with the
Python loop's to rounding (sums in another order), which the tests check on every built-in
part. It is compiled once per machine (:func:`compile_loop`) and loaded from numba's cache
by later processes (:func:`loaded`).
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from gmuk._numba import njit
from gmuk._uk_kernels import _qr_solve, relative_rows, rigid_free_accel, tracking_b, uk_rigid
from gmuk.bodies import BodyKind
from gmuk.control._kernels import apply_control
from gmuk.errors import ConstraintError
from gmuk.forces._kernels import apply_term
from gmuk.gravity import _kernels as _field_kernels
from gmuk.integrators import _dop853_tableau as _tab
from gmuk.integrators._base import RungeKuttaMethod
from gmuk.integrators.dop853 import DOP853
from gmuk.lie._kernels import (
    _compose_exp_into,
    _dexp_inv_apply_into,
    _se3_Ad_into,
    _se3_inverse_into,
    _se3_log_into,
)
from gmuk.orbits._kernels import lvlh_state

if TYPE_CHECKING:
    from gmuk.state import State
    from gmuk.system import System

__all__ = ["Program", "compile_loop", "loaded", "program"]

# Status codes of :func:`advance`.
DONE = 0  #: reached the end time
PAUSE = 1  #: ran its chunk of steps
FULL = 2  #: the output buffers have no room for the next step's outputs
NONFINITE = -1  #: a derivative with NaN or inf
UNDERFLOW = -2  #: step size underflow
MAX_STEPS = -3  #: max_steps reached
FIELD = -4  #: a force kernel's failure (its status in ints[I_FIELD])

# Entries of the integer and float state vectors shared with Python.
I_OUT, I_STEPS, I_REJECTED, I_RHS, I_WRITTEN, I_MAX_STEPS, I_CHUNK, I_FIELD, I_NEED = range(9)
F_T, F_H, F_END, F_RTOL, F_ATOL, F_MAX_STEP, F_BAD_T = range(7)


@dataclass(frozen=True)
class Program:
    """The compiled form of a System and a method (see the module docstring).

    ``parts`` is the tuple the kernels take: (terms (n_terms, 8) int64 — code, rigid, body
    index, ν offset, modeled, parameter start, field start, field end —, parameters, field
    data, J (n_r, 3, 3), J⁻¹, rigid masses, Euclidean masses per entry, rigid ν offsets,
    Euclidean ν offsets, dims [n_r, n_e, n_dof, plant-only loads]). ``method`` is (A, b, c,
    E, E3, A_ext, c_ext, D, ints [s, rows, fsal, adaptive, order, dop853, dense]).
    """

    parts: tuple[Any, ...]
    method: tuple[Any, ...]
    n: int
    #: rows of the stacked constraints
    s: int
    #: the parts evaluated in Python through the C callback (None: every part is compiled)
    python: PythonParts | None = None

    @property
    def n_aux(self) -> int:
        """Length of :func:`rhs`'s other outputs: total, unmodeled, constraint acceleration,
        constraint force (n_dof each), λ (s), the residual, the control (n_dof), ż."""
        dims = self.parts[9]
        return int(5 * dims[2] + self.s + 1 + dims[6])


def _generic(method: RungeKuttaMethod) -> bool:
    cls = type(method)
    return (
        cls.stages is RungeKuttaMethod.stages
        and cls.error_norm is RungeKuttaMethod.error_norm
        and not method.dense_output
    )


def program(system: System, method: RungeKuttaMethod, state: State | None = None) -> Program | str:
    """The compiled form of ``system`` with ``method``, or why there is none (a sentence).

    Force models and constraints without a compiled form are evaluated in Python through a
    C callback (:class:`PythonParts`); the row counts of such constraints are read at
    ``state`` (the initial state), without which they make the System ineligible."""
    from gmuk.solvers import QR_COND_LIMIT, QR_MAX_ROWS
    from gmuk.system import System, _pair

    if type(system).accelerations is not System.accelerations:
        return "the System subclass overrides accelerations"
    if type(system.solver).__module__ != "gmuk.solvers":
        return f"the solve strategy {type(system.solver).__name__} is not a built-in one"
    cons, cparams, uk_params, solve = _constraint_program(system)
    if isinstance(cons, str):
        return cons
    lay = system.layout
    kinds = (BodyKind.RIGID, BodyKind.POINT, BodyKind.SLACK)
    bad = [b.name for b in system.bodies if b.kind not in kinds]
    if bad:
        return f"bodies {bad} are not rigid bodies, point masses or slack coordinates"
    dop853 = type(method) is DOP853
    if not dop853 and not _generic(method):
        return f"the method {type(method).__name__} defines its own step or output"
    py_constraints = [k for k in range(cons.shape[0]) if cons[k, 0] == PYTHON]
    if py_constraints:
        if state is None:
            return "constraints without a compiled form need the initial state for their rows"
        row = 0
        for k in range(cons.shape[0]):
            cons[k, 3] = row
            if cons[k, 0] == PYTHON:
                c = system.constraints[k]
                try:
                    _, b = _pair(c, state)
                    cons[k, 4] = np.asarray(b).reshape(-1).size
                except Exception as exc:  # the Python loop reports it
                    return f"constraint {c.name!r} failed at the initial state ({exc})"
            row += cons[k, 4]
    terms: list[list[int]] = []
    params: list[float] = []
    fields: list[np.ndarray] = []
    field_at: dict[int, tuple[int, int]] = {}
    n_field = 0
    py_forces = []
    for entry in system._force_plan:
        f, _bodies, slots = entry
        compiled_terms = [] if slots is None else [f._compiled_term(b) for b, *_ in slots]
        if slots is None or any(term is None for term in compiled_terms):
            py_forces.append(entry)  # the whole model in Python
            continue
        for (_body, rigid, index, offset, _dof), term in zip(slots, compiled_terms, strict=True):
            assert term is not None
            code, values, data = term
            f0 = f1 = 0
            if data is not None:
                if id(data) not in field_at:
                    field_at[id(data)] = (n_field, n_field + data.size)
                    fields.append(np.asarray(data, dtype=float))
                    n_field += data.size
                f0, f1 = field_at[id(data)]
            terms.append([code, int(rigid), index, offset, int(f.modeled), len(params), f0, f1])
            params.extend(float(v) for v in values)
    nr, ne = lay.n_rigid, lay.n_euclid
    field_data = np.concatenate(fields) if fields else np.zeros(1)
    field_data.setflags(write=False)
    n_rows = int(cons[:, 4].sum())
    if solve == DENSE:  # DenseSolver.solve_rows: QR up to QR_MAX_ROWS rows, certified
        if n_rows > QR_MAX_ROWS:
            return f"more than {QR_MAX_ROWS} constraint rows under the dense solve"
        rcond = system.rcond
        if rcond is None:
            rcond = max(n_rows, lay.n_dof) * float(np.finfo(float).eps)
        uk_params[0] = min(QR_COND_LIMIT, 0.1 / rcond)
    nc = lay.n_control
    ctrl_rows: list[list[int]] = []
    ctrl_params: list[float] = []
    py_controllers = []
    for k, ctl in enumerate(system.controllers):
        term = ctl._compiled_term()
        body = system._ctrl_bodies[k][0] if len(system._ctrl_bodies[k]) == 1 else None
        if term is None or body is None or body.kind is not BodyKind.RIGID:
            py_controllers.append(k)
            continue
        slot = lay.slot(body)
        code, values = term
        z0 = int(system._ctrl_slices[k].start)
        ctrl_rows.append([code, slot.index, slot.offset, z0, len(ctrl_params)])
        ctrl_params.extend(np.asarray(values, dtype=float).tolist())
    python = None
    if py_forces or py_constraints or py_controllers:
        python = PythonParts(system, py_forces, cons, py_constraints, py_controllers)
    io = python.io if python is not None else np.zeros(1)
    callback = python.address if python is not None else 0
    loads_at = python.loads_at if python is not None else 0
    controls_at = python.controls_at if python is not None and py_controllers else 0
    points = [lay.slot(b).index for b in system.bodies if b.kind is BodyKind.POINT]
    point_starts = [12 * nr + half * ne + i for half in (0, 1) for i in points]
    parts = (
        np.array(terms, dtype=np.int64).reshape(-1, 8),
        np.array([*params, 0.0], dtype=float),
        field_data,
        np.ascontiguousarray(system._J, dtype=float).reshape(nr, 3, 3),
        np.ascontiguousarray(system._Jinv, dtype=float).reshape(nr, 3, 3),
        np.ascontiguousarray(system._m_rigid, dtype=float).reshape(nr),
        np.ascontiguousarray(system._m_euclid, dtype=float).reshape(ne),
        np.asarray(lay.rigid_offsets, dtype=np.int64),
        np.asarray(lay.euclid_offsets, dtype=np.int64),
        np.array(
            [
                nr,
                ne,
                lay.n_dof,
                int(system._plant_only_loads),
                n_rows,
                callback,
                nc,
                controls_at,
                solve,
                loads_at,
            ],
            dtype=np.int64,
        ),
        cons,
        cparams,
        uk_params,
        io,
        np.array(ctrl_rows, dtype=np.int64).reshape(-1, 5),
        np.array([*ctrl_params, 0.0], dtype=float),
        # the point masses' 3-vectors in Y (positions, then velocities), for the error weights
        np.array(point_starts, dtype=np.int64),
    )
    s = method.n_stages
    E = np.zeros(method._n_rows) if method.E is None else np.asarray(method.E, dtype=float)
    ints = np.array(
        [
            s,
            method._n_rows,
            int(method.fsal),
            int(method.adaptive),
            method.order,
            int(dop853),
            int(method.dense_output),
        ],
        dtype=np.int64,
    )
    # writable copies: every program has the same argument types (one compiled loop)
    meth = (
        np.array(method.A, dtype=float, order="C"),
        np.array(method.b, dtype=float),
        np.array(method.c, dtype=float),
        np.array(E, dtype=float),
        np.array(_tab.E3 if dop853 else np.zeros(method._n_rows), dtype=float),
        np.array(_tab.A, dtype=float, order="C"),
        np.array(_tab.C, dtype=float),
        np.array(_tab.D, dtype=float, order="C"),
        ints,
    )
    return Program(parts, meth, 12 * nr + 2 * ne + nc, n_rows, python)


#: The C signature of PythonParts' callback: int64 f(int64 phase), 0 on success.
_CALLBACK_TYPE = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_int64)


class PythonParts:
    """The force models, constraints and controllers of a System that have no compiled form,
    evaluated in Python when the compiled right-hand side calls back.

    The compiled loop writes the stage's state into ``io`` and calls a C function (a ctypes
    callback to :meth:`_call`): in phase 0 this builds the :class:`~gmuk.State`, calls the
    force models and constraints as the System does (``System._add_loads``, each
    constraint's ``rows``) and writes their generalized forces and rows back into ``io``; in
    phase 1, after the solve, it calls the controllers with the modeled acceleration
    (``System._controls_of``). Layout of ``io``: t, g (16 n_r), V (6 n_r), x (n_e), ẋ (n_e),
    z (n_c); from ``loads_at`` the modeled and unmodeled generalized forces (2 n_dof); from
    ``controls_at`` the modeled acceleration (n_dof, in), the controls (n_dof) and ż (n_c);
    then for each of these constraints its rows A (rows, n_dof) and b (rows), at the offset
    the constraint table holds. Only such a part costs Python time; a part that raises makes
    the loop stop with :data:`CALLBACK` and leaves the exception in ``error``.
    """

    def __init__(
        self,
        system: System,
        forces: list[Any],
        cons: np.ndarray,
        constraints: list[int],
        controllers: list[int],
    ) -> None:
        lay = system.layout
        nr, ne, nd, nc = lay.n_rigid, lay.n_euclid, lay.n_dof, lay.n_control
        self.system, self.forces, self.layout = system, forces, lay
        self.controllers = controllers
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
        at = ca + 2 * nd + nc
        self.constraints = []
        for k in constraints:
            rows = int(cons[k, 4])
            cons[k, 5] = at
            self.constraints.append(
                (system.constraints[k], system._constraint_cols[k].size,
                 system._constraint_where[k], rows, at)
            )  # fmt: skip
            at += rows * (nd + 1)
        self.io = np.zeros(at)
        self._modeled = self.io[self.loads_at : self.loads_at + nd]
        self._unmodeled = self.io[self.loads_at + nd : self.loads_at + 2 * nd]
        self._state: State | None = None
        self.error: BaseException | None = None
        # resolved once: the callback runs at every evaluation
        from gmuk.constraints.base import as_rows
        from gmuk.state import State as _State
        from gmuk.system import _pair

        self._as_rows, self._make_state, self._pair = as_rows, _State, _pair
        self._c_function = _CALLBACK_TYPE(self._call)  # kept alive with the program
        self.address = int(ctypes.cast(self._c_function, ctypes.c_void_p).value or 0)

    def _call(self, phase: int) -> int:
        try:
            if phase == 0:
                self.evaluate()
            else:
                self.control()
        except BaseException as exc:  # a C caller cannot take an exception: keep it
            self.error = exc
            return 1
        return 0

    def control(self) -> None:
        """The controllers' generalized forces and internal-state rates at the state of the
        last :meth:`evaluate`, given the modeled acceleration in ``io``, into ``io``."""
        assert self._state is not None
        io = self.io
        control, z_dot = self.system._controls_of(
            self.controllers, self._state, io[self._acc].copy()
        )
        io[self._control] = control
        io[self._z_dot] = z_dot

    def evaluate(self) -> None:
        """The parts' loads and rows at the state in ``io``, into ``io``."""
        io, lay = self.io, self.layout
        self._state = state = self._make_state(
            float(io[0]),
            io[self._g].reshape(lay.n_rigid, 4, 4).copy(),
            io[self._V].reshape(lay.n_rigid, 6).copy(),
            io[self._x].copy(),
            io[self._xd].copy(),
            io[self._z].copy(),
            lay,
        )
        if self.forces:
            self._modeled[:] = 0.0
            self._unmodeled[:] = 0.0
            self.system._add_loads(self.forces, state, self._modeled, self._unmodeled)
        nd = lay.n_dof
        for c, width, where, rows, at in self.constraints:
            Ai, bi = self._pair(c, state)
            Ai, bi = self._as_rows(Ai, bi, width, f"constraint {c.name!r}")
            if bi.size != rows:
                raise ConstraintError(
                    f"constraint {c.name!r} gave {bi.size} rows at t = {state.t:.9g} s and "
                    f"{rows} at the start"
                )
            block = io[at : at + rows * nd].reshape(rows, nd)
            block[:] = 0.0
            block[:, where] = Ai.toarray() if hasattr(Ai, "toarray") else Ai
            io[at + rows * nd : at + rows * (nd + 1)] = bi


# Constraint kinds of the compiled right-hand side.
TRACKING_LVLH = 0  #: ConfigurationTracking of an LVLHReference (Eq. 67), Baumgarte optional
RELATIVE = 1  #: RelativeConstraint with a zero desired relative motion (Eq. 73)
PYTHON = 2  #: any other constraint: its rows come from Python (PythonParts), at io[p0:]


def _gains(baumgarte: Any, n: int) -> list[float] | None:
    """[flag, α (n), β (n)] with the gains broadcast to n rows (zeros without Baumgarte), or
    None when they do not broadcast."""
    if baumgarte is None:
        return [0.0] * (1 + 2 * n)
    try:
        alpha = np.broadcast_to(np.asarray(baumgarte.alpha, dtype=float), (n,))
        beta = np.broadcast_to(np.asarray(baumgarte.beta, dtype=float), (n,))
    except ValueError:
        return None
    return [1.0, *alpha.tolist(), *beta.tolist()]


def _constraint_program(system: System) -> tuple[Any, Any, Any, int]:
    """(cons (n_c, 6) int64 — kind, body, other body, first row, rows, parameter start —,
    parameters, the solve's packed constants, the solve: FREE, FUSED or DENSE), or (why
    not, None, None, 0) for a solve strategy that is not compiled. The row counts of PYTHON
    constraints are left to :func:`program`."""
    from gmuk.constraints.relative import RelativeConstraint
    from gmuk.constraints.tracking import ConfigurationTracking
    from gmuk.orbits.lvlh import LVLHReference
    from gmuk.solvers import QR_COND_LIMIT, DenseSolver, FusedRigidSolver

    solver = system.solver
    if not system.constraints:  # every strategy: the free acceleration, then the plant loads
        return np.zeros((0, 6), dtype=np.int64), np.zeros(1), np.zeros(1), FREE
    if type(solver) is FusedRigidSolver:
        kind = FUSED
    elif type(solver) is DenseSolver:
        kind = DENSE
    else:
        why = f"the System's constraints are solved by {type(solver).__name__}, not compiled"
        return why, None, None, 0
    rows: list[list[int]] = []
    params: list[float] = []
    row = 0
    rigid = BodyKind.RIGID
    for c in system.constraints:
        bodies = [system._resolve(b) for b in c.bodies]
        idx = [system.layout.slot(b).index for b in bodies]
        start = len(params)
        tracking = type(c) is ConfigurationTracking and type(c.reference) is LVLHReference
        relative = (
            type(c) is RelativeConstraint
            and c.acceleration is None
            and (c.baumgarte is None or c.velocity is None)
        )
        gains = None
        if tracking or relative:
            gains = _gains(c.baumgarte, 6 if tracking else np.asarray(c.S).shape[0])
        if gains is None or any(b.kind is not rigid for b in bodies):
            # rows from Python (another kind, or Baumgarte gains of a shape the kernels do
            # not take); program() sets their count and place
            rows.append([PYTHON, 0, 0, row, 0, 0])
        elif tracking:
            o = c.reference.orbit
            params += [o.mean_motion, o.e, o.mu, o.p, *np.ravel(c.reference._R_NP), *gains]
            rows.append([TRACKING_LVLH, idx[0], idx[0], row, 6, start])
            row += 6
        else:
            S = np.asarray(c.S, dtype=float)
            params += [*gains[1 : 1 + S.shape[0]], *S.ravel()]
            rows.append([RELATIVE, idx[0], idx[1], row, S.shape[0], start])
            row += S.shape[0]
    cons = np.array(rows, dtype=np.int64)
    if isinstance(solver, FusedRigidSolver):
        # a writable copy: every program has the same argument types
        return cons, np.array([*params, 0.0]), np.array(solver._params), kind
    # P[0], the condition limit, depends on the row count: program() sets it
    P = [QR_COND_LIMIT, system.consistency_tol, *np.ravel(system._Minv_sqrt)]
    return cons, np.array([*params, 0.0]), np.array(P, dtype=float), kind


# ------------------------------------------------------------------------ right-hand side
UK_FAILED = -5  #: the fused solve did not certify its answer (the Python loop decides)
CALLBACK = -6  #: a part evaluated in Python raised (PythonParts.error holds the exception)

# How the right-hand side solves (dims[8]).
FREE = 0  #: no constraints: the free acceleration
FUSED = 1  #: FusedRigidSolver: free acceleration, QR solve and wrenches in one call
DENSE = 2  #: DenseSolver: the free acceleration, then the certified QR solve


@intrinsic
def _call_back(typingctx, address, phase):  # type: ignore[no-untyped-def]
    """Call the C function ``int64 f(int64 phase)`` at ``address`` (a ctypes callback)."""

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        fnty = ir.FunctionType(ir.IntType(64), [ir.IntType(64)])
        return builder.call(builder.inttoptr(args[0], fnty.as_pointer()), [args[1]])

    return types.int64(types.int64, types.int64), codegen


@njit(cache=True)
def rhs(t, Y, G0, parts, dY, aux):  # type: ignore[no-untyped-def]
    """dY/dt at (t, Y) about the base poses G0 into ``dY``, and into ``aux`` (Program.n_aux)
    the total acceleration, the unmodeled generalized forces, the constraint acceleration,
    the constraint wrenches M ν̇_c, the multipliers λ (s), the solve's residual, the
    controllers' generalized forces and their states' rates ż. Returns 0, NONFINITE,
    UK_FAILED, CALLBACK, or −100 − the status of a failed force kernel."""
    terms, params, fdata, J, Jinv, m_r, m_e, r_off, e_off, dims, cons, cparams, P, io = parts[:14]
    ctrls, ctrl_params = parts[14], parts[15]
    nr, ne, ndof, plant, s, nc = dims[0], dims[1], dims[2], dims[3], dims[4], dims[6]
    total = aux[:ndof]
    unmodeled = aux[ndof : 2 * ndof]
    xi = np.empty((nr, 6))
    V = np.empty((nr, 6))
    any_xi = False
    for k in range(nr):
        for i in range(6):
            xi[k, i] = Y[6 * k + i]
            V[k, i] = Y[6 * nr + 6 * k + i]
            if xi[k, i] != 0.0:
                any_xi = True
    g = np.empty((nr, 4, 4))
    if nr:
        _compose_exp_into(G0, xi, g)
    modeled = np.zeros(ndof)
    for i in range(ndof):
        unmodeled[i] = 0.0
    w = np.empty(6)
    gp = np.zeros((4, 4))
    vp = np.zeros(6)
    no_inertia = np.zeros((3, 3))
    x0 = 12 * nr
    for f in range(terms.shape[0]):
        code, rig, idx, off = terms[f, 0], terms[f, 1], terms[f, 2], terms[f, 3]
        p0, f0, f1 = terms[f, 5], terms[f, 6], terms[f, 7]
        if rig:
            status = apply_term(
                code, rig != 0, t, g[idx], V[idx], m_r[idx], J[idx], params[p0:], fdata[f0:f1], w
            )
            dof = 6
        else:
            for i in range(3):
                gp[i, 3] = Y[x0 + idx + i]
                vp[i] = Y[x0 + ne + idx + i]
            status = apply_term(
                code, rig != 0, t, gp, vp, m_e[idx], no_inertia, params[p0:], fdata[f0:f1], w
            )
            dof = 3
        if status != 0:
            return -100 - status
        if terms[f, 4]:
            for i in range(dof):
                modeled[off + i] += w[i]
        else:
            for i in range(dof):
                unmodeled[off + i] += w[i]
    if dims[5] != 0:  # the parts without a compiled form, in Python (PythonParts)
        io[0] = t
        for k in range(nr):
            for a in range(4):
                for e in range(4):
                    io[1 + 16 * k + 4 * a + e] = g[k, a, e]
            for i in range(6):
                io[1 + 16 * nr + 6 * k + i] = V[k, i]
        for i in range(2 * ne + nc):  # x, ẋ, z
            io[1 + 22 * nr + i] = Y[x0 + i]
        if _call_back(dims[5], 0) != 0:
            return CALLBACK
        lo = dims[9]
        for i in range(ndof):
            modeled[i] += io[lo + i]
            unmodeled[i] += io[lo + ndof + i]
    fused = dims[8] == FUSED
    if s and fused:
        # rigid bodies only, every load seen by the solve: the rows, then one compiled call
        A = np.zeros((s, ndof))
        b = np.empty(s)
        _constraint_rows(t, g, V, cons, cparams, io, r_off, A, b)
        out = np.empty(4 * ndof + s + 3)
        uk_rigid(V, modeled, A, b, P, out)
        if out[4 * ndof + s + 2] != 0.0:
            return UK_FAILED
        for i in range(ndof):
            total[i] = out[2 * ndof + i]
            aux[2 * ndof + i] = out[ndof + i]
            aux[3 * ndof + i] = out[3 * ndof + i]
        for i in range(s):
            aux[4 * ndof + i] = out[4 * ndof + i]
        aux[4 * ndof + s] = out[4 * ndof + s]
    else:
        # ν̇_a = M⁻¹(ad*_V 𝕀V + Q): Eq. 10b for rigid bodies, Q/m for point masses
        if nr:
            Q = np.empty((nr, 6))
            for k in range(nr):
                for i in range(6):
                    Q[k, i] = modeled[r_off[k] + i]
            a_r = rigid_free_accel(V, J, Jinv, m_r, Q)
            for k in range(nr):
                for i in range(6):
                    total[r_off[k] + i] = a_r[k, i]
        for i in range(ne):
            total[e_off[i]] = modeled[e_off[i]] / m_e[i]
        for i in range(2 * ndof, 4 * ndof + s + 1):
            aux[i] = 0.0
        if s:  # the dense strategy's QR solve (DenseSolver.solve_rows), certified or handed over
            A = np.zeros((s, ndof))
            b = np.empty(s)
            _constraint_rows(t, g, V, cons, cparams, io, r_off, A, b)
            ac = aux[2 * ndof : 3 * ndof]
            Minv_sqrt = P[2 : 2 + ndof * ndof].reshape((ndof, ndof))
            residual, scale, status = _qr_solve(
                A, b, total, Minv_sqrt, P[0], ac, aux[4 * ndof : 4 * ndof + s]
            )
            if status != 0 or residual > P[1] * scale:
                return UK_FAILED
            aux[4 * ndof + s] = residual
            _apply_M(ac, J, m_r, m_e, r_off, e_off, aux[3 * ndof : 4 * ndof])
            for i in range(ndof):
                total[i] += ac[i]
    control = aux[4 * ndof + s + 1 : 5 * ndof + s + 1]
    z_dot = aux[5 * ndof + s + 1 :]
    for i in range(ndof):
        control[i] = 0.0
    ca = dims[7]
    if ca:  # the controllers, in Python, given the modeled acceleration ν̇_a + ν̇_c
        for i in range(ndof):
            io[ca + i] = total[i]
        if _call_back(dims[5], 1) != 0:
            return CALLBACK
        for i in range(ndof):
            control[i] = io[ca + ndof + i]
        for i in range(nc):
            z_dot[i] = io[ca + 2 * ndof + i]
    if ctrls.shape[0]:  # the compiled controllers (gmuk.control._kernels)
        u = np.empty(6)
        zd = np.empty(6)
        zs = x0 + 2 * ne
        for c in range(ctrls.shape[0]):
            code, k, o, z0, p0 = ctrls[c, 0], ctrls[c, 1], ctrls[c, 2], ctrls[c, 3], ctrls[c, 4]
            apply_control(
                code, t, g[k], V[k], total[o : o + 6], Y[zs + z0 : zs + z0 + 6],
                ctrl_params[p0:], u, zd,
            )  # fmt: skip
            for i in range(6):
                control[o + i] += u[i]
                z_dot[z0 + i] = zd[i]
    if plant:  # unmodeled loads and controls act on the plant: + M⁻¹ (Q_u + u)
        for k in range(nr):
            o = r_off[k]
            for i in range(3):
                total[o + i] += (
                    Jinv[k, i, 0] * (unmodeled[o] + control[o])
                    + Jinv[k, i, 1] * (unmodeled[o + 1] + control[o + 1])
                    + Jinv[k, i, 2] * (unmodeled[o + 2] + control[o + 2])
                )
                total[o + 3 + i] += (unmodeled[o + 3 + i] + control[o + 3 + i]) / m_r[k]
        for i in range(ne):
            o = e_off[i]
            total[o] += (unmodeled[o] + control[o]) / m_e[i]
    # dY = [dexp⁻¹(ξ) V, V̇, ẋ, ẍ]
    if nr:
        if any_xi:
            xd = np.empty((nr, 6))
            _dexp_inv_apply_into(xi, V, xd)
            for k in range(nr):
                for i in range(6):
                    dY[6 * k + i] = xd[k, i]
        else:
            for i in range(6 * nr):
                dY[i] = Y[6 * nr + i]
        for k in range(nr):
            for i in range(6):
                dY[6 * nr + 6 * k + i] = total[r_off[k] + i]
    for i in range(ne):
        dY[x0 + i] = Y[x0 + ne + i]
        dY[x0 + ne + i] = total[e_off[i]]
    for i in range(nc):
        dY[x0 + 2 * ne + i] = z_dot[i]
    for i in range(dY.shape[0]):
        if not math.isfinite(dY[i]):
            return NONFINITE
    return 0


@njit(cache=True)
def _apply_M(a, J, m_r, m_e, r_off, e_off, out):  # type: ignore[no-untyped-def]
    """out = M a for the block-diagonal mass matrix: [J ω̇; m v̇] per rigid body, m ẍ per
    point-mass coordinate (System._apply_M)."""
    for k in range(J.shape[0]):
        o = r_off[k]
        for i in range(3):
            out[o + i] = J[k, i, 0] * a[o] + J[k, i, 1] * a[o + 1] + J[k, i, 2] * a[o + 2]
            out[o + 3 + i] = m_r[k] * a[o + 3 + i]
    for i in range(m_e.shape[0]):
        out[e_off[i]] = m_e[i] * a[e_off[i]]


@njit(cache=True)
def _constraint_rows(t, g, V, cons, cparams, io, r_off, A, b):  # type: ignore[no-untyped-def]
    """The stacked rows (A, b) of the constraints, as their ``rows`` give them: computed
    here (a rigid body's columns start at its offset in ν, ``r_off``), or copied from ``io``
    where PythonParts wrote them."""
    gd = np.empty((4, 4))
    Vd = np.empty(6)
    Vd_dot = np.empty(6)
    bk = np.empty(6)
    R_NP = np.empty((3, 3))
    for c in range(cons.shape[0]):
        kind, i, j, r0, nrow, p0 = (
            cons[c, 0],
            cons[c, 1],
            cons[c, 2],
            cons[c, 3],
            cons[c, 4],
            cons[c, 5],
        )
        if kind == TRACKING_LVLH:
            for a in range(3):
                for e in range(3):
                    R_NP[a, e] = cparams[p0 + 4 + 3 * a + e]
            lvlh_state(
                t,
                cparams[p0],
                cparams[p0 + 1],
                cparams[p0 + 2],
                cparams[p0 + 3],
                R_NP,
                gd,
                Vd,
                Vd_dot,
            )
            tracking_b(g[i], V[i], gd, Vd, Vd_dot, bk)
            if cparams[p0 + 13] != 0.0:
                _baumgarte_tracking(g[i], V[i], gd, Vd, cparams[p0 + 14 :], cparams[p0 + 20 :], bk)
            for r in range(6):
                A[r0 + r, r_off[i] + r] = 1.0
                b[r0 + r] = bk[r]
        elif kind == PYTHON:  # A (nrow, n_dof) then b (nrow) at io[p0:]
            ndof = A.shape[1]
            for a in range(nrow):
                for e in range(ndof):
                    A[r0 + a, e] = io[p0 + a * ndof + e]
                b[r0 + a] = io[p0 + nrow * ndof + a]
        else:  # RELATIVE: columns [V_L, V_B]
            S = np.empty((nrow, 6))
            for a in range(nrow):
                for e in range(6):
                    S[a, e] = cparams[p0 + nrow + 6 * a + e]
            Ak = np.empty((nrow, 12))
            bkr = np.empty(nrow)
            V_BL = np.empty(6)
            relative_rows(g[i], V[i], g[j], V[j], S, np.zeros(6), Ak, bkr, V_BL)
            for a in range(nrow):
                alpha = cparams[p0 + a]
                if alpha != 0.0:
                    q = 0.0
                    for e in range(6):
                        q += S[a, e] * V_BL[e]
                    bkr[a] = bkr[a] - alpha * q
                b[r0 + a] = bkr[a]
                for e in range(6):
                    A[r0 + a, r_off[i] + e] = Ak[a, e]
                    A[r0 + a, r_off[j] + e] = Ak[a, 6 + e]


@njit(cache=True)
def _baumgarte_tracking(g, V, gd, Vd, alpha, beta, b):  # type: ignore[no-untyped-def]
    """b ← b − α e_V − β e_g (gains per row) with e_g = log(g_d⁻¹ g) and
    e_V = V − Ad_{(g_d⁻¹ g)⁻¹} V_d (gmuk.constraints.tracking.tracking_errors)."""
    gd_inv = np.zeros((1, 4, 4))
    gd1 = np.empty((1, 4, 4))
    gd1[0] = gd
    _se3_inverse_into(gd1, gd_inv)
    g_err = np.zeros((1, 4, 4))
    for a in range(4):
        for e in range(4):
            q = 0.0
            for m in range(4):
                q += gd_inv[0, a, m] * g[m, e]
            g_err[0, a, e] = q
    e_g = np.empty((1, 6))
    _se3_log_into(g_err, e_g)
    g_err_inv = np.zeros((1, 4, 4))
    _se3_inverse_into(g_err, g_err_inv)
    Ad = np.zeros((1, 6, 6))
    _se3_Ad_into(g_err_inv, Ad)
    for a in range(6):
        q = 0.0
        for e in range(6):
            q += Ad[0, a, e] * Vd[e]
        e_V = V[a] - q
        b[a] = b[a] - alpha[a] * e_V - beta[a] * e_g[0, a]


@njit(cache=True)
def _scale(Y0, Y1, G0, nr, pts, rtol, atol, sc):  # type: ignore[no-untyped-def]
    """The error weights of :meth:`gmuk.integrate._Problem.scale` (``pts``: where the point
    masses' 3-vectors start in Y; other Euclidean entries are scalars)."""
    for i in range(Y0.shape[0]):
        sc[i] = atol + rtol * max(abs(Y0[i]), abs(Y1[i]))
    for k in range(nr):
        r = math.sqrt(G0[k, 0, 3] ** 2 + G0[k, 1, 3] ** 2 + G0[k, 2, 3] ** 2)
        for i in range(3):
            sc[6 * k + i] = atol + rtol
            sc[6 * k + 3 + i] = atol + rtol * r
        for half in range(2):
            o = 6 * nr + 6 * k + 3 * half
            n0 = math.sqrt(Y0[o] ** 2 + Y0[o + 1] ** 2 + Y0[o + 2] ** 2)
            n1 = math.sqrt(Y1[o] ** 2 + Y1[o + 1] ** 2 + Y1[o + 2] ** 2)
            w = atol + rtol * max(n0, n1)
            sc[o] = sc[o + 1] = sc[o + 2] = w
    # point masses: positions and velocities as 3-vectors
    for o in pts:
        n0 = math.sqrt(Y0[o] ** 2 + Y0[o + 1] ** 2 + Y0[o + 2] ** 2)
        n1 = math.sqrt(Y1[o] ** 2 + Y1[o + 1] ** 2 + Y1[o + 2] ** 2)
        w = atol + rtol * max(n0, n1)
        sc[o] = sc[o + 1] = sc[o + 2] = w


@njit(cache=True)
def _rms(v, sc):  # type: ignore[no-untyped-def]
    acc = 0.0
    for i in range(v.shape[0]):
        acc += (v[i] / sc[i]) ** 2
    return math.sqrt(acc / v.shape[0])


@njit(cache=True)
def initial_step(t, Y, G0, f0, t_end, first_step, max_step, order, parts, fs, ints):  # type: ignore[no-untyped-def]
    """:meth:`gmuk.integrate._Stepper._initial_step` (Hairer's starting step). Returns the
    step, or a negative number on a failed evaluation (status in ints[I_FIELD])."""
    if first_step > 0.0:
        return min(first_step, t_end - t)
    nr, ndof = parts[9][0], parts[9][2]
    n = Y.shape[0]
    sc = np.empty(n)
    _scale(Y, Y, G0, nr, parts[16], fs[F_RTOL], fs[F_ATOL], sc)
    d0 = _rms(Y, sc)
    d1 = _rms(f0, sc)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, t_end - t)
    f1 = np.empty(n)
    aux = np.empty(5 * ndof + parts[9][4] + 1 + parts[9][6])
    ints[I_RHS] += 1
    status = rhs(t + h0, Y + h0 * f0, G0, parts, f1, aux)
    if status != 0:
        ints[I_FIELD] = status
        fs[F_BAD_T] = t + h0
        return -1.0
    acc = 0.0
    for i in range(n):
        acc += ((f1[i] - f0[i]) / sc[i]) ** 2
    d2 = math.sqrt(acc / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100 * h0, h1, max_step, t_end - t)


@njit(cache=True)
def _factor(err, order):  # type: ignore[no-untyped-def]
    return 0.9 * (max(err, 1e-10) ** (-1.0 / order))


@njit(cache=True)
def _interpolate(F, Y0, s, out):  # type: ignore[no-untyped-def]
    """DOP853's continuous extension u(s) into ``out`` (gmuk.integrators.dop853)."""
    n = Y0.shape[0]
    p = F.shape[0]
    acc = np.zeros(n)
    for i in range(p):
        fac = s if i % 2 == 0 else 1.0 - s
        for j in range(n):
            acc[j] = (acc[j] + F[p - 1 - i, j]) * fac
    for j in range(n):
        out[j] = Y0[j] + acc[j]


@njit(cache=True)
def _stage_state(Y, h, a, K, i, out):  # type: ignore[no-untyped-def]
    """out = Y + h Σ_{m<i} a_m K_m: the state at which stage i is evaluated."""
    for j in range(Y.shape[0]):
        q = 0.0
        for m in range(i):
            q += a[m] * K[m, j]
        out[j] = Y[j] + h * q


@njit(cache=True)
def advance(parts, meth, fs, ints, Y, G0, f0, aux, outs, has_outs, bt, bY, bG, baux):  # type: ignore[no-untyped-def]
    """Run steps from (fs[F_T], Y, G0) with f0 = f(t, Y) and the outputs ``aux`` of that
    evaluation (see :func:`rhs`), until the end time, ``ints[I_CHUNK]`` steps, full output
    buffers or a failure; returns the status (module constants). Y, G0, f0, aux, fs and
    ints are updated in place to the last accepted step; outputs are appended to the buffers
    (times bt, states bY, base poses bG, rhs outputs baux) from ints[I_WRITTEN]."""
    A, b, c, E, E3, Ax, Cx, D, mi = meth
    s, n_rows, fsal, adaptive, order, dop853, dense = (
        mi[0],
        mi[1],
        mi[2],
        mi[3],
        mi[4],
        mi[5],
        mi[6],
    )
    dims = parts[9]
    nr, ne = dims[0], dims[1]
    n = Y.shape[0]
    t, h, t_end = fs[F_T], fs[F_H], fs[F_END]
    rtol, atol, max_step = fs[F_RTOL], fs[F_ATOL], fs[F_MAX_STEP]
    out_i = ints[I_OUT]
    n_outs = outs.shape[0]
    cap = bt.shape[0]
    step_to_outputs = (not dense) and has_outs
    use_dense = dense and has_outs
    eps = np.finfo(np.float64).eps
    K = np.empty((n_rows, n))
    Kx = np.empty((_tab.N_STAGES_EXTENDED, n))
    F = np.empty((_tab.INTERPOLATOR_POWER, n))
    Yt = np.empty(n)
    Y1 = np.empty(n)
    f1 = np.empty(n)
    sc = np.empty(n)
    n_aux = aux.shape[0]
    aux1 = np.empty(n_aux)
    tmp_aux = np.empty(n_aux)
    G1 = np.empty((nr, 4, 4))
    R = np.empty((3, 3))
    RtR = np.empty((3, 3))
    u = np.empty(n)
    du = np.empty(n)
    ddy = np.empty(n)
    steps_here = 0
    status = DONE
    while t < t_end:
        if ints[I_STEPS] >= ints[I_MAX_STEPS]:
            status = MAX_STEPS
            break
        if steps_here >= ints[I_CHUNK]:
            status = PAUSE
            break
        h = min(h, max_step)
        t_target = t_end
        if step_to_outputs and out_i < n_outs:
            t_target = min(t_end, outs[out_i])
        landing = t_target - t <= h * (1.0 + 1e-6)
        h_try = t_target - t if landing else h
        if h_try <= 10 * eps * max(1.0, abs(t)):
            status = UNDERFLOW
            fs[F_H] = h_try
            break
        # room for this step's outputs
        need = 1
        if use_dense:
            j = out_i
            while j < n_outs and outs[j] <= t + h_try:
                need += 1
                j += 1
        if ints[I_WRITTEN] + need > cap:
            ints[I_NEED] = need
            status = FULL
            break
        # stages
        for j in range(n):
            K[0, j] = f0[j]
        bad = 0
        for i in range(1, s):
            _stage_state(Y, h_try, A[i], K, i, Yt)
            ints[I_RHS] += 1
            bad = rhs(t + c[i] * h_try, Yt, G0, parts, K[i], tmp_aux)
            if bad != 0:
                fs[F_BAD_T] = t + c[i] * h_try
                break
        if bad != 0:
            status = bad if bad > -100 else FIELD
            ints[I_FIELD] = bad
            break
        for j in range(n):
            q = 0.0
            for i in range(s):
                q += b[i] * K[i, j]
            Y1[j] = Y[j] + h_try * q
        ints[I_RHS] += 1
        bad = rhs(t + h_try, Y1, G0, parts, f1, aux1)
        if bad != 0:
            fs[F_BAD_T] = t + h_try
            status = bad if bad > -100 else FIELD
            ints[I_FIELD] = bad
            break
        if fsal:
            for j in range(n):
                K[n_rows - 1, j] = f1[j]
        h_next = h
        if adaptive:
            _scale(Y, Y1, G0, nr, parts[16], rtol, atol, sc)
            if dop853:
                n5 = 0.0
                n3 = 0.0
                for j in range(n):
                    e5 = 0.0
                    e3 = 0.0
                    for i in range(n_rows):
                        e5 += K[i, j] * E[i]
                        e3 += K[i, j] * E3[i]
                    n5 += (e5 / sc[j]) ** 2
                    n3 += (e3 / sc[j]) ** 2
                err = 0.0
                if n5 != 0.0 or n3 != 0.0:
                    err = abs(h_try) * n5 / math.sqrt((n5 + 0.01 * n3) * n)
            else:
                acc2 = 0.0
                for j in range(n):
                    e = 0.0
                    for i in range(n_rows):
                        e += K[i, j] * E[i]
                    acc2 += (h_try * e / sc[j]) ** 2
                err = math.sqrt(acc2 / n)
            factor = _factor(err, order)
            if err > 1.0:
                ints[I_REJECTED] += 1
                h = h_try * max(0.2, min(0.9, factor))
                continue
            h_next = h_try * min(10.0, max(0.2, factor))
        t_new = t_target if landing else t + h_try
        if use_dense and out_i < n_outs and outs[out_i] < t_new:
            # DOP853's continuous extension: three more stages
            ne_rows = _tab.N_STAGES + 1
            for i in range(ne_rows):
                for j in range(n):
                    Kx[i, j] = K[i, j]
            for i in range(ne_rows, _tab.N_STAGES_EXTENDED):
                _stage_state(Y, h_try, Ax[i], Kx, i, Yt)
                ints[I_RHS] += 1
                bad = rhs(t + Cx[i] * h_try, Yt, G0, parts, Kx[i], tmp_aux)
                if bad != 0:
                    fs[F_BAD_T] = t + Cx[i] * h_try
                    break
            if bad != 0:
                status = bad if bad > -100 else FIELD
                ints[I_FIELD] = bad
                break
            last = _tab.N_STAGES
            for j in range(n):
                dy = Y1[j] - Y[j]
                F[0, j] = dy
                F[1, j] = h_try * K[0, j] - dy
                F[2, j] = 2.0 * dy - h_try * (K[last, j] + K[0, j])
            for r in range(D.shape[0]):
                for j in range(n):
                    q = 0.0
                    for m in range(_tab.N_STAGES_EXTENDED):
                        q += D[r, m] * Kx[m, j]
                    F[3 + r, j] = h_try * q
            if adaptive:
                # the extension's error from its defect at s* = 0.95 (DOP853.interpolant_error)
                s_star = 0.95
                p = F.shape[0]
                for j in range(n):
                    u[j] = 0.0
                    du[j] = 0.0
                for i in range(p):
                    for j in range(n):
                        qq = u[j] + F[p - 1 - i, j]
                        if i % 2 == 0:
                            u[j], du[j] = qq * s_star, du[j] * s_star + qq
                        else:
                            u[j], du[j] = qq * (1.0 - s_star), du[j] * (1.0 - s_star) - qq
                for j in range(n):
                    u[j] += Y[j]
                ints[I_RHS] += 1
                bad = rhs(t + s_star * h_try, u, G0, parts, ddy, tmp_aux)
                if bad != 0:
                    fs[F_BAD_T] = t + s_star * h_try
                    status = bad if bad > -100 else FIELD
                    ints[I_FIELD] = bad
                    break
                acc2 = 0.0
                for j in range(n):
                    acc2 += ((h_try * ddy[j] - du[j]) / sc[j]) ** 2
                err_d = 0.18 * math.sqrt(acc2 / n)
                factor_d = _factor(err_d, order)
                if err_d > 1.0:
                    ints[I_REJECTED] += 1
                    h = h_try * max(0.2, min(0.9, factor_d))
                    continue
                h_next = min(h_next, h_try * min(10.0, max(0.2, factor_d)))
            while out_i < n_outs and outs[out_i] < t_new:
                tt = outs[out_i]
                w = ints[I_WRITTEN]
                _interpolate(F, Y, (tt - t) / h_try, bY[w])
                bad = rhs(tt, bY[w], G0, parts, ddy, baux[w])
                if bad != 0:
                    fs[F_BAD_T] = tt
                    break
                bt[w] = tt
                for k in range(nr):
                    bG[w, k] = G0[k]
                ints[I_WRITTEN] = w + 1
                out_i += 1
            if bad != 0:
                status = bad if bad > -100 else FIELD
                ints[I_FIELD] = bad
                break
        # the new base G₁ = G₀ exp(ξ₁), re-orthonormalised: R ← R(3I − RᵀR)/2
        if nr:
            xi1 = np.empty((nr, 6))
            for k in range(nr):
                for i in range(6):
                    xi1[k, i] = Y1[6 * k + i]
            _compose_exp_into(G0, xi1, G1)
            for k in range(nr):
                for i in range(3):
                    for j in range(3):
                        R[i, j] = G1[k, i, j]
                for i in range(3):
                    for j in range(3):
                        RtR[i, j] = R[0, i] * R[0, j] + R[1, i] * R[1, j] + R[2, i] * R[2, j]
                for i in range(3):
                    for j in range(3):
                        q = 0.0
                        for m in range(3):
                            q += R[i, m] * ((3.0 if m == j else 0.0) - RtR[m, j])
                        G1[k, i, j] = 0.5 * q
            for i in range(6 * nr):
                Y1[i] = 0.0
            for k in range(nr):
                G0[k] = G1[k]
        # the next step's first stage: ξ̇ = V at ξ = 0, and the same accelerations
        for j in range(n):
            Y[j] = Y1[j]
        for i in range(6 * nr):
            f0[i] = Y[6 * nr + i]
        for k in range(nr):
            for i in range(6):
                f0[6 * nr + 6 * k + i] = aux1[parts[7][k] + i]
        x0 = 12 * nr
        for i in range(ne):
            f0[x0 + i] = Y[x0 + ne + i]
            f0[x0 + ne + i] = aux1[parts[8][i]]
        z_at = 5 * dims[2] + dims[4] + 1  # ż in the outputs of rhs
        for i in range(dims[6]):
            f0[x0 + 2 * ne + i] = aux1[z_at + i]
        for i in range(n_aux):
            aux[i] = aux1[i]
        if (not has_outs) or (out_i < n_outs and outs[out_i] == t_new):
            w = ints[I_WRITTEN]
            bt[w] = t_new
            for j in range(n):
                bY[w, j] = Y[j]
            for k in range(nr):
                bG[w, k] = G0[k]
            for i in range(n_aux):
                baux[w, i] = aux1[i]
            ints[I_WRITTEN] = w + 1
            if has_outs:
                out_i += 1
        t, h = t_new, h_next
        ints[I_STEPS] += 1
        steps_here += 1
        fs[F_T] = t
        fs[F_H] = h
        ints[I_OUT] = out_i
    fs[F_T] = t
    if status != UNDERFLOW:
        fs[F_H] = h
    ints[I_OUT] = out_i
    return status


# --------------------------------------------------------------- compiling, once per machine
#: Set to "0" to keep ``simulate`` from compiling the loop in a background process.
BACKGROUND_ENV = "GMUK_BACKGROUND_COMPILE"
#: A background compilation's lock older than this (s) is taken for a dead one's.
LOCK_STALE_S = 900.0
_ENTRIES = ("rhs", "initial_step", "advance")
_spawned = False
_ready = False  # the loop is compiled or loaded in this process (every program's types)
#: What ``simulate(compiled=None)`` does when the loop is not compiled yet: False (default)
#: take the Python loop and compile aside; True compile it first (campaign workers, whose
#: runs must not depend on when the compilation ends).
compile_on_first_use = False


def signatures(prog: Program) -> tuple[tuple[Any, ...], ...]:
    """The numba argument types of :func:`rhs`, :func:`initial_step` and :func:`advance` as
    the driver (gmuk.integrate._CompiledStepper) calls them for ``prog``."""
    from numba import typeof

    f, v = typeof(0.0), typeof(np.empty(1))
    i = typeof(np.empty(1, dtype=np.int64))
    G = typeof(np.empty((1, 4, 4)))
    parts, meth = typeof(prog.parts), typeof(prog.method)
    return (
        (f, v, G, parts, v, v),
        (f, v, G, v, f, f, f, typeof(1), parts, v, i),
        (parts, meth, v, i, v, G, v, v, v, typeof(True), v, typeof(np.empty((1, 1))),
         typeof(np.empty((1, 1, 4, 4))), typeof(np.empty((1, 1)))),
    )  # fmt: skip


def _reference_program() -> Program:
    """The program of a one point mass System: its argument types are every program's."""
    from gmuk.bodies import PointMass
    from gmuk.forces.gravity import PointMassGravity
    from gmuk.system import System

    system = System([PointMass("p", 1.0)], [], [PointMassGravity(1.0)])
    prog = program(system, DOP853())
    assert isinstance(prog, Program), prog
    return prog


def loaded(prog: Program | None = None) -> bool:
    """Whether the loop is compiled for ``prog``'s argument types (all programs share them)
    in this process, loading it from numba's cache when it is there; never compiles.

    This reads numba's dispatcher internals (its cache and overloads, numba 0.59–0.68);
    if they change, it answers False and the loop compiles on the next ``compile_loop``."""
    global _ready
    if _ready:
        return True
    from numba.core.compiler_lock import global_compiler_lock

    sigs = signatures(prog if prog is not None else _reference_program())
    try:
        with global_compiler_lock:
            for name, sig in zip(_ENTRIES, sigs, strict=True):
                disp = globals()[name]
                if tuple(sig) in disp.overloads:
                    continue
                cres = disp._cache.load_overload(sig, disp.targetctx)
                if cres is None:
                    return False
                disp.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
                disp.add_overload(cres)
    except (AttributeError, TypeError):  # numba's internals moved
        return False
    _ready = True
    return True


def _lock_path() -> Path:
    """The lock of a background compilation, one per numba cache folder of this module."""
    cache = getattr(getattr(advance, "_cache", None), "_cache_path", "") or "no-cache"
    key = hashlib.sha256(str(cache).encode()).hexdigest()[:16]
    return Path(tempfile.gettempdir()) / f"gmuk-compile-{key}.lock"


def _cacheable() -> bool:
    return type(getattr(advance, "_cache", None)).__name__ != "NullCache"


def compile_loop(*, background: bool = False, timeout: float = 600.0) -> bool:
    """Compile the step loop once for this machine, or load it from numba's cache.

    Parameters
    ----------
    background : bool
        Start the compilation in a separate process and return at once (False: compile here
        and return when done). Either way one process per cache folder compiles at a time
        (a lock file in the temporary folder); the others wait for it and load its result.
    timeout : float
        The longest to wait (s) for a compilation another process is running; after that,
        this one compiles too.

    Returns
    -------
    bool
        Whether the loop is ready in this process.
    """
    if loaded():
        return True
    if background:
        _spawn()
        return False
    lock = _lock_path()
    deadline = time.monotonic() + timeout
    owned = False
    while time.monotonic() < deadline:
        owned = _take(lock)
        if owned:
            break
        time.sleep(0.5)
        if loaded():
            return True
    try:
        _compile_now()
    finally:
        if owned:
            lock.unlink(missing_ok=True)
    return True


def _compile_now() -> None:
    # The force kernels call the field kernel's one compiled signature (read-only data):
    # resolving it first loads it (or compiles it once) and keeps the loop from compiling
    # a second copy for other argument types.
    _field_kernels.ENTRIES.acceleration_at  # noqa: B018
    for name, sig in zip(_ENTRIES, signatures(_reference_program()), strict=True):
        globals()[name].compile(sig)
    global _ready
    _ready = True


def _take(lock: Path) -> bool:
    """Create ``lock`` (True), or False while another process holds a live one."""
    if lock.exists() and not _lock_held(lock):
        lock.unlink(missing_ok=True)  # a stale one: its process died
    try:
        fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    except FileExistsError:
        return False
    except OSError:  # no temporary folder to write in: compile without a lock
        return True
    os.write(fd, str(os.getpid()).encode())
    os.close(fd)
    return True


@contextlib.contextmanager
def compiling_on_first_use() -> Iterator[None]:
    """Within: ``simulate(compiled=None)`` compiles the loop if it is not compiled yet
    instead of taking the Python loop (:data:`compile_on_first_use`)."""
    global compile_on_first_use
    before, compile_on_first_use = compile_on_first_use, True
    try:
        yield
    finally:
        compile_on_first_use = before


def _lock_held(lock: Path) -> bool:
    try:
        return time.time() - lock.stat().st_mtime < LOCK_STALE_S
    except OSError:
        return False


def _spawn() -> None:
    """Compile the loop in a detached background process, at most once per process and one
    process per cache folder at a time (a lock file), unless GMUK_BACKGROUND_COMPILE=0 or
    numba cannot cache (each process would compile again)."""
    global _spawned
    if _spawned or os.environ.get(BACKGROUND_ENV, "1") == "0" or not _cacheable():
        return
    _spawned = True
    lock = _lock_path()
    if not _take(lock):
        return  # another process is compiling
    try:
        subprocess.Popen(
            [sys.executable, "-m", "gmuk.integrators._compiled", str(lock)],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
            close_fds=True,
        )
    except OSError:
        lock.unlink(missing_ok=True)


def _main(argv: list[str]) -> int:
    """The background compilation: compile the loop (numba caches it), then drop the lock."""
    lock = Path(argv[0]) if argv else None
    try:
        with contextlib.suppress(OSError, AttributeError):
            os.nice(10)  # the user's own runs first
        if not loaded():
            _compile_now()
    finally:
        if lock is not None:
            lock.unlink(missing_ok=True)
    return 0


if __name__ == "__main__":  # run as a module: compile in the imported module, not __main__
    from gmuk.integrators import _compiled

    sys.exit(_compiled._main(sys.argv[1:]))
