"""McCann (2020) Eqs. 24–26 as printed: they differ from the truth by the documented amounts."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

from gmuk.errors import DefinitionError, DomainError
from gmuk.gravity import (
    normalization_4pi,
    thesis_eq24_degree_terms,
    thesis_eq25_radial_acceleration,
    thesis_eq26c_legendre,
    thesis_eq26c_normalization,
)


def test_eq26c_normalization_is_off_by_orders_of_magnitude():
    ratio = lambda n, p: float(thesis_eq26c_normalization(n, p) / normalization_4pi(n, p))  # noqa: E731
    for n in (1, 2, 5, 40):  # p = 0: √(n + ½)/√(2n + 1) = 1/√2 exactly
        assert abs(ratio(n, 0) - 1 / math.sqrt(2)) <= 1e-15
    assert abs(ratio(2, 1) - 1.118033988749895) <= 1e-14
    assert abs(ratio(2, 2) - 2.2022715545545246) <= 1e-14
    assert 7.5e8 < ratio(10, 10) < 7.7e8
    assert 4.7e78 < ratio(50, 50) < 4.9e78
    assert (
        8.6e306
        < float(thesis_eq26c_normalization(150, 150))
        / 1e-306
        * 1e-306
        / float(normalization_4pi(150, 150))
        < 8.8e306
    )
    # even the likely intended √((n + ½)(n−p)!/(n+p)!) is off by 1/√2 (p = 0) and 1/2 (p > 0)
    for n, p in ((3, 0), (3, 2), (7, 7)):
        intended = math.sqrt((n + 0.5) * math.factorial(n - p) / math.factorial(n + p))
        expected = 1 / math.sqrt(2) if p == 0 else 0.5
        assert abs(intended / float(normalization_4pi(n, p)) - expected) <= 1e-14


def test_eq26c_legendre_is_the_printed_product():
    """√(n + ½ (n−p)!/(n+p)!) · P_np(t), P_np from Eqs. 26a–b (mpmath, no CS phase)."""
    t = 0.42
    P = thesis_eq26c_legendre(6, t)
    for n in range(7):
        for p in range(n + 1):
            with mp.workdps(30):
                P_np = (-1) ** p * mp.legenp(n, p, mp.mpf(t), type=2)
                ref = mp.sqrt(n + mp.mpf(1) / 2 * mp.factorial(n - p) / mp.factorial(n + p)) * P_np
            assert abs(P[n, p] - float(ref)) <= 1e-13 * max(1.0, abs(float(ref)))


@pytest.fixture(scope="module")
def sphere_100km(grail):
    rng = np.random.default_rng(3)
    u = rng.normal(size=(2000, 3))
    return u / np.linalg.norm(u, axis=1)[:, None] * (grail.radius + 100e3)


def test_eq25_error_is_tangential_plus_twice_radial_perturbation(grail, sphere_100km):
    """Eq. 25 keeps only the radial derivative and flips the harmonic sum's sign: its error
    is a_t + 2 a_r exactly (a_t, a_r: tangential and radial parts of the perturbation)."""
    f = grail
    r = sphere_100km
    a = f.acceleration(r)
    pert = f.acceleration(r, central=False)
    a25 = thesis_eq25_radial_acceleration(f, r)
    rhat = r / np.linalg.norm(r, axis=1)[:, None]
    p_r = np.sum(pert * rhat, axis=1)[:, None] * rhat
    p_t = pert - p_r
    err = a - a25
    assert np.abs(err - (p_t + 2 * p_r)).max() <= 1e-9 * np.abs(pert).max()
    ratio = np.linalg.norm(err, axis=1) / np.linalg.norm(pert, axis=1)
    assert np.all(ratio >= 1 - 1e-9) and np.all(ratio <= 2 + 1e-9)
    # the figures quoted in gmuk.gravity.thesis (these 2000 points)
    assert abs(np.median(ratio) - 1.51) <= 0.005
    assert np.allclose(np.percentile(ratio, [5, 95]), [1.01, 1.96], atol=0.005)
    rms = np.sqrt(np.mean(np.sum(err**2, 1)) / np.mean(np.sum(pert**2, 1)))
    assert abs(rms - 1.63) <= 0.005
    tangential_energy = np.sum(p_t**2) / np.sum(pert**2)
    assert abs(tangential_energy - 0.45) <= 0.005
    median_tangential = np.median(np.linalg.norm(p_t, axis=1) / np.linalg.norm(pert, axis=1))
    assert abs(median_tangential - 0.76) <= 0.005


def test_eq25_with_eq26c_normalisation_is_wrong_by_orders_of_magnitude(grail, sphere_100km):
    f = grail.truncate(10)
    r = sphere_100km[:200]
    pert = f.acceleration(r, central=False)
    err = f.acceleration(r) - thesis_eq25_radial_acceleration(f, r, normalization="thesis_eq26c")
    assert np.median(np.linalg.norm(err, axis=1) / np.linalg.norm(pert, axis=1)) > 1e6


def test_eq24_degree_terms_rebuild_the_potential(grail):
    f = grail.truncate(60)
    r = np.array([[1.1e6, -0.9e6, 1.3e6], [0.0, 0.0, 1.9e6], [2.0e6, 0.0, 0.0]])
    T = thesis_eq24_degree_terms(f, r)
    rn = np.linalg.norm(r, axis=1)
    n = np.arange(61)
    U = f.mu / rn * np.sum((f.radius / rn)[:, None] ** n * T, axis=1)
    np.testing.assert_allclose(U, f.potential(r), rtol=1e-14)
    assert T.shape == (3, 61) and thesis_eq24_degree_terms(f, r[0]).shape == (61,)
    with pytest.raises(DefinitionError, match="normalization must be one of"):
        thesis_eq24_degree_terms(f, r, normalization="other")
    with pytest.raises(DomainError, match="origin"):
        thesis_eq24_degree_terms(f, [0.0, 0.0, 0.0])


def test_eq25_figures_at_degree_2_and_eq26c_at_degree_150(grail, sphere_100km):
    f = grail.truncate(2)
    r = sphere_100km
    pert = f.acceleration(r, central=False)
    err = f.acceleration(r) - thesis_eq25_radial_acceleration(f, r)
    ratio = np.linalg.norm(err, axis=1) / np.linalg.norm(pert, axis=1)
    assert abs(np.median(ratio) - 1.59) <= 0.005
    rms = np.sqrt(np.mean(np.sum(err**2, 1)) / np.mean(np.sum(pert**2, 1)))
    assert abs(rms - 1.66) <= 0.005
    a = thesis_eq25_radial_acceleration(grail, r[:3], normalization="thesis_eq26c")
    biggest = np.abs(a).max(axis=1)  # (the norm itself would overflow)
    assert np.all((biggest > 1e292) & (biggest < 1e297))
