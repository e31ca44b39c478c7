"""Rigid-body dynamics on SE(3) (McCann 2020, Eqs. 10–11, 17–19).

Eq. 10b is compared with Euler's equations written out by hand; the invariants of torque-free
motion (kinetic energy, spatial momentum) are checked pointwise and along a motion integrated
with scipy's ``solve_ivp``; g̈ (Eqs. 17–19) is compared with finite differences of that motion.
Inertia validation is checked for every rejection and for the flat-plate limit J₃ = J₁ + J₂.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from gmuk.dynamics import (
    check_inertia,
    free_acceleration,
    g_ddot,
    kinetic_energy,
    spatial_inertia,
    spatial_momentum,
)
from gmuk.errors import GmukError, InertiaError, NonFiniteError, ShapeError
from gmuk.lie import se3, so3

PI = np.pi
TOL = 1e-12
PROPERTY = settings(max_examples=60, deadline=None)


def assert_close(actual, expected, tol=TOL, scale=None):
    actual, expected = np.asarray(actual), np.asarray(expected)
    if scale is None:
        scale = max(1.0, np.abs(expected).max(initial=0.0), np.abs(actual).max(initial=0.0))
    err = np.abs(actual - expected).max(initial=0.0)
    assert err <= tol * scale, f"error {err:.3g} > {tol:g} × scale {scale:.3g}"


def _body(moments_raw, w, mass):
    """(m, J) with principal moments obeying the triangle inequality, rotated by exp(w)."""
    a, b, t = moments_raw
    c = abs(a - b) + t * (a + b - abs(a - b))  # J₃ ∈ [|J₁ − J₂|, J₁ + J₂]
    c = max(c, 1e-3)
    R = so3.exp(np.array(w))
    return mass, R @ np.diag([a, b, c]) @ R.T


pos = st.floats(0.1, 10.0)
ang = st.floats(-PI, PI)
bodies = st.builds(
    _body,
    st.tuples(pos, pos, st.floats(0.0, 1.0)),
    st.tuples(ang, ang, ang),
    st.floats(0.01, 1e4),
)
comp = st.floats(-10.0, 10.0)
twists = st.tuples(*[comp] * 6).map(np.array)
wrenches = st.tuples(*[st.floats(-100.0, 100.0)] * 6).map(np.array)
poses = st.builds(
    lambda w, r: se3.exp(np.concatenate([w, r])),
    st.tuples(ang, ang, ang).map(np.array),
    st.tuples(*[st.floats(-1e7, 1e7)] * 3).map(np.array),
)


# --- spatial inertia and its validation ------------------------------------------------------


def test_spatial_inertia_is_blkdiag_J_and_m_identity():
    J = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 4.0]])
    I = spatial_inertia(5.0, J)
    assert np.array_equal(I[:3, :3], J)
    assert np.array_equal(I[3:, 3:], 5.0 * np.eye(3))
    assert np.array_equal(I[:3, 3:], np.zeros((3, 3)))
    assert np.array_equal(I[3:, :3], np.zeros((3, 3)))


@pytest.mark.parametrize(
    ("mass", "J", "fragments"),
    [
        (0.0, np.eye(3), ["mass must be finite and > 0", "got 0.0"]),
        (-1.5, np.eye(3), ["mass", "got -1.5"]),
        (np.nan, np.eye(3), ["mass", "got nan"]),
        (np.inf, np.eye(3), ["mass", "got inf"]),
        ("heavy", np.eye(3), ["mass must be a positive number", "'heavy'"]),
        (1.0, [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], ["symmetric", "0.5"]),
        (1.0, np.diag([1.0, 1.0, -1.0]), ["positive definite", "-1."]),
        (1.0, np.diag([0.0, 1.0, 1.0]), ["positive definite", "[0. 1. 1.]"]),
        (1.0, np.diag([1.0, 1.0, 3.0]), ["triangle inequality", "[1. 1. 3.]", "2 < 3"]),
        (1.0, np.diag([1.0, 2.0, 3.0 + 1e-6]), ["triangle inequality", "3.000001"]),
    ],
)
def test_unphysical_mass_or_inertia_raises_inertia_error_showing_the_values(mass, J, fragments):
    with pytest.raises(InertiaError) as info:
        spatial_inertia(mass, J)
    for fragment in fragments:
        assert fragment in str(info.value)
    assert isinstance(info.value, ValueError) and isinstance(info.value, GmukError)


def test_inertia_error_lists_every_problem_at_once():
    with pytest.raises(InertiaError) as info:
        check_inertia(-2.0, np.diag([1.0, 1.0, 3.0]), name="probe")
    msg = str(info.value)
    assert msg.startswith("probe: ")
    assert "got -2.0" in msg and "triangle inequality" in msg


def test_non_finite_inertia_entries_raise_non_finite_error():
    J = np.eye(3)
    J[1, 1] = np.nan
    with pytest.raises(NonFiniteError, match="1 NaN/inf entry"):
        spatial_inertia(1.0, J)


def test_inertia_of_the_wrong_shape_raises_shape_error_with_both_shapes():
    with pytest.raises(ShapeError) as info:
        spatial_inertia(1.0, np.ones(3))
    assert "(3, 3)" in str(info.value) and "(3,)" in str(info.value)


@pytest.mark.parametrize("w", [np.zeros(3), np.array([0.3, -1.2, 2.0])])
def test_flat_plate_with_j3_equal_j1_plus_j2_is_accepted(w):
    R = so3.exp(w)
    J = R @ np.diag([1.0, 2.0, 3.0]) @ R.T
    I = spatial_inertia(2.0, J)
    assert np.array_equal(I[:3, :3], J)


# --- Eq. 10b ---------------------------------------------------------------------------------


@PROPERTY
@given(bodies, twists, wrenches)
def test_free_acceleration_is_eulers_equations_written_out(body, V, tau):
    m, J = body
    w, v, L, f = V[:3], V[3:], tau[:3], tau[3:]
    w_dot = np.linalg.solve(J, np.cross(J @ w, w) + L)  # J ω̇ = Jω × ω + L
    v_dot = np.cross(v, w) + f / m  # v̇ = v × ω + f/m
    out = free_acceleration(V, spatial_inertia(m, J), tau)
    cond = np.linalg.cond(J)
    scale = max(1.0, np.abs(w_dot).max(), np.abs(v_dot).max())
    assert_close(out[:3], w_dot, tol=TOL * cond, scale=scale)
    assert_close(out[3:], v_dot, scale=scale)


@pytest.mark.parametrize("speed", [1.6e3, 7.8e3])
def test_free_acceleration_has_no_spurious_torque_at_orbital_speeds(speed):
    # 𝕀 V̇ = ad*_V 𝕀V + τ contains m v × v in its torque row, zero but of order ε m|v|² if
    # evaluated as written; at orbital speed that would exceed the gyroscopic torque.
    R = so3.exp([0.4, -0.3, 1.1])
    m, J = 500.0, R @ np.diag([100.0, 200.0, 250.0]) @ R.T
    w = np.array([1.1e-3, -0.7e-3, 0.3e-3])
    v = speed * np.array([0.93, 0.36, -0.071])
    out = free_acceleration(np.concatenate([w, v]), spatial_inertia(m, J))
    euler = np.linalg.solve(J, np.cross(J @ w, w))
    assert np.abs(out[:3] - euler).max() <= 1e-12 * np.abs(euler).max()
    assert_close(out[3:], np.cross(v, w), tol=1e-15)


@PROPERTY
@given(bodies, twists)
def test_free_acceleration_without_wrench_equals_zero_wrench(body, V):
    I = spatial_inertia(*body)
    assert np.array_equal(free_acceleration(V, I), free_acceleration(V, I, np.zeros(6)))


@PROPERTY
@given(bodies, twists)
def test_torque_free_kinetic_energy_rate_is_zero(body, V):
    # d/dt ½ Vᵀ𝕀V = Vᵀ𝕀V̇ = Vᵀ ad*_V 𝕀V = (ad_V V)ᵀ 𝕀V = 0.
    I = spatial_inertia(*body)
    rate = V @ I @ free_acceleration(V, I)
    scale = max(1.0, np.abs(V).max() ** 2 * np.abs(I @ V).max())
    assert abs(rate) <= TOL * scale


@PROPERTY
@given(bodies, twists, wrenches)
def test_kinetic_energy_rate_is_the_power_of_the_wrench(body, V, tau):
    I = spatial_inertia(*body)
    rate = V @ I @ free_acceleration(V, I, tau)
    scale = max(
        1.0, np.abs(V).max() ** 2 * np.abs(I @ V).max(), np.abs(V).max() * np.abs(tau).max()
    )
    assert abs(rate - V @ tau) <= TOL * scale


@PROPERTY
@given(bodies, twists)
def test_kinetic_energy_is_half_omega_J_omega_plus_half_m_v_squared(body, V):
    m, J = body
    expected = 0.5 * V[:3] @ J @ V[:3] + 0.5 * m * V[3:] @ V[3:]
    assert_close(kinetic_energy(V, spatial_inertia(m, J)), expected, tol=1e-14)


# 8th-order central differences: first and second derivatives (offsets −4h … 4h).
D1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
D2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
OFFSETS = np.arange(-4, 5)


@PROPERTY
@given(bodies, twists, wrenches, poses)
@example(  # found by hypothesis: r × p cancels 2.7e5 m out (the round-off scale below)
    body=_body((1.0, 1.0, 0.0), (0.0, 0.0, 0.0), 1.0),
    V=np.array([0.0, 1.0, 0.0, 0.0, 0.0, 1.0]),
    tau=np.zeros(6),
    g=se3.exp(np.array([0.0, 0.0, 0.0, 0.0, 0.0, 269351.0])),
)
def test_spatial_momentum_rate_is_the_applied_wrench_in_the_inertial_frame(body, V, tau, g):
    # Along the motion (ġ = gV^, V̇ from Eq. 10b) dh_N/dt = Ad_{g⁻¹}ᵀ τ; zero when τ = 0.
    I = spatial_inertia(*body)
    h = 1e-3
    for wrench in (np.zeros(6), tau):
        V_dot = free_acceleration(V, I, wrench)
        # Any curve with the motion's tangent (g exp(εV), V + εV̇) has the same first derivative.
        poses = [g @ se3.exp(k * h * V) for k in OFFSETS]
        samples = [
            spatial_momentum(gk, V + k * h * V_dot, I) for gk, k in zip(poses, OFFSETS, strict=True)
        ]
        rate = np.tensordot(D1, np.array(samples), axes=1) / h
        expected = se3.Ad(se3.inverse(g)).T @ wrench
        # Round-off of the stencil: Σ|cₖ| ε |h_N| / h, where |h_N| is the size of the terms
        # summed, not of their sum: r × p cancels when p is along r, but each product keeps
        # its round-off ε|r||p| (a body 2.7e5 m out moving radially).
        terms = [
            np.abs(gk[:3, 3]).max() * np.abs(hk[3:]).max()
            for gk, hk in zip(poses, samples, strict=True)
        ]
        scale = max(1.0, np.abs(samples).max(), max(terms))
        assert_close(rate, expected, tol=100 * np.finfo(float).eps / h, scale=scale)


@PROPERTY
@given(bodies, twists, poses)
def test_spatial_momentum_is_r_cross_p_plus_R_J_omega_and_R_m_v(body, V, g):
    m, J = body
    R, r = g[:3, :3], g[:3, 3]
    p = R @ (m * V[3:])
    expected = np.concatenate([np.cross(r, p) + R @ J @ V[:3], p])
    out = spatial_momentum(g, V, spatial_inertia(m, J))
    assert_close(out, expected, scale=max(1.0, np.abs(r).max()) * max(1.0, np.abs(p).max()))


# --- g̈ (Eqs. 17–19) and a simulated motion ---------------------------------------------------


def _simulate(m, J, g0, V0, wrench, t_eval):
    """Integrate ġ = gV^, V̇ = Eq. 10b for a flattened state (R, r, V) with tight tolerances."""
    I = spatial_inertia(m, J)

    def rhs(t, y):
        R, V = y[:9].reshape(3, 3), y[12:]
        return np.concatenate(
            [(R @ so3.hat(V[:3])).ravel(), R @ V[3:], free_acceleration(V, I, wrench)]
        )

    y0 = np.concatenate([g0[:3, :3].ravel(), g0[:3, 3], V0])
    sol = solve_ivp(
        rhs, (0.0, t_eval[-1]), y0, method="DOP853", t_eval=t_eval, rtol=1e-13, atol=1e-13
    )
    assert sol.success
    g = np.zeros((len(t_eval), 4, 4))
    g[:, :3, :3] = sol.y[:9].T.reshape(-1, 3, 3)
    g[:, :3, 3] = sol.y[9:12].T
    g[:, 3, 3] = 1.0
    return g, sol.y[12:].T, I


MOTIONS = [
    # (mass, J, g0 coordinates, V0, body wrench)
    (2.0, np.diag([1.0, 2.0, 3.0]), np.zeros(6), [0.3, 1.0, 0.2, 0.5, -0.1, 0.2], np.zeros(6)),
    (
        5.0,
        np.array([[2.0, 0.3, -0.1], [0.3, 1.5, 0.2], [-0.1, 0.2, 2.5]]),
        np.array([0.4, -1.0, 2.0, 10.0, -3.0, 7.0]),
        [-0.8, 0.6, 1.1, 2.0, 0.0, -1.0],
        np.array([0.2, -0.1, 0.3, 1.0, 2.0, -0.5]),
    ),
]


@pytest.mark.parametrize(("m", "J", "xi0", "V0", "wrench"), MOTIONS)
def test_g_ddot_matches_finite_differences_of_a_simulated_motion(m, J, xi0, V0, wrench):
    h, t_mid = 0.05, 0.3
    g, V, I = _simulate(m, J, se3.exp(xi0), np.array(V0, float), wrench, t_mid + h * OFFSETS)
    fd = np.tensordot(D2, g, axes=1) / h**2
    k = 4  # the middle of the stencil
    expected = g_ddot(g[k], V[k], free_acceleration(V[k], I, wrench))
    assert np.array_equal(expected[3], np.zeros(4))
    # Integration error ≈ 1e-13 |g| amplified by Σ|cₖ|/h² ≈ 2.6e3 (observed ≤ 8e-10), plus
    # truncation ≈ h⁸|V|¹⁰/3150.
    assert_close(fd, expected, tol=1e-8, scale=max(1.0, np.abs(g).max()))


@pytest.mark.parametrize(("m", "J", "xi0", "V0", "wrench"), MOTIONS)
def test_g_ddot_is_the_sum_of_the_eq_18_and_eq_19_terms(m, J, xi0, V0, wrench):
    g, V, I = se3.exp(xi0), np.array(V0, float), spatial_inertia(m, J)
    u = np.array([0.1, 0.0, -0.2, 3.0, -1.0, 0.5])  # a control wrench
    a = free_acceleration(V, I, wrench)
    Vh = se3.hat(V)
    g_ddot_a = g @ (Vh @ Vh + se3.hat(a))  # Eq. 18
    g_ddot_c = g @ se3.hat(np.linalg.solve(I, u))  # Eq. 19
    assert_close(g_ddot(g, V, free_acceleration(V, I, wrench + u)), g_ddot_a + g_ddot_c, tol=1e-14)


def test_simulated_torque_free_motion_conserves_energy_and_spatial_momentum():
    m, J, xi0, V0, _ = MOTIONS[1]
    g, V, I = _simulate(m, J, se3.exp(xi0), np.array(V0, float), np.zeros(6), np.linspace(0, 3, 7))
    E = kinetic_energy(V, I)
    hN = spatial_momentum(g, V, I)
    assert np.abs(E / E[0] - 1.0).max() <= 1e-11
    assert np.abs(hN - hN[0]).max() <= 1e-11 * np.abs(hN[0]).max()


# --- batching --------------------------------------------------------------------------------


def test_batched_dynamics_equal_a_loop_over_elements():
    rng = np.random.default_rng(8)
    V = rng.normal(size=(2, 3, 6))
    tau = rng.normal(size=(2, 3, 6))
    g = se3.exp(rng.normal(size=(2, 3, 6)))
    I = spatial_inertia(3.0, np.diag([1.0, 2.0, 2.5]))
    I_batch = np.broadcast_to(I, (2, 3, 6, 6)).copy()
    a = free_acceleration(V, I, tau)
    a_b = free_acceleration(V, I_batch, tau)
    E = kinetic_energy(V, I)
    hN = spatial_momentum(g, V, I)
    G = g_ddot(g, V, a)
    for i in range(2):
        for j in range(3):
            assert_close(a[i, j], free_acceleration(V[i, j], I, tau[i, j]), tol=1e-15)
            assert_close(a_b[i, j], a[i, j], tol=1e-15)
            assert_close(E[i, j], kinetic_energy(V[i, j], I), tol=1e-15)
            assert_close(hN[i, j], spatial_momentum(g[i, j], V[i, j], I), tol=1e-15)
            assert_close(G[i, j], g_ddot(g[i, j], V[i, j], a[i, j]), tol=1e-15)
