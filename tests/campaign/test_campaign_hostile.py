"""Campaigns under hostile conditions (issue #25, items 2 and 12): an absurd run count, two
campaign processes on one folder, a campaign killed while its workers run."""

from __future__ import annotations

import contextlib
import io
import os
import signal
import subprocess
import sys
import textwrap
import time
import tracemalloc
from pathlib import Path

import pytest

from gmuk.campaign import Campaign, read_table, resume
from gmuk.campaign.core import MAX_RUNS
from gmuk.campaign.store import ResultStore
from gmuk.cli import main
from gmuk.errors import DefinitionError
from gmuk.runs import FolderInUseError

ROOT = Path(__file__).resolve().parents[2]


def _main(argv):
    """``gmuk.cli.main(argv)`` → (exit status, stderr)."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = main(argv)
    return status, err.getvalue()


# --- item 2: a bounded number of runs, enumerated lazily ---------------------------------------


@pytest.mark.parametrize(
    "flags",
    [
        ["--runs", str(10**20)],
        ["--runs", str(MAX_RUNS + 1)],
        ["--sweep", f"samples=11:{10**20}"],
    ],
    ids=["10**20", "max+1", "sweep"],
)
def test_a_campaign_of_more_runs_than_the_documented_maximum_is_refused_at_once(tmp_path, flags):
    out = tmp_path / "c"
    start = time.monotonic()
    status, err = _main(["campaign", "fcei", *flags, "--out", str(out)])
    assert time.monotonic() - start < 10.0  # refused, not enumerated
    assert status == 2
    assert f"at most {MAX_RUNS:,}" in err and "MAX_RUNS" in err
    assert not out.exists()


def test_the_python_api_refuses_more_runs_than_the_maximum_and_endless_sweeps():
    with pytest.raises(DefinitionError, match="runs must be at most 10,000,000"):
        Campaign("fcei", runs=10**20)
    with pytest.raises(DefinitionError, match="more than 10000000 values"):
        Campaign("apollo16", grid={"degree": range(2, 10**20)})
    Campaign("fcei", runs=MAX_RUNS)  # the maximum itself is a campaign


CALLS = []


def count_and_stop(params):
    """A campaign model that stops its (serial) campaign by SIGINT at its third run."""
    CALLS.append(params["x"])
    if len(CALLS) == 3:
        os.kill(os.getpid(), signal.SIGINT)
    return {"x": float(params["x"])}


def test_a_campaign_of_the_maximum_size_starts_at_once_without_listing_its_runs(tmp_path):
    CALLS.clear()
    campaign = Campaign.from_function(count_and_stop, {"x": 1.0}, runs=MAX_RUNS)
    tracemalloc.start()
    try:
        start = time.monotonic()
        report = campaign.run(tmp_path / "c", progress=False)
        elapsed = time.monotonic() - start
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert report.stopped_by == "SIGINT" and report.finished == 3 and report.runs == MAX_RUNS
    # a list of ten million pending run numbers alone is 80 MB of pointers and ~1 s to build
    assert peak < 40e6, f"peak traced memory {peak / 1e6:.0f} MB"
    assert elapsed < 30.0


# --- item 12: one campaign process per folder; workers die with their campaign -----------------

RUNS = 12


def _start_fcei(out: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    argv = [sys.executable, "-m", "gmuk.cli", "campaign", "fcei", "--runs", str(RUNS)]
    argv += ["--set", "orbits=0.3", "--set", "samples=11", "--seed", "9"]
    argv += ["--workers", "2", "--out", str(out), "--no-progress"]
    return subprocess.Popen(
        argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True
    )


def test_a_second_campaign_resume_while_one_runs_is_refused_and_no_run_is_computed_twice(
    tmp_path,
):
    out = tmp_path / "c"
    proc = _start_fcei(out)
    try:
        deadline = time.monotonic() + 180
        while not any(what == "end" for what, _ in ResultStore(out).attempts()):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the campaign did not get going"
            time.sleep(0.05)
        status, err = _main(["campaign", "--resume", str(out), "--workers", "2"])
        with pytest.raises(FolderInUseError, match=f"process {proc.pid} on host"):
            resume(out, workers=1)
        _, stderr = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    assert status == 2
    assert "is in use by another gmuk process" in err and "gmuk campaign" in err
    assert proc.returncode == 0, stderr
    attempts = ResultStore(out).attempts()
    starts = [k for what, k in attempts if what == "start"]
    assert sorted(starts) == list(range(RUNS))  # every run computed once, none twice
    assert read_table(out).column("run").to_pylist() == list(range(RUNS))
    assert not (out / ".gmuk-lock").exists()


SLEEPY = '''
"""A campaign model whose runs wait while the file HOLD exists (at most 120 s)."""
import time
from pathlib import Path

HOLD = Path(__file__).with_name("hold")


def nap(params):
    deadline = time.monotonic() + 120.0
    while HOLD.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    return {"x": float(params["x"])}
'''

SCRIPT = """
import sys
from gmuk.campaign import Campaign
from sleepy import nap

if __name__ == "__main__":
    Campaign.from_function(nap, {"x": 1.0}, runs=4).run(sys.argv[1], workers=2, progress=False)
"""


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie waiting to be reaped has ended)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_worker_processes_die_with_a_sigkilled_campaign_and_its_folder_can_be_resumed(
    tmp_path, monkeypatch
):
    (tmp_path / "sleepy.py").write_text(textwrap.dedent(SLEEPY))
    (tmp_path / "script.py").write_text(textwrap.dedent(SCRIPT))
    (tmp_path / "hold").touch()
    out = tmp_path / "c"
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    proc = subprocess.Popen(
        [sys.executable, str(tmp_path / "script.py"), str(out)],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    workers: set[int] = set()
    try:
        deadline = time.monotonic() + 180
        while len(workers) < 2:
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the workers did not start runs"
            time.sleep(0.05)
            log = out / "attempts.log"
            lines = log.read_text().split("\n") if log.exists() else []
            workers = {int(w[2]) for w in map(str.split, lines) if len(w) == 3 and w[0] == "start"}
        assert all(_alive(pid) for pid in workers)
        os.kill(proc.pid, signal.SIGKILL)  # the campaign's process only, not its group
        proc.communicate(timeout=60)
        deadline = time.monotonic() + 15.0  # the runs would hold them 120 s
        while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        survivors = [pid for pid in workers if _alive(pid)]
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)  # whatever is left of it
    assert not survivors, f"worker processes {survivors} outlived their campaign"
    # the killed campaign's lock went with it: the folder resumes, each run recorded once
    (tmp_path / "hold").unlink()
    monkeypatch.syspath_prepend(str(tmp_path))
    report = resume(out, workers=1, progress=False)
    assert report.complete and read_table(out).column("run").to_pylist() == [0, 1, 2, 3]
