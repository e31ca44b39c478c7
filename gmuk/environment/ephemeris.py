"""Positions of the Sun, the Earth and the Moon at an epoch, and the constants that go with them.

Geometric positions (no light time, no aberration: what the dynamics needs), in metres, on
ICRF-aligned axes (the GCRS for the geocentric ones), from ERFA's analytic series:

* the Earth about the Sun: ``eraEpv00`` (VSOP2000 fitted to DE405; ERFA's documentation
  gives 4.6 km maximum error in the heliocentric Earth over 1900–2100), so the geocentric
  Sun is minus that vector;
* the Moon about the Earth: ``eraMoon98`` (Meeus 1998, from ELP2000-82, light-time term
  left out).

Measured against JPL's DE421 (``python tests/environment/de421_reference.py``: 2001 epochs
1950–2050, largest distances 10.2 km for the Sun and 20.2 km for the Moon;
``tests/environment/test_ephemeris.py`` holds DE421 values it quotes and, when jplephem and
de421 are installed, the full comparison): the geocentric Sun within :data:`SUN_ACCURACY`
and the geocentric Moon within :data:`MOON_ACCURACY`.

References
----------
ERFA ``eraEpv00``, ``eraMoon98`` (IAU SOFA ``iauEpv00``, ``iauMoon98``); Meeus, J. (1998),
*Astronomical Algorithms*, 2nd ed., ch. 47; Folkner, W. M. et al. (2008), *The Planetary and
Lunar Ephemeris DE421*, JPL IOM 343R-08-003 (GMs below: DE421 / DE430, Folkner et al. 2014);
IAU 2012 Resolution B2 (the astronomical unit); IAU 2015 Resolution B3 (nominal solar radius).
"""

from __future__ import annotations

from typing import Any

import erfa
import numpy as np

from gmuk._validation import FloatArray
from gmuk.celestial import EARTH_MU, EARTH_RADIUS, MOON_RADIUS
from gmuk.environment.time import Epoch
from gmuk.errors import DefinitionError

__all__ = [
    "AU",
    "BODIES",
    "MOON_ACCURACY",
    "MU",
    "RADIUS",
    "SUN_ACCURACY",
    "Ephemeris",
    "position",
]

#: The astronomical unit (m), IAU 2012 Resolution B2.
AU = 1.495978707e11
#: GM (m³/s²): the Sun 1.32712440041939e20 (DE430, Folkner et al. 2014), the Moon
#: 4.902800066e12 (DE421/DE430), the Earth EGM2008's 3.986004415e14 (gmuk.celestial).
MU = {"sun": 1.32712440041939e20, "earth": EARTH_MU, "moon": 4.902800066e12}
#: Radii (m): the Sun's IAU 2015 nominal 6.957e8, the Earth's EGM2008 reference radius
#: (equatorial), the Moon's mean radius 1.738e6 (GRAIL fields' reference radius).
RADIUS = {"sun": 6.957e8, "earth": EARTH_RADIUS, "moon": MOON_RADIUS}
#: The bodies :func:`position` knows.
BODIES = ("sun", "earth", "moon")
#: Largest distance (m) of the geocentric Sun of :func:`position` from DE421's, 1950–2050
#: (``tests/environment/de421_reference.py``: 10.2 km).
SUN_ACCURACY = 1.1e4
#: Largest distance (m) of the geocentric Moon of :func:`position` from DE421's, 1950–2050
#: (``tests/environment/de421_reference.py``: 20.2 km).
MOON_ACCURACY = 2.1e4


def _body(name: Any, what: str) -> str:
    if not isinstance(name, str) or name.lower() not in BODIES:
        raise DefinitionError(f"{what} must be one of {BODIES}; got {name!r}")
    return name.lower()


def _geocentric(body: str, epoch: Epoch) -> FloatArray:
    """Geocentric position of ``body`` (m, GCRS axes) at ``epoch``."""
    if body == "earth":
        return np.zeros(3)
    if body == "sun":
        pvh, _ = erfa.epv00(epoch.jd1_tdb, epoch.jd2_tdb)  # TDB argument
        return np.asarray(-AU * pvh["p"], dtype=float)
    tt1, tt2 = epoch.jd("tt")  # eraMoon98 takes TT
    return np.asarray(AU * erfa.moon98(tt1, tt2)["p"], dtype=float)


def position(body: str, epoch: Epoch, centre: str = "earth") -> FloatArray:
    """Geometric position of ``body`` relative to ``centre`` at ``epoch`` (m, ICRF axes).

    Parameters
    ----------
    body, centre : {"sun", "earth", "moon"}
    epoch : Epoch

    Returns
    -------
    ndarray, shape (3,)
        r (m), on ICRF-aligned axes (GCRS axes for the geocentric positions).

    Raises
    ------
    DefinitionError
        For an unknown body or centre, or an epoch that is not an :class:`Epoch`.

    Notes
    -----
    Accuracy against DE421: see :data:`SUN_ACCURACY`, :data:`MOON_ACCURACY` (the Earth–Moon
    and Earth–Sun vectors; a Sun-from-Moon vector carries both errors).

    References
    ----------
    ERFA ``eraEpv00`` and ``eraMoon98``.
    """
    body, centre = _body(body, "body"), _body(centre, "centre")
    if not isinstance(epoch, Epoch):
        raise DefinitionError(f"epoch must be a gmuk.environment.Epoch; got {epoch!r}")
    return _geocentric(body, epoch) - _geocentric(centre, epoch)


class Ephemeris:
    """A body's position relative to a centre as a function of simulation time: t (s, TDB
    since ``epoch``) ↦ r (3,) m, ICRF-aligned axes.

    It is the ``ephemeris`` callable of time-dependent models (here and, e.g., the
    ``gmuk-thirdbody`` plugin's ``ThirdBodyGravity``).

    Parameters
    ----------
    body, centre : {"sun", "earth", "moon"}
    epoch : Epoch
        The instant of t = 0.

    Examples
    --------
    >>> from gmuk.environment import Epoch, Ephemeris
    >>> moon = Ephemeris("moon", Epoch("2024-01-01T00:00:00"))
    >>> 3.5e8 < float((moon(3600.0) ** 2).sum() ** 0.5) < 4.1e8
    True
    """

    def __init__(self, body: str, epoch: Epoch, centre: str = "earth") -> None:
        self.body = _body(body, "body")
        self.centre = _body(centre, "centre")
        if self.body == self.centre:
            raise DefinitionError(f"an Ephemeris needs a body other than its centre; got {body!r}")
        if not isinstance(epoch, Epoch):
            raise DefinitionError(f"epoch must be a gmuk.environment.Epoch; got {epoch!r}")
        self.epoch = epoch

    def __call__(self, t: float) -> FloatArray:
        """r (3,) m at simulation time t (TDB seconds since :attr:`epoch`)."""
        return position(self.body, self.epoch + t, self.centre)

    def __repr__(self) -> str:
        return f"Ephemeris({self.body!r}, {self.epoch!r}, centre={self.centre!r})"
