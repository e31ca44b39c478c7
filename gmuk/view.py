"""Interactive 3-D views of a trajectory: one self-contained HTML file that opens offline.

:func:`view_html` draws, with plotly, the central body as a sphere (when its radius is
given), each body's path in the inertial frame N, and an animation (play button and time
slider) of each rigid body's axes triad, the columns of R_NB, moving along its path; point
masses are drawn as markers. A system with joints (:mod:`gmuk.robots`) is drawn as its
kinematic skeleton too: each link a capsule about the segments from its body's centre to its
joint frames' origins, and each joint frame's triad (see :func:`view_html`'s notes); a
trajectory carries its joints to the view in its stats (:func:`with_joint_frames`, which the
robot scenarios call), so that ``gmuk run`` and ``gmuk view`` draw them. :func:`write_view`
writes the HTML to a file; ``gmuk view`` and ``gmuk run`` (``view.html`` beside the figures)
call it.

Why plotly and not meshcat
--------------------------
The file must open from disk with no server process and no network. Plotly's
``Figure.to_html(include_plotlyjs=True)`` embeds plotly.js (4.8 MB) in the page and
needs nothing else: the file is the whole view, and the Python side is a pure-Python package
with no running process. Meshcat's static-HTML export asks a running meshcat server
(a ZeroMQ subprocess) for the scene, so producing a file needs a server process. Plotly's
3-D scenes use WebGL, which every current browser has (headless Chromium renders it in
software).

File size
---------
The page is plotly.js plus the data. The data are decimated so that a long run stays small:
each path is drawn through at most ``max_path_points`` samples (default 2000) and the
animation has at most ``max_frames`` frames (default 150), both taken evenly spaced in the
output index (the outputs of a gmuk run are evenly spaced in time), always keeping the first
and last outputs. A self-contained view of one body is then about 5.1 MB whatever the run's
length (a one-orbit FCEI run, 721 outputs: 5.10 MB), of which 4.8 MB is plotly.js; a view
that loads a shared copy of it (``write_view(..., library=FOLDER)``, as ``gmuk run`` writes
them) is about 0.3 MB. A robot's view is larger: each frame holds the vertices of every link's
capsule (2 + 6 × 12 = 74 a link), as plotly.js typed arrays: base64 of the coordinates
rounded to single precision (7 significant digits, far below a pixel), half the length of
doubles; the triangles are written once.
"""

from __future__ import annotations

import base64
import json
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import quote

import numpy as np

from gmuk._validation import FloatArray, check_se3, real_number, strict_integer
from gmuk.errors import DefinitionError, GmukError
from gmuk.trajectory import Trajectory, write_text_atomic

if TYPE_CHECKING:
    from gmuk.constraints.base import Constraint
    from gmuk.engine.system import System

__all__ = [
    "JOINT_FRAMES_KEY",
    "decimate",
    "joint_frames",
    "plotly_js_name",
    "view_html",
    "with_joint_frames",
    "write_plotly_js",
    "write_view",
]

#: Colours of body axes 1, 2, 3 (red, green, blue, as in most 3-D tools).
AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")
#: Colour of the central body's sphere.
SPHERE_COLOUR = "#9a9a9a"
#: A scene wider than this (m) is drawn in km.
KM_ABOVE_M = 1.0e5
#: Colour of the links of a system with joints, and of the ground's.
LINK_COLOUR = "#5a82be"
GROUND_COLOUR = "#505050"
#: A drawn link is a capsule: rings of CAPSULE_SIDES vertices, CAPSULE_CAP_RINGS on each
#: hemispherical cap (its rim included) and a vertex at each pole.
CAPSULE_SIDES = 12
CAPSULE_CAP_RINGS = 3
#: The automatic link radius: this fraction of the robot's size (the largest distance between
#: two points of its skeleton at the first drawn frame), and at least this fraction of the
#: scene's, so that a small robot in a large scene still shows.
LINK_RADIUS_OF_ROBOT = 0.03
LINK_RADIUS_OF_SCENE = 0.004
#: Flat shading of the capsules, lit from high above: their facets show their shape. Plotly
#: drops the normal of a face whose normal's squared length (m⁴ in a scene in metres) is under
#: ``facenormalsepsilon`` (default 1e-6), which leaves only the ambient light on the small faces
#: of a capsule a few centimetres wide: every normal is kept.
CAPSULE_LIGHTING = {
    "ambient": 0.5,
    "diffuse": 0.8,
    "specular": 0.1,
    "roughness": 0.5,
    "facenormalsepsilon": 0.0,
    "vertexnormalsepsilon": 0.0,
}
CAPSULE_LIGHT = {"x": 1e4, "y": -1e4, "z": 1e5}
#: The key of :attr:`Trajectory.stats <gmuk.Trajectory.stats>` under which
#: :func:`with_joint_frames` stores the joints a view draws (saved with the trajectory).
JOINT_FRAMES_KEY = "joint_frames"


def decimate(n: int, most: int) -> np.ndarray:
    """At most ``most`` indices into ``n`` outputs, evenly spaced, first and last kept.

    Parameters
    ----------
    n : int
        Number of outputs (≥ 1).
    most : int
        Largest number of indices to keep (≥ 2).

    Returns
    -------
    ndarray (k,) of int
        Increasing indices, ``k = min(n, most)``.
    """
    # integers only: a string, a bool, a float or an array is refused, not compared
    if isinstance(n, (int, np.integer)) and not isinstance(n, (bool, np.bool_)) and n < 1:
        raise DefinitionError(f"a view needs at least one output; got {n}")
    n = strict_integer(n, "the number of outputs", minimum=1, maximum=2**62)
    try:
        most = strict_integer(most, "most", minimum=2, maximum=10**8)
    except DefinitionError:
        raise DefinitionError(
            f"the number of outputs to keep must be ≥ 2 (an integer); got {most!r:.80}"
        ) from None
    if n <= most:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, most)).astype(np.int64))


def _positions(traj: Trajectory) -> list[tuple[str, FloatArray, FloatArray | None]]:
    """(name, r_N (N, 3) in m, R_NB (N, 3, 3) or None) of every rigid body and point mass."""
    out: list[tuple[str, FloatArray, FloatArray | None]] = []
    for name, kind in zip(traj.body_names, traj.body_kinds, strict=True):
        view = traj.body(name)
        if kind == "rigid":
            out.append((name, view.position, view.R))
        elif kind == "point":
            out.append((name, view.position, None))
    return out


def _segments(starts: FloatArray, ends: FloatArray) -> tuple[list[Any], list[Any], list[Any]]:
    """x, y, z lists of line segments start→end (k, 3), separated by None for plotly."""
    xs: list[Any] = []
    ys: list[Any] = []
    zs: list[Any] = []
    for a, b in zip(starts, ends, strict=True):
        xs += [float(a[0]), float(b[0]), None]
        ys += [float(a[1]), float(b[1]), None]
        zs += [float(a[2]), float(b[2]), None]
    return xs, ys, zs


def _segment_trace(
    starts: Any, ends: Any, colour: str | None, width: float, name: str
) -> dict[str, Any]:
    """One plotly trace of line segments start→end (k, 3) of one colour and width."""
    x, y, z = _segments(np.asarray(starts), np.asarray(ends))
    line: dict[str, Any] = {"width": width, **({} if colour is None else {"color": colour})}
    return dict(type="scatter3d", x=x, y=y, z=z, mode="lines", line=line, name=name)


def _typed(values: Any, single: bool = False) -> dict[str, str]:
    """A float array as plotly.js's typed-array form: base64 of its little-endian doubles
    (dtype ``f8``: every bit kept, in 10.7 characters a number against about 19 for its decimal
    digits), or with ``single`` of the numbers rounded to nearest single-precision floats
    (``f4``: 24 significant bits, a relative error of at most 2⁻²⁴ ≈ 6e-8, in 5.3 characters a
    number) if they all fit in single precision's range (|x| < 3.4e38), else doubles."""
    raw = np.ascontiguousarray(values, dtype="<f8").ravel()
    if single and (raw.size == 0 or np.abs(raw).max() <= np.finfo(np.float32).max):
        return {"dtype": "f4", "bdata": base64.b64encode(raw.astype("<f4").tobytes()).decode()}
    return {"dtype": "f8", "bdata": base64.b64encode(raw.tobytes()).decode("ascii")}


def _capsules(starts: Any, ends: Any, radius: float, tiny: float) -> tuple[FloatArray, np.ndarray]:
    """Closed triangle meshes of capsules: for each segment a → b (k, 3), the points at
    distance ``radius`` from it, a cylinder about it closed by a hemisphere at each end.

    Parameters
    ----------
    starts, ends : array_like (k, 3)
        The segments' ends a and b (any length unit; ``radius`` and ``tiny`` in the same).
    radius : float
        ρ > 0.
    tiny : float
        A segment shorter than this (≥ 0) has no direction: it is drawn as the sphere of
        radius ρ about a, its axis taken along the third axis.

    Returns
    -------
    vertices : ndarray (k V, 3)
        Capsule c's V = 2 + 2 n_r n_s vertices are rows c V … (c + 1) V − 1: the pole
        a − ρ u (u = (b − a)/|b − a|), the cap rings about a from the pole to the rim, those
        about b from the rim to the pole, and the pole b + ρ u. A cap ring at latitude
        β = (π/2) j / n_r (j = 0 … n_r − 1: the rim first) has centre a − ρ sin β u (b + ρ sin β u)
        and radius ρ cos β, its n_s = :data:`CAPSULE_SIDES` vertices at azimuths 2π i / n_s
        about u from a unit normal e₁ of u (e₂ = u × e₁), with n_r = :data:`CAPSULE_CAP_RINGS`.
    triangles : ndarray (k T, 3) of int
        Rows of ``vertices``, counterclockwise seen from outside (T = 4 n_r n_s a capsule:
        a fan at each pole and two triangles for each quad between consecutive rings; the
        rims' band is the cylinder).
    """
    a = np.asarray(starts, dtype=float).reshape(-1, 3)
    b = np.asarray(ends, dtype=float).reshape(-1, 3)
    d = b - a
    length = np.linalg.norm(d, axis=1)
    along = length > tiny
    u = np.where(along[:, None], d / np.where(along, length, 1.0)[:, None], [0.0, 0.0, 1.0])
    # e1: u × (the basis vector least along u), normalised; e2 = u × e1
    e1 = np.cross(u, np.eye(3)[np.argmin(np.abs(u), axis=1)])
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(u, e1)
    n_s, n_r = CAPSULE_SIDES, CAPSULE_CAP_RINGS
    beta = 0.5 * np.pi * np.arange(n_r) / n_r
    side = np.concatenate([-np.ones(n_r), np.ones(n_r)])  # (2 n_r,): a's cap, then b's
    lat = np.concatenate([beta[::-1], beta])
    base = np.concatenate([np.repeat(a[:, None], n_r, 1), np.repeat(b[:, None], n_r, 1)], 1)
    centres = base + (side * radius * np.sin(lat))[None, :, None] * u[:, None, :]
    phi = 2.0 * np.pi * np.arange(n_s) / n_s
    spoke = np.cos(phi)[:, None] * e1[:, None, :] + np.sin(phi)[:, None] * e2[:, None, :]
    rings = centres[:, :, None, :] + (radius * np.cos(lat))[None, :, None, None] * spoke[:, None]
    vertices = np.concatenate(
        [(a - radius * u)[:, None], rings.reshape(len(a), -1, 3), (b + radius * u)[:, None]], 1
    )
    n_v = vertices.shape[1]
    # one capsule's triangles: ring r's vertex i is 1 + r n_s + i
    i = np.arange(n_s)
    nxt = (i + 1) % n_s
    last = n_v - 1
    tri = [np.stack([np.zeros(n_s, int), 1 + nxt, 1 + i], 1)]  # the fan about a's pole
    for r in range(2 * n_r - 1):
        lo, hi = 1 + r * n_s, 1 + (r + 1) * n_s
        tri += [np.stack([lo + i, lo + nxt, hi + nxt], 1), np.stack([lo + i, hi + nxt, hi + i], 1)]
    rim = 1 + (2 * n_r - 1) * n_s
    tri.append(np.stack([rim + i, rim + nxt, np.full(n_s, last)], 1))  # about b's pole
    one = np.concatenate(tri)
    triangles = (one[None] + n_v * np.arange(len(a))[:, None, None]).reshape(-1, 3)
    return vertices.reshape(-1, 3), triangles


def _capsule_trace(
    starts: Any, ends: Any, radius: float, tiny: float, colour: str, name: str
) -> dict[str, Any]:
    """One plotly mesh3d trace of the capsules about the segments start→end (k, 3): the
    vertices computed in double precision, stored in single (:func:`_typed`), which is more
    than a picture shows and halves the page's largest part, the frames' vertices."""
    vertices, triangles = _capsules(starts, ends, radius, tiny)
    return dict(
        type="mesh3d",
        **{c: _typed(vertices[:, n], single=True) for n, c in enumerate("xyz")},
        **{c: triangles[:, n].tolist() for n, c in enumerate("ijk")},
        color=colour,
        flatshading=True,
        lighting=CAPSULE_LIGHTING,
        lightposition=CAPSULE_LIGHT,
        showlegend=True,
        hoverinfo="skip",
        name=name,
    )


# --- joints: the links and the joint frames ------------------------------------------------------


def joint_frames(parts: System | Sequence[Constraint]) -> list[dict[str, Any]]:
    """The joints a view draws: each :class:`gmuk.robots.Joint` among the constraints of a
    System (or among a sequence of constraints), as a record of plain numbers and names.

    Parameters
    ----------
    parts : System or sequence of Constraint
        Constraints that are not joints are left out.

    Returns
    -------
    list of dict
        One per joint, in the constraints' order: ``name``; ``kind`` (the joint's class);
        ``parent``, the parent body's name (None for the ground, the inertial frame N);
        ``child``, the child's; ``X_PJ``, the pose of the joint frame J_p in the parent's
        body frame (in N for the ground), and ``X_CJ``, the pose of J_c in the child's body
        frame (4 × 4 nested lists, translations in m). JSON holds them exactly.

    Raises
    ------
    DefinitionError
        ``parts`` is neither a System nor a sequence.
    """
    from gmuk.engine.system import System
    from gmuk.robots.joints import Joint

    if isinstance(parts, System):
        constraints: Sequence[Any] = parts.constraints
    elif isinstance(parts, Sequence) and not isinstance(parts, (str, bytes)):
        constraints = parts
    else:
        raise DefinitionError(
            f"joints must be a System or a sequence of constraints; got {parts!r:.80}"
        )
    return [
        {
            "name": c.name,
            "kind": type(c).__name__,
            "parent": None if c.grounded else c.body_names[0],
            "child": c.body_names[-1],
            "X_PJ": c.parent_frame.tolist(),
            "X_CJ": c.child_frame.tolist(),
        }
        for c in constraints
        if isinstance(c, Joint)
    ]


def with_joint_frames(traj: Trajectory, parts: System | Sequence[Constraint]) -> Trajectory:
    """``traj`` with :func:`joint_frames` of ``parts`` in its stats (key
    :data:`JOINT_FRAMES_KEY`): its views draw the links and joint frames, also once saved and
    loaded again (``gmuk view RUN_DIR``). The arrays are shared, not copied."""
    return replace(traj, stats={**traj.stats, JOINT_FRAMES_KEY: joint_frames(parts)})


@dataclass(frozen=True)
class _JointFrames:
    """A joint as a view draws it: the bodies it joins (None: the ground) and its frames."""

    name: str
    parent: str | None
    child: str
    X_PJ: FloatArray
    X_CJ: FloatArray


def _joints(traj: Trajectory, joints: System | Sequence[Constraint] | None) -> list[_JointFrames]:
    """The joints to draw: those of ``joints``, or (None) the records in ``traj.stats``,
    checked against the trajectory's rigid bodies."""
    if joints is None:
        records = traj.stats.get(JOINT_FRAMES_KEY)
        if records is None:
            return []
        source = f"the trajectory's stats[{JOINT_FRAMES_KEY!r}]"
    else:
        records, source = joint_frames(joints), "joints"
    keys = "name, parent, child, X_PJ, X_CJ"
    if not isinstance(records, list):
        raise DefinitionError(f"{source} must be a list of joint records; got {records!r:.80}")
    rigid = [n for n, k in zip(traj.body_names, traj.body_kinds, strict=True) if k == "rigid"]
    out = []
    for k, rec in enumerate(records):
        try:
            name, parent, child = str(rec["name"]), rec["parent"], rec["child"]
            X_PJ = check_se3(rec["X_PJ"], f"{source}[{k}]['X_PJ']")
            X_CJ = check_se3(rec["X_CJ"], f"{source}[{k}]['X_CJ']")
        except (KeyError, TypeError, ValueError, GmukError) as exc:
            raise DefinitionError(
                f"{source}[{k}] must be a joint record ({keys}: joint_frames makes them); {exc}"
            ) from None
        for label, body in (("parent", parent), ("child", child)):
            if (body is not None or label == "child") and body not in rigid:
                raise DefinitionError(
                    f"{source}[{k}] (joint {name!r}): its {label} {body!r} is not a rigid body "
                    f"of the trajectory (rigid bodies: {rigid})"
                )
        out.append(_JointFrames(name, parent, child, np.array(X_PJ), np.array(X_CJ)))
    return out


def _poses(traj: Trajectory, name: str, idx: np.ndarray) -> FloatArray:
    """g_NB (k, 4, 4) of rigid body ``name`` at outputs ``idx``."""
    view = traj.body(name)
    g = np.zeros((len(idx), 4, 4))
    g[:, :3, :3], g[:, :3, 3], g[:, 3, 3] = view.R[idx], view.position[idx], 1.0
    return g


def _joint_poses(
    traj: Trajectory, joints: Sequence[_JointFrames], idx: np.ndarray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """At outputs ``idx``: the joint frames' poses ``g_NJp = g_NP X_PJ`` (``X_PJ`` for a joint
    to the ground) and ``g_NJc = g_NC X_CJ``, (k, n_joints, 4, 4); and the positions r_N (m)
    of the parents' and children's centres (body-frame origins), (k, n_joints, 3), N's
    origin for the ground."""
    names = {j.child for j in joints} | {j.parent for j in joints if j.parent is not None}
    g = {name: _poses(traj, name, idx) for name in names}
    ground = np.broadcast_to(np.eye(4), (len(idx), 4, 4))
    g_P = np.stack([ground if j.parent is None else g[j.parent] for j in joints], axis=1)
    g_C = np.stack([g[j.child] for j in joints], axis=1)
    X_PJ = np.stack([j.X_PJ for j in joints])
    X_CJ = np.stack([j.X_CJ for j in joints])
    g_NJp = np.einsum("knij,njl->knil", g_P, X_PJ)
    g_NJc = np.einsum("knij,njl->knil", g_C, X_CJ)
    return g_NJp, g_NJc, g_P[..., :3, 3], g_C[..., :3, 3]


def view_html(
    traj: Trajectory,
    *,
    central_radius: float | None = None,
    title: str = "",
    triad_length: float | None = None,
    max_frames: int = 150,
    max_path_points: int = 2000,
    plotly_src: str | None = None,
    joints: System | Sequence[Constraint] | None = None,
    draw_joint_frames: bool = True,
    joint_triad_length: float | None = None,
    link_radius: float | None = None,
) -> str:
    """The HTML page of an interactive, offline 3-D view of ``traj``.

    Parameters
    ----------
    traj : Trajectory
        Rigid bodies are drawn with their axes triads, point masses as markers; slack
        coordinates are not drawn.
    central_radius : float, optional
        Radius (m) of the central body, drawn as a sphere at N's origin; none if None.
    title : str
        Heading of the view.
    triad_length : float, optional
        Length (m) of each drawn body axis; default 12 % of the scene's size (the bodies of
        an orbit would be invisible at scale), the scene being 1 m across when the bodies do
        not move; with joints drawn, half the joint frames' (``joint_triad_length``).
    max_frames : int
        Most animation frames (≥ 2); see the module's notes on decimation.
    max_path_points : int
        Most samples per drawn path (≥ 2).
    plotly_src : str, optional
        None (default): plotly.js is embedded, and the page is the whole view. Otherwise the
        page loads plotly.js from this URL, relative to the page (a file written by
        :func:`write_plotly_js`); if it is missing there the page says so and how to make a
        self-contained view.
    joints : System or sequence of Constraint, optional
        Whose :class:`gmuk.robots.Joint` constraints to draw (see the notes); None (default):
        those recorded in ``traj.stats`` by :func:`with_joint_frames`, if any.
    draw_joint_frames : bool
        Draw each joint frame J_c's axes triad (True, default) or the links alone.
    joint_triad_length : float, optional
        Length (m) of each drawn joint frame axis; default 12 % of the mechanism's size (the
        largest extent, over the animation's frames, of its joint frame origins and the
        centres of the bodies they join).
    link_radius : float, optional
        Radius ρ (m) of the capsules drawn for the links; default 3 % of the robot's size at
        the first drawn frame (the largest distance between two of its joint frame origins
        and the centres of the bodies they join), and at least 0.4 % of the scene's.

    Returns
    -------
    str
        A complete HTML document: it makes no network request (with ``plotly_src``, only
        the file it names).

    Raises
    ------
    DefinitionError
        No rigid body or point mass to draw, an empty trajectory, a radius or length that
        is not a finite number > 0, or a joint record that does not fit the trajectory (a
        body it names is not one of its rigid bodies).

    Notes
    -----
    A system with joints (gmuk.robots joints between two bodies, or a body and the ground) is
    drawn as its kinematic skeleton, animated with the bodies: each link is a capsule of
    radius ρ (``link_radius``: the points within ρ of a segment, a cylinder closed by two
    hemispheres, drawn as a low-poly mesh) about each segment from its body's centre (its
    body-frame origin) to the origin of a joint frame fixed in it, ``g_NP X_PJ`` for the
    joints it is the parent of and ``g_NC X_CJ`` for those it is the child of; the ground's
    link, grey, runs from N's origin to its joints' frames ``X_PJ``. A segment of no length
    (a joint frame at its body's centre) is a sphere of radius ρ. Each joint frame J_c (the
    child's, which moves with the joint) is drawn as a short triad of its axes 1, 2, 3 in
    red, green and blue.
    """
    import plotly.io

    bodies = _positions(traj)
    if not bodies:
        raise DefinitionError(
            f"nothing to draw: the trajectory has no rigid body or point mass "
            f"(bodies {list(traj.body_names)}, kinds {list(traj.body_kinds)})"
        )
    if not isinstance(title, str):
        raise DefinitionError(f"title must be a string; got {title!r:.80}")
    for label, value in (
        ("central_radius", central_radius),
        ("triad_length", triad_length),
        ("joint_triad_length", joint_triad_length),
        ("link_radius", link_radius),
    ):
        try:
            if value is not None:
                real_number(value, label, positive=True)
        except DefinitionError:
            raise DefinitionError(
                f"{label} must be a finite number > 0 (m); got {value!r:.80}"
            ) from None
        if value is not None and not (np.isfinite(value) and value > 0):
            raise DefinitionError(f"{label} must be a finite number > 0 (m); got {value!r}")
    if not isinstance(draw_joint_frames, (bool, np.bool_)):
        raise DefinitionError(
            f"draw_joint_frames must be True or False; got {draw_joint_frames!r:.80}"
        )
    jointed = _joints(traj, joints)
    n = len(traj)
    path_idx = decimate(n, max_path_points)
    frame_idx = decimate(n, max_frames)

    allpos = np.concatenate([r[path_idx] for _, r, _ in bodies])
    if jointed:
        g_NJp, g_NJc, r_P, r_C = _joint_poses(traj, jointed, frame_idx)
        # (k, m, 3): every point of the skeleton at each kept frame
        skeleton = np.concatenate([g_NJp[..., :3, 3], g_NJc[..., :3, 3], r_P, r_C], axis=1)
        allpos = np.concatenate([allpos, skeleton.reshape(-1, 3)])
        robot_size = float(np.ptp(skeleton, axis=1).max())
        robot_size = robot_size if robot_size > 1e-6 else 1.0
        joint_length = joint_triad_length if joint_triad_length is not None else 0.12 * robot_size
        # the largest distance between two points of the skeleton at the first drawn frame
        reach = float(np.linalg.norm(skeleton[0][:, None] - skeleton[0][None], axis=2).max())
    size = float(np.ptp(allpos, axis=0).max()) if len(allpos) > 1 else 0.0
    if central_radius:  # the diameter, at most float64's largest (a radius near 1e308)
        central_radius = float(central_radius)
        size = max(size, min(2.0 * central_radius, sys.float_info.max))
    size = size if size > 1e-6 else 1.0  # bodies at rest: a 1 m scene
    scale, unit = (1e-3, "km") if size > KM_ABOVE_M else (1.0, "m")
    length = triad_length if triad_length is not None else 0.12 * size
    if jointed and triad_length is None:  # the joint frames' triads stand out, the bodies' less
        length = 0.5 * joint_length
    rho = 0.0  # the links' radius (m)
    if jointed:
        auto = max(LINK_RADIUS_OF_ROBOT * reach, LINK_RADIUS_OF_SCENE * size)
        rho = auto if link_radius is None else float(link_radius)
    tiny = 1e-12 * size  # a shorter segment is drawn as a sphere (m)

    traces: list[Any] = []
    if central_radius:
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 48), np.linspace(0, np.pi, 24))
        rs = central_radius * scale
        traces.append(
            dict(
                type="surface",
                x=rs * np.cos(u) * np.sin(v),
                y=rs * np.sin(u) * np.sin(v),
                z=rs * np.cos(v),
                colorscale=[[0, SPHERE_COLOUR], [1, SPHERE_COLOUR]],
                showscale=False,
                opacity=1.0,
                name="central body",
                hoverinfo="skip",
            )
        )
    for k, (name, r, _) in enumerate(bodies):
        p = r[path_idx] * scale
        traces.append(
            dict(
                type="scatter3d",
                x=p[:, 0],
                y=p[:, 1],
                z=p[:, 2],
                mode="lines",
                # the first path dark grey, the others plotly's colours
                line={"width": 3, **({"color": "rgba(60,60,60,0.8)"} if k == 0 else {})},
                name=f"{name} path",
            )
        )
    grounded = [k for k, j in enumerate(jointed) if j.parent is None]
    if grounded:  # the ground's link: fixed
        ends = np.array([jointed[k].X_PJ[:3, 3] for k in grounded]) * scale
        traces.append(
            _capsule_trace(
                np.zeros_like(ends), ends, rho * scale, tiny * scale, GROUND_COLOUR, "ground"
            )
        )
    first_dynamic = len(traces)

    def skeleton_at(f: int, page: bool) -> list[Any]:
        """The links' capsules (one trace) and the joint frames' triads (one trace per axis)
        at the kept frame ``f``; the capsules' triangles in the page's data only (``page``),
        which the frames' vertices move."""
        starts, ends = [], []
        for k, joint in enumerate(jointed):
            if joint.parent is not None:
                starts.append(r_P[f, k])
                ends.append(g_NJp[f, k, :3, 3])
            starts.append(r_C[f, k])
            ends.append(g_NJc[f, k, :3, 3])
        links = _capsule_trace(
            np.array(starts) * scale,
            np.array(ends) * scale,
            rho * scale,
            tiny * scale,
            LINK_COLOUR,
            "links",
        )
        if not page:
            links = {key: links[key] for key in ("type", "x", "y", "z", "name")}
        out = [links]
        if draw_joint_frames:
            origins = g_NJc[f, :, :3, 3] * scale
            for axis in range(3):
                tips = origins + g_NJc[f, :, :3, axis] * joint_length * scale
                out.append(
                    _segment_trace(origins, tips, AXIS_COLOURS[axis], 6, f"joint axis {axis + 1}")
                )
        return out

    def dynamic(f: int, page: bool = False) -> list[Any]:
        """The triads (one trace per axis, all rigid bodies), the markers and the skeleton at
        the kept frame ``f``: the page's initial data (``page``) or an animation frame's."""
        i = int(frame_idx[f])
        out = []
        rigid = [(r[i], R[i]) for _, r, R in bodies if R is not None]
        starts = np.array([r for r, _ in rigid]).reshape(-1, 3) * scale
        for axis in range(3):
            ends = starts + np.array([R[:, axis] for _, R in rigid]).reshape(-1, 3) * length * scale
            width = 3 if jointed else 7
            out.append(
                _segment_trace(starts, ends, AXIS_COLOURS[axis], width, f"body axis {axis + 1}")
            )
        here = np.array([r[i] for _, r, _ in bodies]) * scale
        out.append(
            dict(
                type="scatter3d",
                x=here[:, 0],
                y=here[:, 1],
                z=here[:, 2],
                mode="markers" if jointed else "markers+text",  # a mechanism's: on hover
                marker={"size": 5, "color": "#111111"},
                text=[name for name, _, _ in bodies],
                textposition="top center",
                name="bodies",
            )
        )
        return out + (skeleton_at(f, page) if jointed else [])

    n_dynamic = 4 + (1 + 3 * draw_joint_frames if jointed else 0)
    names = [f"{traj.t[i]:.6g}" for i in frame_idx]
    frames = [
        dict(
            data=dynamic(f),
            traces=list(range(first_dynamic, first_dynamic + n_dynamic)),
            name=label,
        )
        for f, label in enumerate(names)
    ]
    step_args = {"frame": {"duration": 0, "redraw": True}, "mode": "immediate"}
    axis = {"showbackground": False, "gridcolor": "#dddddd", "zerolinecolor": "#bbbbbb"}
    ranges: list[dict[str, Any]] = [{}, {}, {}]
    if jointed:  # each axis at least half the widest, so that a planar linkage is not flat
        lo, hi = allpos.min(axis=0), allpos.max(axis=0)
        if central_radius:  # the sphere, about N's origin, in the box too
            lo, hi = np.minimum(lo, -central_radius), np.maximum(hi, central_radius)
        half = np.maximum(0.5 * (hi - lo), 0.25 * float((hi - lo).max()))
        half += max(joint_length, rho)
        ranges = [
            {"range": [(c - h) * scale, (c + h) * scale], "autorange": False}
            for c, h in zip(0.5 * (lo + hi), half, strict=True)
        ]
    layout = dict(
        title={"text": title or "gmuk trajectory", "x": 0.02},
        paper_bgcolor="white",
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        legend={"x": 0.01, "y": 0.95},
        scene={
            "domain": {"x": [0.0, 1.0], "y": [0.12, 1.0]},  # the slider below it
            "aspectmode": "data",
            "camera": {"eye": {"x": 0.6, "y": -1.3, "z": 1.2}},
            "xaxis": {**axis, **ranges[0], "title": {"text": f"x_N ({unit})"}},
            "yaxis": {**axis, **ranges[1], "title": {"text": f"y_N ({unit})"}},
            "zaxis": {**axis, **ranges[2], "title": {"text": f"z_N ({unit})"}},
        },
        updatemenus=[
            {
                "type": "buttons",
                "direction": "left",
                "x": 0.02,
                "y": 0.02,
                "xanchor": "left",
                "yanchor": "bottom",
                "buttons": [
                    {
                        "label": "Play",
                        "method": "animate",
                        "args": [
                            None,
                            {
                                "frame": {"duration": 60, "redraw": True},
                                "fromcurrent": True,
                                "transition": {"duration": 0},
                            },
                        ],
                    },
                    {
                        "label": "Pause",
                        "method": "animate",
                        "args": [[None], {**step_args, "transition": {"duration": 0}}],
                    },
                ],
            }
        ],
        sliders=[
            {
                "active": 0,
                "x": 0.15,
                "y": 0.02,
                "font": {"color": "rgba(0,0,0,0)"},  # one tick per frame: no labels
                "ticklen": 2,
                "len": 0.83,
                "yanchor": "bottom",
                "currentvalue": {"prefix": "t = ", "suffix": " s", "font": {"color": "#333"}},
                "steps": [
                    {"label": label, "method": "animate", "args": [[label], step_args]}
                    for label in names
                ],
            }
        ],
    )
    # plain dicts, not validated plotly objects: validating every frame's traces cost most of
    # the view's time (0.8 of 1.15 s for a 150-frame FCEI view)
    # the default template, which a plotly Figure would have applied
    layout["template"] = plotly.io.templates[plotly.io.templates.default].to_plotly_json()
    fig = {"data": traces + dynamic(0, page=True), "frames": frames, "layout": layout}
    html: str = plotly.io.to_html(
        fig,
        validate=False,
        include_plotlyjs=True if plotly_src is None else plotly_src,
        include_mathjax=False,
        full_html=True,
        auto_play=False,  # start at t0; the Play button animates
        default_height="92vh",
        config={"displaylogo": False, "responsive": True},
    )
    if plotly_src is not None:  # a page without its library says so instead of staying blank
        html = html.replace("<body>", "<body>" + _missing_library_note(plotly_src), 1)
    return html


def _missing_library_note(src: str) -> str:
    """A script that, when the page has loaded without plotly.js, replaces it by a note."""
    note = (
        f"This view loads its plotting library from {src!r} beside its folder, which is "
        "missing. Make a self-contained view (one file, no library beside it) with: "
        "gmuk view RUN_DIR --out view.html"
    )
    return (
        "<script>window.addEventListener('load', function () {"
        "if (typeof Plotly === 'undefined') {"
        f"document.body.textContent = {json.dumps(note)};"
        "}});</script>"
    )


def plotly_js_name() -> str:
    """The file name of the shared plotly.js library, with its version:
    ``plotly-<version>.min.js``."""
    from plotly.offline import get_plotlyjs_version

    return f"plotly-{get_plotlyjs_version()}.min.js"


def write_plotly_js(folder: str | Path) -> Path:
    """Write plotly.js (4.8 MB) into ``folder`` as :func:`plotly_js_name`, once: a file
    already there with the same content is kept. Views written with ``plotly_src``
    pointing at it share it (``gmuk run`` does, one copy per output root)."""
    from plotly.offline import get_plotlyjs

    path = Path(folder) / plotly_js_name()
    text = get_plotlyjs()
    try:
        if path.read_text(encoding="utf-8") == text:
            return path
    except (OSError, UnicodeDecodeError):
        pass  # not there yet, or not this library: write it
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_text_atomic(path, text)


def write_view(
    traj: Trajectory,
    path: str | Path,
    *,
    central_radius: float | None = None,
    title: str = "",
    library: str | Path | None = None,
    **options: Any,
) -> Path:
    """Write :func:`view_html` of ``traj`` to ``path`` (atomically); returns the path.

    Parameters
    ----------
    traj : Trajectory
    path : str or Path
        The ``.html`` file to write; its folder is made if missing.
    central_radius : float, optional
        Radius (m) of the central body sphere.
    title : str
    library : str or Path, optional
        None (default): the page embeds plotly.js (4.8 MB) and is the whole view. A folder:
        plotly.js is written there once (:func:`write_plotly_js`) and the page loads it by
        its path relative to the page (about 0.3 MB a page): views of many runs share one
        copy, and a page moved away from it says so when opened.
    **options
        ``triad_length`` (m), ``max_frames``, ``max_path_points``, ``joints``,
        ``draw_joint_frames``, ``joint_triad_length`` (m), ``link_radius`` (m), as
        :func:`view_html`.

    Raises
    ------
    DefinitionError
        ``path`` is an existing folder (``gmuk view --out DIR`` writes ``DIR/view.html``;
        this function writes exactly the file it is given), a file stands where one of its
        folders should be, or as :func:`view_html`.
    OSError
        The file or its folder cannot be written (permissions); ``gmuk view`` reports it as
        a message with exit status 2.
    """
    if not isinstance(path, (str, os.PathLike)) or isinstance(path, bytes):
        raise DefinitionError(f"write_view: path must be a str or a Path; got {path!r:.80}")
    path = Path(path)
    if path.is_dir():
        raise DefinitionError(
            f"write_view: {str(path)!r} is a folder; give the .html file to write "
            f"(e.g. {str(path / 'view.html')!r})"
        )
    blocking = next((p for p in path.parents if p.exists() and not p.is_dir()), None)
    if blocking is not None:
        raise DefinitionError(
            f"write_view: cannot write {str(path)!r}: {str(blocking)!r} is a file, not a folder"
        )
    path.parent.mkdir(parents=True, exist_ok=True)
    src = None
    if library is not None:
        shared = write_plotly_js(library).resolve()
        src = quote(Path(os.path.relpath(shared, path.parent.resolve())).as_posix())
    return write_text_atomic(
        path,
        view_html(traj, central_radius=central_radius, title=title, plotly_src=src, **options),
    )
