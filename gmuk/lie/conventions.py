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

from gmuk._validation import FloatArray, as_array, check_rotation, check_se3
from gmuk.lie import so3

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


def matrix_from_mrp(sigma_BN: Any) -> FloatArray:
    """The rotation ``R_NB`` of the modified Rodrigues parameters ``σ_BN``.

    ``R_NB = [BN]ᵀ`` with Schaub and Junkins's
    ``[BN] = I + (8[σ̃]² − 4(1 − σ²)[σ̃]) / (1 + σ²)²`` (their Eq. 3.152), σ² = σᵀσ.
    Any σ, shadow set or not, gives the same matrix as its shadow.

    Parameters
    ----------
    sigma_BN : array_like (..., 3)
        MRPs of B relative to N (dimensionless).

    Returns
    -------
    ndarray (..., 3, 3)
        ``R_NB``: maps body components to N components.
    """
    s = as_array(sigma_BN, (3,), "sigma_BN")
    S = so3.hat(s)
    s2 = np.einsum("...i,...i->...", s, s)[..., None, None]
    return np.eye(3) + (8.0 * S @ S + 4.0 * (1.0 - s2) * S) / (1.0 + s2) ** 2


def _quaternion(R: FloatArray) -> FloatArray:
    """Unit quaternion (w, x, y, z), w ≥ 0, of rotation matrices (..., 3, 3) (Shepperd's
    method: the largest of 4w², 4x², 4y², 4z² chooses the formula, for accuracy)."""
    t = np.trace(R, axis1=-2, axis2=-1)
    d = np.stack([t, R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]], axis=-1)
    k = np.argmax(d, axis=-1)
    r = R
    # the four candidate formulas, each scaled by 4·(its own largest component)
    cand = np.stack(
        [
            np.stack(
                [
                    1 + t,
                    r[..., 2, 1] - r[..., 1, 2],
                    r[..., 0, 2] - r[..., 2, 0],
                    r[..., 1, 0] - r[..., 0, 1],
                ],
                axis=-1,
            ),
            np.stack(
                [
                    r[..., 2, 1] - r[..., 1, 2],
                    1 + 2 * r[..., 0, 0] - t,
                    r[..., 0, 1] + r[..., 1, 0],
                    r[..., 0, 2] + r[..., 2, 0],
                ],
                axis=-1,
            ),
            np.stack(
                [
                    r[..., 0, 2] - r[..., 2, 0],
                    r[..., 0, 1] + r[..., 1, 0],
                    1 + 2 * r[..., 1, 1] - t,
                    r[..., 1, 2] + r[..., 2, 1],
                ],
                axis=-1,
            ),
            np.stack(
                [
                    r[..., 1, 0] - r[..., 0, 1],
                    r[..., 0, 2] + r[..., 2, 0],
                    r[..., 1, 2] + r[..., 2, 1],
                    1 + 2 * r[..., 2, 2] - t,
                ],
                axis=-1,
            ),
        ],
        axis=-2,
    )
    q = np.take_along_axis(cand, k[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def mrp_from_matrix(R_NB: Any) -> FloatArray:
    """The modified Rodrigues parameters ``σ_BN`` of ``R_NB``, the set with ``|σ| ≤ 1``.

    ``σ = ê tan(Φ/4)`` for the principal rotation of B relative to N by Φ ∈ [0, π] about ê;
    with the quaternion ``(q₀, q)`` of that rotation (q₀ ≥ 0), ``σ = q / (1 + q₀)``. At
    Φ = π both σ and its shadow have ``|σ| = 1``; either may be returned.

    Parameters
    ----------
    R_NB : array_like (..., 3, 3)
        Rotation matrices (checked: RᵀR = I, det +1).

    Returns
    -------
    ndarray (..., 3)
        σ_BN (dimensionless), ``|σ| ≤ 1``.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        ``R_NB`` is not a rotation matrix.
    """
    R = check_rotation(R_NB, "R_NB")
    q = _quaternion(R)
    return q[..., 1:] / (1.0 + q[..., :1])


def mrp_shadow(sigma: Any) -> FloatArray:
    """The shadow set ``σˢ = −σ / |σ|²`` of MRPs: the same attitude, the other way round
    (principal angle Φ − 2π). σ = 0 has no shadow (it is at infinity).

    Parameters
    ----------
    sigma : array_like (..., 3)
        MRPs (dimensionless), each nonzero.

    Returns
    -------
    ndarray (..., 3)

    Raises
    ------
    gmuk.errors.DomainError
        Some σ is zero.
    """
    from gmuk.errors import DomainError

    s = as_array(sigma, (3,), "sigma")
    s2 = np.einsum("...i,...i->...", s, s)[..., None]
    if np.any(s2 == 0.0):
        raise DomainError("sigma = 0 (no rotation) has no shadow set: it would be at infinity")
    return -s / s2


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
