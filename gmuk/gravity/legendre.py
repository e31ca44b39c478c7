"""Fully normalised associated Legendre functions and normalisation factors.

Convention (geodesy "4π" normalisation, no Condon–Shortley phase), as in GRAIL and EGM2008
coefficient files and pyshtools' ``PlmBar``:

``P̄_nm(t) = N_nm P_nm(t)``,  ``N_nm = √[(2 − δ_m0)(2n + 1)(n − m)!/(n + m)!]``,
``P_nm(t) = (1 − t²)^{m/2} dᵐP_n(t)/dtᵐ``,

so that the mean of ``[P̄_nm(sin φ) cos mλ]²`` over the sphere is 1.

:func:`legendre_4pi` uses the standard normalised forward-column recursion (Holmes &
Featherstone 2002, Eqs. 11–13), never factorials. The sectoral values
``P̄_mm = √3 ∏_{k=2..m} √((2k+1)/(2k)) · uᵐ`` (``u = √(1 − t²)``) underflow near the poles
at high order; they are carried as extended-exponent numbers (mantissa · 2^(480 e), after
Fukushima 2012) until the column recursion brings them back into the range of doubles, so
every value that is representable is returned accurately, at any degree. Values below
about 1e-145 in magnitude are returned as 0.

References
----------
Holmes, S. A. & Featherstone, W. E. (2002). A unified approach to the Clenshaw summation
and the recursive computation of very high degree and order normalised associated Legendre
functions. *Journal of Geodesy* 76, 279–299.
Fukushima, T. (2012). Numerical computation of spherical harmonics of arbitrary degree and
order by extending exponent of floating point numbers. *Journal of Geodesy* 86, 271–285.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmuk._numba import njit
from gmuk._validation import FloatArray, as_array
from gmuk.errors import DegreeError, DomainError, NonFiniteError, ShapeError
from gmuk.gravity._kernels import BIG, BIGI

#: The most bytes :func:`legendre_4pi` allocates (as :data:`gmuk.gravity.io.MAX_ARRAY_BYTES`).
MAX_ARRAY_BYTES = 4 * 2**30

__all__ = ["legendre_4pi", "normalization_4pi"]


@njit(cache=True)
def _legendre_columns(nmax, t, out):  # type: ignore[no-untyped-def]
    """Fill out[n, m] = P̄_nm(t) for 0 ≤ m ≤ n ≤ nmax (out zeroed by the caller)."""
    u = math.sqrt((1.0 - t) * (1.0 + t))
    sm = 1.0  # mantissa of P̄_mm
    se = 0  # its exponent, in units of 480 bits
    for m in range(nmax + 1):
        if m == 1:
            sm *= math.sqrt(3.0) * u
        elif m > 1:
            sm *= math.sqrt((2.0 * m + 1.0) / (2.0 * m)) * u
        if sm == 0.0:
            return
        while abs(sm) < BIGI:
            sm *= BIG
            se -= 1
        p1 = sm
        p2 = 0.0
        e = se
        if e == 0:
            out[m, m] = p1
        for n in range(m + 1, nmax + 1):
            a = math.sqrt((2.0 * n - 1.0) * (2.0 * n + 1.0) / ((n - m) * (n + m)))
            b = 0.0
            if n >= m + 2:
                b = math.sqrt(
                    (2.0 * n + 1.0) * (n + m - 1.0) * (n - m - 1.0)
                    / ((n - m) * (n + m) * (2.0 * n - 3.0))
                )  # fmt: skip
            c = a * t * p1 - b * p2
            p2 = p1
            p1 = c
            if e < 0:
                mag = abs(p1)
                if mag >= 1.0:
                    p1 *= BIGI
                    p2 *= BIGI
                    e += 1
                elif mag < BIGI and abs(p2) < BIGI:
                    p1 *= BIG
                    p2 *= BIG
                    e -= 1
                if e == 0:
                    out[n, m] = p1
            else:
                out[n, m] = p1


def legendre_4pi(nmax: int, t: Any) -> FloatArray:
    """Fully normalised (4π) associated Legendre functions P̄_nm(t), no Condon–Shortley phase.

    Parameters
    ----------
    nmax : int
        Maximum degree (≥ 0).
    t : float or array_like, shape (k,)
        Argument(s) in [−1, 1] (for gravity fields ``t = sin φ``, φ the latitude).

    Returns
    -------
    ndarray, shape (nmax+1, nmax+1) or (k, nmax+1, nmax+1)
        ``P[..., n, m]``, lower triangular (zero for m > n).

    Raises
    ------
    DegreeError
        If ``nmax`` is not a non-negative integer.
    ShapeError, NonFiniteError, DomainError
        If ``t`` is not a scalar or 1-D array of finite numbers in [−1, 1].

    Examples
    --------
    >>> P = legendre_4pi(2, 0.5)
    >>> bool(np.isclose(P[1, 1], np.sqrt(3) * np.sqrt(0.75)))
    True
    """
    n = _check_degree(nmax, "nmax")
    tt = as_array(t, (), "t")
    if tt.ndim > 1:
        raise ShapeError(f"t must be a scalar or a 1-D array; got shape {tt.shape}")
    if not np.all(np.isfinite(tt)):
        raise NonFiniteError("t must be finite; got NaN or infinity")
    if np.any(np.abs(tt) > 1.0):
        worst = float(np.max(np.abs(tt)))
        raise DomainError(f"t must lie in [-1, 1]; got |t| = {worst!r}")
    flat = np.atleast_1d(tt)
    size = 8 * flat.shape[0] * (n + 1) ** 2  # refused before allocating, as the readers do
    if size > MAX_ARRAY_BYTES:
        raise DegreeError(
            f"nmax = {nmax!r:.40} would need more than the limit of {MAX_ARRAY_BYTES} bytes "
            f"for {flat.shape[0]} point(s); refused before allocating"
        )
    out = np.zeros((flat.shape[0], n + 1, n + 1))
    for i, ti in enumerate(flat):
        _legendre_columns(n, float(ti), out[i])
    return out[0] if tt.ndim == 0 else out


def normalization_4pi(n: Any, m: Any) -> FloatArray:
    """The 4π normalisation factor ``N_nm = √[(2 − δ_m0)(2n+1)(n−m)!/(n+m)!]``.

    ``N_nm²`` is formed as a ratio of exact (Python) integers, so it is correctly rounded;
    where it underflows (``N_nm < 1e-154``, n ≳ 85 with m ≈ n) ``N_nm`` comes from the
    logarithm of that exact ratio instead (relative error ≲ 1e-13). Values below the smallest
    double (n ≳ 150 with m ≈ n) are 0.

    Parameters
    ----------
    n, m : int or array_like of int
        Degree and order, 0 ≤ m ≤ n (broadcast together).

    Returns
    -------
    ndarray
        ``N_nm`` (dimensionless), with ``P̄_nm = N_nm P_nm``.
    """
    nn, mm = _check_orders(n, m)
    out = np.empty(nn.shape)
    flat_n = nn.astype(np.int64).ravel()
    flat_m = mm.astype(np.int64).ravel()
    top = int(flat_n.max() + flat_m.max()) if flat_n.size else 0
    fact = [1] * (top + 1)
    for k in range(1, top + 1):
        fact[k] = fact[k - 1] * k
    res = out.reshape(-1)
    for i, (ni, mi) in enumerate(zip(flat_n.tolist(), flat_m.tolist(), strict=True)):
        num = (1 if mi == 0 else 2) * (2 * ni + 1) * fact[ni - mi]
        den = fact[ni + mi]
        sq = num / den  # correctly rounded
        if sq >= 2.3e-308:
            res[i] = math.sqrt(sq)
        else:
            res[i] = math.exp(0.5 * (math.log(num) - math.log(den)))
    return out


def _check_degree(n: Any, name: str) -> int:
    """Return ``n`` as an int ≥ 0 or raise :class:`DegreeError`."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise DegreeError(f"{name} must be an integer >= 0; got {n!r}")
    return int(n)


def _check_orders(n: Any, m: Any) -> tuple[FloatArray, FloatArray]:
    """Broadcast integer degree and order arrays, checking 0 ≤ m ≤ n."""
    nn = np.asarray(n)
    mm = np.asarray(m)
    for name, a in (("n", nn), ("m", mm)):
        if a.dtype.kind not in "iu":
            raise DegreeError(f"{name} must be an integer (array); got dtype {a.dtype}")
    nn, mm = np.broadcast_arrays(nn, mm)
    if np.any(mm < 0) or np.any(mm > nn):
        raise DegreeError("degree and order must satisfy 0 <= m <= n")
    return nn.astype(float), mm.astype(float)
