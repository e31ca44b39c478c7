"""The special Euclidean group SE(3) and its algebra se(3), as pure functions of numpy arrays.

Conventions (McCann 2020, Eqs. 6, 9, 12–16):

* a group element is the 4×4 homogeneous matrix ``g_NB = [[R_NB, r_N], [0, 1]]``;
* a twist is ``V = [ω; v]`` (angular first), the body velocity ``ġ = g V^``;
* exponential coordinates are ``ξ = [θ; ρ]`` with ``g = exp(ξ^)``;
* a wrench is ``τ = [L; f]``, dual to the twist.

Every function accepts leading batch axes: twists ``(..., 6)``, elements ``(..., 4, 4)``,
operators ``(..., 6, 6)``.

References
----------
McCann (2020), Eqs. (12), (14)–(16), (20)–(22). Closed forms of exp/log: Murray, Li &
Sastry (1994), §2.3; the left/right Jacobians: Chirikjian, *Stochastic Models, Information
Theory, and Lie Groups*, Vol. 2 (2012), §10.6.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmuk._validation import FloatArray, all_finite, as_array, check_se3, finite_result
from gmuk.errors import DomainError, NotOnGroupError
from gmuk.lie import _kernels
from gmuk.lie import so3 as _so3

__all__ = ["Ad", "ad", "ad_star", "dexp", "dexp_inv", "exp", "hat", "inverse", "log", "vee"]

# hat(V) = V @ _HAT_GEN (6, 16), reshaped to 4×4; ad(V) = V @ _AD_GEN (6, 36), reshaped to 6×6.
_HAT_GEN = np.zeros((6, 4, 4))
_HAT_GEN[:3, :3, :3] = _so3._GEN
_HAT_GEN[3, 0, 3] = _HAT_GEN[4, 1, 3] = _HAT_GEN[5, 2, 3] = 1.0
_HAT_GEN_FLAT = _HAT_GEN.reshape(6, 16)
_AD_GEN = np.zeros((6, 6, 6))
_AD_GEN[:3, :3, :3] = _so3._GEN
_AD_GEN[:3, 3:, 3:] = _so3._GEN
_AD_GEN[3:, 3:, :3] = _so3._GEN
_AD_GEN_FLAT = _AD_GEN.reshape(6, 36)


def _hat(V: FloatArray) -> FloatArray:
    return (V @ _HAT_GEN_FLAT).reshape((*V.shape[:-1], 4, 4))


def _ad(V: FloatArray) -> FloatArray:
    return (V @ _AD_GEN_FLAT).reshape((*V.shape[:-1], 6, 6))


def hat(V: Any) -> FloatArray:
    """Wedge map R⁶ → se(3): ``[ω; v] ↦ [[ω^×, v], [0, 0]]`` (McCann 2020, Eq. 12).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Twist [ω; v] (rad/s, m/s) or exponential coordinates [θ; ρ] (rad, m).

    Returns
    -------
    ndarray, shape (..., 4, 4)

    Notes
    -----
    The thesis writes this map as ``V^∨``; gmuk uses the usual names hat (R⁶ → se(3)) and
    vee (its inverse, the thesis's "unwedge" ``(·)^|``).
    """
    return _hat(as_array(V, (6,), "V"))


def vee(X: Any) -> FloatArray:
    """Inverse of :func:`hat`: ``[[ω^×, v], [0, 0]] ↦ [ω; v]``.

    Parameters
    ----------
    X : array_like, shape (..., 4, 4)
        Elements of se(3): skew rotation block (checked) and a zero last row (checked).

    Returns
    -------
    ndarray, shape (..., 6)
    """
    X = as_array(X, (4, 4), "X")
    last = float(np.abs(X[..., 3, :]).max(initial=0.0))
    if last > _so3.SKEW_TOL * max(1.0, float(np.abs(X).max(initial=0.0))):
        raise NotOnGroupError(
            f"X must be in se(3) with a zero last row; got max|row 4| = {last:.3g}"
        )
    return np.concatenate([_so3.vee(X[..., :3, :3]), X[..., :3, 3]], axis=-1)


def _exp(xi: FloatArray) -> FloatArray:
    flat = np.ascontiguousarray(xi.reshape(-1, 6))
    return _kernels.se3_exp(flat).reshape((*xi.shape[:-1], 4, 4))


def exp(xi: Any) -> FloatArray:
    """Exponential map se(3) → SE(3), accurate for every angle.

    Parameters
    ----------
    xi : array_like, shape (..., 6)
        Exponential coordinates [θ; ρ] (rad, m).

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``[[exp(θ^×), Jₗ(θ) ρ], [0, 1]]`` with the SO(3) left Jacobian
        ``Jₗ = I + ((1 − cos θ)/θ²) θ^× + ((θ − sin θ)/θ³) (θ^×)²`` (series below θ = 1).
    """
    if type(xi) is np.ndarray and xi.shape == (6,) and xi.dtype == np.float64:
        if all_finite(xi):  # one element, the common case: no reshaping round trip
            g = np.empty((4, 4))
            _kernels._se3_exp(xi, g)
            return finite_result(g, "se3.exp", "xi", xi)
    xi = as_array(xi, (6,), "xi")
    return finite_result(_exp(xi), "se3.exp", "xi", xi)


def _log(g: FloatArray) -> FloatArray:
    flat = np.ascontiguousarray(g.reshape(-1, 4, 4))
    return _kernels.se3_log(flat).reshape((*g.shape[:-2], 6))


def log(g: Any) -> FloatArray:
    """Logarithm SE(3) → se(3): exponential coordinates with rotation angle in [0, π].

    Parameters
    ----------
    g : array_like, shape (..., 4, 4)
        SE(3) elements (rotation block and last row checked).

    Returns
    -------
    ndarray, shape (..., 6)
        ``ξ = [θ; ρ]`` with ``exp(ξ) = g``. McCann (2020) writes ``ξ = exp(g)^|`` below
        Eq. 19; the map meant is this logarithm (errata).
    """
    g = check_se3(g, "g")
    return finite_result(_log(g), "se3.log", "g", g)


def _inverse(g: FloatArray) -> FloatArray:
    flat = np.ascontiguousarray(g.reshape(-1, 4, 4))
    return _kernels.se3_inverse(flat).reshape(g.shape)


def inverse(g: Any) -> FloatArray:
    """Group inverse ``g⁻¹ = [[Rᵀ, −Rᵀ r], [0, 1]]``.

    Parameters
    ----------
    g : array_like, shape (..., 4, 4)

    Returns
    -------
    ndarray, shape (..., 4, 4)
    """
    g = check_se3(g, "g")
    return finite_result(_inverse(g), "se3.inverse", "g", g)


def _Ad(g: FloatArray) -> FloatArray:
    flat = np.ascontiguousarray(g.reshape(-1, 4, 4))
    return _kernels.se3_Ad(flat).reshape((*g.shape[:-2], 6, 6))


def Ad(g: Any) -> FloatArray:
    """Adjoint of a group element, ``Ad_g = [[R, 0], [r^× R, R]]`` (McCann 2020, Eq. 16).

    It maps twists in the frame of ``g``'s child to its parent: ``(g V^ g⁻¹)^∨ = Ad_g V``.

    Parameters
    ----------
    g : array_like, shape (..., 4, 4)

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    g = check_se3(g, "g")
    return finite_result(_Ad(g), "se3.Ad", "g", g)


def ad(V: Any) -> FloatArray:
    """Adjoint of the algebra, ``ad_V = [[ω^×, 0], [v^×, ω^×]]`` (McCann 2020, Eq. 14).

    ``ad_V W = [V^, W^]^∨`` (the Lie bracket).

    Parameters
    ----------
    V : array_like, shape (..., 6)

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    return _ad(as_array(V, (6,), "V"))


def ad_star(V: Any) -> FloatArray:
    """Co-adjoint ``ad*_V = ad_Vᵀ = [[−ω^×, −v^×], [0, −ω^×]]`` (McCann 2020, Eq. 15).

    It acts on wrenches [L; f]; Euler's equations read ``𝕀 V̇ = ad*_V 𝕀 V + τ``.

    Parameters
    ----------
    V : array_like, shape (..., 6)

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    return np.swapaxes(ad(V), -1, -2)


def _dexp_inv(xi: FloatArray) -> FloatArray:
    # ad_ξ = [[T, 0], [P, T]]; ad² = [[T², 0], [Y₂, T²]], ad⁴ = [[T⁴, 0], [Y₂T² + T²Y₂, T⁴]],
    # and T⁴ = −θ² T², so the diagonal block I + ½T + (F₁ − θ²F₂) T² = I + ½T + D T².
    flat = np.ascontiguousarray(xi.reshape(-1, 6))
    return _kernels.dexp_inv_matrix(flat).reshape((*xi.shape[:-1], 6, 6))


def dexp_inv(xi: Any) -> FloatArray:
    """Inverse of :func:`dexp`: the exponential-coordinate kinematics ``ξ̇ = dexp_inv(ξ) V``.

    For ``g(t) = exp(ξ(t)^)`` moving with body twist ``V`` (``ġ = g V^``),
    ``ξ̇ = (I + ½ ad_ξ + F₁(θ) ad_ξ² + F₂(θ) ad_ξ⁴) V`` (McCann 2020, Eqs. 20–22, correct
    as printed; errata). This is Pinocchio's ``Jlog6`` at ``exp(ξ)``, reordered to [ω; v].

    Parameters
    ----------
    xi : array_like, shape (..., 6)
        Exponential coordinates [θ; ρ] (rad, m), with ‖θ‖ < 2π.

    Returns
    -------
    ndarray, shape (..., 6, 6)

    Raises
    ------
    DomainError
        If some ‖θ‖ ≥ 2π: dexp is singular at ‖θ‖ = 2π (F₁ has a pole there) and beyond
        it the series no longer inverts :func:`dexp` on the same branch of log, so numbers
        returned there would be meaningless. Reduce θ first (``log(exp(ξ))``).
    ShapeError, NonFiniteError
        If ``xi`` is not (..., 6) finite real numbers, or the result overflows.

    Notes
    -----
    F₁ and F₂ cancel catastrophically as θ → 0 when evaluated as printed; gmuk evaluates
    them through exact rearrangements with Taylor series below θ = 2 (see
    :mod:`gmuk.lie._coeffs`), accurate to round-off for every θ in [0, 2π).

    The check is made here, at the public function; the compiled kernels the integrator
    calls (:mod:`gmuk.lie._kernels`) are not checked: RKMK stages there keep ‖θ‖ small.
    """
    xi = as_array(xi, (6,), "xi")
    theta = np.sqrt(np.einsum("...i,...i->...", xi[..., :3], xi[..., :3]))
    if not np.all(theta < _TWO_PI):  # theta is finite: xi is, and |θ| ≤ √3 · 1.8e308 → inf
        worst = float(np.max(theta))
        raise DomainError(
            f"se3.dexp_inv is defined for ‖θ‖ < 2π (6.283185307179586) rad; got ‖θ‖ = "
            f"{worst!r} rad (reduce ξ first, e.g. se3.log(se3.exp(ξ)))"
        )
    return finite_result(_dexp_inv(xi), "se3.dexp_inv", "xi", xi)


_TWO_PI = 2.0 * np.pi


def _dexp(xi: FloatArray) -> FloatArray:
    # dexp = [[Jᵣ, 0], [−Jᵣ Y Jᵣ, Jᵣ]] where [[X, 0], [Y, X]] = dexp_inv and Jᵣ = X⁻¹ is the
    # SO(3) right Jacobian I − B T + C T².
    flat = np.ascontiguousarray(xi.reshape(-1, 6))
    return _kernels.dexp_matrix(flat).reshape((*xi.shape[:-1], 6, 6))


def dexp(xi: Any) -> FloatArray:
    """Right-trivialised differential of exp: ``V = dexp(ξ) ξ̇`` for ``g = exp(ξ^)``.

    ``dexp(ξ) = Σₖ (−ad_ξ)ᵏ/(k+1)!``, so that ``exp(ξ)⁻¹ d/dt exp(ξ) = (dexp(ξ) ξ̇)^``.
    Equals Pinocchio's ``Jexp6`` reordered to [ω; v].

    Parameters
    ----------
    xi : array_like, shape (..., 6)
        Exponential coordinates [θ; ρ] (rad, m).

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    xi = as_array(xi, (6,), "xi")
    return finite_result(_dexp(xi), "se3.dexp", "xi", xi)
