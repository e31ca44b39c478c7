"""The ``gmuk`` command: list and run the scenarios, check gmuk against Pinocchio.

    gmuk --version
    gmuk list
    gmuk plugins
    gmuk run [NAME] [--out DIR] [--no-plots] [--csv] [--format FMT] [--checkpoint-every S] [...]
    gmuk run [NAME] --stop-at T [...]
    gmuk run [NAME] --resume DIR
    gmuk run NAME --help
    gmuk check [--seed S] [--samples N] [--verbose]
    gmuk view RUN_DIR_or_FILE.npz [--out FILE.html] [--central-radius M] [--max-frames N]
    gmuk campaign SCENARIO --runs N [--workers W | --scheduler ADDR] --out DIR [...]
    gmuk campaign --resume DIR | --summary DIR

``gmuk run`` writes ``DIR/trajectory.npz`` (loadable with :func:`gmuk.load_trajectory`),
``DIR/summary.json`` with the headline figures, the figures, and whatever further data the
scenario writes (its ``write_data``, if it has one). Without NAME it runs ``fcei``. The
flags after NAME are the common ones above and the options the scenario declares
(:class:`gmuk.scenarios.Option`; e.g. ``--orbits K``), listed by ``gmuk run NAME --help``;
options not given take the scenario's defaults. A bad value stops with a message naming the
flag and what came in, exit status 2.

Stopping and resuming (:mod:`gmuk.runs`): SIGINT (Ctrl-C) or SIGTERM stop the run at the next
integration step; the trajectory so far and ``summary.json`` (``status``, the signal, the time
reached) are written and the exit status is 130 or 143. Every simulation writes a checkpoint
into ``DIR/.checkpoints`` every ``--checkpoint-every`` seconds (default 60), so a killed
process (SIGKILL, a power cut) loses at most one interval; ``gmuk run --resume DIR`` continues
the run with the options it was started with. A run that completes removes its checkpoints.

Constraint drift (:func:`gmuk.engine.integrate.simulate`, ``drift_tol``): ``summary.json``
gives each run's ``constraint_violation`` (largest position- and velocity-level residuals,
tolerance, one entry per constraint) and ``drifted``; a run that completed with a constraint
drifted past its tolerance has ``status`` "drifted" (``runs_drifted`` names the runs), prints
why on stderr, and exits with status 3 after writing everything.

One run at a time owns an output folder: ``gmuk run`` (and ``--resume``) holds a lock on
``DIR/.gmuk-lock`` (:mod:`gmuk._locks`; the file names the process, host and start time) for
as long as it runs. A second run into the same folder is refused at once with a
:class:`~gmuk._locks.FolderInUseError` naming the first (exit status 2) and changes nothing
there. The kernel releases the lock when its process ends, however it ends: a killed run never
blocks the next one.

``gmuk view`` writes an interactive 3-D view of a run (:mod:`gmuk.view`): one HTML file that
opens offline in a browser. ``gmuk run`` writes it as ``DIR/view.html`` unless ``--no-plots``,
loading plotly.js from one shared copy in DIR's parent folder (``plotly-<version>.min.js``,
written once: docs/view.rst); ``gmuk view`` writes a self-contained page. ``--out`` names the
HTML file; given an existing folder, ``gmuk view`` writes ``view.html`` into it (as ``cp FILE
DIR`` does). The trajectory file is checked as :func:`gmuk.load_trajectory` checks it; a file
it refuses, or an output it cannot write, stops with a message and exit status 2.

What a run spends its time on: any phase longer than 2 s (loading or compiling the step loop,
simulating, the figures, ...) says so on stderr when 2 s have passed and how long it took when
it ends (on a terminal, the simulation also shows a progress bar); ``summary.json``'s
``time_s`` gives each phase's wall time (s) and their total — ``loop``: loading or compiling
the step loop, ``compile``: compiling the parts' kernels on first use (both once per machine),
``simulation``: the rest of the scenario's run — and ``wall_time_s`` is the simulation's.
``--csv`` also writes the primary run as ``DIR/trajectory.csv``.

Events (:mod:`gmuk.engine.events`): ``--stop-at T`` ends every simulation of the run at the
time T (s) with a terminal event (status "terminated", the state at T as the last output);
``summary.json``'s ``events`` lists, for each run that located any, its events (name, t,
direction, terminal), those a scenario's own simulations define included.

``gmuk check`` prints the table of :func:`gmuk.check <gmuk.crosscheck.check>` and exits 0 if
every quantity agrees with Pinocchio within its tolerance, 1 if any does not.
"""

from __future__ import annotations

import argparse
import json
import shutil
import signal
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import ExitStack, contextmanager
from pathlib import Path
from types import FrameType
from typing import Any, NoReturn

from numba.core import event as numba_event

from gmuk import runs, scenarios
from gmuk._locks import folder_lock
from gmuk.engine.integrate import compile_loop, versions
from gmuk.errors import GmukError
from gmuk.runs import RunControl
from gmuk.scenarios import OptionError, Scenario
from gmuk.trajectory import write_text_atomic

__all__ = ["main"]

DEFAULT_SCENARIO = "fcei"
FORMATS = ("png", "pdf", "svg")


class _Parser(argparse.ArgumentParser):
    """argparse's parser, whose errors are OptionErrors (main reports them and returns 2)
    instead of a SystemExit; --help still exits 0."""

    def error(self, message: str) -> NoReturn:
        raise OptionError(f"{self.prog}: {message}")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="gmuk", description="List and run the scenarios; check gmuk against Pinocchio."
    )
    p.add_argument(
        "--version",
        action="version",
        version=_version_line(),
        help="print gmuk's version (and numba's, numpy's) and exit",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.add_parser("list", help="list the scenarios with one-line descriptions")
    sub.add_parser("plugins", help="list the installed force models (gmuk's and plugins')")
    sub.add_parser(
        "run",
        help="run a scenario and write its data and figures; 'gmuk run NAME --help' lists "
        "its options",
        add_help=False,
    )
    check = sub.add_parser(
        "check",
        help="cross-check gmuk's SE(3) operators and dynamics against Pinocchio",
        description="Compare gmuk's Lie-group operators and rigid-body dynamics with "
        "Pinocchio on seeded random inputs; exit status 1 if any quantity fails.",
    )
    check.add_argument("--seed", type=int, default=0, help="seed of the inputs (default 0)")
    check.add_argument(
        "--samples", type=int, default=1000, help="samples per quantity (default 1000)"
    )
    check.add_argument("--verbose", action="store_true", help="print each row as computed")
    sub.add_parser(
        "compile",
        help="compile the step loop now (once per machine, 20-40 s; the first run compiles it "
        "otherwise, and says so)",
    )
    _add_view_parser(sub)
    # issue #16: campaigns (gmuk.campaign._cli parses their arguments)
    sub.add_parser(
        "campaign",
        help="Monte Carlo dispersions and sweeps of a scenario, resumable; 'gmuk campaign "
        "--help' for its flags",
        add_help=False,
    )
    return p


def _version_line() -> str:
    """``gmuk --version``'s line: gmuk's version and the libraries' that compute a run."""
    v = versions()
    return f"gmuk {v['gmuk']} (numba {v['numba']}, numpy {v['numpy']})"


def _plugins_table() -> list[str]:
    """``gmuk plugins``' lines: a header, then one row per installed force model, each column
    as wide as its longest entry (so a long name never pushes the next column out of line)."""
    from gmuk.forces import registry

    header = ("NAME", "SOURCE", "CLASS")
    rows = [(i.name, i.source, i.target) for i in registry.available()]
    widths = [max(len(row[k]) for row in [header, *rows]) for k in range(2)]
    return [f"{a:<{widths[0]}}  {b:<{widths[1]}}  {c}" for a, b, c in [header, *rows]]


def _run_parser(scenario: Scenario) -> argparse.ArgumentParser:
    """``gmuk run NAME``'s parser: the common flags, then the scenario's declared options."""
    names = ", ".join(s.name for s, _ in scenarios.available())
    p = _Parser(
        prog=f"gmuk run {scenario.name}",
        description=scenario.description,
        allow_abbrev=False,
        epilog=f"Scenarios: {names} ('gmuk list'). Without NAME, 'gmuk run' runs "
        f"{DEFAULT_SCENARIO}.",
    )
    common = p.add_argument_group("output")
    common.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="DIR",
        help=f"output folder (default: ./gmuk-out/{scenario.name})",
    )
    common.add_argument("--no-plots", action="store_true", help="write data only")
    common.add_argument(
        "--csv",
        action="store_true",
        help="also write the primary run as DIR/trajectory.csv (gmuk.Trajectory.to_csv: t, "
        "then each body's position, 3-2-1 Euler angles and body-frame twist, SI units)",
    )
    common.add_argument(
        "--checkpoint-every",
        type=scenarios.non_negative_float,
        default=60.0,
        metavar="SECONDS",
        help="write a checkpoint of each simulation this often (wall time, s) into "
        "DIR/.checkpoints, so that a killed run loses at most one interval; 0: only when a "
        "simulation stops or ends (default: 60)",
    )
    common.add_argument(
        "--resume",
        type=Path,
        default=None,
        metavar="DIR",
        help="continue the run stopped or killed in DIR, with the options it was started with",
    )
    common.add_argument(
        "--stop-at",
        type=scenarios.non_negative_float,
        default=None,
        metavar="T",
        help="end each simulation at the time T (s) with a terminal event (gmuk.Event); its "
        "status is then 'terminated' (kept by --resume)",
    )
    common.add_argument(
        "--format",
        default="png",
        metavar="FMT[,FMT]",
        help=f"figure formats, comma-separated, of {', '.join(FORMATS)} (default: png)",
    )
    own = p.add_argument_group(f"{scenario.name} options")
    for option in scenario.options:
        own.add_argument(
            option.flag,
            dest=f"option:{option.name}",
            default=None,
            metavar="{" + ",".join(map(str, option.choices)) + "}"
            if option.choices
            else option.name.upper(),
            help=option.help_text.replace("%", "%%"),
        )
    return p


#: A phase of ``gmuk run`` that lasts longer than this (s) says on stderr what it is doing.
ANNOUNCE_AFTER_S = 2.0


class _Phases:
    """The wall time of each phase of one ``gmuk run`` (``times``, s, in the order run), and
    a line on stderr for any phase that lasts longer than :data:`ANNOUNCE_AFTER_S`: what it is
    doing when that time has passed, and how long it took when it ends."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.times: dict[str, float] = {}

    @contextmanager
    def phase(self, key: str, doing: str | None) -> Iterator[None]:
        """Time the block as phase ``key``; ``doing`` (None: the block announces itself) is
        what the line on stderr says."""
        start = time.perf_counter()
        announced = threading.Event()

        def announce() -> None:
            announced.set()
            print(f"gmuk: {self.name}: {doing} ...", file=sys.stderr, flush=True)

        timer = threading.Timer(ANNOUNCE_AFTER_S, announce)
        timer.daemon = True
        if doing is not None:
            timer.start()
        try:
            yield
        finally:
            timer.cancel()
            elapsed = time.perf_counter() - start
            self.times[key] = self.times.get(key, 0.0) + elapsed
            if announced.is_set():
                print(f"gmuk: {self.name}: {doing}: {elapsed:.1f} s", file=sys.stderr, flush=True)

    def split(self, key: str, part: str, seconds: float) -> None:
        """Count ``seconds`` of phase ``key`` as phase ``part`` instead, listed before it."""
        seconds = min(seconds, self.times[key])
        order = list(self.times)
        self.times = {
            **{k: self.times[k] for k in order[: order.index(key)]},
            part: self.times.get(part, 0.0) + seconds,
            **{
                k: self.times[k] - (seconds if k == key else 0.0) for k in order[order.index(key) :]
            },
        }

    def summary(self) -> dict[str, float]:
        """``summary.json``'s ``time_s``: each phase's wall time and their total (s)."""
        return {
            **{k: round(v, 3) for k, v in self.times.items()},
            "total": round(sum(self.times.values()), 3),
        }


#: Exit status of a run stopped by a signal: 128 + the signal's number, as shells report it.
EXIT_STATUS = {signal.SIGINT: 130, signal.SIGTERM: 143}
#: Exit status of a ``gmuk run`` that completed with a constraint drifted past its tolerance
#: (status "drifted": the files are written, the results are not on their constraint).
EXIT_DRIFTED = 3


@contextmanager
def _stopping_signals(control: RunControl) -> Iterator[list[int]]:
    """SIGINT and SIGTERM ask the run to stop (:meth:`gmuk.runs.RunControl.request_stop`):
    the simulation running stops at its next step and returns the trajectory so far, later
    ones return at once, and the scenario finishes with what it has. Yields the list of the
    signals received (main thread only; elsewhere the handlers cannot be set and the list
    stays empty)."""
    received: list[int] = []

    def stop(signum: int, frame: FrameType | None) -> None:
        received.append(signum)
        control.request_stop()

    if threading.current_thread() is not threading.main_thread():
        yield received
        return
    previous = {sig: signal.signal(sig, stop) for sig in EXIT_STATUS}
    try:
        yield received
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


#: Where ``gmuk run`` keeps the checkpoints of a run, inside its output folder.
CHECKPOINTS = ".checkpoints"


def _resumed(
    args: argparse.Namespace, scenario: Scenario, name_given: bool, given: dict[str, str]
) -> tuple[Scenario, dict[str, Any], Path]:
    """The scenario, options and output folder of the run to resume from ``--resume DIR``."""
    out: Path = args.resume
    record_path = out / CHECKPOINTS / "run.json"
    try:
        record = json.loads(record_path.read_text())
        name, shown = record["scenario"], dict(record["options"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise OptionError(
            f"--resume {str(out)!r}: no run to resume there ({record_path} is missing or "
            f"unreadable: {type(exc).__name__})"
        ) from None
    if name_given and name != scenario.name:
        raise OptionError(f"--resume {str(out)!r} holds a {name!r} run, not {scenario.name!r}")
    if given or args.out is not None:
        raise OptionError(
            "--resume takes the options and the output folder of the run it continues; "
            "give no other scenario option or --out"
        )
    if args.stop_at is not None:
        raise OptionError(
            "--resume takes the --stop-at of the run it continues (from its run.json); give "
            "no --stop-at"
        )
    stop_at = record.get("stop_at")
    if stop_at is not None and not (isinstance(stop_at, (int, float)) and stop_at >= 0):
        raise OptionError(f"--resume {str(out)!r}: {record_path} has a bad stop_at {stop_at!r}")
    args.stop_at = stop_at
    resumed = scenarios.get(name)
    return resumed, resumed.parse_options(shown), out


def _run(argv: Sequence[str]) -> int:
    argv = list(argv)
    name_given = bool(argv) and not argv[0].startswith("-")
    name = argv.pop(0) if name_given else DEFAULT_SCENARIO
    scenario = scenarios.get(name)
    args, unknown = _run_parser(scenario).parse_known_args(argv)
    if unknown:
        flags = ", ".join(o.flag for o in scenario.options) or "none"
        raise OptionError(
            f"scenario {scenario.name!r} does not take {' '.join(unknown)}; its options: "
            f"{flags} (gmuk run {scenario.name} --help)"
        )
    formats = tuple(f.strip().lower() for f in args.format.split(",") if f.strip())
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise OptionError(
            f"--format takes {', '.join(FORMATS)} (comma-separated); got {args.format!r}"
        )
    given = {
        key.partition(":")[2]: value
        for key, value in vars(args).items()
        if key.startswith("option:") and value is not None
    }
    with ExitStack() as owned:
        # One run at a time in a folder (gmuk._locks): a second one is refused before it
        # touches anything, and the lock dies with its process.
        if args.resume is not None:
            if args.resume.is_dir():
                owned.enter_context(
                    folder_lock(
                        args.resume,
                        "gmuk run --resume",
                        hint="a run is being written or resumed there; wait for it to end",
                    )
                )
            scenario, options, out = _resumed(args, scenario, name_given, given)
        else:
            options = scenario.parse_options(given)
            out = args.out or Path("gmuk-out") / scenario.name
            try:
                out.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise OptionError(
                    f"--out {str(out)!r}: cannot make the output folder: {exc}"
                ) from None
            owned.enter_context(
                folder_lock(
                    out,
                    f"gmuk run {scenario.name}",
                    hint="wait for that run to end, or give another --out",
                )
            )
        return _run_owned(args, scenario, options, out, formats)


def _run_owned(
    args: argparse.Namespace,
    scenario: Scenario,
    options: dict[str, Any],
    out: Path,
    formats: tuple[str, ...],
) -> int:
    """``gmuk run``'s work in ``out``, whose lock the caller holds."""
    folder = out / CHECKPOINTS
    every = args.checkpoint_every if args.checkpoint_every > 0 else float("inf")
    if args.resume is None:
        shutil.rmtree(folder, ignore_errors=True)  # a new run: no stale checkpoints
        folder.mkdir()
        texts = {o.name: o.show(options[o.name]) for o in scenario.options}
        record = {"scenario": scenario.name, "options": texts}
        if args.stop_at is not None:
            record["stop_at"] = args.stop_at
        write_text_atomic(folder / "run.json", json.dumps(record, indent=2) + "\n")
    shown = ", ".join(f"{o.name}={o.show(options[o.name])}" for o in scenario.options)
    phases = _Phases(scenario.name)
    with phases.phase("loop", None):  # the step loop, loaded from numba's cache or compiled
        compile_loop()  # (once per machine, announced on stderr by compile_loop itself)
    events = [] if args.stop_at is None else [_stop_at(args.stop_at)]
    resume = args.resume is not None
    with runs.run_control(folder, every_s=every, resume=resume, events=events) as control:
        with _stopping_signals(control) as received:
            with phases.phase("simulation", f"simulating{f' ({shown})' if shown else ''}"):
                # the parts' kernels compile on first use (once per machine): timed apart
                jit = numba_event.TimingListener()
                with numba_event.install_listener("numba:compile", jit):
                    result = scenario.run(**options)
    phases.split("simulation", "compile", jit.duration if jit.done else 0.0)
    elapsed = phases.times["simulation"]
    primary = result.trajectories[result.primary]
    ended = ("success", "drifted", "terminated")
    stopped = [k for k, v in result.trajectories.items() if v.status not in ended]
    # completed runs whose constraint drifted past simulate's drift_tol
    drifted = [k for k, v in result.trajectories.items() if v.status == "drifted"]
    with phases.phase("save", "writing trajectory.npz"):
        path = primary.save(out / "trajectory.npz")
    status = primary.status
    if status in ("success", "terminated"):
        status = "partial" if stopped else "drifted" if drifted else status
    summary = {
        "scenario": result.name,
        "status": status,
        "message": primary.message,
        "t_reached_s": float(primary.t[-1]) if len(primary.t) else None,
        **({"signal": signal.Signals(received[0]).name} if received else {}),
        **({"runs_not_completed": stopped} if stopped else {}),
        "drifted": bool(drifted),
        **({"runs_drifted": drifted} if drifted else {}),
        "constraint_violation": {
            k: v.stats["constraint_violation"]
            for k, v in result.trajectories.items()
            if "constraint_violation" in v.stats
        },
        **({"events": events_found} if (events_found := _events(result)) else {}),
        "options": {k: list(v) if isinstance(v, tuple) else v for k, v in options.items()},
        **({"orbits": options["orbits"]} if "orbits" in options else {}),
        "wall_time_s": elapsed,  # the simulation phase, as time_s["simulation"]
        "time_s": phases.summary(),
        # what computed it: the same inputs give the same bits under the same versions
        "versions": primary.stats.get("versions") or versions(),
        **result.summary,
    }
    write_text_atomic(out / "summary.json", json.dumps(summary, indent=2, default=str) + "\n")
    if received:
        print(
            f"{result.name}: stopped by {signal.Signals(received[0]).name} at "
            f"t = {summary['t_reached_s']:.6g} s; wrote {path} and {out / 'summary.json'}; "
            f"continue with: gmuk run --resume {out}",
            file=sys.stderr,
        )
        return EXIT_STATUS[signal.Signals(received[0])]
    if not stopped:
        shutil.rmtree(folder, ignore_errors=True)  # complete: the checkpoints are spent
    with _stopping_signals(control) as received:  # a signal now ends the run after this step
        extra: list[Path] = []
        if scenario.write_data is not None:
            with phases.phase("data", "writing the scenario's data files"):
                extra = scenario.write_data(result, out)
        if args.csv and not received:
            with phases.phase("csv", "writing trajectory.csv"):
                extra.append(primary.to_csv(out / "trajectory.csv"))
        figures: list[Path] = []
        if not (args.no_plots or received):
            with phases.phase("figures", "drawing the figures"):
                figures = scenario.figures(result, out, formats)
        if not (args.no_plots or received):
            with phases.phase("view", "writing the 3-D view"):
                figures.append(_write_run_view(primary, out, scenario))
    summary["time_s"] = phases.summary()  # now with the files' phases
    write_text_atomic(out / "summary.json", json.dumps(summary, indent=2, default=str) + "\n")
    if received:
        print(
            f"{result.name}: stopped by {signal.Signals(received[0]).name} after the run "
            f"completed; wrote {path}, {out / 'summary.json'} and {len(figures)} figure "
            "file(s); the figures may be incomplete (gmuk run … --resume is not needed: "
            "run again to make them)",
            file=sys.stderr,
        )
        return EXIT_STATUS[signal.Signals(received[0])]
    spent = ", ".join(f"{k} {v:.2f}" for k, v in phases.times.items() if k != "simulation")
    print(
        f"{result.name}{f' ({shown})' if shown else ''}: {elapsed:.2f} s, status {status} "
        f"(and {spent} s)"
    )
    print("\n".join(_summary_lines(result.summary)))
    for key, check in summary["constraint_violation"].items():
        worst = ", ".join(
            f"{level} {check[level]:.3g}"
            for level in ("position", "velocity")
            if check[level] is not None
        )
        tol = "not judged" if check["tolerance"] is None else f"drift_tol {check['tolerance']:g}"
        print(f"  constraint violation ({key}): {worst or 'none stated'} ({tol})")
    data = f", {len(extra)} further data file(s)" if extra else ""
    print(f"wrote {path}, {out / 'summary.json'}{data} and {len(figures)} figure file(s) in {out}")
    if drifted:
        for k in drifted:
            print(f"{result.name}: run {k!r}: {result.trajectories[k].message}", file=sys.stderr)
        return EXIT_DRIFTED
    return 0


def _stop_at(t_stop: float) -> Any:
    """``--stop-at``'s terminal event: ``t − t_stop`` rising through zero."""
    from gmuk.engine.events import Event

    return Event(lambda t, state: t - t_stop, terminal=True, direction=1, name="stop_at")


def _events(result: Any) -> dict[str, list[dict[str, Any]]]:
    """``summary.json``'s ``events``: each run's located events (name, t, direction,
    terminal), for the runs that located any."""
    return {
        key: [e.to_dict() for e in traj.events]
        for key, traj in result.trajectories.items()
        if traj.events
    }


def _cell(value: Any) -> str:
    """One value of a run's summary as printed: floats to 6 significant digits, a list of
    records as its length (summary.json has them whole)."""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return f"[{len(value)} records: summary.json]"
    return str(value)


def _summary_lines(summary: dict[str, Any]) -> list[str]:
    """The scenario's summary as printed by ``gmuk run``: ``key: value`` lines, then the
    entries that are themselves mappings (e.g. one per case) as one table, a column each."""
    lines = [f"  {k}: {_cell(v)}" for k, v in summary.items() if not isinstance(v, dict)]
    groups = {k: v for k, v in summary.items() if isinstance(v, dict)}
    if groups:
        rows = list(dict.fromkeys(key for group in groups.values() for key in group))
        cells = [[_cell(group.get(row, "")) for group in groups.values()] for row in rows]
        first = max(len(r) for r in rows)
        widths = [max(len(str(name)), *(len(c[j]) for c in cells)) for j, name in enumerate(groups)]
        head = "  ".join(f"{n!s:>{w}}" for n, w in zip(groups, widths, strict=True))
        lines.append(f"  {'':<{first}}  {head}")
        for row, values in zip(rows, cells, strict=True):
            body = "  ".join(f"{c:>{w}}" for c, w in zip(values, widths, strict=True))
            lines.append(f"  {row:<{first}}  {body}")
    return lines


def _check(args: argparse.Namespace) -> int:
    from gmuk.crosscheck import check

    report = check(seed=args.seed, n=args.samples, verbose=args.verbose)
    print(report)
    return 0 if report.ok else 1


# --- gmuk view ----------------------------------------------------------------------------------


def _add_view_parser(sub: Any) -> None:
    view = sub.add_parser(
        "view",
        help="write an interactive 3-D view of a run (one HTML file that opens offline)",
        description="Write a self-contained HTML page showing the central body, each body's "
        "path in N and its axes triad moving along it (time slider and play button). It "
        "makes no network request: open it from disk in any browser.",
    )
    view.add_argument(
        "path", type=Path, metavar="RUN_DIR_or_FILE.npz", help="a gmuk run folder or a .npz"
    )
    view.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="FILE.html",
        help="output file, or an existing folder to write view.html into (default: "
        "RUN_DIR/view.html, or FILE.html beside FILE.npz)",
    )
    view.add_argument(
        "--central-radius",
        type=scenarios.positive_float,
        default=None,
        metavar="M",
        help="radius of the central body sphere (m); default: the run's scenario's (from "
        "RUN_DIR/summary.json), none for a bare .npz",
    )
    view.add_argument(
        "--max-frames",
        type=int,
        default=150,
        metavar="N",
        help="most animation frames; longer runs are decimated (default: 150)",
    )
    view.add_argument(
        "--link-radius",
        type=scenarios.positive_float,
        default=None,
        metavar="M",
        help="radius of the capsules drawn as a jointed run's links (m); default: a "
        "fraction of the robot's reach",
    )


def _scenario_radius(name: object) -> float | None:
    """The central radius (m) of the scenario called ``name``, None if unknown."""
    try:
        return scenarios.get(str(name)).central_radius
    except GmukError:
        return None


def _view(args: argparse.Namespace) -> int:
    from gmuk.trajectory import load_trajectory
    from gmuk.view import JOINT_FRAMES_KEY, write_view

    path: Path = args.path
    summary = path / "summary.json" if path.is_dir() else path.with_name("summary.json")
    npz = path / "trajectory.npz" if path.is_dir() else path
    if not npz.is_file():
        raise OptionError(
            f"gmuk view: expected a gmuk run folder (holding trajectory.npz) or a .npz file; "
            f"got {str(path)!r} ({'no trajectory.npz in it' if path.is_dir() else 'no file'})"
        )
    if args.max_frames < 2:
        raise OptionError(f"gmuk view: --max-frames must be an integer ≥ 2; got {args.max_frames}")
    name = None
    if path.is_dir() and summary.is_file():
        try:
            name = json.loads(summary.read_text()).get("scenario")
        except (OSError, ValueError, AttributeError, RecursionError):
            name = None
        if not isinstance(name, str):
            name = None  # a hand-edited summary: no scenario, no sphere
    radius = args.central_radius
    if radius is None and name is not None:
        radius = _scenario_radius(name)
    out: Path = args.out or (path / "view.html" if path.is_dir() else npz.with_suffix(".html"))
    if out.is_dir():  # like cp FILE DIR: the view goes inside the folder
        out = out / "view.html"
        if out.is_dir():
            raise OptionError(
                f"gmuk view: --out {str(args.out)!r} is a folder holding a folder named "
                "view.html; give the .html file to write"
            )
    traj = load_trajectory(npz)
    if args.link_radius is not None and not traj.stats.get(JOINT_FRAMES_KEY):
        raise OptionError(
            f"gmuk view: --link-radius sets the radius of a jointed run's links, and "
            f"{str(npz)!r} records no joints (a run of gmuk.robots joints does)"
        )
    try:
        written = write_view(
            traj,
            out,
            central_radius=radius,
            title=f"gmuk: {name}" if name else f"gmuk: {npz.name}",
            max_frames=args.max_frames,
            link_radius=args.link_radius,
        )
    except OSError as exc:
        raise OptionError(
            f"gmuk view: cannot write {str(out)!r}: {exc.strerror or exc} (--out takes an "
            "HTML file name or an existing folder)"
        ) from None
    print(f"wrote {written} (open it in a browser; it needs no network)")
    return 0


def _write_run_view(primary: Any, out: Path, scenario: Scenario) -> Path:
    """``gmuk run``'s ``view.html`` of the primary run."""
    from gmuk.view import write_view

    return write_view(
        primary,
        out / "view.html",
        central_radius=scenario.central_radius,
        title=f"gmuk run {scenario.name}",
        library=out.resolve().parent,  # one plotly.js beside the run folders, shared
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gmuk`` console script; returns the exit status (0 success, 1
    ``gmuk check`` found a disagreement, 2 bad input, 3 a run's constraint drifted)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        if argv[:1] == ["run"]:
            return _run(argv[1:])
        if argv[:1] == ["campaign"]:  # issue #16: gmuk campaign (see gmuk.campaign._cli)
            from gmuk.campaign._cli import main as campaign_main

            return campaign_main(argv[1:])
        args = _parser().parse_args(argv)
        if args.command == "list":
            found = scenarios.available()
            width = max([8, *(len(scenario.name) for scenario, _ in found)])
            for scenario, source in found:
                origin = "" if source == "gmuk" else f" [plugin: {source}]"
                print(f"{scenario.name:<{width}} {scenario.description}{origin}")
            return 0
        if args.command == "check":
            return _check(args)
        if args.command == "view":
            return _view(args)
        if args.command == "compile":
            import time

            from gmuk.engine.integrators import _compiled

            start = time.perf_counter()
            was = _compiled.loaded()
            _compiled.compile_loop(announce=False)
            done = "was already compiled" if was else "compiled"
            print(f"the step loop {done} ({time.perf_counter() - start:.1f} s)")
            return 0
        if args.command == "plugins":
            print("\n".join(_plugins_table()))
            return 0
        _parser().print_help()
        return 2
    except GmukError as exc:
        print(f"gmuk: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # a signal outside the integration: nothing was computed yet
        print("gmuk: interrupted", file=sys.stderr)
        return EXIT_STATUS[signal.SIGINT]
    except SystemExit as exc:  # --help or -h (of gmuk or a subcommand): printed, status 0
        return exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 2


if __name__ == "__main__":
    sys.exit(main())
