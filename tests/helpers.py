"""Shared builders for the engine tests (not a test module)."""

from __future__ import annotations

import numpy as np

import gmuk
from gmuk import runs
from gmuk.lie import se3
from gmuk.reference import ReferenceState, ReferenceTrajectory


class Distance(gmuk.HolonomicConstraint):
    """|x_a − x_b|² = d² for body points p_a, p_b (m, body frames) of two rigid bodies: the
    quickstart's residual constraint, written by a user in a few lines."""

    def __init__(self, a, b, p_a, p_b, d, **kw):
        super().__init__([a, b], **kw)
        self.p_a, self.p_b, self.d = np.asarray(p_a), np.asarray(p_b), d

    def residual(self, q, t):
        g_a, g_b = q
        x_a = g_a[:3, :3] @ self.p_a + g_a[:3, 3]
        x_b = g_b[:3, :3] @ self.p_b + g_b[:3, 3]
        return np.array([(x_a - x_b) @ (x_a - x_b) - self.d**2])


class Rows(gmuk.Constraint):
    """The lowest-level user constraint of the issue's API: fixed rows."""

    def __init__(self, bodies, A, b):
        super().__init__(bodies)
        self.A, self.b = A, b

    def rows(self, state):
        return self.A, self.b


class Returns(gmuk.Constraint):
    """A user constraint on body "a" whose rows() returns whatever it is given."""

    def __init__(self, out):
        super().__init__(["a"])
        self.out = out

    def rows(self, state):
        return self.out


class ScrewReference(ReferenceTrajectory):
    """g_d(t) = g0 exp(t ξ): constant body twist V_d = ξ, V̇_d = 0 (closed form)."""

    def __init__(self, g0, xi):
        self.g0, self.xi = np.asarray(g0, float), np.asarray(xi, float)

    def evaluate(self, t):
        return ReferenceState(self.g0 @ se3.exp(t * self.xi), self.xi.copy(), np.zeros(6))


def random_inertia(rng):
    """A random physical central inertia tensor (kg·m²) in a random orientation."""
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    moments = rng.uniform(1.0, 2.0, 3)
    return Q @ np.diag(moments) @ Q.T


def random_rigid_bodies(rng, n, prefix="b"):
    return [
        gmuk.RigidBody(f"{prefix}{i}", rng.uniform(1.0, 5.0), random_inertia(rng)) for i in range(n)
    ]


def random_state(system, rng, scale=1.0):
    names = [b.name for b in system.bodies if b.kind == "rigid"]
    points = [b.name for b in system.bodies if b.kind == "point"]
    return system.state(
        g={n: se3.exp(rng.normal(size=6) * scale) for n in names},
        V={n: rng.normal(size=6) for n in names},
        r={n: rng.normal(size=3) for n in points},
        v={n: rng.normal(size=3) for n in points},
    )


def kkt_solve(M, a, A, b):
    """Solve [M Aᵀ; A 0][ν̇; μ] = [M a; b] (full row rank A)."""
    n, s = M.shape[0], A.shape[0]
    K = np.block([[M, A.T], [A, np.zeros((s, s))]])
    sol = np.linalg.solve(K, np.concatenate([M @ a, b]))
    return sol[:n], sol[n:]


class StopAt(gmuk.ForceModel):
    """No force; asks the enclosing run to stop once t passes ``t_stop``."""

    def __init__(self, t_stop):
        super().__init__()
        self.t_stop = t_stop

    def force(self, t, r_N, v_N, body):
        control = runs.current()
        if control is not None and t > self.t_stop:
            control.request_stop()
        return np.zeros(3)


#: Joint-space inertias above this condition number are left out of the comparisons with
#: pin.aba: there double precision itself fixes no more digits than the 1e-10 asked for
#: (both methods' own errors against a 50-digit solve reach 1e-9 on iCub at 1e10), and
#: tests/robots/test_singular_links.py holds gmuk to that solve instead.
ABA_COND_LIMIT = 1e8


def aba_random_state(model, rng):
    """Pinocchio q (within ±2 rad, seeded from ``rng``), v and τ (standard normal)."""
    import pinocchio as pin

    pin.seed(int(rng.integers(2**31)))  # Pinocchio's own generator, seeded from the test's
    q = pin.randomConfiguration(model, -2.0 * np.ones(model.nq), 2.0 * np.ones(model.nq))
    return q, rng.normal(size=model.nv), rng.normal(size=model.nv)


def joint_space_condition(model, data, q):
    """cond(M(q)) of Pinocchio's joint-space inertia."""
    import pinocchio as pin

    M = pin.crba(model, data, q)
    return float(np.linalg.cond(np.triu(M) + np.triu(M, 1).T))


def worst_aba_difference(robot, n, seed, cond_limit=ABA_COND_LIMIT):
    """max ‖q̈_gmuk − q̈_aba‖ / max(1, ‖q̈_aba‖) over n random states whose joint-space
    inertia has condition number ≤ ``cond_limit`` (drawn until n are kept)."""
    import pinocchio as pin

    model = robot.model
    data = model.createData()
    rng = np.random.default_rng(seed)
    worst, kept = 0.0, 0
    for _ in range(20 * n):
        q, v, tau = aba_random_state(model, rng)
        if joint_space_condition(model, data, q) > cond_limit:
            continue
        expected = pin.aba(model, data, q, v, tau)
        got = robot.forward_dynamics(q, v, tau)
        worst = max(
            worst, float(np.linalg.norm(got - expected) / max(1.0, np.linalg.norm(expected)))
        )
        kept += 1
        if kept == n:
            return worst
    raise AssertionError(f"only {kept} of {20 * n} random states had cond(M) ≤ {cond_limit:g}")
