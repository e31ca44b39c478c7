"""Keplerian (two-body) motion on any conic, as an immutable object of time.

:class:`KeplerOrbit` holds the elements ``(p, e, i, Ω, ω)`` and μ; time ``t`` (s) is
counted from periapsis passage (``t = 0`` at periapsis; negative before it). It gives the
true anomaly and its first two rates, and position, velocity and acceleration in the
perifocal frame P and the inertial frame N.

References
----------
McCann (2020), Section 4.1.2 (ḟ, f̈, v̇_{d/P} and Eqs. 75–78; all correct as printed, see
errata). Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed. (2013),
Ch. 2 (Kepler's problem for each conic).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np

from gmuk._validation import FloatArray, as_array, real_number
from gmuk.errors import OrbitError
from gmuk.orbits import _kernels, kepler
from gmuk.orbits.elements import (
    R_NP,
    _check_nu,
    _inclination,
    _positive,
    semi_latus_rectum,
    state_to_elements,
)

__all__ = ["KeplerOrbit"]

Conic = Literal["ellipse", "parabola", "hyperbola"]


def _float(x: Any, name: str) -> float:
    return float(as_array(x, (), name, batch=False))


def one_time(t: Any, who: str) -> float:
    """``t`` (s) as a float: a real number, never a string, bool, None or complex number
    (a :class:`~gmuk.errors.DefinitionError` naming ``who``); NaN and ±inf pass through (an
    integer beyond float64 as ±inf), for the caller to refuse."""
    if type(t) is float:
        return t
    if isinstance(t, np.floating) or (
        isinstance(t, np.ndarray) and t.ndim == 0 and t.dtype.kind == "f"
    ):
        return float(t)
    return real_number(t, f"{who}: t (s)", allow_inf=True)


@dataclass(frozen=True)
class KeplerOrbit:
    """A Keplerian orbit: a conic with its orientation, traversed under ``−μ r / r³``.

    Build it from elements with :meth:`from_elements` (``a`` or ``p``) or from a state with
    :meth:`from_state`; the constructor takes the semi-latus rectum directly. All methods
    are pure functions of ``t`` (s since periapsis passage) and accept arrays of times of
    any shape ``(...)``: outputs have shape ``(...)`` or ``(..., 3)``.

    Parameters
    ----------
    p : float
        Semi-latus rectum ``h²/μ`` (m), > 0.
    e : float
        Eccentricity, ≥ 0 (``< 1`` ellipse, ``= 1`` parabola, ``> 1`` hyperbola).
    i : float
        Inclination (rad), in ``[0, π]``.
    raan : float
        Right ascension of the ascending node Ω (rad).
    argp : float
        Argument of periapsis ω (rad).
    mu : float
        Gravitational parameter of the central body (m³/s²), > 0.

    Raises
    ------
    OrbitError, NonFiniteError
        For invalid or non-finite elements.

    Notes
    -----
    With ``k = √(μ/p³)`` and ``w = 1 + e cos f``:

    * ``r = p / w`` and ``h = √(μ p)``;
    * ``ḟ = h / r² = k w²`` (McCann 2020, ``ḟ = μ²(1 + e cos f)²/h³``);
    * ``f̈ = −2 k² w³ e sin f`` (McCann 2020, ``f̈ = −2μ⁴/h⁶ (1 + e cos f)³ e sin f``);
    * ``r_P = r [cos f, sin f, 0]``, ``v_P = √(μ/p) [−sin f, e + cos f, 0]``,
      ``a_P = −(μ/r²) [cos f, sin f, 0]`` (McCann 2020, ``v̇_{d/P}``).

    The mean anomaly is ``M = n t`` with ``n = √(μ/a³)`` (ellipse, Eqs. 75–76),
    ``M_p = 2√(μ/p³) t`` (parabola, Barker) or ``M_h = √(μ/(−a)³) t`` (hyperbola);
    see :mod:`gmuk.orbits.kepler`. The elliptic true anomaly is continuous in t (not
    wrapped): ``f(t + T) = f(t) + 2π``.

    References
    ----------
    McCann (2020), Section 4.1.2 and Eqs. (75)–(78).
    """

    p: float
    e: float
    i: float
    raan: float
    argp: float
    mu: float

    def __post_init__(self) -> None:
        # Validate and normalise to Python floats (frozen: set through object.__setattr__).
        values = {name: _float(getattr(self, name), name) for name in self.__dataclass_fields__}
        _positive(values["p"], "p", "m")
        _positive(values["mu"], "mu", "m³/s²")
        if values["e"] < 0.0:
            raise OrbitError(f"e must be ≥ 0; got e = {values['e']!r}")
        _inclination(values["i"])
        for name, value in values.items():
            object.__setattr__(self, name, value)

    # ------------------------------------------------------------------ constructors

    @classmethod
    def from_elements(
        cls,
        a: float | None,
        e: float,
        i: float,
        raan: float,
        argp: float,
        mu: float,
        *,
        p: float | None = None,
    ) -> KeplerOrbit:
        """An orbit from classical elements with the size given by ``a`` or by ``p``.

        Parameters
        ----------
        a : float or None
            Semi-major axis (m): > 0 for an ellipse, < 0 for a hyperbola; ``None`` to give
            ``p`` instead (required for a parabola).
        e, i, raan, argp : float
            Eccentricity, inclination, Ω, ω (rad).
        mu : float
            Gravitational parameter (m³/s²).
        p : float, optional, keyword-only
            Semi-latus rectum (m).

        Raises
        ------
        OrbitError
            If ``a``/``p`` are both or neither given or do not fit the conic of ``e``.
        """
        pp, ee = semi_latus_rectum(a, e, p)
        if pp.ndim or ee.ndim:
            raise OrbitError(f"a KeplerOrbit takes scalar elements; got arrays of shape {pp.shape}")
        return cls(float(pp), float(ee), i, raan, argp, mu)

    @classmethod
    def from_state(cls, r_N: Any, v_N: Any, mu: float) -> tuple[KeplerOrbit, float]:
        """The orbit through a position and velocity, and the time of that state.

        Parameters
        ----------
        r_N : array_like, shape (3,)
            Position (m) in N.
        v_N : array_like, shape (3,)
            Velocity (m/s) in N.
        mu : float
            Gravitational parameter (m³/s²).

        Returns
        -------
        orbit : KeplerOrbit
        t : float
            Time since periapsis passage (s) at which ``orbit.state(t) == (r_N, v_N)``; for
            an ellipse the nearest periapsis is used, ``t ∈ [−T/2, T/2)``. For circular or
            equatorial orbits the angles follow the conventions of
            :mod:`gmuk.orbits.elements` (periapsis at the node or at N₁).
        """
        r = as_array(r_N, (3,), "r_N", batch=False)
        v = as_array(v_N, (3,), "v_N", batch=False)
        el = state_to_elements(r, v, mu)
        orbit = cls(float(el.p), float(el.e), float(el.i), float(el.raan), float(el.argp), mu)
        return orbit, float(orbit.time_from_true_anomaly(kepler.wrap_to_pi(el.nu)))

    # ------------------------------------------------------------------ constants

    @property
    def kind(self) -> Conic:
        """``"ellipse"`` (including circles), ``"parabola"`` (e = 1 exactly) or ``"hyperbola"``."""
        if self.e < 1.0:
            return "ellipse"
        return "parabola" if self.e == 1.0 else "hyperbola"

    @property
    def a(self) -> float:
        """Semi-major axis ``p / (1 − e²)`` (m): ``inf`` for a parabola, < 0 for a hyperbola."""
        den = (1.0 - self.e) * (1.0 + self.e)
        return math.inf if den == 0.0 else self.p / den

    @property
    def h(self) -> float:
        """Specific angular momentum ``√(μ p)`` (m²/s)."""
        return math.sqrt(self.mu * self.p)

    @property
    def energy(self) -> float:
        """Specific orbital energy ``−μ(1 − e²)/(2p)`` (J/kg = m²/s²)."""
        return -0.5 * self.mu * (1.0 - self.e) * (1.0 + self.e) / self.p

    @property
    def mean_motion(self) -> float:
        """Rate of the conic's mean anomaly (rad/s or 1/s).

        ``√(μ/a³)`` for an ellipse (McCann 2020, Eq. 75), ``2√(μ/p³)`` for a parabola
        (Barker), ``√(μ/(−a)³)`` for a hyperbola.
        """
        k = math.sqrt(self.mu / self.p**3)
        if self.kind == "parabola":
            return 2.0 * k
        return k * abs((1.0 - self.e) * (1.0 + self.e)) ** 1.5

    @property
    def period(self) -> float:
        """Orbital period ``2π/n`` (s) of an ellipse; ``inf`` for open conics."""
        return 2.0 * math.pi / self.mean_motion if self.kind == "ellipse" else math.inf

    @property
    def periapsis_radius(self) -> float:
        """``p / (1 + e)`` (m)."""
        return self.p / (1.0 + self.e)

    @cached_property
    def R_NP(self) -> FloatArray:
        """Rotation P → N, ``R₃(Ω) R₁(i) R₃(ω)``, shape (3, 3), read-only."""
        R = R_NP(self.raan, self.i, self.argp)
        R.setflags(write=False)
        return R

    # ------------------------------------------------------------------ anomalies

    def true_anomaly(self, t: Any) -> FloatArray:
        """True anomaly f (rad) at times t (s since periapsis), shape of t.

        Elliptic anomalies are continuous in t (not wrapped, ``f(kT) = 2πk``); open conics
        have ``|f| < arccos(−1/e)``.

        References
        ----------
        McCann (2020), Eqs. (75)–(78).
        """
        t = as_array(t, (), "t")
        M = self.mean_motion * t
        if self.kind == "ellipse":
            return kepler.true_from_mean(M, self.e)
        if self.kind == "parabola":
            return kepler.true_from_parabolic(kepler.parabolic_from_mean(M))
        return kepler.true_from_hyperbolic(kepler.hyperbolic_from_mean(M, self.e), self.e)

    def time_from_true_anomaly(self, f: Any) -> FloatArray:
        """Time since periapsis (s) at which the true anomaly is f (rad), shape of f.

        The inverse of :meth:`true_anomaly`: ``t = M(f)/n`` with M on the same revolution
        as f, so for an ellipse ``f ∈ [2πk, 2π(k + 1))`` gives ``t ∈ [kT, (k + 1)T)``.

        Raises
        ------
        OrbitError
            For an open conic, if ``|f| ≥ arccos(−1/e)``.
        """
        f = as_array(f, (), "f")
        if self.kind == "ellipse":
            M = kepler.mean_from_true(f, self.e)
        elif self.kind == "parabola":
            M = kepler.mean_from_parabolic(kepler.parabolic_from_true(f))
        else:
            M = kepler.mean_from_hyperbolic(kepler.hyperbolic_from_true(f, self.e), self.e)
        return np.asarray(M / self.mean_motion, dtype=np.float64)

    def anomaly_rates(self, t: Any) -> tuple[FloatArray, FloatArray, FloatArray]:
        """True anomaly and its first two time derivatives.

        Parameters
        ----------
        t : array_like, shape (...)
            Time since periapsis (s).

        Returns
        -------
        f : ndarray, shape (...)
            True anomaly (rad).
        f_dot : ndarray, shape (...)
            ``ḟ = √(μ/p³)(1 + e cos f)²`` (rad/s).
        f_ddot : ndarray, shape (...)
            ``f̈ = −2(μ/p³)(1 + e cos f)³ e sin f`` (rad/s²).

        References
        ----------
        McCann (2020), Section 4.1.2 (ḟ and f̈ below Eqs. 71 and 72; correct as printed).
        """
        f = self.true_anomaly(t)
        k = math.sqrt(self.mu / self.p**3)
        w = 1.0 + self.e * np.cos(f)
        return f, k * w * w, -2.0 * k * k * w**3 * self.e * np.sin(f)

    # ------------------------------------------------------------------ states

    def perifocal_state(self, t: Any) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Position, velocity and acceleration in the perifocal frame P.

        Parameters
        ----------
        t : array_like, shape (...)
            Time since periapsis (s).

        Returns
        -------
        r_P, v_P, a_P : ndarray, shape (..., 3)
            m, m/s, m/s² in P: ``r_P = p/(1 + e cos f) [cos f, sin f, 0]``,
            ``v_P = √(μ/p) [−sin f, e + cos f, 0]``, ``a_P = −μ r_P / r³``.

        References
        ----------
        McCann (2020), Eq. (69) (``r_{d/P}``) and ``v̇_{d/P}`` below Eq. (72).
        """
        f = self.true_anomaly(t)
        c, s = np.cos(f), np.sin(f)
        r = self.p / (1.0 + self.e * c)
        k = math.sqrt(self.mu / self.p)
        g = -self.mu / (r * r)
        zero = np.zeros_like(r)
        return (
            np.stack([r * c, r * s, zero], axis=-1),
            np.stack([-k * s, k * (self.e + c), zero], axis=-1),
            np.stack([g * c, g * s, zero], axis=-1),
        )

    def state(self, t: Any) -> tuple[FloatArray, FloatArray]:
        """Position (m) and velocity (m/s) in N at times t, each of shape (..., 3)."""
        r_P, v_P, _ = self.perifocal_state(t)
        return r_P @ self.R_NP.T, v_P @ self.R_NP.T

    def position(self, t: Any) -> FloatArray:
        """Position in N (m), shape (..., 3)."""
        return self.perifocal_state(t)[0] @ self.R_NP.T

    def velocity(self, t: Any) -> FloatArray:
        """Velocity in N (m/s), shape (..., 3)."""
        return self.perifocal_state(t)[1] @ self.R_NP.T

    def acceleration(self, t: Any) -> FloatArray:
        """Two-body acceleration ``−μ r / r³`` in N (m/s²), shape (..., 3)."""
        return self.perifocal_state(t)[2] @ self.R_NP.T

    def kinematics(self, t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Position (m), velocity (m/s) and two-body acceleration (m/s²) in N at one time t
        (s since periapsis), each of shape (3,): the scalar fast path of :meth:`position`,
        :meth:`velocity` and :meth:`acceleration` for right-hand sides that need all three."""
        f = self._scalar_anomaly(one_time(t, "KeplerOrbit.kinematics"))[0]
        c, s = math.cos(f), math.sin(f)
        r = self.p / (1.0 + self.e * c)
        k = math.sqrt(self.mu / self.p)
        g = -self.mu / (r * r)
        R = self.R_NP
        return (
            R @ np.array([r * c, r * s, 0.0]),
            R @ np.array([-k * s, k * (self.e + c), 0.0]),
            R @ np.array([g * c, g * s, 0.0]),
        )

    def state_at_true_anomaly(self, f: Any) -> tuple[FloatArray, FloatArray]:
        """Position (m) and velocity (m/s) in N at true anomalies f (rad), shape (..., 3)."""
        f = as_array(f, (), "f")
        _check_nu(f, np.full(f.shape, self.e))
        c, s = np.cos(f), np.sin(f)
        r = self.p / (1.0 + self.e * c)
        k = math.sqrt(self.mu / self.p)
        zero = np.zeros_like(r)
        r_P = np.stack([r * c, r * s, zero], axis=-1)
        v_P = np.stack([-k * s, k * (self.e + c), zero], axis=-1)
        return r_P @ self.R_NP.T, v_P @ self.R_NP.T

    # ------------------------------------------------------------------ scalar fast path

    def _scalar_anomaly(self, t: float) -> tuple[float, float, float]:
        """(f, ḟ, f̈) for one float t, compiled (the reference's hot path)."""
        out: tuple[float, float, float] = _kernels.anomaly_rates(
            float(t), self.mean_motion, self.e, self.mu, self.p
        )
        return out
