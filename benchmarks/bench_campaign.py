"""Campaign throughput and scheduling overhead: serial vs local processes vs a Dask LocalCluster.

Each backend runs the same campaign of one-orbit FCEI runs (the scenario's tolerances, rtol
3e-15, atol 1e-12, 721 output times; the campaign model's Baumgarte gains, no dispersion:
every run is the thesis's FCEI run with stabilisation) into a fresh folder, and reports

* runs per minute: runs / wall time of ``Campaign.run``, with warm workers (the process
  pool and the LocalCluster are started and warmed by a small campaign first; their start-up
  times are printed separately);
* the coordinating process's CPU time per run (submitting, collecting, storing; for the
  serial backend it includes the runs themselves);
* scheduling overhead per run: ``(W · T_loop − Σ t_run) / N`` — the worker-seconds a run costs
  beyond its own simulation time (``t_run``, measured inside the worker), as a fraction of
  the mean run time. ``T_loop`` is the wall time of the campaign loop (submission, waiting,
  storing each record as a Parquet part, compaction); W the number of workers.

A second, tiny campaign (0.2 % of an orbit per run, ~10 ms) shows the overhead per run in
absolute terms.

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/bench_campaign.py
    ... --runs 8 --tiny-runs 100
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

import gmuk
from gmuk.campaign import Campaign, read_table

ONE_ORBIT = {"orbits": 1.0, "samples": 721, "rtol": 3e-15, "atol": 1e-12, "baumgarte_omega_n": 0.0}
TINY = {"orbits": 0.002, "samples": 21}


def measure(campaign: Campaign, out: Path, workers: int, scheduler: object) -> dict[str, float]:
    t0, c0 = time.perf_counter(), time.process_time()
    report = campaign.run(out, workers=workers, scheduler=scheduler, progress=False)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    assert report.complete and report.failed == 0, report
    t_run = np.array(read_table(out).column("wall_time_s").to_pylist())
    n = campaign.n_runs
    overhead = (workers * report.wall_time_s - t_run.sum()) / n
    return {
        "wall_s": wall,
        "loop_s": report.wall_time_s,
        "runs_per_min": 60.0 * n / wall,
        "mean_run_s": float(t_run.mean()),
        "overhead_per_run_s": overhead,
        "overhead_pct": 100.0 * overhead / float(t_run.mean()),
        "main_cpu_per_run_ms": 1e3 * cpu / n,
    }


def main() -> None:
    gmuk.compile_loop()  # timings of the compiled loop, not of its one-time compilation
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=8, help="one-orbit runs per backend")
    parser.add_argument("--tiny-runs", type=int, default=100, help="tiny runs per backend")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()

    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    import distributed

    from gmuk.campaign.core import _ignore_sigint

    root = Path(tempfile.mkdtemp(prefix="gmuk-bench-campaign-"))
    try:
        t0 = time.perf_counter()
        pool = ProcessPoolExecutor(
            args.workers, multiprocessing.get_context("spawn"), initializer=_ignore_sigint
        )
        warm = Campaign("fcei", runs=4 * args.workers, dispersions={}, fixed=TINY)
        warm.run(root / "warm-pool", workers=args.workers, scheduler=pool, progress=False)
        print(
            f"process pool ({args.workers} workers) start-up and warm-up: "
            f"{time.perf_counter() - t0:.2f} s"
        )
        t0 = time.perf_counter()
        cluster = distributed.LocalCluster(
            n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None
        )
        client = distributed.Client(cluster)
        startup = time.perf_counter() - t0
        print(f"LocalCluster ({args.workers} workers) start-up: {startup:.2f} s")
        # warm the serial process and the Dask workers (numba caches, the FCEI set-up)
        warm.run(root / "warm-serial", progress=False)
        warm.run(root / "warm-dask", workers=args.workers, scheduler=client, progress=False)
        for label, fixed, runs in (
            ("one-orbit FCEI", ONE_ORBIT, args.runs),
            ("tiny (0.002 orbit)", TINY, args.tiny_runs),
        ):
            campaign = Campaign("fcei", runs=runs, dispersions={}, fixed=fixed)
            print(f"\n{label}: {runs} runs")
            print(
                f"{'backend':<22}{'wall s':>9}{'runs/min':>10}{'run s':>9}"
                f"{'overhead/run s':>16}{'overhead %':>12}{'main CPU/run ms':>17}"
            )
            for name, workers, scheduler in (
                ("serial", 1, None),
                (f"processes ({args.workers})", args.workers, pool),
                (f"LocalCluster ({args.workers})", args.workers, client),
            ):
                m = measure(campaign, root / f"{label[:4]}-{name[:5]}", workers, scheduler)
                print(
                    f"{name:<22}{m['wall_s']:>9.2f}{m['runs_per_min']:>10.1f}"
                    f"{m['mean_run_s']:>9.3f}{m['overhead_per_run_s']:>16.4f}"
                    f"{m['overhead_pct']:>12.2f}{m['main_cpu_per_run_ms']:>17.2f}"
                )
        client.close()
        cluster.close()
        pool.shutdown()
    finally:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
