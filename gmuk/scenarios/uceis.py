"""UCEIS: UCEI with the applied torque L_s = [0.005 sin f, 0, 0] N·m on the spacecraft
(f the true anomaly), compared with FCEI (McCann 2020, §4.3.2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gmuk.orbits import fcei_orbit
from gmuk.scenarios import Scenario, ScenarioResult
from gmuk.scenarios import _lvlh as common
from gmuk.scenarios.ucei import pair_summary

NAME = "uceis"
DESCRIPTION = "UCEI plus the roll torque 0.005 sin f N·m: roll responds, the orbit does not"
TORQUE_AMPLITUDE = 0.005  # N·m


def run(orbits: float = 1.0) -> ScenarioResult:
    """Simulate the torqued pair and FCEI over ``orbits`` orbits."""
    orbit = fcei_orbit(common.MU)

    def torque(t: float) -> np.ndarray:
        f = float(orbit.true_anomaly(t))
        return np.array([TORQUE_AMPLITUDE * np.sin(f), 0.0, 0.0, 0.0, 0.0, 0.0])

    pair = common.virtual_pair(orbit, orbits, torque=torque)
    fcei = common.fully_constrained(orbit, orbits)
    return ScenarioResult(NAME, {NAME: pair, "fcei": fcei}, NAME, pair_summary(pair, fcei, orbit))


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """The spacecraft's figure groups and UCEIS against FCEI (overlaid)."""
    return common.figures_for(result, out, formats, [(NAME, "fcei", False)])


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(common.ORBITS,),
    central_radius=common.CENTRAL_RADIUS,
)
