"""Spherical-harmonic gravity fields of central bodies (no bodies, no frames beyond F).

Public API
----------
* :class:`SphericalHarmonicField` ``(mu, radius, C, S, *, degree=None, name=...,
  normalization="4pi", reference=...)``: an immutable field with ``.mu`` (m³/s²),
  ``.radius`` (m), ``.degree``, ``.C``, ``.S``, ``.truncate(n)``, and, at body-fixed
  positions ``r_F`` (m, shape (3,) or (k, 3)): ``potential`` (m²/s²), ``acceleration``
  (m/s², (3,) or (k, 3)), ``hessian`` (1/s², (3, 3) or (k, 3, 3)) and ``evaluate`` (any of
  the three in one pass; ``acceleration_hessian`` is the lean call for ∇U and ∇∇U
  together). ``central=False`` gives the perturbation only (every term but
  C̄₀₀), which is what rigid-body force models add to their point-mass part.
  ``casadi_acceleration`` is the acceleration's symbolic (CasADi) form for
  :mod:`gmuk.optimize`: the same recurrences and constants (:mod:`gmuk.gravity._symbolic`).
* :func:`load` ``(name, degree=None)``: a field shipped with gmuk by name,
  ``"GRGM660PRIM"`` (Moon, GRAIL, to degree 150) or ``"EGM2008"`` (Earth, to degree 70);
  :func:`available` lists them (provenance and licence in ``gmuk/gravity/data/README.md``).
* :func:`load_gfc` (ICGEM ``.gfc``) and :func:`load_shadr` (PDS SHADR ``.tab``, GRAIL's
  archive format): readers returning a field in SI units; malformed files raise
  :class:`gmuk.errors.FileFormatError` naming the file, the line and what was expected.
* :func:`moon_low_degree` (GRGM660PRIM through degree 4, typed in and cited),
  :func:`moon_point_mass`, :func:`earth_point_mass`, and the constants :data:`MOON_MU`,
  :data:`MOON_RADIUS` (GRAIL GRGM660PRIM), :data:`EARTH_MU`, :data:`EARTH_RADIUS`
  (EGM2008).
* :func:`legendre_4pi`, :func:`normalization_4pi`: stable fully normalised Legendre
  functions at any degree and the 4π normalisation factor.
* The thesis's printed (wrong) formulas, under names that say so, for reproducing
  McCann (2020) Chapter 3: :func:`thesis_eq25_radial_acceleration`,
  :func:`thesis_eq26c_normalization`, :func:`thesis_eq26c_legendre`,
  :func:`thesis_eq24_degree_terms` (see :mod:`gmuk.gravity.thesis`).

Conventions
-----------
``U(r) = (μ/r) Σ_{n=0}^{N} (R/r)ⁿ Σ_{m=0}^{n} P̄_nm(sin φ) (C̄_nm cos mλ + S̄_nm sin mλ)``,
positive, with acceleration ``a = +∇U`` (so the central term alone gives ``−μ r/r³``);
φ latitude, λ longitude of ``r_F`` in the body-fixed frame F (origin at the centre of
mass, axes those of the model: DE421 principal axes for GRGM660PRIM, ITRF for EGM2008).
The coefficients are fully normalised, 4π or "geodesy" normalisation, without the
Condon–Shortley phase: ``P̄_nm = √[(2 − δ_m0)(2n+1)(n−m)!/(n+m)!] P_nm`` with
``P_nm(t) = (1 − t²)^{m/2} dᵐP_n/dtᵐ`` — the convention of GRAIL and EGM2008 files and of
pyshtools. SI units throughout; readers convert kilometres.

Formulation
-----------
The potential and its derivatives are evaluated in Cartesian coordinates with normalised
solid harmonics (Cunningham 1970; Montenbruck & Gill 2000, §3.2 give the unnormalised
form), in complex notation ``Φ̄_nm = (R/r)^{n+1} P̄_nm(sin φ) e^{imλ}``, so that
``U = (μ/R) Σ Re[(C̄_nm − i S̄_nm) Φ̄_nm]``. Each Φ̄_nm is a complex *seed* times a real
*column* value, ``Φ̄_nm = σ_m q_nm``:

* ``σ_0 = ρ = R/r``, ``σ_m = k_m ρ (x + i y)/r · σ_{m−1}`` with ``k_1 = √3``,
  ``k_m = √((2m+1)/(2m))``;
* ``q_mm = 1``, ``q_nm = a_nm ρ (z/r) q_{n−1,m} − b_nm ρ² q_{n−2,m}`` with the normalised
  column-recursion coefficients ``a_nm = √((2n−1)(2n+1)/((n−m)(n+m)))``,
  ``b_nm = √((2n+1)(n+m−1)(n−m−1)/((n−m)(n+m)(2n−3)))`` (Holmes & Featherstone 2002,
  Eqs. 11–12), precomputed once per field.

Because σ_m is constant along a column, every sum over n is a real dot product, and the
complex seed multiplies it once per column. Derivatives use the ladder operators
``D± = ∂x ± i∂y`` and ``∂z``, which map solid harmonics onto solid harmonics of the next
degree:

* ``∂z Φ̄_nm = −(1/R) f_n √((n+m+1)(n−m+1)) Φ̄_{n+1,m}``,
* ``D₊ Φ̄_nm = −(1/R) f_n √((n+m+1)(n+m+2)) ε_m Φ̄_{n+1,m+1}`` (``ε_0 = 1/√2``, else 1),
* ``D₋ Φ̄_nm = (1/R) f_n √((n−m+1)(n−m+2)) η_m Φ̄_{n+1,m−1}`` (``η_1 = √2``, else 1),
  and ``D₋ Φ̄_n0 = conj(D₊ Φ̄_n0)``,

with ``f_n = √((2n+1)/(2n+3))``; then ``∂x = (D₊ + D₋)/2``, ``∂y = (D₊ − D₋)/(2i)``, and
the Hessian follows from ``D₊²``, ``D₋²``, ``D±∂z``, ``∂z²`` with ``D₊D₋ = −∂z²``
(Laplace). There is no division by cos φ anywhere: the poles are ordinary points, and the
Hessian is exactly symmetric and, to round-off, traceless. The gradient needs solid
harmonics to degree N+1, the Hessian to N+2; one pass over the coefficients serves
potential, gradient and Hessian together. Cost O(N²) per point; memory per point O(N²)
up to degree 61 (every solid-harmonic column at once, at most 34 kB, on the stack) and
O(N) above (a ring of eight columns).

Any degree: the seeds σ_m underflow near the poles and for large m, and the column values
q_nm can overflow there; both are carried as extended-exponent numbers (mantissa ·
2^(480 e), after Fukushima 2012) and folded together only when a column's contribution is
formed, so terms that matter are never lost to underflow. No factorials are formed
anywhere; every coefficient is a square root of a ratio of small integers.

The kernels are compiled with numba (``gmuk.gravity._kernels``; explicit signatures,
cached on disk, see :mod:`gmuk._numba` for where): the first import compiles them, which
takes tens of seconds, and later imports load them from the cache. A field precomputes its
recursion coefficients and square-root tables once, at construction or ``truncate``.

Speed: a single position given as a float64 array of shape (3,) (any strides) takes a
fast path: one compiled call without numba's type dispatch, which reads the position where
it lies and writes into a fresh result array. Everything else (lists, other dtypes,
batches) goes through the batch kernel. Both run the same per-point code (compiled into
each entry, the single-point ones with their request fixed), and the tests check that they
agree bit for bit, across requests too (``acceleration`` and ``acceleration_hessian``).
Rigid-body gravity wants ∇U and ∇∇U at every step: ``acceleration_hessian`` gives both
from one pass, for less than twice the cost of the acceleration alone. Timings beside
pyshtools, measured in the same run, are in ``benchmarks/README.md``
(``python benchmarks/bench_gravity.py``).

Departures from McCann (2020)
-----------------------------
* Eq. 26c's normalisation is wrong by orders of magnitude (errata); gmuk uses the 4π
  normalisation of the coefficient files. The printed form is kept as
  :func:`thesis_eq26c_normalization`.
* Eq. 25 keeps only the radial derivative of Eq. 24 and flips the sign of the harmonic
  sum; its error is 1–2× the whole harmonic perturbation (median 1.5 at 100 km above the
  Moon with GRGM660PRIM). gmuk returns the full gradient. The printed form is kept as
  :func:`thesis_eq25_radial_acceleration` with the measured figures in
  :mod:`gmuk.gravity.thesis`.
* Eqs. 26a–b with factorials overflow beyond degree ~85 (170!); gmuk uses the recursion
  above.

References
----------
Cunningham, L. E. (1970). On the computation of the spherical harmonic terms needed during
the numerical integration of the orbital motion of an artificial satellite. *Celestial
Mechanics* 2, 207–216.
Montenbruck, O. & Gill, E. (2000). *Satellite Orbits*, §3.2. Springer.
Holmes, S. A. & Featherstone, W. E. (2002). A unified approach to the Clenshaw summation
and the recursive computation of very high degree and order normalised associated
Legendre functions. *Journal of Geodesy* 76, 279–299.
Fukushima, T. (2012). Numerical computation of spherical harmonics of arbitrary degree
and order by extending exponent of floating point numbers. *Journal of Geodesy* 86,
271–285.
Lemoine, F. G., et al. (2013). High-degree gravity models from GRAIL primary mission data.
*J. Geophys. Res. Planets* 118, 1676–1698.
McCann (2020), Eqs. (24)–(26); gmuk errata.
"""

from gmuk.gravity.builtin import (
    EARTH_MU,
    EARTH_RADIUS,
    MOON_MU,
    MOON_RADIUS,
    earth_point_mass,
    moon_low_degree,
    moon_point_mass,
)
from gmuk.gravity.catalog import FieldInfo, available, field_path, load
from gmuk.gravity.field import FieldValues, SphericalHarmonicField
from gmuk.gravity.io import load_gfc, load_shadr
from gmuk.gravity.legendre import legendre_4pi, normalization_4pi
from gmuk.gravity.thesis import (
    thesis_eq24_degree_terms,
    thesis_eq25_radial_acceleration,
    thesis_eq26c_legendre,
    thesis_eq26c_normalization,
)

__all__ = [
    "EARTH_MU",
    "EARTH_RADIUS",
    "MOON_MU",
    "MOON_RADIUS",
    "FieldInfo",
    "FieldValues",
    "SphericalHarmonicField",
    "available",
    "earth_point_mass",
    "field_path",
    "legendre_4pi",
    "load",
    "load_gfc",
    "load_shadr",
    "moon_low_degree",
    "moon_point_mass",
    "normalization_4pi",
    "thesis_eq24_degree_terms",
    "thesis_eq25_radial_acceleration",
    "thesis_eq26c_legendre",
    "thesis_eq26c_normalization",
]
