"""The docs' formulas render offline: MathJax ships with the built pages (the PyPI package
sphinx-mathjax-offline, in the dev extra) instead of loading from a CDN, and a headless
Chromium with the network off shows a docs page's formulas typeset, having asked for nothing
from the network.

A page of the docs (docs/theory/chapter2.rst, 200+ formulas) is built with the docs' own
configuration (``-c docs``) alone, which takes seconds where the whole docs take about a
minute; .ci/run builds the whole docs with ``sphinx-build -W``.
"""

from __future__ import annotations

import html.parser
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGE = "theory/chapter2"  # a page with many inline and displayed formulas

CHROMIUM = (
    shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
)
INSTALL = "apt-get install -y --no-install-recommends chromium (.ci/run installs it)"
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    # the network off: every host name fails to resolve, so nothing can be fetched
    "--host-resolver-rules=MAP * ~NOTFOUND",
    "--virtual-time-budget=20000",  # let MathJax load and typeset before the DOM is dumped
)
NETWORK = re.compile(r"^(https?|wss?|ftp):", re.I)


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> Path:
    """The page built into HTML by sphinx-build with docs/conf.py; the output folder."""
    root = tmp_path_factory.mktemp("docs_offline")
    src, out = root / "src", root / "html"
    (src / PAGE).parent.mkdir(parents=True)
    shutil.copyfile(DOCS / f"{PAGE}.rst", src / f"{PAGE}.rst")
    (src / "index.rst").write_text(f"Docs\n====\n\n.. toctree::\n\n   {PAGE}\n")
    # no -W: links to the pages left out of this small build are unresolved on purpose
    run = subprocess.run(
        [sys.executable, "-m", "sphinx", "-q", "-b", "html", "-c", str(DOCS), str(src), str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    return out


def test_the_pages_load_mathjax_from_their_own_folder(built):
    page = (built / f"{PAGE}.html").read_text()
    scripts = re.findall(r'<script[^>]*\bsrc="([^"]+)"', page)
    mathjax = [s for s in scripts if "mathjax" in s.lower()]
    assert mathjax == ["../_static/mathjax/tex-chtml.js"], scripts
    assert (built / "_static" / "mathjax" / "tex-chtml.js").is_file()
    fonts = built / "_static" / "mathjax" / "output" / "chtml" / "fonts" / "woff-v2"
    assert len(list(fonts.glob("*.woff"))) > 10
    # nothing that the page loads comes from elsewhere (links a reader follows are fine)
    loaded = scripts + re.findall(r'<link[^>]*\bhref="([^"]+)"', page)
    assert [u for u in loaded if NETWORK.match(u) or u.startswith("//")] == []


class _MathReader(html.parser.HTMLParser):
    """Sphinx's math elements (``<span class="math">``, ``<div class="math">``) in a DOM: for
    each, the MathJax containers in it and the text outside them (raw TeX when not typeset);
    and the number of MathJax error elements on the page."""

    VOID = frozenset("area base br col embed hr img input link meta source track wbr".split())

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.math: list[dict] = []  # {"depth", "containers", "raw"}
        self.open: dict | None = None
        self.mjx_depth = 0  # open mjx-* elements inside the current math element
        self.errors = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "mjx-merror":
            self.errors += 1
        if tag in self.VOID:
            return
        self.stack.append(tag)
        classes = (dict(attrs).get("class") or "").split()
        if self.open is None and tag in ("span", "div") and "math" in classes:
            self.open = {"depth": len(self.stack), "containers": 0, "raw": ""}
            self.math.append(self.open)
        elif self.open is not None and tag.startswith("mjx-"):
            self.mjx_depth += 1
            self.open["containers"] += tag == "mjx-container"

    def handle_endtag(self, tag: str) -> None:
        if tag in self.VOID or not self.stack:
            return
        depth = len(self.stack)
        self.stack.pop()
        if self.open is not None:
            if depth == self.open["depth"]:
                self.open, self.mjx_depth = None, 0
            elif tag.startswith("mjx-"):
                self.mjx_depth -= 1

    def handle_data(self, data: str) -> None:
        if self.open is not None and self.mjx_depth == 0:
            self.open["raw"] += data


def _chromium_dom(page: Path) -> tuple[str, list[str]]:
    """The page's DOM after its scripts ran in headless Chromium with the network off, and
    the URLs of the requests the page made (Chromium's network log; the browser's own
    service requests, initiator "not an origin", are not the page's)."""
    with tempfile.TemporaryDirectory() as profile:
        log = Path(profile) / "net.json"
        run = subprocess.run(
            [
                CHROMIUM,
                *FLAGS,
                f"--user-data-dir={profile}/p",
                f"--log-net-log={log}",
                "--dump-dom",
                page.resolve().as_uri(),
            ],
            capture_output=True,
            text=True,
            timeout=180,
        )
        assert run.returncode == 0, run.stderr[-3000:]
        net = json.loads(log.read_text())
    start = net["constants"]["logEventTypes"]["URL_REQUEST_START_JOB"]
    requests = [
        e["params"]["url"]
        for e in net["events"]
        if e["type"] == start
        and "url" in e.get("params", {})
        and e["params"].get("initiator") != "not an origin"
    ]
    return run.stdout, requests


def test_chromium_renders_the_formulas_with_the_network_off(built):
    if CHROMIUM is None:
        reason = f"headless Chromium is needed: {INSTALL}"
        if os.environ.get("GMUK_REQUIRE_CHROMIUM") == "1":
            pytest.fail(f"GMUK_REQUIRE_CHROMIUM=1 but {reason}")
        pytest.skip(reason)
    html_file = built / f"{PAGE}.html"
    source = html_file.read_text()
    dom, requests = _chromium_dom(html_file)

    # no request went to the network (with the CDN, the page asked for its MathJax here)
    assert [u for u in requests if NETWORK.match(u)] == []

    reader = _MathReader()
    reader.feed(source)
    expected = len(reader.math)
    assert expected > 100, "the page should have many formulas"
    assert all("\\" in m["raw"] for m in reader.math[:5])  # raw TeX before typesetting

    reader = _MathReader()
    reader.feed(dom)
    assert len(reader.math) == expected
    untypeset = [m["raw"].strip() for m in reader.math if m["containers"] != 1]
    assert untypeset == [], f"{len(untypeset)} formulas not rendered, e.g. {untypeset[:3]}"
    raw_tex = [m["raw"].strip() for m in reader.math if "\\" in m["raw"]]
    assert raw_tex == [], f"raw TeX left on the page: {raw_tex[:3]}"
    assert reader.errors == 0, "MathJax reported TeX errors"
