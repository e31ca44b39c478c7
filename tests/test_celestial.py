"""CelestialBody: constants, rotation, latitude/longitude, field consistency (Eqs. 60–62)."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.celestial import INERTIAL, MOON_ROTATION_RATE, CelestialBody, UniformRotation
from gmuk.errors import DefinitionError


class FakeField:
    mu, radius, degree = 4.9027998e12, 1.7381e6, 2


def test_moon_defaults_are_the_thesis_constants_with_f_equal_n_at_t0():
    moon = CelestialBody.moon()
    assert moon.mu == 4.9028e12 and moon.radius == 1.738e6
    assert moon.rotation.angle(0.0) == 0.0
    assert moon.rotation.rate == pytest.approx(2.6617e-6, rel=1e-4)
    assert np.allclose(moon.rotation.R_FN(0.0), np.eye(3))


def test_a_field_brings_its_own_gm_and_radius():
    moon = CelestialBody.moon(field=FakeField())
    assert moon.mu == FakeField.mu and moon.radius == FakeField.radius
    with pytest.raises(DefinitionError, match="differs from the field's mu"):
        CelestialBody("x", mu=4.9e12, field=FakeField(), rotation=INERTIAL)


def test_a_field_without_rotation_is_refused_unless_inertial_is_explicit():
    with pytest.raises(DefinitionError, match="needs a rotation model"):
        CelestialBody("x", field=FakeField())
    body = CelestialBody("x", field=FakeField(), rotation=INERTIAL)
    assert body.rotation.rate == 0.0


def test_latitude_longitude_follow_the_rotating_frame():
    moon = CelestialBody.moon()
    lat0, lon0 = np.radians(20.0), np.radians(-45.0)
    r = 1.9e6
    r_F = r * np.array([np.cos(lat0) * np.cos(lon0), np.cos(lat0) * np.sin(lon0), np.sin(lat0)])
    t = 86400.0 * 3
    r_N = moon.rotation.R_NF(t) @ r_F  # Eq. 61
    lat, lon = moon.latitude_longitude(t, r_N)
    assert lat == pytest.approx(lat0, abs=1e-14) and lon == pytest.approx(lon0, abs=1e-14)
    # A point fixed in N drifts westward in longitude at the rotation rate.
    _, lon_t = moon.latitude_longitude(np.array([0.0, 100.0]), np.array([[r, 0, 0]] * 2))
    assert lon_t[1] - lon_t[0] == pytest.approx(-100.0 * MOON_ROTATION_RATE, rel=1e-12)


def test_bad_constants_are_reported_together():
    with pytest.raises(DefinitionError) as info:
        CelestialBody("x", mu=-1.0, radius=0.0, rotation=UniformRotation(0.1))
    assert len(info.value.problems) == 2


def test_celestial_body_is_exported_at_top_level():
    assert gmuk.CelestialBody is CelestialBody


def test_one_time_and_many_times_give_the_same_rotation():
    rot = UniformRotation(2.6617e-6, 0.3)
    times = np.linspace(-1e7, 1e7, 101)
    many_NF, many_FN = rot.R_NF(times), rot.R_FN(times)
    for k, t in enumerate(times):
        one_NF, one_FN = rot.R_NF(float(t)), rot.R_FN(float(t))
        assert one_NF.shape == one_FN.shape == (3, 3)
        np.testing.assert_allclose(one_NF, many_NF[k], rtol=0, atol=4e-16)
        np.testing.assert_array_equal(one_FN, one_NF.T)
        np.testing.assert_allclose(one_FN, many_FN[k], rtol=0, atol=4e-16)
