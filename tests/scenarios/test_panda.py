"""``gmuk run panda``: the Panda arm falling with damped joints, against Pinocchio's ABA."""

from __future__ import annotations

import numpy as np

from gmuk.scenarios import get, panda


def test_the_falling_panda_follows_pinocchio_and_only_loses_energy(tmp_path):
    result = panda.run(duration=0.6, damping=0.5)
    s = result.summary
    traj = result.trajectories["panda"]
    assert traj.success, traj.message
    assert s["pinocchio_max_q_difference_rad"] < 1e-8
    assert s["pinocchio_max_v_difference_rad_s"] < 1e-6
    assert s["energy_dissipated_J"] > 1.0
    assert s["energy_largest_increase_J"] == 0.0
    assert len(s["q_final_rad"]) == 7
    np.testing.assert_allclose(result.data["q"][0], panda.READY, atol=1e-12)
    paths = get("panda").figures(result, tmp_path, ("png",))
    assert [p.name for p in paths] == ["panda_joints.png"] and paths[0].stat().st_size > 10_000


def test_without_damping_the_energy_is_kept():
    result = panda.run(duration=0.3, damping=0.0)
    energy = result.data["energy"]
    assert np.abs(energy - energy[0]).max() < 1e-6 * max(1.0, abs(energy[0]))
