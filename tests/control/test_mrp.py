"""MRP feedback on reaction wheels (issue #29, item 6): gmuk.control.MRPFeedback.

References: gmuk.attitude's MRPs (themselves tested against scipy and Schaub & Junkins),
the law written out with numpy from Basilisk's mrpFeedback/rwMotorTorque equations, the
Lyapunov function of the PD law, and the closed loop's steady state under a constant
disturbance (proportional–derivative: an offset K σ = −L_d; with the integral term: none).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gmuk
from gmuk.actuators import ReactionWheel, WheelArray
from gmuk.attitude import R_NB_from_mrp, mrp_from_R_NB
from gmuk.control.mrp import mrp_short
from gmuk.errors import DefinitionError
from gmuk.lie import so3

I_B = np.diag([900.0, 800.0, 600.0])
J_S = 50.0 / (6000.0 * 2.0 * np.pi / 60.0)

rotation_vectors = st.lists(st.floats(-np.pi, np.pi, allow_nan=False), min_size=3, max_size=3).map(
    np.array
)


@settings(max_examples=200, deadline=None)
@given(rotation_vectors)
def test_kernel_mrps_are_gmuk_attitudes_short_set(phi: np.ndarray) -> None:
    R = so3.exp(phi)
    sigma = np.empty(3)
    mrp_short(np.ascontiguousarray(R), sigma)
    np.testing.assert_allclose(sigma, mrp_from_R_NB(R), atol=1e-14)
    assert np.linalg.norm(sigma) <= 1.0 + 1e-15


def test_error_switches_to_the_shadow_set_past_half_a_turn() -> None:
    """Rotations of 179° and 181° about one axis: the error is the short way round both
    times, so the commanded torque turns the body back across the half-turn, not around."""
    axis = np.array([0.0, 0.0, 1.0])
    sigmas = []
    for deg in (179.0, 181.0):
        R = so3.exp(np.deg2rad(deg) * axis)
        sigma = np.empty(3)
        mrp_short(np.ascontiguousarray(R), sigma)
        sigmas.append(sigma)
    assert sigmas[0][2] > 0.98 and sigmas[1][2] < -0.98


def _pyramid(beta: float = np.deg2rad(54.75)) -> WheelArray:
    axes = [
        [np.cos(beta) * np.cos(a), np.cos(beta) * np.sin(a), np.sin(beta)]
        for a in np.deg2rad([0.0, 90.0, 180.0, 270.0])
    ]
    return WheelArray([ReactionWheel(g, J_S) for g in axes])


@pytest.mark.parametrize("wheels", ["triad", "pyramid"])
def test_command_is_the_basilisk_law_written_out(wheels: str) -> None:
    """L = −K σ − P ω + ω × (I_B ω + Σ J_s Ω g) and u = −Gᵀ(GGᵀ)⁻¹ L (numpy's pseudo-inverse),
    at random states; for the triad u_i = −g_iᵀ L."""
    w = WheelArray([ReactionWheel(g, J_S) for g in np.eye(3)]) if wheels == "triad" else _pyramid()
    ctl = gmuk.MRPFeedback("bus", w, K=3.5, P=30.0, inertia_B=I_B)
    rng = np.random.default_rng(7)
    for _ in range(50):
        R = so3.exp(rng.uniform(-3, 3, 3))
        omega = 0.05 * rng.normal(size=3)
        speeds = 300.0 * rng.normal(size=len(w))
        h = w.momenta(omega, speeds)
        sigma, L, u = ctl.command(R, omega, h)
        H = I_B @ omega + w.G @ (J_S * speeds)
        L_ref = -3.5 * mrp_from_R_NB(R) - 30.0 * omega + np.cross(omega, H)
        np.testing.assert_allclose(sigma, mrp_from_R_NB(R), atol=1e-14)
        np.testing.assert_allclose(L, L_ref, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(u, -np.linalg.pinv(w.G) @ L_ref, rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(ctl.wheel_command(0.0, R, omega, speeds), u, rtol=1e-13)
        if wheels == "triad":
            np.testing.assert_allclose(u, -L_ref, rtol=1e-12, atol=1e-14)


def test_reference_attitude_is_tracked() -> None:
    """With R_NR given, σ is σ_BR: the body at R_NR has zero error and zero command."""
    R_NR = so3.exp(np.array([0.3, -0.2, 0.5]))
    ctl = gmuk.MRPFeedback(
        "bus", [ReactionWheel(g, J_S) for g in np.eye(3)], K=1.0, P=1.0, inertia_B=I_B, R_NR=R_NR
    )
    sigma, L, u = ctl.command(R_NR, np.zeros(3), np.zeros(3))
    np.testing.assert_allclose(sigma, 0.0, atol=1e-15)
    np.testing.assert_allclose(L, 0.0, atol=1e-15)
    np.testing.assert_allclose(u, 0.0, atol=1e-15)


def _pointing(wheels, duration, disturbance=None, at_rest=False, **gains):  # type: ignore[no-untyped-def]
    bus = gmuk.RigidBody("bus", 750.0, wheels.spun_down_inertia(I_B))
    law = gmuk.MRPFeedback(bus, wheels, inertia_B=I_B, **{"K": 3.5, "P": 30.0, **gains})
    forces = [] if disturbance is None else [gmuk.AppliedWrench(bus, [*disturbance, 0, 0, 0])]
    system = gmuk.System([bus], forces=forces, controllers=[law])
    g0 = np.eye(4)
    g0[:3, :3] = R_NB_from_mrp(np.zeros(3) if at_rest else [0.1, 0.2, -0.3])
    omega0 = np.zeros(3) if at_rest else np.array([0.001, -0.01, 0.03])
    state = system.state(
        g={"bus": g0},
        V={"bus": np.r_[omega0, 0, 0, 0]},
        z=law.states(omega0, np.array([100.0, 200.0, 300.0, 50.0][: len(wheels)])),
    )
    t_eval = np.linspace(0.0, duration, 201)
    return law, system.simulate(state, (0.0, duration), rtol=1e-11, atol=1e-11, t_eval=t_eval)


def test_lyapunov_function_never_rises_without_saturation() -> None:
    """Unsaturated motors (no limit), the gyroscopic term cancelled: V = 2K ln(1 + σᵀσ) +
    ½ ωᵀ I_w ω (I_w = I_B − Σ J_s g gᵀ) has V̇ = −P |ω|² ≤ 0 along the closed loop
    (Schaub & Junkins 2018, §8.4); on the pyramid, which runs in Python, as on the triad,
    which runs compiled."""
    for w in (WheelArray([ReactionWheel(g, J_S) for g in np.eye(3)]), _pyramid()):
        _, traj = _pointing(w, 300.0)
        b = traj.body("bus")
        sigma = mrp_from_R_NB(b.R)
        I_w = w.spun_down_inertia(I_B)
        V = 2 * 3.5 * np.log1p((sigma**2).sum(axis=1)) + 0.5 * np.einsum(
            "ki,ij,kj->k", b.omega, I_w, b.omega
        )
        assert np.all(np.diff(V) <= 1e-12 * V[0])
        assert V[-1] < 1e-4 * V[0]


def test_integral_term_removes_the_offset_of_a_constant_disturbance() -> None:
    """A constant body torque L_d on a spacecraft at rest on target: PD settles where
    K σ = L_d (ω = 0); with K_I the integral absorbs it and σ → 0. (From the slew's start
    the saturated first minutes would wind the integral up: Basilisk's integral_limit.)"""
    L_d = np.array([0.01, -0.02, 0.015])
    w = WheelArray([ReactionWheel(g, J_S, max_torque=0.2) for g in np.eye(3)])
    _, pd = _pointing(w, 3000.0, disturbance=L_d, at_rest=True)
    sigma_pd = mrp_from_R_NB(pd.body("bus").R[-1])
    np.testing.assert_allclose(3.5 * sigma_pd, L_d, rtol=1e-5)
    law, pid = _pointing(w, 3000.0, disturbance=L_d, at_rest=True, K_I=1e-3)
    sigma_pid = mrp_from_R_NB(pid.body("bus").R[-1])
    assert np.linalg.norm(sigma_pid) < 1e-3 * np.linalg.norm(sigma_pd)
    # the integral holds what the disturbance needs: P K_I ∫K σ dt = L_d at rest
    np.testing.assert_allclose(30.0 * 1e-3 * pid.z[-1, 3:], L_d, rtol=1e-4)
    assert law.n_states == 6


def test_mrp_feedback_checks_its_definition() -> None:
    w = [ReactionWheel(g, J_S) for g in np.eye(3)]
    with pytest.raises(DefinitionError, match="K must be"):
        gmuk.MRPFeedback("bus", w, K=-1.0, P=1.0, inertia_B=I_B)
    with pytest.raises(DefinitionError, match="span"):
        gmuk.MRPFeedback("bus", w[:2], K=1.0, P=1.0, inertia_B=I_B)
    with pytest.raises(DefinitionError, match="inertia_B"):
        gmuk.MRPFeedback("bus", w, K=1.0, P=1.0, inertia_B=np.eye(2))
    wrong = gmuk.RigidBody("bus", 750.0, I_B)  # the locked inertia, not I_B − Σ J_s g gᵀ
    with pytest.raises(DefinitionError, match="spun_down_inertia"):
        gmuk.MRPFeedback(wrong, w, K=1.0, P=1.0, inertia_B=I_B)
    with pytest.raises(DefinitionError, match="integral"):
        gmuk.MRPFeedback("bus", w, K=1.0, P=1.0, inertia_B=I_B, K_I=0.1).wheel_command(
            0.0, np.eye(3), np.zeros(3), np.zeros(3)
        )
