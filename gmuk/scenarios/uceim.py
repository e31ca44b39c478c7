"""UCEIM: the virtual-spacecraft pair on T²SE(3) — beyond the thesis (its future work).

The pair's constraints written as one ``A g̈ B = C`` (:class:`gmuk.constraints.VirtualPairT2`)
and solved within the reachable accelerations ``g(V^² + V̇^)`` (Gauss's principle on the rows
that A g̈ B = C implies for V̇); compared with UCEI on R⁶. At states along the run it also
evaluates Eq. 80 as printed, to measure how much of its g̈_c no control input can produce and
how far its projection is from the Gauss-optimal answer.

Stabilised as UCEI (beyond the thesis): the pair's C carries Baumgarte terms
(:class:`gmuk.constraints.VirtualPairT2`'s ``baumgarte`` at ``_lvlh.TRACKING_BAUMGARTE`` on
the virtual body's tracking, ``relative_baumgarte`` at ``_lvlh.RELATIVE_BAUMGARTE`` on the
lock), its A and B are the unstabilised ones; unstabilised, the virtual body's attitude left
its reference by π rad within 12 orbits (docs/scenarios/chapter4.rst).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk.constraints import VirtualPairT2
from gmuk.orbits import LVLHReference, fcei_orbit
from gmuk.scenarios import Scenario, ScenarioResult
from gmuk.scenarios import _lvlh as common

NAME = "uceim"
DESCRIPTION = "UCEI on T²SE(3) (future work of the thesis), compared with UCEI on R⁶"


def _pair_t2(orbit: Any, method: str) -> gmuk.System:
    virtual, sc = common.spacecraft("virtual"), common.spacecraft()
    return gmuk.System(
        [virtual, sc],
        [
            VirtualPairT2(
                sc,
                virtual,
                LVLHReference(orbit),
                baumgarte=common.TRACKING_BAUMGARTE,
                relative_baumgarte=common.RELATIVE_BAUMGARTE,
            )
        ],
        [gmuk.GravityGradient(orbit.mu)],
        tangent_bundle_method=method,
    )


def run(orbits: float = 1.0) -> ScenarioResult:
    """Simulate the T²SE(3) pair and UCEI over ``orbits`` orbits."""
    orbit = fcei_orbit(common.MU)
    system = _pair_t2(orbit, "reachable")
    r0 = LVLHReference(orbit).evaluate(0.0)
    state = system.state(
        g={"virtual": r0.g, "spacecraft": r0.g}, V={"virtual": r0.V, "spacecraft": r0.V}
    )
    t = common.time_grid(orbit, orbits)
    t2 = system.simulate(state, (0.0, t[-1]), t_eval=t, rtol=common.RTOL, atol=common.ATOL)
    r6 = common.virtual_pair(orbit, orbits)
    a, b = t2.body("spacecraft"), r6.body("spacecraft")
    eq80 = _pair_t2(orbit, "eq80")
    unreachable, gap = [], []
    for k in range(0, len(t), max(1, len(t) // 24)):
        st = system.state(
            g={n: t2.g_NB[k, i] for i, n in enumerate(t2.body_names)},
            V={n: t2.V_B[k, i] for i, n in enumerate(t2.body_names)},
            t=float(t[k]),
        )
        good, printed = system.accelerations(st), eq80.accelerations(st)
        unreachable.append(printed.unreachable)
        gap.append(
            np.abs(printed.constraint - good.constraint).max() / np.abs(good.constraint).max()
        )
    summary = {
        "max_position_difference_vs_ucei_m": float(
            np.linalg.norm(a.position - b.position, axis=1).max()
        ),
        "max_roll_difference_vs_ucei_rad": float(
            np.abs(common.relative_pose(t2)[:, 0] - common.relative_pose(r6)[:, 0]).max()
        ),
        "max_locked_rotation_rad": float(np.abs(common.relative_pose(t2)[:, 1:3]).max()),
        "eq80_unreachable_fraction_min": float(min(unreachable)),
        "eq80_unreachable_fraction_max": float(max(unreachable)),
        "eq80_projected_constraint_accel_rel_error_max": float(max(gap)),
        "rhs_evaluations": int(t2.stats["n_rhs"]),
        "t2_baumgarte_alpha_per_s": float(common.TRACKING_BAUMGARTE.alpha),
        "t2_baumgarte_beta_per_s2": float(common.TRACKING_BAUMGARTE.beta),
        "t2_relative_baumgarte_alpha_per_s": float(common.RELATIVE_BAUMGARTE.alpha),
    }
    return ScenarioResult(NAME, {NAME: t2, "ucei": r6}, NAME, summary)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """The spacecraft's figure groups and UCEIM − UCEI."""
    return common.figures_for(result, out, formats, [(NAME, "ucei", True)])


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(common.ORBITS,),
    central_radius=common.CENTRAL_RADIUS,
)
