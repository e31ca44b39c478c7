"""The modified-LVLH reference motion of McCann (2020), Section 4.1.2, corrected per the errata
(``docs/errata.rst``).

A spacecraft flies a Keplerian orbit with body axis 1 pointing at the central body
(``b̂₁ = −r̂``), axis 3 along the orbit's angular momentum and axis 2 completing the
right-handed triad (in the orbit plane, opposite the transverse direction): the LVLH frame
turned 180° about the orbit normal. Frames: N inertial, P the orbit's perifocal frame
(fixed: ``g_P = [[R_NP, 0], [0, 1]]``, ``R_NP = R₃(Ω)R₁(i)R₃(ω)``), d the desired body
frame.

Corrected equations implemented (f true anomaly, ω = [0, 0, ḟ]):

* Eq. 69 (corrected; printed transposed)::

      R_{d/P} = [[−cos f,  sin f, 0],
                 [−sin f, −cos f, 0],
                 [     0,      0, 1]]  = R₃(f + π)

  (columns are the body axes in P), ``r_{d/P} = p/(1 + e cos f) [cos f, sin f, 0]``.
* Eq. 70: ``g_d = g_P g_{d/P}``.
* Eq. 71: ``V_{d/P} = [ω; R_{d/P}ᵀ v_{d/P}]`` with ``v_{d/P} = √(μ/p)[−sin f, e + cos f, 0]``;
  in closed form ``R_{d/P}ᵀ v_{d/P} = −√(μ/p) [e sin f, 1 + e cos f, 0] = −[ṙ, r ḟ, 0]``.
* Eq. 72 (corrected translational part)::

      V̇_{d/P} = [ω̇; R_{d/P}ᵀ v̇_{d/P} − ω^× R_{d/P}ᵀ v_{d/P}],   ω̇ = [0, 0, f̈],

  ``v̇_{d/P} = −(μ/r²)[cos f, sin f, 0]``, i.e. ``R_{d/P}ᵀ v̇_{d/P} = [μ/r², 0, 0]``.
* Eq. 73: ``V_d = V_{d/P} + Ad_{g_{d/P}⁻¹} V_P``.
* Eq. 74 (corrected signs)::

      V̇_d = V̇_{d/P} + Ad_{g_{d/P}⁻¹} V̇_P − ad_{V_{d/P}} Ad_{g_{d/P}⁻¹} V_P.

With P inertial (``V_P = V̇_P = 0``) Eqs. 73–74 reduce to ``V_d = V_{d/P}``,
``V̇_d = V̇_{d/P}``; :func:`compose_motion` implements the general form. The reference's
translational acceleration in N, ``R_d (v̇_d + ω_d × v_d) = R_NP v̇_{d/P}``, is exactly the
two-body gravity ``−μ r / r³``, so a point mass in a central field follows it with no
constraint force.

References
----------
McCann (2020), Section 4.1.2, Eqs. (68)–(78), and Section 4.3 (initial condition);
the errata page ``docs/errata.rst`` (Eq. 69 transposed, Eq. 72 translational part, Eq. 74
signs, μ_Moon of Section 4.3). Vallado, *Fundamentals of Astrodynamics and Applications*,
4th ed. (2013), Ch. 2 (perifocal frame) and Ch. 3 (the satellite RSW frame).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmuk._validation import FloatArray, as_array, check_se3
from gmuk.errors import DefinitionError, NonFiniteError
from gmuk.lie import se3
from gmuk.orbits import _kernels
from gmuk.orbits.conics import KeplerOrbit, one_time
from gmuk.reference import ReferenceState, ReferenceTrajectory

__all__ = [
    "MU_MOON_THESIS_CONSISTENT",
    "R_PD",
    "LVLHReference",
    "compose_motion",
    "fccn_orbit",
    "fcei_orbit",
    "section43_initial_state",
    "thesis_eq69_R_dP_as_printed",
]

#: Lunar gravitational parameter (m³/s²) that makes the printed initial condition of
#: McCann (2020), Section 4.3 (ḟ = 4.23818e-4 rad/s, v₂ = −1356.22 m/s at periapsis of the
#: a = 4000 km, e = 0.2 orbit) consistent with the orbit (errata). The usual value,
#: 4.9028e12 m³/s², gives ḟ = 4.2373e-4 rad/s and v₂ = −1355.93 m/s instead.
MU_MOON_THESIS_CONSISTENT = 4.9048695e12


def R_PD(f: Any) -> FloatArray:
    """Attitude of the modified-LVLH frame d in the perifocal frame P (corrected Eq. 69).

    ``R_{d/P} = [[−cos f, sin f, 0], [−sin f, −cos f, 0], [0, 0, 1]] = R₃(f + π)``: the
    columns are the body axes in P, body axis 1 is ``−r̂``, axis 3 the orbit normal.

    Parameters
    ----------
    f : array_like, shape (...)
        True anomaly (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    References
    ----------
    McCann (2020), Eq. (69), which prints the transpose of this matrix (errata).
    """
    f = as_array(f, (), "f")
    c, s = np.cos(f), np.sin(f)
    R = np.zeros((*f.shape, 3, 3))
    R[..., 0, 0] = -c
    R[..., 0, 1] = s
    R[..., 1, 0] = -s
    R[..., 1, 1] = -c
    R[..., 2, 2] = 1.0
    return R


def thesis_eq69_R_dP_as_printed(f: Any) -> FloatArray:
    """McCann (2020), Eq. (69) exactly as printed: ``[[−cos f, −sin f, 0], [sin f, −cos f, 0],
    [0, 0, 1]]``. **Wrong** (the transpose of :func:`R_PD`); kept for comparison only.

    With it, ``R_{d/P}ᵀ Ṙ_{d/P} = −ḟ ê₃^×`` while Eq. (71) assigns ``ω = +ḟ ê₃``, so
    ``ġ = g V^`` fails with a relative error of 2.0 in the angular velocity, and body axis 1
    is ``−[cos f, −sin f, 0]``, not ``−r̂``, except at ``f = 0, π``.

    Parameters
    ----------
    f : array_like, shape (...)
        True anomaly (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    return np.swapaxes(R_PD(f), -1, -2)


def compose_motion(
    g_P: Any,
    V_P: Any,
    V_P_dot: Any,
    g_PD: Any,
    V_PD: Any,
    V_PD_dot: Any,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Pose, body twist and twist rate of ``d`` from those of ``P`` and of ``d`` relative to ``P``.

    * ``g_d = g_P g_{d/P}`` (Eq. 70)
    * ``V_d = V_{d/P} + Ad_{g_{d/P}⁻¹} V_P`` (Eq. 73)
    * ``V̇_d = V̇_{d/P} + Ad_{g_{d/P}⁻¹} V̇_P − ad_{V_{d/P}} Ad_{g_{d/P}⁻¹} V_P``
      (Eq. 74 with the signs corrected, errata).

    Derivation: ``ġ_d = g_P V_P^ g_{d/P} + g_P g_{d/P} V_{d/P}^``
    ``= g_d (Ad_{g_{d/P}⁻¹} V_P + V_{d/P})^``, and
    ``d/dt Ad_{h⁻¹}W = Ad_{h⁻¹}Ẇ − ad_{V_h} Ad_{h⁻¹}W`` for ``ḣ = h V_h^``.

    Parameters
    ----------
    g_P : array_like, shape (..., 4, 4)
        Pose of frame P in N.
    V_P, V_P_dot : array_like, shape (..., 6)
        Body twist ``[ω; v]`` of P (rad/s, m/s, in P) and its rate (rad/s², m/s²).
    g_PD : array_like, shape (..., 4, 4)
        Pose ``g_{d/P}`` of d in P.
    V_PD, V_PD_dot : array_like, shape (..., 6)
        Body twist of d relative to P (in d) and its rate.

    Returns
    -------
    g_d : ndarray, shape (..., 4, 4)
    V_d, V_d_dot : ndarray, shape (..., 6)
        Body twist of d relative to N (in d) and the rate of its components.

    References
    ----------
    McCann (2020), Eqs. (70), (73), (74); errata (Eq. 74).
    """
    gP = check_se3(g_P, "g_P")
    gPD = check_se3(g_PD, "g_PD")
    VP = as_array(V_P, (6,), "V_P")
    VPd = as_array(V_P_dot, (6,), "V_P_dot")
    VPD = as_array(V_PD, (6,), "V_PD")
    VPDd = as_array(V_PD_dot, (6,), "V_PD_dot")
    Ad_inv = se3.Ad(se3.inverse(gPD))
    W = (Ad_inv @ VP[..., None])[..., 0]
    V_d = VPD + W
    V_d_dot = VPDd + (Ad_inv @ VPd[..., None])[..., 0] - (se3.ad(VPD) @ W[..., None])[..., 0]
    return gP @ gPD, V_d, V_d_dot


class LVLHReference(ReferenceTrajectory):
    """The modified-LVLH reference (g_d, V_d, V̇_d) along a Keplerian orbit (any conic).

    Body axis 1 points at the central body, axis 3 along the orbit normal; the origin moves
    on the orbit. Time t is in seconds since periapsis passage.

    Parameters
    ----------
    orbit : KeplerOrbit
        The desired orbit (its μ, p, e, i, Ω, ω).

    Notes
    -----
    The equations (McCann 2020, Eqs. 68–74 as corrected by the errata) are listed in the
    module docstring of :mod:`gmuk.orbits.lvlh`. The perifocal frame is inertial, so
    ``V_d = V_{d/P}`` and ``V̇_d = V̇_{d/P}``; in closed form, with ``r = p/(1 + e cos f)``
    and ``k = √(μ/p)``::

        V_d = [0, 0, ḟ, −k e sin f, −k (1 + e cos f), 0]
        V̇_d = [0, 0, f̈, μ/r² + ḟ v₂, −ḟ v₁, 0]       (v₁, v₂ the entries 4, 5 of V_d)

    :meth:`evaluate` (one time, the integrator's hot path) uses these closed forms;
    :meth:`evaluate_many` (arrays of times) uses the matrix forms of Eqs. 69–72. The tests
    check that the two agree and that both satisfy ``ġ_d = g_d V_d^`` and
    ``d/dt V_d = V̇_d`` by finite differences.

    References
    ----------
    McCann (2020), Section 4.1.2, Eqs. (68)–(78); errata.
    """

    def __init__(self, orbit: KeplerOrbit) -> None:
        if not isinstance(orbit, KeplerOrbit):
            raise DefinitionError(
                f"orbit must be a gmuk.orbits.KeplerOrbit; got {type(orbit).__name__}"
            )
        self._orbit = orbit
        self._R_NP = np.array(orbit.R_NP)
        # The last evaluation: a constraint and a controller on the same reference ask for
        # the same time at every right-hand-side evaluation.
        self._last: tuple[float, ReferenceState] | None = None

    @property
    def orbit(self) -> KeplerOrbit:
        """The desired orbit."""
        return self._orbit

    def __repr__(self) -> str:
        return f"LVLHReference({self._orbit!r})"

    def _compiled_orbit(self) -> list[float] | None:
        """The parameters the compiled loop evaluates this reference from (those of
        :func:`gmuk.orbits._kernels.lvlh_state`: n, e, μ, p and R_NP row by row), or None for
        a subclass with its own ``evaluate``."""
        if type(self).evaluate is not LVLHReference.evaluate:
            return None
        o = self._orbit
        return [o.mean_motion, o.e, o.mu, o.p, *np.ravel(self._R_NP)]

    def evaluate(self, t: float) -> ReferenceState:
        """Desired pose, body twist and twist rate at one time.

        Parameters
        ----------
        t : float
            Time since periapsis passage (s).

        Returns
        -------
        ReferenceState
            ``g`` (4, 4): ``g_d = g_P g_{d/P}`` (m); ``V`` (6,): ``V_d = [ω_d; v_d]`` in the
            desired body frame (rad/s, m/s); ``V_dot`` (6,): ``V̇_d`` (rad/s², m/s²). The
            arrays are read-only: the last evaluation is kept and handed to the next caller
            that asks for the same time.

        Raises
        ------
        NonFiniteError
            If t is NaN or infinite.
        DefinitionError
            If t is not a real number (None, a string, a bool, a complex number).
        """
        t = one_time(t, "LVLHReference.evaluate")
        last = self._last
        if last is not None and last[0] == t:
            return last[1]
        if not math.isfinite(t):
            raise NonFiniteError(f"t must be finite; got {t!r}")
        o = self._orbit
        g, V, V_dot = np.empty((4, 4)), np.empty(6), np.empty(6)
        _kernels.lvlh_state(t, o.mean_motion, o.e, o.mu, o.p, self._R_NP, g, V, V_dot)
        for x in (g, V, V_dot):  # shared with the next caller at the same time: read-only
            x.flags.writeable = False
        out = ReferenceState(g, V, V_dot)
        self._last = (t, out)
        return out

    def relative_to_perifocal(self, t: Any) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``g_{d/P}``, ``V_{d/P}`` and ``V̇_{d/P}`` (McCann 2020, Eqs. 68, 71, 72 corrected).

        Parameters
        ----------
        t : array_like, shape (...)
            Time since periapsis (s).

        Returns
        -------
        g_PD : ndarray, shape (..., 4, 4)
            ``[[R_{d/P}, r_{d/P}], [0, 1]]``.
        V_PD : ndarray, shape (..., 6)
            ``[0, 0, ḟ, R_{d/P}ᵀ v_{d/P}]``.
        V_PD_dot : ndarray, shape (..., 6)
            ``[0, 0, f̈, R_{d/P}ᵀ v̇_{d/P} − ω^× R_{d/P}ᵀ v_{d/P}]``.
        """
        o = self._orbit
        f, fd, fdd = o.anomaly_rates(t)
        r_P, v_P, a_P = o.perifocal_state(t)
        R = R_PD(f)
        Rt = np.swapaxes(R, -1, -2)
        g_PD = np.zeros((*f.shape, 4, 4))
        g_PD[..., :3, :3] = R
        g_PD[..., :3, 3] = r_P
        g_PD[..., 3, 3] = 1.0
        zeros = np.zeros_like(f)
        omega = np.stack([zeros, zeros, fd], axis=-1)
        omega_dot = np.stack([zeros, zeros, fdd], axis=-1)
        v_body = (Rt @ v_P[..., None])[..., 0]
        a_body = (Rt @ a_P[..., None])[..., 0] - np.cross(omega, v_body)
        return (
            g_PD,
            np.concatenate([omega, v_body], axis=-1),
            np.concatenate([omega_dot, a_body], axis=-1),
        )

    def evaluate_many(self, t: Any) -> ReferenceState:
        """:meth:`evaluate` at an array of times, from the matrix forms of Eqs. 69–74.

        Parameters
        ----------
        t : array_like, shape (...)
            Times since periapsis (s).

        Returns
        -------
        ReferenceState
            With ``g`` of shape (..., 4, 4) and ``V``, ``V_dot`` of shape (..., 6).
        """
        g_PD, V_PD, V_PD_dot = self.relative_to_perifocal(t)
        g_P = np.eye(4)
        g_P[:3, :3] = self._R_NP
        zero = np.zeros(6)
        g, V, V_dot = compose_motion(g_P, zero, zero, g_PD, V_PD, V_PD_dot)
        return ReferenceState(g, V, V_dot)


def fccn_orbit(mu: float = MU_MOON_THESIS_CONSISTENT) -> KeplerOrbit:
    """The circular, non-inclined lunar orbit of McCann (2020), Section 4.3.1.1 (FCCN).

    ``a = 4000 km``, ``e = 0`` and all angles 0.

    Parameters
    ----------
    mu : float
        Gravitational parameter (m³/s²); defaults to :data:`MU_MOON_THESIS_CONSISTENT`.
    """
    return KeplerOrbit.from_elements(4.0e6, 0.0, 0.0, 0.0, 0.0, mu)


def fcei_orbit(mu: float = MU_MOON_THESIS_CONSISTENT) -> KeplerOrbit:
    """The eccentric, inclined lunar orbit of McCann (2020), Section 4.3.1.2 (FCEI).

    ``a = 4000 km``, ``e = 0.2``, ``i = 35°``, ``Ω = ω = 0``.

    Parameters
    ----------
    mu : float
        Gravitational parameter (m³/s²); defaults to :data:`MU_MOON_THESIS_CONSISTENT`,
        the value that reproduces the printed initial condition (errata).
    """
    return KeplerOrbit.from_elements(4.0e6, 0.2, math.radians(35.0), 0.0, 0.0, mu)


def section43_initial_state(
    mu: float = MU_MOON_THESIS_CONSISTENT,
) -> tuple[FloatArray, FloatArray]:
    """The consistent initial pose and twist ``(g_d(0), V_d(0))`` of McCann (2020), Section 4.3.

    The spacecraft starts at periapsis (t = 0) of :func:`fcei_orbit` in the modified-LVLH
    attitude. With ``μ = MU_MOON_THESIS_CONSISTENT`` this reproduces the printed numbers
    (``r = [3.2e6, 0, 0]`` m, ``R`` with entries ``−1, −0.81915, −0.57358, 0.81915``,
    ``ω₃ = ḟ = 4.23818e-4`` rad/s, ``v₂ = −1356.22`` m/s) to all printed digits; the
    usual ``μ = 4.9028e12`` does not (errata).

    Parameters
    ----------
    mu : float
        Gravitational parameter (m³/s²).

    Returns
    -------
    g0 : ndarray, shape (4, 4)
        ``g_d(0)`` (m).
    V0 : ndarray, shape (6,)
        ``V_d(0) = [0, 0, ḟ, 0, −√(μ/p)(1 + e), 0]`` (rad/s, m/s), in the body frame.

    References
    ----------
    McCann (2020), Section 4.3 (initial conditions) and Eqs. (69)–(71); errata.
    """
    ref = LVLHReference(fcei_orbit(mu)).evaluate(0.0)
    return ref.g, ref.V
