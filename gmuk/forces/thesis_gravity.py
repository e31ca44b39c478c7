"""McCann (2020)'s rigid-body gravity in a non-uniform field, Eqs. 42 and 59, as printed.

**This is an approximation kept for reproducing the thesis's Chapter 3, not a gravity
model.** Use :class:`~gmuk.forces.gravity.SphericalHarmonicGravity` for physics. See
:class:`ThesisRadialHarmonicGravity` for what is printed, what gmuk reads into it, and how
far it is from a brute-force point-cloud quadrature of the real field.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.special import gammaln

from gmuk._forms import Forms
from gmuk._validation import FloatArray
from gmuk.errors import DefinitionError, DomainError
from gmuk.forces.base import ForceModel
from gmuk.forces.gravity import gravity_gradient_wrench, point_mass_load
from gmuk.gravity.legendre import legendre_4pi

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody

__all__ = ["THESIS_NORMALIZATIONS", "ThesisRadialHarmonicGravity"]

# arguments of the point-mass kernel that a point mass does not have
_NO_INERTIA = np.zeros((3, 3))
_NO_FIELD = np.zeros(1)
_NO_FIELD.setflags(write=False)

#: Choices of P̄_np for :class:`ThesisRadialHarmonicGravity` (see its docstring).
THESIS_NORMALIZATIONS = ("thesis_eq26c_intended", "thesis_eq26c", "4pi")


def _normalization_scale(degree: int, normalization: str) -> FloatArray:
    """Ratio of the chosen P̄_np to the 4π P̄_np, shape (degree+1, degree+1), lower triangle.

    ``inf`` where the printed Eq. 26c factor exceeds the range of doubles.
    """
    n, p = np.tril_indices(degree + 1)
    scale = np.zeros((degree + 1, degree + 1))
    two_minus_delta = np.where(p == 0, 1.0, 2.0)
    if normalization == "4pi":
        scale[n, p] = 1.0
    elif normalization == "thesis_eq26c_intended":
        # √((n+½) r) / √((2−δ)(2n+1) r) = 1/√(2(2−δ)): 1/√2 for p = 0, 1/2 for p > 0
        scale[n, p] = 1.0 / np.sqrt(2.0 * two_minus_delta)
    else:  # "thesis_eq26c": √(n + ½ r) as printed, r = (n−p)!/(n+p)!
        log_ratio = gammaln(n - p + 1.0) - gammaln(n + p + 1.0)
        log_printed = 0.5 * np.log(n + 0.5 * np.exp(log_ratio))
        log_4pi = 0.5 * (np.log(two_minus_delta) + np.log(2.0 * n + 1.0) + log_ratio)
        with np.errstate(over="ignore"):
            scale[n, p] = np.exp(log_printed - log_4pi)
    return scale


class ThesisRadialHarmonicGravity(ForceModel):
    """McCann (2020)'s Eq. 42 force and Eq. 59 torque, as printed: **an approximation kept
    for reproducing Chapter 3 of the thesis, wrong as physics**.

    Use :class:`~gmuk.forces.gravity.SphericalHarmonicGravity` for a correct spherical-harmonic
    field on a rigid body. This class exists so that the thesis's Chapter 3 runs can be
    reproduced and compared with the correct model.

    With the body-frame position ``r = r_B = R_NBᵀ r_N`` (m), ``ρ = R_M/|r|``, J the central
    inertia in the body frame (kg m²), m the mass (kg), and the per-degree angular sums
    frozen at the centre-of-mass direction (latitude θ, longitude φ of ``r_F = R_FN(t) r_N``),

    ``T_n = Σ_{p=0}^{n} P̄_np(sin θ) (C̄_np cos pφ + S̄_np sin pφ)``,

    the wrench in the body frame is

    * Eq. 42: ``f = −μm/|r|³ (r + 3/(m|r|²) [J + ½(tr J − 5 r̂ᵀJr̂) I] r)
      + Σ_{n=1}^{N} μm (n+1) ρⁿ T_n / |r|³ · {r + (n+3)/(m|r|²) (J + (n+2)/4 [tr J −
      (n+5) r̂ᵀJr̂] I) r}`` (N),
    * Eq. 59: ``L = μ/|r|⁵ [3 − Σ_{n=1}^{N} (n+1)(n+3) ρⁿ T_n] r × J r`` (N m).

    A point mass gets ``m a_N`` with ``a`` the printed Eq. 25,
    ``a = −μ r/|r|³ [1 − Σ_{n≥1} (n+1) ρⁿ T_n]`` (what Eq. 42 gives for J = 0).

    Parameters
    ----------
    central_body : CelestialBody
        With a ``field`` (a :class:`~gmuk.gravity.SphericalHarmonicField`: μ, R_M, C̄, S̄)
        and its rotation model R_FN(t).
    degree : int, optional
        Highest degree N of the sums (default: the field's own). ``degree=0`` leaves the
        first term only, which is exactly Eq. 23 (:class:`~gmuk.forces.gravity.GravityGradient`).
    normalization : {"thesis_eq26c_intended", "thesis_eq26c", "4pi"}
        The P̄_np paired with the file's coefficients C̄, S̄ (which are 4π-normalised):

        * ``"thesis_eq26c_intended"`` (default): Eq. 26c with its parentheses restored,
          ``√((n + ½)(n−p)!/(n+p)!) P_np``, the functions normalised on [−1, 1] of the
          handbook Eq. 26 cites (Abramowitz & Stegun). Relative to the 4π functions that
          go with the coefficients this is 1/√2 (p = 0) and 1/2 (p > 0): every harmonic
          is under-weighted. It is the reading that reproduces the thesis's Figure 3.1
          ("almost four kilometers" of position change in one orbit; see Notes).
        * ``"thesis_eq26c"``: literally as printed, ``√(n + ½ (n−p)!/(n+p)!) P_np`` (the
          same factor as :func:`gmuk.gravity.thesis_eq26c_normalization`). Its ratio to the
          4π factor is 7.6e8 at (10, 10) and 8.7e306 at (150, 150): past degree ~4 the
          "perturbation" dwarfs the central term and an orbit leaves the Moon within one
          revolution (measured in Notes). Evaluation raises :class:`~gmuk.errors.DomainError`
          where the sums overflow.
        * ``"4pi"``: the coefficients' own normalisation; isolates the errors of Eqs. 42
          and 59 themselves (sign, radial-only, frozen angles) from those of Eq. 26c.
    bodies : sequence, optional
    modeled : bool

    Notes
    -----
    *Implemented as printed*, with these readings of the print:

    * Eqs. 33/52 (and so 42/59) are written with inertial ``r``; they equal Eq. 23 only
      with ``r_B = Rᵀ r`` in the body frame (or with ``R J Rᵀ``). gmuk evaluates them in the
      body frame (the errata, "Eqs. 23a/23b").
    * ``C̄₀₀`` is taken as 1 (the first term of Eq. 42 has none); the sums start at n = 1.
    * Eq. 42's bracket, ``(n+2)/4 [tr J − (n+5) rᵀJr/|r|²]``, is kept as printed. It is
      *not* what Eq. 40 combines to, which is ``(n+2)/4 tr J − (n+5)/2 rᵀJr/|r|²``
      (the two agree only for n = 0); the difference is a finite-size term, far below the
      other errors (``tests/forces/test_thesis_harmonic_gravity.py`` measures it).

    What is wrong with it (errata, "Eq. 25", "Eq. 26c", "Eqs. 42 and 59"):

    * Eq. 27 differentiates the potential radially only and flips the sign of the harmonic
      sum (the radial derivative is ``−μ r/r³ [1 + Σ (n+1) ρⁿ T_n]``), so even at the
      centre of mass the force misses the tangential part of the perturbation and has the
      radial part with the wrong sign;
    * the angular factor is taken out of the integral over the body (frozen at the centre
      of mass), so the torque contains only the radial-radial curvature of each degree;
    * with ``"thesis_eq26c"`` or ``"thesis_eq26c_intended"``, P̄ does not match the
      coefficients.

    Measured error (``test_error_against_quadrature`` in
    ``tests/forces/test_thesis_harmonic_gravity.py``): Apollo LM, GRGM660PRIM truncated
    to degree N, 120 random positions 50–500 km above the Moon with random attitudes,
    against brute-force point-cloud quadrature of the correct (4π) field. Median (5–95 %)
    of ``|error| / |harmonic part of the truth|``:

    ==========================  =======================  =======================
    normalisation, degree N     force (Eq. 42)           torque (Eq. 59)
    ==========================  =======================  =======================
    ``"4pi"``, 2                1.59 (1.00–1.97)         1.41 (0.95–1.94)
    ``"4pi"``, 10               1.57 (1.02–1.96)         1.31 (0.96–1.96)
    ``"4pi"``, 50 and 150       1.51 (1.01–1.95)         1.33 (0.98–1.85)
    default, 2                  1.40 (1.00–1.66)         1.27 (0.95–1.72)
    default, 10                 1.35 (1.01–1.65)         1.18 (0.94–1.65)
    default, 50 and 150         1.34 (1.01–1.63)         1.18 (0.98–1.56)
    ==========================  =======================  =======================

    A ratio of 1 is what leaving the harmonics out altogether (Eq. 23) gives: Eqs. 42 and
    59 are worse than that for most positions. With ``"4pi"`` the force error lies between
    1 and 2 times the perturbation at every sample (it is ``a_t + 2 a_r``, exactly, at the
    centre of mass).

    One orbit (``test_one_orbit_position_change``; a point mass from the §3.4 initial
    state, ``max |Δr|`` against the central field alone over one period): the default gives
    4.28, 4.80, 4.18, 4.19 km at degrees 2, 10, 50, 150, the nearest to the thesis's
    "almost four kilometers" (Figure 3.1; its degrees are not stated); ``"4pi"`` gives
    6.06, 7.07, 5.86, 5.88 km, ``"thesis_eq26c"`` 4.34 km at degree 2 and 5.7e5 km at
    degree 10, and the correct field
    (:class:`~gmuk.forces.gravity.SphericalHarmonicGravity`) 8.44, 8.09, 7.20, 7.24 km. To
    reproduce the thesis's figures use the default; to isolate the errors of Eqs. 42/59
    from those of Eq. 26c use ``"4pi"``; :doc:`/theory/chapter3` has the derivations.

    References
    ----------
    McCann (2020), Eqs. (23), (25)–(28), (33), (40)–(42), (52), (58)–(59), (60)–(62).
    """

    mass_proportional = True  # gravity: force ∝ m, torque ∝ J

    _forms = Forms(
        compiled="kept in Python: a printed approximation for reproducing Chapter 3, called "
        "back from the compiled loop",
        symbolic="kept in Python: a printed approximation, not for optimisation",
    )

    def __init__(
        self,
        central_body: Any,
        degree: int | None = None,
        *,
        normalization: str = "thesis_eq26c_intended",
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        field: Any = getattr(central_body, "field", None)
        problems = []
        if field is None or not all(hasattr(field, a) for a in ("C", "S", "truncate")):
            problems.append(
                "ThesisRadialHarmonicGravity needs a CelestialBody with a spherical-harmonic "
                "field (C̄, S̄ coefficients); load one with gmuk.gravity.load_gfc(...) and "
                "pass CelestialBody.moon(field=...)"
            )
        if normalization not in THESIS_NORMALIZATIONS:
            problems.append(
                f"normalization must be one of {THESIS_NORMALIZATIONS}; got {normalization!r}"
            )
        if problems:
            raise DefinitionError(problems)
        self.central_body = central_body
        self.field = field if degree is None else field.truncate(degree)
        self.normalization = normalization
        N = int(self.field.degree)
        self.degree = N
        self.mu = float(self.field.mu)
        self.radius = float(self.field.radius)
        scale = _normalization_scale(N, normalization)
        C = np.asarray(self.field.C, dtype=np.float64)[: N + 1, : N + 1]
        S = np.asarray(self.field.S, dtype=np.float64)[: N + 1, : N + 1]
        with np.errstate(over="ignore", invalid="ignore"):  # 0 × inf is a zero coefficient
            self._C = np.where(C == 0.0, 0.0, C * scale)
            self._S = np.where(S == 0.0, 0.0, S * scale)
        self._p = np.arange(N + 1, dtype=float)
        self._n = np.arange(N + 1, dtype=float)

    def degree_terms(self, r_F: FloatArray) -> FloatArray:
        """``T_n`` for n = 0..N at the body-fixed position ``r_F`` (m), shape (N+1,).

        With the chosen normalisation; ``T_n = Σ_p P̄_np(sin θ)(C̄_np cos pφ + S̄_np sin pφ)``
        (dimensionless).

        Raises
        ------
        DomainError
            At the origin, or if the sums overflow (printed Eq. 26c at high degree).
        """
        r = np.asarray(r_F, dtype=float)
        rn = float(np.sqrt(r @ r))
        if rn == 0.0:
            raise DomainError("r_F must not be the origin (latitude and longitude undefined)")
        P = legendre_4pi(self.degree, min(1.0, max(-1.0, float(r[2]) / rn)))
        lon = float(np.arctan2(r[1], r[0]))
        pl = self._p * lon
        with np.errstate(over="ignore", invalid="ignore"):
            T = np.sum(P * (self._C * np.cos(pl) + self._S * np.sin(pl)), axis=1)
        if not np.all(np.isfinite(T)):
            raise DomainError(
                f"the degree sums of Eqs. 42/59 are not finite at r_F = {r.tolist()} with "
                f"normalization={self.normalization!r} to degree {self.degree} (the printed "
                "Eq. 26c factor outgrows the range of doubles); use a lower degree or "
                "normalization='thesis_eq26c_intended' or '4pi'"
            )
        return np.asarray(T)

    def _radial_terms(
        self, t: float, r_N: FloatArray
    ) -> tuple[FloatArray, float, float, FloatArray]:
        """(n, μ/|r|³, |r|², (n+1) ρⁿ T_n for n ≥ 1) at r_N (m)."""
        R_FN = self.central_body.rotation.R_FN(t)
        T = self.degree_terms(R_FN @ r_N)
        r2 = float(r_N @ r_N)
        rn = float(np.sqrt(r2))
        n = self._n[1:]
        rho_n = (self.radius / rn) ** n
        return n, self.mu / (r2 * rn), r2, (n + 1.0) * rho_n * T[1:]

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """The printed Eq. 25 force ``m a`` on a point mass, in N (N): the point-mass force
        (:func:`~gmuk.forces.gravity.point_mass_load`) times ``1 − Σ (n+1) ρⁿ T_n``."""
        r = np.asarray(r_N, dtype=float)
        _, _, _, c = self._radial_terms(t, r)
        g = np.eye(4)
        g[:3, 3] = r
        central = np.empty(3)
        point_mass_load(
            False, float(t), g, np.zeros(6), float(body.mass), _NO_INERTIA,
            np.array([self.mu]), _NO_FIELD, central,
        )  # fmt: skip
        return (1.0 - float(np.sum(c))) * central

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L; f] in the body frame (N·m, N) by Eqs. 59 and 42: their central parts are Eq. 23
        (:func:`~gmuk.forces.gravity.gravity_gradient_wrench`, GravityGradient's kernel), to
        which the harmonic sums add."""
        m = body.mass
        g = np.array(g_NB, dtype=float)
        r_N = g[:3, 3].copy()
        n, mu_r3, r2, c = self._radial_terms(t, r_N)  # c = (n+1) ρⁿ T_n, n ≥ 1
        J = np.array(body.inertia, dtype=float)
        # Eq. 33 (= Eq. 23b in the body frame) and Eq. 52 (= Eq. 23a)
        eq23 = np.empty(6)
        gravity_gradient_wrench(g, self.mu, float(m), J, eq23)
        r_B = g[:3, :3].T @ r_N
        Jr = J @ r_B
        trJ = float(np.trace(J))
        q = float(r_B @ Jr) / r2  # r̂ᵀ J r̂
        # Eq. 42, second line: Σ μ m (n+1) ρⁿ T_n / |r|³ {r + (n+3)/(m r²)(J + (n+2)/4 [..] I) r}
        k = (n + 3.0) / (m * r2)
        scalar = float(np.sum(c * (1.0 + k * (n + 2.0) / 4.0 * (trJ - (n + 5.0) * q))))
        f = eq23[3:] + (mu_r3 * m) * (scalar * r_B + float(np.sum(c * k)) * Jr)
        # Eq. 59: Eq. 23a's torque 3μ/|r|⁵ r × J r times the printed bracket [3 − Σ ...]/3
        bracket = 3.0 - float(np.sum(c * (n + 3.0)))
        return np.concatenate([eq23[:3] * (bracket / 3.0), f])
