"""Lie groups SO(3) and SE(3): pure array functions (McCann 2020, Chapter 2).

Modules
-------
so3
    hat, vee, exp, log for rotations.
se3
    hat, vee, exp, log, inverse, Ad, ad, ad_star, dexp, dexp_inv for rigid motions,
    with twists ordered [ω; v].
euler
    3-2-1 and 3-1-3 Euler angles to and from rotation matrices.
conventions
    Basilisk's MRPs σ_BN, ω_BN_B, r_BN_N, v_BN_N and Pinocchio's SE3, Motion ([v; ω]) to and
    from gmuk's g_NB and V_B = [ω; v].
"""

from gmuk.lie import conventions, euler, se3, so3

__all__ = ["conventions", "euler", "se3", "so3"]
