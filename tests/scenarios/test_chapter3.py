"""Chapter 3 scenario (apollo16): short runs, and the full orbit's headline figures.

Every run uses the GRAIL field shipped with gmuk (GRGM660PRIM to degree 150), by name or
by the path of its file.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gmuk
from gmuk import cli, gravity, scenarios
from gmuk.errors import DefinitionError
from gmuk.gravity import legendre_4pi
from gmuk.orbits import KeplerOrbit
from gmuk.scenarios import apollo16

GRAIL_FILE = gravity.field_path("GRGM660PRIM")


def grail(degree=None):
    return gravity.load("GRGM660PRIM", degree)


@pytest.fixture(scope="module")
def early():
    """The first ~36 s (4 outputs) at degrees 0 and 4 with both models."""
    return apollo16.run(orbits=0.005, degrees=(0, 4))


_HEADLINES = (
    "position_difference_m",
    "position_component_difference_m",
    "radial_difference_m",
    "cross_track_difference_m",
    "velocity_difference_m_s",
    "euler321_difference_deg",
    "angular_velocity_difference_rad_s",
)


def _position_difference(result, key):
    return apollo16.differences(result.trajectories[key], result.trajectories["uniform"])[
        "position_m"
    ]


def test_initial_state_is_the_stated_orbit_with_the_fields_gm():
    field = grail()
    g, V, period = apollo16.initial_state("elements", field.mu, field.radius)
    r, v = g[:3, 3], g[:3, :3] @ V[3:]
    orbit, t = KeplerOrbit.from_state(r, v, field.mu)
    assert abs(t) < 1e-6  # at periselene
    assert orbit.a * (1 - orbit.e) - field.radius == pytest.approx(90e3, abs=1e-6)
    assert orbit.a * (1 + orbit.e) - field.radius == pytest.approx(130e3, abs=1e-6)
    assert math.degrees(orbit.i) == pytest.approx(11.0, abs=1e-12)
    assert period == pytest.approx(orbit.period, rel=1e-14)
    # LVLH attitude: axis 1 at the Moon, axis 3 along the orbit normal, ω = ḟ about axis 3
    R = g[:3, :3]
    assert R[:, 0] @ (r / np.linalg.norm(r)) == pytest.approx(-1.0, abs=1e-15)
    h = np.cross(r, v)
    assert R[:, 2] @ (h / np.linalg.norm(h)) == pytest.approx(1.0, abs=1e-15)
    assert V[:2] == pytest.approx([0.0, 0.0], abs=0.0)
    assert V[2] == pytest.approx(np.linalg.norm(v) / np.linalg.norm(r), rel=1e-14)


def test_printed_initial_state_is_an_86_by_127_km_orbit():
    field = grail()
    g, V, period = apollo16.initial_state("printed", field.mu, field.radius)
    assert g[:3, 3].tolist() == [1.824e6, 0.0, 0.0]
    assert V.tolist() == [0.0, 0.0, 9.03813e-4, 0.0, -1.64863e3, 0.0]
    R_printed = np.array([[-1, 0, 0], [0, -0.98163, -0.19081], [0, -0.19081, 0.98163]])
    assert np.abs(g[:3, :3] - R_printed).max() < 5e-6  # the print has five digits
    orbit, _ = KeplerOrbit.from_state(g[:3, 3], g[:3, :3] @ V[3:], field.mu)
    assert orbit.a * (1 - orbit.e) - field.radius == pytest.approx(86e3, abs=1e-3)
    assert orbit.a * (1 + orbit.e) - field.radius == pytest.approx(127.23e3, abs=10.0)
    # ω₃ printed is not v/r at r = 1824 km (it would be at 1824.083 km)
    assert V[2] / (1.64863e3 / 1.824e6) - 1 == pytest.approx(-4.5e-5, abs=1e-6)
    assert period == pytest.approx(7109.14, abs=0.01)


def test_degree_zero_reproduces_the_uniform_field(early):
    for model in ("correct", "thesis"):
        d = _position_difference(early, f"{model}_deg0")
        assert np.linalg.norm(d, axis=1).max() < 1e-6  # m, over 36 s


def test_correct_model_position_difference_is_half_delta_a_t_squared(early):
    """Δr(t) = ½ Δa t² + O(t³), Δa the field's harmonic acceleration at the start (F = N)."""
    t = early.trajectories["uniform"].t
    r0 = early.trajectories["uniform"].g_NB[0, 0, :3, 3]
    da = grail(4).acceleration(r0, central=False)
    assert np.linalg.norm(da[1:]) > 0.2 * np.linalg.norm(da)  # a tangential part
    d = _position_difference(early, "correct_deg4")
    assert np.linalg.norm(d[0]) == 0.0
    for k, tol in ((1, 0.01), (2, 0.02)):  # measured 0.7 % at 12 s, 1.4 % at 24 s
        expected = 0.5 * da * t[k] ** 2
        assert np.linalg.norm(d[k] - expected) <= tol * np.linalg.norm(expected)


def test_thesis_model_pushes_radially_outward_with_its_own_magnitude(early):
    """Eqs. 42/59 keep only the radial derivative with the harmonic sum's sign flipped, and
    (default) Eq. 26c's parentheses restored: P̄ = 4π P̄ / √2 (p = 0), / 2 (p > 0)."""
    t = early.trajectories["uniform"].t
    r0 = early.trajectories["uniform"].g_NB[0, 0, :3, 3]
    field = grail(4)
    rn = float(np.linalg.norm(r0))
    assert r0[1] == r0[2] == 0.0  # latitude 0, longitude 0 in F at t = 0
    P = legendre_4pi(4, 0.0)
    scale = np.where(np.arange(5) == 0, 1 / math.sqrt(2), 0.5)
    T = (P * field.C[:5, :5] * scale[None, :]).sum(axis=1)
    n = np.arange(1, 5)
    da_radial = field.mu / rn**2 * float(np.sum((n + 1) * (field.radius / rn) ** n * T[1:]))
    assert da_radial > 0  # outward, where the correct radial part is inward
    d = _position_difference(early, "thesis_deg4")
    r_hat = r0 / rn
    for k in (1, 2):
        radial = d[k] @ r_hat
        assert radial == pytest.approx(0.5 * da_radial * t[k] ** 2, rel=0.02)
        assert np.linalg.norm(d[k] - radial * r_hat) < 0.01 * abs(radial)
    correct = _position_difference(early, "correct_deg4")
    assert correct[1] @ r_hat < 0
    assert np.linalg.norm(d[2] - correct[2]) > 0.5 * np.linalg.norm(correct[2])


@pytest.fixture(scope="module")
def short():
    """The first 6 % of the orbit with the defaults: degrees 2, 10, 50, 150, both models."""
    return apollo16.run(orbits=0.06)


def test_default_runs_the_thesis_degrees_with_the_shipped_field(short):
    s = short.summary
    assert s["degrees"] == [2, 10, 50, 150] and s["models"] == ["correct", "thesis"]
    assert s["field"] == "GRGM660PRIM (shipped with gmuk, degree 150)"
    assert s["mu_m3_s2"] == 4.902799806931690e12 and s["reference_radius_m"] == 1.738e6
    assert set(short.trajectories) == {"uniform"} | {
        f"{m}_deg{n}" for m in ("correct", "thesis") for n in (2, 10, 50, 150)
    }
    for n in (2, 150):
        for prefix in (f"correct_deg{n}", f"thesis_deg{n}", f"thesis_vs_correct_deg{n}"):
            assert {k for k in s if k.startswith(prefix + "_")} == {
                f"{prefix}_max_{q}" for q in _HEADLINES
            } | {f"{prefix}_final_along_track_difference_m"}


def test_summary_is_json_with_units_in_the_keys(short):
    assert json.loads(json.dumps(short.summary)) == short.summary
    assert short.summary["period_s"] == pytest.approx(7128.7066, abs=1e-3)
    assert short.summary["duration_s"] == pytest.approx(0.06 * short.summary["period_s"])


def test_difference_grows_from_zero_at_degree_2(short):
    for model in ("correct", "thesis"):
        d = apollo16.differences(short.trajectories[f"{model}_deg2"], short.trajectories["uniform"])
        pos = np.linalg.norm(d["position_m"], axis=1)
        assert pos[0] == 0.0 and np.all(np.diff(pos) > 0)
        assert np.abs(d["euler321_deg"][0]).max() == 0.0
        assert np.abs(d["euler321_deg"][-1]).max() > 0.0
        assert np.linalg.norm(d["omega_rad_s"][-1]) > 0.0


def test_thesis_model_keeps_the_orbit_plane_and_falls_behind(short):
    """A radial-only force cannot tilt the orbit; the correct field pulls the spacecraft
    inward at the start (lower, faster: ahead), the thesis's flipped sign outward (behind)."""
    s = short.summary
    assert s["correct_deg2_max_cross_track_difference_m"] > 0.1  # measured 1.37 m
    assert s["thesis_deg2_max_cross_track_difference_m"] < 1e-5  # measured 2.5e-7 m
    assert s["correct_deg2_final_along_track_difference_m"] > 1.0  # measured +11.3 m
    assert s["thesis_deg2_final_along_track_difference_m"] < -1.0  # measured -9.7 m


def test_figures_and_data_are_written(short, tmp_path):
    paths = apollo16.figures(short, tmp_path, ("png",))
    names = sorted(p.name for p in paths)
    assert names == sorted(
        [
            f"fig3_{k}_{m}.png"
            for m in ("correct", "thesis")
            for k in ("1_position", "2_velocity", "3_euler321", "4_angular_velocity")
        ]
        + ["magnitudes_correct_vs_thesis.png", "orbit_3d.png"]
    )
    assert all(p.is_file() and p.stat().st_size > 10_000 for p in paths)
    data = apollo16.write_data(short, tmp_path)
    assert {p.name for p in data} == {"uniform.npz", "differences.npz"} | {
        f"{m}_deg{n}.npz" for m in ("correct", "thesis") for n in (2, 10, 50, 150)
    }
    diffs = np.load(tmp_path / "differences.npz")
    assert diffs["correct_deg2__position_m"].shape == (len(diffs["t_s"]), 3)
    back = gmuk.load_trajectory(tmp_path / "runs" / "thesis_deg2.npz")
    assert np.array_equal(back.g_NB, short.trajectories["thesis_deg2"].g_NB)


def test_clear_errors_for_bad_fields_and_options(tmp_path):
    with pytest.raises(DefinitionError, match=r"degree 151 requested but field GRGM660PRIM"):
        apollo16.run(orbits=0.01, degrees=(2, 151))
    with pytest.raises(DefinitionError, match="neither a field shipped with gmuk"):
        apollo16.run(orbits=0.01, field=tmp_path / "missing.gfc")
    with pytest.raises(DefinitionError, match="neither a field shipped with gmuk"):
        apollo16.run(orbits=0.01, field="GRGM900C")
    with pytest.raises(DefinitionError, match=r"EGM2008_to70 \(shipped with gmuk.*not lunar"):
        apollo16.run(orbits=0.01, field="EGM2008", degrees=(2,))
    with pytest.raises(DefinitionError, match="model must be"):
        apollo16.run(orbits=0.01, degrees=(2,), model="exact")
    with pytest.raises(DefinitionError, match="initial must be"):
        apollo16.run(orbits=0.01, degrees=(2,), initial="guess")
    with pytest.raises(DefinitionError, match="thesis_normalization must be one of"):
        apollo16.run(orbits=0.01, degrees=(2,), thesis_normalization="none")
    for bad in ((2, 2), (2.5,), (-1,), ()):
        with pytest.raises(DefinitionError, match="distinct integers"):
            apollo16.run(orbits=0.01, degrees=bad)
    with pytest.raises(TypeError, match="field_path"):  # the former name is not swallowed
        apollo16.run(orbits=0.01, field_path=GRAIL_FILE)


def test_field_by_name_path_or_object_is_the_same_field():
    by_name = apollo16.load_field("grgm660prim", (2,))
    by_path = apollo16.load_field(GRAIL_FILE, (2,))
    by_object = apollo16.load_field(grail(10), (2, 10))
    assert by_name[0] is grail()  # read once per process
    assert by_path[2] == f"GRGM660PRIM (from {GRAIL_FILE}, degree 150)"
    assert np.array_equal(by_path[0].C, by_name[0].C) and by_path[0].mu == by_name[0].mu
    assert by_object[2] == "GRGM660PRIM (given as a field, degree 10)"
    with pytest.raises(DefinitionError, match="stops at 10"):
        apollo16.load_field(grail(10), (50,))


def test_cli_list_run_and_errors(tmp_path, capsys):
    assert scenarios.get("apollo16") is apollo16.SCENARIO
    assert cli.main(["list"]) == 0
    listing = capsys.readouterr().out.splitlines()
    assert any(
        line.startswith("apollo16 ") and line.endswith(f" {apollo16.DESCRIPTION}")
        for line in listing
    )
    out = tmp_path / "a16"
    args = ["run", "apollo16", "--orbits", "0.01", "--out", str(out), "--no-plots"]
    assert cli.main([*args, "--degrees", "2", "--model", "correct"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenario"] == "apollo16" and summary["models"] == ["correct"]
    assert summary["options"]["field"] == "GRGM660PRIM" and summary["options"]["degrees"] == [2]
    assert (out / "runs" / "correct_deg2.npz").is_file() and (out / "differences.npz").is_file()
    assert gmuk.load_trajectory(out / "trajectory.npz").body_names == ("spacecraft",)
    capsys.readouterr()
    assert cli.main([*args, "--degrees", "151"]) == 2
    assert "degree 151 requested but field GRGM660PRIM" in capsys.readouterr().err
    assert cli.main([*args, "--field", str(tmp_path / "no.gfc")]) == 2
    assert "neither a field shipped with gmuk (GRGM660PRIM, EGM2008)" in capsys.readouterr().err
    assert cli.main(["run", "fcei", "--field", "x.gfc"]) == 2
    assert "'fcei' does not take --field x.gfc" in capsys.readouterr().err
    assert cli.main([*args, "--degrees", "two"]) == 2
    assert "--degrees must be comma-separated integers" in capsys.readouterr().err
    assert cli.main([*args, "--degrees", "2,2"]) == 2
    assert "--degrees must be distinct integers ≥ 0" in capsys.readouterr().err
    assert cli.main([*args, "--model", "exact"]) == 2
    assert "--model must be one of both, correct, thesis; got 'exact'" in capsys.readouterr().err


def test_field_file_path_on_the_command_line_degree_10(tmp_path):
    out = tmp_path / "a16"
    argv = ["run", "apollo16", "--orbits", "0.02", "--out", str(out), "--no-plots"]
    assert cli.main([*argv, "--field", str(GRAIL_FILE), "--degrees", "2,10"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["mu_m3_s2"] == 4.902799806931690e12 and "degree 150" in s["field"]
    assert str(GRAIL_FILE) in s["field"]
    # degree 10 adds to degree 2, but degree 2 carries most of it this early
    d2 = s["correct_deg2_max_position_difference_m"]
    d10 = s["correct_deg10_max_position_difference_m"]
    assert d2 != d10 and 0.5 < d10 / d2 < 1.5


def test_full_orbit_headline_figures():
    """One orbit at degrees 2, 10, 50, 150, the defaults (``gmuk run apollo16``; measured
    values in docs/scenarios/chapter3.rst)."""
    s = apollo16.run().summary
    for n in apollo16.DEGREES:
        # thesis Eqs. 42/59: "almost four kilometers" (largest component 3.8–4.7 km here)
        assert 3.0e3 < s[f"thesis_deg{n}_max_position_component_difference_m"] < 5.0e3
        # ... and Euler angles "in the neighbourhood of one-twentieth of a degree"
        assert 0.04 < s[f"thesis_deg{n}_max_euler321_difference_deg"] < 0.15
        # the correct model moves the spacecraft about twice as far
        assert 6.5e3 < s[f"correct_deg{n}_max_position_difference_m"] < 9.0e3
        assert 0.15 < s[f"correct_deg{n}_max_euler321_difference_deg"] < 0.3
        assert s[f"thesis_vs_correct_deg{n}_max_position_difference_m"] > 1.0e4
        # mostly along track: correct ahead, thesis behind; thesis stays in the plane
        assert s[f"correct_deg{n}_final_along_track_difference_m"] > 6.5e3
        assert s[f"thesis_deg{n}_final_along_track_difference_m"] < -3.0e3
        assert s[f"thesis_deg{n}_max_cross_track_difference_m"] < 1e-3
        assert s[f"correct_deg{n}_max_cross_track_difference_m"] > 300.0
    # degrees above 50 change little at 90 km
    a, b = (s[f"correct_deg{n}_max_position_difference_m"] for n in (50, 150))
    assert abs(a - b) < 0.01 * b
