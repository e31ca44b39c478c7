"""The figure of the gravity-degree study in docs/campaigns.rst.

    python docs/_static/campaign/plot_degree_study.py VS_UNIFORM_DIR VS_150_DIR OUT.png

VS_UNIFORM_DIR and VS_150_DIR are the folders of ``gmuk campaign apollo16`` run with the
default reference (the uniform field) and with ``--set reference_degree=150``.
"""

from __future__ import annotations

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from gmuk.campaign import read_table


def columns(folder: str) -> dict[str, np.ndarray]:
    rows = [r for r in read_table(folder).to_pylist() if r["status"] == "success"]
    return {
        key: np.array([r[key] for r in rows], dtype=float)
        for key in ("p_degree", "m_max_position_difference_m", "m_max_attitude_difference_rad")
    }


def main() -> None:
    uniform, d150, out = sys.argv[1:4]
    fig, axes = plt.subplots(2, 2, figsize=(8.0, 5.2), sharex=True)
    for row, (folder, label) in enumerate(
        ((uniform, "from the uniform field"), (d150, "from degree 150"))
    ):
        c = columns(folder)
        keep = c["p_degree"] != 150 if row == 1 else np.ones_like(c["p_degree"], dtype=bool)
        for col, (key, unit) in enumerate(
            (("m_max_position_difference_m", "m"), ("m_max_attitude_difference_rad", "rad"))
        ):
            ax = axes[row, col]
            plot = ax.semilogy if row == 1 else ax.plot
            plot(c["p_degree"][keep], c[key][keep], ".-", markersize=3, linewidth=0.8)
            what = "position" if col == 0 else "attitude"
            ax.set_ylabel(f"max {what} difference ({unit})", fontsize=8)
            ax.set_title(f"{what}, {label}", fontsize=9)
            ax.grid(True, which="major", alpha=0.3)
            ax.tick_params(labelsize=8)
    for ax in axes[1]:
        ax.set_xlabel("GRGM660PRIM truncation degree", fontsize=8)
    fig.suptitle("Apollo 16 subsatellite orbit, one orbit, free LM", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=90)


if __name__ == "__main__":
    main()
