"""Every tutorial script (examples/tutorials/) runs with --quick and shows what it claims."""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest
from machine import require_distribution

TUTORIALS = Path(__file__).resolve().parents[1] / "examples" / "tutorials"


def run(name: str) -> dict[str, float]:
    return runpy.run_path(str(TUTORIALS / name), run_name="tutorial")["main"](["--quick"])


CHECKS = {
    # automatic rows agree with the analytic ones to finite-difference accuracy, and the two
    # simulations agree; the pin holds
    "t1_holonomic_constraint.py": lambda r: (
        r["rows_A_relative_difference"] < 1e-13  # exact rows (jets): round-off only
        and r["rows_b_relative_difference"] < 1e-13
        and r["pin_drift_m"] < 1e-9
        and r["runs_position_difference_m"] < 1e-10
    ),
    # the installed plugin is found by the registry and by `gmuk plugins`, and its drag is
    # the exponential decay it should be
    "t2_force_model_plugin.py": lambda r: (
        r["source_is_the_plugin"] == 1
        and r["listed_by_gmuk_plugins"] == 1
        and r["box_speed_vs_exp"] < 1e-9
        and r["ball_speed_vs_exp"] < 1e-9
        and abs(r["box_spin_rad_s"] - 0.3) < 1e-12
    ),
    "t3_three_bodies.py": lambda r: (
        r["hub_tracking_error"] < 1e-9
        and r["arm_roll_vs_closed_form_rad"] < 1e-8
        and r["arm_locked_components_max"] < 1e-8
        and r["slider_vs_closed_form_m"] < 1e-8
        and r["slider_locked_components_max"] < 1e-8
    ),
    # the point-mass run is Kepler's orbit to millimetres; the field moves the orbit by
    # hundreds of metres in a quarter orbit at 100 km
    "t4_gravity_field.py": lambda r: (
        r["point_mass_vs_kepler_m"] < 1e-3
        and 50.0 < r["field_vs_point_mass_m"] < 5e3
        and 95.0 < r["field_altitude_min_km"] <= r["field_altitude_max_km"] < 105.0
    ),
    "t5_own_scenario.py": lambda r: (
        r["flips"] >= 1
        and r["energy_drift"] < 1e-9
        and r["momentum_drift"] < 1e-9
        and r["duration_s"] == 30.0
        and r["wrote_figure_and_view"] == 1
    ),
    # gmuk's joint accelerations are Pinocchio's; the elbow's angle reads the same from the
    # robot's q and from its joint; the torque turns the elbow; the joints hold
    "t6_robot_from_urdf.py": lambda r: (
        r["aba_difference"] < 1e-10
        and r["elbow_column_matches"] < 1e-12
        and r["elbow_turn_rad"] < -1.0
        and r["joint_residual"] < 1e-9
        and r["success"] == 1.0
    ),
    # the slew ends on target with the momentum kept; the two wheel forms fly the same slew;
    # the bearing gives no torque about the spin axis
    "t7_gnc_wheels.py": lambda r: (
        r["final_sigma_norm"] < 1e-4
        and r["final_omega_norm_rad_s"] < 1e-6
        and r["momentum_rel_change"] < 1e-12
        and r["forms_attitude_difference_rad"] < 1e-10
        and r["forms_wheel_speed_difference_rad_s"] < 1e-8
        and r["bearing_spin_torque_max_Nm"] < 1e-14 * r["bearing_torque_max_Nm"]
        and r["bearing_torque_max_Nm"] > 0.01
    ),
    # the System refuses the SRP unless scaled; the mass spent is the firings' propellant;
    # the slew ends in the dead band the minimum impulse bit leaves; the umbra is entered
    # (the quick run's 150 s) and no radiation pressure reaches it there
    "t8_gnc_thrusters.py": lambda r: (
        r["refused_without_scaled_forces"] == 1
        and r["propellant_minus_firings_kg"] < 1e-12
        and r["firings"] > 0
        and r["within_2deg_from_s"] < 150.0
        and r["final_attitude_error_rad"] < 2.0 * r["dead_band_rad"]
        and r["t_final_s"] == 150.0
        and 0.0 < r["umbra_entry_s"] < r["t_final_s"]
        and r["srp_force_final_N"] == 0.0
    ),
}


#: The plugins of this repository a tutorial needs installed (the README's first command
#: installs them): name -> (distribution, its folder).
NEEDS = {
    "t2_force_model_plugin.py": ("gmuk-tutorial", "plugins/gmuk-tutorial"),
    "t5_own_scenario.py": ("gmuk-tutorial", "plugins/gmuk-tutorial"),
}


def test_every_tutorial_is_covered_here():
    assert {p.name for p in TUTORIALS.glob("*.py")} == set(CHECKS), "add a check for each"


#: What a tutorial leaves in the folder it is run from, for the reader to open afterwards.
LEAVES = {
    "t5_own_scenario.py": [
        "gmuk-out/tennis-racket/view.html",
        "gmuk-out/tennis-racket/summary.json",
    ],
}


@pytest.mark.parametrize("name", sorted(CHECKS))
def test_tutorial_runs_quick(name, capsys, tmp_path, monkeypatch):
    if name in NEEDS:
        require_distribution(*NEEDS[name])
    monkeypatch.chdir(tmp_path)  # what a tutorial writes lands here, not in the repository
    result = run(name)
    assert CHECKS[name](result), result
    printed = capsys.readouterr().out
    assert printed
    for path in LEAVES.get(name, []):
        assert (tmp_path / path).is_file(), path
        assert str((tmp_path / path).parent.resolve()) in printed  # it says where
