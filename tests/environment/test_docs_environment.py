"""docs/environment.rst runs as written and prints what it shows."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "environment.rst"
BLOCK = re.compile(r"^\.\. code-block:: (python|text)\n\n((?:   .*\n|\n)+)", re.M)


def _blocks() -> list[tuple[str, str]]:
    text = DOC.read_text(encoding="utf-8")
    out = []
    for m in BLOCK.finditer(text):
        body = "\n".join(line[3:] for line in m.group(2).splitlines()).strip("\n") + "\n"
        out.append((m.group(1), body))
    return out


def test_every_python_block_runs_and_prints_the_text_block_after_it():
    blocks = _blocks()
    assert [k for k, _ in blocks].count("python") == 2
    namespace: dict = {}
    for k, (kind, code) in enumerate(blocks):
        if kind != "python":
            continue
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            exec(compile(code, f"{DOC.name} block {k}", "exec"), namespace)
        shown = blocks[k + 1]
        assert shown[0] == "text", "each python block is followed by the output it prints"
        assert buf.getvalue() == shown[1]
