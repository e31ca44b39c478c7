"""System.accelerations: the Udwadia–Kalaba solve against KKT, redundancy, inconsistency,
sparse vs dense, point masses, validation (McCann 2020, Eqs. 2–3, 63–64)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from helpers import Rows, kkt_solve, random_rigid_bodies, random_state

import gmuk
from gmuk.errors import (
    ConstraintError,
    DefinitionError,
    InconsistentConstraintsError,
    InconsistentConstraintsWarning,
)
from gmuk.lie import se3


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_uk_accelerations_and_multipliers_equal_kkt_solution(n):
    rng = np.random.default_rng(100 + n)
    for _ in range(20):
        bodies = random_rigid_bodies(rng, n)
        s = int(rng.integers(1, 6 * n))
        A, b = rng.normal(size=(s, 6 * n)), rng.normal(size=s)
        system = gmuk.System(bodies, [Rows(bodies, A, b)])
        acc = system.accelerations(random_state(system, rng))
        nu_dot, mu = kkt_solve(system.mass_matrix, acc.free, A, b)
        scale = np.abs(nu_dot).max()
        assert np.abs(acc.total - nu_dot).max() <= 1e-10 * scale
        # Eq. 3's λ is the negative of the KKT multiplier μ (docs/errata.rst), and Aᵀλ = M ν̇_c.
        assert np.abs(acc.multipliers + mu).max() <= 1e-10 * np.abs(mu).max()
        assert np.allclose(A.T @ acc.multipliers, acc.constraint_force, rtol=0, atol=1e-10 * scale)
        assert acc.rank == s
        assert acc.residual <= 1e-12 * max(1.0, np.abs(b).max())


def test_free_acceleration_is_eq_10b_for_each_body():
    rng = np.random.default_rng(1)
    bodies = random_rigid_bodies(rng, 3)
    system = gmuk.System(bodies)
    state = random_state(system, rng)
    acc = system.accelerations(state)
    for body in bodies:
        expected = gmuk.dynamics.free_acceleration(state.twist(body), body.mass_matrix())
        assert np.allclose(acc.of(body, "free"), expected, rtol=1e-13, atol=1e-13)
    assert np.array_equal(acc.constraint, np.zeros(18))
    assert acc.multipliers.shape == (0,)


def test_redundant_rows_give_the_same_motion_with_reduced_rank():
    rng = np.random.default_rng(2)
    bodies = random_rigid_bodies(rng, 2)
    A, b = rng.normal(size=(4, 12)), rng.normal(size=4)
    A_red = np.vstack([A, 2.0 * A[:2] - A[3]])  # a linear combination of existing rows
    b_red = np.concatenate([b, 2.0 * b[:2] - b[3]])
    state_of = {}
    results = []
    for AA, bb in ((A, b), (A_red, b_red)):
        system = gmuk.System(bodies, [Rows(bodies, AA, bb)])
        state_of.setdefault("s", random_state(system, np.random.default_rng(7)))
        results.append(system.accelerations(state_of["s"]))
    plain, redundant = results
    assert redundant.rank == 4 and plain.rank == 4
    assert np.allclose(redundant.total, plain.total, rtol=1e-12, atol=1e-12)
    # The Moore–Penrose multipliers produce the same constraint force.
    assert np.allclose(A_red.T @ redundant.multipliers, plain.constraint_force, atol=1e-10)


def test_inconsistent_constraints_warn_with_residual_and_raise_in_strict_mode():
    rng = np.random.default_rng(3)
    (body,) = random_rigid_bodies(rng, 1)
    A = np.vstack([np.eye(6)[:2], np.eye(6)[:1]])  # row 0 twice with different targets
    b = np.array([1.0, 0.0, 2.0])
    system = gmuk.System([body], [Rows([body], A, b)])
    state = random_state(system, rng)
    with pytest.warns(InconsistentConstraintsWarning, match="inconsistent"):
        acc = system.accelerations(state)
    assert acc.residual == pytest.approx(np.sqrt(0.5), rel=1e-12)  # least squares: ω̇₁ = 1.5
    strict = gmuk.System([body], [Rows([body], A, b)], strict=True)
    with pytest.raises(InconsistentConstraintsError, match="‖A ν̇ − b‖"):
        strict.accelerations(state)


def test_consistent_redundant_constraints_do_not_warn():
    rng = np.random.default_rng(4)
    (body,) = random_rigid_bodies(rng, 1)
    A = np.vstack([np.eye(6)[:2], np.eye(6)[:1]])
    b = np.array([1.0, 0.0, 1.0])
    system = gmuk.System([body], [Rows([body], A, b)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        acc = system.accelerations(random_state(system, rng))
    assert acc.rank == 2
    assert acc.of(body, "total")[0] == pytest.approx(1.0, abs=1e-13)


def test_sparse_path_matches_dense_path():
    rng = np.random.default_rng(5)
    n = 60
    bodies = random_rigid_bodies(rng, n)
    constraints = []
    for _ in range(5 * n // 2):  # pairwise rows between random bodies
        i, j = rng.choice(n, 2, replace=False)
        constraints.append(
            Rows([bodies[i], bodies[j]], rng.normal(size=(2, 12)), rng.normal(size=2))
        )
    dense = gmuk.System(bodies, constraints, sparse=False)
    sparse = gmuk.System(bodies, constraints, sparse=True)
    state = random_state(dense, rng)
    a_d = dense.accelerations(state)
    a_s = sparse.accelerations(state)
    scale = np.abs(a_d.total).max()
    assert np.abs(a_s.total - a_d.total).max() <= 1e-10 * scale
    assert np.abs(a_s.multipliers - a_d.multipliers).max() <= 1e-10 * np.abs(a_d.multipliers).max()
    assert a_s.rank == a_d.rank == 5 * n


def test_sparse_path_handles_redundant_rows_with_minimum_norm_solution():
    rng = np.random.default_rng(6)
    bodies = random_rigid_bodies(rng, 10)
    rows = [
        Rows([bodies[i], bodies[i + 1]], rng.normal(size=(3, 12)), rng.normal(size=3))
        for i in range(9)
    ]
    dup = rows[0]
    rows.append(Rows(list(dup.bodies), dup.A, dup.b))  # an exact duplicate
    dense = gmuk.System(bodies, rows, sparse=False)
    sparse = gmuk.System(bodies, rows, sparse=True)
    state = random_state(dense, rng)
    a_d, a_s = dense.accelerations(state), sparse.accelerations(state)
    assert a_d.rank == 27
    assert a_s.rank is None  # not computed on the sparse fallback, said so
    assert np.abs(a_s.total - a_d.total).max() <= 1e-9 * np.abs(a_d.total).max()


def test_auto_selects_sparse_path_for_large_systems():
    rng = np.random.default_rng(8)
    assert not gmuk.System(random_rigid_bodies(rng, 10)).sparse
    assert gmuk.System(random_rigid_bodies(rng, 100)).sparse


def test_point_masses_use_classical_uk_eq_2():
    rng = np.random.default_rng(9)
    p, q = gmuk.PointMass("p", 2.0), gmuk.PointMass("q", 3.0)
    A, b = rng.normal(size=(2, 6)), rng.normal(size=2)
    system = gmuk.System([p, q], [Rows([p, q], A, b)], [gmuk.UniformGravity((0.0, 0.0, -9.81))])
    state = system.state(
        r={"p": rng.normal(size=3), "q": rng.normal(size=3)},
        v={"p": rng.normal(size=3), "q": rng.normal(size=3)},
    )
    acc = system.accelerations(state)
    M = np.diag([2.0] * 3 + [3.0] * 3)
    a = np.array([0, 0, -9.81] * 2)
    assert np.allclose(acc.free, a)
    expected = np.linalg.solve(M, A.T) @ np.linalg.pinv(A @ np.linalg.solve(M, A.T)) @ (b - A @ a)
    assert np.allclose(acc.constraint, expected, rtol=1e-12, atol=1e-13)


def test_mixed_rigid_point_and_slack_bodies_share_one_solve():
    rng = np.random.default_rng(10)
    (rb,) = random_rigid_bodies(rng, 1)
    pm, sc = gmuk.PointMass("p", 1.5), gmuk.SlackCoordinate("s", mass=0.5)
    A, b = rng.normal(size=(3, 10)), rng.normal(size=3)
    system = gmuk.System([rb, pm, sc], [Rows([rb, pm, sc], A, b)])
    state = system.state(
        g={rb.name: se3.exp(rng.normal(size=6))},
        V={rb.name: rng.normal(size=6)},
        r={"p": np.zeros(3)},
        v={"p": np.ones(3)},
        s={"s": 0.2},
        s_dot={"s": 0.1},
    )
    acc = system.accelerations(state)
    nu_dot, _ = kkt_solve(system.mass_matrix, acc.free, A, b)
    assert np.allclose(acc.total, nu_dot, rtol=1e-11, atol=1e-12)


def test_system_reports_every_definition_problem_at_once():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    a2 = gmuk.RigidBody("a", 2.0, np.eye(3))
    p = gmuk.PointMass("p", 1.0)
    with pytest.raises(DefinitionError) as info:
        gmuk.System(
            [a, a2, p, "not a body"],  # type: ignore[list-item]
            [
                Rows(["ghost"], np.eye(1), np.zeros(1)),
                gmuk.RelativeConstraint("p", "a", free_axes=[0]),
            ],
            [gmuk.AppliedWrench("nobody", np.zeros(6))],
        )
    problems = info.value.problems
    text = str(info.value)
    assert len(problems) >= 5
    for needle in (
        "duplicate body name 'a'",
        "bodies[3]",
        "'ghost'",
        "acts on rigid bodies",
        "'nobody'",
    ):
        assert needle in text


def test_state_requires_every_coordinate_and_rejects_unknown_names():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    p = gmuk.PointMass("p", 1.0)
    system = gmuk.System([a, p])
    with pytest.raises(DefinitionError) as info:
        system.state(g={"a": np.eye(4), "zz": np.eye(4)}, r={"a": np.zeros(3)})
    text = str(info.value)
    assert "missing V['a']" in text and "missing r['p']" in text and "'zz'" in text
    assert "r['a']" in text  # wrong kind of coordinate for a rigid body
    bad = np.eye(4)
    bad[0, 0] = -1.0
    with pytest.raises(gmuk.errors.NotOnGroupError, match="det"):
        system.state(g={"a": bad}, V={"a": np.zeros(6)}, r={"p": np.zeros(3)}, v={"p": np.zeros(3)})


def test_constraint_rows_with_wrong_shape_are_reported():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    system = gmuk.System([a], [Rows([a], np.eye(5), np.zeros(6))])
    state = system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)})
    with pytest.raises(ConstraintError, match=r"A of shape \(s, 6\).*got A \(5, 5\)"):
        system.accelerations(state)


def test_parts_are_frozen_once_in_a_system():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    c = Rows([a], np.eye(6), np.zeros(6))
    c.A = np.eye(6)  # still allowed before the System exists
    gmuk.System([a], [c])
    with pytest.raises(AttributeError, match="frozen"):
        c.A = np.zeros((6, 6))
    with pytest.raises(AttributeError, match="immutable"):
        a.foo = 1  # type: ignore[attr-defined]


def test_multipliers_match_lagrange_eq_3_directly():
    rng = np.random.default_rng(11)
    bodies = random_rigid_bodies(rng, 2)
    A, b = rng.normal(size=(5, 12)), rng.normal(size=5)
    system = gmuk.System(bodies, [Rows(bodies, A, b)])
    acc = system.accelerations(random_state(system, rng))
    Minv = np.linalg.inv(system.mass_matrix)
    lam = np.linalg.solve(A @ Minv @ A.T, b - A @ acc.free)
    assert np.allclose(acc.multipliers, lam, rtol=1e-11)
