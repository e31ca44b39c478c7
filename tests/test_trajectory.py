"""Trajectory: per-body views, save/load, CSV."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.errors import FileFormatError
from gmuk.lie import euler


@pytest.fixture(scope="module")
def traj():
    a = gmuk.RigidBody("a", 2.0, np.diag([1.0, 2.0, 3.0]))
    p = gmuk.PointMass("p", 1.0)
    system = gmuk.System([a, p], forces=[gmuk.UniformGravity(bodies=[p])])
    state = system.state(
        g={"a": np.eye(4)},
        V={"a": [0.1, 0.2, 0.3, 1, 0, 0]},
        r={"p": [0, 0, 10.0]},
        v={"p": [1.0, 0, 0]},
    )
    return system.simulate(state, (0.0, 1.0), t_eval=np.linspace(0, 1, 11))


def test_body_views_give_positions_attitudes_and_rates(traj):
    a, p = traj.body("a"), traj.body("p")
    assert a.position.shape == (11, 3) and a.R.shape == (11, 3, 3)
    assert np.allclose(euler.to_matrix(a.euler("321"), "321"), a.R, atol=1e-14)
    assert np.allclose(a.omega, traj.V_B[:, 0, :3])
    t = traj.t
    assert np.allclose(p.position[:, 2], 10.0 - 0.5 * 9.80665 * t**2, atol=1e-9)
    assert np.allclose(p.position[:, 0], t, atol=1e-12)
    with pytest.raises(gmuk.errors.DefinitionError, match="not a rigid body"):
        _ = p.R
    with pytest.raises(gmuk.errors.DefinitionError, match="no body named"):
        traj.body("zz")


def test_save_and_load_round_trip(traj, tmp_path):
    path = traj.save(tmp_path / "run.npz")
    back = gmuk.load_trajectory(path)
    for name in (
        "t",
        "g_NB",
        "V_B",
        "x",
        "xdot",
        "acceleration",
        "constraint_force",
        "multipliers",
        "residual",
        "rank",
    ):
        assert np.array_equal(getattr(back, name), getattr(traj, name)), name
    assert back.body_names == ("a", "p") and back.status == "success"
    assert back.stats == traj.stats


def test_load_rejects_files_that_are_not_trajectories(tmp_path):
    bad = tmp_path / "x.npz"
    np.savez(bad, t=np.zeros(3))
    with pytest.raises(FileFormatError, match="not a gmuk trajectory"):
        gmuk.load_trajectory(bad)
    (tmp_path / "y.npz").write_text("garbage")
    with pytest.raises(FileFormatError):
        gmuk.load_trajectory(tmp_path / "y.npz")


def test_csv_export_has_labelled_columns(traj, tmp_path):
    path = traj.to_csv(tmp_path / "run.csv")
    header = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert header[0] == "t_s" and "a.psi_rad" in header and "p.vz_m_s" in header
    assert data.shape == (11, len(header))


def test_a_save_stopped_midway_leaves_the_previous_file_and_no_partial_one(
    traj, tmp_path, monkeypatch
):
    path = traj.save(tmp_path / "run.npz")
    before = path.read_bytes()

    def stopped(fh, **arrays):  # writes part of the archive, then the user presses Ctrl-C
        fh.write(b"PK\x03\x04 half an archive")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez_compressed", stopped)
    with pytest.raises(KeyboardInterrupt):
        traj.save(path)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]
    assert gmuk.load_trajectory(path).t.shape == traj.t.shape


def test_save_adds_the_npz_suffix_and_writes_no_temporary_file(traj, tmp_path):
    path = traj.save(tmp_path / "run")
    assert path.name == "run.npz"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]
    assert np.array_equal(gmuk.load_trajectory(path).t, traj.t)
