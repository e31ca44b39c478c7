"""Extending gmuk from outside the package (docs/extending.rst): a constraint kind, a force
model, a solve strategy, an integrator method and a scenario, each defined here and used
through gmuk's public entry points with no change to gmuk itself.

The example is a spherical pendulum: a point mass held at distance ℓ from the origin of N by
a constraint kind that acts on point masses only, under uniform gravity and a linear drag of
our own, integrated by a Runge–Kutta method of our own, and run as a scenario by ``gmuk run``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import gmuk
from gmuk import cli, scenarios
from gmuk.engine import solvers
from gmuk.engine.integrators import RungeKuttaMethod
from gmuk.scenarios import Option, Scenario, ScenarioResult

# --- a constraint kind ---


class DistanceFromOrigin(gmuk.Constraint):
    """|r_N| = ℓ for a point mass: Φ = (r·r − ℓ²)/2, so Φ̈ = r·r̈ + v·v = 0 gives A = rᵀ,
    b = −v·v, plus Baumgarte terms −α r·v − β Φ."""

    body_kinds = frozenset({gmuk.BodyKind.POINT})

    def __init__(self, body, length, alpha=0.0, beta=0.0):
        super().__init__([body])
        self.length, self.alpha, self.beta = float(length), float(alpha), float(beta)

    def rows(self, state):
        (body,) = self.bodies
        r, v = state.position(body), state.velocity(body)
        phi = 0.5 * (r @ r - self.length**2)
        return r[None, :], np.array([-(v @ v) - self.alpha * (r @ v) - self.beta * phi])


# --- a force model ---


class LinearDrag(gmuk.ForceModel):
    """f = −c v (N) on point masses, the same in the body frame on rigid bodies."""

    def __init__(self, c, **kw):
        super().__init__(**kw)
        self.c = float(c)

    def wrench(self, t, g_NB, V_B, body):
        return np.concatenate([np.zeros(3), -self.c * V_B[3:]])

    def force(self, t, r_N, v_N, body):
        return -self.c * v_N


# --- a solve strategy ---


class CountingDense(solvers.DenseSolver):
    """The dense solve, counting its calls."""

    name = "test-counting-dense"
    calls = 0

    def solve(self, state, a, rows=None):
        type(self).calls += 1
        return super().solve(state, a, rows)


# --- an integrator method ---


class Ralston3(RungeKuttaMethod):
    """Ralston's third-order method (fixed step): minimum error bound among 3-stage RK3."""

    name = "test-ralston3"
    A = ((0, 0, 0), (1 / 2, 0, 0), (0, 3 / 4, 0))
    b = (2 / 9, 1 / 3, 4 / 9)
    c = (0, 1 / 2, 3 / 4)
    order = 3


# --- a scenario ---


def pendulum_system(length, drag, solver=None):
    bob = gmuk.PointMass("bob", 2.0)
    parts = dict(
        constraints=[DistanceFromOrigin(bob, length, alpha=2.0, beta=1.0)],
        forces=[gmuk.UniformGravity([0.0, 0.0, -9.81]), LinearDrag(drag)],
    )
    system = gmuk.System([bob], **parts, **({} if solver is None else {"solver": solver}))
    # On the sphere, moving along it: r·v = 0.
    r0 = length * np.array([np.sin(0.5), 0.0, -np.cos(0.5)])
    v0 = np.array([0.0, 1.0, 0.0])
    return system, system.state(r={"bob": r0}, v={"bob": v0})


def pendulum_run(length: float = 1.5, drag: float = 0.3, duration: float = 4.0) -> ScenarioResult:
    system, state = pendulum_system(length, drag, solver="test-counting-dense")
    traj = system.simulate(
        state,
        (0.0, duration),
        t_eval=np.linspace(0.0, duration, 81),
        method="test-ralston3",
        step=1e-3,
    )
    r = traj.x.reshape(len(traj.t), 3)
    summary = {"max_length_error_m": float(np.abs(np.linalg.norm(r, axis=1) - length).max())}
    return ScenarioResult("pendulum", {"pendulum": traj}, "pendulum", summary)


def pendulum_figures(result, out: Path, formats):
    return []


PENDULUM = Scenario(
    "test-pendulum",
    "a spherical pendulum built from parts defined outside gmuk",
    pendulum_run,
    pendulum_figures,
    options=(
        Option("length", scenarios.positive_float, 1.5, "rod length ℓ (m)"),
        Option("drag", float, 0.3, "linear drag coefficient (N·s/m)"),
        Option("duration", scenarios.positive_float, 4.0, "simulated time (s)"),
    ),
)


@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(scenarios.SCENARIOS, "test-pendulum", f"{__name__}:PENDULUM")
    scenarios.refresh()
    yield
    scenarios.refresh()


def test_parts_defined_outside_gmuk_compose_and_run_as_a_scenario(registered, tmp_path):
    CountingDense.calls = 0
    out = tmp_path / "pendulum"
    argv = ["run", "test-pendulum", "--length", "2", "--drag", "0.5", "--out", str(out)]
    assert cli.main([*argv, "--no-plots"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["options"] == {"length": 2.0, "drag": 0.5, "duration": 4.0}
    # Ralston's method at h = 1 ms holds the Baumgarte-stabilised sphere to round-off level.
    assert summary["max_length_error_m"] < 1e-8
    assert CountingDense.calls >= 3 * 4000  # three stages per step, every step
    traj = gmuk.load_trajectory(out / "trajectory.npz")
    assert traj.stats["method"] == "test-ralston3"


def test_the_user_method_converges_at_its_order():
    """The end point of the pendulum converges as h³ under the user's method."""
    system, state = pendulum_system(1.5, 0.3)
    ref = system.simulate(state, (0.0, 1.0), method="DOP853", rtol=1e-13, atol=1e-13)
    errs = []
    for h in (0.02, 0.01, 0.005):
        traj = system.simulate(state, (0.0, 1.0), method="test-ralston3", step=h)
        errs.append(np.abs(traj.x[-1] - ref.x[-1]).max())
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 3.0) < 0.3), orders


def test_the_user_constraint_kind_declares_point_masses_only():
    rigid = gmuk.RigidBody("a", 1.0, np.eye(3))
    with pytest.raises(gmuk.errors.DefinitionError, match="acts on point bodies"):
        gmuk.System([rigid], [DistanceFromOrigin(rigid, 1.0)])


def test_the_user_force_model_acts_on_both_kinds_by_the_methods_it_implements():
    assert LinearDrag.acts_on == {gmuk.BodyKind.RIGID, gmuk.BodyKind.POINT}
    assert solvers.SOLVERS["test-counting-dense"] is CountingDense
