"""Eq. 10b (free rigid-body acceleration) against ``pin.aba`` on a one-body free-flyer model.

The body's inertia sits at the joint origin (the centre of mass), so Pinocchio's local joint
velocity ``v = [v_lin; ω]`` is gmuk's body twist reordered, its ``ddq`` is V̇ reordered, and
the joint torque is the body wrench [f; L]. Gravity is off; q = [r; quaternion (x, y, z, w)].
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from gmuk.dynamics import free_acceleration, spatial_inertia
from gmuk.lie import se3, so3

from .pin_helpers import free_flyer_model, q_from_g, swap_vec

TOL = 1e-12
N = 1000


def random_body(rng):
    """Mass 10⁻²…10⁴ kg; principal moments m k² (k ∈ [0.1, 3] m) obeying J₁ + J₂ ≥ J₃."""
    m = 10.0 ** rng.uniform(-2, 4)
    a, b = m * rng.uniform(0.01, 9.0, size=2)
    c = max(rng.uniform(abs(a - b), a + b), 1e-3 * m)
    R = so3.exp(rng.normal(size=3) * 2.0)
    return m, R @ np.diag([a, b, c]) @ R.T


def test_q_from_g_is_the_free_flyer_configuration_of_the_pose():
    g = se3.exp([0.3, -1.2, 2.0, 1.0, 2.0, 3.0])
    model, data = free_flyer_model(1.0, np.eye(3))
    pin.forwardKinematics(model, data, q_from_g(g))
    assert np.abs(data.oMi[1].homogeneous - g).max() <= 1e-15


def test_free_acceleration_matches_pin_aba_on_1000_samples():
    rng = np.random.default_rng(201)
    model, data = free_flyer_model(1.0, np.eye(3))
    worst = 0.0
    for _ in range(N):
        m, J = random_body(rng)
        model.inertias[1] = pin.Inertia(m, np.zeros(3), J)
        V = np.concatenate([rng.normal(size=3), 10.0 ** rng.uniform(-2, 1) * rng.normal(size=3)])
        tau = m * rng.normal(size=6) * 10.0 ** rng.uniform(-2, 2)
        g = se3.exp(np.concatenate([rng.uniform(-np.pi, np.pi, 3), rng.normal(size=3) * 1e3]))
        ddq = pin.aba(model, data, q_from_g(g), swap_vec(V), swap_vec(tau))
        ours = free_acceleration(V, spatial_inertia(m, J), tau)
        err = np.abs(ours - swap_vec(ddq)).max() / max(1.0, np.abs(ddq).max())
        worst = max(worst, err)
    assert worst <= TOL, worst


def test_torque_free_acceleration_matches_pin_aba_including_zero_twist():
    rng = np.random.default_rng(202)
    model, data = free_flyer_model(1.0, np.eye(3))
    q = q_from_g(np.eye(4))
    for V in [np.zeros(6), np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]), rng.normal(size=6)]:
        m, J = random_body(rng)
        model.inertias[1] = pin.Inertia(m, np.zeros(3), J)
        ddq = pin.aba(model, data, q, swap_vec(V), np.zeros(6))
        ours = free_acceleration(V, spatial_inertia(m, J))
        assert np.abs(ours - swap_vec(ddq)).max() <= TOL * max(1.0, np.abs(ddq).max())


@pytest.mark.parametrize("speed", [1e3, 7e3])
def test_at_orbital_speeds_pinocchio_carries_the_m_v_cross_v_round_off_and_gmuk_does_not(speed):
    # Pinocchio evaluates the bias torque ω × Jω + v × (m v); the second term is zero but
    # leaves ε m|v|² of round-off, so aba's ω̇ differs from Euler's equations by up to
    # ε m|v|²/J_min. gmuk drops the term exactly: it agrees with Euler's equations to 1e-12
    # of |ω̇| and with Pinocchio to 1e-12 of that round-off scale.
    rng = np.random.default_rng(int(speed))
    model, data = free_flyer_model(1.0, np.eye(3))
    for _ in range(50):
        m, J = random_body(rng)
        model.inertias[1] = pin.Inertia(m, np.zeros(3), J)
        w = 1e-3 * rng.normal(size=3)
        v = speed * rng.normal(size=3) / np.sqrt(3.0)
        V = np.concatenate([w, v])
        ddq = swap_vec(pin.aba(model, data, q_from_g(np.eye(4)), swap_vec(V), np.zeros(6)))
        ours = free_acceleration(V, spatial_inertia(m, J))
        euler = np.linalg.solve(J, np.cross(J @ w, w))
        assert np.abs(ours[:3] - euler).max() <= TOL * np.linalg.cond(J) * np.abs(euler).max()
        roundoff_scale = m * np.abs(v).max() ** 2 / np.linalg.eigvalsh(J)[0]
        assert np.abs(ours - ddq).max() <= TOL * max(1.0, np.abs(ddq).max(), roundoff_scale)
