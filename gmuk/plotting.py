"""Figures of trajectories (matplotlib, imported lazily; files only, no windows).

Every function writes one figure per call into ``out_dir`` in each requested format and
returns the paths. Axes carry quantities and SI units; angles are plotted in degrees
(labels say so), as are the thesis's figures.

Conventions every figure follows (for a paper):

- No offset text: tick labels are the values themselves (no ``1e-16+2.768e-4`` above an
  axis), and a power of ten the ticks need is written into the axis label, e.g.
  ``ω1 (10⁻⁸ rad/s)`` (:func:`fold_multipliers`, called on every figure saved here).
- Lengths above 100 km are in km (:func:`length_unit`).
- Angles are unwrapped: a yaw that turns through ±180° is drawn as one continuous curve
  (:func:`unwrap_degrees`), not with vertical jumps.
- A series that is zero, or constant, to round-off relative to its scale (the largest
  magnitude of the quantity, or a physical reference such as the body's acceleration) is
  drawn on a scale that shows it is zero/constant, with a note giving its actual size
  (:func:`round_off_kind`, :func:`show_round_off`), never as noise filling the axis.
- Several series in one panel get distinct line styles and markers
  (:func:`distinct_styles`), so a curve lying on another stays visible.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.trajectory import Trajectory, atomic_write

if TYPE_CHECKING:
    from gmuk.kkt import InequalityKKT

__all__ = [
    "ROUND_OFF_RTOL",
    "compare_body",
    "distinct_styles",
    "fold_multipliers",
    "length_unit",
    "plot_against_nominal",
    "plot_body",
    "plot_components",
    "plot_kkt",
    "plot_log_lines",
    "plot_orbit_3d",
    "plot_panels",
    "round_off_kind",
    "show_round_off",
    "unwrap_degrees",
]

_AXES = ("1", "2", "3")


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


#: A series is zero (or constant) to round-off when its largest magnitude (or its variation)
#: is at most this fraction of its scale. About 45 000 machine epsilons: above what round-off
#: reaches in gmuk's scenarios after cancellations (measured 1e-20 to 2e-12 of the scale,
#: e.g. FCCN's constraint torque spread 1.6e-12, FCEI's translational constraint
#: acceleration 1.5e-13 of the body's acceleration) and below the smallest residual a
#: controller leaves (unmodeled: ω1 at 2e-11 of ω, which is drawn as data).
ROUND_OFF_RTOL = 1e-11

#: Lengths whose largest magnitude exceeds this (m) are plotted in km.
KM_ABOVE_M = 1.0e5

_LINESTYLES = ("-", "--", "-.", ":")
_MARKERS = ("o", "s", "^", "D", "v", "x", "+", "*")
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
_POWER = re.compile(r"(?:1e|10\^\{?)\s*([-+]?\d+)")
_LABEL = re.compile(r"^(?P<symbol>.*?)\s*\((?P<unit>[^()]*)\)\s*$", re.DOTALL)


def length_unit(values: FloatArray) -> tuple[float, str]:
    """(factor, unit) to plot lengths given in m: km when the largest magnitude exceeds
    :data:`KM_ABOVE_M`, else m."""
    finite = np.abs(np.asarray(values, dtype=float))
    finite = finite[np.isfinite(finite)]
    big = finite.size > 0 and float(finite.max()) > KM_ABOVE_M
    return (1e-3, "km") if big else (1.0, "m")


def unwrap_degrees(angles: FloatArray, axis: int = 0) -> FloatArray:
    """Angles in degrees made continuous along ``axis``: every jump of more than 180°
    between consecutive samples is removed by adding a multiple of 360°, and each series is
    then shifted by a multiple of 360° to centre its range in [-180°, 180°] (a full turn
    of yaw reads -180° → 180°, not 180° → 540°)."""
    a = np.asarray(angles, dtype=float)
    if a.size == 0:
        return a.copy()
    u = np.unwrap(a, period=360.0, axis=axis)
    finite = np.where(np.isfinite(u), u, np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN series: no shift
        hi = np.nanmax(finite, axis=axis, keepdims=True)
        lo = np.nanmin(finite, axis=axis, keepdims=True)
    shift = 360.0 * np.round(np.nan_to_num(0.5 * (hi + lo)) / 360.0)
    return u - shift


def _wrap_degrees(angles: FloatArray) -> FloatArray:
    """Angles in degrees brought into [-180°, 180°)."""
    return (np.asarray(angles, dtype=float) + 180.0) % 360.0 - 180.0


def _finite(values: FloatArray | Sequence[FloatArray]) -> FloatArray:
    """The finite values of one array or several, flattened into one."""
    arrays = [values] if isinstance(values, np.ndarray) else list(values)
    if not arrays:
        return np.zeros(0)
    flat = np.concatenate([np.ravel(np.asarray(v, dtype=float)) for v in arrays])
    return flat[np.isfinite(flat)]


def round_off_kind(
    values: FloatArray | Sequence[FloatArray], scale: float, rtol: float = ROUND_OFF_RTOL
) -> str | None:
    """Whether ``values`` are ``"zero"`` or ``"constant"`` to round-off relative to
    ``scale``, else None.

    Zero: every finite value has magnitude ≤ ``rtol·scale``. Constant: not zero, and the
    spread (max − min) is ≤ ``rtol·scale``. A ``scale`` ≤ 0 (e.g. an exactly zero
    quantity, which plots well as it is) or no finite value gives None.
    """
    flat = _finite(values)
    if flat.size == 0 or not (np.isfinite(scale) and scale > 0):
        return None
    if float(np.abs(flat).max()) <= rtol * scale:
        return "zero"
    if float(np.ptp(flat)) <= rtol * scale:
        return "constant"
    return None


def _number(x: float, digits: int) -> str:
    """``x`` to ``digits`` significant digits, as 4.4×10⁻⁸ outside [1e-4, 1e5)."""
    if x == 0 or 1e-4 <= abs(x) < 1e5:
        return f"{float(f'{x:.{digits}g}'):.12g}"
    mantissa, exponent = f"{x:.{digits - 1}e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".") if "." in mantissa else mantissa
    power = f"10{str(int(exponent)).translate(_SUPERSCRIPT)}"
    return power if mantissa == "1" else f"{mantissa}×{power}"


def _split_label(label: str) -> tuple[str, str]:
    """("ω1", "rad/s") from "ω1 (rad/s)"; (label, "") without a unit."""
    match = _LABEL.match(label)
    return (match["symbol"], match["unit"]) if match else (label, "")


def show_round_off(
    ax: Any,
    values: FloatArray | Sequence[FloatArray],
    scale: float,
    ylabel: str = "",
    rtol: float = ROUND_OFF_RTOL,
) -> str | None:
    """Draw an axis whose series are zero or constant to round-off as such.

    When :func:`round_off_kind` finds ``values`` (the series drawn on ``ax``) zero to
    round-off relative to ``scale``, the y-axis spans ±``scale`` (the data lie on 0) and a
    note says "zero to round-off" with the series' largest magnitude; when constant, the
    y-axis spans 0 and the constant with a margin and the note gives the value and the
    spread. Returns the kind, or None (axis untouched).
    """
    kind = round_off_kind(values, scale, rtol)
    if kind is None:
        return None
    flat = _finite(values)
    symbol, unit = _split_label(ylabel)
    symbol = symbol or "value"
    unit = f" {unit}" if unit else ""
    top = True
    if kind == "zero":
        peak = float(np.abs(flat).max())
        ax.set_ylim(-scale, scale)
        note = (
            f"zero to round-off: |{symbol}| ≤ {_number(peak, 2)}{unit}"
            f" = {_number(peak / scale, 1)} × {_number(scale, 3)}{unit}"
        )
    else:
        lo, hi = float(flat.min()), float(flat.max())
        mid = 0.5 * (lo + hi)
        a, b = min(0.0, lo), max(0.0, hi)
        pad = 0.15 * max(b - a, abs(mid))
        ax.set_ylim(a - pad, b + pad)
        top = mid < 0  # the note on the side away from the line
        note = (
            f"constant to round-off: {symbol} = {_number(mid, 7)}{unit}"
            f" (spread {_number(hi - lo, 1)}{unit})"
        )
    ax.text(
        0.01,
        0.96 if top else 0.04,
        note,
        transform=ax.transAxes,
        va="top" if top else "bottom",
        ha="left",
        fontsize=7.5,
        bbox={"boxstyle": "round,pad=0.2", "facecolor": "white", "edgecolor": "0.7", "alpha": 0.9},
    )
    return kind


def distinct_styles(n: int, n_points: int) -> list[dict[str, Any]]:
    """Line keywords for ``n`` series of ``n_points`` samples in one panel: colour, line
    style and (hollow) marker all differ from series to series, and the markers of
    different series sit at different samples, so a curve lying on another stays visible."""
    step = max(1, n_points // 10)
    return [
        {
            "color": f"C{i % 10}",
            "linestyle": _LINESTYLES[i % len(_LINESTYLES)],
            "marker": _MARKERS[i % len(_MARKERS)],
            "markevery": (min(n_points - 1, (i * step) // max(n, 1)) if n_points else 0, step),
            "markersize": 4.5,
            "markerfacecolor": "none",
        }
        for i in range(n)
    ]


def _plain_formatters(ax: Any) -> None:
    """Tick labels without an additive offset on the axes' scalar axes."""
    from matplotlib.ticker import ScalarFormatter

    for axis in (ax.xaxis, ax.yaxis):
        fmt = axis.get_major_formatter()
        if isinstance(fmt, ScalarFormatter):
            fmt.set_useOffset(False)


def fold_multipliers(fig: Any) -> None:
    """Write each axis's power-of-ten multiplier into its label and hide the offset text.

    On every 2-D axes of ``fig`` with scalar tick labels: no additive offset, and a
    multiplier 10^k (which matplotlib prints as ``1e-8`` above the axis) becomes part of the
    label's unit, "ω1 (rad/s)" → "ω1 (10⁻⁸ rad/s)". Call when the figure is complete.
    """
    from matplotlib.ticker import ScalarFormatter

    axes = [ax for ax in fig.axes if getattr(ax, "name", "") != "3d"]
    for ax in axes:
        _plain_formatters(ax)
    fig.canvas.draw()
    for ax in axes:
        for axis in (ax.xaxis, ax.yaxis):
            fmt = axis.get_major_formatter()
            if not isinstance(fmt, ScalarFormatter):
                continue
            # Without an additive offset, the offset text is the multiplier alone: "1e−8"
            # (a minus sign U+2212 or "-"), or with mathtext "×10^{−8}".
            found = _POWER.search(fmt.get_offset().replace("\u2212", "-"))
            if found is None:
                continue
            power = f"10{str(int(found[1])).translate(_SUPERSCRIPT)}"
            label = axis.get_label_text()
            if label:
                symbol, unit = _split_label(label)
                axis.set_label_text(f"{symbol} ({power} {unit})" if unit else f"{label} (×{power})")
            axis.get_offset_text().set_visible(False)


def _figure(
    t: FloatArray,
    series: Sequence[tuple[str, FloatArray]],
    ylabels: Sequence[str],
    title: str,
    out: Path,
    formats: Sequence[str],
    t_label: str = "t (s)",
    scale: float = 0.0,
) -> list[Path]:
    """A 3-row figure: one subplot per component, one line per series (distinct styles
    when several). A row whose series are zero or constant to round-off relative to
    max(``scale``, the largest magnitude of any component) is drawn as such."""
    plt = _pyplot()
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7.0, 6.5), constrained_layout=True)
    magnitude = max([float(np.nanmax(np.abs(y), initial=0.0)) for _, y in series] or [0.0])
    scale = max(scale, magnitude)
    styles = distinct_styles(len(series), len(t)) if len(series) > 1 else [{}]
    for k, ax in enumerate(axes):
        for (label, y), style in zip(series, styles, strict=True):
            ax.plot(t, y[:, k], label=label, **{"lw": 1.2, **style})
        ax.set_ylabel(ylabels[k])
        ax.grid(True, alpha=0.3)
        show_round_off(ax, [y[:, k] for _, y in series], scale, ylabels[k])
    axes[-1].set_xlabel(t_label)
    if len(series) > 1:
        axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(title)
    return _save(plt, fig, out, formats)


class _Quantity:
    """One figure group: values (N, 3) in SI, a symbol and unit per row, a title, what
    kind of quantity ("length", "angle" or ""), and a reference scale for round-off."""

    def __init__(
        self,
        values: FloatArray,
        symbols: Sequence[str],
        unit: str,
        title: str,
        kind: str = "",
        reference: float = 0.0,
    ) -> None:
        self.values, self.symbols, self.unit, self.title = values, list(symbols), unit, title
        self.kind, self.reference = kind, reference

    def scaled(self, values: FloatArray) -> tuple[FloatArray, list[str], float]:
        """``values`` (of this quantity, or a difference of it) in plotting units, the row
        labels, and the round-off reference in those units."""
        factor, unit = length_unit(values) if self.kind == "length" else (1.0, self.unit)
        ylabels = [f"{s} ({unit})" for s in self.symbols]
        return values * factor, ylabels, self.reference * factor


def _quantities(traj: Trajectory, body: str) -> dict[str, _Quantity]:
    view = traj.body(body)
    acc = view.constraint_acceleration
    t = traj.t
    # The body's own acceleration in N: the scale against which its translational
    # constraint acceleration is zero or not (on a tracked natural orbit it is ~1e-13 of it).
    accel = (
        float(np.linalg.norm(np.gradient(view.velocity, t, axis=0), axis=1).max())
        if len(t) > 1
        else 0.0
    )
    return {
        "position": _Quantity(
            view.position, [f"r{a}" for a in _AXES], "m", "Position in N", "length"
        ),
        "velocity": _Quantity(view.velocity, [f"v{a}" for a in _AXES], "m/s", "Velocity in N"),
        "euler321": _Quantity(
            unwrap_degrees(np.degrees(view.euler("321"))),
            ["ψ", "θ", "φ"],
            "deg",
            "3-2-1 Euler angles of R_NB",
            "angle",
            180.0,
        ),
        "body_rates": _Quantity(
            view.omega, [f"ω{a}" for a in _AXES], "rad/s", "Angular velocity, body frame"
        ),
        "constraint_accel_translational": _Quantity(
            acc[:, 3:],
            [f"a{a}" for a in _AXES],
            "m/s²",
            "Translational constraint acceleration, body frame",
            reference=accel,
        ),
        "constraint_accel_rotational": _Quantity(
            acc[:, :3],
            [f"α{a}" for a in _AXES],
            "rad/s²",
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
    angles (unwrapped), body rates, translational and rotational constraint accelerations.
    Components zero or constant to round-off are drawn and noted as such (the translational
    constraint acceleration against the body's acceleration in N)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    for key, q in _quantities(traj, body).items():
        y, ylabels, scale = q.scaled(q.values)
        paths += _figure(
            traj.t,
            [(label or body, y)],
            ylabels,
            f"{q.title} — {label or body}",
            out_dir / f"{prefix}{key}",
            formats,
            scale=scale,
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
    figure group (``difference=True``), or both overlaid. A difference that is zero to
    round-off relative to the quantity itself is drawn and noted as such; Euler-angle
    differences are taken modulo 360° and unwrapped."""
    if a.t.shape != b.t.shape or np.abs(a.t - b.t).max(initial=0.0) > 1e-9 * max(1.0, a.t[-1]):
        raise ValueError("compare_body needs both trajectories sampled at the same times")
    out_dir.mkdir(parents=True, exist_ok=True)
    qa, qb = _quantities(a, body), _quantities(b, body_b or body)
    paths: list[Path] = []
    for key, q in qa.items():
        ya, yb = q.values, qb[key].values
        magnitude = max(float(np.nanmax(np.abs(ya), initial=0.0)), q.reference)
        magnitude = max(magnitude, float(np.nanmax(np.abs(yb), initial=0.0)))
        if difference:
            d = ya - yb
            if q.kind == "angle":
                d = unwrap_degrees(_wrap_degrees(d))
            # Drawn on ±magnitude when at round-off: the unit fits that span.
            span = d if round_off_kind(d, magnitude) is None else np.array([magnitude])
            factor = _factor(q, span)
            ylabels = q.scaled(span)[1]
            series = [(f"{labels[0]} − {labels[1]}", d * factor)]
            ttl = f"{q.title}: {labels[0]} − {labels[1]}"
            ylab = [f"Δ{s}" for s in ylabels]
            scale = magnitude * factor
        else:
            both = np.concatenate([ya, yb])
            factor = _factor(q, both)
            series = [(labels[0], ya * factor), (labels[1], yb * factor)]
            ttl = f"{q.title}: {labels[0]} and {labels[1]}"
            ylab = q.scaled(both)[1]
            scale = magnitude * factor
        paths += _figure(a.t, series, ylab, ttl, out_dir / f"{prefix}{key}", formats, scale=scale)
    return paths


def _factor(q: _Quantity, values: FloatArray) -> float:
    """The factor from SI to the plotting unit of ``values`` of quantity ``q``."""
    return length_unit(values)[0] if q.kind == "length" else 1.0


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
        ``{"linestyle": "--", "color": "C1"}``). The legend is drawn in the first panel,
        and in any later panel with a line not named in a legend above it. A panel whose
        lines are constant to round-off is drawn and noted as such (:func:`show_round_off`).
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
        ys = [np.asarray(y, dtype=float) for _, y, _ in lines]
        show_round_off(ax, ys, max(float(np.nanmax(np.abs(y), initial=0.0)) for y in ys), ylabel)
    axes[-1, 0].set_xlabel(t_label)
    # A legend in the first panel, and in each later panel that has a line not yet named
    # in a legend above it (so no line goes unexplained, and no legend is repeated).
    shown: set[str] = set()
    for i, (_, lines) in enumerate(panels):
        names = {label for label, _, _ in lines if label and not label.startswith("_")}
        if i == 0 or names - shown:
            axes[i, 0].legend(loc="best", fontsize=7, ncol=2)
            shown |= names
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
    figure), and close it. Multipliers are folded into the axis labels first
    (:func:`fold_multipliers`)."""
    paths = []
    try:
        fold_multipliers(fig)
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
    scale = float(np.nanmax(np.abs(y), initial=0.0))
    if nominal is not None:
        scale = max(scale, float(np.nanmax(np.abs(nominal), initial=0.0)))
    for k in range(3):
        ax = axes[k]
        ax.plot(t, y[:, k], color=f"C{k}", lw=1.3, label=label)
        if nominal is not None:
            ax.plot(t, nominal[:, k], color="k", ls="--", lw=1.0, label=nominal_label)
        ax.set_ylabel(ylabels[k])
        ax.grid(True, alpha=0.3)
        drawn = [y[:, k]] if nominal is None else [y[:, k], nominal[:, k]]
        show_round_off(ax, drawn, scale, ylabels[k])
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
