"""Summary of a campaign: a statistics table of its metrics and figures.

``summarize(DIR)`` writes into ``DIR/summary/``:

* ``metrics.csv``: per metric, over the successful runs: count, mean, standard deviation,
  minimum, 5th percentile, median, 95th percentile, maximum;
* ``histograms.png``: a histogram of each metric (up to 12, the model's headline metrics
  first);
* ``scatter.png``: each headline metric against each varied parameter's value (the
  magnitude of a vector: the angle of an attitude error, the norm of a position error), one
  panel per pair — "final error against initial dispersion".
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gmuk.campaign import store as _store
from gmuk.campaign.core import load_campaign

__all__ = ["CampaignSummary", "summarize"]

#: Statistics of :func:`summarize`, in column order.
STATISTICS = ("count", "mean", "std", "min", "p5", "median", "p95", "max")
#: Metrics left out of the figures (bookkeeping, not results).
_BOOKKEEPING = ("m_steps", "m_rhs_evaluations", "m_t_reached_s")


@dataclass(frozen=True)
class CampaignSummary:
    """The summary of a campaign folder.

    Attributes
    ----------
    runs : int
        Runs in the campaign.
    finished, failed : int
        Runs recorded; of those, failed.
    statistics : dict of str to dict of str to float
        Metric (without the ``m_`` prefix) → statistic (:data:`STATISTICS`) → value.
    files : list of Path
        ``metrics.csv`` and the figures written.
    """

    runs: int
    finished: int
    failed: int
    statistics: dict[str, dict[str, float]]
    files: list[Path]

    def table(self) -> str:
        """The statistics as aligned text, one metric a line."""
        head = f"{'metric':<42}" + "".join(f"{s:>12}" for s in STATISTICS)
        lines = [
            f"{self.finished} of {self.runs} runs recorded, {self.failed} failed",
            head,
            "-" * len(head),
        ]
        for name, row in self.statistics.items():
            cells = "".join(
                f"{int(row[s]):>12d}" if s == "count" else f"{row[s]:>12.4g}" for s in STATISTICS
            )
            lines.append(f"{name:<42}{cells}")
        return "\n".join(lines)


def _stats(x: np.ndarray) -> dict[str, float]:
    x = x[np.isfinite(x)]
    if x.size == 0:
        return dict.fromkeys(STATISTICS, math.nan) | {"count": 0.0}
    p5, med, p95 = np.percentile(x, [5, 50, 95])
    return {
        "count": float(x.size),
        "mean": float(x.mean()),
        "std": float(x.std(ddof=1)) if x.size > 1 else 0.0,
        "min": float(x.min()),
        "p5": float(p5),
        "median": float(med),
        "p95": float(p95),
        "max": float(x.max()),
    }


def _column(table: Any, name: str) -> np.ndarray:
    values = table.column(name).to_pylist()
    return np.array([math.nan if v is None else float(v) for v in values])


def _log_scale(y: np.ndarray) -> bool:
    y = y[np.isfinite(y)]
    return bool(y.size and y.min() > 0 and y.max() / y.min() > 100)


def summarize(
    out: str | Path, *, figures: bool = True, formats: Sequence[str] = ("png",)
) -> CampaignSummary:
    """Write the statistics table and the figures of the campaign in ``out`` (module
    docstring) and return the summary; works on a partial campaign too."""
    out = Path(out)
    campaign = load_campaign(out)
    table = _store.read_table(out)
    statuses = table.column("status").to_pylist()
    ok = np.array([s == "success" for s in statuses], dtype=bool)
    metric_cols = [c for c in table.column_names if c.startswith("m_")]
    statistics = {c[2:]: _stats(_column(table, c)[ok]) for c in metric_cols}
    folder = out / "summary"
    folder.mkdir(exist_ok=True)
    csv_path = folder / "metrics.csv"
    with _store.atomic_write(csv_path) as tmp, tmp.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["metric", *STATISTICS])
        for name, row in statistics.items():
            writer.writerow([name, *(repr(row[s]) for s in STATISTICS)])
    files = [csv_path]
    if figures and ok.any():
        model = campaign.campaign_model
        headline = [f"m_{h}" for h in model.headline if f"m_{h}" in metric_cols]
        shown = [
            *headline,
            *(c for c in metric_cols if c not in headline and c not in _BOOKKEEPING),
        ]
        files += _histograms(table, shown[:12], ok, folder, formats, model.name)
        xs = []
        for name in campaign.varied():
            kind = model.parameter(name).kind
            col = f"p_{name}_mag" if kind in ("vector3", "rotation", "scale3") else f"p_{name}"
            if col in table.column_names:
                xs.append((name, col, kind))
        if xs and headline:
            files += _scatter(table, xs, headline, ok, folder, formats, model.name)
    return CampaignSummary(
        runs=campaign.n_runs,
        finished=len(statuses),
        failed=sum(s == "failed" for s in statuses),
        statistics=statistics,
        files=files,
    )


def _grid(n: int) -> tuple[int, int]:
    cols = min(n, 3)
    return math.ceil(n / cols), cols


def _histograms(
    table: Any, cols: list[str], ok: np.ndarray, folder: Path, formats: Sequence[str], title: str
) -> list[Path]:
    from gmuk.plotting import _pyplot, _save

    if not cols:
        return []
    plt = _pyplot()
    rows, ncols = _grid(len(cols))
    fig, axes = plt.subplots(rows, ncols, figsize=(3.2 * ncols, 2.4 * rows), squeeze=False)
    for ax, c in zip(axes.flat, cols, strict=False):
        y = _column(table, c)[ok]
        y = y[np.isfinite(y)]
        if _log_scale(y):
            ax.hist(y, bins=np.geomspace(y.min(), y.max(), 30))
            ax.set_xscale("log")
        else:
            ax.hist(y, bins=30)
        ax.set_xlabel(c[2:], fontsize=7)
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[len(cols) :]:
        ax.set_visible(False)
    fig.suptitle(f"{title}: {int(ok.sum())} successful runs", fontsize=9)
    fig.tight_layout()
    return _save(plt, fig, folder / "histograms", formats)


def _scatter(
    table: Any,
    xs: list[tuple[str, str, str]],
    headline: list[str],
    ok: np.ndarray,
    folder: Path,
    formats: Sequence[str],
    title: str,
) -> list[Path]:
    from gmuk.plotting import _pyplot, _save

    plt = _pyplot()
    rows, ncols = len(headline), len(xs)
    fig, axes = plt.subplots(
        rows, ncols, figsize=(3.2 * ncols, 2.6 * rows), squeeze=False, sharex="col"
    )
    for i, ycol in enumerate(headline):
        y = _column(table, ycol)[ok]
        for j, (name, xcol, kind) in enumerate(xs):
            ax = axes[i, j]
            x = _column(table, xcol)[ok]
            ax.plot(x, y, ".", markersize=3)
            if _log_scale(y):
                ax.set_yscale("log")
            if i == rows - 1:
                unit = " (magnitude)" if kind in ("vector3", "rotation") else ""
                ax.set_xlabel(f"{name}{unit}", fontsize=7)
            if j == 0:
                ax.set_ylabel(ycol[2:], fontsize=7)
            ax.tick_params(labelsize=7)
    fig.suptitle(f"{title}: headline metrics against the varied parameters", fontsize=9)
    fig.tight_layout()
    return _save(plt, fig, folder / "scatter", formats)
