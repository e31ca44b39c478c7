"""Kepler's equation and the anomalies of the three conics, as vectorised functions.

Each solver is written once, as a compiled scalar function (``eccentric_from_mean_scalar``
…, which the compiled reference kernels call at every integrator stage); the vectorised
functions check and broadcast their input and apply the same scalar functions to every
element.

Three "mean anomalies" are linear in the time ``t`` since periapsis passage:

=========  ======================  =============  =======================================
conic      mean anomaly            auxiliary      relation to the true anomaly f
=========  ======================  =============  =======================================
ellipse    ``M = E − e sin E``     ``E``          ``tan(f/2) = √((1+e)/(1−e)) tan(E/2)``
parabola   ``M_p = D + D³/3``      ``D``          ``D = tan(f/2)`` (Barker's equation)
hyperbola  ``M_h = e sinh H − H``  ``H``          ``tan(f/2) = √((e+1)/(e−1)) tanh(H/2)``
=========  ======================  =============  =======================================

with ``M = n t``, ``n = √(μ/a³)`` (McCann 2020, Eqs. 75–78), ``M_p = 2√(μ/p³) t`` and
``M_h = √(μ/(−a)³) t`` (:mod:`gmuk.orbits.conics` applies these rates).

Angle wrapping
--------------
Elliptic anomalies are *not* wrapped: every conversion returns the angle on the same
revolution as its input, so that ``E − M = e sin E ∈ [−e, e]`` and ``|f − E| < π``.
The maps ``M ↦ E ↦ f`` are therefore continuous and increasing on the whole real line
(``t ↦ f(t)`` never jumps), and ``M = 2πk`` gives ``E = f = 2πk``. Use :func:`wrap_to_2pi`
or :func:`wrap_to_pi` to reduce an angle afterwards. The parabolic and hyperbolic true
anomalies lie in ``(−f∞, f∞)`` with ``f∞ = arccos(−1/e)`` (``π`` for the parabola).

Accuracy
--------
Kepler's equation is solved by Newton's method on the range-reduced equation, from a start
that makes the iterates decrease monotonically onto the root (the residual is convex on
``[0, π]``), so convergence is guaranteed for every ``0 ≤ e < 1`` and every ``M``; the
residual is evaluated as ``(E − sin E) + (1 − e) sin E`` (series for ``|E| < 1``) so that
small anomalies at ``e → 1`` keep full relative precision. The result agrees with a
50-digit solution to a few units in the last place (see ``tests/orbits``). The hyperbolic
equation is treated the same way.

References
----------
McCann (2020), Eqs. (75)–(78). Vallado, *Fundamentals of Astrodynamics and Applications*,
4th ed. (2013), Ch. 2 (Algorithms 2–4, Barker's equation). Battin, *An Introduction to
the Mathematics and Methods of Astrodynamics*, rev. ed. (1999), Ch. 4–5.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmuk._numba import njit
from gmuk._validation import FloatArray, as_array
from gmuk.errors import OrbitError

__all__ = [
    "eccentric_from_mean",
    "eccentric_from_mean_scalar",
    "eccentric_from_true",
    "hyperbolic_from_mean",
    "hyperbolic_from_mean_scalar",
    "hyperbolic_from_true",
    "mean_from_eccentric",
    "mean_from_hyperbolic",
    "mean_from_parabolic",
    "mean_from_true",
    "parabolic_from_mean",
    "parabolic_from_mean_scalar",
    "parabolic_from_true",
    "true_from_eccentric",
    "true_from_eccentric_scalar",
    "true_from_hyperbolic",
    "true_from_hyperbolic_scalar",
    "true_from_mean",
    "true_from_parabolic",
    "wrap_to_2pi",
    "wrap_to_pi",
]

_TWO_PI = 2.0 * np.pi
# 2π = _C1 + _C2 + _C3 to ~6e-33; _C1 and _C2 carry 26 significant bits, so k·_C1 and k·_C2
# are exact for |k| < 2²⁷ (Cody–Waite range reduction).
_C1 = 6.283185243606567
_C2 = 6.357301884918343e-08
_C3 = 2.4492935982947064e-16
_MAX_REVS = 2.0**26
_MAX_ITER = 60
_EPS = float(np.finfo(np.float64).eps)
_LOG2 = math.log(2.0)
# Newton stops once its predicted remaining error (quadratic and cubic terms of the step) is
# below _STOP·|root|.
_STOP = 0.05 * _EPS
# 17!, 15!, ..., 3!: denominators of the series of x − sin x and sinh x − x (with 1/19!).
_XMS_DEN = (
    355687428096000.0,
    1307674368000.0,
    6227020800.0,
    39916800.0,
    362880.0,
    5040.0,
    120.0,
    6.0,
)


def _angle(x: Any, name: str) -> FloatArray:
    return as_array(x, (), name)


def _check_elliptic_e(e: Any) -> FloatArray:
    e = as_array(e, (), "e")
    bad = (e < 0.0) | (e >= 1.0)
    if bad.any():
        raise OrbitError(
            f"e must satisfy 0 ≤ e < 1 for an ellipse; got e = {float(e[bad].flat[0])!r}"
        )
    return e


def _check_hyperbolic_e(e: Any) -> FloatArray:
    e = as_array(e, (), "e")
    bad = ~(e > 1.0)
    if bad.any():
        raise OrbitError(f"e must satisfy e > 1 for a hyperbola; got e = {float(e[bad].flat[0])!r}")
    return e


def wrap_to_2pi(angle: Any) -> FloatArray:
    """Reduce angles to ``[0, 2π)`` (rad).

    Parameters
    ----------
    angle : array_like, shape (...)
        Angles (rad).

    Returns
    -------
    ndarray, shape (...)
    """
    a = np.mod(_angle(angle, "angle"), _TWO_PI)
    # np.mod can round a tiny negative input up to exactly 2π.
    return np.where(a >= _TWO_PI, 0.0, a)


def wrap_to_pi(angle: Any) -> FloatArray:
    """Reduce angles to ``(−π, π]`` (rad).

    Parameters
    ----------
    angle : array_like, shape (...)
        Angles (rad).

    Returns
    -------
    ndarray, shape (...)
    """
    a = wrap_to_2pi(angle)
    return np.where(a > np.pi, a - _TWO_PI, a)


def _x_minus_sin(x: FloatArray) -> FloatArray:
    """``x − sin x`` without cancellation, elementwise (:func:`_x_minus_sin_scalar`)."""
    return _each(_X_MINUS_SIN, x)


def _sinh_minus_x(x: FloatArray) -> FloatArray:
    """``sinh x − x`` without cancellation, elementwise (:func:`_sinh_minus_x_scalar`)."""
    return _each(_SINH_MINUS_X, x)


def mean_from_eccentric(E: Any, e: Any) -> FloatArray:
    """Mean anomaly of an ellipse from its eccentric anomaly (Kepler's equation).

    ``M = E − e sin E``, evaluated as ``(E − sin E) + (1 − e) sin E`` for ``|E| < 1`` so
    that ``M`` keeps full relative precision near periapsis when ``e → 1``.

    Parameters
    ----------
    E : array_like, shape (...)
        Eccentric anomaly (rad), any revolution.
    e : array_like, broadcastable with E
        Eccentricity, ``0 ≤ e < 1``.

    Returns
    -------
    ndarray
        Mean anomaly M (rad), on the same revolution as E.

    References
    ----------
    McCann (2020), Eq. (77).
    """
    E = _angle(E, "E")
    e = _check_elliptic_e(e)
    small = _x_minus_sin(E) + (1.0 - e) * np.sin(E)
    return np.where(np.abs(E) < 1.0, small, E - e * np.sin(E))


def eccentric_from_mean(M: Any, e: Any) -> FloatArray:
    """Solve Kepler's equation ``M = E − e sin E`` for the eccentric anomaly.

    The mean anomaly is reduced to ``M_r ∈ [−π, π]`` with a three-part 2π (so the reduction
    adds no error), the equation is solved for ``|M_r|`` and the sign and the revolution are
    restored. The start is the root of the cubic ``(1 − e)E + (e/6)E³ = |M_r|`` (a lower
    bound, exact to O(E⁵) near periapsis); one Newton step from it lands on or above the
    root, and as ``E − e sin E`` is convex on ``[0, π]`` the following Newton iterates
    decrease monotonically to it (clipped to the upper bound ``min(|M_r| + e, π)``).
    Iteration stops when the step is below ``2 ε |E|``, typically after 2–5 steps.

    Parameters
    ----------
    M : array_like, shape (...)
        Mean anomaly (rad), any real value.
    e : array_like, broadcastable with M
        Eccentricity, ``0 ≤ e < 1``.

    Returns
    -------
    ndarray, broadcast shape
        Eccentric anomaly E (rad) on the same revolution as M (``|E − M| ≤ e``).

    Raises
    ------
    OrbitError
        If some ``e`` is outside ``[0, 1)``.
    NonFiniteError
        If an input is NaN or infinite.

    References
    ----------
    McCann (2020), Eq. (77); Vallado (2013), Algorithm 2; Battin (1999), Ch. 5.
    """
    return _each(_ECCENTRIC_FROM_MEAN, _angle(M, "M"), _check_elliptic_e(e))


def _same_revolution(wrapped: FloatArray, ref: FloatArray) -> FloatArray:
    """``wrapped + 2πk`` with k such that the result lies within π of ``ref``."""
    return wrapped + _TWO_PI * np.round((ref - wrapped) / _TWO_PI)


def true_from_eccentric(E: Any, e: Any) -> FloatArray:
    """True anomaly of an ellipse from its eccentric anomaly (McCann 2020, Eq. 78).

    Eq. (78), ``tan(f/2) = √((1+e)/(1−e)) tan(E/2)``, is evaluated as
    ``f = atan2(√(1 − e²) sin E, cos E − e)`` with ``cos E − e = (1 − e) − 2 sin²(E/2)``
    (no cancellation as ``e → 1``) and put on the revolution of E (``|f − E| < π``), so
    the map has no branch cut and is continuous and increasing in E.

    Parameters
    ----------
    E : array_like, shape (...)
        Eccentric anomaly (rad), any revolution.
    e : array_like, broadcastable with E
        Eccentricity, ``0 ≤ e < 1``.

    Returns
    -------
    ndarray
        True anomaly f (rad).

    References
    ----------
    McCann (2020), Eq. (78); Vallado (2013), Ch. 2; Battin (1999), Ch. 4.
    """
    return _each(_TRUE_FROM_ECCENTRIC, _angle(E, "E"), _check_elliptic_e(e))[()]


def eccentric_from_true(f: Any, e: Any) -> FloatArray:
    """Eccentric anomaly of an ellipse from its true anomaly (inverse of Eq. 78).

    ``E = atan2(√(1 − e²) sin f, e + cos f)`` with ``e + cos f = 2 cos²(f/2) − (1 − e)``,
    put on the revolution of f (``|E − f| < π``).

    Parameters
    ----------
    f : array_like, shape (...)
        True anomaly (rad), any revolution.
    e : array_like, broadcastable with f
        Eccentricity, ``0 ≤ e < 1``.

    Returns
    -------
    ndarray
        Eccentric anomaly E (rad).

    References
    ----------
    McCann (2020), Eq. (78); Vallado (2013), Ch. 2; Battin (1999), Ch. 4.
    """
    f = _angle(f, "f")
    e = _check_elliptic_e(e)
    wrapped = np.arctan2(
        np.sqrt((1.0 - e) * (1.0 + e)) * np.sin(f), 2.0 * np.cos(0.5 * f) ** 2 - (1.0 - e)
    )
    return _same_revolution(wrapped, f)


def true_from_mean(M: Any, e: Any) -> FloatArray:
    """True anomaly of an ellipse from its mean anomaly (Eqs. 77 then 78).

    Parameters
    ----------
    M : array_like, shape (...)
        Mean anomaly (rad), any real value.
    e : array_like, broadcastable with M
        Eccentricity, ``0 ≤ e < 1``.

    Returns
    -------
    ndarray
        True anomaly f (rad) on the same revolution as M.

    References
    ----------
    McCann (2020), Eqs. (77)–(78).
    """
    return true_from_eccentric(eccentric_from_mean(M, e), e)


def mean_from_true(f: Any, e: Any) -> FloatArray:
    """Mean anomaly of an ellipse from its true anomaly.

    Parameters
    ----------
    f : array_like, shape (...)
        True anomaly (rad), any revolution.
    e : array_like, broadcastable with f
        Eccentricity, ``0 ≤ e < 1``.

    Returns
    -------
    ndarray
        Mean anomaly M (rad) on the same revolution as f.

    References
    ----------
    McCann (2020), Eqs. (77)–(78).
    """
    return mean_from_eccentric(eccentric_from_true(f, e), e)


# ---------------------------------------------------------------- parabola (Barker's equation)


def mean_from_parabolic(D: Any) -> FloatArray:
    """Parabolic mean anomaly ``M_p = D + D³/3`` from ``D = tan(f/2)`` (Barker's equation).

    With ``M_p = 2√(μ/p³) t`` this is Barker's equation
    ``t = ½√(p³/μ) (D + D³/3)`` (t from periapsis).

    Parameters
    ----------
    D : array_like, shape (...)
        Parabolic anomaly ``tan(f/2)`` (dimensionless).

    Returns
    -------
    ndarray
        ``M_p`` (dimensionless).

    References
    ----------
    Vallado (2013), Ch. 2 (Barker's equation); Battin (1999), Ch. 4.
    """
    D = as_array(D, (), "D")
    return D + D**3 / 3.0


def parabolic_from_mean(M_p: Any) -> FloatArray:
    """Solve Barker's equation ``D + D³/3 = M_p`` for ``D = tan(f/2)`` in closed form.

    With ``D = s − 1/s`` the cubic becomes ``s³ − s⁻³ = 3M_p``, so
    ``s³ = (3|M_p| + √(9M_p² + 4)) / 2`` and ``D = 3|M_p| / (s² + 1 + s⁻²)`` (the last form
    avoids the cancellation of ``s − 1/s`` at small ``M_p``); the sign of ``M_p`` is restored
    and one Newton step polishes the cube-root rounding.

    Parameters
    ----------
    M_p : array_like, shape (...)
        Parabolic mean anomaly ``2√(μ/p³) t`` (dimensionless).

    Returns
    -------
    ndarray
        ``D = tan(f/2)``.

    References
    ----------
    Vallado (2013), Ch. 2 (Barker's equation) and Algorithm 3.
    """
    return _each(_PARABOLIC_FROM_MEAN, as_array(M_p, (), "M_p"))[()]


def true_from_parabolic(D: Any) -> FloatArray:
    """True anomaly ``f = 2 atan D`` of a parabola, in ``(−π, π)``.

    Parameters
    ----------
    D : array_like, shape (...)
        ``tan(f/2)``.

    Returns
    -------
    ndarray
        f (rad).
    """
    return 2.0 * np.arctan(as_array(D, (), "D"))


def parabolic_from_true(f: Any) -> FloatArray:
    """``D = tan(f/2)`` of a parabola from its true anomaly, ``|f| < π``.

    Parameters
    ----------
    f : array_like, shape (...)
        True anomaly (rad).

    Returns
    -------
    ndarray
        D.

    Raises
    ------
    OrbitError
        If ``|f| ≥ π`` (beyond the parabola's asymptote).
    """
    f = _angle(f, "f")
    if (np.abs(f) >= np.pi).any():
        raise OrbitError(
            "a parabola's true anomaly must satisfy |f| < π; got "
            f"{float(f[np.abs(f) >= np.pi].flat[0])!r}"
        )
    return np.tan(0.5 * f)


# ---------------------------------------------------------------- hyperbola


def mean_from_hyperbolic(H: Any, e: Any) -> FloatArray:
    """Hyperbolic mean anomaly ``M_h = e sinh H − H``.

    Evaluated as ``(e − 1) sinh H + (sinh H − H)`` (series for ``|H| < 1``), accurate near
    periapsis when ``e → 1⁺``.

    Parameters
    ----------
    H : array_like, shape (...)
        Hyperbolic anomaly (dimensionless).
    e : array_like, broadcastable with H
        Eccentricity, ``e > 1``.

    Returns
    -------
    ndarray
        ``M_h = √(μ/(−a)³) t``.

    References
    ----------
    Vallado (2013), Ch. 2; Battin (1999), Ch. 4.
    """
    H = as_array(H, (), "H")
    e = _check_hyperbolic_e(e)
    with np.errstate(over="ignore"):
        return (e - 1.0) * np.sinh(H) + _sinh_minus_x(H)


def hyperbolic_from_mean(M_h: Any, e: Any) -> FloatArray:
    """Solve ``e sinh H − H = M_h`` for the hyperbolic anomaly.

    Solved for ``|M_h|`` (the function is odd): both ``asinh(|M_h|/(e − 1))`` and the root of
    ``(e − 1)H + (e/6)H³ = |M_h|`` are upper bounds, the smaller one is improved by two
    steps of the contraction ``H ← asinh((|M_h| + H)/e)`` (which keeps an upper bound) and
    Newton's method then decreases monotonically onto the root (the residual is convex for
    ``H ≥ 0``).

    Parameters
    ----------
    M_h : array_like, shape (...)
        Hyperbolic mean anomaly (dimensionless).
    e : array_like, broadcastable with M_h
        Eccentricity, ``e > 1``.

    Returns
    -------
    ndarray, broadcast shape
        H.

    References
    ----------
    Vallado (2013), Algorithm 4; Battin (1999), Ch. 4.
    """
    return _each(_HYPERBOLIC_FROM_MEAN, as_array(M_h, (), "M_h"), _check_hyperbolic_e(e))


def true_from_hyperbolic(H: Any, e: Any) -> FloatArray:
    """True anomaly of a hyperbola, ``f = 2 atan(√((e+1)/(e−1)) tanh(H/2))``.

    Parameters
    ----------
    H : array_like, shape (...)
        Hyperbolic anomaly.
    e : array_like, broadcastable with H
        Eccentricity, ``e > 1``.

    Returns
    -------
    ndarray
        f (rad), ``|f| < arccos(−1/e)``.

    References
    ----------
    Vallado (2013), Ch. 2; Battin (1999), Ch. 4.
    """
    return _each(_TRUE_FROM_HYPERBOLIC, as_array(H, (), "H"), _check_hyperbolic_e(e))[()]


def hyperbolic_from_true(f: Any, e: Any) -> FloatArray:
    """Hyperbolic anomaly from the true anomaly, ``H = 2 atanh(√((e−1)/(e+1)) tan(f/2))``.

    Parameters
    ----------
    f : array_like, shape (...)
        True anomaly (rad), ``|f| < arccos(−1/e)``.
    e : array_like, broadcastable with f
        Eccentricity, ``e > 1``.

    Returns
    -------
    ndarray
        H.

    Raises
    ------
    OrbitError
        If some ``|f|`` reaches the asymptote ``arccos(−1/e)``.
    """
    f = _angle(f, "f")
    e = _check_hyperbolic_e(e)
    f, e = np.broadcast_arrays(f, e)
    # 1 + e cos f > 0 is the condition for a point on the (attracting) branch.
    bad = (np.abs(f) >= np.pi) | (1.0 + e * np.cos(f) <= 0.0)
    if bad.any():
        j = np.flatnonzero(bad.ravel())[0]
        raise OrbitError(
            "true anomaly beyond the asymptote: a hyperbola needs |f| < arccos(−1/e); got "
            f"f = {float(f.ravel()[j])!r} with e = {float(e.ravel()[j])!r} "
            f"(limit {float(np.arccos(-1.0 / e.ravel()[j]))!r})"
        )
    return 2.0 * np.arctanh(np.sqrt((e - 1.0) / (e + 1.0)) * np.tan(0.5 * f))


# ---------------------------------------------------------------- the scalar definitions
# The algorithms on floats (no validation, no arrays), compiled: the one definition of each.
# The compiled reference kernels call them at every integrator stage; the vectorised
# functions above apply them to every element (:func:`_each`). Callers validate e once. Pass
# floats (an int argument compiles a second version).


@njit(cache=True)
def _round(x: float) -> float:
    """x rounded to the nearest integer (halves to even), as a float; no integer overflow:
    beyond 2⁵² every float is an integer already."""
    if abs(x) < 4503599627370496.0:
        return float(round(x))
    return x


@njit(cache=True)
def _x_minus_sin_scalar(x: float) -> float:
    if abs(x) >= 1.0:
        return x - math.sin(x)
    x2 = x * x
    s = 1.0 / 121645100408832000.0
    for d in _XMS_DEN:
        s = 1.0 / d - x2 * s
    return x * x2 * s


@njit(cache=True)
def _sinh_minus_x_scalar(x: float) -> float:
    if abs(x) >= 1.0:
        return math.sinh(x) - x
    x2 = x * x
    s = 1.0 / 121645100408832000.0
    for d in _XMS_DEN:
        s = 1.0 / d + x2 * s
    return x * x2 * s


@njit(cache=True)
def _cubic_root_scalar(c1: float, c3: float, x: float) -> float:
    q = math.sqrt(c1 / (3.0 * c3))
    return 2.0 * q * math.sinh(math.asinh(x / (2.0 * c1 * q)) / 3.0)


@njit(cache=True)
def eccentric_from_mean_scalar(M: float, e: float) -> float:
    """:func:`eccentric_from_mean` for one finite float M and ``0 ≤ e < 1`` (not checked)."""
    k = _round(M / _TWO_PI)
    if abs(k) < _MAX_REVS:
        Mr = ((M - k * _C1) - k * _C2) - k * _C3
    else:  # beyond 2²⁶ revolutions a plain remainder is as good as anything (as _reduce)
        Mr = (M + math.pi) % _TWO_PI - math.pi
        k = (M - Mr) / _TWO_PI
    x = abs(Mr)
    one_m_e = 1.0 - e
    E = _cubic_root_scalar(one_m_e, e / 6.0, x) if e > 1e-8 else x
    upper = min(x + e, math.pi)
    E = min(E, upper)
    for _ in range(_MAX_ITER):
        resid = _x_minus_sin_scalar(E) + one_m_e * math.sin(E) - x
        deriv = one_m_e + 2.0 * e * math.sin(0.5 * E) ** 2
        step = resid / deriv
        a_step = abs(step)
        err = 0.5 * e * (abs(math.sin(E)) + a_step / 3.0) * a_step * a_step
        E = max(min(E - step, upper), 0.0)
        if err <= _STOP * deriv * E:
            break
    Er = math.copysign(E, Mr)
    return ((Er + k * _C3) + k * _C2) + k * _C1


@njit(cache=True)
def true_from_eccentric_scalar(E: float, e: float) -> float:
    """:func:`true_from_eccentric` for floats (e not checked)."""
    w = math.atan2(
        math.sqrt((1.0 - e) * (1.0 + e)) * math.sin(E), (1.0 - e) - 2.0 * math.sin(0.5 * E) ** 2
    )
    return w + _TWO_PI * _round((E - w) / _TWO_PI)


@njit(cache=True)
def hyperbolic_from_mean_scalar(M: float, e: float) -> float:
    """:func:`hyperbolic_from_mean` for one finite float and ``e > 1`` (not checked)."""
    x = abs(M)
    em1 = e - 1.0
    y = x / em1
    # asinh(y) = log(2y) to double precision beyond 1e300, and in logs y may be beyond
    # float64 (|M| near 1e308, e near 1): the bound stays finite
    bound = math.asinh(y) if y < 1e300 else (_LOG2 + math.log(x)) - math.log(em1)
    H = min(bound, _cubic_root_scalar(em1, e / 6.0, x))
    for _ in range(2):
        H = math.asinh((x + H) / e)
    for _ in range(_MAX_ITER):
        resid = em1 * math.sinh(H) + _sinh_minus_x_scalar(H) - x
        deriv = em1 + e * (2.0 * math.sinh(0.5 * H) ** 2)  # 2e overflows near 1e308
        step = resid / deriv
        a_step = abs(step)
        err = 0.5 * e * (abs(math.sinh(H)) + math.cosh(H) * a_step / 3.0) * a_step * a_step
        H = max(H - step, 0.0)
        if err <= _STOP * deriv * H:
            break
    return math.copysign(H, M)


@njit(cache=True)
def true_from_hyperbolic_scalar(H: float, e: float) -> float:
    """:func:`true_from_hyperbolic` for floats (e not checked)."""
    return 2.0 * math.atan(math.sqrt((e + 1.0) / (e - 1.0)) * math.tanh(0.5 * H))


@njit(cache=True)
def parabolic_from_mean_scalar(M_p: float) -> float:
    """:func:`parabolic_from_mean` for one finite float."""
    x = abs(M_p)
    if x > 1e100:  # 3x may overflow; D = (3x)^(1/3) to a relative 3/D² < 1e-66
        return math.copysign(float(np.cbrt(3.0) * np.cbrt(x)), M_p)
    s = np.cbrt(0.5 * (3.0 * x + math.hypot(3.0 * x, 2.0)))
    D = 3.0 * x / (s * s + 1.0 + 1.0 / (s * s))
    polished = D - (D + D**3 / 3.0 - x) / (1.0 + D * D)  # not finite past D ~ 5e102
    if math.isfinite(polished):
        D = polished
    return math.copysign(D, M_p)


# codes of the scalar functions for :func:`_each_into`
_ECCENTRIC_FROM_MEAN = 0
_TRUE_FROM_ECCENTRIC = 1
_HYPERBOLIC_FROM_MEAN = 2
_TRUE_FROM_HYPERBOLIC = 3
_PARABOLIC_FROM_MEAN = 4
_X_MINUS_SIN = 5
_SINH_MINUS_X = 6


@njit(cache=True)
def _each_into(which, x, y, out):  # type: ignore[no-untyped-def]
    """``out[i] = f(x[i], y[i])`` (or ``f(x[i])``) for the scalar function ``which``."""
    for i in range(x.size):
        if which == _ECCENTRIC_FROM_MEAN:
            out[i] = eccentric_from_mean_scalar(x[i], y[i])
        elif which == _TRUE_FROM_ECCENTRIC:
            out[i] = true_from_eccentric_scalar(x[i], y[i])
        elif which == _HYPERBOLIC_FROM_MEAN:
            out[i] = hyperbolic_from_mean_scalar(x[i], y[i])
        elif which == _TRUE_FROM_HYPERBOLIC:
            out[i] = true_from_hyperbolic_scalar(x[i], y[i])
        elif which == _PARABOLIC_FROM_MEAN:
            out[i] = parabolic_from_mean_scalar(x[i])
        elif which == _X_MINUS_SIN:
            out[i] = _x_minus_sin_scalar(x[i])
        else:
            out[i] = _sinh_minus_x_scalar(x[i])


def _each(which: int, x: FloatArray, y: FloatArray | None = None) -> FloatArray:
    """A scalar function applied to every element of x (and y, broadcast against x): an array
    of the broadcast shape (0-d for scalars)."""
    if y is None:
        xb, yb = x, x
    else:
        xb, yb = np.broadcast_arrays(x, y)
    xs = np.ascontiguousarray(xb, dtype=np.float64).ravel()
    ys = np.ascontiguousarray(yb, dtype=np.float64).ravel()
    out = np.empty(xs.size)
    _each_into(which, xs, ys, out)
    return out.reshape(np.shape(xb))
