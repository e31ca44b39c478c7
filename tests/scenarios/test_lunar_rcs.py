"""``gmuk run lunar-rcs`` (issue #29, item 7): FCCL's ideal wrench flown on twelve RCS
thrusters through the Moon's shadow (gmuk/scenarios/lunar_rcs.py)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from gmuk.environment import EclipseEvent, Epoch
from gmuk.scenarios import ScenarioResult, lunar_rcs


@pytest.fixture(scope="module")
def result() -> ScenarioResult:
    return lunar_rcs.run(duration=240.0)


def test_thrusters_bring_the_attitude_onto_the_reference_within_every_limit(
    result: ScenarioResult,
) -> None:
    s = result.summary
    assert s["on_times_whole_quanta"] and s["no_firing_below_minimum_impulse_bit"]
    assert s["thrusts_all_or_nothing"]
    rot = result.data["attitude_error"]
    assert rot[0] == pytest.approx(np.linalg.norm(lunar_rcs.ROTATION_OFFSET), rel=1e-6)
    t = result.trajectories[result.primary].t
    # from 0.0327 rad to the thrusters' dead band (minimum impulse bit and quantum): < 6 mrad
    assert rot[t >= 20.0].max() < 6e-3
    # the position error, under the law's slow translational gains, shrinks
    pos = result.data["position_error"]
    assert pos[-1] < pos[0]
    # the commands stay within what twelve 445 N thrusters on 2 m arms can give
    assert s["largest_commanded_force_N"] < 2 * lunar_rcs.MAX_THRUST
    assert s["largest_commanded_torque_Nm"] < 4 * lunar_rcs.ARM * lunar_rcs.MAX_THRUST


def test_propellant_is_what_the_firings_spend(result: ScenarioResult) -> None:
    traj = result.trajectories[result.primary]
    on = np.array(traj.stats["firings"]["on_times"])
    spent = float(np.sum(on @ result.data["thrusters"].mass_flow))
    # m ≈ 7063 kg carried through ~10⁴ steps: round-off of ε·m per step, ~1e-11 kg in all
    assert result.summary["propellant_kg"] == pytest.approx(spent, rel=0, abs=1e-9)
    assert traj.z[0, 0] - traj.z[-1, 0] == pytest.approx(spent, rel=0, abs=1e-9)
    assert np.all(np.diff(traj.z[:, 0]) <= 0.0)


def test_umbra_entry_is_where_the_shadow_margin_crosses_zero(result: ScenarioResult) -> None:
    traj = result.trajectories[result.primary]
    entry = [e for e in traj.events if e.name == "moon umbra"]
    assert len(entry) == 1
    t_e = entry[0].t
    assert result.summary["eclipse_entry_s"] == t_e
    assert 200.0 < t_e < 240.0
    ev = EclipseEvent("spacecraft", Epoch.from_iso(lunar_rcs.EPOCH), "moon", centre="moon")
    r = entry[0].state.pose("spacecraft")[:3, 3]
    v = entry[0].state.pose("spacecraft")[:3, :3] @ entry[0].state.twist("spacecraft")[3:]
    # the margin (rad) is zero at the event; it changes at ~4e-4 rad/s here, so a margin of
    # 1e-13 rad is a time error of ~3e-10 s
    assert abs(ev.margin(t_e, r)) < 1e-13
    rate = (ev.margin(t_e + 1e-3, r + 1e-3 * v) - ev.margin(t_e - 1e-3, r - 1e-3 * v)) / 2e-3
    assert rate < 0.0  # entering: the margin falls


def test_command_line_writes_the_summary_and_figures(tmp_path) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "rcs"
    cmd = [sys.executable, "-m", "gmuk.cli", "run", "lunar-rcs", "--duration", "10"]
    subprocess.run([*cmd, "--out", str(out)], check=True, capture_output=True)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["options"] == {"duration": 10.0, "period": 0.5, "max_thrust": 445.0}
    assert summary["eclipse_entry_s"] is None  # the shadow is 220 s away
    assert {p.name for p in out.glob("*.png")} >= {"tracking.png", "on_times.png"}
