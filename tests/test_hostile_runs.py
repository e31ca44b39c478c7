"""Runs under hostile conditions (issue #25, items 1 and 5): two runs into one output
folder, a lock left by a killed run, and checkpoints edited by hand or contradicting the run
they would continue."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import StopAt

import gmuk
from gmuk import runs
from gmuk._locks import LOCK_NAME, FolderInUseError, folder_lock, holder
from gmuk.cli import main
from gmuk.runs import CheckpointError
from gmuk.trajectory import _ARRAYS

ROOT = Path(__file__).resolve().parents[1]


def _main(argv):
    """``gmuk.cli.main(argv)`` → (exit status, stderr)."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = main(argv)
    return status, err.getvalue()


# --- one run per output folder ------------------------------------------------------------------


@pytest.fixture(scope="module")
def contested(tmp_path_factory):
    """A long ``gmuk run maintenance`` into OUT; while it runs, a second ``gmuk run`` and a
    ``gmuk run --resume`` into OUT are tried in this process; then the first is stopped by
    SIGINT. Returns what each saw."""
    out = tmp_path_factory.mktemp("contested") / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    argv = [sys.executable, "-m", "gmuk.cli", "run", "maintenance", "--orbits", "100"]
    argv += ["--compare", "false", "--no-plots", "--checkpoint-every", "1", "--out", str(out)]
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        checkpoint = out / ".checkpoints" / "run-0.npz"
        deadline = time.monotonic() + 180.0
        while not checkpoint.exists() and time.monotonic() < deadline:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.2)
        assert checkpoint.exists(), "the first run did not get going"
        lock_record = holder(out)
        before = checkpoint.stat().st_size
        second = _main(["run", "fcei", "--orbits", "0.02", "--out", str(out), "--no-plots"])
        resumed = _main(["run", "--resume", str(out)])
        time.sleep(1.5)  # the first run goes on writing checkpoints
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(signal.SIGINT)
        _, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return {
        "out": out,
        "pid": proc.pid,
        "lock_record": lock_record,
        "checkpoint_size": before,
        "second": second,
        "resumed": resumed,
        "first_status": proc.returncode,
        "first_stderr": stderr.decode(),
    }


def test_a_second_run_into_the_same_out_directory_is_refused_and_the_first_loses_nothing(
    contested,
):
    out = contested["out"]
    status, err = contested["second"]
    assert status == 2
    assert "is in use by another gmuk process" in err
    assert f"process {contested['pid']} on host" in err  # names the run that owns it
    assert "another --out" in err
    # the first run went on and, stopped by SIGINT, saved everything it computed
    assert contested["first_status"] == 130, contested["first_stderr"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenario"] == "maintenance" and summary["status"] == "interrupted"
    traj = gmuk.load_trajectory(out / "trajectory.npz")
    assert traj.t[-1] == summary["t_reached_s"] > 0.0
    partial = gmuk.load_trajectory(out / ".checkpoints" / "run-0.npz")
    assert partial.t[-1] == traj.t[-1]  # its checkpoints survived the second run
    assert json.loads((out / ".checkpoints" / "run.json").read_text())["scenario"] == (
        "maintenance"
    )
    assert not (out / LOCK_NAME).exists()  # released when the run ended


def test_the_lock_file_names_the_live_process_host_and_start_time(contested):
    record = contested["lock_record"]
    assert record["pid"] == contested["pid"]
    assert record["host"] and record["started_utc"] and record["what"] == "gmuk run maintenance"


def test_a_resume_while_the_run_is_still_going_is_refused(contested):
    status, err = contested["resumed"]
    assert status == 2
    assert "is in use by another gmuk process" in err and "wait for it to end" in err


def test_a_killed_runs_lock_never_blocks_the_next_run(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    code = (
        "import os, signal, sys\n"
        "from gmuk._locks import folder_lock\n"
        "held = folder_lock(sys.argv[1], 'gmuk run fcei')\nheld.__enter__()\n"
        "os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", code, str(out)], env=env)
    assert proc.wait(timeout=300) == -signal.SIGKILL
    assert holder(out)["pid"] == proc.pid  # the dead process's record is left behind
    # the file of a dead process is no lock: the next run takes the folder at once
    status, err = _main(["run", "fcei", "--orbits", "0.02", "--out", str(out), "--no-plots"])
    assert status == 0, err
    assert json.loads((out / "summary.json").read_text())["status"] == "success"
    assert not (out / LOCK_NAME).exists()


def test_a_folder_lock_is_refused_to_a_second_holder_and_free_after_release(tmp_path):
    with folder_lock(tmp_path, "first"):
        with pytest.raises(FolderInUseError, match=f"process {os.getpid()} on host"):
            with folder_lock(tmp_path, "second"):
                pass
    with folder_lock(tmp_path, "third"):
        assert holder(tmp_path)["what"] == "third"


# --- checkpoints -------------------------------------------------------------------------------


def _spring(t_stop=1e9):
    bob = gmuk.PointMass("bob", 0.4)
    system = gmuk.System([bob], [], [gmuk.LinearSpringDamper(3.0, 0.1), StopAt(t_stop)])
    state = system.state(r={"bob": [1.0, 0.0, 0.0]}, v={"bob": [0.0, 1.0, 0.5]})
    return system, state


#: Long enough for several chunks of steps (a stop is seen between chunks).
T_EVAL = np.linspace(0.0, 100.0, 1001)


def _run(system, state, t_eval=T_EVAL):
    return system.simulate(state, (0.0, 100.0), t_eval=t_eval, rtol=1e-10, atol=1e-12)


def _stopped(folder, t_eval=T_EVAL):
    """A checkpoint of the spring stopped at t ≈ 30 s (of 100): ``folder/run-0.npz``."""
    with runs.run_control(folder, every_s=3600.0):
        cut = _run(*_spring(30.0), t_eval=t_eval)
    assert cut.status == "interrupted"
    return folder / "run-0.npz"


def _resume(folder, t_eval=T_EVAL):
    with runs.run_control(folder, resume=True):
        return _run(*_spring(), t_eval=t_eval)


def _edit_file(path, edit_meta=None, edit_arrays=None):
    """Rewrite a checkpoint file as a hand edit would: the checksum is left as it was."""
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays.pop("meta")))
    if edit_meta:
        edit_meta(meta)
    if edit_arrays:
        edit_arrays(arrays)
    with open(path, "wb") as fh:
        np.savez_compressed(fh, meta=np.array(json.dumps(meta)), **arrays)


def _reseal(path, edit):
    """Rewrite a checkpoint through gmuk.runs.save after ``edit(traj, record)``: a record
    that contradicts itself or the run, under a valid checksum."""
    traj = gmuk.load_trajectory(path)
    record = traj.stats.pop("checkpoint")
    record.pop("sha256")
    traj = edit(traj, record) or traj
    runs.save(path, traj, record)


def _set(key, value):
    def edit(meta):
        meta["stats"]["checkpoint"][key] = value

    return edit


def _row_changed(arrays):
    arrays["x"][5, 0] += 1.0
    arrays["r_N"][5, 0, 0] += 1.0  # its copy, kept consistent as a careful editor would


@pytest.mark.parametrize(
    "edit_meta, edit_arrays",
    [
        (_set("complete", True), None),
        (_set("t", -5.0), None),
        (_set("out_i", 40), None),
        (lambda meta: meta.update(status="success"), None),
        (None, _row_changed),
    ],
    ids=["complete", "t", "out_i", "status", "a row's value"],
)
def test_a_hand_edited_checkpoint_is_refused_by_its_checksum(tmp_path, edit_meta, edit_arrays):
    path = _stopped(tmp_path)
    _edit_file(path, edit_meta, edit_arrays)
    with pytest.raises(CheckpointError, match="checksum does not match"):
        _resume(tmp_path)


def _complete_success(traj, record):
    record["complete"] = True
    return dataclasses.replace(traj, status="success")


def _drop_last_rows(traj, record):
    """An out_i edited down with the rows to match: the samples after it would be lost."""
    keep = record["out_i"] - 5
    record["out_i"] = keep
    return dataclasses.replace(traj, **{n: getattr(traj, n)[:keep] for n in _ARRAYS})


@pytest.mark.parametrize(
    "edit, words",
    [
        (lambda traj, rec: rec.update(complete=True), "complete is True but the trajectory"),
        (_complete_success, "complete is true but t ="),
        (lambda traj, rec: rec.update(t=-5.0), "outside the run's span"),
        (lambda traj, rec: rec.update(t=125.0), "outside the run's span"),
        (lambda traj, rec: rec.update(t="7"), "t must be a finite time"),
        (lambda traj, rec: rec.update(h=-1.0), "h must be a finite step"),
        (lambda traj, rec: rec.update(out_i=rec["out_i"] - 10), "but the checkpoint holds"),
        (lambda traj, rec: rec.update(out_i=rec["out_i"] + 1), "but the checkpoint holds"),
        (lambda traj, rec: rec.update(out_i=10**6), "beyond the run's 1001 output times"),
        (lambda traj, rec: rec.update(out_i=True), "out_i must be an integer"),
        (_drop_last_rows, "skips the output time"),
        (lambda traj, rec: rec.update(G0=[1.0]), "G0 has 1 entries"),
        (lambda traj, rec: rec.update(Y=[float("nan")] * len(rec["Y"])), "Y must be a list"),
        (lambda traj, rec: rec.update(complete="yes"), "complete must be true or false"),
        (lambda traj, rec: rec.update(n_steps=-3), "n_steps must be an integer"),
    ],
    ids=[
        "complete-interrupted",
        "complete-early",
        "t-negative",
        "t-beyond-end",
        "t-text",
        "h-negative",
        "out_i-down",
        "out_i-up",
        "out_i-huge",
        "out_i-bool",
        "rows-dropped",
        "G0-size",
        "Y-nan",
        "complete-text",
        "n_steps-negative",
    ],
)
def test_a_resealed_checkpoint_whose_record_contradicts_the_run_is_refused(tmp_path, edit, words):
    path = _stopped(tmp_path)
    _reseal(path, edit)
    with pytest.raises(CheckpointError, match="not consistent") as info:
        _resume(tmp_path)
    assert words in str(info.value)


def test_an_untouched_resealed_checkpoint_still_resumes_to_the_uninterrupted_result(tmp_path):
    plain = _run(*_spring())
    path = _stopped(tmp_path)
    _reseal(path, lambda traj, rec: None)  # the checks accept what gmuk itself writes
    resumed = _resume(tmp_path)
    assert resumed.success
    np.testing.assert_array_equal(resumed.t, plain.t)
    np.testing.assert_allclose(resumed.x, plain.x, rtol=0, atol=1e-9)


def test_a_checkpoint_of_a_run_without_t_eval_is_checked_against_its_last_step(tmp_path):
    path = _stopped(tmp_path, t_eval=None)
    saved = path.read_bytes()
    _reseal(path, lambda traj, rec: rec.update(t=rec["t"] * 0.5))
    with pytest.raises(CheckpointError, match="the last row is at"):
        _resume(tmp_path, t_eval=None)
    path.write_bytes(saved)
    _reseal(path, lambda traj, rec: rec.update(out_i=3))
    with pytest.raises(CheckpointError, match="without t_eval"):
        _resume(tmp_path, t_eval=None)
    path.write_bytes(saved)
    assert _resume(tmp_path, t_eval=None).success  # the genuine one resumes


def test_a_checkpoint_of_an_older_gmuk_without_checksum_is_refused(tmp_path):
    path = _stopped(tmp_path)
    _edit_file(path, _set("version", 1))
    with pytest.raises(CheckpointError, match="older gmuk, without a checksum"):
        _resume(tmp_path)


@pytest.fixture(scope="module")
def interrupted_dir(contested):
    """The folder of the interrupted maintenance run (a partial checkpoint in it)."""
    return contested["out"]


@pytest.mark.parametrize("reseal", [False, True], ids=["hand-edited", "resealed"])
def test_gmuk_run_resume_of_a_checkpoint_edited_to_complete_fails_instead_of_reporting_success(
    tmp_path, interrupted_dir, reseal
):
    out = tmp_path / "out"
    shutil.copytree(interrupted_dir, out)
    path = out / ".checkpoints" / "run-0.npz"
    if reseal:
        _reseal(path, _complete_success)
    else:
        _edit_file(path, _set("complete", True))
    (out / "summary.json").unlink()
    status, err = _main(["run", "--resume", str(out)])
    assert status == 2
    assert ("not consistent" if reseal else "checksum does not match") in err
    assert not (out / "summary.json").exists()  # no "success" reported
    assert path.exists()  # the checkpoint is kept for the user to look at
