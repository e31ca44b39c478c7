"""Hostile input to gmuk.optimize (issue #25, item 8 and the optimiser hang of item 2): clear
GmukErrors saying what was expected, valid input unchanged, and a solve that keeps to its time
budget however large the mesh."""

from __future__ import annotations

import functools
import time

import numpy as np
import pytest

import gmuk
from gmuk.errors import DefinitionError, GmukError, OptimizationError
from gmuk.optimize import (
    Mesh,
    OpenLoopControl,
    OptimalControlProblem,
    interpolation_matrix,
    lgl_nodes,
    register_casadi_form,
)
from gmuk.optimize.mesh import MAX_NODES
from gmuk.scenarios import smd


def _mass_problem(name="p", t_final=1.0):
    mass = gmuk.PointMass(name, 1.0)
    system = gmuk.System([mass])
    state = system.state(r={name: [1.0, 0.0, 0.0]}, v={name: [0.0, 0.0, 0.0]})
    final = {"r": {name: [2.0, 0.0, 0.0]}, "v": {name: [0.0, 0.0, 0.0]}}
    return OptimalControlProblem(system, state, t_final, final=final)


@functools.cache
def _solved():
    return _mass_problem().solve(n_elements=4)


@functools.cache
def _rigid_solved():
    body = gmuk.RigidBody("sat", 10.0, np.diag([1.0, 2.0, 3.0]))
    system = gmuk.System([body])
    state = system.state(g={"sat": np.eye(4)}, V={"sat": np.zeros(6)})
    return OptimalControlProblem(system, state, 1.0).solve(n_elements=2)


# ---------------------------------------------------------------------------- meshes
@pytest.mark.parametrize("n", [float("nan"), float("inf"), "abc", "10", None, [3], 2.5, True, 0])
def test_mesh_uniform_refuses_an_element_count_that_is_not_a_positive_integer(n):
    with pytest.raises(DefinitionError, match="n_elements must be an integer ≥ 1"):
        Mesh.uniform(0.0, 1.0, n)


def test_mesh_uniform_refuses_10_to_the_12_elements_before_allocating():
    tic = time.perf_counter()
    with pytest.raises(DefinitionError, match=r"more than max_nodes = 200000.*pass max_nodes="):
        Mesh.uniform(0.0, 1.0, 10**12)
    assert time.perf_counter() - tic < 1.0
    assert MAX_NODES == 200_000


def test_a_mesh_above_the_node_limit_is_built_when_asked_for_explicitly():
    with pytest.raises(DefinitionError, match="max_nodes"):
        Mesh.uniform(0.0, 1.0, 70_000)
    mesh = Mesh.uniform(0.0, 1.0, 70_000, max_nodes=210_001)
    assert mesh.n_nodes == 210_001
    with pytest.raises(DefinitionError, match="max_nodes"):
        Mesh(np.linspace(0.0, 1.0, 70_001), 3)
    with pytest.raises(DefinitionError, match="max_nodes must be an integer ≥ 2"):
        Mesh.uniform(0.0, 1.0, 3, max_nodes="many")


@pytest.mark.parametrize("degree", [2.5, True, None, np.float64(3.0), "3", 0, 401])
def test_a_mesh_degree_must_be_an_integer_from_1_to_400(degree):
    with pytest.raises(DefinitionError, match="an LGL degree must be"):
        Mesh.uniform(0.0, 1.0, 4, degree)
    with pytest.raises(DefinitionError, match="an LGL degree must be"):
        Mesh([0.0, 0.5, 1.0], degree)


@pytest.mark.parametrize(
    "breaks",
    [
        "0123",
        [True, False],
        [0.0, True],
        [[0.0, 1.0], [2.0, 3.0]],
        [0.0, 1j],
        np.array(["0", "1"]),
        [0.0, 1.0, float("nan")],
        [0.0, float("inf")],
        None,
        5.0,
        [0.0, None],
    ],
)
def test_mesh_breaks_must_be_a_1d_sequence_of_finite_real_numbers(breaks):
    with pytest.raises(DefinitionError, match="mesh breaks"):
        Mesh(breaks, 3)


def test_mesh_breaks_with_an_infinite_span_or_repeated_times_are_refused():
    with pytest.raises(DefinitionError, match="finite span"):
        Mesh([-1e308, 1e308], 3)
    with pytest.raises(DefinitionError, match="strictly increasing"):
        Mesh([0.0, 0.5, 0.5, 1.0], 3)
    with pytest.raises(DefinitionError, match="tf − t0 must be finite"):
        Mesh.uniform(-1e308, 1e308, 4)


def test_a_mesh_element_too_narrow_for_distinct_node_times_is_refused():
    with pytest.raises(DefinitionError, match="too narrow"):
        Mesh([0.0, 1e-320], 3)
    with pytest.raises(DefinitionError, match=r"element 1.*too narrow"):
        Mesh([0.0, 1e9, 1e9 + 1e-6], 3)


@pytest.mark.parametrize(
    ("counts", "message"),
    [
        ([2, "2"], "split count of element 1"),
        ([2.5, 1], "split count of element 0"),
        ([True, 1], "split count of element 0"),
        ([float("nan"), 1], "split count of element 0"),
        ("ab", "split counts must be a sequence"),
        (None, "split counts must be a sequence"),
        ([2], "one count per element"),
        ([10**12, 1], "max_nodes"),
    ],
)
def test_mesh_split_refuses_counts_that_are_not_integers_and_huge_meshes(counts, message):
    with pytest.raises(DefinitionError, match=message):
        Mesh([0.0, 1.0, 2.0], 3).split(counts)


def test_valid_meshes_keep_their_nodes_weights_and_element_lookup():
    mesh = Mesh.uniform(0.0, 2.0, 10.0, np.int64(3))  # an integral float count is taken
    assert mesh.n_elements == 10 and mesh.n_nodes == 31
    x, _ = lgl_nodes(3)
    t_ref = np.concatenate([0.1 + 0.1 * x] + [0.2 * k + 0.1 + 0.1 * x[1:] for k in range(1, 10)])
    assert np.allclose(mesh.times, t_ref, rtol=0, atol=1e-15)
    assert mesh.times[-1] == 2.0 and np.isclose(mesh.quadrature_weights.sum(), 2.0)
    mixed = Mesh([0.0, 1.0, 3.0, 3.5], [2, 5, 1])
    assert [mixed.first_node(k) for k in range(3)] == [0, 2, 7] and mixed.n_nodes == 9
    assert np.isclose(mixed.quadrature_weights @ mixed.times, 3.5**2 / 2)
    assert list(mixed.element_of([0.0, 1.0, 2.9, 3.5])) == [0, 1, 1, 2]
    assert mixed.split([1, 2, 1]).n_elements == 4
    with pytest.raises(DefinitionError, match="times must lie in"):
        mixed.element_of(4.0)
    with pytest.raises(DefinitionError, match="finite"):
        mixed.element_of(float("nan"))


def test_interpolation_nodes_must_be_distinct_finite_real_numbers():
    with pytest.raises(DefinitionError, match="distinct"):
        interpolation_matrix([0.0, 0.0, 1.0], [0.5])
    with pytest.raises(DefinitionError, match="interpolation nodes"):
        interpolation_matrix("ab", [0.5])
    with pytest.raises(DefinitionError, match="interpolation nodes"):
        interpolation_matrix([], [0.5])
    with pytest.raises(DefinitionError, match="evaluation point"):
        interpolation_matrix([0.0, 1.0], float("nan"))
    assert np.allclose(interpolation_matrix([0.0, 1.0], 0.25), [[0.75, 0.25]])


# ---------------------------------------------------------------------------- solve arguments
@pytest.mark.parametrize("guess", [{"y": [0.0]}, "previous", 3, []])
def test_a_guess_that_is_not_a_result_is_refused_saying_what_is_expected(guess):
    with pytest.raises(DefinitionError, match="guess must be an OptimalControlResult"):
        _mass_problem().solve(n_elements=4, guess=guess)


def test_another_systems_result_as_a_guess_is_refused():
    with pytest.raises(DefinitionError, match=r"other bodies.*\('sat', 'rigid', 6\)"):
        _mass_problem().solve(n_elements=4, guess=_rigid_solved())
    other = _mass_problem("q").solve(n_elements=2)
    with pytest.raises(DefinitionError, match=r"other bodies.*\('q', 'point', 3\)"):
        _mass_problem().solve(n_elements=4, guess=other)


def test_a_guess_not_covering_the_span_is_refused():
    short = _mass_problem(t_final=0.5).solve(n_elements=2)
    with pytest.raises(DefinitionError, match=r"guess spans \[0, 0.5\] s"):
        _mass_problem().solve(n_elements=4, guess=short)


def test_a_previous_result_of_the_same_problem_is_still_a_guess():
    result = _mass_problem().solve(n_elements=6, guess=_solved())
    assert result.success and np.isclose(result.objective, 12.0)


@pytest.mark.parametrize("options", [["mu_strategy", "adaptive"], "mu_strategy", 3])
def test_a_list_as_ipopt_options_is_refused_saying_a_mapping_is_expected(options):
    with pytest.raises(DefinitionError, match="ipopt_options must be a mapping"):
        _mass_problem().solve(n_elements=4, ipopt_options=options)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"mu_strategy": ["adaptive"]}, "must be a string, an integer or a number"),
        ({"mu_strategy": True}, "must be a string, an integer or a number"),
        ({"acceptable_tol": float("nan")}, "must not be NaN"),
        ({1: 2}, "non-empty strings"),
        ({"max_iter": 5}, "max_iter="),
        ({"ipopt.max_cpu_time": 1e9}, "max_cpu_time="),
        ({"max_wall_time": 1e9}, "max_cpu_time="),
        ({"no_such_option": 1}, "CasADi refused the IPOPT options"),
    ],
)
def test_ipopt_option_names_and_values_are_checked(options, message):
    with pytest.raises(DefinitionError, match=message):
        _mass_problem().solve(n_elements=4, ipopt_options=options)


def test_valid_ipopt_options_are_still_passed_to_ipopt():
    result = _mass_problem().solve(
        n_elements=4, ipopt_options={"mu_strategy": "adaptive", "acceptable_tol": np.float64(1e-6)}
    )
    assert result.success and np.isclose(result.objective, 12.0)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"max_iter": "abc"}, "max_iter must be an integer"),
        ({"max_iter": None}, "max_iter must be an integer"),
        ({"max_iter": 1e20}, "max_iter must be an integer"),
        ({"max_cpu_time": "1"}, "max_cpu_time"),
        ({"max_cpu_time": float("inf")}, "max_cpu_time"),
        ({"tol": 0.0}, "tol must be a number > 0"),
        ({"log": "False"}, "log must be True or False"),
        ({"log": 1}, "log must be True or False"),
        ({"n_elements": float("nan")}, "n_elements"),
        ({"degree": 2.5}, "LGL degree"),
        ({"mesh": "abc"}, "mesh must be a gmuk.optimize.Mesh"),
    ],
)
def test_solve_arguments_are_checked_before_anything_is_built(kwargs, message, monkeypatch):
    from gmuk.optimize import problem

    def no_build(*args, **kw):
        raise AssertionError("built before checking the arguments")

    problem_ = _mass_problem()
    monkeypatch.setattr(problem, "_Transcription", no_build)
    with pytest.raises(DefinitionError, match=message):
        problem_.solve(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"max_rounds": "abc"}, "max_rounds must be an integer ≥ 1"),
        ({"max_rounds": 0}, "max_rounds must be an integer ≥ 1"),
        ({"max_elements": None}, "max_elements must be an integer ≥ 1"),
        ({"tol": "1e-6"}, "tol must be a number > 0"),
    ],
)
def test_solve_adaptive_arguments_are_checked(kwargs, message):
    with pytest.raises(DefinitionError, match=message):
        _mass_problem().solve_adaptive(**kwargs)


@pytest.mark.parametrize("final", [{"r": [2.0, 0.0, 0.0]}, {"r": "ab"}, {"v": 3}])
def test_final_conditions_must_map_body_names_to_values(final):
    problem = _mass_problem()
    with pytest.raises(DefinitionError, match=r"final\['[rv]'\] must be a mapping body name"):
        OptimalControlProblem(
            problem.system,
            problem.system.state(r={"p": [1.0, 0, 0]}, v={"p": [0.0, 0, 0]}),
            1.0,
            final=final,
        )


# ---------------------------------------------------------------------------- the time budget
def test_a_200000_element_mesh_is_refused_up_front_when_it_cannot_be_built_in_the_budget():
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    mesh = Mesh.uniform(0.0, 30.0, 200_000, 3, max_nodes=600_001)
    tic = time.perf_counter()
    with pytest.raises(OptimizationError, match=r"would take about .* s to build") as info:
        problem.solve(mesh, max_cpu_time=5.0)
    assert time.perf_counter() - tic < 5.0
    assert info.value.status == "Maximum_CpuTime_Exceeded" and info.value.result is None
    assert isinstance(info.value, GmukError)


def test_the_build_stops_with_an_error_when_the_budget_is_spent_building():
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    with pytest.raises(OptimizationError, match="was spent building the NLP") as info:
        problem.solve(n_elements=60, max_cpu_time=1e-6)
    assert info.value.status == "Maximum_CpuTime_Exceeded" and info.value.result is None


def test_a_solve_keeps_to_its_time_budget_building_and_solving():
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    tic = time.perf_counter()
    try:
        problem.solve(n_elements=400, max_cpu_time=0.3)
    except OptimizationError as exc:
        assert exc.status in ("Maximum_CpuTime_Exceeded", "Maximum_WallTime_Exceeded")
    assert time.perf_counter() - tic < 0.3 + 1.0


# ---------------------------------------------------------------------------- results and parts
@pytest.mark.parametrize("t", ["a", float("nan"), [0.5, float("nan")], [[0.1]], 2.0, None, True])
def test_a_result_refuses_times_that_are_not_finite_times_in_its_span(t):
    result = _solved()
    for method in (result.control, result.states_at, _rigid_solved().attitudes_at):
        with pytest.raises(DefinitionError):
            method(t)


def test_open_loop_control_needs_a_result_and_a_name():
    with pytest.raises(DefinitionError, match="needs an OptimalControlResult"):
        OpenLoopControl({})
    with pytest.raises(DefinitionError, match="non-empty str"):
        _solved().controller(3)
    assert _solved().controller().name == "optimal control"


def test_register_casadi_form_refuses_what_is_not_a_part_class_or_a_protocol_method():
    with pytest.raises(DefinitionError, match="ForceModel or Constraint class"):
        register_casadi_form(3, "casadi_force")
    with pytest.raises(DefinitionError, match="method must be one of"):
        register_casadi_form(gmuk.ForceModel, "casadi_forse")

    class Drag(gmuk.ForceModel):
        def force(self, t, r_N, v_N, body):
            return -v_N

    with pytest.raises(DefinitionError, match="decorates a function"):
        register_casadi_form(Drag, "casadi_force")(3)
