"""Third-body perturbation: the Sun, the Earth or the Moon pulling on bodies that orbit the
central body at N's origin.

In a frame centred on the central body (which the third body accelerates too) the
perturbing acceleration of a point at r by a third body of GM μ at d is the tidal
difference ``μ [(d − r)/|d − r|³ − d/|d|³]``. Its two terms nearly cancel (for the Sun on
an Earth orbiter they agree to 1 part in 10⁴), so it is computed in Battin's form, free of
that cancellation:

``a = −μ/|d − r|³ (r + F(q) d)``, ``q = r·(r − 2d)/(d·d)``,
``F(q) = q (3 + 3q + q²)/(1 + (1 + q)^{3/2})``  (F(q) = (1 + q)^{3/2} − 1).

On a rigid body the third body also exerts the gravity-gradient torque of a point mass and
the second-order finite-size force, both McCann (2020) Eq. 23 with the body's position
relative to the third body, ``r − d``: gmuk's one definition of Eq. 23,
:func:`gmuk.forces.gravity.gravity_gradient_wrench`, evaluated there. The central body's
own finite-size (gradient) response is not a force on the orbiter and is not included.

References
----------
Battin, R. H. (1999), *An Introduction to the Mathematics and Methods of Astrodynamics*,
rev. ed., AIAA, §8.4 (Eq. 8.60–8.62); Montenbruck & Gill (2000), §3.3.1; McCann (2020),
Eqs. (23a)–(23b).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._casadi import casadi
from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, real_number, real_vector
from gmuk.environment._loads import call_load
from gmuk.environment.ephemeris import MU, Ephemeris, _body
from gmuk.environment.time import Epoch
from gmuk.errors import DefinitionError
from gmuk.forces.base import ForceModel
from gmuk.forces.gravity import GravityGradient, gravity_gradient_wrench

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody

__all__ = ["ThirdBodyPerturbation", "third_body_load", "tidal_acceleration"]


@njit(cache=True)
def battin_tidal(x, y, z, dx, dy, dz, mu, a):  # type: ignore[no-untyped-def]
    """Write Battin's tidal acceleration (m/s²) of a point at (x, y, z) by a body of GM mu
    at (dx, dy, dz) (m, one frame centred on the central body) into a (3,)."""
    dd = dx * dx + dy * dy + dz * dz
    q = (x * (x - 2.0 * dx) + y * (y - 2.0 * dy) + z * (z - 2.0 * dz)) / dd
    F = q * (3.0 + q * (3.0 + q)) / (1.0 + (1.0 + q) ** 1.5)
    rx, ry, rz = dx - x, dy - y, dz - z
    rho = math.sqrt(rx * rx + ry * ry + rz * rz)
    k = -mu / (rho * rho * rho)
    a[0] = k * (x + F * dx)
    a[1] = k * (y + F * dy)
    a[2] = k * (z + F * dz)


@njit(cache=True)
def third_body_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`ThirdBodyPerturbation`'s kernel (signature ``FORCE_KERNEL``). Parameters
    ``p = (μ, d_x, d_y, d_z)``: the third body's GM (m³/s²) and position d_N (m) at time t.

    Point mass: ``f_N = m a`` (Battin's tidal acceleration). Rigid body: torque and
    finite-size force of Eq. 23 at r − d (:func:`gravity_gradient_wrench`), plus the
    tidal force ``Rᵀ m a`` at the centre of mass, body frame. Returns 0."""
    x, y, z = g[0, 3], g[1, 3], g[2, 3]
    dx, dy, dz = p[1], p[2], p[3]
    a = np.empty(3)
    battin_tidal(x, y, z, dx, dy, dz, p[0], a)
    if not rigid:
        out[0] = m * a[0]
        out[1] = m * a[1]
        out[2] = m * a[2]
        return 0
    gs = g.copy()
    sx, sy, sz = x - dx, y - dy, z - dz
    gs[0, 3], gs[1, 3], gs[2, 3] = sx, sy, sz
    w = np.empty(6)
    gravity_gradient_wrench(gs, p[0], m, J, w)
    rho = math.sqrt(sx * sx + sy * sy + sz * sz)
    k = p[0] * m / (rho * rho * rho)  # w[3:] minus its point-mass part -μm(r − d)/ρ³
    for i in range(3):
        out[i] = w[i]
        fin = w[3 + i] + k * (g[0, i] * sx + g[1, i] * sy + g[2, i] * sz)
        out[3 + i] = m * (g[0, i] * a[0] + g[1, i] * a[1] + g[2, i] * a[2]) + fin
    return 0


def tidal_acceleration(r_N: Any, d_N: Any, mu: float) -> FloatArray:
    """Perturbing acceleration (m/s²) of a point at ``r_N`` by a third body of GM ``mu``
    (m³/s²) at ``d_N`` (m), both relative to the central body, in Battin's form
    (:func:`battin_tidal`): ``μ[(d − r)/|d − r|³ − d/|d|³]`` without its cancellation.

    Parameters
    ----------
    r_N, d_N : array_like, shape (3,)
        Positions relative to the central body (m), one frame.
    mu : float
        The third body's GM (m³/s²).

    Returns
    -------
    ndarray, shape (3,)

    References
    ----------
    Battin (1999), §8.4.
    """
    r = real_vector(r_N, "r_N (m)", 3)
    d = real_vector(d_N, "d_N (m)", 3)
    mu = real_number(mu, "mu (m³/s²)", positive=True)
    a = np.empty(3)
    battin_tidal(r[0], r[1], r[2], d[0], d[1], d[2], mu, a)
    return a


class ThirdBodyPerturbation(ForceModel):
    """The Sun, the Earth or the Moon as a third body, at its ephemeris position.

    Parameters
    ----------
    perturber : {"sun", "earth", "moon"}
        The third body.
    epoch : Epoch
        The instant of simulation time t = 0 (t is TDB seconds since it).
    centre : {"earth", "moon", "sun"}
        The central body at N's origin (default the Earth); N has ICRF-aligned axes.
    mu : float, optional
        The perturber's GM (m³/s²); default :data:`gmuk.environment.MU` of it.
    bodies : sequence, optional
    modeled : bool

    Notes
    -----
    Point masses: ``m a`` with a Battin's tidal acceleration (module docstring). Rigid
    bodies: that force at the centre of mass plus Eq. 23's torque ``3μ/ρ⁵ ρ_B × J ρ_B`` and
    finite-size force at ρ = r − d (:func:`third_body_load`). The perturber's position is
    :func:`gmuk.environment.position` at ``epoch + t`` (ERFA's series, see
    :mod:`gmuk.environment.ephemeris` for their accuracy).

    References
    ----------
    Battin (1999), §8.4; McCann (2020), Eqs. (23a)–(23b); Montenbruck & Gill (2000), §3.3.
    """

    mass_proportional = True  # gravity: force ∝ m, torque ∝ J

    _forms = Forms(
        compiled=(
            "the perturber's position comes from ERFA's ephemeris series at epoch + t, which "
            "the compiled loop cannot call; the physics is one numba kernel (third_body_load) "
            "that the Python form calls with that position"
        ),
        symbolic=True,
    )

    def __init__(
        self,
        perturber: str,
        epoch: Epoch,
        *,
        centre: str = "earth",
        mu: float | None = None,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.perturber = _body(perturber, "perturber")
        self.ephemeris = Ephemeris(self.perturber, epoch, _body(centre, "centre"))
        self.mu = MU[self.perturber] if mu is None else real_number(mu, "mu", positive=True)

    @property
    def epoch(self) -> Epoch:
        """The instant of t = 0."""
        return self.ephemeris.epoch

    def _numeric_time(self, t: Any) -> float:
        """t as a float for the ephemeris; a DefinitionError for a symbolic (CasADi) time."""
        ca = casadi()
        if isinstance(t, (ca.SX, ca.MX)):
            raise DefinitionError(
                f"{self.name}: the symbolic (CasADi) form of ThirdBodyPerturbation takes numeric "
                "times only (the perturber's position is ERFA's series at epoch + t); "
                "gmuk.optimize then transcribes element by element with the nodes' times"
            )
        return float(t)

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force` at a numeric time t (CasADi, 3×1, N): Battin's
        tidal acceleration as :func:`battin_tidal` writes it, times the mass.

        Raises
        ------
        DefinitionError
            For a symbolic t.
        """
        ca = casadi()
        d = ca.DM(self.ephemeris(self._numeric_time(t)))
        q = ca.dot(r_N, r_N - 2.0 * d) / ca.dot(d, d)
        F = q * (3.0 + q * (3.0 + q)) / (1.0 + (1.0 + q) ** 1.5)
        rho = ca.norm_2(d - r_N)
        return (-self.mu * body.mass / (rho * rho * rho)) * (r_N + F * d)

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` at a numeric time t (CasADi, 6×1; N·m, N):
        Eq. 23 at r − d (:meth:`gmuk.GravityGradient.casadi_wrench`, the CasADi form of
        :func:`gravity_gradient_wrench`) for the torque and the finite-size force, plus the
        tidal force :meth:`casadi_force` at the centre of mass, as :func:`third_body_load`."""
        ca = casadi()
        d = ca.DM(self.ephemeris(self._numeric_time(t)))
        R, r = g_NB[:3, :3], g_NB[:3, 3]
        g_s = ca.vertcat(ca.horzcat(R, r - d), ca.DM([[0.0, 0.0, 0.0, 1.0]]))
        w = GravityGradient.casadi_wrench(self, t, g_s, V_B, body)  # type: ignore[arg-type]
        rho = ca.norm_2(r - d)
        finite = w[3:] + (self.mu * body.mass / (rho * rho * rho)) * (R.T @ (r - d))
        f_cm = R.T @ ThirdBodyPerturbation.casadi_force(self, t, r, None, body)
        return ca.vertcat(w[:3], f_cm + finite)

    def _params(self, t: float) -> tuple[float, ...]:
        d = self.ephemeris(t)
        return (self.mu, float(d[0]), float(d[1]), float(d[2]))

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L; f] in the body frame (N·m, N) (:func:`third_body_load`)."""
        return call_load(
            third_body_load, True, t, g_NB, V_B, body, self._params(t), None, self.name
        )

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """``m a`` in N (N), a Battin's tidal acceleration (:func:`third_body_load`)."""
        return call_load(
            third_body_load, False, t, r_N, v_N, body, self._params(t), None, self.name
        )
