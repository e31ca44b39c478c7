"""docs/quickstart.rst works as written: its Python blocks run in order, in one namespace, and
every block that prints is followed by a ``text`` block holding exactly what it printed."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import numpy as np

QUICKSTART = Path(__file__).resolve().parents[1] / "docs" / "quickstart.rst"


def code_blocks(text: str) -> list[tuple[str, str]]:
    """The ``.. code-block::`` directives of a page, in order: (language, dedented code)."""
    pattern = r"^\.\. code-block:: (\w+)\n\n((?:(?: {3}.*)?\n)+)"
    return [
        (lang, re.sub(r"^ {3}", "", body, flags=re.M).strip("\n") + "\n")
        for lang, body in re.findall(pattern, text, re.M)
    ]


def run_quickstart() -> tuple[dict, list[tuple[str, str]]]:
    """Execute the page's Python blocks; return the namespace and (printed, shown) pairs."""
    blocks = code_blocks(QUICKSTART.read_text())
    namespace: dict = {"__name__": "quickstart"}
    pairs = []
    for i, (lang, code) in enumerate(blocks):
        if lang != "python":
            continue
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(code, f"{QUICKSTART}, block {i}", "exec"), namespace)
        shown = blocks[i + 1][1] if i + 1 < len(blocks) and blocks[i + 1][0] == "text" else None
        assert (shown is None) == (out.getvalue() == ""), f"block {i}: output and text block"
        if shown is not None:
            pairs.append((out.getvalue(), shown))
    return namespace, pairs


def test_the_quickstart_runs_and_shows_what_it_prints(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ns, pairs = run_quickstart()
    assert len(pairs) == 3
    for printed, shown in pairs:
        assert printed == shown
    # what the blocks claim
    first = ns["back"]
    assert first.success and len(first) == 101 and (tmp_path / "run.npz").exists()
    assert str(first) == pairs[0][0].rstrip("\n")  # the summary survives save and load
    a = first.body("a")
    assert abs(-a.position[-1, 2] - 0.5 * 9.80665 * 100.0) < 1e-6
    assert np.abs(a.omega - a.omega[0]).max() < 1e-9
    rod, traj = ns["rod"], ns["traj"]
    assert rod.name == "rod" and rod.baumgarte is not None
    assert np.array_equal(rod.baumgarte.alpha, 20.0) and np.array_equal(rod.baumgarte.beta, 100.0)
    assert traj.success and np.abs(ns["length"] - 1.0).max() < 1e-7
    assert traj.stats["constraint_violation"]["constraints"][0]["name"] == "rod"
