"""gmuk.environment.position and Ephemeris against JPL's DE421."""

from __future__ import annotations

import numpy as np
import pytest

from gmuk.environment import MOON_ACCURACY, SUN_ACCURACY, Ephemeris, Epoch, position
from gmuk.errors import DefinitionError

#: DE421 geometric geocentric positions (m, ICRF axes) at TDB instants, from the de421
#: package (2008.1) read by jplephem 2.24: Sun = sun − (earthmoon − moon/(1 + EMRAT)),
#: Moon = moon (``python tests/environment/de421_reference.py`` prints them).
DE421 = {
    "2000-01-01T12:00:00": {
        "sun": [2.6499033629976086e10, -1.3275741737117107e11, -5.7556718419932236e10],
        "moon": [-2.9160838530964088e08, -2.6671683294678754e08, -7.6102487146783546e07],
    },
    "2024-03-20T03:06:00": {
        "sun": [1.4897649476271872e11, -7.9286873758977866e08, -3.4419368978259033e08],
        "moon": [-2.2041686064219370e08, 2.9197860935209298e08, 1.6473306657127225e08],
    },
    "2035-07-01T00:00:00": {
        "sun": [-2.2608672240951778e10, 1.3799593008966245e11, 5.9814856755231506e10],
        "moon": [2.952697724744665e08, 2.140884390501832e08, 6.175142696026649e07],
    },
}
ACCURACY = {"sun": SUN_ACCURACY, "moon": MOON_ACCURACY}


@pytest.mark.parametrize("iso", sorted(DE421))
@pytest.mark.parametrize("body", ["sun", "moon"])
def test_geocentric_sun_and_moon_are_within_the_stated_accuracy_of_de421(iso, body):
    e = Epoch(iso, "tdb")
    err = np.linalg.norm(position(body, e) - np.array(DE421[iso][body]))
    assert err < ACCURACY[body]


def test_the_stated_accuracy_holds_over_1950_2050_against_the_de421_package():
    pytest.importorskip("jplephem")
    pytest.importorskip("de421")
    from de421_reference import largest_errors

    worst = largest_errors(n=401)
    assert worst["sun"] < SUN_ACCURACY
    assert worst["moon"] < MOON_ACCURACY


def test_moon_centred_positions_are_differences_of_geocentric_ones():
    e = Epoch("2026-11-28T10:00:00")
    moon, sun = position("moon", e), position("sun", e)
    np.testing.assert_array_equal(position("earth", e, "moon"), -moon)
    np.testing.assert_allclose(position("sun", e, "moon"), sun - moon, rtol=0, atol=1e-4)
    np.testing.assert_array_equal(position("earth", e), np.zeros(3))
    np.testing.assert_allclose(position("earth", e, "sun"), -sun, rtol=0, atol=1e-4)


def test_ephemeris_is_the_position_at_epoch_plus_t():
    e = Epoch("2024-01-01T00:00:00")
    eph = Ephemeris("moon", e)
    for t in (0.0, 3600.0, 27.3 * 86400.0):
        np.testing.assert_array_equal(eph(t), position("moon", e + t))
    # the Moon moves ~1 km/s about the Earth: a finite difference of the ephemeris says so
    v = (eph(30.0) - eph(-30.0)) / 60.0
    assert 0.9e3 < np.linalg.norm(v) < 1.1e3


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (("mars", Epoch("2024-01-01")), "body must be one of"),
        (("sun", "2024-01-01"), "gmuk.environment.Epoch"),
        (("sun", Epoch("2024-01-01"), "jupiter"), "centre must be one of"),
    ],
)
def test_bad_bodies_and_epochs_are_refused(args, match):
    with pytest.raises(DefinitionError, match=match):
        position(*args)


def test_an_ephemeris_of_its_own_centre_is_refused():
    with pytest.raises(DefinitionError, match="other than its centre"):
        Ephemeris("earth", Epoch("2024-01-01"))
