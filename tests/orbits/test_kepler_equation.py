"""Kepler's equation and the anomaly conversions of gmuk.orbits.kepler (all conics)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gmuk.errors import NonFiniteError, OrbitError
from gmuk.orbits import kepler

try:  # the 50-digit references need mpmath; the other tests run without it
    import mpmath as mp
except ImportError:  # pragma: no cover
    mp = None
else:
    mp.mp.dps = 50

needs_mpmath = pytest.mark.skipif(mp is None, reason="mpmath is needed for 50-digit references")

TWO_PI = 2.0 * math.pi
EPS = np.finfo(float).eps


def same_to_ulps(a: float, b: float, ulps: int = 2) -> bool:
    """a and b equal to within ``ulps`` units in the last place of the larger."""
    b = float(b)
    return abs(a - b) <= ulps * math.ulp(max(abs(a), abs(b)))


def _mp_kepler(M: float, e: float, start: float):
    """The root of E − e sin E = M for the exact binary values of M and e, to 45 digits."""
    return mp.findroot(lambda E: E - mp.mpf(e) * mp.sin(E) - mp.mpf(M), mp.mpf(start), tol=1e-90)


def _mean_anomaly_grid() -> np.ndarray:
    rng = np.random.default_rng(20200801)
    near = np.geomspace(1e-12, 0.3, 40)
    return np.concatenate(
        [
            [0.0, 5e-324, 1e-300, math.pi, np.nextafter(math.pi, 0.0), np.nextafter(math.pi, 4.0)],
            [TWO_PI, np.nextafter(TWO_PI, 0.0), -1e-9, -3.0, -TWO_PI + 1e-7],
            near,  # approaching periapsis from above …
            TWO_PI - near,  # … and from below (M → 2π⁻)
            rng.uniform(0.0, TWO_PI, 120),
        ]
    )


@needs_mpmath
@pytest.mark.parametrize("e", [0.0, 1e-12, 1e-3, 0.1, 0.5, 0.9, 0.97, 0.99, 0.999, 0.999999])
def test_eccentric_anomaly_matches_a_50_digit_solution_for_all_mean_anomalies(e):
    M = _mean_anomaly_grid()
    E = kepler.eccentric_from_mean(M, e)
    E_ref = [_mp_kepler(m, e, x) for m, x in zip(M, E, strict=True)]
    abs_err = np.array([abs(float(r - mp.mpf(float(x)))) for r, x in zip(E_ref, E, strict=True)])
    scale = np.array([max(abs(float(r)), 1e-300) for r in E_ref])
    # The requirement: 1e-15 in E relative to π, for every M in [−2π, 2π] ...
    assert abs_err.max() <= 1e-15 * math.pi
    # ... and in fact a few units in the last place of E itself, even for tiny E at e → 1.
    assert (abs_err / scale).max() <= 4 * EPS


@needs_mpmath
@pytest.mark.parametrize("e", [0.2, 0.99])
def test_large_mean_anomalies_keep_their_revolution_and_full_precision(e):
    M = np.array([2 * math.pi * 3 + 0.5, -2 * math.pi * 7 - 1e-6, 1000.0, 123456.789, -9.9e6])
    E = kepler.eccentric_from_mean(M, e)
    for m, x in zip(M, E, strict=True):
        ref = _mp_kepler(m, e, x)
        assert abs(float(ref - mp.mpf(float(x)))) <= np.spacing(abs(x))
    assert np.all(np.abs(E - M) <= e)


def test_eccentric_anomaly_is_continuous_and_increasing_across_revolutions():
    M = np.linspace(-13.0, 13.0, 20001)  # crosses 0, ±2π, ±4π
    for e in (0.0, 0.5, 0.99):
        E = kepler.eccentric_from_mean(M, e)
        assert np.all(np.diff(E) > 0.0)
        f = kepler.true_from_eccentric(E, e)
        assert np.all(np.diff(f) > 0.0)
    k = np.arange(-3, 4)
    np.testing.assert_allclose(kepler.eccentric_from_mean(TWO_PI * k, 0.7), TWO_PI * k, atol=4e-15)
    np.testing.assert_allclose(kepler.true_from_mean(TWO_PI * k, 0.7), TWO_PI * k, atol=4e-15)


def test_solver_broadcasts_mean_anomaly_against_eccentricity():
    M = np.linspace(0.0, 6.0, 5)[:, None]
    e = np.array([0.0, 0.3, 0.95])
    E = kepler.eccentric_from_mean(M, e)
    assert E.shape == (5, 3)
    np.testing.assert_allclose(E - e * np.sin(E), np.broadcast_to(M, (5, 3)), rtol=0, atol=5e-15)
    assert kepler.eccentric_from_mean(1.0, 0.5).shape == ()


@settings(max_examples=300, deadline=None)
@given(
    M=st.floats(-50.0, 50.0, allow_nan=False, allow_infinity=False),
    e=st.floats(0.0, 0.999, exclude_max=False),
)
def test_the_vectorised_solver_is_the_scalar_one_applied_to_every_element(M, e):
    # One definition: the vectorised function applies the compiled scalar function.
    assert kepler.eccentric_from_mean_scalar(M, e) == kepler.eccentric_from_mean(M, e)
    out = kepler.eccentric_from_mean(np.array([M, -M, 3.0 * M]), e)
    assert out.tolist() == [kepler.eccentric_from_mean_scalar(x, e) for x in (M, -M, 3.0 * M)]


@settings(max_examples=300, deadline=None)
@given(
    E=st.floats(-40.0, 40.0, allow_nan=False, allow_infinity=False),
    e=st.floats(0.0, 0.99),
)
def test_mean_to_eccentric_round_trip(E, e):
    M = kepler.mean_from_eccentric(E, e)
    back = kepler.eccentric_from_mean(M, e)
    # dE/dM = 1/(1 − e cos E) ≤ 100 amplifies the rounding of M.
    assert abs(back - E) <= 4 * EPS * max(abs(E), 1.0) / (1.0 - e * math.cos(E))


@settings(max_examples=300, deadline=None)
@given(
    f=st.floats(-40.0, 40.0, allow_nan=False, allow_infinity=False),
    e=st.floats(0.0, 0.99),
)
def test_true_to_eccentric_to_mean_round_trips_on_the_same_revolution(f, e):
    E = kepler.eccentric_from_true(f, e)
    assert abs(E - f) < math.pi
    np.testing.assert_allclose(kepler.true_from_eccentric(E, e), f, rtol=0, atol=1e-13)
    M = kepler.mean_from_true(f, e)
    # df/dM = (1 + e cos f)² / (1 − e²)^{3/2} (up to 1.4e3 at e = 0.99 near periapsis) amplifies
    # the rounding of M, whose ulp grows with the revolution count |M|/2π.
    df_dM = (1.0 + e * math.cos(f)) ** 2 / (1.0 - e * e) ** 1.5
    bound = 4 * EPS * (max(abs(M), 1.0) * df_dM + max(abs(f), 1.0))
    assert abs(kepler.true_from_mean(M, e) - f) <= bound


@settings(max_examples=200, deadline=None)
@given(E=st.floats(-3.1, 3.1), e=st.floats(0.0, 0.99))
def test_half_angle_form_equals_thesis_eq78(E, e):
    f_thesis = 2.0 * math.atan(math.tan(E / 2.0) * math.sqrt((1.0 + e) / (1.0 - e)))
    f = float(kepler.true_from_eccentric(E, e))
    assert abs(math.remainder(f - f_thesis, TWO_PI)) <= 1e-13


def test_true_anomaly_by_the_geometry_of_the_ellipse():
    # Independent of any anomaly formula: position on the ellipse from E (x = a(cos E − e),
    # y = b sin E) gives f as a polar angle.
    a, e = 1.0, 0.6
    E = np.linspace(-3.0, 3.0, 61)
    x = a * (np.cos(E) - e)
    y = a * math.sqrt(1 - e * e) * np.sin(E)
    np.testing.assert_allclose(kepler.true_from_eccentric(E, e), np.arctan2(y, x), atol=1e-14)


# ------------------------------------------------------------------------------ hyperbola


@needs_mpmath
@pytest.mark.parametrize("e", [1.0 + 1e-9, 1.001, 1.5, 3.0, 30.0])
def test_hyperbolic_anomaly_matches_a_50_digit_solution(e):
    M = np.concatenate([[0.0], np.geomspace(1e-10, 1e6, 60), -np.geomspace(1e-6, 1e3, 5)])
    H = kepler.hyperbolic_from_mean(M, e)
    assert H[0] == 0.0
    for m, x in zip(M[1:], H[1:], strict=True):
        ref = mp.findroot(lambda h, m=m: mp.mpf(e) * mp.sinh(h) - h - mp.mpf(m), mp.mpf(float(x)))
        assert abs(float((ref - mp.mpf(float(x))) / ref)) <= 4 * EPS
        assert same_to_ulps(kepler.hyperbolic_from_mean_scalar(float(m), e), x)


@settings(max_examples=200, deadline=None)
@given(u=st.floats(-0.999, 0.999), e=st.floats(1.001, 20.0))
def test_hyperbolic_true_anomaly_round_trips(u, e):
    f = u * math.acos(-1.0 / e)
    H = kepler.hyperbolic_from_true(f, e)
    np.testing.assert_allclose(kepler.true_from_hyperbolic(H, e), f, rtol=1e-12, atol=1e-14)
    M = kepler.mean_from_hyperbolic(H, e)
    np.testing.assert_allclose(kepler.hyperbolic_from_mean(M, e), H, rtol=1e-12, atol=1e-14)


def test_hyperbolic_true_anomaly_beyond_the_asymptote_is_rejected():
    e = 2.0
    with pytest.raises(OrbitError, match="arccos"):
        kepler.hyperbolic_from_true(math.acos(-1.0 / e) + 1e-9, e)


# ------------------------------------------------------------------------------ parabola


@needs_mpmath
def test_barker_closed_form_solves_the_cubic_to_full_precision():
    M = np.concatenate([[0.0], np.geomspace(1e-300, 1e30, 80), -np.geomspace(1e-8, 1e8, 9)])
    D = kepler.parabolic_from_mean(M)
    assert D[0] == 0.0
    for m, d in zip(M[1:], D[1:], strict=True):
        ref = mp.findroot(lambda x, m=m: x + x**3 / 3 - mp.mpf(m), mp.mpf(float(d)))
        assert abs(float((ref - mp.mpf(float(d))) / ref)) <= 2 * EPS
        assert abs(kepler.parabolic_from_mean_scalar(float(m)) - d) <= 2 * np.spacing(abs(d))


@settings(max_examples=200, deadline=None)
@given(f=st.floats(-3.1, 3.1))
def test_parabolic_anomalies_round_trip(f):
    D = kepler.parabolic_from_true(f)
    M = kepler.mean_from_parabolic(D)
    np.testing.assert_allclose(
        kepler.true_from_parabolic(kepler.parabolic_from_mean(M)), f, rtol=1e-13, atol=1e-15
    )


# ------------------------------------------------------------------------------ wrapping


def test_wrapping_helpers_return_the_documented_ranges():
    x = np.array([-1e-300, -TWO_PI, -math.pi, 0.0, math.pi, 3 * math.pi, 100.0])
    w = kepler.wrap_to_2pi(x)
    assert np.all((w >= 0.0) & (w < TWO_PI))
    p = kepler.wrap_to_pi(x)
    assert np.all((p > -math.pi) & (p <= math.pi))
    np.testing.assert_allclose(np.sin(w), np.sin(x), atol=1e-13)
    np.testing.assert_allclose(np.cos(p), np.cos(x), atol=1e-13)


# ------------------------------------------------------------------------------ errors


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (lambda: kepler.eccentric_from_mean(1.0, -0.1), OrbitError, "0 ≤ e < 1"),
        (lambda: kepler.eccentric_from_mean(1.0, 1.0), OrbitError, "0 ≤ e < 1"),
        (lambda: kepler.true_from_mean([1.0, 2.0], [0.2, 1.5]), OrbitError, r"e = 1\.5"),
        (lambda: kepler.hyperbolic_from_mean(1.0, 1.0), OrbitError, "e > 1"),
        (lambda: kepler.eccentric_from_mean(float("nan"), 0.1), NonFiniteError, "M must be"),
        (lambda: kepler.eccentric_from_mean(1.0, float("nan")), NonFiniteError, "e must be"),
        (lambda: kepler.parabolic_from_true(math.pi), OrbitError, re.escape("|f| < π")),
    ],
)
def test_invalid_input_raises_gmuk_errors_with_clear_messages(call, error, match):
    with pytest.raises(error, match=match):
        call()
