"""Epochs and time scales: UTC, TAI, TT and TDB, through ERFA (pyerfa).

An :class:`Epoch` is one instant. It is read from an ISO string or a two-part Julian date in
any of the four scales and written back in any of them. Internally it is a two-part Julian
date in TDB (Barycentric Dynamical Time), the argument of the ephemerides and the time of
gmuk's dynamics: a simulation time ``t`` (s) is **TDB seconds since an epoch**, so the
instant of a state at time ``t`` is ``epoch + t`` and the time of an instant ``e`` in a run
that starts at ``epoch`` is ``e - epoch`` (s, TDB).

The conversions are ERFA's (the C re-implementation of the IAU SOFA library, by pyerfa):

* UTC ↔ TAI: ``eraUtctai``/``eraTaiutc`` with ERFA's leap-second table (TAI − UTC = 37 s
  since 2017-01-01). UTC days that contain a leap second are handled (``23:59:60``).
  For years past the table's validity ERFA warns (``ErfaWarning``, "dubious year"): a leap
  second announced after that table is unknown to it.
* TAI ↔ TT: TT = TAI + 32.184 s (``eraTaitt``).
* TT ↔ TDB: TDB − TT from ``eraDtdb`` (Fairhead & Bretagnon 1990's series, ~1.7 ms
  amplitude, geocentric: the observer's topocentric terms are zero), ``eraTttdb``/``eraTdbtt``.

References
----------
IAU SOFA Board, *SOFA Time Scale and Calendar Tools* (2021); Fairhead, L. & Bretagnon, P.
(1990), *A&A* 229, 240; Kerr, M. et al., pyerfa (https://github.com/liberfa/pyerfa).
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from typing import Any

import erfa

from gmuk._validation import real_number
from gmuk.errors import DefinitionError

__all__ = ["J2000", "SCALES", "Epoch"]

#: The time scales an Epoch reads and writes.
SCALES = ("utc", "tai", "tt", "tdb")
#: Seconds per day.
DAY = 86400.0
#: JD of J2000.0 (2000-01-01 12:00:00 TDB), the origin of :attr:`Epoch.tdb_seconds`.
J2000_JD = 2451545.0

_ISO = re.compile(
    r"^\s*(?P<y>[+-]?\d{4,})-(?P<mo>\d{2})-(?P<d>\d{2})"
    r"(?:[T ](?P<h>\d{2}):(?P<mi>\d{2})(?::(?P<s>\d{2}(?:\.\d*)?))?)?\s*(?:Z)?\s*$"
)


def _scale(scale: Any) -> str:
    if not isinstance(scale, str) or scale.lower() not in SCALES:
        raise DefinitionError(f"time scale must be one of {SCALES}; got {scale!r}")
    return scale.lower()


def _normalised(jd1: float, jd2: float) -> tuple[float, float]:
    """(jd1, jd2) with jd1 a half-integer (a midnight) and 0 ≤ jd2 < 1: the split that keeps
    the fraction of a day to ~1e-16 d (1e-11 s)."""
    whole = math.floor(jd1 - 0.5) + 0.5
    frac = (jd1 - whole) + jd2
    shift = math.floor(frac)
    return whole + shift, frac - shift


def _dtr(jd1: float, jd2: float) -> float:
    """TDB − TT (s) at a TT or TDB date (the two differ by ~2 ms, where the series changes
    by ~1e-13 s), geocentric (``eraDtdb`` with u = v = 0: no topocentric terms)."""
    return float(erfa.dtdb(jd1, jd2, 0.0, 0.0, 0.0, 0.0))


@functools.total_ordering
@dataclass(frozen=True, init=False)
class Epoch:
    """An instant, held as a two-part Julian date in TDB.

    Build it with :meth:`from_iso` or :meth:`from_jd` (or ``Epoch("2024-03-20T03:06:00",
    "utc")``); read it with :meth:`jd`, :meth:`iso`, :attr:`tdb_seconds`. Arithmetic is in
    TDB seconds: ``epoch + t`` is the instant t seconds (TDB) later, ``b - a`` the TDB
    seconds from a to b. Simulation times are TDB seconds since the run's epoch.

    Parameters
    ----------
    value : str or float or (float, float)
        An ISO 8601 date-time (``"2024-03-20T03:06:00.5"``, ``"2024-03-20 03:06"``,
        ``"2024-03-20"``) or a Julian date, whole or in two parts.
    scale : {"utc", "tai", "tt", "tdb"}
        The scale ``value`` is written in. Default ``"utc"``.

    Raises
    ------
    DefinitionError
        For an unknown scale, a string that is not an ISO date-time, an impossible date
        or non-finite Julian date.

    Examples
    --------
    >>> from gmuk.environment import Epoch
    >>> e = Epoch("2017-01-01T00:00:00", "utc")
    >>> e.iso("tai")
    '2017-01-01T00:00:37.000000'
    >>> (e + 60.0).iso("tdb")[:19]
    '2017-01-01T00:02:09'

    References
    ----------
    IAU SOFA, *Time Scale and Calendar Tools*; ERFA ``eraUtctai``, ``eraTaitt``,
    ``eraTttdb``, ``eraDtdb``.
    """

    jd1_tdb: float
    jd2_tdb: float

    def __init__(self, value: Any, scale: str = "utc") -> None:
        scale = _scale(scale)
        if isinstance(value, Epoch):
            jd1, jd2 = value.jd1_tdb, value.jd2_tdb
        else:
            if isinstance(value, str):
                a, b = _parse_iso(value, scale)
            elif isinstance(value, tuple) and len(value) == 2:
                a = real_number(value[0], "Julian date part 1")
                b = real_number(value[1], "Julian date part 2")
            else:
                a, b = real_number(value, "Julian date"), 0.0
            jd1, jd2 = _to_tdb(a, b, scale)
        jd1, jd2 = _normalised(jd1, jd2)
        object.__setattr__(self, "jd1_tdb", jd1)
        object.__setattr__(self, "jd2_tdb", jd2)

    @classmethod
    def from_iso(cls, text: str, scale: str = "utc") -> Epoch:
        """The instant written ``text`` (ISO 8601, e.g. ``"2024-03-20T03:06:00"``) in ``scale``."""
        if not isinstance(text, str):
            raise DefinitionError(f"an ISO date-time must be a string; got {text!r}")
        return cls(text, scale)

    @classmethod
    def from_jd(cls, jd1: float, jd2: float = 0.0, scale: str = "tdb") -> Epoch:
        """The instant of Julian date ``jd1 + jd2`` (days) in ``scale`` (default TDB)."""
        return cls((jd1, jd2), scale)

    @classmethod
    def from_tdb_seconds(cls, seconds: float) -> Epoch:
        """The instant ``seconds`` TDB seconds after J2000.0 (2000-01-01 12:00:00 TDB)."""
        s = real_number(seconds, "TDB seconds since J2000")
        return cls((J2000_JD, s / DAY), "tdb")

    # ------------------------------------------------------------------ reading

    def jd(self, scale: str = "tdb") -> tuple[float, float]:
        """The two-part Julian date (days) of this instant in ``scale``: (jd1, jd2), jd1 a
        midnight (half-integer) and 0 ≤ jd2 < 1 for TDB, ERFA's split for the others
        (UTC is ERFA's quasi-JD: a day with a leap second has 86401 s)."""
        scale = _scale(scale)
        tdb1, tdb2 = self.jd1_tdb, self.jd2_tdb
        if scale == "tdb":
            return tdb1, tdb2
        tt1, tt2 = erfa.tdbtt(tdb1, tdb2, _dtr(tdb1, tdb2))
        if scale == "tt":
            return _normalised(float(tt1), float(tt2))
        tai1, tai2 = erfa.tttai(tt1, tt2)
        if scale == "tai":
            return _normalised(float(tai1), float(tai2))
        u1, u2 = erfa.taiutc(tai1, tai2)
        return float(u1), float(u2)

    def iso(self, scale: str = "utc", decimals: int = 6) -> str:
        """ISO 8601 ``YYYY-MM-DDTHH:MM:SS.ffffff`` of this instant in ``scale``, rounded to
        ``decimals`` (0–9) decimals of a second."""
        if not isinstance(decimals, int) or isinstance(decimals, bool) or not 0 <= decimals <= 9:
            raise DefinitionError(f"decimals must be an int in 0..9; got {decimals!r}")
        scale = _scale(scale)
        d1, d2 = self.jd(scale)
        y, mo, d, hmsf = erfa.d2dtf(scale.upper(), decimals, d1, d2)
        h, mi, s, f = (int(hmsf[k]) for k in ("h", "m", "s", "f"))
        frac = f".{f:0{decimals}d}" if decimals else ""
        return f"{int(y):04d}-{int(mo):02d}-{int(d):02d}T{h:02d}:{mi:02d}:{s:02d}{frac}"

    @property
    def tdb_seconds(self) -> float:
        """TDB seconds since J2000.0 (2000-01-01 12:00:00 TDB), the ephemeris time of SPICE
        and of the JPL ephemerides (s)."""
        return ((self.jd1_tdb - J2000_JD) + self.jd2_tdb) * DAY

    def tdb_minus_tt(self) -> float:
        """TDB − TT at this instant (s), geocentric (``eraDtdb``; below 1.7 ms in size)."""
        return _dtr(self.jd1_tdb, self.jd2_tdb)

    # ------------------------------------------------------------------ arithmetic

    def __add__(self, seconds: Any) -> Epoch:
        """The instant ``seconds`` TDB seconds after this one."""
        if isinstance(seconds, Epoch):
            return NotImplemented
        s = real_number(seconds, "seconds added to an Epoch (TDB)")
        return Epoch((self.jd1_tdb, self.jd2_tdb + s / DAY), "tdb")

    def __sub__(self, other: Any) -> Any:
        """``later - earlier``: TDB seconds between two epochs (float); ``epoch - t``: the
        instant t TDB seconds before."""
        if isinstance(other, Epoch):
            return ((self.jd1_tdb - other.jd1_tdb) + (self.jd2_tdb - other.jd2_tdb)) * DAY
        return self + (-real_number(other, "seconds subtracted from an Epoch (TDB)"))

    def __lt__(self, other: Epoch) -> bool:
        if not isinstance(other, Epoch):
            return NotImplemented
        return (self - other) < 0.0

    def __repr__(self) -> str:
        return f"Epoch('{self.iso('tdb')}', 'tdb')"


def _parse_iso(text: str, scale: str) -> tuple[float, float]:
    m = _ISO.match(text)
    if m is None:
        raise DefinitionError(
            f"an epoch string must be ISO 8601, 'YYYY-MM-DD[THH:MM[:SS[.fff]]]'; got {text!r}"
        )
    y, mo, d = int(m["y"]), int(m["mo"]), int(m["d"])
    h, mi = int(m["h"] or 0), int(m["mi"] or 0)
    s = float(m["s"] or 0.0)
    try:
        jd1, jd2 = erfa.dtf2d(scale.upper(), y, mo, d, h, mi, s)
    except (ValueError, erfa.ErfaError) as exc:
        raise DefinitionError(f"{text!r} is not a valid {scale.upper()} date-time: {exc}") from None
    return float(jd1), float(jd2)


def _to_tdb(a: float, b: float, scale: str) -> tuple[float, float]:
    if scale == "tdb":
        return a, b
    if scale == "utc":
        a, b = erfa.utctai(a, b)
        scale = "tai"
    if scale == "tai":
        a, b = erfa.taitt(a, b)
    tt1, tt2 = float(a), float(b)
    tdb1, tdb2 = erfa.tttdb(tt1, tt2, _dtr(tt1, tt2))
    return float(tdb1), float(tdb2)


#: J2000.0 as an Epoch (2000-01-01 12:00:00 TDB).
J2000 = Epoch((J2000_JD, 0.0), "tdb")
