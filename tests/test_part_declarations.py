"""Parts declare what they need (body kinds, point-mass path, solve strategy) and the System
checks it once, with no knowledge of the concrete classes."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import Rows, ScrewReference, random_rigid_bodies, random_state

import gmuk
from gmuk.bodies import BodyKind
from gmuk.engine import solvers, uk
from gmuk.errors import DefinitionError


def test_every_body_has_a_mass_a_kind_and_a_dof():
    bodies = [
        gmuk.RigidBody("r", 2.0, np.diag([1.0, 2.0, 2.5])),
        gmuk.PointMass("p", 3.0),
        gmuk.SlackCoordinate("s", 0.5),
    ]
    assert [b.mass for b in bodies] == [2.0, 3.0, 0.5]
    assert [b.kind for b in bodies] == [BodyKind.RIGID, BodyKind.POINT, BodyKind.SLACK]
    assert [b.kind for b in bodies] == ["rigid", "point", "slack"]  # a kind equals its tag
    assert [b.dof for b in bodies] == [6, 3, 1]
    with pytest.raises(gmuk.errors.InertiaError, match="mass"):
        gmuk.PointMass("p", -1.0)


def test_a_layout_takes_kinds_as_tags_or_enums_and_refuses_others():
    lay = gmuk.Layout(("a", "b"), ("rigid", BodyKind.POINT), (6, 3))
    assert lay.kinds == (BodyKind.RIGID, BodyKind.POINT)
    assert lay == gmuk.Layout(("a", "b"), (BodyKind.RIGID, "point"), (6, 3))
    with pytest.raises(DefinitionError, match="wobbly"):
        gmuk.Layout(("a",), ("wobbly",), (6,))


class Recorder(gmuk.ForceModel):
    """Records what each method receives; pushes along x."""

    def __init__(self, **kw):
        super().__init__(**kw)
        object.__setattr__(self, "seen", [])

    def wrench(self, t, g_NB, V_B, body):
        self.seen.append(("wrench", body.name, g_NB.shape, V_B.shape))
        return np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0])

    def force(self, t, r_N, v_N, body):
        self.seen.append(("force", body.name, r_N.copy(), v_N.copy()))
        return np.array([2.0, 0.0, 0.0])


class RigidOnly(gmuk.ForceModel):
    def wrench(self, t, g_NB, V_B, body):
        return np.zeros(6)


def test_point_masses_get_their_position_and_velocity_not_a_made_up_pose():
    a, p = gmuk.RigidBody("a", 1.0, np.eye(3)), gmuk.PointMass("p", 4.0)
    rec = Recorder()
    assert rec.acts_on == {BodyKind.RIGID, BodyKind.POINT}
    system = gmuk.System([a, p], forces=[rec])
    state = system.state(
        g={"a": np.eye(4)}, V={"a": np.zeros(6)}, r={"p": [1.0, 2.0, 3.0]}, v={"p": [4, 5, 6]}
    )
    acc = system.accelerations(state)
    kinds = {entry[0]: entry for entry in rec.seen}
    assert kinds["wrench"][1:] == ("a", (4, 4), (6,))
    assert kinds["force"][1] == "p"
    assert np.array_equal(kinds["force"][2], [1.0, 2.0, 3.0])
    assert np.array_equal(kinds["force"][3], [4.0, 5.0, 6.0])
    assert np.allclose(acc.of("p"), [0.5, 0.0, 0.0])
    assert np.allclose(acc.of("a")[3:], [1.0, 0.0, 0.0])


def test_a_model_acts_by_default_only_on_the_kinds_it_implements():
    a, p = gmuk.RigidBody("a", 1.0, np.eye(3)), gmuk.PointMass("p", 4.0)
    assert RigidOnly.acts_on == {BodyKind.RIGID}
    system = gmuk.System([a, p], forces=[RigidOnly()])  # default bodies: "a" only
    state = system.state(
        g={"a": np.eye(4)}, V={"a": np.zeros(6)}, r={"p": [1.0, 0, 0]}, v={"p": [0, 0, 0]}
    )
    assert np.array_equal(system.accelerations(state).of("p"), np.zeros(3))
    with pytest.raises(DefinitionError, match="acts on rigid bodies; 'p' is a point body"):
        gmuk.System([a, p], forces=[RigidOnly(bodies=["p"])])


def test_a_model_that_implements_nothing_is_refused():
    class Nothing(gmuk.ForceModel):
        pass

    with pytest.raises(DefinitionError, match="neither wrench"):
        Nothing()


def test_a_declared_acts_on_is_checked_for_user_coupling_models():
    class Coupling(gmuk.ForceModel):
        acts_on = frozenset({"point"})

        def wrenches(self, state, bodies):
            return [np.zeros(3) for _ in bodies]

    assert Coupling.acts_on == {BodyKind.POINT}
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    with pytest.raises(DefinitionError, match="acts on point bodies; 'a' is a rigid body"):
        gmuk.System([a], forces=[Coupling(bodies=[a])])


def test_constraints_declare_the_body_kinds_they_take():
    assert gmuk.ConfigurationTracking.body_kinds == {BodyKind.RIGID}
    assert gmuk.RelativeConstraint.body_kinds == {BodyKind.RIGID}
    assert gmuk.HolonomicConstraint.body_kinds == set(BodyKind)

    class OnPointsOnly(Rows):
        body_kinds = frozenset({BodyKind.POINT})

    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    with pytest.raises(DefinitionError, match="acts on point bodies; 'a' is a rigid body"):
        gmuk.System([a], [OnPointsOnly([a], np.eye(6)[:1], np.zeros(1))])


def test_every_tangent_bundle_constraint_gives_rows_like_any_other():
    body = gmuk.RigidBody("a", 2.0, np.diag([1.0, 2.0, 2.5]))
    ref = ScrewReference(np.eye(4), np.array([0.01, 0.02, -0.03, 1.0, 0.0, 0.5]))
    con = gmuk.ConfigurationTrackingT2(body, ref)
    system = gmuk.System([body], [con])
    state = random_state(system, np.random.default_rng(3))
    A, b = con.rows(state)
    A4, B4, C4 = con.tangent_rows(state)
    want = uk.reachable_rows(A4, B4, C4, state.g, state.V)
    assert np.array_equal(A, want[0]) and np.array_equal(b, want[1])


@pytest.mark.parametrize(
    ("kwargs", "expected"),
    [
        ({}, "fused"),
        ({"sparse": True}, "sparse"),
        ({"solver": "dense"}, "dense"),
        ({"solver": solvers.SparseSolver}, "sparse"),
    ],
)
def test_the_solve_strategy_is_chosen_once_and_named(kwargs, expected):
    bodies = random_rigid_bodies(np.random.default_rng(0), 2)
    A = np.random.default_rng(1).normal(size=(5, 12))
    system = gmuk.System(bodies, [Rows(bodies, A, np.ones(5))], **kwargs)
    assert system.solver.name == expected
    assert f"solver={expected!r}" in repr(system)


def test_systems_the_fused_call_cannot_take_get_the_dense_solve():
    a, p = gmuk.RigidBody("a", 1.0, np.eye(3)), gmuk.PointMass("p", 1.0)
    with_point = gmuk.System([a, p], [Rows([p], np.eye(3)[:1], np.zeros(1))])
    assert with_point.solver.name == "dense"
    unmodeled = gmuk.System(
        [a],
        [Rows([a], np.eye(6)[:1], np.zeros(1))],
        [gmuk.UniformGravity([0, 0, -1.0], modeled=False)],
    )
    assert unmodeled.solver.name == "dense"
    assert gmuk.System([a]).solver.name == "dense"


def test_every_strategy_gives_the_same_accelerations():
    rng = np.random.default_rng(11)
    bodies = random_rigid_bodies(rng, 3)
    A, b = rng.normal(size=(8, 18)), rng.normal(size=8)
    forces = [gmuk.UniformGravity([0.0, 0.0, -9.8])]
    results = {}
    for name in ("fused", "dense", "sparse"):
        system = gmuk.System(bodies, [Rows(bodies, A, b)], forces, solver=name)
        state = random_state(system, np.random.default_rng(2))
        results[name] = system.accelerations(state)
    for name in ("dense", "sparse"):
        for field in ("total", "constraint", "multipliers", "constraint_force"):
            u, v = getattr(results[name], field), getattr(results["fused"], field)
            assert np.abs(u - v).max() <= 1e-10 * max(1.0, np.abs(v).max()), (name, field)


def test_bad_solver_choices_are_clear_errors():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    rows = [Rows([a], np.eye(6)[:2], np.zeros(2))]
    with pytest.raises(DefinitionError, match=r"solver must be one of .*'dense'.*got 'qr'"):
        gmuk.System([a], rows, solver="qr")
    with pytest.raises(DefinitionError, match="either solver= or the sparse="):
        gmuk.System([a], rows, solver="dense", sparse=True)
    with pytest.raises(DefinitionError, match="fused solve takes rigid bodies only"):
        gmuk.System([a, gmuk.PointMass("p", 1.0)], rows, solver="fused")


def test_a_user_strategy_registers_by_name_and_is_used():
    class CountingDense(solvers.DenseSolver):
        name = "counting-dense-test"
        calls = 0

        def solve(self, state, a, rows=None):
            type(self).calls += 1
            return super().solve(state, a, rows)

    assert solvers.SOLVERS["counting-dense-test"] is CountingDense
    bodies = random_rigid_bodies(np.random.default_rng(4), 1)
    rows = [Rows(bodies, np.eye(6)[:3], np.ones(3))]
    system = gmuk.System(bodies, rows, solver="counting-dense-test")
    state = random_state(system, np.random.default_rng(5))
    acc = system.accelerations(state)
    assert CountingDense.calls == 1
    assert np.allclose(acc.total[:3], 1.0)
    del solvers.SOLVERS["counting-dense-test"]
