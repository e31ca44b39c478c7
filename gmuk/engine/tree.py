"""Linear-time Udwadia–Kalaba solve for tree-structured constraints (Baraff 1996).

When every constraint couples at most two rigid bodies and the constraints form a tree (or a
forest) with the ground, the constrained equations

``[[M, Aᵀ], [A, 0]] [ν̇_c; μ] = [0; b − A ν̇_a]``,   λ = −μ,

have the sparsity of that tree: order the unknowns as nodes, one per body (its 6 × 6 block
M_i = blkdiag(J_i, m_i I)) and one per constraint (its s_k × s_k zero block), coupled by the
constraint's rows on each of its bodies (A_k's s_k × 6 block on body i). Root each tree of the
forest at a joint to the ground (or, for a tree that never reaches the ground, a floating
base, at its first body) and eliminate leaves first: the block LDLᵀ factorisation then has
no fill-in (Baraff 1996, Sections 3–5), and the whole solve costs O(number of bodies).

With the unknowns of node i written x_i and its parent p (the node next to it on the way to
the root), elimination in leaves-first order is

``D_i = H_ii − Σ_{c child of i} H_ic D_c⁻¹ H_ci``,  ``X_i = D_i⁻¹ H_ip``,

then ``y_i = r_i − Σ_c X_cᵀ y_c``, ``z_i = D_i⁻¹ y_i`` and, from the roots outwards,
``x_i = z_i − X_i x_p``. A body's D_i is its mass matrix plus the positive-semidefinite
reflection of its subtree (positive definite); a constraint's D_k is minus
``A_k,c D_c⁻¹ A_k,cᵀ`` for its child body c (negative definite exactly when the rows on its
child have full row rank). Each D is factorised by Cholesky (of −D_k for a constraint); a
pivot below :data:`PIVOT_TOL` times the block's largest diagonal entry means the rows are
not certified to have full row rank, and the solve falls back to the dense
(QR, else SVD) or the sparse strategy, which decide the rank and the minimum-norm solution.
This is the maximal-coordinate counterpart of Featherstone's articulated-body algorithm.

A joint (:class:`gmuk.robots.Joint`) whose child body is the tree's child of its node has
constant rows G on that child and rows −G Ad_{g_c⁻¹ g_p} on its parent, whatever the poses:
the body and the joint are then eliminated together (:func:`_articulated_step`), as the
articulated-body algorithm does: with S (the joint's motions, G S = 0) and G⁺ (G G⁺ = I) in
the child's frame, the parent receives Xᵀ I_a X, X = Ad_{g_c⁻¹ g_p}, with the articulated
inertia I_a = D_c − D_c S (Sᵀ D_c S)⁻¹ Sᵀ D_c. That is the Schur complement the two node steps
give (Gᵀ (G D_c⁻¹ Gᵀ)⁻¹ G = I_a), for one k × k Cholesky factor (k the joint's motions) in
place of a 6 × 6 and a (6 − k) × (6 − k) one. A pivot of Sᵀ D_c S it cannot certify sends
the pair back to the node steps.

A body with a singular mass block (a link without mass, or a point mass:
``RigidBody(allow_singular=True)``) has no free acceleration of its own: its free acceleration
takes M⁺, the loads M⁺ leaves go on its node's right-hand side (:func:`body_rhs`), and when
its D_i has no Cholesky factor it is eliminated together with the constraint to its parent as
one node, by the null-space method on that constraint's rows (:func:`_eliminate_pair`); the
KKT system keeps its tree, and the solve its linear cost. When every force model has a
compiled form, :func:`tree_state_rigid` evaluates the loads, the rows and the solve in
one compiled call.

The multipliers are the Udwadia–Kalaba ones (``λ = (A M⁻¹ Aᵀ)⁻¹ (b − A ν̇_a)``, Eq. 3 of
McCann 2020), the constraint acceleration ``ν̇_c = M⁻¹ Aᵀ λ`` (Eq. 64): for full row rank A
the KKT solution is unique and equals the Moore–Penrose one of the dense solve.

References
----------
Baraff, D. (1996). Linear-time dynamics using Lagrange multipliers. *Proceedings of
SIGGRAPH 96*, 137–146.
McCann, B. (2020), Eqs. 3 and 64.
"""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numba import types

from gmuk._numba import borrowed, kernel_address, kernel_caller, njit, overload_entry
from gmuk._validation import FloatArray, all_finite
from gmuk.bodies import BodyKind
from gmuk.constraints.base import ROWS_KERNEL, as_rows
from gmuk.dynamics import body_moment, rigid_free_accel_into
from gmuk.engine import _uk_kernels, uk
from gmuk.engine._uk_kernels import consistency_scale
from gmuk.engine.solvers import (
    _EPS,
    _F64,
    _NO_MULTIPLIERS,
    QR_COND_LIMIT,
    QR_MAX_ROWS,
    Accelerations,
    Solution,
    SolveStatus,
    UKSolver,
    _writable,
)
from gmuk.errors import ConstraintError
from gmuk.forces.base import FORCE_KERNEL

if TYPE_CHECKING:
    from gmuk.engine.system import System
    from gmuk.state import State

__all__ = [
    "PIVOT_TOL",
    "TREE",
    "TREE_SIGNATURE",
    "JointSubspace",
    "TreeSolver",
    "body_rhs",
    "subspaces_at",
    "tree_pair",
    "tree_params",
    "tree_rigid",
    "tree_solve",
    "tree_structure",
]

#: A Cholesky pivot of a node's block at or below PIVOT_TOL times the block's largest
#: diagonal entry is not certified: the rows may not have full row rank there, and the
#: solve falls back to the dense or sparse strategy.
PIVOT_TOL = 1e-12
#: Rows of one constraint in a tree solve: at most one body's six freedoms.
MAX_NODE_ROWS = 6
#: Up to this many dof the System keeps dense rows and mass matrix under the tree solve, and
#: a call the tree solve cannot certify takes the dense solve (QR, else SVD) of
#: :class:`~gmuk.engine.solvers.DenseSolver`; above it sparse ones, and the sparse solve
#: (the System's ``SPARSE_THRESHOLD``).
DENSE_FALLBACK_DOF = 300

_RW1 = types.Array(types.float64, 1, "C")
_RW2 = types.Array(types.float64, 2, "C")
_RW3 = types.Array(types.float64, 3, "C")
#: The signature of :func:`tree_rigid` (writable C-contiguous float64 arrays): the System's
#: tree solve calls that overload's compiled function without numba's dispatcher.
TREE_SIGNATURE = types.void(_RW3, _RW2, _RW1, _RW2, _RW1, _RW1, _RW1)
_tree_rigid_c: Any = None

_packed = Accelerations._packed  # (bound once: a classmethod is bound at each lookup)
_SOLVED = float(SolveStatus.SOLVED)
_NOT_FINITE = float(SolveStatus.NOT_FINITE)

#: How the compiled loop solves a System of the tree strategy (``Dims.solve``), beside
#: :mod:`gmuk.engine.integrators._program`'s FREE, FUSED, DENSE and PYTHON_SOLVE (0–3).
TREE = 4

# Layout of the packed parameters P (float64): [unused, consistency_tol, n_b, n_c,
# J (9 n_b), J⁻¹ (9 n_b), m (n_b), order (n_b + n_c), parent (n_b + n_c), body_a (n_c),
# body_b (n_c), rows (n_c), n_singular, singular (n_b), joint subspaces (3 n_c: half, k_d,
# offset), G⁺ and S of each joint with one]. Nodes 0 … n_b − 1 are the bodies, n_b + k
# constraint k; J⁻¹ is J⁺ for a body with a singular mass block (``singular`` 1).
_HEAD = 4


class JointSubspace(NamedTuple):
    """What the tree solve needs of a joint to eliminate its child with it
    (:func:`_articulated_step`): the column half of its rows on the child (0 or 1), and in
    the child's body frame G⁺ (6, s), a right inverse of the rows G on the child
    (G G⁺ = I), and S (6, 6 − s) with G S = 0; the rows on the parent being −G Ad_{g_c⁻¹ g_p}
    (a constraint on the relative pose of the two bodies only)."""

    half: int
    G_pinv: FloatArray
    S: FloatArray


# ----------------------------------------------------------------------------- structure
def tree_structure(
    n_bodies: int, pairs: list[tuple[int, int]]
) -> tuple[np.ndarray, np.ndarray] | str:
    """The elimination order and parents of the body–constraint tree, or why there is none.

    Parameters
    ----------
    n_bodies : int
        Rigid bodies 0 … n_bodies − 1.
    pairs : list of (int, int)
        Each constraint's bodies (a, b), b = −1 for a constraint on one body (to the ground).

    Returns
    -------
    (order, parent) : int64 arrays (n_bodies + n_c,)
        Nodes leaves first (children before their parent) and each node's parent (−1 for a
        root); nodes 0 … n_bodies − 1 are the bodies, n_bodies + k constraint k. Each tree
        that reaches the ground is rooted at its constraint to the ground, any other at its
        first body.
    str
        When the constraints with the ground do not form a forest: what closes a loop.
    """
    nb, nc = n_bodies, len(pairs)
    nn = nb + nc
    # the bipartite graph of bodies and constraints; the ground is node nn
    adj: list[list[int]] = [[] for _ in range(nn + 1)]
    for k, (a, b) in enumerate(pairs):
        node = nb + k
        for body in (a, b):
            other = nn if body < 0 else body
            adj[node].append(other)
            adj[other].append(node)
    parent = np.full(nn + 1, -2, dtype=np.int64)  # −2: not reached yet
    bfs: list[int] = []
    roots = [nn, *range(nb)]  # the ground first, then each body not reached
    for root in roots:
        if parent[root] != -2:
            continue
        parent[root] = -1
        queue = deque([root])
        while queue:
            i = queue.popleft()
            bfs.append(i)
            for j in adj[i]:
                if j == parent[i]:
                    continue
                if parent[j] != -2:
                    what = "the ground" if j == nn or i == nn else "a body"
                    return (
                        "the constraints close a loop (through "
                        f"{what}): a tree solve needs a tree or forest of bodies and "
                        "constraints, each constraint on one body (to the ground) or two"
                    )
                parent[j] = i
                queue.append(j)
    order = np.array([i for i in reversed(bfs) if i != nn], dtype=np.int64)
    par = parent[:nn].copy()
    par[par == nn] = -1  # the ground's children (its constraints) are roots
    return order, par


def tree_params(
    J: FloatArray,
    Jinv: FloatArray,
    m: FloatArray,
    order: np.ndarray,
    parent: np.ndarray,
    pairs: list[tuple[int, int]],
    rows: list[int],
    consistency_tol: float,
    singular: np.ndarray | None = None,
    subspaces: list[JointSubspace | None] | None = None,
) -> np.ndarray:
    """The constant arguments of :func:`tree_solve` and :func:`tree_rigid` in one writable
    float64 vector (see ``_HEAD``): the bodies' central inertias J (n_b, 3, 3) (kg·m²),
    their inverses (J⁺ where the mass block is singular), masses m (n_b,) (kg), the tree
    (:func:`tree_structure`), each constraint's bodies and row count, which bodies have
    a singular mass block (``singular``, bool (n_b,); none by default), and the joints
    whose child the tree puts below them, with their constant G⁺ and S (``subspaces``, one
    :class:`JointSubspace` or None per constraint: those take :func:`_articulated_step`;
    none by default)."""
    nb, nc = m.shape[0], len(pairs)
    flags = np.zeros(nb) if singular is None else np.asarray(singular, dtype=float)
    head = np.concatenate(
        [
            [0.0, float(consistency_tol), float(nb), float(nc)],
            np.ravel(J),
            np.ravel(Jinv),
            np.ravel(m),
            np.asarray(order, dtype=float),
            np.asarray(parent, dtype=float),
            [float(a) for a, _ in pairs],
            [float(b) for _, b in pairs],
            np.asarray(rows, dtype=float),
            [float(np.count_nonzero(flags))],
            flags,
        ]
    )
    table = np.zeros(3 * nc)
    table[0::3] = -1.0
    constants: list[FloatArray] = []
    at = head.size + 3 * nc
    for k, sub in enumerate(subspaces or [None] * nc):
        if sub is None:
            continue
        s_k, kd = sub.G_pinv.shape[1], sub.S.shape[1]
        if s_k != rows[k] or s_k + kd != 6:
            raise ValueError(f"constraint {k}: G⁺ (6, {s_k}) and S (6, {kd}) for {rows[k]} rows")
        child = pairs[k][sub.half]
        if parent[child] != nb + k:  # the tree puts the joint's child above it
            continue
        table[3 * k : 3 * k + 3] = (float(sub.half), float(kd), float(at))
        constants += [sub.G_pinv.ravel(), sub.S.ravel()]
        at += 6 * (s_k + kd)
    return np.concatenate([head, table, *constants]).astype(np.float64)


@njit(cache=True, inline="always")
def singular_at(P: np.ndarray) -> int:
    """Offset in P of the count of bodies with a singular mass block (their flags follow)."""
    nb = int(P[2])
    nc = int(P[3])
    return _HEAD + 19 * nb + 2 * (nb + nc) + 3 * nc


@njit(cache=True, inline="always")
def subspaces_at(P: np.ndarray) -> int:
    """Offset in P of the constraints' joint subspaces (three entries per constraint, see
    :func:`tree_params`), after the singular flags."""
    return singular_at(P) + 1 + int(P[2])


@njit(cache=True)
def body_rhs(V: np.ndarray, Q: np.ndarray, a: np.ndarray, P: np.ndarray, r: np.ndarray) -> None:
    """r_i = Q_i + ad*_V 𝕀V − M_i a_i (6 n_b,) for each body with a singular mass block, 0
    for the others: what of the loads the free acceleration ``a`` (from J⁺, and 1/m → 0)
    leaves to the solve, whose body equations are ``M_i ν̇_c,i + (Aᵀμ)_i = r_i``
    (Udwadia & Phohomsiri 2006: a singular M with the constraints determining ν̇).
    V (n_b, 6) twists, Q (6 n_b,) modeled wrenches (N·m, N), a (6 n_b,)."""
    nb = V.shape[0]
    o = _HEAD
    J = P[o : o + 9 * nb].reshape((nb, 3, 3))
    m = P[o + 18 * nb : o + 19 * nb]
    f = singular_at(P) + 1
    for k in range(nb):
        o6 = 6 * k
        for e in range(6):
            r[o6 + e] = 0.0
        if P[f + k] == 0.0:
            continue
        w0, w1, w2 = V[k, 0], V[k, 1], V[k, 2]
        v0, v1, v2 = V[k, 3], V[k, 4], V[k, 5]
        L = body_moment(V, J, k, Q[o6], Q[o6 + 1], Q[o6 + 2])
        F = (v1 * w2 - v2 * w1, v2 * w0 - v0 * w2, v0 * w1 - v1 * w0)
        for i in range(3):
            r[o6 + i] = L[i] - (
                J[k, i, 0] * a[o6] + J[k, i, 1] * a[o6 + 1] + J[k, i, 2] * a[o6 + 2]
            )
            r[o6 + 3 + i] = Q[o6 + 3 + i] + m[k] * (F[i] - a[o6 + 3 + i])


# ----------------------------------------------------------------------------- kernels
@njit(cache=True, inline="always")
def tree_pair(P: np.ndarray, k: int) -> tuple[int, int]:
    """Constraint k's bodies (a, b) in the packed parameters P (b = −1: to the ground)."""
    nb = int(P[2])
    nc = int(P[3])
    o = _HEAD + 19 * nb + 2 * (nb + nc)
    return int(P[o + k]), int(P[o + nc + k])


@njit(cache=True, inline="always")
def _cholesky(D: np.ndarray, d: int, sign: float, C: np.ndarray) -> bool:
    """C (lower) with C Cᵀ = sign · D[:d, :d], its diagonal stored as reciprocals 1/C_jj
    (the solves multiply: a division's latency dominates these short dependent chains);
    False when a pivot is not above PIVOT_TOL times the largest diagonal entry (or not
    finite). Reads D's lower triangle only."""
    big = 0.0
    for i in range(d):
        big = max(big, sign * D[i, i])
    if not big > 0.0:
        return d == 0
    tol = PIVOT_TOL * big
    for j in range(d):
        acc = sign * D[j, j]
        for k in range(j):
            acc -= C[j, k] * C[j, k]
        if not acc > tol:
            return False
        rjj = 1.0 / np.sqrt(acc)
        C[j, j] = rjj
        for i in range(j + 1, d):
            acc = sign * D[i, j]
            for k in range(j):
                acc -= C[i, k] * C[j, k]
            C[i, j] = acc * rjj
    return True


@njit(cache=True, inline="always")
def _chol_solve(C: np.ndarray, d: int, sign: float, y: np.ndarray) -> None:
    """y ← D⁻¹ y in place for D = sign · C Cᵀ (d × d; C from :func:`_cholesky`)."""
    for i in range(d):
        acc = y[i]
        for k in range(i):
            acc -= C[i, k] * y[k]
        y[i] = acc * C[i, i]
    for i in range(d - 1, -1, -1):
        acc = y[i]
        for k in range(i + 1, d):
            acc -= C[k, i] * y[k]
        y[i] = acc * C[i, i]
    if sign < 0.0:
        for i in range(d):
            y[i] = -y[i]


@njit(cache=True)
def _householder(H: np.ndarray, dk: int, Q: np.ndarray, R: np.ndarray) -> bool:
    """H (6 × dk) = Q [R; 0]: Q (6 × 6) orthogonal, R (dk × dk) upper triangular, by
    Householder reflections; False when a diagonal entry of R is not above PIVOT_TOL times
    the largest column norm of H (H not certified to have full column rank)."""
    Wk = np.zeros((6, 6))
    big = 0.0
    for v in range(dk):
        acc = 0.0
        for u in range(6):
            Wk[u, v] = H[u, v]
            acc += H[u, v] * H[u, v]
        big = max(big, np.sqrt(acc))
    for u in range(6):
        for v in range(6):
            Q[u, v] = 1.0 if u == v else 0.0
    if not big > 0.0:
        return dk == 0
    vec = np.empty(6)
    for j in range(dk):
        norm = 0.0
        for u in range(j, 6):
            norm += Wk[u, j] * Wk[u, j]
        norm = np.sqrt(norm)
        if not norm > PIVOT_TOL * big:
            return False
        alpha = -norm if Wk[j, j] >= 0.0 else norm
        vv = 0.0
        for u in range(6):
            vec[u] = Wk[u, j] if u >= j else 0.0
        vec[j] -= alpha
        for u in range(j, 6):
            vv += vec[u] * vec[u]
        for c in range(j, dk):  # Wk ← (I − 2 v vᵀ / vᵀv) Wk
            acc = 0.0
            for u in range(j, 6):
                acc += vec[u] * Wk[u, c]
            acc *= 2.0 / vv
            for u in range(j, 6):
                Wk[u, c] -= acc * vec[u]
        for r in range(6):  # Q ← Q (I − 2 v vᵀ / vᵀv)
            acc = 0.0
            for u in range(j, 6):
                acc += Q[r, u] * vec[u]
            acc *= 2.0 / vv
            for u in range(j, 6):
                Q[r, u] -= acc * vec[u]
    for u in range(dk):
        for v in range(dk):
            R[u, v] = Wk[u, v] if v >= u else 0.0
    return True


@njit(cache=True)
def _pair_solve(
    D: np.ndarray,
    Q: np.ndarray,
    R: np.ndarray,
    L: np.ndarray,
    dk: int,
    f: np.ndarray,
    g: np.ndarray,
    ws: np.ndarray,
) -> None:
    """[x; μ] = K⁻¹ [f; g] in place of (f, g) for K = [[D, H], [Hᵀ, 0]] (D 6 × 6, H 6 × dk)
    by the null-space method: with H = Q [R; 0] = Q₁R, x = Q₁R⁻ᵀg + Q₂y where
    N y = Q₂ᵀ(f − D Q₁R⁻ᵀg), N = Q₂ᵀ D Q₂ = L Lᵀ (the inertia along the motions joint k
    allows, as in the articulated-body algorithm), and μ = R⁻¹ Q₁ᵀ (f − D x). ``ws`` (4, 6)
    is scratch space."""
    w = ws[0]
    for u in range(dk):  # w = R⁻ᵀ g
        acc = g[u]
        for q in range(u):
            acc -= R[q, u] * w[q]
        w[u] = acc / R[u, u]
    x = ws[1]
    for e in range(6):
        acc = 0.0
        for u in range(dk):
            acc += Q[e, u] * w[u]
        x[e] = acc
    t = ws[2]
    for e in range(6):  # t = f − D x₀
        acc = f[e]
        for q in range(6):
            acc -= D[e, q] * x[q]
        t[e] = acc
    nf = 6 - dk
    yv = ws[3]
    for u in range(nf):
        acc = 0.0
        for e in range(6):
            acc += Q[e, dk + u] * t[e]
        yv[u] = acc
    _chol_solve(L, nf, 1.0, yv)
    for e in range(6):
        acc = 0.0
        for u in range(nf):
            acc += Q[e, dk + u] * yv[u]
        x[e] += acc
    for e in range(6):  # t = f − D x
        acc = f[e]
        for q in range(6):
            acc -= D[e, q] * x[q]
        t[e] = acc
    for u in range(dk - 1, -1, -1):  # μ = R⁻¹ Q₁ᵀ t
        acc = 0.0
        for e in range(6):
            acc += Q[e, u] * t[e]
        for q in range(u + 1, dk):
            acc -= R[u, q] * g[q]
        g[u] = acc / R[u, u]
    for e in range(6):
        f[e] = x[e]


@njit(cache=True)
def _eliminate_pair(i, k, p, nb, A, row0, body_a, dim, D, C, X, y):  # type: ignore[no-untyped-def]
    """Eliminate body i, whose D_i is singular, together with its parent constraint node k
    as one node K = [[D_i, H], [Hᵀ, 0]] (H: constraint k's rows on body i, transposed),
    coupled to k's parent body p (−1: none) by [0; G] (G: k's rows on p).

    K is invertible exactly when H has full column rank and D_i is positive definite on the
    motions of body i that joint k allows with p held (a massless link between two joints:
    its own D_i lacks the freedom of its child's joint, its parent joint supplies it). K is
    solved by the null-space method (:func:`_pair_solve`): a Householder QR of H and the
    Cholesky factor of N = Q₂ᵀ D_i Q₂, each with the pivot test (False: not certified).
    Writes z_K into y[i], y[k]; X_K = K⁻¹ [0; G] into X[i], X[k]; and updates p:
    D_p −= Gᵀ X_k, y_p −= Gᵀ z_k (the block LDLᵀ step of tree_solve for the node K)."""
    dk = dim[k]
    c = k - nb
    half = 0 if int(body_a[c]) == i else 6
    for u in range(6):  # the elimination keeps the lower triangle: mirror it
        for v in range(u + 1, 6):
            D[i, u, v] = D[i, v, u]
    H = np.zeros((6, 6))
    for u in range(6):
        for v in range(dk):
            H[u, v] = A[row0[c] + v, half + u]
    Q = np.empty((6, 6))
    R = np.zeros((6, 6))
    if not _householder(H, dk, Q, R):
        return False
    nf = 6 - dk
    N = np.empty((6, 6))
    for u in range(nf):
        for v in range(nf):
            acc = 0.0
            for e in range(6):
                for q in range(6):
                    acc += Q[e, dk + u] * D[i, e, q] * Q[q, dk + v]
            N[u, v] = acc
    L = C[i]
    if not _cholesky(N, nf, 1.0, L):
        return False
    Di = D[i]
    ws = np.empty((4, 6))
    _pair_solve(Di, Q, R, L, dk, y[i], y[k], ws)  # z_K
    if p < 0:
        return True
    hp = 0 if int(body_a[c]) == p else 6
    f = np.empty(6)
    g = np.empty(6)
    for v in range(6):  # X_K = K⁻¹ [0; G], column by column
        for u in range(6):
            f[u] = 0.0
        for u in range(dk):
            g[u] = A[row0[c] + u, hp + v]
        _pair_solve(Di, Q, R, L, dk, f, g, ws)
        for u in range(6):
            X[i, u, v] = f[u]
        for u in range(dk):
            X[k, u, v] = g[u]
    for u in range(6):  # D_p −= Gᵀ X_k, y_p −= Gᵀ z_k
        for v in range(6):
            acc = 0.0
            for q in range(dk):
                acc += A[row0[c] + q, hp + u] * X[k, q, v]
            D[p, u, v] -= acc
        acc = 0.0
        for q in range(dk):
            acc += A[row0[c] + q, hp + u] * y[k, q]
        y[p, u] -= acc
    return True


@njit(cache=True, inline="always")
def _coupling(i, p, di, dp, nb, A, row0, body_a, H):  # type: ignore[no-untyped-def]
    """H_ip (d_i × d_p) into H: the rows of the constraint node on the body node (i body,
    p constraint k: A_k[:, body i]ᵀ; i constraint k, p body: A_k[:, body p])."""
    if i < nb:
        k = p - nb
        half = 0 if int(body_a[k]) == i else 6
        for u in range(6):
            for v in range(dp):
                H[u, v] = A[row0[k] + v, half + u]
    else:
        k = i - nb
        half = 0 if int(body_a[k]) == p else 6
        for u in range(di):
            for v in range(6):
                H[u, v] = A[row0[k] + u, half + v]


@njit(cache=True, inline="always")
def _eliminate_node(i, p, di, dp, sign, nb, A, row0, body_a, D, C, H, W, y, col):  # type: ignore[no-untyped-def]
    """One step of the block LDLᵀ for node i (d_i) with parent p (d_p; −1: a root): the
    Cholesky factor of D_i, z_i = D_i⁻¹ y_i into y[i], and the parent's update
    D_p −= H_ipᵀ D_i⁻¹ H_ip = sign · Wᵀ W with W = L_i⁻¹ H_ip (D_i = sign · L_i L_iᵀ; its lower
    triangle, which is all the Cholesky reads), y_p −= H_ipᵀ z_i. False, with nothing but
    C[i] written, when D_i is not certified."""
    if not _cholesky(D[i], di, sign, C[i]):
        return False
    for u in range(di):  # z_i (y_i is final: every child has been subtracted)
        col[u] = y[i, u]
    _chol_solve(C[i], di, sign, col)
    if p >= 0:
        _coupling(i, p, di, dp, nb, A, row0, body_a, H)
        for u in range(di):  # row by row: the d_p columns are independent chains
            r_uu = C[i, u, u]
            for v in range(dp):
                acc = H[u, v]
                for q in range(u):
                    acc -= C[i, u, q] * W[q, v]
                W[u, v] = acc * r_uu
        for u in range(dp):
            for v in range(u + 1):
                acc = 0.0
                for q in range(di):
                    acc += W[q, u] * W[q, v]
                D[p, u, v] -= sign * acc
            acc = 0.0
            for q in range(di):
                acc += H[q, u] * col[q]
            y[p, u] -= acc
    for u in range(di):
        y[i, u] = col[u]  # now z_i
    return True


@njit(cache=True, inline="always")
def _substitute_node(i, p, di, dp, nb, A, row0, body_a, C, H, y, col):  # type: ignore[no-untyped-def]
    """x_i = z_i − D_i⁻¹ H_ip x_p into y[i] (y[p] holds x_p), with D_i's factor from
    :func:`_eliminate_node`."""
    _coupling(i, p, di, dp, nb, A, row0, body_a, H)
    for u in range(di):
        acc = 0.0
        for v in range(dp):
            acc += H[u, v] * y[p, v]
        col[u] = acc
    _chol_solve(C[i], di, 1.0 if i < nb else -1.0, col)
    for u in range(di):
        y[i, u] -= col[u]


@njit(cache=True, inline="always")
def _joint_subspace(P, k):  # type: ignore[no-untyped-def]
    """Constraint k's entry in the joint subspaces of P: (column half of its rows on its
    child, number of motions k_d, offset of G⁺ (6 × s_k) then S (6 × k_d), row by row); the
    half is −1 for a constraint without one (see :func:`tree_params`)."""
    o = subspaces_at(P) + 3 * k
    return int(P[o]), int(P[o + 1]), int(P[o + 2])


@njit(cache=True, inline="always")
def _relative_pose(g, c, p, out):  # type: ignore[no-untyped-def]
    """g_c⁻¹ g_p as R = R_cᵀ R_p (out[0:3, 0:3]) and r = R_cᵀ (p_p − p_c) (out[3, 0:3])."""
    for u in range(3):
        for v in range(3):
            out[u, v] = g[c, 0, u] * g[p, 0, v] + g[c, 1, u] * g[p, 1, v] + g[c, 2, u] * g[p, 2, v]
    d0 = g[p, 0, 3] - g[c, 0, 3]
    d1 = g[p, 1, 3] - g[c, 1, 3]
    d2 = g[p, 2, 3] - g[c, 2, 3]
    for u in range(3):
        out[3, u] = g[c, 0, u] * d0 + g[c, 1, u] * d1 + g[c, 2, u] * d2


@njit(cache=True, inline="always")
def _ad_apply(T, x, out):  # type: ignore[no-untyped-def]
    """out = Ad x for Ad = [[R, 0], [r̂R, R]] (R, r as :func:`_relative_pose` stores them)."""
    for u in range(3):
        out[u] = T[u, 0] * x[0] + T[u, 1] * x[1] + T[u, 2] * x[2]
    for u in range(3):
        out[3 + u] = T[u, 0] * x[3] + T[u, 1] * x[4] + T[u, 2] * x[5]
    r0, r1, r2 = T[3, 0], T[3, 1], T[3, 2]
    out[3] += r1 * out[2] - r2 * out[1]
    out[4] += r2 * out[0] - r0 * out[2]
    out[5] += r0 * out[1] - r1 * out[0]


@njit(cache=True, inline="always")
def _ad_transpose_add(T, f, out):  # type: ignore[no-untyped-def]
    """out += Adᵀ f = [Rᵀ (f_τ + f_f × r); Rᵀ f_f] (a wrench from the child's frame to the
    parent's; R, r as :func:`_relative_pose` stores them)."""
    r0, r1, r2 = T[3, 0], T[3, 1], T[3, 2]
    t0 = f[0] + (f[4] * r2 - f[5] * r1)
    t1 = f[1] + (f[5] * r0 - f[3] * r2)
    t2 = f[2] + (f[3] * r1 - f[4] * r0)
    for u in range(3):
        out[u] += T[0, u] * t0 + T[1, u] * t1 + T[2, u] * t2
        out[3 + u] += T[0, u] * f[3] + T[1, u] * f[4] + T[2, u] * f[5]


@njit(cache=True, inline="always")
def _articulated_step(i, kk, p, s, kd, off, P, g, D, C, X, y, Ia, W, ws):  # type: ignore[no-untyped-def]
    """Eliminate body i together with its joint (constraint node kk, s rows, k_d motions)
    to its parent body p (−1: the ground), as the articulated-body algorithm does, in
    maximal coordinates.

    The joint's rows on the child are G (s × 6) with G G⁺ = I and G S = 0 for the constant
    G⁺ (6 × s) and S (6 × k_d) in P, and its rows on the parent are −G X for the relative
    transform X = Ad_{g_c⁻¹ g_p} (the joint constrains the relative pose only). Then the
    pair's equations ``D_i x_i + Gᵀ μ = y_i``, ``G (x_i − X x_p) = y_k`` give
    ``x_i = X x_p + c + S α`` with c = G⁺ y_k, α from Sᵀ of the first, and pass to the
    parent ``D_p += Xᵀ I_a X`` and ``y_p += Xᵀ (y_i − U N⁻¹ Sᵀ y_i − I_a c)`` with
    U = D_i S, N = Sᵀ U = L Lᵀ and the articulated inertia I_a = D_i − U N⁻¹ Uᵀ: the same
    Schur complement as eliminating the body node and then the constraint node
    (Gᵀ (G D_i⁻¹ Gᵀ)⁻¹ G = I_a), with one k_d × k_d factor instead of a 6 × 6 and an s × s.
    Keeps D_i (full) in C[i], U in X[i], L in C[kk], R and r in X[kk]. False, with D[kk]
    left zero, when a diagonal entry N_jj is not above PIVOT_TOL · max diag(D_i) · |S_j|²
    (the round-off of D_i's entries, on the scale of the node steps' pivot test of D_i) or
    a pivot of N's Cholesky factor is not certified."""
    sp = off + 6 * s
    Dc = C[i]
    for u in range(6):
        for v in range(u + 1):
            Dc[u, v] = D[i, u, v]
            Dc[v, u] = D[i, u, v]
    U = X[i]
    for u in range(6):
        for j in range(kd):
            acc = 0.0
            for v in range(6):
                acc += Dc[u, v] * P[sp + v * kd + j]
            U[u, j] = acc
    N = D[kk]
    for j in range(kd):
        for q in range(j + 1):
            acc = 0.0
            for v in range(6):
                acc += P[sp + v * kd + j] * U[v, q]
            N[j, q] = acc
    big = 0.0  # D_i's scale: N_jj at or below PIVOT_TOL of it is round-off of D_i's entries
    for u in range(6):
        big = max(big, Dc[u, u])
    certified = True
    for j in range(kd):
        s2 = 0.0
        for v in range(6):
            s2 += P[sp + v * kd + j] * P[sp + v * kd + j]
        certified = certified and N[j, j] > PIVOT_TOL * big * s2
    L = C[kk]
    if not (certified and _cholesky(N, kd, 1.0, L)):
        for j in range(kd):
            for q in range(kd):
                N[j, q] = 0.0
        return False
    if p < 0:  # a joint to the ground: nothing to pass on
        return True
    for u in range(6):  # W = L⁻¹ Uᵀ, column by column (each a chain of k_d)
        for j in range(kd):
            acc = U[u, j]
            for q in range(j):
                acc -= L[j, q] * W[q, u]
            W[j, u] = acc * L[j, j]
    for u in range(6):  # I_a = D_i − Wᵀ W
        for v in range(u + 1):
            acc = Dc[u, v]
            for j in range(kd):
                acc -= W[j, u] * W[j, v]
            Ia[u, v] = acc
            Ia[v, u] = acc
    T = X[kk]
    _relative_pose(g, i, p, T)
    c = ws[0]
    for u in range(6):  # c = G⁺ y_k
        acc = 0.0
        for q in range(s):
            acc += P[off + u * s + q] * y[kk, q]
        c[u] = acc
    t = ws[1]
    for j in range(kd):  # N⁻¹ Sᵀ y_i
        acc = 0.0
        for v in range(6):
            acc += P[sp + v * kd + j] * y[i, v]
        t[j] = acc
    _chol_solve(L, kd, 1.0, t)
    f = ws[2]
    for u in range(6):  # f = y_i − U N⁻¹ Sᵀ y_i − I_a c
        acc = y[i, u]
        for j in range(kd):
            acc -= U[u, j] * t[j]
        for v in range(6):
            acc -= Ia[u, v] * c[v]
        f[u] = acc
    _ad_transpose_add(T, f, y[p])
    # D_p += Xᵀ I_a X, X = [[R, 0], [r̂R, R]]: Y = I_a X, then the lower triangle of Xᵀ Y
    r0, r1, r2 = T[3, 0], T[3, 1], T[3, 2]
    Y = W  # W is spent: reuse it for Y (6 × 6)
    for u in range(6):
        for j in range(3):
            Y[u, j] = (
                Ia[u, 0] * T[0, j] + Ia[u, 1] * T[1, j] + Ia[u, 2] * T[2, j]
                + Ia[u, 3] * (r1 * T[2, j] - r2 * T[1, j])
                + Ia[u, 4] * (r2 * T[0, j] - r0 * T[2, j])
                + Ia[u, 5] * (r0 * T[1, j] - r1 * T[0, j])
            )  # fmt: skip
            Y[u, 3 + j] = Ia[u, 3] * T[0, j] + Ia[u, 4] * T[1, j] + Ia[u, 5] * T[2, j]
    for u in range(6):
        for v in range(u + 1):
            if u < 3:
                acc = (
                    T[0, u] * Y[0, v] + T[1, u] * Y[1, v] + T[2, u] * Y[2, v]
                    + (r1 * T[2, u] - r2 * T[1, u]) * Y[3, v]
                    + (r2 * T[0, u] - r0 * T[2, u]) * Y[4, v]
                    + (r0 * T[1, u] - r1 * T[0, u]) * Y[5, v]
                )  # fmt: skip
            else:
                acc = T[0, u - 3] * Y[3, v] + T[1, u - 3] * Y[4, v] + T[2, u - 3] * Y[5, v]
            D[p, u, v] += acc
    return True


@njit(cache=True, inline="always")
def _articulated_back(i, kk, p, s, kd, off, P, C, X, y, ws):  # type: ignore[no-untyped-def]
    """The back-substitution of :func:`_articulated_step`: x_i = X x_p + c + S α with
    α = N⁻¹ (Sᵀ y_i − Uᵀ (X x_p + c)), then μ = G⁺ᵀ (y_i − D_i x_i) (G⁺ᵀ Gᵀ = I), into y[i]
    and y[kk] (y[p] holds x_p)."""
    sp = off + 6 * s
    v6 = ws[0]
    if p >= 0:
        _ad_apply(X[kk], y[p], v6)
    else:
        for u in range(6):
            v6[u] = 0.0
    for u in range(6):  # + c = G⁺ y_k
        acc = 0.0
        for q in range(s):
            acc += P[off + u * s + q] * y[kk, q]
        v6[u] += acc
    U = X[i]
    t = ws[1]
    for j in range(kd):
        acc = 0.0
        for v in range(6):
            acc += P[sp + v * kd + j] * y[i, v] - U[v, j] * v6[v]
        t[j] = acc
    _chol_solve(C[kk], kd, 1.0, t)
    for u in range(6):
        acc = v6[u]
        for j in range(kd):
            acc += P[sp + u * kd + j] * t[j]
        v6[u] = acc
    Dc = C[i]
    f = ws[2]
    for u in range(6):  # y_i − D_i x_i
        acc = y[i, u]
        for v in range(6):
            acc -= Dc[u, v] * v6[v]
        f[u] = acc
    for q in range(s):
        acc = 0.0
        for u in range(6):
            acc += P[off + u * s + q] * f[u]
        y[kk, q] = acc
    for u in range(6):
        y[i, u] = v6[u]


@njit(cache=True, inline="always")
def _failed(A: np.ndarray, b: np.ndarray) -> int:
    """The status of a solve that stops early: 2 when A or b has an entry that is not
    finite (checked only then: a finite residual and norms certify them), else 1."""
    for i in range(b.shape[0]):
        if not np.isfinite(b[i]):
            return 2
        for e in range(12):
            if not np.isfinite(A[i, e]):
                return 2
    return 1


@njit(cache=True)
def tree_solve(
    g: np.ndarray,
    a: np.ndarray,
    rhs: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    P: np.ndarray,
    ac: np.ndarray,
    lam: np.ndarray,
) -> tuple[float, float, int]:
    """The UK solve of tree-structured rows by block LDLᵀ with no fill-in (module docstring).

    Parameters
    ----------
    g : ndarray (n_b, 4, 4)
        The bodies' poses (read for the joints that :func:`_articulated_step` eliminates).
    a : ndarray (6 n_b,)
        ν̇_a, the free accelerations [ω̇; v̇] of the bodies (rad/s², m/s²).
    rhs : ndarray (6 n_b,)
        The bodies' right-hand side (:func:`body_rhs`; N·m, N), read only when some body has
        a singular mass block (it may then be empty).
    A : ndarray (s, 12)
        Each constraint's rows on its first body (columns 0–5) and its second (6–11, zero
        for a constraint to the ground), stacked in constraint order.
    b : ndarray (s,)
    P : ndarray
        From :func:`tree_params`.
    ac, lam : ndarray (6 n_b,), (s,)
        Written: ν̇_c and λ.

    Returns
    -------
    (‖A(a + ν̇_c) − b‖₂, scale of the consistency test, status): status 0 solved, 1 not
    certified (a pivot, or a constraint with more than six rows), 2 A or b not finite.
    """
    n_float, n_int = tree_work_sizes(P)
    return _tree_solve(
        g, a, rhs, A, b, P, ac, lam, np.empty(n_float), np.empty(n_int, dtype=np.int64)
    )


@njit(cache=True, inline="always")
def tree_work_sizes(P: np.ndarray) -> tuple[int, int]:
    """The sizes of the float64 and int64 work arrays :func:`_tree_solve` takes for the
    packed tree P: (114 n_n + 102, 6 n_n) for its n_n nodes (bodies and constraints)."""
    nn = int(P[2]) + int(P[3])
    return 114 * nn + 102, 6 * nn


@njit(cache=True)
def _tree_solve(g, a, rhs, A, b, P, ac, lam, fwork, iwork):  # type: ignore[no-untyped-def]
    """:func:`tree_solve` with its work arrays from the caller (``fwork`` float64 and
    ``iwork`` int64, 1-D, at least :func:`tree_work_sizes` long), which holds them and every
    argument for the call: all are used as :func:`gmuk._numba.borrowed` references, so that
    the views of the elimination count no references."""
    g, a, rhs, A, b, P = (
        borrowed(g),
        borrowed(a),
        borrowed(rhs),
        borrowed(A),
        borrowed(b),
        borrowed(P),
    )
    ac, lam, fwork, iwork = borrowed(ac), borrowed(lam), borrowed(fwork), borrowed(iwork)
    nb = int(P[2])
    nc = int(P[3])
    nn = nb + nc
    s = b.shape[0]
    o = _HEAD
    J = P[o : o + 9 * nb].reshape((nb, 3, 3))
    o += 18 * nb  # J, J⁻¹
    m = P[o : o + nb]
    o += nb
    order = P[o : o + nn]
    o += nn
    parent = P[o : o + nn]
    o += nn
    body_a = P[o : o + nc]
    body_b = P[o + nc : o + 2 * nc]
    nrow = P[o + 2 * nc : o + 3 * nc]
    index = iwork[: 3 * nn].reshape((3, nn))
    flags = iwork[3 * nn : 6 * nn].reshape((3, nn))  # 0 or 1
    blocks = fwork[: 108 * nn].reshape((3, nn, 6, 6))
    y = fwork[108 * nn : 114 * nn].reshape((nn, 6))
    scratch = fwork[114 * nn : 114 * nn + 102].reshape((17, 6))
    for i in range(nn):
        flags[0, i] = flags[1, i] = flags[2, i] = 0
        for u in range(6):
            y[i, u] = 0.0
    row0 = index[0, :nc]
    dim = index[1]
    up = index[2]  # the parent in the back-substitution
    r = 0
    for k in range(nc):
        row0[k] = r
        dk = int(nrow[k])
        if dk > 6:
            return np.nan, np.nan, _failed(A, b)
        dim[nb + k] = dk
        r += dk
    if r != s:
        return np.nan, np.nan, _failed(A, b)
    for i in range(nb):
        dim[i] = 6
    D = blocks[0]
    C = blocks[1]
    X = blocks[2]
    D[:] = 0.0
    for i in range(nb):  # D_i = M_i = blkdiag(J_i, m_i I)
        for u in range(3):
            for v in range(3):
                D[i, u, v] = J[i, u, v]
            D[i, 3 + u, 3 + u] = m[i]
    n_singular = int(P[singular_at(P)])
    if n_singular:  # the bodies' right-hand side r_i, zero where M_i is invertible
        for e in range(6 * nb):
            y[e // 6, e % 6] = rhs[e]
    merged = flags[0]  # a constraint node eliminated with its child
    articulated = flags[1]  # a body eliminated with its joint
    stored = flags[2]  # X_i = D_i⁻¹ H_ip kept (eliminated pairs)
    for i in range(nn):
        up[i] = int(parent[i])
    for k in range(nc):  # the joint nodes' right-hand side r_k = b_k − A_k a
        ia = int(body_a[k])
        ib = int(body_b[k])
        for u in range(int(nrow[k])):
            row = row0[k] + u
            acc = b[row]
            for e in range(6):
                acc -= A[row, e] * a[6 * ia + e]
                if ib >= 0:
                    acc -= A[row, 6 + e] * a[6 * ib + e]
            y[nb + k, u] = acc
    H = scratch[0:6]  # H_ip (d_i × d_p)
    W = scratch[6:12]  # L_i⁻¹ H_ip
    col = scratch[12]
    ws = scratch[13:17]
    for step in range(nn):
        i = int(order[step])
        if merged[i] != 0:
            continue
        if i < nb and int(parent[i]) >= nb:  # a body below a joint it can be eliminated with
            kk = int(parent[i])
            half, kd, off = _joint_subspace(P, kk - nb)
            if half >= 0:
                p = int(parent[kk])
                sk = dim[kk]
                if sk == 5:  # one motion (revolute, prismatic, screw) as constants: unrolled
                    ok = _articulated_step(i, kk, p, 5, 1, off, P, g, D, C, X, y, H, W, ws)
                else:
                    ok = _articulated_step(i, kk, p, sk, kd, off, P, g, D, C, X, y, H, W, ws)
                if ok:
                    merged[kk] = 1
                    articulated[i] = 1
                    up[i] = p
                    continue
        di = dim[i]
        sign = 1.0 if i < nb else -1.0
        p = int(parent[i])
        dp = dim[p] if p >= 0 else 0
        # the common block sizes as constants, so that the compiler unrolls their loops
        if di == 6 and dp == 5:
            ok = _eliminate_node(i, p, 6, 5, sign, nb, A, row0, body_a, D, C, H, W, y, col)
        elif di == 5 and dp == 6:
            ok = _eliminate_node(i, p, 5, 6, sign, nb, A, row0, body_a, D, C, H, W, y, col)
        else:
            ok = _eliminate_node(i, p, di, dp, sign, nb, A, row0, body_a, D, C, H, W, y, col)
        if not ok:
            if not (n_singular and i < nb and p >= 0):
                return np.nan, np.nan, _failed(A, b)
            # a singular body's D_i: eliminate it with its joint to the parent, one node
            if not _eliminate_pair(i, p, int(parent[p]), nb, A, row0, body_a, dim, D, C, X, y):
                return np.nan, np.nan, _failed(A, b)
            merged[p] = 1
            stored[i] = 1
            stored[p] = 1
            up[i] = int(parent[p])
    # x_i = z_i − D_i⁻¹ H_ip x_p (X_i x_p where stored), roots first (y holds z, then x)
    for step in range(nn - 1, -1, -1):
        i = int(order[step])
        p = up[i]
        if articulated[i] != 0:
            kk = int(parent[i])
            _half, kd, off = _joint_subspace(P, kk - nb)
            if dim[kk] == 5:
                _articulated_back(i, kk, p, 5, 1, off, P, C, X, y, ws)
            else:
                _articulated_back(i, kk, p, dim[kk], kd, off, P, C, X, y, ws)
            continue
        if p < 0 or (merged[i] != 0 and stored[i] == 0):
            continue
        di = dim[i]
        dp = dim[p]
        if stored[i] != 0:
            for u in range(di):
                acc = 0.0
                for v in range(dp):
                    acc += X[i, u, v] * y[p, v]
                y[i, u] -= acc
            continue
        if di == 6 and dp == 5:
            _substitute_node(i, p, 6, 5, nb, A, row0, body_a, C, H, y, col)
        elif di == 5 and dp == 6:
            _substitute_node(i, p, 5, 6, nb, A, row0, body_a, C, H, y, col)
        else:
            _substitute_node(i, p, di, dp, nb, A, row0, body_a, C, H, y, col)
    for i in range(nb):
        for e in range(6):
            ac[6 * i + e] = y[i, e]
    for k in range(nc):
        for u in range(int(nrow[k])):
            lam[row0[k] + u] = -y[nb + k, u]
    # the residual ‖A(a + ν̇_c) − b‖₂ and the scale of the consistency test
    rr = 0.0
    nA = 0.0
    nbb = 0.0
    for k in range(nc):
        ia = int(body_a[k])
        ib = int(body_b[k])
        for u in range(int(nrow[k])):
            row = row0[k] + u
            acc = -b[row]
            for e in range(6):
                acc += A[row, e] * (a[6 * ia + e] + ac[6 * ia + e])
                nA += A[row, e] * A[row, e]
                if ib >= 0:
                    acc += A[row, 6 + e] * (a[6 * ib + e] + ac[6 * ib + e])
                    nA += A[row, 6 + e] * A[row, 6 + e]
            rr += acc * acc
            nbb += b[row] * b[row]
    na = 0.0
    nac = 0.0
    for e in range(6 * nb):
        na += a[e] * a[e]
        nac += ac[e] * ac[e]
    if not (np.isfinite(nA) and np.isfinite(nbb)) and _failed(A, b) == 2:
        return np.nan, np.nan, 2
    scale = consistency_scale(np.sqrt(nbb), np.sqrt(nA), np.sqrt(na), np.sqrt(nac))
    return np.sqrt(rr), scale, 0


@njit(cache=True)
def tree_rigid(
    g: np.ndarray,
    V: np.ndarray,
    Q: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    P: np.ndarray,
    out: np.ndarray,
) -> None:
    """Free accelerations (Eq. 10b) of the bodies at poses g (n_b, 4, 4) with twists
    V (n_b, 6) under the modeled wrenches Q
    (6 n_b,), :func:`tree_solve` of the rows A (s, 12), b (s,), the constraint wrenches
    Aᵀλ (M ν̇_c, less :func:`body_rhs` for a body with a singular mass block) and the
    total, into ``out`` (4n + s + 3, n = 6 n_b): ``[a, ν̇_c, total, M ν̇_c, λ,
    residual, scale, status]``, status 3 when solved but ``residual > consistency_tol ·
    scale``; the other entries are meaningful only for status 0 and 3 (the layout of
    :func:`gmuk.engine._uk_kernels.uk_rigid`)."""
    n_float, n_int = tree_work_sizes(P)
    _tree_rigid(
        g, V, Q, A, b, P, out, np.empty(12 * V.shape[0] + n_float), np.empty(n_int, np.int64)
    )


@njit(cache=True)
def _tree_rigid(g, V, Q, A, b, P, out, work, iwork):  # type: ignore[no-untyped-def]
    """:func:`tree_rigid` with its work arrays from the caller, which holds them and every
    argument for the call (``work`` at least 12 n_b + the float work of
    :func:`tree_work_sizes`, ``iwork`` its int work)."""
    g, V, Q, A, b = borrowed(g), borrowed(V), borrowed(Q), borrowed(A), borrowed(b)
    P, out, work, iwork = borrowed(P), borrowed(out), borrowed(work), borrowed(iwork)
    nb = V.shape[0]
    n = 6 * nb
    s = b.shape[0]
    o = _HEAD
    J = P[o : o + 9 * nb].reshape((nb, 3, 3))
    Jinv = P[o + 9 * nb : o + 18 * nb].reshape((nb, 3, 3))
    m = P[o + 18 * nb : o + 19 * nb]
    a = work[:n]
    rhs = work[n : 2 * n]
    rigid_free_accel_into(V, J, Jinv, m, Q.reshape((nb, 6)), a.reshape((nb, 6)))
    ac = out[n : 2 * n]
    for e in range(n):
        rhs[e] = 0.0
    if P[singular_at(P)] != 0.0:  # bodies with a singular mass block
        body_rhs(V, Q, a, P, rhs)
    residual, scale, status = _tree_solve(
        g, a, rhs, A, b, P, ac, out[4 * n : 4 * n + s], work[2 * n :], iwork
    )
    for k in range(nb):
        for i in range(6):
            r = 6 * k + i
            out[r] = a[r]
            out[2 * n + r] = a[r] + ac[r]
        for i in range(3):
            o3 = 6 * k
            out[3 * n + o3 + i] = (
                J[k, i, 0] * ac[o3] + J[k, i, 1] * ac[o3 + 1] + J[k, i, 2] * ac[o3 + 2]
            ) - rhs[o3 + i]
            out[3 * n + o3 + 3 + i] = m[k] * ac[o3 + 3 + i] - rhs[o3 + 3 + i]
    out[4 * n + s] = residual
    out[4 * n + s + 1] = scale
    if status == 0 and residual > P[1] * scale:
        status = 3
    out[4 * n + s + 2] = status


_call_rows = kernel_caller(ROWS_KERNEL, "constraint")


@njit(cache=True, inline="always")
def kernel_rows(t, g, V, cons, cparams, c, Ak, bk):  # type: ignore[no-untyped-def]
    """Constraint ``c`` of the table ``cons`` by its compiled kernel: its rows on its first
    body (columns 0–5 of Ak (nrow, 12)) and its second (6–11), b into bk. Returns the
    kernel's status (0: written)."""
    g, V, cparams = borrowed(g), borrowed(V), borrowed(cparams)  # views for the kernel
    i, j, p0 = cons[c, 1], cons[c, 2], cons[c, 5]
    second = j if j >= 0 else i
    return _call_rows(cons[c, 0], (t, g[i], V[i], g[second], V[second], cparams[p0:], Ak, bk))


@njit(cache=True, inline="always")
def constraint_block(t, g, V, cons, cparams, c, A, b):  # type: ignore[no-untyped-def]
    """Constraint ``c``'s rows by :func:`kernel_rows` into its block of the tree's A (s, 12)
    and b (s,), from row ``cons[c, 3]`` (the kernel writes into the block itself; columns
    6–11 are zeroed after it for a constraint on one body). Returns the kernel's status."""
    # the caller holds the arguments: their views (the row blocks) count no references
    g, V, cons, cparams, A, b = (
        borrowed(g),
        borrowed(V),
        borrowed(cons),
        borrowed(cparams),
        borrowed(A),
        borrowed(b),
    )
    r0, nrow = cons[c, 3], cons[c, 4]
    status = kernel_rows(t, g, V, cons, cparams, c, A[r0 : r0 + nrow], b[r0 : r0 + nrow])
    if status != 0:
        return status
    if cons[c, 2] < 0:  # one body: what the kernel wrote for a second is not a row
        for a in range(nrow):
            for e in range(6, 12):
                A[r0 + a, e] = 0.0
    return 0


@njit(cache=True)
def tree_rows_rigid(
    t: float,
    g: np.ndarray,
    V: np.ndarray,
    Q: np.ndarray,
    cons: np.ndarray,
    cparams: np.ndarray,
    P: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    out: np.ndarray,
) -> int:
    """The constraints' rows by their compiled kernels, then :func:`tree_rigid`: one call
    for a System whose constraints all have a compiled form.

    ``cons`` (n_c, 6) int64 holds each constraint's kernel address
    (:func:`gmuk._numba.kernel_address` for :data:`gmuk.constraints.base.ROWS_KERNEL`), its
    bodies (the second −1 for one body), first row, row count and the start of its
    parameters in ``cparams``, as the compiled loop's constraint table does; the rows go into
    A (s, 12) and b (s,), the results into ``out`` as :func:`tree_rigid` writes them. Returns
    0, or the status of a constraint kernel that failed (then ``out`` is not written)."""
    g, V, Q, cons, cparams = (
        borrowed(g),
        borrowed(V),
        borrowed(Q),
        borrowed(cons),
        borrowed(cparams),
    )
    P, A, b, out = borrowed(P), borrowed(A), borrowed(b), borrowed(out)
    status = _blocks_of_rows(t, g, V, cons, cparams, A, b)
    if status != 0:
        return status
    tree_rigid(g, V, Q, A, b, P, out)
    return 0


@njit(cache=True)
def _blocks_of_rows(t, g, V, cons, cparams, A, b):  # type: ignore[no-untyped-def]
    """Every constraint of the table ``cons`` by :func:`constraint_block` into A and b.
    Returns 0, or the status of the first kernel that failed."""
    for c in range(cons.shape[0]):
        status = constraint_block(t, g, V, cons, cparams, c, A, b)
        if status != 0:
            return status
    return 0


_call_force = kernel_caller(FORCE_KERNEL, "force model")


@njit(cache=True)
def rigid_loads(t, g, V, terms, params, fdata, P, Q, w):  # type: ignore[no-untyped-def]
    """Q (6 n_b,) ← the sum of the compiled force terms' wrenches [τ; f] (N·m, N, body
    frames) at the poses g (n_b, 4, 4) and twists V (n_b, 6): the table ``terms`` (n, 8) of
    :func:`gmuk.engine.integrators._program.pack_terms` (kernel address, rigid, body, ν
    offset, modeled, parameter start, field start, field end), each kernel called as the
    compiled loop calls it, with the body's mass and inertia from P, writing into ``w`` (6,).
    Returns 0, or the status of a kernel that failed."""
    g, V, terms, params, fdata = (
        borrowed(g),
        borrowed(V),
        borrowed(terms),
        borrowed(params),
        borrowed(fdata),
    )
    P, Q, w = borrowed(P), borrowed(Q), borrowed(w)
    nb = V.shape[0]
    J = P[_HEAD : _HEAD + 9 * nb].reshape((nb, 3, 3))
    m = P[_HEAD + 18 * nb : _HEAD + 19 * nb]
    for e in range(Q.shape[0]):
        Q[e] = 0.0
    for f in range(terms.shape[0]):
        kernel, idx, off = terms[f, 0], terms[f, 2], terms[f, 3]
        p0, f0, f1 = terms[f, 5], terms[f, 6], terms[f, 7]
        args = (True, t, g[idx], V[idx], m[idx], J[idx], params[p0:], fdata[f0:f1], w)
        status = _call_force(kernel, args)
        if status != 0:
            return status
        for i in range(6):
            Q[off + i] += w[i]
    return 0


@njit(cache=True, inline="always")
def one_call_tables(ints, floats):  # type: ignore[no-untyped-def]
    """The tables of :func:`tree_state_rigid` from its two packed arrays (their layout is
    :meth:`TreeSolver._one_call_tables`'s): (terms, cons, params, cparams, P)."""
    nt, nc = ints[0], ints[1]
    terms = ints[4 : 4 + 8 * nt].reshape((nt, 8))
    cons = ints[4 + 8 * nt : 4 + 8 * nt + 6 * nc].reshape((nc, 6))
    return terms, cons, floats[: ints[2]], floats[ints[2] : ints[3]], floats[ints[3] :]


@njit(cache=True)
def tree_state_rigid(t, g, V, ints, floats, fdata, out):  # type: ignore[no-untyped-def]
    """The loads (:func:`rigid_loads`), the rows (:func:`constraint_block`) and the solve
    (:func:`tree_rigid`) in one call, from a State's own read-only arrays g (n_b, 4, 4) and
    V (n_b, 6) of any strides: for a System whose force models and constraints all have a
    compiled form and whose loads all go through the solve. ``ints`` and ``floats`` pack the
    force terms, the constraint table, the parameters and the tree (:func:`one_call_tables`),
    ``fdata`` is the force models' field data. Writes ``out`` as :func:`tree_rigid` does
    (``out`` (4n + s + 3) sets s) and returns 0 only when the call is solved and certified
    (status 0) and every entry of ``out`` is finite, so that the caller need not scan them
    again; 1 otherwise (the caller's general path then decides, and names what failed).

    Allocates one float64 and one int64 work array, from which every other array is a
    view (:func:`_tree_state`)."""
    nb = V.shape[0]
    s = out.shape[0] - 24 * nb - 3
    n_float, n_int = tree_work_sizes(floats[ints[3] :])
    work = np.empty(22 * nb + 13 * s + 6 + 6 * nb + 12 * nb + n_float)
    return _tree_state(t, g, V, ints, floats, fdata, out, work, np.empty(n_int, np.int64))


@njit(cache=True)
def _tree_state(t, g, V, ints, floats, fdata, out, work, iwork):  # type: ignore[no-untyped-def]
    """:func:`tree_state_rigid` with its work arrays, held by the caller."""
    ints, floats, fdata, out = borrowed(ints), borrowed(floats), borrowed(fdata), borrowed(out)
    work, iwork = borrowed(work), borrowed(iwork)
    terms, cons, params, cparams, P = one_call_tables(ints, floats)
    nb = V.shape[0]
    s = out.shape[0] - 24 * nb - 3
    gw = work[: 16 * nb].reshape((nb, 4, 4))  # writable C-contiguous copies: the kernels' types
    Vw = work[16 * nb : 22 * nb].reshape((nb, 6))
    for k in range(nb):
        for u in range(4):
            for e in range(4):
                gw[k, u, e] = g[k, u, e]
        for e in range(6):
            Vw[k, e] = V[k, e]
    o = 22 * nb
    A = work[o : o + 12 * s].reshape((s, 12))
    for e in range(12 * s):
        work[o + e] = 0.0
    b = work[o + 12 * s : o + 13 * s]
    o += 13 * s
    w = work[o : o + 6]
    Q = work[o + 6 : o + 6 + 6 * nb]
    o += 6 + 6 * nb
    if rigid_loads(t, gw, Vw, terms, params, fdata, P, Q, w) != 0:
        return 1
    if _blocks_of_rows(t, gw, Vw, cons, cparams, A, b) != 0:
        return 1
    _tree_rigid(gw, Vw, Q, A, b, P, out, work[o:], iwork)
    if out[-1] != 0.0:
        return 1
    not_finite = False  # x − x is 0 for a finite x, NaN otherwise: no branch per entry
    for e in range(out.shape[0] - 1):
        not_finite |= out[e] - out[e] != 0.0
    return 1 if not_finite else 0


_I2 = types.Array(types.int64, 2, "C")
_RO1 = types.Array(types.float64, 1, "C", readonly=True)
#: The signature of :func:`tree_rows_rigid` as the System calls it.
TREE_ROWS_SIGNATURE = types.int64(
    types.float64, _RW3, _RW2, _RW1, _I2, _RW1, _RW1, _RW2, _RW1, _RW1
)
#: The signature of :func:`tree_state_rigid` as the System calls it: a State's read-only
#: arrays, of any strides.
TREE_STATE_SIGNATURE = types.int64(
    types.float64,
    types.Array(types.float64, 3, "A", readonly=True),
    types.Array(types.float64, 2, "A", readonly=True),
    types.Array(types.int64, 1, "C"),
    _RW1,
    _RO1,
    _RW1,
)
_tree_rows_c: Any = None
_tree_state_c: Any = None  # the entry of tree_state_rigid


def _tree_state_entry() -> Any:
    """The compiled entry of :func:`tree_state_rigid` for :data:`TREE_STATE_SIGNATURE`."""
    global _tree_state_c
    if _tree_state_c is None:
        _tree_state_c = overload_entry(tree_state_rigid, TREE_STATE_SIGNATURE)
    return _tree_state_c


def _tree_rows_entry() -> Any:
    """The compiled entry of :func:`tree_rows_rigid` for :data:`TREE_ROWS_SIGNATURE`."""
    global _tree_rows_c
    if _tree_rows_c is None:
        _tree_rows_c = overload_entry(tree_rows_rigid, TREE_ROWS_SIGNATURE)
    return _tree_rows_c


def _tree_entry() -> Any:
    """The compiled entry of :func:`tree_rigid` for :data:`TREE_SIGNATURE`, compiled (or
    loaded from the cache) once."""
    global _tree_rigid_c
    if _tree_rigid_c is None:
        _tree_rigid_c = overload_entry(tree_rigid, TREE_SIGNATURE)
    return _tree_rigid_c


# ----------------------------------------------------------------------------- strategy
class _Blocks(NamedTuple):
    """Rows in blocks (A (s, 12), b (s,)) that the tree solve could not certify."""

    A: FloatArray
    b: FloatArray


def _constraint_pairs(system: System) -> tuple[list[tuple[int, int]], list[str]]:
    """Each constraint's rigid bodies as (a, b) (b = −1 for one body), and what keeps a
    constraint out of a tree solve."""
    pairs: list[tuple[int, int]] = []
    problems: list[str] = []
    lay = system.layout
    for c in system.constraints:
        who = f"{type(c).__name__} {c.name!r}"
        if getattr(c, "unilateral", False):
            problems.append(f"{who} is unilateral (the tree solve takes equalities only)")
            continue
        bodies = [system._resolve(r) for r in c.bodies]
        if not 1 <= len(bodies) <= 2:
            problems.append(f"{who} acts on {len(bodies)} bodies (the tree solve takes 1 or 2)")
            continue
        if any(b.kind is not BodyKind.RIGID for b in bodies):
            problems.append(f"{who} acts on a body that is not rigid")
            continue
        idx = [lay.slot(b).index for b in bodies]
        if len(idx) == 2 and idx[0] == idx[1]:
            problems.append(f"{who} acts twice on one body")
            continue
        pairs.append((idx[0], idx[1] if len(idx) == 2 else -1))
    return pairs, problems


def _scale(A: FloatArray, b: FloatArray, a: FloatArray, ac: FloatArray) -> float:
    """The consistency test's scale (:func:`consistency_scale`) of rows A, b and the free and
    constraint accelerations a, ac."""
    return float(
        consistency_scale(
            np.sqrt(b @ b), np.sqrt(np.sum(A * A)), np.linalg.norm(a), np.linalg.norm(ac)
        )
    )


class TreeSolver(UKSolver):
    """Tree-structured constraints on rigid bodies in linear time (Baraff 1996).

    Applies when every body is rigid and every constraint is an equality on one rigid body
    (to the ground) or two, with the constraints forming a tree or forest with the ground
    (a robot's joints, fixed or floating base). The solve is the block LDLᵀ factorisation of
    the module docstring, compiled: its cost grows linearly with the number of bodies. A
    call whose rows it cannot certify to have full row rank (a Cholesky pivot, more than six
    rows in one constraint) or whose residual is above the consistency test takes the dense
    solve (up to :data:`DENSE_FALLBACK_DOF` dof; QR, else SVD) or the sparse one, which
    decide the rank and warn as they do under those strategies. Above
    :data:`DENSE_FALLBACK_DOF` dof the System keeps its rows and mass matrix in sparse blocks:
    no n_dof × n_dof matrix is formed.
    """

    name = "tree"
    sparse = False  # the System asks wants_sparse: by its size

    @classmethod
    def wants_sparse(cls, system: System) -> bool:
        """Sparse rows and mass blocks above :data:`DENSE_FALLBACK_DOF` dof, dense below
        (as the System keeps them for the dense strategies)."""
        return system.layout.n_dof > DENSE_FALLBACK_DOF

    def __init__(self, system: System) -> None:
        super().__init__(system)
        pairs, _ = _constraint_pairs(system)
        structure = tree_structure(system.layout.n_rigid, pairs)
        assert not isinstance(structure, str)  # problems() has checked it
        self._order, self._parent = structure
        self._pairs = pairs
        self._width = [6 if b < 0 else 12 for _, b in pairs]
        self._lay = lay = system.layout
        self._n = lay.n_dof
        self._V_shape = (lay.n_rigid, 6)
        self._zero_loads = system._zero_loads
        self._zero_z = system._zero_z
        #: The fields of a one-call Accelerations that do not depend on the state.
        self._shared = {
            "layout": lay,
            "extra": self._zero_loads,
            "control_force": self._zero_loads,
            "unmodeled_force": self._zero_loads,
            "unreachable": 0.0,
            "z_dot": self._zero_z,
        }
        self._constraints = system.constraints
        self._rows_n: list[int] | None = None
        # the joints the solve eliminates with their child, as the articulated-body algorithm
        self._subspaces = [c._tree_subspace() for c in system.constraints]
        self._P = np.zeros(1)
        self._last_rhs = np.zeros(system.layout.n_dof)
        terms = [c._compiled_term() for c in system.constraints]
        # every constraint compiled: its rows in the same compiled call as the solve
        self._cons: np.ndarray | None = None
        self._cparams = np.zeros(1)
        if all(t is not None for t in terms):  # the row counts are known: pack P now
            rows = [int(t[2]) for t in terms if t is not None]
            self._pack(rows)
            table: list[list[int]] = []
            cparams: list[float] = []
            r0 = 0
            for term, (ia, ib), k in zip(terms, pairs, rows, strict=True):
                assert term is not None
                kernel, values, _ = term
                table.append([kernel_address(kernel, ROWS_KERNEL), ia, ib, r0, k, len(cparams)])
                cparams += values
                r0 += k
            self._cons = np.array(table, dtype=np.int64).reshape(-1, 6)
            self._cparams = np.array([*cparams, 0.0])
            self._s = r0
            _tree_rows_entry()
        # every load compiled and seen by the solve: loads, rows and solve in one call
        self._loads_table: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._one_call: tuple[Any, ...] | None = None  # _one_call_tables
        if self._cons is not None and not system._plant_only_loads and not system.controllers:
            from gmuk.engine.integrators import _program

            plan, in_python = _program.force_terms(system._force_plan)
            if not in_python and all(term[3] for term in plan):  # rigid bodies only
                self._loads_table = _program.pack_terms(plan)
                self._one_call_tables()
                _tree_state_entry()
        from gmuk.engine.system import _pair

        self._pair = _pair
        _tree_entry()

    def _pack(self, rows: list[int]) -> None:
        s = self.system
        self._rows_n = rows
        self._P = tree_params(
            s._J, s._Jinv, s._m_rigid, self._order, self._parent, self._pairs, rows,
            s.consistency_tol, s._singular, self._subspaces,
        )  # fmt: skip
        if getattr(self, "_loads_table", None) is not None:
            self._one_call_tables()

    def _one_call_tables(self) -> None:
        """The tables of :func:`tree_state_rigid` packed into two arrays (fewer arguments to
        convert at each call): ``ints`` = [n_terms, n_constraints, end of the force
        parameters, end of the constraint parameters, the force terms (n_terms, 8) row by
        row, the constraint table (n_c, 6) row by row] and ``floats`` = [force parameters,
        constraint parameters, the packed tree P]; the field data stays read-only beside
        them."""
        assert self._loads_table is not None and self._cons is not None
        terms, params, fdata = self._loads_table
        head = [terms.shape[0], self._cons.shape[0], params.size, params.size + self._cparams.size]
        n, s = self._n, self._s
        self._one_call = (
            np.concatenate([np.array(head), terms.ravel(), self._cons.ravel()]).astype(np.int64),
            np.concatenate([params, self._cparams, self._P]),
            fdata,
            4 * n + s + 3,  # the size of the call's output
            n,
            s,
            self._shared,
        )

    def loop_constants(self, state: State) -> np.ndarray:
        """The packed tree (:func:`tree_params`) after its first two entries, which the
        compiled program puts in front (``solve_constants`` of
        :class:`gmuk.engine.integrators._program.SystemView`), with each constraint's row
        count as it is at ``state``."""
        if self._cons is None:  # packs the row counts of constraints evaluated in Python
            self._blocks(state)
        return np.array(self._P[2:])

    @classmethod
    def problems(cls, system: System) -> list[str]:
        """Rigid bodies only; equalities on one or two bodies forming a tree or forest with
        the ground."""
        out = []
        if system.layout.n_euclid:
            out.append("the tree solve takes rigid bodies only")
        pairs, problems = _constraint_pairs(system)
        out += problems
        if not problems:
            lay = system.layout
            if not np.array_equal(lay.rigid_offsets, 6 * np.arange(lay.n_rigid)):
                out.append("the tree solve takes rigid bodies only")
            structure = tree_structure(lay.n_rigid, pairs)
            if isinstance(structure, str):
                out.append(structure)
        return [f"solver 'tree': {p}" for p in out]

    # -- rows in blocks
    def _blocks(self, state: State) -> tuple[FloatArray, FloatArray]:
        """Each constraint's rows (s, 12) on its first and second body, and b (s,)."""
        pair = self._pair
        got = []
        for c, width in zip(self._constraints, self._width, strict=True):
            Ai, bi = pair(c, state)
            if not (
                type(Ai) is np.ndarray
                and type(bi) is np.ndarray
                and Ai.dtype == np.float64
                and bi.dtype == np.float64
                and bi.ndim == 1
                and Ai.shape == (bi.shape[0], width)
            ):
                Ai, bi = as_rows(Ai, bi, width, f"constraint {c.name!r}")
                if hasattr(Ai, "toarray"):
                    Ai = Ai.toarray()
            got.append((Ai, bi))
        rows = [bi.shape[0] for _, bi in got]
        if rows != self._rows_n:
            self._pack(rows)
        s = sum(rows)
        A = np.zeros((s, 12))
        b = np.empty(s)
        r = 0
        for (Ai, bi), width in zip(got, self._width, strict=True):
            k = bi.shape[0]
            A[r : r + k, :width] = Ai
            b[r : r + k] = bi
            r += k
        return A, b

    def _dense(self, A: FloatArray) -> FloatArray:
        """The stacked A (s, n_dof) of blocks (s, 12)."""
        out = np.zeros((A.shape[0], self._n))
        r = 0
        for (ia, ib), k in zip(self._pairs, self._rows_n or [], strict=True):
            out[r : r + k, 6 * ia : 6 * ia + 6] = A[r : r + k, :6]
            if ib >= 0:
                out[r : r + k, 6 * ib : 6 * ib + 6] = A[r : r + k, 6:]
            r += k
        return out

    # -- the solve
    def accelerations(self, state: State) -> Accelerations:
        """One compiled call (free acceleration, tree solve, wrenches) when nothing acts on
        the plant beyond the solve, with the loads in it too when every force model is
        compiled; the general path otherwise."""
        one = self._one_call
        if one is not None:  # one compiled call from the State's own arrays
            ints, floats, fdata, size, n, s, shared = one
            out = np.empty(size)
            if _tree_state_c(float(state.t), state.g, state.V, ints, floats, fdata, out) == 0:
                return _packed(out, n, s, shared)
            # a kernel failed or the call is not certified: the path below decides
        system = self.system
        modeled, unmodeled = self._loads(state)
        if system._plant_only_loads:
            return self._general(state, modeled, unmodeled, None)
        n = self._n
        V = state.V
        status = -1.0
        if self._cons is not None:  # rows and solve in one compiled call
            s = self._s
            A, b = np.zeros((s, 12)), np.empty(s)
            out = np.empty(4 * n + s + 3)
            if (
                _tree_rows_c(
                    float(state.t),
                    np.array(state.g, dtype=float),  # writable copies: the kernels' types
                    np.array(V, dtype=float),
                    np.array(modeled, dtype=float),
                    self._cons,
                    self._cparams,
                    self._P,
                    A,
                    b,
                    out,
                )
                == 0
            ):
                status = float(out[-1])
        if status < 0.0:  # rows in Python (or a constraint kernel failed: its error)
            A, b = self._blocks(state)
            s = b.size
            out = np.empty(4 * n + s + 3)
            g = np.array(state.g, dtype=float)  # a writable copy: the kernel's type
            if V.dtype == _F64 and V.shape == self._V_shape and V.flags.c_contiguous:
                _tree_rigid_c(g, _writable(V), _writable(modeled), A, b, self._P, out)
            else:
                tree_rigid(g, np.ascontiguousarray(V, dtype=float), modeled, A, b, self._P, out)
            status = float(out[-1])
        if status == _SOLVED:
            return self._solved(out, s, unmodeled)
        if status == _NOT_FINITE:
            self._not_finite(state)
        return self._general(state, modeled, unmodeled, _Blocks(A, b))

    def _solved(self, out: FloatArray, s: int, unmodeled: FloatArray) -> Accelerations:
        """The Accelerations of a certified compiled call (``out`` as :func:`tree_rigid`
        writes it)."""
        n = self._n
        return Accelerations._from_dict(
            {
                "layout": self._lay,
                "free": out[:n],
                "constraint": out[n : 2 * n],
                "extra": self._zero_loads,
                "total": out[2 * n : 3 * n],
                "constraint_force": out[3 * n : 4 * n],
                "control_force": self._zero_loads,
                "unmodeled_force": unmodeled,
                "multipliers": out[4 * n : 4 * n + s] if s else _NO_MULTIPLIERS,
                "residual": float(out[-3]),
                "rank": s,
                "unreachable": 0.0,
                "z_dot": self._zero_z,
            }
        )

    def _not_finite(self, state: State) -> None:
        self.system.constraint_rows(state)  # raises ConstraintError naming the constraint
        raise ConstraintError(f"constraint rows at t = {state.t:.9g} s are not finite")

    def solve(self, state: State, a: FloatArray, rows: Any = None) -> Solution:
        """The tree solve of the rows at ``state``, with the dense or sparse solve where it
        cannot certify its answer (``rows``: the blocks a call could not certify, or None)."""
        a = np.ascontiguousarray(a, dtype=float)
        r = self._rhs(state, a)
        if isinstance(rows, _Blocks):
            return self._fallback(state, a, rows.A, rows.b, r)
        A, b = self._blocks(state)
        if b.size == 0:
            return np.zeros_like(a), np.zeros(0), 0, 0.0, 0.0
        ac = np.zeros(self._n)
        lam = np.zeros(b.size)
        residual, scale, status = tree_solve(
            np.ascontiguousarray(state.g, dtype=float), a, r, A, b, self._P, ac, lam
        )
        if status == 0 and residual <= self.system.consistency_tol * scale:
            return ac, lam, b.size, float(residual), 0.0
        if status == 2 or not (all_finite(A) and all_finite(b)):
            self._not_finite(state)
        return self._fallback(state, a, A, b, r)

    def _rhs(self, state: State, a: FloatArray) -> FloatArray:
        """:func:`body_rhs` at ``state`` for the free acceleration ``a`` (zeros when no body
        has a singular mass block), kept for :meth:`_constraint_wrench`."""
        r = np.zeros(self._n)
        if self.system._singular.any():
            modeled, _ = self._loads(state)
            V = np.ascontiguousarray(state.V, dtype=float)
            body_rhs(V, np.ascontiguousarray(modeled, dtype=float), a, self._P, r)
        self._last_rhs = r
        return r

    def _constraint_wrench(self, ac: FloatArray) -> FloatArray:
        """Aᵀλ = M ν̇_c − r of the solve just made (r from :meth:`_rhs`: zero but for
        bodies with a singular mass block)."""
        return self.system._apply_M(ac) - self._last_rhs

    def _fallback(
        self, state: State, a: FloatArray, A: FloatArray, b: FloatArray, r: FloatArray
    ) -> Solution:
        """The dense (QR, else SVD) or sparse solve of the same rows, which decides the rank
        and warns on inconsistent rows as under those strategies; for a System with singular
        mass blocks, the dense KKT system (:meth:`_singular_kkt`)."""
        system = self.system
        A_full = self._dense(A)
        if system._singular.any():
            return self._singular_kkt(state, a, A_full, b, r)
        if not system.sparse:
            Ms = system._Minv_sqrt
            rcond = system.rcond if system.rcond is not None else max(A_full.shape) * _EPS
            if A_full.shape[0] <= QR_MAX_ROWS:
                ac, lam, residual, scale, status = _uk_kernels.uk_qr(
                    A_full, b, a, Ms, min(QR_COND_LIMIT, 0.1 / rcond)
                )
                if status == _SOLVED:
                    self.check_consistency(state, residual, scale)
                    return ac, lam, b.size, float(residual), 0.0
            ac, lam, rank, residual, scale = _uk_kernels.uk_dense(A_full, b, a, Ms, rcond)
            self.check_consistency(state, residual, scale)
            return ac, lam, int(rank), float(residual), 0.0
        import scipy.sparse as sp

        A_sp = sp.csr_matrix(A_full)
        ac, lam, rank_sp = uk.solve_sparse(
            A_sp, b - A_sp @ a, system._Minv_sp, system._Minv_sqrt_sp, system.sparse_solver
        )
        residual = float(np.linalg.norm(A_sp @ (a + ac) - b))
        self.check_consistency(state, residual, _scale(A, b, a, ac))
        return ac, lam, rank_sp, residual, 0.0

    def _singular_kkt(
        self, state: State, a: FloatArray, A: FloatArray, b: FloatArray, r: FloatArray
    ) -> Solution:
        """``[[M, Aᵀ], [A, 0]] [ν̇_c; μ] = [r; b − A a]`` solved densely, when the tree solve
        cannot certify a System with singular mass blocks: its answer if the KKT matrix has
        full rank (the motion is determined), a ConstraintError naming the state otherwise
        (no minimum-norm choice stands in for a motion the equations leave free)."""
        n, s = self._n, b.size
        K = np.zeros((n + s, n + s))
        K[:n, :n] = self.system.mass_matrix
        K[:n, n:] = A.T
        K[n:, :n] = A
        rhs = np.concatenate([r, b - A @ a])
        sv = np.linalg.svd(K, compute_uv=False)
        if not sv[-1] > max(K.shape) * _EPS * sv[0]:
            raise ConstraintError(
                f"at t = {state.t:.9g} s the constrained equations are singular: bodies with "
                "a singular mass block (allow_singular) have motions that neither their mass "
                "nor their constraints determine (e.g. a massless link at the end of a chain)"
            )
        x = np.linalg.solve(K, rhs)
        ac, lam = x[:n], -x[n:]
        residual = float(np.linalg.norm(A @ (a + ac) - b))
        self.check_consistency(state, residual, _scale(A, b, a, ac))
        return ac, lam, s, residual, 0.0
