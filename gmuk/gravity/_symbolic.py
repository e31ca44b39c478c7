"""The symbolic (CasADi) form of a :class:`~gmuk.gravity.SphericalHarmonicField`.

:mod:`gmuk.optimize` needs the field as a CasADi expression of a symbolic position, so that
CasADi can differentiate it exactly. This module writes the acceleration ∇U with the
recurrences of the compiled kernel (:mod:`gmuk.gravity._kernels`; the formulation is in the
package docstring, :mod:`gmuk.gravity`), reading every number it needs — degree, μ, R, the
4π-normalised C̄ and S̄, the column-recursion coefficients a_nm and b_nm, the sectoral
factors k_m and the square-root tables f, h, G — from the field's own data vector
(:func:`~gmuk.gravity._kernels.field_data`). The constants are therefore the kernel's, bit for
bit; only the order of some products differs (each gradient weight is multiplied into its
coefficient once, as a constant, instead of into the solid harmonic at every evaluation), so
the symbolic and the compiled accelerations agree to round-off (1e-15 relative, measured in
``tests/forces/test_harmonic_symbolic.py``):

* seeds ``σ_0 = ρ``, ``σ_j = k_j ρ (x + i y)/r · σ_{j−1}`` (ρ = R/r), complex, j ≤ N + 1;
* columns ``q_jj = 1``, ``q_nj = a_nj ρ (z/r) q_{n−1,j} − b_nj ρ² q_{n−2,j}``, n ≤ N + 1;
* the ladder sums of the gradient, per order m, against the columns m and m ± 1 one degree
  higher, weighted by ``w⁰ = f_n √((n+m+1)(n−m+1))``, ``w⁺ = f_n √((n+m+1)(n+m+2))``,
  ``w⁻ = f_n √((n−m+1)(n−m+2))`` (times 1/√2 for m = 0 raising, √2 for m = 1 lowering),
  combined with the seeds as in :func:`~gmuk.gravity._kernels._point_body`;
* ``a_x = μ/(2R²) (g⁻_r − g⁺_r)``, ``a_y = −μ/(2R²) (g⁺_i + g⁻_i)``, ``a_z = −μ/R² g_z``.

The Hessian ∇∇U and the third derivatives that rigid-body gravity needs are CasADi's exact
derivatives of this acceleration (:func:`rigid_function`).

Each expression is built once per field and request, as a CasADi ``Function`` of an SX
position (kept in a small cache keyed by the field's data): called with SX it expands into
the caller's expression, with MX it is one call node, with numbers (DM, NumPy) it evaluates.
The graph is compact: about 25 operations per coefficient pair (n, m) — a Function of 5 821
instructions at degree 20, 33 278 at 50, 287 302 at 150 — terms whose coefficient is exactly
zero left out;
building it takes 0.03 s at degree 20 and 0.4 s at degree 150 (once per field). The figures
of :mod:`gmuk.optimize` with it are in ``docs/optimize_lunar.rst``.

Range. The symbolic form evaluates in plain double precision: it does not carry the
extended exponents the kernel uses against underflow and overflow at high degree near the
poles (Fukushima 2012), which a smooth expression for an NLP cannot branch into. Where the
seeds underflow (high order, near a pole) their terms are negligible: the tests compare it
with the kernel to 1e-12 up to the shipped degrees (150 for the Moon, 70 for the Earth),
poles included, and synthetic fields with Kaula-like random coefficients agreed to 1e-12 at
degrees 300 and 600 from the reference sphere outwards, poles included, when this was
written.
"""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict
from typing import Any

import numpy as np

from gmuk._casadi import casadi
from gmuk.gravity import _kernels

__all__ = ["acceleration", "acceleration_function", "rigid_function"]

#: Functions kept (built expressions of recently used fields; the least recently used goes).
CACHE_SIZE = 8

_CACHE: OrderedDict[tuple[str, bytes], Any] = OrderedDict()

_SQRT2 = math.sqrt(2.0)
_ISQRT2 = 1.0 / math.sqrt(2.0)


def _key(field: Any, kind: str) -> tuple[str, bytes]:
    """The cache key of a field's function: the request and a digest of its data vector (which
    holds everything the field evaluates with)."""
    data = np.ascontiguousarray(field._data)
    return kind, hashlib.blake2b(data.tobytes(), digest_size=20).digest()


def _cached(field: Any, kind: str, build: Any) -> Any:
    key = _key(field, kind)
    fn = _CACHE.get(key)
    if fn is None:
        fn = build()
        _CACHE[key] = fn
        while len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
    else:
        _CACHE.move_to_end(key)
    return fn


def _acceleration_expression(data: Any, r: Any, central: bool) -> Any:
    """∇U (3×1, m/s², frame F) at the CasADi position ``r`` (3×1, m) of the field whose data
    vector (:func:`~gmuk.gravity._kernels.field_data`) is ``data``; ``central=False`` leaves
    out the central term C̄₀₀ μ/r."""
    ca = casadi()
    d = np.asarray(data, dtype=float)
    N = int(d[0])
    mu, R = float(d[1]), float(d[2])
    M = N + 2  # the degree of the recursion tables
    Mc = N + 1  # the gradient needs solid harmonics one degree higher
    oC, oS, oA, oB, of, _oF, oh, oG, _ = _kernels.offsets(N)
    f, h, G = d[of:], d[oh:], d[oG:]

    def col(m: int, n: int) -> int:  # as _kernels._col
        return m * (n + 1) - m * (m - 1) // 2

    x, y, z = r[0], r[1], r[2]
    rn = ca.sqrt(x * x + y * y + z * z)
    rho = R / rn
    rho_s = rho * (x / rn)
    rho_t = rho * (y / rn)
    rhou = rho * z / rn
    rho2 = rho * rho

    # seeds σ_j (real, imaginary), j = 0 … N + 1
    seeds: list[tuple[Any, Any]] = [(rho, 0.0)]
    for j in range(1, Mc + 1):
        kj = float(d[oA + col(j, M)])
        fr, fi = kj * rho_s, kj * rho_t
        sr, si = seeds[-1]
        seeds.append((fr * sr - fi * si, fr * si + fi * sr))

    # columns, all orders j at once, degree after degree: Q[j, n] = q_nj (0 for j > n), with
    # q_nn = 1 and q_nj = (a_nj ρu) q_{n−1,j} − (b_nj ρ²) q_{n−2,j}, as _kernels._q_column
    rows: list[Any] = [ca.SX.ones(1, 1)]
    for n in range(1, Mc + 1):
        js = np.arange(n)
        a_at = oA + (js * (M + 1) - js * (js - 1) // 2) + n - js  # a_nj, j = 0 … n − 1
        c = (ca.DM(d[a_at]) * rhou) * rows[n - 1]
        if n >= 2:  # b_nj = 0 for j = n − 1
            k2 = js[:-1]
            b_at = oB + (k2 * (M + 1) - k2 * (k2 - 1) // 2) + n - k2
            c = c - ca.vertcat((ca.DM(d[b_at]) * rho2) * rows[n - 2], 0.0)
        rows.append(ca.vertcat(c, 1.0))
    Q = ca.horzcat(*[ca.vertcat(v, ca.SX(Mc - n, 1)) for n, v in enumerate(rows)])

    def dot(weights: Any, m: int, first: int) -> Any:
        """Σ_n wₙ q_{n+1, m} over n = first … N, the weights' exact zeros left out."""
        w = ca.sparsify(ca.DM(np.asarray(weights, dtype=float)))
        if w.nnz() == 0:
            return 0.0
        return ca.mtimes(Q[m, first + 1 : N + 2], w)

    gz: Any = 0.0
    gpr: Any = 0.0
    gpi: Any = 0.0
    gmr: Any = 0.0
    gmi: Any = 0.0
    for m in range(N + 1):
        n0 = 1 if (not central and m == 0) else m
        if n0 > N:
            continue
        ns = np.arange(n0, N + 1)
        at = oC + col(m, N) + ns - m
        Cm, Sm = d[at], d[at - oC + oS]
        w0 = f[ns] * h[ns + m + 1] * h[ns - m + 1]
        wp = f[ns] * G[ns + m + 1] * (_ISQRT2 if m == 0 else 1.0)
        s0r, s0i = seeds[m]
        spr, spi = seeds[m + 1]
        # the sums against q_{n+1, m} (column m), q_{n+1, m+1} and q_{n+1, m−1}
        zc, zs = dot(w0 * Cm, m, n0), dot(w0 * Sm, m, n0)
        pc = dot(wp * Cm, m + 1, n0)
        gz = gz + (zc * s0r + zs * s0i)
        if m == 0:  # S̄_n0 = 0; the lowering operator acts on the conjugate
            gpr = gpr + pc * spr
            gpi = gpi + pc * spi
            gmr = gmr - pc * spr
            gmi = gmi + pc * spi
            continue
        wm = f[ns] * G[ns - m + 1] * (_SQRT2 if m == 1 else 1.0)
        ps = dot(wp * Sm, m + 1, n0)
        mc, ms = dot(wm * Cm, m - 1, n0), dot(wm * Sm, m - 1, n0)
        smr, smi = seeds[m - 1]
        gpr = gpr + (pc * spr + ps * spi)
        gpi = gpi + (pc * spi - ps * spr)
        gmr = gmr + (mc * smr + ms * smi)
        gmi = gmi + (mc * smi - ms * smr)
    k = 0.5 * mu / (R * R)
    return ca.vertcat(k * (gmr - gpr), -k * (gpi + gmi), (-2.0 * k) * gz)


def acceleration_function(field: Any, *, central: bool = True) -> Any:
    """The CasADi ``Function`` r_F (3×1, m) → ∇U (3×1, m/s²) of ``field`` (SX inside; built
    once and cached).

    Parameters
    ----------
    field : SphericalHarmonicField
    central : bool
        Include the central term C̄₀₀ μ/r (default), or give the perturbation only.
    """
    ca = casadi()

    def build() -> Any:
        r = ca.SX.sym("r_F", 3)
        a = _acceleration_expression(field._data, r, central)
        return ca.Function(f"gravity_deg{field.degree}", [r], [a], ["r_F"], ["a_F"])

    return _cached(field, "a" if central else "a_perturbation", build)


def acceleration(field: Any, r_F: Any, *, central: bool = True) -> Any:
    """∇U (3×1, m/s², frame F) of ``field`` at the body-fixed position ``r_F`` (m): a CasADi
    SX, MX or DM column for an SX, MX or DM (or NumPy) ``r_F`` of 3 entries."""
    ca = casadi()
    if isinstance(r_F, (ca.SX, ca.MX, ca.DM)):
        arg = r_F
    else:
        arg = ca.DM(np.asarray(r_F, dtype=float))
    if arg.numel() != 3:
        from gmuk.errors import ShapeError

        raise ShapeError(f"r_F must have 3 entries (m); got shape {arg.shape}")
    return acceleration_function(field, central=central)(ca.reshape(arg, 3, 1))


def rigid_function(field: Any, *, finite_size: bool) -> Any:
    """The CasADi ``Function`` (r_F (3×1, m), Π_F (3×3, kg·m²)) → (a_F, H_F, s_F) of
    ``field`` for rigid-body gravity, all in F: the acceleration ∇U (m/s²), its Hessian ∇∇U
    (1/s², CasADi's exact derivative, symmetrised) and the second-order finite-size force
    ``s_F = ½ ∇(tr(H Π))`` (N) of a body whose second moment of mass about its centre of mass
    is Π_F (the third derivatives, exact; zero when ``finite_size`` is False).
    """
    ca = casadi()

    def build() -> Any:
        r = ca.SX.sym("r_F", 3)
        Pi = ca.SX.sym("Pi_F", 3, 3)
        a = _acceleration_expression(field._data, r, True)
        H = ca.jacobian(a, r)
        H = 0.5 * (H + H.T)
        s = 0.5 * ca.gradient(ca.dot(H, Pi), r) if finite_size else ca.SX.zeros(3, 1)
        return ca.Function(
            f"rigid_gravity_deg{field.degree}",
            [r, Pi],
            [a, H, s],
            ["r_F", "Pi_F"],
            ["a_F", "H_F", "s_F"],
        )

    return _cached(field, "rigid_finite" if finite_size else "rigid", build)
