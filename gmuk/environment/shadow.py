"""Conical shadow of an occulting body: the fraction of the Sun's disc a point sees.

Seen from the point r, the Sun's disc has apparent radius ``a = asin(R_sun/|s − r|)``, the
occulter's ``b = asin(R_occ/|o − r|)``, and their centres are ``c`` apart (angle between
s − r and o − r). With the discs taken as plane circles of radii a and b at distance c
(Montenbruck & Gill 2000, §3.4.2):

* ``c ≥ a + b``: no overlap, fraction 1 (sunlight);
* ``c ≤ b − a``: the Sun hidden, fraction 0 (umbra);
* ``c ≤ a − b``: the occulter inside the Sun's disc, ``1 − b²/a²`` (antumbra);
* otherwise (penumbra), the overlap area ``A = a² acos(x/a) + b² acos((c − x)/b) − c y``
  with ``x = (c² + a² − b²)/(2c)``, ``y = √(a² − x²)``, and fraction ``1 − A/(π a²)``.

The same three angles give the eclipse event's signed margins (:func:`shadow_margin`):
``c − (a + b)`` (penumbra: positive in full sunlight) and ``c − (b − a)`` (umbra: positive
outside the umbra), smooth through entry and exit, where the fraction has kinks.

References
----------
Montenbruck, O. & Gill, E. (2000), *Satellite Orbits*, Springer, §3.4.2, Eqs. 3.85–3.87.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gmuk._numba import njit
from gmuk._validation import real_number, real_vector
from gmuk.environment.ephemeris import RADIUS
from gmuk.errors import DefinitionError, DomainError

__all__ = [
    "casadi_fraction",
    "margin_from_angles",
    "shadow_angles",
    "shadow_fraction",
    "shadow_margin",
]


@njit(cache=True)
def shadow_angles(r, s, o, R_sun, R_occ):  # type: ignore[no-untyped-def]
    """(a, b, c) (rad): the apparent radii of the Sun (centre s, radius R_sun) and of the
    occulter (centre o, radius R_occ) seen from r, and the angle between their centres; all
    positions (3,) in one frame (m). c is taken as ``atan2(|u × w|, u · w)``, accurate at any
    angle. Returns b = -1 when r is inside the occulter or the Sun (no defined view)."""
    ux, uy, uz = s[0] - r[0], s[1] - r[1], s[2] - r[2]
    wx, wy, wz = o[0] - r[0], o[1] - r[1], o[2] - r[2]
    du = math.sqrt(ux * ux + uy * uy + uz * uz)
    dw = math.sqrt(wx * wx + wy * wy + wz * wz)
    if du <= R_sun or dw <= R_occ:
        return 0.0, -1.0, 0.0
    a = math.asin(R_sun / du)
    b = math.asin(R_occ / dw)
    cx, cy, cz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
    c = math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), ux * wx + uy * wy + uz * wz)
    return a, b, c


@njit(cache=True)
def fraction_from_angles(a, b, c):  # type: ignore[no-untyped-def]
    """The fraction of the Sun's disc (apparent radius a) left visible by an occulter's disc
    (apparent radius b) whose centre is c away (rad; Montenbruck & Gill 2000, Eq. 3.87)."""
    if c >= a + b:
        return 1.0
    if c <= b - a:
        return 0.0
    if c <= a - b:
        return 1.0 - (b * b) / (a * a)
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = math.sqrt(max(a * a - x * x, 0.0))
    area = (
        a * a * math.acos(min(max(x / a, -1.0), 1.0))
        + b * b * math.acos(min(max((c - x) / b, -1.0), 1.0))
        - c * y
    )
    return 1.0 - area / (math.pi * a * a)


@njit(cache=True)
def fraction_at(r, s, o, R_sun, R_occ):  # type: ignore[no-untyped-def]
    """:func:`shadow_fraction`'s kernel: the fraction in [0, 1], or -1 for a point inside the
    occulter or the Sun."""
    a, b, c = shadow_angles(r, s, o, R_sun, R_occ)
    if b < 0.0:
        return -1.0
    return fraction_from_angles(a, b, c)


def casadi_fraction(r: Any, s: Any, o: Any, R_sun: float, R_occ: float) -> Any:
    """The symbolic (CasADi) form of :func:`fraction_at` for a point r (CasADi 3×1, m), the
    Sun at s and the occulter at o (3×1, m): the same angles and the same four cases, as
    ``if_else`` (the point is assumed outside both bodies)."""
    from gmuk._casadi import casadi

    ca = casadi()
    u, w = s - r, o - r
    a = ca.asin(R_sun / ca.norm_2(u))
    b = ca.asin(R_occ / ca.norm_2(w))
    c = ca.atan2(ca.norm_2(ca.cross(u, w)), ca.dot(u, w))
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = ca.sqrt(ca.fmax(a * a - x * x, 0.0))
    area = (
        a * a * ca.acos(ca.fmin(ca.fmax(x / a, -1.0), 1.0))
        + b * b * ca.acos(ca.fmin(ca.fmax((c - x) / b, -1.0), 1.0))
        - c * y
    )
    partial = 1.0 - area / (math.pi * a * a)
    inner = ca.if_else(c <= a - b, 1.0 - (b * b) / (a * a), partial)
    return ca.if_else(c >= a + b, 1.0, ca.if_else(c <= b - a, 0.0, inner))


def margin_from_angles(a: float, b: float, c: float, kind: str) -> float:
    """The signed margin (rad) of :func:`shadow_margin` from the angles of
    :func:`shadow_angles`: ``c − (b − a)`` (umbra) or ``c − (a + b)`` (penumbra)."""
    return float(c - (b - a) if kind == "umbra" else c - (a + b))


def _inputs(
    r_sat: Any, r_sun: Any, r_occulter: Any, R_occ: Any, R_sun: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
    r = real_vector(r_sat, "r_sat (m)", 3, error=DefinitionError)
    s = real_vector(r_sun, "r_sun (m)", 3, error=DefinitionError)
    o = real_vector(r_occulter, "r_occulter (m)", 3, error=DefinitionError)
    Ro = real_number(R_occ, "R_occ (occulter radius, m)", positive=True)
    Rs = real_number(R_sun, "R_sun (Sun radius, m)", positive=True)
    return r, s, o, Ro, Rs


def shadow_fraction(
    r_sat: Any, r_sun: Any, r_occulter: Any, R_occ: float, R_sun: float = RADIUS["sun"]
) -> float:
    """Fraction of the Sun's disc visible from ``r_sat`` past one spherical occulter.

    Parameters
    ----------
    r_sat, r_sun, r_occulter : array_like, shape (3,)
        Positions of the point, of the Sun's centre and of the occulter's centre (m), in any
        one frame.
    R_occ : float
        Occulter radius (m), e.g. ``gmuk.environment.RADIUS["earth"]``.
    R_sun : float
        Sun radius (m); default the IAU 2015 nominal 6.957e8.

    Returns
    -------
    float
        ν in [0, 1]: 1 in sunlight, 0 in the umbra, between in the penumbra (and in the
        antumbra, ``1 − b²/a²``). The solar radiation pressure is ν times its unshadowed
        value.

    Raises
    ------
    DefinitionError
        For positions that are not 3 finite numbers or radii that are not > 0.
    DomainError
        For a point inside the occulter or the Sun.

    Examples
    --------
    >>> from gmuk.environment import shadow_fraction
    >>> sun = [1.496e11, 0.0, 0.0]
    >>> shadow_fraction([-7.0e6, 0.0, 0.0], sun, [0.0, 0.0, 0.0], 6.378e6)  # behind the Earth
    0.0
    >>> shadow_fraction([0.0, 7.0e6, 0.0], sun, [0.0, 0.0, 0.0], 6.378e6)
    1.0

    References
    ----------
    Montenbruck & Gill (2000), §3.4.2.
    """
    r, s, o, Ro, Rs = _inputs(r_sat, r_sun, r_occulter, R_occ, R_sun)
    nu = float(fraction_at(r, s, o, Rs, Ro))
    if nu < 0.0:
        raise DomainError(
            f"shadow_fraction: r_sat = {r.tolist()} m is inside the occulter (radius {Ro} m "
            f"at {o.tolist()}) or the Sun; a shadow is defined outside both"
        )
    return nu


def shadow_margin(
    r_sat: Any,
    r_sun: Any,
    r_occulter: Any,
    R_occ: float,
    kind: str = "umbra",
    R_sun: float = RADIUS["sun"],
) -> float:
    """Signed angular margin (rad) to a shadow's boundary: ``c − (b − a)`` for the umbra,
    ``c − (a + b)`` for the penumbra (a, b, c of :func:`shadow_angles`). Positive outside
    the shadow, zero on its cone, negative inside; smooth where the fraction has kinks.
    Arguments as :func:`shadow_fraction`; ``kind`` is "umbra" or "penumbra"."""
    if kind not in ("umbra", "penumbra"):
        raise DefinitionError(f"kind must be 'umbra' or 'penumbra'; got {kind!r}")
    r, s, o, Ro, Rs = _inputs(r_sat, r_sun, r_occulter, R_occ, R_sun)
    a, b, c = shadow_angles(r, s, o, Rs, Ro)
    if b < 0.0:
        raise DomainError(
            f"shadow_margin: r_sat = {r.tolist()} m is inside the occulter or the Sun"
        )
    return margin_from_angles(a, b, c, kind)
