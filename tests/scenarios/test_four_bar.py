"""gmuk run four-bar: the free four-bar linkage under gravity (gmuk/scenarios/four_bar.py)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gmuk import scenarios
from gmuk.cli import main
from gmuk.errors import DomainError
from gmuk.scenarios import four_bar as fb


def test_four_bar_summary_closes_the_loop_and_keeps_the_energy():
    result = scenarios.get("four-bar").run(duration=1.0)
    s = result.summary
    assert s["constraint_rows"] == 20 and s["constraint_rank"] == 17
    assert s["loop_position_residual_max"] < 1e-10
    assert s["loop_velocity_residual_max"] < 1e-10
    assert s["freudenstein_residual_max"] < 1e-10
    assert s["energy_drift_rel"] < 1e-11
    # the crank turns more than once, at the time the energy integral gives
    assert s["crank_angle_final_rad"] > 2 * math.pi
    t_ref = fb.crank_time(s["crank_angle_final_rad"], 0.0, s["crank_rate0_rad_per_s"])
    assert abs(t_ref[0] - s["duration_s"]) < 1e-10
    E = result.data["energy"]
    assert E.shape == result.trajectories["four-bar"].t.shape


def test_gmuk_run_four_bar_writes_its_summary_and_figures(tmp_path):
    out = tmp_path / "fb"
    assert main(["run", "four-bar", "--duration", "0.2", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    # the crank angle the command line reports is reached at 0.2 s by the energy integral
    assert abs(fb.crank_time(summary["crank_angle_final_rad"], 0.0, 8.0)[0] - 0.2) < 1e-10
    assert summary["energy_drift_rel"] < 1e-11
    for stem in ("angles", "closure_energy"):
        assert (out / f"{stem}.png").is_file()


def test_angles_refuse_a_crank_angle_where_the_loop_cannot_close():
    # a non-Grashof set of links does not close at every crank angle
    with pytest.raises(DomainError, match="does not close"):
        fb.angles(np.array([0.0, math.pi]), a=0.5, b=0.2, c=0.2, d=0.6)
