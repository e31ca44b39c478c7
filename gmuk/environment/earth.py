"""The Earth for Earth orbits: its constants and its gravity field at an epoch.

Constants (one definition each, in :mod:`gmuk.celestial`): GM = 3.986004415e14 m³/s² and
reference (equatorial) radius 6378136.3 m of EGM2008 (Pavlis et al. 2012), rotation rate
ω_E = 7.292115e-5 rad/s (IERS Conventions 2010, Table 1.1; WGS 84).

:func:`earth_gravity` gives the shipped EGM2008 field (to degree 70) as a
:class:`gmuk.SphericalHarmonicGravity` on bodies, with the Earth's body-fixed frame turning
uniformly about N's third axis at ω_E from its orientation at an epoch: the Earth Rotation
Angle θ(epoch) (IAU 2000, ``eraEra00``, UT1 taken as UTC: ``|UT1 − UTC| < 0.9 s``, i.e. under
6.6e-5 rad). Precession, nutation and polar motion are not modelled: N's axes are the GCRS's,
and the field's pole is N's third axis (the true pole is ~0.2° from it in the 2020s);
the rotation is uniform (``|ω_E − dθ/dt|`` = 1.5e-12 rad/s, 1.3e-7 rad a day).

References
----------
Pavlis, N. K. et al. (2012), *J. Geophys. Res.* 117, B04406 (EGM2008); Petit, G. & Luzum, B.
(eds.) (2010), IERS Conventions (2010), IERS Technical Note 36, §1.2 and §5.5.3 (ERA);
ERFA ``eraEra00``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import erfa

from gmuk.celestial import (
    EARTH_MU,
    EARTH_RADIUS,
    EARTH_ROTATION_RATE,
    CelestialBody,
    UniformRotation,
)
from gmuk.environment.time import Epoch
from gmuk.errors import DefinitionError
from gmuk.forces.gravity import SphericalHarmonicGravity

if TYPE_CHECKING:
    from gmuk.bodies import Body

__all__ = [
    "EARTH_MU",
    "EARTH_RADIUS",
    "EARTH_ROTATION_RATE",
    "earth_gravity",
    "earth_rotation",
    "earth_rotation_angle",
]


def earth_rotation_angle(epoch: Epoch) -> float:
    """The Earth Rotation Angle θ (rad, in [0, 2π)) at ``epoch``, with UT1 taken as UTC
    (IAU 2000, ``eraEra00``; error < 6.6e-5 rad from ``|UT1 − UTC| < 0.9 s``)."""
    if not isinstance(epoch, Epoch):
        raise DefinitionError(f"epoch must be a gmuk.environment.Epoch; got {epoch!r}")
    u1, u2 = epoch.jd("utc")
    return float(erfa.era00(u1, u2))


def earth_rotation(epoch: Epoch | None = None) -> UniformRotation:
    """The Earth's uniform rotation about N's third axis at ω_E, with angle θ(epoch) at
    t = 0 (:func:`earth_rotation_angle`), or 0 (F = N at t = 0) without an epoch."""
    angle = 0.0 if epoch is None else earth_rotation_angle(epoch)
    return UniformRotation(EARTH_ROTATION_RATE, angle)


def earth_gravity(
    degree: int | None = None,
    epoch: Epoch | None = None,
    *,
    finite_size_force: bool = True,
    bodies: Sequence[Body | str] | None = None,
    modeled: bool = True,
) -> SphericalHarmonicGravity:
    """The Earth's EGM2008 gravity (shipped to degree 70) on bodies orbiting it.

    Parameters
    ----------
    degree : int, optional
        Truncation degree, 0–70 (default 70). Degree 0 is the point mass μ/r.
    epoch : Epoch, optional
        The instant of t = 0: the field's frame starts at the Earth Rotation Angle of that
        instant (:func:`earth_rotation`); default F = N at t = 0.
    finite_size_force, bodies, modeled
        As :class:`gmuk.SphericalHarmonicGravity`.

    Returns
    -------
    SphericalHarmonicGravity
        With a compiled form on point masses (uniform rotation), a symbolic one for
        :mod:`gmuk.optimize`.

    Raises
    ------
    DegreeError
        For a degree outside 0–70.

    Examples
    --------
    >>> from gmuk.environment import Epoch, earth_gravity
    >>> g = earth_gravity(8, Epoch("2024-01-01T00:00:00"))
    >>> g.field.degree, g.central_body.name
    (8, 'Earth')

    References
    ----------
    Pavlis et al. (2012); IERS Conventions (2010).
    """
    from gmuk import gravity

    field = gravity.load("EGM2008", degree)
    earth = CelestialBody.earth(field=field, rotation=earth_rotation(epoch))
    return SphericalHarmonicGravity(
        earth, finite_size_force=finite_size_force, bodies=bodies, modeled=modeled
    )
