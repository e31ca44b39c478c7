"""System.accelerations against Pinocchio's constrained forward dynamics (issue #3).

For n free-flying rigid bodies and random full-row-rank rows A ν̇ = b, gmuk's UK solution
(McCann 2020, Eq. 64) must equal ``pin.forwardDynamics(model, data, q, v, τ, J, γ)``, which
solves ``[M Jᵀ; J 0][a; −λ] = [τ − h; −γ]``: so J = A (columns reordered) and γ = −b; the
multipliers of Eq. 3 equal ``data.lambda_c`` (docs/errata.rst).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import gmuk
from gmuk.lie import se3

from .pin_helpers import q_from_g, swap_vec


def _model(bodies):
    model = pin.Model()
    model.gravity = pin.Motion.Zero()
    for i, body in enumerate(bodies):
        j = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), f"ff{i}")
        model.appendBodyToJoint(
            j, pin.Inertia(body.mass, np.zeros(3), body.inertia), pin.SE3.Identity()
        )
    return model, model.createData()


class Rows(gmuk.Constraint):
    def __init__(self, bodies, A, b):
        super().__init__(bodies)
        self.A, self.b = A, b

    def rows(self, state):
        return self.A, self.b


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_uk_equals_pinocchio_constrained_forward_dynamics(n):
    rng = np.random.default_rng(40 + n)
    worst_a = worst_l = 0.0
    for _ in range(40):
        bodies = []
        for i in range(n):
            Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
            bodies.append(
                gmuk.RigidBody(f"b{i}", rng.uniform(1, 5), Q @ np.diag(rng.uniform(1, 2, 3)) @ Q.T)
            )
        s = int(rng.integers(1, 6 * n))
        A, b = rng.normal(size=(s, 6 * n)), rng.normal(size=s)
        system = gmuk.System(bodies, [Rows(bodies, A, b)])
        g = [se3.exp(rng.normal(size=6)) for _ in range(n)]
        V = rng.normal(size=(n, 6))
        state = system.state(
            g={bd.name: gi for bd, gi in zip(bodies, g, strict=True)},
            V={bd.name: Vi for bd, Vi in zip(bodies, V, strict=True)},
        )
        acc = system.accelerations(state)

        model, data = _model(bodies)
        q = np.concatenate([q_from_g(gi) for gi in g])
        v = swap_vec(V).ravel()
        J = swap_vec(A.reshape(s, n, 6)).reshape(s, 6 * n)
        ddq = pin.forwardDynamics(model, data, q, v, np.zeros(6 * n), J, -b)
        a_pin = swap_vec(np.asarray(ddq).reshape(n, 6)).ravel()
        worst_a = max(worst_a, np.abs(acc.total - a_pin).max() / np.abs(a_pin).max())
        worst_l = max(
            worst_l, np.abs(acc.multipliers - data.lambda_c).max() / np.abs(data.lambda_c).max()
        )
    assert worst_a <= 1e-10
    assert worst_l <= 1e-10
