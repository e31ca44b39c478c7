"""FCCN: fully constrained, circular, non-inclined lunar orbit (McCann 2020, §4.3.1.1).

a = 4000 km, e = 0, i = 0. On a circular orbit the constraint wrench is constant.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gmuk.orbits import fccn_orbit
from gmuk.scenarios import Scenario, ScenarioResult
from gmuk.scenarios import _lvlh as common

NAME = "fccn"
DESCRIPTION = "fully constrained LVLH tracking on a circular equatorial orbit, a = 4000 km"


def run(orbits: float = 1.0) -> ScenarioResult:
    """Simulate ``orbits`` orbits."""
    orbit = fccn_orbit(common.MU)
    traj = common.fully_constrained(orbit, orbits)
    summary = common.fully_constrained_summary(traj, orbit)
    torque = traj.body("spacecraft").constraint_force[:, :3]
    summary["constraint_torque_relative_variation"] = float(
        np.ptp(torque, axis=0).max() / np.abs(torque).max()
    )
    # On the reference: the torque, relative to itself; the force (≈ 2e-10 N, the finite-size
    # term of Eq. 23b) is what is left of m·(b − a_free) after cancelling ≈ 2.2e3 N of
    # gravity, so its variation is compared with that gravity force (round-off: ~1e-16).
    nominal = common.nominal_constraint_wrench(orbit, traj.t)
    summary["nominal_constraint_torque_relative_variation"] = float(
        np.ptp(nominal[:, :3], axis=0).max() / np.abs(nominal[:, :3]).max()
    )
    force_variation = float(np.ptp(nominal[:, 3:], axis=0).max())
    gravity = common.spacecraft().mass * orbit.mu / orbit.a**2
    summary["nominal_constraint_force_variation_N"] = force_variation
    summary["nominal_constraint_force_variation_over_gravity"] = force_variation / gravity
    return ScenarioResult(NAME, {NAME: traj}, NAME, summary)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Position, velocity, Euler angles, body rates, constraint accelerations."""
    return common.figures_for(result, out, formats)


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(common.ORBITS,),
    central_radius=common.CENTRAL_RADIUS,
)
