"""Tutorial 5: your own scenario, run from the command line.

A scenario is a ``gmuk.scenarios.Scenario``: a name, a one-line description, the options it
takes (each a ``gmuk.scenarios.Option``, which becomes a flag with help text), a
``run(**options)`` returning a ``ScenarioResult`` and a ``figures(result, out, formats)``.
``plugins/gmuk-tutorial/gmuk_tutorial/tennis_racket.py`` defines one — a torque-free body
spun about its intermediate axis, which flips over — and the package's ``pyproject.toml``
registers it::

    [project.entry-points."gmuk.scenarios"]
    tennis-racket = "gmuk_tutorial.tennis_racket:SCENARIO"

Once the package is installed, ``gmuk list`` shows it, ``gmuk run tennis-racket --help``
lists its options and ``gmuk run tennis-racket --duration 60`` runs it like any thesis
scenario: trajectory.npz, summary.json, its figure and the 3-D view.html. This script does
exactly that, into ``gmuk-out/tennis-racket`` in the current folder (``gmuk run``'s own
default; ``--out DIR`` for another), reads the summary back, and prints where the run is, so
that you can open its view.html and figure afterwards.

Run: python examples/tutorials/t5_own_scenario.py [--quick] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path


def gmuk(*args: str) -> str:
    """Run the ``gmuk`` command (as ``python -m gmuk.cli``) and return what it printed."""
    done = subprocess.run([sys.executable, "-m", "gmuk.cli", *args], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"gmuk {' '.join(args)} failed ({done.returncode}): {done.stderr}")
    return done.stdout


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a short run (for the tests)")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("gmuk-out") / "tennis-racket",
        help="output folder (default: gmuk-out/tennis-racket in the current folder)",
    )
    args = parser.parse_args(argv)
    duration = "30" if args.quick else "120"

    listed = [line for line in gmuk("list").splitlines() if line.startswith("tennis-racket")]
    if not listed:
        sys.exit("tennis-racket is not installed: pip install -e plugins/gmuk-tutorial")
    print(listed[0])
    out = args.out
    print(gmuk("run", "tennis-racket", "--duration", duration, "--out", str(out)))
    summary = json.loads((out / "summary.json").read_text())
    files = sorted(p.name for p in out.iterdir())
    result = {
        "flips": float(summary["flips"]),
        "energy_drift": float(summary["energy_drift"]),
        "momentum_drift": float(summary["momentum_drift"]),
        "duration_s": float(summary["options"]["duration"]),
        "wrote_figure_and_view": float({"body_rates.png", "view.html"} <= set(files)),
    }
    for k, v in result.items():
        print(f"{k:>22}: {v:.3g}")
    print(f"\nThe run is in {out.resolve()}: {', '.join(files)}")
    print(f"Open {(out / 'view.html').resolve()} in a browser to watch the body flip.")
    return result


if __name__ == "__main__":
    main()
