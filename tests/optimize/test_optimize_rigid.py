"""Rigid bodies by local exponential coordinates: minimum-effort slews on SO(3)."""

from __future__ import annotations

import functools

import numpy as np
from slew_problems import GENERAL_INERTIA, slew_problem

import gmuk
from gmuk.lie import so3
from gmuk.optimize import Mesh, _so3
from gmuk.optimize.problem import _Transcription

T = 60.0  # s


def _rotation_angles(R_a, R_b):
    return np.linalg.norm(so3.log(np.swapaxes(R_a, -1, -2) @ R_b), axis=-1)


def _slew(inertia, axis, n_elements, degree=3):
    rotation = 0.5 * np.pi * np.asarray(axis) / np.linalg.norm(axis)
    problem = slew_problem(inertia, rotation, T)
    body = problem.system.bodies[0]
    state = problem.system.state(g={"sat": np.eye(4)}, V={"sat": np.zeros(6)})
    gf = np.eye(4)
    gf[:3, :3] = so3.exp(rotation)
    return body, state, gf, problem, problem.solve(Mesh.uniform(0.0, T, n_elements, degree))


@functools.cache
def _general_slew():
    return _slew(GENERAL_INERTIA, [1.0, 1.0, 1.0], 12, 4)


def test_principal_axis_slew_has_the_analytic_minimum_effort():
    """Rest to rest about a principal axis: θ̈ linear in t, J = 12 J_z θ²/T³."""
    _, _, gf, _, result = _slew(np.diag([10.0, 12.0, 15.0]), [0.0, 0.0, 1.0], 6)
    expected = 12.0 * 15.0 * (0.5 * np.pi) ** 2 / T**3
    assert abs(result.objective - expected) < 1e-9 * expected
    assert _rotation_angles(result.R_NB[-1, 0], gf[:3, :3]) < 1e-10


def test_attitude_is_a_rotation_at_every_node_and_reaches_the_target():
    _, _, gf, _, result = _general_slew()
    assert result.success
    R = result.R_NB[:, 0]
    assert np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max() < 1e-10
    assert np.abs(np.linalg.det(R) - 1.0).max() < 1e-10
    assert _rotation_angles(R[-1], gf[:3, :3]) < 1e-9
    np.testing.assert_allclose(result.V_B[-1, 0], 0.0, atol=1e-12)
    # the gyroscopic coupling makes the control three-axis
    assert np.all(np.abs(result.u[:, :3]).max(axis=0) > 1e-4)
    assert result.kkt_residuals()["stationarity_relative"] < 1e-8


def test_resimulating_the_optimal_control_tracks_the_plan_to_1e_4_rad():
    body, state, gf, _, result = _general_slew()
    driven = gmuk.System([body], controllers=[result.controller()])
    traj = driven.simulate(state, (0.0, T), t_eval=result.t, rtol=1e-11, atol=1e-12)
    err = _rotation_angles(traj.g_NB[:, 0, :3, :3], result.R_NB[:, 0])
    assert err.max() < 1e-4
    assert _rotation_angles(traj.g_NB[-1, 0, :3, :3], gf[:3, :3]) < 1e-4
    # and the attitude between nodes, from the element's θ interpolant
    t_mid = 0.5 * (result.t[1:] + result.t[:-1])
    traj_mid = driven.simulate(state, (0.0, T), t_eval=t_mid, rtol=1e-11, atol=1e-12)
    assert (
        _rotation_angles(traj_mid.g_NB[:, 0, :3, :3], result.attitudes_at(t_mid)[:, 0]).max() < 1e-4
    )


def test_batched_dynamics_agree_with_the_node_by_node_evaluation():
    _, _, _, problem, result = _general_slew()
    tr = _Transcription(problem, result.mesh, build=False)
    rng = np.random.default_rng(3)
    y = result.y + rng.normal(size=result.y.shape)  # translation and rotation both moving
    batch = tr._rhs_batch(result.t, y, result.u, result.R_NB)
    loop = np.array(
        [
            tr._rhs_num(float(t), y[i], result.u[i], list(result.R_NB[i]))
            for i, t in enumerate(result.t)
        ]
    )
    np.testing.assert_allclose(batch, loop, atol=1e-13)


def test_series_exponential_and_chart_kinematics():
    rng = np.random.default_rng(0)
    for angle in (0.0, 1e-9, 0.4, 1.5, 2.6):
        th = rng.normal(size=3)
        th *= angle / np.linalg.norm(th)
        assert np.abs(_so3.exp_numeric(th) - so3.exp(th)).max() < 1e-15 * 4
        omega = rng.normal(size=3)
        rate = _so3.theta_rate_numeric(th, omega)
        h = 1e-6
        dR = (so3.exp(th + h * rate) - so3.exp(th - h * rate)) / (2 * h)
        np.testing.assert_allclose(dR, so3.exp(th) @ so3.hat(omega), atol=1e-8)


def test_the_unrolled_transcription_gives_the_mapped_optimum(monkeypatch):
    """The per-node transcription (parts called with numeric times) and the mapped one are
    the same NLP."""
    _, _, _, problem, mapped = _general_slew()

    def refuse(self):
        raise gmuk.errors.DefinitionError("forced")

    monkeypatch.setattr(_Transcription, "_build_mapped", refuse)
    unrolled = problem.solve(mapped.mesh)
    assert abs(unrolled.objective - mapped.objective) < 1e-9 * mapped.objective
    np.testing.assert_allclose(unrolled.R_NB, mapped.R_NB, atol=1e-8)


def test_a_slew_refines_from_its_previous_solution():
    rotation = [1.5, 1.5, 0.0]  # 122°: more than one element's chart bound
    gf = np.eye(4)
    gf[:3, :3] = so3.exp(rotation)
    problem = slew_problem(GENERAL_INERTIA, rotation, T)
    result = problem.solve_adaptive(Mesh.uniform(0.0, T, 2, 3), tol=1e-7)
    steps = result.refinement
    assert steps[-1].max_error <= 1e-7 and len(steps) >= 2
    fine = problem.solve(Mesh.uniform(0.0, T, 24, 5))
    assert abs(result.objective - fine.objective) < 1e-6 * fine.objective
    assert _rotation_angles(result.R_NB[-1, 0], gf[:3, :3]) < 1e-9
    R = result.R_NB[:, 0]
    assert np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max() < 1e-10
