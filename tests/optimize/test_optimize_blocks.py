"""The NLP's derivatives assembled from its blocks (gmuk.optimize._blocks) equal CasADi's own
derivatives of the same NLP, and inequalities that bound one variable become variable
bounds with the rows' values and multipliers."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from slew_problems import slew_problem

import gmuk
from gmuk.lie import so3
from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.optimize.problem import _Transcription
from gmuk.scenarios import smd


def _smd() -> tuple[OptimalControlProblem, Mesh]:
    system, state = smd.build("smd-bi")
    return OptimalControlProblem(system, state, 30.0), Mesh.uniform(0.0, 30.0, 5, 3)


def _slew() -> tuple[OptimalControlProblem, Mesh]:
    return slew_problem(), Mesh.uniform(0.0, 60.0, 3, 4)


def _two_bodies() -> tuple[OptimalControlProblem, Mesh]:
    """A rigid body and a point mass joined by a spring, a tilted plane bound on the rigid
    body (a row: not one variable), a bound along y on the point mass (a variable bound),
    a custom cost, two rigid final conditions."""
    a = gmuk.RigidBody("a", 3.0, np.diag([1.0, 2.0, 2.5]))
    b = gmuk.PointMass("b", 2.0)
    spring = gmuk.SpringDamper(a, [0.1, 0.0, 0.0], b, [0, 0, 0], stiffness=4.0, damping=0.3)
    tilted = gmuk.PlaneBound(a, [1.0, 1.0, 0.0], lower=-1.0, name="tilted")
    along_y = gmuk.PlaneBound(b, [0.0, -2.0, 0.0], upper=0.5, name="y")
    system = gmuk.System([a, b], [tilted, along_y], [spring])
    state = system.state(
        g={"a": np.eye(4)}, V={"a": np.zeros(6)}, r={"b": [1.0, 0.0, 0.0]}, v={"b": [0, 0, 0]}
    )
    gf = np.eye(4)
    gf[:3, :3] = so3.exp(np.array([0.0, 0.0, 0.6]))

    def cost(t, q, nu, u):
        return ca.sumsqr(u[0]) + 0.5 * ca.sumsqr(u[1]) + 0.1 * ca.sumsqr(nu[0])

    problem = OptimalControlProblem(
        system, state, 5.0, final={"g": {"a": gf}, "V": {"a": np.zeros(6)}}, cost=cost
    )
    return problem, Mesh.uniform(0.0, 5.0, 4, 3)


@pytest.mark.parametrize("make", [_smd, _slew, _two_bodies], ids=["smd", "slew", "two-bodies"])
def test_assembled_derivatives_equal_casadis_own(make):
    problem, mesh = make()
    tr = _Transcription(problem, mesh)
    assert tr.mapped and set(tr.derivatives) == {"grad_f", "jac_g", "hess_lag"}
    rng = np.random.default_rng(3)
    x = 0.1 * rng.normal(size=tr.n_x)
    _, p = tr._sample_point()
    lam_f, lam_g = 0.7, rng.normal(size=tr.g.shape[0])
    lam, sigma = ca.MX.sym("lam", tr.g.shape[0]), ca.MX.sym("sigma")
    lagrangian = sigma * tr.f + ca.dot(lam, tr.g)
    own = {
        "jac_g": ca.Function("j", [tr.x, tr.p], [tr.g, ca.jacobian(tr.g, tr.x)])(x, p),
        "grad_f": ca.Function("g", [tr.x, tr.p], [tr.f, ca.gradient(tr.f, tr.x)])(x, p),
        "hess_lag": [
            ca.Function("h", [tr.x, tr.p, sigma, lam], [ca.triu(ca.hessian(lagrangian, tr.x)[0])])(
                x, p, lam_f, lam_g
            )
        ],
    }
    for name, reference in own.items():
        args = (x, p, lam_f, lam_g) if name == "hess_lag" else (x, p)
        mine = tr.derivatives[name](*args)
        mine = mine if isinstance(mine, (list, tuple)) else [mine]
        for m, r in zip(mine, reference, strict=True):
            m, r = np.array(ca.DM(m)), np.array(ca.DM(r))
            scale = max(1.0, np.abs(r).max())
            assert np.abs(m - r).max() <= 1e-13 * scale, name


def test_a_bound_along_one_coordinate_becomes_a_variable_bound_with_the_rows_numbers(
    monkeypatch,
):
    problem, _ = _smd()
    mesh = Mesh.uniform(0.0, 30.0, 40, 3)
    tr = _Transcription(problem, mesh)
    assert list(tr.bounds) == [0]  # the PlaneBound on x: y_0 = x, a = 1, d = 0
    bounded = problem.solve(mesh)
    monkeypatch.setattr(_Transcription, "_simple_bounds", lambda self: {})
    rows = problem.solve(mesh)
    assert bounded.stats["n_constraints"] == rows.stats["n_constraints"] - (mesh.n_nodes - 1)
    assert bounded.objective == pytest.approx(rows.objective, rel=1e-10)
    b, r = bounded.path["x"], rows.path["x"]
    assert (b.lower, b.upper) == (r.lower, r.upper) == (1.0, 2.0)
    np.testing.assert_allclose(b.value, r.value, atol=1e-9)
    np.testing.assert_allclose(b.multiplier, r.multiplier, atol=1e-7 * np.abs(r.multiplier).max())
    kb, kr = bounded.kkt(), rows.kkt()
    for side in ("x.lower", "x.upper"):
        np.testing.assert_allclose(kb[side].mu, kr[side].mu, atol=1e-7 * kr[side].mu.max())


def test_only_an_inequality_on_one_variable_with_nothing_else_on_it_becomes_a_bound():
    problem, mesh = _two_bodies()
    tr = _Transcription(problem, mesh)
    # "y" (−y_b ≤ 0.5: PlaneBound normalises n) bounds the point mass's y; "tilted" (x + y
    # of a, over √2) is not one variable
    names = {problem._constraints[i][0].name: v for i, v in tr.bounds.items()}
    assert set(names) == {"y"}
    r, a, d = names["y"]
    assert (a, d) == (-1.0, 0.0)
    nodes = tr._path_nodes[[c.name for c, _, _ in problem._constraints].index("y")]
    assert np.all(tr.lbx[nodes * problem.n_y + r] == -0.5)
    assert np.all(np.isinf(tr.ubx[nodes * problem.n_y + r]))
