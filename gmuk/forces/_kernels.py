"""Compiled kernels of the built-in force models (the integrator's hot path)."""

from __future__ import annotations

import math

from gmuk._numba import njit

__all__ = ["gravity_gradient_wrench"]


@njit(cache=True)
def gravity_gradient_wrench(g, mu, m, J, out):  # type: ignore[no-untyped-def]
    """Write McCann (2020) Eq. 23's body-frame wrench [L; f] (N·m, N) of a rigid body of mass
    m and central inertia J (3, 3) at pose g (4, 4) in the field of a point mass μ at the
    origin into ``out`` (6,): with r_B = Rᵀ r,

    ``L = 3μ/r⁵ r_B × J r_B``,
    ``f = −μm/r³ (r_B + 3/(m r²) (J r_B + ½(tr J − 5 r_Bᵀ J r_B / r²) r_B))``.
    """
    x = g[0, 0] * g[0, 3] + g[1, 0] * g[1, 3] + g[2, 0] * g[2, 3]
    y = g[0, 1] * g[0, 3] + g[1, 1] * g[1, 3] + g[2, 1] * g[2, 3]
    z = g[0, 2] * g[0, 3] + g[1, 2] * g[1, 3] + g[2, 2] * g[2, 3]
    jx = J[0, 0] * x + J[0, 1] * y + J[0, 2] * z
    jy = J[1, 0] * x + J[1, 1] * y + J[1, 2] * z
    jz = J[2, 0] * x + J[2, 1] * y + J[2, 2] * z
    r2 = x * x + y * y + z * z
    rn = math.sqrt(r2)
    k = 3.0 * mu / (r2 * r2 * rn)
    out[0] = k * (y * jz - z * jy)
    out[1] = k * (z * jx - x * jz)
    out[2] = k * (x * jy - y * jx)
    c = 0.5 * (J[0, 0] + J[1, 1] + J[2, 2] - 5.0 * (x * jx + y * jy + z * jz) / r2)
    a = 3.0 / (m * r2)
    kf = -mu * m / (r2 * rn)
    out[3] = kf * (x + a * (jx + c * x))
    out[4] = kf * (y + a * (jy + c * y))
    out[5] = kf * (z + a * (jz + c * z))
