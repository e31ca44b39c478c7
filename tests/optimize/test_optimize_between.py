"""Path inequalities between the nodes: the result reports how far the state's interpolant
leaves the bounds there, and adaptive refinement with ``bound_tol`` brings it under."""

from __future__ import annotations

import numpy as np
import pytest

from gmuk.errors import DefinitionError
from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.scenarios import smd


def _smd() -> OptimalControlProblem:
    system, state = smd.build("smd-bi")  # 1 m ≤ x ≤ 2 m
    return OptimalControlProblem(system, state, 30.0)


def _brute_force_violation(result, per_element=400):
    """max(1 − x, x − 2, 0) on a dense grid of the interpolant, element by element."""
    worst = 0.0
    for a, b in zip(result.mesh.breaks[:-1], result.mesh.breaks[1:], strict=True):
        t = np.linspace(a, b, per_element)[1:-1]
        x = result.states_at(t)[:, 0]
        worst = max(worst, float(np.max(np.maximum(np.maximum(1.0 - x, x - 2.0), 0.0))))
    return worst


def test_the_violation_between_the_nodes_is_that_of_the_interpolant():
    result = _smd().solve(Mesh.uniform(0.0, 30.0, 40, 3))
    reported = result.violation_between_nodes()
    assert set(reported) == {"x"}
    dense = _brute_force_violation(result)
    # 20 samples per element against 400: the same peak to a few percent, never above it
    assert 0.0 < reported["x"] <= dense * (1 + 1e-12)
    assert reported["x"] == pytest.approx(dense, rel=0.05)
    # at the nodes the bounds hold (IPOPT's bound relaxation aside)
    x_nodes = result.y[:, 0]
    assert np.all((x_nodes >= 1.0 - 1e-7) & (x_nodes <= 2.0 + 1e-7))


def test_refinement_with_bound_tol_brings_the_smd_between_node_violation_under_1e_6_m():
    result = _smd().solve_adaptive(
        Mesh.uniform(0.0, 30.0, 10, 3), tol=1e-6, bound_tol=1e-6, max_rounds=12
    )
    steps = result.refinement
    assert steps[0].max_bound_violation > 1e-2
    assert steps[-1].max_bound_violation <= 1e-6
    assert result.violation_between_nodes()["x"] <= 1e-6
    assert _brute_force_violation(result) <= 1e-6
    assert steps[-1].max_error <= 1e-6


def test_without_bound_tol_the_history_has_no_violation_figures():
    result = _smd().solve_adaptive(Mesh.uniform(0.0, 30.0, 10, 3), tol=1e-2)
    assert all(np.isnan(s.max_bound_violation) for s in result.refinement)


@pytest.mark.parametrize("bad", [0.0, -1e-6, float("nan"), "1e-6"])
def test_bound_tol_must_be_a_positive_number(bad):
    with pytest.raises(DefinitionError, match="bound_tol"):
        _smd().solve_adaptive(bound_tol=bad)
