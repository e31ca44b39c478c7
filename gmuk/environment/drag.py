"""Atmospheric drag: an exponential atmosphere that turns with the Earth, on cannonballs.

Density (:class:`ExponentialAtmosphere`): piecewise exponential in the altitude h above a
sphere of the Earth's equatorial radius, ``ρ(h) = ρ₀ exp(−(h − h₀)/H)`` with (h₀, ρ₀, H) the
band of the largest base altitude h₀ ≤ h in Vallado's table (below: :data:`VALLADO_2013`,
from the U.S. Standard Atmosphere 1976 below 25 km and CIRA-72 above, up to 1000 km; the
last band is used above 1000 km).

Force (:class:`AtmosphericDrag`): the atmosphere co-rotates with the Earth about N's third
axis at ω_E, so the body moves through it at ``v_rel = v − ω_E × r``, and

``f = −½ ρ(h) C_D A |v_rel| v_rel``

at the centre of mass (no torque), for point masses and rigid bodies.

References
----------
Vallado, D. A. (2013), *Fundamentals of Astrodynamics and Applications*, 4th ed.,
Microcosm Press, §8.6.2, Table 8-4 ("Exponential Atmospheric Model"); the same values in
Wertz (1978), *Spacecraft Attitude Determination and Control*, p. 820.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._casadi import casadi
from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, real_number
from gmuk.celestial import EARTH_RADIUS, EARTH_ROTATION_RATE
from gmuk.errors import DefinitionError, DomainError
from gmuk.forces.base import ForceModel, com_load

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody

__all__ = ["VALLADO_2013", "AtmosphericDrag", "ExponentialAtmosphere", "drag_load"]

#: Vallado (2013) Table 8-4: base altitude h₀ (km), nominal density ρ₀ (kg/m³), scale
#: height H (km).
VALLADO_2013 = (
    (0.0, 1.225, 7.249),
    (25.0, 3.899e-2, 6.349),
    (30.0, 1.774e-2, 6.682),
    (40.0, 3.972e-3, 7.554),
    (50.0, 1.057e-3, 8.382),
    (60.0, 3.206e-4, 7.714),
    (70.0, 8.770e-5, 6.549),
    (80.0, 1.905e-5, 5.799),
    (90.0, 3.396e-6, 5.382),
    (100.0, 5.297e-7, 5.877),
    (110.0, 9.661e-8, 7.263),
    (120.0, 2.438e-8, 9.473),
    (130.0, 8.484e-9, 12.636),
    (140.0, 3.845e-9, 16.149),
    (150.0, 2.070e-9, 22.523),
    (180.0, 5.464e-10, 29.740),
    (200.0, 2.789e-10, 37.105),
    (250.0, 7.248e-11, 45.546),
    (300.0, 2.418e-11, 53.628),
    (350.0, 9.518e-12, 53.298),
    (400.0, 3.725e-12, 58.515),
    (450.0, 1.585e-12, 60.828),
    (500.0, 6.967e-13, 63.822),
    (600.0, 1.454e-13, 71.835),
    (700.0, 3.614e-14, 88.667),
    (800.0, 1.170e-14, 124.64),
    (900.0, 5.245e-15, 181.05),
    (1000.0, 3.019e-15, 268.00),
)


@njit(cache=True)
def exponential_density(h, table):  # type: ignore[no-untyped-def]
    """ρ (kg/m³) at altitude h (m) from ``table``: 3 numbers per band, h₀ (m), ρ₀ (kg/m³),
    H (m), bands by increasing h₀, the first at 0. Returns -1 below the first band."""
    n = table.shape[0] // 3
    if not h >= table[0]:
        return -1.0
    k = 0
    while k + 1 < n and table[3 * (k + 1)] <= h:
        k += 1
    return table[3 * k + 1] * math.exp(-(h - table[3 * k]) / table[3 * k + 2])


@njit(cache=True)
def drag_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`AtmosphericDrag`'s kernel (signature ``FORCE_KERNEL``). Parameters
    ``p = (C_D A, ω_E, R_E)`` (m², rad/s, m); ``field`` the density table
    (:func:`exponential_density`). Force ``−½ ρ C_D A |v_rel| v_rel``, v_rel = v − ω_E ẑ × r,
    at the centre of mass (a rigid body's v = R V[3:]). Returns 0, or 1 below the table."""
    x, y, z = g[0, 3], g[1, 3], g[2, 3]
    if rigid:
        vx = g[0, 0] * V[3] + g[0, 1] * V[4] + g[0, 2] * V[5]
        vy = g[1, 0] * V[3] + g[1, 1] * V[4] + g[1, 2] * V[5]
        vz = g[2, 0] * V[3] + g[2, 1] * V[4] + g[2, 2] * V[5]
    else:
        vx, vy, vz = V[0], V[1], V[2]
    rho = exponential_density(math.sqrt(x * x + y * y + z * z) - p[2], field)
    if rho < 0.0:
        return 1
    wx, wy, wz = vx + p[1] * y, vy - p[1] * x, vz
    k = -0.5 * rho * p[0] * math.sqrt(wx * wx + wy * wy + wz * wz)
    com_load(rigid, g, k * wx, k * wy, k * wz, out)
    return 0


class ExponentialAtmosphere:
    """Piecewise exponential density ρ(h) (kg/m³) of the altitude h (m).

    Parameters
    ----------
    table : sequence of (h₀ km, ρ₀ kg/m³, H km)
        Bands by strictly increasing base altitude, the first at 0 km; default
        :data:`VALLADO_2013` (Vallado 2013, Table 8-4).

    Examples
    --------
    >>> from gmuk.environment import ExponentialAtmosphere
    >>> float(ExponentialAtmosphere().density(400e3))  # Vallado's ρ₀ at 400 km
    3.725e-12
    """

    def __init__(self, table: Sequence[Sequence[float]] = VALLADO_2013) -> None:
        rows = np.asarray(table, dtype=float)
        if rows.ndim != 2 or rows.shape[1] != 3 or rows.shape[0] < 1 or not np.isfinite(rows).all():
            raise DefinitionError(
                "an atmosphere table is rows (h0 km, rho0 kg/m³, H km) of finite numbers; got "
                f"shape {rows.shape}"
            )
        if rows[0, 0] != 0.0 or (np.diff(rows[:, 0]) <= 0).any() or (rows[:, 1:] <= 0).any():
            raise DefinitionError(
                "an atmosphere table starts at h0 = 0 km, with increasing h0 and rho0, H > 0"
            )
        data = (rows * [1e3, 1.0, 1e3]).ravel()
        data.setflags(write=False)
        self.table = tuple(tuple(float(v) for v in r) for r in rows)
        self._data = data

    def casadi_density(self, h: Any) -> Any:
        """ρ(h) (kg/m³) of a CasADi altitude h (m): the bands of :func:`exponential_density`
        as a chain of ``if_else`` (the band of the largest h₀ ≤ h; no check below 0 m)."""
        ca = casadi()
        d = self._data
        rho = d[1] * ca.exp(-(h - d[0]) / d[2])
        for k in range(1, d.shape[0] // 3):
            band = d[3 * k + 1] * ca.exp(-(h - d[3 * k]) / d[3 * k + 2])
            rho = ca.if_else(h >= d[3 * k], band, rho)
        return rho

    def density(self, h: Any) -> FloatArray:
        """ρ (kg/m³) at altitude h (m), scalar or array; a DomainError below 0 m."""
        hs = np.asarray(h, dtype=float)
        out = np.array([exponential_density(float(v), self._data) for v in hs.ravel()])
        if (out < 0).any() or not np.isfinite(hs).all():
            raise DomainError(f"the atmosphere's density needs finite altitudes >= 0 m; got {h!r}")
        return out.reshape(hs.shape)


class AtmosphericDrag(ForceModel):
    """Drag of a co-rotating exponential atmosphere on cannonballs: ``−½ ρ C_D A |v_rel| v_rel``.

    Parameters
    ----------
    C_D : float
        Drag coefficient (typically 2.0–2.4).
    area : float
        Cross-section A (m²).
    atmosphere : ExponentialAtmosphere, optional
        Default Vallado (2013)'s table.
    rotation_rate : float
        ω_E (rad/s) of the atmosphere about N's third axis; default the Earth's 7.292115e-5
        (IERS).
    radius : float
        R (m) of the sphere altitudes are measured from; default the Earth's equatorial
        6378136.3 (EGM2008).
    bodies : sequence, optional
    modeled : bool

    Notes
    -----
    The force acts at the centre of mass: no torque. N's third axis stands for the Earth's
    rotation axis (GCRS z; the true pole differs by precession and nutation, ~0.2° in the
    2020s, which changes v_rel by ~1e-3 of ω_E r). The ballistic coefficient is
    ``C_D A / m`` with each body's own mass.

    References
    ----------
    Vallado (2013), §8.6.2, Eq. 8-31 and Table 8-4.
    """

    _kernel = staticmethod(drag_load)
    _forms = Forms(compiled=True, symbolic=True)

    def __init__(
        self,
        C_D: float,
        area: float,
        *,
        atmosphere: ExponentialAtmosphere | None = None,
        rotation_rate: float = EARTH_ROTATION_RATE,
        radius: float = EARTH_RADIUS,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.C_D = real_number(C_D, "C_D", positive=True)
        self.area = real_number(area, "area (m²)", positive=True)
        atmosphere = ExponentialAtmosphere() if atmosphere is None else atmosphere
        if not isinstance(atmosphere, ExponentialAtmosphere):
            raise DefinitionError(
                f"atmosphere must be an ExponentialAtmosphere; got {atmosphere!r}"
            )
        self.atmosphere = atmosphere
        self.rotation_rate = real_number(rotation_rate, "rotation_rate (rad/s)")
        self.radius = real_number(radius, "radius (m)", positive=True)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[0; f_B] (N·m, N) (:func:`drag_load`)."""
        return self._kernel_load(True, t, g_NB, V_B, body)

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """f_N (N) (:func:`drag_load`)."""
        return self._kernel_load(False, t, r_N, v_N, body)

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force` (CasADi, 3×1, N): :func:`drag_load`'s formula
        with the density of :meth:`ExponentialAtmosphere.casadi_density`."""
        ca = casadi()
        h = ca.norm_2(r_N) - self.radius
        w = r_N[0] * self.rotation_rate
        v_rel = ca.vertcat(v_N[0] + self.rotation_rate * r_N[1], v_N[1] - w, v_N[2])
        k = -0.5 * self.C_D * self.area * self.atmosphere.casadi_density(h)
        return k * ca.norm_2(v_rel) * v_rel

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` (CasADi, 6×1): ``[0; Rᵀ f_N]`` with
        f_N = :meth:`casadi_force` at the centre of mass, v_N = R V_B[3:]."""
        ca = casadi()
        R = g_NB[:3, :3]
        f_N = AtmosphericDrag.casadi_force(self, t, g_NB[:3, 3], R @ V_B[3:], body)
        return ca.vertcat(ca.DM.zeros(3, 1), R.T @ f_N)

    def _kernel_params(self, body: Body) -> tuple[tuple[float, ...], Any]:
        return (self.C_D * self.area, self.rotation_rate, self.radius), self.atmosphere._data

    def _kernel_failure(self, status: int, t: float, g: FloatArray) -> Exception:
        h = float(np.linalg.norm(g[:3, 3])) - self.radius
        return DomainError(
            f"{self.name}: the atmosphere is defined at altitudes >= 0 m; got h = {h!r} m at "
            f"r_N = {g[:3, 3].tolist()} m, t = {t!r} s"
        )
