"""Figures of trajectories (matplotlib, imported lazily; files only, no windows).

Every function writes one figure per call into ``out_dir`` in each requested format and
returns the paths. Axes carry quantities and SI units; angles are plotted in degrees
(labels say so), as are the thesis's figures.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.trajectory import Trajectory, atomic_write

if TYPE_CHECKING:
    from gmuk.kkt import InequalityKKT

__all__ = [
    "compare_body",
    "plot_against_nominal",
    "plot_body",
    "plot_components",
    "plot_kkt",
    "plot_log_lines",
    "plot_orbit_3d",
    "plot_panels",
]

_AXES = ("1", "2", "3")


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _figure(
    t: FloatArray,
    series: Sequence[tuple[str, FloatArray]],
    ylabels: Sequence[str],
    title: str,
    out: Path,
    formats: Sequence[str],
    t_label: str = "t (s)",
) -> list[Path]:
    """A 3-row figure: one subplot per component, one line per series."""
    plt = _pyplot()
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7.0, 6.5), constrained_layout=True)
    for k, ax in enumerate(axes):
        for label, y in series:
            ax.plot(t, y[:, k], label=label, lw=1.2)
        ax.set_ylabel(ylabels[k])
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel(t_label)
    if len(series) > 1:
        axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(title)
    return _save(plt, fig, out, formats)


def _quantities(traj: Trajectory, body: str) -> dict[str, tuple[FloatArray, list[str], str]]:
    view = traj.body(body)
    acc = view.constraint_acceleration
    return {
        "position": (view.position, [f"r{a} (m)" for a in _AXES], "Position in N"),
        "velocity": (view.velocity, [f"v{a} (m/s)" for a in _AXES], "Velocity in N"),
        "euler321": (
            np.degrees(view.euler("321")),
            ["ψ (deg)", "θ (deg)", "φ (deg)"],
            "3-2-1 Euler angles of R_NB",
        ),
        "body_rates": (
            view.omega,
            [f"ω{a} (rad/s)" for a in _AXES],
            "Angular velocity, body frame",
        ),
        "constraint_accel_translational": (
            acc[:, 3:],
            [f"a{a} (m/s²)" for a in _AXES],
            "Translational constraint acceleration, body frame",
        ),
        "constraint_accel_rotational": (
            acc[:, :3],
            [f"α{a} (rad/s²)" for a in _AXES],
            "Rotational constraint acceleration, body frame",
        ),
    }


def plot_body(
    traj: Trajectory,
    body: str,
    out_dir: Path,
    formats: Sequence[str] = ("png",),
    prefix: str = "",
    label: str | None = None,
) -> list[Path]:
    """The six thesis figure groups of one rigid body: position, velocity, 3-2-1 Euler
    angles, body rates, translational and rotational constraint accelerations."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    for key, (y, ylabels, title) in _quantities(traj, body).items():
        paths += _figure(
            traj.t,
            [(label or body, y)],
            ylabels,
            f"{title} — {label or body}",
            out_dir / f"{prefix}{key}",
            formats,
        )
    return paths


def compare_body(
    a: Trajectory,
    b: Trajectory,
    body: str,
    out_dir: Path,
    formats: Sequence[str] = ("png",),
    labels: tuple[str, str] = ("a", "b"),
    difference: bool = True,
    prefix: str = "",
    body_b: str | None = None,
) -> list[Path]:
    """Compare one body in two runs sampled at the same times: the difference a − b of each
    figure group (``difference=True``), or both overlaid."""
    if a.t.shape != b.t.shape or np.abs(a.t - b.t).max(initial=0.0) > 1e-9 * max(1.0, a.t[-1]):
        raise ValueError("compare_body needs both trajectories sampled at the same times")
    out_dir.mkdir(parents=True, exist_ok=True)
    qa, qb = _quantities(a, body), _quantities(b, body_b or body)
    paths: list[Path] = []
    for key, (ya, ylabels, title) in qa.items():
        yb = qb[key][0]
        if difference:
            series = [(f"{labels[0]} − {labels[1]}", ya - yb)]
            ttl = f"{title}: {labels[0]} − {labels[1]}"
            ylab = [f"Δ{s}" for s in ylabels]
        else:
            series = [(labels[0], ya), (labels[1], yb)]
            ttl = f"{title}: {labels[0]} and {labels[1]}"
            ylab = list(ylabels)
        paths += _figure(a.t, series, ylab, ttl, out_dir / f"{prefix}{key}", formats)
    return paths


def plot_components(
    t: FloatArray,
    series: Sequence[tuple[str, FloatArray]],
    ylabels: Sequence[str],
    title: str,
    out: Path,
    formats: Sequence[str] = ("png",),
    t_label: str = "t (s)",
) -> list[Path]:
    """One 3-row figure of vector quantities: row k shows component k of every series.

    Parameters
    ----------
    t : ndarray (N,)
        Abscissa (s unless ``t_label`` says otherwise).
    series : sequence of (label, ndarray (N, 3))
        One line per series in each row; a legend when there are several.
    ylabels : sequence of 3 str
        Row labels with units, e.g. ``"Δr1 (m)"``.
    title : str
    out : Path
        Output path without suffix; one file per format is written beside it.
    formats : sequence of str
    t_label : str

    Returns
    -------
    list of Path
    """
    out.parent.mkdir(parents=True, exist_ok=True)
    return _figure(t, series, ylabels, title, out, formats, t_label)


def plot_panels(
    t: FloatArray,
    panels: Sequence[tuple[str, Sequence[tuple[str, FloatArray, dict[str, Any]]]]],
    title: str,
    out: Path,
    formats: Sequence[str] = ("png",),
    t_label: str = "t (s)",
) -> list[Path]:
    """One figure with a row per panel, each with its own lines and styles.

    Parameters
    ----------
    t : ndarray (N,)
    panels : sequence of (ylabel, lines)
        ``lines`` is a sequence of (label, y (N,), matplotlib line keywords such as
        ``{"linestyle": "--", "color": "C1"}``). The legend is drawn in the first panel.
    title : str
    out : Path
        Output path without suffix.
    formats : sequence of str
    t_label : str

    Returns
    -------
    list of Path
    """
    plt = _pyplot()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(
        len(panels),
        1,
        sharex=True,
        figsize=(7.5, 2.2 * len(panels) + 1.0),
        constrained_layout=True,
        squeeze=False,
    )
    for ax, (ylabel, lines) in zip(axes[:, 0], panels, strict=True):
        for label, y, style in lines:
            ax.plot(t, y, label=label, **{"lw": 1.2, **style})
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel(t_label)
    axes[0, 0].legend(loc="best", fontsize=7, ncol=2)
    fig.suptitle(title)
    return _save(plt, fig, out, formats)


def _time_axis(ax: Any, t: FloatArray, t_scale: str, t_linear: float) -> None:
    """Linear time axis, or symmetric-log (linear on [0, t_linear], logarithmic beyond),
    spanning exactly the data."""
    if t_scale == "symlog":
        ax.set_xscale("symlog", linthresh=t_linear)
    elif t_scale != "linear":
        raise ValueError(f"t_scale must be 'linear' or 'symlog'; got {t_scale!r}")
    ax.set_xlim(float(t[0]), float(t[-1]))


def _save(plt: Any, fig: Any, out: Path, formats: Sequence[str]) -> list[Path]:
    """Write ``fig`` once per format, each file atomically (a stopped run leaves no half
    figure), and close it."""
    paths = []
    try:
        for fmt in formats:
            path = out.with_suffix(f".{fmt}")
            with atomic_write(path) as tmp:
                fig.savefig(tmp, dpi=150, format=fmt)
            paths.append(path)
    finally:
        plt.close(fig)
    return paths


def plot_against_nominal(
    t: FloatArray,
    y: FloatArray,
    nominal: FloatArray | None,
    ylabels: Sequence[str],
    title: str,
    out: Path,
    formats: Sequence[str] = ("png",),
    *,
    label: str = "run",
    nominal_label: str = "nominal",
    norm: tuple[str, FloatArray] | None = None,
    t_label: str = "t (s)",
    t_scale: str = "linear",
    t_linear: float = 1.0,
) -> list[Path]:
    """One figure of a vector quantity against its nominal (McCann 2020, Chapter 5 style).

    Row k shows component k of the run (solid, colour k) and of the nominal (black, dashed);
    an optional last row shows a norm (e.g. the error against the nominal) on a logarithmic
    axis, where non-positive values are left out.

    Parameters
    ----------
    t : ndarray (N,)
        Abscissa (s unless ``t_label`` says otherwise).
    y : ndarray (N, 3)
        The run's components.
    nominal : ndarray (N, 3) or None
        The nominal's components at the same times (no dashed lines when None).
    ylabels : sequence of 3 str
        Row labels with units, e.g. ``"r1 (km)"``.
    title : str
    out : Path
        Output path without suffix; one file per format is written beside it.
    formats : sequence of str
    label, nominal_label : str
        Legend entries.
    norm : (str, ndarray (N,)), optional
        Label with units and values of the log-scaled last row.
    t_label : str
    t_scale : {"linear", "symlog"}
        "symlog" is linear on [0, ``t_linear``] and logarithmic beyond: a fast transient and a
        slow convergence in one figure.
    t_linear : float
        End of the linear part of a "symlog" axis (same unit as t).

    Returns
    -------
    list of Path
    """
    plt = _pyplot()
    out.parent.mkdir(parents=True, exist_ok=True)
    rows = 3 + (norm is not None)
    fig, axes = plt.subplots(
        rows, 1, sharex=True, figsize=(7.5, 1.9 * rows + 1.0), constrained_layout=True
    )
    for k in range(3):
        ax = axes[k]
        ax.plot(t, y[:, k], color=f"C{k}", lw=1.3, label=label)
        if nominal is not None:
            ax.plot(t, nominal[:, k], color="k", ls="--", lw=1.0, label=nominal_label)
        ax.set_ylabel(ylabels[k])
        ax.grid(True, alpha=0.3)
        if nominal is not None:
            ax.legend(loc="best", fontsize=7)
    if norm is not None:
        ax = axes[3]
        values = np.asarray(norm[1], dtype=float)
        ax.plot(t, np.where(values > 0, values, np.nan), color="C3", lw=1.3)
        ax.set_yscale("log")
        ax.set_ylabel(norm[0])
        ax.grid(True, which="both", alpha=0.3)
    _time_axis(axes[-1], t, t_scale, t_linear)
    axes[-1].set_xlabel(t_label)
    fig.suptitle(title)
    return _save(plt, fig, out, formats)


def plot_log_lines(
    t: FloatArray,
    lines: Sequence[tuple[str, FloatArray, dict[str, Any]]],
    ylabel: str,
    title: str,
    out: Path,
    formats: Sequence[str] = ("png",),
    *,
    t_label: str = "t (s)",
    t_scale: str = "linear",
    t_linear: float = 1.0,
) -> list[Path]:
    """One panel of positive quantities on a logarithmic axis (non-positive values are left
    out), e.g. the error norms of several runs.

    Parameters
    ----------
    t : ndarray (N,)
    lines : sequence of (label, y (N,), matplotlib line keywords)
    ylabel : str
        With units.
    title : str
    out : Path
        Output path without suffix.
    formats : sequence of str
    t_label : str
    t_scale : {"linear", "symlog"}
    t_linear : float
        End of the linear part of a "symlog" axis.

    Returns
    -------
    list of Path
    """
    plt = _pyplot()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7.5, 4.0), constrained_layout=True)
    for label, y, style in lines:
        values = np.asarray(y, dtype=float)
        ax.plot(t, np.where(values > 0, values, np.nan), label=label, **{"lw": 1.3, **style})
    ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    _time_axis(ax, t, t_scale, t_linear)
    ax.set_xlabel(t_label)
    ax.legend(loc="best", fontsize=8)
    fig.suptitle(title)
    return _save(plt, fig, out, formats)


def plot_kkt(
    kkt: InequalityKKT,
    out: Path,
    formats: Sequence[str] = ("png",),
    *,
    title: str | None = None,
) -> list[Path]:
    """The KKT conditions of one bound along a trajectory (McCann 2020, Table 6.1; the
    thesis's Figures 6.6, 6.12, 6.18–6.19): the constraint value g (≤ 0 when feasible), the
    multiplier μ (≥ 0 when dual feasible) and their product μg (0 under complementary
    slackness).

    Parameters
    ----------
    kkt : gmuk.kkt.InequalityKKT
    out : Path
        Output path without suffix.
    formats : sequence of str
    title : str, optional

    Returns
    -------
    list of Path
    """
    unit, mu_unit = kkt.unit or "unit of h", kkt.multiplier_unit
    zero = {"color": "0.5", "linestyle": ":", "lw": 0.8}
    panels: list[tuple[str, list[tuple[str, FloatArray, dict[str, Any]]]]] = [
        (
            f"g ({unit})",
            [("g: primal feasible when ≤ 0", kkt.g, {"color": "C0"}), ("0", 0 * kkt.g, zero)],
        ),
        (f"μ ({mu_unit})", [("μ: dual feasible when ≥ 0", kkt.mu, {"color": "C1"})]),
        (
            f"μ g ({mu_unit}·{unit})",
            [("μ g: complementary slackness when 0", kkt.complementarity, {"color": "C2"})],
        ),
    ]
    side = "h ≤ u" if kkt.side == "upper" else "h ≥ l"
    name = title or f"KKT conditions of {kkt.constraint} ({side}, bound {kkt.bound:g} {unit})"
    return plot_panels(kkt.t, panels, name, out, formats)


def plot_orbit_3d(
    traj: Trajectory,
    body: str,
    out: Path,
    formats: Sequence[str] = ("png",),
    *,
    central_radius: float | None = None,
    n_triads: int = 8,
    triad_length: float | None = None,
    title: str | None = None,
) -> list[Path]:
    """The path of one rigid body in N, in 3-D, with its axes triad at a few instants.

    The triads are the columns of R_NB (body axes 1, 2, 3 in red, green, blue) drawn at
    ``n_triads`` outputs evenly spaced in index, the first and last included; the central
    body is a wireframe sphere at N's origin when ``central_radius`` is given. Lengths are
    drawn in km when the scene is wider than 100 km, else in m; the axes have equal scale.

    Parameters
    ----------
    traj : Trajectory
    body : str
        Name of a rigid body of ``traj``.
    out : Path
        Output path without suffix.
    formats : sequence of str
    central_radius : float, optional
        Radius (m) of the central body.
    n_triads : int
        Number of instants with a triad (≥ 2).
    triad_length : float, optional
        Drawn length (m) of each axis; default 12 % of the scene's size.
    title : str, optional

    Returns
    -------
    list of Path
    """
    from gmuk.view import AXIS_COLOURS, KM_ABOVE_M, decimate

    view = traj.body(body)
    r_N, R_NB = view.position, view.R
    size = max(float(np.ptp(r_N, axis=0).max()), 2.0 * (central_radius or 0.0))
    size = size if size > 1e-6 else 1.0  # a body at rest: a 1 m scene
    scale, unit = (1e-3, "km") if size > KM_ABOVE_M else (1.0, "m")
    length = (triad_length if triad_length is not None else 0.12 * size) * scale
    plt = _pyplot()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(6.5, 6.0), constrained_layout=True)
    ax = fig.add_subplot(projection="3d")
    if central_radius:
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 36), np.linspace(0, np.pi, 18))
        rs = central_radius * scale
        ax.plot_wireframe(
            rs * np.cos(u) * np.sin(v),
            rs * np.sin(u) * np.sin(v),
            rs * np.cos(v),
            color="0.75",
            lw=0.4,
        )
    p = r_N * scale
    ax.plot(*p.T, color="0.25", lw=1.0, label=f"{body} path")
    for n, i in enumerate(decimate(len(traj), max(2, n_triads))):
        for k in range(3):
            ax.quiver(
                *p[i],
                *(R_NB[i, :, k] * length),
                color=AXIS_COLOURS[k],
                lw=1.5,
                arrow_length_ratio=0.15,
                label=f"body axis {k + 1}" if n == 0 else None,
            )
    lo = p.min(axis=0) - length
    hi = p.max(axis=0) + length
    if central_radius:
        lo, hi = np.minimum(lo, -central_radius * scale), np.maximum(hi, central_radius * scale)
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1e-12)))
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_xlabel(f"x_N ({unit})")
    ax.set_ylabel(f"y_N ({unit})")
    ax.set_zlabel(f"z_N ({unit})")
    ax.legend(loc="upper left", fontsize=8)
    fig.suptitle(title or f"Orbit and attitude of {body} (N frame)")
    return _save(plt, fig, out, formats)
