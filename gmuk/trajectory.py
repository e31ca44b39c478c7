"""Trajectory: the time-major record of a simulation, with per-body views and save/load.

Arrays are time-first: ``t`` (N,), ``g_NB`` (N, n_rigid, 4, 4), ``V_B`` (N, n_rigid, 6),
point-mass and slack coordinates ``x``/``xdot`` (N, n_euclid), controller states ``z``
(N, n_control), and the recorded generalized quantities (N, n_dof) in System body order:
``acceleration``, ``constraint_acceleration``, ``constraint_force`` (M ν̇_c: the constraint
wrench [L; f] of each rigid body in its body frame), ``control_force`` and
``unmodeled_force``; ``multipliers`` (N, s), ``residual`` (N,), ``rank`` (N,; −1 where not
computed).
"""

from __future__ import annotations

import functools
import json
import math
import os
import tempfile
import zipfile
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from gmuk._validation import FloatArray, strict_integer
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError, FileFormatError
from gmuk.lie import euler, so3
from gmuk.state import Layout, State

__all__ = ["BodyTrajectory", "EventRecord", "Trajectory", "load_trajectory"]

#: The version of the ``.npz`` format :meth:`Trajectory.save` writes. 2 added the ``r_N`` and
#: ``v_N`` copies of the point masses' states; :func:`load_trajectory` reads 1 and 2.
FORMAT_VERSION = 2
_ARRAYS = (
    "t",
    "g_NB",
    "V_B",
    "x",
    "xdot",
    "z",
    "acceleration",
    "constraint_acceleration",
    "constraint_force",
    "control_force",
    "unmodeled_force",
    "multipliers",
    "residual",
    "rank",
)


@dataclass(frozen=True, eq=False)
class EventRecord:
    """One located event of a run (:class:`gmuk.Event`, :func:`gmuk.engine.integrate.simulate`).

    Attributes
    ----------
    name : str
        The event's name.
    t : float
        The crossing time (s), located to 1e-13 s (or 4 ε abs(t)) on the step's continuous
        extension.
    direction : int
        +1: the function rose through zero; -1: it fell.
    terminal : bool
        Whether the event ended the run (then its state is the trajectory's last output).
    state : State
        The state at ``t`` (from the step's continuous extension).
    """

    name: str
    t: float
    direction: int
    terminal: bool
    state: State

    def to_dict(self) -> dict[str, Any]:
        """The event without its state, as JSON-ready values (``summary.json``)."""
        return {"name": self.name, "t": self.t, "direction": self.direction,
                "terminal": self.terminal}  # fmt: skip

    def __repr__(self) -> str:
        kind = "terminal" if self.terminal else "recorded"
        way = "rising" if self.direction > 0 else "falling"
        return f"EventRecord({self.name!r}, t={self.t!r} s, {way}, {kind})"


@dataclass(frozen=True, eq=False, repr=False)
class Trajectory:
    """The result of :meth:`gmuk.System.simulate`.

    ``print(traj)`` (and its ``repr``) is a summary of one screen: status, samples and time
    span, bodies, constraint rows, the largest residual, the drift check, how it was
    integrated, and the size of its arrays (see :meth:`summary`).

    Attributes
    ----------
    t : ndarray (N,)
        Times (s).
    g_NB : ndarray (N, n_rigid, 4, 4)
        Poses of the rigid bodies.
    V_B : ndarray (N, n_rigid, 6)
        Body twists [ω; v] (rad/s, m/s).
    x, xdot : ndarray (N, n_euclid)
        Point-mass positions r_N (m) / slack values, and their rates.
    z : ndarray (N, n_control)
        Controllers' internal states.
    acceleration, constraint_acceleration : ndarray (N, n_dof)
        Total acceleration ν̇ and constraint acceleration ν̇_c (Eq. 64).
    constraint_force, control_force, unmodeled_force : ndarray (N, n_dof)
        Constraint force M ν̇_c = Aᵀλ; controller and unmodeled forces.
    multipliers : ndarray (N, s)
    residual : ndarray (N,)
        ‖A(ν̇_a + ν̇_c) − b‖ at each output.
    rank : ndarray (N,) of int
        Rank of A (−1 where not computed).
    body_names, body_kinds : tuple of str
    body_dofs : tuple of int
    status : {"success", "terminated", "drifted", "interrupted", "failed"}
        "terminated": a terminal event ended the run (the last of ``events``); "drifted":
        the run completed its span (or ended at a terminal event) but a constraint drifted off
        past ``drift_tol`` (:func:`gmuk.engine.integrate.simulate`); the message says which
        and when.
    message : str
    stats : dict
        ``n_rhs`` (right-hand-side evaluations), ``n_steps``, ``n_rejected``, ``method``;
        from :func:`gmuk.engine.integrate.simulate` also ``drifted`` (bool) and
        ``constraint_violation`` (the constraint check: largest residuals, tolerance, one
        entry per constraint).
    events : tuple of EventRecord
        The events located during the run (:class:`gmuk.Event`), in time order; a
        terminal one is last.
    """

    t: FloatArray
    g_NB: FloatArray
    V_B: FloatArray
    x: FloatArray
    xdot: FloatArray
    z: FloatArray
    acceleration: FloatArray
    constraint_acceleration: FloatArray
    constraint_force: FloatArray
    control_force: FloatArray
    unmodeled_force: FloatArray
    multipliers: FloatArray
    residual: FloatArray
    rank: np.ndarray
    body_names: tuple[str, ...]
    body_kinds: tuple[str, ...]
    body_dofs: tuple[int, ...]
    status: str = "success"
    message: str = ""
    stats: dict[str, Any] = field(default_factory=dict)
    events: tuple[EventRecord, ...] = ()

    @functools.cached_property
    def layout(self) -> Layout:
        """The body index of this trajectory (built once: every :meth:`state` shares it)."""
        kinds = tuple(BodyKind(k) for k in self.body_kinds)
        return Layout(self.body_names, kinds, self.body_dofs, self.z.shape[1])

    @property
    def success(self) -> bool:
        """Whether the run ended as asked on its constraints: at the end of its time span
        (status "success") or at a terminal event ("terminated"); not "drifted",
        "interrupted" or "failed"."""
        return self.status in ("success", "terminated")

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def summary(self, max_bodies: int = 8) -> str:
        """A summary of the run in at most 10 lines of at most ~100 characters.

        Parameters
        ----------
        max_bodies : int
            Bodies listed by name (the others are counted).

        Returns
        -------
        str
            Status, number of samples and time span (s); bodies with their kinds; constraint
            rows (columns of ``multipliers``) and the largest ``residual`` ‖A ν̇ − b‖; the
            drift check (largest position and velocity residuals, in each constraint's units,
            against ``drift_tol``) when recorded; method, tolerances, steps and loop when
            recorded; controller states; the size of the arrays; the message, if any.
        """
        n = len(self)
        span = f"t = {self.t[0]:.6g} … {self.t[-1]:.6g} s" if n else "no samples"
        lines = [f"<gmuk.Trajectory: {self.status}, {n} sample{'s' * (n != 1)}, {span}>"]

        def row(label: str, text: str) -> None:
            lines.append(f"{label + ':':<14}{text}")

        groups: dict[str, list[str]] = {}
        for i, (name, kind) in enumerate(zip(self.body_names, self.body_kinds, strict=True)):
            if i < max_bodies:
                groups.setdefault(kind, []).append(name)
        shown = "; ".join(f"{', '.join(names)} ({kind})" for kind, names in groups.items())
        more = len(self.body_names) - max_bodies
        row(f"Bodies ({len(self.body_names)})", shown + (f"; … +{more} more" if more > 0 else ""))
        finite = self.residual[np.isfinite(self.residual)]
        largest = f"{finite.max():.2e}" if finite.size else "n/a"
        s_rows = self.multipliers.shape[1]
        rows = f"{s_rows} row{'s' * (s_rows != 1)}, largest residual ‖A ν̇ − b‖ {largest}"
        row("Constraints", rows if s_rows else "none")
        check = self.stats.get("constraint_violation")
        if isinstance(check, dict) and check.get("constraints"):
            tol = check.get("tolerance")
            verdict = "drifted" if check.get("drifted") else "held"
            against = "not judged" if tol is None else f"drift_tol {tol:g}: {verdict}"
            row(
                "Drift check",
                f"position ≤ {_brief(check.get('position'))}, velocity ≤ "
                f"{_brief(check.get('velocity'))} ({len(check['constraints'])} checked; {against})",
            )
        how = []
        if "method" in self.stats:
            how.append(str(self.stats["method"]))
        if "rtol" in self.stats and "atol" in self.stats:
            how.append(f"rtol {self.stats['rtol']:g}, atol {self.stats['atol']:g}")
        if "compiled" in self.stats:
            how.append("compiled loop" if self.stats["compiled"] else "Python loop")
        if how:
            row("Integration", ", ".join(how))
        if "n_steps" in self.stats:
            steps = f"{self.stats['n_steps']} ({self.stats.get('n_rejected', 0)} rejected)"
            if "n_rhs" in self.stats:
                steps += f", {self.stats['n_rhs']} evaluations of the dynamics"
            row("Steps", steps)
        if self.events:
            names: dict[str, int] = {}
            for e in self.events:
                names[e.name] = names.get(e.name, 0) + 1
            listed = ", ".join(f"{k} ×{v}" if v > 1 else k for k, v in names.items())
            last = self.events[-1]
            end = f"; ended by {last.name!r} at t = {last.t:.9g} s" if last.terminal else ""
            row("Events", f"{len(self.events)} ({listed}){end}")
        if self.z.shape[1]:
            row("Controllers", f"{self.z.shape[1]} internal states (z)")
        nbytes = sum(getattr(self, k).nbytes for k in _ARRAYS)
        row("Size", f"{_size(nbytes)} in {len(_ARRAYS)} arrays")
        if self.message:
            text = " ".join(self.message.split())
            row("Message", text if len(text) <= 160 else text[:159] + "…")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return self.summary()

    __str__ = __repr__

    def _point_columns(self) -> np.ndarray:
        lay = self.layout
        idx = [
            lay.slot(name).index + np.arange(3)
            for name, kind in zip(self.body_names, self.body_kinds, strict=True)
            if kind == BodyKind.POINT
        ]
        return np.array(idx, dtype=np.int64).reshape(-1, 3)

    @property
    def r_N(self) -> FloatArray:
        """Positions of the point masses, shape (N, n_point, 3), in N (m), in body order."""
        return self.x[:, self._point_columns()]

    @property
    def v_N(self) -> FloatArray:
        """Velocities of the point masses, shape (N, n_point, 3), in N (m/s)."""
        return self.xdot[:, self._point_columns()]

    def state(self, i: int) -> State:
        """The State at output ``i`` (a copy; negative indices count from the end).

        ``i`` is an output index (an integer), not a time: a string, float, bool or
        sequence is a :class:`~gmuk.errors.DefinitionError`."""
        n = len(self)
        what = "Trajectory.state: i (an output index, not a time)"
        if isinstance(i, np.ndarray):  # even 0-d: an index is a number, not an array
            raise DefinitionError(f"{what} must be an integer; got an array {i!r:.60}")
        i = strict_integer(i, what)
        if not -n <= i < n:
            raise DefinitionError(f"output index {i} out of range for {n} outputs")
        return State._adopt(  # fresh copies, which the State makes read-only and keeps
            float(self.t[i]),
            np.array(self.g_NB[i], dtype=np.float64),
            np.array(self.V_B[i], dtype=np.float64),
            np.array(self.x[i], dtype=np.float64),
            np.array(self.xdot[i], dtype=np.float64),
            np.array(self.z[i], dtype=np.float64),
            self.layout,
        )

    def body(self, name: str) -> BodyTrajectory:
        """Per-body view (positions, attitudes, rates, wrenches) of body ``name``."""
        if name not in self.body_names:
            raise DefinitionError(f"no body named {name!r}; bodies are {list(self.body_names)}")
        return BodyTrajectory(self, name)

    def save(self, path: str | Path) -> Path:
        """Save to a compressed ``.npz`` (arrays plus JSON metadata); returns the path.

        Besides the attributes, the file holds ``r_N`` and ``v_N`` (N, n_point, 3): the
        point masses' positions and velocities in body order (``meta["body_kinds"]``).

        The file is written atomically: to a temporary file in the same folder, then renamed
        over ``path``, so a run stopped while saving leaves the previous file (or none), never
        a half-written one.
        """
        path = Path(path)
        if path.suffix != ".npz":
            path = path.with_suffix(path.suffix + ".npz")
        meta = {
            "format_version": FORMAT_VERSION,
            "body_names": list(self.body_names),
            "body_kinds": list(self.body_kinds),
            "body_dofs": list(self.body_dofs),
            "status": self.status,
            "message": self.message,
            "stats": self.stats,
        }
        if self.events:
            meta["events"] = [_event_meta(e) for e in self.events]
        arrays = {k: getattr(self, k) for k in _ARRAYS}
        # Convenience copies for readers without gmuk: point masses as (N, n_point, 3).
        arrays["r_N"], arrays["v_N"] = self.r_N, self.v_N
        with atomic_write(path) as tmp:
            with open(tmp, "wb") as fh:
                np.savez_compressed(fh, meta=np.array(json.dumps(meta)), **arrays)
        return path

    def to_csv(self, path: str | Path) -> Path:
        """Write a CSV: t, then per rigid body position (m), 3-2-1 Euler angles (rad), ω and
        v (body frame); per point mass r_N and v_N; per slack value and rate."""
        cols: list[FloatArray] = [self.t[:, None]]
        header = ["t_s"]
        for name, kind in zip(self.body_names, self.body_kinds, strict=True):
            view = self.body(name)
            if kind == "rigid":
                cols += [view.position, view.euler("321"), view.omega, view.v]
                header += [
                    f"{name}.{q}"
                    for q in (
                        "x_m",
                        "y_m",
                        "z_m",
                        "psi_rad",
                        "theta_rad",
                        "phi_rad",
                        "wx_rad_s",
                        "wy_rad_s",
                        "wz_rad_s",
                        "vx_m_s",
                        "vy_m_s",
                        "vz_m_s",
                    )
                ]
            elif kind == "point":
                cols += [view.position, view.velocity]
                header += [
                    f"{name}.{q}" for q in ("x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s")
                ]
            else:
                cols += [view.position, view.velocity]
                header += [f"{name}.s", f"{name}.s_dot"]
        path = Path(path)
        np.savetxt(path, np.hstack(cols), delimiter=",", header=",".join(header), comments="")
        return path


def _event_meta(event: EventRecord) -> dict[str, Any]:
    """An event as the file's metadata holds it: JSON floats round-trip exactly."""
    st = event.state
    state = {k: np.asarray(getattr(st, k)).tolist() for k in ("g", "V", "x", "xdot", "z")}
    return {**event.to_dict(), "state": state}


def _brief(value: Any) -> str:
    """A residual of the drift check: 3 significant digits, or "n/a" for None."""
    return "n/a" if value is None else f"{value:.2e}"


def _size(nbytes: int) -> str:
    """A number of bytes in B, kB, MB or GB (powers of 1000)."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= scale:
            return f"{nbytes / scale:.1f} {unit}"
    return f"{nbytes} B"


@dataclass(frozen=True, eq=False)
class BodyTrajectory:
    """Time histories of one body of a :class:`Trajectory`."""

    traj: Trajectory
    name: str

    def __repr__(self) -> str:
        kind = self.traj.body_kinds[self.traj.body_names.index(self.name)]
        return f"<gmuk.BodyTrajectory {self.name!r} ({kind}), {len(self.traj)} samples>"

    def _slot(self) -> Any:
        return self.traj.layout.slot(self.name)

    def _dof_slice(self, arr: FloatArray) -> FloatArray:
        s = self._slot()
        return arr[:, s.offset : s.offset + s.dof]

    @property
    def position(self) -> FloatArray:
        """Position r_N (N, 3) (m); the value (N, 1) of a slack coordinate."""
        s = self._slot()
        if s.kind == "rigid":
            return self.traj.g_NB[:, s.index, :3, 3]
        return self.traj.x[:, s.index : s.index + s.dof]

    @property
    def velocity(self) -> FloatArray:
        """Inertial velocity v_N (N, 3) (m/s); the rate (N, 1) of a slack coordinate."""
        s = self._slot()
        if s.kind == "rigid":
            return np.einsum("nij,nj->ni", self.R, self.v)
        return self.traj.xdot[:, s.index : s.index + s.dof]

    @property
    def R(self) -> FloatArray:
        """Attitude R_NB (N, 3, 3) of a rigid body."""
        return self.traj.g_NB[:, self._rigid(), :3, :3]

    def euler(self, seq: str = "321") -> FloatArray:
        """Euler angles (N, 3) (rad) of R_NB, see :mod:`gmuk.lie.euler`."""
        return euler.from_matrix(self.R, seq)  # type: ignore[arg-type]

    def rotation_vector(self) -> FloatArray:
        """log(R_NB) (N, 3) (rad)."""
        return so3.log(self.R)

    @property
    def omega(self) -> FloatArray:
        """Body angular velocity ω (N, 3) (rad/s), body frame."""
        return self.traj.V_B[:, self._rigid(), :3]

    @property
    def v(self) -> FloatArray:
        """Body-frame translational velocity v (N, 3) (m/s)."""
        return self.traj.V_B[:, self._rigid(), 3:]

    @property
    def acceleration(self) -> FloatArray:
        """Total acceleration (N, dof): [ω̇; v̇] (body frame) or a_N."""
        return self._dof_slice(self.traj.acceleration)

    @property
    def constraint_force(self) -> FloatArray:
        """Constraint wrench [L; f] (N, 6) in the body frame (N·m, N), or force (N, 3)."""
        return self._dof_slice(self.traj.constraint_force)

    @property
    def control_force(self) -> FloatArray:
        """Controller wrench (N, dof)."""
        return self._dof_slice(self.traj.control_force)

    @property
    def constraint_acceleration(self) -> FloatArray:
        """Constraint acceleration ν̇_c (N, dof): [J⁻¹L_c; f_c/m] for a rigid body
        (rad/s², m/s², body frame), or a_c (N, 3) of a point mass."""
        return self._dof_slice(self.traj.constraint_acceleration)

    def _rigid(self) -> int:
        s = self._slot()
        if s.kind != "rigid":
            raise DefinitionError(f"{self.name!r} is a {s.kind} body, not a rigid body")
        return int(s.index)


def _current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: The process's file-creation mask, read once (reading it means setting it).
_UMASK = _current_umask()


@contextmanager
def atomic_write(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; renamed over ``path`` when the block
    ends normally, removed when it raises (or is interrupted)."""
    path = Path(path)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    tmp = Path(name)
    os.chmod(tmp, 0o666 & ~_UMASK)  # as open() would create it (mkstemp makes it 0600)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (see :func:`atomic_write`)."""
    with atomic_write(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


#: Most bytes :func:`load_trajectory` decompresses by default: the sum of the sizes the
#: archive declares for the members it reads (1 GiB; raise it with ``max_bytes=``).
MAX_BYTES = 2**30
#: Deflate expands data at most 1032 times; a member declaring a larger ratio of
#: uncompressed to compressed size states a false size (a zip bomb or a forged header).
MAX_COMPRESSION_RATIO = 1100
#: Most bytes of the JSON metadata member.
MAX_META_BYTES = 64 * 2**20
#: Tolerance of the rotation checks on the saved poses: ‖RᵀR − I‖_max, abs(det R − 1) and the
#: bottom row's distance to [0, 0, 0, 1]. gmuk's integrator keeps R on SO(3) to round-off
#: (about 1e-15 per step); a looser bound than :data:`gmuk._validation.GROUP_TOL` lets
#: files from other programs that store fewer digits load.
POSE_TOL = 1e-6
#: The values of :attr:`Trajectory.status` ("drifted" since gmuk's drift check; files
#: written before it carry the other three and load as they are).
STATUSES = ("success", "terminated", "drifted", "interrupted", "failed")
_DOFS = {"rigid": 6, "point": 3, "slack": 1}
_META_KEYS = ("format_version", "body_names", "body_kinds", "body_dofs", "status", "message")
_NPY_MAGIC = b"\x93NUMPY"
_ZIP_MAGIC = (b"PK\x03\x04", b"PK\x05\x06")
#: Members of a trajectory ``.npz`` (without ``.npy``): the arrays, the metadata and the
#: point masses' copies (format version 2).
_MEMBERS = (*_ARRAYS, "meta", "r_N", "v_N")


def load_trajectory(path: str | Path, *, max_bytes: int = MAX_BYTES) -> Trajectory:
    """Load a trajectory saved by :meth:`Trajectory.save`.

    Reads every format version up to this gmuk's (:data:`FORMAT_VERSION`; version 1 files,
    written before the ``r_N``/``v_N`` copies, load the same) and refuses newer ones.

    The file is treated as untrusted: everything is checked before it is used, and memory
    is allocated only for what the archive declares and the checks allow.

    Parameters
    ----------
    path : str or path-like
        The ``.npz`` file.
    max_bytes : int
        Most bytes to decompress (the sum of the members' declared uncompressed sizes);
        default :data:`MAX_BYTES` (1 GiB). A larger file is refused before anything is
        decompressed; pass a larger value to read it.

    Returns
    -------
    Trajectory
        Arrays bit-identical to those saved.

    Raises
    ------
    FileFormatError
        The message names the file and, where it applies, the member and what was expected.
        Refused are:

        * a path that is not a readable regular file; a ``.npy`` file (one array) or any
          other file that is not a zip archive; a truncated or corrupted archive (bad CRC);
        * *allocation before reading*: a member compressed other than stored or deflated,
          or encrypted; a member whose declared uncompressed size is more than
          :data:`MAX_COMPRESSION_RATIO` times its compressed size (more than deflate can
          give: a zip bomb or a forged size); declared sizes summing to more than
          ``max_bytes``; an array header (shape, dtype) that does not describe exactly the
          member's declared size (a 300-byte header claiming 10¹² entries is refused
          before any allocation); object, complex, string, boolean or structured dtypes;
          the arrays are then read with reads bounded by those checked sizes;
        * a member that is not part of a trajectory, or given twice; a missing array;
        * *metadata*: not a JSON object, a ``format_version`` that is not an integer
          between 1 and :data:`FORMAT_VERSION` (a newer one asks to upgrade gmuk),
          body names that are not distinct strings, unknown body kinds, ``body_dofs``
          that are not integers (6.7 is not read as 6) or not those of the body kinds
          (rigid 6, point 3, slack 1), a ``status`` not in :data:`STATUSES`, a
          ``message`` that is not a string, ``stats`` that is not an object or whose
          ``n_rhs``, ``n_steps``, ``n_rejected`` (integers ≥ 0), ``method`` (str),
          ``rtol``, ``atol`` (finite ≥ 0), ``compiled``, ``drifted`` (bool),
          ``versions``, ``checkpoint`` or ``constraint_violation`` (objects) have the
          wrong type;
        * *events* (``meta["events"]``, written when the run located any): not a list of
          objects with a name, a finite time (not decreasing), a direction ±1, a terminal
          flag (true for the last only, at the last output's time) and a finite state of
          the trajectory's bodies, poses on SE(3) within :data:`POSE_TOL`;
        * *arrays*: shapes that disagree with the bodies or with each other; NaN or
          infinity; times ``t`` that do not strictly increase; poses whose rotation
          block is not a rotation (‖RᵀR − I‖ or abs(det R − 1) above :data:`POSE_TOL`, a
          reflection included) or whose bottom row is not [0, 0, 0, 1]; a negative
          ``residual``; a ``rank`` outside [−1, n_dof]; ``r_N``/``v_N`` that are not
          the point masses' columns of ``x``/``xdot`` (or absent from a version-2 file).
    DefinitionError
        ``max_bytes`` is not an integer > 0.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise FileFormatError(f"load_trajectory: path must be a str or os.PathLike; got {path!r}")
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, (int, np.integer)) or max_bytes < 1:
        raise DefinitionError(
            f"load_trajectory: max_bytes must be an integer > 0; got {max_bytes!r}"
        )
    path = Path(path)
    if not path.is_file():
        raise FileFormatError(
            f"{path}: {'not a regular file' if path.exists() else 'no such file'}"
        )
    try:
        members = _read_members(path, int(max_bytes))
    except FileFormatError:
        raise
    except (
        OSError,
        ValueError,
        EOFError,
        zipfile.BadZipFile,
        zlib.error,
        NotImplementedError,  # a flipped compression-method byte
        RuntimeError,  # a flipped encryption flag
    ) as exc:
        raise FileFormatError(
            f"{path}: cannot read as a gmuk trajectory .npz (truncated or corrupted?): "
            f"{type(exc).__name__}: {exc}"
        ) from None
    meta = _parse_meta(members.pop("meta"), path)
    version, body, status, message, stats = _check_meta(meta, path)
    copies: dict[str, np.ndarray] = {k: members.pop(k) for k in ("r_N", "v_N") if k in members}
    arrays = _check_dtypes(members, path)
    traj = Trajectory(**arrays, **body, status=status, message=message, stats=stats)
    _check_consistent(traj, path)
    if "events" in meta:
        traj = replace(traj, events=_check_events(meta["events"], traj, path))
    _check_values(traj, path)
    _check_copies(traj, copies, version, path)
    return traj


def _read_members(path: Path, max_bytes: int) -> dict[str, np.ndarray]:
    """The trajectory's members as arrays, every size checked before it is allocated."""
    with path.open("rb") as fh:
        magic = fh.read(8)
    if magic.startswith(_NPY_MAGIC):
        raise FileFormatError(
            f"{path}: a .npy file (a single numpy array), not a gmuk trajectory .npz; "
            "trajectories are saved by Trajectory.save as .npz archives"
        )
    if not magic.startswith(_ZIP_MAGIC):
        raise FileFormatError(
            f"{path}: not a gmuk trajectory .npz (not a zip archive: starts with {magic[:4]!r})"
        )
    with zipfile.ZipFile(path) as zf:
        infos: dict[str, zipfile.ZipInfo] = {}
        for info in zf.infolist():
            name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
            if name not in _MEMBERS:
                raise FileFormatError(
                    f"{path}: member {info.filename!r} is not part of a gmuk trajectory "
                    f"(expected {', '.join(f'{m}.npy' for m in _MEMBERS)})"
                )
            if name in infos:
                raise FileFormatError(f"{path}: member {info.filename!r} appears twice")
            infos[name] = info
        missing = [k for k in (*_ARRAYS, "meta") if k not in infos]
        if missing:
            raise FileFormatError(
                f"{path}: not a gmuk trajectory (missing {', '.join(map(repr, missing))})"
            )
        total = 0
        for name, info in infos.items():
            _check_member_sizes(path, name, info)
            total += info.file_size
        if total > max_bytes:
            raise FileFormatError(
                f"{path}: the archive declares {total} bytes uncompressed, more than the "
                f"limit of {max_bytes} (load_trajectory(..., max_bytes=...) raises it); "
                "nothing was decompressed"
            )
        return {name: _read_member(zf, info, path, name) for name, info in infos.items()}


def _check_member_sizes(path: Path, name: str, info: zipfile.ZipInfo) -> None:
    """Refuse, before decompressing, a member whose method or declared sizes are not those
    of numpy's own (stored or deflated, unencrypted, a ratio deflate can give)."""
    where = f"{path}: member {info.filename!r}"
    if info.flag_bits & 0x1:
        raise FileFormatError(f"{where} is encrypted; gmuk trajectories are not")
    if info.compress_type == zipfile.ZIP_STORED:
        if info.file_size != info.compress_size:
            raise FileFormatError(
                f"{where} is stored uncompressed but declares {info.file_size} bytes "
                f"uncompressed and {info.compress_size} compressed"
            )
    elif info.compress_type == zipfile.ZIP_DEFLATED:
        if info.file_size > MAX_COMPRESSION_RATIO * max(info.compress_size, 1):
            raise FileFormatError(
                f"{where} declares {info.file_size} bytes from {info.compress_size} "
                f"compressed, a ratio above {MAX_COMPRESSION_RATIO} (deflate gives at most "
                "1032): a zip bomb or a forged size; nothing was decompressed"
            )
    else:
        raise FileFormatError(
            f"{where} uses zip compression method {info.compress_type}; expected stored (0) "
            "or deflated (8), as numpy writes"
        )
    if name == "meta" and info.file_size > MAX_META_BYTES:
        raise FileFormatError(
            f"{where}: metadata of {info.file_size} bytes, above the limit of {MAX_META_BYTES}"
        )


def _read_member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, path: Path, name: str) -> np.ndarray:
    """One ``.npy`` member, its header checked against the declared size before the array
    is allocated, then read with bounded reads (and its CRC checked)."""
    where = f"{path}: member {info.filename!r}"
    with zf.open(info) as fh:
        try:
            major, minor = np.lib.format.read_magic(fh)
            if (major, minor) == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(
                    fh, max_header_size=10000
                )
            elif (major, minor) == (2, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(
                    fh, max_header_size=10000
                )
            else:
                raise FileFormatError(
                    f"{where}: .npy format version {major}.{minor}; expected 1.0 or 2.0"
                )
        except FileFormatError:
            raise
        except (ValueError, TypeError, SyntaxError, EOFError) as exc:
            raise FileFormatError(f"{where}: not a valid .npy array header: {exc}") from None
        if dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None:
            raise FileFormatError(f"{where}: dtype {dtype} is not a plain numeric dtype")
        allowed = "U" if name == "meta" else "iu" if name == "rank" else "f"
        if dtype.kind not in allowed or dtype.itemsize == 0:
            what = {"U": "a string", "iu": "integers", "f": "real floats"}[allowed]
            raise FileFormatError(f"{where}: dtype {dtype}; expected {what}")
        count = 1
        for n in shape:
            count *= n
        header = fh.tell()
        needed = header + count * dtype.itemsize
        if needed != info.file_size:
            raise FileFormatError(
                f"{where}: the header claims shape {shape} of {dtype} ({count * dtype.itemsize} "
                f"bytes) but the archive declares {info.file_size - header} bytes of data; "
                "refused before allocating"
            )
        array = np.empty(count, dtype=dtype)
        raw = array.view(np.uint8).reshape(-1)
        done = 0
        while done < raw.size:
            chunk = fh.read(min(raw.size - done, 1 << 24))
            if not chunk:
                raise FileFormatError(
                    f"{where}: ends after {done} of {raw.size} data bytes (truncated)"
                )
            raw[done : done + len(chunk)] = np.frombuffer(chunk, dtype=np.uint8)
            done += len(chunk)
        if fh.read(1):  # also makes zipfile check the CRC
            raise FileFormatError(f"{where}: holds more bytes than its header describes")
    return array.reshape(shape, order="F" if fortran else "C")


def _parse_meta(meta_array: np.ndarray, path: Path) -> dict[str, Any]:
    if meta_array.shape != ():
        raise FileFormatError(
            f"{path}: member 'meta.npy' has shape {meta_array.shape}; expected one string"
        )
    try:
        meta = json.loads(str(meta_array[()]))
    except (ValueError, RecursionError) as exc:
        raise FileFormatError(
            f"{path}: metadata is not valid JSON: {type(exc).__name__}: {str(exc)[:200]}"
        ) from None
    if not isinstance(meta, dict):
        raise FileFormatError(f"{path}: metadata is not a JSON object")
    return meta


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _check_meta(
    meta: dict[str, Any], path: Path
) -> tuple[int, dict[str, Any], str, str, dict[str, Any]]:
    """(format version, body fields, status, message, stats), each checked."""
    version = meta.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise FileFormatError(f"{path}: format_version must be a positive integer; got {version!r}")
    if version > FORMAT_VERSION:
        raise FileFormatError(
            f"{path}: trajectory format version {version} was written by a newer gmuk; "
            f"this one reads versions up to {FORMAT_VERSION}: upgrade gmuk"
        )
    missing = [k for k in (*_META_KEYS, "stats") if k not in meta]
    if missing:
        raise FileFormatError(
            f"{path}: not a gmuk trajectory (missing metadata {', '.join(map(repr, missing))})"
        )
    names, kinds, dofs = meta["body_names"], meta["body_kinds"], meta["body_dofs"]
    for key, value in (("body_names", names), ("body_kinds", kinds), ("body_dofs", dofs)):
        if not isinstance(value, list):
            raise FileFormatError(f"{path}: metadata {key} must be a list; got {value!r:.80}")
    if not (len(names) == len(kinds) == len(dofs)):
        raise FileFormatError(
            f"{path}: metadata body_names, body_kinds and body_dofs have lengths "
            f"{len(names)}, {len(kinds)}, {len(dofs)}; expected one entry per body"
        )
    if not all(isinstance(n, str) for n in names) or len(set(names)) != len(names):
        raise FileFormatError(
            f"{path}: metadata body_names must be distinct strings; got {names!r:.200}"
        )
    for name, kind, dof in zip(names, kinds, dofs, strict=True):
        if kind not in _DOFS:
            raise FileFormatError(
                f"{path}: body {name!r} has kind {kind!r}; expected one of {list(_DOFS)}"
            )
        if not _is_int(dof) or dof != _DOFS[kind]:
            raise FileFormatError(
                f"{path}: body {name!r} ({kind}) has body_dofs {dof!r}; expected the integer "
                f"{_DOFS[kind]}"
            )
    status, message, stats = meta["status"], meta["message"], meta["stats"]
    if status not in STATUSES:
        raise FileFormatError(
            f"{path}: metadata status must be one of {list(STATUSES)}; got {status!r:.80}"
        )
    if not isinstance(message, str):
        raise FileFormatError(f"{path}: metadata message must be a string; got {message!r:.80}")
    _check_stats(stats, path)
    body = {"body_names": tuple(names), "body_kinds": tuple(kinds), "body_dofs": tuple(dofs)}
    return version, body, status, message, stats


def _check_events(raw: Any, traj: Trajectory, path: Path) -> tuple[EventRecord, ...]:
    """The metadata's ``events`` as EventRecords: each a name, a finite time, a direction
    ±1, a terminal flag and a state of the trajectory's bodies (poses checked as the arrays'
    are); in time order, a terminal one last and at the last output's time."""

    def bad(i: int, why: str) -> FileFormatError:
        return FileFormatError(f"{path}: metadata events[{i}]: {why}")

    if not isinstance(raw, list):
        raise FileFormatError(f"{path}: metadata events must be a list; got {raw!r:.80}")
    lay = traj.layout
    shapes = {"g": (lay.n_rigid, 4, 4), "V": (lay.n_rigid, 6), "x": (lay.n_euclid,),
              "xdot": (lay.n_euclid,), "z": (lay.n_control,)}  # fmt: skip
    out: list[EventRecord] = []
    for i, e in enumerate(raw):
        keys = {"name", "t", "direction", "terminal", "state"}
        if not isinstance(e, dict) or set(e) != keys:
            raise bad(i, f"must be an object with keys {sorted(keys)}; got {e!r:.80}")
        name, t, direction, terminal, st = (e[k] for k in ("name", "t", "direction",
                                                           "terminal", "state"))  # fmt: skip
        if not isinstance(name, str) or not name:
            raise bad(i, f"name must be a non-empty string; got {name!r:.80}")
        if not (isinstance(t, (int, float)) and not isinstance(t, bool) and math.isfinite(t)):
            raise bad(i, f"t must be a finite time (s); got {t!r:.80}")
        if terminal is True and len(traj) and t != traj.t[-1]:
            raise bad(i, f"a terminal event at t = {t!r} s must be the last output's time")
        if out and t < out[-1].t:
            raise bad(i, f"t = {t!r} s comes before the previous event's {out[-1].t!r} s")
        if not _is_int(direction) or direction not in (-1, 1):
            raise bad(i, f"direction must be -1 or 1; got {direction!r:.80}")
        if not isinstance(terminal, bool) or (terminal and i != len(raw) - 1):
            raise bad(i, f"terminal must be true or false, and true for the last event only; "
                      f"got {terminal!r:.80}")  # fmt: skip
        if not isinstance(st, dict) or set(st) != set(shapes):
            raise bad(i, f"state must be an object with keys {sorted(shapes)}")
        arrays = {}
        for key, shape in shapes.items():
            try:
                a = np.array(st[key], dtype=np.float64)
            except (TypeError, ValueError, OverflowError):
                raise bad(i, f"state[{key!r}] is not an array of numbers") from None
            if a.size == 0 and math.prod(shape) == 0:  # JSON keeps no shape of an empty list
                a = a.reshape(shape)
            if a.shape != shape or not np.isfinite(a).all():
                raise bad(i, f"state[{key!r}] must be finite of shape {shape}; got {a.shape}")
            arrays[key] = a
        if lay.n_rigid:
            R = arrays["g"][:, :3, :3]
            off = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max()
            row = np.abs(arrays["g"][:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max()
            if off > POSE_TOL or row > POSE_TOL or np.abs(np.linalg.det(R) - 1).max() > POSE_TOL:
                raise bad(i, "state['g'] holds a pose that is not on SE(3)")
        state = State(float(t), arrays["g"], arrays["V"], arrays["x"], arrays["xdot"],
                      arrays["z"], lay)  # fmt: skip
        out.append(EventRecord(name, float(t), int(direction), terminal, state))
    return tuple(out)


def _check_stats(stats: Any, path: Path) -> None:
    """The recognised entries of ``stats`` have their types; other entries are kept."""
    if not isinstance(stats, dict):
        raise FileFormatError(f"{path}: metadata stats must be an object; got {stats!r:.80}")
    checks: dict[str, tuple[str, Any]] = {
        "n_rhs": ("an integer ≥ 0", lambda v: _is_int(v) and v >= 0),
        "n_steps": ("an integer ≥ 0", lambda v: _is_int(v) and v >= 0),
        "n_rejected": ("an integer ≥ 0", lambda v: _is_int(v) and v >= 0),
        "method": ("a string", lambda v: isinstance(v, str)),
        "rtol": ("a finite number ≥ 0", _non_negative_number),
        "atol": ("a finite number ≥ 0", _non_negative_number),
        "compiled": ("true or false", lambda v: isinstance(v, bool)),
        "versions": ("an object", lambda v: isinstance(v, dict)),
        "checkpoint": ("an object", lambda v: isinstance(v, dict)),
        "drifted": ("true or false", lambda v: isinstance(v, bool)),
        "constraint_violation": ("an object", lambda v: isinstance(v, dict)),
    }
    for key, (what, ok) in checks.items():
        if key in stats and not ok(stats[key]):
            raise FileFormatError(
                f"{path}: metadata stats[{key!r}] must be {what}; got {stats[key]!r:.80}"
            )


def _non_negative_number(value: Any) -> bool:
    return (
        isinstance(value, (int, float))
        and not isinstance(value, bool)
        and math.isfinite(value)
        and value >= 0
    )


def _check_dtypes(members: dict[str, np.ndarray], path: Path) -> dict[str, Any]:
    """The arrays as float64 (int64 for ``rank``); exact conversions only."""
    out: dict[str, Any] = {}
    for name in _ARRAYS:
        a = members[name]
        if name == "rank":
            if a.dtype.kind == "u" and a.size and int(a.max()) > np.iinfo(np.int64).max:
                raise FileFormatError(f"{path}: array 'rank' holds values beyond int64")
            out[name] = a.astype(np.int64, copy=False)
        else:
            out[name] = a.astype(np.float64, copy=False)  # float16/32 -> 64 is exact
    return out


def _check_consistent(traj: Trajectory, path: Path) -> None:
    """The arrays' shapes agree with the bodies and with each other (a file edited by hand
    or by another program is refused rather than misread)."""
    if traj.z.ndim != 2:
        raise FileFormatError(
            f"{path}: array 'z' has shape {traj.z.shape}; expected (N, n_control)"
        )
    lay = traj.layout
    n = traj.t.shape[0] if traj.t.ndim == 1 else -1
    expected = {
        "t": (n,),
        "g_NB": (n, lay.n_rigid, 4, 4),
        "V_B": (n, lay.n_rigid, 6),
        "x": (n, lay.n_euclid),
        "xdot": (n, lay.n_euclid),
        "z": (n, lay.n_control),
        "acceleration": (n, lay.n_dof),
        "constraint_acceleration": (n, lay.n_dof),
        "constraint_force": (n, lay.n_dof),
        "control_force": (n, lay.n_dof),
        "unmodeled_force": (n, lay.n_dof),
        "residual": (n,),
        "rank": (n,),
    }
    for name, shape in expected.items():
        got = getattr(traj, name).shape
        if got != shape:
            raise FileFormatError(
                f"{path}: array {name!r} has shape {got}; the metadata say {shape}"
            )
    if traj.multipliers.ndim != 2 or traj.multipliers.shape[0] != n:
        raise FileFormatError(f"{path}: array 'multipliers' has shape {traj.multipliers.shape}")
    for name in _ARRAYS:  # gmuk records finite outputs only
        values = getattr(traj, name)
        if values.dtype.kind not in "iuf" or not np.isfinite(values).all():
            raise FileFormatError(f"{path}: array {name!r} holds non-finite or non-real values")


def _check_values(traj: Trajectory, path: Path) -> None:
    """Times increase, poses are on SE(3), residuals and ranks are in their ranges."""
    steps = np.diff(traj.t)
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0))
        raise FileFormatError(
            f"{path}: times t must strictly increase; t[{i + 1}] = {float(traj.t[i + 1])!r} "
            f"follows t[{i}] = {float(traj.t[i])!r}"
        )
    g = traj.g_NB
    if g.size:
        rigid = [n for n, k in zip(traj.body_names, traj.body_kinds, strict=True) if k == "rigid"]
        row = np.abs(g[..., 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=-1)
        R = g[..., :3, :3]
        ortho = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(axis=(-1, -2))
        det = np.linalg.det(R)
        for label, bad in (
            ("bottom row is not [0, 0, 0, 1]", row > POSE_TOL),
            ("rotation block is not orthonormal (RᵀR ≠ I)", ortho > POSE_TOL),
            (
                "rotation block is a reflection or not a rotation (det R ≠ 1)",
                np.abs(det - 1.0) > POSE_TOL,
            ),
        ):
            if bad.any():
                i, k = (int(v) for v in np.argwhere(bad)[0])
                raise FileFormatError(
                    f"{path}: array 'g_NB': the pose of body "
                    f"{rigid[k]!r} at output {i} (t = {float(traj.t[i])!r} s): "
                    f"{label} (‖RᵀR − I‖ = {ortho[i, k]:.3g}, det R = {det[i, k]:.6g}, bottom "
                    f"row off by {row[i, k]:.3g}; tolerance {POSE_TOL})"
                )
    if (traj.residual < 0).any():
        raise FileFormatError(f"{path}: array 'residual' holds negative norms")
    n_dof = traj.layout.n_dof
    if traj.rank.size and not (-1 <= traj.rank.min() and traj.rank.max() <= n_dof):
        raise FileFormatError(
            f"{path}: array 'rank' holds values outside [-1, {n_dof}] (-1: not computed)"
        )


def _check_copies(
    traj: Trajectory, copies: dict[str, np.ndarray], version: int, path: Path
) -> None:
    """``r_N`` and ``v_N`` are present from version 2 on and equal to the point masses'
    columns of ``x`` and ``xdot``."""
    if version >= 2 and len(copies) != 2:
        raise FileFormatError(
            f"{path}: format version {version} files hold 'r_N' and 'v_N'; "
            f"{'only one is' if copies else 'neither is'} present"
        )
    for name, expected in (("r_N", traj.r_N), ("v_N", traj.v_N)):
        if name not in copies:
            continue
        got = copies[name]
        if got.shape != expected.shape or not np.array_equal(got, expected):
            raise FileFormatError(
                f"{path}: array {name!r} (shape {got.shape}) is not the point masses' "
                f"columns of {'x' if name == 'r_N' else 'xdot'} (shape {expected.shape})"
            )
