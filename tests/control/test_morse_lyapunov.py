"""The Morse–Lyapunov tracking controller (McCann 2020, Section 5): the error dynamics it
assigns, its Lyapunov function, the printed law's divergence, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gmuk
from gmuk.control import MorseLyapunovController, morse_s, morse_s_rate_matrix
from gmuk.errors import DefinitionError, GmukError
from gmuk.lie import se3, so3
from gmuk.orbits import LVLHReference, fcei_orbit
from gmuk.scenarios import _lvlh as common

A = np.array([3.0, 2.0, 1.0])
#: The disturbed initial state of McCann (2020), Section 5.1, rotation block as printed.
R_PRINTED = np.array(
    [[-0.88728, 0.35421, -0.29541], [-0.25042, -0.90782, -0.33637], [-0.38733, -0.22448, 0.89420]]
)
V_PRINTED = np.array([0.05, 0.07, 0.01044, -5.69501e2, -1.17817e3, 328.89840])
R_PRINTED_POSITION = np.array([3.201e6, 163.150, 4997.447])


def fccl(variant="corrected", extra_forces=(), **gains):
    orbit = fcei_orbit(common.MU)
    sc = common.spacecraft()
    ref = LVLHReference(orbit)
    ctl = MorseLyapunovController(sc, ref, variant=variant, **gains)
    system = gmuk.System(
        [sc],
        [gmuk.ConfigurationTracking(sc, ref)],
        [gmuk.GravityGradient(orbit.mu), *extra_forces],
        [ctl],
    )
    U, _, Vt = np.linalg.svd(R_PRINTED)
    g0 = np.eye(4)
    g0[:3, :3] = U @ Vt
    g0[:3, 3] = R_PRINTED_POSITION
    return system, system.state(g={"spacecraft": g0}, V={"spacecraft": V_PRINTED}), ctl, orbit


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(-3.0, 3.0), min_size=6, max_size=6))
def test_s_is_eq_84_and_its_rate_matrix_is_its_derivative(x):
    E = so3.exp(np.array(x[:3]))
    w = np.array(x[3:])
    direct = sum(A[i] * np.cross(E.T @ np.eye(3)[i], np.eye(3)[i]) for i in range(3))
    assert np.allclose(morse_s(E, A), direct, rtol=0, atol=1e-14)
    h = 1e-6
    fd = (morse_s(E @ so3.exp(h * w), A) - morse_s(E @ so3.exp(-h * w), A)) / (2 * h)
    assert np.allclose(morse_s_rate_matrix(E, A) @ w, fd, rtol=0, atol=1e-8)


def test_s_vanishes_at_the_identity_and_the_three_saddles_only():
    for E in (np.eye(3), np.diag([1.0, -1, -1]), np.diag([-1.0, 1, -1]), np.diag([-1.0, -1, 1])):
        assert np.abs(morse_s(E, A)).max() == 0.0
    rng = np.random.default_rng(1)
    for _ in range(200):
        assert np.linalg.norm(morse_s(so3.exp(rng.normal(size=3)), A)) > 1e-6


def _psi(ctl, t, g, V):
    return ctl.errors(t, g, V).psi


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_closed_loop_follows_the_assigned_error_dynamics(seed):
    """Along the System's total acceleration, ψ̇ = −K₂ψ − κ[0; q] − k_I z (central
    differences of ψ along ġ = gV^, V̇ = acc.total)."""
    rng = np.random.default_rng(seed)
    system, _, ctl, _ = fccl(k_integral=1e-3)
    t = 1000.0 * rng.uniform()
    ref = ctl.reference.evaluate(t)
    g = ref.g @ se3.exp(np.r_[rng.normal(size=3), 1e3 * rng.normal(size=3)])
    V = ref.V + np.r_[0.05 * rng.normal(size=3), 5.0 * rng.normal(size=3)]
    z = rng.normal(size=6)
    state = system.state(g={"spacecraft": g}, V={"spacecraft": V}, z=z, t=t)
    acc = system.accelerations(state)
    Vdot = acc.total

    def central(h):
        plus = _psi(ctl, t + h, g @ se3.exp(h * V + 0.5 * h * h * Vdot), V + h * Vdot)
        minus = _psi(ctl, t - h, g @ se3.exp(-h * V + 0.5 * h * h * Vdot), V - h * Vdot)
        return (plus - minus) / (2 * h)

    # Central differences err by O(h²), large here (|v| ≈ 1.4 km/s turns with the body):
    # Richardson's extrapolation of h = 2.5 ms and 1.25 ms leaves O(h⁴), below the round-off
    # of positions of 3.2e6 m over 2h (≈ 3e-7 m/s²).
    psi_dot = (4.0 * central(1.25e-3) - central(2.5e-3)) / 3.0
    e = ctl.errors(t, g, V)
    want = -ctl._K2 * e.psi - np.r_[0, 0, 0, ctl.kappa * e.q] - ctl.k_integral * z
    assert np.allclose(psi_dot, want, rtol=0, atol=1e-6 * max(1.0, np.abs(want).max()))
    assert np.array_equal(acc.z_dot, e.psi)
    # The UK wrench and the controller's are recorded apart; the total adds both.
    assert np.allclose(acc.extra, np.linalg.solve(system.mass_matrix, acc.control_force))


def test_on_the_nominal_motion_the_controller_does_nothing():
    system, _, ctl, _ = fccl()
    ref = ctl.reference.evaluate(123.0)
    state = system.state(g={"spacecraft": ref.g}, V={"spacecraft": ref.V}, t=123.0)
    acc = system.accelerations(state)
    # zero to round-off of the loads it adds to (gravity ≈ 3.4 kN on the spacecraft)
    scale = np.abs(system.mass_matrix @ acc.total).max()
    assert np.abs(acc.control_force).max() <= 1e-12 * scale


def test_fccl_converges_with_a_lyapunov_function_that_never_increases():
    system, state, ctl, orbit = fccl()
    t = np.linspace(0.0, 600.0, 121)
    traj = system.simulate(state, (0.0, 600.0), t_eval=t, rtol=1e-9, atol=1e-9, method="DOPRI5")
    W, W_dot = ctl.lyapunov(traj)
    assert np.all(np.diff(W) <= 1e-9 * W[0])
    assert W_dot.max() <= 0.0
    # Ẇ agrees with the slope of W along the run (trapezoid rule over each interval).
    slope = np.diff(W) / np.diff(t)
    mid = 0.5 * (W_dot[1:] + W_dot[:-1])
    assert np.allclose(slope[60:], mid[60:], rtol=2e-2, atol=1e-6 * abs(W[0]))
    pos, att = common.reference_errors(traj, orbit)
    assert att[-1] < 1e-6 and att[0] > 0.5
    assert pos[-1] < 0.9 * pos[0]


def test_the_printed_law_diverges_on_the_lvlh_orbit():
    system, state, _, orbit = fccl(variant="thesis")
    t = np.linspace(0.0, 2.0, 5)
    traj = system.simulate(state, (0.0, 2.0), t_eval=t, rtol=1e-8, atol=1e-8)
    pos, _ = common.reference_errors(traj, orbit)
    assert pos[-1] > 2.0 * pos[0]  # 5.1 km → 12.6 km in 2 s, then ≈ e^{t}


def test_bad_input_is_a_clear_gmuk_error():
    sc = common.spacecraft()
    ref = LVLHReference(fcei_orbit(common.MU))
    with pytest.raises(DefinitionError, match=r"ReferenceTrajectory.*got dict"):
        MorseLyapunovController(sc, {"g": np.eye(4)})  # type: ignore[arg-type]
    with pytest.raises(DefinitionError, match=r"RigidBody.*got PointMass"):
        MorseLyapunovController(gmuk.PointMass("p", 1.0), ref)  # type: ignore[arg-type]
    with pytest.raises(DefinitionError, match=r"RigidBody.*got str"):
        MorseLyapunovController("spacecraft", ref)  # type: ignore[arg-type]
    for gains, needle in (
        ({"k11": -1.0}, "k11 must be a number > 0"),
        ({"k21": [1.0, 2.0]}, r"k21 must be a finite number > 0 or 3 .*shape \(2,\)"),
        ({"k22": [1.0, -2.0, 1.0]}, r"k22 must be a finite number > 0 .*-2.0"),
        ({"kappa": "x"}, "kappa must be a number"),
        ({"a": (1.0, 1.0, 2.0)}, "distinct"),
        ({"a": (1.0, 2.0)}, "a must be 3 finite numbers"),
        ({"k_integral": -1e-3}, "k_integral must be a number >= 0"),
        ({"morse_weight": 1.0}, "morse_weight must be < 4 k11 min"),
        ({"variant": "printed"}, "variant must be"),
        ({"bound": 3.0}, "bound must be a callable"),
    ):
        with pytest.raises(DefinitionError, match=needle):
            MorseLyapunovController(sc, ref, **gains)
    assert issubclass(DefinitionError, GmukError)
    other = common.spacecraft("other")
    with pytest.raises(DefinitionError, match=r"controller .* refers to unknown body 'other'"):
        gmuk.System([sc], controllers=[MorseLyapunovController(other, ref)])


def test_a_user_bound_is_subtracted_and_a_bad_one_named():
    system, state, ctl, _ = fccl()
    sc = system.bodies[0]
    bound = np.array([1e-6, 0, 0, 1e-3, 0, 0])
    robust = gmuk.System(
        system.bodies,
        system.constraints,
        system.forces,
        [MorseLyapunovController(sc, ctl.reference, bound=lambda t, g, V: bound)],
    )
    u0 = system.accelerations(state).control_force
    u1 = robust.accelerations(
        robust.state(g={"spacecraft": state.g[0]}, V={"spacecraft": state.V[0]})
    ).control_force
    assert np.allclose(u0 - u1, sc.mass_matrix() @ bound, rtol=0, atol=1e-12 * np.abs(u0).max())
    broken = gmuk.System(
        system.bodies,
        system.constraints,
        system.forces,
        [MorseLyapunovController(sc, ctl.reference, bound=lambda t, g, V: [1.0])],
    )
    with pytest.raises(DefinitionError, match=r"bound.*must return 6 finite numbers"):
        broken.accelerations(
            broken.state(g={"spacecraft": state.g[0]}, V={"spacecraft": state.V[0]})
        )
