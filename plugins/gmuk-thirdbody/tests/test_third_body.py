"""The third-body plugin: physics checks and discovery through gmuk's entry points."""

import numpy as np
import pytest
from gmuk_thirdbody import EARTH_FROM_MOON, ThirdBodyGravity, third_body_acceleration

import gmuk
from gmuk.forces import registry
from gmuk.lie import se3

MU_EARTH = 3.986004418e14


def potential(r, d, mu):
    """Third-body disturbing potential R = μ(1/|d − r| − d·r/|d|³) (Montenbruck & Gill 3.35)."""
    return mu * (1.0 / np.linalg.norm(d - r) - d @ r / np.linalg.norm(d) ** 3)


def test_acceleration_is_the_gradient_of_the_disturbing_potential():
    rng = np.random.default_rng(0)
    d = EARTH_FROM_MOON(1.0e5)
    for _ in range(10):
        r = rng.normal(size=3) * 2.0e6
        h = 2.0e3  # truncation ~h²/(6|r|²) ≈ 2e-7, round-off ~eps·R/(h|a|) ≈ 5e-9
        grad = np.array(
            [
                (potential(r + h * e, d, MU_EARTH) - potential(r - h * e, d, MU_EARTH)) / (2 * h)
                for e in np.eye(3)
            ]
        )
        a = third_body_acceleration(r, d, MU_EARTH)
        assert np.allclose(a, grad, rtol=1e-6, atol=1e-15)


def test_tidal_limit_far_from_the_third_body():
    d = np.array([3.844e8, 0.0, 0.0])
    r = np.array([1.0e6, 2.0e6, -5.0e5])
    dn = np.linalg.norm(d)
    u = d / dn
    tidal = MU_EARTH / dn**3 * (3 * u * (u @ r) - r)
    a = third_body_acceleration(r, d, MU_EARTH)
    assert np.linalg.norm(a - tidal) < 2e-2 * np.linalg.norm(tidal)  # next term ~ |r|/|d|


def test_rigid_body_torque_matches_point_cloud_quadrature():
    mass, J = 1.0e6, np.diag([3.0e8, 4.0e8, 5.0e8])
    body = gmuk.RigidBody("s", mass, J)
    Pi = 0.5 * np.trace(J) - np.diag(J)
    s = np.sqrt(3.0 * Pi / mass)
    pts = np.concatenate([np.diag(s), -np.diag(s)])
    g = se3.exp(np.array([0.3, -0.4, 0.2, 0.0, 0.0, 0.0]))
    g[:3, 3] = [1.8e6, 0.0, 0.0]
    ephem = lambda t: np.array([1.8e6 + 5.0e3, 2.0e3, 0.0])  # noqa: E731 - a close attractor
    w = ThirdBodyGravity(MU_EARTH * 1e-6, ephem).wrench(0.0, g, np.zeros(6), body)
    R, r, d = g[:3, :3], g[:3, 3], ephem(0.0)
    L = np.zeros(3)
    for p in pts:
        x = r + R @ p
        L += np.cross(p, R.T @ (mass / 6 * MU_EARTH * 1e-6 * (d - x) / np.linalg.norm(d - x) ** 3))
    assert np.linalg.norm(w[:3] - L) < 1e-3 * np.linalg.norm(L)  # (size/distance)² ≈ 1e-5


def test_gmuk_discovers_the_plugin_by_its_entry_point():
    registry.refresh()
    assert registry.get("third_body") is ThirdBodyGravity
    names = {i.name: i.source for i in registry.available()}
    assert names["third_body"] == "gmuk-thirdbody"
    model = registry.create("third_body", mu=MU_EARTH, ephemeris=EARTH_FROM_MOON)
    assert isinstance(model, gmuk.ForceModel)


def test_bad_arguments_are_rejected():
    with pytest.raises(gmuk.errors.DefinitionError, match="mu"):
        ThirdBodyGravity(-1.0, EARTH_FROM_MOON)
    with pytest.raises(gmuk.errors.DefinitionError, match="callable"):
        ThirdBodyGravity(1.0, "earth")
