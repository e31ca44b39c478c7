"""The 3-D view of a system with joints (issue #28, item 5): each link a capsule about the
segments from its body's centre to the origins of the joint frames fixed in it, the ground's link
from N's origin, and each joint frame J_c's axes triad, animated with the trajectory; the robot
scenarios hand their joints to the view; headless Chromium renders and animates the page with no
JavaScript error."""

from __future__ import annotations

import base64
import json
import re
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from test_view import FLAGS, render

import gmuk
from gmuk.errors import DefinitionError
from gmuk.robots import Joint
from gmuk.scenarios import four_bar, panda
from gmuk.trajectory import load_trajectory
from gmuk.view import (
    JOINT_FRAMES_KEY,
    LINK_COLOUR,
    LINK_RADIUS_OF_ROBOT,
    LINK_RADIUS_OF_SCENE,
    _capsules,
    _typed,
    decimate,
    joint_frames,
    view_html,
    with_joint_frames,
    write_view,
)


def trajectory_through(states: list[gmuk.State]) -> gmuk.Trajectory:
    """A Trajectory whose outputs are ``states`` (kinematics only: no integration)."""
    lay = states[0].layout
    n, n_dof = len(states), sum(lay.dofs)
    zeros = np.zeros((n, n_dof))
    return gmuk.Trajectory(
        t=np.array([s.t for s in states]),
        g_NB=np.array([s.g for s in states]),
        V_B=np.array([s.V for s in states]),
        x=np.zeros((n, 0)),
        xdot=np.zeros((n, 0)),
        z=np.zeros((n, 0)),
        acceleration=zeros,
        constraint_acceleration=zeros,
        constraint_force=zeros,
        control_force=zeros,
        unmodeled_force=zeros,
        multipliers=np.zeros((n, 0)),
        residual=np.zeros(n),
        rank=np.zeros(n, dtype=int),
        body_names=tuple(lay.names),
        body_kinds=tuple(k.value for k in lay.kinds),
        body_dofs=tuple(lay.dofs),
    )


def four_bar_turning(n: int = 25) -> tuple[gmuk.System, gmuk.Trajectory]:
    """The four-bar at n crank angles over a turn (states on its loop, at 8 rad/s)."""
    system, _, _ = four_bar.build()
    theta2 = np.linspace(0.0, 2.0 * np.pi, n)
    traj = trajectory_through([four_bar.state_at(system, float(a), 8.0) for a in theta2])
    return system, replace(traj, t=theta2 / 8.0)


@pytest.fixture(scope="module")
def linkage() -> tuple[gmuk.System, gmuk.Trajectory]:
    return four_bar_turning()


@pytest.fixture(scope="module")
def arm() -> tuple[gmuk.System, gmuk.Trajectory]:
    """The Panda at 12 configurations between its ready posture and a bent one."""
    robot = panda.build(damping=0.0)
    bent = panda.READY + np.array([0.6, 0.4, -0.5, 0.7, 0.9, -0.8, 1.2])
    states = [
        robot.state(panda.READY + s * (bent - panda.READY), np.zeros(robot.nv), t=s)
        for s in np.linspace(0.0, 1.0, 12)
    ]
    return robot.system, trajectory_through(states)


def no_constant(name: str) -> None:
    raise AssertionError(f"the page's data hold {name}")


def figure(page: str) -> tuple[list[dict], list[dict]]:
    """(data, frames) of a view page; a NaN or an infinity in them fails."""
    plot = r"Plotly\.newPlot\(\s*\"[^\"]+\",\s*(\[.*?\]),\s*\{"
    add = r"Plotly\.addFrames\(\s*['\"][^'\"]+['\"],\s*(\[.*\])\);"
    data, frames = (json.loads(re.search(x, page, re.S)[1], parse_constant=no_constant)
                    for x in (plot, add))  # fmt: skip
    return data, frames


def segments(trace: dict) -> np.ndarray:
    """The (start, end) points (k, 2, 3) of a trace of segments separated by None."""
    xyz = [[np.nan if v is None else v for v in trace[c]] for c in "xyz"]
    points = np.array(xyz, dtype=float).T
    assert np.isnan(points[2::3]).all()
    return np.stack([points[0::3], points[1::3]], axis=1)


def named(traces: list[dict], name: str) -> dict:
    (trace,) = [t for t in traces if t.get("name") == name]
    return trace


def numbers(values: list | dict) -> np.ndarray:
    """A trace's coordinates: a list, or plotly.js's typed-array form (base64 of little-endian
    doubles, f8, or singles, f4), as doubles."""
    if isinstance(values, dict):
        dtype = {"f8": "<f8", "f4": "<f4"}[values["dtype"]]
        return np.frombuffer(base64.b64decode(values["bdata"]), dtype=dtype).astype(float)
    return np.array(values, dtype=float)


def mesh(trace: dict, first: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The vertices (n, 3) and triangles (t, 3) of a mesh3d trace; an animation frame's trace
    moves the vertices of ``first``, the page's trace, whose triangles it keeps. The capsules'
    vertices are stored in single precision."""
    assert trace["type"] == "mesh3d"
    assert all(trace[c]["dtype"] == "f4" for c in "xyz")
    vertices = np.stack([numbers(trace[c]) for c in "xyz"], axis=1)
    faces = first if first is not None else trace
    triangles = np.array([faces[c] for c in "ijk"]).T
    assert triangles.dtype.kind == "i"
    return vertices, triangles


def distance_to_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from each point p (n, 3) to the segment a b (a point if a = b)."""
    d = b - a
    dd = float(d @ d)
    t = np.clip((p - a) @ d / dd, 0.0, 1.0) if dd > 0 else np.zeros(len(p))
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


def pieces(trace: dict) -> int:
    """The number of separate surfaces of a mesh3d trace (connected by its triangles)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    vertices, triangles = mesh(trace)
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]]])
    n = len(vertices)
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    return int(connected_components(graph, directed=False)[0])


#: Single precision's unit round-off: rounding x to the nearest float32 x̃ (24 significant bits,
#: consecutive float32s 2⁻²³ |x̃| apart at most) moves it by |x̃ − x| ≤ 2⁻²⁴ |x̃|, half that
#: spacing (x̃ normal: |x̃| > 1.2e-38). A vertex p stored as p̃ then moves by
#: ‖p̃ − p‖ ≤ 2⁻²⁴ ‖p̃‖ (coordinate by coordinate), about 6e-8 m at 1 m from N's origin.
SINGLE = 2.0**-24


def stored_error(vertices: np.ndarray) -> np.ndarray:
    """The bound 2⁻²⁴ ‖p̃‖ on how far each stored vertex p̃ (n, 3) is from the double-precision
    vertex it rounds."""
    return SINGLE * np.linalg.norm(vertices, axis=1)


def check_mesh(
    vertices: np.ndarray, triangles: np.ndarray, links: np.ndarray, rho: float, moved: np.ndarray
) -> None:
    """``vertices`` (n, 3) and ``triangles`` (t, 3) are one closed capsule of radius rho about
    each segment of ``links`` (k, 2, 3), in order: each capsule's vertices at distance rho from
    its segment, its caps reaching rho beyond the segment's ends along it, its triangles a
    closed surface. The double-precision geometry is exact to round-off, 1e-12 rho; a vertex
    that may have moved by up to ``moved`` (n,) from it, being stored in single precision, is
    within that more: the distance to a segment and the offset along it change by no more than
    the point moves."""
    assert np.isfinite(vertices).all()
    n_caps = len(links)
    assert n_caps > 0 and len(vertices) % n_caps == 0  # one capsule a segment, all alike
    per = len(vertices) // n_caps
    assert triangles.min() >= 0 and triangles.max() < len(vertices)
    # each triangle joins three vertices of one capsule, each capsule has as many
    owner = triangles // per
    assert (owner == owner[:, :1]).all()
    assert np.array_equal(
        np.bincount(owner[:, 0], minlength=n_caps), [len(triangles) // n_caps] * n_caps
    )
    # closed and consistently oriented: each directed edge once, its reverse once
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    assert len({tuple(e) for e in edges}) == len(edges)
    assert {tuple(e) for e in edges} == {(b, a) for a, b in edges}
    for c, (a, b) in enumerate(links):
        p, e = vertices[c * per : (c + 1) * per], moved[c * per : (c + 1) * per]
        off = np.abs(distance_to_segment(p, a, b) - rho)
        assert (off <= 1e-12 * rho + e).all(), (off / rho).max()
        length = np.linalg.norm(b - a)
        if length > 0:  # the caps: rho beyond each end, along the segment
            u = (b - a) / length
            assert abs(((p - b) @ u).max() - rho) <= 1e-12 * rho + e.max()
            assert abs(((p - a) @ u).min() + rho) <= 1e-12 * rho + e.max()


def check_capsules(trace: dict, first: dict | None, links: np.ndarray, rho: float) -> None:
    """``trace`` (the page's, or an animation frame's moving that of ``first``) draws one
    closed capsule of radius rho about each segment of ``links`` (k, 2, 3), to single
    precision: each stored vertex p̃ within 1e-12 rho + 2⁻²⁴ ‖p̃‖ (:data:`SINGLE`) of where
    it should be."""
    vertices, triangles = mesh(trace, first)
    check_mesh(vertices, triangles, links, rho, stored_error(vertices))


def expected_skeleton(system: gmuk.System, state: gmuk.State, length: float):
    """The links' segments (body centre → joint frame origin) and the J_c triads' segments
    of every joint, from the Joint objects and the State (independent of gmuk.view)."""
    links, axes, ground = [], [[], [], []], []
    for joint in system.constraints:
        if not isinstance(joint, Joint):
            continue
        g_NJc = state.pose(joint.child) @ joint.child_frame
        if joint.parent is None:
            ground.append((np.zeros(3), joint.parent_frame[:3, 3]))
        else:
            g_NP = state.pose(joint.parent)
            links.append((g_NP[:3, 3], (g_NP @ joint.parent_frame)[:3, 3]))
        links.append((state.pose(joint.child)[:3, 3], g_NJc[:3, 3]))
        for a in range(3):
            axes[a].append((g_NJc[:3, 3], g_NJc[:3, 3] + length * g_NJc[:3, a]))
    return np.array(links), [np.array(a) for a in axes], np.array(ground)


@pytest.mark.parametrize("which", ["linkage", "arm"])
def test_the_links_are_capsules_about_the_joint_frames_at_every_frame(which, request):
    system, traj = request.getfixturevalue(which)
    length, rho = 0.05, 0.02
    page = view_html(traj, joints=system, max_frames=7, joint_triad_length=length, link_radius=rho)
    data, frames = figure(page)
    kept = decimate(len(traj), 7)
    assert [f["name"] for f in frames] == [f"{traj.t[i]:.6g}" for i in kept]
    page_links = named(data, "links")
    for f, i in enumerate(kept):
        links, axes, ground = expected_skeleton(system, traj.state(int(i)), length)
        drawn = frames[f]["data"]
        # metres (the scene is under 100 km): capsules about the segments to round-off
        check_capsules(named(drawn, "links"), page_links, links, rho)
        for a in range(3):
            np.testing.assert_allclose(
                segments(named(drawn, f"joint axis {a + 1}")), axes[a], rtol=0, atol=1e-12
            )
        # the mesh in double precision, before it is stored: exact to round-off
        vertices, triangles = _capsules(links[:, 0], links[:, 1], rho, 0.0)
        check_mesh(vertices, triangles, links, rho, np.zeros(len(vertices)))
        assert np.array_equal(triangles, mesh(page_links)[1])
        if f == 0:  # the first frame is the page's initial data
            check_capsules(page_links, None, links, rho)
            assert named(drawn, "links") == {k: page_links[k] for k in named(drawn, "links")}
        assert "i" not in named(drawn, "links")  # the frames move the page's mesh
    if len(ground):  # the four-bar: O2 and O4; the Panda: its base (a sphere: at N's origin)
        check_capsules(named(data, "ground"), None, ground, rho)
        # the page stores the nearest singles of the double-precision mesh, bit for bit
        exact, _ = _capsules(ground[:, 0], ground[:, 1], rho, 0.0)
        stored = named(data, "ground")
        for n, c in enumerate("xyz"):
            assert stored[c]["dtype"] == "f4"
            assert base64.b64decode(stored[c]["bdata"]) == exact[:, n].astype("<f4").tobytes()
    # the links move: the middle frame's differ from the first's
    first, middle = (mesh(named(frames[k]["data"], "links"), page_links)[0] for k in (0, 3))
    assert np.abs(first - middle).max() > 0.05


def test_single_precision_is_kept_for_numbers_it_holds():
    """The capsules' typed arrays: the nearest singles of the doubles (f4), or the doubles
    themselves (f8) for numbers beyond single precision's range (|x| > 3.4e38)."""
    x = np.array([0.1, -2.0 / 3.0, 1e38, 0.0])
    small = _typed(x, single=True)
    assert small["dtype"] == "f4" and numbers(small).tolist() == x.astype(np.float32).tolist()
    assert np.all(np.abs(numbers(small) - x) <= SINGLE * np.abs(numbers(small)))
    huge = _typed(np.append(x, -1e39), single=True)
    assert huge["dtype"] == "f8" and numbers(huge).tolist() == [*x, -1e39]
    assert _typed(x)["dtype"] == "f8"


def robot_reach(system: gmuk.System, state: gmuk.State) -> float:
    """The largest distance between two of the joint frame origins and the centres of the
    bodies they join (N's origin for the ground)."""
    points = []
    for joint in system.constraints:
        if isinstance(joint, Joint):
            g_NP = np.eye(4) if joint.parent is None else state.pose(joint.parent)
            g_NC = state.pose(joint.child)
            points += [g_NP[:3, 3], g_NC[:3, 3]]
            points += [(g_NP @ joint.parent_frame)[:3, 3], (g_NC @ joint.child_frame)[:3, 3]]
    p = np.array(points)
    return max(float(np.linalg.norm(p - q, axis=1).max()) for q in p)


@pytest.mark.parametrize("which", ["linkage", "arm"])
def test_the_automatic_link_radius_is_a_fraction_of_the_robot_or_of_the_scene(which, request):
    system, traj = request.getfixturevalue(which)
    later = trajectory_through([traj.state(i) for i in range(5, len(traj))])
    radii = []
    for shown in (traj, later):  # the robot at the first drawn frame, for every frame
        data, frames = figure(view_html(shown, joints=system, max_frames=4))
        rho = LINK_RADIUS_OF_ROBOT * robot_reach(system, shown.state(0))
        for f, i in enumerate(decimate(len(shown), 4)):
            links, _, _ = expected_skeleton(system, shown.state(int(i)), 1.0)
            check_capsules(named(frames[f]["data"], "links"), named(data, "links"), links, rho)
        radii.append(rho)
        assert 0.005 < rho < 0.05  # m: a few centimetres for a robot about a metre across
    assert radii[0] != radii[1]
    # beside a body 200 m wide, the robot is small: its links 0.4 % of the scene
    links, _, ground = expected_skeleton(system, traj.state(0), 1.0)
    data, _ = figure(view_html(traj, joints=system, central_radius=100.0))
    check_capsules(named(data, "links"), None, links, LINK_RADIUS_OF_SCENE * 200.0)
    # a scene over 100 km is drawn in km, the capsules too
    data, _ = figure(view_html(traj, joints=system, central_radius=1e6))
    rho = LINK_RADIUS_OF_SCENE * 2e6
    check_capsules(named(data, "links"), None, links * 1e-3, rho * 1e-3)
    check_capsules(named(data, "ground"), None, ground * 1e-3, rho * 1e-3)


def test_a_link_of_no_length_is_a_sphere(linkage):
    """A joint frame at its body's centre: the child's segment has no length; its capsule is
    the sphere of radius rho about the point, with no NaN in the page."""
    system, traj = linkage
    records = joint_frames(system)
    X_CJ = np.array(records[1]["X_CJ"])
    X_CJ[:3, 3] = 0.0  # joint A's frame at the coupler's centre
    records[1] = {**records[1], "X_CJ": X_CJ.tolist()}
    odd = replace(traj, stats={JOINT_FRAMES_KEY: records})
    data, frames = figure(view_html(odd, link_radius=0.03))
    vertices, _ = mesh(named(data, "links"))
    # the crank's two segments, then the coupler's, whose centre is now also its end
    per = len(vertices) // 6
    sphere = vertices[2 * per : 3 * per]
    centre = odd.state(0).pose("coupler")[:3, 3]
    off = np.abs(np.linalg.norm(sphere - centre, axis=1) - 0.03)  # in single precision
    assert (off <= 1e-12 * 0.03 + stored_error(sphere)).all()
    assert np.isfinite(mesh(named(data, "ground"))[0]).all()
    for fr in frames:
        assert np.isfinite(mesh(named(fr["data"], "links"), named(data, "links"))[0]).all()
    assert pieces(named(data, "links")) == 6


def test_the_number_of_traces_is_the_paths_the_ground_and_the_moving_parts(linkage, arm):
    system, traj = linkage
    for draw, moving in ((True, 4 + 1 + 3), (False, 4 + 1)):
        data, frames = figure(view_html(traj, joints=system, draw_joint_frames=draw))
        static = 3 + 1  # three bars' paths, the ground
        assert len(data) == static + moving
        assert [t["name"] for t in data[:static]] == [
            "crank path",
            "coupler path",
            "rocker path",
            "ground",
        ]
        assert all(fr["traces"] == list(range(static, static + moving)) for fr in frames)
        assert all(len(fr["data"]) == moving for fr in frames)
        # two capsules for a joint between bars (A, B), one for a joint to the ground
        assert pieces(named(data, "links")) == 2 + 2 + 1 + 1
        assert pieces(named(data, "ground")) == 2
    # the Panda: seven links' paths, its base on the ground; seven joints, one to the ground
    system, traj = arm
    data, _ = figure(view_html(traj, joints=system))
    assert len(data) == 7 + 1 + 8
    assert pieces(named(data, "links")) == 2 * 6 + 1
    # a trajectory without joints is drawn as before: paths, body axes, markers
    plain, _ = figure(view_html(traj))
    assert [t["name"] for t in plain[7:]] == [
        "body axis 1",
        "body axis 2",
        "body axis 3",
        "bodies",
    ]


def test_the_joints_travel_with_the_trajectory_through_save_and_load(linkage, tmp_path):
    system, traj = linkage
    marked = with_joint_frames(traj, system)
    assert JOINT_FRAMES_KEY not in traj.stats  # a new Trajectory; the arrays shared
    assert marked.g_NB is traj.g_NB
    records = marked.stats[JOINT_FRAMES_KEY]
    assert [(r["name"], r["parent"], r["child"]) for r in records] == [
        ("O2", None, "crank"),
        ("A", "crank", "coupler"),
        ("B", "coupler", "rocker"),
        ("O4", None, "rocker"),
    ]
    assert records == joint_frames(system.constraints)
    loaded = load_trajectory(marked.save(tmp_path / "four_bar.npz"))
    # JSON holds the frames exactly: the same figure as from the System itself
    assert figure(view_html(loaded)) == figure(view_html(traj, joints=system))
    assert figure(view_html(marked)) == figure(view_html(traj, joints=system))


def test_a_view_refuses_joints_that_do_not_fit_the_trajectory(linkage):
    system, traj = linkage
    good = joint_frames(system)
    wrong_body = [{**good[1], "child": "crankshaft"}]
    bent = [{**good[0], "X_PJ": (2.0 * np.eye(4)).tolist()}]
    for records, message in (
        (wrong_body, r"its child 'crankshaft' is not a rigid body of the trajectory"),
        (bent, r"stats\['joint_frames'\]\[0\] must be a joint record"),
        ([{"name": "O2"}], r"must be a joint record .*'parent'"),
        ("O2", "must be a list of joint records"),
    ):
        odd = replace(traj, stats={JOINT_FRAMES_KEY: records})
        with pytest.raises(DefinitionError, match=message):
            view_html(odd)
    with pytest.raises(DefinitionError, match="joints must be a System or a sequence"):
        view_html(traj, joints=42)  # type: ignore[arg-type]
    with pytest.raises(DefinitionError, match="draw_joint_frames must be True or False"):
        view_html(traj, joints=system, draw_joint_frames="no")  # type: ignore[arg-type]
    with pytest.raises(DefinitionError, match="joint_triad_length must be a finite number > 0"):
        view_html(traj, joints=system, joint_triad_length=-0.1)


@pytest.mark.parametrize(
    ("name", "duration", "n_joints", "n_grounded"),
    [("panda", 0.05, 7, 1), ("four-bar", 0.02, 4, 2), ("stewart", 0.01, 18, 6)],
)
def test_the_robot_scenarios_hand_their_joints_to_gmuk_runs_view(
    name, duration, n_joints, n_grounded, tmp_path
):
    """The scenario's trajectory carries its joints, so ``gmuk run``'s view.html (and ``gmuk
    view`` of the run folder, from trajectory.npz) draws the mechanism."""
    from gmuk.scenarios import get

    result = get(name).run(duration=duration)
    traj = result.trajectories[result.primary]
    records = traj.stats[JOINT_FRAMES_KEY]
    assert len(records) == n_joints
    assert sum(r["parent"] is None for r in records) == n_grounded
    if name == "panda":
        assert [r["name"] for r in records] == list(result.data["robot"].joints)
    page = write_view(load_trajectory(traj.save(tmp_path / "trajectory.npz")), tmp_path / "v.html")
    data, _ = figure(page.read_text())
    drawn = [t["name"] for t in data]
    assert "ground" in drawn and "links" in drawn and "joint axis 3" in drawn
    assert pieces(named(data, "links")) == 2 * n_joints - n_grounded


# --- headless Chromium --------------------------------------------------------------------------

#: A caught error or rejected promise marks <html data-js-error="its message">; once plotly has
#: added the frames, the page animates to the last one and marks <body data-animated="yes">.
WATCH = """<script>
function caught(text) { document.documentElement.setAttribute('data-js-error', text); }
window.addEventListener('error', function (e) { caught(String(e.message)); });
window.addEventListener('unhandledrejection', function (e) { caught(String(e.reason)); });
</script>"""
ANIMATE = """<script>
var tries = 0, timer = setInterval(function () {
  var gd = document.querySelector('.plotly-graph-div');
  var frames = gd && gd._transitionData && gd._transitionData._frames;
  if ((!frames || !frames.length) && ++tries < 200) { return; }
  clearInterval(timer);
  Plotly.animate(gd, [frames[frames.length - 1].name],
                 {frame: {duration: 0, redraw: true}, transition: {duration: 0},
                  mode: 'immediate'})
    .then(function () { document.body.setAttribute('data-animated', 'yes'); });
}, 50);
</script>"""


def watched(page: str) -> str:
    """``page`` with the error watcher first in its head and the animation at its end."""
    return page.replace("<head>", "<head>" + WATCH, 1).replace("</body>", ANIMATE + "</body>", 1)


def error_and_dom(chromium: str, path: Path, profile: Path) -> tuple[str | None, str]:
    """The page's script error (None if none) and its DOM after headless Chromium ran it,
    with 60 s of virtual time: the capsules' frames take longer to lay out than the budget
    of the views without them."""
    flags = [
        "--virtual-time-budget=60000" if f.startswith("--virtual-time-budget") else f for f in FLAGS
    ]
    text = subprocess.run(
        [chromium, *flags, f"--user-data-dir={profile}", "--dump-dom", path.resolve().as_uri()],
        check=True,
        capture_output=True,
        text=True,
        timeout=180,
    ).stdout
    found = re.search(r'<html[^>]*data-js-error="([^"]*)"', text)
    return (found[1] if found else None), text


def link_pixels(image: np.ndarray) -> int:
    """Pixels of a lit shade of the links' colour, LINK_COLOUR (#rrggbb) = c: s c, each
    channel's ratio to c within 4 % of their mean s, 0.6 < s < 1.3. The capsules' facets
    facing the light are near s = 1; those in the ambient light alone (s = 0.5) are left out,
    as is plotly's text colour (#2a3f5f, 0.48 c)."""
    colour = np.array([int(LINK_COLOUR[k : k + 2], 16) for k in (1, 3, 5)])
    ratio = image / colour
    s = ratio.mean(axis=2)
    shade = np.abs(ratio - s[..., None]).max(axis=2) < 0.04 * s
    return int((shade & (s > 0.6) & (s < 1.3)).sum())


def test_chromium_draws_and_animates_a_robot_view_with_no_script_error(chromium, tmp_path, arm):
    system, traj = arm
    page = view_html(traj, joints=system, title="Panda", max_frames=30)
    (tmp_path / "arm.html").write_text(watched(page))
    # Headless Chromium sometimes dumps the DOM before plotly.js's animation promise resolves
    # (seen in about one run in three on a loaded 2-core box, with no script error): a
    # script error fails at once; a page that did not get to animate is run again, twice.
    for attempt in range(3):
        error, text = error_and_dom(chromium, tmp_path / "arm.html", tmp_path / f"p1-{attempt}")
        assert error is None, error
        if 'data-animated="yes"' in text:
            break
    assert 'data-animated="yes"' in text, "the view never reached its last frame"
    # the watcher catches an error: a page whose script fails says so
    (tmp_path / "bad.html").write_text(
        watched(page.replace("</body>", "<script>null.x</script></body>"))
    )
    error, _ = error_and_dom(chromium, tmp_path / "bad.html", tmp_path / "p2")
    assert error is not None and "null" in error, error
    # the links are drawn, and lit: thousands of pixels of lit shades of their colour, none in
    # the same view without joints
    image, requests = render(chromium, write_view(traj, tmp_path / "v.html", joints=system),
                             tmp_path / "v.png")  # fmt: skip
    bare, _ = render(chromium, write_view(traj, tmp_path / "b.html"), tmp_path / "b.png")
    assert requests == []
    assert link_pixels(image) > 1_000 and link_pixels(bare) < 50, (
        link_pixels(image),
        link_pixels(bare),
    )


def test_gmuk_view_takes_the_links_radius_and_refuses_it_without_joints(linkage, tmp_path, capsys):
    from gmuk.cli import main

    system, traj = linkage
    npz = with_joint_frames(traj, system).save(tmp_path / "four_bar.npz")
    assert main(["view", str(npz), "--link-radius", "0.02", "--out", str(tmp_path / "v.html")]) == 0
    data, _ = figure((tmp_path / "v.html").read_text())
    kept = decimate(len(traj), 150)
    links, _, _ = expected_skeleton(system, traj.state(int(kept[0])), 0.05)
    check_capsules(named(data, "links"), None, links, 0.02)
    for bad in ("0", "-0.1", "nan", "inf", "wide"):
        assert main(["view", str(npz), "--link-radius", bad]) == 2
        assert "--link-radius" in capsys.readouterr().err
    bare = traj.save(tmp_path / "bare.npz")  # no joints recorded
    assert main(["view", str(bare), "--link-radius", "0.02"]) == 2
    assert "records no joints" in capsys.readouterr().err
