"""Chapter 6 scenarios: the spring–mass–damper under inequalities and the trajectory
maintenance, from Python and from the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gmuk
from gmuk import cli, scenarios
from gmuk.errors import DefinitionError
from gmuk.scenarios import maintenance, smd


@pytest.mark.parametrize("case", ["smd-gt", "smd-lt", "smd-bi"])
def test_smd_command_writes_point_mass_arrays_and_the_summary_keys(case, tmp_path, capsys):
    out = tmp_path / case
    assert cli.main(["run", case, "--duration", "3", "--out", str(out), "--no-plots"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for key in ("x_min", "x_max", "x_final", "control_accel_final", "primal_violation_max"):
        assert np.isfinite(summary[key]), key
    assert summary["primal_violation_max"] <= 1e-9
    with np.load(out / "trajectory.npz") as data:
        assert data["r_N"].shape == (301, 1, 3)
        assert data["v_N"].shape == (301, 1, 3)
        assert data["r_N"][0, 0, 0] == smd.CASES[case][1]
        # stays on the x axis (to round-off of the constraint solve)
        assert np.abs(data["r_N"][:, 0, 1:]).max() <= 1e-12
        assert summary["x_min"] == data["r_N"][:, 0, 0].min()
    assert case in capsys.readouterr().out


@pytest.mark.parametrize("case", ["smd-gt", "smd-lt", "smd-bi"])
def test_every_bound_of_an_smd_case_becomes_active(case):
    (lower, upper), *_ = smd.CASES[case]
    result = scenarios.get(case).run(duration=10.0)
    x = result.trajectories[case].r_N[:, 0, 0]
    if lower is not None:
        assert x.min() - lower < 1e-3
    if upper is not None:
        assert upper - x.max() < 1e-3
    kkt = result.data["kkt"]
    assert len(kkt.inequalities) == (lower is not None) + (upper is not None)
    assert max(b.primal_violation.max() for b in kkt.inequalities.values()) <= 1e-9


def test_smd_figures_are_written(tmp_path):
    result = scenarios.get("smd-bi").run(duration=2.0)
    paths = smd.figures(result, tmp_path, ("png",))
    names = sorted(p.name for p in paths)
    assert names == sorted(
        [
            "position.png",
            "velocity.png",
            "control.png",
            "effort.png",
            "multipliers.png",
            "kkt_upper.png",
            "kkt_lower.png",
        ]
    )
    assert all(p.stat().st_size > 10_000 for p in paths)


def test_steady_states_are_the_nearest_feasible_rest_points():
    assert smd.steady_state("smd-gt") == (5.0, 25.0)
    assert smd.steady_state("smd-lt") == (0.0, 0.0)
    assert smd.steady_state("smd-bi") == (1.0, 5.0)


def test_smd_options_refuse_bad_values(capsys):
    assert cli.main(["run", "smd-gt", "--slack-damping", "-1"]) == 2
    assert "--slack-damping must be a finite number >= 0; got '-1'" in capsys.readouterr().err
    assert cli.main(["run", "smd-lt", "--slack-mass", "0"]) == 2
    assert "--slack-mass must be a finite number > 0" in capsys.readouterr().err


@pytest.fixture(scope="module")
def maintained_ten_orbits():
    return maintenance.run(orbits=10.0, compare=False)


def test_maintenance_holds_the_position_bound_for_ten_orbits(maintained_ten_orbits):
    result = maintained_ten_orbits
    traj = result.trajectories["maintenance"]
    orbit = result.data["orbit"]
    assert traj.success and traj.t[-1] == pytest.approx(10.0 * orbit.period, rel=1e-12)
    e, e_dot = maintenance.errors(traj, orbit)
    excess = np.linalg.norm(e, axis=1) - maintenance.DELTA
    assert excess.max() <= 0.0
    assert excess.max() > -1.0  # the bound is reached: the test is not vacuous
    assert np.linalg.norm(e_dot, axis=1).max() <= maintenance.GAMMA
    assert result.summary["bound_excess_max"] == excess.max()
    assert result.summary["orbits"] == 10.0
    kkt = result.data["kkt_maintenance"]
    assert set(kkt.inequalities) == {"position.upper", "velocity.upper"}
    assert kkt.summary()["stationarity_max"] < 1e-12


def test_without_bounds_the_spacecraft_leaves_the_reference_by_kilometres():
    result = maintenance.run(orbits=1.0, degree=20, velocity_bound=0.0, compare=True)
    assert set(result.trajectories) == {"maintenance", "free"}
    assert result.summary["free_position_error_max_m"] > 3000.0
    assert result.summary["bound_excess_max"] <= 0.0
    assert "velocity_bound_excess_max" not in result.summary


def test_maintenance_command_and_figures(tmp_path, capsys):
    out = tmp_path / "m"
    argv = ["run", "maintenance", "--orbits", "0.3", "--degree", "10", "--out", str(out)]
    assert cli.main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["orbits"] == 0.3 and summary["degree"] == 10
    assert summary["bound_excess_max"] <= 0.0
    figures = {p.name for p in out.glob("*.png")}
    assert {
        "orbit.png",
        "position_error.png",
        "relative_motion.png",
        "position_error_norm.png",
        "velocity_error.png",
        "control.png",
        "control_effort.png",
        "kkt_position.png",
        "kkt_velocity.png",
    } <= figures
    with np.load(out / "trajectory.npz") as data:
        assert data["r_N"].shape[1:] == (1, 3)
    capsys.readouterr()


def test_maintenance_refuses_a_degree_beyond_the_field():
    with pytest.raises(DefinitionError, match="degree 151 exceeds the field's 150"):
        maintenance.run(orbits=0.01, degree=151)


def test_tracking_error_bound_refuses_a_start_on_the_reference():
    orbit = maintenance.reference_orbit(gmuk.gravity.MOON_MU, gmuk.gravity.MOON_RADIUS)
    craft = gmuk.PointMass("c", 300.0)
    bound = gmuk.TrackingErrorBound(craft, orbit, 100.0, name="p")
    system = gmuk.System([craft], [bound])
    r0, v0 = orbit.state(0.0)
    message = r"'p': the position error is zero.*form='squared'"
    with pytest.raises(gmuk.errors.ConstraintError, match=message):
        system.state(r={"c": r0}, v={"c": v0})
    squared = gmuk.TrackingErrorBound(craft, orbit, 100.0, form="squared", name="p")
    state = gmuk.System([craft], [squared]).state(r={"c": r0}, v={"c": v0})
    assert state.x[3] == pytest.approx(np.sqrt(0.5 * 100.0**2))
