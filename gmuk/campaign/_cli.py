"""``gmuk campaign``: run, resume and summarise campaigns from the command line::

    gmuk campaign SCENARIO --runs N [--seed S] [--workers W | --scheduler ADDR] --out DIR
                  [--set NAME=VALUE]… [--disperse NAME=SPEC]… [--sweep NAME=VALUES]…
                  [--save-trajectories] [--no-progress]
    gmuk campaign --resume DIR [--workers W | --scheduler ADDR]
    gmuk campaign --summary DIR [--format png,pdf]
    gmuk campaign SCENARIO --parameters

Dispersion specs (angles in degrees, other values in the parameter's SI unit):
``cone:DEG`` (attitude error uniform on SO(3) within DEG ≤ 180), ``ball:R`` (uniform in the
ball of radius R), ``normal3:S`` or ``normal3:S1,S2,S3`` (Gaussian 3-vector), ``uniform:LO,HI``,
``normal:MEAN,STD``, ``choice:A,B,…``, ``range:LO,HI`` (integers, inclusive),
``moments:LO,HI`` (second-moment scale factors). Sweep values: ``A,B,C`` or ``LO:HI[:STEP]``
(integers, inclusive). Without ``--disperse`` or ``--sweep`` the scenario's own dispersions or
sweep apply; ``--disperse``/``--set`` of a parameter replace its default dispersion.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from gmuk.campaign.core import MAX_RUNS
from gmuk.campaign.dispersions import (
    AttitudeCone,
    Choice,
    Dispersion,
    GaussianVector,
    IntegerRange,
    Normal,
    SecondMomentScale,
    Uniform,
    UniformBall,
)
from gmuk.scenarios import OptionError

__all__ = ["main", "parse_dispersion"]

#: Exit status of a campaign stopped by a signal (as ``gmuk run``'s).
EXIT_STATUS = {"SIGINT": 130, "SIGTERM": 143}


def _numbers(text: str, flag: str, count: int | None = None) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if not values or (count is not None and len(values) != count):
        need = f"{count} comma-separated numbers" if count else "comma-separated numbers"
        raise OptionError(f"{flag} needs {need}; got {text!r}")
    return values


def _integers(text: str, flag: str) -> list[int]:
    try:
        return [int(v) for v in text.split(",")]
    except ValueError:
        raise OptionError(f"{flag} needs comma-separated integers; got {text!r}") from None


def _split(text: str, flag: str) -> tuple[str, str]:
    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise OptionError(f"{flag} takes NAME=VALUE; got {text!r}")
    return name.strip(), value.strip()


def parse_dispersion(text: str) -> tuple[str, Dispersion]:
    """``NAME=KIND:ARGS`` → (name, dispersion); see the module docstring."""
    flag = "--disperse"
    name, spec = _split(text, flag)
    kind, _, args = spec.partition(":")
    kind = kind.strip().lower()
    where = f"{flag} {text!r}"
    if kind == "cone":
        (deg,) = _numbers(args, where, 1)
        return name, AttitudeCone(math.radians(deg))
    if kind == "ball":
        (radius,) = _numbers(args, where, 1)
        return name, UniformBall(radius)
    if kind == "normal3":
        return name, GaussianVector(tuple(_numbers(args, where)))
    if kind == "uniform":
        lo, hi = _numbers(args, where, 2)
        return name, Uniform(lo, hi)
    if kind == "normal":
        mean, std = _numbers(args, where, 2)
        return name, Normal(mean, std)
    if kind == "choice":
        try:
            return name, Choice(tuple(_integers(args, where)))
        except OptionError:
            return name, Choice(tuple(_numbers(args, where)))
    if kind == "range":
        bounds = _integers(args, where)
        if len(bounds) != 2:
            raise OptionError(f"{where}: range needs LO,HI (integers)")
        return name, IntegerRange(bounds[0], bounds[1])
    if kind == "moments":
        lo, hi = _numbers(args, where, 2)
        return name, SecondMomentScale(lo, hi)
    raise OptionError(
        f"{where}: unknown dispersion {kind!r}; use cone:DEG, ball:R, normal3:S, uniform:LO,HI, "
        "normal:MEAN,STD, choice:A,B,…, range:LO,HI or moments:LO,HI"
    )


def _sweep(text: str) -> tuple[str, list[Any]]:
    name, spec = _split(text, "--sweep")
    if ":" in spec:
        parts = spec.split(":")
        try:
            lo, hi, *step = (int(p) for p in parts)
        except ValueError:
            raise OptionError(f"--sweep {text!r}: LO:HI[:STEP] takes integers") from None
        if len(parts) > 3 or (step and step[0] < 1) or hi < lo:
            raise OptionError(f"--sweep {text!r}: need LO ≤ HI and STEP ≥ 1")
        values = range(lo, hi + 1, step[0] if step else 1)
        count = (hi - lo) // (step[0] if step else 1) + 1  # len(values), without overflow
        if count > MAX_RUNS:
            raise OptionError(
                f"--sweep {text!r}: {count:,} values; a campaign runs at most {MAX_RUNS:,} "
                "(gmuk.campaign.core.MAX_RUNS)"
            )
        return name, list(values)
    try:
        return name, _integers(spec, "--sweep")
    except OptionError:
        return name, list(_numbers(spec, f"--sweep {text!r}"))


def _value(model: Any, name: str, text: str) -> Any:
    kind = model.parameter(name).kind
    where = f"--set {name}={text}"
    if kind == "integer":
        return _integers(text, where)[0] if "," not in text else _integers(text, where)
    if kind == "real":
        return _numbers(text, where, 1)[0]
    return tuple(_numbers(text, where, 3))


def _parser() -> argparse.ArgumentParser:
    from gmuk.cli import _Parser

    p = _Parser(
        prog="gmuk campaign",
        description="Monte Carlo dispersions and parameter sweeps of a scenario, stored "
        "incrementally in DIR (resumable).\n\nDispersion specs"
        + __doc__.split("Dispersion specs", 1)[1].replace("``", "").replace("%", "%%"),
        allow_abbrev=False,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    from gmuk.campaign.models import supported

    p.add_argument("scenario", nargs="?", help=", ".join(supported()))
    p.add_argument(
        "--runs",
        type=int,
        default=None,
        help=f"number of runs, at most {MAX_RUNS:,} (default: the sweep's size)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the dispersions (default 0)")
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help=f"local worker processes; 1 runs serially (default: {os.cpu_count()}, the CPUs)",
    )
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDR",
        help="a Dask scheduler address (tcp://host:8786), or 'local' for a LocalCluster of "
        "--workers processes",
    )
    p.add_argument(
        "--connect-timeout",
        type=float,
        default=5.0,
        metavar="SECONDS",
        help="how long to wait for --scheduler ADDR to answer (default 5)",
    )
    p.add_argument("--out", type=Path, default=None, metavar="DIR", help="campaign folder")
    p.add_argument("--resume", type=Path, default=None, metavar="DIR", help="continue DIR")
    p.add_argument("--summary", type=Path, default=None, metavar="DIR", help="summarise DIR")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument("--disperse", action="append", default=[], metavar="NAME=SPEC")
    p.add_argument("--sweep", action="append", default=[], metavar="NAME=VALUES")
    p.add_argument("--save-trajectories", action="store_true", help="DIR/trajectories/run-K.npz")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--format", default="png", help="summary figure formats (default png)")
    p.add_argument("--parameters", action="store_true", help="list the scenario's parameters")
    return p


def _backend_args(args: argparse.Namespace) -> tuple[int, Any]:
    if not 0 < args.connect_timeout < math.inf:
        raise OptionError(f"--connect-timeout must be > 0; got {args.connect_timeout}")
    if args.workers is not None and args.workers < 1:
        raise OptionError(f"--workers must be ≥ 1; got {args.workers}")
    if args.scheduler is not None and args.scheduler != "local" and args.workers is not None:
        raise OptionError("give --workers or --scheduler ADDR, not both (--workers sizes 'local')")
    workers = args.workers if args.workers is not None else (os.cpu_count() or 1)
    return workers, args.scheduler


def _report(report: Any) -> int:
    failed = f", {report.failed} failed" if report.failed else ""
    print(
        f"{report.finished} of {report.runs} runs recorded{failed} in {report.out} "
        f"({report.computed} computed now on {report.backend}, {report.wall_time_s:.1f} s)"
    )
    if report.stopped_by:
        print(
            f"gmuk campaign: stopped by {report.stopped_by}; continue with: gmuk campaign "
            f"--resume {report.out}",
            file=sys.stderr,
        )
        return EXIT_STATUS.get(report.stopped_by, 130)
    return 0


def main(argv: Sequence[str]) -> int:
    """``gmuk campaign …``; returns the exit status (GmukErrors propagate to gmuk.cli)."""
    from gmuk.campaign.core import Campaign, resume
    from gmuk.campaign.models import get_model

    args = _parser().parse_args(list(argv))
    modes = [m for m in ("resume", "summary") if getattr(args, m) is not None]
    if len(modes) > 1 or (modes and args.scenario):
        raise OptionError("give a SCENARIO, --resume DIR or --summary DIR (one of them)")
    progress = False if args.no_progress else None
    if args.summary is not None:
        from gmuk.campaign.summary import summarize

        formats = tuple(f.strip() for f in args.format.split(",") if f.strip())
        summary = summarize(args.summary, formats=formats)
        print(summary.table())
        print(f"wrote {', '.join(str(f) for f in summary.files)}")
        return 0
    if args.resume is not None:
        if args.runs is not None or args.set or args.disperse or args.sweep or args.out:
            raise OptionError(
                "--resume takes the campaign's own definition; give only --workers or --scheduler"
            )
        workers, scheduler = _backend_args(args)
        return _report(
            resume(
                args.resume,
                workers=workers,
                scheduler=scheduler,
                progress=progress,
                connect_timeout_s=args.connect_timeout,
            )
        )
    if not args.scenario:
        raise OptionError(
            "give a SCENARIO (gmuk campaign fcei --runs 20 --out DIR), "
            "--resume DIR or --summary DIR"
        )
    model = get_model(args.scenario)
    if args.parameters:
        for prm in model.parameters:
            print(
                f"{prm.name:<24} {prm.kind:<9} default {prm.default!r:<28} {prm.help}; "
                f"{prm.domain()}"
            )
        return 0
    if args.out is None:
        raise OptionError("--out DIR is required (the campaign folder)")
    fixed = {
        name: _value(model, name, value)
        for name, value in map(lambda t: _split(t, "--set"), args.set)
    }
    dispersions = dict(model.default_dispersions)
    given = dict(parse_dispersion(t) for t in args.disperse)
    for name in [*fixed, *given]:
        model.parameter(name)
        dispersions.pop(name, None)
    dispersions |= given
    grid: dict[str, Sequence[Any]] | None = None
    if args.sweep:
        grid = dict(_sweep(t) for t in args.sweep)
        for name in grid:
            model.parameter(name)
            dispersions.pop(name, None)
            if name in fixed:
                raise OptionError(f"--set and --sweep both give {name!r}")
    elif any(name in model.default_grid for name in [*fixed, *given]):
        grid = {k: v for k, v in model.default_grid.items() if k not in fixed and k not in given}
    if args.runs is None and not (model.default_grid if grid is None else grid):
        raise OptionError(f"--runs N is required: {model.name} has no sweep here to count runs")
    campaign = Campaign(
        model,
        runs=args.runs,
        seed=args.seed,
        dispersions=dispersions,
        fixed=fixed,
        grid=grid,
        save_trajectories=args.save_trajectories,
    )
    workers, scheduler = _backend_args(args)
    return _report(
        campaign.run(
            args.out,
            workers=workers,
            scheduler=scheduler,
            progress=progress,
            connect_timeout_s=args.connect_timeout,
        )
    )
