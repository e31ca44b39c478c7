"""Rigid-body dynamics on SE(3) as pure functions (McCann 2020, Eqs. 10–11, 17–19).

The body frame B sits at the centre of mass. Twists ``V_B = [ω; v]`` are the velocity of B
relative to N expressed in B (rad/s, m/s); wrenches ``τ_B = [L; f]`` are torques about the
centre of mass and forces, expressed in B (N·m, N).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmuk._numba import njit
from gmuk._validation import NOT_REAL, FloatArray, as_array, check_se3
from gmuk.errors import InertiaError
from gmuk.lie import se3

__all__ = [
    "check_inertia",
    "free_acceleration",
    "g_ddot",
    "kinetic_energy",
    "rigid_free_accel",
    "spatial_inertia",
    "spatial_momentum",
]

#: Relative tolerance for symmetry of J and for the triangle inequalities of its moments.
INERTIA_TOL = 1e-9


@njit(cache=True)
def rigid_free_accel(
    V: np.ndarray, J: np.ndarray, Jinv: np.ndarray, m: np.ndarray, Q: np.ndarray
) -> np.ndarray:
    """V̇ = 𝕀⁻¹(ad*_V 𝕀 V + Q) for n rigid bodies: (n, 6) twists and wrenches → (n, 6).

    ad*_V 𝕀V = [Jω × ω; m v × ω] (McCann 2020, Eq. 10b, written out).
    """
    n = V.shape[0]
    out = np.empty((n, 6))
    for k in range(n):
        w0, w1, w2 = V[k, 0], V[k, 1], V[k, 2]
        v0, v1, v2 = V[k, 3], V[k, 4], V[k, 5]
        h0 = J[k, 0, 0] * w0 + J[k, 0, 1] * w1 + J[k, 0, 2] * w2
        h1 = J[k, 1, 0] * w0 + J[k, 1, 1] * w1 + J[k, 1, 2] * w2
        h2 = J[k, 2, 0] * w0 + J[k, 2, 1] * w1 + J[k, 2, 2] * w2
        L0 = h1 * w2 - h2 * w1 + Q[k, 0]
        L1 = h2 * w0 - h0 * w2 + Q[k, 1]
        L2 = h0 * w1 - h1 * w0 + Q[k, 2]
        for i in range(3):
            out[k, i] = Jinv[k, i, 0] * L0 + Jinv[k, i, 1] * L1 + Jinv[k, i, 2] * L2
        im = 1.0 / m[k]
        out[k, 3] = v1 * w2 - v2 * w1 + Q[k, 3] * im
        out[k, 4] = v2 * w0 - v0 * w2 + Q[k, 4] * im
        out[k, 5] = v0 * w1 - v1 * w0 + Q[k, 5] * im
    return out


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
        Mass–inertia tensor 𝕀 = blkdiag(J, m I₃) from :func:`spatial_inertia` (the body
        frame at the centre of mass).
    wrench : array_like, shape (..., 6), optional
        Total applied wrench [L; f] in the body frame (N·m, N): external plus control
        (τ + u in the thesis). Zero if omitted.

    Returns
    -------
    ndarray, shape (..., 6)
        ``V̇ = [ω̇; v̇]`` (rad/s², m/s²): the rate of the body-frame components of V.
        For 𝕀 = blkdiag(J, mI) this is Euler's equation ``J ω̇ = Jω × ω + L`` and
        ``v̇ = v × ω + f/m``, evaluated by the kernel the System and the compiled loop use
        (:func:`rigid_free_accel`), which writes ad*_V 𝕀V out without the
        term m v × v (zero, but of order ε m|v|² when evaluated: 1e-5 N·m for 500 kg at
        7 km/s).

    Raises
    ------
    InertiaError
        If 𝕀 is not of the form blkdiag(J, m I₃) (its off-diagonal blocks zero and its
        lower block m times the identity, exactly as :func:`spatial_inertia` builds it).
    """
    V = as_array(V, (6,), "V")
    I = as_array(inertia, (6, 6), "inertia")
    tau = np.zeros(6) if wrench is None else as_array(wrench, (6,), "wrench")
    m = I[..., 3, 3]
    lower = I[..., 3:, 3:]
    if (
        np.any(I[..., :3, 3:] != 0.0)
        or np.any(I[..., 3:, :3] != 0.0)
        or np.any(lower != m[..., None, None] * np.eye(3))
        or not np.all(m > 0.0)
    ):
        raise InertiaError(
            "inertia must be blkdiag(J, m I₃) with m > 0, the mass–inertia tensor about the "
            "centre of mass (gmuk.dynamics.spatial_inertia); got off-diagonal blocks, a lower "
            f"block that is not m times the identity, or m ≤ 0 (m = {m.ravel()[:3].tolist()})"
        )
    shape = np.broadcast_shapes(V.shape[:-1], I.shape[:-2], tau.shape[:-1])
    n = int(np.prod(shape))
    # fresh C-contiguous float64 arrays: the types the kernel is compiled for
    J = np.array(np.broadcast_to(I[..., :3, :3], (*shape, 3, 3)), dtype=np.float64).reshape(n, 3, 3)
    out = rigid_free_accel(
        np.array(np.broadcast_to(V, (*shape, 6)), dtype=np.float64).reshape(n, 6),
        J,
        np.linalg.inv(J),
        np.array(np.broadcast_to(m, shape), dtype=np.float64).reshape(n),
        np.array(np.broadcast_to(tau, (*shape, 6)), dtype=np.float64).reshape(n, 6),
    )
    return out.reshape(*shape, 6)


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
