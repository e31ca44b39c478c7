"""Central bodies: gravitational parameter, reference radius, rotation, optional field.

The inertial frame N and the body-fixed frame F share their origin (the central body's
centre of mass). With the default uniform spin about the common third axis (McCann 2020,
Section 3.3, Eq. 61), ``R_NF(t) = R₃(η(t))`` with ``η(t) = η₀ + ω t``, so that
``r_F = R_FN r_N = R_NFᵀ r_N``; latitude and longitude follow from r_F (Eqs. 60, 62).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from gmuk._validation import FloatArray, as_array, real_number
from gmuk.errors import DefinitionError

__all__ = ["INERTIAL", "CelestialBody", "UniformRotation"]

#: Sidereal rotation rate of the Moon, 2π / 27.321661 d (rad/s): synchronous with its
#: sidereal month (IAU WGCCRE 2015 gives W = 13.17635815° per day).
MOON_ROTATION_RATE = 2.0 * math.pi / (27.321661 * 86400.0)
#: GM of the Moon used in McCann (2020), Chapter 3 (m³/s²).
MOON_MU_THESIS = 4.9028e12
#: Reference (mean) radius of the Moon used in McCann (2020) and in GRAIL fields (m).
MOON_RADIUS = 1.738e6
#: Earth: GM (EGM2008, m³/s²), reference radius (m), rotation rate (IERS, rad/s).
EARTH_MU = 3.986004415e14
EARTH_RADIUS = 6.3781363e6
EARTH_ROTATION_RATE = 7.292115e-5


@dataclass(frozen=True)
class UniformRotation:
    """Uniform spin of the body-fixed frame F about N's third axis.

    Parameters
    ----------
    rate : float
        ω (rad/s), positive counter-clockwise about axis 3.
    angle0 : float
        η₀ = η(0) (rad): F coincides with N at t = 0 when 0.
    """

    rate: float
    angle0: float = 0.0

    def __post_init__(self) -> None:
        # real numbers only: a bool, complex number, string or array is refused, not converted
        object.__setattr__(self, "rate", real_number(self.rate, "rotation rate"))
        object.__setattr__(self, "angle0", real_number(self.angle0, "rotation angle0"))

    def angle(self, t: Any) -> Any:
        """η(t) (rad)."""
        return self.angle0 + self.rate * np.asarray(t, dtype=float)

    def R_NF(self, t: Any) -> FloatArray:
        """Rotation taking F components to N components, shape (3, 3) or (k, 3, 3)."""
        if type(t) is float:  # one time (the integrator's hot path): no array arithmetic
            eta_f = self.angle0 + self.rate * t
            c1, s1 = math.cos(eta_f), math.sin(eta_f)
            return np.array(((c1, -s1, 0.0), (s1, c1, 0.0), (0.0, 0.0, 1.0)))
        eta = np.asarray(self.angle(t))
        c, s = np.cos(eta), np.sin(eta)
        R = np.zeros((*eta.shape, 3, 3))
        R[..., 0, 0] = R[..., 1, 1] = c
        R[..., 1, 0], R[..., 0, 1] = s, -s
        R[..., 2, 2] = 1.0
        return R

    def R_FN(self, t: Any) -> FloatArray:
        """Rotation taking N components to F components (Eq. 61's R_FN)."""
        if type(t) is float:
            eta_f = self.angle0 + self.rate * t
            c1, s1 = math.cos(eta_f), math.sin(eta_f)
            return np.array(((c1, s1, 0.0), (-s1, c1, 0.0), (0.0, 0.0, 1.0)))
        return np.swapaxes(self.R_NF(t), -1, -2)


#: No rotation: the body-fixed frame is inertial (an explicit choice).
INERTIAL = UniformRotation(0.0)


class CelestialBody:
    """A central body at the origin of N.

    Parameters
    ----------
    name : str
    mu : float, optional
        GM (m³/s²). Taken from ``field`` when a field is given (then it must be omitted or
        equal: one model's coefficients are never mixed with another's GM).
    radius : float, optional
        Reference radius (m); as ``mu`` with respect to the field.
    rotation : UniformRotation, optional
        Orientation of the body-fixed frame. Required when a field is given (pass
        :data:`INERTIAL` to state that the field does not rotate); default :data:`INERTIAL`
        without a field.
    field : SphericalHarmonicField, optional
        Gravity field in the body-fixed frame (anything with ``mu``, ``radius``,
        ``acceleration(r_F)`` and ``hessian(r_F)``).
    """

    def __init__(
        self,
        name: str,
        mu: float | None = None,
        radius: float | None = None,
        *,
        rotation: UniformRotation | None = None,
        field: Any = None,
    ) -> None:
        problems = []
        if field is not None:
            for label, given in (("mu", mu), ("radius", radius)):
                own = float(getattr(field, label))
                if given is not None and not math.isclose(float(given), own, rel_tol=1e-15):
                    problems.append(
                        f"{label}={given!r} differs from the field's {label} "
                        f"{own!r}; a field's coefficients go with its own {label}"
                    )
            mu, radius = float(field.mu), float(field.radius)
            if rotation is None:
                problems.append(
                    "a field needs a rotation model: pass rotation="
                    "gmuk.UniformRotation(rate) or rotation=gmuk.INERTIAL (also in "
                    "gmuk.celestial) explicitly"
                )
        if not isinstance(name, str) or not name:
            problems.append(f"name must be a non-empty string; got {name!r}")
        for label, given, what in (
            ("mu", mu, "mu must be a finite GM > 0 (m³/s²)"),
            ("radius", radius, "radius must be a finite number > 0 (m)"),
        ):
            try:
                real_number(given, label, positive=True)
            except DefinitionError:
                problems.append(f"{what}; got {given!r}")
        if rotation is not None and not isinstance(rotation, UniformRotation):
            problems.append(f"rotation must be a UniformRotation; got {type(rotation).__name__}")
        if problems:
            raise DefinitionError([f"CelestialBody {name!r}: {p}" for p in problems])
        self.name = name
        self.mu = float(mu)  # type: ignore[arg-type]
        self.radius = float(radius)  # type: ignore[arg-type]
        self.rotation = INERTIAL if rotation is None else rotation
        self.field = field

    @classmethod
    def moon(
        cls, field: Any = None, *, mu: float | None = None, rotation: UniformRotation | None = None
    ) -> CelestialBody:
        """The Moon with McCann (2020)'s constants (GM 4.9028e12 m³/s², radius 1738 km),
        spinning at its sidereal rate with F = N at t = 0 (η(0) = 0).

        With a ``field``, GM and radius are the field's own (``moon(field=f).mu == f.mu``);
        ``mu`` overrides the thesis GM only without a field.
        """
        rot = rotation if rotation is not None else UniformRotation(MOON_ROTATION_RATE)
        if field is not None:
            return cls("Moon", mu, None, rotation=rot, field=field)
        return cls("Moon", MOON_MU_THESIS if mu is None else mu, MOON_RADIUS, rotation=rot)

    @classmethod
    def earth(cls, field: Any = None, *, rotation: UniformRotation | None = None) -> CelestialBody:
        """The Earth (EGM2008 GM and radius; IERS rotation rate, F = N at t = 0)."""
        rot = rotation if rotation is not None else UniformRotation(EARTH_ROTATION_RATE)
        if field is not None:
            return cls("Earth", None, None, rotation=rot, field=field)
        return cls("Earth", EARTH_MU, EARTH_RADIUS, rotation=rot)

    def to_fixed(self, t: Any, r_N: Any) -> FloatArray:
        """Body-fixed position r_F = R_FN(t) r_N (m); r_N (3,) or (k, 3) with t scalar or (k,)."""
        r = as_array(r_N, (3,), "r_N")
        return (self.rotation.R_FN(t) @ r[..., None])[..., 0]

    def latitude_longitude(self, t: Any, r_N: Any) -> tuple[FloatArray, FloatArray]:
        """Latitude θ ∈ [−π/2, π/2] and longitude φ ∈ (−π, π] (rad), Eqs. 60 and 62."""
        rF = self.to_fixed(t, r_N)
        lat = np.arctan2(rF[..., 2], np.hypot(rF[..., 0], rF[..., 1]))
        lon = np.arctan2(rF[..., 1], rF[..., 0])
        return lat, lon

    def __repr__(self) -> str:
        f = "" if self.field is None else f", field degree {getattr(self.field, 'degree', '?')}"
        return (
            f"CelestialBody({self.name!r}, mu={self.mu:.10g}, radius={self.radius:.10g}, "
            f"rotation rate={self.rotation.rate:.6g} rad/s{f})"
        )
