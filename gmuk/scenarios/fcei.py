"""FCEI: fully constrained, elliptical, inclined lunar orbit on R⁶ (McCann 2020, §4.3.1.2).

a = 4000 km, e = 0.2, i = 35°, Ω = ω = 0; the spacecraft is held in the modified-LVLH
attitude (axis 1 at the Moon, axis 3 along the orbit normal) by Eq. 67 rows, A = I₆.

Beyond the thesis, the rows carry critical Baumgarte terms at ω_n = 1e-3 s⁻¹
(:data:`gmuk.scenarios._lvlh.TRACKING_BAUMGARTE`, whose comment justifies the gains from the
orbit's time scales): unstabilised, the attitude error grows from round-off by e^{2.8} per
orbit and ``--orbits 12`` ended π rad off the reference. With them, 12 orbits end on it (7.1e-14
rad, 2.7e-7 m at most; docs/scenarios/chapter4.rst, "Stabilisation").
"""

from __future__ import annotations

from pathlib import Path

from gmuk.orbits import fcei_orbit
from gmuk.scenarios import Scenario, ScenarioResult
from gmuk.scenarios import _lvlh as common

NAME = "fcei"
DESCRIPTION = "fully constrained LVLH tracking, a = 4000 km, e = 0.2, i = 35° (Eq. 67, R⁶)"


def run(orbits: float = 1.0) -> ScenarioResult:
    """Simulate ``orbits`` orbits from periselene."""
    orbit = fcei_orbit(common.MU)
    traj = common.fully_constrained(orbit, orbits)
    return ScenarioResult(NAME, {NAME: traj}, NAME, common.fully_constrained_summary(traj, orbit))


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
