"""The space environment at an epoch: time scales, ephemerides, third bodies, solar radiation
pressure, drag, the Earth's gravity and the eclipse event.

Simulation time ``t`` (s) is **TDB seconds since an epoch**: a model built with an
:class:`Epoch` evaluates its ephemerides at ``epoch + t``. Positions are in metres on
ICRF-aligned axes (GCRS axes about the Earth), centred on the central body at N's origin.

* :class:`Epoch`: UTC, TAI, TT, TDB (ERFA), ISO strings and Julian dates.
* :func:`position`, :class:`Ephemeris`: the Sun, the Earth and the Moon (ERFA's ``epv00``
  and ``moon98``; accuracy against DE421 in :mod:`gmuk.environment.ephemeris`).
* :class:`ThirdBodyPerturbation`: tidal force (Battin's form) and, on rigid bodies, the
  third body's gravity-gradient torque.
* :class:`CannonballSRP`, :class:`FlatPlateSRP` with :class:`Plate`: solar radiation
  pressure with the conical shadow (:func:`shadow_fraction`) of the Earth and the Moon.
* :class:`AtmosphericDrag` with :class:`ExponentialAtmosphere` (Vallado's table).
* :func:`earth_gravity`: the shipped EGM2008 field, oriented at an epoch.
* :class:`EclipseEvent`: umbra or penumbra entry and exit, for :meth:`gmuk.System.simulate`.
"""

from gmuk.environment.drag import VALLADO_2013, AtmosphericDrag, ExponentialAtmosphere
from gmuk.environment.earth import (
    EARTH_MU,
    EARTH_RADIUS,
    EARTH_ROTATION_RATE,
    earth_gravity,
    earth_rotation,
    earth_rotation_angle,
)
from gmuk.environment.eclipse import EclipseEvent
from gmuk.environment.ephemeris import (
    AU,
    BODIES,
    MOON_ACCURACY,
    MU,
    RADIUS,
    SUN_ACCURACY,
    Ephemeris,
    position,
)
from gmuk.environment.shadow import shadow_fraction, shadow_margin
from gmuk.environment.srp import SOLAR_PRESSURE_1AU, CannonballSRP, FlatPlateSRP, Plate
from gmuk.environment.third_body import ThirdBodyPerturbation, tidal_acceleration
from gmuk.environment.time import J2000, SCALES, Epoch

__all__ = [
    "AU",
    "BODIES",
    "EARTH_MU",
    "EARTH_RADIUS",
    "EARTH_ROTATION_RATE",
    "J2000",
    "MOON_ACCURACY",
    "MU",
    "RADIUS",
    "SCALES",
    "SOLAR_PRESSURE_1AU",
    "SUN_ACCURACY",
    "VALLADO_2013",
    "AtmosphericDrag",
    "CannonballSRP",
    "EclipseEvent",
    "Ephemeris",
    "Epoch",
    "ExponentialAtmosphere",
    "FlatPlateSRP",
    "Plate",
    "ThirdBodyPerturbation",
    "earth_gravity",
    "earth_rotation",
    "earth_rotation_angle",
    "position",
    "shadow_fraction",
    "shadow_margin",
    "tidal_acceleration",
]
