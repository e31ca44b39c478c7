"""Chapter 5 scenarios: FCCL (disturbed start, Morse–Lyapunov control) and unmodeled lunar
harmonics, in shortened form; the full default runs are `slow` tests."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gmuk
from gmuk import cli, scenarios
from gmuk.celestial import CelestialBody
from gmuk.errors import DefinitionError
from gmuk.forces import SphericalHarmonicGravity
from gmuk.orbits import fcei_orbit
from gmuk.scenarios import _lvlh as common
from gmuk.scenarios import fccl, unmodeled

PERIOD = fcei_orbit(common.MU).period


def test_the_printed_rotation_block_is_projected_to_its_nearest_rotation():
    R = fccl.initial_pose()[:3, :3]
    P = fccl.PRINTED_ROTATION
    assert np.abs(P.T @ P - np.eye(3)).max() > 6e-6  # not a rotation as printed
    assert np.allclose(R.T @ R, np.eye(3), rtol=0, atol=1e-15)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-15)
    assert np.abs(R - P).max() <= 4e-6
    # nearest in the Frobenius norm ⇔ P = R S with S symmetric positive definite (polar)
    S = R.T @ P
    assert np.allclose(S, S.T, rtol=0, atol=1e-15)
    assert np.linalg.eigvalsh(0.5 * (S + S.T)).min() > 0.99
    assert np.array_equal(fccl.initial_pose()[:3, 3], fccl.PRINTED_POSITION)


def test_settling_time_and_integral_norm():
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    assert fccl.settling_time(t, np.array([5.0, 2.0, 0.5, 2.0, 0.1]), 1.0) == 4.0
    assert fccl.settling_time(t, np.array([0.5, 0.2, 0.1, 0.0, 0.0]), 1.0) == 0.0
    assert fccl.settling_time(t, np.array([5.0, 0.2, 0.1, 0.0, 2.0]), 1.0) is None
    values = np.column_stack([3.0 * t, 4.0 * t])  # norm 5t
    assert fccl.integral_norm(t, values) == pytest.approx(5.0 * 8.0)


@pytest.fixture(scope="module")
def fccl_600s():
    return fccl.run(orbits=600.0 / PERIOD)


def test_fccl_converges_in_attitude_with_w_never_increasing(fccl_600s):
    s = fccl_600s.summary
    assert s["initial_position_error_m"] == pytest.approx(5099.1, abs=0.1)
    assert s["initial_attitude_error_rad"] == pytest.approx(0.5688, abs=1e-4)
    assert s["attitude_settling_time_s"] is not None and s["attitude_settling_time_s"] < 60.0
    assert s["final_attitude_error_rad"] < 1e-7
    assert s["final_position_error_m"] < 0.9 * s["initial_position_error_m"]
    assert s["max_lyapunov_W_dot"] < 0.0
    assert s["max_lyapunov_W_increase_over_W0"] <= 1e-9
    assert s["lyapunov_W_final_over_W0"] < 0.9
    # the controller's torque has died out; its force is what holds the slow translation
    assert s["final_control_torque_N_m"] < 1e-6 * s["peak_control_torque_N_m"]
    assert s["nominal_max_position_error_m"] < 1e-6


def test_fccl_corrective_wrench_is_the_control_wrench_once_on_the_nominal(fccl_600s):
    traj, nominal = fccl_600s.trajectories["fccl"], fccl_600s.trajectories["nominal"]
    d = fccl.corrective_wrench(traj, nominal)
    u = traj.body("spacecraft").control_force
    late = traj.t > 300.0  # attitude converged: UK torque = nominal UK torque, but for the
    # gravity-gradient torque's change over the 4.5 km position error (3 Δr/r ≈ 4e-3 of it)
    L_n = np.abs(nominal.body("spacecraft").constraint_force[:, :3]).max()
    assert np.abs(d[late, :3] - u[late, :3]).max() < 1e-2 * L_n
    # at t = 0 the rotated nominal differs from the unrotated one (0.57 rad apart)
    e = fccl.tracking_norms(traj, fcei_orbit(common.MU))
    assert e["attitude_rad"][0] > 0.5 and np.isfinite(d).all()


def test_baumgarte_comparison_runs_and_reports_each_design():
    orbits = 300.0 / PERIOD
    trajs, rows = fccl.compare_baumgarte(orbits, designs=(("fast", 0.43, 0.1),))
    assert set(trajs) == {"baumgarte_fast"} and set(rows) == {"fast"}
    row = rows["fast"]
    assert row["omega_rotation_rad_s"] == 0.43
    assert row["attitude_settling_time_s"] is not None and row["attitude_settling_time_s"] < 60
    assert row["final_position_error_m"] < 1.0  # ω_n = 0.1 rad/s on the translation rows
    assert row["corrective_effort_force_N_s"] > 0 and "lyapunov_W0" not in row


def test_harmonic_perturbation_is_the_field_minus_its_central_term():
    field = gmuk.gravity.load("GRGM660PRIM", degree=8)
    moon = CelestialBody.moon(field=field)
    pert = unmodeled.HarmonicPerturbation(moon)
    full = SphericalHarmonicGravity(moon, finite_size_force=False)
    central = gmuk.GravityGradient(field.mu)
    sc = common.spacecraft()
    rng = np.random.default_rng(3)
    for _ in range(3):
        g = np.eye(4)
        g[:3, :3] = gmuk.lie.so3.exp(rng.normal(size=3))
        direction = rng.normal(size=3)
        g[:3, 3] = 3.2e6 * direction / np.linalg.norm(direction)
        t = 1e4 * rng.uniform()
        w_full = full.wrench(t, g, np.zeros(6), sc)
        w_split = central.wrench(t, g, np.zeros(6), sc) + pert.wrench(t, g, np.zeros(6), sc)
        w_pert = pert.wrench(t, g, np.zeros(6), sc)
        # the split differs by GravityGradient's finite-size force (~1e-9 of gravity)
        assert np.allclose(w_split[3:], w_full[3:], rtol=0, atol=1e-8 * np.abs(w_full[3:]).max())
        assert np.allclose(w_split[:3], w_full[:3], rtol=0, atol=1e-9 * np.abs(w_full[:3]).max())
        # the perturbation is ~1e-4 of gravity: not the central term counted twice
        assert 1e-6 < np.abs(w_pert[3:]).max() / np.abs(w_full[3:]).max() < 1e-3
        # on a point mass: the field's force minus the point-mass one
        p, r, v = gmuk.PointMass("p", 10.0), g[:3, 3], np.zeros(3)
        f_split = pert.force(t, r, v, p) + gmuk.PointMassGravity(field.mu).force(t, r, v, p)
        f_full = full.force(t, r, v, p)
        assert np.allclose(f_split, f_full, rtol=0, atol=1e-12 * np.abs(f_full).max())
    assert pert.modeled is False
    with pytest.raises(DefinitionError, match="degree must be an integer >= 2"):
        unmodeled.HarmonicPerturbation(moon, degree=1)
    with pytest.raises(DefinitionError, match="stops at 8"):
        unmodeled.HarmonicPerturbation(moon, degree=9)


def test_load_field_refuses_unknown_and_bad_degrees(tmp_path):
    with pytest.raises(DefinitionError, match="neither a field shipped"):
        unmodeled.load_field(str(tmp_path / "missing.gfc"))
    with pytest.raises(DefinitionError, match=r"degree \(--degree\) must be an integer >= 2"):
        unmodeled.load_field("GRGM660PRIM", 1)
    with pytest.raises(DefinitionError, match="stops at 150"):
        unmodeled.load_field("GRGM660PRIM", 151)
    with pytest.raises(DefinitionError, match="not lunar"):
        unmodeled.load_field("EGM2008", 4)
    field, note = unmodeled.load_field("grgm660prim", 4)
    assert field.degree == 4 and "truncated to degree 4" in note


def test_unmodeled_control_keeps_the_deviation_below_the_uncontrolled_drift():
    s = unmodeled.run(orbits=0.05, degree=4, rtol=1e-9).summary
    controlled = s["controlled_max_position_deviation_m"]
    assert controlled < 1.0
    assert s["uncontrolled_max_position_deviation_m"] > 10 * controlled
    assert s["uncontrolled_final_position_deviation_m"] > 1.0  # ≈ ½ a t², a ≈ 5e-5 m/s²
    assert s["controlled_max_attitude_deviation_rad"] < s["uncontrolled_max_attitude_deviation_rad"]
    assert s["nominal_max_position_deviation_m"] < 1e-6
    # the M–L force ends up cancelling the unmodeled force
    assert s["final_force_rejection_residual_N"] < 0.05 * s["peak_unmodeled_force_N"]
    assert s["max_robust_term_m_s2"] < 1e-24  # Eq. 90 as printed: negligible


def test_cli_runs_both_scenarios_and_writes_summaries_and_figures(tmp_path):
    out = tmp_path / "fccl"
    assert cli.main(["run", "fccl", "--orbits", "0.02", "--out", str(out), "--no-plots"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for key in (
        "attitude_settling_time_s",
        "position_settling_time_s",
        "final_position_error_m",
        "max_position_error_m",
        "final_attitude_error_rad",
        "max_attitude_error_rad",
        "peak_control_force_N",
        "peak_control_torque_N_m",
        "max_lyapunov_W_dot",
        "max_lyapunov_W_increase_over_W0",
        "control_effort_force_N_s",
        "control_effort_torque_N_m_s",
    ):
        assert key in summary, key
    assert summary["scenario"] == "fccl" and summary["options"]["orbits"] == 0.02
    assert gmuk.load_trajectory(out / "trajectory.npz").body_names == ("spacecraft",)
    out = tmp_path / "unmodeled"
    argv = ["run", "unmodeled", "--orbits", "0.004", "--degree", "3", "--rtol", "1e-8"]
    assert cli.main([*argv, "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["degree"] == 3 and "controlled_max_position_deviation_m" in summary
    names = {p.stem for p in out.glob("*.png")}
    assert {f"fig5_{k}" for k in ("11_position", "16_ml_translational_control")} <= names
    assert "unmodeled_position_deviation" in names and "orbit_3d" in names and len(names) == 11


def test_fccl_figures_with_the_baumgarte_runs(tmp_path):
    result = fccl.run(orbits=0.004, baumgarte=True)
    assert {"fccl", "nominal", "baumgarte_matched"} <= set(result.trajectories)
    assert "baumgarte_orbit_rate_corrective_effort_force_N_s" in result.summary
    paths = fccl.figures(result, tmp_path, ("png",))
    names = {p.stem for p in paths}
    assert {f"fig5_{i:02d}" for i in range(1, 11)} == {n[:7] for n in names if n[:4] == "fig5"}
    assert {"fccl_lyapunov", "fccl_baumgarte_position_m"} <= names
    assert all(p.stat().st_size > 10_000 for p in paths)


def test_the_scenarios_use_the_controllers_default_integral_gain():
    from gmuk.control import MorseLyapunovController
    from gmuk.orbits import LVLHReference

    ctl = MorseLyapunovController(common.spacecraft(), LVLHReference(fcei_orbit(common.MU)))
    assert ctl.k_integral == fccl.K_INTEGRAL
    for name in ("fccl", "unmodeled"):
        assert scenarios.get(name).option("k_integral").default == ctl.k_integral


def test_scenarios_are_registered():
    names = [name for name, _ in scenarios.describe()]
    assert "fccl" in names and "unmodeled" in names
    assert scenarios.get("fccl").option("orbits").default == fccl.ORBITS
    with pytest.raises(scenarios.OptionError, match="--k-integral"):
        scenarios.get("fccl").parse_options({"k_integral": "-1"})
    with pytest.raises(scenarios.OptionError, match="--degree"):
        scenarios.get("unmodeled").parse_options({"degree": "1"})


@pytest.mark.slow
def test_fccl_full_default_run_meets_the_acceptance_figures():
    s = fccl.run().summary  # two orbits, default gains
    assert s["final_position_error_m"] < 1.0  # measured 0.45 m
    assert s["final_attitude_error_rad"] < 1e-3  # measured 4.5e-13 rad
    assert s["position_settling_time_s"] is not None  # measured 4.15e4 s (1.83 orbits)
    assert s["attitude_settling_time_s"] < 60.0  # measured 21.0 s
    assert s["max_lyapunov_W_dot"] < 0.0
    assert s["max_lyapunov_W_increase_over_W0"] <= 1e-9  # measured −5e-11 (never increases)
    assert s["lyapunov_W_final_over_W0"] < 1e-6
    assert s["final_control_force_N"] < 1e-6 * s["peak_control_force_N"]
    assert s["final_control_torque_N_m"] < 1e-6 * s["peak_control_torque_N_m"]


@pytest.mark.slow
def test_unmodeled_full_default_run_meets_the_acceptance_figures():
    s = unmodeled.run().summary  # one orbit, degree 10
    assert s["controlled_max_position_deviation_m"] <= 1.0  # measured 0.100 m
    assert s["uncontrolled_max_position_deviation_m"] > 100.0  # measured 1.9 km
    assert s["controlled_max_attitude_deviation_rad"] < 1e-9
    assert s["final_force_rejection_residual_N"] < 0.01 * s["peak_unmodeled_force_N"]
