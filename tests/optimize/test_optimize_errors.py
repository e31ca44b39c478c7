"""Bad input to gmuk.optimize: clear GmukErrors naming the part, IPOPT's status, no hangs."""

from __future__ import annotations

import subprocess
import sys

import casadi as ca
import numpy as np
import pytest

import gmuk
from gmuk.errors import DefinitionError, GmukError, OptimizationError
from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.scenarios import smd


def _mass_system(constraints=(), forces=(), controllers=()):
    mass = gmuk.PointMass("p", 1.0)
    system = gmuk.System([mass], constraints, forces, controllers)
    return mass, system, system.state(r={"p": [1.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]})


class FixedRows(gmuk.Constraint):
    def rows(self, state):
        return np.eye(3), np.zeros(3)


def test_a_constraint_kind_without_a_path_form_is_refused_by_name():
    _, system, state = _mass_system([FixedRows(["p"], name="rows-only")])
    with pytest.raises(DefinitionError, match="'rows-only' is a FixedRows, a kind"):
        OptimalControlProblem(system, state, 1.0)


class FloatDrag(gmuk.ForceModel):
    def force(self, t, r_N, v_N, body):
        return -float(v_N[0]) * np.array([1.0, 0.0, 0.0])


class CasadiDrag(FloatDrag):
    def casadi_force(self, t, r_N, v_N, body):
        return -ca.vertcat(v_N[0], 0.0, 0.0)


def test_a_force_model_without_a_casadi_form_is_named_with_the_fix():
    _, system, state = _mass_system(forces=[FloatDrag(name="drag")])
    problem = OptimalControlProblem(system, state, 1.0)
    with pytest.raises(DefinitionError, match=r"force model 'drag' \(FloatDrag\).*casadi_force"):
        problem.solve(n_elements=2)


def test_a_force_model_with_a_casadi_method_is_used():
    _, system, state = _mass_system(forces=[CasadiDrag(name="drag")])
    final = {"r": {"p": [2.0, 0.0, 0.0]}, "v": {"p": [0.0, 0.0, 0.0]}}
    result = OptimalControlProblem(system, state, 2.0, final=final).solve(n_elements=8)
    # the control works against the drag: more effort than the frictionless 12 d²/T³
    assert result.objective > 12.0 * 1.0 / 2.0**3


class Zero(gmuk.Controller):
    def control(self, state, z):
        return [np.zeros(3)], np.zeros(0)


def test_controllers_are_refused():
    mass = gmuk.PointMass("p", 1.0)
    ctl = Zero([mass], name="pd")
    system = gmuk.System([mass], controllers=[ctl])
    state = system.state(r={"p": [0.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]})
    with pytest.raises(DefinitionError, match="controllers"):
        OptimalControlProblem(system, state, 1.0)


def test_a_final_state_outside_a_bound_is_infeasible_before_solving():
    system, state = smd.build("smd-bi")
    with pytest.raises(OptimizationError, match="final state violates 'x'") as info:
        OptimalControlProblem(
            system, state, 30.0, final={"r": {"mass": [3.0, 0, 0]}, "v": {"mass": [0, 0, 0]}}
        )
    assert info.value.status == "Infeasible_Bounds" and isinstance(info.value, GmukError)


class UnitCircle(gmuk.HolonomicConstraint):
    def residual(self, q, t):
        r = q[0]
        return [r[0] ** 2 + r[1] ** 2 - 1.0, r[2]]


def test_an_infeasible_problem_reports_ipopts_status():
    mass = gmuk.PointMass("p", 1.0)
    system = gmuk.System([mass], [UnitCircle([mass])])
    state = system.state(r={"p": [1.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]})
    problem = OptimalControlProblem(system, state, 1.0, final={"r": {"p": [2.0, 0.0, 0.0]}})
    with pytest.raises(OptimizationError) as info:
        problem.solve(n_elements=4, max_iter=200)
    assert info.value.status in (
        "Infeasible_Problem_Detected",
        "Restoration_Failed",
        "Local_Infeasibility",
    )
    assert info.value.status in str(info.value)
    assert info.value.result is not None and not info.value.result.success


def test_the_iteration_limit_stops_the_solver_with_its_log_on_request():
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    with pytest.raises(OptimizationError, match="Maximum_Iterations_Exceeded") as info:
        problem.solve(n_elements=20, max_iter=2, log=True)
    result = info.value.result
    assert info.value.status == "Maximum_Iterations_Exceeded"
    assert result.iterations == 2 and result.log is not None
    assert "iter" in result.log and "inf_pr" in result.log
    assert result.iteration_history["inf_pr"].size == 3  # iterations 0, 1, 2


def test_the_cpu_time_limit_stops_the_solver():
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    with pytest.raises(OptimizationError) as info:
        problem.solve(n_elements=150, max_cpu_time=1e-4)
    assert info.value.status in ("Maximum_CpuTime_Exceeded", "Maximum_WallTime_Exceeded")


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"t_final": 0.0}, "t_final must be >"),
        ({"final": {"g": {"p": np.eye(4)}}}, "'g' is for rigid bodies"),
        ({"final": {"r": {"q": [0, 0, 0]}}}, "unknown body 'q'"),
        ({"final": {"x": {}}}, "keys 'g', 'V', 'r', 'v'"),
        ({"final": 3}, "final must be a State"),
        ({"cost": 1.0}, "cost must be a callable"),
        ({"max_element_rotation": 2.0}, "max_element_rotation"),
    ],
)
def test_bad_problem_definitions_are_refused(kwargs, message):
    _, system, state = _mass_system()
    args = {"t_final": 1.0, **kwargs}
    with pytest.raises(DefinitionError, match=message):
        OptimalControlProblem(system, state, **args)


def test_bad_meshes_and_solver_options_are_refused():
    _, system, state = _mass_system()
    problem = OptimalControlProblem(system, state, 1.0)
    with pytest.raises(DefinitionError, match="the mesh spans"):
        problem.solve(Mesh.uniform(0.0, 2.0, 3))
    with pytest.raises(DefinitionError, match="strictly increasing"):
        Mesh([0.0, 0.5, 0.5, 1.0])
    with pytest.raises(DefinitionError, match="needs 2 degrees"):
        Mesh([0.0, 0.5, 1.0], [3])
    with pytest.raises(DefinitionError, match="max_cpu_time"):
        problem.solve(n_elements=2, max_cpu_time=-1.0)
    with pytest.raises(DefinitionError, match="max_iter"):
        problem.solve(n_elements=2, max_iter=1.5)


def test_import_gmuk_does_not_import_casadi():
    code = "import sys, gmuk; print('casadi' in sys.modules, 'gmuk.optimize' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


class FloatValue(gmuk.InequalityConstraint):
    """h = x through float(): fine with numbers, NaN with CasADi symbols."""

    def value(self, q, nu, t):
        return float(q[0][0])


def test_a_part_that_turns_symbols_into_nan_is_named():
    mass = gmuk.PointMass("p", 1.0)
    system = gmuk.System([mass], [FloatValue([mass], lower=0.0, name="x-float")])
    state = system.state(r={"p": [1.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]})
    with pytest.raises(DefinitionError, match=r"constraint 'x-float' \(FloatValue\).*float\(\)"):
        OptimalControlProblem(system, state, 1.0).solve(n_elements=3)


def test_a_missing_casadi_says_how_to_install_it(monkeypatch):
    _, system, state = _mass_system()
    monkeypatch.setitem(sys.modules, "casadi", None)  # import casadi now raises ImportError
    with pytest.raises(gmuk.errors.MissingDependencyError, match=r'pip install "gmuk\[optimize\]"'):
        OptimalControlProblem(system, state, 1.0)
