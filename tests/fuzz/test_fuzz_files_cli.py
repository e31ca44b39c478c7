"""Fuzz the readers (load_gfc, load_shadr, load_trajectory) with hostile files and the
``gmuk`` command with hostile option values (issue #15)."""

from __future__ import annotations

import functools
import io
import itertools
import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
from fuzz_inputs import REFUSED, fuzz_pair, outcome
from hypothesis import strategies as st

import gmuk
from gmuk import cli, scenarios
from gmuk.gravity import load_gfc, load_shadr
from gmuk.scenarios import Option, ScenarioResult

_TMP = Path(tempfile.mkdtemp(prefix="gmuk-fuzz-"))
_COUNTER = itertools.count()


def _fresh(suffix: str) -> Path:
    return _TMP / f"f{next(_COUNTER)}{suffix}"


GFC_LINES = [
    "earth_gravity_constant 0.3986004415E+15",
    "radius 0.63781363E+07",
    "norm fully_normalized",
    "max_degree 3",
    "end_of_head",
    "gfc 0 0 1.0d0 0.0d0",
    "gfc 2 0 -0.484165143790815e-03 0.0",
    "gfc 2 1 -0.2e-09 0.1e-08",
    "gfc 2 2 0.24e-05 -0.14e-05",
    "gfc 3 0 0.95e-06 0.0",
    "gfc 3 1 0.20e-05 0.24e-06",
    "gfc 3 2 0.90e-06 -0.61e-06",
    "gfc 3 3 0.72e-06 0.14e-05",
]
SHADR_LINES = [
    "1.7380000000000000E+03, 4.9028000000000000E+03, 0.0, 3, 3, 1, 0.0, 0.0",
    *(
        f"{n:5d}, {m:5d}, {1e-6 * (n + m):.16E}, {-1e-6 * m:.16E}, 0.0, 0.0"
        for n in range(1, 4)
        for m in range(n + 1)
    ),
]
TOKENS = st.sampled_from(
    [
        "nan",
        "inf",
        "-inf",
        "1e308",
        "1e309",
        "-1",
        "0",
        "99999999999",
        "1.5",
        "",
        "x",
        "1d999",
        "0x10",
        "  ",
        "\x00",
        "é",
        "gfc",
        ",",
        "end_of_head",
        "max_degree",
        "4",
        "1e-320",
    ]
)


def _mutate(lines: list[str]):
    """Files made from ``lines`` by replacing tokens, lines, truncating or adding bytes."""

    @st.composite
    def build(draw):
        out = list(lines)
        for _ in range(draw(st.integers(1, 4))):
            how = draw(st.sampled_from(["token", "token", "line", "drop", "dup", "cut"]))
            i = draw(st.integers(0, len(out) - 1)) if out else 0
            if not out:
                break
            if how == "token":
                parts = out[i].replace(",", " , ").split()
                if parts:
                    j = draw(st.integers(0, len(parts) - 1))
                    parts[j] = draw(TOKENS)
                    out[i] = " ".join(parts).replace(" , ", ", ")
            elif how == "line":
                out[i] = draw(st.one_of(TOKENS, st.text(max_size=20)))
            elif how == "drop":
                del out[i]
            elif how == "dup":
                out.insert(i, out[i])
            else:
                out = out[:i]
        data = "\n".join(out).encode("utf-8", "surrogatepass") + b"\n"
        if draw(st.booleans()):
            data = data[: draw(st.integers(0, len(data)))]
        if draw(st.integers(0, 9)) == 0:
            data = draw(st.binary(max_size=40)) + data
        return data

    return build()


degrees = st.one_of(
    st.none(), st.sampled_from([0, 1, 2, 3, 4, -1, 10**9, 2.5, True, "3", np.int64(2)])
)


def _check_reader(entry, reader, args) -> None:
    data, degree = args
    path = _fresh(".txt")
    path.write_bytes(data)
    field = outcome(entry, reader, path, degree=degree)
    if field is REFUSED:
        return
    assert field.mu > 0 and field.radius > 0
    assert np.isfinite(field.C).all() and np.isfinite(field.S).all()
    assert degree is None or (isinstance(degree, (int, np.integer)) and field.degree == degree)
    assert not isinstance(degree, bool), "a bool degree was taken"


(
    test_load_gfc_reads_a_field_or_raises_a_gmuk_error,
    test_load_gfc_reads_a_field_or_raises_a_gmuk_error_slow,
) = fuzz_pair(
    st.tuples(_mutate(GFC_LINES), degrees),
    lambda a: _check_reader("gravity.load_gfc", load_gfc, a),
    fast=60,
    slow=1000,
)
(
    test_load_shadr_reads_a_field_or_raises_a_gmuk_error,
    test_load_shadr_reads_a_field_or_raises_a_gmuk_error_slow,
) = fuzz_pair(
    st.tuples(_mutate(SHADR_LINES), degrees),
    lambda a: _check_reader("gravity.load_shadr", load_shadr, a),
    fast=60,
    slow=1000,
)


def test_the_unmutated_files_are_read():  # the mutations start from valid files
    for reader, lines in ((load_gfc, GFC_LINES), (load_shadr, SHADR_LINES)):
        path = _fresh(".txt")
        path.write_text("\n".join(lines) + "\n")
        assert reader(path).degree == 3


# ------------------------------------------------------------------------- trajectories
@functools.cache
def _saved() -> bytes:
    system = gmuk.System(
        [gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 2.5])), gmuk.PointMass("p", 1.0)]
    )
    state = system.state(
        g={"a": np.eye(4)},
        V={"a": np.array([0.1, 0.2, 0.3, 1, 0, 0])},
        r={"p": np.ones(3)},
        v={"p": np.zeros(3)},
    )
    traj = system.simulate(state, (0.0, 1e-2), t_eval=np.linspace(0, 1e-2, 4))
    path = _fresh(".npz")
    traj.save(path)
    return path.read_bytes()


def _members() -> dict[str, np.ndarray]:
    with np.load(io.BytesIO(_saved()), allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


HOSTILE_ARRAYS = [
    np.array(np.nan),
    np.array([np.inf]),
    np.zeros(0),
    np.zeros((2, 2, 2, 2, 2)),
    np.array(["x"]),
    np.array([True]),
    np.array([1e308, -1e308]),
    np.array([1 + 1j]),
    np.array(5),
]


@st.composite
def trajectory_files(draw):
    how = draw(st.sampled_from(["flip", "cut", "member", "meta", "drop", "junk"]))
    data = _saved()
    if how == "flip":
        i = draw(st.integers(0, len(data) - 1))
        return data[:i] + bytes([data[i] ^ draw(st.integers(1, 255))]) + data[i + 1 :]
    if how == "cut":
        return data[: draw(st.integers(0, len(data) - 1))]
    if how == "junk":
        return draw(st.binary(max_size=64))
    members = _members()
    keys = sorted(members)
    key = draw(st.sampled_from(keys))
    if how == "drop":
        del members[key]
    elif how == "member":
        nan_copy = members[key] * np.nan if members[key].dtype.kind in "fiu" else members[key]
        members[key] = draw(st.one_of(st.sampled_from(HOSTILE_ARRAYS), st.just(nan_copy)))
    else:  # edit the metadata JSON
        meta_key = next((k for k in keys if "meta" in k), key)
        try:
            meta = json.loads(str(members[meta_key]))
        except ValueError:
            meta = {}
        if isinstance(meta, dict) and meta:
            field = draw(st.sampled_from(sorted(meta)))
            meta[field] = draw(
                st.one_of(st.none(), st.integers(-5, 10**6), st.text(max_size=4), st.just([1, "x"]))
            )
        members[meta_key] = np.array(json.dumps(meta))
    buf = io.BytesIO()
    np.savez(buf, **members)
    return buf.getvalue()


@pytest.mark.parametrize(("offset", "value"), [(8, 99), (6, 1)])
def test_load_trajectory_reads_or_refuses_a_flipped_zip_header(offset, value):
    # zipfile reads a member's method from the central directory: a flipped byte in the first
    # local header may be harmless; if it is not, the error is a FileFormatError
    original = _saved()
    data = bytearray(original)
    data[offset] = value  # first local header: compression method / flag bits
    path, clean = _fresh(".npz"), _fresh(".npz")
    path.write_bytes(bytes(data))
    clean.write_bytes(original)
    try:
        traj = gmuk.load_trajectory(path)
    except gmuk.errors.FileFormatError:
        return
    np.testing.assert_array_equal(traj.g_NB, gmuk.load_trajectory(clean).g_NB)


def test_load_trajectory_refuses_a_z_of_the_wrong_shape():
    members = _members()
    members["z"] = np.zeros(4)
    path = _fresh(".npz")
    np.savez(path, **members)
    with pytest.raises(gmuk.errors.FileFormatError, match="z"):
        gmuk.load_trajectory(path).layout


def test_load_trajectory_refuses_non_finite_arrays():
    members = _members()
    members["V_B"] = members["V_B"] * np.nan
    path = _fresh(".npz")
    np.savez(path, **members)
    with pytest.raises(gmuk.errors.FileFormatError, match="V_B"):
        gmuk.load_trajectory(path)


def check_load_trajectory(data) -> None:
    path = _fresh(".npz")
    path.write_bytes(data)
    traj = outcome("load_trajectory", gmuk.load_trajectory, path)
    if traj is REFUSED:
        return
    assert np.isfinite(traj.t).all() and np.isfinite(traj.g_NB).all()
    assert np.isfinite(traj.V_B).all() and traj.t.shape[0] == traj.g_NB.shape[0]


(
    test_load_trajectory_reads_or_raises_file_format_error,
    test_load_trajectory_reads_or_raises_file_format_error_slow,
) = fuzz_pair(trajectory_files(), check_load_trajectory, fast=60, slow=1000)


def test_load_trajectory_of_an_unmutated_file_works():
    path = _fresh(".npz")
    path.write_bytes(_saved())
    assert gmuk.load_trajectory(path).t.size == 4


# -------------------------------------------------------------------------------- CLI
def _probe_run(rate=1.0, moments=(1.0, 2.0, 3.0), duration=1e-3, stiff=False, mode="a"):
    system = gmuk.System([gmuk.RigidBody("box", 1.0, np.diag(moments))])
    state = system.state(g={"box": np.eye(4)}, V={"box": np.array([0, rate, 0, 0, 0, 0.0])})
    traj = system.simulate(state, (0.0, duration), max_steps=100, on_failure="return")
    return ScenarioResult("fuzzprobe", {"main": traj}, "main", {"rate": rate})


PROBE = scenarios.Scenario(
    "fuzzprobe",
    "a tiny scenario for fuzzing option values",
    _probe_run,
    lambda result, out, formats: [],
    options=(
        Option("rate", float, 1.0, "spin rate (rad/s)"),
        Option("moments", scenarios.comma_separated(float), (1.0, 2.0, 3.0), "moments"),
        Option("duration", scenarios.positive_float, 1e-3, "simulated time (s)"),
        Option("stiff", scenarios.boolean, False, "a flag"),
        Option("mode", str, "a", "a choice", choices=("a", "b")),
    ),
)

values = st.one_of(
    st.sampled_from(
        [
            "nan",
            "inf",
            "-inf",
            "1e308",
            "1e309",
            "0",
            "-0",
            "1",
            "2.5",
            "",
            " ",
            "x",
            "1,2",
            "1,,2",
            "nan,1,1",
            "1e-320",
            "true",
            "no",
            "a",
            "b",
            "é",
            "٣",
            "0x1p3",
            "1_0",
        ]
    ),
    st.text(
        alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters="\x00"),
        max_size=8,
    ),
)


@pytest.fixture(scope="module")
def probe():
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(scenarios.SCENARIOS, "fuzzprobe", f"{__name__}:PROBE")
        scenarios.refresh()
        yield
    scenarios.refresh()


def _main(argv):
    """cli.main, with SystemExit counted as a raise (main must return its status)."""
    try:
        return cli.main(argv)
    except SystemExit as exc:  # pragma: no cover - reported as a failure
        raise AssertionError(f"cli.main({argv!r}) raised SystemExit({exc.code!r})") from None


def check_cli_scenario_option(args) -> None:
    flag, value = args
    if value.startswith("-"):
        return  # argparse reads it as a flag: see test_cli_..._starting_with_a_dash
    out = _fresh("")
    status = outcome(
        "cli.main run (option values)",
        _main,
        ["run", "fuzzprobe", flag, value, "--no-plots", "--out", str(out)],
    )
    assert status in (0, 2), f"exit status {status} for {flag} {value!r}"
    if status == 0:
        assert (out / "trajectory.npz").is_file()
        summary = json.loads((out / "summary.json").read_text())
        assert summary["scenario"] == "fuzzprobe"
        # a failed probe run (e.g. --rate 1e308) saves an empty trajectory; it says so
        n = gmuk.load_trajectory(out / "trajectory.npz").t.size
        assert n >= 1 or summary["status"] != "success"
    else:
        assert not (out / "trajectory.npz").exists()


flags = st.sampled_from(["--rate", "--moments", "--duration", "--stiff", "--mode", "--format"])
_cli_fast, _cli_slow = fuzz_pair(
    st.tuples(flags, values), check_cli_scenario_option, fast=40, slow=600
)


def test_cli_option_values_exit_0_or_2_and_never_raise(probe):
    _cli_fast()


@pytest.mark.slow
def test_cli_option_values_exit_0_or_2_and_never_raise_slow(probe):
    _cli_slow.__wrapped__ if False else _cli_slow()


def test_real_scenarios_parse_hostile_option_values_into_values_or_option_errors():
    # every declared option of every scenario, without running any (parse_options only)
    for scenario, _ in scenarios.available():
        if scenario.name == "fuzzprobe":
            continue  # ours, with a plain float option: NaN is its run's to refuse
        for option in scenario.options:
            for text in ["nan", "inf", "-1", "0", "1e309", "", "x", "1,,2", "é", "٣", "1e-320"]:
                got = outcome(
                    f"scenario.parse_options ({scenario.name})",
                    scenario.parse_options,
                    {option.name: text},
                )
                if got is not REFUSED:
                    assert option.name in got


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "fuzzprobe", "--checkpoint-every", "abc"],
        ["run", "fuzzprobe", "--rate", "-1e308"],
        ["check", "--seed", "x"],
        ["check", "--samples", "nan"],
    ],
)
def test_cli_argparse_errors_return_2_without_raising(probe, argv):
    assert _main([*argv, "--out", str(_fresh(""))] if argv[0] == "run" else argv) == 2
