"""Nothing lost: failures and interruptions keep every computed step."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.errors import GmukWarning, SimulationError


class Faulty(gmuk.ForceModel):
    """A force that turns NaN (or raises) after ``t_fail``."""

    def __init__(self, t_fail, exc=None):
        super().__init__(["a"])
        self.t_fail, self.exc = t_fail, exc

    def wrench(self, t, g_NB, V_B, body):
        if t > self.t_fail:
            if self.exc is not None:
                raise self.exc
            return np.full(6, np.nan)
        return np.zeros(6)


def make(force):
    body = gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 3.0]))
    system = gmuk.System([body], forces=[force])
    return system, system.state(g={"a": np.eye(4)}, V={"a": [0.1, 0.2, 0.3, 1.0, 0.0, 0.0]})


def test_nan_failure_raises_with_the_trajectory_so_far():
    system, state = make(Faulty(2.0))
    with pytest.raises(SimulationError, match="non-finite") as info:
        system.simulate(state, (0.0, 5.0), t_eval=np.linspace(0, 5, 51))
    traj = info.value.trajectory
    assert traj.status == "failed" and "t = " in traj.message
    # Every output up to the last accepted step is kept (outputs inside the failing step
    # cannot be produced): a prefix of t_eval ending before the fault.
    assert traj.t[-1] <= 2.0 and len(traj) >= 5
    assert np.allclose(traj.t, np.linspace(0, 5, 51)[: len(traj)])


def test_failure_can_return_instead_of_raise():
    system, state = make(Faulty(1.0))
    traj = system.simulate(state, (0.0, 5.0), on_failure="return")
    assert traj.status == "failed" and not traj.success
    assert traj.t[-1] <= 1.0 and len(traj) > 2


def test_user_code_error_is_wrapped_and_chained():
    system, state = make(Faulty(1.0, exc=ZeroDivisionError("boom")))
    with pytest.raises(SimulationError, match="boom") as info:
        system.simulate(state, (0.0, 5.0))
    assert isinstance(info.value.__cause__, ZeroDivisionError)
    assert info.value.trajectory.t[-1] <= 1.0


def test_keyboard_interrupt_returns_the_trajectory_so_far():
    system, state = make(Faulty(1.5, exc=KeyboardInterrupt()))
    with pytest.warns(GmukWarning, match="interrupted"):
        traj = system.simulate(state, (0.0, 5.0), t_eval=np.linspace(0, 5, 11))
    assert traj.status == "interrupted"
    assert traj.t[-1] <= 1.5 and len(traj) >= 2
    assert np.allclose(traj.t, np.linspace(0, 5, 11)[: len(traj)])


def test_max_steps_failure_is_reported():
    system, state = make(Faulty(100.0))
    with pytest.raises(SimulationError, match="max_steps"):
        system.simulate(state, (0.0, 5.0), max_steps=3)
