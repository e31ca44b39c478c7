"""Stopping, checkpointing and resuming the simulations of a run.

Inside ``with run_control(...)``, every :func:`gmuk.engine.integrate.simulate` call (numbered 0, 1,
2, … in call order, so a scenario that runs several simulations gets one file each):

* stops at the next step once :meth:`RunControl.request_stop` has been called (a signal
  handler's job) and returns the trajectory so far with ``status="interrupted"``; a call that
  starts after the request returns at once, with its initial state only;
* with a ``checkpoint_dir``, writes its trajectory so far and the integrator's state to
  ``checkpoint_dir/run-<k>.npz`` every ``every_s`` seconds of wall time, when it stops, and
  when it ends (then marked complete) — each file written atomically, so a killed process
  loses at most one interval;
* with ``resume=True``, returns the trajectory of a complete checkpoint without integrating,
  and continues a partial one from its last step. A checkpoint of a different simulation (other
  bodies, times, method, tolerances or initial state) is refused, never continued.

``gmuk run NAME --out DIR`` uses this (checkpoints in ``DIR/.checkpoints``, removed after a
run that completes); ``gmuk run --resume DIR`` continues an interrupted or killed run with
the options it was started with.

A checkpoint is a trajectory file (:func:`gmuk.load_trajectory` reads it) whose
``stats["checkpoint"]`` holds the integrator's state as JSON (floats round-trip exactly). A
resumed run takes the same steps as an uninterrupted one except that the first step after the
resume recomputes the derivative at the base pose, where the uninterrupted run reuses the one
of the step before: the results agree to the integrator's tolerance, not bit for bit.

A checkpoint is trusted only as far as it can be checked. :func:`save` seals it with a
SHA-256 checksum over its record and its trajectory (every array, the status, message, bodies
and stats); :func:`load` refuses, with a :class:`CheckpointError` that says why, a file whose
checksum does not match (edited by hand or corrupted), a checkpoint of another simulation (its
:func:`fingerprint` differs), and a record that contradicts itself or the run it would
continue: a time ``t`` outside the span ``[t0, t_end]``, a step ``h`` that is not a finite
positive number, an output index ``out_i`` outside ``[0, len(t_eval)]`` or not equal to the
number of rows written (whose times must be ``t_eval[:out_i]``), rows after ``t``, ``complete``
without ``t == t_end`` and status ``"success"`` (or, status ``"terminated"``, a terminal event at
``t`` that is the last row), a base pose or state of the wrong size or not finite, other bodies
than the run's. Nothing is resumed silently wrong.

Events (:mod:`gmuk.engine.events`) are part of a checkpoint: those located up to its step are
in its trajectory (``traj.events``, covered by the checksum) and a resumed run appends the later
ones, each once; the events (their class, name, direction and terminal flag) are in the
fingerprint, so a run resumed with other events is refused.
"""

from __future__ import annotations

import contextvars
import hashlib
import json
import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._locks import FolderInUseError
from gmuk._validation import real_number
from gmuk.errors import FileFormatError, GmukError

if TYPE_CHECKING:
    from gmuk.state import State
    from gmuk.trajectory import Trajectory

__all__ = [
    "CheckpointError",
    "Fingerprint",
    "FolderInUseError",
    "RunControl",
    "current",
    "run_control",
]

#: Version of the checkpoint record in ``stats["checkpoint"]`` (2: sealed with ``sha256``).
CHECKPOINT_VERSION = 2


class CheckpointError(GmukError, ValueError):
    """A checkpoint that cannot be used to resume this simulation."""


@dataclass
class RunControl:
    """The stop request, checkpoint folder and resume flag of the simulations of a run
    (see the module docstring). Made by :func:`run_control`."""

    checkpoint_dir: Path | None = None
    every_s: float = 60.0
    resume: bool = False
    stop_requested: bool = False
    calls: int = 0
    written: list[Path] = field(default_factory=list)
    #: Events (gmuk.Event) added to every simulation of the run (``gmuk run --stop-at``).
    events: tuple[Any, ...] = ()

    def request_stop(self) -> None:
        """Ask the running simulation (and every later one) to stop at its next step."""
        self.stop_requested = True

    def next_path(self) -> Path | None:
        """The checkpoint file of the next simulation call (and count the call)."""
        k = self.calls
        self.calls += 1
        if self.checkpoint_dir is None:
            return None
        return self.checkpoint_dir / f"run-{k}.npz"


_CURRENT: contextvars.ContextVar[RunControl | None] = contextvars.ContextVar(
    "gmuk_run_control", default=None
)


def current() -> RunControl | None:
    """The RunControl of the enclosing :func:`run_control`, if any."""
    return _CURRENT.get()


@contextmanager
def run_control(
    checkpoint_dir: str | Path | None = None,
    *,
    every_s: float = 60.0,
    resume: bool = False,
    events: Any = None,
) -> Iterator[RunControl]:
    """Stop requests, periodic checkpoints and resuming for the simulations run inside.

    Parameters
    ----------
    checkpoint_dir : str or Path, optional
        Folder for the checkpoints (made if missing); None: no checkpoints.
    every_s : float
        Wall-time interval between checkpoints (s), > 0.
    resume : bool
        Use the checkpoints found in ``checkpoint_dir``.
    events : Event or sequence of Event, optional
        Events (:class:`gmuk.Event`) added to the events of every simulation inside (a
        checkpoint records them in its fingerprint: resume with the same ones).
    """
    from gmuk.engine.events import check_events

    every = real_number(every_s, "every_s", positive=True, allow_inf=True)
    folder = None
    if checkpoint_dir is not None:
        folder = Path(checkpoint_dir)
        folder.mkdir(parents=True, exist_ok=True)
    control = RunControl(folder, every, bool(resume), events=check_events(events))
    token = _CURRENT.set(control)
    try:
        yield control
    finally:
        _CURRENT.reset(token)


class Fingerprint(str):
    """A simulation's fingerprint: the hex digest of :func:`fingerprint` (a ``str``), carrying
    what :func:`load` checks a checkpoint's record against.

    Parameters
    ----------
    digest : str
        The SHA-256 hex digest.
    t_span : tuple of float
        The run's span (t0, t_end) (s); kept as ``t0`` and ``t_end``.
    outs : ndarray (n_out,) or None
        The output times (s); None: every step is an output.
    bodies : tuple
        The body names, kinds and dofs.
    g_shape : tuple of int
        The shape of the base poses, (n_rigid, 4, 4).
    """

    t0: float
    t_end: float
    outs: np.ndarray | None
    bodies: tuple[tuple[str, ...], tuple[str, ...], tuple[int, ...]]
    g_shape: tuple[int, ...]

    def __new__(
        cls,
        digest: str,
        *,
        t_span: tuple[float, float],
        outs: np.ndarray | None,
        bodies: tuple[tuple[str, ...], tuple[str, ...], tuple[int, ...]],
        g_shape: tuple[int, ...],
    ) -> Fingerprint:
        self = super().__new__(cls, digest)
        self.t0, self.t_end = float(t_span[0]), float(t_span[1])
        self.outs = None if outs is None else np.asarray(outs, dtype=float).reshape(-1)
        self.bodies = bodies
        self.g_shape = tuple(g_shape)
        return self


def fingerprint(state0: State, settings: dict[str, Any], outs: np.ndarray | None) -> Fingerprint:
    """A hash of what determines a simulation: bodies, initial state, span, output times,
    method and tolerances (``settings`` holds ``t_span`` and the method's settings)."""
    h = hashlib.sha256()
    lay = state0.layout
    h.update(repr((lay.names, tuple(map(str, lay.kinds)), lay.dofs, lay.n_control)).encode())
    h.update(repr(sorted(settings.items())).encode())
    for arr in (state0.g, state0.V, state0.x, state0.xdot, state0.z):
        h.update(np.ascontiguousarray(arr, dtype=float).tobytes())
    if outs is not None:
        h.update(np.ascontiguousarray(outs).tobytes())
    t_span = settings.get("t_span", (state0.t, math.inf))
    bodies = (
        tuple(lay.names),
        tuple(getattr(k, "value", str(k)) for k in lay.kinds),
        tuple(int(d) for d in lay.dofs),
    )
    return Fingerprint(
        h.hexdigest(), t_span=t_span, outs=outs, bodies=bodies, g_shape=np.shape(state0.g)
    )


def checksum(traj: Trajectory, record: dict[str, Any]) -> str:
    """SHA-256 (hex) of a checkpoint: its ``record`` (without ``sha256``) and ``traj`` — every
    array with its shape, the status, message, bodies and stats (without the record)."""
    from gmuk.trajectory import _ARRAYS

    meta = {
        "record": {k: v for k, v in record.items() if k != "sha256"},
        "status": traj.status,
        "message": traj.message,
        "bodies": [list(traj.body_names), list(traj.body_kinds), list(traj.body_dofs)],
        "stats": {k: v for k, v in traj.stats.items() if k != "checkpoint"},
    }
    if traj.events:  # as saved (gmuk.trajectory._event_meta), states included
        from gmuk.trajectory import _event_meta

        meta["events"] = [_event_meta(e) for e in traj.events]
    # as the file holds it: JSON (tuples become lists, keys strings), then in canonical order
    text = json.dumps(json.loads(json.dumps(meta, default=str)), sort_keys=True)
    h = hashlib.sha256(text.encode())
    for name in _ARRAYS:
        arr = np.asarray(getattr(traj, name))
        little = np.ascontiguousarray(arr, dtype=arr.dtype.newbyteorder("<"))
        h.update(f"|{name}|{little.dtype.str}|{arr.shape}|".encode())
        h.update(little.tobytes())
    return h.hexdigest()


def save(path: Path, traj: Trajectory, record: dict[str, Any]) -> None:
    """Write ``traj`` with the integrator's ``record`` as a checkpoint (atomically), sealed
    with its :func:`checksum` in ``record["sha256"]``."""
    full = {"version": CHECKPOINT_VERSION, **record}
    full.pop("sha256", None)
    full["sha256"] = checksum(traj, full)
    traj.stats["checkpoint"] = full
    try:
        traj.save(path)
    finally:
        traj.stats.pop("checkpoint", None)


def load(path: Path, expected: str) -> tuple[Trajectory, dict[str, Any]]:
    """A checkpoint's trajectory and record, checked to be what gmuk wrote (its checksum), to
    belong to the simulation whose fingerprint is ``expected``, and (when ``expected`` is a
    :class:`Fingerprint`) to be consistent with that simulation's span and output times.

    Raises
    ------
    CheckpointError
        For any of the failures listed in the module docstring; the message names the file
        and what is wrong.
    """
    from gmuk.trajectory import load_trajectory

    try:
        traj = load_trajectory(path)
    except FileFormatError as exc:
        raise CheckpointError(f"cannot resume from {path}: {exc}") from None
    record = traj.stats.pop("checkpoint", None)
    if not isinstance(record, dict):
        raise CheckpointError(f"{path}: not a gmuk checkpoint (no checkpoint record)")
    version = record.get("version")
    if version != CHECKPOINT_VERSION:
        why = (
            "written by an older gmuk, without a checksum"
            if isinstance(version, int) and not isinstance(version, bool) and version < 2
            else f"checkpoint version {version!r}; this gmuk reads {CHECKPOINT_VERSION}"
        )
        raise CheckpointError(
            f"{path}: cannot resume from this checkpoint ({why}); start the run afresh "
            "without --resume"
        )
    stored = record.pop("sha256", None)
    if not isinstance(stored, str) or stored != checksum(traj, record):
        raise CheckpointError(
            f"{path}: the checkpoint's checksum does not match its contents: the file was "
            "changed after gmuk wrote it (edited, or corrupted); it is not resumed. Start the "
            "run afresh without --resume"
        )
    if record.get("fingerprint") != expected:
        raise CheckpointError(
            f"{path}: the checkpoint was written by a different simulation (bodies, initial "
            "state, times, method or tolerances differ); resume with the options the run was "
            "started with, or start afresh without --resume"
        )
    _check_record(path, traj, record, expected)
    return traj, record


def _is_real(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _is_count(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _check_record(path: Path, traj: Trajectory, record: dict[str, Any], expected: str) -> None:
    """The record's fields have their types and agree with each other, with the checkpoint's
    rows and with the run ``expected`` describes (module docstring)."""

    def bad(why: str) -> CheckpointError:
        return CheckpointError(f"{path}: checkpoint record is not consistent: {why}; not resumed")

    for key in ("t", "h", "out_i", "Y", "G0", "complete"):
        if key not in record:
            raise CheckpointError(f"{path}: checkpoint record lacks {key!r}")
    t, h, out_i, complete = record["t"], record["h"], record["out_i"], record["complete"]
    if not _is_real(t):
        raise bad(f"t must be a finite time (s); got {t!r}")
    if not (_is_real(h) and h > 0):
        raise bad(f"h must be a finite step > 0 (s); got {h!r}")
    if not _is_count(out_i):
        raise bad(f"out_i must be an integer ≥ 0; got {out_i!r}")
    if not isinstance(complete, bool):
        raise bad(f"complete must be true or false; got {complete!r}")
    for key in ("n_steps", "n_rejected", "n_rhs"):
        if key in record and not _is_count(record[key]):
            raise bad(f"{key} must be an integer ≥ 0; got {record[key]!r}")
    for key in ("Y", "G0"):
        values = record[key]
        if not (isinstance(values, list) and all(_is_real(v) for v in values)):
            raise bad(f"{key} must be a list of finite numbers")
    terminated = traj.status == "terminated"
    if complete != (traj.status in ("success", "terminated")):
        raise bad(f"complete is {complete} but the trajectory's status is {traj.status!r}")
    if terminated and not (traj.events and traj.events[-1].terminal and traj.events[-1].t == t):
        raise bad(f"status 'terminated' but no terminal event at t = {t!r} s")
    times = np.asarray(traj.t, dtype=float)
    if times.size > 1 and np.any(np.diff(times) < 0):
        raise bad("the checkpoint's output times run backwards")
    if not isinstance(expected, Fingerprint):
        return
    t0, t_end = expected.t0, expected.t_end
    if not t0 <= t <= t_end:
        raise bad(f"t = {t!r} s is outside the run's span [{t0!r}, {t_end!r}] s")
    if complete and t != t_end and not terminated:
        raise bad(f"complete is true but t = {t!r} s, not the end of the span {t_end!r} s")
    bodies = (tuple(traj.body_names), tuple(traj.body_kinds), tuple(traj.body_dofs))
    if bodies != expected.bodies:
        raise bad("its bodies are not the run's")
    if len(record["G0"]) != math.prod(expected.g_shape):
        raise bad(
            f"G0 has {len(record['G0'])} entries; the run's base poses have "
            f"{math.prod(expected.g_shape)}"
        )
    rows = times.size
    if rows and (times[0] < t0 or times[-1] > t_end):
        raise bad("its output times leave the run's span")
    outs = expected.outs
    if outs is None:  # every step is an output: rows from t0 to t, out_i unused
        if out_i != 0:
            raise bad(f"out_i = {out_i} for a run without t_eval (expected 0)")
        if rows and times[-1] != t:
            raise bad(f"the last row is at {times[-1]!r} s but t = {t!r} s")
        return
    if out_i > outs.size:
        raise bad(f"out_i = {out_i} is beyond the run's {outs.size} output times")
    if terminated:  # the outputs before the terminal event, then the event's state at t
        if rows != out_i + 1 or not np.array_equal(times[:-1], outs[:out_i]) or times[-1] != t:
            raise bad("its rows are not the output times before the terminal event and t")
        return
    if rows != out_i or not np.array_equal(times, outs[:out_i]):
        raise bad(
            f"out_i = {out_i} but the checkpoint holds {rows} rows"
            if rows != out_i
            else "its rows are not at the run's output times t_eval[:out_i]"
        )
    if out_i < outs.size and not outs[out_i] > t:
        raise bad(
            f"out_i = {out_i} skips the output time {outs[out_i]!r} s, which is not after "
            f"t = {t!r} s"
        )
    if complete and out_i != outs.size:
        raise bad(f"complete is true but only {out_i} of {outs.size} outputs were written")
