"""``gmuk run lunar-flyby`` (issue #29, item 7): a rigid spacecraft on a hyperbolic lunar
approach, stopped at periapsis by a terminal ApsisEvent and compared with the Kepler conic
(gmuk/scenarios/lunar_flyby.py)."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from gmuk import cli
from gmuk.errors import DefinitionError
from gmuk.scenarios import OptionError
from gmuk.scenarios import lunar_flyby as flyby

EPS = np.finfo(float).eps


@pytest.mark.parametrize(
    ("vinf", "altitude", "start_radius", "duration"),
    [(1000.0, 100e3, 10e6, 20000.0), (2500.0, 50e3, 10e6, 20000.0), (400.0, 300e3, 30e6, 4e4)],
)
def test_point_mass_periapsis_is_the_kepler_conics(vinf, altitude, start_radius, duration) -> None:
    """Measured at rtol = atol = 1e-13 (default case): time 1.3e-10 s, radius 2.3e-8 m,
    speed 1.2e-10 m/s from the conic's (at most 2.8e-10 s, 1.8e-7 m, 2.0e-10 m/s in the
    three cases). The bounds hold a margin of 5 or more and still catch a GM off by 1e-11
    relative (measured: periapsis radius 1.1e-5 m, speed 1.5e-8 m/s, time 8.4e-9 s off)."""
    s = flyby.run(vinf, altitude, start_radius=start_radius, duration=duration).summary
    assert s["periapsis_reached"] is True
    assert abs(s["periapsis_time_diff_s"]) <= 1e-9 + 2e-13 * s["kepler_periapsis_time_s"]
    assert abs(s["periapsis_radius_diff_m"]) <= 1e-6
    assert abs(s["periapsis_speed_diff_m_s"]) <= 4e-9
    assert s["kepler_periapsis_altitude_m"] == pytest.approx(altitude, rel=1e-12)
    # the conic itself: vis-viva at periapsis, v_p² = v∞² + 2μ/r_p
    rp = s["kepler_periapsis_radius_m"]
    assert s["kepler_periapsis_speed_m_s"] ** 2 == pytest.approx(
        vinf**2 + 2.0 * s["mu_m3_s2"] / rp, rel=1e-14
    )
    # the point-mass energy v²/2 − μ/r = v∞²/2 is conserved, to round-off of the periapsis
    # kinetic energy v_p²/2 (measured 1.3e-12, 2.9e-13 and 7.2e-12 of v∞²/2: 0.2, 0.15 and
    # 0.23 of that scale in the three cases)
    assert s["energy_rel_change"] <= 1e-12 * s["kepler_periapsis_speed_m_s"] ** 2 / vinf**2
    assert s["max_position_diff_m"] <= 1e-5  # measured 1.2e-6 m (the dense output's error)


def test_the_start_is_on_the_conic_at_the_stated_radius() -> None:
    result = flyby.run(duration=1.0)
    traj, orbit, t0 = result.trajectories[flyby.NAME], result.data["orbit"], result.data["t0"]
    body = traj.body(flyby.BODY)
    r0, v0 = body.position[0], body.velocity[0]
    assert np.linalg.norm(r0) == pytest.approx(10e6, rel=1e-14)
    assert r0 @ v0 < 0.0  # incoming branch
    np.testing.assert_allclose(r0, orbit.position(t0), rtol=0, atol=1e-8)
    np.testing.assert_allclose(v0, orbit.velocity(t0), rtol=0, atol=1e-11)
    energy = 0.5 * v0 @ v0 - orbit.mu / np.linalg.norm(r0)
    assert energy == pytest.approx(0.5 * 1000.0**2, rel=1e-12)
    assert orbit.kind == "hyperbola" and orbit.a == pytest.approx(-orbit.mu / 1000.0**2)


@pytest.mark.parametrize("degree", [0, 10])
def test_the_event_is_located_at_the_zero_of_the_radial_speed(degree) -> None:
    result = flyby.run(degree=degree)
    traj = result.trajectories[flyby.NAME]
    record = flyby.periapsis_record(traj)
    assert record is not None and record.terminal and record.direction == 1
    assert traj.status == "terminated" and traj.t[-1] == record.t
    r, v = traj.body(flyby.BODY).position[-1], traj.body(flyby.BODY).velocity[-1]
    rn, vn = np.linalg.norm(r), np.linalg.norm(v)
    rdot = r @ v / rn
    assert rdot == pytest.approx(result.summary["periapsis_radial_speed_m_s"], abs=EPS * vn)
    # ṙ is zero to the round-off of r·v/|r| (measured 6.8e-17 |v| at degree 0) ...
    assert abs(rdot) <= 4 * EPS * vn
    # ... so the crossing is within ṙ/r̈ ≤ 1e-12 s of the dense output's zero (r̈ ≈ 2 m/s²)
    rddot = (vn**2 - rdot**2) / rn - result.summary["mu_m3_s2"] / rn**2
    assert abs(rdot / rddot) <= 1e-12


def test_harmonics_move_the_periapsis_and_the_summary_says_how_far() -> None:
    """GRAIL to degree 10 against the conic: measured −23 m in radius, +0.016 s, +0.16 m/s
    (degree 150: −23.3 m, 0.0162 s, 0.157 m/s)."""
    s = flyby.run(degree=10).summary
    assert s["periapsis_reached"] is True
    assert 5.0 < -s["periapsis_radius_diff_m"] < 100.0
    assert 1e-3 < s["periapsis_time_diff_s"] < 0.1
    assert 0.01 < s["periapsis_speed_diff_m_s"] < 1.0
    assert s["periapsis_radius_diff_m"] == pytest.approx(
        s["periapsis_radius_m"] - s["kepler_periapsis_radius_m"], rel=1e-12
    )
    assert s["energy_rel_change"] > 1e-5  # the two-body energy is not conserved with harmonics


def test_a_run_that_ends_first_reports_no_periapsis() -> None:
    s = flyby.run(duration=100.0).summary
    assert s["periapsis_reached"] is False
    assert s["periapsis_time_s"] is None and s["periapsis_time_diff_s"] is None
    assert s["kepler_periapsis_time_s"] > 6000.0


def test_bad_options_are_refused() -> None:
    scenario = flyby.SCENARIO
    for given, message in [
        ({"vinf": "0"}, "--vinf must be a finite number > 0; got '0'"),
        ({"periapsis_altitude": "-5"}, "--periapsis-altitude must be a finite number > 0"),
        ({"degree": "1"}, "--degree must be 0 (point mass) or an integer >= 2; got '1'"),
        ({"degree": "-2"}, "--degree must be 0 (point mass) or an integer >= 2; got '-2'"),
        ({"degree": "2.5"}, "--degree must be a value _degree accepts"),
        ({"start_radius": "inf"}, "--start-radius must be a finite number > 0; got 'inf'"),
        ({"duration": "nan"}, "--duration must be a finite number > 0; got 'nan'"),
    ]:
        with pytest.raises(OptionError, match=message.replace("(", r"\(").replace(")", r"\)")):
            scenario.parse_options(given)
    with pytest.raises(DefinitionError, match="degree 151 requested but GRGM660PRIM stops at 150"):
        flyby.run(degree=151)
    with pytest.raises(DefinitionError, match="start_radius must exceed the periapsis radius"):
        flyby.run(start_radius=1.8e6)
    with pytest.raises(DefinitionError, match="vinf"):
        flyby.run(vinf=math.nan)


def test_command_line_writes_the_summary_keys(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "flyby"
    cmd = [sys.executable, "-m", "gmuk.cli", "run", "lunar-flyby", "--vinf", "1500"]
    subprocess.run([*cmd, "--out", str(out), "--no-plots"], check=True, capture_output=True)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["options"] == {
        "vinf": 1500.0,
        "periapsis_altitude": 100e3,
        "degree": 0,
        "start_radius": 10e6,
        "duration": 20000.0,
    }
    for key in (
        "periapsis_time_s",
        "periapsis_radius_m",
        "periapsis_altitude_m",
        "periapsis_speed_m_s",
        "kepler_periapsis_time_s",
        "kepler_periapsis_radius_m",
        "kepler_periapsis_speed_m_s",
        "periapsis_time_diff_s",
        "periapsis_radius_diff_m",
        "periapsis_speed_diff_m_s",
    ):
        assert isinstance(summary[key], float), key
    assert summary["status"] == "terminated"
    assert summary["events"]["lunar-flyby"][0]["name"] == "periapsis"
    assert summary["events"]["lunar-flyby"][0]["t"] == summary["periapsis_time_s"]
    # a bad combination is a clear error, and nothing is written
    bad = tmp_path / "bad"
    assert cli.main(["run", "lunar-flyby", "--start-radius", "1e6", "--out", str(bad)]) == 2
    assert "start_radius must exceed the periapsis radius" in capsys.readouterr().err
    assert not (bad / "summary.json").exists()
