"""Rigid-body dynamics on SE(3) as pure functions (McCann 2020, Eqs. 10–11, 17–19).

The body frame B sits at the centre of mass. Twists ``V_B = [ω; v]`` are the velocity of B
relative to N expressed in B (rad/s, m/s); wrenches ``τ_B = [L; f]`` are torques about the
centre of mass and forces, expressed in B (N·m, N).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmuk._validation import NOT_REAL, FloatArray, as_array, check_se3
from gmuk.errors import InertiaError
from gmuk.lie import se3

__all__ = [
    "check_inertia",
    "free_acceleration",
    "g_ddot",
    "kinetic_energy",
    "spatial_inertia",
    "spatial_momentum",
]

#: Relative tolerance for symmetry of J and for the triangle inequalities of its moments.
INERTIA_TOL = 1e-9

_TWO_COLUMNS = np.ones(2)


def check_inertia(mass: Any, J: Any, name: str = "body") -> tuple[float, FloatArray]:
    """Validate a mass and a central inertia tensor.

    Parameters
    ----------
    mass : float
        Mass m (kg), finite and > 0.
    J : array_like, shape (3, 3)
        Inertia tensor about the centre of mass in the body frame (kg·m²): symmetric,
        positive definite, principal moments satisfying ``Jᵢ + Jⱼ ≥ Jₖ`` (to 1e-9 relative).
    name : str
        Used in error messages.

    Returns
    -------
    (float, ndarray (3, 3))
        The mass and J as float64.

    Raises
    ------
    InertiaError
        Listing every violated condition with the values that came in.
    """
    problems: list[str] = []
    try:
        if isinstance(mass, NOT_REAL):  # float() would take True and "2" silently
            raise TypeError
        m = float(mass)
    except (TypeError, ValueError, OverflowError):
        raise InertiaError(f"{name}: mass must be a positive number (kg); got {mass!r}") from None
    if not np.isfinite(m) or m <= 0.0:
        problems.append(f"mass must be finite and > 0 (kg); got {m!r}")
    Jm = as_array(J, (3, 3), f"{name}: inertia", batch=False)
    scale = max(float(np.abs(Jm).max()), np.finfo(float).tiny)
    asym = float(np.abs(Jm / scale - Jm.T / scale).max()) * scale  # no overflow near 1e308
    if asym > INERTIA_TOL * scale:
        problems.append(f"inertia must be symmetric; got max|J − Jᵀ| = {asym:.3g} kg·m²")
    else:
        # eigenvalues of J / scale, then scaled back: no overflow for entries near 1e308
        moments = np.linalg.eigvalsh(0.5 * (Jm / scale + Jm.T / scale)) * scale
        if moments[0] <= 0.0:
            problems.append(
                f"inertia must be positive definite; got principal moments "
                f"{np.array2string(moments, precision=6)} kg·m²"
            )
        elif moments[0] / scale + moments[1] / scale < moments[2] / scale * (1.0 - INERTIA_TOL):
            problems.append(
                f"principal moments must satisfy the triangle inequality J₁ + J₂ ≥ J₃; got "
                f"{np.array2string(moments, precision=6)} kg·m² "
                f"({moments[0] + moments[1]:.6g} < {moments[2]:.6g})"
            )
    if problems:
        raise InertiaError(f"{name}: " + "; ".join(problems))
    return m, Jm


def spatial_inertia(mass: Any, J: Any) -> FloatArray:
    """The mass–inertia tensor ``𝕀 = blkdiag(J, m I₃)`` (McCann 2020, Eq. 11).

    Parameters
    ----------
    mass : float
        Mass (kg).
    J : array_like, shape (3, 3)
        Central inertia tensor in the body frame (kg·m²).

    Returns
    -------
    ndarray, shape (6, 6)
        Ordered to act on [ω; v] and return [h; p] (kg·m²/s, kg·m/s).

    Raises
    ------
    InertiaError
        See :func:`check_inertia`.
    """
    m, Jm = check_inertia(mass, J)
    out = np.zeros((6, 6))
    out[:3, :3] = Jm
    out[3:, 3:] = m * np.eye(3)
    return out


def free_acceleration(V: Any, inertia: Any, wrench: Any = None) -> FloatArray:
    """Body acceleration of a free rigid body, ``V̇ = 𝕀⁻¹(ad*_V 𝕀 V + τ)`` (Eq. 10b).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Body twist [ω; v] (rad/s, m/s).
    inertia : array_like, shape (6, 6) or (..., 6, 6)
        Mass–inertia tensor 𝕀 from :func:`spatial_inertia`.
    wrench : array_like, shape (..., 6), optional
        Total applied wrench [L; f] in the body frame (N·m, N): external plus control
        (τ + u in the thesis). Zero if omitted.

    Returns
    -------
    ndarray, shape (..., 6)
        ``V̇ = [ω̇; v̇]`` (rad/s², m/s²): the rate of the body-frame components of V.
        For 𝕀 = blkdiag(J, mI) this is Euler's equation ``J ω̇ = Jω × ω + L`` and
        ``v̇ = v × ω + f/m``.
    """
    V = as_array(V, (6,), "V")
    I = as_array(inertia, (6, 6), "inertia")
    h = (I @ V[..., None])[..., 0]
    # ad*_V 𝕀V = [h_ang × ω + h_lin × v; h_lin × ω]. For 𝕀 = blkdiag(J, mI) the term
    # h_lin × v = m v × v vanishes, but evaluated as written it leaves a spurious torque of
    # order ε m|v|² (1e-5 N·m for 500 kg at 7 km/s). For the torque row, the isotropic part
    # I₃₃ v of h_lin, whose cross product with v is exactly zero, is removed first.
    H = h[..., None] * _TWO_COLUMNS
    H[..., 3:, 0] -= I[..., 3, 3][..., None] * V[..., 3:]
    both = np.swapaxes(se3._ad(V), -1, -2) @ H
    rhs = both[..., 1]
    rhs[..., :3] = both[..., :3, 0]
    if wrench is not None:
        rhs = rhs + as_array(wrench, (6,), "wrench")
    return np.linalg.solve(I, rhs[..., None])[..., 0]


def g_ddot(g: Any, V: Any, V_dot: Any) -> FloatArray:
    """Second time derivative of the configuration, ``g̈ = g (V^² + V̇^)`` (Eqs. 17–19).

    With ``V̇ = V̇_a + V̇_c`` this is ``g̈_a + g̈_c`` of Eqs. 18–19.

    Parameters
    ----------
    g : array_like, shape (..., 4, 4)
        Pose g_NB.
    V : array_like, shape (..., 6)
        Body twist (rad/s, m/s).
    V_dot : array_like, shape (..., 6)
        Body acceleration (rad/s², m/s²).

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``g̈`` (an element of T²SE(3); its last row is zero).
    """
    g = check_se3(g, "g")
    Vh = se3._hat(as_array(V, (6,), "V"))
    return g @ (Vh @ Vh + se3._hat(as_array(V_dot, (6,), "V_dot")))


def kinetic_energy(V: Any, inertia: Any) -> FloatArray:
    """Kinetic energy ``½ Vᵀ 𝕀 V`` (J).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Body twists [ω; v] (rad/s, m/s), body frame.
    inertia : array_like, shape (6, 6) or (..., 6, 6)
        Mass–inertia tensor 𝕀 (kg·m², kg), body frame (:func:`spatial_inertia`).

    Returns
    -------
    ndarray, shape (...)
    """
    V = as_array(V, (6,), "V")
    I = as_array(inertia, (6, 6), "inertia")
    return 0.5 * np.einsum("...i,...i->...", V, (I @ V[..., None])[..., 0])


def spatial_momentum(g: Any, V: Any, inertia: Any) -> FloatArray:
    """Momentum in the inertial frame, ``h_N = Ad_{g⁻¹}ᵀ 𝕀 V`` = [r × p + R J ω; R m v].

    Conserved for a free body with no applied wrench.

    Parameters
    ----------
    g : array_like, shape (..., 4, 4)
        Pose g_NB.
    V : array_like, shape (..., 6)
        Body twist.
    inertia : array_like, shape (6, 6) or (..., 6, 6)

    Returns
    -------
    ndarray, shape (..., 6)
        [angular momentum about the origin of N; linear momentum], in N (kg·m²/s, kg·m/s).
    """
    g = check_se3(g, "g")
    V = as_array(V, (6,), "V")
    I = as_array(inertia, (6, 6), "inertia")
    AdT = np.swapaxes(se3._Ad(se3._inverse(g)), -1, -2)
    return (AdT @ (I @ V[..., None]))[..., 0]
