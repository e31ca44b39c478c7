"""Conversions between gmuk's conventions and Basilisk's and Pinocchio's.

gmuk writes a body's pose as ``g_NB`` (4×4: ``R_NB`` maps body components to inertial ones,
the translation is r_N, the body origin in N) and its velocity as the body twist
``V_B = [ω; v]``: angular velocity of B relative to N, then the velocity of B's origin,
both in body components (McCann 2020, Eqs. 9–10).

Basilisk (Schaub and Junkins's notation) gives the attitude as modified Rodrigues parameters
``σ_BN`` (B relative to N), the rates ``ω_BN_B`` (B relative to N, in B components), and the
translational state as ``r_BN_N``, ``v_BN_N`` (in N components). The direction cosine matrix
of σ is ``[BN]`` (maps N components to B components), so ``R_NB = [BN]ᵀ``. σ and its shadow
``σˢ = −σ/|σ|²`` are the same attitude; Basilisk keeps ``|σ| ≤ 1`` by switching to the
shadow set, and :func:`mrp_from_matrix` returns that one.

Pinocchio's ``SE3`` object (``M.rotation``, ``M.translation``) is the same map as ``g_NB``
when it is a placement ``oMb`` of the body in the world. Its ``Motion`` and ``Force`` objects,
and ``.vector`` / ``.np`` of them, put the linear part first: ``[v; ω]`` and ``[f; τ]``,
where gmuk puts the angular part first: ``[ω; v]`` and ``[τ; f]`` (McCann 2020, Eq. 9).

References
----------
Schaub, H. and Junkins, J. L., *Analytical Mechanics of Space Systems*, 4th ed., AIAA, 2018,
§3.5 (modified Rodrigues parameters, Eq. 3.152 for [BN] in terms of σ, the shadow set).
Carpentier, J. et al., The Pinocchio C++ library, IEEE/SICE SII 2019 (spatial algebra
conventions: motion and force vectors with the linear part first).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmuk import attitude
from gmuk._validation import FloatArray, as_array, check_se3

__all__ = [
    "from_basilisk",
    "from_pinocchio_motion",
    "from_pinocchio_se3",
    "matrix_from_mrp",
    "mrp_from_matrix",
    "mrp_shadow",
    "swap_halves",
    "to_basilisk",
    "to_pinocchio_motion",
    "to_pinocchio_se3",
]


# MRPs are defined once, in gmuk.attitude; these are their names here (kept for users).
matrix_from_mrp = attitude.R_NB_from_mrp
mrp_from_matrix = attitude.mrp_from_R_NB
mrp_shadow = attitude.mrp_shadow


def to_basilisk(g_NB: Any, V_B: Any) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Basilisk's ``(σ_BN, ω_BN_B, r_BN_N, v_BN_N)`` of gmuk's ``(g_NB, V_B)``.

    Parameters
    ----------
    g_NB : array_like (..., 4, 4)
        Poses of B in N (m for the translation).
    V_B : array_like (..., 6)
        Body twists ``[ω; v]`` (rad/s, m/s) in B.

    Returns
    -------
    sigma_BN : ndarray (..., 3)
        MRPs with ``|σ| ≤ 1``.
    omega_BN_B : ndarray (..., 3)
        Angular velocity of B relative to N in B (rad/s): ``V_B[:3]``.
    r_BN_N : ndarray (..., 3)
        Position of B's origin in N (m).
    v_BN_N : ndarray (..., 3)
        Its velocity in N (m/s): ``R_NB v``.
    """
    g = check_se3(g_NB, "g_NB")
    V = as_array(V_B, (6,), "V_B")
    R = g[..., :3, :3]
    v_N = np.einsum("...ij,...j->...i", R, V[..., 3:])
    return mrp_from_matrix(R), V[..., :3].copy(), g[..., :3, 3].copy(), v_N


def from_basilisk(
    sigma_BN: Any, omega_BN_B: Any, r_BN_N: Any, v_BN_N: Any
) -> tuple[FloatArray, FloatArray]:
    """gmuk's ``(g_NB, V_B)`` of Basilisk's ``(σ_BN, ω_BN_B, r_BN_N, v_BN_N)``.

    Parameters
    ----------
    sigma_BN : array_like (..., 3)
        MRPs of B relative to N (either set).
    omega_BN_B : array_like (..., 3)
        Angular velocity of B relative to N in B (rad/s).
    r_BN_N, v_BN_N : array_like (..., 3)
        Position (m) and velocity (m/s) of B's origin, in N.

    Returns
    -------
    g_NB : ndarray (..., 4, 4)
    V_B : ndarray (..., 6)
        ``[ω_BN_B; R_NBᵀ v_BN_N]`` (rad/s, m/s), in B.
    """
    R = matrix_from_mrp(sigma_BN)
    w = as_array(omega_BN_B, (3,), "omega_BN_B")
    r = as_array(r_BN_N, (3,), "r_BN_N")
    v = as_array(v_BN_N, (3,), "v_BN_N")
    g = np.zeros((*R.shape[:-2], 4, 4))
    g[..., :3, :3], g[..., :3, 3], g[..., 3, 3] = R, r, 1.0
    v_B = np.einsum("...ji,...j->...i", R, v)
    return g, np.concatenate(np.broadcast_arrays(w, v_B), axis=-1)


def swap_halves(x: Any) -> FloatArray:
    """Swap the 3-vector halves of 6-vectors: Pinocchio's ``[v; ω]`` ↔ gmuk's ``[ω; v]``
    (and ``[f; τ]`` ↔ ``[τ; f]``). Its own inverse.

    Parameters
    ----------
    x : array_like (..., 6)

    Returns
    -------
    ndarray (..., 6)
    """
    a = as_array(x, (6,), "x")
    return np.concatenate([a[..., 3:], a[..., :3]], axis=-1)


def to_pinocchio_se3(g_NB: Any) -> Any:
    """A ``pinocchio.SE3`` placement of the pose ``g_NB`` (4, 4) (no batch axes): rotation
    ``R_NB``, translation r_N (m)."""
    import pinocchio as pin

    g = check_se3(g_NB, "g_NB")
    if g.ndim != 2:
        from gmuk.errors import ShapeError

        raise ShapeError(f"g_NB must have shape (4, 4) for one pinocchio.SE3; got {g.shape}")
    return pin.SE3(g[:3, :3].copy(), g[:3, 3].copy())


def from_pinocchio_se3(M: Any) -> FloatArray:
    """The pose ``g_NB`` (4, 4) of a ``pinocchio.SE3`` placement ``M`` (``M.homogeneous``)."""
    return check_se3(np.array(M.homogeneous, dtype=float), "M.homogeneous")


def to_pinocchio_motion(V_B: Any) -> Any:
    """A ``pinocchio.Motion`` of the twist ``V_B = [ω; v]`` (6,) (rad/s, m/s): its
    ``.angular`` is ω, ``.linear`` is v, ``.vector`` is ``[v; ω]``."""
    import pinocchio as pin

    V = as_array(V_B, (6,), "V_B", batch=False)
    return pin.Motion(V[3:].copy(), V[:3].copy())


def from_pinocchio_motion(m: Any) -> FloatArray:
    """The twist ``[ω; v]`` (6,) (rad/s, m/s) of a ``pinocchio.Motion`` ``m``, in the frame
    ``m`` is expressed in (the body frame for a body velocity)."""
    return np.concatenate([np.asarray(m.angular, float), np.asarray(m.linear, float)])
