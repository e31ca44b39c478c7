"""Compiled kernels for the System's hot path (free accelerations, dense UK solve).

The compiled loop and the System's fused solve call :func:`uk_rigid` with the same argument
types, :data:`UK_RIGID_SIGNATURE` (writable C-contiguous float64 arrays, the loop's): one
compile of it and of its callees (or one load from numba's cache) serves both. The System
calls that overload's compiled function directly, without numba's dispatcher (which
resolves the types of its arguments on every call). Such a call does not check its
arguments: they must be exactly the declared types (float64, C-contiguous, writable, the
declared dimensions), or the kernel reads memory wrongly. The System checks that before it
takes this path and calls the dispatcher otherwise.
"""

from __future__ import annotations

import numpy as np
from numba import types

from gmuk._numba import njit
from gmuk.dynamics import rigid_free_accel

_RW1 = types.Array(types.float64, 1, "C")
_RW2 = types.Array(types.float64, 2, "C")


@njit(cache=True)
def uk_dense(
    A: np.ndarray, b: np.ndarray, a: np.ndarray, Minv_sqrt: np.ndarray, rcond: float
) -> tuple[np.ndarray, np.ndarray, int, float, float]:
    """Moore–Penrose UK solve through the SVD of B = A M^{-1/2} (McCann 2020, Eq. 64).

    Returns (ν̇_c, λ, rank, ‖A(a + ν̇_c) − b‖₂, scale), with the scale of the consistency
    test of :func:`consistency_scale`.
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
    scale = consistency_scale(
        np.sqrt(np.sum(b * b)),
        np.sqrt(np.sum(A * A)),
        np.sqrt(np.sum(a * a)),
        np.sqrt(np.sum(ac * ac)),
    )
    return ac, lam, rank, np.sqrt(np.sum(res * res)), scale


@njit(cache=True, inline="always")
def consistency_scale(norm_b: float, norm_A: float, norm_a: float, norm_ac: float) -> float:
    """The scale of the consistency test ``‖A(a + ν̇_c) − b‖₂ > tol · scale``:
    ``‖b‖₂ + ‖A‖_F (‖a‖₂ + ‖ν̇_c‖₂)``, the size of the terms whose rounding the residual
    holds (so the test is relative: rows and right-hand side scaled by any c > 0, the
    decision is the same; contradictory rows scaled by 1e-8 are still inconsistent, and
    consistent ones scaled by 1e-8 or 1e8 still consistent). It has no absolute floor: a
    residual is compared with the size of the rows, never with 1.

    The residual of a least-squares solution is at most ‖b − A a‖₂ ≤ scale, so the relative
    residual of contradictory rows is of order one; with ``a = b = 0`` the solution and the
    residual are exactly zero and the test passes."""
    return norm_b + norm_A * (norm_a + norm_ac)


@njit(cache=True)
def _qr_solve(
    A: np.ndarray,
    b: np.ndarray,
    a: np.ndarray,
    Minv_sqrt: np.ndarray,
    cond_limit: float,
    ac: np.ndarray,
    lam: np.ndarray,
) -> tuple[float, float, int]:
    """UK solve (McCann 2020, Eq. 64) for full-row-rank A by Householder QR of Bᵀ = (A M^{-1/2})ᵀ.

    With Bᵀ = Q R (R upper triangular s×s), B Bᵀ = RᵀR, so the minimum-norm solution of
    B y = r = b − A a is y = Q R⁻ᵀ r, ν̇_c = M^{-1/2} y, and λ = (B Bᵀ)⁻¹ r = R⁻¹ R⁻ᵀ r: the
    same quantities as the SVD solve when A has full row rank, at a fraction of the cost for
    the small systems where LAPACK's per-call set-up dominates.

    Full row rank is *certified*, not assumed: with ‖R⁻¹‖₂ ≤ √s ‖R⁻¹‖₁ and
    σ_max ≤ ‖R‖_F, the bound κ₂(B) ≤ √s ‖R⁻¹‖₁ ‖R‖_F is computed exactly from R⁻¹; above
    ``cond_limit`` (or for s > n, a zero pivot, or NaN/inf input) the status asks the caller
    for the SVD solve instead.

    Writes ν̇_c into ``ac`` (n,) and λ into ``lam`` (s,); returns (‖A(a + ν̇_c) − b‖₂,
    scale, status): the second is the scale of the consistency test
    (:func:`consistency_scale`, ‖b‖₂ + ‖A‖_F (‖a‖₂ + ‖ν̇_c‖₂)); status 0 solved, 1 use the
    SVD solve, 2 A or b not finite.
    """
    s, n = A.shape
    for i in range(s):
        if not np.isfinite(b[i]):
            return np.nan, np.nan, 2
        for k in range(n):
            if not np.isfinite(A[i, k]):
                return np.nan, np.nan, 2
    if s > n or s == 0:
        return np.nan, np.nan, 1
    # Bᵀ (n×s), built column by column: X[:, i] = M^{-1/2} A[i]ᵀ (M^{-1/2} is symmetric).
    X = np.empty((n, s))
    for i in range(s):
        for r in range(n):
            acc = 0.0
            for k in range(n):
                acc += Minv_sqrt[r, k] * A[i, k]
            X[r, i] = acc
    res = np.empty(s)
    for i in range(s):
        acc = 0.0
        for k in range(n):
            acc += A[i, k] * a[k]
        res[i] = b[i] - acc
    # Householder QR in place: reflectors v_k (stored below and on the diagonal of X),
    # beta_k = 2 / vᵀv, R's diagonal in d.
    beta = np.empty(s)
    d = np.empty(s)
    for k in range(s):
        nrm2 = 0.0
        for r in range(k, n):
            nrm2 += X[r, k] * X[r, k]
        nrm = np.sqrt(nrm2)
        if nrm == 0.0:
            return np.nan, np.nan, 1
        xk = X[k, k]
        alpha = -nrm if xk >= 0.0 else nrm
        X[k, k] = xk - alpha
        beta[k] = 1.0 / (nrm * (nrm + abs(xk)))  # 2 / vᵀv with vᵀv = 2‖x‖(‖x‖ + |x_k|)
        d[k] = alpha
        for j in range(k + 1, s):
            dot = 0.0
            for r in range(k, n):
                dot += X[r, k] * X[r, j]
            f = beta[k] * dot
            for r in range(k, n):
                X[r, j] -= f * X[r, k]
    # R (s×s upper) and its inverse.
    R = np.zeros((s, s))
    for i in range(s):
        R[i, i] = d[i]
        for j in range(i + 1, s):
            R[i, j] = X[i, j]
    Ri = np.zeros((s, s))
    for j in range(s):
        Ri[j, j] = 1.0 / R[j, j]
        for i in range(j - 1, -1, -1):
            acc = 0.0
            for k in range(i + 1, j + 1):
                acc += R[i, k] * Ri[k, j]
            Ri[i, j] = -acc / R[i, i]
    norm_Ri_1 = 0.0
    norm_R_F2 = 0.0
    for j in range(s):
        col = 0.0
        for i in range(j + 1):
            col += abs(Ri[i, j])
            norm_R_F2 += R[i, j] * R[i, j]
        norm_Ri_1 = max(norm_Ri_1, col)
    if not (np.sqrt(s) * norm_Ri_1 * np.sqrt(norm_R_F2) <= cond_limit):
        return np.nan, np.nan, 1
    # z = R⁻ᵀ r, λ = R⁻¹ z, y = Q [z; 0] = H_0 … H_{s−1} [z; 0].
    z = np.zeros(n)
    for i in range(s):
        acc = 0.0
        for k in range(i + 1):
            acc += Ri[k, i] * res[k]
        z[i] = acc
    for i in range(s):
        acc = 0.0
        for k in range(i, s):
            acc += Ri[i, k] * z[k]
        lam[i] = acc
    for k in range(s - 1, -1, -1):
        dot = 0.0
        for r in range(k, n):
            dot += X[r, k] * z[r]
        f = beta[k] * dot
        for r in range(k, n):
            z[r] -= f * X[r, k]
    for r in range(n):
        acc = 0.0
        for k in range(n):
            acc += Minv_sqrt[r, k] * z[k]
        ac[r] = acc
    rr = 0.0
    nA = 0.0
    nb = 0.0
    for i in range(s):
        acc = -res[i]
        for k in range(n):
            acc += A[i, k] * ac[k]
            nA += A[i, k] * A[i, k]
        rr += acc * acc
        nb += b[i] * b[i]
    na = 0.0
    nac = 0.0
    for k in range(n):
        na += a[k] * a[k]
        nac += ac[k] * ac[k]
    scale = consistency_scale(np.sqrt(nb), np.sqrt(nA), np.sqrt(na), np.sqrt(nac))
    return np.sqrt(rr), scale, 0


@njit(cache=True)
def uk_qr(
    A: np.ndarray, b: np.ndarray, a: np.ndarray, Minv_sqrt: np.ndarray, cond_limit: float
) -> tuple[np.ndarray, np.ndarray, float, float, int]:
    """:func:`_qr_solve` returning (ν̇_c, λ, residual, scale, status)."""
    ac = np.zeros(A.shape[1])
    lam = np.zeros(A.shape[0])
    residual, scale, status = _qr_solve(A, b, a, Minv_sqrt, cond_limit, ac, lam)
    return ac, lam, residual, scale, status


def rigid_params(
    J: np.ndarray,
    Jinv: np.ndarray,
    m: np.ndarray,
    Minv_sqrt: np.ndarray,
    M: np.ndarray,
    cond_limit: float,
    consistency_tol: float,
) -> np.ndarray:
    """The constant arguments of :func:`uk_rigid` packed in one vector:
    ``[cond_limit, consistency_tol, J (9 n_b), J⁻¹ (9 n_b), m (n_b), M^{-1/2} (n²), M (n²)]``
    for n_b rigid bodies and n = 6 n_b (one argument to unbox instead of seven).

    Writable, as the compiled loop's parameters are: :func:`uk_rigid` then has the same
    argument types from Python as from the loop, and one compile serves both (its owner
    keeps it private instead of marking it read-only)."""
    P = np.concatenate(
        [
            [float(cond_limit), float(consistency_tol)],
            np.ravel(J),
            np.ravel(Jinv),
            np.ravel(m),
            np.ravel(Minv_sqrt),
            np.ravel(M),
        ]
    ).astype(np.float64)
    return P


@njit(cache=True, inline="always")
def _uk_rigid(
    V: np.ndarray, Q: np.ndarray, A: np.ndarray, b: np.ndarray, P: np.ndarray, out: np.ndarray
) -> None:
    n = A.shape[1]
    s = A.shape[0]
    nb = n // 6
    cond_limit = P[0]
    consistency_tol = P[1]
    o = 2
    J = P[o : o + 9 * nb].reshape((nb, 3, 3))
    o += 9 * nb
    Jinv = P[o : o + 9 * nb].reshape((nb, 3, 3))
    o += 9 * nb
    m = P[o : o + nb]
    o += nb
    Minv_sqrt = P[o : o + n * n].reshape((n, n))
    o += n * n
    M = P[o : o + n * n].reshape((n, n))
    a = rigid_free_accel(V, J, Jinv, m, Q.reshape((nb, 6))).reshape(-1)
    ac = out[n : 2 * n]
    residual, scale, status = _qr_solve(A, b, a, Minv_sqrt, cond_limit, ac, out[4 * n : 4 * n + s])
    for r in range(n):
        out[r] = a[r]
        out[2 * n + r] = a[r] + ac[r]
        acc = 0.0
        for k in range(n):
            acc += M[r, k] * ac[k]
        out[3 * n + r] = acc
    out[4 * n + s] = residual
    out[4 * n + s + 1] = scale
    if status == 0 and residual > consistency_tol * scale:
        status = 3
    out[4 * n + s + 2] = status


@njit(cache=True)
def uk_rigid(
    V: np.ndarray, Q: np.ndarray, A: np.ndarray, b: np.ndarray, P: np.ndarray, out: np.ndarray
) -> None:
    """One call for a dense all-rigid System whose loads the UK solve all sees.

    Free accelerations (Eq. 10b) of the twists V (n_b, 6) under the modeled wrenches Q (n,),
    the QR solve of :func:`_qr_solve` of A (s, n) ν̇ = b, the constraint wrenches M ν̇_c and
    the total, written into ``out`` (4n + s + 3,): ``[a (n), ν̇_c (n), total (n), M ν̇_c (n),
    λ (s), residual, scale, status]``, with status 3 when solved but ``residual >
    consistency_tol · scale`` (the caller warns or raises); the other entries are
    meaningful only for status 0 and 3. P from :func:`rigid_params`. Any array layout.

    The caller allocates ``out``: boxing an array that a numba kernel returns costs several
    times what ``np.empty`` does in Python (numba unpickles the array's dtype on every
    return).
    """
    _uk_rigid(V, Q, A, b, P, out)


#: The signature of :func:`uk_rigid` that the compiled loop calls and the System's fused
#: solve calls through its compiled entry (writable C-contiguous float64 arrays): one compile.
UK_RIGID_SIGNATURE = types.void(_RW2, _RW1, _RW2, _RW1, _RW1, _RW1)
