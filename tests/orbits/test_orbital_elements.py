"""Orbital elements ↔ inertial state (gmuk.orbits.elements), for every conic."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gmuk.errors import NonFiniteError, OrbitError, ShapeError
from gmuk.lie import euler
from gmuk.orbits import (
    CIRCULAR_TOL,
    R_NP,
    elements_to_state,
    perifocal_state,
    state_to_elements,
)

MU_EARTH_KM = 398600.0e9  # m³/s², the value of Curtis's examples
MU = 4.9048695e12
TWO_PI = 2.0 * math.pi


def _angle_diff(a, b):
    return np.abs(np.remainder(np.asarray(a) - np.asarray(b) + math.pi, TWO_PI) - math.pi)


def test_textbook_example_curtis_4_3():
    # Curtis, Orbital Mechanics for Engineering Students, Example 4.3 (printed to 4 digits).
    r = np.array([-6045.0, -3490.0, 2500.0]) * 1e3
    v = np.array([-3.457, 6.618, 2.533]) * 1e3
    el = state_to_elements(r, v, MU_EARTH_KM)
    assert math.sqrt(el.p * MU_EARTH_KM) == pytest.approx(58310e6, rel=1e-4)
    assert math.degrees(el.i) == pytest.approx(153.2, abs=0.05)
    assert math.degrees(el.raan) == pytest.approx(255.3, abs=0.05)
    assert el.e == pytest.approx(0.1712, abs=5e-5)
    assert math.degrees(el.argp) == pytest.approx(20.07, abs=0.005)
    assert math.degrees(el.nu) == pytest.approx(28.45, abs=0.005)
    assert el.a == pytest.approx(8788e3, rel=1e-4)


def test_textbook_example_vallado_2_5():
    # Vallado, Fundamentals of Astrodynamics and Applications, Example 2-5 (RV2COE).
    mu = 398600.4418e9
    r = np.array([6524.834, 6862.875, 6448.296]) * 1e3
    v = np.array([4.901327, 5.533756, -1.976341]) * 1e3
    el = state_to_elements(r, v, mu)
    assert el.p == pytest.approx(11067.790e3, rel=2e-6)
    assert el.a == pytest.approx(36127.343e3, rel=2e-6)
    assert el.e == pytest.approx(0.832853, abs=1e-6)
    assert math.degrees(el.i) == pytest.approx(87.870, abs=1e-3)
    assert math.degrees(el.raan) == pytest.approx(227.89, abs=0.01)
    assert math.degrees(el.argp) == pytest.approx(53.38, abs=0.01)
    assert math.degrees(el.nu) == pytest.approx(92.335, abs=1e-3)


angles = st.floats(0.0, TWO_PI, exclude_max=True)


@settings(max_examples=300, deadline=None)
@given(
    rp=st.floats(1.8e6, 2e7),
    e=st.one_of(st.floats(1e-4, 0.97), st.floats(1.02, 6.0)),
    i=st.floats(1e-4, math.pi - 1e-4),
    raan=angles,
    argp=angles,
    u=st.floats(-0.95, 0.95),
)
def test_elements_state_elements_round_trip_for_ellipses_and_hyperbolas(rp, e, i, raan, argp, u):
    p = rp * (1.0 + e)
    nu = u * math.pi if e < 1.0 else u * math.acos(-1.0 / e)
    r, v = elements_to_state(None, e, i, raan, argp, nu, MU, p=p)
    el = state_to_elements(r, v, MU)
    assert el.p == pytest.approx(p, rel=1e-12)
    assert el.e == pytest.approx(e, rel=1e-10, abs=1e-12)
    assert el.i == pytest.approx(i, abs=1e-12)
    # ω and ν are individually ill-conditioned for e → 0 and Ω for i → 0 (their sums are not).
    assert _angle_diff(el.raan, raan) <= 1e-12 / math.sin(i)
    assert _angle_diff(el.argp + el.nu, argp + nu) <= 1e-11 / math.sin(i)
    assert _angle_diff(el.nu, nu) <= 1e-11 / e


def _random_states(rng, n):
    # Position and velocity of random orbits of every kind (bound and unbound).
    r = rng.normal(size=(n, 3)) * 4e6
    rn = np.linalg.norm(r, axis=1, keepdims=True)
    v_circ = np.sqrt(MU / rn)
    v = rng.normal(size=(n, 3)) * v_circ * rng.uniform(0.3, 1.0, (n, 1))
    return r, v


def test_state_elements_state_round_trip_including_special_orbits():
    rng = np.random.default_rng(7)
    r, v = _random_states(rng, 400)
    specials = []
    rc = 3e6
    vc = math.sqrt(MU / rc)
    for i, ecc in [(0.0, 0.0), (math.pi, 0.0), (0.0, 0.3), (math.pi, 0.3), (0.7, 0.0)]:
        for nu in (0.0, 1.0, 4.0):
            rr, vv = elements_to_state(None, ecc, i, 0.4, 1.3, nu, MU, p=rc)
            specials.append((rr, vv))
    specials.append((np.array([rc, 0.0, 0.0]), np.array([0.0, vc, 0.0])))  # circular, i = 0
    specials.append((np.array([rc, 0.0, 0.0]), np.array([0.0, -vc, 0.0])))  # circular, i = π
    r = np.concatenate([r, [s[0] for s in specials]])
    v = np.concatenate([v, [s[1] for s in specials]])
    el = state_to_elements(r, v, MU)
    r2, v2 = elements_to_state(None, el.e, el.i, el.raan, el.argp, el.nu, MU, p=el.p)
    np.testing.assert_allclose(r2, r, rtol=0, atol=1e-12 * np.abs(r).max())
    dv = np.linalg.norm(v2 - v, axis=1) / np.linalg.norm(v, axis=1)
    assert dv.max() <= 1e-11


def test_special_case_conventions():
    rc, f = 3e6, 1.1
    # Circular inclined: ω = 0 and ν is the argument of latitude u = ω + ν.
    r, v = elements_to_state(None, 0.0, 0.5, 2.0, 0.7, f, MU, p=rc)
    el = state_to_elements(r, v, MU)
    assert el.e < CIRCULAR_TOL
    assert el.argp == 0.0
    assert el.raan == pytest.approx(2.0, abs=1e-13)
    assert el.nu == pytest.approx(0.7 + f, abs=1e-12)
    # Prograde equatorial ellipse: Ω = 0 and ω is the longitude of periapsis Ω + ω.
    r, v = elements_to_state(None, 0.4, 0.0, 2.0, 0.7, f, MU, p=rc)
    el = state_to_elements(r, v, MU)
    assert (el.raan, el.i) == (0.0, 0.0)
    assert el.argp == pytest.approx(2.7, abs=1e-13)
    assert el.nu == pytest.approx(f, abs=1e-13)
    # Retrograde equatorial ellipse: Ω = 0 and ω is measured from N₁ about the angular
    # momentum (−N₃): it becomes ω − Ω (mod 2π).
    r, v = elements_to_state(None, 0.4, math.pi, 2.0, 0.7, f, MU, p=rc)
    el = state_to_elements(r, v, MU)
    assert el.raan == 0.0
    assert el.i == pytest.approx(math.pi, abs=1e-15)
    assert el.argp == pytest.approx((0.7 - 2.0) % TWO_PI, abs=1e-13)
    periapsis_dir = R_NP(2.0, math.pi, 0.7)[:, 0]
    np.testing.assert_allclose(R_NP(0.0, math.pi, el.argp)[:, 0], periapsis_dir, atol=1e-13)
    # Circular equatorial: Ω = ω = 0, ν is the true longitude (angle of r from N₁).
    r, v = elements_to_state(None, 0.0, 0.0, 2.0, 0.7, f, MU, p=rc)
    el = state_to_elements(r, v, MU)
    assert (el.raan, el.argp) == (0.0, 0.0)
    assert el.nu == pytest.approx(math.atan2(r[1], r[0]) % TWO_PI, abs=1e-13)


@settings(max_examples=200, deadline=None)
@given(
    p=st.floats(2e6, 2e7),
    e=st.floats(0.0, 4.0),
    i=st.floats(0.0, math.pi),
    raan=angles,
    argp=angles,
    u=st.floats(-0.95, 0.95),
)
def test_energy_angular_momentum_and_eccentricity_vector_match_the_elements(p, e, i, raan, argp, u):
    nu = u * (math.pi if e <= 1.0 else math.acos(-1.0 / e))
    r, v = elements_to_state(None, e, i, raan, argp, nu, MU, p=p)
    rn, vn = np.linalg.norm(r), np.linalg.norm(v)
    energy = 0.5 * vn**2 - MU / rn
    assert energy == pytest.approx(-MU * (1.0 - e * e) / (2.0 * p), rel=1e-11, abs=1e-11 * MU / p)
    h = np.cross(r, v)
    R = R_NP(raan, i, argp)
    np.testing.assert_allclose(h, math.sqrt(MU * p) * R[:, 2], rtol=0, atol=1e-12 * np.sqrt(MU * p))
    e_vec = np.cross(v, h) / MU - r / rn
    np.testing.assert_allclose(e_vec, e * R[:, 0], rtol=0, atol=1e-11)
    assert rn == pytest.approx(p / (1.0 + e * math.cos(nu)), rel=1e-14)


def test_semi_major_axis_and_semi_latus_rectum_describe_the_same_orbit():
    args = (0.3, 0.9, 1.0, 2.0, 0.5, MU)
    r_a, v_a = elements_to_state(5e6, *args)
    r_p, v_p = elements_to_state(None, *args, p=5e6 * (1 - 0.3**2))
    np.testing.assert_allclose(r_a, r_p, rtol=1e-15)
    np.testing.assert_allclose(v_a, v_p, rtol=1e-15)
    r_h, _ = elements_to_state(-5e6, 1.4, 0.9, 1.0, 2.0, 0.5, MU)
    r_hp, _ = elements_to_state(None, 1.4, 0.9, 1.0, 2.0, 0.5, MU, p=-5e6 * (1 - 1.4**2))
    np.testing.assert_allclose(r_h, r_hp, rtol=1e-15)


def test_parabola_from_p_has_zero_energy_and_is_recovered_with_e_one():
    r, v = elements_to_state(None, 1.0, 0.3, 0.2, 0.1, 2.0, MU, p=4e6)
    assert 0.5 * v @ v - MU / np.linalg.norm(r) == pytest.approx(0.0, abs=1e-12 * MU / 4e6)
    el = state_to_elements(r, v, MU)
    assert el.e == pytest.approx(1.0, abs=1e-14)
    assert el.nu == pytest.approx(2.0, abs=1e-13)
    assert abs(el.a) > 1e16


def test_elements_broadcast_over_leading_axes():
    nu = np.linspace(0.0, 6.0, 7)[:, None]
    e = np.array([0.0, 0.5, 0.9])
    r, v = elements_to_state(7e6, e, 0.4, 0.3, 0.2, nu, MU)
    assert r.shape == v.shape == (7, 3, 3)
    el = state_to_elements(r, v, MU)
    assert el.p.shape == (7, 3)
    np.testing.assert_allclose(el.e, np.broadcast_to(e, (7, 3)), atol=1e-12)


def test_rotation_NP_is_the_313_euler_rotation():
    rng = np.random.default_rng(3)
    ang = rng.uniform([0, 0, 0], [TWO_PI, math.pi, TWO_PI], size=(50, 3))
    R = R_NP(ang[:, 0], ang[:, 1], ang[:, 2])
    np.testing.assert_allclose(R, euler.to_matrix(ang, "313"), atol=1e-15)
    np.testing.assert_allclose(
        R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-15
    )


def test_perifocal_state_is_the_thesis_eq69_position():
    mu, p, e, f = MU, 3.84e6, 0.2, 0.8
    h = math.sqrt(mu * p)
    r_P, v_P = perifocal_state(p, e, f, mu)
    r69 = h**2 / (mu * (1 + e * math.cos(f))) * np.array([math.cos(f), math.sin(f), 0.0])
    np.testing.assert_allclose(r_P, r69, rtol=1e-15)
    # v = ṙ r̂ + r ḟ θ̂ with ḟ = h/r².
    rn = np.linalg.norm(r_P)
    v_expected = (mu / h) * e * math.sin(f) * r_P / rn + (h / rn) * np.array(
        [-math.sin(f), math.cos(f), 0.0]
    )
    np.testing.assert_allclose(v_P, v_expected, rtol=1e-14)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        (dict(a=4e6, e=-0.1), OrbitError, "e must be ≥ 0"),
        (dict(a=-4e6, e=0.2), OrbitError, "ellipse .* needs a > 0"),
        (dict(a=0.0, e=0.2), OrbitError, "ellipse .* needs a > 0"),
        (dict(a=4e6, e=1.5), OrbitError, "hyperbola .* needs a < 0"),
        (dict(a=4e6, e=1.0), OrbitError, "parabola .* give p"),
        (dict(a=4e6, e=0.2, p=3e6), OrbitError, "exactly one .* both"),
        (dict(a=None, e=0.2), OrbitError, "exactly one .* neither"),
        (dict(a=None, e=0.2, p=-1.0), OrbitError, "p must be > 0"),
        (dict(a=4e6, e=0.2, i=-0.1), OrbitError, r"i must lie in \[0, π\]"),
        (dict(a=4e6, e=0.2, mu=0.0), OrbitError, "mu must be > 0"),
        (dict(a=-4e6, e=2.0, nu=2.2), OrbitError, "beyond the asymptote"),
        (dict(a=None, e=1.0, p=1e6, nu=math.pi), OrbitError, "beyond the asymptote"),
        (dict(a=float("nan"), e=0.2), NonFiniteError, "a must be finite"),
        (dict(a=4e6, e=0.2, nu=float("inf")), NonFiniteError, "nu must be finite"),
    ],
)
def test_invalid_elements_raise_gmuk_errors_with_clear_messages(kwargs, error, match):
    full = dict(i=0.1, raan=0.2, argp=0.3, nu=0.4, mu=MU, p=None)
    full.update(kwargs)
    a, e = full.pop("a"), full.pop("e")
    with pytest.raises(error, match=match):
        elements_to_state(
            a, e, full["i"], full["raan"], full["argp"], full["nu"], full["mu"], p=full["p"]
        )


@pytest.mark.parametrize(
    ("r", "v", "error", "match"),
    [
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], OrbitError, "non-zero"),
        ([1e6, 0.0, 0.0], [2e3, 0.0, 0.0], OrbitError, "parallel"),
        ([1e6, 0.0], [0.0, 1e3, 0.0], ShapeError, r"r_N must have shape \(\.\.\., 3\)"),
        ([1e6, 0.0, float("nan")], [0.0, 1e3, 0.0], NonFiniteError, "r_N must be finite"),
    ],
)
def test_invalid_states_raise_gmuk_errors(r, v, error, match):
    with pytest.raises(error, match=match):
        state_to_elements(r, v, MU)
