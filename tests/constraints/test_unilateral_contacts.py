"""Unilateral contacts that satisfy the KKT conditions exactly (gmuk.constraints.unilateral,
gmuk.engine.contact): the solve against a brute-force enumeration of active sets, impacts
against Newton's law and the bouncing ball's closed form, a box dropped on a plane coming to
rest, and bad input."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

import gmuk
from gmuk.constraints.unilateral import PointPlaneContact
from gmuk.engine.contact import (
    ContactSolver,
    contact_kkt,
    impulse,
    simulate_with_impacts,
    solve_with_inequalities,
)
from gmuk.errors import DefinitionError
from gmuk.lie import so3


def _brute_force(a, M, A, b, equal, ineq):
    """Gauss's principle with inequalities by enumeration: every subset of the inequality
    rows taken as equalities (KKT solve of the full system), keeping the feasible one with
    λ ≥ 0 and the least cost."""
    best = None
    for r in range(len(ineq) + 1):
        for subset in itertools.combinations(ineq, r):
            rows = list(equal) + list(subset)
            n, s = M.shape[0], len(rows)
            K = np.block([[M, -A[rows].T], [A[rows], np.zeros((s, s))]])
            rhs = np.concatenate([M @ a, b[rows]])
            try:
                sol = np.linalg.solve(K, rhs)
            except np.linalg.LinAlgError:
                continue
            acc, lam = sol[:n], sol[n:]
            if (lam[len(equal) :] < -1e-9).any() or (A[ineq] @ acc - b[ineq] < -1e-9).any():
                continue
            cost = 0.5 * (acc - a) @ M @ (acc - a)
            if best is None or cost < best[0] - 1e-12:
                best = (cost, acc)
    return best


def test_the_least_distance_solve_is_gauss_principle_with_inequalities():
    rng = np.random.default_rng(0)
    for _ in range(200):
        n, s_eq, s_in = 6, int(rng.integers(0, 3)), int(rng.integers(1, 5))
        L = rng.normal(size=(n, n))
        M = L @ L.T + n * np.eye(n)
        w, U = np.linalg.eigh(M)
        Minv_sqrt = U @ np.diag(w**-0.5) @ U.T
        A = rng.normal(size=(s_eq + s_in, n))
        b = rng.normal(size=s_eq + s_in) * 3.0
        a = rng.normal(size=n)
        equal = np.arange(s_eq)
        ineq = np.arange(s_eq, s_eq + s_in)
        ac, lam, rank, residual = solve_with_inequalities(a, Minv_sqrt, A, b, equal, ineq)
        acc = a + ac
        expected = _brute_force(a, M, A, b, equal, ineq)
        assert expected is not None
        np.testing.assert_allclose(acc, expected[1], atol=1e-10)
        # the KKT conditions, to round-off
        np.testing.assert_allclose(M @ ac, A.T @ lam, atol=1e-10)
        assert (lam[ineq] >= 0.0).all()
        slack = A[ineq] @ acc - b[ineq]
        assert slack.min() > -1e-10
        assert np.abs(lam[ineq] * slack).max() < 1e-10
        assert residual < 1e-10 and rank == s_eq


def test_redundant_contact_rows_are_solved_with_nonnegative_multipliers():
    """A box resting flat on four corners: four rows of rank three, the weight shared."""
    box = gmuk.RigidBody("box", 2.0, np.diag([0.02, 0.03, 0.04]))
    corners = [(x, y, -0.05) for x in (-0.1, 0.1) for y in (-0.1, 0.1)]
    floor = PointPlaneContact(box, corners)
    system = gmuk.System([box], [floor], [gmuk.UniformGravity((0, 0, -9.81))])
    assert isinstance(system.solver, ContactSolver)
    g = np.eye(4)
    g[2, 3] = 0.05
    acc = system.accelerations(system.state(g={"box": g}, V={"box": np.zeros(6)}))
    np.testing.assert_allclose(acc.total, 0.0, atol=1e-12)
    assert (acc.multipliers >= 0.0).all()
    assert acc.multipliers.sum() == pytest.approx(2.0 * 9.81, rel=1e-12)


def test_an_open_gap_exerts_nothing_and_a_lifting_contact_lets_go():
    box = gmuk.RigidBody("box", 1.0, np.diag([0.01, 0.01, 0.01]))
    floor = PointPlaneContact(box, [0.0, 0.0, -0.05])
    up = gmuk.AppliedWrench(box, [0, 0, 0, 0, 0, 20.0], frame="inertial")
    system = gmuk.System([box], [floor], [gmuk.UniformGravity((0, 0, -9.81)), up])
    g = np.eye(4)
    g[2, 3] = 0.05
    acc = system.accelerations(system.state(g={"box": g}, V={"box": np.zeros(6)}))
    assert acc.multipliers[0] == 0.0
    assert acc.total[5] == pytest.approx(20.0 - 9.81, rel=1e-12)
    g[2, 3] = 0.5  # far above: open
    acc = system.accelerations(system.state(g={"box": g}, V={"box": np.zeros(6)}))
    assert acc.multipliers[0] == 0.0


def test_an_impact_follows_newtons_law_of_restitution():
    ball = gmuk.RigidBody("ball", 1.0, np.eye(3) * 0.004)
    floor = PointPlaneContact(ball, [0.0, 0.0, -0.1], restitution=0.8)
    system = gmuk.System([ball], [floor], [gmuk.UniformGravity((0, 0, -9.81))])
    g = np.eye(4)
    g[2, 3] = 0.1
    state = system.state(g={"ball": g}, V={"ball": [0.3, 0.0, 0.0, 1.0, 0.0, -4.0]})
    after, lam = impulse(system, state)
    # the contact point's normal velocity reverses with e = 0.8; the impulse is along n
    _, rate = floor.gaps(after)
    assert rate[0] == pytest.approx(0.8 * 4.0, rel=1e-12)
    assert lam[0] > 0.0
    # tangential velocity and spin about the vertical through the point are untouched
    assert after.V[0][3] == pytest.approx(1.0, rel=1e-12)
    after, _ = impulse(system, state, plastic=True)
    assert abs(floor.gaps(after)[1][0]) < 1e-12


def test_a_bouncing_ball_hits_at_the_closed_form_times_and_comes_to_rest(tmp_path: Path) -> None:
    """Drop from h: impacts at t₁ = √(2h/g), then every 2 eⁿ v₁ / g; the series sums to
    t₁ (1 + 2e/(1 − e)), after which the ball rests (impacts below 1 mm/s are plastic)."""
    e, h, g0 = 0.8, 1.0, 9.81
    ball = gmuk.RigidBody("ball", 1.0, np.eye(3) * 0.004)
    floor = PointPlaneContact(ball, [0.0, 0.0, -0.1], restitution=e, name="floor")
    system = gmuk.System([ball], [floor], [gmuk.UniformGravity((0, 0, -g0))])
    start = np.eye(4)
    start[2, 3] = h + 0.1
    state = system.state(g={"ball": start}, V={"ball": np.zeros(6)})
    T = 5.0
    traj = simulate_with_impacts(
        system, state, (0.0, T), t_eval=np.linspace(0.0, T, 51), rtol=1e-12, atol=1e-12
    )
    assert traj.success, traj.message
    times = np.array([ev.t for ev in traj.events])
    v1 = math.sqrt(2 * g0 * h)
    expected = v1 / g0 + np.concatenate([[0.0], np.cumsum(2 * v1 * e ** np.arange(1, 25) / g0)])
    np.testing.assert_allclose(times[:20], expected[:20], atol=1e-11)
    assert times[-1] < v1 / g0 * (1 + 2 * e / (1 - e))
    kkt = contact_kkt(system, traj)["floor"].summary()
    assert kkt["penetration"] <= 1e-9
    assert kkt["negative_multiplier"] == 0.0
    assert kkt["complementarity"] <= 1e-9
    end = traj.state(-1)
    assert abs(end.pose("ball")[2, 3] - 0.1) < 1e-9 and np.abs(end.V).max() < 1e-9
    assert traj.stats["impacts"] == len(times)
    # the impacts ended segments, not the run: recorded events, and the run saves and loads
    assert not any(ev.terminal for ev in traj.events)
    back = gmuk.load_trajectory(traj.save(tmp_path / "ball.npz"))
    assert [ev.t for ev in back.events] == list(times)


def test_a_box_dropped_on_a_plane_comes_to_rest_with_kkt_to_round_off():
    m, a, b, c = 2.0, 0.2, 0.15, 0.1
    box = gmuk.RigidBody("box", m, m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b]))
    corners = [(sx * a / 2, sy * b / 2, sz * c / 2) for sx in (-1, 1) for sy in (-1, 1)
               for sz in (-1, 1)]  # fmt: skip
    floor = PointPlaneContact(box, corners, restitution=0.5, name="floor")
    system = gmuk.System([box], [floor], [gmuk.UniformGravity((0.0, 0.0, -9.81))])
    start = np.eye(4)
    start[:3, :3] = so3.exp(np.array([0.3, 0.2, 0.0]))
    start[2, 3] = 0.5
    state = system.state(g={"box": start}, V={"box": np.zeros(6)})
    traj = simulate_with_impacts(
        system, state, (0.0, 3.0), t_eval=np.linspace(0.0, 3.0, 301), rtol=1e-10, atol=1e-10
    )
    assert traj.success, traj.message
    assert traj.stats["impacts"] > 10
    kkt = contact_kkt(system, traj)["floor"]
    summary = kkt.summary()
    assert summary["penetration"] <= 1e-9
    assert summary["negative_multiplier"] == 0.0
    assert summary["complementarity"] <= 1e-9
    end = traj.state(-1)
    gaps, rates = floor.gaps(end)
    down = np.argsort(gaps)[:4]
    assert gaps[down].max() < 1e-9  # resting on a face: four corners down, at rest
    assert np.abs(rates).max() < 1e-9
    # frictionless: sliding and spinning about the normal are free; none was given
    assert np.abs(end.V).max() < 1e-7
    assert kkt.multiplier[-1].sum() == pytest.approx(m * 9.81, rel=1e-9)


def test_bad_contacts_say_what_is_wrong():
    box = gmuk.RigidBody("box", 1.0, np.eye(3))
    with pytest.raises(DefinitionError, match="restitution"):
        PointPlaneContact(box, [0, 0, 0], restitution=1.5)
    with pytest.raises(DefinitionError, match="normal"):
        PointPlaneContact(box, [0, 0, 0], normal=(0, 0, 0))
    with pytest.raises(gmuk.errors.ShapeError):
        PointPlaneContact(box, [[0, 0]])
    floor = PointPlaneContact(box, [0, 0, 0])
    system = gmuk.System([box], [floor])
    state = system.state(g={"box": np.eye(4)}, V={"box": np.zeros(6)})
    with pytest.raises(DefinitionError, match="events"):
        simulate_with_impacts(system, state, (0.0, 1.0), events=[])


def test_a_pendulum_comes_to_rest_on_its_joint_stop_with_the_static_torque():
    """A rod on a revolute joint to the ground, gravity across it, a stop at 0.5 rad:
    it swings onto the stop, bounces (e = 0.3) and rests there, the stop's multiplier the
    gravity torque m g l cos θ."""
    from gmuk.constraints.unilateral import JointLimit
    from gmuk.lie import se3
    from gmuk.robots import RevoluteJoint

    m, l, g0 = 2.0, 0.7, 9.81
    rod = gmuk.RigidBody("rod", m, np.diag([1e-3, m * (2 * l) ** 2 / 12, m * (2 * l) ** 2 / 12]))
    X = np.eye(4)
    X[:3, 3] = (l, 0.0, 0.0)
    hinge = RevoluteJoint(None, rod, axis=(0, 0, 1), child_frame=X)
    stop = JointLimit(hinge, lower=-0.5, upper=0.5, restitution=0.3, name="stop")
    system = gmuk.System([rod], [hinge, stop], [gmuk.UniformGravity((0.0, -g0, 0.0))])
    state = system.state(g={"rod": se3.inverse(X)}, V={"rod": np.zeros(6)})
    traj = simulate_with_impacts(
        system, state, (0.0, 3.0), t_eval=np.linspace(0.0, 3.0, 61), rtol=1e-11, atol=1e-11
    )
    assert traj.success, traj.message
    q = hinge.coordinates_along(traj)[:, 0]
    assert traj.stats["impacts"] >= 2 and q.max() <= 0.5 + 1e-9
    assert q[-1] == pytest.approx(0.5, abs=1e-9)
    kkt = contact_kkt(system, traj)["stop"]
    summary = kkt.summary()
    assert summary["penetration"] <= 1e-9 and summary["complementarity"] <= 1e-9
    assert summary["negative_multiplier"] == 0.0
    assert kkt.multiplier[-1, 1] == pytest.approx(m * g0 * l * math.cos(0.5), rel=1e-9)
    assert kkt.multiplier[-1, 0] == 0.0


def test_a_joint_limit_needs_one_coordinate_and_an_ordered_range():
    from gmuk.constraints.unilateral import JointLimit
    from gmuk.robots import RevoluteJoint, SphericalJoint

    a, b = gmuk.RigidBody("a", 1.0, np.eye(3)), gmuk.RigidBody("b", 1.0, np.eye(3))
    with pytest.raises(DefinitionError, match="one coordinate"):
        JointLimit(SphericalJoint(a, b), -1.0, 1.0)
    with pytest.raises(DefinitionError, match="lower < upper"):
        JointLimit(RevoluteJoint(a, b), 1.0, -1.0)
