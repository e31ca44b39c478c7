"""Stopping, checkpointing and resuming simulations (gmuk.runs)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import StopAt

import gmuk
from gmuk import runs
from gmuk.runs import CheckpointError


def _pendulum(extra=()):
    bob = gmuk.PointMass("bob", 0.4)
    system = gmuk.System(
        [bob],
        [gmuk.PlaneBound(bob, [0, 0, 1.0], lower=-1.0, name="floor")],
        [gmuk.UniformGravity(), gmuk.LinearSpringDamper(3.0, 0.1), *extra],
    )
    state = system.state(r={"bob": [1.0, 0.0, 0.0]}, v={"bob": [0.0, 1.0, 0.5]})
    return system, state


T_EVAL = np.linspace(0.0, 20.0, 401)


def _run(system, state, **kw):
    return system.simulate(state, (0.0, 20.0), t_eval=T_EVAL, rtol=1e-10, atol=1e-12, **kw)


def test_a_complete_checkpoint_is_returned_on_resume_without_integrating(tmp_path):
    system, state = _pendulum()
    with runs.run_control(tmp_path, every_s=1e-9):
        first = _run(system, state)
    assert first.success and (tmp_path / "run-0.npz").exists()
    saved = gmuk.load_trajectory(tmp_path / "run-0.npz")
    assert saved.stats["checkpoint"]["complete"] is True
    np.testing.assert_array_equal(saved.x, first.x)
    with runs.run_control(tmp_path, resume=True) as control:
        again = _run(system, state)
        assert control.calls == 1
    assert again.success and "checkpoint" not in again.stats
    np.testing.assert_array_equal(again.x, first.x)
    np.testing.assert_array_equal(again.multipliers, first.multipliers)


def test_a_stopped_run_resumes_to_the_uninterrupted_result(tmp_path):
    plain = _run(*_pendulum())
    stopping, state = _pendulum([StopAt(7.3)])
    with runs.run_control(tmp_path, every_s=3600.0):
        cut = _run(stopping, state)
    assert cut.status == "interrupted" and "stopped on request" in cut.message
    assert 7.3 < cut.t[-1] < 20.0
    record = gmuk.load_trajectory(tmp_path / "run-0.npz").stats["checkpoint"]
    assert record["complete"] is False and record["t"] >= cut.t[-1]
    system, state = _pendulum([StopAt(1e9)])  # the same simulation, no longer stopping
    with runs.run_control(tmp_path, resume=True):
        resumed = _run(system, state)
    assert resumed.success
    np.testing.assert_array_equal(resumed.t, plain.t)
    np.testing.assert_allclose(resumed.x, plain.x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(resumed.multipliers, plain.multipliers, rtol=1e-7, atol=1e-9)


def test_a_checkpoint_of_another_simulation_is_refused(tmp_path):
    system, state = _pendulum()
    with runs.run_control(tmp_path, every_s=1e-9):
        _run(system, state)
    other = state.replace(x=state.x + 1e-3)
    with runs.run_control(tmp_path, resume=True):
        with pytest.raises(CheckpointError, match="different simulation"):
            _run(system, other)
    (tmp_path / "run-0.npz").write_bytes(b"not a checkpoint")
    with runs.run_control(tmp_path, resume=True):
        with pytest.raises(CheckpointError, match="cannot resume"):
            _run(system, state)


def test_after_a_stop_request_later_simulations_return_at_once(tmp_path):
    system, state = _pendulum()
    with runs.run_control() as control:
        control.request_stop()
        traj = _run(system, state)
    assert traj.status == "interrupted" and len(traj) == 1 and traj.t[0] == 0.0
    assert traj.stats["n_rhs"] == 0


def test_run_control_arguments():
    with pytest.raises(gmuk.errors.DefinitionError, match="every_s must be a number > 0"):
        with runs.run_control(every_s=0.0):
            pass
    assert runs.current() is None
