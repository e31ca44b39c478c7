"""Hostile parts (issue #25, item 4, and item 10's scaled inconsistent constraints).

Parts (force models, constraints, controllers, users' subclasses) get a read-only State and
their return values are checked where the System collects them: real numbers only (no
booleans, complex numbers or strings), exactly the expected shape (ż is never broadcast),
finite. The test of inconsistent constraints is relative to the size of the rows.

Every run is made twice, by ``System.simulate`` (the compiled loop, which calls Python parts
back) and by ``gmuk.testing.reference_simulate`` (the Python loop): both must refuse a
hostile part the same way, naming it. Each test also checks that honest input still works,
so that a check refusing everything would fail too.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from helpers import Rows

import gmuk
from gmuk.errors import (
    ConstraintError,
    DefinitionError,
    GmukError,
    InconsistentConstraintsError,
    InconsistentConstraintsWarning,
    NonFiniteError,
    SimulationError,
)
from gmuk.testing import reference_simulate

LOOPS = {
    "compiled": lambda system, state, span, **kw: system.simulate(state, span, **kw),
    "reference": reference_simulate,
}
V0 = [0.1, -0.2, 0.3, 1.0, 0.5, -0.25]


def rigid(name="a"):
    return gmuk.RigidBody(name, 2.0, np.diag([1.0, 2.0, 3.0]))


def state_of(system, z=None):
    return system.state(g={"a": np.eye(4)}, V={"a": V0}, z=z)


def refused(run, system, state, error, *words):
    """Run and check that it fails with ``error`` (the part's error, chained by the loop's
    SimulationError) whose message holds every word."""
    with pytest.raises((SimulationError, error)) as info:
        run(system, state, (0.0, 0.5))
    exc = info.value
    cause = exc.__cause__ if isinstance(exc, SimulationError) else exc
    assert isinstance(cause, error), repr(cause)
    for word in words:
        assert word in str(exc), (word, str(exc))
    return exc


# --- parts that write into the state they are given ----------------------------------------


class WritingForce(gmuk.ForceModel):
    """A force model that scales the twist it is given in place."""

    def wrench(self, t, g_NB, V_B, body):
        V_B *= 2.0
        return np.zeros(6)


class WritingWrenches(gmuk.ForceModel):
    """A force model (own wrenches()) that writes into the State's poses."""

    def wrenches(self, state, bodies):
        state.g[0, 0, 3] += 1.0
        return [np.zeros(6) for _ in bodies]


class WritingController(gmuk.Controller):
    """A controller that zeroes its internal state in place."""

    def __init__(self):
        super().__init__(["a"], n_states=3, name="resetter")

    def initial_state(self):
        return np.array([1.0, 2.0, 3.0])

    def control(self, state, z):
        z[:] = 0.0
        return [np.zeros(6)], np.zeros(3)


class WritingConstraint(gmuk.Constraint):
    """A constraint that writes into the State's twists."""

    def rows(self, state):
        state.V[0, 3] = 0.0
        return np.eye(6)[:1], np.zeros(1)


def writers():
    return {
        "force": ([], [WritingForce()], [], "force 'WritingForce'"),
        "wrenches": ([], [WritingWrenches()], [], "force 'WritingWrenches'"),
        "controller": ([], [], [WritingController()], "controller 'resetter'"),
        "constraint": ([WritingConstraint(["a"])], [], [], "constraint 'WritingConstraint'"),
    }


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("kind", ["force", "wrenches", "controller", "constraint"])
def test_a_part_that_writes_into_its_state_leaves_the_callers_state_unchanged(kind, loop):
    constraints, forces, controllers, who = writers()[kind]
    system = gmuk.System([rigid()], constraints, forces, controllers)
    state0 = state_of(system)
    before = [a.copy() for a in (state0.g, state0.V, state0.x, state0.xdot, state0.z)]
    exc = refused(LOOPS[loop], system, state0, DefinitionError, who, "read-only")
    assert "t = 0 s" in str(exc)  # refused at the first evaluation, not later
    after = (state0.g, state0.V, state0.x, state0.xdot, state0.z)
    assert all(np.array_equal(x, y) for x, y in zip(before, after, strict=True))
    with pytest.raises(DefinitionError, match="read-only"):  # System.accelerations too
        system.accelerations(state0)


def test_a_states_arrays_are_read_only_copies_never_the_callers_arrays():
    system = gmuk.System([rigid()], controllers=[WritingController()])
    g, V, z = np.eye(4), np.array(V0), np.array([1.0, 2.0, 3.0])
    state = system.state(g={"a": g}, V={"a": V}, z=z)
    for a in (state.g, state.V, state.x, state.xdot, state.z, state.pose("a"), state.twist("a")):
        assert not a.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            a[...] = 0.0
    # the caller's arrays are neither frozen nor shared: changing them changes no State
    assert g.flags.writeable and V.flags.writeable and z.flags.writeable
    V[0] = z[0] = 99.0
    assert state.V[0, 0] == V0[0] and state.z[0] == 1.0
    # the constructor copies writable arrays (and views of them) too
    mine = np.zeros((1, 6))
    other = gmuk.State(0.0, state.g, mine, state.x, state.xdot, state.z[:], state.layout)
    mine[0, 0] = 5.0
    assert other.V[0, 0] == 0.0 and mine.flags.writeable
    assert other.g is state.g  # a State's own (read-only) arrays are shared, not copied
    frozen_view_of_writable = mine.view()
    frozen_view_of_writable.setflags(write=False)
    third = state.replace(V=frozen_view_of_writable)
    mine[0, 1] = 7.0
    assert third.V[0, 1] == 0.0


@pytest.mark.parametrize("loop", LOOPS)
def test_honest_parts_that_compute_on_copies_of_their_state_still_run(loop):
    class CopyingForce(gmuk.ForceModel):
        def wrench(self, t, g_NB, V_B, body):
            w = V_B.copy()
            w *= -0.1
            return w

    class Damping(gmuk.ForceModel):
        def wrench(self, t, g_NB, V_B, body):
            return -0.1 * V_B

    system = gmuk.System([rigid()], [], [CopyingForce()])
    state0 = state_of(system)
    traj = LOOPS[loop](system, state0, (0.0, 0.5))
    assert traj.success and np.array_equal(state0.V[0], V0)
    same = gmuk.System([rigid()], [], [Damping()])
    expected = LOOPS[loop](same, state_of(same), (0.0, 0.5))
    assert np.array_equal(traj.V_B, expected.V_B) and not np.array_equal(traj.V_B[-1, 0], V0)


# --- controllers' ż ------------------------------------------------------------------------


class ZDot(gmuk.Controller):
    """A controller with three internal states returning the given ż (and zero wrenches)."""

    def __init__(self, z_dot, u=None):
        super().__init__(["a"], n_states=3, name="zdot")
        self.z_dot, self.u = z_dot, u

    def control(self, state, z):
        return [np.zeros(6) if self.u is None else self.u], self.z_dot


@pytest.mark.parametrize("loop", LOOPS)
def test_a_controller_returning_a_scalar_z_dot_for_three_states_is_refused(loop):
    system = gmuk.System([rigid()], controllers=[ZDot(1.0)])
    refused(LOOPS[loop], system, state_of(system), DefinitionError, "controller 'zdot'",
            "z_dot", "3 entries", "t = 0 s")  # fmt: skip
    honest = gmuk.System([rigid()], controllers=[ZDot(np.ones(3))])
    traj = LOOPS[loop](honest, state_of(honest), (0.0, 0.5))
    assert np.allclose(traj.z[-1], 0.5)


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("z_dot", [np.ones(2), np.ones(4), np.ones((2, 3)), [], [1.0, [2.0, 3.0]]])
def test_a_controller_returning_z_dot_of_the_wrong_length_is_refused(loop, z_dot):
    system = gmuk.System([rigid()], controllers=[ZDot(z_dot)])
    refused(LOOPS[loop], system, state_of(system), DefinitionError, "controller 'zdot'")


@pytest.mark.parametrize("loop", LOOPS)
def test_a_controller_returning_z_dot_with_three_entries_in_another_shape_is_taken(loop):
    column = gmuk.System([rigid()], controllers=[ZDot(np.ones((3, 1)))])
    flat = gmuk.System([rigid()], controllers=[ZDot(np.ones(3))])
    a = LOOPS[loop](column, state_of(column), (0.0, 0.5))
    b = LOOPS[loop](flat, state_of(flat), (0.0, 0.5))
    assert np.array_equal(a.z, b.z) and np.array_equal(a.V_B, b.V_B)


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_controller_returning_nan_in_z_dot_is_refused(loop, bad):
    system = gmuk.System([rigid()], controllers=[ZDot(np.array([0.0, bad, 0.0]))])
    refused(LOOPS[loop], system, state_of(system), NonFiniteError, "controller 'zdot'", "z_dot",
            "non-finite", "t = 0 s")  # fmt: skip


# --- complex, string and boolean returns ---------------------------------------------------

HOSTILE = {
    "complex": np.full(6, 1.0 + 2.0j),
    "complex with zero imaginary part": np.full(6, 1.0 + 0.0j),
    "strings": ["1.5"] * 6,
    "string array": np.array(["1.5"] * 6),
    "booleans": np.ones(6, dtype=bool),
    "boolean list": [True, False, True, False, True, False],
    "objects": np.array([1.0, None, 1.0, 1.0, 1.0, 1.0], dtype=object),
    "a string": "1.5",
    "a bool": True,
    "a complex": 1.5j,
}


class Returns(gmuk.ForceModel):
    """A force model returning the given value for every body."""

    def __init__(self, value):
        super().__init__(name="hostile")
        self.value = value

    def wrench(self, t, g_NB, V_B, body):
        return self.value

    def force(self, t, r_N, v_N, body):
        return self.value


class ReturnsList(Returns):
    """The same through its own wrenches() (the other path of the System)."""

    def wrenches(self, state, bodies):
        return [self.value for _ in bodies]


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("cls", [Returns, ReturnsList])
@pytest.mark.parametrize("value", list(HOSTILE), ids=list(HOSTILE))
def test_complex_string_and_boolean_returns_from_force_models_are_refused(loop, cls, value):
    system = gmuk.System([rigid()], [], [cls(HOSTILE[value])])
    refused(LOOPS[loop], system, state_of(system), DefinitionError, "force 'hostile'",
            "rigid body 'a'", "real numbers", "t = 0 s")  # fmt: skip


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("value", list(HOSTILE), ids=list(HOSTILE))
def test_complex_string_and_boolean_returns_from_controllers_are_refused(loop, value):
    wrench = gmuk.System([rigid()], controllers=[ZDot(np.zeros(3), u=HOSTILE[value])])
    refused(LOOPS[loop], wrench, state_of(wrench), DefinitionError, "controller 'zdot'",
            "rigid body 'a'", "real numbers")  # fmt: skip
    z_dot = np.asarray(HOSTILE[value]).reshape(-1)[:3] if np.ndim(HOSTILE[value]) else value
    z_dot = HOSTILE[value] if not np.ndim(HOSTILE[value]) else z_dot
    rate = gmuk.System([rigid()], controllers=[ZDot(z_dot)])
    refused(LOOPS[loop], rate, state_of(rate), DefinitionError, "controller 'zdot'", "z_dot")


@pytest.mark.parametrize("loop", LOOPS)
def test_integer_and_list_returns_are_taken_as_the_same_floats(loop):
    ints = gmuk.System([rigid()], [], [Returns([1, 0, -2, 0, 3, 0])], [ZDot([1, 2, 3])])
    floats = gmuk.System(
        [rigid()], [], [Returns(np.array([1.0, 0.0, -2.0, 0.0, 3.0, 0.0]))],
        [ZDot(np.array([1.0, 2.0, 3.0]))],
    )  # fmt: skip
    a = LOOPS[loop](ints, state_of(ints), (0.0, 0.5))
    b = LOOPS[loop](floats, state_of(floats), (0.0, 0.5))
    for field in ("t", "g_NB", "V_B", "z"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_force_model_returning_nan_is_refused_naming_the_model_the_body_and_the_time(loop, bad):
    b = gmuk.RigidBody("b", 1.0, np.eye(3))
    system = gmuk.System([rigid(), b], [], [Returns(np.array([0, 0, 0, 0, bad, 0.0]))])
    state = system.state(g={"a": np.eye(4), "b": np.eye(4)}, V={"a": V0, "b": V0})
    refused(LOOPS[loop], system, state, NonFiniteError, "force 'hostile'", "rigid body 'a'",
            "non-finite", "t = 0 s")  # fmt: skip


@pytest.mark.parametrize("loop", LOOPS)
def test_a_force_models_wrench_of_the_wrong_length_is_refused(loop):
    system = gmuk.System([rigid()], [], [Returns(np.ones(3))])
    refused(LOOPS[loop], system, state_of(system), DefinitionError, "force 'hostile'",
            "shape (3,)", "(6,)")  # fmt: skip


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("where", ["A", "b"])
def test_boolean_constraint_rows_are_refused(loop, where):
    A, b = np.eye(6)[:2], np.zeros(2)
    rows = Rows(["a"], A.astype(bool) if where == "A" else A, b.astype(bool) if where == "b" else b)
    system = gmuk.System([rigid()], [rows])
    refused(LOOPS[loop], system, state_of(system), ConstraintError, "constraint 'Rows'",
            "booleans", where)  # fmt: skip
    ints = Rows(["a"], A.astype(int), b.astype(int))  # integers are real numbers
    honest = gmuk.System([rigid()], [ints])
    assert LOOPS[loop](honest, state_of(honest), (0.0, 0.5)).success


@pytest.mark.parametrize("loop", LOOPS)
def test_complex_constraint_rows_are_refused(loop):
    system = gmuk.System([rigid()], [Rows(["a"], np.eye(6)[:2] * (1 + 1j), np.zeros(2))])
    refused(LOOPS[loop], system, state_of(system), ConstraintError, "constraint 'Rows'")


# --- item 10: inconsistent constraints at any scale ---------------------------------------

CONTRADICTORY = (np.array([[1.0, 0, 0, 0, 0, 0], [1.0, 0, 0, 0, 0, 0]]), np.array([1.0, 0.0]))
CONSISTENT = (np.array([[1.0, 0, 0, 0, 0, 0], [2.0, 0, 0, 0, 0, 0]]), np.array([1.0, 2.0]))
SOLVERS = ["fused", "dense", "sparse"]


def scaled(rows, c, solver, strict=False):
    A, b = rows
    return gmuk.System([rigid()], [Rows(["a"], c * A, c * b)], solver=solver, strict=strict)


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("c", [1.0, 1e-8, 1e-12, 1e8])
def test_contradictory_constraints_scaled_by_1e_minus_8_still_warn(solver, c):
    system = scaled(CONTRADICTORY, c, solver)
    with pytest.warns(InconsistentConstraintsWarning, match="inconsistent"):
        system.accelerations(state_of(system))
    strict = scaled(CONTRADICTORY, c, solver, strict=True)
    with pytest.raises(InconsistentConstraintsError):
        strict.accelerations(state_of(strict))


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("c", [1.0, 1e-8, 1e-12, 1e8])
def test_consistent_constraints_scaled_by_1e_minus_8_or_1e8_do_not_warn(solver, c):
    system = scaled(CONSISTENT, c, solver, strict=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        acc = system.accelerations(state_of(system))
    assert np.allclose(acc.total[0], 1.0, rtol=1e-12)  # ω̇_x = 1 from the rows
    # full-rank rows scaled as well (the certified QR path)
    full = gmuk.System([rigid()], [Rows(["a"], c * np.eye(6)[:3], c * np.ones(3))],
                       solver=solver, strict=True)  # fmt: skip
    assert np.allclose(full.accelerations(state_of(full)).total[:3], 1.0, rtol=1e-12)


@pytest.mark.parametrize("loop", LOOPS)
@pytest.mark.parametrize("solver", ["fused", "dense"])
def test_contradictory_constraints_scaled_by_1e_minus_8_stop_a_strict_run_in_both_loops(
    loop, solver
):
    system = scaled(CONTRADICTORY, 1e-8, solver, strict=True)
    refused(LOOPS[loop], system, state_of(system), InconsistentConstraintsError, "inconsistent")
    honest = scaled(CONSISTENT, 1e-8, solver, strict=True)
    traj = LOOPS[loop](honest, state_of(honest), (0.0, 0.5))
    assert traj.success


def test_the_qr_kernel_and_the_svd_solve_use_the_same_relative_scale():
    from gmuk.engine import _uk_kernels

    rng = np.random.default_rng(3)
    for c in (1e-8, 1.0, 1e8):
        A, b, a = c * rng.normal(size=(3, 6)), c * rng.normal(size=3), rng.normal(size=6)
        Ms = np.eye(6)
        ac, _, res, scale, status = _uk_kernels.uk_qr(A, b, a, Ms, 1e8)
        _, _, _, res2, scale2 = _uk_kernels.uk_dense(A, b, a, Ms, 6 * 2.2e-16)
        assert status == 0 and np.isclose(scale, scale2, rtol=1e-12)
        expected = np.linalg.norm(b) + np.linalg.norm(A) * (np.linalg.norm(a) + np.linalg.norm(ac))
        assert np.isclose(scale, expected, rtol=1e-12)
        assert res < 1e-14 * scale and res2 < 1e-14 * scale2


def test_every_refusal_is_a_gmuk_error():
    for error in (DefinitionError, NonFiniteError, ConstraintError, InconsistentConstraintsError):
        assert issubclass(error, GmukError)
