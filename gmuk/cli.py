"""The ``gmuk`` command: list and run the thesis scenarios.

    gmuk list
    gmuk plugins
    gmuk run NAME [--orbits K] [--out DIR] [--no-plots] [--format png,pdf]
    gmuk run apollo16 [--field PATH] [--degrees 2,10] [--model correct|thesis|both]

``gmuk run`` writes ``DIR/trajectory.npz`` (loadable with :func:`gmuk.load_trajectory`),
``DIR/summary.json`` with the headline figures, the figures, and whatever further data the
scenario writes (its ``write_data(result, out_dir)``, if it has one). ``--field``,
``--degrees`` and ``--model`` go to scenarios whose ``run`` takes ``field_path``, ``degrees``
and ``model`` (apollo16); giving them to another scenario is an error.
"""

from __future__ import annotations

import argparse
import inspect
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType

from gmuk import scenarios
from gmuk.errors import GmukError

__all__ = ["main"]

DEFAULT_SCENARIO = "fcei"


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="gmuk", description="List and run the thesis scenarios.")
    sub = p.add_subparsers(dest="command")
    sub.add_parser("list", help="list the scenarios with one-line descriptions")
    sub.add_parser("plugins", help="list the installed force models (gmuk's and plugins')")
    run = sub.add_parser("run", help="run a scenario and write its data and figures")
    run.add_argument(
        "name",
        nargs="?",
        default=DEFAULT_SCENARIO,
        help=f"scenario name (default: {DEFAULT_SCENARIO}); see 'gmuk list'",
    )
    run.add_argument("--orbits", type=float, default=1.0, help="orbits to simulate (default 1)")
    run.add_argument(
        "--out", type=Path, default=None, help="output folder (default: ./gmuk-out/NAME)"
    )
    run.add_argument("--no-plots", action="store_true", help="write data only")
    run.add_argument(
        "--format",
        default="png",
        help="figure formats, comma-separated (default: png), e.g. png,pdf",
    )
    run.add_argument(
        "--field",
        type=Path,
        default=None,
        metavar="PATH",
        help="gravity-field file (ICGEM .gfc) for scenarios that take one (apollo16: "
        "degrees > 4 need it; default: $GMUK_GRAVITY_FIELD)",
    )
    run.add_argument(
        "--degrees",
        default=None,
        help="harmonic degrees, comma-separated, for scenarios that take them (apollo16)",
    )
    run.add_argument(
        "--model",
        choices=("correct", "thesis", "both"),
        default=None,
        help="gravity model(s) for scenarios that take one (apollo16; default both)",
    )
    return p


def _scenario_options(module: ModuleType, args: argparse.Namespace) -> dict[str, object]:
    """The scenario-specific options given on the command line, checked against ``run``."""
    given: dict[str, object] = {}
    if args.field is not None:
        given["field_path"] = args.field
    if args.degrees is not None:
        try:
            given["degrees"] = tuple(int(d) for d in args.degrees.split(",") if d.strip())
        except ValueError:
            raise GmukError(
                f"--degrees takes comma-separated integers, e.g. 2,10; got {args.degrees!r}"
            ) from None
    if args.model is not None:
        given["model"] = args.model
    params = inspect.signature(module.run).parameters
    flags = {"field_path": "--field", "degrees": "--degrees", "model": "--model"}
    unused = [flags[k] for k in given if k not in params]
    if unused:
        raise GmukError(f"scenario {args.name!r} does not take {', '.join(unused)}")
    return given


def _run(args: argparse.Namespace) -> int:
    module = scenarios.load(args.name)
    if not args.orbits > 0:
        raise GmukError(f"--orbits must be > 0; got {args.orbits}")
    formats = tuple(f.strip().lower() for f in args.format.split(",") if f.strip())
    bad = [f for f in formats if f not in ("png", "pdf", "svg")]
    if bad or not formats:
        raise GmukError(f"--format takes png, pdf or svg (comma-separated); got {args.format!r}")
    options = _scenario_options(module, args)
    out = args.out or Path("gmuk-out") / args.name.lower()
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    result = module.run(orbits=args.orbits, **options)
    elapsed = time.perf_counter() - t0
    path = result.trajectories[result.primary].save(out / "trajectory.npz")
    summary = {
        "scenario": result.name,
        "orbits": args.orbits,
        "wall_time_s": elapsed,
        **result.summary,
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2, default=float) + "\n")
    extra = module.write_data(result, out) if hasattr(module, "write_data") else []
    figures = [] if args.no_plots else module.figures(result, out, formats)
    print(f"{result.name}: {args.orbits:g} orbit(s) in {elapsed:.2f} s")
    for key, value in result.summary.items():
        print(f"  {key}: {value:.6g}" if isinstance(value, float) else f"  {key}: {value}")
    data = f", {len(extra)} further data file(s)" if extra else ""
    print(f"wrote {path}, {out / 'summary.json'}{data} and {len(figures)} figure file(s) in {out}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gmuk`` console script; returns the exit status."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "list":
            for name, text in scenarios.describe():
                print(f"{name:<8} {text}")
            return 0
        if args.command == "run":
            return _run(args)
        if args.command == "plugins":
            from gmuk.forces import registry

            for info in registry.available():
                print(f"{info.name:<22} {info.source:<16} {info.target}")
            return 0
        _parser().print_help()
        return 2
    except GmukError as exc:
        print(f"gmuk: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
