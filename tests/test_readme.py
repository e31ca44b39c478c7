"""The README works as written: its set-up commands, and its Python example run as it stands."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from gmuk import cli

README = (Path(__file__).resolve().parents[1] / "README.md").read_text()


def blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README, re.S)


def test_the_set_up_commands_are_the_two_of_ci():
    (setup, *_) = blocks("bash")
    assert setup.splitlines() == [
        'pip install -e ".[dev]" -e plugins/gmuk-thirdbody -e plugins/gmuk-tutorial '
        "&& gmuk run fcei",
        "pytest",
    ]
    # .ci/run reads the two lines from the README's "Set up" block and runs them as written
    ci = (Path(__file__).resolve().parents[1] / ".ci" / "run").read_text()
    assert "/^## Set up/" in ci and '-c "${SETUP[0]}"' in ci and '-c "${SETUP[1]}"' in ci


def test_the_python_example_runs_and_holds_its_pin(tmp_path, monkeypatch, capsys):
    (example,) = blocks("python")
    assert len(example.splitlines()) <= 20
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(example, "README.md", "exec"), namespace)
    printed = capsys.readouterr().out
    assert printed.startswith("max |A ν̇ − b| = ") and "pin drift = " in printed
    # the figures the README quotes are the ones the example prints
    residual, drift = re.findall(r"= ([0-9.e+-]+)", printed)
    text = " ".join(README.split())
    assert f"largest constraint residual ({residual} here)" in text
    assert f"10 s ({drift} m at the default tolerances)" in text
    traj = namespace["traj"]
    assert traj.success and len(traj) == 501
    assert traj.residual.max() < 1e-12 and np.abs(namespace["pin_N"]).max() < 1e-7
    # the comment's next step works too
    assert cli.main(["view", "pendulum.npz"]) == 0
    assert (tmp_path / "pendulum.html").stat().st_size > 1_000_000


def test_the_picture_and_the_pages_it_names_exist():
    root = Path(__file__).resolve().parents[1]
    for path in re.findall(r"\]\((docs/[^)]+)\)", README) + re.findall(r"`(docs/[\w/.]+)`", README):
        if path.startswith(("docs/_build", "docs/gallery")):
            continue  # made by sphinx-build (the gallery pages by docs/_ext/gmuk_gallery.py)
        assert (root / path).exists(), path
