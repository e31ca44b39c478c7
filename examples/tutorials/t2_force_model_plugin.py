"""Tutorial 2: a force model in a package of its own, found by name once installed.

The package is ``plugins/gmuk-tutorial`` of this repository: ``gmuk_tutorial/drag.py``
defines ``LinearDrag`` (f = −c v, a ``gmuk.ForceModel`` subclass) and its ``pyproject.toml``
registers it under the entry-point group ``gmuk.force_models``::

    [project.entry-points."gmuk.force_models"]
    linear_drag = "gmuk_tutorial.drag:LinearDrag"

Install it (``pip install -e plugins/gmuk-tutorial``), and gmuk finds it: ``gmuk plugins``
lists it and ``gmuk.forces.registry.create("linear_drag", ...)`` builds it by name. This
script checks both, then flies a rigid body and a point mass through the drag and compares
their speed with v₀ exp(−c t / m).

Run: python examples/tutorials/t2_force_model_plugin.py [--quick]
"""

from __future__ import annotations

import argparse
import subprocess
import sys

import numpy as np

import gmuk
from gmuk.forces import registry


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a short run (for the tests)")
    args = parser.parse_args(argv)
    duration = 5.0 if args.quick else 50.0

    # 1. discovered: by the registry and by the command line
    info = {i.name: i for i in registry.available()}
    if "linear_drag" not in info:
        sys.exit("linear_drag is not installed: pip install -e plugins/gmuk-tutorial")
    listed = subprocess.run(
        [sys.executable, "-m", "gmuk.cli", "plugins"], capture_output=True, text=True, check=True
    ).stdout
    line = next(row for row in listed.splitlines() if row.startswith("linear_drag"))
    print(f"gmuk plugins: {line}")

    # 2. used by name
    c = 0.8  # N·s/m
    drag = registry.create("linear_drag", coefficient=c)
    box = gmuk.RigidBody("box", mass=4.0, inertia=np.diag([1.0, 2.0, 3.0]))  # kg, kg·m²
    ball = gmuk.PointMass("ball", mass=2.0)  # kg
    system = gmuk.System([box, ball], [], [drag])
    state = system.state(
        g={"box": np.eye(4)},
        V={"box": [0.0, 0.0, 0.3, 2.0, 0.0, 0.0]},  # spinning about axis 3, moving along 1
        r={"ball": [0.0, 0.0, 0.0]},
        v={"ball": [0.0, 1.5, 0.0]},
    )
    t = np.linspace(0.0, duration, 51)
    traj = system.simulate(state, (0.0, duration), t_eval=t, rtol=1e-11, atol=1e-12)
    speed_box = np.linalg.norm(traj.body("box").velocity, axis=1)
    speed_ball = np.linalg.norm(traj.body("ball").velocity, axis=1)
    result = {
        "source_is_the_plugin": float(info["linear_drag"].source == "gmuk-tutorial"),
        "listed_by_gmuk_plugins": float("gmuk-tutorial" in line),
        "box_speed_vs_exp": float(np.abs(speed_box - 2.0 * np.exp(-c * t / 4.0)).max()),
        "ball_speed_vs_exp": float(np.abs(speed_ball - 1.5 * np.exp(-c * t / 2.0)).max()),
        "box_spin_rad_s": float(traj.body("box").omega[-1, 2]),  # no torque: unchanged
    }
    for k, v in result.items():
        print(f"{k:>22}: {v:.3g}")
    return result


if __name__ == "__main__":
    main()
