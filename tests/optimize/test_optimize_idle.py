"""Components the problem's structure holds at zero (OptimalControlProblem.idle) are held at
zero by the transcription: the same optimum with a smaller NLP, and only where it is proved."""

from __future__ import annotations

import numpy as np
import pytest
from slew_problems import slew_problem

import gmuk
from gmuk.errors import DefinitionError
from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.scenarios import smd

MESH = Mesh.uniform(0.0, 30.0, 40, 3)


def _mass(anchor=(0.0, 0.0, 0.0), v0=(6.0, 0.0, 0.0), constraints=(), **options):
    mass = gmuk.PointMass("mass", 2.0)
    bound = gmuk.PlaneBound(mass, [1.0, 0.0, 0.0], lower=1.0, upper=2.0, name="x")
    spring = gmuk.LinearSpringDamper(10.0, 5.0, anchor=list(anchor), bodies=[mass])
    system = gmuk.System([mass], [bound, *[c(mass) for c in constraints]], [spring])
    state = system.state(r={"mass": [1.5, 0.0, 0.0]}, v={"mass": list(v0)})
    return OptimalControlProblem(system, state, 30.0, **options)


def test_a_mass_moved_along_one_axis_is_solved_on_that_axis_with_the_same_optimum():
    system, state = smd.build("smd-bi")
    reduced = OptimalControlProblem(system, state, 30.0)
    states, controls = reduced.idle
    assert states.tolist() == [1, 2, 4, 5] and controls.tolist() == [1, 2]  # y, z
    full = OptimalControlProblem(system, state, 30.0, eliminate_idle=False)
    a, b = reduced.solve(MESH), full.solve(MESH)
    assert a.stats["idle_states"] == 4 and b.stats["idle_states"] == 0
    assert a.stats["n_constraints"] == b.stats["n_constraints"] - 4 * 3 * MESH.n_elements
    assert a.objective == pytest.approx(b.objective, rel=1e-10)
    np.testing.assert_allclose(a.y, b.y, atol=1e-7)
    np.testing.assert_allclose(a.u, b.u, atol=1e-5 * np.abs(b.u).max())
    assert np.all(a.y[:, [1, 2, 4, 5]] == 0.0) and np.all(a.u[:, 1:] == 0.0)


def test_the_translation_of_a_body_that_only_slews_is_held_at_zero():
    mesh = Mesh.uniform(0.0, 60.0, 8, 4)
    reduced = slew_problem()
    # r_N (0-2) and v_B (6-8); the body force f (controls 3-5)
    assert reduced.idle[0].tolist() == [0, 1, 2, 6, 7, 8]
    assert reduced.idle[1].tolist() == [3, 4, 5]
    full = slew_problem(eliminate_idle=False)
    a, b = reduced.solve(mesh), full.solve(mesh)
    assert a.objective == pytest.approx(b.objective, rel=1e-9)
    np.testing.assert_allclose(a.R_NB, b.R_NB, atol=1e-8)


@pytest.mark.parametrize(
    ("make", "states", "controls"),
    [
        # the spring pulls towards an anchor off the x axis: y is driven, z still idle
        (lambda: _mass(anchor=(0.0, 0.5, 0.0)), [2, 5], [2]),
        # moving along y at the start: y is not zero
        (lambda: _mass(v0=(6.0, 0.1, 0.0)), [2, 5], [2]),
        # a control bound that excludes zero: that control, and the states it drives
        (
            lambda: _mass(control_bounds={"mass": ([-np.inf, 0.1, -np.inf], [np.inf] * 3)}),
            [2, 5],
            [2],
        ),
        # a path constraint on y
        (
            lambda: _mass(constraints=[lambda m: gmuk.PlaneBound(m, [0, 1, 0], upper=1.0)]),
            [2, 5],
            [2],
        ),
        # a user's running cost in the x and y controls: only z is left idle (a user's
        # cost must not depend on an idle component at all)
        (
            lambda: _mass(cost=lambda t, q, nu, u: u[0][0] ** 2 + u[0][1] ** 4),
            [2, 5],
            [2],
        ),
    ],
    ids=["anchor-off-axis", "moving-in-y", "bound-excludes-zero", "path-on-y", "cost-on-y"],
)
def test_only_what_is_proved_idle_is_held_at_zero(make, states, controls):
    problem = make()
    assert problem.idle[0].tolist() == states
    assert problem.idle[1].tolist() == controls
    reduced = problem.solve(MESH)
    problem.eliminate_idle = False
    full = problem.solve(MESH)
    assert reduced.objective == pytest.approx(full.objective, rel=1e-8)


@pytest.mark.parametrize("bad", [1, "no", None])
def test_eliminate_idle_must_be_a_bool(bad):
    with pytest.raises(DefinitionError, match="eliminate_idle must be True or False"):
        _mass(eliminate_idle=bad)
