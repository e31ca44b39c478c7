"""Fuzz what a run leaves and reads back (issue #25): a trajectory's save/load round trip
and its accessors, checkpoints and resume (stopped at any time, records edited), campaigns
of a user function, ``gmuk.view`` and the ``gmuk`` subcommands ``view``, ``campaign``,
``check``, ``list`` and ``plugins``.

Oracles: a saved trajectory loads back bit-identical (every array, names, status, stats);
a run stopped anywhere and resumed equals the uninterrupted run to 1e-12 (RK4: the same
steps), and a checkpoint edited by hand is refused with a CheckpointError or gives that
same result, never another; a campaign's table has one row per run whose metrics are the
function's of the row's parameters, the same seed gives the same table bit for bit, and a
resume of a finished campaign computes nothing and changes nothing; a view is one HTML page
that never carries a ``</script>`` it was given; ``gmuk`` exits 0, 1 or 2 and never raises.
"""

from __future__ import annotations

import contextlib
import functools
import io
import itertools
import json
import math
import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fuzz_inputs import REFUSED, fuzz_pair, honest_real, junk, outcome, scalars
from helpers import StopAt
from hypothesis import strategies as st

import gmuk
from gmuk import cli, runs
from gmuk.campaign import Campaign, Normal, Parameter, Uniform, read_table, resume
from gmuk.lie import se3
from gmuk.view import decimate, view_html, write_view

_TMP = Path(tempfile.mkdtemp(prefix="gmuk-fuzz-runs-"))
_COUNTER = itertools.count()


def _fresh(suffix: str = "") -> Path:
    return _TMP / f"r{next(_COUNTER)}{suffix}"


# ------------------------------------------------------------------ save/load round trip
def _simulate_small(n_rigid, n_point, seed, method, n_out):
    rng = np.random.default_rng(seed)
    bodies = [gmuk.RigidBody(f"b{i}", 1.0 + i, np.diag([1.0, 2.0, 2.5])) for i in range(n_rigid)]
    bodies += [gmuk.PointMass(f"p{i}", 1.0 + i) for i in range(n_point)]
    forces = [gmuk.UniformGravity()] if n_point else []
    system = gmuk.System(bodies, forces=forces)
    state = system.state(
        g={f"b{i}": se3.exp(rng.normal(size=6)) for i in range(n_rigid)},
        V={f"b{i}": rng.normal(size=6) for i in range(n_rigid)},
        r={f"p{i}": rng.normal(size=3) for i in range(n_point)},
        v={f"p{i}": rng.normal(size=3) for i in range(n_point)},
    )
    kw = {"step": 1e-2} if method == "RK4" else {}
    t_eval = np.linspace(0.0, 0.1, n_out) if n_out else None
    return system.simulate(state, (0.0, 0.1), method=method, t_eval=t_eval, **kw)


ARRAYS = ("t", "g_NB", "V_B", "x", "xdot", "z", "multipliers", "residual", "rank")


def check_round_trip(args) -> None:
    n_rigid, n_point, seed, method, n_out, suffix = args
    if n_rigid + n_point == 0:
        return
    traj = _simulate_small(n_rigid, n_point, seed, method, n_out)
    path = _fresh(suffix)
    saved = outcome("Trajectory.save", traj.save, path)
    assert saved is not REFUSED and saved.suffix == ".npz"
    back = outcome("load_trajectory (round trip)", gmuk.load_trajectory, saved)
    assert back is not REFUSED, "a saved trajectory was refused on reading"
    for name in ARRAYS:
        a, b = getattr(traj, name), getattr(back, name)
        assert a.dtype == b.dtype and a.shape == b.shape, f"{name}: dtype or shape changed"
        assert np.array_equal(a, b, equal_nan=True), f"{name} changed on the round trip"
        assert a.tobytes() == b.tobytes(), f"{name} is not bit-identical"
    for name in ("body_names", "body_kinds", "body_dofs", "status", "message"):
        assert getattr(traj, name) == getattr(back, name), f"{name} changed on the round trip"
    assert json.dumps(traj.stats, sort_keys=True, default=str) == json.dumps(
        back.stats, sort_keys=True, default=str
    )
    # a second save of what was loaded writes the same arrays again
    again = gmuk.load_trajectory(back.save(_fresh(".npz")))
    assert all(np.array_equal(getattr(again, n), getattr(traj, n)) for n in ARRAYS)


(
    test_a_saved_trajectory_loads_back_bit_identical,
    test_a_saved_trajectory_loads_back_bit_identical_slow,
) = fuzz_pair(
    st.tuples(
        st.integers(0, 2),
        st.integers(0, 2),
        st.integers(0, 2**32 - 1),
        st.sampled_from(["DOP853", "RK4", "DOPRI5"]),
        st.sampled_from([0, 1, 2, 7]),
        st.sampled_from([".npz", "", ".bin"]),
    ),
    check_round_trip,
    fast=15,
    slow=400,
)


@functools.cache
def _traj():
    return _simulate_small(1, 1, 0, "DOP853", 9)


def check_accessors(args) -> None:
    which, value = args
    traj = _traj()
    if which == "state":
        s = outcome("Trajectory.state", traj.state, value)
        if s is not REFUSED:
            assert isinstance(value, (int, np.integer)) and not isinstance(value, bool), value
            i = int(value)
            assert np.array_equal(s.g, traj.g_NB[i]) and s.t == traj.t[i]
    elif which == "body":
        b = outcome("Trajectory.body", traj.body, value)
        if b is not REFUSED:
            assert value in traj.body_names
    else:
        body = traj.body("b0")
        angles = outcome("BodyTrajectory.euler", body.euler, value)
        if angles is not REFUSED:
            assert isinstance(value, str), f"euler took seq {value!r}"
            R = gmuk.lie.euler.to_matrix(angles, value)
            assert np.abs(R - traj.g_NB[:, 0, :3, :3]).max() < 1e-9


(
    test_trajectory_accessors_take_indices_names_and_sequences,
    test_trajectory_accessors_take_indices_names_and_sequences_slow,
) = fuzz_pair(
    st.tuples(
        st.sampled_from(["state", "body", "euler"]),
        st.one_of(
            st.integers(-12, 12),
            st.sampled_from(["b0", "p0", "321", "313", "123", "xyz", "ZYX", "32", ""]),
            scalars,
        ),
    ),
    check_accessors,
    fast=40,
    slow=1000,
)


# ------------------------------------------------------------------ checkpoints, resume
def _pendulum(t_stop):
    bob = gmuk.PointMass("bob", 0.4)
    system = gmuk.System(
        [bob],
        [gmuk.PlaneBound(bob, [0, 0, 1.0], lower=-1.0, name="floor")],
        [gmuk.UniformGravity(), gmuk.LinearSpringDamper(3.0, 0.1), StopAt(t_stop)],
    )
    state = system.state(r={"bob": [1.0, 0.0, 0.0]}, v={"bob": [0.0, 1.0, 0.5]})
    return system, state


T_EVAL = np.linspace(0.0, 2.0, 41)


def _run(system, state, method):
    kw = {"step": 1e-2} if method == "RK4" else {"rtol": 1e-10, "atol": 1e-12}
    return system.simulate(state, (0.0, 2.0), t_eval=T_EVAL, method=method, **kw)


@functools.cache
def _uninterrupted(method):
    return _run(*_pendulum(1e9), method)


def _edit_checkpoint(path: Path, field: str, value) -> None:
    """Rewrite ``path`` with ``stats["checkpoint"][field] = value`` (or a member changed)."""
    with np.load(path, allow_pickle=False) as z:
        members = {k: z[k] for k in z.files}
    meta_key = next(k for k in members if "meta" in k)
    meta = json.loads(str(members[meta_key]))
    record = meta.get("stats", {}).get("checkpoint", {})
    if field in record:
        record[field] = value
    elif field in members and members[field].dtype.kind == "f":
        members[field] = members[field] + 1e-9
    members[meta_key] = np.array(json.dumps(meta))
    buf = io.BytesIO()
    np.savez(buf, **members)
    path.write_bytes(buf.getvalue())


def check_resume(args) -> None:
    method, t_stop, every_s, edit = args
    folder = _fresh()
    system, state = _pendulum(t_stop)
    entry = f"run_control + resume ({method})"
    with runs.run_control(folder, every_s=every_s):
        cut = outcome(entry + " [first part]", _run, system, state, method)
    assert cut is not REFUSED and cut.status in ("interrupted", "success")
    plain = _uninterrupted(method)
    if cut.status == "success":
        assert t_stop >= 2.0 or cut.t[-1] == 2.0
    checkpoint = folder / "run-0.npz"
    assert checkpoint.exists(), "a stopped run left no checkpoint"
    if edit is not None:
        _edit_checkpoint(checkpoint, *edit)

    def resumed():
        with runs.run_control(folder, resume=True):
            return _run(*_pendulum(1e9), method)

    again = outcome(entry, resumed)
    if again is REFUSED:
        assert edit is not None, "an untouched checkpoint was refused"
        return
    assert again.success, f"{entry}: {again.status}: {again.message}"
    assert np.array_equal(again.t, plain.t), "the resumed run has other output times"
    tol = 1e-12 if method == "RK4" else 1e-8
    scale = 1.0 + np.abs(plain.x).max()
    assert np.abs(again.x - plain.x).max() <= tol * scale, (
        f"{entry}: resumed differs from uninterrupted by {np.abs(again.x - plain.x).max():.3g}"
        f" (edit {edit!r})"
    )
    assert np.abs(again.xdot - plain.xdot).max() <= tol * (1 + np.abs(plain.xdot).max())


edits = st.one_of(
    st.none(),
    st.none(),
    st.tuples(
        st.sampled_from(["t", "h", "out_i", "complete", "status", "base", "x", "xdot"]),
        st.one_of(
            st.sampled_from([-5.0, 0.0, 0.5, 2.0, 1e308, True, False, None, "x", [], 3]),
            st.floats(allow_nan=False, allow_infinity=False),
        ),
    ),
)

(
    test_a_stopped_run_resumes_to_the_uninterrupted_result_or_is_refused,
    test_a_stopped_run_resumes_to_the_uninterrupted_result_or_is_refused_slow,
) = fuzz_pair(
    st.tuples(
        st.sampled_from(["RK4", "RK4", "DOP853"]),
        st.one_of(st.floats(0.0, 1.99), st.sampled_from([0.0, 1.0, 5.0])),
        st.sampled_from([1e-9, 3600.0]),
        edits,
    ),
    check_resume,
    fast=12,
    slow=250,
)


def test_run_control_options_are_checked():
    for every_s in (0.0, -1.0, math.nan, "1", True, None, [1.0]):
        got = outcome(
            "run_control", lambda e=every_s: runs.run_control(_fresh(), every_s=e).__enter__()
        )
        assert got is REFUSED, f"run_control took every_s={every_s!r}"


# --------------------------------------------------------------------------- campaigns
def metrics(params):
    """A campaign function (importable by name): metrics from the parameters."""
    return {"y": 2.0 * params["x"] + params["n"], "norm": float(np.linalg.norm(params["v"]))}


PARAMETERS = {
    "x": Parameter("x", "real", 1.0, "a real", low=-10.0, high=10.0),
    "n": Parameter("n", "integer", 3, "an integer", low=0, high=100),
    "v": (1.0, 0.0, 0.0),
}


def check_campaign(args) -> None:
    runs_n, seed, dispersion, fixed = args
    dispersions = None if dispersion is None else {"x": dispersion}
    entry = "Campaign.from_function"
    campaign = outcome(
        entry,
        Campaign.from_function,
        metrics,
        PARAMETERS,
        runs=runs_n,
        seed=seed,
        dispersions=dispersions,
        fixed=fixed,
    )
    if campaign is REFUSED:
        return
    assert isinstance(runs_n, (int, np.integer)) and not isinstance(runs_n, bool), runs_n
    assert isinstance(seed, (int, np.integer)) and not isinstance(seed, bool), seed
    if fixed:
        x = fixed.get("x")
        assert x is None or (honest_real(x) and -10 <= float(x) <= 10), f"took x={x!r}"
    if runs_n > 6:
        return  # constructed lazily: the large ones are not run here
    out = _fresh()
    report = outcome("Campaign.run", campaign.run, out, hang_s=60.0)
    assert report is not REFUSED, "an accepted campaign failed to run"
    assert report.finished == report.computed == runs_n and report.failed == 0
    table = read_table(out).to_pylist()
    assert [r["run"] for r in table] == list(range(runs_n)), "runs lost or duplicated"
    for r in table:
        x, n = r["p_x"], r["p_n"]
        v = np.array([r["p_v_1"], r["p_v_2"], r["p_v_3"]])
        assert r["m_y"] == 2.0 * x + n and r["m_norm"] == float(np.linalg.norm(v))
        assert -10 <= x <= 10, f"a dispersed x = {x} left its domain"
    # the same campaign again gives the same table, and a resume of it computes nothing
    out2 = _fresh()
    campaign.run(out2)
    cols = [c for c in read_table(out).column_names if c not in ("wall_time_s", "worker")]
    assert read_table(out).select(cols).equals(read_table(out2).select(cols))
    again = outcome("campaign.resume (complete)", resume, out)
    assert again is not REFUSED and again.computed == 0 and again.finished == runs_n
    assert read_table(out).select(cols).equals(read_table(out2).select(cols))


def _campaign_strategy():
    return st.tuples(
        st.one_of(st.integers(0, 4), st.sampled_from([10**20, -1, 6]), scalars),
        st.one_of(st.integers(0, 2**32), scalars),
        st.one_of(
            st.none(),
            st.tuples(
                st.sampled_from([Normal, Uniform]),
                st.one_of(st.floats(-1, 0), scalars),
                st.one_of(st.floats(0.1, 2), scalars),
            ),
        ),
        st.one_of(
            st.none(),
            st.fixed_dictionaries({"x": st.one_of(st.floats(-12, 12), scalars)}),
            st.fixed_dictionaries({"nope": st.just(1.0)}),
            junk,
        ),
    )


def check_campaign_args(args) -> None:
    runs_n, seed, disp, fixed = args
    dispersion = None
    if disp is not None:
        kind, a, b = disp
        dispersion = outcome(f"campaign.{kind.__name__}", kind, a, b)
        if dispersion is REFUSED:
            return
        assert honest_real(a) and honest_real(b), f"{kind.__name__} took {a!r:.60}, {b!r:.60}"
    check_campaign((runs_n, seed, dispersion, fixed))


(
    test_campaigns_of_a_function_record_every_run_once_and_repeat_bit_for_bit,
    test_campaigns_of_a_function_record_every_run_once_and_repeat_bit_for_bit_slow,
) = fuzz_pair(_campaign_strategy(), check_campaign_args, fast=15, slow=150)


# -------------------------------------------------------------------------------- view
def check_view(args) -> None:
    option, value, title = args
    traj = _traj()
    kw = {option: value} if option else {}
    html = outcome("view.view_html", view_html, traj, title=title, **kw)
    if html is REFUSED:
        assert not isinstance(title, str) or option, f"view_html refused title {title!r:.80}"
        return
    assert isinstance(title, str), f"view_html took title {title!r:.80}"
    assert html.lstrip().lower().startswith("<!doctype html") and html.count("</html>") == 1
    assert "</script><script>" not in title or "</script><script>alert" not in html
    if option in ("central_radius", "triad_length") and value is not None:
        assert honest_real(value) and 0 < float(value) < math.inf, f"took {option}={value!r}"
    if option in ("max_frames", "max_path_points"):
        assert isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= 2


(
    test_view_html_takes_honest_options_and_escapes_titles,
    test_view_html_takes_honest_options_and_escapes_titles_slow,
) = fuzz_pair(
    st.tuples(
        st.sampled_from([None, "central_radius", "triad_length", "max_frames", "max_path_points"]),
        st.one_of(st.integers(-3, 500), scalars),
        st.one_of(
            st.sampled_from(["", "orbit", "</script><script>alert(1)</script>", "é<&>\"'"]),
            st.text(max_size=12),
            junk,
        ),
    ),
    check_view,
    fast=30,
    slow=600,
)


def check_decimate(args) -> None:
    n, most = args
    idx = outcome("view.decimate", decimate, n, most)
    if idx is REFUSED:
        return
    for v in (n, most):  # integers (0-d integer arrays too), never bools, floats, strings
        assert np.ndim(v) == 0 and np.asarray(v).dtype.kind in "iu", f"decimate took {v!r}"
    n, most = int(n), int(most)
    assert n >= 1 and most >= 2
    assert idx.size <= min(n, most) and idx[0] == 0 and idx[-1] == n - 1
    assert (np.diff(idx) > 0).all()


(
    test_decimate_keeps_first_and_last_and_at_most_most,
    test_decimate_keeps_first_and_last_and_at_most_most_slow,
) = fuzz_pair(
    st.tuples(st.one_of(st.integers(-2, 10**6), scalars), st.one_of(st.integers(-2, 500), scalars)),
    check_decimate,
    fast=60,
    slow=1500,
)


def check_write_view(target) -> None:
    path = target(_fresh()) if callable(target) else target
    if isinstance(path, str):  # a relative junk name: under the fuzz's folder, not the cwd
        path = str(_fresh() / path) if path.strip("./") else path
    here = _fresh()
    here.mkdir()
    with contextlib.chdir(here):  # whatever stays relative lands there, not in the cwd
        out = outcome("view.write_view", write_view, _traj(), path)
    if out is REFUSED:
        return
    assert out.is_file() and out.read_text(encoding="utf-8").count("</html>") == 1


def _targets():
    def in_dir(p: Path) -> Path:
        p.mkdir()
        return p

    def html(p: Path) -> Path:
        return p.with_suffix(".html")

    def missing_parent(p: Path) -> Path:
        return p / "no" / "such" / "view.html"

    def blocked(p: Path) -> Path:
        p.mkdir()
        (p / "view.html").mkdir()
        return p

    def a_file_as_parent(p: Path) -> Path:
        p.write_text("x")
        return p / "view.html"

    return st.one_of(
        st.sampled_from([in_dir, html, missing_parent, blocked, a_file_as_parent]), junk
    )


(
    test_write_view_writes_a_page_or_refuses_the_path,
    test_write_view_writes_a_page_or_refuses_the_path_slow,
) = fuzz_pair(_targets(), check_write_view, fast=20, slow=300)


# -------------------------------------------------------------------------------- CLI
def _main(argv):
    try:
        return cli.main(argv)
    except SystemExit as exc:  # must return its status instead
        raise AssertionError(f"cli.main({argv!r}) raised SystemExit({exc.code!r})") from None


@functools.cache
def _saved_file() -> str:
    path = _fresh(".npz")
    _traj().save(path)
    return str(path)


def _hostile_file(how: str) -> str:
    path = _fresh(".npz")
    data = Path(_saved_file()).read_bytes()
    if how == "ok":
        return _saved_file()
    if how == "cut":
        path.write_bytes(data[: len(data) // 2])
    elif how == "empty":
        path.write_bytes(b"")
    elif how == "dir":
        path.mkdir()
    elif how == "missing":
        pass
    elif how == "npy":
        np.save(path.with_suffix(".npy"), np.zeros(3))
        return str(path.with_suffix(".npy"))
    elif how == "zip":
        with zipfile.ZipFile(path, "w") as z:
            z.writestr("x.npy", b"\x93NUMPY junk")
    return str(path)


VIEW_VALUES = ["nan", "inf", "-1", "0", "1", "2", "1e309", "", "x", "3.5", "1e6", "٣"]


def check_cli_view(args) -> None:
    how, flag, value, out_how = args
    argv = ["view", _hostile_file(how)]
    if flag:
        argv += [flag, value]
    out = _fresh()
    if out_how == "dir":
        out.mkdir()
    elif out_how == "file":
        out = out.with_suffix(".html")
    if out_how != "none":
        argv += ["--out", str(out)]
    status = outcome("cli.main view", _main, argv)
    assert status in (0, 2), f"exit status {status} for {argv}"
    if status == 0:
        assert how == "ok", f"gmuk view read a {how} file"
        written = out / "view.html" if out_how == "dir" else out
        if out_how != "none":
            assert written.is_file() and "</html>" in written.read_text(encoding="utf-8")


(
    test_cli_view_exits_0_or_2_and_writes_a_page,
    test_cli_view_exits_0_or_2_and_writes_a_page_slow,
) = fuzz_pair(
    st.tuples(
        st.sampled_from(["ok", "ok", "ok", "cut", "empty", "dir", "missing", "npy", "zip"]),
        st.sampled_from([None, "--central-radius", "--max-frames"]),
        st.sampled_from(VIEW_VALUES),
        st.sampled_from(["dir", "file", "file"]),
    ),
    check_cli_view,
    fast=25,
    slow=600,
)

CAMPAIGN_TOKENS = [
    "fcei", "ucei", "nope", "--runs", "0", "1", "-1", "10", "1e3", "nan", "99999999999999999999",
    "--seed", "x", "--workers", "0", "--set", "orbits=nan", "orbits=-1", "samples=2",
    "--disperse", "x=cone:500", "initial_attitude_error=cone:nan", "a=ball:-1", "b=normal:0,",
    "c=uniform:2,1", "d=choice:", "e=range:3,1", "f=moments:0,0", "--sweep", "degree=5:1",
    "degree=1:10**9", "--parameters", "--summary", "--resume", "--format", "png,xyz",
    "--no-progress", "--save-trajectories", "=", "", "é",
]  # fmt: skip


def check_cli_campaign(tokens) -> None:
    out = _fresh()
    argv = ["campaign", *tokens]
    if "--out" not in argv:
        argv += ["--out", str(out)]
    has_runs = "--runs" in tokens
    if has_runs:
        i = tokens.index("--runs")
        nxt = tokens[i + 1] if i + 1 < len(tokens) else ""
        if nxt.isdigit() and int(nxt) > 0:
            return  # a real scenario run is not for the fuzz (see tests/campaign)
    if "--resume" in tokens or "--summary" in tokens:
        argv = [*argv[:-2], str(out)] if argv[-2] == "--out" else argv
    status = outcome("cli.main campaign", _main, argv, hang_s=60.0)
    assert status in (0, 2), f"exit status {status} for {argv}"


(
    test_cli_campaign_exits_0_or_2_on_any_argument_list,
    test_cli_campaign_exits_0_or_2_on_any_argument_list_slow,
) = fuzz_pair(
    st.lists(st.sampled_from(CAMPAIGN_TOKENS), min_size=0, max_size=6),
    check_cli_campaign,
    fast=40,
    slow=1500,
)


def check_cli_misc(argv) -> None:
    status = outcome("cli.main (list, plugins, check, help)", _main, argv, hang_s=60.0)
    assert status in (0, 1, 2), f"exit status {status} for {argv}"
    if argv in (["list"], ["plugins"]):
        assert status == 0


(
    test_cli_subcommands_exit_with_a_status_and_never_raise,
    test_cli_subcommands_exit_with_a_status_and_never_raise_slow,
) = fuzz_pair(
    st.one_of(
        st.sampled_from([["list"], ["plugins"], [], ["--help"], ["nope"], ["list", "x"]]),
        st.tuples(
            st.sampled_from(["0", "1", "-1", "x", "nan", "1e3", "", "99999999999999999999"]),
            st.sampled_from(["0", "1", "3", "-1", "x", "nan", "1e3", "", "2.5"]),
        ).map(lambda t: ["check", "--seed", t[0], "--samples", t[1]]),
        st.lists(st.sampled_from(["list", "check", "view", "-h", "--x", "run", ""]), max_size=3),
    ),
    check_cli_misc,
    fast=20,
    slow=300,
)


pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")
