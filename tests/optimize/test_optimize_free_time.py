"""Control bounds and a free final time: the minimum-time rest-to-rest slew about a principal
axis is bang-bang with the analytic switching and final times, and the minimum of effort plus
elapsed time has the analytic final time."""

from __future__ import annotations

import numpy as np
import pytest
from slew_problems import slew_problem

from gmuk.errors import DefinitionError
from gmuk.optimize import Mesh

J_Z = 15.0  # kg m², the principal axis of the slew
THETA = 0.5 * np.pi  # rad
TAU_MAX = 0.5  # N m


def _slew(**options):
    return slew_problem(np.diag([10.0, 12.0, J_Z]), [0.0, 0.0, THETA], 20.0, **options)


def _minimum_time():
    """Only the torque about z, |τ_z| ≤ τ_max; the cost is the elapsed time alone."""
    return _slew(
        cost=lambda t, q, nu, u: 0,
        control_bounds={"sat": ([0, 0, -TAU_MAX, 0, 0, 0], [0, 0, TAU_MAX, 0, 0, 0])},
        free_final_time=(1.0, 100.0),
        time_cost=1.0,
    )


def _switching_times(t, u):
    """Where the nodal control changes sign: the zero of the line through the nodes either
    side."""
    i = np.flatnonzero(np.sign(u[:-1]) * np.sign(u[1:]) < 0)
    i = np.union1d(i, np.flatnonzero(u[1:-1] == 0.0))  # a node exactly at zero
    out = []
    for j in i:
        if u[j] == 0.0:
            out.append(t[j])
        else:
            out.append(t[j] - u[j] * (t[j + 1] - t[j]) / (u[j + 1] - u[j]))
    return np.unique(np.round(out, 12))


@pytest.mark.parametrize("n_elements", [20, 40])
def test_minimum_time_slew_is_bang_bang_with_the_analytic_switching_time(n_elements):
    # rest to rest by θ about a principal axis with |τ| ≤ τ_max: a double integrator,
    # full torque to mid-slew then full reverse, t_f = 2 √(θ J_z / τ_max)
    t_final = 2.0 * np.sqrt(THETA * J_Z / TAU_MAX)
    r = _minimum_time().solve(Mesh.uniform(0.0, 20.0, n_elements, 3), tol=1e-12)
    assert r.stats["t_final"] == pytest.approx(t_final, abs=1e-6)
    assert r.t[-1] == r.stats["t_final"] and r.mesh.tf == pytest.approx(r.t[-1], abs=1e-12)
    tau = r.u[:, 2]
    switches = _switching_times(r.t, tau)
    np.testing.assert_allclose(switches, [0.5 * t_final], atol=1e-6)
    # saturated everywhere else, at the bounds to IPOPT's bound relaxation
    away = np.abs(r.t - 0.5 * r.t[-1]) > 1e-9  # the node at the switch takes 0
    np.testing.assert_allclose(np.abs(tau[away]), TAU_MAX, atol=1e-7)
    assert np.all(np.abs(r.u[:, [0, 1, 3, 4, 5]]) <= 1e-7)


def test_effort_plus_elapsed_time_has_the_analytic_final_time():
    # ∫ τ²/J_z dt = 12 J_z θ² / T³ at the optimum for a slew in T, plus c T: T* = (36 J_z θ²/c)^¼
    c = 1e-3
    r = _slew(free_final_time=(1.0, 100.0), time_cost=c).solve(
        Mesh.uniform(0.0, 20.0, 12, 4), tol=1e-12
    )
    expected = (36.0 * J_Z * THETA**2 / c) ** 0.25
    assert r.stats["t_final"] == pytest.approx(expected, rel=1e-8)
    assert r.objective == pytest.approx(12 * J_Z * THETA**2 / expected**3 + c * expected, rel=1e-8)


def test_a_free_time_result_is_a_guess_for_a_finer_mesh():
    coarse = _minimum_time().solve(Mesh.uniform(0.0, 20.0, 10, 3))
    fine = _minimum_time().solve(Mesh.uniform(0.0, 20.0, 40, 3), guess=coarse)
    assert fine.stats["t_final"] == pytest.approx(coarse.stats["t_final"], abs=1e-5)


def test_control_bounds_hold_at_every_node():
    # unbounded, the minimum-effort torque peaks at 6 J_z θ/T² = 0.35 N m; 0.3 N m binds and
    # still allows the slew (its minimum time is 17.7 s < 20 s)
    r = _slew(control_bounds={"sat": (-0.3, [0.3, 0.3, 0.3, None, None, None])}).solve(
        Mesh.uniform(0.0, 20.0, 8, 3)
    )
    assert np.all(np.abs(r.u[:, :3]) <= 0.3 + 1e-8)
    assert np.abs(r.u[:, :3]).max() == pytest.approx(0.3, abs=1e-6)  # it binds (IPOPT tol)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"control_bounds": [(-1, 1)]}, "must map body names"),
        ({"control_bounds": {"nobody": (-1, 1)}}, "names unknown body"),
        ({"control_bounds": {"sat": (-1, 1, 2)}}, r"must be \(lower, upper\)"),
        ({"control_bounds": {"sat": ([-1, -1], 1)}}, "6 numbers"),
        ({"control_bounds": {"sat": (float("nan"), 1)}}, "not NaN"),
        ({"control_bounds": {"sat": (1, -1)}}, "exceeds upper"),
        ({"free_final_time": 30.0}, r"\(t_min, t_max\)"),
        ({"free_final_time": (25.0, 30.0)}, "t_min ≤ t_final ≤ t_max"),
        ({"free_final_time": (-1.0, 30.0)}, "t_min ≤ t_final ≤ t_max"),
        ({"time_cost": 1.0}, "give free_final_time"),
        ({"time_cost": -1.0, "free_final_time": (1.0, 30.0)}, "≥ 0"),
    ],
)
def test_bad_control_bounds_and_final_time_options_are_refused(options, message):
    with pytest.raises(DefinitionError, match=message):
        _slew(**options)


def test_adaptive_refinement_with_a_free_final_time_closes_in_on_the_switch():
    # 5 elements: the switch at mid-slew falls inside the middle element, which the
    # estimates split until the smeared switch no longer moves the final time much
    t_final = 2.0 * np.sqrt(THETA * J_Z / TAU_MAX)
    r = _minimum_time().solve_adaptive(Mesh.uniform(0.0, 20.0, 5, 3), tol=1e-6, max_rounds=6)
    first = r.refinement[0]
    assert len(r.refinement) > 1 and r.mesh.n_elements > 5
    assert abs(r.stats["t_final"] - t_final) < 1e-2 * abs(first.objective - t_final)
    assert r.mesh.tf == pytest.approx(r.stats["t_final"], rel=1e-14)
