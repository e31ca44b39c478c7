"""Bad input at the public boundary is a gmuk error naming the argument (issue #15)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from helpers import Returns

import gmuk
from gmuk.errors import ConstraintError, DefinitionError, EulerSequenceError
from gmuk.lie import euler


@pytest.fixture(scope="module")
def system():
    return gmuk.System([gmuk.RigidBody("a", 1.0, np.eye(3))])


@pytest.fixture(scope="module")
def state(system):
    return system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)})


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"bodies": None}, "bodies must be a sequence"),
        ({"constraints": None}, "constraints must be a sequence"),
        ({"forces": "gravity"}, "forces must be a sequence"),
        ({"controllers": 3}, "controllers must be a sequence"),
        ({"rcond": 0.0}, "rcond must be a number > 0; got 0.0"),
        ({"rcond": 1.5}, "rcond must be in (0, 1) or None; got 1.5"),
        ({"consistency_tol": "x"}, "consistency_tol must be a number > 0; got 'x'"),
        ({"consistency_tol": float("nan")}, "consistency_tol must be finite; got nan"),
        ({"strict": "no"}, "strict must be True or False; got 'no'"),
    ],
)
def test_system_arguments(kwargs, message):
    args = {"bodies": [gmuk.RigidBody("a", 1.0, np.eye(3))], **kwargs}
    with pytest.raises(DefinitionError, match=re.escape(message)):
        gmuk.System(**args)


def test_state_arguments(system):
    with pytest.raises(DefinitionError, match="g must be a mapping of body name to value"):
        system.state(g="a", V={"a": np.zeros(6)})
    with pytest.raises(DefinitionError, match=re.escape("t must be a real number; got array")):
        system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)}, t=np.array([1.0, 2.0]))
    with pytest.raises(DefinitionError, match="t must be finite"):
        system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)}, t=float("inf"))


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"method": "RK4", "step": complex(0.1, 1)}, "step must be a number > 0; got (0.1+1j)"),
        ({"method": "RK4", "step": -0.1}, "step must be a number > 0; got -0.1"),
        ({"t_eval": "abc"}, "t_eval must be an array of finite real times (s); got 'abc'"),
        ({"rtol": "x"}, "rtol must be a number > 0; got 'x'"),
        ({"atol": 0.0}, "atol must be a number > 0; got 0.0"),
        ({"first_step": -1.0}, "first_step must be a number > 0; got -1.0"),
        ({"max_step": 0.0}, "max_step must be a number > 0; got 0.0"),
        ({"max_steps": -1}, "max_steps must be an integer >= 1; got -1"),
        ({"max_steps": 2.5}, "max_steps must be an integer >= 1; got 2.5"),
        ({"progress": "x"}, "progress must be True, False or None; got 'x'"),
    ],
)
def test_simulate_options(system, state, options, message):
    with pytest.raises(DefinitionError, match=re.escape(message)):
        system.simulate(state, (0.0, 1.0), **options)


def test_simulate_state_and_span(system, state):
    with pytest.raises(DefinitionError, match=r"state0 must be a gmuk\.State"):
        system.simulate(None, (0.0, 1.0))
    for span in (None, "ab", (0.0,), (0.0, 1.0, 2.0)):
        with pytest.raises(DefinitionError, match="t_span must be a pair"):
            system.simulate(state, span)
    with pytest.raises(DefinitionError, match="t_span must be finite"):
        system.simulate(state, (0.0, float("inf")))
    assert system.simulate(state, (0.0, 1.0), max_step=np.inf).success  # inf is a valid bound


@pytest.mark.parametrize(
    ("out", "message"),
    [
        (None, "rows() must return a pair (A, b); got NoneType"),
        ((np.zeros((1, 6)),), "rows() must return a pair (A, b); got tuple of length 1"),
        ({"A": 1, "b": 2}, "rows() must return a pair (A, b); got dict"),
        ("ab", "rows() must return a pair (A, b); got str"),
        (([[1.0, 2.0], [3.0]], [0.0, 0.0]), "as arrays of real numbers"),
        ((np.zeros((1, 6)), None), "as arrays of real numbers"),
        (([[1j] * 6], [0.0]), "as arrays of real numbers"),
        ((np.zeros((1, 5)), np.zeros(1)), "must return A of shape (s, 6)"),
    ],
)
def test_a_user_constraint_returning_the_wrong_structure(state, out, message):
    system = gmuk.System([gmuk.RigidBody("a", 1.0, np.eye(3))], [Returns(out)])
    with pytest.raises(ConstraintError, match=re.escape(message)):
        system.accelerations(state)
    with pytest.raises(ConstraintError, match="'Returns'"):  # names the constraint
        system.constraint_rows(state)


def test_a_list_pair_of_rows_is_accepted(state):
    system = gmuk.System([gmuk.RigidBody("a", 1.0, np.eye(3))], [Returns([np.eye(6)[:1], [0]])])
    assert system.accelerations(state).multipliers.shape == (1,)


def test_extreme_inertia_is_checked_without_overflow():
    # 1e308 kg·m² has a subnormal inverse (1e-308 < 2.2e-308): refused since issue #25
    with pytest.raises(gmuk.errors.InertiaError, match="J⁻¹ is finite"):
        gmuk.RigidBody("big", 1.0, np.eye(3) * 1e308)
    body = gmuk.RigidBody("big", 1.0, np.eye(3) * 4e307)  # valid, if absurd
    assert body.inertia[0, 0] == 4e307
    with pytest.raises(gmuk.errors.InertiaError, match="triangle inequality"):
        gmuk.RigidBody("flat", 1.0, np.diag([1e307, 1e307, 1e308]))


def test_euler_sequence_must_be_a_string():
    with pytest.raises(EulerSequenceError, match="seq must be one of"):
        euler.to_matrix(np.zeros(3), np.array(["321"]))
    with pytest.raises(EulerSequenceError, match="seq must be one of"):
        euler.from_matrix(np.eye(3), 321)


HOSTILE = [None, "x", 1j, float("nan"), float("inf"), -1.0, [1.0, 2.0], True, [[1, 2], [3]]]


def _orbit():
    return gmuk.orbits.KeplerOrbit.from_elements(2e6, 0.1, 0.2, 0.0, 0.0, 4.9e12)


CONSTRUCTORS = {
    "PointMassGravity": lambda v: gmuk.PointMassGravity(v),
    "GravityGradient": lambda v: gmuk.GravityGradient(v),
    "LinearSpringDamper": lambda v: gmuk.LinearSpringDamper(v),
    "SpringDamper": lambda v: gmuk.SpringDamper("p", [0, 0, 0], None, [0, 0, 1], stiffness=v),
    "SlackDamping": lambda v: gmuk.SlackDamping(v),
    "Baumgarte": lambda v: gmuk.Baumgarte(v, 1.0),
    "PlaneBound normal": lambda v: gmuk.PlaneBound("p", v, lower=0.0),
    "PlaneBound lower": lambda v: gmuk.PlaneBound("p", [0, 0, 1], lower=v),
    "AppliedWrench": lambda v: gmuk.AppliedWrench("p", v),
    "LVLHReference": lambda v: gmuk.orbits.LVLHReference(v),
    "TrackingErrorBound": lambda v: gmuk.TrackingErrorBound("p", _orbit(), v),
}


@pytest.mark.parametrize("name", sorted(CONSTRUCTORS))
@pytest.mark.parametrize("value", HOSTILE, ids=repr)
def test_part_constructors_refuse_hostile_values_with_gmuk_errors(name, value):
    if (name, value) in (("Baumgarte", [1.0, 2.0]), ("PlaneBound lower", -1.0)):
        CONSTRUCTORS[name](value)  # valid: per-row gains; a bound below zero
        return
    with pytest.raises(gmuk.errors.GmukError):
        CONSTRUCTORS[name](value)


def test_state_refuses_an_empty_batch_of_poses_for_one_body():
    # found by the slow fuzz suite: a (0, 4, 4) pose passed the group check (nothing to
    # check) and failed later with numpy's broadcast error
    body = gmuk.RigidBody("a", 1.0, np.eye(3))
    system = gmuk.System([body])
    with pytest.raises(gmuk.errors.ShapeError, match=r"g\['a'\] must have shape \(4, 4\)"):
        system.state(g={"a": np.zeros((0, 4, 4))}, V={"a": np.zeros(6)})
