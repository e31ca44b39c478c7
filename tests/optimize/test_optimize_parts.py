"""The CasADi forms of gmuk's built-in parts agree with their numeric methods."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import gmuk
from gmuk.errors import DefinitionError
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
        lambda a, b, c: gmuk.GravityGradient(3.986e14),
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


# --- forms declared on the class, and who inherits them (gmuk._forms) ---


def _spring_case():
    rng = np.random.default_rng(11)
    bodies, state = _random_state(rng)
    targets = [bodies[1], bodies[0]]  # a point mass and a rigid body
    q, nu = _casadi_args(state, targets)
    return state, targets, q, nu


def test_a_subclass_that_keeps_the_physics_inherits_the_casadi_form():
    class Renamed(gmuk.LinearSpringDamper):
        def __init__(self, k, c):
            super().__init__(k, c, anchor=[0.3, 0.0, -0.1], name="renamed")

    state, targets, q, nu = _spring_case()
    model = Renamed(2.0, 0.3)
    symbolic = parts.force_terms(model, state.t, q, nu, targets)
    for w_num, w_ca in zip(model.wrenches(state, targets), symbolic, strict=True):
        np.testing.assert_allclose(np.asarray(ca.DM(w_ca)).ravel(), w_num, rtol=1e-13, atol=1e-12)


def test_a_subclass_that_changes_the_physics_does_not_inherit_the_casadi_form():
    class Stiffer(gmuk.LinearSpringDamper):
        def force(self, t, r_N, v_N, body):
            return 2.0 * super().force(t, r_N, v_N, body)

    state, targets, q, nu = _spring_case()
    with pytest.raises(DefinitionError, match=r"Stiffer overrides a numeric method of Linear"):
        parts.force_terms(Stiffer(2.0, 0.3), state.t, q, nu, targets)

    class StifferWithItsForm(Stiffer):
        def casadi_force(self, t, r_N, v_N, body):
            return 2.0 * gmuk.LinearSpringDamper.casadi_force(self, t, r_N, v_N, body)

    model = StifferWithItsForm(2.0, 0.3)
    (w_ca,) = parts.force_terms(model, state.t, q[:1], nu[:1], targets[:1])
    (w_num,) = model.wrenches(state, targets[:1])
    np.testing.assert_allclose(np.asarray(ca.DM(w_ca)).ravel(), w_num, rtol=1e-13)
    # its wrench() is still the parent's, but the parent's casadi_wrench is not inherited:
    # the class changed force(), and gmuk cannot tell which of the parent's forms still hold
    with pytest.raises(DefinitionError, match="rigid body 'a'"):
        parts.force_terms(model, state.t, q[1:], nu[1:], targets[1:])


def test_an_inequality_that_changes_its_value_falls_back_to_the_generic_path():
    class Shifted(gmuk.PlaneBound):
        def value(self, q, nu, t):  # written with operations CasADi supports
            n, r = self.normal, q[0][:3, 3]
            return n[0] * r[0] + n[1] * r[1] + n[2] * r[2] + 1.0

    rng = np.random.default_rng(5)
    bodies, state = _random_state(rng)
    bound = Shifted(bodies[0], [1.0, 2.0, -1.0], upper=10.0, name="shifted")
    q, nu = _casadi_args(state, [bodies[0]])
    num = bound.value((state.pose(bodies[0]),), (state.twist(bodies[0]),), state.t)
    assert bound._declared_form("casadi_value") is None
    assert float(parts.inequality_value(bound, q, nu, state.t)) == pytest.approx(num, rel=1e-14)


def test_a_form_registered_for_a_users_class_is_found_for_that_class_only():
    class Drag(gmuk.ForceModel):
        def __init__(self, c):
            super().__init__()
            self.c = c

        def force(self, t, r_N, v_N, body):
            return -self.c * v_N

    class HeavierDrag(Drag):
        pass

    @parts.register_casadi_form(Drag, "casadi_force")
    def _drag(model, t, r_N, v_N, body):
        return -model.c * v_N

    state, targets, q, nu = _spring_case()
    try:
        (f_ca,) = parts.force_terms(Drag(0.7), state.t, q[:1], nu[:1], targets[:1])
        (f_num,) = Drag(0.7).wrenches(state, targets[:1])
        np.testing.assert_allclose(np.asarray(ca.DM(f_ca)).ravel(), f_num, rtol=1e-15)
        with pytest.raises(DefinitionError, match="HeavierDrag"):
            parts.force_terms(HeavierDrag(0.7), state.t, q[:1], nu[:1], targets[:1])
    finally:
        del parts._FORMS[(Drag, "casadi_force")]
