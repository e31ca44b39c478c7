"""Thrusters (issue #29, item 2): allocation within limits, pulse-width modulation with a
minimum impulse bit and an on-time quantum, the mass they spend, and a slew that respects
every limit at every step.

Independent references: the rocket equation (a thruster through the centre of mass), the
spin-up of a body whose mass scales uniformly (ω = J₀⁻¹ τ (m₀/k) ln(m₀/m)), and scipy's
solve_ivp on the variable-mass point-mass equations in a central field.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.integrate

import gmuk
from gmuk.actuators import (
    G0,
    Thruster,
    Thrusters,
    ThrusterSet,
    couple_thrusters,
    simulate_pulsed,
)
from gmuk.attitude import R_NB_from_mrp, mrp_from_R_NB
from gmuk.constraints.unilateral import PointPlaneContact
from gmuk.errors import DefinitionError, ShapeError

INERTIA = np.diag([300.0, 250.0, 200.0])
MASS = 500.0


def _spacecraft(
    thrusters: ThrusterSet, *, dry_mass: float = 0.0, forces: tuple = ()
) -> tuple[gmuk.RigidBody, Thrusters, gmuk.System]:
    body = gmuk.RigidBody("sc", MASS, INERTIA)
    ctl = Thrusters(body, thrusters, dry_mass=dry_mass)
    return body, ctl, gmuk.System([body], forces=list(forces), controllers=[ctl])


def _at_rest(system: gmuk.System, sigma: np.ndarray | None = None) -> gmuk.State:
    g = np.eye(4)
    g[:3, :3] = R_NB_from_mrp(np.zeros(3) if sigma is None else sigma)
    return system.state({"sc": g}, {"sc": np.zeros(6)})


# ---------------------------------------------------------------- one thruster


def test_thruster_column_is_its_torque_and_force_per_newton() -> None:
    t = Thruster([1.0, 2.0, 0.5], [0.0, 0.6, 0.8], 22.0, 220.0)
    np.testing.assert_array_equal(
        t.column, np.r_[np.cross([1.0, 2.0, 0.5], [0, 0.6, 0.8]), 0, 0.6, 0.8]
    )
    assert t.mass_flow == pytest.approx(22.0 / (220.0 * 9.80665), rel=1e-15)


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        (([0, 0, 0], [1.0, 0.1, 0.0], 1.0, 200.0), {}, "unit vector"),
        (([0, 0, 0], [1.0, 0.0, 0.0], 0.0, 200.0), {}, "max_thrust must be a number > 0"),
        (([0, 0, 0], [1.0, 0.0, 0.0], 1.0, -3.0), {}, "isp must be a number > 0"),
        (([0, 0, 0], [1.0, 0.0, 0.0], 1.0, 200.0), {"min_impulse_bit": -1e-3}, ">= 0"),
        (([0, 0, 0], [1.0, 0.0, 0.0], 1.0, 200.0), {"on_time_quantum": np.nan}, "finite"),
        (([0, 0], [1.0, 0.0, 0.0], 1.0, 200.0), {}, "position_B"),
    ],
)
def test_thruster_refuses_what_is_not_a_thruster(args: tuple, kwargs: dict, match: str) -> None:
    with pytest.raises(DefinitionError, match=match):
        Thruster(*args, **kwargs)


def test_thruster_is_immutable() -> None:
    t = Thruster([0, 0, 0], [1, 0, 0], 1.0, 200.0)
    with pytest.raises(AttributeError, match="immutable"):
        t.max_thrust = 2.0  # type: ignore[misc]


# ---------------------------------------------------------------- allocation


def test_allocation_reaches_a_command_within_reach_inside_the_limits() -> None:
    ts = couple_thrusters(1.2, 10.0, 220.0)
    rng = np.random.default_rng(7)
    for _ in range(20):
        torque = rng.uniform(-20.0, 20.0, size=3)  # reach: 2 · 1.2 m · 10 N = 24 N·m per axis
        a = ts.allocate(np.r_[torque, 0.0, 0.0, 0.0])
        assert np.all(a.thrusts >= 0.0) and np.all(a.thrusts <= 10.0)
        np.testing.assert_allclose(a.wrench, np.r_[torque, 0, 0, 0], rtol=0, atol=1e-9)
        assert a.error < 1e-9


def test_allocation_saturates_a_command_beyond_reach_at_the_closest_wrench() -> None:
    ts = couple_thrusters(1.0, 10.0, 220.0)
    a = ts.allocate([50.0, -3.0, 0.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(a.wrench, [20.0, -3.0, 0.0, 0.0, 0.0, 0.0], atol=1e-9)
    assert a.error == pytest.approx(30.0, rel=1e-12)
    assert np.all(a.thrusts <= 10.0)


def test_allocation_spends_the_least_propellant_among_equal_wrenches() -> None:
    # Two thrusters with the same line of action: the efficient one (higher Isp) does it all.
    poor = Thruster([0, 0, 0], [1, 0, 0], 10.0, 150.0)
    good = Thruster([0, 0, 0], [1, 0, 0], 10.0, 300.0)
    a = ThrusterSet([poor, good]).allocate([0, 0, 0, 7.0, 0, 0])
    np.testing.assert_allclose(a.thrusts, [0.0, 7.0], atol=1e-9)
    # Beyond the good one's limit, the poor one gives the rest.
    a = ThrusterSet([poor, good]).allocate([0, 0, 0, 13.0, 0, 0])
    np.testing.assert_allclose(a.thrusts, [3.0, 10.0], atol=1e-9)


def test_allocation_weights_trade_torque_against_force() -> None:
    # One thruster off the centre of mass: a pure force command cannot be met without torque.
    ts = ThrusterSet([Thruster([0, 1.0, 0], [1, 0, 0], 10.0, 200.0)])
    torque_heavy = ts.allocate([0, 0, 0, 5.0, 0, 0], weights=[100, 100, 100, 1, 1, 1])
    force_heavy = ts.allocate([0, 0, 0, 5.0, 0, 0], weights=[1, 1, 1, 100, 100, 100])
    assert torque_heavy.thrusts[0] < 1e-3 < force_heavy.thrusts[0]


def test_allocation_refuses_a_command_of_the_wrong_shape() -> None:
    ts = couple_thrusters(1.0, 10.0, 220.0)
    with pytest.raises(ShapeError):
        ts.allocate([1.0, 2.0, 3.0])
    with pytest.raises(DefinitionError, match="weights"):
        ts.allocate(np.zeros(6), weights=[1, 1, 1, 0, 1, 1])


# ---------------------------------------------------------------- modulation


def test_on_times_are_whole_quanta_and_drop_firings_below_the_minimum_impulse_bit() -> None:
    t = Thruster([0, 0, 0], [1, 0, 0], 10.0, 200.0, min_impulse_bit=0.05, on_time_quantum=0.004)
    ts = ThrusterSet([t] * 5)
    f = np.array([0.0, 0.04, 0.06, 3.3337, 10.0])  # N, over a 1 s period
    on = ts.on_times(f, 1.0)
    # 0.004 s → 0.04 N·s < 0.05: dropped; 0.006 s → 0.008 s (2 quanta, 0.08 N·s); 0.33337 s
    # → 83 quanta; the whole period.
    np.testing.assert_allclose(on, [0.0, 0.0, 0.008, 83 * 0.004, 1.0], rtol=0, atol=1e-15)
    assert np.all(np.abs(on / 0.004 - np.round(on / 0.004)) < 1e-9)


def test_on_times_never_pass_the_period_when_it_is_not_a_whole_number_of_quanta() -> None:
    ts = ThrusterSet([Thruster([0, 0, 0], [1, 0, 0], 10.0, 200.0, on_time_quantum=0.3)])
    assert ts.on_times([10.0], 1.0)[0] == pytest.approx(0.9, abs=1e-15)


def test_on_times_refuse_thrusts_outside_the_limits() -> None:
    ts = couple_thrusters(1.0, 10.0, 220.0)
    with pytest.raises(DefinitionError, match=r"\[0, max_thrust\]"):
        ts.on_times(np.r_[11.0, np.zeros(11)], 1.0)
    with pytest.raises(DefinitionError, match="period"):
        ts.on_times(np.zeros(12), 0.0)


# ---------------------------------------------------------------- the varying mass


def _burn(ts: ThrusterSet, span: float, forces: tuple = ()) -> gmuk.Trajectory:
    """Every valve open for the whole span (throttle 1)."""
    _, _, system = _spacecraft(ts, forces=forces)
    state = _at_rest(system)
    z = np.r_[MASS, np.ones(len(ts))]
    return system.simulate(state.replace(z=z), (0.0, span), rtol=1e-12, atol=1e-12)


def test_a_burn_through_the_centre_of_mass_follows_the_rocket_equation() -> None:
    F, isp = 400.0, 310.0
    traj = _burn(ThrusterSet([Thruster([0, 0, 0], [1, 0, 0], F, isp)]), 200.0)
    m = MASS - F / (isp * G0) * traj.t
    np.testing.assert_allclose(traj.z[:, 0], m, rtol=1e-12)
    dv = isp * G0 * np.log(MASS / m)  # Tsiolkovsky
    np.testing.assert_allclose(traj.V_B[:, 0, 3], dv, rtol=1e-10, atol=1e-12)
    assert np.abs(traj.V_B[:, 0, [0, 1, 2, 4, 5]]).max() == 0.0


def test_a_couple_spins_up_a_shrinking_body_at_the_uniformly_scaled_inertia() -> None:
    F, isp, arm = 10.0, 220.0, 1.0
    ts = ThrusterSet(list(couple_thrusters(arm, F, isp))[:2])  # the +x couple
    traj = _burn(ts, 300.0)
    k = 2 * F / (isp * G0)
    expected = 2 * arm * F / INERTIA[0, 0] * (MASS / k) * np.log(MASS / (MASS - k * traj.t))
    np.testing.assert_allclose(traj.V_B[:, 0, 0], expected, rtol=1e-10, atol=1e-14)


def test_a_burn_in_a_central_field_matches_the_variable_mass_point_equations() -> None:
    mu, r0 = 4.9028e12, 1.85e6
    F, isp = 50.0, 230.0
    ts = ThrusterSet([Thruster([0, 0, 0], [0, 1, 0], F, isp)])  # along the velocity
    _, _, system = _spacecraft(ts, forces=(gmuk.PointMassGravity(mu),))
    v0 = np.sqrt(mu / r0)
    g = np.eye(4)
    g[:3, 3] = [r0, 0.0, 0.0]
    state = system.state({"sc": g}, {"sc": np.r_[0, 0, 0, 0, v0, 0]}, z=np.r_[MASS, 1.0])
    T = 1500.0
    traj = system.simulate(state, (0.0, T), t_eval=[T], rtol=1e-12, atol=1e-12)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        r, v, m = y[:3], y[3:6], y[6]
        return np.r_[
            v, -mu * r / np.linalg.norm(r) ** 3 + F / m * np.array([0, 1, 0]), -F / (isp * G0)
        ]

    ref = scipy.integrate.solve_ivp(
        rhs, (0, T), np.r_[r0, 0, 0, 0, v0, 0, MASS], method="DOP853", rtol=1e-13, atol=1e-9
    )
    np.testing.assert_allclose(traj.g_NB[-1, 0, :3, 3], ref.y[:3, -1], rtol=0, atol=1e-4)
    np.testing.assert_allclose(traj.z[-1, 0], ref.y[6, -1], rtol=1e-13)


# ---------------------------------------------------------------- what the System refuses


@pytest.mark.parametrize(
    "force",
    [
        gmuk.AppliedWrench("sc", np.r_[0, 0, 0, 1.0, 0, 0]),
        "srp",
    ],
)
def test_a_force_not_proportional_to_mass_on_the_thrusting_body_is_refused(force: object) -> None:
    if force == "srp":
        from gmuk import environment as env

        force = env.CannonballSRP(env.Epoch.from_iso("2026-11-29T00:00:00"), 2.0, 1.3)
    with pytest.raises(DefinitionError, match="not proportional to its mass"):
        _spacecraft(couple_thrusters(1.0, 10.0, 220.0), forces=(force,))


def test_a_scaled_force_acts_on_the_current_mass() -> None:
    # A constant body-frame push (SRP-like, not ∝ m) beside a burn along the same axis:
    # v = (F + F_e) / k · ln(m₀ / m) with k = F / (I_sp g₀), the rocket equation's form.
    F, F_e, isp = 400.0, 30.0, 310.0
    body = gmuk.RigidBody("sc", MASS, INERTIA)
    push = gmuk.AppliedWrench("sc", np.r_[0, 0, 0, F_e, 0, 0])
    ctl = Thrusters(body, [Thruster([0, 0, 0], [1, 0, 0], F, isp)], scaled_forces=[push])
    system = gmuk.System([body], forces=[push], controllers=[ctl])
    state = _at_rest(system).replace(z=np.r_[MASS, 1.0])
    traj = system.simulate(state, (0.0, 200.0), rtol=1e-12, atol=1e-12)
    k = F / (isp * G0)
    expected = (F + F_e) / k * np.log(MASS / (MASS - k * traj.t))
    np.testing.assert_allclose(traj.V_B[:, 0, 3], expected, rtol=1e-10, atol=1e-12)


def test_scaled_forces_must_be_the_systems_and_the_body_unconstrained() -> None:
    body = gmuk.RigidBody("sc", MASS, INERTIA)
    push = gmuk.AppliedWrench("sc", np.r_[0, 0, 0, 1.0, 0, 0])
    ctl = Thrusters(body, couple_thrusters(1.0, 10.0, 220.0), scaled_forces=[push])
    with pytest.raises(DefinitionError, match="not one of the System's forces"):
        gmuk.System([body], controllers=[ctl])
    ctl = Thrusters(body, couple_thrusters(1.0, 10.0, 220.0), scaled_forces=[push])
    floor = PointPlaneContact(body, [[0.0, 0.0, -1.0]], normal=[0, 0, 1], height=-10.0)
    with pytest.raises(DefinitionError, match="must be unconstrained"):
        gmuk.System([body], constraints=[floor], forces=[push], controllers=[ctl])
    with pytest.raises(DefinitionError, match="ForceModel"):
        Thrusters(body, couple_thrusters(1.0, 10.0, 220.0), scaled_forces=["srp"])  # type: ignore[list-item]


def test_gravity_on_the_thrusting_body_is_accepted() -> None:
    _spacecraft(
        couple_thrusters(1.0, 10.0, 220.0),
        forces=(gmuk.PointMassGravity(3.986e14), gmuk.GravityGradient(3.986e14)),
    )


def test_a_constraint_tying_the_thrusting_body_to_another_is_refused() -> None:
    body = gmuk.RigidBody("sc", MASS, INERTIA)
    other = gmuk.RigidBody("other", 10.0, np.eye(3))
    ctl = Thrusters(body, couple_thrusters(1.0, 10.0, 220.0))
    tie = gmuk.RelativeConstraint(other, body, free_axes=[])
    with pytest.raises(DefinitionError, match="ties 'sc' to"):
        gmuk.System([body, other], constraints=[tie], controllers=[ctl])


def test_a_second_controller_on_the_thrusting_body_is_refused() -> None:
    body = gmuk.RigidBody("sc", MASS, INERTIA)
    a = Thrusters(body, couple_thrusters(1.0, 10.0, 220.0))
    b = Thrusters(body, couple_thrusters(1.0, 10.0, 220.0), name="second")
    with pytest.raises(DefinitionError, match="also acts on 'sc'"):
        gmuk.System([body], controllers=[a, b])


def test_thrusters_refuse_a_body_name_and_a_dry_mass_above_the_mass() -> None:
    with pytest.raises(DefinitionError, match="RigidBody itself"):
        Thrusters("sc", couple_thrusters(1.0, 10.0, 220.0))  # type: ignore[arg-type]
    with pytest.raises(DefinitionError, match="exceeds"):
        Thrusters(gmuk.RigidBody("sc", 5.0, np.eye(3)), couple_thrusters(1, 1, 1), dry_mass=6)


# ---------------------------------------------------------------- a pulsed slew

QUANTUM, MIB, F_MAX, PERIOD = 0.01, 0.05, 10.0, 1.0


def _slew(span: float = 200.0, **options: object) -> tuple[Thrusters, gmuk.Trajectory]:
    ts = couple_thrusters(1.0, F_MAX, 220.0, min_impulse_bit=MIB, on_time_quantum=QUANTUM)
    _, ctl, system = _spacecraft(ts, dry_mass=480.0)
    state = _at_rest(system, np.array([0.2, -0.1, 0.3]))

    def law(t: float, state: gmuk.State, mass: float) -> np.ndarray:
        g, V = state.pose("sc"), state.twist("sc")
        return np.r_[-20.0 * mrp_from_R_NB(g[:3, :3]) - 150.0 * V[:3], 0.0, 0.0, 0.0]

    opts = {"rtol": 1e-10, "atol": 1e-10, **options}
    return ctl, simulate_pulsed(system, state, (0.0, span), ctl, law, PERIOD, **opts)


@pytest.fixture(scope="module")
def slew() -> tuple[Thrusters, gmuk.Trajectory]:
    return _slew()


def test_pulsed_slew_respects_every_limit_at_every_step(slew: tuple) -> None:
    ctl, traj = slew
    ts = ctl.thrusters
    valves = traj.z[:, 1:]
    assert set(np.unique(valves)) <= {0.0, 1.0}  # every thruster fully on or off
    on = np.array(traj.stats["firings"]["on_times"])
    starts = np.array(traj.stats["firings"]["t"])
    assert on.shape == (len(starts), len(ts))
    fired = on > 0
    assert np.all(on <= PERIOD + 1e-15)
    assert np.all(np.abs(on / QUANTUM - np.round(on / QUANTUM)) < 1e-9)  # whole quanta
    assert np.all(F_MAX * on[fired] >= MIB - 1e-12)  # no impulse below the minimum bit
    # The valves in the trajectory are the commanded on-times: open at t iff t − t_k < t_on.
    k = np.searchsorted(starts, traj.t, side="right") - 1
    open_expected = traj.t[:, None] < starts[k, None] + on[k]  # shut from t_k + t_on on
    np.testing.assert_array_equal(valves.astype(bool), open_expected)
    # The wrench felt at each output is the open thrusters' at full thrust, over m / m₀.
    force = traj.control_force[:, :6] * (traj.z[:, :1] / MASS)
    np.testing.assert_allclose(force, (F_MAX * valves) @ ts.B.T, rtol=0, atol=1e-9)


def test_pulsed_slew_spends_exactly_the_propellant_of_its_firings(slew: tuple) -> None:
    ctl, traj = slew
    on = np.array(traj.stats["firings"]["on_times"])
    spent = float(np.sum(on @ ctl.thrusters.mass_flow))
    assert traj.stats["propellant"] == pytest.approx(spent, rel=1e-12)
    assert MASS - traj.z[-1, 0] == pytest.approx(spent, rel=1e-12)


def test_pulsed_slew_brings_the_attitude_to_rest_without_a_net_force(slew: tuple) -> None:
    _, traj = slew
    assert np.linalg.norm(mrp_from_R_NB(traj.g_NB[-1, 0, :3, :3])) < 0.02
    assert np.linalg.norm(traj.V_B[-1, 0, :3]) < 1e-3
    assert np.abs(traj.V_B[:, 0, 3:]).max() < 1e-12  # couples only


def test_pulsed_run_gives_the_requested_output_times_once_each() -> None:
    _, traj = _slew(10.0, t_eval=np.linspace(0.0, 10.0, 41))
    np.testing.assert_array_equal(traj.t, np.linspace(0.0, 10.0, 41))
    _, every = _slew(10.0)
    assert np.all(np.diff(every.t) > 0)  # one output per time, the state after a switch
    np.testing.assert_allclose(traj.g_NB[-1], every.g_NB[-1], rtol=0, atol=1e-9)


def test_pulsed_run_never_spends_below_the_dry_mass() -> None:
    ts = couple_thrusters(1.0, F_MAX, 220.0, on_time_quantum=QUANTUM)
    _, ctl, system = _spacecraft(ts, dry_mass=MASS - 0.02)  # 20 g of propellant
    state = _at_rest(system, np.array([0.5, 0.0, 0.0]))

    def full_x(t: float, state: gmuk.State, mass: float) -> np.ndarray:
        return np.r_[-100.0, 0.0, 0.0, 0.0, 0.0, 0.0]

    traj = simulate_pulsed(system, state, (0.0, 30.0), ctl, full_x, PERIOD, rtol=1e-10, atol=1e-10)
    assert traj.z[-1, 0] >= MASS - 0.02 - 1e-12
    assert traj.stats["propellant"] > 0.019  # it did fire until the tank was (nearly) empty
    assert np.all(np.array(traj.stats["firings"]["on_times"])[-5:] == 0.0)


def test_events_between_requested_outputs_are_kept() -> None:
    # The rate crossing falls in pieces of the run that keep no output time: its record must
    # still reach the joined trajectory, as in the run that outputs every step.
    cross = gmuk.Event(lambda t, s: 0.02 - abs(s.twist("sc")[2]), direction=0, name="rate")
    _, sparse = _slew(60.0, events=[cross], t_eval=[0.0, 30.0, 60.0])
    _, every = _slew(60.0, events=[cross])
    assert len(every.events) >= 2
    assert [e.t for e in sparse.events] == [e.t for e in every.events]
    assert sparse.status == every.status == "success"


def test_a_failing_piece_fails_the_pulsed_run_even_without_outputs_of_its_own() -> None:
    _, traj = _slew(10.0, t_eval=[0.0, 10.0], max_steps=2, on_failure="return")
    assert traj.status == "failed" and "steps" in traj.message
    assert traj.t.tolist() == [0.0]


def test_a_terminal_event_ends_a_pulsed_run() -> None:
    stop = gmuk.Event(lambda t, s: 0.03 - abs(s.twist("sc")[2]), terminal=True, name="rate")
    _, traj = _slew(100.0, events=[stop])
    assert traj.status == "terminated"
    assert traj.events[-1].name == "rate"
    assert abs(traj.V_B[-1, 0, 2]) == pytest.approx(0.03, abs=1e-9)
    assert traj.t[-1] < 100.0


def test_simulate_pulsed_refuses_bad_arguments() -> None:
    ts = couple_thrusters(1.0, 10.0, 220.0)
    _, ctl, system = _spacecraft(ts)
    state = _at_rest(system)
    stranger = Thrusters(gmuk.RigidBody("sc", MASS, INERTIA), ts)
    zero = lambda t, s, m: np.zeros(6)  # noqa: E731
    with pytest.raises(DefinitionError, match="not one of the System's controllers"):
        simulate_pulsed(system, state, (0, 1), stranger, zero, 1.0)
    with pytest.raises(DefinitionError, match="callable"):
        simulate_pulsed(system, state, (0, 1), ctl, "law", 1.0)  # type: ignore[arg-type]
    with pytest.raises(DefinitionError, match="period"):
        simulate_pulsed(system, state, (0, 1), ctl, zero, -1.0)
    with pytest.raises(DefinitionError, match="increasing"):
        simulate_pulsed(system, state, (1, 0), ctl, zero, 1.0)
    with pytest.raises(ShapeError, match="law's wrench"):
        simulate_pulsed(system, state, (0, 1), ctl, lambda t, s, m: np.zeros(3), 1.0)


def test_a_pulsed_run_saves_and_loads_with_its_firings(tmp_path: object, slew: tuple) -> None:
    _, traj = slew
    short = dataclasses.replace(traj)
    path = short.save(tmp_path / "slew.npz")  # type: ignore[operator]
    back = gmuk.load_trajectory(path)
    assert back.stats["firings"]["on_times"] == traj.stats["firings"]["on_times"]
    np.testing.assert_array_equal(back.z, traj.z)
