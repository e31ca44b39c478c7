"""The bounded spring–mass–damper by direct collocation: against an independent hand-written
CasADi transcription, KKT conditions, mesh refinement, equality path constraints, user costs."""

from __future__ import annotations

import functools
import itertools
import math

import casadi as ca
import numpy as np
import pytest
from handwritten_lobatto import solve_smd

import gmuk
from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.scenarios import smd


@functools.cache
def _bounded(n_elements: int = 150, degree: int = 3):
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    return problem, problem.solve(Mesh.uniform(0.0, 30.0, n_elements, degree))


def test_bounded_smd_objective_agrees_with_a_handwritten_transcription_to_1e_6():
    _, result = _bounded()
    ref = solve_smd(n_elements=150, degree=3, t_final=30.0, x0=1.5, v0=6.0, lower=1.0, upper=2.0)
    assert ref["status"] == "Solve_Succeeded" and result.status == "Solve_Succeeded"
    assert abs(result.objective - ref["objective"]) <= 1e-6 * abs(ref["objective"])
    np.testing.assert_allclose(result.t, ref["t"], atol=1e-12)
    np.testing.assert_allclose(result.r_N[:, 0, 0], ref["x"], atol=1e-6)
    np.testing.assert_allclose(result.u[:, 0], ref["u"], atol=1e-4 * np.abs(ref["u"]).max())
    # nothing acts off the x axis
    assert np.abs(result.r_N[:, 0, 1:]).max() < 1e-9 and np.abs(result.u[:, 1:]).max() < 1e-6


def test_bounded_smd_optimum_satisfies_the_bounds_and_the_kkt_conditions():
    _, result = _bounded()
    x = result.r_N[:, 0, 0]
    assert x.min() >= 1.0 - 1e-7 and x.max() <= 2.0 + 1e-7
    assert x.min() < 1.0 + 1e-6 and x.max() > 2.0 - 1e-6  # both bounds are reached
    res = result.kkt_residuals()
    assert res["stationarity_relative"] < 1e-8
    assert res["primal_violation"] < 1e-7
    assert res["dual_violation"] == 0.0
    kkt = result.kkt()
    assert set(kkt) == {"x.lower", "x.upper"}
    for b in kkt.values():
        s = b.summary()
        assert s["primal_violation_max"] < 1e-7
        assert s["dual_violation_max"] == 0.0
        # μ is nonzero only where the bound is active
        active = np.abs(b.g) < 1e-5
        assert np.abs(b.mu[~active]).max(initial=0.0) < 1e-3 * np.abs(b.mu).max()
    assert np.abs(kkt["x.lower"].mu).max() > 1.0  # the lower bound holds the mass


def test_objective_converges_under_adaptive_mesh_refinement():
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0)
    result = problem.solve_adaptive(Mesh.uniform(0.0, 30.0, 10, 3), tol=1e-6)
    steps = result.refinement
    assert steps is not None and len(steps) >= 3
    assert steps[-1].max_error <= 1e-6
    errors = [s.max_error for s in steps]
    assert all(b < a for a, b in itertools.pairwise(errors))
    assert abs(steps[-1].objective - steps[-2].objective) < 1e-5 * steps[-1].objective
    assert abs(steps[0].objective - steps[-1].objective) > 1e-2 * steps[-1].objective
    assert result.mesh.n_elements == steps[-1].n_elements


def test_the_thesis_single_five_point_element_is_a_mesh_of_one_element():
    system, state = smd.build("smd-bi")
    result = OptimalControlProblem(system, state, 30.0).solve(Mesh([0.0, 30.0], 4))
    assert result.mesh.n_nodes == 5 and result.success
    assert result.r_N[:, 0, 0].min() >= 1.0 - 1e-7


def test_a_user_cost_replaces_the_gauss_cost():
    system, state = smd.build("smd-bi")
    problem = OptimalControlProblem(system, state, 30.0, cost=lambda t, q, nu, u: ca.sumsqr(u[0]))
    result = problem.solve(Mesh.uniform(0.0, 30.0, 150, 3))
    _, default = _bounded()
    # ∫|u|² dt = m ∫ uᵀM⁻¹u dt, and the same control is optimal
    assert abs(result.objective - smd.MASS * default.objective) < 1e-6 * result.objective
    assert result.path["x"].cost_unit == "cost"


class UnitCircle(gmuk.HolonomicConstraint):
    """x² + y² = 1, z = 0, written with operations CasADi takes (no float())."""

    def residual(self, q, t):
        r = q[0]
        return [r[0] ** 2 + r[1] ** 2 - 1.0, r[2]]


def test_a_holonomic_constraint_is_held_at_every_node():
    mass = gmuk.PointMass("p", 1.0)
    system = gmuk.System([mass], [UnitCircle([mass])])
    state = system.state(r={"p": [1.0, 0.0, 0.0]}, v={"p": [0.0, 0.0, 0.0]})
    final = {"r": {"p": [0.0, 1.0, 0.0]}, "v": {"p": [0.0, 0.0, 0.0]}}
    problem = OptimalControlProblem(system, state, 4.0, final=final)
    result = problem.solve(Mesh.uniform(0.0, 4.0, 16, 4))
    r = result.r_N[:, 0]
    np.testing.assert_allclose(np.hypot(r[:, 0], r[:, 1]), 1.0, atol=1e-9)
    np.testing.assert_allclose(r[-1], [0.0, 1.0, 0.0], atol=1e-12)
    pc = result.path["UnitCircle"]
    assert pc.kind == "holonomic" and pc.value.shape == (result.mesh.n_nodes - 2, 2)
    # the centripetal force is the control's radial part: the circle's multiplier is nonzero
    assert np.abs(pc.multiplier[:, 0]).max() > 1e-3


def test_the_open_loop_controller_reproduces_the_unconstrained_plan():
    """A free SMD driven to rest at x = 1 m: re-simulated with the interpolated control."""
    mass = gmuk.PointMass("mass", smd.MASS)
    system = gmuk.System([mass], forces=[gmuk.LinearSpringDamper(smd.STIFFNESS, smd.DAMPING)])
    state = system.state(r={"mass": [0.0, 0.0, 0.0]}, v={"mass": [0.0, 0.0, 0.0]})
    final = {"r": {"mass": [1.0, 0.0, 0.0]}, "v": {"mass": [0.0, 0.0, 0.0]}}
    result = OptimalControlProblem(system, state, 5.0, final=final).solve(
        Mesh.uniform(0.0, 5.0, 20, 4)
    )
    driven = gmuk.System(
        [mass],
        forces=[gmuk.LinearSpringDamper(smd.STIFFNESS, smd.DAMPING)],
        controllers=[result.controller()],
    )
    traj = driven.simulate(state, (0.0, 5.0), t_eval=result.t, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(traj.r_N[:, 0], result.r_N[:, 0], atol=1e-6)
    with pytest.raises(gmuk.errors.DefinitionError, match="times must lie"):
        result.control(5.5)


class Push(gmuk.ForceModel):
    """A time-varying push written with math.sin: it needs a numeric time."""

    def force(self, t, r_N, v_N, body):
        return np.array([math.sin(t), 0.0, 0.0])

    def casadi_force(self, t, r_N, v_N, body):
        return ca.DM([math.sin(t), 0.0, 0.0])


def test_parts_that_need_a_numeric_time_fall_back_to_one_expression_per_node():
    mass = gmuk.PointMass("mass", smd.MASS)
    system = gmuk.System([mass], forces=[Push()])
    state = system.state(r={"mass": [0.0, 0.0, 0.0]}, v={"mass": [0.0, 0.0, 0.0]})
    final = {"r": {"mass": [0.0, 0.0, 0.0]}, "v": {"mass": [0.0, 0.0, 0.0]}}
    result = OptimalControlProblem(system, state, 2 * math.pi, final=final).solve(
        Mesh.uniform(0.0, 2 * math.pi, 12, 5)
    )
    # holding the mass still against sin t costs ∫ sin²t / m dt = π/m; moving it may cost less
    assert 0.0 < result.objective < math.pi / smd.MASS
    assert result.success


def test_mixed_degrees_and_the_mapped_mesh_agree_where_they_coincide(monkeypatch):
    from gmuk.optimize.problem import _Transcription

    problem, mapped = _bounded()

    def refuse(self):
        raise gmuk.errors.DefinitionError("forced")

    monkeypatch.setattr(_Transcription, "_build_mapped", refuse)
    unrolled = problem.solve(mapped.mesh)
    assert abs(unrolled.objective - mapped.objective) < 1e-9 * mapped.objective
    mixed = problem.solve(Mesh(np.linspace(0.0, 30.0, 151), [3, 4] * 75))
    assert mixed.success and abs(mixed.objective / mapped.objective - 1.0) < 1e-2


class Line:
    """A reference moving along x at 1 m/s."""

    def kinematics(self, t):
        return np.array([t, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]), np.zeros(3)


def test_a_tracking_error_bound_holds_at_every_node():
    mass = gmuk.PointMass("p", 1.0)
    bound = gmuk.TrackingErrorBound(mass, Line(), 0.1, form="squared", name="near")
    system = gmuk.System([mass], [bound])
    # start 0.05 m off the reference, at rest: the control must catch it up within 0.1 m
    state = system.state(r={"p": [0.0, 0.05, 0.0]}, v={"p": [0.0, 0.0, 0.0]})
    result = OptimalControlProblem(system, state, 4.0).solve(Mesh.uniform(0.0, 4.0, 16, 3))
    err = result.r_N[:, 0] - np.stack([result.t, 0 * result.t, 0 * result.t], axis=1)
    assert result.path["near"].t[0] > 0.0  # the reference needs numeric times: unrolled
    assert np.linalg.norm(err, axis=1).max() <= 0.1 + 1e-7
    assert np.linalg.norm(err, axis=1).max() > 0.1 - 1e-6  # the bound is reached
    assert result.path["near"].value.shape == (result.mesh.n_nodes - 1,)
