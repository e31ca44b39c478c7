"""The linear-time tree solve (gmuk.engine.tree, Baraff 1996) against the dense solve and
Pinocchio's ABA.

For full-row-rank rows the KKT solution is unique, so the tree solve's accelerations,
multipliers and constraint wrenches must equal the dense (QR / SVD) solve's to round-off; on
robots from URDF its joint accelerations must equal ``pin.aba``'s. Rows it cannot certify
take the dense solve, and the compiled loop runs it without calling back into Python.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import gmuk
from gmuk.constraints.base import Constraint
from gmuk.engine.tree import (
    TREE,
    TreeSolver,
    subspaces_at,
    tree_params,
    tree_solve,
    tree_structure,
)
from gmuk.errors import DefinitionError, NonFiniteError
from gmuk.lie import se3
from gmuk.robots import (
    CylindricalJoint,
    FixedJoint,
    PlanarJoint,
    PrismaticJoint,
    RevoluteJoint,
    Robot,
    SphericalJoint,
    UniversalJoint,
    example_robot_data,
)

FINGERS = ("panda_finger_joint1", "panda_finger_joint2")
ROBOTS = {
    "panda": ("panda_description/urdf/panda.urdf", "fixed", FINGERS),
    "solo12": ("solo_description/robots/solo12.urdf", "floating", ()),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "fixed", ()),
}
#: What "the same to round-off" means here: relative to the largest entry of the field.
RTOL = 1e-12
FIELDS = ("free", "constraint", "total", "constraint_force", "multipliers")


def _robot(name: str, **kw) -> Robot:
    path, base, locked = ROBOTS[name]
    return Robot.from_urdf(example_robot_data(path), base=base, locked_joints=locked, **kw)


def _random_qv(model, rng):
    pin.seed(int(rng.integers(2**31)))
    q = pin.randomConfiguration(model, -2.0 * np.ones(model.nq), 2.0 * np.ones(model.nq))
    return q, rng.normal(size=model.nv)


def _relative(got, expected) -> float:
    scale = max(float(np.abs(expected).max(initial=0.0)), 1e-300)
    return float(np.abs(np.asarray(got) - np.asarray(expected)).max(initial=0.0)) / scale


def _assert_same(acc_tree, acc_dense) -> None:
    for field in FIELDS:
        err = _relative(getattr(acc_tree, field), getattr(acc_dense, field))
        assert err <= RTOL, f"{field}: relative difference {err:.3g}"
    assert acc_tree.rank == acc_dense.rank == acc_tree.multipliers.size
    assert acc_tree.residual <= 1e-9 * max(1.0, float(np.abs(acc_tree.total).max()))


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_tree_equals_dense_on_robots(name):
    """Accelerations, multipliers and constraint wrenches at random states, with gravity and
    joint damping (force models evaluated in Python) acting."""
    tree = _robot(name, solver="tree", damping=0.7)
    dense = _robot(name, solver="dense", damping=0.7)
    assert isinstance(tree.system.solver, TreeSolver)
    rng = np.random.default_rng(28)
    for _ in range(5):
        q, v = _random_qv(tree.model, rng)
        _assert_same(
            tree.system.accelerations(tree.state(q, v)),
            dense.system.accelerations(dense.state(q, v)),
        )


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_compiled_loads_give_the_python_loads_numbers_bit_for_bit(name):
    """Gravity alone (a compiled force model): one compiled call from the state (loads, rows,
    solve) gives exactly the numbers of the compiled call that takes the loads summed in
    Python, and the general path's to round-off; a model without a compiled form (joint
    damping here) keeps the loads in Python."""
    robot = _robot(name, solver="tree")
    solver = robot.system.solver
    one_call = solver._one_call
    assert one_call is not None and solver._loads_table is not None
    assert _robot(name, solver="tree", damping=0.7).system.solver._one_call is None
    rng = np.random.default_rng(31)
    for _ in range(5):
        q, v = _random_qv(robot.model, rng)
        state = robot.state(q, v)
        fast = robot.system.accelerations(state)
        assert fast._finite_checked  # the one call answered
        solver._one_call = None
        try:
            python_loads = robot.system.accelerations(state)
        finally:
            solver._one_call = one_call
        assert not python_loads._finite_checked
        general = solver._general(state, *solver._loads(state), None)
        for field in FIELDS:
            np.testing.assert_array_equal(getattr(fast, field), getattr(python_loads, field))
        _assert_same(fast, general)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_tree_joint_accelerations_equal_pinocchio_aba(name):
    robot = _robot(name, solver="tree")
    model = robot.model
    data = model.createData()
    rng = np.random.default_rng(96)
    for _ in range(5):
        q, v = _random_qv(model, rng)
        tau = rng.normal(size=model.nv)
        expected = pin.aba(model, data, q, v, tau)
        got = robot.forward_dynamics(q, v, tau)
        err = np.linalg.norm(got - expected) / max(1.0, np.linalg.norm(expected))
        assert err <= 1e-10


def _links(n: int) -> list[gmuk.RigidBody]:
    rng = np.random.default_rng(n)
    out = []
    for i in range(n):
        m = 0.5 + rng.random()
        J = np.diag(0.03 + 0.02 * rng.random(3))  # principal moments within a factor 5/3
        out.append(gmuk.RigidBody(f"l{i}", m, J))
    return out


def _random_state(system: gmuk.System, seed: int) -> gmuk.State:
    rng = np.random.default_rng(seed)
    g, V = {}, {}
    for b in system.bodies:
        g[b.name] = se3.exp(rng.normal(size=6))
        V[b.name] = rng.normal(size=6)
    return system.state(g=g, V=V)


def _same_state(system: gmuk.System, state: gmuk.State) -> gmuk.State:
    """``state`` as a state of ``system`` (the same bodies)."""
    names = [b.name for b in system.bodies]
    return system.state(
        g={n: state.g[i] for i, n in enumerate(names)},
        V={n: state.V[i] for i, n in enumerate(names)},
    )


def _half(x: float) -> np.ndarray:
    X = np.eye(4)
    X[0, 3] = x
    return X


def _chain(n: int, **kw) -> gmuk.System:
    links = _links(n)
    half = _half(0.15)
    joints = [RevoluteJoint(None, links[0], child_frame=np.linalg.inv(half))]
    joints += [
        RevoluteJoint(
            links[i - 1],
            links[i],
            axis=(0.0, 1.0 if i % 2 else 0.0, 1.0),
            parent_frame=half,
            child_frame=np.linalg.inv(half),
        )
        for i in range(1, n)
    ]
    return gmuk.System(links, joints, [gmuk.UniformGravity((0.0, -9.81, 0.0))], **kw)


def test_long_chain_equals_dense():
    """60 links, 300 rows: beyond the dense solve's QR (it takes the SVD)."""
    tree, dense = _chain(60, solver="tree"), _chain(60, solver="dense")
    state = _random_state(tree, 1)
    _assert_same(tree.accelerations(state), dense.accelerations(_same_state(dense, state)))


def _branched(**kw) -> gmuk.System:
    """A forest: a grounded tree with every joint kind and branching bodies, a floating tree
    (no joint to the ground) and a lone free body."""
    b = _links(12)
    X = _half(0.2)
    Xi = np.linalg.inv(X)
    joints = [
        SphericalJoint(None, b[0], child_frame=Xi),
        RevoluteJoint(b[0], b[1], parent_frame=X, child_frame=Xi),
        PrismaticJoint(b[0], b[2], axis=(0, 1, 0), parent_frame=X, child_frame=Xi),
        UniversalJoint(b[0], b[3], parent_frame=X, child_frame=Xi),
        CylindricalJoint(b[1], b[4], axis=(1, 0, 0), parent_frame=X, child_frame=Xi),
        FixedJoint(b[4], b[5], parent_frame=X, child_frame=Xi),
        PlanarJoint(b[2], b[6], parent_frame=X, child_frame=Xi),
        # a floating tree rooted at b[7], its joints listed child-first for the other order
        RevoluteJoint(b[8], b[9], parent_frame=X, child_frame=Xi),
        SphericalJoint(b[7], b[8], parent_frame=X, child_frame=Xi),
        PrismaticJoint(b[7], b[10], parent_frame=X, child_frame=Xi),
    ]
    forces = [gmuk.UniformGravity((0.0, 0.0, -9.81))]
    return gmuk.System(b, joints, forces, **kw)


def test_branched_forest_equals_dense():
    tree, dense = _branched(solver="tree"), _branched(solver="dense")
    for seed in range(4):
        state = _random_state(tree, seed)
        _assert_same(tree.accelerations(state), dense.accelerations(_same_state(dense, state)))


def test_tree_structure_orders_children_first():
    # 0 — 1 — 2 by constraints 0 (ground–0), 1 (0–1), 2 (2–1)
    order, parent = tree_structure(3, [(0, -1), (0, 1), (2, 1)])
    place = {int(node): k for k, node in enumerate(order)}
    for node, p in enumerate(parent):
        if p >= 0:
            assert place[node] < place[int(p)]
    assert parent[3] == -1  # the joint to the ground is the root
    assert isinstance(tree_structure(2, [(0, -1), (1, -1), (0, 1)]), str)  # through the ground
    assert isinstance(tree_structure(2, [(0, 1), (1, 0)]), str)  # two constraints, one pair


def test_refuses_what_is_not_a_tree():
    links = _links(4)
    X, Xi = _half(0.2), np.linalg.inv(_half(0.2))
    loop = [
        RevoluteJoint(None, links[0], child_frame=Xi),
        RevoluteJoint(links[0], links[1], parent_frame=X, child_frame=Xi),
        RevoluteJoint(None, links[1], parent_frame=_half(1.0), child_frame=X),
    ]
    with pytest.raises(DefinitionError, match="close a loop"):
        gmuk.System(links[:2], loop, solver="tree")
    point = gmuk.PointMass("p", 1.0)
    with pytest.raises(DefinitionError, match="rigid bodies only"):
        gmuk.System([links[0], point], [RevoluteJoint(None, links[0])], solver="tree")


class _Redundant(Constraint):
    """Two copies of one row on one body (to the ground): A has rank 1."""

    def rows(self, state):
        row = np.array([0.0, 0.0, 0.0, 1.0, 0.5, 0.0])
        return np.vstack([row, 2.0 * row]), np.array([1.0, 2.0])


def test_rows_without_full_rank_take_the_dense_solve():
    """The tree solve cannot certify these rows, so the SVD decides: the same minimum-norm
    answer and rank as the dense strategy."""
    body = _links(1)[0]
    tree = gmuk.System([body], [_Redundant([body])], solver="tree")
    dense = gmuk.System([body], [_Redundant([body])], solver="dense")
    state = _random_state(tree, 3)
    got = tree.accelerations(state)
    expected = dense.accelerations(_same_state(dense, state))
    assert got.rank == expected.rank == 1
    for field in FIELDS:
        assert _relative(getattr(got, field), getattr(expected, field)) <= RTOL


class _PythonRevolute(RevoluteJoint):
    """A revolute joint whose rows come from Python (no compiled form)."""

    def rows(self, state):
        return super().rows(state)


def _python_rows_chain(n: int) -> gmuk.System:
    links = _links(n)
    half = _half(0.15)
    joints = [RevoluteJoint(None, links[0], child_frame=np.linalg.inv(half))]
    joints += [
        (_PythonRevolute if i % 2 else RevoluteJoint)(
            links[i - 1], links[i], parent_frame=half, child_frame=np.linalg.inv(half)
        )
        for i in range(1, n)
    ]
    return gmuk.System(links, joints, [gmuk.UniformGravity((0.0, -9.81, 0.0))], solver="tree")


def _count_python_solves(system: gmuk.System) -> list[int]:
    """Counts the System's accelerations in Python (the loop's PHASE_ACCELERATIONS)."""
    calls = [0]
    inner = system._accelerations

    def counted(state):
        calls[0] += 1
        return inner(state)

    system._accelerations = counted
    return calls


def test_compiled_loop_runs_the_tree_solve():
    """Panda: the same trajectory as the fused strategy, with no solve in Python per step."""
    path, _, locked = ROBOTS["panda"]
    tree = Robot.from_urdf(example_robot_data(path), locked_joints=locked, solver="tree")
    fused = Robot.from_urdf(example_robot_data(path), locked_joints=locked)
    assert tree.system.compiled_solve == (TREE, "")
    rng = np.random.default_rng(12)
    q0, v0 = _random_qv(tree.model, rng)
    calls = _count_python_solves(tree.system)
    t = np.linspace(0.0, 0.3, 4)
    a = tree.system.simulate(tree.state(q0, v0), (0.0, 0.3), t_eval=t)
    b = fused.system.simulate(fused.state(q0, v0), (0.0, 0.3), t_eval=t)
    assert a.stats["compiled"] and a.stats["n_rhs"] > 100
    assert calls[0] <= 2  # the checks at the start, not the steps
    assert np.abs(tree.configuration(a) - fused.configuration(b)).max() <= 1e-9
    assert np.abs(np.asarray(a.multipliers) - np.asarray(b.multipliers)).max() <= 1e-6 * max(
        1.0, float(np.abs(np.asarray(b.multipliers)).max())
    )


def test_compiled_loop_takes_rows_from_python():
    """Constraints without a compiled form: their dense rows go into the tree's blocks."""
    system = _python_rows_chain(6)
    links = system.bodies
    g, V = {}, {}
    for i, body in enumerate(links):
        pose = np.eye(4)
        pose[0, 3] = 0.3 * i + 0.15
        g[body.name], V[body.name] = pose, np.zeros(6)
    state = system.state(g=g, V=V)
    calls = _count_python_solves(system)
    traj = system.simulate(state, (0.0, 0.2), t_eval=[0.0, 0.1, 0.2])
    assert calls[0] <= 2
    compiled = _chain_like(system)
    reference = compiled.simulate(compiled.state(g=g, V=V), (0.0, 0.2), t_eval=[0.0, 0.1, 0.2])
    assert np.abs(np.asarray(traj.acceleration) - np.asarray(reference.acceleration)).max() <= 1e-8


def _chain_like(system: gmuk.System) -> gmuk.System:
    """The same System with every joint's compiled form, under the dense strategy."""
    joints = [
        RevoluteJoint(
            j.parent, j.child, axis=j.axis, parent_frame=j.parent_frame, child_frame=j.child_frame
        )
        for j in system.constraints
    ]
    return gmuk.System(list(system.bodies), joints, list(system.forces), solver="dense")


def test_rows_without_full_rank_on_a_large_system_take_the_sparse_solve():
    """Above the dense threshold the System keeps sparse blocks, and the uncertified rows go
    to the sparse solve (minimum norm by LSMR): the same accelerations as the SVD."""
    bodies = _links(51)  # 306 dof
    tree = gmuk.System(bodies, [_Redundant([bodies[0]])], solver="tree")
    dense = gmuk.System(bodies, [_Redundant([bodies[0]])], solver="dense")
    assert tree.sparse and not dense.sparse
    state = _random_state(tree, 5)
    got = tree.accelerations(state)
    expected = dense.accelerations(_same_state(dense, state))
    assert expected.rank == 1
    for field in ("total", "constraint", "constraint_force"):
        assert _relative(getattr(got, field), getattr(expected, field)) <= 1e-10


def test_stabilised_joints_and_unmodeled_loads_equal_dense():
    """Baumgarte terms in b, and an unmodeled load (the general path: the solve, then the
    plant-only acceleration), in Python and through the compiled loop."""
    systems = {}
    for solver in ("tree", "dense"):
        links = _links(8)
        X, Xi = _half(0.15), np.linalg.inv(_half(0.15))
        stab = gmuk.Baumgarte(alpha=20.0, beta=100.0)
        joints = [SphericalJoint(None, links[0], child_frame=Xi, baumgarte=stab)]
        joints += [
            RevoluteJoint(links[i - 1], links[i], parent_frame=X, child_frame=Xi, baumgarte=stab)
            for i in range(1, 8)
        ]
        forces = [
            gmuk.UniformGravity((0.0, 0.0, -9.81)),
            gmuk.UniformGravity((0.5, 0.0, 0.0), modeled=False),
        ]
        systems[solver] = gmuk.System(links, joints, forces, solver=solver)
    tree, dense = systems["tree"], systems["dense"]
    state = _random_state(tree, 11)  # joints violated: the Baumgarte terms act
    _assert_same(tree.accelerations(state), dense.accelerations(_same_state(dense, state)))
    assert tree.compiled_solve == (TREE, "")
    calls = _count_python_solves(tree)
    a = tree.simulate(state, (0.0, 0.05), t_eval=[0.0, 0.05])
    b = dense.simulate(_same_state(dense, state), (0.0, 0.05), t_eval=[0.0, 0.05])
    assert calls[0] <= 2
    assert np.abs(np.asarray(a.V_B) - np.asarray(b.V_B)).max() <= 1e-8


# ------------------------------------------------------ joints eliminated with their child
def _articulated(system: gmuk.System) -> list[bool]:
    """Which constraints the tree solve eliminates with their child body
    (:func:`gmuk.engine.tree._articulated_step`)."""
    P = system.solver._P
    at = subspaces_at(P)
    return [P[at + 3 * k] >= 0.0 for k in range(int(P[3]))]


def _node_by_node(system: gmuk.System) -> np.ndarray:
    """The packed tree of ``system`` with no joint subspace: every node eliminated alone."""
    solver = system.solver
    return tree_params(
        system._J, system._Jinv, system._m_rigid, solver._order, solver._parent, solver._pairs,
        solver._rows_n, system.consistency_tol, system._singular,
    )  # fmt: skip


def _both_solves(system: gmuk.System, state: gmuk.State) -> tuple[tuple, tuple]:
    """(ν̇_c, λ, status) of the tree solve with the joints' subspaces and without."""
    solver = system.solver
    A, b = solver._blocks(state)
    g = np.ascontiguousarray(state.g, dtype=float)
    a = np.random.default_rng(0).normal(size=system.layout.n_dof)
    out = []
    for P in (solver._P, _node_by_node(system)):
        ac, lam = np.zeros(a.size), np.zeros(b.size)
        _residual, _scale, status = tree_solve(g, a, np.zeros(a.size), A, b, P, ac, lam)
        out.append((ac, lam, status))
    return out[0], out[1]


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_robot_joints_are_eliminated_with_their_child(name):
    """Every joint of the URDF robots takes the articulated step, whose answer is the
    node-by-node elimination's to round-off (the same Schur complement)."""
    robot = _robot(name, solver="tree")
    assert all(_articulated(robot.system))
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, v = _random_qv(robot.model, rng)
        (ac, lam, status), (ac0, lam0, status0) = _both_solves(robot.system, robot.state(q, v))
        assert status == status0 == 0
        assert _relative(ac, ac0) <= RTOL and _relative(lam, lam0) <= RTOL


def test_every_joint_kind_but_the_universal_is_eliminated_with_its_child():
    """The universal joint's constrained rotation moves with it (its rows on the child are
    not constant): node by node. Violated joints (random poses) change nothing: the rows on
    the parent are −G Ad_{g_c⁻¹ g_p} at any poses."""
    system = _branched(solver="tree")
    kinds = [type(c).__name__ for c in system.constraints]
    assert [k for k, yes in zip(kinds, _articulated(system), strict=True) if not yes] == [
        "UniversalJoint"
    ]
    for seed in range(3):
        (ac, lam, status), (ac0, lam0, status0) = _both_solves(system, _random_state(system, seed))
        assert status == status0 == 0
        assert _relative(ac, ac0) <= RTOL and _relative(lam, lam0) <= RTOL


def test_a_joint_whose_child_is_nearer_the_root_is_eliminated_node_by_node():
    """A floating pair listed child first: the tree is rooted at the joint's child, so the
    joint's constant rows are on the body above it, and the solve takes Baraff's steps."""
    links = _links(2)
    X, Xi = _half(0.2), np.linalg.inv(_half(0.2))
    joint = RevoluteJoint(links[1], links[0], parent_frame=X, child_frame=Xi)
    tree = gmuk.System(links, [joint], solver="tree")
    dense = gmuk.System(links, [joint], solver="dense")
    assert _articulated(tree) == [False]
    state = _random_state(tree, 2)
    _assert_same(tree.accelerations(state), dense.accelerations(_same_state(dense, state)))


def test_a_joint_with_rows_from_python_is_eliminated_node_by_node():
    """A subclass with its own ``rows`` promises nothing about them."""
    system = _python_rows_chain(4)
    system.accelerations(_random_state(system, 4))  # packs the row counts from Python
    assert _articulated(system) == [True, False, True, False]
    assert _PythonRevolute(None, "x")._tree_subspace() is None


def test_a_joint_inertia_at_round_off_of_the_body_is_not_certified():
    """A 1000 kg rod whose moment about the revolute axis (through its centre) is 1e-10
    kg·m²: Sᵀ D S is below PIVOT_TOL of D's largest entry, at the round-off of D's entries.
    The articulated step refuses it, as the node steps refuse D (the same pivot test), and
    the solve is left to the dense one; a moment of 1e-6 kg·m² is certified and equals the
    dense solve."""
    for moment, certified in ((1e-10, False), (1e-6, True)):
        rod = gmuk.RigidBody("rod", 1000.0, np.diag([moment, 1.0, 1.0]))
        joint = RevoluteJoint(None, rod, axis=(1.0, 0.0, 0.0), child_frame=_half(-0.3))
        parts = ([rod], [joint], [gmuk.UniformGravity((0.0, 0.0, -9.81))])
        tree = gmuk.System(*parts, solver="tree")
        twist = np.array([0.3, 0.1, -0.2, 0.0, 0.0, 0.0])
        state = tree.state(g={"rod": np.eye(4)}, V={"rod": twist})
        assert _articulated(tree) == [True]
        (_, _, status), (_, _, status0) = _both_solves(tree, state)
        assert (status == 0) is certified and status0 == status
        if certified:
            dense = gmuk.System(*parts, solver="dense")
            _assert_same(tree.accelerations(state), dense.accelerations(state))


def test_the_one_call_path_never_returns_an_acceleration_that_overflowed():
    """Finite rows, a weight that overflows: the compiled one-call path (loads, rows and solve
    from the State's arrays) must not hand back inf; the general path names the failure."""
    link = gmuk.RigidBody("link", 1e300, np.diag([1.0, 2.0, 3.0]) * 1e300)
    hinge = RevoluteJoint(None, link, axis=[0.0, 1.0, 0.0])
    system = gmuk.System([link], [hinge], [gmuk.UniformGravity([0.0, 0.0, -1e300])], solver="tree")
    assert system.solver._loads_table is not None  # the one-call path is the one taken
    state = system.state(g={"link": np.eye(4)}, V={"link": [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]})
    with pytest.raises(NonFiniteError, match=r"non-finite|overflow"):
        system.accelerations(state)
    # and a finite call through the same path is certified without a second scan
    light = gmuk.System(
        [gmuk.RigidBody("link", 1.0, np.diag([1.0, 2.0, 3.0]))],
        [RevoluteJoint(None, "link", axis=[0.0, 1.0, 0.0])],
        [gmuk.UniformGravity()],
        solver="tree",
    )
    acc = light.accelerations(light.state(g={"link": np.eye(4)}, V={"link": np.zeros(6)}))
    assert acc._finite_checked and np.all(np.isfinite(acc.total))


def test_a_one_call_accelerations_reads_like_any_other():
    """The one compiled call hands back its output array, and the Accelerations makes each
    field the first time it is read: every field, ``of``, ``repr``, ``dataclasses.replace``
    and pickling behave as for the general path's, and a name that is not a field is an
    AttributeError."""
    import dataclasses
    import pickle

    robot = _robot("panda", solver="tree")
    q, v = _random_qv(robot.model, np.random.default_rng(5))
    state = robot.state(q, v)
    fast = robot.system.accelerations(state)
    general = robot.system.solver._general(state, *robot.system.solver._loads(state), None)
    assert fast._finite_checked and not general._finite_checked
    for f in dataclasses.fields(general):
        got, expected = getattr(fast, f.name), getattr(general, f.name)
        if isinstance(expected, np.ndarray):
            assert got.shape == expected.shape, f.name
            assert _relative(got, expected) <= RTOL, f.name
        elif f.name == "residual":
            assert got <= 1e-9 * max(1.0, float(np.abs(fast.total).max()))
        else:
            assert got == expected, f.name
    link = robot.system.layout.names[0]
    np.testing.assert_array_equal(fast.of(link, "constraint_force"), fast.constraint_force[:6])
    assert "total=" in repr(fast)
    back = pickle.loads(pickle.dumps(fast))
    np.testing.assert_array_equal(back.total, fast.total)
    assert back.rank == fast.rank == fast.multipliers.size
    moved = dataclasses.replace(fast, total=np.zeros_like(fast.total))
    assert not moved.total.any() and moved.free is not None
    with pytest.raises(AttributeError, match="no attribute 'totl'"):
        fast.totl
    import copy

    np.testing.assert_array_equal(copy.deepcopy(fast).multipliers, fast.multipliers)


def test_the_one_call_path_takes_state_arrays_of_any_strides():
    """A State may share read-only arrays that are not C-contiguous (views of another
    array): the one compiled call reads them through their strides, with the same numbers
    as from contiguous copies."""
    robot = _robot("ur5", solver="tree")
    q, v = _random_qv(robot.model, np.random.default_rng(8))
    state = robot.state(q, v)
    n = state.g.shape[0]
    g_wide = np.zeros((n, 4, 8))
    g_wide[:, :, ::2] = state.g
    V_wide = np.zeros((n, 12))
    V_wide[:, ::2] = state.V
    for a in (g_wide, V_wide):
        a.setflags(write=False)
    strided = state.replace(g=g_wide[:, :, ::2], V=V_wide[:, ::2])
    assert not strided.g.flags.c_contiguous and not strided.V.flags.c_contiguous
    assert np.shares_memory(strided.g, g_wide)  # shared, not copied into C order
    fast = robot.system.accelerations(strided)
    assert fast._finite_checked
    for field in FIELDS:
        np.testing.assert_array_equal(
            getattr(fast, field), getattr(robot.system.accelerations(state), field)
        )
