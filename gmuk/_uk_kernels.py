"""Compiled kernels for the System's hot path (free accelerations, dense UK solve)."""

from __future__ import annotations

import numpy as np
from numba import njit


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


@njit(cache=True)
def uk_dense(
    A: np.ndarray, b: np.ndarray, a: np.ndarray, Minv_sqrt: np.ndarray, rcond: float
) -> tuple[np.ndarray, np.ndarray, int, float, float]:
    """Moore–Penrose UK solve through the SVD of B = A M^{-1/2} (McCann 2020, Eq. 64).

    Returns (ν̇_c, λ, rank, ‖A(a + ν̇_c) − b‖₂, ‖A a‖₂).
    """
    Aa = A @ a
    r = b - Aa
    B = A @ Minv_sqrt
    U, sig, Wt = np.linalg.svd(B, full_matrices=False)
    cut = rcond * sig[0] if sig.size else 0.0
    rank = 0
    for i in range(sig.size):
        if sig[i] > cut:
            rank += 1
    Ur = np.ascontiguousarray(U[:, :rank])
    Wr = np.ascontiguousarray(Wt[:rank].T)
    c = (Ur.T @ r) / sig[:rank]
    y = Wr @ c
    lam = Ur @ (c / sig[:rank])
    ac = Minv_sqrt @ y
    res = A @ (a + ac) - b
    return ac, lam, rank, np.sqrt(np.sum(res * res)), np.sqrt(np.sum(Aa * Aa))


@njit(cache=True, inline="always")
def _hat4(x: np.ndarray, M: np.ndarray) -> None:
    M[0, 0] = M[1, 1] = M[2, 2] = 0.0
    M[0, 1], M[0, 2], M[1, 2] = -x[2], x[1], -x[0]
    M[1, 0], M[2, 0], M[2, 1] = x[2], -x[1], x[0]
    M[0, 3], M[1, 3], M[2, 3] = x[3], x[4], x[5]
    M[3, 0] = M[3, 1] = M[3, 2] = M[3, 3] = 0.0


@njit(cache=True, inline="always")
def _mul4(A: np.ndarray, B: np.ndarray, out: np.ndarray) -> None:
    for i in range(4):
        for j in range(4):
            out[i, j] = (
                A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j] + A[i, 3] * B[3, j]
            )


@njit(cache=True)
def tracking_b(
    g: np.ndarray, V: np.ndarray, gd: np.ndarray, Vd: np.ndarray, Vd_dot: np.ndarray
) -> np.ndarray:
    """b of Eq. 67, projected: se(3) part of g⁻¹ g_d (V_d^² + V̇_d^) − V^² as a twist.

    Explicit 4×4 loops: BLAS calls on such small matrices cost more than the arithmetic.
    """
    H = np.empty((4, 4))
    Hd = np.empty((4, 4))
    T1 = np.empty((4, 4))
    T2 = np.empty((4, 4))
    ginv = np.zeros((4, 4))
    for i in range(3):
        for j in range(3):
            ginv[i, j] = g[j, i]
        ginv[i, 3] = -(g[0, i] * g[0, 3] + g[1, i] * g[1, 3] + g[2, i] * g[2, 3])
    ginv[3, 3] = 1.0
    _hat4(Vd, Hd)
    _mul4(Hd, Hd, T1)  # V_d^²
    _hat4(Vd_dot, H)
    for i in range(4):
        for j in range(4):
            T1[i, j] += H[i, j]  # V_d^² + V̇_d^
    _mul4(ginv, gd, T2)  # g⁻¹ g_d
    _mul4(T2, T1, Hd)  # g⁻¹ g_d (V_d^² + V̇_d^)
    _hat4(V, H)
    _mul4(H, H, T1)  # V^²
    out = np.empty(6)
    out[0] = 0.5 * ((Hd[2, 1] - T1[2, 1]) - (Hd[1, 2] - T1[1, 2]))
    out[1] = 0.5 * ((Hd[0, 2] - T1[0, 2]) - (Hd[2, 0] - T1[2, 0]))
    out[2] = 0.5 * ((Hd[1, 0] - T1[1, 0]) - (Hd[0, 1] - T1[0, 1]))
    out[3] = Hd[0, 3] - T1[0, 3]
    out[4] = Hd[1, 3] - T1[1, 3]
    out[5] = Hd[2, 3] - T1[2, 3]
    return out
