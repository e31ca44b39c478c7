"""The gmuk command and the scenario registry: declared options, plugins, errors.

A scenario defined here, outside the package (``TUMBLE``), is registered both ways gmuk
offers (one line in ``SCENARIOS``, or an entry point of the group ``gmuk.scenarios``) and
run through ``gmuk.cli.main`` with its own options.
"""

from __future__ import annotations

import dataclasses
import inspect
import json
from pathlib import Path

import numba
import numpy as np
import pytest

import gmuk
from gmuk import _plugins, cli, plotting, scenarios
from gmuk.errors import DefinitionError, GmukError, PluginWarning
from gmuk.scenarios import Option, OptionError, Scenario, ScenarioResult
from gmuk.view import plotly_js_name

# --- a scenario that is not part of gmuk --------------------------------------------------------


def tumble_run(
    spin: float = 1.0, moments: tuple[float, ...] = (1.0, 2.0, 3.0), duration: float = 5.0
) -> ScenarioResult:
    """A torque-free body spun about its intermediate axis, nudged about the others."""
    body = gmuk.RigidBody("box", 2.0, np.diag(moments))
    system = gmuk.System([body], [], [])
    V0 = np.array([1e-3 * spin, spin, 1e-3 * spin, 0.0, 0.0, 0.0])
    state = system.state(g={"box": np.eye(4)}, V={"box": V0})
    t = np.linspace(0.0, duration, 51)
    traj = system.simulate(state, (0.0, duration), t_eval=t, rtol=1e-11, atol=1e-11)
    omega = traj.body("box").omega
    energy = 0.5 * np.einsum("ni,i,ni->n", omega, np.asarray(moments), omega)
    summary = {
        "spin_rad_s": spin,
        "moments_kg_m2": list(moments),
        "max_abs_omega1_rad_s": float(np.abs(omega[:, 0]).max()),
        "energy_relative_drift": float(np.ptp(energy) / energy[0]),
    }
    return ScenarioResult("tumble", {"tumble": traj}, "tumble", summary)


def tumble_figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    traj = result.trajectories["tumble"]
    series = [("ω", traj.body("box").omega)]
    labels = [f"ω{k} (rad/s)" for k in "123"]
    return plotting.plot_components(traj.t, series, labels, "Tumbling box", out / "omega", formats)


TUMBLE = Scenario(
    "tumble",
    "torque-free box spun about its intermediate axis",
    tumble_run,
    tumble_figures,
    options=(
        Option("spin", float, 1.0, "initial rate about body axis 2 (rad/s)"),
        Option(
            "moments",
            scenarios.comma_separated(float),
            (1.0, 2.0, 3.0),
            "principal moments J1,J2,J3 (kg·m²)",
        ),
        Option("duration", scenarios.positive_float, 5.0, "simulated time (s)"),
    ),
)


class _EntryPoint:
    """Stands in for an installed distribution's entry point."""

    class _Dist:
        name = "gmuk-tumble"

    group = scenarios.ENTRY_POINT_GROUP
    dist = _Dist()

    def __init__(self, name, load):
        self.name, self.value, self._load = name, f"gmuk_tumble:{name}", load

    def load(self):
        return self._load()


@pytest.fixture
def plugins(monkeypatch):
    """Replace the installed scenario entry points by the given ones."""

    def install(*eps):
        monkeypatch.setattr(
            _plugins.metadata,
            "entry_points",
            lambda group: list(eps) if group == scenarios.ENTRY_POINT_GROUP else [],
        )
        scenarios.refresh()

    yield install
    scenarios.refresh()


@pytest.fixture
def registered(monkeypatch):
    """TUMBLE registered by one line in SCENARIOS, as a scenario of gmuk would be."""
    monkeypatch.setitem(scenarios.SCENARIOS, "tumble", f"{__name__}:TUMBLE")
    scenarios.refresh()
    yield
    scenarios.refresh()


def test_a_scenario_registered_in_one_line_runs_with_its_declared_options(
    registered, tmp_path, capsys
):
    assert scenarios.get("tumble") is TUMBLE
    assert cli.main(["list"]) == 0
    listing = capsys.readouterr().out
    width = max(len(name) for name, _ in scenarios.describe())  # names padded to the longest
    assert f"{'tumble':<{width}} {TUMBLE.description}" in listing
    assert f"{'unmodeled':<{width}} Ch. 5" in listing
    out = tmp_path / "tumble"
    argv = ["run", "tumble", "--spin", "2", "--moments", "1,2,2.5", "--out", str(out)]
    assert cli.main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenario"] == "tumble"
    # what computed it, as the trajectory records it too
    assert summary["versions"] == {
        "gmuk": gmuk.__version__,
        "numba": numba.__version__,
        "numpy": np.__version__,
    }
    assert summary["options"] == {"spin": 2.0, "moments": [1.0, 2.0, 2.5], "duration": 5.0}
    assert summary["spin_rad_s"] == 2.0 and summary["moments_kg_m2"] == [1.0, 2.0, 2.5]
    assert summary["energy_relative_drift"] < 1e-9
    assert summary["max_abs_omega1_rad_s"] > 1e-3 * 2.0  # the intermediate axis is unstable
    assert (out / "omega.png").is_file()
    traj = gmuk.load_trajectory(out / "trajectory.npz")
    assert traj.t[-1] == 5.0 and traj.body_names == ("box",)
    assert traj.stats["versions"] == summary["versions"]
    assert "tumble (spin=2.0, moments=1.0,2.0,2.5, duration=5.0)" in capsys.readouterr().out


def test_help_of_a_scenario_lists_its_options_with_defaults(registered, capsys):
    assert cli.main(["run", "tumble", "--help"]) == 0  # returned, not a SystemExit
    text = " ".join(capsys.readouterr().out.split())
    assert "usage: gmuk run tumble" in text and TUMBLE.description in text
    assert "--spin SPIN initial rate about body axis 2 (rad/s) (default: 1.0)" in text
    assert "--moments MOMENTS principal moments J1,J2,J3 (kg·m²) (default: 1.0,2.0,3.0)" in text
    assert "--out DIR" in text and "--format" in text and "--no-plots" in text
    assert "--orbits" not in text  # not declared by this scenario


def test_bad_values_name_the_flag_and_what_came_in(registered, tmp_path, capsys):
    out = ["--out", str(tmp_path / "x")]
    cases = [
        (["--spin", "fast"], "--spin must be a number; got 'fast'"),
        (["--duration", "-1"], "--duration must be a finite number > 0; got '-1'"),
        (["--moments", "1,,3"], "--moments must be one or more comma-separated values"),
        (["--moments", "1,a"], "--moments must be comma-separated numbers, e.g. 2,10,50; got"),
        (["--orbits", "2"], "scenario 'tumble' does not take --orbits 2; its options: --spin"),
        (["--format", "gif"], "--format takes png, pdf, svg"),
    ]
    for args, message in cases:
        assert cli.main(["run", "tumble", *args, *out]) == 2, args
        assert message in capsys.readouterr().err, args
    assert not (tmp_path / "x").exists()  # nothing ran


def test_a_plugin_scenario_is_discovered_and_run(plugins, tmp_path, capsys):
    plugins(_EntryPoint("tumble", lambda: TUMBLE))
    assert [s.name for s, _ in scenarios.available()][-1] == "tumble"
    assert cli.main(["list"]) == 0
    assert "[plugin: gmuk-tumble]" in capsys.readouterr().out
    out = tmp_path / "p"
    argv = ["run", "tumble", "--duration", "1", "--no-plots", "--out", str(out)]
    assert cli.main(argv) == 0
    assert json.loads((out / "summary.json").read_text())["options"]["duration"] == 1.0
    assert not list(out.glob("*.png")) and not (out / "view.html").exists()  # --no-plots


def test_broken_plugins_warn_and_are_skipped(plugins):
    def fail():
        raise ImportError("no module named gmuk_tumble")

    plugins(
        _EntryPoint("broken", fail),
        _EntryPoint("not_a_scenario", lambda: tumble_run),
        _EntryPoint("misnamed", lambda: TUMBLE),
        _EntryPoint("fcei", lambda: TUMBLE),
    )
    with pytest.warns(PluginWarning) as record:
        names = [s.name for s, _ in scenarios.available()]
    text = " | ".join(str(w.message) for w in record)
    assert "'broken'" in text and "failed to load" in text and "ImportError" in text
    assert "'not_a_scenario'" in text and "not a gmuk.scenarios.Scenario" in text
    assert "'misnamed'" in text and "a Scenario named 'tumble'" in text
    assert "'fcei'" in text and "name is taken by gmuk" in text
    assert names == list(scenarios.SCENARIOS)
    assert scenarios.get("fcei").run.__module__ == "gmuk.scenarios.fcei"


def test_discovery_is_cached(plugins, monkeypatch):
    calls = []
    plugins()
    monkeypatch.setattr(_plugins.metadata, "entry_points", lambda group: calls.append(group) or [])
    scenarios.refresh()
    scenarios.available()
    scenarios.get("fcei")
    scenarios.describe()
    assert calls == [scenarios.ENTRY_POINT_GROUP]


def test_gmuk_run_alone_runs_fcei_with_its_defaults(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["run"]) == 0
    out = tmp_path / "gmuk-out" / "fcei"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenario"] == "fcei" and summary["orbits"] == 1.0
    assert summary["options"] == {"orbits": 1.0}
    assert len(list(out.glob("*.png"))) == 7  # the six thesis groups and orbit_3d
    assert (out / "view.html").is_file()
    assert "fcei (orbits=1.0)" in capsys.readouterr().out


def test_a_run_says_what_it_is_doing_and_what_its_time_went_to(
    plugins, tmp_path, monkeypatch, capsys
):
    """Every phase longer than ANNOUNCE_AFTER_S is announced on stderr with its time; the
    summary's time_s has every phase and their total; --csv writes the primary run."""
    plugins(_EntryPoint("tumble", lambda: TUMBLE))
    monkeypatch.setattr(cli, "ANNOUNCE_AFTER_S", 0.0)  # every phase counts as long
    out = tmp_path / "runs" / "t"
    assert cli.main(["run", "tumble", "--duration", "1", "--csv", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    for doing in ("simulating (spin=1", "writing trajectory.npz", "writing trajectory.csv"):
        assert f"gmuk: tumble: {doing}" in err, err
    assert "gmuk: tumble: drawing the figures: " in err and "3-D view" in err
    times = json.loads((out / "summary.json").read_text())["time_s"]
    phases = ["loop", "compile", "simulation", "save", "csv", "figures", "view"]
    assert list(times) == [*phases, "total"]
    assert times["total"] == pytest.approx(sum(times[k] for k in phases), abs=1e-2)
    header = (out / "trajectory.csv").read_text().splitlines()[0].split(",")
    table = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    traj = gmuk.load_trajectory(out / "trajectory.npz")
    assert header[:2] == ["t_s", "box.x_m"] and table.shape == (len(traj), len(header))
    np.testing.assert_array_equal(table[:, 0], traj.t)
    # the view loads the one plotly.js written beside the run folders
    assert (tmp_path / "runs" / plotly_js_name()).is_file()
    assert f'src="../{plotly_js_name()}"' in (out / "view.html").read_text()


def test_declared_defaults_are_the_run_functions_defaults():
    for scenario, _ in scenarios.available():
        params = inspect.signature(scenario.run).parameters
        for option in scenario.options:
            assert option.name in params, (scenario.name, option.name)
            assert params[option.name].default == option.default, (scenario.name, option.name)
        # every keyword of run with a default is reachable from the command line
        assert {o.name for o in scenario.options} == {
            n for n, p in params.items() if p.default is not inspect.Parameter.empty
        }, scenario.name


#: the thesis's orbital scenarios, which take --orbits (the others take --duration)
THESIS_ORBITS = (
    "apollo16", "fccn", "fcei", "fceim", "ucei", "uceis", "uceim", "fccl", "unmodeled",
    "maintenance",
)  # fmt: skip


def test_every_builtin_scenario_takes_orbits_and_keeps_its_module_api():
    import importlib

    for name, target in scenarios.SCENARIOS.items():
        if name.startswith("smd-"):  # one module, three scenarios, no orbits
            module_name, attribute = target.split(":")
            scenario = getattr(importlib.import_module(module_name), attribute)
            assert scenario is scenarios.get(name)
            assert scenario.option("duration").default == 30.0
            continue
        module = importlib.import_module(target.split(":")[0])
        assert module.SCENARIO is scenarios.get(name)
        assert (module.NAME, module.DESCRIPTION) == (name, module.SCENARIO.description)
        assert module.SCENARIO.run is module.run and module.SCENARIO.figures is module.figures
        if name not in THESIS_ORBITS:  # beyond the thesis: a duration in seconds
            assert module.SCENARIO.option("duration").default > 0.0, name
            continue
        orbits = module.SCENARIO.option("orbits")
        # fccl runs two orbits by default (its position error needs 1.83), maintenance the
        # ten its bound is to hold for, the others one
        assert orbits.default == {"fccl": 2.0, "maintenance": 10.0}.get(name, 1.0)
        assert orbits.parse("0.5") == 0.5
        with pytest.raises(OptionError, match="--orbits must be a finite number > 0; got '0'"):
            orbits.parse("0")


def test_option_parsers():
    degrees = scenarios.comma_separated(int)
    assert degrees("2, 10,50") == (2, 10, 50)
    for bad in ("", "2,", "2.5", "a"):
        with pytest.raises(ValueError, match="comma-separated"):
            degrees(bad)
    assert [scenarios.boolean(t) for t in ("Yes", "off", "1", "FALSE")] == [1, 0, 1, 0]
    with pytest.raises(ValueError, match="true or false"):
        scenarios.boolean("maybe")
    for bad in ("0", "-2", "nan", "inf", "x"):
        with pytest.raises(ValueError, match="finite number > 0"):
            scenarios.positive_float(bad)
    option = Option("model", str, "both", "which", ("both", "correct"))
    assert option.parse("correct") == "correct" and option.flag == "--model"
    with pytest.raises(OptionError, match="--model must be one of both, correct; got 'exact'"):
        option.parse("exact")
    count = Option("sample_count", int, 3, "samples")
    assert count.flag == "--sample-count" and count.help_text == "samples (default: 3)"
    with pytest.raises(OptionError, match=r"--sample-count must be an integer; got '3\.5'"):
        count.parse("3.5")
    assert isinstance(OptionError("x"), GmukError)


def test_bad_definitions_are_refused():
    with pytest.raises(DefinitionError, match="type=bool"):
        Option("fast", bool, False, "x")
    with pytest.raises(DefinitionError, match="not one of the choices"):
        Option("model", str, "exact", "x", ("both", "correct"))
    with pytest.raises(DefinitionError, match="Python identifier"):
        Option("two words", str, "", "x")
    spin = Option("spin", float, 1.0, "x")
    for options, message in (
        ((spin, spin), "declared twice: spin"),
        ((Option("out", str, "", "x"),), "reserved for the gmuk run command"),
    ):
        with pytest.raises(DefinitionError, match=message):
            Scenario("tumble", "d", tumble_run, tumble_figures, options)
    with pytest.raises(DefinitionError, match="lower case"):
        Scenario("Tumble", "d", tumble_run, tumble_figures)
    with pytest.raises(OptionError, match="has no option 'speed'; it takes spin"):
        TUMBLE.parse_options({"speed": "2"})


def test_unknown_scenario_and_no_command(capsys):
    assert cli.main(["run", "nope"]) == 2
    assert "unknown scenario 'nope'; available: apollo16, fccn" in capsys.readouterr().err
    assert cli.main([]) == 2
    assert "check" in capsys.readouterr().out


def test_an_impossible_span_or_output_folder_is_a_clear_error(tmp_path, capsys):
    assert cli.main(["run", "fcei", "--orbits", "1e300", "--out", str(tmp_path / "a")]) == 2
    assert "asks for 7.21e+302 output times" in capsys.readouterr().err
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert cli.main(["run", "fcei", "--orbits", "0.01", "--out", str(blocker / "sub")]) == 2
    assert "cannot make the output folder" in capsys.readouterr().err


def test_the_parts_compile_time_is_counted_apart_from_the_simulation():
    """Numba's compile events inside the scenario's run go to time_s["compile"] (listed
    before the simulation), and the simulation keeps the rest."""
    phases = cli._Phases("x")
    for key in ("loop", "simulation", "save"):
        with phases.phase(key, None):
            pass
    phases.times.update(loop=1.0, simulation=5.0, save=0.5)
    phases.split("simulation", "compile", 3.0)
    assert phases.times == {"loop": 1.0, "compile": 3.0, "simulation": 2.0, "save": 0.5}
    phases.split("simulation", "compile", 9.0)  # never more than the phase had
    assert phases.times["simulation"] == 0.0 and phases.times["compile"] == 5.0
    assert phases.summary()["total"] == 6.5


def compiling_tumble_run(
    spin: float = 1.0, moments: tuple[float, ...] = (1.0, 2.0, 3.0), duration: float = 5.0
) -> ScenarioResult:
    """tumble_run after compiling a kernel of its own (a new one each time: never cached)."""
    numba.njit(lambda x: x + 1.0)(1.0)
    return tumble_run(spin, moments, duration)


def test_a_run_that_compiles_says_so_in_its_time(plugins, tmp_path):
    plugins(_EntryPoint("tumble", lambda: dataclasses.replace(TUMBLE, run=compiling_tumble_run)))
    out = tmp_path / "c"
    argv = ["run", "tumble", "--duration", "0.5", "--no-plots", "--out", str(out)]
    assert cli.main(argv) == 0
    times = json.loads((out / "summary.json").read_text())["time_s"]
    assert times["compile"] > 0.0 and times["simulation"] >= 0.0


def test_a_summary_of_cases_prints_as_one_table():
    """smd-compare's summary is one mapping per case: printed as a column per case, rows
    aligned, a list of records as its length, a key missing from a case left blank."""
    lines = cli._summary_lines(
        {
            "steps": 12,
            "gt": {"objective": 37393.6123, "status": "ok", "refinement": [{"n": 1}, {"n": 2}]},
            "bi": {"objective": 1580.47, "status": "ok", "only_here": 1e-9},
        }
    )
    assert lines[0] == "  steps: 12"
    head, *rows = lines[1:]
    assert head.split() == ["gt", "bi"]
    table = {r.split()[0]: r for r in rows}
    assert table["objective"].split() == ["objective", "37393.6", "1580.47"]
    assert table["refinement"].split()[1:] == ["[2", "records:", "summary.json]"]
    assert table["only_here"].split() == ["only_here", "1e-09"]
    assert len({len(r) for r in lines[1:]}) == 1  # every row as wide as the head: aligned
