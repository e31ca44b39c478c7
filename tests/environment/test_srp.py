"""gmuk.environment.CannonballSRP, FlatPlateSRP and Plate."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.environment import (
    AU,
    RADIUS,
    SOLAR_PRESSURE_1AU,
    CannonballSRP,
    Epoch,
    FlatPlateSRP,
    Plate,
    position,
    shadow_fraction,
)
from gmuk.errors import DefinitionError
from gmuk.lie import so3

EPOCH = Epoch("2024-03-20T03:06:00")
SAT = gmuk.PointMass("sat", 500.0)
BODY = gmuk.RigidBody("sc", 500.0, np.diag([100.0, 200.0, 250.0]))


def _pose(R: np.ndarray, r: np.ndarray) -> np.ndarray:
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = R, r
    return g


def _sun_unit(t: float, r: np.ndarray) -> tuple[np.ndarray, float]:
    """Unit vector body → Sun and the pressure P₀ (AU/ρ)² there (N/m²), from position()."""
    u = position("sun", EPOCH + t) - r
    rho = np.linalg.norm(u)
    return u / rho, SOLAR_PRESSURE_1AU * (AU / rho) ** 2


def test_cannonball_pushes_away_from_the_sun_with_the_inverse_square_pressure():
    model = CannonballSRP(EPOCH, area=2.0, C_R=1.3, occulters=())
    r, t = np.array([0.0, 4.2e7, 0.0]), 100.0
    e, P = _sun_unit(t, r)
    f = model.force(t, r, np.zeros(3), SAT)
    np.testing.assert_allclose(f, -P * 1.3 * 2.0 * e, rtol=1e-13)
    assert 4.4e-6 < P < 4.7e-6  # near equinox the Earth is ~0.996 au from the Sun


def test_cannonball_on_a_rigid_body_is_the_same_force_in_the_body_frame_without_torque():
    model = CannonballSRP(EPOCH, area=2.0, C_R=1.3)
    R = so3.exp(np.array([0.5, -0.2, 1.0]))
    r = np.array([1.0e6, 4.2e7, 3.0e6])
    w = model.wrench(5.0, _pose(R, r), np.zeros(6), BODY)
    np.testing.assert_array_equal(w[:3], 0.0)
    np.testing.assert_allclose(w[3:], R.T @ model.force(5.0, r, np.zeros(3), SAT), rtol=1e-14)


def test_shadow_scales_the_force_by_the_visible_fraction():
    model = CannonballSRP(EPOCH, area=1.0, C_R=1.0)
    s = position("sun", EPOCH)
    s_hat = s / np.linalg.norm(s)
    # behind the Earth: umbra, no force
    r_umbra = -7.0e6 * s_hat
    np.testing.assert_array_equal(model.force(0.0, r_umbra, np.zeros(3), SAT), 0.0)
    # in the penumbra: the unshadowed force times the fraction
    side = np.cross(s_hat, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    for y in np.linspace(6.30e6, 6.50e6, 9):
        r = -4.2e7 * s_hat + y * side
        nu = shadow_fraction(r, s, np.zeros(3), RADIUS["earth"]) * shadow_fraction(
            r, s, position("moon", EPOCH), RADIUS["moon"]
        )
        open_sky = CannonballSRP(EPOCH, area=1.0, C_R=1.0, occulters=())
        np.testing.assert_allclose(
            model.force(0.0, r, np.zeros(3), SAT),
            nu * open_sky.force(0.0, r, np.zeros(3), SAT),
            rtol=1e-14,
            atol=1e-30,
        )


def _facing_sun(t: float, r: np.ndarray) -> np.ndarray:
    """A rotation R_NB whose body x axis points at the Sun."""
    e, _ = _sun_unit(t, r)
    a = np.cross([1.0, 0.0, 0.0], e)
    ang = np.arctan2(np.linalg.norm(a), e[0])
    return so3.exp(a / np.linalg.norm(a) * ang)


def test_an_absorbing_plate_facing_the_sun_is_a_cannonball_with_c_r_1():
    r, t = np.array([0.0, 4.2e7, 0.0]), 0.0
    R = _facing_sun(t, r)
    plate = FlatPlateSRP(EPOCH, [Plate(3.0, [1.0, 0.0, 0.0], 0.0, 0.0, 1.0)], occulters=())
    ball = CannonballSRP(EPOCH, area=3.0, C_R=1.0, occulters=())
    w = plate.wrench(t, _pose(R, r), np.zeros(6), BODY)
    np.testing.assert_allclose(
        w[3:], R.T @ ball.force(t, r, np.zeros(3), SAT), rtol=0, atol=1e-12 * np.linalg.norm(w)
    )
    np.testing.assert_allclose(w[:3], 0.0, atol=1e-25)


@pytest.mark.parametrize("tilt", [0.0, 0.3, 1.0, 1.4])
def test_a_mirror_plate_is_pushed_along_its_normal_by_2_p_a_cos2(tilt):
    r, t = np.array([0.0, 4.2e7, 0.0]), 0.0
    e_N, P = _sun_unit(t, r)
    R = _facing_sun(t, r) @ so3.exp(np.array([0.0, 0.0, tilt]))  # normal tilted from the Sun
    n_B = np.array([1.0, 0.0, 0.0])
    c_B = np.array([0.2, 1.5, -0.4])
    plate = FlatPlateSRP(EPOCH, [Plate(2.0, n_B, 1.0, 0.0, 0.0, c_B)], occulters=())
    w = plate.wrench(t, _pose(R, r), np.zeros(6), BODY)
    cos = float(n_B @ (R.T @ e_N))
    assert cos == pytest.approx(np.cos(tilt), abs=1e-12)
    F = -2.0 * P * 2.0 * cos**2 * n_B
    np.testing.assert_allclose(w[3:], F, rtol=1e-12, atol=1e-22)
    np.testing.assert_allclose(w[:3], np.cross(c_B, F), rtol=1e-12, atol=1e-22)


def test_diffuse_plate_and_a_plate_facing_away():
    r, t = np.array([0.0, 4.2e7, 0.0]), 0.0
    _, P = _sun_unit(t, r)
    R = _facing_sun(t, r)
    front = Plate(1.0, [1.0, 0.0, 0.0], 0.0, 1.0, 0.0)
    back = Plate(1.0, [-1.0, 0.0, 0.0], 0.0, 1.0, 0.0)
    w = FlatPlateSRP(EPOCH, [front, back], occulters=()).wrench(t, _pose(R, r), np.zeros(6), BODY)
    # Lambertian facing the Sun: −P A (e + 2/3 n), with n = e: −(5/3) P A along x; the back is dark
    np.testing.assert_allclose(w[3:], [-5.0 / 3.0 * P, 0.0, 0.0], rtol=1e-12, atol=1e-22)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"area": 1.0, "normal_B": [1.0, 1.0, 0.0], "specular": 1, "diffuse": 0, "absorbed": 0},
         "unit vector"),
        ({"area": 1.0, "normal_B": [1.0, 0.0, 0.0], "specular": 0.5, "diffuse": 0.2,
          "absorbed": 0.2}, "must be 1"),
        ({"area": -1.0, "normal_B": [1.0, 0.0, 0.0], "specular": 1, "diffuse": 0,
          "absorbed": 0}, "area"),
    ],
)  # fmt: skip
def test_bad_plates_are_refused(kwargs, match):
    with pytest.raises(DefinitionError, match=match):
        Plate(**kwargs)


def test_bad_models_are_refused():
    with pytest.raises(DefinitionError, match="C_R must be in"):
        CannonballSRP(EPOCH, 1.0, 2.5)
    with pytest.raises(DefinitionError, match="occulters"):
        CannonballSRP(EPOCH, 1.0, 1.5, occulters=("sun",))
    with pytest.raises(DefinitionError, match="Plate"):
        FlatPlateSRP(EPOCH, [])
    with pytest.raises(DefinitionError, match="Epoch"):
        CannonballSRP("2024", 1.0, 1.5)


def test_symbolic_forms_match_in_sunlight_penumbra_and_umbra():
    ca = pytest.importorskip("casadi")
    s = position("sun", EPOCH)
    s_hat = s / np.linalg.norm(s)
    side = np.cross(s_hat, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    ball = CannonballSRP(EPOCH, area=1.0, C_R=1.4)
    plates = FlatPlateSRP(
        EPOCH,
        [
            Plate(2.0, n, 0.3, 0.2, 0.5, [0.1, 0.4, -0.2])
            for n in np.vstack([np.eye(3), -np.eye(3)])
        ],
    )
    R = so3.exp(np.array([0.2, -0.5, 0.9]))
    nus = []
    for y in np.linspace(6.0e6, 6.8e6, 17):  # umbra → penumbra → sunlight, 42 000 km behind
        r = -4.2e7 * s_hat + y * side
        nus.append(shadow_fraction(r, s, np.zeros(3), RADIUS["earth"]))
        f_py = ball.force(0.0, r, np.zeros(3), SAT)
        f_ca = np.asarray(ca.DM(ball.casadi_force(0.0, ca.DM(r), None, SAT))).ravel()
        np.testing.assert_allclose(f_ca, f_py, rtol=1e-12, atol=1e-12 * np.linalg.norm(f_py))
        g = _pose(R, r)
        w_py = plates.wrench(0.0, g, np.zeros(6), BODY)
        w_ca = np.asarray(ca.DM(plates.casadi_wrench(0.0, ca.DM(g), None, BODY))).ravel()
        np.testing.assert_allclose(w_ca, w_py, rtol=1e-12, atol=1e-12 * np.abs(w_py).max())
    assert nus[0] == 0.0 and nus[-1] == 1.0 and any(0.0 < v < 1.0 for v in nus)
    with pytest.raises(DefinitionError, match="numeric times only"):
        ball.casadi_force(ca.SX.sym("t"), ca.SX.sym("r", 3), None, SAT)
