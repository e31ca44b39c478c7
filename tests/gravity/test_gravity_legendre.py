"""Fully normalised Legendre functions: pyshtools, mpmath, orthonormality, normalisation."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

from gmuk.errors import DegreeError, DomainError, NonFiniteError, ShapeError
from gmuk.gravity import legendre_4pi, normalization_4pi

T_VALUES = [-1.0, -0.9999999, -0.3, 0.0, 0.5, 0.99, 1.0]


def _pysh_table(nmax, t):
    pysh = pytest.importorskip("pyshtools")
    flat = pysh.legendre.PlmBar(nmax, t)
    P = np.zeros((nmax + 1, nmax + 1))
    n, m = np.tril_indices(nmax + 1)
    P[n, m] = flat[n * (n + 1) // 2 + m]
    return P


@pytest.mark.parametrize("t", T_VALUES)
def test_matches_pyshtools_plmbar(t):
    nmax = 200
    P = legendre_4pi(nmax, t)
    ref = _pysh_table(nmax, t)
    scale = np.sqrt(2 * (2 * np.arange(nmax + 1) + 1))[:, None]  # bound on |P̄_nm|
    assert np.abs(P - ref).max() <= 1e-13 * scale.max()
    assert np.all(np.abs(P - ref) <= 1e-13 * scale)
    assert np.all(np.triu(P, 1) == 0)


def test_degree_2000_near_the_pole_against_pyshtools():
    """PlmBar scales by 1e-280 (Holmes & Featherstone) and is good to degree ~2800."""
    t = math.sin(math.radians(89.5))
    P = legendre_4pi(2000, t)
    ref = _pysh_table(2000, t)
    assert np.all(np.isfinite(P))
    assert np.abs(P - ref).max() <= 1e-12 * np.sqrt(2 * 4001)


@pytest.mark.parametrize(
    ("n", "m", "t"), [(1200, 0, 0.3), (1200, 600, 0.3), (1200, 1, 0.99), (900, 450, -0.7)]
)
def test_high_degree_entries_against_mpmath(n, m, t):
    """mpmath's legenp carries the Condon–Shortley phase (−1)ᵐ; exact factorials in mpmath."""
    with mp.workdps(40):
        x = mp.mpf(t)
        norm = mp.sqrt((2 - (m == 0)) * (2 * n + 1) * mp.factorial(n - m) / mp.factorial(n + m))
        ref = float((-1) ** m * norm * mp.legenp(n, m, x, type=2))
    val = legendre_4pi(n, t)[n, m]
    assert abs(val - ref) <= 1e-12 * max(1.0, abs(ref))


def test_orthonormality_by_gauss_legendre_quadrature():
    """∫ P̄_nm P̄_km dt = 2 (2 − δ_m0) δ_nk, exact with 80 nodes for n, k ≤ 60."""
    nmax = 60
    t, w = np.polynomial.legendre.leggauss(80)
    P = legendre_4pi(nmax, t)  # (80, 61, 61)
    for m in (0, 1, 7, 30, 60):
        G = np.einsum("q,qn,qk->nk", w, P[:, m:, m], P[:, m:, m])
        expected = 2 * (2 - (m == 0)) * np.eye(nmax + 1 - m)
        assert np.abs(G - expected).max() <= 1e-12


def test_low_degree_closed_forms():
    t = 0.37
    u = math.sqrt(1 - t * t)
    P = legendre_4pi(3, t)
    assert abs(P[1, 0] - math.sqrt(3) * t) < 1e-15
    assert abs(P[1, 1] - math.sqrt(3) * u) < 1e-15  # + sign: no Condon–Shortley phase
    assert abs(P[2, 0] - math.sqrt(5) * (3 * t * t - 1) / 2) < 1e-15
    assert abs(P[2, 2] - math.sqrt(15) / 2 * u * u) < 1e-15
    assert abs(P[3, 3] - math.sqrt(35 / 8) * u**3) < 1e-15


def test_normalization_factor():
    for n in range(21):
        for m in range(n + 1):
            exact = math.sqrt(
                (2 - (m == 0)) * (2 * n + 1) * math.factorial(n - m) / math.factorial(n + m)
            )
            assert abs(normalization_4pi(n, m) - exact) <= 1e-14 * exact
    arr = normalization_4pi(np.array([2, 3]), np.array([0, 3]))
    assert arr.shape == (2,)
    assert normalization_4pi(200, 200) == 0.0  # below the smallest double: underflows


def test_errors():
    with pytest.raises(DegreeError, match="nmax must be an integer >= 0; got -1"):
        legendre_4pi(-1, 0.1)
    with pytest.raises(DegreeError):
        legendre_4pi(2.0, 0.1)
    with pytest.raises(DomainError, match=r"t must lie in \[-1, 1\]; got \|t\| = 1.5"):
        legendre_4pi(3, [0.1, 1.5])
    with pytest.raises(NonFiniteError):
        legendre_4pi(3, np.nan)
    with pytest.raises(ShapeError):
        legendre_4pi(3, np.zeros((2, 2)))
    with pytest.raises(DegreeError, match="0 <= m <= n"):
        normalization_4pi(2, 3)
    with pytest.raises(DegreeError, match="integer"):
        normalization_4pi(2.5, 1)
