"""Gravity on bodies from a central body at the origin of N.

* :class:`PointMassGravity`: ``f = −μ m r/|r|³`` at the centre of mass, no torque.
* :class:`SphericalHarmonicGravity`: a body-fixed field of any degree, correct to second
  order in the body's size (see the class).
* :class:`GravityGradient`: the point-mass field on a finite rigid body to second order in its
  size (McCann 2020, Eqs. 23a–b, from Schaub & Junkins 2018), in the body frame with
  ``r_B = Rᵀ r``:

  ``L = 3μ/|r|⁵ · r_B × (J r_B)``,
  ``f = −μm/|r|³ · (r_B + 3/(m|r|²) [J + ½(tr J − 5 r̂_Bᵀ J r̂_B) I] r_B)``.

  ERRATA: correct as printed with r_B = Rᵀr (Eqs. 33/52 write inertial r, where J must be
  R J Rᵀ); both match point-cloud quadrature to 1e-11.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.errors import DefinitionError
from gmuk.forces.base import ForceModel

if TYPE_CHECKING:
    from gmuk.bodies import Body

__all__ = ["GravityGradient", "PointMassGravity", "SphericalHarmonicGravity"]


def _check_mu(mu: float) -> float:
    m = float(mu)
    if not (np.isfinite(m) and m > 0):
        raise DefinitionError(
            f"mu must be a finite gravitational parameter > 0 (m³/s²); got {mu!r}"
        )
    return m


class PointMassGravity(ForceModel):
    """Central point-mass gravity at the centre of mass (no torque).

    Parameters
    ----------
    mu : float
        Gravitational parameter μ of the central body (m³/s²), at the origin of N.
    bodies : sequence, optional
        Bodies it acts on (default: all rigid bodies and point masses).
    modeled : bool
    """

    def __init__(
        self, mu: float, *, bodies: Sequence[Body | str] | None = None, modeled: bool = True
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.mu = _check_mu(mu)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: Body) -> FloatArray:
        """[0; m Rᵀ a_N] for a rigid body (N·m, N, body frame); m a_N for a point mass (N)."""
        r = g_NB[:3, 3]
        rn = float(np.sqrt(r @ r))
        f_N = (-self.mu * body.mass / rn**3) * r  # type: ignore[attr-defined]
        if body.kind == "rigid":
            return np.concatenate([np.zeros(3), g_NB[:3, :3].T @ f_N])
        return f_N


class GravityGradient(ForceModel):
    """Uniform-field (point-mass) gravity on a finite rigid body: Eq. 23 force and torque.

    Parameters
    ----------
    mu : float
        Gravitational parameter μ (m³/s²) of the central body at the origin of N.
    bodies : sequence, optional
    modeled : bool

    Notes
    -----
    Point masses get the point-mass force. The neglected terms are third order in
    (body size / distance) relative to the finite-size part (zero for bodies symmetric
    about their centre of mass, then fourth order).

    References
    ----------
    McCann (2020), Eqs. (23a)–(23b); Schaub & Junkins, *Analytical Mechanics of Space
    Systems* (2018), §4.4.
    """

    def __init__(
        self, mu: float, *, bodies: Sequence[Body | str] | None = None, modeled: bool = True
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.mu = _check_mu(mu)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: Body) -> FloatArray:
        """[L_G; f_G] in the body frame (N·m, N), or the point-mass force for a particle."""
        m = float(body.mass)  # type: ignore[attr-defined]
        r_N = g_NB[:3, 3]
        if body.kind != "rigid":
            return (-self.mu * m / float(np.sqrt(r_N @ r_N)) ** 3) * r_N
        J = body.inertia  # type: ignore[attr-defined]
        r_B = g_NB[:3, :3].T @ r_N
        r2 = float(r_B @ r_B)
        rn = np.sqrt(r2)
        Jr = J @ r_B
        L = (3.0 * self.mu / (r2 * r2 * rn)) * np.cross(r_B, Jr)
        shape = Jr + 0.5 * (np.trace(J) - 5.0 * float(r_B @ Jr) / r2) * r_B
        f = (-self.mu * m / (r2 * rn)) * (r_B + (3.0 / (m * r2)) * shape)
        return np.concatenate([L, f])


class SphericalHarmonicGravity(ForceModel):
    """Gravity of a central body's spherical-harmonic field on bodies, to second order in size.

    For a rigid body with central inertia J (body frame) at r, with U the field's potential,
    H = ∇∇U its Hessian and Π = ∫ δr δrᵀ dm = ½ tr(J) I − J:

    * force ``F = m ∇U(r) + ½ ∇³U : Π`` (the second term by a central difference of
      tr(H Π) along three axes; ~1e-13 of F for a lunar orbiter, larger for big structures near
      small bodies; ``finite_size_force=False`` skips it),
    * torque ``Lᵢ = εᵢⱼₖ (H_B J)ⱼₖ = (J H_B − H_B J)^∨`` with ``H_B = Rᵀ H R``,

    all in the body frame. A point mass gets ``m ∇U``. The field is evaluated in the
    body-fixed frame F of the central body, ``r_F = R_FN(t) r_N``.

    Parameters
    ----------
    central_body : CelestialBody
        With a ``field`` (and its rotation model).
    degree : int, optional
        Truncate the field to this degree (default: the field's own).
    finite_size_force : bool
        Include the ½ ∇³U : Π force term (default True).
    bodies : sequence, optional
    modeled : bool

    Notes
    -----
    McCann (2020), Eqs. 42 and 59 approximate this with the angular factor frozen at the
    centre-of-mass direction and the radial-only Eq. 25; see
    :class:`ThesisRadialHarmonicGravity` and the errata.
    """

    def __init__(
        self,
        central_body: Any,
        degree: int | None = None,
        *,
        finite_size_force: bool = True,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        field = getattr(central_body, "field", None)
        if field is None:
            raise DefinitionError(
                "SphericalHarmonicGravity needs a CelestialBody with a field; "
                "load one with gmuk.gravity.load_gfc(...) and pass "
                "CelestialBody.moon(field=...)"
            )
        self.central_body = central_body
        self.field = field if degree is None else field.truncate(degree)
        self.finite_size_force = bool(finite_size_force)

    def _fixed(self, t: float) -> tuple[FloatArray, FloatArray]:
        R_FN = self.central_body.rotation.R_FN(t)
        return R_FN, R_FN.T

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: Body) -> FloatArray:
        """[L; f] in the body frame (N·m, N), or f_N for a point mass (N)."""
        m = float(body.mass)  # type: ignore[attr-defined]
        R_FN, R_NF = self._fixed(t)
        r_F = R_FN @ g_NB[:3, 3]
        if body.kind != "rigid":
            return m * (R_NF @ self.field.acceleration(r_F))
        J = body.inertia  # type: ignore[attr-defined]
        R_FB = R_FN @ g_NB[:3, :3]  # body components → F components
        a_F = self.field.acceleration(r_F)
        H_B = R_FB.T @ self.field.hessian(r_F) @ R_FB
        JH = J @ H_B - H_B @ J
        L = np.array([JH[2, 1], JH[0, 2], JH[1, 0]])
        f_F = m * a_F
        if self.finite_size_force:
            Pi_F = R_FB @ (0.5 * np.trace(J) * np.eye(3) - J) @ R_FB.T
            h = 1e-4 * float(np.sqrt(r_F @ r_F))
            grad = np.empty(3)
            for i in range(3):
                e = np.zeros(3)
                e[i] = h
                grad[i] = (
                    np.tensordot(self.field.hessian(r_F + e), Pi_F)
                    - np.tensordot(self.field.hessian(r_F - e), Pi_F)
                ) / (2.0 * h)
            f_F = f_F + 0.5 * grad
        return np.concatenate([L, R_FB.T @ f_F])
