"""Compiled kernels of the built-in force models (the integrator's hot path)."""

from __future__ import annotations

import math

import numpy as np

from gmuk._numba import njit
from gmuk.gravity._kernels import acceleration_at

__all__ = [
    "GRAVITY_GRADIENT",
    "HARMONIC_POINT",
    "POINT_MASS",
    "SPRING",
    "UNIFORM",
    "apply_term",
    "gravity_gradient_wrench",
]


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


# ---------------------------------------------------------------------------------------
# Compiled terms: the built-in force models' formulas, as the compiled step loop
# (gmuk.integrators._compiled) calls them. Each model's ``_compiled_term`` names its code
# and packs its parameters; the Python methods remain the definition, and the tests hold
# the two to the same numbers.

#: −μ m r/|r|³ (PointMassGravity; GravityGradient on point masses). Parameters: (μ,).
POINT_MASS = 0
#: McCann (2020) Eq. 23 on a rigid body (GravityGradient). Parameters: (μ,).
GRAVITY_GRADIENT = 1
#: m R_FNᵀ ∇U(R_FN r_N) on a point mass (SphericalHarmonicGravity), F spinning uniformly
#: about N's third axis. Parameters: (η₀, ω); the field's data vector beside them.
HARMONIC_POINT = 2
#: m g_N (UniformGravity). Parameters: (g_N,).
UNIFORM = 3
#: −k(r − r_a) − c v (LinearSpringDamper). Parameters: (k, c, r_a).
SPRING = 4


@njit(cache=True)
def apply_term(code, rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """Write one built-in force model's load on one body into ``out``: the body-frame
    wrench [L; f] (6,) of a rigid body at pose ``g`` (4, 4) with twist ``V`` (6,), or the
    force f_N (3,) on a point mass, then at ``g[:3, 3]`` with velocity ``V[:3]`` (both N).

    Returns 0, or the spherical-harmonic kernel's nonzero status code.
    """
    if code == GRAVITY_GRADIENT and rigid:
        gravity_gradient_wrench(g, p[0], m, J, out)
        return 0
    if rigid:
        x, y, z = g[0, 3], g[1, 3], g[2, 3]
        # inertial velocity R v_B, for the damper
        vx = g[0, 0] * V[3] + g[0, 1] * V[4] + g[0, 2] * V[5]
        vy = g[1, 0] * V[3] + g[1, 1] * V[4] + g[1, 2] * V[5]
        vz = g[2, 0] * V[3] + g[2, 1] * V[4] + g[2, 2] * V[5]
    else:
        x, y, z = g[0, 3], g[1, 3], g[2, 3]
        vx, vy, vz = V[0], V[1], V[2]
    if code == POINT_MASS or code == GRAVITY_GRADIENT:
        rn = math.sqrt(x * x + y * y + z * z)
        k = -p[0] * m / rn**3
        fx, fy, fz = k * x, k * y, k * z
    elif code == HARMONIC_POINT:
        eta = p[0] + p[1] * t
        c, s = math.cos(eta), math.sin(eta)
        r_F = np.empty(3)
        r_F[0] = c * x + s * y
        r_F[1] = -s * x + c * y
        r_F[2] = z
        a_F = np.empty(3)
        status = acceleration_at(field, r_F, a_F, True)
        if status != 0:
            return status
        fx = m * (c * a_F[0] - s * a_F[1])
        fy = m * (s * a_F[0] + c * a_F[1])
        fz = m * a_F[2]
    elif code == UNIFORM:
        fx, fy, fz = m * p[0], m * p[1], m * p[2]
    else:  # SPRING
        fx = -p[0] * (x - p[2]) - p[1] * vx
        fy = -p[0] * (y - p[3]) - p[1] * vy
        fz = -p[0] * (z - p[4]) - p[1] * vz
    if rigid:  # [0; Rᵀ f_N]
        out[0] = out[1] = out[2] = 0.0
        out[3] = g[0, 0] * fx + g[1, 0] * fy + g[2, 0] * fz
        out[4] = g[0, 1] * fx + g[1, 1] * fy + g[2, 1] * fz
        out[5] = g[0, 2] * fx + g[1, 2] * fy + g[2, 2] * fz
    else:
        out[0], out[1], out[2] = fx, fy, fz
    return 0
