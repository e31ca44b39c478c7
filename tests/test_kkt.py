"""KKT diagnostics of inequality constraints (gmuk.kkt, McCann 2020 Table 6.1) and the
spring–mass–damper scenarios SMD-GT, SMD-LT, SMD-BI (§6.5.1): multipliers against an
independent KKT solve, feasibility, steady states, the 1/t approach of the undamped contact,
the sign of μ, and the diagnostics' interface.

The UK multiplier λ gives the constraint force Aᵀλ; the block system
``[[M, Aᵀ], [A, 0]] [ν̇; y] = [Q; b]`` has ``y = −λ``, and the KKT multiplier of a bound is
``μ = −σλ`` (σ = +1 slack, −1 excess).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import gmuk
from gmuk import plotting
from gmuk.errors import DefinitionError
from gmuk.kkt import InequalityKKT, KKTDiagnostics, kkt_diagnostics
from gmuk.scenarios import smd

CASES = ("smd-gt", "smd-lt", "smd-bi")


def run(case, duration=30.0, slack_damping=0.0):
    """One SMD run (cached: each takes 0.3–1.5 s)."""
    return _run(case, float(duration), float(slack_damping))


def diagnostics(case, duration=30.0, slack_damping=0.0):
    """kkt_diagnostics of :func:`run` (cached)."""
    return _diagnostics(case, float(duration), float(slack_damping))


@functools.cache
def _run(case, duration, slack_damping):
    return smd.simulate(case, duration, slack_damping=slack_damping)


@functools.cache
def _diagnostics(case, duration, slack_damping):
    return kkt_diagnostics(*_run(case, duration, slack_damping))


def smd_bounds(case):
    """[(bound, σ)] in the order of the rows (upper first)."""
    (lower, upper), *_ = smd.CASES[case]
    out = [] if upper is None else [(upper, 1.0)]
    return out if lower is None else [*out, (lower, -1.0)]


def smd_kkt_solve(case, state, slack_damping):
    """Accelerations and λ at ``state`` from M, A, b and Q written out for the SMD System:
    mass 2 kg (3 dof) and one unit-mass coordinate per bound, rows of ``x − bound + σw² = 0``
    with the scenario's Baumgarte gains, Q = −k r − c v (and −C ẇ on the slacks)."""
    bounds = smd_bounds(case)
    k = len(bounds)
    n = 3 + k
    r, v = state.x[:3], state.xdot[:3]
    w, w_dot = state.x[3:], state.xdot[3:]
    alpha, beta = 10.0, 25.0
    M = np.diag([2.0, 2.0, 2.0] + [1.0] * k)
    Q = np.concatenate([-10.0 * r - 5.0 * v, -slack_damping * w_dot])
    A = np.zeros((k, n))
    b = np.zeros(k)
    for i, (bound, sigma) in enumerate(bounds):
        A[i, 0] = 1.0
        A[i, 3 + i] = 2.0 * sigma * w[i]
        phi = r[0] - bound + sigma * w[i] ** 2
        phi_dot = v[0] + 2.0 * sigma * w[i] * w_dot[i]
        b[i] = -2.0 * sigma * w_dot[i] ** 2 - alpha * phi_dot - beta * phi
    K = np.block([[M, A.T], [A, np.zeros((k, k))]])
    sol = np.linalg.solve(K, np.concatenate([Q, b]))
    return sol[:n], -sol[n:], Q


# ---------------------------------------------------------------------------- 2. multipliers
@pytest.mark.parametrize("slack_damping", [0.0, 20.0])
@pytest.mark.parametrize("case", CASES)
def test_multipliers_equal_an_independent_kkt_solve(case, slack_damping):
    system, traj = run(case, 30.0, slack_damping)
    assert system.layout.names[0] == "mass" and traj.x.shape[1] == 3 + len(smd_bounds(case))
    slack = np.abs(traj.x[:, 3:]).min(axis=1)
    samples = {*np.linspace(0, len(traj) - 1, 9).astype(int), int(slack.argmin())}  # + contact
    for i in sorted(samples):
        state = traj.state(i)
        nu_dot, lam, Q = smd_kkt_solve(case, state, slack_damping)
        scale = max(np.linalg.norm(Q), np.linalg.norm(lam))  # λ may vanish (LT at t = 0)
        acc = system.accelerations(state)
        np.testing.assert_allclose(acc.multipliers, lam, rtol=1e-8, atol=1e-8 * scale)
        np.testing.assert_allclose(traj.multipliers[i], lam, rtol=1e-8, atol=1e-8 * scale)
        np.testing.assert_allclose(acc.total, nu_dot, rtol=1e-8, atol=1e-8 * scale)


def test_kkt_multiplier_is_minus_sigma_lambda_and_g_is_sigma_h_minus_bound():
    _, traj = run("smd-bi", 30.0, 20.0)
    kkt = diagnostics("smd-bi", 30.0, 20.0)
    x = traj.r_N[:, 0, 0]
    upper, lower = kkt["x.upper"], kkt["x.lower"]
    np.testing.assert_array_equal(upper.mu, -traj.multipliers[:, 0])
    np.testing.assert_array_equal(lower.mu, traj.multipliers[:, 1])
    np.testing.assert_array_equal(upper.h, x)
    np.testing.assert_array_equal(upper.g, x - 2.0)
    np.testing.assert_array_equal(lower.g, 1.0 - x)
    np.testing.assert_array_equal(upper.slack, traj.x[:, 3])
    np.testing.assert_array_equal(lower.slack_rate, traj.xdot[:, 4])
    assert (upper.side, upper.bound, lower.side, lower.bound) == ("upper", 2.0, "lower", 1.0)
    assert upper.constraint == lower.constraint == "x"
    assert upper.unit == "m" and upper.multiplier_unit == "N"
    # at rest on the lower bound the spring (k·1 m = 10 N) is held by μ = 10 N ≥ 0
    assert lower.mu[-1] == pytest.approx(10.0, rel=1e-6)
    assert upper.mu[-1] == pytest.approx(0.0, abs=1e-6)


# ---------------------------------------------------------------------------- 3. acceptance
@pytest.mark.parametrize(
    ("case", "slack_damping"),
    [(c, 0.0) for c in CASES] + [("smd-gt", 20.0), ("smd-bi", 20.0)],
)
def test_smd_bounds_are_never_violated(case, slack_damping):
    kkt = diagnostics(case, 30.0, slack_damping)
    assert len(kkt.t) == 3001
    for bound in kkt.inequalities.values():
        assert bound.primal_violation.max() <= 1e-9
        assert bound.summary()["primal_violation_max"] <= 1e-9


def test_smd_lt_comes_to_rest_at_the_spring_origin_with_no_control():
    _, traj = run("smd-lt")
    assert abs(traj.r_N[-1, 0, 0]) < 1e-6
    assert abs(smd.control_acceleration(traj)[-1]) < 1e-6
    assert traj.r_N[:, 0, 0].max() > 1.0 - 1e-4  # it did reach the bound x ≤ 1 on the way


@pytest.mark.parametrize(("case", "x_ss", "u_ss"), [("smd-gt", 5.0, 25.0), ("smd-bi", 1.0, 5.0)])
def test_smd_with_slack_damping_settles_on_the_bound_held_by_the_spring_force(case, x_ss, u_ss):
    _, traj = run(case, 30.0, 20.0)
    assert smd.steady_state(case) == (x_ss, u_ss)
    assert traj.r_N[-1, 0, 0] == pytest.approx(x_ss, abs=1e-6)
    assert smd.control_acceleration(traj)[-1] == pytest.approx(u_ss, abs=1e-6)  # k x / m


def test_smd_gt_without_slack_damping_approaches_the_bound_like_one_over_t():
    """Measured: max(x − 5) over [7.5, 15] s / over [15, 30] s = 2.54 (a pure 1/t gives 2;
    the local exponent of the bounce peaks is −1.58 over 2–8 s, −1.24 over 8–30 s and −1.10
    over 30–60 s, i.e. x − 5 ≈ 0.22 m·s/(t − 2.65 s))."""
    _, traj = run("smd-gt")
    t, x = traj.t, traj.r_N[:, 0, 0]
    early = (x - 5.0)[(t >= 7.5) & (t <= 15.0)].max()
    late = (x - 5.0)[(t >= 15.0) & (t <= 30.0)].max()
    assert 1.4 < early / late < 2.8
    assert 0.0 < late < 0.02  # not yet settled: the contact is elastic
    assert smd.control_acceleration(traj)[-1] != pytest.approx(25.0, abs=1e-3)


# ---------------------------------------------------------------------------- 7. diagnostics
def test_smd_lt_violates_dual_feasibility_in_the_transient():
    """Measured: μ < 0 first between 2.11 s and 3.82 s (after the contact at 0.36 s, when the
    mass swings back and the slack's inertia pulls it), worst μ = −0.10089 N at t = 2.72 s,
    and again in each later half-swing, shrinking with the motion."""
    kkt = diagnostics("smd-lt")
    b = kkt["x.upper"]
    t = b.t
    worst = b.dual_violation.max()
    assert worst == pytest.approx(0.10089, abs=1e-4)
    assert t[b.dual_violation.argmax()] == pytest.approx(2.72, abs=0.015)
    assert b.dual_violation[t < 2.1].max() == 0.0  # the contact itself is KKT
    assert b.summary()["dual_violation_max"] == worst
    assert np.abs(b.mu[t > 20.0]).max() < 1e-8  # at rest: no force


def test_smd_gt_is_dual_feasible_throughout():
    kkt = diagnostics("smd-gt")
    assert kkt["x.lower"].mu.min() > 2.7  # measured 2.758 N at t = 0.12 s
    assert kkt["x.lower"].summary()["dual_violation_max"] == 0.0


@pytest.mark.parametrize("case", CASES)
def test_stationarity_of_gauss_function_is_at_round_off(case):
    kkt = diagnostics(case)
    assert kkt.stationarity.max() <= 1e-12
    assert kkt.summary()["stationarity_max"] <= 1e-12
    assert kkt.stationarity.max() > 0.0  # computed, not skipped


def test_kkt_diagnostics_of_another_systems_trajectory_is_a_definition_error():
    gt_system, _ = run("smd-gt")
    _, lt_traj = run("smd-lt")
    with pytest.raises(DefinitionError, match="not the System's") as info:
        kkt_diagnostics(gt_system, lt_traj)
    assert "x.upper" in str(info.value) and "x.lower" in str(info.value)


def test_kkt_diagnostics_with_the_same_bodies_but_other_rows_is_a_definition_error():
    mass = gmuk.PointMass(smd.BODY, smd.MASS)
    bound = gmuk.PlaneBound(mass, [1.0, 0.0, 0.0], lower=5.0, name="x")
    system = gmuk.System([mass], [bound, FixedRows([mass])])
    _, traj = run("smd-gt")
    with pytest.raises(DefinitionError, match="2 rows") as info:
        kkt_diagnostics(system, traj)
    assert "1 multipliers" in str(info.value)


class FixedRows(gmuk.Constraint):
    """ÿ = 0 on the mass: one extra row."""

    def rows(self, state):
        return np.array([[0.0, 1.0, 0.0]]), np.array([0.0])


def test_unknown_bound_name_is_a_definition_error_listing_the_bounds():
    kkt = diagnostics("smd-bi")
    with pytest.raises(DefinitionError, match="nope") as info:
        kkt["nope"]
    assert "['x.lower', 'x.upper']" in str(info.value)


def test_summaries_have_their_documented_keys():
    kkt = diagnostics("smd-bi")
    assert isinstance(kkt, KKTDiagnostics)
    assert set(kkt.summary()) == {"bounds", "stationarity_max"}
    assert set(kkt.summary()["bounds"]) == {"x.upper", "x.lower"}
    for b in kkt.inequalities.values():
        assert isinstance(b, InequalityKKT)
        s = b.summary()
        assert set(s) == {"primal_violation_max", "dual_violation_max", "complementarity_abs_max"}
        assert all(isinstance(v, float) for v in s.values())
        assert s["complementarity_abs_max"] == np.abs(b.mu * b.g).max()


def test_plot_kkt_writes_a_png(tmp_path):
    b = diagnostics("smd-gt")["x.lower"]
    paths = plotting.plot_kkt(b, tmp_path / "kkt_lower", ("png",))
    assert [p.suffix for p in paths] == [".png"]
    assert paths[0].exists() and paths[0].stat().st_size > 0
    assert paths[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------------------- trajectory
def test_saved_trajectory_holds_point_mass_positions_and_velocities(tmp_path):
    _, traj = run("smd-bi")
    path = traj.save(tmp_path / "bi.npz")
    with np.load(path) as data:
        assert data["r_N"].shape == (len(traj), 1, 3)
        assert data["v_N"].shape == (len(traj), 1, 3)
        np.testing.assert_array_equal(data["r_N"][:, 0], traj.x[:, :3])
        np.testing.assert_array_equal(data["v_N"][:, 0], traj.xdot[:, :3])
        np.testing.assert_array_equal(data["multipliers"], traj.multipliers)
    loaded = gmuk.load_trajectory(path)
    np.testing.assert_array_equal(loaded.r_N, traj.r_N)


@pytest.mark.parametrize("i", [0, 1, 1234, -1])
def test_trajectory_state_round_trips_an_output(i):
    system, traj = run("smd-bi")
    state = traj.state(i)
    assert state.t == traj.t[i]
    np.testing.assert_array_equal(state.x, traj.x[i])
    np.testing.assert_array_equal(state.xdot, traj.xdot[i])
    assert state.layout == system.layout
    np.testing.assert_array_equal(system.accelerations(state).multipliers, traj.multipliers[i])
    # the state owns its arrays, read-only: neither it nor the trajectory can change the other
    assert not np.shares_memory(state.x, traj.x) and not state.x.flags.writeable
    with pytest.raises(DefinitionError, match="out of range"):
        traj.state(len(traj))
