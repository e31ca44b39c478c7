"""gmuk.lie.conventions against Basilisk's (Schaub–Junkins) and Pinocchio's definitions:
MRPs against scipy's Rotation and the textbook formulas, twists against Pinocchio itself."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from gmuk.errors import DomainError, NotOnGroupError
from gmuk.lie import conventions as cv
from gmuk.lie import se3, so3

RNG = np.random.default_rng(18)


def dcm_BN(e: np.ndarray, phi: float) -> np.ndarray:
    """Schaub–Junkins's [BN] of the principal rotation (ê, Φ) of B relative to N:
    cos Φ I + (1 − cos Φ) ê êᵀ − sin Φ [ẽ] (maps N components to B components)."""
    E = so3.hat(e)
    return np.cos(phi) * np.eye(3) + (1 - np.cos(phi)) * np.outer(e, e) - np.sin(phi) * E


def random_unit(n: int) -> np.ndarray:
    v = RNG.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_mrps_are_e_tan_phi_over_4_of_the_principal_rotation():
    for e, phi in zip(random_unit(200), RNG.uniform(0, np.pi * 0.999, 200), strict=True):
        R_NB = dcm_BN(e, phi).T
        assert np.allclose(cv.mrp_from_matrix(R_NB), e * np.tan(phi / 4), atol=1e-14)
        assert np.allclose(cv.matrix_from_mrp(e * np.tan(phi / 4)), R_NB, atol=1e-14)


def test_mrps_agree_with_scipy_and_keep_the_set_inside_the_unit_sphere():
    rot = Rotation.random(2000, random_state=18)
    R = rot.as_matrix()
    sigma = cv.mrp_from_matrix(R)
    assert np.abs(sigma - rot.as_mrp()).max() < 1e-14
    assert np.linalg.norm(sigma, axis=1).max() <= 1 + 1e-15
    assert np.abs(cv.matrix_from_mrp(sigma) - R).max() < 1e-14
    assert np.abs(Rotation.from_mrp(sigma).as_matrix() - R).max() < 1e-14
    # the identity and half turns (|σ| = 1, both sets valid)
    assert np.allclose(cv.mrp_from_matrix(np.eye(3)), 0.0)
    for axis in np.eye(3):
        half = so3.exp(np.pi * axis)
        s = cv.mrp_from_matrix(half)
        assert np.isclose(np.linalg.norm(s), 1.0) and np.allclose(np.abs(s), axis)
        assert np.allclose(cv.matrix_from_mrp(s), half, atol=1e-15)


def test_the_shadow_set_is_the_same_attitude_outside_the_unit_sphere():
    sigma = cv.mrp_from_matrix(Rotation.random(500, random_state=7).as_matrix())
    shadow = cv.mrp_shadow(sigma)
    assert np.all(np.linalg.norm(shadow, axis=1) >= 1 - 1e-15)
    assert np.abs(cv.matrix_from_mrp(shadow) - cv.matrix_from_mrp(sigma)).max() < 1e-13
    assert np.allclose(cv.mrp_shadow(shadow), sigma, atol=1e-14)
    # a large σ (Φ near 2π) maps back inside the unit sphere through the matrix
    assert np.allclose(cv.mrp_from_matrix(cv.matrix_from_mrp(shadow)), sigma, atol=1e-13)
    with pytest.raises(DomainError, match="no shadow set"):
        cv.mrp_shadow([0.0, 0.0, 0.0])


def test_mrp_rates_follow_basilisks_kinematics_with_body_rates():
    """σ̇ = ¼ [(1 − σ²) I + 2[σ̃] + 2 σσᵀ] ω_BN_B (Schaub–Junkins Eq. 3.163): the body
    rates of gmuk's V_B are Basilisk's ω_BN_B."""
    for _ in range(50):
        R0 = Rotation.random(random_state=int(RNG.integers(1 << 30))).as_matrix()
        w = RNG.normal(size=3)
        h = 1e-6
        s_plus = cv.mrp_from_matrix(R0 @ so3.exp(h * w))
        s_minus = cv.mrp_from_matrix(R0 @ so3.exp(-h * w))
        s = cv.mrp_from_matrix(R0)
        if np.linalg.norm(s) > 0.99:  # a switch to the shadow set in the stencil
            continue
        B = (1 - s @ s) * np.eye(3) + 2 * so3.hat(s) + 2 * np.outer(s, s)
        assert np.allclose((s_plus - s_minus) / (2 * h), 0.25 * B @ w, atol=1e-8)


def test_basilisk_states_round_trip_and_velocities_are_inertial():
    g = se3.exp(RNG.normal(size=(100, 6)))
    V = RNG.normal(size=(100, 6))
    sigma, w, r, v_N = cv.to_basilisk(g, V)
    assert np.allclose(w, V[:, :3]) and np.allclose(r, g[:, :3, 3])
    assert np.allclose(v_N, np.einsum("nij,nj->ni", g[:, :3, :3], V[:, 3:]))
    g2, V2 = cv.from_basilisk(sigma, w, r, v_N)
    assert np.abs(g2 - g).max() < 1e-13 and np.abs(V2 - V).max() < 1e-13
    with pytest.raises(NotOnGroupError):
        cv.to_basilisk(np.diag([1.0, 1.0, -1.0, 1.0]), V[0])


def test_pinocchio_se3_is_the_pose_g_NB():
    for _ in range(50):
        g = se3.exp(RNG.normal(size=6))
        M = cv.to_pinocchio_se3(g)
        p = RNG.normal(size=3)
        assert np.allclose(M.act(p), g[:3, :3] @ p + g[:3, 3])  # body point → N
        assert np.allclose(cv.from_pinocchio_se3(M), g)


def test_pinocchio_motions_are_twists_with_the_halves_swapped():
    for _ in range(50):
        V = RNG.normal(size=6)
        m = cv.to_pinocchio_motion(V)
        assert np.allclose(m.vector, cv.swap_halves(V))
        assert np.allclose(cv.from_pinocchio_motion(m), V)
        # the same group exponential and adjoint under both orderings
        assert np.allclose(pin.exp6(m).homogeneous, se3.exp(V), atol=1e-13)
        g = se3.exp(RNG.normal(size=6))
        moved = cv.to_pinocchio_se3(g).act(m)
        assert np.allclose(cv.from_pinocchio_motion(moved), se3.Ad(g) @ V, atol=1e-13)
    assert np.allclose(cv.swap_halves(cv.swap_halves(np.arange(6.0))), np.arange(6.0))
