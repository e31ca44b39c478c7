"""Field values against independent references: pyshtools, mpmath direct sums, finite
differences, Laplace's equation.

Measured (2026-11-22), relative to |a| for totals and to |a − a_central| for perturbations.
GRGM660PRIM at degrees 2–150 (50–500 km up) and EGM2008 at 2–70 (200–800 km up) against
pyshtools: total ≤ 7.5e-15 below latitude 89°, ≤ 6.7e-14 at ±89.9°; perturbation ≤ 1.7e-10
(GRAIL), 2.6e-11 (EGM2008); potential ≤ 8.5e-16. pyshtools' own error grows toward the poles:
at 89.999° its perturbation is off by 8.9e-9 where gmuk agrees with mpmath to 4.9e-15.
Exact poles (GRAIL, against mpmath): perturbation ≤ 2.8e-15. Degree 1200 (Kaula): exact
poles against mpmath ≤ 1.0e-15 (total), ≤ 1.7e-14 (perturbation), 6.2e-16 (Hessian);
equator and generic points against pyshtools ≤ 2.1e-14 (total), potential ≤ 1.9e-15.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

from .refs import (
    MpField,
    kaula_field,
    mp_gradient,
    mp_hessian,
    mp_potential,
    point,
    pysh_acceleration,
    pysh_potential,
)

pytest.importorskip("pyshtools")

LATLON = [(0, 0), (0, 90), (0, -170), (0, 179.9), (30, 45), (-45, -120), (60, 10), (89.9, 30)]
LATLON += [(-89.9, 200)]


def _points(radius, heights=(50e3, 100e3, 500e3)):
    return [point(radius + h, la, lo) for h in heights for la, lo in LATLON]


def _central(field, r):
    return -field.mu * r / np.linalg.norm(r) ** 3


def _check_against_pyshtools(field, points):
    worst_total = worst_pert = worst_pot = 0.0
    for r in points:
        a = field.acceleration(r)
        a_ref = pysh_acceleration(field, r)
        pert = field.acceleration(r, central=False)
        pert_ref = a_ref - _central(field, r)
        worst_total = max(worst_total, np.linalg.norm(a - a_ref) / np.linalg.norm(a))
        worst_pert = max(worst_pert, np.linalg.norm(pert - pert_ref) / np.linalg.norm(pert))
        u = field.potential(r)
        worst_pot = max(worst_pot, abs(u - pysh_potential(field, r)) / u)
    return worst_total, worst_pert, worst_pot


@pytest.mark.parametrize("degree", [2, 10, 50, 150])
def test_grail_acceleration_and_potential_match_pyshtools(grail, degree):
    field = grail.truncate(degree)
    total, pert, pot = _check_against_pyshtools(field, _points(field.radius))
    assert total <= 1e-12
    # pyshtools' perturbation is good to ~1e-10 at ±89.9° (see the arbitration below)
    assert pert <= 1e-9
    assert pot <= 1e-13


@pytest.mark.parametrize("degree", [2, 10, 70])
def test_egm2008_acceleration_and_potential_match_pyshtools(egm, degree):
    field = egm.truncate(degree)
    total, pert, pot = _check_against_pyshtools(field, _points(field.radius, (200e3, 800e3)))
    assert total <= 1e-12
    assert pert <= 1e-9
    assert pot <= 1e-13


def test_near_pole_gmuk_agrees_with_mpmath_where_pyshtools_drifts(grail):
    """At 89.999° pyshtools' tangential components lose digits (1/sin θ); mpmath arbitrates.

    Orders m contribute O((n cos φ)ᵐ/m!) there: orders ≤ 12 give the sum to 1e-25.
    """
    field = grail
    r = point(field.radius + 50e3, 89.999, -60.0)
    ref = mp_gradient(MpField(field, orders=range(13), dps=40, central=False), r)
    pert = field.acceleration(r, central=False)
    assert np.linalg.norm(pert - ref) / np.linalg.norm(ref) <= 1e-12
    pysh_pert = pysh_acceleration(field, r) - _central(field, r)
    assert np.linalg.norm(pysh_pert - ref) / np.linalg.norm(ref) > 1e-9  # pyshtools drifts


@pytest.mark.parametrize("sign", [1, -1])
def test_exact_poles_match_mpmath(grail, sign):
    """x = y = 0 exactly: only orders ≤ 2 are non-zero at the pole (≤ 4 kept for the
    finite differences); no division by cos φ anywhere in gmuk."""
    field = grail
    r = np.array([0.0, 0.0, sign * (field.radius + 100e3)])
    mf = MpField(field, orders=range(5), dps=40, central=False)
    ref_pert = mp_gradient(mf, r)
    pert = field.acceleration(r, central=False)
    assert np.linalg.norm(pert - ref_pert) / np.linalg.norm(ref_pert) <= 1e-12
    a = field.acceleration(r)
    assert np.linalg.norm(a - (ref_pert + _central(field, r))) / np.linalg.norm(a) <= 1e-15
    with mp.workdps(40):
        u_ref = float(mp_potential(MpField(field, orders=[0], dps=40), *map(mp.mpf, r)))
    assert abs(field.potential(r) - u_ref) / u_ref <= 1e-15


@pytest.fixture(scope="module")
def kaula1200():
    return kaula_field(1200, seed=1)


@pytest.mark.parametrize("sign", [1, -1])
def test_degree_1200_exact_poles_against_mpmath(kaula1200, sign):
    """Synthetic Kaula field C̄, S̄ ~ N(0, (1e-5/n²)²) to degree 1200, 50 km up, at a pole."""
    f = kaula1200
    r = np.array([0.0, 0.0, sign * (f.radius + 50e3)])
    mf = MpField(f, orders=range(5), dps=40, central=False)
    ref_pert = mp_gradient(mf, r)
    pert, a = f.acceleration(r, central=False), f.acceleration(r)
    assert np.linalg.norm(pert - ref_pert) / np.linalg.norm(ref_pert) <= 1e-11
    assert np.linalg.norm(a - ref_pert - _central(f, r)) / np.linalg.norm(a) <= 1e-14
    if sign == 1:  # one Hessian: 19 mpmath sums of 4 × 1200 terms; 60 digits, as the
        # second differences with h = 1e-15 r lose 30 of them
        H_ref = mp_hessian(MpField(f, orders=range(4), dps=60), r)
        H = f.hessian(r)
        assert np.abs(H - H_ref).max() / np.abs(H_ref).max() <= 1e-13


@pytest.mark.parametrize(("lat", "lon"), [(0.0, 10.0), (0.0, -170.0), (37.0, 123.0), (68.4, 200.0)])
def test_degree_1200_against_pyshtools(kaula1200, lat, lon):
    """Equator and generic points; at 68.4° (cos φ ≈ 1/e) the column values pass 2^480 and
    the seeds fall below 2^-480, so the extended-exponent paths run."""
    f = kaula1200
    r = point(f.radius + 50e3, lat, lon)
    a = f.acceleration(r)
    assert np.linalg.norm(a - pysh_acceleration(f, r)) / np.linalg.norm(a) <= 1e-12
    u = f.potential(r)
    assert abs(u - pysh_potential(f, r)) / u <= 1e-13


def test_extended_exponents_keep_a_term_whose_seed_underflows():
    """A single term C̄[2700, 993] at 68.4°: the sectoral seed ~ cos⁹⁹³ φ ≈ 1e-431 is not a
    double, yet the term P̄_{2700,993}(sin φ) is of order 1 (m ≈ n cos φ). Without extended
    exponents the term would vanish and only the central term remain."""
    from gmuk.gravity import MOON_MU, MOON_RADIUS, SphericalHarmonicField

    N, m = 2700, 993
    C = np.zeros((N + 1, N + 1))
    S = np.zeros((N + 1, N + 1))
    C[0, 0] = 1.0
    C[N, m] = 1e-4
    S[N, m] = -3e-5
    f = SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S)
    r = point(MOON_RADIUS * 1.0001, 68.4, 17.0)
    ref = mp_gradient(MpField(f, orders=[m], dps=40), r)
    pert = f.acceleration(r, central=False)
    assert np.linalg.norm(ref) > 1e-4 * np.linalg.norm(_central(f, r))  # a sizeable term
    assert np.linalg.norm(pert - ref) / np.linalg.norm(ref) <= 1e-11
    with mp.workdps(40):
        u_ref = float(mp_potential(MpField(f, orders=[m], dps=40), *map(mp.mpf, r)))
    assert abs(f.potential(r, central=False) - u_ref) <= 1e-11 * abs(u_ref)


@pytest.mark.slow
@pytest.mark.parametrize("lat", [68.4, 75.0, 85.0, 45.0])
def test_degree_2700_against_pyshtools(lat):
    """Beyond degree ~1900 plain doubles underflow at mid-latitudes (e^{-n/e} < 1e-308)."""
    f = kaula_field(2700, seed=2)
    r = point(f.radius + 20e3, lat, 33.0)
    a = f.acceleration(r)
    assert np.linalg.norm(a - pysh_acceleration(f, r)) / np.linalg.norm(a) <= 1e-12


@pytest.mark.slow
@pytest.mark.parametrize(("lat", "lon"), [(0.0, -170.0), (37.0, 123.0)])
def test_degree_400_perturbation_against_full_mpmath_sum(lat, lon):
    """Every order summed in mpmath: gmuk's perturbation to 1e-14 (pyshtools: 1e-10)."""
    f = kaula_field(400, seed=1)
    r = point(f.radius + 50e3, lat, lon)
    ref = mp_gradient(MpField(f, dps=30, central=False), r)
    pert = f.acceleration(r, central=False)
    assert np.linalg.norm(pert - ref) / np.linalg.norm(ref) <= 1e-13


# --------------------------------------------------------------------- Hessian, gradient


def _fd_jacobian(fun, r, h):
    return np.array([(fun(r + h * e) - fun(r - h * e)) / (2 * h) for e in np.eye(3)]).T


@pytest.mark.parametrize("degree", [2, 50, 150])
def test_hessian_matches_finite_differences_and_laplace(grail, degree):
    f = grail.truncate(degree)
    pole = np.array([0.0, 0.0, f.radius + 70e3])
    for r in [*_points(f.radius, (50e3, 300e3))[::2], pole]:
        H = f.hessian(r)
        rn = np.linalg.norm(r)
        central_scale = 2 * f.mu / rn**3  # norm of the central term's Hessian
        # central differences of the acceleration, step 1 m: error (n h / r)² ~ 1e-8 of the
        # degree-n part; compare with 1e-9 of the central scale
        H_fd = _fd_jacobian(f.acceleration, r, 1.0)
        assert np.abs(H - H_fd).max() <= 1e-9 * central_scale
        assert np.array_equal(H, H.T)
        assert abs(np.trace(H)) <= 1e-15 * central_scale
        # the perturbation Hessian alone, against differences of the perturbation
        Hp = f.hessian(r, central=False)
        Hp_fd = _fd_jacobian(lambda q: f.acceleration(q, central=False), r, 1.0)
        assert np.abs(Hp - Hp_fd).max() <= 1e-6 * np.abs(Hp).max()


def test_gradient_of_potential_is_the_acceleration(grail):
    f = grail.truncate(50)
    for r in _points(f.radius, (100e3,)):
        g_fd = np.array(
            [(f.potential(r + e) - f.potential(r - e)) / 2.0 for e in np.eye(3)]
        )  # step 1 m
        a = f.acceleration(r)
        assert np.abs(a - g_fd).max() <= 1e-8 * np.linalg.norm(a)


def test_central_term_alone_is_the_point_mass(grail):
    f = grail.truncate(0)
    r = np.array([1.2e6, -0.7e6, 1.5e6])
    rn = np.linalg.norm(r)
    np.testing.assert_allclose(f.acceleration(r), -f.mu * r / rn**3, rtol=1e-15, atol=0)
    np.testing.assert_allclose(f.potential(r), f.mu / rn, rtol=1e-15)
    H_ref = f.mu * (3 * np.outer(r, r) / rn**5 - np.eye(3) / rn**3)
    assert np.abs(f.hessian(r) - H_ref).max() <= 1e-15 * np.abs(H_ref).max()
