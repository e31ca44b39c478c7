"""The Udwadia–Kalaba solves: dense, sparse, and on T²SE(3).

Given the block-diagonal mass matrix M (𝕀̄ for rigid bodies), the free accelerations a and
the constraint rows ``A ν̇ = b``, the constraint acceleration is the Moore–Penrose solution

``ν̇_c = M⁻¹ Aᵀ (A M⁻¹ Aᵀ)⁺ (b − A a) = M^{-1/2} (A M^{-1/2})⁺ (b − A a)``

(McCann 2020, Eqs. 2 and 64), and the Lagrange multipliers ``λ = (A M⁻¹ Aᵀ)⁺ (b − A a)``
(Eq. 3), so that the constraint force is ``Q_c = M ν̇_c = Aᵀ λ``. Sign convention: λ is
Pinocchio's ``lambda_c`` and the negative of μ in the KKT system
``[M Aᵀ; A 0][ν̇; μ] = [M a; b]`` (errata).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from gmuk._validation import FloatArray
from gmuk.engine import _uk_kernels
from gmuk.lie import se3

__all__ = [
    "matrix_power_spd",
    "reachable_rows",
    "solve_dense",
    "solve_sparse",
    "solve_tangent_bundle",
]


def solve_dense(
    A: FloatArray,
    b: FloatArray,
    a: FloatArray,
    Minv_sqrt: FloatArray,
    rcond: float | None = None,
) -> tuple[FloatArray, FloatArray, int, float]:
    """Minimum-norm UK solution via the SVD of ``B = A M^{-1/2}``.

    Parameters
    ----------
    A : ndarray (s, n)
    b : ndarray (s,)
    a : ndarray (n,)
        Free acceleration ν̇_a.
    Minv_sqrt : ndarray (n, n)
        ``M^{-1/2}`` (symmetric).
    rcond : float, optional
        Singular values below ``rcond · σ_max`` count as zero; default ``max(s, n) · eps``.

    Returns
    -------
    (ν̇_c (n,), λ (s,), rank, residual ‖A(a + ν̇_c) − b‖₂)
    """
    s, n = A.shape
    if s == 0:
        return np.zeros(n), np.zeros(0), 0, 0.0
    if rcond is None:
        rcond = max(s, n) * float(np.finfo(float).eps)
    ac, lam, rank, residual, _ = _uk_kernels.uk_dense(
        np.ascontiguousarray(A, dtype=float),
        np.asarray(b, dtype=float),
        np.asarray(a, dtype=float),
        np.ascontiguousarray(Minv_sqrt, dtype=float),
        rcond,
    )
    return ac, lam, int(rank), float(residual)


def solve_sparse(
    A: sp.csr_matrix,
    r: FloatArray,
    Minv: sp.csr_matrix,
    Minv_sqrt: sp.csr_matrix,
    method: str = "lu",
    rtol: float = 1e-13,
) -> tuple[FloatArray, FloatArray, int | None]:
    """UK solution for large sparse systems.

    ``method="lu"`` factorises ``K = A M⁻¹ Aᵀ`` (SuperLU, minimum-degree ordering on
    K + Kᵀ): exact, and fast when the constraint graph is chain- or mesh-like, but with
    heavy fill-in for randomly coupled bodies. ``method="cg"`` solves K λ = r by
    Jacobi-preconditioned conjugate gradients (K is symmetric positive semi-definite) to
    ``rtol``; preferable for large randomly coupled systems. If the chosen solve fails
    (singular K with ``"lu"``, no convergence with ``"cg"``), the minimum-norm least-squares
    solution of ``A M^{-1/2} y = r`` is computed by LSMR and ν̇_c = M^{-1/2} y. Agrees with
    :func:`solve_dense` to 1e-10.

    Parameters
    ----------
    A : scipy.sparse matrix (s, n)
        Constraint rows.
    r : ndarray (s,)
        ``b − A ν̇_a``, the constraint violation of the free acceleration (units of b).
    Minv, Minv_sqrt : scipy.sparse matrix (n, n)
        M⁻¹ and M^{-1/2} of the mass–inertia matrix (1/kg, 1/(kg·m²)).
    method : {"lu", "cg"}
    rtol : float
        Relative tolerance of the conjugate-gradient solve.

    Returns
    -------
    (ν̇_c (n,), λ (s,), rank or None)
        The rank is known (= s) only when the LU factorisation succeeded.
    """
    s = A.shape[0]
    if s == 0:
        return np.zeros(A.shape[1]), np.zeros(0), 0
    K = (A @ Minv @ A.T).tocsc()
    r_norm = max(float(np.linalg.norm(r)), 1e-300)
    lam: FloatArray | None = None
    rank: int | None = None
    if method == "lu":
        try:
            lam = spla.splu(K, permc_spec="MMD_AT_PLUS_A").solve(r)
            rank = s
        except RuntimeError:  # SuperLU: "Factor is exactly singular"
            lam = None
    elif method == "cg":
        d = K.diagonal()
        precond = sp.diags(np.where(d > 0, 1.0 / np.where(d > 0, d, 1.0), 1.0))
        lam, info = spla.cg(K, r, rtol=rtol, atol=0.0, maxiter=10 * s, M=precond)
        if info != 0:
            lam = None
    else:
        raise ValueError(f"method must be 'lu' or 'cg'; got {method!r}")
    if (
        lam is not None
        and np.isfinite(lam).all()
        and (np.linalg.norm(K @ lam - r) <= 1e-10 * r_norm)
    ):
        return Minv @ (A.T @ lam), lam, rank
    B = (A @ Minv_sqrt).tocsr()
    y = spla.lsmr(B, r, atol=rtol, btol=rtol, maxiter=20 * max(B.shape))[0]
    lam = spla.lsmr(K, r, atol=rtol, btol=rtol, maxiter=20 * s)[0]
    return Minv_sqrt @ y, lam, None


def matrix_power_spd(M: FloatArray, p: float) -> FloatArray:
    """M^p of a symmetric positive-definite matrix (by eigendecomposition).

    Parameters
    ----------
    M : ndarray (n, n)
        Symmetric positive definite, e.g. the mass–inertia matrix (kg, kg·m²); the result
        has the units of M to the power p.
    p : float
        The power, e.g. −1/2 or −1/4.
    """
    w, Q = np.linalg.eigh(M)
    return (Q * w**p) @ Q.T


def solve_tangent_bundle(
    A: FloatArray,
    B: FloatArray,
    C: FloatArray,
    g: FloatArray,
    gdd_a: FloatArray,
    I_tilde_m14: FloatArray,
) -> tuple[FloatArray, float, float]:
    """Constraint accelerations on T²SE(3) from ``A g̈ B = C`` (McCann 2020, Eq. 80).

    ``g̈_c = 𝕀̃^{-1/4} (A 𝕀̃^{-1/4})⁺ (C − A g̈_a B) (𝕀̃^{-1/4} B)⁺ 𝕀̃^{-1/4}``, with
    ``𝕀̃ = blkdiag(J₁, m₁, …, Jₙ, mₙ)`` (4n × 4n) and ``g̈_a = blkdiag(g̈_a,i)``.

    Parameters
    ----------
    A : ndarray (m, 4n)
    B : ndarray (4n, p)
    C : ndarray (m, p)
    g : ndarray (n, 4, 4)
        Poses of the bodies.
    gdd_a : ndarray (n, 4, 4)
        Free accelerations g̈_a,i = g_i (V_i^² + V̇_a,i^) (Eq. 18).
    I_tilde_m14 : ndarray (4n, 4n)
        𝕀̃^{-1/4}.

    Returns
    -------
    V_dot_c : ndarray (n, 6)
        ``(g_i⁻¹ g̈_c,ii)`` projected onto se(3) (skew rotation part, translation column).
    unreachable : float
        Frobenius norm of what the projection discarded plus the off-diagonal blocks of g̈_c,
        relative to ‖g̈_c‖: zero when Eq. 80's g̈_c is reachable by a control input.
    residual : float
        ‖A g̈ B − C‖_F with the projected accelerations, relative to max(‖C‖, 1).
    """
    n = g.shape[0]
    Gdd_a = scipy.linalg.block_diag(*gdd_a)
    Y = C - A @ Gdd_a @ B
    Gdd_c = (
        I_tilde_m14
        @ np.linalg.pinv(A @ I_tilde_m14)
        @ Y
        @ np.linalg.pinv(I_tilde_m14 @ B)
        @ I_tilde_m14
    )
    V_dot_c = np.empty((n, 6))
    projected = np.zeros_like(Gdd_c)
    for i in range(n):
        blk = slice(4 * i, 4 * i + 4)
        X = se3._inverse(g[i]) @ Gdd_c[blk, blk]
        W = X[:3, :3]
        Ws = 0.5 * (W - W.T)
        V_dot_c[i] = np.concatenate([[Ws[2, 1], Ws[0, 2], Ws[1, 0]], X[:3, 3]])
        projected[blk, blk] = g[i] @ se3._hat(V_dot_c[i])
    scale = max(float(np.linalg.norm(Gdd_c)), 1e-300)
    unreachable = float(np.linalg.norm(Gdd_c - projected)) / scale
    Gdd = Gdd_a + projected
    residual = float(np.linalg.norm(A @ Gdd @ B - C)) / max(float(np.linalg.norm(C)), 1.0)
    return V_dot_c, unreachable, residual


def reachable_rows(
    A: FloatArray, B: FloatArray, C: FloatArray, g: FloatArray, V: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """``A g̈ B = C`` restricted to reachable accelerations, as R⁶ rows in the body twists.

    Every reachable g̈ is ``g̈_i = g_i (V_i^² + V̇_i^)`` (Eqs. 17–19), so the constraint is
    linear in ``V̇``: ``Σ_i A_i g_i V̇_i^ B_i = C − Σ_i A_i g_i V_i^² B_i``, with A_i, B_i the
    blocks of A, B belonging to body i. Solving these rows by Gauss's principle (Eq. 64)
    is the Udwadia–Kalaba solution of the T²SE(3) constraint within the reachable set; it
    is the projection gmuk uses where Eq. 80's g̈_c is not reachable (errata).

    Parameters
    ----------
    A : ndarray (m, 4k)
    B : ndarray (4k, p)
    C : ndarray (m, p)
    g : ndarray (k, 4, 4)
        Poses of the constraint's bodies.
    V : ndarray (k, 6)
        Their body twists.

    Returns
    -------
    A6 : ndarray (m·p, 6k)
        Rows acting on [V̇₁; …; V̇ₖ].
    b6 : ndarray (m·p,)
    """
    k = g.shape[0]
    E = se3._hat(np.eye(6))  # (6, 4, 4): the se(3) basis
    rhs = np.array(C, dtype=float)
    cols = []
    for i in range(k):
        Ai, Bi = A[:, 4 * i : 4 * i + 4], B[4 * i : 4 * i + 4, :]
        Vh = se3._hat(V[i])
        rhs = rhs - Ai @ g[i] @ Vh @ Vh @ Bi
        cols.append(np.stack([(Ai @ g[i] @ E[j] @ Bi).ravel() for j in range(6)], axis=1))
    return np.hstack(cols), rhs.ravel()
