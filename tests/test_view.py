"""The 3-D views: gmuk.view's offline HTML, plotting.plot_orbit_3d, gmuk view, and a headless
Chromium that renders the HTML as a person would see it."""

from __future__ import annotations

import base64
import html.parser
import json
import re
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

import gmuk
from gmuk import plotting
from gmuk.celestial import MOON_RADIUS
from gmuk.cli import main
from gmuk.errors import DefinitionError
from gmuk.orbits import fcei_orbit
from gmuk.view import decimate, plotly_js_name, view_html, write_plotly_js, write_view


def orbit_trajectory(n: int = 400, orbits: float = 1.0) -> gmuk.Trajectory:
    """A rigid body on the FCEI orbit, its axis 1 pointing at the Moon (synthetic: Kepler's
    solution sampled, no integration)."""
    orbit = fcei_orbit()
    t = np.linspace(0.0, orbits * orbit.period, n)
    r, v = orbit.state(t)
    e1 = -r / np.linalg.norm(r, axis=1, keepdims=True)
    h = np.cross(r, v)
    e3 = h / np.linalg.norm(h, axis=1, keepdims=True)
    R = np.stack([e1, np.cross(e3, e1), e3], axis=2)
    g = np.zeros((n, 1, 4, 4))
    g[:, 0, :3, :3], g[:, 0, :3, 3], g[:, 0, 3, 3] = R, r, 1.0
    z6 = np.zeros((n, 6))
    return gmuk.Trajectory(
        t=t,
        g_NB=g,
        V_B=np.zeros((n, 1, 6)),
        x=np.zeros((n, 0)),
        xdot=np.zeros((n, 0)),
        z=np.zeros((n, 0)),
        acceleration=z6,
        constraint_acceleration=z6,
        constraint_force=z6,
        control_force=z6,
        unmodeled_force=z6,
        multipliers=np.zeros((n, 0)),
        residual=np.zeros(n),
        rank=np.zeros(n, dtype=int),
        body_names=("spacecraft",),
        body_kinds=("rigid",),
        body_dofs=(6,),
    )


class _Fetches(html.parser.HTMLParser):
    """Every URL in an attribute a browser would fetch (src, href, data, poster, srcset,
    action) and every url(...) or @import in a style."""

    def __init__(self) -> None:
        super().__init__()
        self.urls: list[str] = []
        self._in_style = False

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("src", "href", "data", "poster", "srcset", "action") and value:
                self.urls.append(value)
            if name == "style" and value:
                self.urls += re.findall(r"url\(\s*['\"]?([^'\")]+)", value)
        self._in_style = tag == "style"

    def handle_endtag(self, tag):
        self._in_style = False

    def handle_data(self, data):
        if self._in_style:
            self.urls += re.findall(r"url\(\s*['\"]?([^'\")]+)", data)
            self.urls += re.findall(r"@import\s+['\"]([^'\"]+)", data)


def fetched_urls(page: str) -> list[str]:
    """The URLs the page's markup makes a browser fetch from elsewhere (not data:/#/blob:)."""
    parser = _Fetches()
    parser.feed(page)
    return [u for u in parser.urls if not u.startswith(("data:", "#", "blob:", "javascript:"))]


def plotly_array(value) -> np.ndarray:
    """A plotly data array: a JSON list, or (plotly ≥ 6) base64 typed-array data."""
    if isinstance(value, dict):
        raw = base64.b64decode(value["bdata"])
        shape = value.get("shape", "-1")
        shape = tuple(int(k) for k in str(shape).split(",")) if isinstance(shape, str) else shape
        return np.frombuffer(raw, dtype=np.dtype(value["dtype"])).reshape(shape)
    return np.array(value, dtype=float)


@pytest.fixture(scope="module")
def page() -> str:
    return view_html(orbit_trajectory(), central_radius=MOON_RADIUS, title="FCEI")


def test_view_html_fetches_nothing_from_the_network(page):
    assert page.lstrip().lower().startswith("<html") or "<!doctype" in page[:50].lower()
    assert fetched_urls(page) == []
    # plotly.js is embedded, not loaded from a CDN
    assert "<script src" not in page.replace(" ", " ")
    assert "plotly.js v" in page or "plotly.js" in page
    # the detector does find a fetched URL: a page that loads a script from a CDN fails
    assert fetched_urls('<script src="https://cdn.example/x.js"></script>') == [
        "https://cdn.example/x.js"
    ]
    assert fetched_urls('<div style="background:url(http://a.b/c.png)"></div>') == [
        "http://a.b/c.png"
    ]


def test_view_has_the_sphere_path_triads_and_one_frame_per_kept_output(page):
    data = json.loads(
        re.search(r"Plotly\.newPlot\(\s*\"[^\"]+\",\s*(\[.*?\]),\s*\{", page, re.S)[1]
    )
    kinds = [trace["type"] for trace in data]
    assert kinds[0] == "surface"  # the Moon
    assert kinds.count("scatter3d") == 1 + 3 + 1  # path, axes 1-3, markers
    assert page.count('"name":"') >= 400  # frames are named by their time
    # the sphere's radius is the Moon's, in km
    x = plotly_array(data[0]["x"])
    assert np.isclose(np.abs(x).max(), MOON_RADIUS / 1e3, rtol=1e-2)


def test_long_runs_are_decimated_so_the_file_stays_small():
    short = view_html(orbit_trajectory(n=200), central_radius=MOON_RADIUS)
    long = view_html(orbit_trajectory(n=100_000, orbits=10.0), central_radius=MOON_RADIUS)
    # 500 times the outputs cost less than 10 % more bytes: paths ≤ 2000 points, ≤ 150 frames
    # (docs/view.rst gives the sizes; tests/docs_figures.py regenerates them)
    assert len(long) < 1.1 * len(short), (len(long), len(short))
    assert len(long) < 6_000_000
    idx = decimate(100_000, 150)
    assert len(idx) == 150 and idx[0] == 0 and idx[-1] == 99_999 and np.all(np.diff(idx) > 0)
    assert list(decimate(5, 150)) == [0, 1, 2, 3, 4]


def test_view_refuses_what_it_cannot_draw():
    with pytest.raises(DefinitionError, match="central_radius must be a finite number > 0"):
        view_html(orbit_trajectory(n=10), central_radius=-1.0)
    with pytest.raises(DefinitionError, match="number of outputs to keep must be ≥ 2"):
        view_html(orbit_trajectory(n=10), max_frames=1)


def test_gmuk_view_writes_the_html_of_a_run_folder_with_its_scenarios_moon(tmp_path, capsys):
    orbit_trajectory(n=50).save(tmp_path / "trajectory.npz")
    (tmp_path / "summary.json").write_text(json.dumps({"scenario": "fcei"}))
    assert main(["view", str(tmp_path)]) == 0
    text = (tmp_path / "view.html").read_text()
    assert '"name":"central body"' in text and "gmuk: fcei" in text
    # a bare .npz has no central body unless given one
    assert main(["view", str(tmp_path / "trajectory.npz"), "--out", str(tmp_path / "b.html")]) == 0
    assert '"name":"central body"' not in (tmp_path / "b.html").read_text()
    assert main(["view", str(tmp_path / "missing")]) == 2
    assert "expected a gmuk run folder" in capsys.readouterr().err


def test_plot_orbit_3d_writes_the_figure(tmp_path):
    paths = plotting.plot_orbit_3d(
        orbit_trajectory(n=100),
        "spacecraft",
        tmp_path / "orbit_3d",
        ("png", "svg"),
        central_radius=MOON_RADIUS,
    )
    assert [p.suffix for p in paths] == [".png", ".svg"]
    svg = paths[1].read_text()
    assert "x_N (km)" in svg or "x_N" in svg
    assert paths[0].stat().st_size > 10_000


# --- headless Chromium ---------------------------------------------------------------------------
# The `chromium` fixture (tests/conftest.py) gives its path, or skips naming the apt-get command
# that installs it (fails instead under GMUK_REQUIRE_CHROMIUM=1, which .ci/run sets).

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",  # WebGL in software: our own trusted page
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=900,700",
    "--virtual-time-budget=15000",  # let plotly.js lay out and draw the WebGL scene
)


def render(chromium: str, html_path: Path, png: Path) -> tuple[np.ndarray, list[str]]:
    """Screenshot (H, W, 3) of the page by the browser ``chromium``, and the URLs of the
    requests the page made (from Chromium's network log; the browser's own service requests
    are not the page's)."""
    from PIL import Image

    with tempfile.TemporaryDirectory() as profile:
        log = Path(profile) / "net.json"
        subprocess.run(
            [
                chromium,
                *FLAGS,
                f"--user-data-dir={profile}/p",
                f"--log-net-log={log}",
                f"--screenshot={png}",
                html_path.resolve().as_uri(),
            ],
            check=True,
            capture_output=True,
            timeout=180,
        )
        net = json.loads(log.read_text())
    start = net["constants"]["logEventTypes"]["URL_REQUEST_START_JOB"]
    page_requests = [
        e["params"]["url"]
        for e in net["events"]
        if e["type"] == start
        and "url" in e.get("params", {})
        and e["params"].get("initiator") != "not an origin"
    ]
    image = np.asarray(Image.open(png).convert("RGB")).astype(float)
    return image, page_requests


def sphere_pixels(image: np.ndarray) -> int:
    """Pixels of the shaded grey sphere: grey (channels within 8 of each other), between
    90 and 210, in the middle of the plot (the legend and labels are elsewhere)."""
    h, w, _ = image.shape
    mid = image[h // 5 : 4 * h // 5, w // 4 : 3 * w // 4]
    grey = np.ptp(mid, axis=2) < 8
    level = mid.mean(axis=2)
    return int((grey & (level > 90) & (level < 210)).sum())


def test_chromium_renders_the_view_offline_and_shows_the_moon(chromium, tmp_path):
    traj = orbit_trajectory(n=300)
    with_moon = write_view(traj, tmp_path / "moon.html", central_radius=MOON_RADIUS)
    without = write_view(traj, tmp_path / "bare.html")
    image, requests = render(chromium, with_moon, tmp_path / "moon.png")
    bare, bare_requests = render(chromium, without, tmp_path / "bare.png")
    assert requests == [] and bare_requests == []
    # not blank: a white page has no spread; the rendered scene has lines, text, shading
    assert image.std() > 15 and (image.mean(axis=2) < 200).mean() > 0.03
    # the Moon is drawn: thousands of shaded grey pixels where the bare view has almost none
    moon, none = sphere_pixels(image), sphere_pixels(bare)
    assert moon > 15_000 and none < 2_000, (moon, none)
    # the triads are drawn: pure red, green and blue axis colours are present
    for colour in ((214, 39, 40), (44, 160, 44), (31, 119, 180)):
        assert (np.abs(image - colour).max(axis=2) < 30).sum() > 20, colour


def test_the_network_log_catches_a_page_that_fetches(chromium, tmp_path):
    """The check above can fail: a page loading an image from a server is seen making it."""
    page = tmp_path / "fetching.html"
    page.write_text('<html><body><img src="http://127.0.0.1:9/x.png"></body></html>')
    _, requests = render(chromium, page, tmp_path / "fetching.png")
    assert requests == ["http://127.0.0.1:9/x.png"]


def test_orbit_scenarios_declare_the_moon_and_a_bad_radius_is_refused():
    from gmuk import scenarios
    from gmuk.scenarios import Scenario

    radii = {s.name: s.central_radius for s, source in scenarios.available() if source == "gmuk"}
    assert radii["fcei"] == radii["maintenance"] == MOON_RADIUS
    assert radii["smd-gt"] is None
    with pytest.raises(DefinitionError, match="central_radius must be a finite number > 0"):
        Scenario("x", "x", lambda: None, lambda r, o, f: [], central_radius=-1.0)


def test_views_sharing_one_plotly_library_render_offline_and_say_when_it_is_gone(
    chromium, tmp_path
):
    """``gmuk run``'s views load one plotly.js beside the run folders (``library=``): each
    page is small, renders as the self-contained one does, and a page moved away from the
    library says how to make a self-contained view instead of staying blank."""
    traj = orbit_trajectory(n=300)
    pages = [
        write_view(traj, tmp_path / run / "view.html", central_radius=MOON_RADIUS, library=tmp_path)
        for run in ("run a", "run b")  # a space in the folder: the page quotes the URL
    ]
    assert [p.name for p in tmp_path.glob("plotly-*.min.js")] == [plotly_js_name()]
    embedded = view_html(traj, central_radius=MOON_RADIUS)
    assert all(p.stat().st_size < 0.1 * len(embedded) for p in pages)
    image, requests = render(chromium, pages[0], tmp_path / "shared.png")
    assert [u for u in requests if not u.startswith("file:")] == []
    assert sphere_pixels(image) > 15_000
    (tmp_path / plotly_js_name()).unlink()
    dom = subprocess.run(
        [chromium, *FLAGS, f"--user-data-dir={tmp_path}/p", "--dump-dom", pages[1].as_uri()],
        check=True,
        capture_output=True,
        text=True,
        timeout=180,
    ).stdout
    assert "plotting library" in dom and "gmuk view RUN_DIR --out view.html" in dom


def test_write_plotly_js_keeps_a_good_copy_and_replaces_a_damaged_one(tmp_path):
    first = write_plotly_js(tmp_path)
    stamp = first.stat().st_mtime_ns
    assert write_plotly_js(tmp_path).stat().st_mtime_ns == stamp  # the same: not rewritten
    first.write_text("truncated")
    from plotly.offline import get_plotlyjs

    assert write_plotly_js(tmp_path).read_text() == get_plotlyjs()
