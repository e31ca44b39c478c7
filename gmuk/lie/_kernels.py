"""Compiled (numba) kernels for SO(3)/SE(3): the single implementation behind gmuk.lie.

Every kernel takes flattened batches (leading axis n) and loops in machine code, so a single
element costs one compiled call instead of a chain of numpy calls, each with its own
overhead. The batch maps (``se3_exp``, ``compose_exp``, …) are thin Python functions that
allocate their result and let a kernel (``_se3_exp_into``, …) fill it: boxing an array that
a numba kernel returns costs several times what ``np.empty`` does (numba unpickles the
array's dtype on every return).
Formulas and series thresholds are documented in :mod:`gmuk.lie._coeffs` and in the public
modules :mod:`gmuk.lie.so3`, :mod:`gmuk.lie.se3`.
"""

from __future__ import annotations

import math

import numpy as np

from gmuk._numba import borrowed, njit
from gmuk.lie._coeffs import _C_SERIES, _D_SERIES, _DE_SERIES_BELOW, _E_SERIES, _SERIES_BELOW

_C = tuple(float(c) for c in _C_SERIES)  # highest power first (np.polyval order)
_D = tuple(float(c) for c in _D_SERIES)
_E = tuple(float(c) for c in _E_SERIES)
_T = float(_SERIES_BELOW)
_TDE = float(_DE_SERIES_BELOW)
#: Below this x = θ² (θ ≤ 0.5 rad, the angles of an integrator's stage increments) the
#: series are summed with fewer terms (:func:`_leading_terms`).
_SHORT_BELOW = 0.25


def _leading_terms(coeffs: tuple[float, ...], x_max: float) -> tuple[float, ...]:
    """The lowest-power coefficients of a series in x (``coeffs`` highest power first)
    whose dropped terms sum, for 0 ≤ x ≤ x_max, to less than 2⁻⁵⁶ of the series' smallest
    value there (|c₀| less every other term at x_max): below a quarter of the last bit."""
    c = coeffs[::-1]
    low = abs(c[0]) - sum(abs(v) * x_max**k for k, v in enumerate(c) if k)
    for keep in range(1, len(c) + 1):
        if sum(abs(v) * x_max**k for k, v in enumerate(c) if k >= keep) < 2.0**-56 * low:
            return coeffs[len(c) - keep :]
    return coeffs


_C_SHORT = _leading_terms(_C, _SHORT_BELOW)
_D_SHORT = _leading_terms(_D, _SHORT_BELOW)
_E_SHORT = _leading_terms(_E, _SHORT_BELOW)


@njit(cache=True, inline="always")
def _horner(coeffs: tuple, x: float) -> float:
    acc = 0.0
    for c in coeffs:
        acc = acc * x + c
    return acc


@njit(cache=True, inline="always")
def _series(coeffs: tuple, short: tuple, x: float) -> float:
    """The series ``coeffs`` at x, with its leading terms ``short`` only where the rest is
    below the last bit (x ≤ :data:`_SHORT_BELOW`)."""
    return _horner(short, x) if x <= _SHORT_BELOW else _horner(coeffs, x)


@njit(cache=True)
def _sinc(t: float) -> float:
    return 1.0 if t == 0.0 else math.sin(t) / t


@njit(cache=True)
def _b(t: float) -> float:
    """(1 − cos θ)/θ² = ½ sinc²(θ/2)."""
    s = _sinc(0.5 * t)
    return 0.5 * s * s


@njit(cache=True)
def _c(t: float) -> float:
    """(θ − sin θ)/θ³."""
    if t < _T:
        return _series(_C, _C_SHORT, t * t)
    return (t - math.sin(t)) / (t * t * t)


@njit(cache=True)
def _d(t: float) -> float:
    """(1 − (θ/2) cot(θ/2))/θ²."""
    if t < _TDE:
        return _series(_D, _D_SHORT, t * t)
    h = 0.5 * t
    return (1.0 - h / math.tan(h)) / (t * t)


@njit(cache=True)
def _f1_f2(t: float) -> tuple[float, float]:
    d = _d(t)
    if t < _TDE:
        e = _series(_E, _E_SHORT, t * t)
    else:
        e = (d - 1.0 / 12.0) / (t * t)
    return 2.5 * d - 0.5 * t * t * d * d - 0.125, 1.5 * e - 0.5 * d * d


@njit(cache=True, inline="always")
def _cross(
    a0: float, a1: float, a2: float, b0: float, b1: float, b2: float
) -> tuple[float, float, float]:
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True)
def _rot_exp(w0: float, w1: float, w2: float, R: np.ndarray) -> None:
    t = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    a = _sinc(t)
    b = _b(t)
    c = math.cos(t)
    R[0, 0] = c + b * w0 * w0
    R[1, 1] = c + b * w1 * w1
    R[2, 2] = c + b * w2 * w2
    R[0, 1] = b * w0 * w1 - a * w2
    R[1, 0] = b * w0 * w1 + a * w2
    R[0, 2] = b * w0 * w2 + a * w1
    R[2, 0] = b * w0 * w2 - a * w1
    R[1, 2] = b * w1 * w2 - a * w0
    R[2, 1] = b * w1 * w2 + a * w0


@njit(cache=True)
def _so3_exp_into(w: np.ndarray, out: np.ndarray) -> None:
    """:func:`so3_exp` written into ``out``."""
    n = w.shape[0]
    for k in range(n):
        _rot_exp(w[k, 0], w[k, 1], w[k, 2], out[k])


def so3_exp(w: np.ndarray) -> np.ndarray:
    """(n, 3) → (n, 3, 3)."""
    out = np.empty((w.shape[0], 3, 3))
    _so3_exp_into(w, out)
    return out


@njit(cache=True)
def _rot_log(R: np.ndarray) -> tuple[float, float, float, float]:
    """Rotation vector and angle of R (angle in [0, π]); robust near π."""
    c = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)
    s0 = 0.5 * (R[2, 1] - R[1, 2])
    s1 = 0.5 * (R[0, 2] - R[2, 0])
    s2 = 0.5 * (R[1, 0] - R[0, 1])
    s = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    t = math.atan2(s, min(1.0, max(-1.0, c)))
    if c < 0.0 and s < 0.1:
        # Axis from the symmetric part (R + Rᵀ)/2 − c I = (1 − c) e eᵀ, largest diagonal.
        d0, d1, d2 = R[0, 0] - c, R[1, 1] - c, R[2, 2] - c
        if d0 >= d1 and d0 >= d2:
            k = 0
            skk = d0
        elif d1 >= d2:
            k = 1
            skk = d1
        else:
            k = 2
            skk = d2
        col0 = 0.5 * (R[0, k] + R[k, 0]) - (c if k == 0 else 0.0)
        col1 = 0.5 * (R[1, k] + R[k, 1]) - (c if k == 1 else 0.0)
        col2 = 0.5 * (R[2, k] + R[k, 2]) - (c if k == 2 else 0.0)
        nrm = math.sqrt(skk * (1.0 - c))
        e0, e1, e2 = col0 / nrm, col1 / nrm, col2 / nrm
        if e0 * s0 + e1 * s1 + e2 * s2 < 0.0:
            e0, e1, e2 = -e0, -e1, -e2
        return t * e0, t * e1, t * e2, t
    f = 1.0 / _sinc(t)
    return f * s0, f * s1, f * s2, t


@njit(cache=True)
def _so3_log_into(R: np.ndarray, out: np.ndarray) -> None:
    """:func:`so3_log` written into ``out``."""
    n = R.shape[0]
    for k in range(n):
        # R[k, :3, :3], not R[k]: the block has the layout ("A") the compiled loop's
        # _se3_log_into gives _rot_log, so one compile of _rot_log serves both
        w0, w1, w2, _ = _rot_log(R[k, :3, :3])
        out[k, 0], out[k, 1], out[k, 2] = w0, w1, w2


def so3_log(R: np.ndarray) -> np.ndarray:
    """(n, 3, 3) → (n, 3)."""
    out = np.empty((R.shape[0], 3))
    _so3_log_into(R, out)
    return out


@njit(cache=True)
def _se3_exp(xi: np.ndarray, g: np.ndarray) -> None:
    g = borrowed(g)  # the caller holds it: its view below counts no references
    w0, w1, w2 = xi[0], xi[1], xi[2]
    r0, r1, r2 = xi[3], xi[4], xi[5]
    t = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    _rot_exp(w0, w1, w2, g[:3, :3])
    b = _b(t)
    c = _c(t)
    x0, x1, x2 = _cross(w0, w1, w2, r0, r1, r2)
    wr = w0 * r0 + w1 * r1 + w2 * r2
    t2 = t * t
    g[0, 3] = r0 + b * x0 + c * (w0 * wr - t2 * r0)
    g[1, 3] = r1 + b * x1 + c * (w1 * wr - t2 * r1)
    g[2, 3] = r2 + b * x2 + c * (w2 * wr - t2 * r2)
    g[3, 0] = g[3, 1] = g[3, 2] = 0.0
    g[3, 3] = 1.0


@njit(cache=True)
def _se3_exp_into(xi: np.ndarray, out: np.ndarray) -> None:
    """:func:`se3_exp` written into ``out``."""
    n = xi.shape[0]
    for k in range(n):
        _se3_exp(xi[k], out[k])


def se3_exp(xi: np.ndarray) -> np.ndarray:
    """(n, 6) → (n, 4, 4)."""
    out = np.empty((xi.shape[0], 4, 4))
    _se3_exp_into(xi, out)
    return out


@njit(cache=True)
def _compose_exp_into(G0: np.ndarray, xi: np.ndarray, out: np.ndarray) -> None:
    """:func:`compose_exp` written into ``out``."""
    G0, xi, out = borrowed(G0), borrowed(xi), borrowed(out)  # the caller holds them
    n = xi.shape[0]
    E = np.empty((4, 4))
    for k in range(n):
        _se3_exp(xi[k], E)
        G = G0[k]
        for i in range(3):
            for j in range(4):
                out[k, i, j] = G[i, 0] * E[0, j] + G[i, 1] * E[1, j] + G[i, 2] * E[2, j]
            out[k, i, 3] += G[i, 3]
        out[k, 3, 0] = out[k, 3, 1] = out[k, 3, 2] = 0.0
        out[k, 3, 3] = 1.0


def compose_exp(G0: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """G0 · exp(ξ^) for (n, 4, 4) and (n, 6) → (n, 4, 4).

    The arrays are passed C-contiguous (copied if not): the kernel then has the compiled
    loop's argument types, and one compile serves both."""
    out = np.empty((xi.shape[0], 4, 4))
    _compose_exp_into(np.ascontiguousarray(G0), np.ascontiguousarray(xi), out)
    return out


@njit(cache=True)
def _se3_log_into(g: np.ndarray, out: np.ndarray) -> None:
    """:func:`se3_log` written into ``out``."""
    n = g.shape[0]
    for k in range(n):
        w0, w1, w2, t = _rot_log(g[k, :3, :3])
        p0, p1, p2 = g[k, 0, 3], g[k, 1, 3], g[k, 2, 3]
        d = _d(t)
        x0, x1, x2 = _cross(w0, w1, w2, p0, p1, p2)
        wp = w0 * p0 + w1 * p1 + w2 * p2
        t2 = t * t
        out[k, 0], out[k, 1], out[k, 2] = w0, w1, w2
        out[k, 3] = p0 - 0.5 * x0 + d * (w0 * wp - t2 * p0)
        out[k, 4] = p1 - 0.5 * x1 + d * (w1 * wp - t2 * p1)
        out[k, 5] = p2 - 0.5 * x2 + d * (w2 * wp - t2 * p2)


def se3_log(g: np.ndarray) -> np.ndarray:
    """(n, 4, 4) → (n, 6)."""
    out = np.empty((g.shape[0], 6))
    _se3_log_into(g, out)
    return out


@njit(cache=True, inline="always")
def _ad_tuple(xi, W):  # type: ignore[no-untyped-def]
    """:func:`_ad_apply` on 6-tuples: ad_ξ W = [θ × ω_W; ρ × ω_W + θ × v_W] (6-tuple)."""
    a0, a1, a2 = _cross(xi[0], xi[1], xi[2], W[0], W[1], W[2])
    b0, b1, b2 = _cross(xi[3], xi[4], xi[5], W[0], W[1], W[2])
    c0, c1, c2 = _cross(xi[0], xi[1], xi[2], W[3], W[4], W[5])
    return a0, a1, a2, b0 + c0, b1 + c1, b2 + c2


@njit(cache=True, inline="always")
def _ad_apply(xi: np.ndarray, W: np.ndarray, out: np.ndarray) -> None:
    """out = ad_ξ W = [θ × ω_W; ρ × ω_W + θ × v_W] (:func:`_ad_tuple`)."""
    r = _ad_tuple((xi[0], xi[1], xi[2], xi[3], xi[4], xi[5]), (W[0], W[1], W[2], W[3], W[4], W[5]))
    out[0], out[1], out[2], out[3], out[4], out[5] = r


@njit(cache=True)
def _dexp_inv_apply_into(xi: np.ndarray, V: np.ndarray, out: np.ndarray) -> None:
    """:func:`dexp_inv_apply` written into ``out``."""
    xi, V, out = borrowed(xi), borrowed(V), borrowed(out)  # the caller holds them
    n = xi.shape[0]
    for k in range(n):
        x = (xi[k, 0], xi[k, 1], xi[k, 2], xi[k, 3], xi[k, 4], xi[k, 5])
        t = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        f1, f2 = _f1_f2(t)
        w1 = _ad_tuple(x, (V[k, 0], V[k, 1], V[k, 2], V[k, 3], V[k, 4], V[k, 5]))
        w2 = _ad_tuple(x, w1)
        w4 = _ad_tuple(x, _ad_tuple(x, w2))
        for i in range(6):
            out[k, i] = V[k, i] + 0.5 * w1[i] + f1 * w2[i] + f2 * w4[i]


def dexp_inv_apply(xi: np.ndarray, V: np.ndarray) -> np.ndarray:
    """ξ̇ = (I + ½ad + F₁ad² + F₂ad⁴) V, row by row: (n, 6), (n, 6) → (n, 6) (Eq. 20)."""
    out = np.empty((xi.shape[0], 6))
    _dexp_inv_apply_into(xi, V, out)
    return out


@njit(cache=True)
def _hat3(v0: float, v1: float, v2: float, M: np.ndarray) -> None:
    M[0, 0] = M[1, 1] = M[2, 2] = 0.0
    M[0, 1], M[0, 2] = -v2, v1
    M[1, 0], M[1, 2] = v2, -v0
    M[2, 0], M[2, 1] = -v1, v0


@njit(cache=True)
def dexp_inv_matrix(xi: np.ndarray) -> np.ndarray:
    """(n, 6) → (n, 6, 6): [[X, 0], [Y, X]] with X = I + ½T + D T², Y = ½P + F₁Y₂ + F₂Y₄."""
    n = xi.shape[0]
    out = np.zeros((n, 6, 6))
    T = np.empty((3, 3))
    P = np.empty((3, 3))
    for k in range(n):
        x = xi[k]
        t = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        f1, f2 = _f1_f2(t)
        d = _d(t)
        _hat3(x[0], x[1], x[2], T)
        _hat3(x[3], x[4], x[5], P)
        T2 = T @ T
        Y2 = P @ T + T @ P
        Y4 = Y2 @ T2 + T2 @ Y2
        X = np.eye(3) + 0.5 * T + d * T2
        Y = 0.5 * P + f1 * Y2 + f2 * Y4
        out[k, :3, :3] = X
        out[k, 3:, 3:] = X
        out[k, 3:, :3] = Y
    return out


@njit(cache=True)
def dexp_matrix(xi: np.ndarray) -> np.ndarray:
    """(n, 6) → (n, 6, 6): [[Jᵣ, 0], [−Jᵣ Y Jᵣ, Jᵣ]] with Jᵣ = I − B T + C T²."""
    n = xi.shape[0]
    inv = dexp_inv_matrix(xi)
    out = np.zeros((n, 6, 6))
    T = np.empty((3, 3))
    for k in range(n):
        x = xi[k]
        t = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        _hat3(x[0], x[1], x[2], T)
        Jr = np.eye(3) - _b(t) * T + _c(t) * (T @ T)
        out[k, :3, :3] = Jr
        out[k, 3:, 3:] = Jr
        Y = np.ascontiguousarray(inv[k, 3:, :3])
        out[k, 3:, :3] = -(Jr @ Y) @ Jr
    return out


@njit(cache=True)
def rotation_errors(R: np.ndarray) -> tuple[float, float, int]:
    """Worst ‖RᵀR − I‖_max and |det R − 1| over (n, 3, 3), and the index of the worst."""
    worst_o = worst_d = -1.0
    idx = 0
    for k in range(R.shape[0]):
        M = R[k]
        eo = 0.0
        for i in range(3):
            for j in range(3):
                s = M[0, i] * M[0, j] + M[1, i] * M[1, j] + M[2, i] * M[2, j]
                e = abs(s - (1.0 if i == j else 0.0))
                eo = max(eo, e if e == e else np.inf)  # NaN (inf − inf) is no match
        det = (
            M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
            - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
            + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0])
        )
        ed = abs(det - 1.0)
        if ed != ed:
            ed = np.inf
        if eo + ed > worst_o + worst_d or k == 0:
            worst_o, worst_d, idx = eo, ed, k
    return worst_o, worst_d, idx


@njit(cache=True)
def se3_errors(g: np.ndarray) -> tuple[float, float, float, int, int]:
    """Over (n, 4, 4): worst last-row error and its index, worst ‖RᵀR − I‖_max and
    |det R − 1| of the rotation blocks, and the index of the worst rotation block."""
    worst_row = 0.0
    k_row = 0
    for k in range(g.shape[0]):
        e = max(abs(g[k, 3, 0]), abs(g[k, 3, 1]), abs(g[k, 3, 2]), abs(g[k, 3, 3] - 1.0))
        if e != e:
            e = np.inf
        if e > worst_row:
            worst_row, k_row = e, k
    # a C-contiguous copy of the blocks: rotation_errors then has the argument types that
    # gmuk._validation.check_rotation gives it, and compiles once (explicit loops, not
    # np.ascontiguousarray, whose own compile costs what the second one saved)
    R = np.empty((g.shape[0], 3, 3))
    for k in range(g.shape[0]):
        for i in range(3):
            for j in range(3):
                R[k, i, j] = g[k, i, j]
    orth, det, k_rot = rotation_errors(R)
    return worst_row, orth, det, k_rot, k_row


@njit(cache=True)
def _se3_inverse_into(g: np.ndarray, out: np.ndarray) -> None:
    """:func:`se3_inverse` written into ``out``."""
    for k in range(g.shape[0]):
        for i in range(3):
            for j in range(3):
                out[k, i, j] = g[k, j, i]
            out[k, i, 3] = -(
                g[k, 0, i] * g[k, 0, 3] + g[k, 1, i] * g[k, 1, 3] + g[k, 2, i] * g[k, 2, 3]
            )
        out[k, 3, 3] = 1.0


def se3_inverse(g: np.ndarray) -> np.ndarray:
    """(n, 4, 4) → (n, 4, 4): [[Rᵀ, −Rᵀ r], [0, 1]]."""
    out = np.zeros((g.shape[0], 4, 4))
    _se3_inverse_into(g, out)
    return out


@njit(cache=True)
def _se3_Ad_into(g: np.ndarray, out: np.ndarray) -> None:
    """:func:`se3_Ad` written into ``out``."""
    for k in range(g.shape[0]):
        r0, r1, r2 = g[k, 0, 3], g[k, 1, 3], g[k, 2, 3]
        for j in range(3):
            c0, c1, c2 = g[k, 0, j], g[k, 1, j], g[k, 2, j]
            out[k, 0, j] = out[k, 3, 3 + j] = c0
            out[k, 1, j] = out[k, 4, 3 + j] = c1
            out[k, 2, j] = out[k, 5, 3 + j] = c2
            out[k, 3, j] = r1 * c2 - r2 * c1
            out[k, 4, j] = r2 * c0 - r0 * c2
            out[k, 5, j] = r0 * c1 - r1 * c0


def se3_Ad(g: np.ndarray) -> np.ndarray:
    """(n, 4, 4) → (n, 6, 6): [[R, 0], [r^× R, R]] (McCann 2020, Eq. 16)."""
    out = np.zeros((g.shape[0], 6, 6))
    _se3_Ad_into(g, out)
    return out
