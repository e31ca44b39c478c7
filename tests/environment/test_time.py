"""gmuk.environment.Epoch: time scales, leap seconds, TDB − TT, arithmetic in TDB seconds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gmuk.environment import J2000, Epoch
from gmuk.errors import DefinitionError


def test_tai_minus_utc_steps_by_the_leap_second_of_2016_12_31():
    before = Epoch("2016-12-31T12:00:00", "utc")
    after = Epoch("2017-01-01T12:00:00", "utc")
    # TAI − UTC = 36 s before the leap second, 37 s after (IERS Bulletin C 52)
    assert before.iso("tai") == "2016-12-31T12:00:36.000000"
    assert after.iso("tai") == "2017-01-01T12:00:37.000000"
    # the UTC day with the leap second is 86401 s of TT long; in TDB seconds, plus the
    # change of TDB − TT over it
    drift = after.tdb_minus_tt() - before.tdb_minus_tt()
    assert after - before == pytest.approx(86401.0 + drift, abs=1e-6)


def test_the_leap_second_itself_is_an_instant_of_its_own():
    leap = Epoch("2016-12-31T23:59:60.5", "utc")
    assert leap.iso("utc") == "2016-12-31T23:59:60.500000"
    assert Epoch("2017-01-01T00:00:00", "utc") - leap == pytest.approx(0.5, abs=1e-6)


def test_tt_is_tai_plus_32_184_s():
    e = Epoch("2024-06-01T00:00:00", "tai")
    assert e.iso("tt") == "2024-06-01T00:00:32.184000"
    tai, tt = e.jd("tai"), e.jd("tt")
    assert ((tt[0] - tai[0]) + (tt[1] - tai[1])) * 86400.0 == pytest.approx(32.184, abs=1e-6)


def _usno_tdb_minus_tt(jd_tt: float) -> float:
    """TDB − TT (s) from Kaplan (2005), USNO Circular 179, Eq. 2.6: the seven largest terms
    of Fairhead & Bretagnon's series, good to 10 µs over 1600–2200 (independent of ERFA)."""
    T = (jd_tt - 2451545.0) / 36525.0
    return (
        0.001657 * math.sin(628.3076 * T + 6.2401)
        + 0.000022 * math.sin(575.3385 * T + 4.2970)
        + 0.000014 * math.sin(1256.6152 * T + 6.1969)
        + 0.000005 * math.sin(606.9777 * T + 4.0212)
        + 0.000005 * math.sin(52.9691 * T + 0.4444)
        + 0.000002 * math.sin(21.3299 * T + 5.5431)
        + 0.000010 * T * math.sin(628.3076 * T + 4.2490)
    )


@pytest.mark.parametrize("year", [1950, 1987, 2000, 2013, 2026, 2049])
def test_tdb_minus_tt_agrees_with_the_usno_series_to_10_microseconds(year):
    for month in (1, 4, 7, 10):
        e = Epoch(f"{year}-{month:02d}-15T06:00:00", "tt")
        tdb, tt = e.jd("tdb"), e.jd("tt")
        diff = ((tdb[0] - tt[0]) + (tdb[1] - tt[1])) * 86400.0
        assert diff == pytest.approx(e.tdb_minus_tt(), abs=1e-9)
        assert abs(diff - _usno_tdb_minus_tt(sum(tt))) < 1e-5


def test_j2000_is_noon_tdb_and_11_58_55_816_utc():
    assert J2000.tdb_seconds == 0.0
    assert J2000.iso("tdb") == "2000-01-01T12:00:00.000000"
    # J2000.0 in UTC (TT − UTC = 32.184 + 32 s then), up to TDB − TT at that instant
    utc = Epoch("2000-01-01T11:58:55.816", "utc")
    assert utc.tdb_seconds == pytest.approx(J2000.tdb_minus_tt(), abs=1e-8)


def test_adding_simulation_seconds_is_tdb_and_round_trips():
    e = Epoch("2024-03-20T03:06:00", "utc")
    for t in (0.0, 1e-3, 5400.0, -86400.0, 3.15e7):
        later = e + t
        assert later - e == pytest.approx(t, abs=1e-7)
        assert later.tdb_seconds - e.tdb_seconds == pytest.approx(t, abs=1e-6)
        assert (later - t) - e == pytest.approx(0.0, abs=1e-7)
    # one day of TDB is one day of TT less the change of TDB − TT over it (~3e-5 s here)
    day = e + 86400.0
    tt0, tt1 = e.jd("tt"), day.jd("tt")
    drift = day.tdb_minus_tt() - e.tdb_minus_tt()
    assert abs(drift) > 1e-6
    assert ((tt1[0] - tt0[0]) + (tt1[1] - tt0[1])) * 86400.0 == pytest.approx(
        86400.0 - drift, abs=1e-7
    )


@pytest.mark.parametrize("scale", ["utc", "tai", "tt", "tdb"])
def test_iso_and_julian_dates_round_trip_in_every_scale(scale):
    text = "2025-11-05T17:45:12.250000"
    e = Epoch(text, scale)
    assert e.iso(scale) == text
    assert Epoch.from_jd(*e.jd(scale), scale=scale) - e == pytest.approx(0.0, abs=2e-7)
    assert Epoch.from_iso(text, scale) == e


def test_epochs_compare_and_subtract_in_tdb_seconds():
    a, b = Epoch("2024-01-01"), Epoch("2024-01-02")
    assert a < b and not b < a
    assert a <= b and b >= a and b > a and not a > b
    assert b - a == pytest.approx(86400.0 + b.tdb_minus_tt() - a.tdb_minus_tt(), abs=1e-6)
    assert Epoch.from_tdb_seconds(a.tdb_seconds) - a == pytest.approx(0.0, abs=1e-6)


def test_agrees_with_astropy_time():
    at = pytest.importorskip("astropy.time")
    for iso in ("1980-01-06T00:00:00", "2016-12-31T23:59:60.25", "2024-03-20T03:06:00"):
        ref = at.Time(iso, scale="utc", precision=6)
        e = Epoch(iso, "utc")
        for scale in ("tai", "tt", "tdb"):
            jd = getattr(ref, scale)
            mine = e.jd(scale)
            assert ((mine[0] - jd.jd1) + (mine[1] - jd.jd2)) * 86400.0 == pytest.approx(
                0.0, abs=1e-6
            )


@pytest.mark.parametrize(
    ("value", "scale", "match"),
    [
        ("2024-13-01", "utc", "not a valid UTC"),
        ("yesterday", "utc", "ISO 8601"),
        ("2024-01-01", "gps", "time scale"),
        (float("nan"), "tdb", "finite"),
        (None, "tdb", "real number"),
    ],
)
def test_bad_input_says_what_came_in(value, scale, match):
    with pytest.raises(DefinitionError, match=match):
        Epoch(value, scale)


def test_adding_a_non_number_is_refused():
    with pytest.raises(DefinitionError, match="seconds added"):
        Epoch("2024-01-01") + np.array([1.0, 2.0])
