"""UCEI: under-constrained through the virtual-spacecraft pair (McCann 2020, §4.1.3).

Body "virtual" is fully constrained to the FCEI reference; body "spacecraft" is constrained
relative to it in five directions and free to rotate about its first axis.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gmuk.orbits import fcei_orbit
from gmuk.scenarios import Scenario, ScenarioResult
from gmuk.scenarios import _lvlh as common

NAME = "ucei"
DESCRIPTION = "virtual-spacecraft pair: spacecraft free about axis 1 relative to the LVLH body"


def pair_summary(pair: Any, fcei: Any, orbit: Any) -> dict[str, Any]:
    """Headline figures of a pair run against FCEI."""
    rel = common.relative_pose(pair)
    a, b = pair.body("spacecraft"), fcei.body("spacecraft")
    acc_a, acc_b = a.constraint_acceleration[:, 3:], b.constraint_acceleration[:, 3:]
    pos, _ = common.reference_errors(pair, orbit, "virtual")
    return {
        # the five locked components of log(g_L⁻¹ g_B), by unit: rotations about axes 2, 3
        # (rad) and the translation (m; its floor is the round-off of |r| ≈ 4e6 m)
        "max_locked_rotation_rad": float(np.abs(rel[:, 1:3]).max()),
        "max_locked_translation_m": float(np.abs(rel[:, 3:]).max()),
        "max_locked_translation_over_distance": float(
            np.abs(rel[:, 3:]).max() / np.linalg.norm(pair.body("virtual").position, axis=1).max()
        ),
        "max_abs_roll_rad": float(np.abs(rel[:, 0]).max()),
        "translational_constraint_accel_rel_diff_vs_fcei": float(
            np.abs(acc_a - acc_b).max() / np.abs(acc_b).max()
        ),
        "max_position_difference_vs_fcei_m": float(
            np.linalg.norm(a.position - b.position, axis=1).max()
        ),
        "max_velocity_difference_vs_fcei_m_s": float(
            np.linalg.norm(a.velocity - b.velocity, axis=1).max()
        ),
        "virtual_max_position_error_m": float(pos.max()),
        "rhs_evaluations": int(pair.stats["n_rhs"]),
    }


def run(orbits: float = 1.0) -> ScenarioResult:
    """Simulate the pair and FCEI over ``orbits`` orbits."""
    orbit = fcei_orbit(common.MU)
    pair = common.virtual_pair(orbit, orbits)
    fcei = common.fully_constrained(orbit, orbits)
    return ScenarioResult(NAME, {NAME: pair, "fcei": fcei}, NAME, pair_summary(pair, fcei, orbit))


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """The spacecraft's figure groups and UCEI − FCEI."""
    return common.figures_for(result, out, formats, [(NAME, "fcei", True)])


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(common.ORBITS,),
    central_radius=common.CENTRAL_RADIUS,
)
