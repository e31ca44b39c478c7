"""Lie-group integrator (RKMK): invariants, convergence order, group membership, outputs."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.dynamics import kinetic_energy, spatial_momentum
from gmuk.lie import se3

J = np.diag([1.0, 2.0, 3.0])


def free_body(V0=(0.3, 1.0, 0.2, 0.02, -0.01, 0.03)):
    body = gmuk.RigidBody("a", 2.0, J)
    system = gmuk.System([body])
    return system, system.state(g={"a": np.eye(4)}, V={"a": np.array(V0)})


def invariants_drift(traj, system):
    I = system.mass_matrix
    E = kinetic_energy(traj.V_B[:, 0], I)
    h = spatial_momentum(traj.g_NB[:, 0], traj.V_B[:, 0], I)
    return np.abs(E / E[0] - 1).max(), np.abs(h - h[0]).max() / np.linalg.norm(h[0])


def test_torque_free_body_conserves_energy_and_momentum_over_100_periods():
    system, state = free_body()
    period = 2 * np.pi / np.linalg.norm(state.V[0, :3])
    traj = system.simulate(state, (0.0, 100 * period), rtol=1e-14, atol=1e-14)
    dE, dh = invariants_drift(traj, system)
    # Drift is proportional to the tolerance and grows linearly: 9e-12 here, 9e-11 at 1000.
    assert dE < 1e-10 and dh < 1e-10
    R = traj.g_NB[:, 0, :3, :3]
    assert np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max() <= 1e-13


@pytest.mark.slow
def test_torque_free_body_conserves_energy_and_momentum_over_1000_periods():
    system, state = free_body()
    period = 2 * np.pi / np.linalg.norm(state.V[0, :3])
    traj = system.simulate(state, (0.0, 1000 * period), rtol=1e-14, atol=1e-14)
    dE, dh = invariants_drift(traj, system)
    assert dE < 1e-10 and dh < 1e-10
    R = traj.g_NB[:, 0, :3, :3]
    assert np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max() <= 1e-13


def _end_error(method, h, system, state, ref):
    kw = (
        {"step": h}
        if method == "RK4"
        else {"first_step": h, "max_step": h, "rtol": 1.0, "atol": 1.0}
    )
    traj = system.simulate(state, (0.0, 4.0), method=method, t_eval=[4.0], **kw)
    return np.abs(se3.log(se3.inverse(ref) @ traj.g_NB[-1, 0])).max()


@pytest.mark.parametrize(
    ("method", "order", "steps"),
    [("RK4", 4, (0.2, 0.1)), ("DOPRI5", 5, (0.4, 0.2)), ("DOP853", 8, (0.5, 0.25))],
)
def test_convergence_order_on_se3(method, order, steps):
    system, state = free_body((0.9, 2.0, 0.4, 1.0, -0.5, 0.3))
    ref = system.simulate(state, (0.0, 4.0), t_eval=[4.0], rtol=1e-14, atol=1e-14).g_NB[-1, 0]
    e1, e2 = (_end_error(method, h, system, state, ref) for h in steps)
    observed = np.log2(e1 / e2)
    assert observed == pytest.approx(order, abs=0.35), (e1, e2)


def test_dense_output_agrees_with_stepping_onto_output_times():
    system, state = free_body((0.9, 2.0, 0.4, 1.0, -0.5, 0.3))
    t = np.linspace(0.0, 5.0, 37)
    dense = system.simulate(state, (0.0, 5.0), t_eval=t, rtol=1e-12, atol=1e-12)
    stepped = system.simulate(state, (0.0, 5.0), t_eval=t, method="DOPRI5", rtol=1e-13, atol=1e-13)
    assert np.array_equal(dense.t, t)
    assert np.abs(dense.g_NB - stepped.g_NB).max() < 1e-10
    assert np.abs(dense.V_B - stepped.V_B).max() < 1e-10
    assert dense.stats["n_rhs"] < stepped.stats["n_rhs"]


def test_simulate_rejects_bad_arguments():
    system, state = free_body()
    with pytest.raises(gmuk.errors.DefinitionError, match="t_span"):
        system.simulate(state, (1.0, 0.0))
    with pytest.raises(gmuk.errors.DefinitionError, match="t_eval"):
        system.simulate(state, (0.0, 1.0), t_eval=[0.5, 0.2])
    with pytest.raises(gmuk.errors.DefinitionError, match="step"):
        system.simulate(state, (0.0, 1.0), method="RK4")
    with pytest.raises(gmuk.errors.DefinitionError, match="method"):
        system.simulate(state, (0.0, 1.0), method="Euler")


def test_progress_bar_appears_on_request_and_not_otherwise(capsys):
    system, state = free_body()
    system.simulate(state, (0.0, 2.0), progress=True)
    assert "s(sim)" in capsys.readouterr().err
    system.simulate(state, (0.0, 2.0), progress=False)
    system.simulate(state, (0.0, 2.0))  # default: only on a terminal, and captured is not one
    assert capsys.readouterr().err == ""
