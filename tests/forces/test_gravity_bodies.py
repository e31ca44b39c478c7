"""Gravity force models on rigid bodies against brute-force point-cloud quadrature."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.lie import se3

MU = 4.9048695e12  # m³/s²


def cloud(mass, J):
    """Six equal point masses at ±s_k e_k reproducing m and the principal inertia J (diag):
    Π = ∫δr δrᵀ dm = ½ tr(J) I − J, and Π_kk = (m/3) s_k²."""
    Pi = 0.5 * np.trace(J) - np.diag(J)
    s = np.sqrt(3.0 * Pi / mass)
    pts = np.concatenate([np.diag(s), -np.diag(s)])
    return pts, np.full(6, mass / 6)


def quadrature(g, pts, masses, mu):
    """Σ mᵢ a(r + R δrᵢ) and Σ δrᵢ × fᵢ, in the body frame."""
    R, r = g[:3, :3], g[:3, 3]
    f_B, L_B = np.zeros(3), np.zeros(3)
    for p, m in zip(pts, masses, strict=True):
        x = r + R @ p
        fi = R.T @ (-mu * m * x / np.linalg.norm(x) ** 3)
        f_B += fi
        L_B += np.cross(p, fi)
    return L_B, f_B


@pytest.mark.parametrize("seed", range(5))
def test_gravity_gradient_error_vs_quadrature_is_fourth_order(seed):
    rng = np.random.default_rng(seed)
    mass, J = 1.0e6, np.diag([3.0e8, 4.0e8, 5.0e8])  # a 50 m-scale structure (kg, kg·m²)
    body = gmuk.RigidBody("s", mass, J)
    pts, masses = cloud(mass, J)
    size = np.abs(pts).max()
    g = se3.exp(rng.normal(size=6))
    direction = g[:3, 3] / np.linalg.norm(g[:3, 3])
    errors = []
    for k in (100.0, 200.0):  # |r| = k × size
        g[:3, 3] = k * size * direction
        w = gmuk.GravityGradient(MU).wrench(0.0, g, np.zeros(6), body)
        L_q, f_q = quadrature(g, pts, masses, MU)
        f_point = g[:3, :3].T @ (-MU * mass * g[:3, 3] / np.linalg.norm(g[:3, 3]) ** 3)
        errors.append(
            (
                np.linalg.norm(w[3:] - f_q) / np.linalg.norm(f_q - f_point),
                np.linalg.norm(w[:3] - L_q) / np.linalg.norm(L_q),
            )
        )
    (ef1, eL1), (ef2, eL2) = errors
    # Eq. 23 is exact to second order; a centrally symmetric cloud has no third-order term,
    # so the relative error of the finite-size part falls as (size/r)²: ×4 per doubling.
    assert ef1 / ef2 == pytest.approx(4.0, rel=0.05)
    assert eL1 / eL2 == pytest.approx(4.0, rel=0.05)
    assert ef2 < 2e-4 and eL2 < 2e-4  # (1/200)² = 2.5e-5 times a coefficient of a few


def test_point_mass_gravity_on_rigid_and_point_bodies():
    body, p = gmuk.RigidBody("s", 2.0, np.eye(3)), gmuk.PointMass("p", 3.0)
    g = se3.exp(np.array([0.3, -0.2, 0.1, 7.0e6, 1.0e6, -2.0e6]))
    r = g[:3, 3]
    a_N = -MU * r / np.linalg.norm(r) ** 3
    w = gmuk.PointMassGravity(MU).wrench(0.0, g, np.zeros(6), body)
    assert np.allclose(w[:3], 0) and np.allclose(g[:3, :3] @ w[3:], 2.0 * a_N, rtol=1e-14)
    assert np.allclose(gmuk.PointMassGravity(MU).force(0.0, r, np.zeros(3), p), 3.0 * a_N)


def test_gravity_models_reject_bad_mu():
    with pytest.raises(gmuk.errors.DefinitionError, match="mu"):
        gmuk.GravityGradient(-1.0)


class PointField:
    """A degree-0 'field': U = μ/r, for checking the rigid-body expansion against Eq. 23."""

    def __init__(self, mu, radius=1.0):
        self.mu, self.radius, self.degree = mu, radius, 0

    def acceleration(self, r):
        return -self.mu * r / np.linalg.norm(r) ** 3

    def hessian(self, r):
        n = np.linalg.norm(r)
        u = r / n
        return self.mu / n**3 * (3.0 * np.outer(u, u) - np.eye(3))


def test_spherical_harmonic_model_with_a_point_field_equals_eq_23():
    rng = np.random.default_rng(3)
    moon = gmuk.CelestialBody("pt", field=PointField(MU), rotation=gmuk.UniformRotation(2.66e-6))
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    J = Q @ np.diag([3.0e8, 4.0e8, 5.0e8]) @ Q.T
    body = gmuk.RigidBody("s", 1.0e6, J)
    sh = gmuk.forces.SphericalHarmonicGravity(moon)
    gg = gmuk.GravityGradient(MU)
    for t in (0.0, 5.0e4):
        g = se3.exp(rng.normal(size=6))
        g[:3, 3] *= 2.0e5 / np.linalg.norm(g[:3, 3])  # 200 km: finite-size part ~1e-8
        w_sh = sh.wrench(t, g, np.zeros(6), body)
        w_gg = gg.wrench(t, g, np.zeros(6), body)
        point = g[:3, :3].T @ (-MU * 1.0e6 * g[:3, 3] / np.linalg.norm(g[:3, 3]) ** 3)
        assert np.linalg.norm(w_sh[:3] - w_gg[:3]) <= 1e-12 * np.linalg.norm(w_gg[:3])
        assert np.linalg.norm(w_sh[3:] - w_gg[3:]) <= 1e-6 * np.linalg.norm(w_gg[3:] - point)


def test_spherical_harmonic_gravity_needs_a_field():
    with pytest.raises(gmuk.errors.DefinitionError, match="needs a CelestialBody with a field"):
        gmuk.forces.SphericalHarmonicGravity(gmuk.CelestialBody.moon())


def test_harmonic_wrench_is_the_same_with_or_without_the_one_pass_field_call():
    # SphericalHarmonicGravity takes ∇U and ∇∇U from one acceleration_hessian call when the
    # field has it, and from acceleration() and hessian() otherwise (a duck-typed field):
    # the same numbers either way.
    field = gmuk.gravity.moon_low_degree()

    class TwoCalls:
        mu, radius, degree = field.mu, field.radius, field.degree
        acceleration = staticmethod(field.acceleration)
        hessian = staticmethod(field.hessian)

    rot = gmuk.UniformRotation(2.66e-6)
    one = gmuk.forces.SphericalHarmonicGravity(gmuk.CelestialBody("m", field=field, rotation=rot))
    two = gmuk.forces.SphericalHarmonicGravity(
        gmuk.CelestialBody("m", field=TwoCalls(), rotation=rot)
    )
    rng = np.random.default_rng(5)
    body = gmuk.RigidBody("s", 1.5e4, np.diag([2.0e4, 3.0e4, 4.0e4]))
    for t in (0.0, 3.0e4):
        g = se3.exp(rng.normal(size=6))
        g[:3, 3] *= 1.9e6 / np.linalg.norm(g[:3, 3])
        np.testing.assert_array_equal(
            one.wrench(t, g, np.zeros(6), body), two.wrench(t, g, np.zeros(6), body)
        )
