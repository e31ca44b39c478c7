"""The run-level constraint check (issue #25, item 11): a run whose constraint drifts past
``drift_tol`` says so (status "drifted", stats, a warning, summary.json and the exit status of
``gmuk run``), one that stays on its constraint does not, and the long Chapter 4 scenarios stay
on their constraint."""

from __future__ import annotations

import functools
import json
import warnings

import numpy as np
import pytest

import gmuk
from gmuk import cli
from gmuk.errors import DefinitionError, GmukWarning
from gmuk.trajectory import STATUSES, load_trajectory


class Wall(gmuk.HolonomicConstraint):
    """x = 0 for a point mass, with analytic rows whose bias is off by ``error`` (m/s²): the
    rows then push the mass off its constraint, φ = ½·error·t², as integration error
    would, only faster."""

    def __init__(self, body, error=0.0, baumgarte=None):
        super().__init__([body], baumgarte=baumgarte)
        self.error = error

    def residual(self, q, t):
        return np.array([q[0][0]])

    def jacobian(self, q, t):
        return np.array([[1.0, 0.0, 0.0]])

    def bias(self, q, nu, t):
        return np.array([self.error])

    def rate(self, q, nu, t):
        return np.array([nu[0][0]])


def _run(error, x0=0.0, baumgarte=None, **options):
    p = gmuk.PointMass("p", 2.0)
    system = gmuk.System([p], [Wall(p, error, baumgarte)], [gmuk.UniformGravity((0, 0, -1.0))])
    state = system.state(r={"p": [x0, 0.0, 0.0]}, v={"p": [0.0, 1.0, 0.0]})
    return system.simulate(state, (0.0, 2.0), t_eval=np.linspace(0.0, 2.0, 41), **options)


def test_a_run_that_drifts_past_the_tolerance_is_flagged():
    with pytest.warns(GmukWarning, match="drifted off"):
        traj = _run(1e-3)  # φ = 5e-4 t²: 2e-3 m at t = 2 s
    assert traj.status == "drifted" and not traj.success
    assert "Wall" in traj.message and "drift_tol = 1e-06" in traj.message
    check = traj.stats["constraint_violation"]
    assert traj.stats["drifted"] is True and check["drifted"] is True
    assert check["tolerance"] == 1e-6 and check["samples"] == 41
    assert check["position"] == pytest.approx(2e-3, rel=1e-6)
    assert check["velocity"] == pytest.approx(2e-3, rel=1e-6)
    (entry,) = check["constraints"]
    assert entry["name"] == "Wall" and entry["on_start"] is True and entry["drifted"]
    # φ = 5e-4 t² passes 1e-6 m after 0.045 s: the first output beyond is t = 0.05 s
    assert entry["t_drifted"] == pytest.approx(0.05)


def test_a_run_that_stays_on_its_constraint_is_not_flagged():
    with warnings.catch_warnings():
        warnings.simplefilter("error", GmukWarning)
        traj = _run(0.0)
    assert traj.status == "success" and traj.success and traj.message == ""
    check = traj.stats["constraint_violation"]
    assert traj.stats["drifted"] is False and check["drifted"] is False
    assert check["position"] <= 1e-12 and check["velocity"] <= 1e-12


def test_the_tolerance_is_an_option_and_none_only_records():
    traj = _run(1e-3, drift_tol=1e-2)  # 2e-3 m stays within 1e-2
    assert traj.status == "success" and traj.stats["constraint_violation"]["tolerance"] == 1e-2
    with warnings.catch_warnings():
        warnings.simplefilter("error", GmukWarning)
        traj = _run(1e-3, drift_tol=None)
    assert traj.status == "success" and traj.stats["drifted"] is False
    assert traj.stats["constraint_violation"]["position"] == pytest.approx(2e-3, rel=1e-6)
    for bad in (0.0, -1.0, "1e-6", True, float("nan")):
        with pytest.raises(DefinitionError, match="drift_tol"):
            _run(0.0, drift_tol=bad)


def test_a_run_that_starts_off_its_constraint_and_converges_is_not_flagged():
    gains = gmuk.Baumgarte.critical(5.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GmukWarning)
        traj = _run(0.0, x0=0.1, baumgarte=gains)
    (entry,) = traj.stats["constraint_violation"]["constraints"]
    assert traj.status == "success" and entry["on_start"] is False and not entry["drifted"]
    assert entry["initial_position"] == pytest.approx(0.1)
    assert abs(traj.x[-1, 0]) <= 1e-3  # brought back by the Baumgarte terms


def test_the_flag_round_trips_through_save_and_load(tmp_path):
    assert "drifted" in STATUSES
    with pytest.warns(GmukWarning):
        traj = _run(1e-3)
    back = load_trajectory(traj.save(tmp_path / "drifted.npz"))
    assert back.status == "drifted" and not back.success and back.message == traj.message
    assert back.stats["drifted"] is True
    assert back.stats["constraint_violation"] == traj.stats["constraint_violation"]
    # a file written before the check (no drift entries) still loads
    old = _run(0.0)
    stats = {k: v for k, v in old.stats.items() if k not in ("drifted", "constraint_violation")}
    older = gmuk.Trajectory(**{**old.__dict__, "stats": stats})
    assert load_trajectory(older.save(tmp_path / "older.npz")).success


def test_gmuk_run_reports_a_drifted_run_in_its_status_summary_and_exit_status(
    tmp_path, monkeypatch, capsys
):
    """FCEI without its Baumgarte terms (the thesis's bare Eq. 67 rows) drifts off its
    reference from the fourth orbit on."""
    from gmuk.scenarios import _lvlh

    bare = functools.partial(_lvlh.fully_constrained, baumgarte=None)
    monkeypatch.setattr(_lvlh, "fully_constrained", bare)
    out = tmp_path / "fcei"
    with pytest.warns(GmukWarning, match="drifted off"):
        code = cli.main(["run", "fcei", "--orbits", "4.5", "--out", str(out), "--no-plots"])
    assert code == cli.EXIT_DRIFTED == 3
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "drifted" and summary["drifted"] is True
    assert summary["runs_drifted"] == ["fcei"]
    check = summary["constraint_violation"]["fcei"]
    assert check["drifted"] is True and check["position"] > 1e-6
    assert "drifted off" in summary["message"]
    assert load_trajectory(out / "trajectory.npz").status == "drifted"
    assert not (out / ".checkpoints").exists()  # the run completed: checkpoints spent
    captured = capsys.readouterr()
    assert "status drifted" in captured.out and "drifted off" in captured.err


def test_twelve_fcei_orbits_stay_on_the_reference(tmp_path):
    """``gmuk run fcei --orbits 12`` ended π rad off its reference with status "success"
    before the scenario's Baumgarte terms; it now ends on it (measured 7.1e-14 rad and
    2.7e-7 m at most over the 12 orbits, 6.6 s)."""
    out = tmp_path / "fcei12"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        code = cli.main(["run", "fcei", "--orbits", "12", "--out", str(out), "--no-plots"])
    assert code == 0
    assert not [w for w in caught if "drift" in str(w.message)]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "success" and summary["drifted"] is False
    assert summary["max_attitude_error_rad"] <= 1e-12
    assert summary["max_position_error_m"] <= 1e-6
    assert summary["constraint_violation"]["fcei"]["position"] <= 1e-6
    traj = load_trajectory(out / "trajectory.npz")
    assert traj.success and traj.t[-1] == pytest.approx(12 * 22696.0, rel=1e-3)
