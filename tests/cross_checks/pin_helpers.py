"""The one place where gmuk's [ω; v] ordering meets Pinocchio's [v; ω] ordering.

gmuk orders twists ``V = [ω; v]``, wrenches ``τ = [L; f]`` and exponential coordinates
``ξ = [θ; ρ]`` angular first (McCann 2020, Eq. 9); Pinocchio orders motions and forces
linear first. The conversions live in :mod:`gmuk.crosscheck` (which ``gmuk check`` runs); the
cross-check tests take them from here under these names, so that the tests and the
installed check convert the same way (``docs/conventions.rst``, Ordering).

``SWAP`` is the permutation ``[[0, I₃], [I₃, 0]]`` as an index array; it is symmetric and
its own inverse, so the same two functions convert in both directions.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from gmuk.crosscheck import _SWAP as SWAP
from gmuk.crosscheck import _free_flyer_model
from gmuk.crosscheck import _from_pin_se3 as from_pin_se3
from gmuk.crosscheck import _q_from_g as q_from_g
from gmuk.crosscheck import _swap_op as swap_op
from gmuk.crosscheck import _swap_vec as swap_vec
from gmuk.crosscheck import _to_pin_se3 as to_pin_se3

__all__ = [
    "SWAP",
    "free_flyer_model",
    "from_pin_se3",
    "q_from_g",
    "swap_op",
    "swap_vec",
    "to_pin_se3",
]


def free_flyer_model(mass: float, J: np.ndarray) -> tuple[pin.Model, pin.Data]:
    """A Pinocchio model of one rigid body on a free-flyer joint, without gravity.

    The body's centre of mass is at the joint origin, so the joint frame is gmuk's body
    frame B and the joint velocity ``v = [v_lin; ω]`` is the body twist in Pinocchio order.
    """
    return _free_flyer_model([(mass, J)])
