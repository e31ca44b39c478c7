"""The compiled step loop: gmuk's one integrator loop, the RKMK method of
:mod:`gmuk.engine.integrate` run in machine code.

Every System runs here. The parts that have compiled forms run compiled: the built-in
gravity, uniform-gravity and linear spring–damper models (``ForceModel._compiled_term``,
unless a subclass overrides their methods), LVLH configuration tracking and relative
constraints on rigid bodies, the corrected Morse–Lyapunov law on an LVLH reference
(``Controller._compiled_term``), the free acceleration and the Udwadia–Kalaba solve of the
``"fused"``, ``"dense"`` and ``"tree"`` strategies (the tree solve's rows in blocks of each
constraint's one or two bodies, :func:`_constraint_blocks`). Everything else is called back
in Python from inside the loop through a C function (:class:`PythonParts`), and costs only
its own Python:

* force models, constraints and controllers without a compiled form (phases
  :data:`PHASE_LOADS` and :data:`PHASE_CONTROLS`);
* the whole acceleration, ``System._accelerations`` (:data:`PHASE_ACCELERATIONS`), for a
  System whose solve strategy has no compiled form (sparse, Eq. 80, a user's), for a System
  subclass with its own ``accelerations``, and for a state at which the compiled QR solve
  cannot certify its answer (rank-deficient or ill-conditioned rows): the strategy's own
  Python solve decides there, as it does in :meth:`System.accelerations`.

The method is read from the method object (:class:`MethodTable`): its tableau, its
step-size controller's constants and, for DOP853, its continuous extension and defect
control. A method that replaces the tableau's step with its own Python (``stages``,
``error_norm``, ``interpolant``) cannot run here; :func:`program` says so.

The loop sees no System: it runs a :class:`~gmuk.engine.integrators._program.Program`, the arrays
and the Python callback that a System builds from its parts' declarations
(:meth:`gmuk.System.compiled_program`, :mod:`gmuk.engine.integrators._program`).

The loop runs a chunk of steps and returns, so that Python can see stop requests, write
checkpoints and drain the output buffers between chunks. It is compiled once per machine,
in the foreground, announced on stderr (:func:`compile_loop`), and loaded from numba's cache
by later processes: the same inputs give the same bits whether the cache was cold or warm.
"""

from __future__ import annotations

import contextlib
import enum
import functools
import math
import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from gmuk._numba import borrowed, kernel_address, kernel_caller, njit
from gmuk.control.base import CONTROL_KERNEL
from gmuk.dynamics import rigid_free_accel_into
from gmuk.engine._uk_kernels import _qr_solve, uk_rigid
from gmuk.engine.integrators import _dop853_tableau as _tab
from gmuk.engine.integrators._program import (
    FUSED,
    PHASE_ACCELERATIONS,
    PHASE_CONTROLS,
    PHASE_LOADS,
    PYTHON,
    PYTHON_SOLVE,
    Program,
    reference_records,
)
from gmuk.engine.tree import (
    TREE,
    _tree_solve,
    body_rhs,
    constraint_block,
    kernel_rows,
    singular_at,
    tree_pair,
    tree_work_sizes,
)
from gmuk.forces.base import FORCE_KERNEL
from gmuk.lie._kernels import _compose_exp_into, _dexp_inv_apply_into

__all__ = ["Status", "advance", "compile_loop", "loaded"]


class Status(enum.IntEnum):
    """What :func:`advance` and :func:`rhs` return."""

    DONE = 0  #: reached the end time (rhs: evaluated)
    PAUSE = 1  #: ran its chunk of steps
    FULL = 2  #: the output buffers have no room for the next step's outputs
    NONFINITE = -1  #: a derivative or an output (aux) with NaN or inf
    UNDERFLOW = -2  #: step size underflow
    MAX_STEPS = -3  #: max_steps reached
    FIELD = -4  #: a compiled part's kernel failed (its status in ints[I_FIELD])
    CALLBACK = -5  #: a part evaluated in Python raised (PythonParts.error holds it)


# The statuses as plain ints for the kernels.
DONE, PAUSE, FULL = int(Status.DONE), int(Status.PAUSE), int(Status.FULL)
NONFINITE, UNDERFLOW = int(Status.NONFINITE), int(Status.UNDERFLOW)
MAX_STEPS, FIELD, CALLBACK = int(Status.MAX_STEPS), int(Status.FIELD), int(Status.CALLBACK)

# Entries of the integer and float state vectors shared between the loop and its driver.
I_OUT = 0  #: the next output time's index
I_STEPS = 1  #: accepted steps
I_REJECTED = 2  #: rejected steps
I_RHS = 3  #: right-hand side evaluations
I_WRITTEN = 4  #: rows written to the output buffers in this chunk
I_MAX_STEPS = 5  #: the step budget
I_CHUNK = 6  #: steps per chunk
I_FIELD = 7  #: a failed part kernel's status
I_NEED = 8  #: output rows the next step needs (status FULL)
I_STARTED = 9  #: 0 until the first evaluation at the start time is done
I_FRESH = 10  #: 1 for a run from its initial state, 0 for one resumed from a checkpoint
I_RHS_KERNEL = 11  #: the address of the compiled :func:`rhs` (:func:`rhs_address`)
N_INTS = 12
F_T = 0  #: time of the last accepted step (s)
F_H = 1  #: the next step size (s); 0 asks the loop for the starting step
F_END = 2  #: end time (s)
F_RTOL = 3
F_ATOL = 4
F_MAX_STEP = 5
F_FIRST_STEP = 6  #: the user's first step (s), 0 if none
F_BAD_T = 7  #: the time of a failed evaluation (s)
N_FLOATS = 8


# ------------------------------------------------------------------------ right-hand side
# The parts' kernels, called through the addresses in the program's tables (gmuk._numba).
_call_force = kernel_caller(FORCE_KERNEL, "force model")
_call_control = kernel_caller(CONTROL_KERNEL, "controller")


def _rhs_signature() -> Any:
    """:func:`rhs`'s signature: every program's records have the same types."""
    from numba import typeof

    v, ints, G = np.empty(1), np.empty(1, dtype=np.int64), np.empty((1, 4, 4))
    parts = reference_records()[0]
    return types.int64(*(typeof(x) for x in (0.0, v, G, parts, v, v, ints)))


#: The signature :func:`rhs` is compiled for, and the caller of that compiled function. A
#: step's stages call :func:`rhs` directly (a call through an address costs about 0.3 µs
#: more on a rigid body: its arguments go through memory); the rarer evaluations (the start,
#: the starting step, the continuous extension) call it through its address
#: (``ints[I_RHS_KERNEL]``), so that its code is not compiled again inside each of them.
RHS_SIGNATURE = _rhs_signature()
_call_rhs = kernel_caller(RHS_SIGNATURE, "right-hand side")


@intrinsic
def _call_back(typingctx, address, phase):  # type: ignore[no-untyped-def]
    """Call the C function ``int64 f(int64 phase)`` at ``address`` (a ctypes callback)."""

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        fnty = ir.FunctionType(ir.IntType(64), [ir.IntType(64)])
        return builder.call(builder.inttoptr(args[0], fnty.as_pointer()), [args[1]])

    return types.int64(types.int64, types.int64), codegen


#: The decorator of the loop's helpers, which only compiled code calls (rhs, advance and
#: each other): without the CPython and C wrappers that a call from Python or C would need,
#: which numba otherwise lowers, optimises and compiles to machine code for every function
#: (issue #24, the cold compile). Such a helper cannot be called from Python.
_helper = njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)


@_helper
def _write_state(t, g, V, Y, d, io):  # type: ignore[no-untyped-def]
    """The stage's state into ``io`` for the Python callback (PythonParts.state)."""
    nr = d.n_rigid
    io[0] = t
    for k in range(nr):
        for a in range(4):
            for e in range(4):
                io[1 + 16 * k + 4 * a + e] = g[k, a, e]
        for i in range(6):
            io[1 + 16 * nr + 6 * k + i] = V[k, i]
    for i in range(2 * d.n_euclid + d.n_control):  # x, ẋ, z
        io[1 + 22 * nr + i] = Y[12 * nr + i]


@_helper
def _python_accelerations(parts, aux):  # type: ignore[no-untyped-def]
    """The whole acceleration from Python (PHASE_ACCELERATIONS) into ``aux``; the state is
    in ``io`` already. Returns the status."""
    d = parts.dims
    if _call_back(d.callback, PHASE_ACCELERATIONS) != 0:
        return CALLBACK
    io = parts.io
    for i in range(aux.shape[0]):
        aux[i] = io[d.accel_at + i]
    return DONE


@njit(cache=True)
def rhs(t, Y, G0, parts, dY, aux, ints):  # type: ignore[no-untyped-def]
    """dY/dt at (t, Y) about the base poses G0 into ``dY``, and into ``aux`` the other outputs
    (:func:`aux_layout`: total acceleration, unmodeled generalized forces, constraint
    acceleration, constraint wrenches M ν̇_c, multipliers λ, the solve's residual, the
    controllers' generalized forces, their states' rates ż, the rank of A). Returns a
    :class:`Status`: DONE, NONFINITE, CALLBACK, or FIELD with the failed kernel's status in
    ``ints[I_FIELD]``.

    Allocates the evaluation's work arrays, one float64 and one int64
    (:func:`_work_sizes`), and holds them for :func:`_evaluate`."""
    parts = borrowed(parts)  # the caller holds it: the calls below count none of its arrays
    n_float, n_int = _work_sizes(parts)
    return _evaluate(
        t, Y, G0, parts, dY, aux, ints, np.empty(n_float), np.empty(n_int, dtype=np.int64)
    )


@_helper
def _work_sizes(parts):  # type: ignore[no-untyped-def]
    """The sizes of :func:`_evaluate`'s float64 and int64 work arrays: the poses, the loads,
    the rows, the free accelerations, the fused solve's outputs and the tree solve's work."""
    d = parts.dims
    nr, ndof, s = d.n_rigid, d.n_dof, d.n_rows
    tree_float, tree_int = 0, 0
    if s and d.solve == TREE:
        tree_float, tree_int = tree_work_sizes(parts.uk_params)
    n_float = (
        16 * nr + 2 * ndof + 6 + 31  # g, modeled, the body's rhs, w, a point mass's pose
        + s * (1 + max(12, ndof)) + 4 * ndof + s + 3  # b, A, the fused solve's out
        + 12 * nr + 12  # Q and the free accelerations, u and ż of a controller
        + tree_float
    )  # fmt: skip
    return n_float, tree_int


@_helper
def _evaluate(t, Y, G0, parts, dY, aux, ints, work, iwork):  # type: ignore[no-untyped-def]
    """:func:`rhs` with its work arrays, from which every array of the evaluation is a
    view."""
    d = parts.dims
    # borrowed references (gmuk._numba.borrowed): the caller holds the arguments for the
    # call, and the views taken of them below then count no references
    Y, G0, dY, aux, ints = borrowed(Y), borrowed(G0), borrowed(dY), borrowed(aux), borrowed(ints)
    work, iwork = borrowed(work), borrowed(iwork)
    terms, params = borrowed(parts.terms), borrowed(parts.params)
    fdata = borrowed(parts.field_data)
    J, Jinv = borrowed(parts.J), borrowed(parts.Jinv)
    m_r, m_e = borrowed(parts.m_rigid), borrowed(parts.m_euclid)
    r_off, e_off = borrowed(parts.rigid_offsets), borrowed(parts.euclid_offsets)
    io = borrowed(parts.io)
    cons, cparams, P = borrowed(parts.cons), borrowed(parts.cparams), borrowed(parts.uk_params)
    nr, ne, ndof, s, nc = d.n_rigid, d.n_euclid, d.n_dof, d.n_rows, d.n_control
    # the work arrays, in the order of _work_sizes
    g = work[: 16 * nr].reshape((nr, 4, 4))
    o = 16 * nr
    modeled = work[o : o + ndof]
    r_body = work[o + ndof : o + 2 * ndof]  # body_rhs where a mass block is singular
    w = work[o + 2 * ndof : o + 2 * ndof + 6]
    o += 2 * ndof + 6
    gp = work[o : o + 16].reshape((4, 4))
    vp = work[o + 16 : o + 22]
    no_inertia = work[o + 22 : o + 31].reshape((3, 3))
    o += 31
    b = work[o : o + s]
    o += s
    width = 12 if d.solve == TREE else ndof  # the tree's blocks, or the stacked rows
    A = work[o : o + s * width].reshape((s, width))
    o += s * max(12, ndof)
    out = work[o : o + 4 * ndof + s + 3]
    o += 4 * ndof + s + 3
    Q = work[o : o + 6 * nr].reshape((nr, 6))
    a_r = work[o + 6 * nr : o + 12 * nr].reshape((nr, 6))
    o += 12 * nr
    u = work[o : o + 6]
    zd = work[o + 6 : o + 12]
    tree_work = work[o + 12 :]
    total = aux[:ndof]
    # views of Y, not copies: nothing is allocated per evaluation that a view can replace
    xi = Y[: 6 * nr].reshape((nr, 6))
    V = Y[6 * nr : 12 * nr].reshape((nr, 6))
    any_xi = False
    for i in range(6 * nr):
        if Y[i] != 0.0:
            any_xi = True
            break
    if nr:
        _compose_exp_into(G0, xi, g)
    x0 = 12 * nr
    z_dot = aux[5 * ndof + s + 1 : 5 * ndof + s + 1 + nc]
    # the whole acceleration in Python (PHASE_ACCELERATIONS): a program without a compiled
    # solve, or a state whose rows the compiled QR solve cannot certify
    in_python = d.solve == PYTHON_SOLVE
    if in_python:
        _write_state(t, g, V, Y, d, io)
    else:
        # compiled force terms, then the parts in Python, the solve, the controllers and
        # the loads on the plant (in this function, not a helper inlined into it: numba's
        # inlining copies and retypes the helper's IR at each compilation)
        unmodeled = aux[ndof : 2 * ndof]
        for i in range(ndof):
            modeled[i] = 0.0
            unmodeled[i] = 0.0
        if d.point_terms:  # a point mass's pose and velocity, as its force kernels take them
            for i in range(16):
                gp[i // 4, i % 4] = 0.0
            for i in range(6):
                vp[i] = 0.0
            for i in range(9):
                no_inertia[i // 3, i % 3] = 0.0
        for f in range(terms.shape[0]):
            kernel, rig, idx, off = terms[f, 0], terms[f, 1], terms[f, 2], terms[f, 3]
            p0, f0, f1 = terms[f, 5], terms[f, 6], terms[f, 7]
            if rig:
                args = (True, t, g[idx], V[idx], m_r[idx], J[idx], params[p0:], fdata[f0:f1], w)
                status = _call_force(kernel, args)
                dof = 6
            else:
                for i in range(3):
                    gp[i, 3] = Y[x0 + idx + i]
                    vp[i] = Y[x0 + ne + idx + i]
                args = (False, t, gp, vp, m_e[idx], no_inertia, params[p0:], fdata[f0:f1], w)
                status = _call_force(kernel, args)
                dof = 3
            if status != 0:  # the failing state to io, where Python describes the failure
                ints[I_FIELD] = status
                _write_state(t, g, V, Y, d, io)
                return FIELD
            if terms[f, 4]:
                for i in range(dof):
                    modeled[off + i] += w[i]
            else:
                for i in range(dof):
                    unmodeled[off + i] += w[i]
        written = False
        if d.python_parts:  # the parts without a compiled form, in Python (PythonParts)
            _write_state(t, g, V, Y, d, io)
            written = True
            if _call_back(d.callback, PHASE_LOADS) != 0:
                return CALLBACK
            lo = d.loads_at
            for i in range(ndof):
                modeled[i] += io[lo + i]
                unmodeled[i] += io[lo + ndof + i]
        rank_at = 5 * ndof + s + 1 + nc
        if s:  # the stacked rows: (s, n_dof) for the fused or the dense solve, blocks (s, 12)
            for i in range(s):  # on each constraint's one or two bodies for the tree solve
                for e in range(A.shape[1]):
                    A[i, e] = 0.0
            if d.solve == TREE:
                status = _constraint_blocks(t, g, V, cons, cparams, io, r_off, P, A, b)
            else:
                status = _constraint_rows(t, g, V, cons, cparams, io, r_off, A, b)
            if status != 0:
                ints[I_FIELD] = status
                _write_state(t, g, V, Y, d, io)
                return FIELD
        if s and d.solve == FUSED:
            # rigid bodies only, every load seen by the solve: one compiled call
            uk_rigid(V, modeled, A, b, P, out)
            if out[4 * ndof + s + 2] != 0.0:  # not certified: the Python solve decides
                if not written:
                    _write_state(t, g, V, Y, d, io)
                in_python = True
            else:
                for i in range(ndof):
                    total[i] = out[2 * ndof + i]
                    aux[2 * ndof + i] = out[ndof + i]
                    aux[3 * ndof + i] = out[3 * ndof + i]
                for i in range(s):
                    aux[4 * ndof + i] = out[4 * ndof + i]
                aux[4 * ndof + s] = out[4 * ndof + s]
                aux[rank_at] = s
        else:
            # ν̇_a = M⁻¹(ad*_V 𝕀V + Q): Eq. 10b for rigid bodies, Q/m for point masses
            if nr:
                for k in range(nr):
                    for i in range(6):
                        Q[k, i] = modeled[r_off[k] + i]
                rigid_free_accel_into(V, J, Jinv, m_r, Q, a_r)
                for k in range(nr):
                    for i in range(6):
                        total[r_off[k] + i] = a_r[k, i]
            for i in range(ne):
                total[e_off[i]] = modeled[e_off[i]] / m_e[i]
            for i in range(2 * ndof, 4 * ndof + s + 1):
                aux[i] = 0.0
            aux[rank_at] = d.free_rank
            if s:  # the dense strategy's certified QR solve (DenseSolver.solve_rows), or
                # the tree strategy's certified block LDLᵀ (TreeSolver.solve)
                ac = aux[2 * ndof : 3 * ndof]
                singular = False
                if d.solve == TREE:
                    singular = P[singular_at(P)] != 0.0
                    if singular:  # bodies with a singular mass block
                        body_rhs(V, modeled, total, P, r_body)
                    residual, scale, status = _tree_solve(
                        g,
                        total,
                        r_body,
                        A,
                        b,
                        P,
                        ac,
                        aux[4 * ndof : 4 * ndof + s],
                        tree_work,
                        iwork,
                    )
                else:
                    Minv_sqrt = P[2 : 2 + ndof * ndof].reshape((ndof, ndof))
                    residual, scale, status = _qr_solve(
                        A, b, total, Minv_sqrt, P[0], ac, aux[4 * ndof : 4 * ndof + s]
                    )
                if status != 0 or residual > P[1] * scale:  # the Python solve decides
                    if not written:
                        _write_state(t, g, V, Y, d, io)
                    in_python = True
                else:
                    aux[4 * ndof + s] = residual
                    aux[rank_at] = s
                    _apply_M(ac, J, m_r, m_e, r_off, e_off, aux[3 * ndof : 4 * ndof])
                    if singular:  # Aᵀλ = M ν̇_c − r
                        for i in range(ndof):
                            aux[3 * ndof + i] -= r_body[i]
                    for i in range(ndof):
                        total[i] += ac[i]
        if not in_python:  # the controllers and the loads on the plant
            control = aux[4 * ndof + s + 1 : 5 * ndof + s + 1]
            for i in range(ndof):
                control[i] = 0.0
            ca = d.controls_at
            if ca:  # the controllers in Python, given the modeled acceleration ν̇_a + ν̇_c
                for i in range(ndof):
                    io[ca + i] = total[i]
                if _call_back(d.callback, PHASE_CONTROLS) != 0:
                    return CALLBACK
                for i in range(ndof):
                    control[i] = io[ca + ndof + i]
                for i in range(nc):
                    z_dot[i] = io[ca + 2 * ndof + i]
            ctrls, ctrl_params = parts.ctrls, parts.ctrl_params
            if ctrls.shape[0]:  # the compiled controllers (their kernels' addresses in ctrls)
                zs = x0 + 2 * ne
                for c in range(ctrls.shape[0]):
                    kernel, k, o = ctrls[c, 0], ctrls[c, 1], ctrls[c, 2]
                    z0, p0 = ctrls[c, 3], ctrls[c, 4]
                    z = Y[zs + z0 : zs + z0 + 6]
                    args = (t, g[k], V[k], total[o : o + 6], z, ctrl_params[p0:], u, zd)
                    status = _call_control(kernel, args)
                    if status != 0:
                        ints[I_FIELD] = status
                        _write_state(t, g, V, Y, d, io)
                        return FIELD
                    for i in range(6):
                        control[o + i] += u[i]
                        z_dot[z0 + i] = zd[i]
            if d.plant_only:  # unmodeled loads and controls act on the plant: + M⁻¹ (Q_u + u)
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
    if in_python:
        status = _python_accelerations(parts, aux)
        if status != DONE:
            return status
    # dY = [dexp⁻¹(ξ) V, V̇, ẋ, ẍ, ż]
    if nr:
        if any_xi:
            _dexp_inv_apply_into(xi, V, dY[: 6 * nr].reshape((nr, 6)))
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
    # every entry finite, the outputs too (forces, multipliers, the residual): x − x is 0
    # for a finite x and NaN otherwise, so that the test needs no branch per entry
    not_finite = False
    for i in range(dY.shape[0]):
        not_finite |= dY[i] - dY[i] != 0.0
    for i in range(aux.shape[0]):
        not_finite |= aux[i] - aux[i] != 0.0
    return NONFINITE if not_finite else DONE


@_helper
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


@_helper
def _constraint_rows(t, g, V, cons, cparams, io, r_off, A, b):  # type: ignore[no-untyped-def]
    """The stacked rows (A, b) of the constraints, as their ``rows`` give them: computed by
    their kernels (through the addresses in ``cons``; a rigid body's columns start at its offset in
    ν, ``r_off``), or copied from ``io`` where PythonParts wrote them. Returns 0 or the
    status of a failed kernel."""
    ndof = A.shape[1]
    for c in range(cons.shape[0]):
        kind, i, j, r0, nrow, p0 = (
            cons[c, 0],
            cons[c, 1],
            cons[c, 2],
            cons[c, 3],
            cons[c, 4],
            cons[c, 5],
        )
        if kind == PYTHON:  # A (nrow, n_dof) then b (nrow) at io[p0:]
            for a in range(nrow):
                for e in range(ndof):
                    A[r0 + a, e] = io[p0 + a * ndof + e]
                b[r0 + a] = io[p0 + nrow * ndof + a]
            continue
        Ak = np.empty((nrow, 12))
        bk = np.empty(nrow)
        status = kernel_rows(t, g, V, cons, cparams, c, Ak, bk)
        if status != 0:
            return status
        for a in range(nrow):
            b[r0 + a] = bk[a]
            for e in range(6):
                A[r0 + a, r_off[i] + e] = Ak[a, e]
            if j >= 0:
                for e in range(6):
                    A[r0 + a, r_off[j] + e] = Ak[a, 6 + e]
    return 0


@_helper
def _constraint_blocks(t, g, V, cons, cparams, io, r_off, P, A, b):  # type: ignore[no-untyped-def]
    """The rows of the tree solve (:func:`gmuk.engine.tree.tree_solve`): each constraint's
    rows on its first body (columns 0–5 of A (s, 12)) and its second (6–11), computed by its
    kernel or copied from the dense rows PythonParts wrote into ``io`` (the bodies from the
    packed tree ``P``). Returns 0 or the status of a failed kernel."""
    g, V, cparams, io, A, b = (
        borrowed(g),
        borrowed(V),
        borrowed(cparams),
        borrowed(io),
        borrowed(A),
        borrowed(b),
    )
    ndof = 6 * r_off.shape[0]  # rigid bodies only
    for c in range(cons.shape[0]):
        kind, r0, nrow, p0 = cons[c, 0], cons[c, 3], cons[c, 4], cons[c, 5]
        if kind == PYTHON:  # A (nrow, n_dof) then b (nrow) at io[p0:]
            ia, ib = tree_pair(P, c)
            for a in range(nrow):
                for e in range(6):
                    A[r0 + a, e] = io[p0 + a * ndof + r_off[ia] + e]
                    if ib >= 0:
                        A[r0 + a, 6 + e] = io[p0 + a * ndof + r_off[ib] + e]
                b[r0 + a] = io[p0 + nrow * ndof + a]
            continue
        status = constraint_block(t, g, V, cons, cparams, c, A, b)
        if status != 0:
            return status
    return 0


@_helper
def _scale(Y0, Y1, G0, nr, pts, rtol, atol, sc):  # type: ignore[no-untyped-def]
    """The error weights of :meth:`gmuk.engine.integrate._Problem.scale` (``pts``: where the point
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


@_helper
def _rms(v, sc):  # type: ignore[no-untyped-def]
    acc = 0.0
    for i in range(v.shape[0]):
        acc += (v[i] / sc[i]) ** 2
    return math.sqrt(acc / v.shape[0])


@_helper
def _interpolate(F, Y0, s, out):  # type: ignore[no-untyped-def]
    """DOP853's continuous extension u(s) into ``out`` (gmuk.engine.integrators.dop853)."""
    n = Y0.shape[0]
    p = F.shape[0]
    acc = np.zeros(n)
    for i in range(p):
        fac = s if i % 2 == 0 else 1.0 - s
        for j in range(n):
            acc[j] = (acc[j] + F[p - 1 - i, j]) * fac
    for j in range(n):
        out[j] = Y0[j] + acc[j]


@_helper
def _stage_state(Y, h, a, K, i, out):  # type: ignore[no-untyped-def]
    """out = Y + h Σ_{m<i} a_m K_m: the state at which stage i is evaluated (the sum over m
    in the outer loop, so that the inner one runs along K's rows; the same additions, in the
    same order, for each entry)."""
    n = Y.shape[0]
    for j in range(n):
        out[j] = 0.0
    for m in range(i):
        am = a[m]
        for j in range(n):
            out[j] += am * K[m, j]
    for j in range(n):
        out[j] = Y[j] + h * out[j]


@_helper
def _factor(err, m):  # type: ignore[no-untyped-def]
    """The step-size factor for a scaled error estimate (1: at tolerance): the classical
    ``safety · err^(−1/order)``, err floored so that a zero estimate grows the step by the
    largest factor."""
    return m.safety * (max(err, m.error_floor) ** (-1.0 / m.order))


@_helper
def _grown(h, err, m):  # type: ignore[no-untyped-def]
    """The next step after an accepted one of size h."""
    return h * min(m.max_factor, max(m.min_factor, _factor(err, m)))


@_helper
def _shrunk(h, err, m):  # type: ignore[no-untyped-def]
    """The retry after a rejected step of size h."""
    return h * max(m.min_factor, min(m.max_factor_rejected, _factor(err, m)))


@_helper
def _fail(status, t, fs, ints):  # type: ignore[no-untyped-def]
    """Record a failed evaluation at time t; returns the status to report."""
    fs[F_BAD_T] = t
    return status


@_helper
def _initial_step(t, Y, G0, f0, parts, m, fs, ints):  # type: ignore[no-untyped-def]
    """Hairer's starting step (Hairer, Nørsett & Wanner, Solving ODEs I, §II.4), or the
    user's first step. Returns the step, or −(status) after a failed evaluation."""
    t_end = fs[F_END]
    if fs[F_FIRST_STEP] > 0.0:
        return min(fs[F_FIRST_STEP], t_end - t)
    d = parts.dims
    n = Y.shape[0]
    sc = np.empty(n)
    _scale(Y, Y, G0, d.n_rigid, parts.point_starts, fs[F_RTOL], fs[F_ATOL], sc)
    d0 = _rms(Y, sc)
    d1 = _rms(f0, sc)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, t_end - t)
    Yt = np.empty(n)
    for i in range(n):
        Yt[i] = Y[i] + h0 * f0[i]
    f1 = np.empty(n)
    aux = np.empty(aux_size_of(d))
    ints[I_RHS] += 1
    status = _call_rhs(ints[I_RHS_KERNEL], (t + h0, Yt, G0, parts, f1, aux, ints))
    if status != DONE:
        _fail(status, t + h0, fs, ints)
        return float(status)
    acc = 0.0
    for i in range(n):
        acc += ((f1[i] - f0[i]) / sc[i]) ** 2
    d2 = math.sqrt(acc / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (m.order + 1))
    return min(100 * h0, h1, fs[F_MAX_STEP], t_end - t)


@_helper
def aux_size_of(d):  # type: ignore[no-untyped-def]
    """:func:`aux_size` of a program's dims."""
    return 5 * d.n_dof + d.n_rows + 2 + d.n_control


@_helper
def _record(t, Y, G0, aux, ints, bt, bY, bG, baux):  # type: ignore[no-untyped-def]
    """Append one output row (t, Y, G0, aux) to the buffers."""
    w = ints[I_WRITTEN]
    bt[w] = t
    for j in range(Y.shape[0]):
        bY[w, j] = Y[j]
    for k in range(G0.shape[0]):
        for a in range(4):
            for e in range(4):
                bG[w, k, a, e] = G0[k, a, e]
    for i in range(aux.shape[0]):
        baux[w, i] = aux[i]
    ints[I_WRITTEN] = w + 1


@_helper
def _start(parts, m, fs, ints, Y, G0, f0, aux, outs, has_outs, bt, bY, bG, baux):  # type: ignore[no-untyped-def]
    """The first evaluation at the start time: f0 and aux, the output at the start time of
    a fresh run, and the starting step when none is set. Returns the status."""
    t = fs[F_T]
    ints[I_RHS] += 1
    status = _call_rhs(ints[I_RHS_KERNEL], (t, Y, G0, parts, f0, aux, ints))
    if status != DONE:
        return _fail(status, t, fs, ints)
    ints[I_STARTED] = 1
    if ints[I_FRESH]:
        if (not has_outs) or outs[0] == t:
            _record(t, Y, G0, aux, ints, bt, bY, bG, baux)
            if has_outs:
                ints[I_OUT] = 1
        if m.adaptive and fs[F_H] <= 0.0:
            h = _initial_step(t, Y, G0, f0, parts, m, fs, ints)
            if h <= 0.0:
                return int(h)
            fs[F_H] = h
    return DONE


@_helper
def _step_error(K, Y, Y1, G0, h, parts, m, fs, sc):  # type: ignore[no-untyped-def]
    """The scaled error of a step (≤ 1: within tolerance), its weights into ``sc``."""
    n = Y.shape[0]
    _scale(Y, Y1, G0, parts.dims.n_rigid, parts.point_starts, fs[F_RTOL], fs[F_ATOL], sc)
    if m.dop853:  # Hairer's combination of the order-5 and order-3 estimates
        n5 = 0.0
        n3 = 0.0
        for j in range(n):
            e5 = 0.0
            e3 = 0.0
            for i in range(m.n_rows):
                e5 += K[i, j] * m.E[i]
                e3 += K[i, j] * m.E3[i]
            n5 += (e5 / sc[j]) ** 2
            n3 += (e3 / sc[j]) ** 2
        if n5 == 0.0 and n3 == 0.0:
            return 0.0
        return abs(h) * n5 / math.sqrt((n5 + m.e3_weight * n3) * n)
    acc2 = 0.0
    for j in range(n):
        e = 0.0
        for i in range(m.n_rows):
            e += K[i, j] * m.E[i]
        acc2 += (h * e / sc[j]) ** 2
    return math.sqrt(acc2 / n)


@_helper
def _extension(t, h, Y, Y1, K, G0, parts, m, fs, ints, F):  # type: ignore[no-untyped-def]
    """DOP853's continuous extension on [t, t + h] into F (three more stages). Returns the
    status."""
    n = Y.shape[0]
    n_ext = m.A_ext.shape[0]
    Kx = np.empty((n_ext, n))
    Yt = np.empty(n)
    tmp_aux = np.empty(aux_size_of(parts.dims))
    first = m.n_stages + 1
    for i in range(first):
        for j in range(n):
            Kx[i, j] = K[i, j]
    for i in range(first, n_ext):
        _stage_state(Y, h, m.A_ext[i], Kx, i, Yt)
        ints[I_RHS] += 1
        status = _call_rhs(
            ints[I_RHS_KERNEL], (t + m.c_ext[i] * h, Yt, G0, parts, Kx[i], tmp_aux, ints)
        )
        if status != DONE:
            return _fail(status, t + m.c_ext[i] * h, fs, ints)
    last = m.n_stages
    for j in range(n):
        dy = Y1[j] - Y[j]
        F[0, j] = dy
        F[1, j] = h * K[0, j] - dy
        F[2, j] = 2.0 * dy - h * (K[last, j] + K[0, j])
    for r in range(m.D.shape[0]):
        for j in range(n):
            q = 0.0
            for k in range(n_ext):
                q += m.D[r, k] * Kx[k, j]
            F[3 + r, j] = h * q
    return DONE


@_helper
def _extension_error(t, h, Y, F, G0, parts, m, fs, ints, sc):  # type: ignore[no-untyped-def]
    """The continuous extension's error from its defect at s* (DOP853.interpolant_error):
    returns (scaled error, status)."""
    n = Y.shape[0]
    s_star = m.defect_node
    p = F.shape[0]
    u = np.zeros(n)
    du = np.zeros(n)
    for i in range(p):
        for j in range(n):
            qq = u[j] + F[p - 1 - i, j]
            if i % 2 == 0:
                u[j], du[j] = qq * s_star, du[j] * s_star + qq
            else:
                u[j], du[j] = qq * (1.0 - s_star), du[j] * (1.0 - s_star) - qq
    for j in range(n):
        u[j] += Y[j]
    ddy = np.empty(n)
    tmp_aux = np.empty(aux_size_of(parts.dims))
    ints[I_RHS] += 1
    status = _call_rhs(ints[I_RHS_KERNEL], (t + s_star * h, u, G0, parts, ddy, tmp_aux, ints))
    if status != DONE:
        return 0.0, _fail(status, t + s_star * h, fs, ints)
    acc2 = 0.0
    for j in range(n):
        acc2 += ((h * ddy[j] - du[j]) / sc[j]) ** 2
    return m.defect_gain * math.sqrt(acc2 / n), DONE


@_helper
def _new_base(Y1, G0, nr):  # type: ignore[no-untyped-def]
    """G₀ ← G₀ exp(ξ₁), re-orthonormalised by one Newton–Schulz step R ← R(3I − RᵀR)/2, and
    ξ₁ ← 0 (in place)."""
    if nr == 0:
        return
    xi1 = np.empty((nr, 6))
    for k in range(nr):
        for i in range(6):
            xi1[k, i] = Y1[6 * k + i]
    G1 = np.empty((nr, 4, 4))
    _compose_exp_into(G0, xi1, G1)
    R = np.empty((3, 3))
    RtR = np.empty((3, 3))
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
                for a in range(3):
                    q += R[i, a] * ((3.0 if a == j else 0.0) - RtR[a, j])
                G1[k, i, j] = 0.5 * q
    for i in range(6 * nr):
        Y1[i] = 0.0
    for k in range(nr):
        for a in range(4):
            for e in range(4):
                G0[k, a, e] = G1[k, a, e]


@_helper
def _first_stage(Y, aux, parts, f0):  # type: ignore[no-untyped-def]
    """The next step's first stage at the new base: ξ̇ = V at ξ = 0, and the accelerations
    of the step end's evaluation (aux)."""
    d = parts.dims
    nr, ne = d.n_rigid, d.n_euclid
    for i in range(6 * nr):
        f0[i] = Y[6 * nr + i]
    for k in range(nr):
        for i in range(6):
            f0[6 * nr + 6 * k + i] = aux[parts.rigid_offsets[k] + i]
    x0 = 12 * nr
    for i in range(ne):
        f0[x0 + i] = Y[x0 + ne + i]
        f0[x0 + ne + i] = aux[parts.euclid_offsets[i]]
    z_at = 5 * d.n_dof + d.n_rows + 1  # ż in the outputs of rhs
    for i in range(d.n_control):
        f0[x0 + 2 * ne + i] = aux[z_at + i]


@njit(cache=True)
def advance(parts, m, fs, ints, Y, G0, f0, aux, outs, has_outs, bt, bY, bG, baux):  # type: ignore[no-untyped-def]
    """Run steps from (fs[F_T], Y, G0) until the end time, ``ints[I_CHUNK]`` steps, full
    output buffers or a failure; returns the :class:`Status`.

    The first call (``ints[I_STARTED]`` 0) evaluates f0 and aux at the start and, for a fresh
    run, records the output at the start time and takes the starting step. Y, G0, f0 (f at
    the last accepted step), aux (its other outputs), fs and ints are updated in place to
    the last accepted step; outputs are appended to the buffers (times bt, states bY, base
    poses bG, rhs outputs baux) from ints[I_WRITTEN]."""
    # borrowed references (gmuk._numba.borrowed): the caller holds the arguments, and each
    # call below would otherwise count every array of the records on entry and on exit
    parts, m = borrowed(parts), borrowed(m)
    if ints[I_STARTED] == 0:
        status = _start(parts, m, fs, ints, Y, G0, f0, aux, outs, has_outs, bt, bY, bG, baux)
        if status != DONE:
            return status
    nr = parts.dims.n_rigid
    n = Y.shape[0]
    t, h, t_end = fs[F_T], fs[F_H], fs[F_END]
    out_i = ints[I_OUT]
    n_outs = outs.shape[0]
    use_dense = m.dense and has_outs
    step_to_outputs = (not m.dense) and has_outs
    eps = np.finfo(np.float64).eps
    K = np.empty((m.n_rows, n))
    F = np.empty((_tab.INTERPOLATOR_POWER, n))
    Yt = np.empty(n)
    Y1 = np.empty(n)
    sc = np.empty(n)
    aux1 = np.empty(aux.shape[0])
    steps_here = 0
    status = DONE
    while t < t_end:
        if ints[I_STEPS] >= ints[I_MAX_STEPS]:
            status = MAX_STEPS
            break
        if steps_here >= ints[I_CHUNK]:
            status = PAUSE
            break
        h = min(h, fs[F_MAX_STEP])
        t_target = min(t_end, outs[out_i]) if step_to_outputs and out_i < n_outs else t_end
        # land exactly on the target when within a hair of it (no sliver steps)
        landing = t_target - t <= h * (1.0 + 1e-6)
        h_try = t_target - t if landing else h
        if h_try <= 10 * eps * max(1.0, abs(t)):
            status = UNDERFLOW
            fs[F_H] = h_try
            break
        need = 1  # room for this step's outputs
        j = out_i
        while use_dense and j < n_outs and outs[j] <= t + h_try:
            need += 1
            j += 1
        if ints[I_WRITTEN] + need > bt.shape[0]:
            ints[I_NEED] = need
            status = FULL
            break
        for j in range(n):
            K[0, j] = f0[j]
        for i in range(1, m.n_stages):
            _stage_state(Y, h_try, m.A[i], K, i, Yt)
            ints[I_RHS] += 1
            status = rhs(t + m.c[i] * h_try, Yt, G0, parts, K[i], aux1, ints)
            if status != DONE:
                status = _fail(status, t + m.c[i] * h_try, fs, ints)
                break
        if status != DONE:
            break
        _stage_state(Y, h_try, m.b, K, m.n_stages, Y1)
        ints[I_RHS] += 1
        status = rhs(t + h_try, Y1, G0, parts, Yt, aux1, ints)  # Yt: f(t + h, y₁)
        if status != DONE:
            status = _fail(status, t + h_try, fs, ints)
            break
        if m.fsal:
            for j in range(n):
                K[m.n_rows - 1, j] = Yt[j]
        h_next = h
        if m.adaptive:
            err = _step_error(K, Y, Y1, G0, h_try, parts, m, fs, sc)
            if err > 1.0:
                ints[I_REJECTED] += 1
                h = _shrunk(h_try, err, m)
                continue
            h_next = _grown(h_try, err, m)
        t_new = t_target if landing else t + h_try
        if use_dense and out_i < n_outs and outs[out_i] < t_new:
            status = _extension(t, h_try, Y, Y1, K, G0, parts, m, fs, ints, F)
            if status != DONE:
                break
            if m.adaptive:  # the extension must meet the tolerance too, or a shorter retry
                err_d, status = _extension_error(t, h_try, Y, F, G0, parts, m, fs, ints, sc)
                if status != DONE:
                    break
                if err_d > 1.0:
                    ints[I_REJECTED] += 1
                    h = _shrunk(h_try, err_d, m)
                    continue
                h_next = min(h_next, _grown(h_try, err_d, m))
            while out_i < n_outs and outs[out_i] < t_new:
                tt = outs[out_i]
                w = ints[I_WRITTEN]
                _interpolate(F, Y, (tt - t) / h_try, bY[w])
                status = _call_rhs(ints[I_RHS_KERNEL], (tt, bY[w], G0, parts, Yt, baux[w], ints))
                if status != DONE:
                    status = _fail(status, tt, fs, ints)
                    break
                _record(tt, bY[w], G0, baux[w], ints, bt, bY, bG, baux)
                out_i += 1
            if status != DONE:
                break
        _new_base(Y1, G0, nr)
        for j in range(n):
            Y[j] = Y1[j]
        _first_stage(Y, aux1, parts, f0)
        for i in range(aux.shape[0]):
            aux[i] = aux1[i]
        if (not has_outs) or (out_i < n_outs and outs[out_i] == t_new):
            _record(t_new, Y, G0, aux, ints, bt, bY, bG, baux)
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
#: What a cold compilation of the loop takes on a 2-core machine (s), as announced.
EXPECTED_COMPILE_S = "20-40 s"
_ready = False  # the loop is compiled or loaded in this process (every program's types)


def signature(prog: Program | None = None) -> tuple[Any, ...]:
    """The numba argument types of :func:`advance` as the driver calls it: every program has
    the same types (:func:`gmuk.engine.integrators._program.reference_records` stands for all)."""
    from numba import typeof

    parts, method = (prog.parts, prog.method) if prog is not None else reference_records()
    v = typeof(np.empty(1))
    i = typeof(np.empty(1, dtype=np.int64))
    G = typeof(np.empty((1, 4, 4)))
    return (
        typeof(parts), typeof(method), v, i, v, G, v, v, v, typeof(True), v,
        typeof(np.empty((1, 1))), typeof(np.empty((1, 1, 4, 4))), typeof(np.empty((1, 1))),
    )  # fmt: skip


def loaded(prog: Program | None = None) -> bool:
    """Whether the loop (:func:`rhs` and :func:`advance`) is compiled in this process, loading
    it from numba's cache when it is there; never compiles.

    This reads numba's dispatcher internals (its cache and overloads, numba 0.59–0.68);
    if they change, it answers False and the loop compiles on the next ``compile_loop``."""
    global _ready
    if not _ready:
        _ready = _load(rhs, RHS_SIGNATURE) and _load(advance, signature(prog))
    return _ready


def _load(kernel: Any, sig: Any) -> bool:
    """Whether ``kernel`` has its overload for ``sig`` in this process, loading it from numba's
    cache if it is there (never compiling). ``sig`` is what the kernel was compiled with (a
    signature or a tuple of argument types): numba's cache index is keyed by it."""
    from numba.core.compiler_lock import global_compiler_lock

    args = tuple(getattr(sig, "args", sig))
    try:
        with global_compiler_lock:
            if args not in kernel.overloads:
                cres = kernel._cache.load_overload(sig, kernel.targetctx)
                if cres is None:
                    return False
                kernel.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
                kernel.add_overload(cres)
    except (AttributeError, TypeError):  # numba's internals moved
        return False
    return True


def compile_loop(*, announce: bool = True, timeout: float = 900.0) -> bool:
    """Compile the step loop once for this machine, or load it from numba's cache.

    Compiling takes 20–40 s on a 2-core machine (once; later processes load the loop in a
    fraction of a second). With ``announce`` it says so on stderr, in one line, before it
    starts. One process compiles at a time per cache folder: the others wait on a lock (an
    advisory lock that the operating system releases when its process ends, killed or
    not) and then load what it compiled.

    Parameters
    ----------
    announce : bool
        Write one line to stderr when the loop has to be compiled (default True).
    timeout : float
        The longest to wait (s) for another process's compilation; after that this one
        compiles too.

    Returns
    -------
    bool
        True: the loop is ready in this process.
    """
    if loaded():
        return True
    start = time.perf_counter()
    with _compile_lock(timeout, announce) as waited:
        if waited and loaded():  # the other process compiled it
            return True
        if announce:
            print(
                f"gmuk: compiling the integrator loop for this machine, once "
                f"(about {EXPECTED_COMPILE_S}; `gmuk compile` does it ahead) ...",
                end="",
                file=sys.stderr,
                flush=True,
            )
        _compile_now()
        if announce:
            print(f" done in {time.perf_counter() - start:.1f} s", file=sys.stderr, flush=True)
    return True


def _compile_now() -> None:
    rhs_address()
    advance.compile(signature())
    global _ready
    _ready = True


@functools.cache
def rhs_address() -> int:
    """The address of :func:`rhs` compiled for :data:`RHS_SIGNATURE` (compiled, or loaded from
    numba's cache, once per process): what the driver puts in ``ints[I_RHS_KERNEL]``."""
    return kernel_address(rhs, RHS_SIGNATURE)


def _lock_path() -> Path:
    """The lock file beside the loop's numba cache (the temporary folder without one)."""
    import tempfile

    cache = getattr(getattr(advance, "_cache", None), "_cache_path", "") or ""
    folder = Path(cache) if cache else Path(tempfile.gettempdir())
    return folder / "gmuk-compile.lock"


@contextlib.contextmanager
def _compile_lock(timeout: float, announce: bool) -> Iterator[bool]:
    """Hold the compile lock inside (yields whether another process held it first).

    An advisory ``flock`` on a file beside the cache: it belongs to a live process only, so
    a compiler that was killed blocks nobody. Without ``fcntl`` (Windows) or a writable
    folder there is no lock, and concurrent processes may each compile."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield False
        return
    try:
        path = _lock_path()
        path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o644)
    except OSError:
        yield False
        return
    waited = False
    deadline = time.monotonic() + timeout
    try:
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if not waited and announce:
                    print(
                        "gmuk: waiting for another process that compiles the integrator loop",
                        file=sys.stderr,
                        flush=True,
                    )
                waited = True
                if time.monotonic() > deadline:
                    break  # compile without the lock
                time.sleep(0.2)
        yield waited
    finally:
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)
