"""Every example script runs and reports physically sensible figures."""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(name):
    return runpy.run_path(str(EXAMPLES / name), run_name="example")["main"]()


def test_every_example_is_covered_here():
    scripts = {p.name for p in EXAMPLES.glob("*.py")}
    assert scripts == set(CHECKS), "add a check for each new example"


CHECKS = {
    # a planar loop of 3-D revolute joints: 20 rows of rank 17, taken as they are; the loop
    # stays closed (Freudenstein's equation) while the crank falls from the top
    "closed_loop_four_bar.py": lambda r: (
        r["constraint_rows"] == 20
        and r["constraint_rank"] == 17
        and r["crank_swing_deg"] > 90.0
        and r["freudenstein_residual_max"] < 1e-10
    ),
    "custom_orbit_tracking.py": lambda r: (
        r["max_position_error_m"] < 1e-5 and r["max_constraint_torque_N_m"] > 0
    ),
    # touches the floor, never goes through it, rests on it with the normal force = weight,
    # and the frictionless floor leaves the horizontal speed alone
    # Penetration at contact is set by rounding, not by the tolerance: up to 2.1e-9 m over
    # initial velocities nudged by ±1e-15 to 1e-14 (relative), rtol 1e-10 to 1e-13, either loop
    "inequality_floor.py": lambda r: (
        r["min_height_m"] < 1e-3
        and r["primal_violation_max_m"] <= 1e-8
        and abs(r["normal_force_vs_weight"]) < 1e-8
        and abs(r["final_horizontal_speed_m_s"] - 0.5) < 1e-9
    ),
    # the planned slew reaches its target on SO(3) and the simulator flies it to 1e-4 rad
    "optimal_slew.py": lambda r: (
        r["final_attitude_error_rad"] < 1e-9
        and r["orthogonality"] < 1e-10
        and r["flown_vs_plan_rad"] < 1e-4
    ),
    # the planned station keeping converges and the simulator, running the compiled field,
    # flies it to a millimetre (the collocation error on 40 elements: 8.3e-4 m)
    "optimal_lunar_correction.py": lambda r: (
        r["status"] == "Solve_Succeeded"
        and r["iterations"] < 20
        and 0.5 < r["delta_v_m_s"] < 2.0
        and r["free_miss_m"] > 1e3
        and r["flown_vs_plan_m"] < 1e-2
        and r["flown_final_miss_m"] < 1e-2
    ),
    "free_rigid_body.py": lambda r: r["energy_drift"] < 1e-10 and r["orthogonality"] < 1e-13,
    "spherical_pendulum.py": lambda r: r["radius_error_m"] < 1e-8 and r["mean_tension_N"] > 0,
    "virtual_pair.py": lambda r: r["locked_components_max"] < 1e-9 and r["roll_vs_analytic"] < 1e-8,
}


@pytest.mark.parametrize("name", sorted(CHECKS))
def test_example_runs(name, capsys):
    result = run(name)
    assert CHECKS[name](result), result
    assert capsys.readouterr().out  # it printed its figures
