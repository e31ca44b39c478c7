"""Make the gallery's committed figures: run each scenario's command and keep a few figures.

    python docs/make_gallery.py            # every scenario in COMMANDS (a few minutes)
    python docs/make_gallery.py fcei smd-gt

For each scenario, runs ``gmuk run NAME ARGS --out TMP``, copies the listed figures into
``docs/_static/gallery/NAME/`` as PNGs of at most 150 kB (resized to 760 px wide, a
128-colour palette by fast octree, which keeps the axis colours apart) and writes
``entry.json`` (the command, the thesis figures, the captions), which the Sphinx extension
``docs/_ext/gmuk_gallery.py`` turns into the page ``gallery/NAME``. It also renders FCEI's
``view.html`` in headless Chromium into ``docs/_static/view_fcei.png`` (the README's
picture). Run on demand, never in CI. A new scenario needs an entry in COMMANDS.
"""

from __future__ import annotations

import json
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

DOCS = Path(__file__).resolve().parent
STATIC = DOCS / "_static" / "gallery"
WIDTH = 760
COLOURS = 128

_CH4 = [
    ("orbit_3d", "The orbit about the Moon, with the spacecraft's body axes at eight instants."),
    ("position", "Position in N."),
    ("euler321", "3-2-1 Euler angles of R_NB."),
    ("body_rates", "Body angular velocity."),
]

#: name → (arguments after ``gmuk run NAME``, thesis figures, [(figure stem, caption)], doc).
COMMANDS: dict[str, tuple[str, str, list[tuple[str, str]], str]] = {
    "apollo16": (
        "",
        "Figures 3.1–3.4",
        [
            ("orbit_3d", "The Apollo 16 subsatellite orbit about the Moon (90 × 130 km)."),
            (
                "fig3_1_position_correct",
                "Position difference from the uniform field, correct field model (Fig. 3.1).",
            ),
            (
                "magnitudes_correct_vs_thesis",
                "Differences from the uniform field: correct model and thesis Eqs. 42/59.",
            ),
        ],
        "scenarios/chapter3",
    ),
    "fccn": ("", "Figures 4.2–4.7", _CH4, "scenarios/chapter4"),
    "fcei": ("", "Figures 4.8–4.13", _CH4, "scenarios/chapter4"),
    "fceim": (
        "",
        "Figures 4.14–4.19",
        [
            _CH4[0],
            ("fceim_vs_fcei/position", "Position difference FCEIM − FCEI."),
            ("fceim_vs_fcei/euler321", "Euler-angle difference FCEIM − FCEI."),
        ],
        "scenarios/chapter4",
    ),
    "ucei": (
        "",
        "Figures 4.20–4.25",
        [
            _CH4[0],
            ("euler321", "3-2-1 Euler angles: the spacecraft rolls about its free axis."),
            ("ucei_vs_fcei/position", "Position difference UCEI − FCEI."),
        ],
        "scenarios/chapter4",
    ),
    "uceis": (
        "",
        "Figures 4.26–4.31",
        [
            _CH4[0],
            ("euler321", "3-2-1 Euler angles under the roll torque."),
            ("body_rates", "Body angular velocity."),
        ],
        "scenarios/chapter4",
    ),
    "uceim": (
        "",
        "none: UCEI on T²SE(3), beyond the thesis",
        [
            _CH4[0],
            ("uceim_vs_ucei/position", "Position difference UCEIM − UCEI."),
            ("uceim_vs_ucei/euler321", "Euler-angle difference UCEIM − UCEI."),
        ],
        "scenarios/chapter4",
    ),
    "fccl": (
        "",
        "Figures 5.1–5.10",
        [
            ("orbit_3d", "The FCEI orbit flown under Morse–Lyapunov tracking control."),
            ("fig5_01_position", "Position against the reference (Fig. 5.1)."),
            ("fig5_07_ml_translational_control", "Morse–Lyapunov translational control."),
            ("fccl_lyapunov", "The Lyapunov function W along the run."),
        ],
        "scenarios/chapter5",
    ),
    "unmodeled": (
        "",
        "Figures 5.11–5.18",
        [
            ("orbit_3d", "The FCEI orbit under unmodeled lunar harmonics, controlled."),
            ("unmodeled_position_deviation", "Position deviation: controlled and UK alone."),
            ("fig5_16_ml_translational_control", "Morse–Lyapunov translational control."),
        ],
        "scenarios/chapter5",
    ),
    "smd-gt": (
        "",
        "Figures 6.1–6.6",
        [
            ("position", "Position of the mass against its bound."),
            ("control", "Constraint (control) force."),
            ("kkt_lower", "KKT conditions of the bound."),
        ],
        "scenarios/chapter6",
    ),
    "smd-lt": (
        "",
        "Figures 6.7–6.12",
        [
            ("position", "Position of the mass against its bound."),
            ("control", "Constraint (control) force."),
            ("kkt_upper", "KKT conditions of the bound."),
        ],
        "scenarios/chapter6",
    ),
    "smd-bi": (
        "",
        "Figures 6.13–6.19",
        [
            ("position", "Position of the mass between its two bounds."),
            ("multipliers", "Lagrange multipliers of both bounds."),
            ("kkt_upper", "KKT conditions of the upper bound."),
        ],
        "scenarios/chapter6",
    ),
    "smd-compare": (
        "",
        "Figures 6.20–6.27",
        [
            (
                "smd-bi/position",
                "Bounded SMD (1 m ≤ x ≤ 2 m): UK with slack beside the direct optimum.",
            ),
            ("smd-bi/control", "Control acceleration of both answers."),
            ("smd-bi/multipliers", "Multipliers of the bounds."),
            ("smd-bi/kkt", "KKT conditions of both answers."),
        ],
        "scenarios/smd_compare",
    ),
    "maintenance": (
        "",
        "Figures 6.28–6.34",
        [
            ("orbit", "Orbit and two-body reference in the GRAIL field (Fig. 6.28)."),
            ("relative_motion", "Relative motion inside the δ sphere (Fig. 6.30)."),
            ("position_error_norm", "Position error magnitude (Fig. 6.31)."),
            ("control", "Control acceleration (Fig. 6.33)."),
        ],
        "scenarios/chapter6",
    ),
    "four-bar": (
        "",
        "none (beyond the thesis: closed loops of robot joints, issue #28)",
        [
            ("angles", "Crank and rocker angles of the free four-bar under gravity."),
            ("closure_energy", "Freudenstein's residual of the loop and the energy drift."),
        ],
        "robotics_loops",
    ),
    "stewart": (
        "",
        "none (beyond the thesis: closed loops of robot joints, issue #28)",
        [("sag_forces", "Platform sag and leg forces under gravity with PD legs.")],
        "robotics_loops",
    ),
    "panda": (
        "",
        "none (beyond the thesis: robots, issue #28)",
        [
            (
                "panda_joints",
                "The Panda's joint angles, their difference from Pinocchio's ABA (DOP853 at "
                "1e-12), and the mechanical energy its damped joints dissipate.",
            ),
        ],
        "robotics",
    ),
    "rw-pointing": (
        "",
        "none (beyond the thesis: Basilisk's reaction-wheel pointing example, issue #29)",
        [
            ("attitude", "Attitude σ_BN under MRP feedback, from (0.1, 0.2, −0.3) to 0."),
            ("rates", "Body rates ω_BN (rad/s)."),
            ("wheel_speeds", "Wheel speeds relative to the bus (rpm)."),
            ("motor_torques", "Motor torques, at their 0.2 N·m limit early in the slew."),
        ],
        "tutorials/gnc_wheels",
    ),
    "lunar-rcs": (
        "",
        "none (beyond the thesis: FCCL's ideal wrench flown on RCS thrusters, issue #29)",
        [
            (
                "tracking",
                "Attitude and position errors from the LVLH reference, and the mass the "
                "thrusters spend; the dashed line is the umbra entry.",
            ),
            ("on_times", "Every firing: one tick per control period a thruster fires."),
        ],
        "thrusters",
    ),
    "lunar-flyby": (
        "--degree 150",
        "none (beyond the thesis: a hyperbolic lunar flyby stopped at periapsis, issue #29)",
        [
            (
                "altitude",
                "Altitude from 8262 km down to periapsis, where a terminal event stops the run.",
            ),
            ("speed", "Speed against the Kepler conic's."),
            (
                "kepler_difference",
                "Position minus the Kepler conic's: the GRAIL field to degree 150.",
            ),
        ],
        "scenarios/lunar_flyby",
    ),
    "quadruped": (
        "--duration 0.3",
        "none (beyond the thesis: robots with contacts, issue #28)",
        [
            (
                "quadruped_contacts",
                "Solo12 landing 1 mm onto four frictionless feet: base height, the feet's normal "
                "forces (their sum the weight) and each contact's complementarity.",
            ),
        ],
        "robotics",
    ),
}


def small_png(src: Path, dst: Path, colours: int = COLOURS) -> None:
    """``src`` resized to WIDTH px and reduced to a palette of ``colours``, as ``dst``."""
    im = Image.open(src).convert("RGB")
    if im.width > WIDTH:
        im = im.resize((WIDTH, round(im.height * WIDTH / im.width)), Image.Resampling.LANCZOS)
    im.quantize(colours, method=Image.Quantize.FASTOCTREE).save(dst, optimize=True)


def picture(src: Path, dst: Path) -> None:
    """A screenshot without the blank rows below the page's content and its scroll bar,
    resized to WIDTH px, in full colour (the shaded sphere bands in a palette)."""
    im = Image.open(src).convert("RGB")
    ink = np.asarray(im)[:, :-24].min(axis=2) < 235  # not white (scroll bar left out)
    rows = np.flatnonzero(ink.any(axis=1))
    im = im.crop((0, 0, im.width - 20, min(im.height, int(rows[-1]) + 16)))
    if im.width > WIDTH:
        im = im.resize((WIDTH, round(im.height * WIDTH / im.width)), Image.Resampling.LANCZOS)
    im.save(dst, optimize=True)


def screenshot(html: Path, png: Path) -> None:
    """Headless Chromium's picture of a view (the flags of tests/test_view.py)."""
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run(
            [
                shutil.which("chromium") or "chromium",
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--enable-unsafe-swiftshader",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                f"--user-data-dir={profile}",
                "--window-size=900,640",
                "--virtual-time-budget=15000",
                f"--screenshot={png}",
                html.resolve().as_uri(),
            ],
            check=True,
            capture_output=True,
            timeout=180,
        )


def make(name: str, work: Path) -> None:
    args, thesis, figures, doc = COMMANDS[name]
    out = work / name
    command = f"gmuk run {name} {args}".strip()
    subprocess.run([*shlex.split(command), "--out", str(out)], check=True)
    dest = STATIC / name
    shutil.rmtree(dest, ignore_errors=True)
    dest.mkdir(parents=True)
    entries = []
    for stem, caption in figures:
        file = stem.replace("/", "__") + ".png"
        small_png(out / f"{stem}.png", dest / file)
        entries.append({"file": file, "caption": caption})
    entry = {"command": command, "thesis": thesis, "figures": entries, "doc": doc}
    (dest / "entry.json").write_text(json.dumps(entry, indent=2, ensure_ascii=False) + "\n")
    if name == "fcei":
        shot = work / "view.png"
        screenshot(out / "view.html", shot)
        picture(shot, DOCS / "_static" / "view_fcei.png")
    print(f"{name}: {len(entries)} figure(s) in {dest}")


def main(names: list[str]) -> None:
    unknown = [n for n in names if n not in COMMANDS]
    if unknown:
        sys.exit(f"no COMMANDS entry for {', '.join(unknown)}; add one in {__file__}")
    with tempfile.TemporaryDirectory() as work:
        for name in names or list(COMMANDS):
            make(name, Path(work))


if __name__ == "__main__":
    main(sys.argv[1:])
