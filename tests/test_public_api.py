"""Every name the README and the docs use under ``gmuk.`` exists, and ``__all__`` is honest."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

import gmuk

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.rst"))]
#: Dotted names, e.g. gmuk.System, gmuk.gravity.load, gmuk.lie.se3.exp.
DOTTED = re.compile(r"\bgmuk(?:\.[A-Za-z_][A-Za-z_0-9]*)+")


def resolve(dotted: str) -> object:
    """The object a dotted gmuk name refers to, importing submodules as needed."""
    parts = dotted.split(".")
    obj: object = gmuk
    for i, part in enumerate(parts[1:], start=1):
        if hasattr(obj, part):
            obj = getattr(obj, part)
            continue
        obj = importlib.import_module(".".join(parts[: i + 1]))
    return obj


def _names_in_docs() -> list[tuple[str, str]]:
    found = set()
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in DOTTED.finditer(text):
            name = m.group(0)
            if name.startswith("gmuk.force_models") or name.startswith("gmuk.scenarios."):
                continue  # the entry-point groups, not attributes
            found.add((path.relative_to(ROOT).as_posix(), name))
    return sorted(found)


def _table_cell_names() -> list[str]:
    """Bare class names listed beside a gmuk.Name in the same README table cell: the reader
    takes them as top-level names too."""
    names = []
    for line in (ROOT / "README.md").read_text(encoding="utf-8").splitlines():
        if not line.startswith("|"):
            continue
        cell = line.split("|")[1]
        ticked = re.findall(r"`([^`]+)`", cell)
        if any(t.startswith("gmuk.") and t[5:6].isupper() for t in ticked):
            names += [f"gmuk.{t}" for t in ticked if re.fullmatch(r"[A-Z][A-Za-z0-9]*", t)]
    return names


@pytest.mark.parametrize(("where", "name"), _names_in_docs())
def test_every_gmuk_name_in_the_readme_and_docs_exists(where, name):
    try:
        resolve(name)
    except (AttributeError, ModuleNotFoundError) as exc:
        pytest.fail(f"{where} uses {name}, which does not exist: {exc}")


def test_bare_names_beside_top_level_names_in_the_readme_table_are_top_level():
    names = _table_cell_names()
    assert "gmuk.SphericalHarmonicGravity" in names  # the case that was missing
    missing = [n for n in names if not hasattr(gmuk, n[5:])]
    assert not missing, f"README lists these as top-level names but gmuk has none: {missing}"


def test_all_lists_only_real_names_and_every_public_class_the_docs_name():
    assert all(hasattr(gmuk, n) for n in gmuk.__all__)
    for name in ("SphericalHarmonicGravity", "INERTIAL", "BodyKind", "UKSolver", "gravity"):
        assert name in gmuk.__all__


def test_unknown_attributes_are_still_attribute_errors():
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        gmuk.Nope
