"""`gmuk run` stopped by SIGINT or SIGTERM: the trajectory so far is saved, summary.json says
how the run ended and how far it got, and the exit status is 128 + the signal number."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import pytest

import gmuk


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_stopped_run_saves_what_it_computed_and_says_so(tmp_path, sig, status):
    out = tmp_path / "maintenance"
    # 100 maintained orbits in the degree-150 field take over a minute here: the signal comes
    # well before the end.
    cmd = [
        sys.executable,
        "-m",
        "gmuk.cli",
        "run",
        "maintenance",
        "--orbits",
        "100",
        "--compare",
        "false",
        "--out",
        str(out),
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(8.0)  # import (compiled kernels cached by the earlier tests) and some orbits
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == status, (stdout, stderr)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert summary["signal"] == signal.Signals(sig).name
    traj = gmuk.load_trajectory(out / "trajectory.npz")
    assert traj.status == "interrupted"
    assert 0.0 < summary["t_reached_s"] == traj.t[-1] < 100 * 7071.0
    assert not list(out.glob("*.png"))  # no figures of a run that did not finish
    assert not list(out.glob(".*.part"))
    assert f"stopped by {signal.Signals(sig).name}" in stderr


def test_a_completed_run_says_success(tmp_path):
    out = tmp_path / "fcei"
    assert gmuk.cli.main(["run", "fcei", "--orbits", "0.02", "--out", str(out), "--no-plots"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "success" and "signal" not in summary
    assert summary["t_reached_s"] == pytest.approx(0.02 * 22696.0, rel=1e-3)
