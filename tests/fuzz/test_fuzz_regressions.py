"""Regression tests for what the issue #25 fuzz found at the public boundary and gmuk now
does (one test per behaviour)."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk import orbits
from gmuk.errors import DefinitionError, DegreeError, ShapeError
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
