"""Compiled kernels of :mod:`gmuk.gravity` (numba, cached on disk).

The formulation is described in the package docstring; this module holds the numerics only.

Field data
----------
Everything one field needs at evaluation time lives in one read-only float64 vector, built
once by :func:`field_data` (one array argument keeps the numba dispatch cost of a
single-point call low). With ``N`` the degree and ``M = N + 2`` (the Hessian needs solid
harmonics two degrees higher), its sections, in order, are

======== ================= ===========================================================
section  length            content
======== ================= ===========================================================
header   ``HEADER``        ``[N, μ, R, 0, ...]``
C, S     ``L(N)`` each     ``C[n, m]``, ``S[n, m]``, packed column by column (``m``
                           outer, ``n = m..N`` inner)
A, B     ``L(M)`` each     recursion coefficients ``a_nm``, ``b_nm`` of the normalised
                           column recursion, packed as above for degree ``M``; the
                           entry ``n = m`` of ``A`` holds the sectoral factor ``k_m``
f, F     ``M + 2`` each    ``f_n = √((2n+1)/(2n+3))`` and ``F_n = f_n f_{n+1}``
h, G     ``2M + 8`` each   ``h_k = √k`` and ``G_k = √(k(k+1))``
w⁰,w⁺,w⁻ ``L(N)`` each     weights of the gradient sums, packed as C (only up to
         (none above       degree ``WEIGHTED``): ``w⁰_nm = f_n h_{n+m+1} h_{n-m+1}``,
         ``WEIGHTED``)     ``w⁺_nm = f_n G_{n+m+1}``, ``w⁻_nm = f_n G_{n-m+1}``
======== ================= ===========================================================

with ``L(N) = (N+1)(N+2)/2``.

Indices inside the loops are unsigned (``uint64``) so that no negative-index wraparound
test is compiled into them: numba adds one for signed indices, a branch on every access
that slows these loops substantially and prevents vectorisation.

The gradient weights are products of f, h and G entries, stored so that the gradient
sums, the bulk of an acceleration, do four multiplications fewer per term (computed in
the order the sums multiply the factors otherwise; the accelerations checked did not
change by a bit). Above
degree ``WEIGHTED`` they are left out and the sums multiply the factors themselves: the
three extra vectors would more than double the memory a call streams through, and at
degree 660 that cost more time than the multiplications it saves.

Workspace
---------
:func:`_point` evaluates one point in a workspace of ``(W + 2) K + 10`` floats, ``W``
being one more than the highest degree of solid harmonic needed: ``K`` solid-harmonic
columns of ``W`` values each, the ``K`` column seeds σ (real parts, then imaginary parts)
and ten results (U, ∇U, and the upper triangle of the Hessian, row by row). Two layouts
(:func:`layout`), with the same arithmetic in the same order (their results are equal bit
for bit, as the tests check):

* flat, for ``W ≤`` :data:`FLAT_WIDTH` (degree ≤ 61 whatever the request): ``K = W``, column
  j in slot j; every column is made first (at m = 0), then every sum. The recursion and
  the sums then run as two separate tight loops, which is faster at low degree than
  making each column when the sums reach it (figures in ``benchmarks/README.md``,
  Gravity);
* a ring above that: ``K = 8``, column j in slot ``j mod 8``, each column made when the
  sums first need it, so that the workspace stays small at high degree.

:func:`evaluate` loops over points with one workspace; the ``*_at`` kernels are the
single-point entries used by the public single-point calls. Workspaces of up to
:data:`STACK_FLOATS` floats (any flat one; a ring up to degree 523) live on the stack of
the calling kernel, larger ones on the heap: allocating and releasing a heap workspace on
every call would cost about as much as a whole low-degree series.

Calling without numba's dispatcher
----------------------------------
Numba's dispatcher resolves argument types on every call, which costs more than
evaluating a low-degree field. :func:`entry` returns the compiled function of a
single-signature kernel, which skips that resolution (:data:`ENTRIES` compiles each on
first use, so that a process without spherical harmonics never compiles them); it does
not check the arguments
beyond their Python type, so callers must pass exactly the declared types (float64, the
declared number of dimensions, C-contiguous except the single-point position, which may
have any strides). :mod:`gmuk.gravity.field` does.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import carray, types, uint64
from numba.core import cgutils
from numba.extending import intrinsic

from gmuk._numba import LazyEntries, entry, njit  # entry re-exported for callers
from gmuk._validation import FloatArray

__all__ = [
    "ENTRIES",
    "FLAT_WIDTH",
    "HEADER",
    "NOT_ONE_POINT",
    "STACK_FLOATS",
    "WEIGHTED",
    "acceleration_at",
    "acceleration_hessian_at",
    "entry",
    "evaluate",
    "field_data",
    "layout",
    "offsets",
    "potential_at",
    "workspace_size",
]

#: Length of the header of the field data vector.
HEADER = 8

#: Highest degree whose data vector holds the gradient weights (see the module docstring).
WEIGHTED = 100

#: Mantissa range of the extended-exponent ("X-number") arithmetic: values are kept as
#: mantissa · BIG^e with the mantissa renormalised into [BIG⁻¹, BIG) when it leaves it.
BIG = 2.0**480
BIGI = 2.0**-480
SQRT2 = math.sqrt(2.0)
ISQRT2 = 1.0 / math.sqrt(2.0)

#: Status codes returned by :func:`evaluate` (``code + 4 · index of the point``).
OK = 0
BAD_INPUT = 1
AT_ORIGIN = 2
BAD_OUTPUT = 3

#: Reassociation lets LLVM vectorise the sums (their order changes, their accuracy does
#: not: every term is of one sign-indefinite magnitude and the totals are compared with
#: independent references to 1e-15 in the tests); "contract" allows fused multiply-adds.
_SUMS = {"contract", "reassoc"}

_RO = types.Array(types.float64, 1, "C", readonly=True)
_RW = types.Array(types.float64, 1, "C")
#: A single position: any float64 vector, contiguous or not (it is only read).
_RA = types.Array(types.float64, 1, "A", readonly=True)
_RW2 = types.Array(types.float64, 2, "C")

_U1 = np.uint64(1)
_U2 = np.uint64(2)


@njit(cache=True, inline="always")
def _tri(n: int) -> int:
    """Number of entries (n+1)(n+2)/2 of a lower triangle of degree n."""
    return (n + 1) * (n + 2) // 2


@njit(cache=True, inline="always")
def _col(m: int, n: int) -> int:
    """Offset of column m in a column-packed lower triangle of degree n."""
    return m * (n + 1) - m * (m - 1) // 2


def offsets(N: int) -> tuple[int, int, int, int, int, int, int, int, int]:
    """Section offsets (C, S, A, B, f, F, h, G) and total length of a degree-N data vector.

    Up to degree ``WEIGHTED`` the gradient weights follow G: ``w⁰`` at ``oG + 2M + 8``,
    then ``w⁺`` and ``w⁻``.
    """
    M = N + 2
    L = (N + 1) * (N + 2) // 2
    LM = (M + 1) * (M + 2) // 2
    nh = 2 * M + 8
    oC = HEADER
    oS = oC + L
    oA = oS + L
    oB = oA + LM
    of = oB + LM
    oF = of + M + 2
    oh = oF + M + 2
    oG = oh + nh
    return oC, oS, oA, oB, of, oF, oh, oG, oG + nh + (3 * L if N <= WEIGHTED else 0)


def field_data(mu: float, radius: float, C: FloatArray, S: FloatArray) -> FloatArray:
    """Build the read-only data vector of a field (see the module docstring).

    Parameters
    ----------
    mu : float
        GM (m³/s²).
    radius : float
        Reference radius R (m).
    C, S : ndarray, shape (N+1, N+1)
        Fully normalised (4π) coefficients, lower triangular.

    Returns
    -------
    ndarray, shape (n_data,)
        Read-only.
    """
    N = C.shape[0] - 1
    M = N + 2
    oC, oS, oA, oB, of, oF, oh, oG, size = offsets(N)
    d = np.zeros(size)
    d[0], d[1], d[2] = N, mu, radius
    rows, cols = np.tril_indices(N + 1)
    order = np.lexsort((rows, cols))  # column by column, n increasing within a column
    d[oC:oS] = C[rows[order], cols[order]]
    d[oS:oA] = S[rows[order], cols[order]]
    # Recursion coefficients of the normalised column recursion (Holmes & Featherstone
    # 2002, Eqs. 11-12), for degree M; ratios of small integers, no factorials.
    rows, cols = np.tril_indices(M + 1)
    order = np.lexsort((rows, cols))
    n = rows[order].astype(float)
    m = cols[order].astype(float)
    a = np.empty_like(n)
    b = np.zeros_like(n)
    diag = n == m
    sub = ~diag
    a[sub] = np.sqrt((2 * n[sub] - 1) * (2 * n[sub] + 1) / ((n[sub] - m[sub]) * (n[sub] + m[sub])))
    far = n >= m + 2
    b[far] = np.sqrt(
        (2 * n[far] + 1)
        * (n[far] + m[far] - 1)
        * (n[far] - m[far] - 1)
        / ((n[far] - m[far]) * (n[far] + m[far]) * (2 * n[far] - 3))
    )
    md = m[diag]
    sectoral = np.sqrt((2 * md + 1) / (2 * np.maximum(md, 1.0)))  # k_m, m >= 2
    sectoral[md == 1] = math.sqrt(3.0)
    sectoral[md == 0] = 1.0
    a[diag] = sectoral
    d[oA:oB] = a
    d[oB:of] = b
    k = np.arange(M + 2, dtype=float)
    f = np.sqrt((2 * k + 1) / (2 * k + 3))
    d[of:oF] = f
    d[oF : oF + M + 1] = f[:-1] * f[1:]
    k = np.arange(oG - oh, dtype=float)
    h = np.sqrt(k)
    G = np.sqrt(k * (k + 1))
    d[oh:oG] = h
    oW = oG + len(k)
    d[oG:oW] = G
    if N <= WEIGHTED:
        _gradient_weights(d, N, oW, f, h, G)
    d = _numba_owned(d)
    d.setflags(write=False)
    return d


@njit(cache=True)
def _numba_owned(a):  # type: ignore[no-untyped-def]
    """A copy of ``a`` allocated by numba.

    numba passes such an array to a compiled function as is; for any other array it
    allocates a wrapper on every call and frees it afterwards, a cost every single-point
    call would pay, the data vector being an argument of each.
    """
    return a.copy()


def _gradient_weights(
    d: FloatArray, N: int, oW: int, f: FloatArray, h: FloatArray, G: FloatArray
) -> None:
    """Write w⁰, w⁺, w⁻ into ``d`` from ``oW`` on (packed as C, multiplied in the order
    :func:`_gradient_sums` multiplies the factors)."""
    L = (N + 1) * (N + 2) // 2
    rows, cols = np.tril_indices(N + 1)
    order = np.lexsort((rows, cols))
    n_ = rows[order]
    m_ = cols[order]
    fn = f[n_]
    d[oW : oW + L] = fn * h[n_ + m_ + 1] * h[n_ - m_ + 1]
    d[oW + L : oW + 2 * L] = fn * G[n_ + m_ + 1]
    d[oW + 2 * L : oW + 3 * L] = fn * G[n_ - m_ + 1]


@njit(cache=True)
def _rescale(Q, base, count):  # type: ignore[no-untyped-def]
    """``Q[base : base + count] *= BIG⁻¹``: the rare overflow branch of :func:`_q_column`.

    A function of its own so that the loop of :func:`_q_column` stays short (inline, LLVM
    hoisted this loop's bounds into every step of the recursion).
    """
    for i in range(count):
        Q[base + uint64(i)] *= BIGI


@njit(cache=True, fastmath={"contract"})
def _q_column(d, oa, ob, j, M, rhou, rho2, Q, qo):  # type: ignore[no-untyped-def]
    """Real part q_n, n = j..M, of solid-harmonic column j, with q_j = 1.

    ``Φ̄_nj = σ_j q_n`` where σ_j is the column's complex seed. Values are scaled by
    BIG⁻¹ whenever one exceeds BIG (rare: high degree near the poles); the number of
    scalings is returned so that the caller can fold BIG^e into σ_j.
    """
    e = 0
    base_a = uint64(oa)
    base_b = uint64(ob)
    base_q = uint64(qo + j)
    Q[base_q] = 1.0
    p1 = 1.0
    p2 = 0.0
    for i in range(1, M - j + 1):
        k = uint64(i)
        c = (d[base_a + k] * rhou) * p1 - (d[base_b + k] * rho2) * p2
        Q[base_q + k] = c
        p2 = p1
        p1 = c
        if abs(c) > BIG:
            _rescale(Q, base_q, i + 1)
            p1 *= BIGI
            p2 *= BIGI
            e += 1
    return e


@njit(cache=True, fastmath=_SUMS)
def _potential_sums(d, oc, os_, Q, q0, L):  # type: ignore[no-untyped-def]
    """Σ C q and Σ S q along one column (potential)."""
    uc = 0.0
    us = 0.0
    bc = uint64(oc)
    bs = uint64(os_)
    b0 = uint64(q0)
    for i in range(L):
        k = uint64(i)
        q = Q[b0 + k]
        uc += d[bc + k] * q
        us += d[bs + k] * q
    return uc, us


@njit(cache=True, fastmath=_SUMS)
def _gradient_sums(d, oc, os_, of, oha, ohb, oga, ogb, Q, q0, qp, qm, L):  # type: ignore[no-untyped-def]
    """Weighted sums of one coefficient column against solid-harmonic columns m, m±1."""
    zc = 0.0
    zs = 0.0
    pc = 0.0
    ps = 0.0
    mc = 0.0
    ms = 0.0
    bc = uint64(oc)
    bs = uint64(os_)
    bf = uint64(of)
    bha = uint64(oha)
    bhb = uint64(ohb)
    bga = uint64(oga)
    bgb = uint64(ogb)
    b0 = uint64(q0)
    bp = uint64(qp)
    bm = uint64(qm)
    for i in range(L):
        k = uint64(i)
        c = d[bc + k]
        s = d[bs + k]
        fn = d[bf + k]
        t = fn * d[bha + k] * d[bhb + k] * Q[b0 + k]
        zc += t * c
        zs += t * s
        t = fn * d[bga + k] * Q[bp + k]
        pc += t * c
        ps += t * s
        t = fn * d[bgb + k] * Q[bm + k]
        mc += t * c
        ms += t * s
    return zc, zs, pc, ps, mc, ms


@njit(cache=True, fastmath=_SUMS)
def _weighted_gradient_sums(d, oc, os_, ow0, owp, owm, Q, q0, qp, qm, L):  # type: ignore[no-untyped-def]
    """Sums of one coefficient column against solid-harmonic columns m, m±1, weighted by
    w⁰, w⁺, w⁻ (see the module docstring)."""
    zc = 0.0
    zs = 0.0
    pc = 0.0
    ps = 0.0
    mc = 0.0
    ms = 0.0
    bc = uint64(oc)
    bs = uint64(os_)
    b0w = uint64(ow0)
    bpw = uint64(owp)
    bmw = uint64(owm)
    b0 = uint64(q0)
    bp = uint64(qp)
    bm = uint64(qm)
    for i in range(L):
        k = uint64(i)
        c = d[bc + k]
        s = d[bs + k]
        t = d[b0w + k] * Q[b0 + k]
        zc += t * c
        zs += t * s
        t = d[bpw + k] * Q[bp + k]
        pc += t * c
        ps += t * s
        t = d[bmw + k] * Q[bm + k]
        mc += t * c
        ms += t * s
    return zc, zs, pc, ps, mc, ms


@njit(cache=True, fastmath=_SUMS)
def _hessian_sums(d, oc, os_, oF, oha, ohb, oga, ogb, Q, q0, qp, qpp, qm, qmm, L):  # type: ignore[no-untyped-def]
    """Weighted sums of one coefficient column against solid-harmonic columns m, m±1, m±2."""
    xc = 0.0
    xs = 0.0
    yc = 0.0
    ys = 0.0
    zc = 0.0
    zs = 0.0
    uc = 0.0
    us = 0.0
    vc = 0.0
    vs = 0.0
    bc = uint64(oc)
    bs = uint64(os_)
    bF = uint64(oF)
    bha = uint64(oha)
    bhb = uint64(ohb)
    bga = uint64(oga)
    bgb = uint64(ogb)
    b0 = uint64(q0)
    bp = uint64(qp)
    bpp = uint64(qpp)
    bm = uint64(qm)
    bmm = uint64(qmm)
    for i in range(L):
        k = uint64(i)
        w = d[bF + k]
        c = d[bc + k] * w
        s = d[bs + k] * w
        ab = d[bha + k] * d[bhb + k]
        ga1 = d[bga + k]
        gb1 = d[bgb + k]
        t = ga1 * d[bga + k + _U2] * Q[bpp + k]
        xc += t * c
        xs += t * s
        t = ab * d[bga + k + _U1] * Q[bp + k]
        yc += t * c
        ys += t * s
        t = ga1 * gb1 * Q[b0 + k]
        zc += t * c
        zs += t * s
        t = ab * d[bgb + k + _U1] * Q[bm + k]
        uc += t * c
        us += t * s
        t = gb1 * d[bgb + k + _U2] * Q[bmm + k]
        vc += t * c
        vs += t * s
    return xc, xs, yc, ys, zc, zs, uc, us, vc, vs


def _point_body(d, x, y, z, mode, Q, flat):  # type: ignore[no-untyped-def]
    """Values at one body-fixed point (x, y, z) (m), left in the workspace ``Q``.

    ``mode`` as in :func:`evaluate`; ``flat`` and the length of ``Q`` as given by
    :func:`layout` (a ring's seed section, ``Q[8W : 8W + 16]``, zeroed). On success (status
    0) the last ten floats of the workspace are U, ∇U and (H_xx, H_xy, H_xz, H_yy, H_yz,
    H_zz), those requested by ``mode``. Otherwise the status: 1 non-finite input, 2 the
    origin, 3 a non-finite result.
    """
    N = int(d[0])
    mu = d[1]
    R = d[2]
    want_u = (mode & 1) != 0
    want_a = (mode & 2) != 0
    want_h = (mode & 4) != 0
    skip0 = (mode & 8) != 0
    lead = 2 if want_h else (1 if want_a else 0)
    M = N + 2
    Mc = N + lead  # highest degree of solid harmonic needed
    L = _tri(N)
    LM = _tri(M)
    oC = HEADER
    oS = oC + L
    oA = oS + L
    oB = oA + LM
    of = oB + LM
    oF = of + M + 2
    oh = oF + M + 2
    oG = oh + 2 * M + 8
    oW = oG + 2 * M + 8  # gradient weights w⁰, w⁺, w⁻ (up to degree WEIGHTED)
    W = Mc + 1
    K = W if flat else 8  # column slots
    mask = -1 if flat else 7  # column j lives in slot j & mask
    WK = K * W  # the seeds σ follow the columns: K real parts, then K imaginary parts
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        return BAD_INPUT
    rn = math.sqrt(x * x + y * y + z * z)
    if rn == 0.0:
        return AT_ORIGIN
    rho = R / rn
    s = x / rn
    t = y / rn
    rhou = rho * z / rn
    rho2 = rho * rho
    # seed σ_j of solid-harmonic column j: mantissa (sr, si) times BIG^se
    sr = rho
    si = 0.0
    se = 0
    zero_from = Mc + 1  # columns from here on are identically zero (x = y = 0)
    done = -1
    pot = 0.0
    gpr = 0.0
    gpi = 0.0
    gmr = 0.0
    gmi = 0.0
    gz = 0.0
    hppr = 0.0
    hppi = 0.0
    hmmr = 0.0
    hmmi = 0.0
    hzz = 0.0
    hpzr = 0.0
    hpzi = 0.0
    hmzr = 0.0
    hmzi = 0.0
    for m in range(N + 1):
        if m - lead >= zero_from:
            break
        # flat layout: every column at m = 0, then every sum; ring: solid-harmonic columns
        # m - 2 .. m + lead must be available
        while done < (Mc if flat else m + lead):
            j = done + 1
            slot = j & mask
            qo = slot * W
            if j > 0 and j < zero_from:
                kj = d[oA + _col(j, M)]
                fr = kj * rho * s
                fi = kj * rho * t
                nr = fr * sr - fi * si
                si = fr * si + fi * sr
                sr = nr
                mag = max(abs(sr), abs(si))
                if mag == 0.0:
                    zero_from = j
                else:
                    while mag < BIGI:
                        sr *= BIG
                        si *= BIG
                        mag *= BIG
                        se -= 1
                    while se < 0 and mag >= 1.0:
                        sr *= BIGI
                        si *= BIGI
                        mag *= BIGI
                        se += 1
            if j < zero_from:
                oa = oA + _col(j, M)
                ob = oB + _col(j, M)
                e = se + _q_column(d, oa, ob, j, Mc, rhou, rho2, Q, qo)
                er = sr
                ei = si
                while e > 0:
                    er *= BIG
                    ei *= BIG
                    e -= 1
                while e < 0:
                    er *= BIGI
                    ei *= BIGI
                    e += 1
                Q[WK + slot] = er
                Q[WK + K + slot] = ei
            else:
                for k in range(j, Mc + 1):
                    Q[qo + k] = 0.0
                Q[WK + slot] = 0.0
                Q[WK + K + slot] = 0.0
            done = j
        n0 = 1 if (skip0 and m == 0) else m
        Lm = N + 1 - n0
        if Lm <= 0:
            continue
        cofs = _col(m, N) + n0 - m
        q0 = (m & mask) * W
        qp = ((m + 1) & mask) * W
        qm = ((m - 1) & mask) * W if m >= 1 else qp
        s0r = Q[WK + (m & mask)]
        s0i = Q[WK + K + (m & mask)]
        spr = Q[WK + ((m + 1) & mask)]
        spi = Q[WK + K + ((m + 1) & mask)]
        if want_u:
            uc, us = _potential_sums(d, oC + cofs, oS + cofs, Q, q0 + n0, Lm)
            pot += uc * s0r + us * s0i
        if want_a:
            k1 = n0 + 1
            if flat or N <= WEIGHTED:
                zc, zs, pc, ps, mc, ms = _weighted_gradient_sums(
                    d, oC + cofs, oS + cofs, oW + cofs, oW + L + cofs, oW + 2 * L + cofs,
                    Q, q0 + k1, qp + k1, qm + k1, Lm,
                )  # fmt: skip
            else:
                zc, zs, pc, ps, mc, ms = _gradient_sums(
                    d, oC + cofs, oS + cofs, of + n0,
                    oh + n0 + m + 1, oh + n0 - m + 1, oG + n0 + m + 1, oG + n0 - m + 1,
                    Q, q0 + k1, qp + k1, qm + k1, Lm,
                )  # fmt: skip
            gz += zc * s0r + zs * s0i
            if m == 0:
                pc *= ISQRT2
                gpr += pc * spr
                gpi += pc * spi
                gmr -= pc * spr
                gmi += pc * spi
            else:
                gpr += pc * spr + ps * spi
                gpi += pc * spi - ps * spr
                if m == 1:
                    mc *= SQRT2
                    ms *= SQRT2
                smr = Q[WK + ((m - 1) & mask)]
                smi = Q[WK + K + ((m - 1) & mask)]
                gmr += mc * smr + ms * smi
                gmi += mc * smi - ms * smr
        if want_h:
            k2 = n0 + 2
            qpp = ((m + 2) & mask) * W
            qmm = ((m - 2) & mask) * W if m >= 2 else qp
            xc, xs, yc, ys, zc, zs, uc, us, vc, vs = _hessian_sums(
                d, oC + cofs, oS + cofs, oF + n0,
                oh + n0 + m + 1, oh + n0 - m + 1, oG + n0 + m + 1, oG + n0 - m + 1,
                Q, q0 + k2, qp + k2, qpp + k2, qm + k2, qmm + k2, Lm,
            )  # fmt: skip
            sppr = Q[WK + ((m + 2) & mask)]
            sppi = Q[WK + K + ((m + 2) & mask)]
            hzz += zc * s0r + zs * s0i
            if m == 0:
                # S[n, 0] = 0; the lowering operator acts on the conjugate
                xc *= ISQRT2
                yc *= ISQRT2
                hppr += xc * sppr
                hppi += xc * sppi
                hpzr += yc * spr
                hpzi += yc * spi
                hmzr += yc * spr
                hmzi -= yc * spi
                hmmr += xc * sppr
                hmmi -= xc * sppi
            else:
                hppr += xc * sppr + xs * sppi
                hppi += xc * sppi - xs * sppr
                hpzr += yc * spr + ys * spi
                hpzi += yc * spi - ys * spr
                smr = Q[WK + ((m - 1) & mask)]
                smi = Q[WK + K + ((m - 1) & mask)]
                if m == 1:
                    uc *= SQRT2
                    us *= SQRT2
                    # lowering twice from order 1 lands on the conjugate of order 1
                    hmmr -= zc * s0r - zs * s0i
                    hmmi += zc * s0i + zs * s0r
                else:
                    if m == 2:
                        vc *= SQRT2
                        vs *= SQRT2
                    smmr = Q[WK + ((m - 2) & mask)]
                    smmi = Q[WK + K + ((m - 2) & mask)]
                    hmmr += vc * smmr + vs * smmi
                    hmmi += vc * smmi - vs * smmr
                hmzr -= uc * smr + us * smi
                hmzi -= uc * smi - us * smr
    o = WK + 2 * K
    if want_u:
        u = (mu / R) * pot
        if not math.isfinite(u):
            return BAD_OUTPUT
        Q[o] = u
    if want_a:
        k_ = 0.5 * mu / (R * R)
        ax = k_ * (gmr - gpr)
        ay = -k_ * (gpi + gmi)
        az = -2.0 * k_ * gz
        if not (math.isfinite(ax) and math.isfinite(ay) and math.isfinite(az)):
            return BAD_OUTPUT
        Q[o + 1] = ax
        Q[o + 2] = ay
        Q[o + 3] = az
    if want_h:
        k_ = mu / (R * R * R)
        hxx = 0.25 * k_ * (hppr + hmmr - 2.0 * hzz)
        hyy = -0.25 * k_ * (hppr + hmmr + 2.0 * hzz)
        hxy = 0.25 * k_ * (hppi - hmmi)
        hxz = 0.5 * k_ * (hpzr + hmzr)
        hyz = 0.5 * k_ * (hpzi - hmzi)
        hz = k_ * hzz
        if not (
            math.isfinite(hxx) and math.isfinite(hyy) and math.isfinite(hz)
            and math.isfinite(hxy) and math.isfinite(hxz) and math.isfinite(hyz)
        ):  # fmt: skip
            return BAD_OUTPUT
        Q[o + 4] = hxx
        Q[o + 5] = hxy
        Q[o + 6] = hxz
        Q[o + 7] = hyy
        Q[o + 8] = hyz
        Q[o + 9] = hz
    return OK


#: :func:`_point_body` compiled on its own: the batch kernel and the potential entry call it
#: with the mode and the layout known only at run time, the acceleration entries for a
#: ring (degree 62 and up, where the series dominates the cost of a call) ...
_point = njit(cache=True)(_point_body)
#: ... and inlined into the acceleration entries for the flat layout, each of which fixes
#: every mode bit but the central-term one: LLVM then drops the ring, the potential and the
#: unused derivative code. The smaller machine code makes a call from Python faster (such a
#: call starts with cold caches and branch history), although a compiled loop barely shows
#: the difference. The ring is not inlined: that lengthens the first import's compilation
#: for no measurable speed (figures in benchmarks/README.md, Gravity).
_point_inline = njit(cache=True, inline="always")(_point_body)


#: Widest workspace laid out flat (see the module docstring): ``W = N + lead + 1`` up to
#: this (degree 63 for the potential, 62 for the acceleration, 61 with the Hessian).
FLAT_WIDTH = 64


@njit(cache=True, inline="always")
def layout(N: int, mode: int) -> tuple[bool, int]:
    """Layout of the workspace of :func:`_point` for degree N and ``mode``: whether it is
    flat (else a ring of eight columns), and its length (floats)."""
    lead = 2 if (mode & 4) != 0 else (1 if (mode & 2) != 0 else 0)
    W = N + lead + 1
    flat = W <= FLAT_WIDTH
    K = W if flat else 8
    return flat, (W + 2) * K + 10


@njit(cache=True, inline="always")
def workspace_size(N: int, mode: int) -> int:
    """Length of the workspace of :func:`_point` for degree N and ``mode`` (floats)."""
    return layout(N, mode)[1]


#: Largest workspace taken on the stack (floats; 34 kB): the widest flat one, or a ring up
#: to degree 523 with the Hessian.
STACK_FLOATS = (FLAT_WIDTH + 2) * FLAT_WIDTH + 10


@intrinsic
def _stack_floats(typingctx):  # type: ignore[no-untyped-def]
    """Pointer to STACK_FLOATS float64 reserved on the stack of the calling function.

    The space belongs to the compiled function this call ends up in (it is allocated in
    that function's entry block, once, however often the call executes), so only
    ``inline="always"`` helpers may use it on their caller's behalf, and nothing made from
    it may outlive that function's call.
    """

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        return cgutils.alloca_once(builder, ir.DoubleType(), size=STACK_FLOATS)

    return types.CPointer(types.float64)(), codegen


@njit(cache=True, inline="always")
def _workspace(N, mode):  # type: ignore[no-untyped-def]
    """A workspace for :func:`_point`, the offset of its results and whether it is flat.

    On the stack of the kernel this is inlined into when it is small enough (see
    :data:`STACK_FLOATS`), on the heap otherwise. Either way every call has a workspace
    of its own (a stack frame is per call and per thread), so concurrent or nested calls
    cannot share one. The seeds and results of a ring are zeroed (a flat layout has every
    seed written by :func:`_point`).
    """
    flat, size = layout(N, mode)
    if size <= STACK_FLOATS:
        Q = carray(_stack_floats(), size)
    else:
        Q = np.empty(size)
    if not flat:
        Q[size - 26 :] = 0.0
    return Q, size - 10, flat


# One explicit signature each (ENTRIES below): positions typed read-only accept writable
# arrays as well, so a read-only input never triggers a second compilation. Compiled (or
# loaded from numba's on-disk cache) on first use, not on import.
@njit(cache=True)
def evaluate(d, r, out, hess, mode):  # type: ignore[no-untyped-def]
    """Potential, gradient and/or Hessian of a field at points (see the package docstring).

    Parameters
    ----------
    d : ndarray, shape (n_data,)
        Field data from :func:`field_data`.
    r : ndarray, shape (3k,)
        Body-fixed positions (m), point after point.
    out : ndarray, shape (k · stride,)
        Written per point, in order: U (1, if bit 1 of ``mode``) and ∇U (3, bit 2);
        ``stride`` is the number of values requested (may be empty if neither is).
    hess : ndarray, shape (3k, 3)
        The Hessian of point i in rows 3i..3i+2 (bit 4; may be empty otherwise).
    mode : int
        Bits: 1 potential, 2 gradient, 4 Hessian, 8 leave out the central term C00 μ/r.

    Returns
    -------
    int
        0, or ``code + 4 i`` for the first failing point i: code 1 non-finite input,
        2 point at the origin, 3 non-finite result.
    """
    want_u = (mode & 1) != 0
    want_a = (mode & 2) != 0
    want_h = (mode & 4) != 0
    stride = (1 if want_u else 0) + (3 if want_a else 0)
    Q, o, flat = _workspace(int(d[0]), mode)
    for ip in range(r.shape[0] // 3):
        code = _point(d, r[3 * ip], r[3 * ip + 1], r[3 * ip + 2], mode, Q, flat)
        if code:
            return code + 4 * ip
        k = ip * stride
        if want_u:
            out[k] = Q[o]
            k += 1
        if want_a:
            out[k] = Q[o + 1]
            out[k + 1] = Q[o + 2]
            out[k + 2] = Q[o + 3]
        if want_h:
            h0 = 3 * ip
            hess[h0, 0] = Q[o + 4]
            hess[h0, 1] = Q[o + 5]
            hess[h0, 2] = Q[o + 6]
            hess[h0 + 1, 0] = Q[o + 5]
            hess[h0 + 1, 1] = Q[o + 7]
            hess[h0 + 1, 2] = Q[o + 8]
            hess[h0 + 2, 0] = Q[o + 6]
            hess[h0 + 2, 1] = Q[o + 8]
            hess[h0 + 2, 2] = Q[o + 9]
    return OK


#: Status of a single-point entry given a position of another length than 3 (the caller
#: then takes the general path, which raises the ShapeError).
NOT_ONE_POINT = -1

# Single-point entries. Each takes the field data, the body-fixed position ``r`` (m; any
# float64 vector, strided or read-only: it is only read), arrays to write the results
# into, and ``central`` (include the central term C00 mu/r or not), and returns the status
# code of :func:`evaluate` for one point, or NOT_ONE_POINT; the outputs are left
# unwritten on failure. Callers must pass float64 vectors (the compiled entries do not
# check dtypes; see gmuk._numba.entry).
#
# The two acceleration entries repeat their five lines of workspace and dispatch on
# purpose: each needs its own inlined copy of the per-point code with its own constant
# mode. Moving those lines into an inline="always" helper (inlining within inlining) makes
# the first import's compilation much longer (benchmarks/README.md, Gravity).


@njit(cache=True)
def acceleration_at(d, r, out, central):  # type: ignore[no-untyped-def]
    """∇U (m/s²) at the point ``r`` (m), written into ``out`` (3,)."""
    if r.shape[0] != 3:
        return NOT_ONE_POINT
    mode = 2 if central else 10
    Q, o, flat = _workspace(int(d[0]), mode)
    if flat:  # inlined, request and layout fixed
        code = _point_inline(d, r[0], r[1], r[2], mode, Q, True)
    else:  # degree 62 and up: the series dominates the call
        code = _point(d, r[0], r[1], r[2], mode, Q, False)
    if code == OK:
        out[0] = Q[o + 1]
        out[1] = Q[o + 2]
        out[2] = Q[o + 3]
    return code


@njit(cache=True)
def acceleration_hessian_at(d, r, out, hess, central):  # type: ignore[no-untyped-def]
    """∇U (m/s²) into ``out`` (3,) and ∇∇U (1/s²) into ``hess`` (3, 3), in one pass."""
    if r.shape[0] != 3:
        return NOT_ONE_POINT
    mode = 6 if central else 14
    Q, o, flat = _workspace(int(d[0]), mode)
    if flat:  # inlined, request and layout fixed
        code = _point_inline(d, r[0], r[1], r[2], mode, Q, True)
    else:  # degree 62 and up: the series dominates the call
        code = _point(d, r[0], r[1], r[2], mode, Q, False)
    if code == OK:
        out[0] = Q[o + 1]
        out[1] = Q[o + 2]
        out[2] = Q[o + 3]
        hess[0, 0] = Q[o + 4]
        hess[0, 1] = Q[o + 5]
        hess[0, 2] = Q[o + 6]
        hess[1, 0] = Q[o + 5]
        hess[1, 1] = Q[o + 7]
        hess[1, 2] = Q[o + 8]
        hess[2, 0] = Q[o + 6]
        hess[2, 1] = Q[o + 8]
        hess[2, 2] = Q[o + 9]
    return code


@njit(cache=True)
def potential_at(d, r, out, central):  # type: ignore[no-untyped-def]
    """U (m²/s²) at the point ``r`` (m), written to ``out[0]``."""
    if r.shape[0] != 3:
        return NOT_ONE_POINT
    mode = np.int64(1) if central else np.int64(9)
    Q, o, flat = _workspace(int(d[0]), mode)
    code = _point(d, r[0], r[1], r[2], mode, Q, flat)
    if code == OK:
        out[0] = Q[o]
    return code


#: The compiled entries of the kernels above (see :class:`gmuk._numba.LazyEntries`).
ENTRIES = LazyEntries(
    evaluate=(evaluate, types.int64(_RO, _RO, _RW, _RW2, types.int64)),
    acceleration_at=(acceleration_at, types.int64(_RO, _RA, _RW, types.boolean)),
    potential_at=(potential_at, types.int64(_RO, _RA, _RW, types.boolean)),
    acceleration_hessian_at=(
        acceleration_hessian_at,
        types.int64(_RO, _RA, _RW, _RW2, types.boolean),
    ),
)
