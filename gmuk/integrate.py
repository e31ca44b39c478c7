"""Lie-group integrators: Runge–Kutta–Munthe-Kaas (RKMK) on SE(3)ⁿ × Rᵏ.

Each step starts from poses G₀ and integrates, with an explicit Runge–Kutta method, the
local problem in exponential coordinates ξ (one 6-vector per rigid body, ξ(0) = 0):

``g = G₀ exp(ξ^)``, ``ξ̇ = dexp⁻¹(ξ) V`` (McCann 2020, Eq. 20), ``V̇ = ν̇(g, V, t)``,

together with the Euclidean coordinates (point masses, slack coordinates) and controller
states. The step ends with ``G₁ = G₀ exp(ξ₁^)``, so poses stay on SE(3) by construction;
one Newton–Schulz iteration ``R ← R (3I − RᵀR)/2`` per step removes round-off drift, keeping
‖RᵀR − I‖ at the 1e-16 level over any number of steps.

The Runge–Kutta method is an object (:mod:`gmuk.integrators`):
:class:`~gmuk.integrators.DOP853` (default; Dormand–Prince 8(5,3), adaptive, with a continuous
extension of order 7 for output times whose error is controlled too),
:class:`~gmuk.integrators.DOPRI5` (Dormand–Prince 5(4), adaptive, stepping exactly onto output
times) and :class:`~gmuk.integrators.RK4` (classical, fixed step). :func:`simulate` accepts a
registered name (case-insensitive), a :class:`~gmuk.integrators.RungeKuttaMethod` subclass or
an instance; a subclass with a ``name`` registers itself.

Error weights follow one rule for the whole state: every 3-vector is weighed by its
Euclidean norm, every scalar by its absolute value, each taking the larger of its values at
both ends of the step, ``w = atol + rtol · max(‖u(t₀)‖, ‖u(t₁)‖)`` on each component of u.
The 3-vectors are a rigid body's ω and v (twist, body frame), a point mass's position r_N and
velocity v_N, and the two halves of ξ: its rotation part is weighed against 1 rad
(``w = atol + rtol``) and its translation part against the distance ‖r‖ of the step's base
pose. Slack coordinates and controller states are scalars. No weight depends on how the
inertial or body axes are chosen. The step error is the RMS of (error / w) over all entries
(DOP853: Hairer's combination of its order-5 and order-3 estimates in that norm).

References
----------
Munthe-Kaas, "High order Runge–Kutta methods on manifolds", Appl. Numer. Math. 29 (1999).
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk import runs
from gmuk._validation import FloatArray, real_number
from gmuk.errors import DefinitionError, GmukError, GmukWarning, SimulationError

# The method classes and the registry, re-exported here for convenience.
from gmuk.integrators import DOP853 as DOP853
from gmuk.integrators import DOPRI5 as DOPRI5
from gmuk.integrators import METHODS as METHODS
from gmuk.integrators import RK4 as RK4
from gmuk.integrators import RungeKuttaMethod as RungeKuttaMethod
from gmuk.integrators import _compiled
from gmuk.integrators import get_method as get_method
from gmuk.integrators import method_names as method_names
from gmuk.integrators._base import label
from gmuk.lie import _kernels
from gmuk.state import State
from gmuk.trajectory import _ARRAYS, Trajectory

if TYPE_CHECKING:
    from gmuk.system import Accelerations, System

__all__ = ["METHODS", "compile_loop", "simulate"]

#: Compile the step loop now (once per machine); see :func:`simulate`'s ``compiled``.
compile_loop = _compiled.compile_loop


class _Problem:
    """The RKMK vector field on Y = [ξ (6 n_r), V (6 n_r), x, ẋ, z] about base poses G₀.

    ``G0`` holds the current step's base poses; the stepper sets it before each step.
    """

    def __init__(self, system: System) -> None:
        self.system = system
        lay = system.layout
        self.layout = lay
        self.nr, self.ne, self.nc = lay.n_rigid, lay.n_euclid, lay.n_control
        nr6 = 6 * self.nr
        self.s_xi = slice(0, nr6)
        self.s_V = slice(nr6, 2 * nr6)
        self.s_x = slice(2 * nr6, 2 * nr6 + self.ne)
        self.s_xd = slice(2 * nr6 + self.ne, 2 * nr6 + 2 * self.ne)
        self.s_z = slice(2 * nr6 + 2 * self.ne, 2 * nr6 + 2 * self.ne + self.nc)
        self.size = 2 * nr6 + 2 * self.ne + self.nc
        self.rigid_idx = (lay.rigid_offsets[:, None] + np.arange(6)).reshape(-1, 6)
        # Entries of Y holding point masses' positions and velocities, one row per 3-vector
        # (positions first), for the error weights; None without point masses.
        pts = [sl.index for sl in map(lay.slot, lay.names) if sl.kind == "point"]
        self.point_idx: np.ndarray | None = None
        if pts:
            cols = np.array(pts, dtype=np.intp)[:, None] + np.arange(3)
            self.point_idx = np.concatenate([self.s_x.start + cols, self.s_xd.start + cols])
        self.G0: FloatArray = np.zeros((self.nr, 4, 4))
        self.acc: Accelerations | None = None
        self.n_rhs = 0

    def pack(self, state: State) -> FloatArray:
        Y = np.zeros(self.size)
        Y[self.s_V] = state.V.ravel()
        Y[self.s_x] = state.x
        Y[self.s_xd] = state.xdot
        Y[self.s_z] = state.z
        return Y

    def state(self, t: float, Y: FloatArray, G0: FloatArray) -> State:
        xi = Y[self.s_xi].reshape(-1, 6)
        g = _kernels.compose_exp(G0, xi) if self.nr else G0
        return State(
            t,
            g,
            Y[self.s_V].reshape(-1, 6).copy(),
            Y[self.s_x].copy(),
            Y[self.s_xd].copy(),
            Y[self.s_z].copy(),
            self.layout,
        )

    def deriv(self, Y: FloatArray, acc: Accelerations) -> FloatArray:
        dY = np.empty(self.size)
        xi = Y[self.s_xi].reshape(-1, 6)
        V = Y[self.s_V].reshape(-1, 6)
        if self.nr:
            dY[self.s_xi] = _kernels.dexp_inv_apply(xi, V).ravel() if xi.any() else V.ravel()
            dY[self.s_V] = acc.total[self.rigid_idx].ravel()
        e = self.layout.euclid_offsets
        dY[self.s_x] = Y[self.s_xd]
        dY[self.s_xd] = acc.total[e]
        dY[self.s_z] = acc.z_dot
        return dY

    def rhs(self, t: float, Y: FloatArray) -> FloatArray:
        """dY/dt at (t, Y) about ``G0``: the method's ``f``. The System's accelerations of
        the latest call are kept in ``acc`` (the step end records them)."""
        self.n_rhs += 1
        # the System's unchecked entry: simulate checked the layout once, and dY is checked
        # for NaN and inf below (System.accelerations would check the results a second time)
        self.acc = acc = self.system._accelerations(self.state(t, Y, self.G0))
        dY = self.deriv(Y, acc)
        if not np.isfinite(dY).all():
            raise FloatingPointError(f"non-finite derivative at t = {t:.9g} s")
        return dY

    def scale(
        self, Y0: FloatArray, Y1: FloatArray, G0: FloatArray, rtol: float, atol: float
    ) -> FloatArray:
        """Error weights, one per entry of Y (the larger of the values at both ends).

        Every 3-vector is weighed by its norm, so that no weight depends on how the
        inertial or body axes are chosen: ξ's rotation part against 1 rad, its translation
        part (body-frame components) against the distance ‖r‖ of the base pose, the twist's
        ω and v and a point mass's position and velocity by their norms. Scalars (slack
        coordinates, controller states) by their absolute values.
        """
        sc = atol + rtol * np.maximum(np.abs(Y0), np.abs(Y1))
        if self.nr:
            r = np.linalg.norm(G0[:, :3, 3], axis=1)
            xi_sc = np.empty((self.nr, 2, 3))
            xi_sc[:, 0] = atol + rtol
            xi_sc[:, 1] = (atol + rtol * r)[:, None]
            sc[self.s_xi] = xi_sc.ravel()
            V = np.maximum(
                np.linalg.norm(Y0[self.s_V].reshape(-1, 2, 3), axis=2),
                np.linalg.norm(Y1[self.s_V].reshape(-1, 2, 3), axis=2),
            )
            sc[self.s_V] = np.repeat(atol + rtol * V, 3)
        idx = self.point_idx
        if idx is not None:
            n = np.maximum(np.linalg.norm(Y0[idx], axis=1), np.linalg.norm(Y1[idx], axis=1))
            sc[idx] = (atol + rtol * n)[:, None]
        return sc

    def advance_base(self, Y: FloatArray, G0: FloatArray) -> tuple[FloatArray, FloatArray]:
        """G₁ = G₀ exp(ξ₁), re-orthonormalised; returns (G₁, Y with ξ reset to 0)."""
        if not self.nr:
            return G0, Y
        G1 = _kernels.compose_exp(G0, Y[self.s_xi].reshape(-1, 6))
        R = G1[:, :3, :3]
        G1[:, :3, :3] = 0.5 * R @ (3.0 * np.eye(3) - np.swapaxes(R, -1, -2) @ R)
        Y = Y.copy()
        Y[self.s_xi] = 0.0
        return G1, Y


class _Recorder:
    """Collects output states and their diagnostics: rows of (State, Accelerations) from the
    Python loop, and blocks of arrays from the compiled one, in the order they come."""

    def __init__(self, problem: _Problem, prefix: Trajectory | None = None) -> None:
        self.p = problem
        self.rows: list[tuple[State, Accelerations]] = []
        # Earlier output: column blocks (dicts of arrays), each followed by the rows after it.
        self.blocks: list[dict[str, Any]] = []
        # The outputs of a resumed run's checkpoint, which come before the rows.
        self.prefix = prefix

    def add(self, state: State, acc: Accelerations | None = None) -> None:
        if acc is None:
            acc = self.p.system.accelerations(state)
        self.rows.append((state, acc))

    def add_block(self, columns: dict[str, Any]) -> None:
        """Append outputs given as arrays (the compiled loop's buffers)."""
        if self.rows:
            self.blocks.append(self._columns(self.rows))
            self.rows = []
        self.blocks.append(columns)

    def _columns(self, rows: list[tuple[State, Accelerations]]) -> dict[str, Any]:
        lay = self.p.layout
        n = len(rows)

        def stack(fn: Any, shape: tuple[int, ...]) -> FloatArray:
            return np.array([fn(s, a) for s, a in rows]).reshape((n, *shape))

        s_rows = {a.multipliers.size for _, a in rows}
        if len(s_rows) > 1:
            raise GmukError("the number of constraint rows changed during the run")
        n_mult = s_rows.pop() if s_rows else 0
        return {
            "t": np.array([s.t for s, _ in rows], dtype=float),
            "g_NB": stack(lambda s, a: s.g, (lay.n_rigid, 4, 4)),
            "V_B": stack(lambda s, a: s.V, (lay.n_rigid, 6)),
            "x": stack(lambda s, a: s.x, (lay.n_euclid,)),
            "xdot": stack(lambda s, a: s.xdot, (lay.n_euclid,)),
            "z": stack(lambda s, a: s.z, (lay.n_control,)),
            "acceleration": stack(lambda s, a: a.total, (lay.n_dof,)),
            "constraint_acceleration": stack(lambda s, a: a.constraint, (lay.n_dof,)),
            "constraint_force": stack(lambda s, a: a.constraint_force, (lay.n_dof,)),
            "control_force": stack(lambda s, a: a.control_force, (lay.n_dof,)),
            "unmodeled_force": stack(lambda s, a: a.unmodeled_force, (lay.n_dof,)),
            "multipliers": stack(lambda s, a: a.multipliers, (n_mult,)),
            "residual": np.array([a.residual for _, a in rows], dtype=float),
            "rank": np.array([-1 if a.rank is None else a.rank for _, a in rows], dtype=np.int64),
        }

    def build(self, status: str, message: str, stats: dict[str, Any]) -> Trajectory:
        lay = self.p.layout
        blocks = [*self.blocks, self._columns(self.rows)]
        if self.prefix is not None:
            blocks.insert(0, {name: getattr(self.prefix, name) for name in _ARRAYS})
        blocks = [blk for blk in blocks if blk["t"].size] or blocks[-1:]
        if len({blk["multipliers"].shape[1] for blk in blocks}) > 1:
            raise GmukError("the number of constraint rows changed during the run")
        joined = {name: np.concatenate([blk[name] for blk in blocks]) for name in _ARRAYS}
        return Trajectory(
            **joined,
            body_names=lay.names,
            body_kinds=lay.kinds,
            body_dofs=lay.dofs,
            status=status,
            message=message,
            stats=stats,
        )


class _Progress:
    """A tqdm bar that appears only for runs longer than ``delay`` seconds on a terminal."""

    def __init__(self, enabled: bool | None, t0: float, t1: float, delay: float = 2.0) -> None:
        self.enabled = sys.stderr.isatty() if enabled is None else bool(enabled)
        self.t0, self.t1 = t0, t1
        self.start = time.monotonic()
        self.delay = 0.0 if enabled else delay
        self.bar: Any = None

    def update(self, t: float) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            if time.monotonic() - self.start < self.delay:
                return
            from tqdm import tqdm

            self.bar = tqdm(total=self.t1 - self.t0, unit="s(sim)", leave=False)
        self.bar.update(t - self.t0 - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def simulate(
    system: System,
    state0: State,
    t_span: tuple[float, float],
    *,
    t_eval: Any = None,
    method: str | type[RungeKuttaMethod] | RungeKuttaMethod = "DOP853",
    rtol: float = 1e-10,
    atol: float = 1e-10,
    step: float | None = None,
    first_step: float | None = None,
    max_step: float = np.inf,
    max_steps: int = 1_000_000,
    progress: bool | None = None,
    on_failure: str = "raise",
    compiled: bool | None = None,
) -> Trajectory:
    """Integrate a System on SE(3)ⁿ × Rᵏ from ``state0`` over ``t_span``.

    Parameters
    ----------
    system : System
    state0 : State
        Initial state; its ``t`` is replaced by ``t_span[0]``.
    t_span : (float, float)
        Start and end times (s), end > start.
    t_eval : array_like, shape (k,), optional
        Output times (s) within t_span (increasing). Default: every accepted step.
    method : str, RungeKuttaMethod subclass or instance
        The Runge–Kutta method (:mod:`gmuk.integrators`): a registered name,
        case-insensitive — ``"DOP853"`` (default), ``"DOPRI5"``, ``"RK4"`` or any name a
        user subclass registered (see :data:`METHODS`) — or a class or an instance.
    rtol, atol : float
        Relative and absolute tolerances (adaptive methods), applied with one rule: each
        3-vector u of the state is weighed by its norm, each scalar by its absolute value,
        ``w = atol + rtol · max(‖u(t₀)‖, ‖u(t₁)‖)`` over the step. The 3-vectors are the
        twist's ω (rad/s) and v (m/s), a point mass's position (m) and velocity (m/s), and
        the step's exponential coordinates ξ, whose rotation part is weighed against 1 rad
        and translation part against the distance ‖r‖ (m) of the step's base pose. Slack
        coordinates and controller states are scalars. No weight depends on the choice of
        axes. With a method that has a continuous extension (DOP853) and ``t_eval``, the
        tolerances bound the error of the interpolated outputs too.
    step : float
        Step size (s) for a fixed-step method such as RK4 (required there); ignored by the
        adaptive ones.
    first_step, max_step : float, optional
        Step-size bounds (s) for the adaptive methods.
    max_steps : int
        Give up (status "failed") after this many steps.
    progress : bool, optional
        Show a progress bar: True always, False never, None (default) only on a terminal and
        once the run has taken more than 2 s.
    on_failure : {"raise", "return"}
        On failure (step-size underflow, NaN, a singular or inconsistent solve in strict mode,
        too many steps): raise :class:`gmuk.errors.SimulationError` carrying the trajectory
        so far as ``.trajectory`` (default), or return that trajectory with
        ``status="failed"`` and the reason in ``message``. A KeyboardInterrupt always returns
        the trajectory so far with ``status="interrupted"`` (and a warning).
    compiled : bool, optional
        Run the step loop compiled (:mod:`gmuk.integrators._compiled`): None (default) when the
        System qualifies — rigid bodies, point masses and slack coordinates, solved by the
        ``"fused"`` or ``"dense"`` strategy (or unconstrained) — and the method is DOP853 or a plain
        tableau; True requires it (a :class:`~gmuk.errors.DefinitionError` says why a System does
        not qualify); False always runs the Python loop. Built-in force models, the LVLH tracking
        and relative constraints and the Morse–Lyapunov law run compiled; any other force model,
        constraint or controller is called in Python from inside the compiled loop, and costs only
        its own Python. Both loops give the same results to rounding (docs/architecture.rst);
        ``stats["compiled"]`` says which ran. A failure inside the compiled loop (a part that
        raises, a field evaluated inside the body, a NaN, a step-size underflow, a solve it cannot
        certify) is retried by the Python loop from the last accepted step, which raises the error
        it always raises, with the trajectory so far. The loop is compiled once per machine and then
        loaded from numba's cache: under None, a run that finds it not compiled yet takes the Python
        loop and starts the compilation in a background process for the runs after it
        (:func:`compile_loop` compiles it now; ``GMUK_BACKGROUND_COMPILE=0`` turns the background
        process off), while True compiles it in this process first.

    Returns
    -------
    Trajectory
        ``stats["method"]`` holds the method's name.

    Raises
    ------
    DefinitionError
        For an unknown method name (the message lists the registered ones) or bad arguments.
    gmuk.runs.CheckpointError
        When resuming from a checkpoint written by another simulation.

    Notes
    -----
    Inside :func:`gmuk.runs.run_control` the call stops at the next step once a stop is
    requested (``status="interrupted"``, no warning), writes checkpoints of its progress, and
    resumes from them (see :mod:`gmuk.runs`); ``gmuk run`` uses this.
    """
    m = get_method(method)
    if not isinstance(on_failure, str) or on_failure not in ("raise", "return"):
        raise DefinitionError(f"on_failure must be 'raise' or 'return'; got {on_failure!r}")
    if not isinstance(state0, State):
        raise DefinitionError(
            f"state0 must be a gmuk.State (from System.state); got {type(state0).__name__}"
        )
    pair_error = DefinitionError(
        f"t_span must be a pair (start, end) of real times in s; got {t_span!r:.60}"
    )
    if isinstance(t_span, np.ndarray):
        if t_span.shape != (2,):
            raise pair_error
    elif not isinstance(t_span, (tuple, list)) or len(t_span) != 2:
        raise pair_error
    try:
        t0, t1 = (real_number(v, "t_span") for v in t_span)
    except DefinitionError as exc:
        if "finite" in str(exc):
            raise
        raise pair_error from None
    if not t1 > t0:
        raise DefinitionError(f"t_span must be finite with end > start; got {t_span!r}")
    if state0.layout != system.layout:
        raise DefinitionError("state0 belongs to another System (layouts differ)")
    outs = None if t_eval is None else _times(t_eval)
    if outs is not None and (
        outs.size == 0
        or np.any(np.diff(outs) <= 0)
        or outs[0] < t0
        or outs[-1] > t1
        or not np.isfinite(outs).all()
    ):
        raise DefinitionError(f"t_eval must be strictly increasing within t_span {t_span}")
    if not m.adaptive and step is None:
        raise DefinitionError(
            f"method {label(m)!r} has a fixed step and needs a positive step (step=...)"
        )
    if step is not None:
        step = real_number(step, "step", positive=True)
    rtol = real_number(rtol, "rtol", positive=True)
    atol = real_number(atol, "atol", positive=True)
    if first_step is not None:
        first_step = real_number(first_step, "first_step", positive=True)
    max_step = real_number(max_step, "max_step", positive=True, allow_inf=True)
    if isinstance(max_steps, (bool, np.bool_)) or not isinstance(max_steps, (int, np.integer)):
        raise DefinitionError(f"max_steps must be an integer >= 1; got {max_steps!r}")
    if max_steps < 1:
        raise DefinitionError(f"max_steps must be an integer >= 1; got {max_steps!r}")
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise DefinitionError(f"progress must be True, False or None; got {progress!r}")
    if compiled is not None and not isinstance(compiled, (bool, np.bool_)):
        raise DefinitionError(f"compiled must be True, False or None; got {compiled!r}")
    plan: _compiled.Program | str = "not asked for"
    if compiled is None or compiled:
        plan = _compiled.program(system, m, state0.replace(t=t0))
        if compiled and isinstance(plan, str):
            raise DefinitionError(f"this System cannot run compiled: {plan}")
        if compiled:
            _compiled.compile_loop()
        elif not isinstance(plan, str) and not _compiled.loaded(plan):
            if _compiled.compile_on_first_use:
                _compiled.compile_loop()
            else:
                # first use on this machine: compiling takes 10-30 s, more than most runs:
                # this run takes the Python loop while another process compiles the loop
                _compiled.compile_loop(background=True)
                plan = "the compiled loop is not compiled yet on this machine"

    state0 = state0.replace(t=t0)
    control = runs.current()
    checkpoint = control.next_path() if control is not None else None
    prefix: Trajectory | None = None
    record: dict[str, Any] | None = None
    fingerprint = ""
    if checkpoint is not None:
        settings = {
            "t_span": (t0, t1),
            "method": label(m),
            "rtol": rtol,
            "atol": atol,
            "step": step,
            "first_step": first_step,
            "max_step": max_step,
        }
        fingerprint = runs.fingerprint(state0, settings, outs)
        if control is not None and control.resume and checkpoint.exists():
            prefix, record = runs.load(checkpoint, fingerprint)
            if record["complete"]:
                return prefix
    prob = _Problem(system)
    rec = _Recorder(prob, prefix)
    stepper = (
        _Stepper(prob, m, rtol, atol, step, first_step, max_step)
        if isinstance(plan, str)
        else _CompiledStepper(prob, m, rtol, atol, step, first_step, max_step, plan)
    )
    stepper.control, stepper.checkpoint = control, checkpoint
    stepper.fingerprint, stepper.recorder = fingerprint, rec
    bar = _Progress(progress, t0, t1)
    status, message = "success", ""
    try:
        stepper.run(state0, t1, outs, rec, max_steps, bar, resume=record)
    except _StopRequested:
        status, message = "interrupted", f"stopped on request at t = {stepper.t:.9g} s"
    except KeyboardInterrupt:
        status, message = "interrupted", f"interrupted by the user at t = {stepper.t:.9g} s"
        warnings.warn(message + "; returning the trajectory so far", GmukWarning, stacklevel=2)
    except Exception as exc:
        status = "failed"
        message = f"failed at t = {stepper.t:.9g} s: {type(exc).__name__}: {exc}"
        if on_failure == "raise":
            traj = rec.build(status, message, stepper.stats())
            bar.close()
            stepper.save_checkpoint(traj)
            raise SimulationError(message, traj) from exc
    finally:
        bar.close()
    traj = rec.build(status, message, stepper.stats())
    stepper.save_checkpoint(traj)
    return traj


def _times(t_eval: Any) -> FloatArray:
    """``t_eval`` as a 1-D float array of finite real times, or a DefinitionError."""
    bad = DefinitionError(f"t_eval must be an array of finite real times (s); got {t_eval!r:.60}")
    try:
        raw = np.asarray(t_eval)
    except (TypeError, ValueError, OverflowError):
        raise bad from None
    if raw.dtype.kind not in "iuf":
        raise bad
    try:
        outs = raw.astype(float).reshape(-1)
    except OverflowError:
        raise bad from None
    if not np.isfinite(outs).all():
        raise bad
    return outs


class _StopRequested(Exception):
    """The run's RunControl asked the simulation to stop (gmuk.runs)."""


def _step_factor(err: float, order: int) -> float:
    """The step-size factor for a scaled error estimate ``err`` (1: at tolerance): the
    classical ``0.9 err^(−1/order)``, with err floored so that a zero estimate grows the step
    by the callers' upper clip."""
    return 0.9 * (max(err, 1e-10) ** (-1.0 / order))


class _StepFailure(RuntimeError):
    """Step-size underflow or too many steps."""


class _Stepper:
    """The RKMK step loop: step-size control, output times, base-pose updates. Everything
    that depends on the Runge–Kutta method is asked of the method object."""

    def __init__(
        self,
        prob: _Problem,
        method: RungeKuttaMethod,
        rtol: float,
        atol: float,
        step: float | None,
        first_step: float | None,
        max_step: float,
    ) -> None:
        self.p = prob
        self.method = method
        self.rtol, self.atol = rtol, atol
        self.fixed = step
        self.first_step = first_step
        self.max_step = max_step
        self.t = 0.0
        self.n_steps = self.n_rejected = 0
        # Checkpointing (gmuk.runs): the last accepted step's integrator state.
        self.control: runs.RunControl | None = None
        self.checkpoint: Path | None = None
        self.fingerprint = ""
        self.recorder: _Recorder | None = None
        self.last_save = time.monotonic()
        self.at: tuple[FloatArray, FloatArray, float, int] | None = None  # Y, G0, h, out_i

    def save_checkpoint(self, traj: Trajectory | None = None) -> None:
        """Write the checkpoint (the trajectory so far and the last accepted step)."""
        if self.checkpoint is None or self.at is None:
            return
        Y, G0, h, out_i = self.at
        if traj is None:
            assert self.recorder is not None
            traj = self.recorder.build("interrupted", "checkpoint", self.stats())
        record = {
            "fingerprint": self.fingerprint,
            "complete": traj.status == "success",
            "t": self.t,
            "h": h,
            "out_i": out_i,
            "Y": Y.tolist(),
            "G0": G0.ravel().tolist(),
            "n_steps": self.n_steps,
            "n_rejected": self.n_rejected,
            "n_rhs": self.p.n_rhs,
        }
        runs.save(self.checkpoint, traj, record)
        self.last_save = time.monotonic()

    def _after_step(self) -> None:
        control = self.control
        if control is None:
            return
        if control.stop_requested:
            raise _StopRequested
        if self.checkpoint is not None and time.monotonic() - self.last_save >= control.every_s:
            self.save_checkpoint()

    def stats(self) -> dict[str, Any]:
        return {
            "n_rhs": self.p.n_rhs,
            "n_steps": self.n_steps,
            "n_rejected": self.n_rejected,
            "method": label(self.method),
            "rtol": self.rtol,
            "atol": self.atol,
            "compiled": isinstance(self, _CompiledStepper),
        }

    def _initial_step(self, t: float, Y: FloatArray, f0: FloatArray, t_end: float) -> float:
        if self.first_step is not None:
            return min(self.first_step, t_end - t)
        sc = self.p.scale(Y, Y, self.p.G0, self.rtol, self.atol)
        d0 = np.sqrt(np.mean((Y / sc) ** 2))
        d1 = np.sqrt(np.mean((f0 / sc) ** 2))
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, t_end - t)
        f1 = self.p.rhs(t + h0, Y + h0 * f0)
        d2 = np.sqrt(np.mean(((f1 - f0) / sc) ** 2)) / h0
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1.0 / (self.method.order + 1))
        return float(min(100 * h0, h1, self.max_step, t_end - t))

    def run(
        self,
        state0: State,
        t_end: float,
        outs: FloatArray | None,
        rec: _Recorder,
        max_steps: int,
        bar: _Progress,
        resume: dict[str, Any] | None = None,
    ) -> None:
        p, m = self.p, self.method
        f = p.rhs
        b, s, order = m.b, m.n_stages, m.order
        fsal, adaptive = m.fsal, m.adaptive
        dense = m.dense_output and outs is not None
        step_to_outputs = m.steps_onto_outputs and outs is not None
        rtol, atol = self.rtol, self.atol
        G0: FloatArray
        Y: FloatArray
        if resume is not None:  # from the last accepted step of a checkpoint (gmuk.runs)
            t = self.t = float(resume["t"])
            G0 = np.array(resume["G0"], dtype=float).reshape(state0.g.shape)
            p.G0 = G0
            Y = np.array(resume["Y"], dtype=float)
            if Y.shape != (p.size,):
                raise runs.CheckpointError(
                    f"checkpoint state has {Y.size} entries; expected {p.size}"
                )
            p.n_rhs = int(resume.get("n_rhs", 0))
            self.n_steps = int(resume.get("n_steps", 0))
            self.n_rejected = int(resume.get("n_rejected", 0))
            f0 = f(t, Y)
            out_i = int(resume["out_i"])
            h = float(resume["h"])
        else:
            t = self.t = state0.t
            G0 = p.G0 = state0.g.copy()
            Y = p.pack(state0)
            if self.control is not None and self.control.stop_requested:
                rec.add(state0)  # asked to stop before starting: the initial state only
                raise _StopRequested
            f0 = f(t, Y)
            acc0 = p.acc
            assert acc0 is not None
            out_i = 0
            if outs is None or outs[0] == t:
                rec.add(state0, acc0)
                out_i = 0 if outs is None else 1
            h = self._initial_step(t, Y, f0, t_end) if adaptive else float(self.fixed or 0)
        self.at = (Y, G0, h, out_i)
        while t < t_end:
            if self.n_steps >= max_steps:
                raise _StepFailure(f"reached max_steps = {max_steps}")
            h = min(h, self.max_step)
            t_target = t_end
            if step_to_outputs and outs is not None and out_i < outs.size:
                t_target = min(t_end, outs[out_i])
            # Land exactly on the target when within a hair of it (no sliver steps); t + h_try
            # may round to a neighbour of t_target, so the step ends at t_target itself.
            landing = t_target - t <= h * (1.0 + 1e-6)
            h_try = t_target - t if landing else h
            if h_try <= 10 * np.finfo(float).eps * max(1.0, abs(t)):
                raise _StepFailure(f"step size underflow (h = {h_try:.3g} s)")
            K = m.stages(f, t, Y, h_try, f0)
            Y1 = Y + h_try * (b @ K[:s])
            f1 = f(t + h_try, Y1)  # reused as the next step's first stage
            acc1 = p.acc
            if fsal:
                K[-1] = f1
            if adaptive:
                sc = p.scale(Y, Y1, G0, rtol, atol)
                err = m.error_norm(K, h_try, sc)
                factor = _step_factor(err, order)
                if err > 1.0:
                    self.n_rejected += 1
                    h = h_try * max(0.2, min(0.9, factor))
                    continue
                h_next = h_try * min(10.0, max(0.2, factor))
            else:
                h_next = h
            t_new = t_target if landing else t + h_try
            if dense and outs is not None:
                hit = outs[out_i:][outs[out_i:] < t_new]
                if hit.size:
                    interp = m.interpolant(f, t, Y, h_try, K, Y1)
                    if adaptive:
                        # Output times inside the step: the continuous extension must meet
                        # the tolerance as well, or the step is retried shorter.
                        err_d = m.interpolant_error(f, interp, sc)
                        factor_d = _step_factor(err_d, order)
                        if err_d > 1.0:
                            self.n_rejected += 1
                            h = h_try * max(0.2, min(0.9, factor_d))
                            continue
                        h_next = min(h_next, h_try * min(10.0, max(0.2, factor_d)))
                    for tt in hit:
                        st = p.state(float(tt), interp(float(tt)), G0)
                        rec.add(st)
                        out_i += 1
            G1, Y1r = p.advance_base(Y1, G0)
            state1 = p.state(t_new, Y1r, G1)
            assert acc1 is not None
            f0 = p.deriv(Y1r, acc1)  # same accelerations; ξ̇ = V at the new base (ξ = 0)
            if outs is None or (out_i < outs.size and outs[out_i] == t_new):
                rec.add(state1, acc1)
                if outs is not None:
                    out_i += 1
            t, Y, G0, h = t_new, Y1r, G1, h_next
            p.G0 = G0
            self.t = t
            self.n_steps += 1
            self.at = (Y, G0, h, out_i)
            bar.update(t)
            self._after_step()


#: The compiled loop's output buffers: times, states Y, base poses and the right-hand side's
#: other outputs (gmuk.integrators._compiled.rhs), one row per output.
_Buffers = tuple[FloatArray, FloatArray, FloatArray, FloatArray]


class _CompiledStepper(_Stepper):
    """The step loop of :class:`_Stepper` run compiled (:mod:`gmuk.integrators._compiled`)
    in chunks of steps; between chunks Python drains the outputs, updates the progress bar,
    sees stop requests and writes checkpoints. A failure inside the compiled loop hands the
    run to the Python loop at the last accepted step, which meets the same failure and
    reports it as it always does."""

    #: Steps per chunk: a chunk is the longest a stop request waits.
    chunk = 256

    def __init__(
        self,
        prob: _Problem,
        method: RungeKuttaMethod,
        rtol: float,
        atol: float,
        step: float | None,
        first_step: float | None,
        max_step: float,
        program: _compiled.Program,
    ) -> None:
        super().__init__(prob, method, rtol, atol, step, first_step, max_step)
        self.program = program

    def _block(self, n_out: int, bufs: _Buffers, acc0: Accelerations) -> dict[str, Any]:
        """The first ``n_out`` buffered outputs as Trajectory columns."""
        bt, bY, bG, baux = (b[:n_out] for b in bufs)
        p = self.p
        lay = p.layout
        nr, nd, s = lay.n_rigid, lay.n_dof, self.program.s
        if nr:
            xi = bY[:, p.s_xi].reshape(-1, 6)
            g = _kernels.compose_exp(np.ascontiguousarray(bG).reshape(-1, 4, 4), xi)
        else:
            g = np.zeros((0, 4, 4))
        if s:  # the fused solve certified every row: its rank is s
            residual, rank = baux[:, 4 * nd + s].copy(), np.full(n_out, s, dtype=np.int64)
        else:  # the unconstrained solve's constants
            residual = np.full(n_out, float(acc0.residual))
            rank = np.full(n_out, -1 if acc0.rank is None else acc0.rank, dtype=np.int64)
        return {
            "t": bt.copy(),
            "g_NB": g.reshape(n_out, nr, 4, 4),
            "V_B": bY[:, p.s_V].reshape(n_out, nr, 6).copy(),
            "x": bY[:, p.s_x].copy(),
            "xdot": bY[:, p.s_xd].copy(),
            "z": bY[:, p.s_z].copy(),
            "acceleration": baux[:, :nd].copy(),
            "constraint_acceleration": baux[:, 2 * nd : 3 * nd].copy(),
            "constraint_force": baux[:, 3 * nd : 4 * nd].copy(),
            "control_force": baux[:, 4 * nd + s + 1 : 5 * nd + s + 1].copy(),
            "unmodeled_force": baux[:, nd : 2 * nd].copy(),
            "multipliers": baux[:, 4 * nd : 4 * nd + s].copy(),
            "residual": residual,
            "rank": rank,
        }

    def run(
        self,
        state0: State,
        t_end: float,
        outs: FloatArray | None,
        rec: _Recorder,
        max_steps: int,
        bar: _Progress,
        resume: dict[str, Any] | None = None,
    ) -> None:
        p, m, prog = self.p, self.method, self.program
        n = p.size
        ints = np.zeros(9, dtype=np.int64)
        h = 0.0
        if resume is not None:
            t = float(resume["t"])
            G0 = np.array(resume["G0"], dtype=float).reshape(state0.g.shape)
            Y = np.array(resume["Y"], dtype=float)
            if Y.shape != (n,):
                raise runs.CheckpointError(f"checkpoint state has {Y.size} entries; expected {n}")
            ints[_compiled.I_RHS] = int(resume.get("n_rhs", 0))
            ints[_compiled.I_STEPS] = int(resume.get("n_steps", 0))
            ints[_compiled.I_REJECTED] = int(resume.get("n_rejected", 0))
            ints[_compiled.I_OUT] = int(resume["out_i"])
            h = float(resume["h"])
        else:
            t = state0.t
            G0 = state0.g.copy()
            Y = p.pack(state0)
            if self.control is not None and self.control.stop_requested:
                rec.add(state0)
                raise _StopRequested
        self.t = t
        p.G0 = G0
        # the accelerations at the start, in Python: the constant residual and rank of an
        # unconstrained solve, and the first output row exactly as the Python loop makes it
        acc0 = self.p.system._accelerations(p.state(t, Y, G0))
        n_aux = prog.n_aux
        f0, aux = np.empty(n), np.empty(n_aux)
        ints[_compiled.I_RHS] += 1
        fs = np.array([t, 0.0, t_end, self.rtol, self.atol, self.max_step, 0.0])
        status = _compiled.rhs(t, Y, G0, prog.parts, f0, aux)
        if resume is None and status == 0:
            if outs is None or outs[0] == t:
                rec.add(state0, acc0)
                ints[_compiled.I_OUT] = 0 if outs is None else 1
            if not m.adaptive:
                h = float(self.fixed or 0)
            else:
                h = _compiled.initial_step(
                    t, Y, G0, f0, t_end, self.first_step or 0.0, self.max_step, m.order,
                    prog.parts, fs, ints,
                )  # fmt: skip
                status = 0 if h > 0 else -1
        p.n_rhs = int(ints[_compiled.I_RHS])
        if status != 0:
            self._raise_interrupt()
            self._hand_over(state0, t_end, Y, G0, h, ints, outs, rec, max_steps, bar, resume)
            return
        out_arr = np.zeros(0) if outs is None else outs
        cap = self.chunk + 1
        bufs = self._buffers(cap, n, p.layout.n_rigid, n_aux)
        ints[_compiled.I_MAX_STEPS] = max_steps
        ints[_compiled.I_CHUNK] = self.chunk
        fs[_compiled.F_H] = h
        self.at = (Y.copy(), G0.copy(), h, int(ints[_compiled.I_OUT]))
        while True:
            fs[_compiled.F_T] = t
            ints[_compiled.I_WRITTEN] = 0
            status = _compiled.advance(
                prog.parts, prog.method, fs, ints, Y, G0, f0, aux,
                out_arr, outs is not None, *bufs,
            )  # fmt: skip
            n_out = int(ints[_compiled.I_WRITTEN])
            if n_out:
                rec.add_block(self._block(n_out, bufs, acc0))
            t, h = float(fs[_compiled.F_T]), float(fs[_compiled.F_H])
            self.t = t
            p.G0 = G0
            p.n_rhs = int(ints[_compiled.I_RHS])
            self.n_steps = int(ints[_compiled.I_STEPS])
            self.n_rejected = int(ints[_compiled.I_REJECTED])
            self.at = (Y.copy(), G0.copy(), h, int(ints[_compiled.I_OUT]))
            bar.update(t)
            if status == _compiled.DONE:
                return
            if status < 0:
                self._raise_interrupt()
                self._hand_over(state0, t_end, Y, G0, h, ints, outs, rec, max_steps, bar, resume)
                return
            if status == _compiled.FULL and n_out == 0:  # one step has more outputs than room
                cap = 2 * int(ints[_compiled.I_NEED]) + cap
                bufs = self._buffers(cap, n, p.layout.n_rigid, n_aux)
            self._after_step()

    def _raise_interrupt(self) -> None:
        """Re-raise a KeyboardInterrupt (or another non-Exception) that a part evaluated in
        Python caught from a signal; an Exception is left to the Python loop, which meets
        it again at the same stage and reports it as it always does."""
        python = self.program.python
        if python is not None and python.error is not None:
            error, python.error = python.error, None
            if not isinstance(error, Exception):
                raise error

    @staticmethod
    def _buffers(cap: int, n: int, nr: int, n_aux: int) -> _Buffers:
        return np.empty(cap), np.empty((cap, n)), np.empty((cap, nr, 4, 4)), np.empty((cap, n_aux))

    def _hand_over(
        self,
        state0: State,
        t_end: float,
        Y: FloatArray,
        G0: FloatArray,
        h: float,
        ints: np.ndarray,
        outs: FloatArray | None,
        rec: _Recorder,
        max_steps: int,
        bar: _Progress,
        resume: dict[str, Any] | None,
    ) -> None:
        """Continue in the Python loop from the last accepted step (after a failure), or
        from the start when the compiled loop failed before its first step."""
        if resume is None and ints[_compiled.I_STEPS] == 0:
            rec.rows.clear()
            rec.blocks.clear()
            self.p.n_rhs = 0
            _Stepper.run(self, state0, t_end, outs, rec, max_steps, bar)
            return
        record = resume or {}
        if ints[_compiled.I_STEPS] > int(record.get("n_steps", -1)):
            record = {
                "t": self.t,
                "G0": G0.ravel().tolist(),
                "Y": Y.tolist(),
                "n_rhs": int(ints[_compiled.I_RHS]),
                "n_steps": int(ints[_compiled.I_STEPS]),
                "n_rejected": int(ints[_compiled.I_REJECTED]),
                "out_i": int(ints[_compiled.I_OUT]),
                "h": h,
            }
        _Stepper.run(self, state0, t_end, outs, rec, max_steps, bar, resume=record)
