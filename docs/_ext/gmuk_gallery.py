"""Sphinx extension: one gallery page per gmuk scenario, generated at build time.

For every scenario of :func:`gmuk.scenarios.available` that gmuk itself ships, the page
``gallery/NAME`` shows the command that makes its figures, the thesis figures they correspond
to, its options (from the Scenario's own declarations) and the committed figures of that run,
``docs/_static/gallery/NAME/`` (``entry.json`` and PNGs, made by ``docs/make_gallery.py``).
A scenario without a committed entry gets a page saying so and a Sphinx warning, which fails
the ``sphinx-build -W`` of CI; ``tests/test_gallery.py`` names what to add.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

DOCS = Path(__file__).resolve().parents[1]
STATIC = DOCS / "_static" / "gallery"
PAGES = DOCS / "gallery"
#: Most bytes of a committed gallery figure.
MAX_PNG_BYTES = 150_000


def scenario_names() -> list[str]:
    """The names of gmuk's own scenarios, in thesis order (plugins' are not in the gallery:
    their figures are their package's)."""
    from gmuk import scenarios

    return [s.name for s, source in scenarios.available() if source == "gmuk"]


def entry(name: str) -> dict[str, Any] | None:
    """The committed gallery entry of scenario ``name`` (its ``entry.json``), or None."""
    path = STATIC / name / "entry.json"
    if not path.is_file():
        return None
    data: dict[str, Any] = json.loads(path.read_text())
    return data


def problems(name: str) -> list[str]:
    """What is missing or wrong in the gallery entry of ``name`` (empty when complete)."""
    how = (
        f"add {name!r} to COMMANDS in docs/make_gallery.py and run "
        f"'python docs/make_gallery.py {name}', then commit docs/_static/gallery/{name}/"
    )
    e = entry(name)
    if e is None:
        return [
            f"scenario {name!r} has no gallery entry "
            f"(docs/_static/gallery/{name}/entry.json): {how}"
        ]
    out = []
    for key in ("command", "thesis", "figures"):
        if not e.get(key):
            out.append(f"gallery entry of {name!r} has no {key!r}: {how}")
    if not str(e.get("command", "")).startswith(f"gmuk run {name}"):
        out.append(f"gallery entry of {name!r}: its command must start 'gmuk run {name}'")
    for fig in e.get("figures", []):
        path = STATIC / name / fig["file"]
        if not path.is_file():
            out.append(f"gallery entry of {name!r}: figure {path.relative_to(DOCS)} is missing")
        elif path.stat().st_size > MAX_PNG_BYTES:
            out.append(
                f"gallery figure {path.relative_to(DOCS)} is {path.stat().st_size} bytes "
                f"(at most {MAX_PNG_BYTES})"
            )
    return out


def _page(name: str) -> str:
    from gmuk import scenarios

    scenario = scenarios.get(name)
    title = f"{name} — {scenario.description}"
    lines = [title, "=" * len(title), ""]
    e = entry(name)
    if e is None:
        lines += ["No figures are committed for this scenario yet.", ""]
        return "\n".join(lines)
    lines += [
        f"**Thesis:** {e['thesis']}.",
        "",
        "The figures below are made by:",
        "",
        ".. code-block:: bash",
        "",
        f"   {e['command']}",
        "",
    ]
    if e.get("note"):
        lines += [e["note"], ""]
    if e.get("doc"):
        lines += [f"The set-up and the measured figures: :doc:`../{e['doc']}`.", ""]
    if scenario.options:
        lines += ["Options (``gmuk run " + name + " --help``):", ""]
        for o in scenario.options:
            text = o.help_text.replace("*", r"\*")
            lines.append(f"* ``{o.flag}``: {text}")
        lines.append("")
    for fig in e["figures"]:
        lines += [
            f".. figure:: ../_static/gallery/{name}/{fig['file']}",
            "   :width: 90%",
            "",
            f"   {fig['caption']}",
            "",
        ]
    return "\n".join(lines)


def generate(app: Any) -> None:
    """Write ``docs/gallery/index.rst`` and one page per scenario (builder-inited)."""
    from sphinx.util import logging

    log = logging.getLogger(__name__)
    PAGES.mkdir(exist_ok=True)
    names = scenario_names()
    index = [
        "Gallery",
        "=======",
        "",
        "One page per ``gmuk run`` scenario: the command, the thesis figures it corresponds "
        "to, its options and the figures of that run. Every ``gmuk run`` also writes "
        "``view.html``, an interactive 3-D view that opens offline (:doc:`../view`).",
        "",
        ".. toctree::",
        "   :maxdepth: 1",
        "",
        *[f"   {n}" for n in names],
        "",
    ]
    _write(PAGES / "index.rst", "\n".join(index))
    for name in names:
        for problem in problems(name):
            log.warning(problem)
        _write(PAGES / f"{name}.rst", _page(name))
    for stale in PAGES.glob("*.rst"):
        if stale.stem != "index" and stale.stem not in names:
            stale.unlink()


def _write(path: Path, text: str) -> None:
    """Write only when changed, so that Sphinx does not rebuild unchanged pages."""
    if not path.is_file() or path.read_text() != text:
        path.write_text(text)


def setup(app: Any) -> dict[str, Any]:
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
