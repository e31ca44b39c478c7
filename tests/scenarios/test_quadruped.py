"""``gmuk run quadruped``: Solo12 landing on four exact contacts (slow: the contact solve and
the joints' springs run in Python at every evaluation)."""

from __future__ import annotations

import pytest

from gmuk.scenarios import get, quadruped


@pytest.mark.slow
def test_the_quadruped_lands_on_four_feet_with_kkt_to_round_off(tmp_path):
    result = quadruped.run(duration=0.05)
    s = result.summary
    assert result.trajectories["quadruped"].success
    assert s["impacts"] >= 1
    assert s["max_penetration_m"] <= 1e-9
    assert s["max_negative_multiplier_N"] == 0.0
    assert s["max_complementarity"] <= 1e-9
    assert all(f > 0.0 for f in s["foot_forces_end_N"])  # standing on all four feet
    paths = get("quadruped").figures(result, tmp_path, ("png",))
    assert [p.name for p in paths] == ["quadruped_contacts.png"]
