"""gmuk.environment.shadow_fraction and shadow_margin: the conical shadow."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from gmuk.environment import RADIUS, shadow_fraction, shadow_margin
from gmuk.environment.shadow import fraction_from_angles, shadow_angles
from gmuk.errors import DefinitionError, DomainError

AU = 1.495978707e11
R_E, R_S = RADIUS["earth"], RADIUS["sun"]
SUN = np.array([AU, 0.0, 0.0])
EARTH = np.zeros(3)


def _visible_by_quadrature(a: float, b: float, c: float) -> float:
    """Fraction of a disc of radius a (centre 0) outside a disc of radius b (centre (c, 0)),
    by integrating the covered chord length over x (scipy.integrate.quad): an independent
    computation of the lens area the closed form gives."""

    def covered(x: float) -> float:
        h_sun = math.sqrt(max(a * a - x * x, 0.0))
        h_occ = math.sqrt(max(b * b - (x - c) ** 2, 0.0))
        return 2.0 * min(h_sun, h_occ)

    lo, hi = max(-a, c - b), min(a, c + b)
    if hi <= lo:
        return 1.0
    # the integrand has a kink where the circles cross (x = (a² − b² + c²)/2c): quad is told
    crossing = (a * a - b * b + c * c) / (2.0 * c) if c > 0.0 else lo
    kinks = [crossing] if lo < crossing < hi else None
    area, _ = quad(covered, lo, hi, epsabs=0.0, epsrel=1e-12, limit=200, points=kinks)
    return 1.0 - area / (math.pi * a * a)


@settings(max_examples=200, deadline=None)
@given(
    a=st.floats(1e-3, 1e-2),
    ratio=st.floats(0.1, 10.0),
    s=st.floats(0.0, 1.2),
)
def test_fraction_equals_the_lens_area_by_quadrature(a, ratio, s):
    b = a * ratio
    c = s * (a + b)
    assert fraction_from_angles(a, b, c) == pytest.approx(_visible_by_quadrature(a, b, c), abs=1e-9)


def test_sunlit_umbra_and_penumbra_of_the_earth():
    # sunlit beside the Earth, in the umbra right behind it
    assert shadow_fraction([0.0, 7e6, 0.0], SUN, EARTH, R_E) == 1.0
    assert shadow_fraction([-7e6, 0.0, 0.0], SUN, EARTH, R_E) == 0.0
    # a point at distance x behind the Earth, offset y: the penumbra lies between the
    # cones tangent to both spheres; straight from their half-angles (similar triangles)
    x = 4.2e7
    sin_u = (R_S - R_E) / AU  # umbra cone half-angle (converging)
    sin_p = (R_S + R_E) / AU  # penumbra cone half-angle (diverging)
    y_umbra = R_E / math.cos(math.asin(sin_u)) - x * math.tan(math.asin(sin_u))
    y_pen = R_E / math.cos(math.asin(sin_p)) + x * math.tan(math.asin(sin_p))
    assert shadow_fraction([-x, y_umbra * (1 - 1e-6), 0.0], SUN, EARTH, R_E) == 0.0
    assert 0.0 < shadow_fraction([-x, y_umbra * (1 + 1e-6), 0.0], SUN, EARTH, R_E) < 1e-3
    assert 1 - 1e-3 < shadow_fraction([-x, y_pen * (1 - 1e-6), 0.0], SUN, EARTH, R_E) < 1.0
    assert shadow_fraction([-x, y_pen * (1 + 1e-6), 0.0], SUN, EARTH, R_E) == 1.0
    # the margins vanish on those cones (to the cones' planar approximation, ~1e-12 rad)
    assert shadow_margin([-x, y_umbra, 0.0], SUN, EARTH, R_E, "umbra") == pytest.approx(
        0.0, abs=1e-12
    )
    assert shadow_margin([-x, y_pen, 0.0], SUN, EARTH, R_E, "penumbra") == pytest.approx(
        0.0, abs=1e-12
    )


def test_antumbra_sees_a_ring_of_the_sun():
    # far beyond the umbra's apex (1.39e9 m behind the Earth) the Earth is inside the Sun's disc
    r = np.array([-5e9, 0.0, 0.0])
    a, b, c = shadow_angles(r, SUN, EARTH, R_S, R_E)
    assert c == 0.0 and b < a
    assert shadow_fraction(r, SUN, EARTH, R_E) == pytest.approx(1 - (b / a) ** 2, rel=1e-14)


def test_fraction_is_continuous_and_monotonic_across_the_penumbra():
    ys = np.linspace(6.0e6, 6.8e6, 2001)
    nu = np.array([shadow_fraction([-4.2e7, y, 0.0], SUN, EARTH, R_E) for y in ys])
    assert nu[0] == 0.0 and nu[-1] == 1.0
    assert (np.diff(nu) >= 0).all()
    assert np.abs(np.diff(nu)).max() < 0.01


def test_margin_is_positive_outside_and_negative_inside():
    for y, kind in ((7e6, "umbra"), (7e6, "penumbra")):
        assert shadow_margin([0.0, y, 0.0], SUN, EARTH, R_E, kind) > 0
        assert shadow_margin([-7e6, 0.0, 0.0], SUN, EARTH, R_E, kind) < 0


def test_bad_input_is_refused_with_what_came_in():
    with pytest.raises(DefinitionError, match="r_sat"):
        shadow_fraction([1.0, 2.0], SUN, EARTH, R_E)
    with pytest.raises(DefinitionError, match="R_occ"):
        shadow_fraction([0.0, 7e6, 0.0], SUN, EARTH, -1.0)
    with pytest.raises(DomainError, match="inside the occulter"):
        shadow_fraction([1e6, 0.0, 0.0], SUN, EARTH, R_E)
    with pytest.raises(DefinitionError, match="kind"):
        shadow_margin([0.0, 7e6, 0.0], SUN, EARTH, R_E, "antumbra")
