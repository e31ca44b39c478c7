"""Legendre–Gauss–Lobatto (LGL) nodes, weights, differentiation and integration matrices.

Pure numpy, no CasADi. On ``[−1, 1]`` with degree p (p + 1 nodes):

nodes
    ``x₀ = −1``, ``x_p = 1`` and the p − 1 zeros of ``P'_p`` (P_p the Legendre polynomial).
    The interior zeros are the Gauss–Jacobi nodes of weight ``(1 − x²)`` (α = β = 1): the
    eigenvalues of the symmetric tridiagonal Jacobi matrix with zero diagonal and
    off-diagonal ``√(n(n + 2)/((2n + 1)(2n + 3)))``, n = 1 … p − 2 (Golub & Welsch 1969),
    each polished by two Newton steps on ``P'_p`` (``P''_p`` from Legendre's equation).
weights
    ``w_j = 2 / (p(p + 1) P_p(x_j)²)``; the rule is exact for polynomials of degree ≤ 2p − 1.
differentiation matrix
    ``D_ij = P_p(x_i) / (P_p(x_j)(x_i − x_j))`` for i ≠ j, and the diagonal by the
    negative-sum trick ``D_ii = −Σ_{j≠i} D_ij`` (exact on constants, and more accurate in
    floating point than the closed form ``∓p(p + 1)/4``; Baltensperger & Trummer 2003).
integration matrix
    ``A_ij = ∫_{−1}^{x_i} ℓ_j(s) ds`` with ℓ_j the Lagrange polynomial of node j, from the
    discrete Legendre expansion ``ℓ_j = w_j Σ_k P_k(x_j) P_k / γ_k`` (γ_k = 2/(2k + 1),
    γ_p = 2/p on the LGL grid) and ``∫_{−1}^{x} P_k = (P_{k+1} − P_{k−1})/(2k + 1)``. Its last
    row is the weights. It is the Butcher matrix of the Lobatto IIIA collocation method that
    :mod:`gmuk.optimize` uses (with ``c = (x + 1)/2`` and a factor ½).

Everything is evaluated by the three-term Legendre recurrence, stable at any degree (tested
to p = 200).

References
----------
Golub, G. H. & Welsch, J. H. (1969), Calculation of Gauss quadrature rules, *Math. Comp.* 23.
Canuto, Hussaini, Quarteroni & Zang (2006), *Spectral Methods: Fundamentals in Single
Domains*, §2.3 (LGL nodes, weights, Eq. 2.3.12) and §2.4 (differentiation matrix).
Baltensperger, R. & Trummer, M. R. (2003), Spectral differencing with a twist, *SIAM J. Sci.
Comput.* 24(5).
Hairer, Nørsett & Wanner (1993), *Solving Ordinary Differential Equations I*, §II.7
(collocation; Lobatto IIIA).
"""

from __future__ import annotations

import functools
import operator
from typing import Any

import numpy as np

from gmuk._validation import FloatArray, as_array, real_number, real_sequence
from gmuk.errors import DefinitionError

__all__ = [
    "barycentric_weights",
    "interpolation_matrix",
    "legendre",
    "lgl_differentiation_matrix",
    "lgl_integration_matrix",
    "lgl_nodes",
]

#: Largest degree accepted (nodes are distinct and the recurrences accurate well beyond it).
MAX_DEGREE = 400


def _degree(p: Any) -> int:
    try:
        if isinstance(p, (bool, np.bool_)):
            raise TypeError
        n = operator.index(p)
    except TypeError:
        raise DefinitionError(f"an LGL degree must be an integer ≥ 1; got {p!r}") from None
    if not 1 <= n <= MAX_DEGREE:
        raise DefinitionError(f"an LGL degree must be in [1, {MAX_DEGREE}]; got {n}")
    return n


def legendre(p: int, x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``P_p(x)`` and ``P'_p(x)`` by the three-term recurrence.

    Parameters
    ----------
    p : int
        Degree, ≥ 0.
    x : ndarray
        Points in [−1, 1] (any shape).

    Returns
    -------
    P, dP : ndarray, the shape of x

    Raises
    ------
    DefinitionError
        For a degree that is not an integer in [0, 400].
    ShapeError, NonFiniteError
        For points that are not finite real numbers.
    """
    if not (isinstance(p, (int, np.integer)) and not isinstance(p, bool) and p == 0):
        p = _degree(p)
    x = as_array(x, (), "points x")
    p0, p1 = np.ones_like(x), x.copy()
    d0, d1 = np.zeros_like(x), np.ones_like(x)
    if p == 0:
        return p0, d0
    for n in range(1, p):
        # (n+1) P_{n+1} = (2n+1) x P_n − n P_{n−1};  P'_{n+1} = P'_{n−1} + (2n+1) P_n
        p0, p1 = p1, ((2 * n + 1) * x * p1 - n * p0) / (n + 1)
        d0, d1 = d1, d0 + (2 * n + 1) * p0
    return p1, d1


@functools.lru_cache(maxsize=64)
def _nodes_weights(p: int) -> tuple[FloatArray, FloatArray]:
    if p == 1:
        x = np.array([-1.0, 1.0])
    else:
        n = np.arange(1, p - 1, dtype=float)
        off = np.sqrt(n * (n + 2.0) / ((2.0 * n + 1.0) * (2.0 * n + 3.0)))
        interior = np.linalg.eigvalsh(np.diag(off, 1) + np.diag(off, -1)) if p > 2 else np.zeros(1)
        for _ in range(2):  # Newton on P'_p, with P''_p = (2x P'_p − p(p+1) P_p)/(1 − x²)
            P, dP = legendre(p, interior)
            ddP = (2.0 * interior * dP - p * (p + 1) * P) / (1.0 - interior**2)
            interior = interior - dP / ddP
        interior = 0.5 * (interior - interior[::-1])  # exact symmetry x ↔ −x
        x = np.concatenate([[-1.0], np.sort(interior), [1.0]])
    P, _ = legendre(p, x)
    w = 2.0 / (p * (p + 1) * P**2)
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w


def lgl_nodes(p: int) -> tuple[FloatArray, FloatArray]:
    """LGL nodes and quadrature weights of degree p on [−1, 1].

    Parameters
    ----------
    p : int
        Polynomial degree, 1 ≤ p ≤ 400 (p + 1 nodes; p = 1 is the trapezoidal rule).

    Returns
    -------
    x : ndarray (p + 1,)
        Increasing nodes, ``x[0] = −1``, ``x[-1] = 1`` (read-only).
    w : ndarray (p + 1,)
        Weights, summing to 2, exact for polynomials of degree ≤ 2p − 1 (read-only).
    """
    return _nodes_weights(_degree(p))


def _nodes(x: Any) -> FloatArray:
    """Interpolation nodes: a 1-D sequence of at least one finite, distinct real number."""
    a = real_sequence(x, "interpolation nodes x", min_size=1)
    if np.unique(a).size != a.size:
        raise DefinitionError(f"interpolation nodes x must be distinct; got {x!r:.80}")
    return a


def barycentric_weights(x: FloatArray) -> FloatArray:
    """Barycentric weights ``1/Π_{k≠j}(x_j − x_k)`` of distinct nodes, scaled to max 1.

    ``x`` is a 1-D sequence of at least one finite, distinct real number (else
    :class:`DefinitionError`)."""
    x = _nodes(x)
    diff = x[:, None] - x[None, :]
    np.fill_diagonal(diff, 1.0)
    # products in log form would lose the sign; scaling each factor by 2/(range) keeps
    # the product within float range for a few hundred nodes
    scale = 2.0 / (x.max() - x.min()) if x.size > 1 else 1.0
    b = 1.0 / np.prod(diff * scale, axis=1)
    return b / np.abs(b).max()


def interpolation_matrix(x: FloatArray, y: FloatArray) -> FloatArray:
    """The matrix L (len(y), len(x)) with ``L @ f(x) = p(y)``, p the interpolant of f on x.

    Barycentric formula (second kind), exact at the nodes.

    Parameters
    ----------
    x : ndarray (n,)
        Distinct, finite nodes (n ≥ 1).
    y : float or ndarray (m,)
        Finite evaluation points.

    Raises
    ------
    DefinitionError
        For nodes or points that are not finite real numbers of these shapes, or nodes
        that repeat.
    """
    x = _nodes(x)
    if np.ndim(y) == 0 and not isinstance(y, (str, bytes)):
        y = np.array([real_number(y, "evaluation point y")])
    else:
        y = real_sequence(y, "evaluation points y")
    b = barycentric_weights(x)
    diff = y[:, None] - x[None, :]
    exact = diff == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = b[None, :] / diff
        L = terms / terms.sum(axis=1, keepdims=True)
    rows = exact.any(axis=1)
    L[rows] = exact[rows].astype(float)
    return L


@functools.lru_cache(maxsize=64)
def _differentiation(p: int) -> FloatArray:
    x, _ = _nodes_weights(p)
    P, _ = legendre(p, x)
    diff = x[:, None] - x[None, :]
    np.fill_diagonal(diff, 1.0)
    D = (P[:, None] / P[None, :]) / diff
    np.fill_diagonal(D, 0.0)
    np.fill_diagonal(D, -D.sum(axis=1))
    D.setflags(write=False)
    return D


def lgl_differentiation_matrix(p: int) -> FloatArray:
    """The LGL differentiation matrix D (p + 1, p + 1) on [−1, 1].

    ``D @ f(x)`` is the derivative of the degree-p interpolant of f at the nodes, exact for
    polynomials of degree ≤ p (read-only array).
    """
    return _differentiation(_degree(p))


@functools.lru_cache(maxsize=64)
def _integration(p: int) -> FloatArray:
    x, w = _nodes_weights(p)
    # P_k at the nodes, k = 0 … p + 1
    Pk = np.empty((p + 2, p + 1))
    Pk[0] = 1.0
    Pk[1] = x
    for n in range(1, p + 1):
        Pk[n + 1] = ((2 * n + 1) * x * Pk[n] - n * Pk[n - 1]) / (n + 1)
    gamma = 2.0 / (2.0 * np.arange(p + 1) + 1.0)
    gamma[p] = 2.0 / p  # the discrete norm of P_p on the LGL grid
    # I_k(x_i) = ∫_{-1}^{x_i} P_k
    Ik = np.empty((p + 1, p + 1))
    Ik[0] = x + 1.0
    for k in range(1, p + 1):
        Ik[k] = (Pk[k + 1] - Pk[k - 1]) / (2 * k + 1)
    # ℓ_j = w_j Σ_k P_k(x_j) P_k / γ_k  ⇒  A_ij = Σ_k I_k(x_i) P_k(x_j) w_j / γ_k
    A = Ik.T @ (Pk[: p + 1] * (w[None, :] / gamma[:, None]))
    A[0] = 0.0
    A.setflags(write=False)
    return A


def lgl_integration_matrix(p: int) -> FloatArray:
    """The LGL integration matrix A (p + 1, p + 1) on [−1, 1]:
    ``A_ij = ∫_{−1}^{x_i} ℓ_j(s) ds``.

    ``A @ f(x)`` integrates the degree-p interpolant of f from −1 to each node, exact for
    polynomials f of degree ≤ p; ``A[0] = 0`` and ``A[-1] = w`` (read-only array).
    """
    return _integration(_degree(p))
