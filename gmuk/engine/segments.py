"""Runs made of consecutive segments: the outputs to keep of each segment, and one Trajectory
of them all.

A run that must stop and start again — at an impact
(:func:`gmuk.engine.contact.simulate_with_impacts`) or where a thruster's valve opens or closes
(:func:`gmuk.actuators.simulate_pulsed`) — integrates one segment at a time, each from the last
state of the one before, changed by what happened at the boundary. Each segment ends at the
boundary; the joined Trajectory keeps one output per time: the state *after* the boundary (the
next segment's first) when every step is output, only the requested times when ``t_eval`` was
given.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.trajectory import EventRecord, Trajectory

__all__ = ["join", "segment_times", "trimmed"]


def segment_times(times: FloatArray | None, a: float, b: float, first: bool) -> FloatArray | None:
    """The ``t_eval`` of the segment [a, b] of a run asked for ``times`` (None: every step):
    the requested times in (a, b] (in [a, b] for the first segment), and b itself, which the
    next segment starts from (:func:`trimmed` drops it again unless it was requested)."""
    if times is None:
        return None
    inside = times[((times >= a) if first else (times > a)) & (times <= b)]
    return inside if inside.size and inside[-1] == b else np.append(inside, b)


def trimmed(traj: Trajectory, times: FloatArray | None, drop_last: bool) -> Trajectory:
    """The outputs of one segment to keep: without its last state when ``drop_last`` (the
    next segment starts from the state after the boundary), and only the requested
    ``times`` when they were given."""
    n = len(traj)
    keep = np.ones(n, dtype=bool)
    if drop_last and n:
        keep[-1] = False
    if times is not None:
        keep &= np.isin(traj.t, times)
    fields: dict[str, Any] = {}
    for f in dataclasses.fields(Trajectory):
        value = getattr(traj, f.name)
        if isinstance(value, np.ndarray) and value.shape[:1] == (n,):
            fields[f.name] = value[keep]
    return dataclasses.replace(traj, **fields)


def join(
    parts: Sequence[Trajectory],
    *,
    stats: dict[str, Any] | None = None,
    events: Sequence[EventRecord] | None = None,
) -> Trajectory:
    """One trajectory of consecutive segments: their time-major fields concatenated, the
    step counts summed, the last segment's status and message (even when it kept no output:
    an interrupted or failed last piece), its other ``stats`` updated with ``stats``, and the
    segments' events in time order (or ``events`` when given)."""
    last = parts[-1]
    kept = [p for p in parts if len(p)] or [last]
    first = kept[0]
    fields: dict[str, Any] = {}
    for f in dataclasses.fields(Trajectory):
        value = getattr(first, f.name)
        if isinstance(value, np.ndarray) and value.shape[:1] == first.t.shape[:1]:
            fields[f.name] = np.concatenate([getattr(p, f.name) for p in kept])
    merged = dict(last.stats)
    for key in ("n_rhs", "n_steps", "n_rejected"):
        if all(key in p.stats for p in parts):
            merged[key] = sum(int(p.stats[key]) for p in parts)
    merged.update(stats or {})
    found = tuple(e for p in parts for e in p.events) if events is None else tuple(events)
    return dataclasses.replace(last, **fields, stats=merged, events=found)
