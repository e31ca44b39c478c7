"""Gravity on bodies from a central body at the origin of N.

* :class:`PointMassGravity`: ``f = −μ m r/|r|³`` at the centre of mass, no torque.
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
from typing import TYPE_CHECKING

import numpy as np

from gmuk._validation import FloatArray
from gmuk.errors import DefinitionError
from gmuk.forces.base import ForceModel

if TYPE_CHECKING:
    from gmuk.bodies import Body

__all__ = ["GravityGradient", "PointMassGravity"]


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
