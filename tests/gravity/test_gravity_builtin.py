"""Built-in constants and the typed-in low-degree lunar field, checked against the files."""

from __future__ import annotations

import numpy as np
import pytest

from gmuk.errors import DegreeError
from gmuk.gravity import (
    EARTH_MU,
    EARTH_RADIUS,
    MOON_MU,
    MOON_RADIUS,
    earth_point_mass,
    moon_low_degree,
    moon_point_mass,
)
from gmuk.gravity.builtin import _GRGM660PRIM_LOW


def test_constants_are_the_files_values(grail, egm):
    assert MOON_MU == grail.mu and MOON_RADIUS == grail.radius
    assert EARTH_MU == egm.mu and EARTH_RADIUS == egm.radius
    import gmuk.celestial as cel

    assert cel.EARTH_MU == EARTH_MU and cel.EARTH_RADIUS == EARTH_RADIUS
    assert cel.MOON_RADIUS == MOON_RADIUS
    assert MOON_MU != cel.MOON_MU_THESIS  # the thesis's 4.9028e12 is not GRAIL's GM


def test_typed_coefficients_are_grgm660prim_to_the_printed_digits(grail):
    """Every typed value equals the file's value rounded to 8 significant digits."""
    assert len(_GRGM660PRIM_LOW) == 12  # degrees 2..4, every order
    for (n, m), (c, s) in _GRGM660PRIM_LOW.items():
        assert c == float(f"{grail.C[n, m]:.7e}"), (n, m)
        assert s == float(f"{grail.S[n, m]:.7e}"), (n, m)
        # and the rounding is within the formal sigmas or below 5e-8 relative
        assert abs(c - grail.C[n, m]) <= max(grail.sigma_C[n, m], 5e-8 * abs(grail.C[n, m]))


def test_low_degree_field_against_the_file(grail):
    f = moon_low_degree()
    assert f.degree == 4 and f.mu == grail.mu and f.radius == grail.radius
    assert f.C[0, 0] == 1.0 and np.all(f.C[1] == 0) and np.all(f.S[1] == 0)
    ref = grail.truncate(4)
    rng = np.random.default_rng(11)
    for _ in range(20):
        u = rng.normal(size=3)
        r = u / np.linalg.norm(u) * (MOON_RADIUS + rng.uniform(30e3, 3000e3))
        pert, pert_ref = f.acceleration(r, central=False), ref.acceleration(r, central=False)
        assert np.linalg.norm(pert - pert_ref) <= 1e-7 * np.linalg.norm(pert_ref)
    assert moon_low_degree(2).degree == 2
    with pytest.raises(DegreeError, match="between 0 and the coefficients' degree 4; got 5"):
        moon_low_degree(5)
    assert "Lemoine" in f.reference


def test_point_mass_fields():
    r = np.array([1.0e6, 2.0e6, -0.5e6])
    rn = np.linalg.norm(r)
    for f, mu in ((moon_point_mass(), MOON_MU), (earth_point_mass(), EARTH_MU)):
        assert f.degree == 0 and f.mu == mu
        np.testing.assert_allclose(f.acceleration(r), -mu * r / rn**3, rtol=1e-15)
