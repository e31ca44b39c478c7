"""Campaign runs: backends agree bit for bit, failures are recorded, the store resumes and
stays readable, trajectories and summaries are written."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gmuk.campaign import (
    AttitudeCone,
    Campaign,
    Parameter,
    RunSetup,
    UniformBall,
    read_table,
    resume,
    summarize,
)
from gmuk.campaign.store import ResultStore
from gmuk.errors import GmukError
from gmuk.trajectory import load_trajectory

#: A tiny dispersed FCEI campaign: 0.2 % of an orbit (45 s), 21 output times per run.
TINY = {"orbits": 0.002, "samples": 21}


def rows(out, drop=("wall_time_s", "worker")):
    """The table's rows without the columns that differ between backends by nature."""
    return read_table(out).drop_columns(list(drop)).to_pylist()


def same(a, b):
    """Equal, NaN equal to NaN (bit-for-bit comparison of the floats otherwise)."""
    if a.keys() != b.keys():
        return False
    for key in a:
        x, y = a[key], b[key]
        if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
            continue
        if x != y:
            return False
    return True


def test_local_cluster_with_two_workers_equals_serial_run_for_run(tmp_path):
    campaign = Campaign("fcei", runs=20, seed=11, fixed=TINY)
    serial = campaign.run(tmp_path / "serial", workers=1)
    dask = campaign.run(tmp_path / "dask", workers=2, scheduler="local")
    assert (serial.backend, dask.backend) == ("serial", "dask")
    assert serial.finished == dask.finished == 20 and serial.failed == dask.failed == 0
    a, b = rows(tmp_path / "serial"), rows(tmp_path / "dask")
    assert [r["run"] for r in a] == list(range(20))
    assert all(same(x, y) for x, y in zip(a, b, strict=True))
    # the runs did different things: the dispersions are there
    assert len({r["m_initial_attitude_error_rad"] for r in a}) == 20
    # Dask workers ran them (other processes than this one)
    workers = set(read_table(tmp_path / "dask").column("worker").to_pylist())
    assert all(not w.endswith(f":{__import__('os').getpid()}") for w in workers)


def test_local_processes_equal_serial_run_for_run(tmp_path):
    campaign = Campaign("ucei", runs=6, seed=2, fixed=TINY)
    campaign.run(tmp_path / "serial", workers=1)
    campaign.run(tmp_path / "procs", workers=2)
    a, b = rows(tmp_path / "serial"), rows(tmp_path / "procs")
    assert len(a) == 6 and all(same(x, y) for x, y in zip(a, b, strict=True))
    assert all(r["status"] == "success" for r in a)


def test_dispersed_fcei_start_converges_under_baumgarte(tmp_path):
    """The Baumgarte terms pull a 10° / 100 m start onto the reference: after 2.5 time
    constants' worth of several e-foldings the errors are orders of magnitude smaller."""
    campaign = Campaign(
        "fcei",
        runs=3,
        seed=5,
        fixed={"orbits": 0.01, "samples": 101, "baumgarte_omega_n": 0.1},
        dispersions={
            "attitude_error": AttitudeCone(math.radians(10.0)),
            "position_error_m": UniformBall(100.0),
        },
    )
    campaign.run(tmp_path / "c")
    for r in read_table(tmp_path / "c").to_pylist():
        assert r["m_initial_attitude_error_rad"] <= math.radians(10.0)
        assert r["m_final_attitude_error_rad"] < 1e-6 * max(r["m_initial_attitude_error_rad"], 1e-3)
        assert r["m_final_position_error_m"] < 1e-4 * max(r["m_initial_position_error_m"], 1.0)
        assert r["m_attitude_settling_time_s"] < 227.0
        assert r["m_max_constraint_residual"] < 1e-9


def test_the_fccl_controller_brings_large_attitude_errors_back(tmp_path):
    """The Chapter 5 closed loop from starts up to 170° off: the attitude error falls by
    orders of magnitude within 3 % of an orbit (the almost-global convergence study)."""
    campaign = Campaign(
        "fccl",
        runs=2,
        seed=11,
        fixed={"orbits": 0.03, "samples": 31},
        dispersions={"attitude_error": AttitudeCone(math.radians(170.0))},
    )
    campaign.run(tmp_path / "c")
    for r in read_table(tmp_path / "c").to_pylist():
        assert r["status"] == "success"
        assert r["m_initial_attitude_error_rad"] <= math.radians(170.0)
        assert r["m_final_attitude_error_rad"] < 1e-3 * r["m_initial_attitude_error_rad"]
        assert r["m_peak_control_torque_N_m"] > 0.0


def flaky(params):
    """Metrics of a toy model that fails for odd runs."""
    if params["k"] % 2:
        raise RuntimeError(f"odd run {params['k']}")
    return {"double": 2.0 * params["x"]}


def test_a_failed_run_is_recorded_with_its_traceback_and_the_campaign_goes_on(tmp_path):
    from gmuk.campaign import IntegerRange

    campaign = Campaign.from_function(
        flaky,
        {"k": 0, "x": 1.5},
        runs=6,
        grid={"k": list(range(6))},
        dispersions={"x": IntegerRange(1, 3)},
    )
    report = campaign.run(tmp_path / "c")
    assert (report.finished, report.failed) == (6, 3)
    table = read_table(tmp_path / "c").to_pylist()
    for r in table:
        if r["p_k"] % 2:
            assert r["status"] == "failed"
            assert r["error"] == f"RuntimeError: odd run {r['p_k']}"
            assert "Traceback" in r["traceback"] and "flaky" in r["traceback"]
            assert r["m_double"] is None
        else:
            assert r["status"] == "success" and r["m_double"] == 2.0 * r["p_x"]
    # resuming a complete campaign computes nothing, and failed runs are not retried
    again = resume(tmp_path / "c")
    assert again.computed == 0 and again.finished == 6


def oscillator(params):
    """A point mass on a spring, dispersed start: returns a RunSetup."""
    import gmuk

    p = gmuk.PointMass("p", 1.0)
    system = gmuk.System([p], [], [gmuk.LinearSpringDamper(params["k"], bodies=[p])])
    state = system.state(r={"p": params["r0"]}, v={"p": np.zeros(3)})
    return RunSetup(
        system,
        state,
        (0.0, 1.0),
        {"rtol": 1e-10, "atol": 1e-12},
        metrics=lambda traj: {"final_distance_m": float(np.linalg.norm(traj.x[-1, :3]))},
    )


def test_user_function_returning_a_run_setup_saves_trajectories_and_resumes(tmp_path):
    campaign = Campaign.from_function(
        oscillator,
        {
            "k": Parameter("k", "real", 4.0, "stiffness (N/m)", low=0.0, low_open=True),
            "r0": (1.0, 0.0, 0.0),
        },
        runs=4,
        seed=3,
        dispersions={"r0": UniformBall(2.0)},
        save_trajectories=True,
        headline=("final_distance_m",),
    )
    out = tmp_path / "c"
    report = campaign.run(out)
    assert report.complete
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["campaign"]["model"]["function"].endswith(":oscillator")
    for r in read_table(out).to_pylist():
        traj = load_trajectory(out / r["trajectory"])
        r0 = np.array([r["p_r0_1"], r["p_r0_2"], r["p_r0_3"]])
        assert np.array_equal(traj.x[0, :3], r0)
        # x(1) = r0 cos(2·1): the record's metric is the saved trajectory's
        expected = np.linalg.norm(r0) * abs(math.cos(2.0))
        assert r["m_final_distance_m"] == pytest.approx(expected, rel=1e-8)
    summary = summarize(out)
    assert summary.statistics["final_distance_m"]["count"] == 4
    assert {p.name for p in summary.files} == {"metrics.csv", "histograms.png", "scatter.png"}


def test_resume_runs_only_the_missing_runs_and_a_crash_mid_compaction_is_harmless(tmp_path):
    out = tmp_path / "c"
    campaign = Campaign("fcei", runs=8, seed=4, fixed=TINY)
    full = campaign.run(tmp_path / "full")
    assert full.computed == 8
    # a campaign of which runs 0–3 finished, and whose compaction was killed after writing
    # runs.parquet but before removing the parts: rows duplicated across files
    st = ResultStore(out)
    st.create(json.loads((tmp_path / "full" / "manifest.json").read_text()))
    first = [r for r in read_table(tmp_path / "full").to_pylist() if r["run"] < 4]
    st.append(first[:2])
    st.append(first[2:])
    st.close()
    import shutil

    table = read_table(out)
    import pyarrow.parquet as pq

    pq.write_table(table, out / "runs.parquet")  # the compacted copy, parts still there
    assert read_table(out).num_rows == 4  # duplicates dropped on read
    report = resume(out)
    assert report.computed == 4 and report.finished == 8
    starts = [k for what, k in st.attempts() if what == "start"]
    assert sorted(starts) == [4, 5, 6, 7]  # none of 0–3 computed again
    assert all(same(x, y) for x, y in zip(rows(out), rows(tmp_path / "full"), strict=True))
    assert not list((out / "parts").glob("journal-*"))  # compacted at the end
    shutil.rmtree(out)


def test_a_folder_holding_a_campaign_is_refused_before_any_run(tmp_path):
    campaign = Campaign("fcei", runs=2, fixed=TINY)
    campaign.run(tmp_path / "c")
    with pytest.raises(GmukError, match=r"already holds a campaign.*--resume"):
        campaign.run(tmp_path / "c")
    with pytest.raises(GmukError, match="no campaign to resume"):
        resume(tmp_path / "empty")


def test_a_scheduler_address_runs_the_campaign_on_that_cluster(tmp_path):
    """The address path (what --scheduler tcp://… takes), with a cluster of this test's."""
    import distributed

    campaign = Campaign("fcei", runs=3, seed=8, fixed=TINY)
    campaign.run(tmp_path / "serial")
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        report = campaign.run(tmp_path / "addr", scheduler=cluster.scheduler_address)
        assert report.backend == "dask" and report.complete
        # the campaign closed its own client, not the cluster
        assert cluster.status.name == "running"
    assert all(
        same(x, y) for x, y in zip(rows(tmp_path / "serial"), rows(tmp_path / "addr"), strict=True)
    )


def test_unreachable_scheduler_is_a_gmuk_error_before_any_run(tmp_path):
    campaign = Campaign("fcei", runs=2, fixed=TINY)
    with pytest.raises(GmukError, match=r"cannot reach the Dask scheduler at tcp://127\.0\.0\.1:9"):
        campaign.run(tmp_path / "c", scheduler="tcp://127.0.0.1:9", connect_timeout_s=0.5)
    assert not (tmp_path / "c").exists()
    with pytest.raises(GmukError, match="workers must be an integer ≥ 1"):
        campaign.run(tmp_path / "c", workers=0)


def test_gravity_degree_sweep_of_the_chapter3_orbit(tmp_path):
    """Degree 0 is the uniform field (a difference at round-off of the 1.8e6 m radius);
    degrees 2 and 10 move the LM by metres within 2 % of an orbit."""
    campaign = Campaign(
        "apollo16", grid={"degree": [0, 2, 10]}, fixed={"orbits": 0.02, "samples": 11}
    )
    report = campaign.run(tmp_path / "c")
    assert report.finished == 3 and report.failed == 0
    by_degree = {r["p_degree"]: r for r in read_table(tmp_path / "c").to_pylist()}
    assert by_degree[0]["m_max_position_difference_m"] < 1e-9
    assert by_degree[0]["m_max_attitude_difference_rad"] < 1e-14
    for degree in (2, 10):
        assert by_degree[degree]["m_max_position_difference_m"] > 1.0
        assert by_degree[degree]["m_max_attitude_difference_rad"] > 1e-7


def test_a_journal_cut_short_by_a_kill_keeps_its_complete_chunks(tmp_path):
    """A SIGKILL while a chunk is being appended leaves its first bytes: the reader keeps
    every complete chunk before it and ignores the tail."""
    campaign = Campaign("fcei", runs=3, seed=4, fixed=TINY)
    campaign.run(tmp_path / "full")
    records = read_table(tmp_path / "full").to_pylist()
    out = tmp_path / "c"
    st = ResultStore(out)
    st.create(json.loads((tmp_path / "full" / "manifest.json").read_text()))
    st.append([records[0]])
    st.append([records[1]])
    (journal,) = (out / "parts").glob("journal-*.arrows")
    two = journal.stat().st_size  # flushed: the two chunks are in the file
    st.append([records[2]])
    st.close()
    data = journal.read_bytes()
    assert read_table(out).column("run").to_pylist() == [0, 1, 2]
    for cut in (two + 1, two + 8, two + 9, (two + len(data)) // 2, len(data) - 1):
        journal.write_bytes(data[:cut])
        assert read_table(out).column("run").to_pylist() == [0, 1]
    journal.write_bytes(data[:5])  # not even a whole length prefix
    assert read_table(out).num_rows == 0
    report = resume(out)
    assert report.computed == 3 and report.finished == 3
