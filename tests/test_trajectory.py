"""Trajectory: per-body views, save/load, CSV."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import gmuk
from gmuk.errors import FileFormatError
from gmuk.lie import euler
from gmuk.trajectory import FORMAT_VERSION


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


def _rewrite(src, dst, *, meta_change=None, drop=(), replace=None):
    """A copy of the .npz ``src`` with its metadata edited, arrays dropped or replaced."""
    with np.load(src, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files if k not in drop}
    meta = json.loads(str(arrays["meta"]))
    if meta_change:
        meta_change(meta)
    arrays["meta"] = np.array(json.dumps(meta))
    arrays.update(replace or {})
    np.savez_compressed(dst, **arrays)
    return dst


def test_older_format_versions_load_and_newer_ones_are_refused(traj, tmp_path):
    path = traj.save(tmp_path / "run.npz")
    assert json.loads(str(np.load(path)["meta"]))["format_version"] == FORMAT_VERSION == 2

    def version(v):
        return lambda meta: meta.update(format_version=v)

    # version 1: written before the r_N / v_N copies
    v1 = _rewrite(path, tmp_path / "v1.npz", meta_change=version(1), drop=("r_N", "v_N"))
    back = gmuk.load_trajectory(v1)
    np.testing.assert_array_equal(back.r_N, traj.r_N)
    newer = _rewrite(path, tmp_path / "v3.npz", meta_change=version(3))
    with pytest.raises(FileFormatError, match="format version 3 was written by a newer gmuk"):
        gmuk.load_trajectory(newer)
    for bad in (0, "2", None, 1.5):
        odd = _rewrite(path, tmp_path / "odd.npz", meta_change=version(bad))
        with pytest.raises(FileFormatError, match="format_version must be a positive integer"):
            gmuk.load_trajectory(odd)


def test_corrupted_truncated_or_edited_files_are_format_errors(traj, tmp_path):
    path = traj.save(tmp_path / "run.npz")
    raw = path.read_bytes()
    cases = {
        "truncated": raw[: len(raw) // 2],
        "empty": b"",
        "flipped": raw[:200] + bytes(b ^ 0xFF for b in raw[200:400]) + raw[400:],
    }
    for name, content in cases.items():
        p = tmp_path / f"{name}.npz"
        p.write_bytes(content)
        with pytest.raises(FileFormatError, match=re.escape(str(p))):
            gmuk.load_trajectory(p)
    edits = {
        "no body names": dict(meta_change=lambda m: m.pop("body_names")),
        "wrong body dofs": dict(meta_change=lambda m: m.update(body_dofs=[6, 4])),
        "meta not an object": dict(meta_change=lambda m: m.clear()),
        "short array": dict(replace={"V_B": np.zeros((3, 1, 6))}),
        "missing array": dict(drop=("residual",)),
    }
    for name, how in edits.items():
        p = _rewrite(path, tmp_path / "edited.npz", **how)
        with pytest.raises(
            FileFormatError, match=re.escape(str(p))
        ):  # every message names the file
            gmuk.load_trajectory(p)
        assert name
    with pytest.raises(FileFormatError, match="no such file"):
        gmuk.load_trajectory(tmp_path / "absent.npz")
    with pytest.raises(FileFormatError, match="not a regular file"):
        gmuk.load_trajectory(tmp_path)
    with pytest.raises(FileFormatError, match=r"path must be a str or os\.PathLike"):
        gmuk.load_trajectory(None)


def test_saved_files_get_the_permissions_open_would_give(traj, tmp_path):
    import os

    mask = os.umask(0o022)
    os.umask(mask)
    path = traj.save(tmp_path / "perm.npz")
    assert path.stat().st_mode & 0o777 == 0o666 & ~mask
