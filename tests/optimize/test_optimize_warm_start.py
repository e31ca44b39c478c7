"""Warm starts and continuation: a result as the guess for a changed parameter, with or
without its multipliers, and the solve's time per phase."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.errors import DefinitionError
from gmuk.optimize import Mesh, OptimalControlProblem

MESH = Mesh.uniform(0.0, 30.0, 60, 3)


def _smd(upper: float) -> OptimalControlProblem:
    """The bounded SMD with the upper bound on x as the parameter that changes (m)."""
    mass = gmuk.PointMass("mass", 2.0)
    bound = gmuk.PlaneBound(mass, [1.0, 0.0, 0.0], lower=1.0, upper=upper, name="x")
    spring = gmuk.LinearSpringDamper(10.0, 5.0, bodies=[mass])
    system = gmuk.System([mass], [bound], [spring])
    state = system.state(r={"mass": [1.5, 0.0, 0.0]}, v={"mass": [6.0, 0.0, 0.0]})
    return OptimalControlProblem(system, state, 30.0)


def test_a_warm_start_on_the_same_mesh_reaches_the_same_optimum_in_fewer_iterations():
    previous = _smd(2.0).solve(MESH)
    problem = _smd(1.95)
    cold = problem.solve(MESH)
    warm = problem.solve(MESH, guess=previous, warm_start=True)
    assert warm.stats["warm_started"] and not cold.stats["warm_started"]
    assert warm.objective == pytest.approx(cold.objective, rel=1e-9)
    np.testing.assert_allclose(warm.y, cold.y, atol=1e-6)
    assert warm.iterations < cold.iterations


def test_on_another_mesh_the_warm_start_falls_back_to_the_guess_states():
    previous = _smd(2.0).solve(Mesh.uniform(0.0, 30.0, 30, 3))
    problem = _smd(1.95)
    result = problem.solve(MESH, guess=previous, warm_start=True)
    assert not result.stats["warm_started"]
    assert result.objective == pytest.approx(problem.solve(MESH).objective, rel=1e-9)


def test_a_result_is_a_guess_for_a_changed_parameter_without_its_multipliers():
    previous = _smd(2.0).solve(MESH)
    result = _smd(1.8).solve(MESH, guess=previous)
    assert not result.stats["warm_started"]
    assert result.objective == pytest.approx(_smd(1.8).solve(MESH).objective, rel=1e-9)


@pytest.mark.parametrize("bad", [1, "yes", None])
def test_warm_start_must_be_a_bool(bad):
    with pytest.raises(DefinitionError, match="warm_start must be True or False"):
        _smd(2.0).solve(MESH, warm_start=bad)


def test_the_solve_time_is_split_into_evaluations_and_ipopts_own_work():
    t = _smd(2.0).solve(MESH).timings
    assert t["evaluations_s"] > 0.0 and t["ipopt_s"] > 0.0
    assert t["evaluations_s"] + t["ipopt_s"] == pytest.approx(t["solve_s"], rel=1e-12)
    assert t["transcription_s"] + t["solve_s"] == pytest.approx(t["total_s"], rel=1e-12)
