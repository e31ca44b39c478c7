"""What a new user meets in the first hour (issue #26, items 1 and 8): `gmuk --version`, the
`gmuk plugins` table, tests that say what the machine lacks, and failures that name a public
gmuk error, never a private class."""

from __future__ import annotations

import re
import subprocess
import sys
import traceback
from pathlib import Path

import numpy as np
import pytest
from machine import CHROMIUM_INSTALL, chromium_or_skip, require_distribution

import gmuk
from gmuk import cli
from gmuk.errors import GmukError, SimulationError
from gmuk.forces import registry

ROOT = Path(__file__).resolve().parents[1]

# --- gmuk --version ------------------------------------------------------------------------------


def test_gmuk_version_prints_the_version_and_exits_0(capsys):
    try:
        status = cli.main(["--version"])
    except SystemExit as exc:  # argparse's version action exits
        status = exc.code
    assert status == 0
    out = capsys.readouterr().out
    assert out.startswith(f"gmuk {gmuk.__version__} (numba ") and "numpy" in out


def test_the_console_script_accepts_version():
    run = subprocess.run(
        [sys.executable, "-m", "gmuk.cli", "--version"], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[:2] == ["gmuk", gmuk.__version__]


# --- gmuk plugins --------------------------------------------------------------------------------


def _columns(line: str) -> list[int]:
    """Where each column of a table line starts (columns are separated by 2+ spaces)."""
    return [0] + [m.end() for m in re.finditer(r" {2,}", line)]


def test_gmuk_plugins_has_a_header_and_aligned_columns(capsys):
    assert cli.main(["plugins"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["NAME", "SOURCE", "CLASS"]
    assert len(lines) == 1 + len(registry.available())
    starts = _columns(lines[0])
    for line, info in zip(lines[1:], registry.available(), strict=True):
        assert line.split() == [info.name, info.source, info.target]
        assert _columns(line) == starts, (line, lines[0])


def test_gmuk_plugins_long_names_do_not_push_columns_out_of_line(monkeypatch, capsys):
    cls = registry.get("uniform_gravity")
    infos = [
        registry.ForceModelInfo("a", cls, "gmuk", "m:A"),
        registry.ForceModelInfo("a_very_long_force_model_name_indeed", cls, "p", "m:B"),
        registry.ForceModelInfo("b", cls, "a-plugin-distribution-with-a-long-name", "m:C"),
    ]
    monkeypatch.setattr(registry, "available", lambda: infos)
    assert cli.main(["plugins"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len({tuple(_columns(line)) for line in lines}) == 1, lines
    assert [line.split()[0] for line in lines] == ["NAME", "a", infos[1].name, "b"]


# --- what the machine lacks ----------------------------------------------------------------------


def test_without_chromium_a_test_skips_naming_the_install_command():
    with pytest.raises(pytest.skip.Exception) as info:
        chromium_or_skip(None, {})
    assert CHROMIUM_INSTALL in str(info.value) and "apt-get install" in CHROMIUM_INSTALL
    assert chromium_or_skip("/usr/bin/chromium", {}) == "/usr/bin/chromium"


def test_without_chromium_ci_fails_instead_of_skipping():
    with pytest.raises(pytest.fail.Exception, match="GMUK_REQUIRE_CHROMIUM=1") as info:
        chromium_or_skip(None, {"GMUK_REQUIRE_CHROMIUM": "1"})
    assert CHROMIUM_INSTALL in str(info.value)


def test_every_chromium_test_takes_the_fixture():
    """A test that starts Chromium gets it from the `chromium` fixture (which skips or fails
    saying what is missing), not from a module-level lookup and an assert."""
    for path in ROOT.glob("tests/**/test_*.py"):
        if path.name in ("test_fresh_machine.py", "test_docs_offline.py"):
            continue  # this file; test_docs_offline.py has its own check, same env variable
        text = path.read_text()
        if "chromium" not in text.lower():
            continue
        assert 'shutil.which("chromium")' not in text, path
        for test in re.findall(r"def (test_\w*chromium\w*)\(([^)]*)\)", text):
            assert "chromium" in test[1].split(", "), (path, test)


def test_a_missing_plugin_fails_with_the_pip_command():
    with pytest.raises(pytest.fail.Exception) as info:
        require_distribution("gmuk-no-such-plugin", "plugins/gmuk-no-such-plugin")
    assert "pip install -e plugins/gmuk-no-such-plugin" in str(info.value)
    require_distribution("gmuk", ".")  # installed: nothing happens


def test_the_readme_set_up_installs_the_plugins_the_tests_use_and_ci_runs_it():
    readme = (ROOT / "README.md").read_text()
    block = re.search(r"## Set up\s+```bash\n(.*?)```", readme, re.S)[1]
    first, second = block.strip().splitlines()
    for plugin in ("plugins/gmuk-thirdbody", "plugins/gmuk-tutorial"):
        assert f"-e {plugin}" in first
    assert second.strip() == "pytest"
    # .ci/run runs the block's two lines as written (it reads them from the README)
    ci = (ROOT / ".ci" / "run").read_text()
    assert "/^## Set up/" in ci and "README.md" in ci
    assert '-c "${SETUP[0]}"' in ci and '-c "${SETUP[1]}"' in ci
    assert "export GMUK_REQUIRE_CHROMIUM=1" in ci and "apt-get install" in ci
    # the docs' front page gives the same two commands
    index = (ROOT / "docs" / "index.rst").read_text()
    assert f"   {first.strip()}\n   {second.strip()}\n" in index


# --- failures name public errors -----------------------------------------------------------------

PRIVATE_NAME = re.compile(r"(?m)^(?:[\w.]*\.)?_[A-Za-z]\w*: ")


def _body_system(*forces: gmuk.ForceModel) -> tuple[gmuk.System, gmuk.State]:
    body = gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 3.0]))
    system = gmuk.System([body], forces=list(forces))
    return system, system.state(g={"a": np.eye(4)}, V={"a": [0.1, 0.2, 0.3, 1.0, 0.0, 0.0]})


@pytest.mark.parametrize(
    ("options", "says"),
    [
        ({"max_steps": 3}, "reached max_steps = 3"),
        ({"rtol": 1e-300, "atol": 1e-300}, "non-finite derivative"),
    ],
    ids=["max_steps", "non_finite"],
)
def test_the_loops_own_failures_are_a_public_simulation_error(options, says):
    """The issue's `_StepFailure: step size underflow`: the loop's own failures (underflow,
    max_steps, a non-finite derivative) are gmuk.errors.SimulationError, chained to nothing."""
    system, state = _body_system()
    with pytest.raises(SimulationError, match=says) as info:
        system.simulate(state, (0.0, 5.0), **options)
    assert isinstance(info.value, GmukError)
    # what a user sees: the whole traceback names gmuk.errors.SimulationError, nothing private
    shown = "".join(traceback.format_exception(info.value))
    assert "gmuk.errors.SimulationError: failed at t = " in shown
    assert not PRIVATE_NAME.search(shown), shown
    assert info.value.__cause__ is None
    # the run's message gives the reason, with no class name
    returned = system.simulate(state, (0.0, 5.0), on_failure="return", **options)
    assert returned.status == "failed" and says in returned.message
    assert not re.search(r"\b_?[A-Z]\w*(Error|Failure|Exception)\b", returned.message)


def test_the_integrator_defines_no_private_error_class():
    """Every failure the loop reports is made by _loop_failure, a public SimulationError."""
    from gmuk.engine import integrate

    source = Path(integrate.__file__).read_text()
    assert not re.search(r"class _\w+\((?:GmukError|\w*Error)", source)
    assert isinstance(integrate._loop_failure("step size underflow (h = 1e-20 s)"), SimulationError)


class _Blows(gmuk.ForceModel):
    """A force that turns infinite after t = 0.5 s."""

    def __init__(self) -> None:
        super().__init__(["a"])

    def wrench(self, t, g_NB, V_B, body):
        return np.full(6, np.inf) if t > 0.5 else np.zeros(6)


def test_a_parts_non_finite_load_names_the_public_error():
    system, state = _body_system(_Blows())
    with pytest.raises(SimulationError, match="NonFiniteError: force '_Blows'") as info:
        system.simulate(state, (0.0, 5.0))
    shown = "".join(traceback.format_exception(info.value))
    assert not PRIVATE_NAME.search(shown), shown
    assert "gmuk.errors.NonFiniteError: " in shown


def test_a_parts_own_error_stays_chained_with_its_type():
    class Boom(gmuk.ForceModel):
        def __init__(self) -> None:
            super().__init__(["a"])

        def wrench(self, t, g_NB, V_B, body):
            raise ZeroDivisionError("boom")

    system, state = _body_system(Boom())
    with pytest.raises(SimulationError, match="ZeroDivisionError: boom") as info:
        system.simulate(state, (0.0, 1.0))
    assert isinstance(info.value.__cause__, ZeroDivisionError)
