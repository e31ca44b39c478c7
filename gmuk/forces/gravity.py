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

Each model's formula is written once, in the numba kernel beside its class
(:func:`point_mass_load`, :func:`gravity_gradient_load`, :func:`harmonic_point_load`): the
class's ``wrench``/``force`` call it, and so does the compiled step loop
(through :data:`~gmuk.forces.base.FORCE_KERNEL`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._casadi import casadi
from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, real_number, strict_bool
from gmuk.bodies import BodyKind
from gmuk.celestial import CelestialBody, UniformRotation
from gmuk.errors import DefinitionError, GmukError
from gmuk.forces.base import ForceModel, com_load
from gmuk.gravity._kernels import acceleration_at
from gmuk.gravity.field import SphericalHarmonicField

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody

__all__ = [
    "GravityGradient",
    "PointMassGravity",
    "SphericalHarmonicGravity",
    "field_wrench",
    "gravity_gradient_load",
    "gravity_gradient_wrench",
    "harmonic_point_load",
    "point_mass_load",
]


def _check_mu(mu: float) -> float:
    return real_number(mu, "mu (gravitational parameter, m³/s²)", positive=True)


@njit(cache=True)
def point_mass_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`PointMassGravity`'s kernel: ``f_N = −μ m r_N/|r_N|³`` at the centre of mass of a
    body of mass m at ``g[:3, 3]`` (m), written into ``out`` as a force kernel does
    (:func:`~gmuk.forces.base.com_load`). Parameters ``p = (μ,)`` (m³/s²). Returns 0."""
    x, y, z = g[0, 3], g[1, 3], g[2, 3]
    rn = math.sqrt(x * x + y * y + z * z)
    k = -p[0] * m / rn**3
    com_load(rigid, g, k * x, k * y, k * z, out)
    return 0


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

    mass_proportional = True  # gravity: force ∝ m, torque ∝ J

    _kernel = staticmethod(point_mass_load)
    _forms = Forms(compiled=True, symbolic=True)

    def __init__(
        self, mu: float, *, bodies: Sequence[Body | str] | None = None, modeled: bool = True
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.mu = _check_mu(mu)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[0; Rᵀ f_N] in the body frame (N·m, N) (:func:`point_mass_load`)."""
        return self._kernel_load(True, t, g_NB, V_B, body)

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """``−μ m r_N/|r_N|³`` (N) (:func:`point_mass_load`)."""
        return self._kernel_load(False, t, r_N, v_N, body)

    def _kernel_params(self, body: Body) -> tuple[tuple[float, ...], None]:
        return (self.mu,), None

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force` (CasADi, 3×1)."""
        ca = casadi()
        rn2 = ca.sumsqr(r_N)
        return (-self.mu * body.mass) * r_N / (rn2 * ca.sqrt(rn2))

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` (CasADi, 6×1)."""
        ca = casadi()
        f = PointMassGravity.casadi_force(self, t, g_NB[:3, 3], None, body)
        return ca.vertcat(ca.DM.zeros(3, 1), g_NB[:3, :3].T @ f)


@njit(cache=True)
def gravity_gradient_wrench(g, mu, m, J, out):  # type: ignore[no-untyped-def]
    """Write McCann (2020) Eq. 23's body-frame wrench [L; f] (N·m, N) of a rigid body of mass
    m and central inertia J (3, 3) at pose g (4, 4) in the field of a point mass μ at the
    origin into ``out`` (6,): with r_B = Rᵀ r,

    ``L = 3μ/r⁵ r_B × J r_B``,
    ``f = −μm/r³ (r_B + 3/(m r²) (J r_B + ½(tr J − 5 r_Bᵀ J r_B / r²) r_B))``.
    """
    x = g[0, 0] * g[0, 3] + g[1, 0] * g[1, 3] + g[2, 0] * g[2, 3]
    y = g[0, 1] * g[0, 3] + g[1, 1] * g[1, 3] + g[2, 1] * g[2, 3]
    z = g[0, 2] * g[0, 3] + g[1, 2] * g[1, 3] + g[2, 2] * g[2, 3]
    jx = J[0, 0] * x + J[0, 1] * y + J[0, 2] * z
    jy = J[1, 0] * x + J[1, 1] * y + J[1, 2] * z
    jz = J[2, 0] * x + J[2, 1] * y + J[2, 2] * z
    r2 = x * x + y * y + z * z
    rn = math.sqrt(r2)
    k = 3.0 * mu / (r2 * r2 * rn)
    out[0] = k * (y * jz - z * jy)
    out[1] = k * (z * jx - x * jz)
    out[2] = k * (x * jy - y * jx)
    c = 0.5 * (J[0, 0] + J[1, 1] + J[2, 2] - 5.0 * (x * jx + y * jy + z * jz) / r2)
    a = 3.0 / (m * r2)
    kf = -mu * m / (r2 * rn)
    out[3] = kf * (x + a * (jx + c * x))
    out[4] = kf * (y + a * (jy + c * y))
    out[5] = kf * (z + a * (jz + c * z))


@njit(cache=True)
def gravity_gradient_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`GravityGradient`'s kernel: Eq. 23 on a rigid body
    (:func:`gravity_gradient_wrench`), the point-mass force (:func:`point_mass_load`) on a
    point mass. Parameters ``p = (μ,)`` (m³/s²). Returns 0."""
    if rigid:
        gravity_gradient_wrench(g, p[0], m, J, out)
        return 0
    return point_mass_load(rigid, t, g, V, m, J, p, field, out)


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

    mass_proportional = True  # gravity: force ∝ m, torque ∝ J

    _kernel = staticmethod(gravity_gradient_load)
    _forms = Forms(compiled=True, symbolic=True)

    def __init__(
        self, mu: float, *, bodies: Sequence[Body | str] | None = None, modeled: bool = True
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.mu = _check_mu(mu)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L_G; f_G] in the body frame (N·m, N) (:func:`gravity_gradient_wrench`)."""
        return self._kernel_load(True, t, g_NB, V_B, body)

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """The point-mass force ``−μ m r_N/|r_N|³`` on a particle (N)
        (:func:`point_mass_load`)."""
        return self._kernel_load(False, t, r_N, v_N, body)

    def _kernel_params(self, body: Body) -> tuple[tuple[float, ...], None]:
        return (self.mu,), None

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force` (CasADi, 3×1): the point-mass force."""
        return PointMassGravity.casadi_force(self, t, r_N, v_N, body)  # type: ignore[arg-type]

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` (CasADi, 6×1): Eq. 23 as
        :func:`gravity_gradient_wrench` writes it, with r_B = Rᵀ r_N,
        ``L = 3μ/r⁵ r_B × J r_B`` and
        ``f = −μm/r³ (r_B + 3/(m r²) (J r_B + ½(tr J − 5 r_Bᵀ J r_B / r²) r_B))``."""
        ca = casadi()
        J, m = ca.DM(body.inertia), body.mass
        r_B = g_NB[:3, :3].T @ g_NB[:3, 3]
        j = J @ r_B
        r2 = ca.sumsqr(r_B)
        rn = ca.sqrt(r2)
        L = (3.0 * self.mu / (r2 * r2 * rn)) * ca.cross(r_B, j)
        c = 0.5 * (float(np.trace(body.inertia)) - 5.0 * ca.dot(r_B, j) / r2)
        f = (-self.mu * m / (r2 * rn)) * (r_B + (3.0 / (m * r2)) * (j + c * r_B))
        return ca.vertcat(L, f)


def _shipped_body(name: str, degree: int | None) -> CelestialBody:
    """The central body of a shipped field, with that field (truncated to ``degree``)."""
    from gmuk import gravity

    field = gravity.load(name, degree)
    body = next(i.body for i in gravity.available() if i.name.upper() == name.upper())
    return CelestialBody.moon(field=field) if body == "Moon" else CelestialBody.earth(field=field)


@njit(cache=True)
def harmonic_point_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`SphericalHarmonicGravity`'s kernel on a point mass: ``f_N = m R_FNᵀ ∇U(R_FN r_N)``
    with F spinning uniformly about N's third axis, ``R_FN = R₃(η₀ + ω t)``. Parameters
    ``p = (η₀, ω)`` (rad, rad/s); ``field`` is the field's data vector
    (:mod:`gmuk.gravity._kernels`). Returns 0, or the field kernel's nonzero status."""
    x, y, z = g[0, 3], g[1, 3], g[2, 3]
    eta = p[0] + p[1] * t
    c, s = math.cos(eta), math.sin(eta)
    r_F = np.empty(3)
    r_F[0] = c * x + s * y
    r_F[1] = -s * x + c * y
    r_F[2] = z
    a_F = np.empty(3)
    status = acceleration_at(field, r_F, a_F, True)
    if status != 0:
        return status
    fx = m * (c * a_F[0] - s * a_F[1])
    fy = m * (s * a_F[0] + c * a_F[1])
    com_load(rigid, g, fx, fy, m * a_F[2], out)
    return 0


def field_wrench(
    a_F: FloatArray, H_F: FloatArray, R_FB: FloatArray, mass: float, J: FloatArray
) -> FloatArray:
    """The wrench [L; f] (N·m, N; body frame) of a gravity field on a rigid body, to first
    order in its size: ``L = (J H_B − H_B J)^∨`` with ``H_B = R_FBᵀ H_F R_FB`` and
    ``f = m R_FBᵀ a_F``.

    Parameters
    ----------
    a_F : ndarray, shape (3,)
        The field's acceleration ∇U at the centre of mass, in F (m/s²).
    H_F : ndarray, shape (3, 3)
        Its gradient tensor ∇∇U there, in F (1/s²).
    R_FB : ndarray, shape (3, 3)
        The body's attitude in F (body components → F components).
    mass : float
        m (kg).
    J : ndarray, shape (3, 3)
        Central inertia in the body frame (kg·m²).
    """
    H_B = R_FB.T @ H_F @ R_FB
    JH = J @ H_B - H_B @ J
    return np.concatenate([[JH[2, 1], JH[0, 2], JH[1, 0]], mass * (R_FB.T @ a_F)])


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
        Include the ½ ∇³U : Π force term (default True); exactly True or False (a string
        such as ``"False"`` is refused, not read by its truthiness).
    bodies : sequence, optional
        Each body at most once.
    modeled : bool
        Exactly True or False.

    Raises
    ------
    DefinitionError
        If ``central_body`` has no field, ``finite_size_force`` or ``modeled`` is not a
        bool, or ``bodies`` lists a body twice.
    DegreeError
        If ``degree`` is not an integer within the field's degree.

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

    On a point mass about a uniformly spinning central body
    (:class:`~gmuk.celestial.UniformRotation`) in a :class:`~gmuk.gravity.SphericalHarmonicField`
    the force is :func:`harmonic_point_load`, the kernel the compiled loop calls; other
    rotation models and fields are evaluated in Python through the field's ``acceleration``.

    The symbolic (CasADi) forms for :mod:`gmuk.optimize`, :meth:`casadi_force` and
    :meth:`casadi_wrench`, need a :class:`~gmuk.gravity.SphericalHarmonicField` (its
    :meth:`~gmuk.gravity.SphericalHarmonicField.casadi_acceleration`: the kernel's recurrences
    in CasADi). The central body's rotation enters as ``R_FN(t)``: for a
    :class:`~gmuk.celestial.UniformRotation` written with ``cos``/``sin`` of the time, which
    may be symbolic; for any other rotation model only at a numeric time (the optimiser then
    transcribes element by element with the nodes' times). On a rigid body the Hessian and
    the finite-size force's third derivatives are CasADi's exact derivatives of the
    acceleration (the numeric :meth:`wrench` takes the latter by central differences; the two
    differ by far less than the round-off of the total force).
    """

    mass_proportional = True  # gravity: force ∝ m, torque ∝ J

    _kernel = staticmethod(harmonic_point_load)
    _forms = Forms(compiled=True, symbolic=True)

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
        self.include_finite_size_force = strict_bool(finite_size_force, "finite_size_force")
        self._step = 2e-4 / (int(getattr(self.field, "degree", 0)) + 3)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L; f] in the body frame (N·m, N)."""
        m = body.mass
        R_FN = self.central_body.rotation.R_FN(t)
        r_F = R_FN @ g_NB[:3, 3]
        R_FB = R_FN @ g_NB[:3, :3]  # body components → F components
        both = getattr(self.field, "acceleration_hessian", None)  # one pass if the field can
        if both is not None:
            a_F, H_F = both(r_F)
        else:
            a_F, H_F = self.field.acceleration(r_F), self.field.hessian(r_F)
        w = field_wrench(a_F, H_F, R_FB, m, body.inertia)
        if self.include_finite_size_force:
            w[3:] += R_FB.T @ self._finite_size_F(r_F, R_FB, body.inertia)
        return w

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """m R_FNᵀ ∇U(R_FN r_N), in N (N) (:func:`harmonic_point_load` where it applies)."""
        if self._kernel_params(body) is not None:
            return self._kernel_load(False, t, r_N, v_N, body)
        R_FN = self.central_body.rotation.R_FN(t)
        return body.mass * (R_FN.T @ self.field.acceleration(R_FN @ r_N))

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force`: ``m R_FN(t)ᵀ ∇U(R_FN(t) r_N)`` (CasADi, 3×1, N).

        Parameters
        ----------
        t : float or casadi.SX or casadi.MX
            Time (s); symbolic only for a :class:`~gmuk.celestial.UniformRotation`.
        r_N : casadi.SX, casadi.MX or casadi.DM, shape (3, 1)
            Position in N (m).
        v_N : any
            Unused.
        body : Body

        Raises
        ------
        DefinitionError
            For a field that is not a :class:`~gmuk.gravity.SphericalHarmonicField`, or a
            symbolic time with a rotation model other than UniformRotation.
        """
        R_FN = self._casadi_R_FN(t)
        a_F = self.field.casadi_acceleration(R_FN @ r_N)
        return body.mass * (R_FN.T @ a_F)

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench`: [L; f] in the body frame (CasADi, 6×1; N·m, N).

        ``L = (J H_B − H_B J)^∨``, ``f = R_FBᵀ (m ∇U + ½ ∇(tr(H Π)))`` with H = ∇∇U and its
        gradient CasADi's exact derivatives of the field's symbolic acceleration
        (:func:`gmuk.gravity._symbolic.rigid_function`); the finite-size term only with
        ``finite_size_force``. Arguments and errors as :meth:`casadi_force` (g_NB 4×4 in N,
        m; V_B unused).
        """
        from gmuk.gravity import _symbolic

        ca = casadi()
        R_FN = self._casadi_R_FN(t)
        R_FB = R_FN @ g_NB[:3, :3]
        r_F = R_FN @ g_NB[:3, 3]
        J = np.asarray(body.inertia, dtype=float)
        Pi_B = ca.DM(0.5 * np.trace(J) * np.eye(3) - J)
        fn = _symbolic.rigid_function(self.field, finite_size=self.include_finite_size_force)
        a_F, H_F, s_F = fn(r_F, R_FB @ Pi_B @ R_FB.T)
        H_B = R_FB.T @ H_F @ R_FB
        JH = ca.DM(J) @ H_B - H_B @ ca.DM(J)
        f_B = R_FB.T @ (body.mass * a_F + s_F)
        return ca.vertcat(JH[2, 1], JH[0, 2], JH[1, 0], f_B)

    def _symbolic_field(self) -> None:
        """Raise the DefinitionError of a field without a CasADi form."""
        if type(self.field) is not SphericalHarmonicField:
            raise DefinitionError(
                f"{self.name}: the symbolic (CasADi) form of SphericalHarmonicGravity needs a "
                f"gmuk.gravity.SphericalHarmonicField; this model's field is a "
                f"{type(self.field).__name__}, which has no CasADi form"
            )

    def _casadi_R_FN(self, t: Any) -> Any:
        """R_FN(t) (3×3) as a CasADi matrix: of ``cos``/``sin`` of a symbolic t for a
        :class:`~gmuk.celestial.UniformRotation`, the rotation model's numbers at a numeric t
        (any model); a DefinitionError for a symbolic t with another model."""
        ca = casadi()
        self._symbolic_field()
        rot = self.central_body.rotation
        if isinstance(t, (ca.SX, ca.MX)):
            if type(rot) is not UniformRotation:
                raise DefinitionError(
                    f"{self.name}: the symbolic (CasADi) form of SphericalHarmonicGravity "
                    "takes a symbolic time only for a central body spinning uniformly "
                    f"(gmuk.UniformRotation); {self.central_body.name}'s rotation is a "
                    f"{type(rot).__name__}, supported at numeric times only (gmuk.optimize "
                    "then transcribes element by element)"
                )
            eta = rot.angle0 + rot.rate * t
            c, s = ca.cos(eta), ca.sin(eta)
            return ca.vertcat(
                ca.horzcat(c, s, 0.0), ca.horzcat(-s, c, 0.0), ca.horzcat(0.0, 0.0, 1.0)
            )
        return ca.DM(rot.R_FN(float(t)))

    def _kernel_params(self, body: Body) -> tuple[tuple[float, float], Any] | None:
        """(η₀, ω) and the field's data for a point mass in a
        :class:`~gmuk.gravity.SphericalHarmonicField` about a central body spinning uniformly
        (:class:`~gmuk.celestial.UniformRotation`); None otherwise (rigid bodies, other
        rotation models and fields: Python)."""
        rot = self.central_body.rotation
        data = getattr(self.field, "_data", None)
        if (
            body.kind is not BodyKind.POINT
            or type(rot) is not UniformRotation
            or type(self.field) is not SphericalHarmonicField
            or data is None
        ):
            return None
        return (float(rot.angle0), float(rot.rate)), data

    def _kernel_failure(self, status: int, t: float, g: FloatArray) -> Exception:
        """The field's own error at the failing point (what ``field.acceleration`` raises)."""
        R_FN = self.central_body.rotation.R_FN(t)
        try:
            self.field.acceleration(R_FN @ g[:3, 3])
        except GmukError as exc:
            return exc
        return super()._kernel_failure(status, t, g)

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
