"""The rotation group SO(3) and its algebra so(3), as pure functions of numpy arrays.

Every function accepts leading batch axes: a rotation vector is ``(..., 3)``, a rotation
matrix ``(..., 3, 3)``. Rotation matrices here are ``R_NB``: they map body (B) components
to inertial (N) components.

References
----------
McCann (2020), Eq. (13) (the cross-product matrix). Exponential and logarithm: the
Rodrigues formula, e.g. Murray, Li & Sastry, *A Mathematical Introduction to Robotic
Manipulation* (1994), §2.2.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmuk._validation import FloatArray, as_array, check_rotation, finite_result
from gmuk.errors import NotOnGroupError
from gmuk.lie import _kernels

__all__ = ["exp", "hat", "log", "vee"]

# hat(w) = w @ _GEN.reshape(3, 9): the generators E_k = hat(e_k), stacked.
_GEN = np.zeros((3, 3, 3))
_GEN[0, 2, 1], _GEN[0, 1, 2] = 1.0, -1.0
_GEN[1, 0, 2], _GEN[1, 2, 0] = 1.0, -1.0
_GEN[2, 1, 0], _GEN[2, 0, 1] = 1.0, -1.0
_GEN_FLAT = _GEN.reshape(3, 9)

#: Tolerance for the skew-symmetry check in :func:`vee` (relative to the largest entry).
SKEW_TOL = 1e-9


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """a × b of two 3-vectors, written out: numpy's cross (axis handling for any shape)
    costs more than the six products on the right-hand side's hot path."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def _hat(w: FloatArray) -> FloatArray:
    return (w @ _GEN_FLAT).reshape((*w.shape[:-1], 3, 3))


def _vee(W: FloatArray) -> FloatArray:
    return np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], axis=-1)


def hat(w: Any) -> FloatArray:
    """Cross-product matrix ``w^×`` of a 3-vector, so that ``hat(w) @ x == cross(w, x)``.

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Angular vector (e.g. ω in rad/s, or a rotation vector in rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        The skew-symmetric matrix of McCann (2020), Eq. (13).
    """
    return _hat(as_array(w, (3,), "w"))


def vee(W: Any) -> FloatArray:
    """Inverse of :func:`hat`: the 3-vector of a skew-symmetric matrix.

    Parameters
    ----------
    W : array_like, shape (..., 3, 3)
        Skew-symmetric matrices.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    NotOnGroupError
        If ``W`` is not skew-symmetric to ``SKEW_TOL`` relative to its largest entry
        (gmuk does not silently drop the symmetric part).
    """
    W = as_array(W, (3, 3), "W")
    # in halves: W + Wᵀ itself would overflow for entries near 1e308
    half = float(np.abs(0.5 * W + 0.5 * np.swapaxes(W, -1, -2)).max(initial=0.0))
    scale = max(1.0, float(np.abs(W).max(initial=0.0)))
    if half > 0.5 * SKEW_TOL * scale:
        raise NotOnGroupError(
            f"W must be skew-symmetric (W + Wᵀ = 0 to {SKEW_TOL:g} relative); "
            f"got max|W + Wᵀ| = {2.0 * half:.3g}"
        )
    return _vee(W)


def _exp(w: FloatArray) -> FloatArray:
    flat = np.ascontiguousarray(w.reshape(-1, 3))
    return _kernels.so3_exp(flat).reshape((*w.shape[:-1], 3, 3))


def exp(w: Any) -> FloatArray:
    """Exponential map so(3) → SO(3) (Rodrigues), accurate for every angle.

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Rotation vector θ e (rad): axis e times angle θ.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``R = cos θ I + (sin θ/θ) w^× + ((1 − cos θ)/θ²) w wᵀ``; no series switch is
        needed because both coefficients are evaluated as sinc functions.
    """
    w = as_array(w, (3,), "w")
    return finite_result(_exp(w), "so3.exp", "w", w)


def _log(R: FloatArray) -> FloatArray:
    flat = np.ascontiguousarray(R.reshape(-1, 3, 3))
    return _kernels.so3_log(flat).reshape(R.shape[:-1])


def log(R: Any) -> FloatArray:
    """Logarithm SO(3) → so(3), the rotation vector with angle θ ∈ [0, π].

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices (checked: RᵀR = I to 1e-9 and det = +1).

    Returns
    -------
    ndarray, shape (..., 3)
        Rotation vector θ e (rad). At exactly θ = π both ±π e are valid; the sign is
        then chosen from the largest axis component being positive.

    Notes
    -----
    θ comes from ``atan2(|vee(R − Rᵀ)|/2, (tr R − 1)/2)``, accurate at every angle. The axis
    comes from the antisymmetric part, except near π (sin θ < 0.1, cos θ < 0) where it is
    read from the symmetric part so that a rotation by exactly π works.
    """
    return _log(check_rotation(R, "R"))
