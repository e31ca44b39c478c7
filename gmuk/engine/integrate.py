"""Lie-group integrators: Runge–Kutta–Munthe-Kaas (RKMK) on SE(3)ⁿ × Rᵏ.

Each step starts from poses G₀ and integrates, with an explicit Runge–Kutta method, the
local problem in exponential coordinates ξ (one 6-vector per rigid body, ξ(0) = 0):

``g = G₀ exp(ξ^)``, ``ξ̇ = dexp⁻¹(ξ) V`` (McCann 2020, Eq. 20), ``V̇ = ν̇(g, V, t)``,

together with the Euclidean coordinates (point masses, slack coordinates) and controller
states. The step ends with ``G₁ = G₀ exp(ξ₁^)``, so poses stay on SE(3) by construction;
one Newton–Schulz iteration ``R ← R (3I − RᵀR)/2`` per step removes round-off drift, keeping
‖RᵀR − I‖ at the 1e-16 level over any number of steps.

The Runge–Kutta method is an object (:mod:`gmuk.engine.integrators`):
:class:`~gmuk.engine.integrators.DOP853`
(default; Dormand–Prince 8(5,3), adaptive, with a continuous
extension of order 7 for output times whose error is controlled too),
:class:`~gmuk.engine.integrators.DOPRI5` (Dormand–Prince 5(4), adaptive, stepping exactly onto
output
times) and :class:`~gmuk.engine.integrators.RK4` (classical, fixed step). :func:`simulate` accepts a
registered name (case-insensitive), a :class:`~gmuk.engine.integrators.RungeKuttaMethod` subclass or
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
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from gmuk import runs
from gmuk._validation import FloatArray, real_number
from gmuk.engine.events import XTOL, Event, check_events, event_value

# The method classes and the registry, re-exported here for convenience.
from gmuk.engine.integrators import DOP853 as DOP853
from gmuk.engine.integrators import DOPRI5 as DOPRI5
from gmuk.engine.integrators import METHODS as METHODS
from gmuk.engine.integrators import RK4 as RK4
from gmuk.engine.integrators import RungeKuttaMethod as RungeKuttaMethod
from gmuk.engine.integrators import _compiled, _program
from gmuk.engine.integrators import get_method as get_method
from gmuk.engine.integrators import method_names as method_names
from gmuk.engine.integrators._base import label
from gmuk.engine.integrators._dop853_tableau import INTERPOLATOR_POWER
from gmuk.errors import DefinitionError, GmukError, GmukWarning, SimulationError
from gmuk.lie import _kernels
from gmuk.state import State
from gmuk.trajectory import _ARRAYS, EventRecord, Trajectory

if TYPE_CHECKING:
    from gmuk.engine.system import Accelerations, System

__all__ = ["DRIFT_SAMPLES", "METHODS", "check_drift", "compile_loop", "simulate", "versions"]

#: Compile the step loop now (once per machine); :func:`simulate` does it on first use.
compile_loop = _compiled.compile_loop


class _Packing:
    """The integrator's state vector Y = [ξ (6 n_r), V (6 n_r), x, ẋ, z] of a System about
    base poses G₀: where each part sits, and the conversions to and from a State."""

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

    def pack(self, state: State) -> FloatArray:
        Y = np.zeros(self.size)
        Y[self.s_V] = state.V.ravel()
        Y[self.s_x] = state.x
        Y[self.s_xd] = state.xdot
        Y[self.s_z] = state.z
        return Y

    def adopt(self, t: float, Y: FloatArray, G0: FloatArray) -> State:
        """:meth:`state` without the State constructor's checks and copies (its arrays are
        fresh: the State takes them over)."""
        xi = Y[self.s_xi].reshape(-1, 6)
        g = _kernels.compose_exp(G0, xi) if self.nr else G0.copy()
        return State._adopt(
            t,
            g,
            Y[self.s_V].reshape(-1, 6).copy(),
            Y[self.s_x].copy(),
            Y[self.s_xd].copy(),
            Y[self.s_z].copy(),
            self.layout,
        )

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


class _Recorder:
    """Collects output states and their diagnostics: rows of (State, Accelerations) from the
    Python loop, and blocks of arrays from the compiled one, in the order they come."""

    def __init__(self, problem: _Packing, prefix: Trajectory | None = None) -> None:
        self.p = problem
        self.rows: list[tuple[State, Accelerations]] = []
        # Earlier output: column blocks (dicts of arrays), each followed by the rows after it.
        self.blocks: list[dict[str, Any]] = []
        # The outputs of a resumed run's checkpoint, which come before the rows.
        self.prefix = prefix
        # The events located so far (after the prefix's).
        self.events: list[EventRecord] = []

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
        events = (*(self.prefix.events if self.prefix is not None else ()), *self.events)
        return Trajectory(
            **joined,
            body_names=lay.names,
            body_kinds=lay.kinds,
            body_dofs=lay.dofs,
            status=status,
            message=message,
            stats=stats,
            events=events,
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
    drift_tol: float | None = 1e-6,
    events: Event | Sequence[Event] | None = None,
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
        The Runge–Kutta method (:mod:`gmuk.engine.integrators`): a registered name,
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
        Deprecated and ignored: every run takes gmuk's one loop, compiled
        (:mod:`gmuk.engine.integrators._compiled`). Built-in force models, the LVLH tracking and
        relative constraints and the Morse–Lyapunov law run compiled; any other force model,
        constraint, controller or solve strategy is called back in Python from inside the loop
        and costs only its own Python. ``compiled=False`` raises a DefinitionError (the
        Python loop is a test oracle now, :func:`gmuk.testing.reference_simulate`). The loop is
        compiled once per machine, on first use, in this process (announced on stderr in one
        line; ``gmuk compile`` does it ahead) and then loaded from numba's cache: the results do
        not depend on the cache's state.
    drift_tol : float or None
        How far a constraint may drift from where the run started it, in the units of its
        residual (default 1e-6: 1 µm, 1 µrad, 1 µm/s; see Notes). A run that completes its
        span (or ends at a terminal event) with a constraint past it ends with
        ``status="drifted"`` (so
        ``traj.success`` is False) and a GmukWarning. None measures and records the
        violations without judging them (for runs that leave their constraint by design,
        e.g. under unmodeled forces).
    events : Event or sequence of Event, optional
        Functions of (t, state) whose sign changes are located (:mod:`gmuk.engine.events`;
        docs/events.rst): after each accepted step, by Brent's method to 1e-13 s on the
        step's continuous extension (DOP853's dense output; for DOPRI5 and RK4 a step of the
        method from the step's start to each trial time). A recorded event goes into
        ``traj.events`` and changes none of the trajectory's other numbers; the first
        terminal one ends the run at its time, with its state as the last output and
        ``status="terminated"``. The event functions are evaluated in Python at every step,
        so the loop hands back each step (15-20 µs per step on a 2-core box:
        benchmarks/README.md, "Events in simulate").
        Inside :func:`gmuk.runs.run_control`, the control's ``events`` are added.

    Returns
    -------
    Trajectory
        ``stats`` holds the method's name, the numbers of evaluations, steps and rejected
        steps, the versions of gmuk, numba and numpy that computed it, and the constraint
        check: ``stats["drifted"]`` (bool) and ``stats["constraint_violation"]`` (below).
        With events, ``stats["n_event_rhs"]`` counts the evaluations spent locating them
        (not in ``n_rhs``); ``traj.events`` holds them (:class:`gmuk.trajectory.EventRecord`).

    Raises
    ------
    DefinitionError
        For an unknown method name (the message lists the registered ones) or bad arguments,
        among them events that are not :class:`gmuk.Event` objects, share a name, or whose
        function does not return one real number at the start (NonFiniteError for NaN).
    gmuk.runs.CheckpointError
        When resuming from a checkpoint written by another simulation.

    Notes
    -----
    Inside :func:`gmuk.runs.run_control` the call stops at the next step once a stop is
    requested (``status="interrupted"``, no warning), writes checkpoints of its progress, and
    resumes from them (see :mod:`gmuk.runs`); ``gmuk run`` uses this.

    **Constraint drift.** The rows ``A ν̇ = b`` hold a constraint at the acceleration level
    only: integration error that leaves it is not pulled back unless Baumgarte terms do it,
    and can grow (exponentially, on an unstable manifold). After the run, every constraint
    that states its residuals (:meth:`gmuk.Constraint.violation`: holonomic φ and φ̇,
    nonholonomic ψ, inequalities' slack equalities, tracking errors log(g_d⁻¹ g) and the
    twist error, a relative constraint's twist error) is evaluated at the output times (at
    most :data:`DRIFT_SAMPLES` of them, evenly spread, first and last included). A
    constraint whose residuals all start within ``drift_tol`` (2-norm) is *drifted* when the
    norm of one of them grows by more than ``drift_tol`` above its start value. A
    constraint that starts off its manifold (a disturbed start that Baumgarte terms or a
    controller bring back) is recorded but not judged: its velocity error must first grow
    while it converges. ``stats["constraint_violation"]`` holds ``position`` and
    ``velocity`` (the largest norms over the constraints and outputs, each in its
    residual's units, None when no constraint states that level), ``tolerance``,
    ``drifted``, ``samples`` and one entry per constraint (``name``, ``position``,
    ``velocity``, their start values, ``on_start``, ``drifted``, ``t_drifted``). The
    tolerance applies to each residual as the constraint states it: the tracking
    constraints weigh translations against the reference's distance and speed (as the
    integrator's error weights do) and keep rotations in rad; a user's residual has its
    own units, for which gmuk knows no scale (raise ``drift_tol`` for a residual in m on a
    scale of 1e6 m or more). 1e-6 is far above what the integrator leaves on a stabilised
    or stable constraint (FCEI over 12 orbits: 7e-14 rad and 2.4e-7 m, 8e-14 of its
    distance) and far below a drift that spoils a result (unstabilised FCEI passes it
    within 4 orbits and ends π rad off). An interrupted or failed run
    is checked and recorded too, its status unchanged; a residual that raises is
    recorded under ``error`` and judged as not drifted.
    """
    run = check_run(
        system, state0, t_span, t_eval=t_eval, method=method, rtol=rtol, atol=atol, step=step,
        first_step=first_step, max_step=max_step, max_steps=max_steps, on_failure=on_failure,
    )  # fmt: skip
    if drift_tol is not None:
        drift_tol = real_number(drift_tol, "drift_tol", positive=True)
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise DefinitionError(f"progress must be True, False or None; got {progress!r}")
    if compiled is not None:
        if not isinstance(compiled, (bool, np.bool_)):
            raise DefinitionError(f"compiled must be True, False or None; got {compiled!r}")
        if not compiled:
            raise DefinitionError(
                "compiled=False: gmuk has one loop, the compiled one; the Python loop is a test "
                "oracle (gmuk.testing.reference_simulate)"
            )
        warnings.warn(
            "simulate(compiled=...) is deprecated: every run is compiled",
            DeprecationWarning,
            stacklevel=2,
        )
    _program.method_table(run.method)  # a method the loop cannot run: say so first
    control = runs.current()
    found = check_events(events)
    if control is not None and control.events:
        found = check_events((*found, *control.events))
    for event in found:  # a function that cannot be evaluated: said before the run
        event_value(event, run.t0, run.state0)
    checkpoint = control.next_path() if control is not None else None
    prefix: Trajectory | None = None
    record: dict[str, Any] | None = None
    fingerprint = ""
    if checkpoint is not None:
        settings = {
            "t_span": (run.t0, run.t1),
            "method": label(run.method),
            "rtol": run.rtol,
            "atol": run.atol,
            "step": run.step,
            "first_step": run.first_step,
            "max_step": run.max_step,
        }
        if found:  # (only then: the fingerprints of runs without events are unchanged)
            settings["events"] = [
                (type(e).__qualname__, e.name, e.direction, e.terminal) for e in found
            ]
        fingerprint = runs.fingerprint(run.state0, settings, run.outs)
        if control is not None and control.resume and checkpoint.exists():
            prefix, record = runs.load(checkpoint, fingerprint)
            if record["complete"]:
                return check_drift(system, prefix, drift_tol)
    packing = _Packing(system)
    rec = _Recorder(packing, prefix)
    loop = _Loop(packing, run, found)
    loop.control, loop.checkpoint = control, checkpoint
    loop.fingerprint, loop.recorder = fingerprint, rec
    bar = _Progress(progress, run.t0, run.t1)
    status, message = "success", ""
    try:
        loop.run(rec, bar, resume=record)
        if loop.terminal is not None:
            status = "terminated"
            message = f"terminal event {loop.terminal.name!r} at t = {loop.terminal.t:.15g} s"
    except _StopRequested:
        status, message = "interrupted", f"stopped on request at t = {loop.t:.9g} s"
    except KeyboardInterrupt:
        status, message = "interrupted", f"interrupted by the user at t = {loop.t:.9g} s"
        warnings.warn(message + "; returning the trajectory so far", GmukWarning, stacklevel=2)
    except Exception as exc:
        status = "failed"
        message = f"failed at t = {loop.t:.9g} s: {_describe(exc)}"
        if run.on_failure == "raise":
            traj = rec.build(status, message, loop.stats())
            bar.close()
            loop.save_checkpoint(traj)
            # the loop's own failure says all in the message: no chained traceback of it
            cause = None if _own_failure(exc) else exc
            raise SimulationError(message, check_drift(system, traj, drift_tol)) from cause
    finally:
        bar.close()
    traj = rec.build(status, message, loop.stats())
    loop.save_checkpoint(traj)  # before the drift check: a checkpoint records the run itself
    return check_drift(system, traj, drift_tol)


#: The most output times at which :func:`check_drift` evaluates the constraints' residuals
#: (in Python, about 50 µs a constraint and a time: 2001 cost four times an FCEI orbit's own
#: simulation). An unstabilised constraint drifts exponentially, so the last output, always
#: included, shows it; 65 evenly spread times find a transient excursion of some length.
DRIFT_SAMPLES = 65


def check_drift(system: System, traj: Trajectory, drift_tol: float | None) -> Trajectory:
    """``traj`` with the constraint check of :func:`simulate` (its Notes, "Constraint
    drift") in ``stats``; a completed run whose constraint drifted past ``drift_tol`` gets
    ``status="drifted"``, a message saying which and when, and a GmukWarning."""
    n = len(traj)
    picks = np.arange(n) if n <= DRIFT_SAMPLES else np.linspace(0, n - 1, DRIFT_SAMPLES)
    idx = np.unique(np.round(picks).astype(np.int64))
    states = _SampledStates(traj, idx) if system.constraints else _SampledStates(traj, idx[:0])
    # the poses and twists at those times, stacked once for every constraint
    stacked = (traj.g_NB[idx], traj.V_B[idx]) if len(states) else None
    found = [_constraint_drift(c, states, drift_tol, stacked) for c in system.constraints]
    entries = [e for e in found if e is not None]

    def largest(level: str) -> float | None:
        values = [e[level] for e in entries if e[level] is not None]
        return max(values) if values else None

    drifted = [e for e in entries if e["drifted"]]
    check = {
        "position": largest("position"),
        "velocity": largest("velocity"),
        "tolerance": drift_tol,
        "drifted": bool(drifted),
        "samples": len(states),
        "constraints": entries,
    }
    status, message = traj.status, traj.message
    stats = {**traj.stats, "drifted": bool(drifted), "constraint_violation": check}
    if drifted:
        first = min(drifted, key=lambda e: e["t_drifted"])
        what = (
            f"constraint {first['name']!r} drifted off: its residual grew past drift_tol = "
            f"{drift_tol:g} at t = {first['t_drifted']:.9g} s (largest ‖position‖ "
            f"{_show(first['position'])}, ‖velocity‖ {_show(first['velocity'])}, in its units)"
        )
        if status == "success":
            status, message = "drifted", what
        elif status == "terminated":  # ended by its event, but off its constraint
            status, message = "drifted", f"{message}; {what}"
        else:
            message = f"{message}; {what}"
        warnings.warn(
            f"{what}: the run is not on its constraint (stabilise it with gmuk.Baumgarte; "
            "docs/reliability.rst, 'Constraint drift')",
            GmukWarning,
            stacklevel=3,
        )
    return replace(traj, status=status, message=message, stats=stats)


def _show(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.3g}"


class _SampledStates(Sequence[State]):
    """The States of a trajectory at the output indices ``idx``, each made when first read
    (a constraint that reads its residuals from the stacked arrays reads only the first)."""

    def __init__(self, traj: Trajectory, idx: Any) -> None:
        self._traj = traj
        self._idx = [int(i) for i in idx]
        self._made: dict[int, State] = {}
        self.times = traj.t[idx]

    def __len__(self) -> int:
        return len(self._idx)

    def __getitem__(self, k: Any) -> Any:
        if isinstance(k, slice):
            return [self[j] for j in range(*k.indices(len(self)))]
        k = range(len(self))[k]  # an IndexError out of range, negative k from the end
        state = self._made.get(k)
        if state is None:
            state = self._made[k] = self._traj.state(self._idx[k])
        return state


def _constraint_drift(
    con: Any,
    states: Sequence[State],
    tol: float | None,
    stacked: tuple[FloatArray, FloatArray] | None = None,
) -> dict[str, Any] | None:
    """One constraint's entry of the drift check over ``states``; None when it states no
    residual. ``stacked``: the states' poses (N, n_rigid, 4, 4) and twists (N, n_rigid, 6),
    for a constraint that reads its residuals at every state at once."""
    violation = getattr(con, "violation", None)
    if violation is None or not states:
        return None
    name = str(getattr(con, "name", type(con).__name__))
    norms: dict[str, list[float]] = {"position": [], "velocity": []}
    try:
        along = getattr(con, "_violation_along", None)  # the residuals at every state at once
        both = along(states, stacked) if along is not None else None
        if both is not None:
            for level, values in zip(("position", "velocity"), both, strict=True):
                v = np.linalg.norm(values, axis=1)
                norms[level] = np.where(v == v, v, np.inf).tolist()
        else:
            for s in states:
                pos, vel = violation(s)
                for level, value in (("position", pos), ("velocity", vel)):
                    if value is not None:
                        v = float(np.linalg.norm(np.asarray(value, dtype=float)))
                        norms[level].append(v if v == v else np.inf)
    except Exception as exc:  # a part's residual failing: recorded, the run is kept
        warnings.warn(
            f"the drift check of constraint {name!r} failed ({_describe(exc)}); not checked",
            GmukWarning,
            stacklevel=4,
        )
        return {"name": name, "position": None, "velocity": None, "initial_position": None,
                "initial_velocity": None, "on_start": None, "drifted": False,
                "t_drifted": None, "error": _describe(exc)}  # fmt: skip
    if not norms["position"] and not norms["velocity"]:
        return None
    times = states.times if isinstance(states, _SampledStates) else np.array([s.t for s in states])
    start = {k: (v[0] if v else None) for k, v in norms.items()}
    on_start = all(v is None or v <= tol for v in start.values()) if tol is not None else None
    t_drifted = None
    if on_start:
        for values in norms.values():
            if values:
                arr = np.array(values)
                over = np.nonzero(arr > arr[0] + (tol or 0.0))[0]
                if over.size:
                    t = float(times[over[0]])
                    t_drifted = t if t_drifted is None else min(t_drifted, t)

    def finite(v: float) -> float | None:
        return v if np.isfinite(v) else None

    return {
        "name": name,
        "position": finite(max(norms["position"])) if norms["position"] else None,
        "velocity": finite(max(norms["velocity"])) if norms["velocity"] else None,
        "initial_position": None if start["position"] is None else finite(start["position"]),
        "initial_velocity": None if start["velocity"] is None else finite(start["velocity"]),
        "on_start": on_start,
        "drifted": t_drifted is not None,
        "t_drifted": t_drifted,
    }


def _loop_failure(message: str) -> SimulationError:
    """One of the loop's own failures (step-size underflow, too many steps, a non-finite
    derivative): a public :class:`SimulationError` marked as the loop's, so that a user never
    meets a private class name in a message or traceback."""
    exc = SimulationError(message)
    exc._gmuk_loop_failure = True  # type: ignore[attr-defined]
    return exc


def _own_failure(exc: BaseException) -> bool:
    """Whether ``exc`` is one of the loop's own failures (:func:`_loop_failure`)."""
    return getattr(exc, "_gmuk_loop_failure", False) is True


def _describe(exc: BaseException) -> str:
    """A failure's reason: the loop's own failures by their message, a part's error with its
    type."""
    if _own_failure(exc):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


def _times(t_eval: Any) -> FloatArray:
    """``t_eval`` as a 1-D float array of finite real times, or a DefinitionError."""

    def bad() -> DefinitionError:  # made only when raised: the repr of a long array is slow
        return DefinitionError(
            f"t_eval must be an array of finite real times (s); got {t_eval!r:.60}"
        )

    try:
        raw = np.asarray(t_eval)
    except (TypeError, ValueError, OverflowError):
        raise bad() from None
    if raw.dtype.kind not in "iuf":
        raise bad()
    try:
        outs = raw.astype(float).reshape(-1)
    except OverflowError:
        raise bad() from None
    if not np.isfinite(outs).all():
        raise bad()
    return outs


class _Run(NamedTuple):
    """The checked arguments of a run."""

    method: RungeKuttaMethod
    state0: State
    t0: float
    t1: float
    outs: FloatArray | None
    rtol: float
    atol: float
    step: float | None
    first_step: float | None
    max_step: float
    max_steps: int
    on_failure: str


def check_run(
    system: System,
    state0: State,
    t_span: Any,
    *,
    t_eval: Any,
    method: Any,
    rtol: Any,
    atol: Any,
    step: Any,
    first_step: Any,
    max_step: Any,
    max_steps: Any,
    on_failure: Any,
) -> _Run:
    """:func:`simulate`'s arguments checked (a DefinitionError names the first bad one)."""
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
    return _Run(
        m, state0.replace(t=t0), t0, t1, outs, rtol, atol, step, first_step, max_step,
        int(max_steps), on_failure,
    )  # fmt: skip


class _StopRequested(Exception):
    """The run's RunControl asked the simulation to stop (gmuk.runs)."""


def versions() -> dict[str, str]:
    """The versions of gmuk and the libraries that computed a run."""
    import numba

    from gmuk import __version__

    return {"gmuk": __version__, "numba": numba.__version__, "numpy": np.__version__}


#: The loop's output buffers: times, states Y, base poses and the right-hand side's other
#: outputs (gmuk.engine.integrators._program.aux_layout), one row per output.
_Buffers = tuple[FloatArray, FloatArray, FloatArray, FloatArray]


class _Loop:
    """Drives the compiled loop (:func:`gmuk.engine.integrators._compiled.advance`) in chunks of
    steps; between chunks Python drains the outputs, updates the progress bar, sees stop
    requests and writes checkpoints. A failure is raised with the trajectory so far kept in
    the recorder; nothing is ever retried by another loop."""

    #: Steps per chunk: a chunk is the longest a stop request waits.
    chunk = 256

    def __init__(self, packing: _Packing, run: _Run, events: tuple[Event, ...] = ()) -> None:
        self.p = packing
        self.run_args = run
        self.method = run.method
        # Events: the loop hands back every step (a chunk of one), whose end Python checks.
        self.events = events
        self.terminal: EventRecord | None = None
        self.n_event_rhs = 0
        self.g_prev: list[float] = []  # the events' values at the last accepted step
        self.rtol, self.atol = run.rtol, run.atol
        self.t = run.t0
        self.n_steps = self.n_rejected = self.n_rhs = 0
        # Checkpointing (gmuk.runs): the last accepted step's integrator state.
        self.control: runs.RunControl | None = None
        self.checkpoint: Path | None = None
        self.fingerprint = ""
        self.recorder: _Recorder | None = None
        self.last_save = time.monotonic()
        self.at: tuple[FloatArray, FloatArray, float, int] | None = None  # Y, G0, h, out_i

    def stats(self) -> dict[str, Any]:
        stats = {
            "n_rhs": self.n_rhs,
            "n_steps": self.n_steps,
            "n_rejected": self.n_rejected,
            "method": label(self.method),
            "rtol": self.rtol,
            "atol": self.atol,
            "compiled": True,
            "versions": versions(),
        }
        if self.events:
            stats["n_event_rhs"] = self.n_event_rhs
        return stats

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
            "complete": traj.status in ("success", "terminated"),
            "t": self.t,
            "h": h,
            "out_i": out_i,
            "Y": Y.tolist(),
            "G0": G0.ravel().tolist(),
            "n_steps": self.n_steps,
            "n_rejected": self.n_rejected,
            "n_rhs": self.n_rhs,
        }
        runs.save(self.checkpoint, traj, record)
        self.last_save = time.monotonic()

    def _after_chunk(self) -> None:
        control = self.control
        if control is None:
            return
        if control.stop_requested:
            raise _StopRequested
        if self.checkpoint is not None and time.monotonic() - self.last_save >= control.every_s:
            self.save_checkpoint()

    def _block(self, n_out: int, bufs: _Buffers, prog: _program.Program) -> dict[str, Any]:
        """The first ``n_out`` buffered outputs as Trajectory columns."""
        bt, bY, bG, baux = (b[:n_out] for b in bufs)
        p = self.p
        lay = p.layout
        nr = lay.n_rigid
        if nr:
            xi = bY[:, p.s_xi].reshape(-1, 6)
            g = _kernels.compose_exp(np.ascontiguousarray(bG).reshape(-1, 4, 4), xi)
        else:
            g = np.zeros((0, 4, 4))
        where = _program.aux_layout(lay.n_dof, prog.s, lay.n_control)
        columns = {name: baux[:, where[name]].copy() for name in where if name != "z_dot"}
        columns["rank"] = columns["rank"].astype(np.int64)
        return {
            "t": bt.copy(),
            "g_NB": g.reshape(n_out, nr, 4, 4),
            "V_B": bY[:, p.s_V].reshape(n_out, nr, 6).copy(),
            "x": bY[:, p.s_x].copy(),
            "xdot": bY[:, p.s_xd].copy(),
            "z": bY[:, p.s_z].copy(),
            **columns,
        }

    def run(self, rec: _Recorder, bar: _Progress, resume: dict[str, Any] | None = None) -> None:
        args, p = self.run_args, self.p
        n = p.size
        ints = np.zeros(_compiled.N_INTS, dtype=np.int64)
        fs = np.zeros(_compiled.N_FLOATS)
        state0 = args.state0
        if resume is not None:  # from the last accepted step of a checkpoint (gmuk.runs)
            t = float(resume["t"])
            G0 = np.array(resume["G0"], dtype=float).reshape(state0.g.shape)
            Y = np.array(resume["Y"], dtype=float)
            if Y.shape != (n,):
                raise runs.CheckpointError(f"checkpoint state has {Y.size} entries; expected {n}")
            ints[_compiled.I_RHS] = int(resume.get("n_rhs", 0))
            ints[_compiled.I_STEPS] = int(resume.get("n_steps", 0))
            ints[_compiled.I_REJECTED] = int(resume.get("n_rejected", 0))
            ints[_compiled.I_OUT] = int(resume["out_i"])
            fs[_compiled.F_H] = float(resume["h"])
        else:
            t = state0.t
            G0 = state0.g.copy()
            Y = p.pack(state0)
            ints[_compiled.I_FRESH] = 1
            if self.control is not None and self.control.stop_requested:
                rec.add(state0)  # asked to stop before starting: the initial state only
                raise _StopRequested
            if not self.method.adaptive:
                fs[_compiled.F_H] = float(args.step or 0.0)
        self.t = t
        self.at = (Y.copy(), G0.copy(), float(fs[_compiled.F_H]), int(ints[_compiled.I_OUT]))
        # the program reads the row counts of Python constraints at the start: a part that
        # raises there fails the run at its start time
        prog = p.system.compiled_program(self.method, p.state(t, Y, G0))
        _compiled.compile_loop()
        ints[_compiled.I_RHS_KERNEL] = _compiled.rhs_address()
        fs[[_compiled.F_T, _compiled.F_END, _compiled.F_RTOL, _compiled.F_ATOL]] = (
            t, args.t1, self.rtol, self.atol,
        )  # fmt: skip
        fs[_compiled.F_MAX_STEP] = args.max_step
        fs[_compiled.F_FIRST_STEP] = args.first_step or 0.0
        ints[_compiled.I_MAX_STEPS] = args.max_steps
        ints[_compiled.I_CHUNK] = self.chunk
        outs = args.outs
        out_arr = np.zeros(0) if outs is None else outs
        f0, aux = np.empty(n), np.empty(prog.n_aux)
        cap = self.chunk + 1
        bufs = self._buffers(cap, n, p.layout.n_rigid, prog.n_aux)
        if self.events:  # their values at the start (a resumed run: at its step)
            start_state = state0 if resume is None else p.state(t, Y, G0)
            self.g_prev = [event_value(e, t, start_state) for e in self.events]
            drive = (prog, fs, ints, Y, G0, f0, aux, out_arr, outs is not None)
            return self._run_events(rec, bar, drive)
        while True:
            ints[_compiled.I_WRITTEN] = 0
            status = _compiled.advance(
                prog.parts, prog.method, fs, ints, Y, G0, f0, aux,
                out_arr, outs is not None, *bufs,
            )  # fmt: skip
            n_out = int(ints[_compiled.I_WRITTEN])
            if n_out:
                rec.add_block(self._block(n_out, bufs, prog))
            self.t = float(fs[_compiled.F_T])
            self.n_rhs = int(ints[_compiled.I_RHS])
            self.n_steps = int(ints[_compiled.I_STEPS])
            self.n_rejected = int(ints[_compiled.I_REJECTED])
            if ints[_compiled.I_STARTED]:
                h = float(fs[_compiled.F_H])
                self.at = (Y.copy(), G0.copy(), h, int(ints[_compiled.I_OUT]))
            bar.update(self.t)
            if status == _compiled.DONE:
                return
            if status < 0:
                raise self._failure(status, prog, fs, ints)
            if status == _compiled.FULL and n_out == 0:  # one step has more outputs than room
                cap = 2 * int(ints[_compiled.I_NEED]) + cap
                bufs = self._buffers(cap, n, p.layout.n_rigid, prog.n_aux)
            self._after_chunk()

    def _run_events(self, rec: _Recorder, bar: _Progress, drive: tuple[Any, ...]) -> None:
        """:meth:`run` with events: the loop takes one step per call and Python looks at the
        events at its end (:meth:`_step_events`). The outputs stay in the buffers for up to
        :attr:`chunk` steps, as without events, and are drained then (:meth:`_drain`), at
        the end, at a terminal event, on a stop request or a failure."""
        prog, fs, ints, Y, G0, f0, aux, out_arr, has_outs = drive
        p, C = self.p, _compiled
        n = Y.size
        ints[C.I_CHUNK] = 1
        ints[C.I_WRITTEN] = 0
        cap = self.chunk + 1
        bufs = self._buffers(cap, n, p.layout.n_rigid, prog.n_aux)
        pending = 0  # steps since the last drain
        while True:
            begun = bool(ints[C.I_STARTED])
            start = (float(fs[C.F_T]), Y.copy(), G0.copy(), f0.copy() if begun else None)
            steps_before = int(ints[C.I_STEPS])
            status = C.advance(
                prog.parts, prog.method, fs, ints, Y, G0, f0, aux, out_arr, has_outs, *bufs
            )
            if int(ints[C.I_STEPS]) > steps_before:
                pending += 1
                try:
                    term = self._step_events(rec, prog, start, fs, ints, Y, G0)
                except BaseException:  # the step is kept, then the failure reported
                    self._drain(rec, bufs, prog, fs, ints, Y, G0, bar)
                    raise
                if term is not None:
                    self._drain(rec, bufs, prog, fs, ints, Y, G0, bar, term)
                    return
            stop = self.control is not None and self.control.stop_requested
            if status == C.PAUSE and pending < self.chunk and not stop:
                continue
            rows = int(ints[C.I_WRITTEN])
            self._drain(rec, bufs, prog, fs, ints, Y, G0, bar)
            pending = 0
            if status == C.DONE:
                return
            if status < 0:
                raise self._failure(status, prog, fs, ints)
            if status == C.FULL and rows == 0:  # one step has more outputs than room
                cap = 2 * int(ints[C.I_NEED]) + cap
                bufs = self._buffers(cap, n, p.layout.n_rigid, prog.n_aux)
            self._after_chunk()

    def _drain(
        self,
        rec: _Recorder,
        bufs: _Buffers,
        prog: _program.Program,
        fs: FloatArray,
        ints: np.ndarray,
        Y: FloatArray,
        G0: FloatArray,
        bar: _Progress,
        term: EventRecord | None = None,
    ) -> None:
        """The buffered outputs to the recorder and the loop's state to ``self`` (counters,
        time, the checkpoint's step). With a terminal event ``term``: only the outputs
        before it, then its state, where the run ends."""
        C = _compiled
        rows = int(ints[C.I_WRITTEN])
        dropped = 0
        if rows:
            block = self._block(rows, bufs, prog)
            if term is not None:
                keep = block["t"] < term.t
                dropped = rows - int(keep.sum())
                block = {name: col[keep] for name, col in block.items()}
            rec.add_block(block)
        ints[C.I_WRITTEN] = 0
        self.n_rhs = int(ints[C.I_RHS])
        self.n_steps = int(ints[C.I_STEPS])
        self.n_rejected = int(ints[C.I_REJECTED])
        h = float(fs[C.F_H])
        if term is not None:
            rec.add(term.state)
            out_i = 0 if self.run_args.outs is None else int(ints[C.I_OUT]) - dropped
            self.at = (self.p.pack(term.state), term.state.g.copy(), h, out_i)
            self.t = term.t
            self.terminal = term
        else:
            self.t = float(fs[C.F_T])
            if ints[C.I_STARTED]:
                self.at = (Y.copy(), G0.copy(), h, int(ints[C.I_OUT]))
        bar.update(self.t)

    def _step_events(
        self,
        rec: _Recorder,
        prog: _program.Program,
        start: tuple[float, FloatArray, FloatArray, FloatArray | None],
        fs: FloatArray,
        ints: np.ndarray,
        Y: FloatArray,
        G0: FloatArray,
    ) -> EventRecord | None:
        """The events of the step just accepted, from ``start`` (t, Y, G0, f0) to the loop's
        (fs[F_T], Y, G0): each whose value changed sign (in its direction) is located and
        recorded in ``rec.events``, in time order. Returns the first terminal one (the run
        ends there; recorded events after it are dropped), or None."""
        p = self.p
        t1 = float(fs[_compiled.F_T])
        end = p.adopt(t1, Y, G0)
        values = [event_value(e, t1, end) for e in self.events]
        crossed = []
        for e, g0, g1 in zip(self.events, self.g_prev, values, strict=True):
            rising, falling = g0 < 0.0 <= g1, g0 > 0.0 >= g1
            if (rising and e.direction >= 0) or (falling and e.direction <= 0):
                crossed.append((e, 1 if rising else -1))
        self.g_prev = values
        if not crossed:
            return None
        at = self._continuous(prog, start, t1, fs, ints)
        found = []
        for e, way in crossed:
            t_e = self._locate(e, at, start[0], t1)
            found.append(EventRecord(e.name, t_e, way, e.terminal, at(t_e)))
        found.sort(key=lambda r: (r.t, r.terminal))
        term = next((r for r in found if r.terminal), None)
        if term is None:
            rec.events.extend(found)
            return None
        rec.events.extend(r for r in found if r.t <= term.t and not r.terminal)
        rec.events.append(term)
        return term

    def _continuous(
        self,
        prog: _program.Program,
        start: tuple[float, FloatArray, FloatArray, FloatArray | None],
        t1: float,
        fs: FloatArray,
        ints: np.ndarray,
    ) -> Any:
        """The state at any time of the step [start t, t1] as a function of t: DOP853's
        continuous extension, or a step of the method from the step's start for methods
        without one. The step is taken again by the loop's own helpers (_event_step)."""
        from gmuk.engine.integrators import _event_step

        t0, Y0, G0, f0 = start
        p, m = self.p, prog.method
        n = Y0.size
        fs_x, ints_x = fs.copy(), ints.copy()  # scratch: the run's counters stay the loop's
        ints_x[_compiled.I_RHS] = 0

        def check(status: int) -> None:
            self.n_event_rhs += int(ints_x[_compiled.I_RHS])
            ints_x[_compiled.I_RHS] = 0
            if status != _compiled.DONE:
                raise self._failure(status, prog, fs_x, ints_x)

        if f0 is None:  # the first step of a run: f at its start, as the loop's start has it
            f0 = np.empty(n)
            ints_x[_compiled.I_RHS] += 1
            check(_compiled.rhs(t0, Y0, G0, prog.parts, f0, np.empty(prog.n_aux), ints_x))
        K = np.empty((max(m.n_rows, m.n_stages + 1), n))
        Y1 = np.empty(n)
        h = t1 - t0
        if m.dense:
            F = np.empty((INTERPOLATOR_POWER, n))
            check(_event_step.dense_step(prog.parts, m, fs_x, ints_x, t0, h, Y0, G0, f0, K, Y1, F))

            def at(t: float) -> State:
                u = np.empty(n)
                _event_step.interpolate(F, Y0, (t - t0) / h, u)
                return p.adopt(t, u, G0)

            return at

        def at_stepped(t: float) -> State:
            if t == t0:
                return p.adopt(t, Y0, G0)
            Yt = np.empty(n)
            check(
                _event_step.method_step(prog.parts, m, fs_x, ints_x, t0, t - t0, Y0, G0, f0, K, Yt)
            )
            return p.adopt(t, Yt, G0)

        return at_stepped

    @staticmethod
    def _locate(event: Event, at: Any, t0: float, t1: float) -> float:
        """The time in [t0, t1] where ``event`` crosses zero along ``at`` (Brent, XTOL)."""
        from scipy.optimize import brentq

        def g(t: float) -> float:
            return event_value(event, t, at(t))

        ga, gb = g(t0), g(t1)
        if gb == 0.0 or ((ga > 0.0) == (gb > 0.0) and ga != 0.0):
            return t1  # the crossing is at the step's end, within the interpolant's round-off
        if ga == 0.0:
            return t0
        return float(brentq(g, t0, t1, xtol=XTOL))

    def _failure(
        self, status: int, prog: _program.Program, fs: FloatArray, ints: np.ndarray
    ) -> BaseException:
        """The exception that reports a failed chunk."""
        t_bad = float(fs[_compiled.F_BAD_T])
        if status == _compiled.CALLBACK:
            error, prog.python.error = prog.python.error, None
            if error is not None:
                return error
            return _loop_failure(f"a part evaluated in Python failed at t = {t_bad:.9g} s")
        if status == _compiled.UNDERFLOW:
            return _loop_failure(f"step size underflow (h = {float(fs[_compiled.F_H]):.3g} s)")
        if status == _compiled.MAX_STEPS:
            return _loop_failure(f"reached max_steps = {self.run_args.max_steps}")
        if status == _compiled.FIELD:
            return self._field_failure(prog, t_bad, int(ints[_compiled.I_FIELD]))
        return _loop_failure(
            f"non-finite derivative or output (accelerations, constraint forces, multipliers "
            f"or the solve's residual) at t = {t_bad:.9g} s"
        )

    def _field_failure(self, prog: _program.Program, t_bad: float, code: int) -> BaseException:
        """A compiled force kernel's failure, described by the model that failed: the
        System's Python accelerations at the failing stage (which the loop left in the
        program's ``io``) raise the model's own error."""
        try:
            self.p.system.accelerations(prog.python.state())
        except Exception as exc:  # the model's own description
            return exc
        return _loop_failure(
            f"a compiled part's kernel failed (status {code}) at t = {t_bad:.9g} s; its Python "
            "form raised nothing there (a field evaluated inside its body, or a kernel the "
            "loop does not know?)"
        )

    @staticmethod
    def _buffers(cap: int, n: int, nr: int, n_aux: int) -> _Buffers:
        return np.empty(cap), np.empty((cap, n)), np.empty((cap, nr, 4, 4)), np.empty((cap, n_aux))
