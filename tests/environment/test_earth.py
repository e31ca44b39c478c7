"""gmuk.environment.earth_gravity and the Earth's rotation at an epoch."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gmuk
from gmuk.environment import (
    EARTH_MU,
    EARTH_RADIUS,
    EARTH_ROTATION_RATE,
    Epoch,
    earth_gravity,
    earth_rotation_angle,
)
from gmuk.errors import DefinitionError, DegreeError


def _era_iers(jd1: float, jd2: float) -> float:
    """IERS Conventions (2010), Eq. 5.15: θ = 2π (0.7790572732640 + 1.00273781191135448 Du),
    Du = JD(UT1) − 2451545.0 = (jd1 − 2451545.0) + jd2 (written here independently of
    ERFA; the whole days of Du drop out of 2π Du)."""
    du = (jd1 - 2451545.0) + jd2
    frac = (jd1 % 1.0) + (jd2 % 1.0)  # Du mod 1, up to whole days
    return (2.0 * math.pi * (0.7790572732640 + 0.00273781191135448 * du + frac)) % (2.0 * math.pi)


@pytest.mark.parametrize(
    "iso", ["2000-01-01T12:00:00", "2024-03-20T03:06:00", "2026-06-30T23:00:00"]
)
def test_rotation_angle_is_the_iers_era_of_utc(iso):
    e = Epoch(iso, "utc")
    assert earth_rotation_angle(e) == pytest.approx(_era_iers(*e.jd("utc")), abs=1e-12)


def test_constants_are_egm2008_and_iers():
    assert EARTH_MU == 3.986004415e14
    assert EARTH_RADIUS == 6378136.3
    assert EARTH_ROTATION_RATE == 7.292115e-5
    field = gmuk.gravity.load("EGM2008", 2)
    assert field.mu == EARTH_MU
    assert field.radius == EARTH_RADIUS


def test_degree_zero_is_the_point_mass():
    sat = gmuk.PointMass("sat", 100.0)
    r = np.array([4.0e6, -5.0e6, 2.0e6])
    f = earth_gravity(0, Epoch("2024-01-01")).force(100.0, r, np.zeros(3), sat)
    np.testing.assert_allclose(
        f, gmuk.PointMassGravity(EARTH_MU).force(0.0, r, np.zeros(3), sat), rtol=1e-14
    )


def test_the_field_turns_from_the_epochs_rotation_angle():
    e = Epoch("2024-03-20T03:06:00")
    model = earth_gravity(8, e)
    sat = gmuk.PointMass("sat", 1.0)
    r = np.array([5.0e6, 4.0e6, 3.0e6])
    theta = earth_rotation_angle(e)
    # the same body-fixed point: at t = 0 under this model, and at t = θ/ω under F = N at 0
    fixed_frame = earth_gravity(8)
    t = theta / EARTH_ROTATION_RATE
    np.testing.assert_allclose(
        model.force(0.0, r, np.zeros(3), sat),
        fixed_frame.force(t, r, np.zeros(3), sat),
        rtol=1e-12,
    )
    assert model.central_body.rotation.rate == EARTH_ROTATION_RATE


def test_bad_degree_and_epoch_are_refused():
    with pytest.raises(DegreeError):
        earth_gravity(71)
    with pytest.raises(DefinitionError, match="Epoch"):
        earth_gravity(4, "2024-01-01")  # type: ignore[arg-type]
