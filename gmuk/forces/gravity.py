"""Gravity on bodies from a central body at the origin of N.

* :class:`PointMassGravity`: ``f = −μ m r/|r|³`` at the centre of mass, no torque.
* :class:`SphericalHarmonicGravity`: a body-fixed field of any degree, correct to second
  order in the body's size (see the class).
* :class:`GravityGradient`: the point-mass field on a finite rigid body to second order in its
  size (McCann 2020, Eqs. 23a–b, from Schaub & Junkins 2018), in the body frame with
  ``r_B = Rᵀ r``:

  ``L = 3μ/|r|⁵ · r_B × (J r_B)``,
  ``f = −μm/|r|³ · (r_B + 3/(m|r|²) [J + ½(tr J − 5 r̂_Bᵀ J r̂_B) I] r_B)``.

  Errata (docs/errata.rst): correct as printed with r_B = Rᵀr (Eqs. 33/52 write inertial r,
  where J must be R J Rᵀ); both match point-cloud quadrature to 1e-11.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray, real_number
from gmuk.bodies import BodyKind
from gmuk.celestial import CelestialBody, UniformRotation
from gmuk.errors import DefinitionError
from gmuk.forces import _kernels
from gmuk.forces.base import ForceModel
from gmuk.gravity.field import SphericalHarmonicField

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody

__all__ = ["GravityGradient", "PointMassGravity", "SphericalHarmonicGravity"]


def _check_mu(mu: float) -> float:
    return real_number(mu, "mu (gravitational parameter, m³/s²)", positive=True)


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

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[0; m Rᵀ a_N] in the body frame (N·m, N)."""
        return np.concatenate([np.zeros(3), g_NB[:3, :3].T @ self.force(t, g_NB[:3, 3], V_B, body)])

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """``−μ m r_N/|r_N|³`` (N)."""
        rn = float(np.sqrt(r_N @ r_N))
        return (-self.mu * body.mass / rn**3) * r_N

    def _compiled_term(self, body: Body) -> tuple[int, tuple[float, ...], Any] | None:
        if not self._methods_are(PointMassGravity):
            return None
        return _kernels.POINT_MASS, (self.mu,), None


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

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L_G; f_G] in the body frame (N·m, N); compiled
        (:func:`gmuk.forces._kernels.gravity_gradient_wrench`)."""
        out = np.empty(6)
        _kernels.gravity_gradient_wrench(g_NB, self.mu, body.mass, body.inertia, out)
        return out

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """The point-mass force ``−μ m r_N/|r_N|³`` on a particle (N)."""
        return (-self.mu * body.mass / float(np.sqrt(r_N @ r_N)) ** 3) * r_N

    def _compiled_term(self, body: Body) -> tuple[int, tuple[float, ...], Any] | None:
        if not self._methods_are(GravityGradient):
            return None
        return _kernels.GRAVITY_GRADIENT, (self.mu,), None


def _shipped_body(name: str, degree: int | None) -> CelestialBody:
    """The central body of a shipped field, with that field (truncated to ``degree``)."""
    from gmuk import gravity

    field = gravity.load(name, degree)
    body = next(i.body for i in gravity.available() if i.name.upper() == name.upper())
    return CelestialBody.moon(field=field) if body == "Moon" else CelestialBody.earth(field=field)


class SphericalHarmonicGravity(ForceModel):
    """Gravity of a central body's spherical-harmonic field on bodies, to second order in size.

    For a rigid body with central inertia J (body frame) at r, with U the field's potential,
    H = ∇∇U its Hessian and Π = ∫ δr δrᵀ dm = ½ tr(J) I − J:

    * force ``F = m ∇U(r) + ½ ∇³U : Π`` (the second term by central differences of
      tr(H Π), step ``2e-4 |r|/(N+3)``; ~1e-13 of F for a lunar orbiter, larger for big
      structures near small bodies; ``finite_size_force=False`` skips it; the term alone is
      :meth:`finite_size_force`),
    * torque ``Lᵢ = εᵢⱼₖ (H_B J)ⱼₖ = (J H_B − H_B J)^∨`` with ``H_B = Rᵀ H R``,

    all in the body frame. A point mass gets ``m ∇U``. The field is evaluated in the
    body-fixed frame F of the central body, ``r_F = R_FN(t) r_N``.

    Accuracy (``tests/forces/test_harmonic_bodies.py``, brute-force point-cloud quadrature,
    Apollo LM with GRGM660PRIM at degrees 0, 10, 50, 150, 50–500 km, poles included):
    finite-size force within 1.4e-8 and torque within 5e-10 of the truth (relative); the
    neglected terms are of third order in (body size / field scale) relative to the
    finite-size part, fourth order for centrally symmetric bodies.

    Parameters
    ----------
    central_body : CelestialBody or str
        A CelestialBody with a ``field`` (and its rotation model), or the name of a field
        shipped with gmuk (``"GRGM660PRIM"``: the Moon, ``"EGM2008"``: the Earth; see
        :func:`gmuk.gravity.available`), which gives that body with its default rotation
        (:meth:`CelestialBody.moon`, :meth:`CelestialBody.earth`).
    degree : int, optional
        Truncate the field to this degree (default: the field's own).
    finite_size_force : bool
        Include the ½ ∇³U : Π force term (default True).
    bodies : sequence, optional
    modeled : bool

    Examples
    --------
    The GRAIL lunar field to degree 50 on every body of a System, in one line:

    >>> import gmuk
    >>> moon_gravity = gmuk.SphericalHarmonicGravity("GRGM660PRIM", degree=50)
    >>> moon_gravity.central_body.name, moon_gravity.field.degree
    ('Moon', 50)

    Notes
    -----
    McCann (2020), Eqs. 42 and 59 approximate this with the angular factor frozen at the
    centre-of-mass direction and the radial-only Eq. 25; see
    :class:`~gmuk.forces.thesis_gravity.ThesisRadialHarmonicGravity` and the errata.
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
        if isinstance(central_body, str):
            central_body = _shipped_body(central_body, degree)
            degree = None  # already truncated on loading
        field = getattr(central_body, "field", None)
        if field is None:
            raise DefinitionError(
                "SphericalHarmonicGravity needs a CelestialBody with a field, or the name of "
                "a shipped field (e.g. SphericalHarmonicGravity('GRGM660PRIM', degree=50)); "
                f"got {central_body!r}"
            )
        self.central_body = central_body
        self.field = field if degree is None else field.truncate(degree)
        self.include_finite_size_force = bool(finite_size_force)
        self._step = 2e-4 / (int(getattr(self.field, "degree", 0)) + 3)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L; f] in the body frame (N·m, N)."""
        m = body.mass
        R_FN = self.central_body.rotation.R_FN(t)
        r_F = R_FN @ g_NB[:3, 3]
        J = body.inertia
        R_FB = R_FN @ g_NB[:3, :3]  # body components → F components
        both = getattr(self.field, "acceleration_hessian", None)  # one pass if the field can
        if both is not None:
            a_F, H_F = both(r_F)
        else:
            a_F, H_F = self.field.acceleration(r_F), self.field.hessian(r_F)
        H_B = R_FB.T @ H_F @ R_FB
        JH = J @ H_B - H_B @ J
        L = np.array([JH[2, 1], JH[0, 2], JH[1, 0]])
        f_B = m * (R_FB.T @ a_F)
        if self.include_finite_size_force:
            f_B = f_B + R_FB.T @ self._finite_size_F(r_F, R_FB, J)
        return np.concatenate([L, f_B])

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """m ∇U at r_N, in N (N)."""
        R_FN = self.central_body.rotation.R_FN(t)
        return body.mass * (R_FN.T @ self.field.acceleration(R_FN @ r_N))

    def _compiled_term(self, body: Body) -> tuple[int, tuple[float, ...], Any] | None:
        """Point masses in a field with a compiled kernel, the central body spinning
        uniformly (:class:`~gmuk.celestial.UniformRotation`); None otherwise."""
        rot = self.central_body.rotation
        data = getattr(self.field, "_data", None)
        if (
            body.kind is not BodyKind.POINT
            or not self._methods_are(SphericalHarmonicGravity)
            or type(rot) is not UniformRotation
            or type(self.field) is not SphericalHarmonicField
            or data is None
        ):
            return None
        return _kernels.HARMONIC_POINT, (float(rot.angle0), float(rot.rate)), data

    def finite_size_force(self, t: float, g_NB: FloatArray, body: RigidBody) -> FloatArray:
        """The second-order finite-size force ``½ ∇³U : Π`` alone, in the body frame (N).

        It is what :meth:`wrench` adds to ``m ∇U(r)`` (and so what tests compare with a
        quadrature: for a lunar orbiter it is ~1e-13 of the total force, below the
        round-off of the sum). Zero for a point mass.

        Parameters
        ----------
        t : float
            Time (s), for the central body's rotation.
        g_NB : ndarray, shape (4, 4)
            Pose of the body in N (m).
        body : Body
        """
        if body.kind is not BodyKind.RIGID:
            return np.zeros(3)
        R_FN = self.central_body.rotation.R_FN(t)
        r_F = R_FN @ g_NB[:3, 3]
        R_FB = R_FN @ g_NB[:3, :3]
        return np.asarray(R_FB.T @ self._finite_size_F(r_F, R_FB, body.inertia))

    def _finite_size_F(self, r_F: FloatArray, R_FB: FloatArray, J: FloatArray) -> FloatArray:
        """``½ ∇(tr(H Π))`` at r_F in F components (N), Π = R_FB (½ tr J I − J) R_FBᵀ.

        Central differences of the Hessian (six single-point calls: a field need not
        take batches) with step ``h = 2e-4 |r| / (N + 3)``. The degree-N terms vary on the
        scale |r|/N, so a step fixed relative to |r| alone is too coarse at high degree: the
        former 1e-4 |r| left an error of 1.2e-6 of this term at degree 150, 50 km above the
        Moon, where this step leaves 4e-10 (truncation ~(hN/|r|)², round-off
        ~1e-16 (N+3)/2e-4; ``test_finite_difference_step_scales_with_degree`` in
        ``tests/forces/test_harmonic_bodies.py``).
        """
        Pi_F = R_FB @ (0.5 * np.trace(J) * np.eye(3) - J) @ R_FB.T
        h = self._step * float(np.sqrt(r_F @ r_F))
        trHP = np.empty(6)
        for k, x in enumerate(r_F + h * np.concatenate([np.eye(3), -np.eye(3)])):
            trHP[k] = float(np.tensordot(self.field.hessian(x), Pi_F))
        return np.asarray(0.5 * (trHP[:3] - trHP[3:]) / (2.0 * h))
