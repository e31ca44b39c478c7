"""Euler angles of the 3-2-1 and 3-1-3 sequences, to and from rotation matrices ``R_NB``.

Convention: ``angles[..., i]`` is the rotation about body axis ``seq[i]``, applied in order
(intrinsic rotations), so that

* ``"321"``: ``R_NB = R₃(ψ) R₂(θ) R₁(φ)`` with ``angles = [ψ, θ, φ]`` (yaw, pitch, roll);
* ``"313"``: ``R_NB = R₃(Ω) R₁(i) R₃(ω)`` with ``angles = [Ω, i, ω]``,

where ``Rₖ(a)`` is the active rotation by ``a`` about axis k. Equivalently, the
direction-cosine matrix ``[BN] = R_NBᵀ = M₁(φ) M₂(θ) M₃(ψ)`` of Schaub & Junkins,
*Analytical Mechanics of Space Systems* (2018), §3.3. All angles in radians.

Ranges returned by :func:`from_matrix`: for "321", ψ, φ ∈ (−π, π] and θ ∈ [−π/2, π/2];
for "313", Ω, ω ∈ (−π, π] and i ∈ [0, π]. At the singular attitudes (θ = ±π/2 for "321",
i = 0 or π for "313") only a sum or difference of the outer angles is defined: the last
angle is then set to 0 and the first carries the whole rotation.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from gmuk._validation import FloatArray, as_array, check_rotation
from gmuk.attitude import axis_rotation
from gmuk.errors import EulerSequenceError

__all__ = ["SEQUENCES", "from_matrix", "to_matrix"]

Sequence = Literal["321", "313"]
SEQUENCES: tuple[str, ...] = ("321", "313")

# Below this |cos θ| (321) or |sin i| (313), the attitude is treated as singular. The angles
# returned there reproduce R to about 2 × _GIMBAL_TOL.
_GIMBAL_TOL = 1e-14


def _check_seq(seq: str) -> None:
    if not isinstance(seq, str) or seq not in SEQUENCES:
        raise EulerSequenceError(f"seq must be one of {SEQUENCES}; got {seq!r}")


def _atan2(y: FloatArray, x: FloatArray) -> FloatArray:
    """atan2 with values in (−π, π]: −π (from y = −0.0 or a rounded residual) becomes π."""
    a = np.arctan2(y, x)
    return np.where(a <= -np.pi, np.pi, a)


def to_matrix(angles: Any, seq: Sequence = "321") -> FloatArray:
    """Rotation matrix ``R_NB`` from Euler angles.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Angles (rad) about the axes of ``seq``, in order.
    seq : {"321", "313"}

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    _check_seq(seq)
    a = as_array(angles, (3,), "angles")
    axes = [int(ch) - 1 for ch in seq]
    return (
        axis_rotation(axes[0], a[..., 0])
        @ axis_rotation(axes[1], a[..., 1])
        @ axis_rotation(axes[2], a[..., 2])
    )


def from_matrix(R: Any, seq: Sequence = "321") -> FloatArray:
    """Euler angles of a rotation matrix ``R_NB``.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices (checked).
    seq : {"321", "313"}

    Returns
    -------
    ndarray, shape (..., 3)
        Angles (rad) in the ranges given in the module docstring.
    """
    _check_seq(seq)
    R = check_rotation(R, "R")
    if seq == "321":
        cth = np.hypot(R[..., 0, 0], R[..., 1, 0])
        th = np.arctan2(-R[..., 2, 0], cth)
        regular = cth > _GIMBAL_TOL
        psi = np.where(
            regular,
            _atan2(R[..., 1, 0], R[..., 0, 0]),
            # θ = ±π/2: R = R₃(ψ ∓ φ)-like; with φ = 0, ψ from the second column.
            _atan2(-R[..., 0, 1], R[..., 1, 1]),
        )
        # φ from the residual R₁(φ) = (R₃(ψ) R₂(θ))ᵀ R, not from row 3 of R alone: near
        # gimbal lock ψ and φ are each ill-conditioned (error ε/cos θ) and only this keeps
        # the three angles consistent, so that they reproduce R to round-off.
        M = np.swapaxes(axis_rotation(2, psi) @ axis_rotation(1, th), -1, -2) @ R
        phi = np.where(regular, _atan2(M[..., 2, 1], M[..., 1, 1]), 0.0)
        return np.stack([psi, th, phi], axis=-1)
    sin_i = np.hypot(R[..., 0, 2], R[..., 1, 2])
    inc = np.arctan2(sin_i, R[..., 2, 2])
    regular = sin_i > _GIMBAL_TOL
    raan = np.where(
        regular, _atan2(R[..., 0, 2], -R[..., 1, 2]), _atan2(R[..., 1, 0], R[..., 0, 0])
    )
    # ω from the residual R₃(ω) = (R₃(Ω) R₁(i))ᵀ R (see the 3-2-1 case).
    M = np.swapaxes(axis_rotation(2, raan) @ axis_rotation(0, inc), -1, -2) @ R
    argp = np.where(regular, _atan2(M[..., 1, 0], M[..., 0, 0]), 0.0)
    return np.stack([raan, inc, argp], axis=-1)
