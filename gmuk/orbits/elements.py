"""Classical orbital elements ↔ inertial position and velocity, for every conic.

Elements are ``(p, e, i, Ω, ω, ν)``: semi-latus rectum ``p`` (m), eccentricity ``e``,
inclination ``i ∈ [0, π]``, right ascension of the ascending node ``Ω``, argument of
periapsis ``ω`` and true anomaly ``ν`` (rad). The semi-latus rectum is the size parameter
used internally because it is finite and positive for every conic (``a = p/(1 − e²)`` is
infinite for a parabola and negative for a hyperbola). :func:`elements_to_state` accepts
either ``a`` or ``p``.

The perifocal frame P has axis 1 towards periapsis, axis 3 along the angular momentum;
``R_NP = R₃(Ω) R₁(i) R₃(ω)`` maps P components to the inertial frame N (McCann 2020,
Section 4.1.2: "the 3-1-3 Euler angle rotation matrix from the perifocal frame to the
inertial frame").

Conventions for the special cases (:func:`state_to_elements`)
-------------------------------------------------------------
An element that is undefined is set to 0 and the angle it would have carried moves into
the next one, so that ``elements_to_state(state_to_elements(r, v))`` always gives back
``(r, v)``:

* **equatorial** (``sin i < EQUATORIAL_TOL``; prograde i = 0 or retrograde i = π): no node
  line, ``Ω = 0``; ω is then the longitude of periapsis, measured from the N₁ axis about
  the angular momentum.
* **circular** (``e < CIRCULAR_TOL``): no periapsis, ``ω = 0``; ν is then the argument of
  latitude u (from the ascending node).
* **circular and equatorial**: ``Ω = ω = 0``; ν is the true longitude (from N₁, measured
  about the angular momentum).

Angles are returned in ``[0, 2π)`` (i in ``[0, π]``). For parabolas and hyperbolas ν lies
in ``(−ν∞, ν∞)``, ``ν∞ = arccos(−1/e)`` (negative before periapsis).

References
----------
Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed. (2013), Ch. 2,
Algorithms 9 (RV2COE) and 10 (COE2RV); Curtis, *Orbital Mechanics for Engineering
Students*, 3rd ed. (2014), Algorithms 4.2 and 4.5. McCann (2020), Eqs. (69)–(70).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from gmuk._validation import FloatArray, as_array
from gmuk.errors import OrbitError

__all__ = [
    "CIRCULAR_TOL",
    "EQUATORIAL_TOL",
    "R_NP",
    "OrbitalElements",
    "elements_to_state",
    "perifocal_state",
    "semi_latus_rectum",
    "state_to_elements",
]

#: Below this eccentricity :func:`state_to_elements` treats the orbit as circular.
CIRCULAR_TOL = 1e-11
#: Below this sin(i) (rad) :func:`state_to_elements` treats the orbit as equatorial.
EQUATORIAL_TOL = 1e-11

_TWO_PI = 2.0 * np.pi


class OrbitalElements(NamedTuple):
    """Classical orbital elements (arrays of a common broadcast shape).

    Attributes
    ----------
    p : ndarray
        Semi-latus rectum (m), > 0.
    e : ndarray
        Eccentricity, ≥ 0 (``< 1`` ellipse, ``= 1`` parabola, ``> 1`` hyperbola).
    i : ndarray
        Inclination (rad), in ``[0, π]``.
    raan : ndarray
        Right ascension of the ascending node Ω (rad), ``[0, 2π)``.
    argp : ndarray
        Argument of periapsis ω (rad), ``[0, 2π)``.
    nu : ndarray
        True anomaly ν (rad); see the module notes for circular/equatorial orbits.
    """

    p: FloatArray
    e: FloatArray
    i: FloatArray
    raan: FloatArray
    argp: FloatArray
    nu: FloatArray

    @property
    def a(self) -> FloatArray:
        """Semi-major axis ``p / (1 − e²)`` (m): ``+∞`` for a parabola, < 0 for a hyperbola."""
        den = (1.0 - self.e) * (1.0 + self.e)
        with np.errstate(divide="ignore"):
            return np.where(den == 0.0, np.inf, self.p / np.where(den == 0.0, 1.0, den))


def _positive(x: Any, name: str, unit: str) -> FloatArray:
    x = as_array(x, (), name)
    if (x <= 0.0).any():
        raise OrbitError(f"{name} must be > 0 ({unit}); got {float(x[x <= 0.0].flat[0])!r}")
    return x


def _eccentricity(e: Any) -> FloatArray:
    e = as_array(e, (), "e")
    if (e < 0.0).any():
        raise OrbitError(f"e must be ≥ 0; got e = {float(e[e < 0.0].flat[0])!r}")
    return e


def _inclination(i: Any) -> FloatArray:
    i = as_array(i, (), "i")
    bad = (i < 0.0) | (i > np.pi)
    if bad.any():
        raise OrbitError(
            "i must lie in [0, π] rad (a negative inclination is i → −i with Ω → Ω + π); "
            f"got i = {float(i[bad].flat[0])!r}"
        )
    return i


def semi_latus_rectum(a: Any | None, e: Any, p: Any | None = None) -> tuple[FloatArray, FloatArray]:
    """Check a conic's size and shape parameters and return ``(p, e)``.

    Give exactly one of ``a`` and ``p``. With ``a``: ``a > 0`` requires ``e < 1``
    (ellipse), ``a < 0`` requires ``e > 1`` (hyperbola), and a parabola (``e = 1``) must be
    given by ``p``; then ``p = a (1 − e²)``.

    Parameters
    ----------
    a : array_like or None
        Semi-major axis (m).
    e : array_like
        Eccentricity, ≥ 0.
    p : array_like or None
        Semi-latus rectum (m), > 0.

    Returns
    -------
    p, e : ndarray
        Broadcast to a common shape.

    Raises
    ------
    OrbitError
        If both or neither of a, p are given, or they do not fit the conic of ``e``.
    NonFiniteError
        If an input is NaN or infinite.
    """
    e = _eccentricity(e)
    if (a is None) == (p is None):
        raise OrbitError(
            "give exactly one of the semi-major axis a and the semi-latus rectum p; got "
            + ("both" if a is not None else "neither")
        )
    if p is not None:
        pp = _positive(p, "p", "m")
        pp, e = np.broadcast_arrays(pp, e)
        return np.array(pp, dtype=np.float64), np.array(e, dtype=np.float64)
    aa = as_array(a, (), "a")
    aa, e = np.broadcast_arrays(aa, e)
    for mask, msg in (
        ((e < 1.0) & (aa <= 0.0), "an ellipse (e < 1) needs a > 0"),
        ((e > 1.0) & (aa >= 0.0), "a hyperbola (e > 1) needs a < 0"),
        (e == 1.0, "a parabola (e = 1) has no finite a: give p instead"),
    ):
        if mask.any():
            j = np.flatnonzero(mask.ravel())[0]
            raise OrbitError(
                f"{msg}; got a = {float(aa.ravel()[j])!r} m with e = {float(e.ravel()[j])!r}"
            )
    return aa * ((1.0 - e) * (1.0 + e)), np.array(e, dtype=np.float64)


def R_NP(raan: Any, i: Any, argp: Any) -> FloatArray:
    """Rotation from the perifocal frame P to the inertial frame N, ``R₃(Ω) R₁(i) R₃(ω)``.

    Columns are the perifocal axes (periapsis direction, 90° ahead in the orbit plane,
    angular momentum) in N.

    Parameters
    ----------
    raan, i, argp : array_like, broadcastable
        Ω, i, ω (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    References
    ----------
    McCann (2020), Section 4.1.2 (text below Eq. 70); Vallado (2013), Ch. 2 (the
    PQW → IJK transformation of COE2RV).
    """
    W = as_array(raan, (), "raan")
    inc = as_array(i, (), "i")
    w = as_array(argp, (), "argp")
    W, inc, w = np.broadcast_arrays(W, inc, w)
    cW, sW, ci, si, cw, sw = np.cos(W), np.sin(W), np.cos(inc), np.sin(inc), np.cos(w), np.sin(w)
    R = np.empty((*W.shape, 3, 3))
    R[..., 0, 0] = cW * cw - sW * sw * ci
    R[..., 0, 1] = -cW * sw - sW * cw * ci
    R[..., 0, 2] = sW * si
    R[..., 1, 0] = sW * cw + cW * sw * ci
    R[..., 1, 1] = -sW * sw + cW * cw * ci
    R[..., 1, 2] = -cW * si
    R[..., 2, 0] = sw * si
    R[..., 2, 1] = cw * si
    R[..., 2, 2] = ci
    return R


def _check_nu(nu: FloatArray, e: FloatArray) -> None:
    bad = (e >= 1.0) & ((1.0 + e * np.cos(nu) <= 0.0) | (np.abs(nu) >= np.pi))
    if bad.any():
        j = np.flatnonzero(bad.ravel())[0]
        ej = float(e.ravel()[j])
        raise OrbitError(
            f"true anomaly beyond the asymptote: an open conic (e = {ej!r}) needs "
            f"|ν| < arccos(−1/e) = {float(np.arccos(-1.0 / ej))!r} rad; "
            f"got ν = {float(nu.ravel()[j])!r}"
        )


def perifocal_state(p: Any, e: Any, nu: Any, mu: Any) -> tuple[FloatArray, FloatArray]:
    """Position and velocity in the perifocal frame P.

    ``r_P = p/(1 + e cos ν) [cos ν, sin ν, 0]``, ``v_P = √(μ/p) [−sin ν, e + cos ν, 0]``.
    The arguments broadcast together (scalars or arrays of one shape S).

    Parameters
    ----------
    p : array_like
        Semi-latus rectum (m), > 0.
    e : array_like
        Eccentricity, ≥ 0.
    nu : array_like
        True anomaly (rad); for ``e ≥ 1``, ``|ν| < arccos(−1/e)``.
    mu : array_like
        Gravitational parameter (m³/s²), > 0.

    Returns
    -------
    r_P, v_P : ndarray, shape (..., 3)
        m and m/s, in P.

    Raises
    ------
    OrbitError
        When the state overflows float64 (an eccentricity near 1e308, say).

    References
    ----------
    McCann (2020), Eq. (69) (``r_{d/P}``, with ``h²/μ = p``); Vallado (2013), Algorithm 10.
    """
    p = _positive(p, "p", "m")
    e = _eccentricity(e)
    nu = as_array(nu, (), "nu")
    mu = _positive(mu, "mu", "m³/s²")
    p, e, nu, mu = np.broadcast_arrays(p, e, nu, mu)
    _check_nu(nu, e)
    c, s = np.cos(nu), np.sin(nu)
    with np.errstate(over="ignore", invalid="ignore"):  # checked below, with a clear error
        r = p / (1.0 + e * c)
        k = np.sqrt(mu / p)
        zero = np.zeros_like(r)
        r_P = np.stack([r * c, r * s, zero], axis=-1)
        v_P = np.stack([-k * s, k * (e + c), zero], axis=-1)
    if not (np.isfinite(r_P).all() and np.isfinite(v_P).all()):
        raise OrbitError(
            "the perifocal state is not finite in float64 (p, e, ν, μ too large or too "
            "small for one another)"
        )
    return r_P, v_P


def elements_to_state(
    a: Any | None,
    e: Any,
    i: Any,
    raan: Any,
    argp: Any,
    nu: Any,
    mu: Any,
    *,
    p: Any | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Inertial position and velocity from classical orbital elements (any conic).

    Parameters
    ----------
    a : array_like or None
        Semi-major axis (m): > 0 for an ellipse, < 0 for a hyperbola. Pass ``None`` and
        give ``p`` instead (required for a parabola).
    e : array_like
        Eccentricity, ≥ 0.
    i : array_like
        Inclination (rad), in ``[0, π]``.
    raan : array_like
        Right ascension of the ascending node Ω (rad).
    argp : array_like
        Argument of periapsis ω (rad).
    nu : array_like
        True anomaly (rad); for an open conic ``|ν| < arccos(−1/e)``. For circular or
        equatorial orbits pass the angle described in the module notes (argument of
        latitude, true longitude) with ω and/or Ω set to 0.
    mu : array_like
        Gravitational parameter of the central body (m³/s²), > 0.
    p : array_like, optional, keyword-only
        Semi-latus rectum (m), > 0, instead of ``a``.

    All arguments broadcast together.

    Returns
    -------
    r_N, v_N : ndarray, shape (..., 3)
        Position (m) and velocity (m/s) in the inertial frame N.

    Raises
    ------
    OrbitError
        For e < 0, a and p both or neither given, a of the wrong sign for the conic, an
        inclination outside [0, π], a non-positive μ or p, or ν beyond an asymptote.
    NonFiniteError
        If an input is NaN or infinite.

    References
    ----------
    McCann (2020), Eqs. (69)–(70); Vallado (2013), Algorithm 10 (COE2RV).
    """
    pp, ee = semi_latus_rectum(a, e, p)
    inc = _inclination(i)
    r_P, v_P = perifocal_state(pp, ee, nu, mu)
    R = R_NP(raan, inc, argp)
    return (R @ r_P[..., None])[..., 0], (R @ v_P[..., None])[..., 0]


def _unit(x: FloatArray) -> FloatArray:
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _angle_about(u: FloatArray, w: FloatArray, axis: FloatArray) -> FloatArray:
    """Angle from unit vector u to vector w, measured positively about the unit ``axis``."""
    return np.arctan2(np.einsum("...k,...k", axis, np.cross(u, w)), np.einsum("...k,...k", u, w))


def state_to_elements(r_N: Any, v_N: Any, mu: Any) -> OrbitalElements:
    """Classical orbital elements from inertial position and velocity (any conic).

    Parameters
    ----------
    r_N : array_like, shape (..., 3)
        Position relative to the central body (m), in N.
    v_N : array_like, shape (..., 3)
        Velocity (m/s), in N.
    mu : array_like, broadcastable to r_N.shape[:-1]
        Gravitational parameter (m³/s²), > 0.

    Returns
    -------
    OrbitalElements
        ``p = h²/μ``, ``e = |e_vec|`` with ``e_vec = ((v² − μ/r) r − (r·v) v)/μ``, and the
        angles, with the conventions of the module notes for circular (``e < CIRCULAR_TOL``)
        and equatorial (``sin i < EQUATORIAL_TOL``) orbits.

    Raises
    ------
    OrbitError
        If ``r = 0``, ``μ ≤ 0``, or ``r × v = 0`` (rectilinear motion has no orbit plane).
    ShapeError, NonFiniteError
        For arrays of the wrong shape or with NaN/inf.

    References
    ----------
    Vallado (2013), Algorithm 9 (RV2COE); Curtis (2014), Algorithm 4.2.
    """
    r = as_array(r_N, (3,), "r_N")
    v = as_array(v_N, (3,), "v_N")
    mu_a = _positive(mu, "mu", "m³/s²")
    r, v = np.broadcast_arrays(r, v)
    mu_a = np.broadcast_to(mu_a, r.shape[:-1])
    rn = np.linalg.norm(r, axis=-1)
    h = np.cross(r, v)
    hn = np.linalg.norm(h, axis=-1)
    if (rn == 0.0).any():
        raise OrbitError("r_N must be non-zero (the position relative to the central body)")
    if (hn <= 1e-14 * rn * np.linalg.norm(v, axis=-1)).any():
        raise OrbitError(
            "r_N and v_N are parallel (angular momentum r × v = 0): rectilinear motion has "
            "no orbital elements"
        )
    h_hat = h / hn[..., None]
    p = hn * hn / mu_a
    # Eccentricity vector (Vallado 2013, Algorithm 9).
    rv = np.einsum("...k,...k", r, v)
    vv = np.einsum("...k,...k", v, v)
    e_vec = ((vv - mu_a / rn)[..., None] * r - rv[..., None] * v) / mu_a[..., None]
    e = np.linalg.norm(e_vec, axis=-1)
    # Inclination from atan2 (accurate near 0 and π, unlike arccos).
    i = np.arctan2(np.hypot(h_hat[..., 0], h_hat[..., 1]), h_hat[..., 2])
    # Node vector n = N₃ × h; for equatorial orbits use N₁ and Ω = 0.
    n = np.stack([-h_hat[..., 1], h_hat[..., 0], np.zeros_like(hn)], axis=-1)
    nn = np.linalg.norm(n, axis=-1)
    equatorial = nn < EQUATORIAL_TOL
    n_hat = np.where(
        equatorial[..., None],
        np.array([1.0, 0.0, 0.0]),
        n / np.where(equatorial, 1.0, nn)[..., None],
    )
    raan = np.where(equatorial, 0.0, np.mod(np.arctan2(n_hat[..., 1], n_hat[..., 0]), _TWO_PI))
    circular = e < CIRCULAR_TOL
    e_hat = np.where(circular[..., None], n_hat, e_vec / np.where(circular, 1.0, e)[..., None])
    argp = np.where(circular, 0.0, np.mod(_angle_about(n_hat, e_hat, h_hat), _TWO_PI))
    nu = _angle_about(e_hat, r, h_hat)
    # Closed orbits: ν in [0, 2π). Open ones: ν in (−ν∞, ν∞), as returned by atan2.
    nu = np.where(e < 1.0, np.mod(nu, _TWO_PI), nu)
    nu = np.where(nu >= _TWO_PI, 0.0, nu)
    raan = np.where(raan >= _TWO_PI, 0.0, raan)
    argp = np.where(argp >= _TWO_PI, 0.0, argp)
    return OrbitalElements(p=p, e=e, i=i, raan=raan, argp=argp, nu=nu)
