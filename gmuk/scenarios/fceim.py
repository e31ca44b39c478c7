"""FCEIM: FCEI solved on the double tangent bundle T²SE(3) (McCann 2020, §4.2, Eq. 80),
compared with FCEI on R⁶ (the thesis saw millimetre differences; both are the same
accelerations to round-off, so the difference is integration noise).

Stabilised as FCEI (beyond the thesis): the T² constraint's C carries critical Baumgarte
terms at ``_lvlh.TRACKING_BAUMGARTE`` on Φ = g − g_d (:class:`gmuk.ConfigurationTrackingT2`'s
``baumgarte``; A = B = I₄ unchanged). Unstabilised, ``gmuk run fceim --orbits 12`` ended π rad
off its reference (status "drifted"); docs/scenarios/chapter4.rst gives the figures."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gmuk.orbits import fcei_orbit
from gmuk.scenarios import Scenario, ScenarioResult
from gmuk.scenarios import _lvlh as common

NAME = "fceim"
DESCRIPTION = "FCEI on T²SE(3) (A g̈ B = C, Eq. 80), compared with FCEI on R⁶"


def run(orbits: float = 1.0) -> ScenarioResult:
    """Simulate both formulations over ``orbits`` orbits."""
    orbit = fcei_orbit(common.MU)
    t2 = common.fully_constrained(orbit, orbits, tangent=True)
    r6 = common.fully_constrained(orbit, orbits)
    summary = common.fully_constrained_summary(t2, orbit)
    a, b = t2.body("spacecraft"), r6.body("spacecraft")
    summary["max_position_difference_vs_fcei_m"] = float(
        np.linalg.norm(a.position - b.position, axis=1).max()
    )
    summary["max_velocity_difference_vs_fcei_m_s"] = float(
        np.linalg.norm(a.velocity - b.velocity, axis=1).max()
    )
    summary["t2_baumgarte_alpha_per_s"] = float(common.TRACKING_BAUMGARTE.alpha)
    summary["t2_baumgarte_beta_per_s2"] = float(common.TRACKING_BAUMGARTE.beta)
    return ScenarioResult(NAME, {NAME: t2, "fcei": r6}, NAME, summary)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """FCEIM's figure groups and FCEIM − FCEI."""
    return common.figures_for(result, out, formats, [(NAME, "fcei", True)])


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(common.ORBITS,),
    central_radius=common.CENTRAL_RADIUS,
)
