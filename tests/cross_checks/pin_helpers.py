"""The one place where gmuk's [ω; v] ordering meets Pinocchio's [v; ω] ordering.

gmuk orders twists ``V = [ω; v]``, wrenches ``τ = [L; f]`` and exponential coordinates
``ξ = [θ; ρ]`` angular first (McCann 2020, Eq. 9); Pinocchio orders motions and forces
linear first. Every conversion between the two goes through :data:`SWAP` here, and nowhere
else in the test suite (DESIGN.md, Conventions 1).

``SWAP`` is the permutation matrix ``[[0, I₃], [I₃, 0]]``; it is symmetric and its own
inverse, so the same two functions convert in both directions.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

__all__ = [
    "SWAP",
    "free_flyer_model",
    "from_pin_se3",
    "q_from_g",
    "swap_op",
    "swap_vec",
    "to_pin_se3",
]

#: Permutation [ω; v] ↔ [v; ω] as an index array (applied on the last axis).
SWAP = np.array([3, 4, 5, 0, 1, 2])


def swap_vec(x: np.ndarray) -> np.ndarray:
    """Reorder 6-vectors between [angular; linear] and [linear; angular] (last axis)."""
    return np.asarray(x, dtype=float)[..., SWAP]


def swap_op(A: np.ndarray) -> np.ndarray:
    """Reorder a 6×6 operator acting on and returning 6-vectors: ``P A P`` with P = SWAP."""
    return np.asarray(A, dtype=float)[..., SWAP, :][..., :, SWAP]


def to_pin_se3(g: np.ndarray) -> pin.SE3:
    """A 4×4 homogeneous matrix as a ``pin.SE3`` (no reordering is involved)."""
    g = np.asarray(g, dtype=float)
    return pin.SE3(g[:3, :3].copy(), g[:3, 3].copy())


def from_pin_se3(M: pin.SE3) -> np.ndarray:
    """A ``pin.SE3`` as a 4×4 homogeneous matrix."""
    return np.array(M.homogeneous)


def free_flyer_model(mass: float, J: np.ndarray) -> tuple[pin.Model, pin.Data]:
    """A Pinocchio model of one rigid body on a free-flyer joint, without gravity.

    The body's centre of mass is at the joint origin, so the joint frame is gmuk's body
    frame B and the joint velocity ``v = [v_lin; ω]`` is the body twist in Pinocchio order.
    """
    model = pin.Model()
    model.gravity = pin.Motion.Zero()
    jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "free_flyer")
    inertia = pin.Inertia(float(mass), np.zeros(3), np.asarray(J, dtype=float))
    model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
    return model, model.createData()


def q_from_g(g: np.ndarray) -> np.ndarray:
    """Free-flyer configuration ``[translation; quaternion (x, y, z, w)]`` of a pose g_NB."""
    g = np.asarray(g, dtype=float)
    quat = pin.Quaternion(g[:3, :3].copy())
    return np.concatenate([g[:3, 3], quat.coeffs()])
