"""Series constants of the SO(3)/SE(3) coefficient functions, and a vectorised numpy reference
for D, F₁ and F₂ (the compiled kernels in :mod:`gmuk.lie._kernels` are the implementation
gmuk uses; these functions are the readable form the tests check them against).

Each function takes an array of angles θ ≥ 0 (rad) and returns an array of the same shape.
Where the closed form cancels catastrophically (θ → 0) a Taylor series in θ² is used below
``_SERIES_BELOW`` (C) or ``_DE_SERIES_BELOW`` (D, E); the series converge for θ < 2π and
are truncated where the next term is below 1e-20 relative at the switch-over, so both
branches agree to round-off there.
The series coefficients are exact rationals (derived symbolically; see the errata page,
``docs/errata.rst``, "Numerically fragile", for F₁ and F₂ of McCann (2020), Eqs. 21–22).
"""

from __future__ import annotations

from fractions import Fraction
from math import factorial

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

# NOTE: gmuk.lie._kernels freezes these constants into numba's on-disk cache, which is keyed on
# _kernels.py only (on its content in recent numba versions, so touching the file is not
# enough). After changing a constant here, clear that cache (see gmuk._numba for where it
# is) so that the kernels recompile; the mpmath tests fail on stale kernels.
_SERIES_BELOW = 1.0

# C(θ) = (θ − sin θ)/θ³ = Σ_k (−1)^k θ^{2k} / (2k+3)!
_C_SERIES = np.array([(-1) ** k / factorial(2 * k + 3) for k in range(11)])[::-1].copy()

# D(θ) = (1 − (θ/2) cot(θ/2))/θ² = 1/12 + θ²/720 + … = Σₙ |B₂ₙ| θ²ⁿ⁻²/(2n)! (Bernoulli numbers)
_D_TERMS = [
    Fraction(1, 12),
    Fraction(1, 720),
    Fraction(1, 30240),
    Fraction(1, 1209600),
    Fraction(1, 47900160),
    Fraction(691, 1307674368000),
    Fraction(1, 74724249600),
    Fraction(3617, 10670622842880000),
    Fraction(43867, 5109094217170944000),
    Fraction(174611, 802857662698291200000),
    Fraction(77683, 14101100039391805440000),
    Fraction(236364091, 1693824136731743669452800000),
    Fraction(657931, 186134520519971831808000000),
    Fraction(3392780147, 37893265687455865519472640000000),
    Fraction(1723168255201, 759790291646040068357842010112000000),
    Fraction(7709321041217, 134196726836183700385281186201600000000),
    Fraction(151628697551, 104199811425742637946218332815360000000),
    Fraction(26315271553053477373, 713925872841910517552409860896601407488000000000),
    Fraction(154210205991661, 165165037094716140555791754978970828800000000),
    Fraction(261082718496449122051, 11039333782344056345696120477635448049500160000000000),
    Fraction(1520097643918070802691, 2537441048661701096768915546877587895305109504000000000),
    Fraction(2530297234481911294093, 166746126054911786359100164509098633120050053120000000000),
]
# D and E switch to their closed forms only at θ = 2: E = (D − 1/12)/θ² loses a factor
# ≈ 60/θ² to cancellation and D = (1 − (θ/2)cot(θ/2))/θ² about 12/θ², which left F₂ with
# errors up to 1e-13 relative just above θ = 1. The 22 terms above reach 1e-21 at θ = 2.
_DE_SERIES_BELOW = 2.0
# E(θ) = (D(θ) − 1/12)/θ²: the same series shifted by one term.
_E_SERIES = np.array([float(c) for c in _D_TERMS[1:]])[::-1].copy()
_D_SERIES = np.array([float(c) for c in _D_TERMS])[::-1].copy()


def _split(
    theta: FloatArray, below: float = _SERIES_BELOW
) -> tuple[NDArray[np.bool_], FloatArray, FloatArray]:
    """Return (small-mask, θ² for the series, θ clipped away from 0 for the closed form)."""
    small = theta < below
    return small, theta * theta, np.where(small, below, theta)


def dexp_inv_d(theta: FloatArray) -> FloatArray:
    """D(θ) = (1 − (θ/2) cot(θ/2))/θ², with value 1/12 at θ = 0 (singular at θ = 2π)."""
    small, t2, tc = _split(theta, _DE_SERIES_BELOW)
    h = 0.5 * tc
    closed = (1.0 - h / np.tan(h)) / (tc * tc)
    return np.where(small, np.polyval(_D_SERIES, t2), closed)


def dexp_inv_f1_f2(theta: FloatArray) -> tuple[FloatArray, FloatArray]:
    """F₁(θ) and F₂(θ) of McCann (2020), Eqs. 21–22, without cancellation.

    Rewritten exactly in terms of D and E = (D − 1/12)/θ²:
    ``F₁ = 5D/2 − θ²D²/2 − 1/8`` and ``F₂ = 3E/2 − D²/2``, so that
    ``F₁ − θ²F₂ = D`` holds to round-off. Limits: F₁(0) = 1/12, F₂(0) = −1/720.
    """
    small, t2, tc = _split(theta, _DE_SERIES_BELOW)
    d = dexp_inv_d(theta)
    e_closed = (dexp_inv_d(tc) - 1.0 / 12.0) / (tc * tc)
    e = np.where(small, np.polyval(_E_SERIES, t2), e_closed)
    f1 = 2.5 * d - 0.5 * t2 * d * d - 0.125
    f2 = 1.5 * e - 0.5 * d * d
    return f1, f2
