"""Reaction wheels (issue #29, item 1): the motor's limits, the two forms, momentum.

The two forms are the Udwadia–Kalaba one (each wheel a rigid body on a relative constraint
free about its spin axis, the motor a modeled torque pair) and the internal-momentum one
(the bus alone, the wheels' momenta as controller states). Independent references: a wheel
on a principal axis driven by a constant torque (the bus's rate is then −u t / I_w, exactly),
the conservation of the total angular momentum, and each form against the other.
"""

from __future__ import annotations

import numpy as np
import pytest
from rw_setup import (
    I_B,
    J_S,
    RPM,
    SPEEDS0,
    internal,
    momentum_N_internal,
    momentum_N_uk,
    uk,
    uk_wheel_speeds,
    wheels,
)

import gmuk
from gmuk.actuators import MomentumWheels, ReactionWheel, WheelArray, WheelMotors
from gmuk.actuators.wheels import wheel_array_torque, wheel_spin_torque
from gmuk.errors import DefinitionError


def test_motor_clips_its_command_at_the_torque_limit() -> None:
    w = ReactionWheel([0, 0, 1], 0.1, max_torque=0.2)
    assert w.spin_torque(5.0, 10.0) == 0.2
    assert w.spin_torque(-5.0, 10.0) == -0.2
    assert w.spin_torque(0.05, 10.0) == 0.05


def test_motor_gives_no_torque_that_would_spin_the_wheel_past_its_speed_limit() -> None:
    w = ReactionWheel([0, 0, 1], 0.1, max_torque=0.2, max_speed=100.0)
    assert w.spin_torque(0.1, 100.0) == 0.0
    assert w.spin_torque(-0.1, -100.0) == 0.0
    assert w.spin_torque(-0.1, 100.0) == -0.1  # slowing down is allowed
    assert w.spin_torque(0.1, 99.0) == 0.1


def test_viscous_friction_opposes_the_relative_speed() -> None:
    w = ReactionWheel([0, 1, 0], 0.1, friction=1e-4)
    assert w.spin_torque(0.0, 300.0) == pytest.approx(-0.03, rel=1e-15)
    assert wheel_spin_torque(0.01, -200.0, np.inf, np.inf, 1e-4) == pytest.approx(0.03)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"axis_B": [1.0, 0.0, 1e-3], "spin_inertia": 0.1}, "unit vector"),
        ({"axis_B": [1, 0, 0], "spin_inertia": 0.0}, "spin_inertia"),
        ({"axis_B": [1, 0, 0], "spin_inertia": 0.1, "max_torque": -1.0}, "max_torque"),
        ({"axis_B": [1, 0, 0], "spin_inertia": 0.1, "friction": -1.0}, "friction"),
        ({"axis_B": [1, 0], "spin_inertia": 0.1}, "axis_B"),
    ],
)
def test_wheel_refuses_bad_definitions(kwargs: dict, match: str) -> None:
    with pytest.raises(DefinitionError, match=match):
        ReactionWheel(**kwargs)


def test_wheel_is_immutable() -> None:
    w = ReactionWheel([1, 0, 0], 0.1)
    with pytest.raises(AttributeError, match="immutable"):
        w.max_torque = 1.0
    with pytest.raises(ValueError, match="read-only"):
        w.axis_B[0] = 0.5


def test_wheel_frame_has_the_spin_axis_first_and_is_a_rotation() -> None:
    rng = np.random.default_rng(3)
    for _ in range(20):
        g = rng.normal(size=3)
        R = ReactionWheel(g / np.linalg.norm(g), 0.1).frame_B()
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-15)
        assert np.linalg.det(R) == pytest.approx(1.0)
        np.testing.assert_allclose(R[:, 0], g / np.linalg.norm(g), atol=1e-15)


def test_momenta_and_speeds_are_inverse_and_give_the_issue_momentum() -> None:
    w = wheels()
    omega = np.array([0.001, -0.01, 0.03])
    h = w.momenta(omega, SPEEDS0)
    np.testing.assert_allclose(w.speeds(omega, h), SPEEDS0, rtol=1e-15)
    # H = I_B ω + J_s Σ Ω_i g_i (issue #29) = I_w ω + G h
    H = w.angular_momentum_B(I_B, omega, SPEEDS0)
    np.testing.assert_allclose(w.spun_down_inertia(I_B) @ omega + w.G @ h, H, rtol=1e-14)
    np.testing.assert_allclose(H, I_B @ omega + J_S * SPEEDS0, rtol=1e-15)


def _constant_torque(form: str) -> tuple[gmuk.Trajectory, float]:
    """One wheel on the bus's z axis (a principal axis), its motor at a constant 0.01 N·m
    from rest: the bus turns about z with ω_z = −u t / I_w,zz (both forms)."""
    u = 0.01
    w = WheelArray([ReactionWheel([0, 0, 1], J_S)])
    V0 = {"bus": np.zeros(6)}
    if form == "internal":
        # the controller-free way: constant command, the wheel momentum as a state
        bus = gmuk.RigidBody("bus", 750.0, w.spun_down_inertia(I_B))

        class Constant(gmuk.Controller):
            def control(self, state, z):  # type: ignore[no-untyped-def]
                h_dot = np.array([u])
                L = np.empty(3)
                wheel_array_torque(state.twist("bus")[:3], z, w.G, h_dot, L)
                return [np.r_[L, 0.0, 0.0, 0.0]], h_dot

        ctl = Constant(["bus"], n_states=1)
        system = gmuk.System([bus], controllers=[ctl])
        state = system.state(g={"bus": np.eye(4)}, V=V0, z=[0.0])
        I_zz = w.spun_down_inertia(I_B)[2, 2]
    else:
        bus = gmuk.RigidBody("bus", 750.0, w.uk_bus_inertia(I_B))
        bodies, cons = w.uk_parts(bus)
        motors = WheelMotors(bus, bodies, w, lambda t, R, om, sp: np.array([u]))
        system = gmuk.System([bus, *bodies], constraints=cons, forces=[motors])
        g_w, V_w = w.uk_state(bodies, np.eye(4), np.zeros(6), [0.0])
        state = system.state(g={"bus": np.eye(4), **g_w}, V={**V0, **V_w})
        I_zz = w.spun_down_inertia(I_B)[2, 2]
    traj = system.simulate(state, (0.0, 20.0), rtol=1e-12, atol=1e-12)
    return traj, u / I_zz


@pytest.mark.parametrize("form", ["internal", "uk"])
def test_constant_motor_torque_spins_the_bus_back_at_the_analytic_rate(form: str) -> None:
    traj, rate = _constant_torque(form)
    omega = traj.body("bus").omega
    np.testing.assert_allclose(omega[:, 2], -rate * traj.t, rtol=1e-11, atol=1e-16)
    np.testing.assert_allclose(omega[:, :2], 0.0, atol=1e-16)


def test_internal_momentum_form_conserves_momentum_over_ten_minutes() -> None:
    """The issue's 600 s MRP slew with friction: motors, friction and gyroscopic torques are
    all internal, so H_N stays constant to 1e-12 relative (measured 1.1e-13 at rtol 1e-13)."""
    s = internal(wheels(friction=1e-4))
    traj = s.system.simulate(s.state, (0.0, 600.0), rtol=1e-13, atol=1e-13)
    H = momentum_N_internal(s, traj)
    assert np.abs(H - H[0]).max() / np.linalg.norm(H[0]) <= 1e-12
    assert np.abs(traj.body("bus").omega[-1]).max() < 1e-5  # it did slew


@pytest.mark.slow
def test_uk_form_conserves_momentum_over_ten_minutes() -> None:
    """Free wheels at 100–300 rpm on a tumbling bus, 600 s, the Udwadia–Kalaba bearing
    torques the only coupling: H_N constant to 1e-12 relative at rtol = atol = 1e-15
    (measured 4.4e-13; 62641 steps, about 20 s)."""
    s = uk(wheels(), motors=False)
    traj = s.system.simulate(s.state, (0.0, 600.0), rtol=1e-15, atol=1e-15, max_steps=10**7)
    H = momentum_N_uk(s, traj)
    assert np.abs(H - H[0]).max() / np.linalg.norm(H[0]) <= 1e-12


def test_uk_form_conserves_momentum_under_motors_and_friction() -> None:
    """The motor pair and friction are internal in the UK form too: over the first 10 s of
    the slew H_N moves by at most 1e-12 relative at rtol = atol = 1e-14 (measured 6.8e-13),
    and what moves is the integrator's error: it is ten times larger per decade of
    tolerance (7.2e-11 at 1e-12), where a leak in the model would not shrink."""
    errors = []
    for tol in (1e-12, 1e-14):
        s = uk(wheels(friction=1e-4))
        traj = s.system.simulate(s.state, (0.0, 10.0), rtol=tol, atol=tol)
        H = momentum_N_uk(s, traj)
        errors.append(np.abs(H - H[0]).max() / np.linalg.norm(H[0]))
    assert errors[1] <= 1e-12
    assert errors[0] > 30.0 * errors[1]


def test_the_two_forms_agree_under_mrp_feedback() -> None:
    """The first 30 s of the slew (motors saturated, then not; friction on): bus attitude,
    rates and wheel speeds of the UK form at rtol 1e-12 and of the internal-momentum form
    at 1e-13 agree to 1e-9 (each form's own change between tolerances is below that)."""
    w = wheels(friction=1e-4)
    a, b = internal(w), uk(w)
    t_eval = np.linspace(0.0, 30.0, 31)
    ta = a.system.simulate(a.state, (0.0, 30.0), rtol=1e-13, atol=1e-13, t_eval=t_eval)
    tb = b.system.simulate(b.state, (0.0, 30.0), rtol=1e-12, atol=1e-12, t_eval=t_eval)
    Ra, Rb = ta.body("bus").R, tb.body("bus").R
    angle = np.array(
        [np.linalg.norm(gmuk.lie.so3.log(x.T @ y)) for x, y in zip(Ra, Rb, strict=True)]
    )
    assert angle.max() < 1e-9
    np.testing.assert_allclose(tb.body("bus").omega, ta.body("bus").omega, rtol=0, atol=1e-10)
    speeds_a = np.array(
        [w.speeds(o, z[:3]) for o, z in zip(ta.body("bus").omega, ta.z, strict=True)]
    )
    np.testing.assert_allclose(uk_wheel_speeds(b, tb), speeds_a, rtol=0, atol=1e-8)
    # the motors were saturated at the start and not at the end: both regimes were compared
    u0 = a.law.command(Ra[0], ta.body("bus").omega[0], ta.z[0, :3])[2]
    assert np.abs(u0).max() > 0.2
    assert np.abs(speeds_a[-1] - speeds_a[0]).max() > 10 * RPM


def test_wheel_motors_checks_its_definition() -> None:
    w = wheels()
    with pytest.raises(DefinitionError, match="one wheel body per wheel"):
        WheelMotors("bus", ["a", "b"], w)
    with pytest.raises(DefinitionError, match="callable"):
        WheelMotors("bus", ["a", "b", "c"], w, command=3.0)
    with pytest.raises(DefinitionError, match="ReactionWheel"):
        WheelArray([])


def test_one_command_flies_both_forms_and_momentum_wheels_is_mrp_feedback() -> None:
    """MomentumWheels driven by MRPFeedback.wheel_command (Python, called back) flies the
    same 60 s as MRPFeedback itself (compiled) to the integrator's tolerance: at
    rtol = atol = 1e-14 the wheel momenta differ by 2.7e-12 N·m·s (3.8e-10 at 1e-13; the
    step sequences differ: MRPFeedback carries three integral states more). The
    internal-momentum physics is one definition under any command."""
    w = wheels(friction=1e-4)
    a = internal(w)
    bus = gmuk.RigidBody("bus", 750.0, w.spun_down_inertia(I_B))
    driven = MomentumWheels(bus, w, a.law.wheel_command)
    system = gmuk.System([bus], controllers=[driven])
    state = system.state(
        g={"bus": a.state.pose("bus")},
        V={"bus": a.state.twist("bus")},
        z=driven.states(a.state.twist("bus")[:3], SPEEDS0),
    )
    t_eval = np.linspace(0.0, 60.0, 7)
    ta = a.system.simulate(a.state, (0.0, 60.0), rtol=1e-14, atol=1e-14, t_eval=t_eval)
    tb = system.simulate(state, (0.0, 60.0), rtol=1e-14, atol=1e-14, t_eval=t_eval)
    Ra, Rb = ta.body("bus").R, tb.body("bus").R
    angle = [np.linalg.norm(gmuk.lie.so3.log(x.T @ y)) for x, y in zip(Ra, Rb, strict=True)]
    assert max(angle) < 1e-12
    np.testing.assert_allclose(tb.z, ta.z[:, :3], rtol=1e-11, atol=0)
    with pytest.raises(DefinitionError, match="callable"):
        MomentumWheels(bus, w, None)  # type: ignore[arg-type]
