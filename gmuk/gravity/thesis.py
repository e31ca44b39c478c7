"""McCann (2020)'s printed gravity formulas, Eqs. 24–26, kept for reproducing Chapter 3.

**These formulas are wrong** (see the errata); gmuk's physics uses
:class:`~gmuk.gravity.SphericalHarmonicField`. They are kept under names that say where
they come from so that the thesis's rigid-body Eqs. 27–59 can be rebuilt on them and
compared with the correct model.

* :func:`thesis_eq26c_normalization`, :func:`thesis_eq26c_legendre`: the printed
  normalisation ``P̄_np = √(n + ½ (n−p)!/(n+p)!) P_np``. Coefficient files (GRAIL,
  EGM2008) and pyshtools use ``√[(2 − δ_p0)(2n+1)(n−p)!/(n+p)!]`` (4π, no Condon–Shortley
  phase). Measured ratio printed/4π: 0.707 at (n, p) = (2, 0), 1.12 at (2, 1), 2.20 at
  (2, 2), 7.6e8 at (10, 10), 4.8e78 at (50, 50), 8.7e306 at (150, 150): orders of
  magnitude; even ``√((n + ½)(n−p)!/(n+p)!)`` is off by exactly 1/√2 (p = 0) and 1/2
  (p > 0).
* :func:`thesis_eq25_radial_acceleration`: the printed Eq. 25,
  ``a = −μ r/r³ [1 − Σ_{n≥1} Σ_p (n+1)(R/r)ⁿ P̄_np(sin φ)(C̄ cos pλ + S̄ sin pλ)]``.
  It keeps only the radial derivative of Eq. 24 and flips the sign of the harmonic sum
  (the radial derivative is ``−μ r/r³ [1 + Σ …]``), so its error is exactly
  ``a_t + 2 a_r`` where ``a_t``, ``a_r`` are the tangential and radial parts of the
  harmonic perturbation: between 1× (purely tangential perturbation) and 2× (purely
  radial) the whole harmonic effect. Measured with GRGM660PRIM to degree 150 (4π P̄) at
  2000 random points 100 km above the reference sphere: ``|a_eq25 − a| / |a − a_central|``
  has median 1.51 (5–95 %: 1.01–1.96), RMS error / RMS perturbation 1.63; the tangential
  part carries 45 % of the perturbation's energy (median ``|a_t|/|a_pert|`` = 0.76); with
  degree 2 only: median 1.59, RMS ratio 1.66. (The errata's "97–99 % tangential, error
  about twice the harmonic effect" is not what these measurements give; the bound 1–2× is
  exact.) With the Eq. 26c normalisation as well the perturbation is wrong by many orders
  of magnitude: error/perturbation median 8.5e6 at degree 10, accelerations of 1e292–1e296
  m/s² at degree 150. ``tests/gravity/test_thesis.py`` recomputes these figures.
* :func:`thesis_eq24_degree_terms`: the per-degree angular sums ``T_n`` of Eq. 24,
  ``U = (μ/r) Σ_n (R/r)ⁿ T_n``; with the 4π normalisation this is the correct potential's
  decomposition (the thesis's Q of Eq. 28 is ``(n+1) Rⁿ T_n``).

References
----------
McCann (2020), Eqs. (24)–(28); errata: "Eq. 26c normalisation", "Eq. 25 (point-mass
acceleration)".
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.special import gammaln

from gmuk._validation import FloatArray, as_array
from gmuk.errors import DefinitionError, DomainError
from gmuk.gravity.field import SphericalHarmonicField
from gmuk.gravity.legendre import _check_orders, legendre_4pi

__all__ = [
    "thesis_eq24_degree_terms",
    "thesis_eq25_radial_acceleration",
    "thesis_eq26c_legendre",
    "thesis_eq26c_normalization",
]

_NORMS = ("4pi", "thesis_eq26c")


def thesis_eq26c_normalization(n: Any, p: Any) -> FloatArray:
    """The normalisation factor of McCann (2020), Eq. 26c, as printed: ``√(n + ½ (n−p)!/(n+p)!)``.

    **Wrong** (see the module docstring); the correct factor is :func:`normalization_4pi`.

    Parameters
    ----------
    n, p : int or array_like of int
        Degree and order, 0 ≤ p ≤ n (dimensionless; arrays broadcast together).

    Returns
    -------
    ndarray
        The printed factor (log-gamma ratios, no factorial overflow).
    """
    nn, pp = _check_orders(n, p)
    ratio = np.exp(gammaln(nn - pp + 1.0) - gammaln(nn + pp + 1.0))
    return np.asarray(np.sqrt(nn + 0.5 * ratio))


def thesis_eq26c_legendre(nmax: int, t: Any) -> FloatArray:
    """Associated Legendre functions with the thesis's Eq. 26c normalisation (**wrong**).

    ``P̄ᵗʰ_np(t) = √(n + ½ (n−p)!/(n+p)!) P_np(t)`` with ``P_np`` unnormalised and without
    the Condon–Shortley phase (Eqs. 26a–b), computed as ``(factor / N_np) P̄_np(t)`` from the
    stable 4π functions; entries beyond the range of doubles are ``inf``.

    Parameters
    ----------
    nmax : int
    t : float or array_like, shape (k,)
        In [−1, 1].

    Returns
    -------
    ndarray, shape (nmax+1, nmax+1) or (k, nmax+1, nmax+1)
    """
    P = legendre_4pi(nmax, t)
    n, p = np.tril_indices(nmax + 1)
    log_ratio = gammaln(n - p + 1.0) - gammaln(n + p + 1.0)
    log_thesis = 0.5 * np.log(n + 0.5 * np.exp(log_ratio))
    log_4pi = 0.5 * (np.log(np.where(p == 0, 1.0, 2.0)) + np.log(2.0 * n + 1.0) + log_ratio)
    scale = np.zeros((nmax + 1, nmax + 1))
    with np.errstate(over="ignore"):
        scale[n, p] = np.exp(log_thesis - log_4pi)
    with np.errstate(over="ignore", invalid="ignore"):
        out = P * scale
    out[..., scale == 0] = 0.0
    return np.asarray(out)


def thesis_eq24_degree_terms(
    field: SphericalHarmonicField, r_F: Any, *, normalization: str = "4pi"
) -> FloatArray:
    """Angular sums ``T_n = Σ_p P̄_np(sin φ)(C̄_np cos pλ + S̄_np sin pλ)`` of Eq. 24.

    Parameters
    ----------
    field : SphericalHarmonicField
    r_F : array_like, shape (3,) or (k, 3)
        Body-fixed position(s) (m); φ latitude, λ longitude of r_F.
    normalization : {"4pi", "thesis_eq26c"}
        Which P̄ to use: the correct 4π functions (matching the coefficients) or the
        thesis's Eq. 26c ones.

    Returns
    -------
    ndarray, shape (N+1,) or (k, N+1)
        ``T_n`` (dimensionless); ``U = (μ/r) Σ_n (R/r)ⁿ T_n`` with the 4π choice.
    """
    r = as_array(r_F, (3,), "r_F")
    if normalization not in _NORMS:
        raise DefinitionError(f"normalization must be one of {_NORMS}; got {normalization!r}")
    pts = r.reshape(-1, 3)
    rn = np.linalg.norm(pts, axis=1)
    if np.any(rn == 0):
        raise DomainError("r_F must not be the origin (latitude and longitude undefined)")
    N = field.degree
    sin_lat = np.clip(pts[:, 2] / rn, -1.0, 1.0)
    lon = np.arctan2(pts[:, 1], pts[:, 0])
    legendre = legendre_4pi if normalization == "4pi" else thesis_eq26c_legendre
    p = np.arange(N + 1)
    T = np.empty((pts.shape[0], N + 1))
    for i in range(pts.shape[0]):  # one (N+1, N+1) table at a time
        P = legendre(N, float(sin_lat[i]))
        trig = field.C * np.cos(p * lon[i]) + field.S * np.sin(p * lon[i])
        with np.errstate(over="ignore", invalid="ignore"):
            T[i] = np.sum(P * trig, axis=1)
    return np.asarray(T.reshape(*r.shape[:-1], N + 1))


def thesis_eq25_radial_acceleration(
    field: SphericalHarmonicField, r_F: Any, *, normalization: str = "4pi"
) -> FloatArray:
    """McCann (2020), Eq. 25 as printed: radial-only, with the harmonic sum's sign flipped.

    ``a = −μ r/r³ [1 − Σ_{n=1}^{N} (n+1)(R/r)ⁿ T_n]`` with ``T_n`` from
    :func:`thesis_eq24_degree_terms` (``C̄₀₀`` is taken as 1, as printed). **Wrong**: see the
    module docstring for the measured error; the correct acceleration is
    :meth:`SphericalHarmonicField.acceleration`.

    Parameters
    ----------
    field : SphericalHarmonicField
    r_F : array_like, shape (3,) or (k, 3)
        Body-fixed position(s) (m).
    normalization : {"4pi", "thesis_eq26c"}
        P̄ used in the sum (default: the correct 4π functions, isolating Eq. 25's own
        errors).

    Returns
    -------
    ndarray, shape (3,) or (k, 3)
        Acceleration (m/s²) in the frame of r_F.
    """
    r = as_array(r_F, (3,), "r_F")
    T = thesis_eq24_degree_terms(field, r, normalization=normalization)
    rn = np.linalg.norm(r, axis=-1)
    n = np.arange(field.degree + 1)
    ratio = (field.radius / rn)[..., None] ** n
    with np.errstate(over="ignore", invalid="ignore"):
        bracket = 1.0 - np.sum(((n + 1) * ratio * T)[..., 1:], axis=-1)
        a = -(field.mu / rn**3 * bracket)[..., None] * r
    return np.asarray(a)
