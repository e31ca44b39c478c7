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

import json
import os
import tempfile
import zipfile
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError, FileFormatError
from gmuk.lie import euler, so3
from gmuk.state import Layout, State

__all__ = ["BodyTrajectory", "Trajectory", "load_trajectory"]

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
class Trajectory:
    """The result of :meth:`gmuk.System.simulate`.

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
    status : {"success", "interrupted", "failed"}
    message : str
    stats : dict
        ``n_rhs`` (right-hand-side evaluations), ``n_steps``, ``n_rejected``, ``method``.
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

    @property
    def layout(self) -> Layout:
        """The body index of this trajectory."""
        kinds = tuple(BodyKind(k) for k in self.body_kinds)
        return Layout(self.body_names, kinds, self.body_dofs, self.z.shape[1])

    @property
    def success(self) -> bool:
        """Whether the run reached the end of its time span."""
        return self.status == "success"

    def __len__(self) -> int:
        return int(self.t.shape[0])

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
        """The State at output ``i`` (a copy; negative indices count from the end)."""
        n = len(self)
        if not -n <= i < n:
            raise DefinitionError(f"output index {i} out of range for {n} outputs")
        return State(
            float(self.t[i]),
            self.g_NB[i].copy(),
            self.V_B[i].copy(),
            self.x[i].copy(),
            self.xdot[i].copy(),
            self.z[i].copy(),
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


@dataclass(frozen=True, eq=False)
class BodyTrajectory:
    """Time histories of one body of a :class:`Trajectory`."""

    traj: Trajectory
    name: str

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


def load_trajectory(path: str | Path) -> Trajectory:
    """Load a trajectory saved by :meth:`Trajectory.save`.

    Reads every format version up to this gmuk's (:data:`FORMAT_VERSION`; version 1 files,
    written before the ``r_N``/``v_N`` copies, load the same) and refuses newer ones.

    Raises
    ------
    FileFormatError
        If the path is not a readable file, the file is not a gmuk trajectory (not an
        ``.npz``, truncated or corrupted, missing or inconsistent arrays or metadata), or it
        was written by a newer gmuk (its format version is above this one's).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise FileFormatError(f"load_trajectory: path must be a str or os.PathLike; got {path!r}")
    path = Path(path)
    if not path.is_file():
        raise FileFormatError(
            f"{path}: {'not a regular file' if path.exists() else 'no such file'}"
        )
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            if not isinstance(meta, dict):
                raise FileFormatError(f"{path}: metadata is not a JSON object")
            version = meta.get("format_version")
            if not isinstance(version, int) or version < 1:
                raise FileFormatError(
                    f"{path}: format_version must be a positive integer; got {version!r}"
                )
            if version > FORMAT_VERSION:
                raise FileFormatError(
                    f"{path}: trajectory format version {version} was written by a newer gmuk; "
                    f"this one reads versions up to {FORMAT_VERSION}: upgrade gmuk"
                )
            arrays: dict[str, Any] = {k: np.asarray(data[k]) for k in _ARRAYS}
    except FileFormatError:
        raise
    except KeyError as exc:
        raise FileFormatError(f"{path}: not a gmuk trajectory (missing {exc})") from None
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
    names = {f.name for f in fields(Trajectory)}
    kw = {k: v for k, v in meta.items() if k in names}
    try:
        body = {
            "body_names": tuple(str(n) for n in meta["body_names"]),
            "body_kinds": tuple(str(k) for k in meta["body_kinds"]),
            "body_dofs": tuple(int(d) for d in meta["body_dofs"]),
        }
        traj = Trajectory(**arrays, **{**kw, **body})
        _check_consistent(traj, path)
    except FileFormatError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise FileFormatError(
            f"{path}: inconsistent trajectory metadata or arrays: {type(exc).__name__}: {exc}"
        ) from None
    return traj


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
