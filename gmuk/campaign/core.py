"""Campaign: a model, its dispersions and sweep, a seed; run on a backend, stored, resumed."""

from __future__ import annotations

import ctypes
import hashlib
import itertools
import math
import os
import signal
import socket
import sys
import threading
import time
import traceback
from collections.abc import Iterator, Mapping, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np

from gmuk import runs as _runs
from gmuk._locks import folder_lock
from gmuk.campaign import store as _store
from gmuk.campaign.dispersions import Dispersion, check_sequence, dispersion_from_dict, magnitude
from gmuk.campaign.models import CampaignModel, FunctionModel, get_model, model_from_dict
from gmuk.errors import DefinitionError, GmukError

__all__ = ["Campaign", "CampaignReport", "resume"]

#: Seconds to wait for a Dask scheduler to answer before giving up.
CONNECT_TIMEOUT_S = 5.0

#: The most runs in one campaign (and values in one sweep): ten million. The folder keeps a
#: row per run and a resume reads the finished runs' indices, so a campaign stays within a
#: few GB at this size; a larger one is refused when it is defined, before any folder is made
#: (split it into campaigns of other seeds). Runs are enumerated lazily, never listed.
MAX_RUNS = 10_000_000


def _stream_key(name: str) -> int:
    """A stable 32-bit number of a parameter name (its random stream's spawn key)."""
    return int.from_bytes(hashlib.sha256(name.encode()).digest()[:4], "little")


def _mapping(value: Any, name: str) -> dict[Any, Any]:
    """``value`` as a dict, refusing what is not a mapping (``fixed=1j``, a string, bytes,
    ``...``) with a :class:`DefinitionError` instead of ``dict()``'s raw TypeError."""
    if not isinstance(value, Mapping):
        raise DefinitionError(
            f"{name} must be a mapping of parameter name to value (a dict) or None; "
            f"got {type(value).__name__} {value!r:.60}"
        )
    return dict(value)


def _plain(value: Any) -> Any:
    """``value`` for JSON: tuples as lists."""
    return list(value) if isinstance(value, tuple) else value


@dataclass(frozen=True)
class Campaign:
    """A Monte Carlo campaign or parameter sweep of one campaign model.

    Parameters
    ----------
    model : str or CampaignModel
        A scenario with campaign support (``"fcei"``, ``"ucei"``, ``"apollo16"``:
        :func:`gmuk.campaign.supported`) or a model (e.g. :meth:`from_function`).
    runs : int, optional
        Number of runs, 1 to :data:`MAX_RUNS` (ten million). Default: the number of grid
        points; required without a grid.
    seed : int
        Seed (≥ 0). Run k's random values come from ``SeedSequence(seed, spawn_key=(k,
        key(name)))`` for each dispersed parameter ``name`` alone, so a run is the same on any
        backend, number of workers and order of completion, and adding a dispersion does not
        change the values drawn for the others.
    dispersions : mapping of str to Dispersion, optional
        Parameter name → distribution. Default: the model's own (``fcei``/``ucei``: a 10°
        attitude cone, a 100 m position ball, 0.1 m/s Gaussian velocity errors and a
        Baumgarte ω_n uniform in [0.03, 0.1] rad/s); ``{}`` for none.
    fixed : mapping of str to value, optional
        Parameter name → value for every run (e.g. ``{"orbits": 0.02}``).
    grid : mapping of str to sequence, optional
        A sweep: parameter name → values; the grid is the Cartesian product of the
        sequences in the order given (the last varies fastest), and run k takes grid point
        ``k mod (number of points)``. Default: the model's own (``apollo16``: degree 2…150).
    save_trajectories : bool
        Save each run's trajectory as ``DIR/trajectories/run-K.npz``.

    Raises
    ------
    DefinitionError
        An unknown scenario (the message lists the supported ones), an unknown parameter, a
        parameter given twice, a value or dispersion outside its parameter's domain (a mass
        scale that can be ≤ 0, …), a bad run count or seed.
    """

    model: CampaignModel | str
    runs: int | None = None
    seed: int = 0
    dispersions: Mapping[str, Dispersion] | None = None
    fixed: Mapping[str, Any] | None = None
    grid: Mapping[str, Sequence[Any]] | None = None
    save_trajectories: bool = False
    _points: int = field(default=1, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        model = get_model(self.model) if isinstance(self.model, str) else self.model
        if not isinstance(model, CampaignModel):
            raise DefinitionError(
                f"model must be a scenario name or a gmuk.campaign.CampaignModel; got {model!r}"
            )
        set_ = object.__setattr__
        set_(self, "model", model)
        disp = _mapping(
            model.default_dispersions if self.dispersions is None else self.dispersions,
            "dispersions",
        )
        fixed = _mapping({} if self.fixed is None else self.fixed, "fixed")
        grid_in = _mapping(model.default_grid if self.grid is None else self.grid, "grid")
        seen: dict[str, str] = {}
        for role, names in (("fixed", fixed), ("dispersions", disp), ("grid", grid_in)):
            for name in names:
                model.parameter(name)
                if name in seen:
                    raise DefinitionError(
                        f"parameter {name!r} is given in both {seen[name]} and {role}; give it once"
                    )
                seen[name] = role
        for name, d in disp.items():
            model.parameter(name).check_dispersion(d)
        fixed = {k: model.parameter(k).check(v) for k, v in fixed.items()}
        grid = {
            k: tuple(
                model.parameter(k).check(v)
                for v in check_sequence(vals, f"grid[{k!r}]", limit=MAX_RUNS)
            )
            for k, vals in grid_in.items()
        }
        points = math.prod(len(v) for v in grid.values())
        runs = points if self.runs is None and grid else self.runs
        if isinstance(runs, bool) or not isinstance(runs, (int, np.integer)) or runs < 1:
            raise DefinitionError(
                f"runs must be an integer ≥ 1 (the default is the grid's size, without a grid "
                f"give it); got {self.runs!r}"
            )
        if runs > MAX_RUNS:
            what = "the grid's size" if self.runs is None else "runs"
            raise DefinitionError(
                f"{what} must be at most {MAX_RUNS:,} (gmuk.campaign.core.MAX_RUNS, the most "
                f"runs a campaign folder holds); got {int(runs):,}. Split the campaign into "
                "several of other seeds"
            )
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, (int, np.integer))
            or (self.seed < 0)
        ):
            raise DefinitionError(f"seed must be an integer ≥ 0; got {self.seed!r}")
        set_(self, "runs", int(runs))
        set_(self, "seed", int(self.seed))
        set_(self, "dispersions", disp)
        set_(self, "fixed", fixed)
        set_(self, "grid", grid)
        set_(self, "save_trajectories", bool(self.save_trajectories))
        set_(self, "_points", points)

    @property
    def n_runs(self) -> int:
        """Number of runs (``runs`` after construction)."""
        assert self.runs is not None
        return self.runs

    @property
    def campaign_model(self) -> CampaignModel:
        """The model (``model`` after construction)."""
        assert isinstance(self.model, CampaignModel)
        return self.model

    @classmethod
    def from_function(
        cls,
        function: Any,
        parameters: Mapping[str, Any],
        *,
        headline: Sequence[str] = (),
        **kwargs: Any,
    ) -> Campaign:
        """A campaign of a user function (:class:`gmuk.campaign.FunctionModel`): ``function
        (params) -> RunSetup | dict of metrics``; ``parameters`` name → Parameter or nominal
        value; the other keywords as for :class:`Campaign`."""
        return cls(FunctionModel(function, parameters, tuple(headline)), **kwargs)

    # --- the runs ---------------------------------------------------------------------------

    def parameters(self, k: int) -> dict[str, Any]:
        """Every parameter's value in run ``k`` (0 ≤ k < runs): nominal, fixed, grid point,
        then the dispersed values drawn from (seed, k) alone."""
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < self.n_runs:
            raise DefinitionError(f"run index must be an integer in [0, {self.runs}); got {k!r}")
        model = self.campaign_model
        values = {p.name: p.default for p in model.parameters}
        assert self.fixed is not None and self.grid is not None and self.dispersions is not None
        values |= self.fixed
        if self.grid:
            point = int(k) % self._points
            for name, choices in reversed(list(self.grid.items())):
                point, i = divmod(point, len(choices))
                values[name] = choices[i]
        for name, d in self.dispersions.items():
            seq = np.random.SeedSequence(self.seed, spawn_key=(int(k), _stream_key(name)))
            values[name] = model.parameter(name).check(d.sample(np.random.default_rng(seq)))
        return values

    def varied(self) -> list[str]:
        """Names of the parameters that vary between runs (dispersed or swept)."""
        assert self.grid is not None and self.dispersions is not None
        return [*self.grid, *self.dispersions]

    def to_dict(self) -> dict[str, Any]:
        """The definition as JSON-serialisable data (the manifest's ``campaign``)."""
        assert self.grid is not None and self.dispersions is not None and self.fixed is not None
        return {
            "model": self.campaign_model.to_dict(),
            "runs": self.runs,
            "seed": self.seed,
            "dispersions": {k: d.to_dict() for k, d in self.dispersions.items()},
            "fixed": {k: _plain(v) for k, v in self.fixed.items()},
            "grid": {k: [_plain(v) for v in vals] for k, vals in self.grid.items()},
            "save_trajectories": self.save_trajectories,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Campaign:
        """The campaign :meth:`to_dict` describes."""
        try:
            model = model_from_dict(data["model"])
            return cls(
                model,
                runs=data["runs"],
                seed=data["seed"],
                dispersions={k: dispersion_from_dict(v) for k, v in data["dispersions"].items()},
                fixed={k: tuple(v) if isinstance(v, list) else v for k, v in data["fixed"].items()},
                grid={
                    k: [tuple(v) if isinstance(v, list) else v for v in vals]
                    for k, vals in data["grid"].items()
                },
                save_trajectories=data["save_trajectories"],
            )
        except (KeyError, TypeError, AttributeError) as exc:
            raise DefinitionError(f"not a campaign definition: {exc!r}") from None

    def run_one(self, k: int, out: str | Path | None = None) -> dict[str, Any]:
        """Run ``k`` in this process and return its record (see :func:`execute`)."""
        return execute(self, k, None if out is None else str(out))

    def run(
        self,
        out: str | Path,
        *,
        workers: int = 1,
        scheduler: Any = None,
        progress: bool | None = None,
        connect_timeout_s: float = CONNECT_TIMEOUT_S,
    ) -> CampaignReport:
        """Run the campaign, storing each run's record in ``out`` as it finishes.

        Parameters
        ----------
        out : str or Path
            The campaign folder (:mod:`gmuk.campaign.store`); it must not hold a campaign
            already (continue one with :func:`resume`).
        workers : int
            1: serial, in this process (for debugging); > 1: that many local worker
            processes; with ``scheduler="local"``, a Dask ``LocalCluster`` of that many
            single-threaded worker processes.
        scheduler : str, distributed.Client, cluster or Executor, optional
            A Dask scheduler's address (``"tcp://host:8786"``), ``"local"``, a
            ``distributed.Client`` or a cluster object (e.g. ``LocalCluster``); or a
            ``concurrent.futures.Executor`` of processes (``workers`` then says how many runs
            to keep queued on it, ≈ its number of workers). Clients and executors given here
            are left open.
        progress : bool, optional
            Show a progress bar (tqdm): True, False, or None (default) on a terminal only.
        connect_timeout_s : float
            How long to wait for a scheduler address to answer (s).

        Returns
        -------
        CampaignReport

        Raises
        ------
        GmukError
            Bad ``workers``, an unreachable scheduler, a folder that holds a campaign or
            cannot be made — before any run starts.
        gmuk._locks.FolderInUseError
            Another live process (a campaign or a resume) owns the folder.

        Notes
        -----
        SIGINT or SIGTERM stop the campaign: no new run starts; runs in progress on local
        worker processes finish and are recorded (a second signal abandons them), a serial
        run in progress stops at its next step and is not recorded, and on Dask the runs not
        yet finished are cancelled (Dask does not tell a queued task from a running one).
        Continue with :func:`resume`.

        The call owns the folder while it runs (a lock on ``out/.gmuk-lock``,
        :mod:`gmuk._locks`): another campaign or resume of it is refused, so no run is
        computed twice. The kernel releases the lock when the process ends, however it ends.
        Local worker processes die with the campaign's process, even when it is killed
        (SIGKILL): they are started with a parent-death signal on Linux and watch their
        parent's pid everywhere.
        """
        backend = _backend(workers, scheduler, connect_timeout_s)
        st = _store.ResultStore(out)
        with ExitStack() as owned:
            try:
                try:
                    st.out.mkdir(parents=True, exist_ok=True)
                except OSError as exc:
                    raise GmukError(f"cannot make the campaign folder {st.out}: {exc}") from None
                owned.enter_context(_own(st.out))
                st.create(_manifest(self))
            except BaseException:
                backend.close()
                raise
            return _drive(self, st, backend, progress)


def resume(
    out: str | Path,
    *,
    workers: int = 1,
    scheduler: Any = None,
    progress: bool | None = None,
    connect_timeout_s: float = CONNECT_TIMEOUT_S,
) -> CampaignReport:
    """Continue the campaign in ``out``: run only those of its runs with no record.

    The campaign's definition comes from ``out/manifest.json``; ``workers``, ``scheduler`` and
    ``progress`` as for :meth:`Campaign.run` (they do not change any run's result).

    Raises
    ------
    gmuk._locks.FolderInUseError
        Another live process is running or resuming this campaign (two at once would compute
        every pending run twice); nothing is started.
    """
    st = _store.ResultStore(out)
    campaign = Campaign.from_dict(st.manifest()["campaign"])
    with _own(st.out):
        backend = _backend(workers, scheduler, connect_timeout_s)
        return _drive(campaign, st, backend, progress)


@contextmanager
def _own(out: Path) -> Iterator[None]:
    """Hold the campaign folder's lock (one campaign process per folder; gmuk._locks)."""
    with folder_lock(
        out,
        "gmuk campaign",
        hint="it is being run or resumed already: wait for it to end (gmuk campaign --summary "
        "reads it meanwhile)",
    ):
        yield


def load_campaign(out: str | Path) -> Campaign:
    """The campaign whose folder is ``out`` (from its manifest)."""
    return Campaign.from_dict(_store.ResultStore(out).manifest()["campaign"])


def _manifest(campaign: Campaign) -> dict[str, Any]:
    from gmuk import __version__

    return {
        "format": _store.FORMAT,
        "version": _store.FORMAT_VERSION,
        "gmuk_version": __version__,
        "created_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "campaign": campaign.to_dict(),
    }


# --- one run -------------------------------------------------------------------------------------


def _flatten(campaign: Campaign, params: Mapping[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for p in campaign.campaign_model.parameters:
        value = params[p.name]
        if p.kind in ("vector3", "rotation", "scale3"):
            for i, c in enumerate(value, start=1):
                out[f"p_{p.name}_{i}"] = float(c)
            out[f"p_{p.name}_mag"] = magnitude(p.kind, value)
        else:
            out[f"p_{p.name}"] = value
    return out


def execute(campaign: Campaign, k: int, out: str | None) -> dict[str, Any]:
    """Run ``k`` of ``campaign`` and return its record (a flat dict, one table row).

    A failure (an exception, or a simulation that ends with status ``"failed"``) is recorded
    with ``status="failed"``, the error and its traceback; a simulation stopped by a signal
    gives ``status="interrupted"`` (not stored). With ``out``, the worker appends ``start`` and
    ``end`` lines to ``out/attempts.log`` and saves the trajectory when asked.
    """
    t0 = time.perf_counter()
    pid = os.getpid()
    _store.log_attempt(out, f"start {k} {pid}")
    record: dict[str, Any] = {
        "run": int(k),
        "status": "success",
        "error": None,
        "traceback": None,
        "wall_time_s": math.nan,
        "worker": f"{socket.gethostname()}:{pid}",
        "trajectory": None,
    }
    params = campaign.parameters(k)
    record |= _flatten(campaign, params)
    try:
        traj, metrics = campaign.campaign_model.run(params)
        if traj is not None and traj.status != "success":
            record["status"] = traj.status
            record["error"] = traj.message
        if traj is not None and campaign.save_trajectories and out is not None:
            rel = Path(_store.TRAJECTORIES) / f"run-{int(k):06d}.npz"
            (Path(out) / _store.TRAJECTORIES).mkdir(exist_ok=True)
            traj.save(Path(out) / rel)
            record["trajectory"] = str(rel)
        record |= {f"m_{name}": float(v) for name, v in metrics.items()}
    except Exception as exc:
        control = _runs.current()
        # a model that fails on the short trajectory of a stopped run was stopped, not failed
        stopped = control is not None and control.stop_requested
        record["status"] = "interrupted" if stopped else "failed"
        record["error"] = f"{type(exc).__name__}: {exc}"
        record["traceback"] = traceback.format_exc()
    record["wall_time_s"] = time.perf_counter() - t0
    _store.log_attempt(out, f"end {k} {pid} {record['status']}")
    return record


def execute_many(campaign: Campaign, ks: Sequence[int], out: str | None) -> list[dict[str, Any]]:
    """:func:`execute` for each of the runs ``ks`` in turn (one task of a backend)."""
    return [execute(campaign, k, out) for k in ks]


#: A task holds runs worth about this much time (s), so that a backend's cost per task (about
#: 2 ms on a Dask LocalCluster, 0.4 ms on local processes) is a few percent of it at most.
TASK_S = 0.1
#: The most runs in one task.
TASK_RUNS_MAX = 64


# --- backends ------------------------------------------------------------------------------------


def _ignore_sigint() -> None:
    """The parent alone decides when a campaign stops."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


#: Linux's ``prctl`` option that sends the process a signal when its parent dies.
_PR_SET_PDEATHSIG = 1
#: How often a worker checks that its parent is alive (s), where prctl is not available.
PARENT_POLL_S = 1.0


def _worker_init(parent: int) -> None:
    """Worker-process initializer: ignore SIGINT (:func:`_ignore_sigint`) and die with the
    campaign's process ``parent``, even when it is killed by SIGKILL — by a parent-death
    signal (SIGKILL) on Linux, and everywhere by a daemon thread that ends the worker once
    its parent pid changes (the parent is gone: the worker was re-parented)."""
    _ignore_sigint()
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # pragma: no cover - no prctl: the thread below
            pass
    if os.getppid() != parent:  # the parent died before the signal was armed
        os._exit(1)
    threading.Thread(
        target=_watch_parent, args=(parent,), name="gmuk-parent-watch", daemon=True
    ).start()


def _watch_parent(parent: int) -> None:
    """End this worker process once ``parent`` is no longer its parent."""
    while True:
        time.sleep(PARENT_POLL_S)
        if os.getppid() != parent:
            os._exit(1)


class _Backend:
    """Runs records somewhere; ``submit`` returns a future with ``done()`` and ``result()``."""

    name = "serial"
    slots = 1

    def submit(self, campaign: Campaign, ks: list[int], out: str) -> Any:
        """A future of the records (a list) of the runs ``ks``."""
        raise NotImplementedError

    def wait(self, futures: set[Any], timeout: float) -> set[Any]:
        raise NotImplementedError

    def cancel(self, futures: set[Any]) -> None:
        for f in futures:
            f.cancel()

    def abandon(self) -> None:
        self.close()

    def close(self) -> None:
        pass


class _Processes(_Backend):
    name = "processes"

    def __init__(self, workers: int, pool: Any = None) -> None:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        self.slots = workers
        self.own = pool is None
        self.pool = pool or ProcessPoolExecutor(
            workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_worker_init,
            initargs=(os.getpid(),),
        )

    def submit(self, campaign: Campaign, ks: list[int], out: str) -> Any:
        from concurrent.futures.process import BrokenProcessPool

        try:
            return self.pool.submit(execute_many, campaign, ks, out)
        except BrokenProcessPool:
            raise GmukError(
                "the campaign's worker processes died (a crash, or a script without a main "
                "guard: workers are started with the 'spawn' method, which imports the main "
                "script again, so a script that runs a campaign with workers > 1 must keep its "
                "code under if __name__ == '__main__':)"
            ) from None

    def wait(self, futures: set[Any], timeout: float) -> set[Any]:
        from concurrent.futures import FIRST_COMPLETED
        from concurrent.futures import wait as cf_wait

        done, _ = cf_wait(futures, timeout=timeout, return_when=FIRST_COMPLETED)
        return set(done)

    def abandon(self) -> None:
        if not self.own:
            return
        # The runs in progress are dropped: end the worker processes (this pool's own).
        for p in list(getattr(self.pool, "_processes", {}).values()):
            p.terminate()
        self.pool.shutdown(wait=False, cancel_futures=True)

    def close(self) -> None:
        if self.own:
            self.pool.shutdown(wait=True, cancel_futures=True)


class _Dask(_Backend):
    name = "dask"

    def __init__(self, scheduler: Any, workers: int, timeout: float) -> None:
        try:
            import distributed
        except ImportError:
            raise GmukError(
                "the Dask backend needs dask.distributed; install it with "
                "pip install 'gmuk[campaign]'"
            ) from None
        self.cluster = None
        self.own_client = True
        if isinstance(scheduler, distributed.Client):
            self.client, self.own_client = scheduler, False
        elif isinstance(scheduler, str) and scheduler == "local":
            self.cluster = distributed.LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=40,
            )
            self.client = distributed.Client(self.cluster)
        elif isinstance(scheduler, str):
            if "://" not in scheduler:
                raise GmukError(
                    f"--scheduler takes a Dask scheduler address such as tcp://host:8786, or "
                    f"'local'; got {scheduler!r}"
                )
            try:
                self.client = distributed.Client(scheduler, timeout=timeout)
            except (OSError, TimeoutError, ValueError) as exc:
                raise GmukError(
                    f"cannot reach the Dask scheduler at {scheduler} within {timeout:g} s: "
                    f"{type(exc).__name__}: {exc}"
                ) from None
        else:  # a cluster object (LocalCluster, …)
            if not hasattr(scheduler, "scheduler_address"):
                raise GmukError(
                    f"scheduler must be an address, 'local', a distributed.Client or a Dask "
                    f"cluster; got {scheduler!r}"
                )
            self.client = distributed.Client(scheduler)
        self.slots = max(1, sum(self.client.nthreads().values()))

    def submit(self, campaign: Campaign, ks: list[int], out: str) -> Any:
        return self.client.submit(
            execute_many,
            campaign,
            ks,
            out,
            pure=False,
            key=f"gmuk-runs-{ks[0]}-{len(ks)}-{os.getpid()}-{time.monotonic_ns()}",
        )

    def wait(self, futures: set[Any], timeout: float) -> set[Any]:
        import distributed

        try:
            distributed.wait(list(futures), timeout=timeout, return_when="FIRST_COMPLETED")
        except TimeoutError:  # none finished within the timeout (the caller checks signals)
            pass
        return {f for f in futures if f.done()}

    def cancel(self, futures: set[Any]) -> None:
        pending = [f for f in futures if f.status == "pending"]
        if pending:
            self.client.cancel(pending)

    def abandon(self) -> None:
        self.close()

    def close(self) -> None:
        if self.own_client:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _backend(workers: Any, scheduler: Any, timeout: float = CONNECT_TIMEOUT_S) -> _Backend:
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise GmukError(f"workers must be an integer ≥ 1; got {workers!r}")
    if not (isinstance(timeout, (int, float)) and 0 < timeout < math.inf):
        raise GmukError(f"connect_timeout_s must be a finite number > 0; got {timeout!r}")
    from concurrent.futures import Executor

    if isinstance(scheduler, Executor):
        return _Processes(int(workers), scheduler)
    if scheduler is not None:
        return _Dask(scheduler, int(workers), float(timeout))
    return _Processes(int(workers)) if workers > 1 else _Backend()


# --- the loop ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CampaignReport:
    """What a call of :meth:`Campaign.run` or :func:`resume` did.

    Attributes
    ----------
    out : Path
    runs : int
        Runs in the campaign.
    finished : int
        Runs recorded in the folder now (earlier calls included).
    failed : int
        Of those, runs recorded with ``status="failed"``.
    computed : int
        Runs this call computed and recorded.
    stopped_by : str or None
        The signal that stopped the call (``"SIGINT"``, ``"SIGTERM"``), if any.
    wall_time_s : float
    backend : str
        ``"serial"``, ``"processes"`` or ``"dask"``.
    """

    out: Path
    runs: int
    finished: int
    failed: int
    computed: int
    stopped_by: str | None
    wall_time_s: float
    backend: str

    @property
    def complete(self) -> bool:
        """Every run is recorded."""
        return self.finished == self.runs


class _Stop:
    def __init__(self) -> None:
        self.signals: list[int] = []
        self.control: Any = None

    def __call__(self, signum: int, frame: FrameType | None) -> None:
        self.signals.append(signum)
        if self.control is not None:
            self.control.request_stop()


@contextmanager
def _signals(stop: _Stop) -> Iterator[None]:
    """SIGINT and SIGTERM ask the campaign to stop (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


#: The longest finished runs wait before the journal gets them (s): one chunk per interval
#: instead of one per run, so that a run costs well under a millisecond of bookkeeping; a
#: SIGKILL loses at most this much finished work (its runs are done again on resume).
FLUSH_S = 0.25


def _drive(
    campaign: Campaign, st: _store.ResultStore, backend: _Backend, progress: bool | None
) -> CampaignReport:
    from tqdm.auto import tqdm

    t0 = time.perf_counter()
    out = str(st.out)
    abandoned = False  # a second signal: the runs in progress are dropped
    pending: list[dict[str, Any]] = []  # finished records not yet in the journal
    try:
        st.compact()
        done = st.finished()
        # the runs to do, enumerated lazily (a campaign may hold up to MAX_RUNS runs)
        todo = (k for k in range(campaign.n_runs) if k not in done)
        left = campaign.n_runs - sum(1 for k in done if 0 <= k < campaign.n_runs)
        show = sys.stderr.isatty() if progress is None else bool(progress)
        bar = tqdm(
            total=campaign.n_runs,
            initial=len(done),
            disable=not show,
            desc=f"campaign {campaign.campaign_model.name}",
            unit="run",
        )
        stop = _Stop()
        computed = 0
        last_flush = time.monotonic()

        def store(records: list[dict[str, Any]], *, flush: bool = False) -> None:
            """Keep the finished records; write them to the journal as one chunk at most
            every FLUSH_S seconds (and when the campaign ends or stops)."""
            nonlocal computed, last_flush
            kept = [r for r in records if r["status"] != "interrupted"]
            pending.extend(kept)
            computed += len(kept)
            bar.update(len(kept))
            if pending and (flush or time.monotonic() - last_flush >= FLUSH_S):
                st.append(pending)
                pending.clear()
                last_flush = time.monotonic()

        with _signals(stop):
            if backend.name == "serial":
                with _runs.run_control() as control:
                    stop.control = control
                    for k in todo:
                        if stop.signals:
                            break
                        store([execute(campaign, k, out)])
            else:
                running: set[Any] = set()
                window = 2 * backend.slots + 2  # tasks queued ahead, so no worker waits
                per_task = 1  # runs per task, from the runs' own times once some are known
                times: list[float] = []
                while True:
                    if not stop.signals:
                        while left > 0 and len(running) < window:
                            # never so many per task that a worker is left without one
                            share = -(-left // (2 * backend.slots))
                            n = max(1, min(per_task, share))
                            ks = list(itertools.islice(todo, n))  # in run order
                            left = left - len(ks) if ks else 0
                            if ks:
                                running.add(backend.submit(campaign, ks, out))
                    elif len(stop.signals) == 1 and running:
                        backend.cancel(running)
                    if len(stop.signals) > 1:
                        abandoned = True
                        break
                    if not running:
                        break
                    finished = backend.wait(running, 0.2)
                    running -= finished
                    records = []
                    for f in finished:
                        if f.cancelled():
                            continue
                        try:
                            records.extend(f.result())
                        except BaseException:  # a lost worker: its runs stay to do
                            continue
                    times += [r["wall_time_s"] for r in records if r["status"] == "success"]
                    if times:
                        mean = max(float(np.mean(times[-50:])), 1e-6)
                        per_task = int(min(TASK_RUNS_MAX, max(1, TASK_S // mean)))
                    store(records)
                if abandoned:
                    backend.abandon()
        store([], flush=True)
        bar.close()
    finally:
        if pending:  # an error in the loop: keep what finished
            st.append(pending)
        if not abandoned:
            backend.close()
    st.compact()
    table = _store.read_table(st.out)
    statuses = table.column("status").to_pylist()
    return CampaignReport(
        out=st.out,
        runs=campaign.n_runs,
        finished=len(statuses),
        failed=sum(s == "failed" for s in statuses),
        computed=computed,
        stopped_by=signal.Signals(stop.signals[0]).name if stop.signals else None,
        wall_time_s=time.perf_counter() - t0,
        backend=backend.name,
    )
