"""``gmuk campaign``: bad input refused before any run; a campaign stopped by SIGINT or
killed by SIGKILL resumes with no run computed twice and none lost, its table readable."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gmuk.campaign import read_table
from gmuk.campaign.core import FLUSH_S
from gmuk.campaign.store import ResultStore
from gmuk.cli import main

ROOT = Path(__file__).resolve().parents[2]
RUNS = 30


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["nosuch", "--runs", "3"], "unknown scenario 'nosuch'; campaigns support: fcei"),
        (["smd-gt", "--runs", "3"], "'smd-gt' has no campaign support"),
        (["fcei", "--runs", "3", "--disperse", "attitude_error=cone:200"], "at most 180°"),
        (["fcei", "--runs", "3", "--disperse", "mass_scale=uniform:-0.5,1.2"], "must stay > 0"),
        (["fcei", "--runs", "3", "--set", "mass_scale=-1"], "must be > 0"),
        (["fcei", "--runs", "0"], "runs must be an integer ≥ 1"),
        (["fcei"], "--runs N is required"),
        (["apollo16", "--set", "degree=10"], "--runs N is required"),
        (["fcei", "--runs", "3", "--disperse", "orbits=zeta:1"], "unknown dispersion 'zeta'"),
        (["fcei", "--runs", "3", "--workers", "0"], "--workers must be ≥ 1"),
        (
            ["fcei", "--runs", "3", "--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "0.5"],
            "cannot reach the Dask scheduler at tcp://127.0.0.1:9 within 0.5 s",
        ),
    ],
)
def test_bad_input_is_refused_before_any_run(tmp_path, capsys, argv, words):
    out = tmp_path / "c"
    assert main(["campaign", *argv, "--out", str(out)]) == 2
    assert words in capsys.readouterr().err
    assert not out.exists()


def test_campaign_summary_and_parameters_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "c"
    argv = ["campaign", "ucei", "--runs", "3", "--workers", "1", "--set", "orbits=0.002"]
    assert main([*argv, "--set", "samples=11", "--out", str(out), "--no-progress"]) == 0
    assert "3 of 3 runs recorded" in capsys.readouterr().out
    assert main(["campaign", "--summary", str(out)]) == 0
    text = capsys.readouterr().out
    assert "final_attitude_error_rad" in text and "3 of 3 runs recorded, 0 failed" in text
    assert (out / "summary" / "scatter.png").exists()
    assert main(["campaign", "apollo16", "--parameters"]) == 0
    assert "degree" in capsys.readouterr().out
    assert main(["campaign", "--resume", str(out), "--runs", "4"]) == 2


def _start(out: Path, workers: int) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    argv = [sys.executable, "-m", "gmuk.cli", "campaign", "fcei", "--runs", str(RUNS)]
    # runs of 0.05–0.1 s (the compiled loop): long enough to signal a campaign midway
    argv += ["--set", "orbits=0.3", "--set", "samples=11", "--seed", "9"]
    argv += ["--workers", str(workers), "--out", str(out), "--no-progress"]
    return subprocess.Popen(
        argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True
    )


def _wait_for_ends(proc: subprocess.Popen, out: Path, n: int) -> None:
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        ends = [k for what, k in ResultStore(out).attempts() if what == "end"]
        if len(ends) >= n:
            return
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.02)
    pytest.fail("the campaign did not get going")


def _resume_and_check(out: Path, finished_before: set[int], log_before: int) -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-m", "gmuk.cli", "campaign", "--resume", str(out), "--workers", "2"],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert f"{RUNS} of {RUNS} runs recorded" in done.stdout
    attempts = ResultStore(out).attempts()
    restarted = {k for what, k in attempts[log_before:] if what == "start"}
    assert not restarted & finished_before  # no finished run computed again
    assert restarted == set(range(RUNS)) - finished_before  # the others, each once
    table = read_table(out)
    assert table.column("run").to_pylist() == list(range(RUNS))  # none lost, none doubled
    assert set(table.column("status").to_pylist()) == {"success"}
    ends = [k for what, k in attempts if what == "end"]
    assert all(ends.count(k) == 1 for k in finished_before)


def test_sigint_stops_cleanly_and_resume_completes(tmp_path):
    out = tmp_path / "c"
    proc = _start(out, workers=2)
    try:
        _wait_for_ends(proc, out, 4)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    assert b"stopped by SIGINT; continue with: gmuk campaign --resume" in err
    finished = set(read_table(out).column("run").to_pylist())
    assert 4 <= len(finished) < RUNS
    # the runs in progress finished and were recorded: every started run has a row
    attempts = ResultStore(out).attempts()
    assert {k for what, k in attempts if what == "start"} == finished
    _resume_and_check(out, finished, len(attempts))


def test_sigterm_stops_a_serial_campaign_mid_run_and_resume_completes(tmp_path):
    """Serially, the run in progress stops at its next step and is not recorded: every run
    started has a row or an 'end K PID interrupted' line, and resume runs it again."""
    out = tmp_path / "c"
    proc = _start(out, workers=1)
    try:
        _wait_for_ends(proc, out, 4)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 143, err
    finished = set(read_table(out).column("run").to_pylist())
    assert 4 <= len(finished) < RUNS
    log = (out / "attempts.log").read_text().splitlines()
    started = {int(line.split()[1]) for line in log if line.startswith("start")}
    interrupted = {int(line.split()[1]) for line in log if line.endswith(" interrupted")}
    assert started == finished | interrupted and not finished & interrupted
    _resume_and_check(out, finished, len(ResultStore(out).attempts()))


def test_sigkill_leaves_a_readable_table_and_resume_completes(tmp_path):
    out = tmp_path / "c"
    proc = _start(out, workers=1)
    try:
        _wait_for_ends(proc, out, 5)
        # finished runs reach the journal within FLUSH_S (one chunk per interval): give the
        # five that ended that long, so the kill costs at most the runs after them
        time.sleep(FLUSH_S + 0.2)
        os.killpg(proc.pid, signal.SIGKILL)  # the campaign's own process group
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == -signal.SIGKILL
    finished = set(read_table(out).column("run").to_pylist())  # readable after the kill
    assert 4 <= len(finished) < RUNS
    attempts = ResultStore(out).attempts()
    assert finished <= {k for what, k in attempts if what == "end"}
    _resume_and_check(out, finished, len(attempts))
