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
"""

from __future__ import annotations

import contextvars
import hashlib
import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import real_number
from gmuk.errors import FileFormatError, GmukError

if TYPE_CHECKING:
    from gmuk.state import State
    from gmuk.trajectory import Trajectory

__all__ = ["CheckpointError", "RunControl", "current", "run_control"]

#: Version of the checkpoint record in ``stats["checkpoint"]``.
CHECKPOINT_VERSION = 1


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
    checkpoint_dir: str | Path | None = None, *, every_s: float = 60.0, resume: bool = False
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
    """
    every = real_number(every_s, "every_s", positive=True, allow_inf=True)
    folder = None
    if checkpoint_dir is not None:
        folder = Path(checkpoint_dir)
        folder.mkdir(parents=True, exist_ok=True)
    control = RunControl(folder, every, bool(resume))
    token = _CURRENT.set(control)
    try:
        yield control
    finally:
        _CURRENT.reset(token)


def fingerprint(state0: State, settings: dict[str, Any], outs: np.ndarray | None) -> str:
    """A hash of what determines a simulation: bodies, initial state, span, output times,
    method and tolerances."""
    h = hashlib.sha256()
    lay = state0.layout
    h.update(repr((lay.names, tuple(map(str, lay.kinds)), lay.dofs, lay.n_control)).encode())
    h.update(repr(sorted(settings.items())).encode())
    for arr in (state0.g, state0.V, state0.x, state0.xdot, state0.z):
        h.update(np.ascontiguousarray(arr, dtype=float).tobytes())
    if outs is not None:
        h.update(np.ascontiguousarray(outs).tobytes())
    return h.hexdigest()


def save(path: Path, traj: Trajectory, record: dict[str, Any]) -> None:
    """Write ``traj`` with the integrator's ``record`` as a checkpoint (atomically)."""
    traj.stats["checkpoint"] = {"version": CHECKPOINT_VERSION, **record}
    try:
        traj.save(path)
    finally:
        traj.stats.pop("checkpoint", None)


def load(path: Path, expected: str) -> tuple[Trajectory, dict[str, Any]]:
    """A checkpoint's trajectory and record, checked to belong to the simulation whose
    fingerprint is ``expected``."""
    from gmuk.trajectory import load_trajectory

    try:
        traj = load_trajectory(path)
    except FileFormatError as exc:
        raise CheckpointError(f"cannot resume from {path}: {exc}") from None
    record = traj.stats.pop("checkpoint", None)
    if not isinstance(record, dict) or record.get("version") != CHECKPOINT_VERSION:
        raise CheckpointError(f"{path}: not a gmuk checkpoint (version {CHECKPOINT_VERSION})")
    if record.get("fingerprint") != expected:
        raise CheckpointError(
            f"{path}: the checkpoint was written by a different simulation (bodies, initial "
            "state, times, method or tolerances differ); resume with the options the run was "
            "started with, or start afresh without --resume"
        )
    for key in ("t", "h", "out_i", "Y", "G0", "complete"):
        if key not in record:
            raise CheckpointError(f"{path}: checkpoint record lacks {key!r}")
    if not (math.isfinite(record["t"]) and record["h"] > 0):
        raise CheckpointError(f"{path}: checkpoint record is not usable: t or h invalid")
    return traj, record
