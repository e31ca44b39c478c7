"""``gmuk run rw-pointing`` (issue #29, item 7): Basilisk's reaction-wheel pointing example
with its physics stated (gmuk/scenarios/rw_pointing.py)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

from gmuk.attitude import R_NB_from_mrp
from gmuk.lie import so3
from gmuk.scenarios import rw_pointing


def test_slew_ends_at_rest_on_the_inertial_attitude_within_every_limit() -> None:
    result = rw_pointing.run()
    s, hist = result.summary, result.data["histories"]
    assert set(s) >= {"sigma_BN", "omega_BN_B", "wheel_speeds"}
    assert np.linalg.norm(s["sigma_BN"]) < 1e-4  # from |σ| = 0.37 (about 82°)
    assert np.linalg.norm(s["omega_BN_B"]) < 1e-6
    # the motors hit their 0.2 N·m limit and never exceed it; the speeds stay far from 6000 rpm
    assert np.abs(hist["motor_torques"]).max() == rw_pointing.MAX_TORQUE
    assert np.abs(hist["wheel_speeds"]).max() < 0.5 * rw_pointing.MAX_SPEED
    # no external torque: the momentum the wheels end with is the spacecraft's initial H_N
    assert s["momentum_rel_change"] <= 1e-12
    H0 = R_NB_from_mrp(rw_pointing.SIGMA0) @ (
        rw_pointing.INERTIA_B @ rw_pointing.OMEGA0 + rw_pointing.SPIN_INERTIA * rw_pointing.SPEEDS0
    )
    at_rest = rw_pointing.SPIN_INERTIA * np.asarray(s["wheel_speeds"])  # ω ≈ 0, R_NB ≈ I
    np.testing.assert_allclose(at_rest, H0, atol=2e-4 * np.linalg.norm(H0))


def test_uk_form_flies_the_same_slew() -> None:
    a = rw_pointing.run(duration=20.0)
    b = rw_pointing.run(duration=20.0, form="uk")
    ha, hb = a.data["histories"], b.data["histories"]
    Ra, Rb = R_NB_from_mrp(ha["sigma_BN"]), R_NB_from_mrp(hb["sigma_BN"])
    angle = [np.linalg.norm(so3.log(x.T @ y)) for x, y in zip(Ra, Rb, strict=True)]
    assert max(angle) < 1e-9
    np.testing.assert_allclose(hb["wheel_speeds"], ha["wheel_speeds"], rtol=1e-9, atol=0)
    np.testing.assert_allclose(hb["motor_torques"], ha["motor_torques"], rtol=0, atol=1e-9)
    # the UK form at rtol 1e-12 (its ≤ 1e-12 conservation is tested at 1e-14: test_wheels.py)
    assert b.summary["momentum_rel_change"] < 1e-9


def test_command_line_writes_the_summary_keys(tmp_path) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "rw"
    cmd = [sys.executable, "-m", "gmuk.cli", "run", "rw-pointing", "--duration", "30"]
    subprocess.run([*cmd, "--out", str(out), "--no-plots"], check=True, capture_output=True)
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary["sigma_BN"]) == 3 and len(summary["omega_BN_B"]) == 3
    assert len(summary["wheel_speeds"]) == 3
    assert summary["options"] == {"duration": 30.0, "form": "internal"}
