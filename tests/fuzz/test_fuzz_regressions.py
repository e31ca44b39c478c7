"""Regression tests for what the issue #25 fuzz found at the public boundary and gmuk now
does (one test per behaviour)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import gmuk
from gmuk import orbits
from gmuk.errors import ConstraintError, DefinitionError, DegreeError, ShapeError
from gmuk.gravity import SphericalHarmonicField, legendre_4pi
from gmuk.view import decimate, view_html, write_view


@pytest.mark.filterwarnings("error")
def test_parabolic_from_mean_stays_finite_for_mean_anomalies_near_float_max():
    M = np.array([1e308, -1e308, 1e101])
    D = orbits.parabolic_from_mean(M)
    assert np.isfinite(D).all() and np.array_equal(np.sign(D), np.sign(M))
    np.testing.assert_allclose(orbits.mean_from_parabolic(D[2:]), M[2:], rtol=1e-12)


@pytest.mark.parametrize("t", ["", "0.5", [True], 0.5j])
def test_legendre_4pi_refuses_cosines_that_are_not_real_numbers(t):
    with pytest.raises(ShapeError, match="t must be"):
        legendre_4pi(3, t)


@pytest.mark.parametrize("nmax", [10**6, 10**400])
def test_legendre_4pi_refuses_a_degree_too_large_to_allocate(nmax):
    with pytest.raises(DegreeError, match="refused before allocating"):
        legendre_4pi(nmax, 0.1)


def test_a_field_refuses_a_mu_beyond_float64_with_a_definition_error():
    with pytest.raises(DefinitionError, match="mu must be finite"):
        SphericalHarmonicField(-(10**400), 1.0, [[1.0]], [[0.0]])


@pytest.mark.parametrize(("mu", "radius"), [("1.0", 1.0), (True, 1.0), (1.0, "1.0"), (1.0, True)])
def test_a_field_refuses_a_mu_or_radius_given_as_a_string_or_bool(mu, radius):
    with pytest.raises(DefinitionError, match="must be a number > 0"):
        SphericalHarmonicField(mu, radius, [[1.0]], [[0.0]])


def test_a_field_refuses_coefficients_beyond_float64_with_a_shape_error():
    with pytest.raises(ShapeError, match="C must be a numeric array"):
        SphericalHarmonicField(1.0, 1.0, [[10**400]], [[0.0]])


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("Moon", "", 1.0), "mu must be"),
        (("Moon", 1j, 1.0), "mu must be"),
        (("Moon", 10**400, 1.0), "mu must be"),
        (("Moon", 1.0, True), "radius must be"),
        ((object(), 1.0, 1.0), "name must be a non-empty string"),
    ],
)
def test_celestial_body_refuses_constants_that_are_not_real_positive_numbers(args, message):
    with pytest.raises(DefinitionError, match=message):
        gmuk.CelestialBody(*args)


@pytest.mark.parametrize("rate", [True, "1e-6", 1e-6j, 10**400])
def test_uniform_rotation_refuses_a_rate_that_is_not_a_real_number(rate):
    with pytest.raises(DefinitionError, match="rotation rate must be"):
        gmuk.UniformRotation(rate)


@pytest.mark.parametrize(
    ("n", "most"), [("", 0), (np.array(9.3), 5), (10, 2.5), (10, True), (10**400, 5), (5, 10**400)]
)
def test_decimate_refuses_counts_that_are_not_integers(n, most):
    with pytest.raises(DefinitionError):
        decimate(n, most)


def _traj():
    system = gmuk.System([gmuk.RigidBody("a", 1.0, np.eye(3))])
    state = system.state(g={"a": np.eye(4)}, V={"a": np.array([0.1, 0, 0, 1, 0, 0])})
    return system.simulate(state, (0.0, 0.1), t_eval=np.linspace(0, 0.1, 3))


@pytest.mark.parametrize(
    "kwargs",
    [
        {"title": True},
        {"title": b"x"},
        {"max_frames": b"x"},
        {"triad_length": 10**400},
        {"central_radius": "1"},
    ],
)
def test_view_html_refuses_titles_and_options_of_the_wrong_type(kwargs):
    with pytest.raises(DefinitionError):
        view_html(_traj(), **kwargs)


@pytest.mark.parametrize("path", [b"view.html", 3, None])
def test_write_view_refuses_a_path_that_is_not_a_str_or_path(path):
    with pytest.raises(DefinitionError, match="path must be a str or a Path"):
        write_view(_traj(), path)


# ---------------------------------------------------------------- issue #25, second round
class _Scripted(gmuk.InequalityConstraint):
    """h = whatever ``make`` returns (an InequalityConstraint whose value() is hostile)."""

    def __init__(self, make):
        super().__init__(["a"], lower=-10.0, name="scripted")
        self.make = make

    def value(self, q, nu, t):
        return self.make()


def _bounded_point(make):
    return gmuk.System([gmuk.PointMass("a", 1.0)], [_Scripted(make)])


@pytest.mark.parametrize(
    "h",
    ["1.0", True, np.True_, b"", object(), None, 1j, np.array("1.0"), np.array(True), [1.0]],
    ids=lambda h: "object()" if type(h) is object else repr(h),  # stable across workers
)
def test_inequality_value_that_is_not_a_real_number_is_refused_naming_constraint_and_time(h):
    system = _bounded_point(lambda: h)
    with pytest.raises(ConstraintError, match="must be a") as info:
        system.state(r={"a": [1.0, 0, 0]}, v={"a": [0, 0, 0]})
    assert "'scripted'" in str(info.value) and "t = 0.0" in str(info.value)


@pytest.mark.parametrize("h", [float("nan"), -np.inf, 10**400], ids=repr)
def test_inequality_value_that_is_not_finite_is_refused_naming_constraint_and_time(h):
    system = _bounded_point(lambda: h)
    with pytest.raises(ConstraintError, match="not finite") as info:
        system.state(r={"a": [1.0, 0, 0]}, v={"a": [0, 0, 0]})
    assert "'scripted'" in str(info.value) and "t = 0.0" in str(info.value)


@pytest.mark.parametrize("h", [1.0, 1, np.float32(1.0), np.int64(1), np.array(1.0)], ids=repr)
def test_inequality_value_as_any_real_number_type_gives_the_slack_of_the_float(h):
    state = _bounded_point(lambda: h).state(r={"a": [1.0, 0, 0]}, v={"a": [0, 0, 0]})
    assert state.x[3] == np.sqrt(11.0)


@pytest.mark.filterwarnings("error")
def test_plane_bound_normal_near_float_max_is_normalised_without_overflow():
    bound = gmuk.PlaneBound("a", [1e308, 1e308, 0.0], lower=0.0)
    np.testing.assert_allclose(bound.normal, [2**-0.5, 2**-0.5, 0.0], rtol=1e-15)


@pytest.mark.parametrize("i", ["b0", {}, None, 0.0, True, 1j, [0], np.array(1)], ids=repr)
def test_trajectory_state_refuses_an_index_that_is_not_an_integer(i):
    with pytest.raises(DefinitionError, match="output index"):
        _traj().state(i)


def test_trajectory_state_takes_python_and_numpy_integers():
    traj = _traj()
    assert traj.state(np.int64(-1)).t == traj.t[-1] and traj.state(1).t == traj.t[1]


@pytest.mark.parametrize("argv", [["--help"], ["list", "-h"], ["check", "--help"]])
def test_cli_help_returns_status_0_instead_of_raising_system_exit(argv, capsys):
    from gmuk import cli

    assert cli.main(argv) == 0
    assert "usage: gmuk" in capsys.readouterr().out


def campaign_metrics(params):
    """A campaign function (importable by name)."""
    return {"y": 2.0 * params["x"]}


@pytest.mark.parametrize("role", ["fixed", "dispersions", "grid"])
@pytest.mark.parametrize("value", [1j, Ellipsis, b"x", "x", 3], ids=repr)
def test_campaign_refuses_fixed_dispersions_or_grid_that_are_not_mappings(role, value):
    from gmuk.campaign import Campaign

    with pytest.raises(DefinitionError, match=f"{role} must be a mapping"):
        Campaign.from_function(campaign_metrics, {"x": 1.0}, runs=2, **{role: value})


@pytest.mark.parametrize("n", [10**400, 10**6 + 1])
def test_check_refuses_a_sample_count_it_cannot_allocate_before_allocating(n):
    with pytest.raises(DefinitionError, match="n must be at most"):
        gmuk.check(n=n)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize(
    ("M", "e"), [(0.2, 1e308), (0.2, 1.7976931348623157e308), (1e308, 1.0000001), (1e308, 1.5)]
)
def test_hyperbolic_from_mean_stays_finite_for_eccentricities_or_anomalies_near_float_max(M, e):
    H = orbits.hyperbolic_from_mean(M, e)
    assert np.isfinite(H) and H > 0
    np.testing.assert_allclose(orbits.mean_from_hyperbolic(H, e), M, rtol=1e-13)


@pytest.mark.parametrize("t", [None, "1.0", True, 1j, np.array("1.0")], ids=repr)
def test_lvlh_reference_refuses_a_time_that_is_not_a_real_number(t):
    ref = orbits.LVLHReference(orbits.fccn_orbit())
    with pytest.raises(DefinitionError, match="t \\(s\\) must be a real number"):
        ref.evaluate(t)


def test_lvlh_reference_takes_integer_and_numpy_times_as_the_float():
    ref = orbits.LVLHReference(orbits.fccn_orbit())
    want = ref.evaluate(3.0).g.copy()
    for t in (3, np.int64(3), np.float32(3.0), np.array(3.0)):
        assert np.array_equal(ref.evaluate(t).g, want)


@pytest.mark.parametrize("gain", [np.array("1.1"), np.array(True), np.array(1j)], ids=repr)
def test_morse_lyapunov_refuses_a_0d_array_of_strings_booleans_or_complex_numbers(gain):
    body = gmuk.RigidBody("sc", 1.0, np.eye(3))
    ref = orbits.LVLHReference(orbits.fccn_orbit())
    with pytest.raises(DefinitionError, match="k11 must be a"):
        gmuk.MorseLyapunovController(body, ref, k11=gain)


@pytest.mark.filterwarnings("error")
def test_view_html_draws_a_central_body_of_radius_near_float_max_without_overflow():
    page = view_html(_traj(), central_radius=1e308)
    assert page.count("</html>") == 1


def test_write_view_refuses_a_path_under_a_regular_file(tmp_path):
    (tmp_path / "f").write_text("not a folder")
    with pytest.raises(DefinitionError, match="is a file, not a folder"):
        write_view(_traj(), tmp_path / "f" / "view.html")
    assert (tmp_path / "f").read_text() == "not a folder"


@pytest.mark.parametrize("argv", [["run", "-h"], ["run", "-h", "check"]])
def test_cli_run_help_returns_status_0_instead_of_raising_system_exit(argv, capsys):
    from gmuk import cli

    assert cli.main(argv) == 0
    assert "usage:" in capsys.readouterr().out


@pytest.mark.parametrize("args", [(10**400, 1.0), (0.0, -(10**400))])
@pytest.mark.parametrize("kind", ["Normal", "Uniform"])
def test_campaign_dispersions_refuse_integers_beyond_float64(kind, args):
    from gmuk import campaign

    with pytest.raises(DefinitionError, match="must be finite"):
        getattr(campaign, kind)(*args)


@pytest.mark.parametrize(
    ("name", "value"), [("x", 10**400), ("x", -(10**400)), ("n", 10**400), ("v", (10**400, 0, 0))]
)
def test_campaign_parameter_values_beyond_float64_are_refused_as_not_finite(name, value):
    from gmuk.campaign import Campaign, Parameter

    params = {
        "x": 1.0,
        "n": Parameter("n", "integer", 3, "an integer", low=0, high=100),
        "v": (1.0, 0.0, 0.0),
    }
    with pytest.raises(DefinitionError, match="must be finite"):
        Campaign.from_function(campaign_metrics, params, runs=2, fixed={name: value})


def test_a_perifocal_state_that_overflows_float64_is_an_orbit_error():
    from gmuk.errors import OrbitError
    from gmuk.orbits import elements_to_state

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning on the way
        with pytest.raises(OrbitError, match="not finite"):
            elements_to_state(None, 1.7976931348623157e308, 1e-36, 0, 0, 0, 3.986e14, p=1000.0)
