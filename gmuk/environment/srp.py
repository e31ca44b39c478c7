"""Solar radiation pressure: cannonball and flat-plate models, with the conical shadow of the
Earth and the Moon.

The pressure at distance ρ from the Sun is ``P = P₀ (AU/ρ)²`` with P₀ = 4.56e-6 N/m² at
1 au (Montenbruck & Gill 2000, Eq. 3.69), times the visible fraction ν of the Sun's disc
(:func:`~gmuk.environment.shadow_fraction`, the product over the occulters: two
simultaneous partial eclipses are taken as independent). With ``e`` the unit vector from the
body to the Sun:

* cannonball (:class:`CannonballSRP`): ``f = −ν P C_R A e`` at the centre of mass;
* flat plates (:class:`FlatPlateSRP`): each plate of area A, outward unit normal n (body
  frame), specular, diffuse and absorbed fractions C_s + C_d + C_a = 1, lit when
  ``cos θ = n·e > 0``, receives
  ``F = −ν P A cos θ [(1 − C_s) e + 2 (C_s cos θ + C_d/3) n]`` (Montenbruck & Gill 2000,
  Eq. 3.75 with Lambertian diffuse reflection), at its centre of pressure c (body frame,
  from the centre of mass), and so the torque ``c × F``. Self-shadowing between plates is
  not modelled.

Each model's force is one numba kernel (:func:`cannonball_srp_load`,
:func:`flat_plate_srp_load`) that the Python form calls with the Sun's position and ν at
``epoch + t``; the compiled loop cannot call the ephemerides, so it calls the Python form.
The symbolic (CasADi) forms, for :mod:`gmuk.optimize`, take numeric times (the shadow as
:func:`~gmuk.environment.shadow.casadi_fraction`).

References
----------
Montenbruck, O. & Gill, E. (2000), *Satellite Orbits*, §3.4; Vallado, D. A. (2013),
*Fundamentals of Astrodynamics and Applications*, 4th ed., §8.6.4.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._casadi import casadi
from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, check_sequence, real_number, real_vector
from gmuk.environment._loads import call_load
from gmuk.environment.ephemeris import AU, RADIUS, _body, position
from gmuk.environment.shadow import casadi_fraction, fraction_at
from gmuk.environment.time import Epoch
from gmuk.errors import DefinitionError, DomainError
from gmuk.forces.base import ForceModel, com_load

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody

__all__ = [
    "SOLAR_PRESSURE_1AU",
    "CannonballSRP",
    "FlatPlateSRP",
    "Plate",
    "cannonball_srp_load",
    "flat_plate_srp_load",
]

#: Solar radiation pressure at 1 au on a perfect absorber (N/m²), Montenbruck & Gill (2000),
#: Eq. 3.69 (solar flux 1367 W/m² over c).
SOLAR_PRESSURE_1AU = 4.56e-6

_SRP_COMPILED = (
    "the Sun's and the occulters' positions come from ERFA's ephemeris series at epoch + t, "
    "which the compiled loop cannot call; the physics is one numba kernel that the Python "
    "form calls with those positions and the shadow fraction"
)


@njit(cache=True)
def cannonball_srp_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`CannonballSRP`'s kernel (signature ``FORCE_KERNEL``). Parameters
    ``p = (ν P₀ AU² C_R A, s_x, s_y, s_z)``: the pressure constant (N·m²… times the shadow
    fraction ν) and the Sun's position s_N (m). Force ``k/ρ² (r − s)/ρ``, ``ρ = |r − s|``, at
    the centre of mass. Returns 0."""
    ux, uy, uz = g[0, 3] - p[1], g[1, 3] - p[2], g[2, 3] - p[3]
    rho = math.sqrt(ux * ux + uy * uy + uz * uz)
    k = p[0] / (rho * rho * rho)
    com_load(rigid, g, k * ux, k * uy, k * uz, out)
    return 0


@njit(cache=True)
def flat_plate_srp_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`FlatPlateSRP`'s kernel (signature ``FORCE_KERNEL``), rigid bodies only.
    Parameters ``p = (ν P₀ AU², s_x, s_y, s_z)``; ``field`` holds 10 numbers per plate:
    area (m²), unit normal n_B (3), centre of pressure c_B (3, m), C_s, C_d, C_a. Writes the
    body-frame [L; f] (N·m, N). Returns 0."""
    ux, uy, uz = p[1] - g[0, 3], p[2] - g[1, 3], p[3] - g[2, 3]  # body → Sun, in N
    rho = math.sqrt(ux * ux + uy * uy + uz * uz)
    P = p[0] / (rho * rho)
    e = np.empty(3)
    for i in range(3):  # e_B = Rᵀ u/ρ
        e[i] = (g[0, i] * ux + g[1, i] * uy + g[2, i] * uz) / rho
    for i in range(6):
        out[i] = 0.0
    for k in range(field.shape[0] // 10):
        q = field[10 * k : 10 * k + 10]
        area, cs, cd = q[0], q[7], q[8]
        cos = q[1] * e[0] + q[2] * e[1] + q[3] * e[2]
        if cos <= 0.0:
            continue
        ke = -P * area * cos * (1.0 - cs)
        kn = -P * area * cos * 2.0 * (cs * cos + cd / 3.0)
        fx = ke * e[0] + kn * q[1]
        fy = ke * e[1] + kn * q[2]
        fz = ke * e[2] + kn * q[3]
        out[0] += q[5] * fz - q[6] * fy
        out[1] += q[6] * fx - q[4] * fz
        out[2] += q[4] * fy - q[5] * fx
        out[3] += fx
        out[4] += fy
        out[5] += fz
    return 0


@dataclass(frozen=True)
class Plate:
    """A flat surface of a body for :class:`FlatPlateSRP`.

    Parameters
    ----------
    area : float
        A (m²), > 0.
    normal_B : array_like, shape (3,)
        Outward unit normal in the body frame (``|n| = 1`` to 1e-9; not normalised for you).
        Only the side it points to is lit (a panel lit on both sides is two plates).
    specular, diffuse, absorbed : float
        The fractions C_s, C_d, C_a of the incoming light, each in [0, 1], summing to 1
        (to 1e-12).
    position_B : array_like, shape (3,)
        Centre of pressure from the centre of mass, body frame (m); default the origin.
    """

    area: float
    normal_B: Any
    specular: float
    diffuse: float
    absorbed: float
    position_B: Any = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "area", real_number(self.area, "Plate area (m²)", positive=True))
        n = real_vector(self.normal_B, "Plate normal_B", 3)
        if abs(float(np.linalg.norm(n)) - 1.0) > 1e-9:
            raise DefinitionError(
                f"Plate normal_B must be a unit vector (|n| = 1 to 1e-9); got |n| = "
                f"{float(np.linalg.norm(n))!r}"
            )
        n.setflags(write=False)
        object.__setattr__(self, "normal_B", n)
        c = real_vector(self.position_B, "Plate position_B (m)", 3)
        c.setflags(write=False)
        object.__setattr__(self, "position_B", c)
        coeffs = []
        for name in ("specular", "diffuse", "absorbed"):
            v = real_number(getattr(self, name), f"Plate {name} fraction", non_negative=True)
            if v > 1.0:
                raise DefinitionError(f"Plate {name} fraction must be in [0, 1]; got {v!r}")
            object.__setattr__(self, name, v)
            coeffs.append(v)
        if abs(sum(coeffs) - 1.0) > 1e-12:
            raise DefinitionError(
                "Plate specular + diffuse + absorbed must be 1 (to 1e-12); got "
                f"{coeffs[0]!r} + {coeffs[1]!r} + {coeffs[2]!r} = {sum(coeffs)!r}"
            )

    def packed(self) -> FloatArray:
        """The 10 numbers of the plate as :func:`flat_plate_srp_load` reads them."""
        return np.concatenate(
            [
                [self.area],
                self.normal_B,
                self.position_B,
                [self.specular, self.diffuse, self.absorbed],
            ]
        )


class _Illumination:
    """The Sun's position and the visible fraction of its disc at epoch + t, from the
    ephemerides and the occulters (shared by the two SRP models)."""

    def __init__(self, epoch: Epoch, centre: str, occulters: Any, pressure: float) -> None:
        if not isinstance(epoch, Epoch):
            raise DefinitionError(f"epoch must be a gmuk.environment.Epoch; got {epoch!r}")
        self.epoch = epoch
        self.centre = _body(centre, "centre")
        if self.centre == "sun":
            raise DefinitionError("solar radiation pressure needs a centre other than the Sun")
        occ = tuple(_body(o, "occulter") for o in check_sequence(occulters, "occulters"))
        if "sun" in occ or len(set(occ)) != len(occ):
            raise DefinitionError(
                f"occulters must be distinct among ('earth', 'moon'); got {occulters!r}"
            )
        self.occulters = occ
        self.pressure = real_number(pressure, "pressure at 1 au (N/m²)", positive=True)

    def at(self, t: float, r_N: FloatArray) -> tuple[FloatArray, float]:
        """(s_N, ν): the Sun's position (m) and the visible fraction at r_N, time t."""
        e = self.epoch + t
        s = position("sun", e, self.centre)
        nu = 1.0
        for o in self.occulters:
            o_N = position(o, e, self.centre)
            f = float(fraction_at(r_N, s, o_N, RADIUS["sun"], RADIUS[o]))
            if f < 0.0:
                raise DomainError(
                    f"solar radiation pressure: r_N = {np.asarray(r_N).tolist()} m is inside "
                    f"the {o} at t = {t!r} s"
                )
            nu *= f
        return s, nu


def _casadi_illumination(model: Any, t: Any, r_N: Any) -> tuple[Any, Any]:
    """(s_N as CasADi DM, ν as a CasADi expression of r_N) at a numeric time t: the
    symbolic form of :meth:`_Illumination.at` (:func:`~gmuk.environment.shadow.casadi_fraction`
    per occulter). A DefinitionError for a symbolic t."""
    ca = casadi()
    if isinstance(t, (ca.SX, ca.MX)):
        raise DefinitionError(
            f"{model.name}: the symbolic (CasADi) form of {type(model).__name__} takes numeric "
            "times only (the Sun and the occulters are ERFA's series at epoch + t); "
            "gmuk.optimize then transcribes element by element with the nodes' times"
        )
    ill = model.illumination
    e = ill.epoch + float(t)
    s = ca.DM(position("sun", e, ill.centre))
    nu = 1.0
    for o in ill.occulters:
        o_N = ca.DM(position(o, e, ill.centre))
        nu = nu * casadi_fraction(r_N, s, o_N, RADIUS["sun"], RADIUS[o])
    return s, nu


class CannonballSRP(ForceModel):
    """Solar radiation pressure on a sphere ("cannonball"): ``f = −ν P C_R A e``.

    Parameters
    ----------
    epoch : Epoch
        The instant of t = 0 (t in TDB seconds).
    area : float
        Cross-section A (m²).
    C_R : float
        Reflectivity coefficient, in [1, 2] (1: absorber, 2: mirror).
    occulters : sequence of {"earth", "moon"}
        Bodies whose conical shadow is taken into account (default both; ``()`` for none).
    centre : {"earth", "moon"}
        The central body at N's origin (ICRF-aligned axes).
    pressure : float
        P₀ at 1 au (N/m²), default :data:`SOLAR_PRESSURE_1AU`.
    bodies : sequence, optional
    modeled : bool

    Notes
    -----
    The force acts at the centre of mass (no torque) of rigid bodies and point masses alike.

    References
    ----------
    Montenbruck & Gill (2000), Eq. 3.76.
    """

    _forms = Forms(compiled=_SRP_COMPILED, symbolic=True)

    def __init__(
        self,
        epoch: Epoch,
        area: float,
        C_R: float,
        *,
        occulters: Sequence[str] = ("earth", "moon"),
        centre: str = "earth",
        pressure: float = SOLAR_PRESSURE_1AU,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.illumination = _Illumination(epoch, centre, occulters, pressure)
        self.area = real_number(area, "area (m²)", positive=True)
        self.C_R = real_number(C_R, "C_R", positive=True)
        if not 1.0 <= self.C_R <= 2.0:
            raise DefinitionError(f"C_R must be in [1, 2]; got {C_R!r}")

    def _params(self, t: float, r_N: FloatArray) -> tuple[float, ...]:
        s, nu = self.illumination.at(t, r_N)
        k = nu * self.illumination.pressure * AU * AU * self.C_R * self.area
        return (k, float(s[0]), float(s[1]), float(s[2]))

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[0; f_B] (N·m, N) (:func:`cannonball_srp_load`)."""
        p = self._params(t, np.asarray(g_NB, dtype=float)[:3, 3])
        return call_load(cannonball_srp_load, True, t, g_NB, V_B, body, p, None, self.name)

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """f_N (N) (:func:`cannonball_srp_load`)."""
        p = self._params(t, np.asarray(r_N, dtype=float))
        return call_load(cannonball_srp_load, False, t, r_N, v_N, body, p, None, self.name)

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force` at a numeric time t (CasADi, 3×1, N):
        :func:`cannonball_srp_load`'s ``k (r − s)/ρ³`` with the shadow of
        :func:`~gmuk.environment.shadow.casadi_fraction`. A DefinitionError for a symbolic t."""
        ca = casadi()
        s, nu = _casadi_illumination(self, t, r_N)
        k = self.illumination.pressure * AU * AU * self.C_R * self.area
        rho = ca.norm_2(r_N - s)
        return (k * nu / (rho * rho * rho)) * (r_N - s)

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` (CasADi, 6×1): ``[0; Rᵀ f_N]``."""
        ca = casadi()
        f_N = CannonballSRP.casadi_force(self, t, g_NB[:3, 3], None, body)
        return ca.vertcat(ca.DM.zeros(3, 1), g_NB[:3, :3].T @ f_N)


class FlatPlateSRP(ForceModel):
    """Solar radiation pressure on a body made of flat plates: force and torque about the
    centre of mass, body frame.

    Parameters
    ----------
    epoch : Epoch
        The instant of t = 0 (t in TDB seconds).
    plates : sequence of Plate
        The body's lit surfaces (area, normal, centre of pressure, optical fractions).
    occulters, centre, pressure, bodies, modeled
        As :class:`CannonballSRP`.

    Notes
    -----
    Rigid bodies only (the force depends on the attitude). Each plate is lit or not by the
    sign of n·e; plates do not shadow each other.

    References
    ----------
    Montenbruck & Gill (2000), §3.4.1, Eq. 3.75; Vallado (2013), §8.6.4.
    """

    _forms = Forms(compiled=_SRP_COMPILED, symbolic=True)

    def __init__(
        self,
        epoch: Epoch,
        plates: Sequence[Plate],
        *,
        occulters: Sequence[str] = ("earth", "moon"),
        centre: str = "earth",
        pressure: float = SOLAR_PRESSURE_1AU,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.illumination = _Illumination(epoch, centre, occulters, pressure)
        plates = check_sequence(plates, "plates")
        if not plates or not all(isinstance(p, Plate) for p in plates):
            raise DefinitionError(
                f"plates must be a non-empty sequence of gmuk.environment.Plate; got {plates!r}"
            )
        self.plates = tuple(plates)
        data = np.concatenate([p.packed() for p in self.plates])
        data.setflags(write=False)
        self._data = data

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L; f] in the body frame (N·m, N) (:func:`flat_plate_srp_load`)."""
        s, nu = self.illumination.at(t, np.asarray(g_NB, dtype=float)[:3, 3])
        k = nu * self.illumination.pressure * AU * AU
        p = (k, float(s[0]), float(s[1]), float(s[2]))
        return call_load(flat_plate_srp_load, True, t, g_NB, V_B, body, p, self._data, self.name)

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` at a numeric time t (CasADi, 6×1; N·m, N):
        :func:`flat_plate_srp_load`'s sum over the lit plates (``if_else`` on n·e > 0) with
        the shadow of :func:`~gmuk.environment.shadow.casadi_fraction`. A DefinitionError for
        a symbolic t."""
        ca = casadi()
        R, r = g_NB[:3, :3], g_NB[:3, 3]
        s, nu = _casadi_illumination(self, t, r)
        u = s - r
        rho = ca.norm_2(u)
        e = R.T @ (u / rho)
        P = nu * self.illumination.pressure * AU * AU / (rho * rho)
        L, F = ca.DM.zeros(3, 1), ca.DM.zeros(3, 1)
        for plate in self.plates:
            n, c = ca.DM(plate.normal_B), ca.DM(plate.position_B)
            cos = ca.dot(n, e)
            f = (-P * plate.area * cos) * (
                (1.0 - plate.specular) * e + 2.0 * (plate.specular * cos + plate.diffuse / 3.0) * n
            )
            f = ca.if_else(cos > 0.0, f, ca.DM.zeros(3, 1))
            L = L + ca.cross(c, f)
            F = F + f
        return ca.vertcat(L, F)
