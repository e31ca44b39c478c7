"""Figures ready for a paper (issue #26, item 4), checked on the matplotlib objects.

Every figure saved by gmuk.plotting: no offset text (a multiplier goes into the axis label),
lengths above 100 km in km, Euler angles unwrapped, series that are zero or constant to
round-off drawn and noted as such, overlapping curves in distinct styles. Synthetic data
(a circular orbit tracked in LVLH with round-off noise added), no simulation: fast.
"""

from __future__ import annotations

import re

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from gmuk import plotting
from gmuk.trajectory import Trajectory

MU = 4.9028e12  # m³/s², the Moon
A = 4.0e6  # m


@pytest.fixture
def figures(monkeypatch):
    """The figures gmuk.plotting saves, kept open (``_save`` closes them through
    ``plt.close``) so the test can read them after the real saving path ran."""
    kept: list = []
    monkeypatch.setattr(plt, "close", kept.append)
    yield kept
    monkeypatch.undo()
    plt.close("all")


def _rot_z(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros((len(angle), 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1.0
    return R


def lvlh_circular(n_out: int = 121, orbits: float = 1.0, seed: int = 1) -> Trajectory:
    """A body on a circular equatorial orbit (a = 4000 km), axis 1 at the Moon, the yaw
    starting at 180° (so the 3-2-1 yaw wraps at once), ω = (0, 0, n) and a translational
    constraint acceleration that is zero, each with round-off noise (~1e-16 relative)."""
    rng = np.random.default_rng(seed)
    n = np.sqrt(MU / A**3)
    t = np.linspace(0.0, orbits * 2 * np.pi / n, n_out)
    f = n * t
    r_N = A * np.stack([np.cos(f), np.sin(f), 1e-20 * rng.standard_normal(n_out)], axis=1)
    v_N = A * n * np.stack([-np.sin(f), np.cos(f), np.zeros(n_out)], axis=1)
    R = _rot_z(f + np.pi)  # axis 1 points at the Moon: yaw = f + 180°
    g = np.zeros((n_out, 1, 4, 4))
    g[:, 0, :3, :3], g[:, 0, :3, 3], g[:, 0, 3, 3] = R, r_N, 1.0
    omega = np.stack([1e-21 * rng.standard_normal(n_out), 1e-20 * rng.standard_normal(n_out)], 1)
    omega = np.concatenate([omega, n + 1e-19 * rng.standard_normal((n_out, 1))], axis=1)
    v_B = np.einsum("nji,nj->ni", R, v_N)
    acc_c = np.zeros((n_out, 6))
    acc_c[:, :3] = [-5.13e-10, 1.23e-8, -2.62e-9]  # constant torque per inertia ...
    acc_c[:, :3] += 1e-22 * rng.standard_normal((n_out, 3))  # ... to round-off
    acc_c[:, 3:] = 3e-14 * rng.standard_normal((n_out, 3))  # zero to round-off
    empty = np.zeros((n_out, 0))
    six = np.zeros((n_out, 6))
    return Trajectory(
        t=t,
        g_NB=g,
        V_B=np.concatenate([omega, v_B], axis=1)[:, None, :],
        x=empty,
        xdot=empty,
        z=empty,
        acceleration=six,
        constraint_acceleration=acc_c,
        constraint_force=six,
        control_force=six,
        unmodeled_force=six,
        multipliers=empty,
        residual=np.zeros(n_out),
        rank=np.full(n_out, 6),
        body_names=("spacecraft",),
        body_kinds=("rigid",),
        body_dofs=(6,),
    )


@pytest.fixture(scope="module")
def body_figs(tmp_path_factory):
    """plot_body's six figures of :func:`lvlh_circular`, by file stem (drawn once)."""
    kept: list = []
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plt, "close", kept.append)
        paths = plotting.plot_body(
            lvlh_circular(), "spacecraft", tmp_path_factory.mktemp("body"), label="FCCN"
        )
    yield by_name(kept, paths)
    plt.close("all")


def by_name(figs, paths) -> dict:
    """Saved figure per file stem."""
    assert len(figs) == len(paths)
    return {p.stem: f for f, p in zip(figs, paths, strict=True)}


def notes(ax) -> list[str]:
    return [t.get_text() for t in ax.texts]


def no_offset_text(fig) -> None:
    """No visible offset/multiplier text above or beside any 2-D axis."""
    fig.canvas.draw()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            text = axis.get_offset_text()
            assert not (text.get_visible() and text.get_text()), (ax.get_ylabel(), text)


def test_body_figures_have_no_offset_text_and_positions_in_km(body_figs):
    figs = body_figs
    for fig in figs.values():
        no_offset_text(fig)
    labels = [ax.get_ylabel() for ax in figs["position"].axes]
    assert labels == ["r1 (km)", "r2 (km)", "r3 (km)"]
    ax = figs["position"].axes[0]
    assert 3900 < max(abs(v) for v in ax.get_ylim()) < 5000  # km, not 1e6 m
    assert np.abs(ax.lines[0].get_ydata()).max() == pytest.approx(A / 1e3)


def test_euler_angles_are_unwrapped(body_figs):
    raw = np.degrees(lvlh_circular().body("spacecraft").euler("321"))
    assert np.abs(np.diff(raw[:, 0])).max() > 300  # the wrapped yaw jumps by ~360°
    for ax in body_figs["euler321"].axes:
        y = np.asarray(ax.lines[0].get_ydata())
        assert np.abs(np.diff(y)).max() < 180.0, ax.get_ylabel()
    yaw = np.asarray(body_figs["euler321"].axes[0].lines[0].get_ydata())
    assert np.ptp(yaw) == pytest.approx(360.0, abs=2.0)  # a full turn, drawn continuously
    assert -181 < yaw.min() and yaw.max() < 181  # centred: -180° → 180°, not 180° → 540°


def test_unwrap_degrees_removes_every_jump_and_keeps_differences_mod_360():
    rng = np.random.default_rng(0)
    true = np.cumsum(rng.uniform(-170, 170, size=(500, 3)), axis=0)
    wrapped = (true + 180) % 360 - 180
    u = plotting.unwrap_degrees(wrapped)
    assert np.abs(np.diff(u, axis=0)).max() < 180
    k = (u - true) / 360
    assert np.allclose(k, np.round(k[0]), atol=1e-9)  # the same curve, shifted by whole turns


def test_round_off_series_are_noted_and_drawn_on_a_scale_that_shows_it(body_figs):
    figs = body_figs
    # Body rates: ω1, ω2 ~1e-20 rad/s are zero, ω3 is constant, to round-off.
    w1, w2, w3 = figs["body_rates"].axes
    for ax in (w1, w2):
        (note,) = notes(ax)
        assert note.startswith("zero to round-off")
        lo, hi = ax.get_ylim()
        assert hi == pytest.approx(-lo) and hi > 1e-4  # ±|ω|: the noise lies on zero
    (note,) = notes(w3)
    assert note.startswith("constant to round-off: ω3 = 0.0002767") and "rad/s" in note
    lo, hi = w3.get_ylim()
    assert lo <= 0 < 2.8e-4 < hi < 4e-4  # the constant against zero, not its 1e-19 noise
    # Translational constraint acceleration: ~3e-14 m/s² against a body acceleration of
    # μ/a² ≈ 0.31 m/s².
    for ax in figs["constraint_accel_translational"].axes:
        (note,) = notes(ax)
        assert "zero to round-off" in note and "m/s²" in note
        assert ax.get_ylim()[1] == pytest.approx(MU / A**2, rel=0.02)
    # Rotational: constant torques, one label with its power of ten.
    for ax in figs["constraint_accel_rotational"].axes:
        assert notes(ax)[0].startswith("constant to round-off")
    # Signals are left alone.
    for ax in [*figs["position"].axes[:2], *figs["velocity"].axes[:2], figs["euler321"].axes[0]]:
        assert notes(ax) == [], ax.get_ylabel()
    assert notes(figs["position"].axes[2])[0].startswith("zero to round-off: |r3|")


def test_round_off_kind_thresholds():
    y = np.array([1.0, 1.0 + 1e-14, 1.0 - 1e-14])
    assert plotting.round_off_kind(y, 1.0) == "constant"
    assert plotting.round_off_kind(y - 1.0, 1.0) == "zero"
    assert plotting.round_off_kind(1e-6 * np.sin(np.arange(9.0)), 1.0) is None
    assert plotting.round_off_kind(np.zeros(4), 0.0) is None  # nothing to compare with
    assert plotting.round_off_kind(np.array([np.nan, 1e-20]), 1.0) == "zero"


def test_multipliers_are_folded_into_the_label(tmp_path, figures):
    t = np.linspace(0, 10, 50)
    y = 1e-8 * np.stack([np.sin(t), np.cos(t), t], axis=1)
    big = 3e7 * np.stack([np.sin(t), np.cos(t), t / 10], axis=1)
    (path,) = plotting.plot_components(
        t, [("a", y)], ["α1 (rad/s²)", "α2 (rad/s²)", "α3"], "tiny", tmp_path / "tiny"
    )
    (path2,) = plotting.plot_components(
        t, [("b", big)], ["x (N)", "y (N)", "z (N)"], "big", tmp_path / "big"
    )
    tiny, large = figures
    no_offset_text(tiny)
    no_offset_text(large)
    a1, a2, a3 = (ax.get_ylabel() for ax in tiny.axes)
    assert re.fullmatch(r"α1 \(10⁻[⁸⁹] rad/s²\)", a1) and re.fullmatch(r"α2 \(10⁻[⁸⁹] rad/s²\)", a2)
    assert re.fullmatch(r"α3 \(×10⁻[⁷⁸]\)", a3)  # no unit: the factor after the label
    assert all(re.fullmatch(r"[xyz] \(10⁷ N\)", ax.get_ylabel()) for ax in large.axes)
    assert path.exists() and path2.exists()


def test_overlapping_curves_get_distinct_styles(tmp_path, figures):
    t = np.linspace(0, 1, 200)
    y = np.stack([np.sin(t), np.cos(t), t], axis=1)
    plotting.plot_components(
        t,
        [(f"degree {n}", y * (1 + 1e-6 * i)) for i, n in enumerate((2, 10, 50, 150))],
        ["Δr1 (m)", "Δr2 (m)", "Δr3 (m)"],
        "overlap",
        tmp_path / "overlap",
    )
    (fig,) = figures
    for ax in fig.axes:
        styles = [(ln.get_linestyle(), ln.get_marker(), ln.get_color()) for ln in ax.lines]
        assert len(styles) == 4
        assert len({s[0] for s in styles}) == 4 and len({s[1] for s in styles}) == 4
        starts = {ln.get_markevery()[0] for ln in ax.lines}
        assert len(starts) == 4  # markers of coinciding curves at different samples
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()][2] == "degree 50"


def test_compare_body_difference_at_round_off_is_noted(tmp_path, figures):
    a, b = lvlh_circular(seed=1), lvlh_circular(seed=2)
    paths = plotting.compare_body(a, b, "spacecraft", tmp_path, labels=("M", "R6"))
    figs = by_name(figures, paths)
    for ax in figs["position"].axes:
        assert notes(ax) and notes(ax)[0].startswith("zero to round-off: |Δr")
    for ax in figs["euler321"].axes:  # yaw 180° vs -180° is no difference
        assert np.abs(np.asarray(ax.lines[0].get_ydata())).max() < 1e-6
    for fig in figs.values():
        no_offset_text(fig)


def test_plot_panels_notes_a_constant_panel_and_shows_no_offset(tmp_path, figures):
    t = np.linspace(0, 1, 100)
    c = 2.768367496e-4 + 1e-19 * np.sin(40 * t)
    plotting.plot_panels(
        t,
        [("ω3 (rad/s)", [("ω3", c, {})]), ("x (m)", [("x", np.sin(t), {})])],
        "panels",
        tmp_path / "panels",
    )
    (fig,) = figures
    no_offset_text(fig)
    assert notes(fig.axes[0])[0].startswith("constant to round-off: ω3 = 0.0002768367")
    assert notes(fig.axes[1]) == []


def test_plot_panels_explains_every_line_once(tmp_path, figures):
    """A line first met in a later panel gets a legend there (maintenance's velocity error:
    the thesis run and γ are only in the norm panel); repeated labels are not re-legended."""
    t = np.linspace(0, 1, 50)
    one = [("maintained", np.sin(t), {})]
    plotting.plot_panels(
        t,
        [
            ("Δv1 (m/s)", one),
            ("Δv2 (m/s)", one),
            ("‖ṙ_e‖ (m/s)", [*one, ("thesis", np.cos(t), {}), ("γ", 0 * t + 1, {})]),
        ],
        "velocity error",
        tmp_path / "v",
    )
    (fig,) = figures
    legends = [ax.get_legend() for ax in fig.axes]
    assert legends[0] is not None and legends[1] is None
    assert {t.get_text() for t in legends[2].get_texts()} == {"maintained", "thesis", "γ"}
