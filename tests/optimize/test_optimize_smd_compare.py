"""gmuk run smd-compare: the UK slack runs beside the direct optimum."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gmuk import cli
from gmuk.scenarios import OptionError, smd_compare


def test_smd_compare_tabulates_the_direct_optimum_below_the_uk_answer(tmp_path):
    out = tmp_path / "cmp"
    assert (
        cli.main(
            [
                "run",
                "smd-compare",
                "--cases",
                "smd-bi,smd-lt",
                "--duration",
                "6",
                "--elements",
                "30",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    for case in ("smd-bi", "smd-lt"):
        s = summary[case]
        assert s["direct_status"] == "Solve_Succeeded"
        # the optimum costs less than the UK slack answer, which is feasible but not optimal
        assert s["objective_direct"] < s["objective_uk"]
        assert s["objective_ratio_uk_over_direct"] > 1.0
        assert s["direct_primal_violation_max"] < 1e-6 and s["direct_dual_violation_max"] == 0.0
        # the trapezoid on the UK grid and the LGL quadrature measure the same optimum
        assert abs(s["objective_direct"] / s["objective_direct_quadrature"] - 1.0) < 1e-2
    figures = sorted(p.name for p in (out / "smd-bi").glob("*.png"))
    assert figures == [
        "control.png",
        "effort.png",
        "kkt.png",
        "multipliers.png",
        "position.png",
        "velocity.png",
    ]
    with np.load(out / "direct_smd-bi.npz") as data:
        assert data["r_N"].shape == (91, 3)
        assert data["r_N"][:, 0].min() >= 1.0 - 1e-6
        assert {"mu_x.lower", "mu_x.upper"} <= set(data.files)


def test_unknown_cases_are_refused():
    with pytest.raises(OptionError, match="--cases"):
        smd_compare.run(cases=("smd-xx",))
