"""The CasADi forms of gmuk's built-in parts agree with their numeric methods."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import gmuk
from gmuk.lie import so3
from gmuk.optimize import parts


def _random_state(rng):
    a = gmuk.RigidBody("a", 3.0, np.diag([1.0, 2.0, 2.5]))
    b = gmuk.PointMass("b", 2.0)
    c = gmuk.RigidBody("c", 5.0, np.diag([2.0, 2.0, 3.0]))
    g_a, g_c = np.eye(4), np.eye(4)
    g_a[:3, :3], g_a[:3, 3] = so3.exp(rng.normal(size=3)), rng.normal(size=3)
    g_c[:3, :3], g_c[:3, 3] = so3.exp(rng.normal(size=3)), rng.normal(size=3) + 3.0
    system = gmuk.System([a, b, c])
    state = system.state(
        g={"a": g_a, "c": g_c},
        V={"a": rng.normal(size=6), "c": rng.normal(size=6)},
        r={"b": rng.normal(size=3) + np.array([5.0, 0.0, 0.0])},
        v={"b": rng.normal(size=3)},
        t=0.7,
    )
    return (a, b, c), state


def _casadi_args(state, bodies):
    q = tuple(
        ca.DM(state.pose(x)) if x.kind == "rigid" else ca.DM(state.position(x)) for x in bodies
    )
    nu = tuple(
        ca.DM(state.twist(x)) if x.kind == "rigid" else ca.DM(state.velocity(x)) for x in bodies
    )
    return q, nu


@pytest.mark.parametrize(
    "make",
    [
        lambda a, b, c: gmuk.LinearSpringDamper(3.0, 0.4, anchor=[0.1, -0.2, 0.3]),
        lambda a, b, c: gmuk.UniformGravity(),
        lambda a, b, c: gmuk.PointMassGravity(3.986e14),
        lambda a, b, c: gmuk.AppliedWrench(
            a, lambda t: [t, 2.0, 3.0, -1.0, 0.5, t], frame="inertial"
        ),
        lambda a, b, c: gmuk.AppliedWrench(b, [1.0, 2.0, 3.0]),
        lambda a, b, c: gmuk.SpringDamper(
            a, [0.1, 0.2, 0.3], c, [-0.3, 0.0, 0.2], stiffness=4.0, damping=0.5, rest_length=0.5
        ),
        lambda a, b, c: gmuk.SpringDamper(
            b, [0.0, 0.0, 0.0], a, [0.2, 0.1, 0.0], stiffness=2.0, damping=0.3
        ),
        lambda a, b, c: gmuk.SpringDamper(c, [0.0, 0.1, 0.0], None, [1.0, 1.0, 1.0], stiffness=2.0),
    ],
)
def test_casadi_forms_equal_the_numeric_forces(make):
    rng = np.random.default_rng(7)
    bodies, state = _random_state(rng)
    model = make(*bodies)
    if model.bodies is None:
        targets = [x for x in bodies if x.kind in model.acts_on]
    else:
        names = [x if isinstance(x, str) else x.name for x in model.bodies]
        targets = [next(x for x in bodies if x.name == n) for n in names]
    numeric = model.wrenches(state, targets)
    q, nu = _casadi_args(state, targets)
    symbolic = parts.force_terms(model, state.t, q, nu, targets)
    for w_num, w_ca in zip(numeric, symbolic, strict=True):
        np.testing.assert_allclose(np.asarray(ca.DM(w_ca)).ravel(), w_num, rtol=1e-13, atol=1e-12)


def test_plane_and_tracking_bounds_equal_their_numeric_values():
    rng = np.random.default_rng(3)
    bodies, state = _random_state(rng)
    plane = gmuk.PlaneBound(bodies[0], [1.0, 2.0, -1.0], upper=10.0, name="plane")
    q, nu = _casadi_args(state, [bodies[0]])
    qn = (state.pose(bodies[0]),)
    num = plane.value(qn, (state.twist(bodies[0]),), state.t)
    assert float(parts.inequality_value(plane, q, nu, state.t)) == pytest.approx(num, rel=1e-14)


def test_a_coupled_spring_is_transcribed_and_its_plan_re_simulates():
    from gmuk.optimize import Mesh, OptimalControlProblem

    a, b = gmuk.PointMass("a", 1.0), gmuk.PointMass("b", 2.0)
    spring = gmuk.SpringDamper(
        a, [0, 0, 0], b, [0, 0, 0], stiffness=5.0, damping=0.2, rest_length=1.0
    )
    system = gmuk.System([a, b], forces=[spring])
    state = system.state(
        r={"a": [0.0, 0.0, 0.0], "b": [1.5, 0.0, 0.0]},
        v={"a": [0.0, 0.0, 0.0], "b": [0.0, 0.0, 0.0]},
    )
    final = {
        "r": {"a": [1.0, 0.5, 0.0], "b": [2.0, 0.5, 0.0]},
        "v": {"a": [0.0, 0.0, 0.0], "b": [0.0, 0.0, 0.0]},
    }
    result = OptimalControlProblem(system, state, 3.0, final=final).solve(
        Mesh.uniform(0.0, 3.0, 20, 4)
    )
    driven = gmuk.System([a, b], forces=[spring], controllers=[result.controller()])
    traj = driven.simulate(state, (0.0, 3.0), t_eval=result.t, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(traj.r_N, result.r_N, atol=1e-5)
