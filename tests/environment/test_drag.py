"""gmuk.environment.AtmosphericDrag and ExponentialAtmosphere."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gmuk
from gmuk.environment import (
    EARTH_MU,
    EARTH_RADIUS,
    EARTH_ROTATION_RATE,
    VALLADO_2013,
    AtmosphericDrag,
    ExponentialAtmosphere,
)
from gmuk.errors import DefinitionError, DomainError
from gmuk.lie import so3

SAT = gmuk.PointMass("sat", 400.0)


def test_density_is_the_table_value_at_each_base_altitude():
    atm = ExponentialAtmosphere()
    for h0, rho0, _ in VALLADO_2013:
        assert float(atm.density(h0 * 1e3)) == pytest.approx(rho0, rel=1e-15)


def test_density_decays_with_the_band_scale_height():
    atm = ExponentialAtmosphere()
    # 420 km lies in the 400 km band: ρ₀ = 3.725e-12 kg/m³, H = 58.515 km (Vallado Table 8-4)
    assert float(atm.density(420e3)) == pytest.approx(
        3.725e-12 * math.exp(-20.0 / 58.515), rel=1e-14
    )
    # above 1000 km the last band goes on
    assert float(atm.density(1200e3)) == pytest.approx(
        3.019e-15 * math.exp(-200.0 / 268.0), rel=1e-14
    )
    h = np.array([[0.0, 1e5], [3e5, 9e5]])
    assert atm.density(h).shape == (2, 2)


def test_force_is_minus_half_rho_cda_v_rel_squared_against_the_rotating_air():
    model = AtmosphericDrag(2.2, 1.5)
    r = np.array([3.0e6, 5.0e6, 2.5e6])
    r *= (EARTH_RADIUS + 350e3) / np.linalg.norm(r)
    v = np.array([-6.0e3, 3.0e3, 2.5e3])
    v_rel = v - np.cross([0.0, 0.0, EARTH_ROTATION_RATE], r)
    rho = 9.518e-12  # the 350 km band's ρ₀ (Vallado Table 8-4)
    expected = -0.5 * rho * 2.2 * 1.5 * np.linalg.norm(v_rel) * v_rel
    np.testing.assert_allclose(model.force(0.0, r, v, SAT), expected, rtol=1e-13)


def test_rigid_body_gets_the_same_force_in_its_frame_from_its_body_velocity():
    model = AtmosphericDrag(2.2, 1.5)
    body = gmuk.RigidBody("sc", 400.0, np.diag([10.0, 20.0, 25.0]))
    R = so3.exp(np.array([0.4, 0.9, -0.3]))
    r = np.array([EARTH_RADIUS + 500e3, 0.0, 0.0])
    v_N = np.array([0.0, 7.6e3, 100.0])
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = R, r
    V_B = np.concatenate([[0.01, 0.0, 0.02], R.T @ v_N])
    w = model.wrench(0.0, g, V_B, body)
    np.testing.assert_array_equal(w[:3], 0.0)
    np.testing.assert_allclose(w[3:], R.T @ model.force(0.0, r, v_N, SAT), rtol=1e-13)


def test_a_circular_orbit_decays_at_rho_b_sqrt_mu_a_per_second():
    """With constant density and no rotation, a circular orbit's semi-major axis falls at
    da/dt = −ρ B √(μ a), B = C_D A/m (King-Hele 1987, *Satellite Orbits in an Atmosphere*,
    ch. 4; from the drag power −½ρ B v³ m and E = −μm/2a): over one orbit
    Δa = −2π ρ B a². The terms left out are of relative order Δa/a = 2.3e-5 (a changes
    during the orbit); the run agrees to 6e-6."""
    rho, C_D, area, m = 1e-11, 2.2, 10.0, 400.0
    atm = ExponentialAtmosphere([(0.0, rho, 1e15)])  # a scale height of 1e15 km: constant
    body = gmuk.PointMass("sat", m)
    drag = AtmosphericDrag(C_D, area, atmosphere=atm, rotation_rate=0.0)
    system = gmuk.System([body], forces=[gmuk.PointMassGravity(EARTH_MU), drag])
    a0 = EARTH_RADIUS + 400e3
    v0 = math.sqrt(EARTH_MU / a0)
    state = system.state(r={"sat": [a0, 0.0, 0.0]}, v={"sat": [0.0, v0, 0.0]})
    T = 2.0 * math.pi * math.sqrt(a0**3 / EARTH_MU)
    traj = system.simulate(state, t_span=(0.0, T), rtol=1e-12, atol=1e-9)
    r, v = traj.body("sat").position[-1], traj.body("sat").velocity[-1]
    a1 = 1.0 / (2.0 / np.linalg.norm(r) - v @ v / EARTH_MU)  # vis-viva
    expected = -2.0 * math.pi * rho * C_D * area / m * a0**2
    assert a1 - a0 == pytest.approx(expected, rel=2e-5)


def test_below_the_surface_is_a_domain_error():
    model = AtmosphericDrag(2.2, 1.0)
    with pytest.raises(DomainError, match="altitudes >= 0"):
        model.force(0.0, np.array([6.0e6, 0.0, 0.0]), np.zeros(3), SAT)


@pytest.mark.parametrize(
    "table",
    [[(10.0, 1.0, 5.0)], [(0.0, 1.0, 5.0), (0.0, 0.5, 5.0)], [(0.0, -1.0, 5.0)], [[1.0, 2.0]]],
)
def test_bad_tables_are_refused(table):
    with pytest.raises(DefinitionError, match="atmosphere table"):
        ExponentialAtmosphere(table)


def test_bad_coefficients_are_refused():
    with pytest.raises(DefinitionError, match="C_D"):
        AtmosphericDrag(-1.0, 1.0)
    with pytest.raises(DefinitionError, match="atmosphere must be"):
        AtmosphericDrag(2.2, 1.0, atmosphere=VALLADO_2013)  # type: ignore[arg-type]


def test_symbolic_density_picks_the_same_band_as_the_kernel():
    ca = pytest.importorskip("casadi")
    atm = ExponentialAtmosphere()
    h = ca.SX.sym("h")
    fn = ca.Function("rho", [h], [atm.casadi_density(h)])
    for km in (0.0, 24.999, 25.0, 149.0, 150.0, 399.9, 400.0, 999.0, 1000.0, 1500.0):
        assert float(fn(km * 1e3)) == pytest.approx(float(atm.density(km * 1e3)), rel=1e-14)
