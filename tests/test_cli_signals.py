"""`gmuk run` stopped by SIGINT or SIGTERM: the trajectory so far is saved, summary.json says
how the run ended and how far it got, and the exit status is 128 + the signal number."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import gmuk


def _maintenance(out, orbits, *extra):
    """``gmuk run maintenance`` for ``orbits`` orbits into ``out``."""
    cmd = [sys.executable, "-m", "gmuk.cli", "run", "maintenance", "--orbits", orbits]
    return [*cmd, "--out", str(out), *extra]


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_stopped_run_saves_what_it_computed_and_says_so(tmp_path, sig, status):
    out = tmp_path / "maintenance"
    # 100 maintained orbits in the degree-150 field take over a minute here: the signal comes
    # well before the end.
    cmd = _maintenance(out, "100", "--compare", "false")
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


def test_a_killed_run_resumes_from_its_last_checkpoint_to_the_uninterrupted_result(tmp_path):
    out = tmp_path / "killed"
    # 4 orbits (about 3 s compiled), a checkpoint every 0.3 s: killed after a few of them
    proc = subprocess.Popen(
        _maintenance(out, "4", "--no-plots", "--checkpoint-every", "0.3", "--compare", "false"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    checkpoint = out / ".checkpoints" / "run-0.npz"
    deadline = time.monotonic() + 60.0
    while not checkpoint.exists() and time.monotonic() < deadline:
        time.sleep(0.2)
    time.sleep(0.7)  # a checkpoint or two further into the run
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    assert not (out / "trajectory.npz").exists()
    partial = gmuk.load_trajectory(checkpoint)  # readable: written atomically
    assert partial.stats["checkpoint"]["complete"] is False
    assert 0.0 < partial.t[-1] < 4 * 7071.0
    resumed = subprocess.run(
        [sys.executable, "-m", "gmuk.cli", "run", "--resume", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert resumed.returncode == 0, resumed.stderr
    assert not (out / ".checkpoints").exists()  # spent
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "success" and summary["options"]["compare"] is False
    from gmuk.scenarios import maintenance

    plain = maintenance.run(orbits=4.0, compare=False).trajectories["maintenance"]
    back = gmuk.load_trajectory(out / "trajectory.npz")
    np.testing.assert_array_equal(back.t, plain.t)
    np.testing.assert_allclose(back.r_N, plain.r_N, rtol=0, atol=1e-6)


def test_a_stop_ends_every_simulation_of_a_scenario_and_resume_completes_them(tmp_path):
    out = tmp_path / "three"
    # 5 orbits: the primary run takes about 3 s compiled; the signal comes once it has
    # written its first checkpoint (after 0.3 s of it), well before its end
    cmd = _maintenance(out, "5", "--no-plots", "--checkpoint-every", "0.3")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120.0
    while not (out / ".checkpoints" / "run-0.npz").exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert proc.poll() is None, proc.communicate()
    assert not (out / ".checkpoints" / "run-1.npz").exists()  # the primary is still running
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 143, stderr
    assert b"continue with: gmuk run --resume" in stderr
    summary = json.loads((out / "summary.json").read_text())
    # the primary run stopped; the two that follow it returned at once
    assert summary["runs_not_completed"] == ["maintenance", "position_only", "free"]
    resumed = subprocess.run(
        [sys.executable, "-m", "gmuk.cli", "run", "maintenance", "--resume", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert resumed.returncode == 0, resumed.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "success" and "runs_not_completed" not in summary
    assert summary["bound_excess_max"] <= 0.0


def test_resume_refuses_what_it_cannot_continue(tmp_path, capsys):
    assert gmuk.cli.main(["run", "--resume", str(tmp_path)]) == 2
    assert "no run to resume there" in capsys.readouterr().err
    record = tmp_path / ".checkpoints"
    record.mkdir()
    (record / "run.json").write_text(json.dumps({"scenario": "smd-gt", "options": {}}))
    assert gmuk.cli.main(["run", "fcei", "--resume", str(tmp_path)]) == 2
    assert "holds a 'smd-gt' run, not 'fcei'" in capsys.readouterr().err
    assert gmuk.cli.main(["run", "smd-gt", "--resume", str(tmp_path), "--duration", "2"]) == 2
    assert "give no other scenario option or --out" in capsys.readouterr().err
