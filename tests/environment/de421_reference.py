"""DE421 positions of the Sun and the Moon, for the ephemeris accuracy of gmuk.environment.

Needs ``jplephem`` and ``de421`` (pip; not gmuk dependencies). As a script it prints the
largest distances of :func:`gmuk.environment.position`'s geocentric Sun and Moon from DE421's
over 1950–2050 (2001 epochs, TDB), the figures quoted as ``SUN_ACCURACY`` and
``MOON_ACCURACY`` in ``gmuk/environment/ephemeris.py``, and the reference values that
``tests/environment/test_ephemeris.py`` quotes::

    python tests/environment/de421_reference.py
"""

from __future__ import annotations

import numpy as np

from gmuk.environment import Epoch, position

KM = 1e3


def de421() -> object:
    """jplephem's Ephemeris of the de421 package (ICRF axes, km)."""
    import de421 as module
    from jplephem.ephem import Ephemeris

    return Ephemeris(module)


def geocentric(eph: object, body: str, jd1: float, jd2: float) -> np.ndarray:
    """DE421's geometric geocentric position of the "sun" or the "moon" (m, ICRF axes) at
    TDB Julian date jd1 + jd2."""
    moon = np.asarray(eph.position("moon", jd1, jd2), dtype=float).ravel() * KM  # type: ignore[attr-defined]
    if body == "moon":
        return moon
    emb = np.asarray(eph.position("earthmoon", jd1, jd2), dtype=float).ravel() * KM  # type: ignore[attr-defined]
    sun = np.asarray(eph.position("sun", jd1, jd2), dtype=float).ravel() * KM  # type: ignore[attr-defined]
    earth = emb - moon * eph.earth_share  # type: ignore[attr-defined]
    return sun - earth


def largest_errors(start: str = "1950-01-01", end: str = "2050-01-01", n: int = 2001) -> dict:
    """Largest distance (m) of gmuk's geocentric Sun and Moon from DE421's, n epochs."""
    eph = de421()
    a, b = Epoch(start, "tdb"), Epoch(end, "tdb")
    worst = {"sun": 0.0, "moon": 0.0}
    for s in np.linspace(0.0, b - a, n):
        e = a + float(s)
        for body in worst:
            d = np.linalg.norm(position(body, e) - geocentric(eph, body, e.jd1_tdb, e.jd2_tdb))
            worst[body] = max(worst[body], float(d))
    return worst


if __name__ == "__main__":
    print("largest distance from DE421, 1950-2050 (m):", largest_errors())
    eph = de421()
    for iso in ("2000-01-01T12:00:00", "2024-03-20T03:06:00", "2035-07-01T00:00:00"):
        e = Epoch(iso, "tdb")
        for body in ("sun", "moon"):
            r = geocentric(eph, body, e.jd1_tdb, e.jd2_tdb)
            print(iso, body, np.array2string(r, precision=17, separator=", "))
