"""Every gmuk scenario has a gallery page with committed figures (docs/_ext/gmuk_gallery.py)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"


def gallery():
    spec = importlib.util.spec_from_file_location("gmuk_gallery", DOCS / "_ext" / "gmuk_gallery.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_scenario_has_a_complete_gallery_entry():
    g = gallery()
    names = g.scenario_names()
    assert "fcei" in names and "maintenance" in names
    problems = [p for name in names for p in g.problems(name)]
    assert not problems, "\n".join(problems)


def test_a_scenario_without_figures_is_reported_with_what_to_add(monkeypatch):
    g = gallery()
    monkeypatch.setattr(g, "STATIC", DOCS / "_static" / "no-such-gallery")
    (problem,) = g.problems("smd-compare")
    assert "scenario 'smd-compare' has no gallery entry" in problem
    assert "docs/make_gallery.py" in problem and "docs/_static/gallery/smd-compare/" in problem


def test_the_make_gallery_script_knows_every_scenario():
    """A new scenario must be added to docs/make_gallery.py's COMMANDS to get figures."""
    spec = importlib.util.spec_from_file_location("make_gallery", DOCS / "make_gallery.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    missing = sorted(set(gallery().scenario_names()) - set(module.COMMANDS))
    assert not missing, f"add {missing} to COMMANDS in docs/make_gallery.py and run it"


@pytest.mark.parametrize("name", ["fcei", "smd-gt"])
def test_a_generated_page_shows_the_command_thesis_figures_and_options(name):
    page = gallery()._page(name)
    assert f"gmuk run {name}" in page and "**Thesis:** Figures" in page
    assert ".. figure:: ../_static/gallery/" in page and "Options (" in page
