"""Force models (modeled and unmodeled) and controllers with internal states."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import Rows
from scipy.integrate import cumulative_simpson

import gmuk
from gmuk.lie import se3


def test_spring_between_point_masses_conserves_energy_and_damper_dissipates():
    p, q = gmuk.PointMass("p", 1.0), gmuk.PointMass("q", 2.0)
    for c, check in ((0.0, "conserve"), (0.5, "decay")):
        spring = gmuk.SpringDamper(
            p, np.zeros(3), q, np.zeros(3), stiffness=10.0, damping=c, rest_length=1.0
        )
        system = gmuk.System([p, q], forces=[spring])
        state = system.state(
            r={"p": [0, 0, 0], "q": [1.5, 0, 0]}, v={"p": [0, 0.1, 0], "q": [0, -0.05, 0]}
        )
        traj = system.simulate(state, (0.0, 10.0), rtol=1e-12, atol=1e-12)
        d = np.linalg.norm(traj.x[:, 3:] - traj.x[:, :3], axis=1)
        E = (
            0.5 * np.sum(traj.xdot[:, :3] ** 2, 1)
            + np.sum(traj.xdot[:, 3:] ** 2, 1)
            + 5.0 * (d - 1.0) ** 2
        )
        if check == "conserve":
            assert np.abs(E / E[0] - 1).max() < 1e-10
        else:
            assert E[-1] < 0.1 * E[0]
        momentum = traj.xdot[:, :3] + 2.0 * traj.xdot[:, 3:]
        assert np.abs(momentum - momentum[0]).max() < 1e-11


def test_spring_on_a_rigid_body_point_produces_the_lever_arm_torque():
    a = gmuk.RigidBody("a", 1.0, np.eye(3))
    spring = gmuk.SpringDamper(a, [0.0, 1.0, 0.0], None, [2.0, 1.0, 0.0], stiffness=3.0)
    system = gmuk.System([a], forces=[spring])
    state = system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)})
    (w,) = spring.wrenches(state, [a])
    assert np.allclose(w, [0, 0, -6.0, 6.0, 0, 0])  # f = 3·2 x̂ at p = ŷ: L = p × f = −6 ẑ


def test_inertial_applied_wrench_is_rotated_into_the_body_frame():
    a = gmuk.RigidBody("a", 2.0, np.eye(3))
    force = gmuk.AppliedWrench(a, [0, 0, 1.0, 1.0, 0, 0], frame="inertial")
    g = se3.exp(np.array([0, 0, np.pi / 2, 0, 0, 0]))
    w = force.wrench(0.0, g, np.zeros(6), a)
    assert np.allclose(w, [0, 0, 1.0, 0, -1.0, 0], atol=1e-15)


def test_unmodeled_force_acts_on_the_plant_but_not_on_the_constraint_solve():
    a = gmuk.RigidBody("a", 2.0, np.eye(3))
    kick = np.array([0, 0, 0, 4.0, 0, 0])
    locked = Rows([a], np.eye(6)[3:4], np.zeros(1))  # v̇₁ = 0
    modeled = gmuk.System([a], [locked], [gmuk.AppliedWrench(a, kick)])
    unmodeled = gmuk.System([a], [locked], [gmuk.AppliedWrench(a, kick, modeled=False)])
    state = modeled.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)})
    acc_m, acc_u = modeled.accelerations(state), unmodeled.accelerations(state)
    assert acc_m.total[3] == pytest.approx(0.0, abs=1e-15)  # the solve cancels a known force
    assert acc_u.total[3] == pytest.approx(2.0)  # a disturbance the solve did not see
    assert np.allclose(acc_u.unmodeled_force, kick)


class IntegralPD(gmuk.Controller):
    """Drives a point mass to the origin; z integrates the position error.

    Closed loop: s³ + 3s² + 3s + 1 = (s + 1)³ per axis.
    """

    def __init__(self, body):
        super().__init__([body], n_states=3)

    def control(self, state, z):
        r, v = state.position("p"), state.velocity("p")
        return [-3.0 * r - 3.0 * v - 1.0 * z], r


def test_controller_wrench_and_internal_state_are_integrated():
    p = gmuk.PointMass("p", 1.0)
    system = gmuk.System([p], controllers=[IntegralPD(p)])
    state = system.state(r={"p": [1.0, -2.0, 0.5]}, v={"p": np.zeros(3)})
    assert np.array_equal(state.z, np.zeros(3))
    traj = system.simulate(
        state, (0.0, 20.0), t_eval=np.linspace(0, 20, 2001), rtol=1e-11, atol=1e-12
    )
    r = traj.x
    assert np.abs(r[-1]).max() < 1e-5  # (s + 1)³: |r| ≲ 2 · 20² e⁻²⁰ / 2
    integral = cumulative_simpson(r, x=traj.t, axis=0, initial=0.0)
    assert np.abs(traj.z - integral).max() < 1e-8  # Simpson error on a 0.01 s grid: ~1e-10
    assert np.allclose(traj.control_force[0], [-3.0, 6.0, -1.5])
