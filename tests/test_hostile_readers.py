"""Readers under hostile input (issue #25, item 6; ``gmuk view --out DIR`` of item 12).

``load_trajectory`` / ``gmuk view`` and the gravity-field readers refuse, with a
:class:`gmuk.errors.FileFormatError` naming the file and what is wrong, every file gmuk did
not write or that was edited into nonsense, and they allocate nothing before the archive's
declared sizes and the array headers have been checked against each other and a budget.
"""

from __future__ import annotations

import io
import json
import re
import struct
import time
import tracemalloc
import zlib
from pathlib import Path

import numpy as np
import pytest

import gmuk
from gmuk.cli import main
from gmuk.errors import DefinitionError, FileFormatError
from gmuk.gravity import load_gfc, load_shadr
from gmuk.trajectory import load_trajectory

# ----------------------------------------------------------------------------- helpers


def _rotations(n: int, seed: int) -> np.ndarray:
    """n proper rotations (Rodrigues' formula of random rotation vectors)."""
    rng = np.random.default_rng(seed)
    out = np.empty((n, 3, 3))
    for i, w in enumerate(rng.normal(size=(n, 3))):
        th = np.linalg.norm(w)
        k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / th
        out[i] = np.eye(3) + np.sin(th) * k + (1 - np.cos(th)) * k @ k
    return out


def _trajectory(n: int = 6) -> gmuk.Trajectory:
    """A rigid body, a point mass and a slack coordinate, one controller state, two
    constraint rows: every array of a trajectory file is non-trivial."""
    rng = np.random.default_rng(1)
    g = np.zeros((n, 1, 4, 4))
    g[:, 0, :3, :3] = _rotations(n, 2)
    g[:, 0, :3, 3] = rng.normal(size=(n, 3)) * 1e6
    g[:, 0, 3, 3] = 1.0
    n_dof = 6 + 3 + 1

    def r(*shape: int) -> np.ndarray:
        return rng.normal(size=(n, *shape))

    return gmuk.Trajectory(
        t=np.linspace(0.0, 10.0, n),
        g_NB=g,
        V_B=r(1, 6),
        x=r(4),
        xdot=r(4),
        z=r(1),
        acceleration=r(n_dof),
        constraint_acceleration=r(n_dof),
        constraint_force=r(n_dof),
        control_force=r(n_dof),
        unmodeled_force=np.zeros((n, n_dof)),
        multipliers=r(2),
        residual=np.abs(r()) * 1e-14,
        rank=np.full(n, 2, dtype=np.int64),
        body_names=("box", "ball", "gap"),
        body_kinds=("rigid", "point", "slack"),
        body_dofs=(6, 3, 1),
        status="success",
        message="",
        stats={"n_rhs": 12, "n_steps": 2, "n_rejected": 0, "method": "dopri5", "rtol": 1e-10},
    )


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> Path:
    return _trajectory().save(tmp_path_factory.mktemp("hostile") / "run.npz")


def _members(path: Path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _meta(path: Path) -> dict:
    return json.loads(str(_members(path)["meta"]))


def _rewrite(saved: Path, out: Path, *, meta=None, **arrays) -> Path:
    """A copy of ``saved`` with members replaced (``meta`` a function editing the JSON)."""
    members = _members(saved)
    if meta is not None:
        m = json.loads(str(members["meta"]))
        meta(m)
        members["meta"] = np.array(json.dumps(m))
    members.update(arrays)
    np.savez_compressed(out, **members)
    return out


def _npy_bytes(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, array, allow_pickle=False)
    return buf.getvalue()


def _npy_header(shape: tuple[int, ...], descr: str = "<f8") -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buf, {"descr": descr, "fortran_order": False, "shape": shape}
    )
    return buf.getvalue()


def _zip(entries: list[tuple[str, bytes, int, int, int]]) -> bytes:
    """A zip archive written by hand: (name, payload, method, declared uncompressed size,
    crc) per member, so that the declared sizes can say what a hostile file says."""
    out = bytearray()
    central = bytearray()
    for name, payload, method, size, crc in entries:
        raw = name.encode()
        offset = len(out)
        out += struct.pack(
            "<IHHHHHIIIHH", 0x04034B50, 20, 0, method, 0, 0, crc, len(payload), size, len(raw), 0
        )
        out += raw + payload
        central += struct.pack(
            "<IHHHHHHIIIHHHHHII",
            0x02014B50,
            20,
            20,
            0,
            method,
            0,
            0,
            crc,
            len(payload),
            size,
            len(raw),
            0,
            0,
            0,
            0,
            0,
            offset,
        )
        central += raw
    cd_offset = len(out)
    out += central
    out += struct.pack(
        "<IHHHHIIH", 0x06054B50, 0, 0, len(entries), len(entries), len(central), cd_offset, 0
    )
    return bytes(out)


def _deflate(data: bytes) -> bytes:
    c = zlib.compressobj(6, zlib.DEFLATED, -15)
    return c.compress(data) + c.flush()


def _archive_with(saved: Path, name: str, payload: bytes, size: int, crc: int) -> bytes:
    """The members of ``saved``, deflated honestly, with member ``name`` replaced."""
    entries = []
    for key, array in _members(saved).items():
        data = _npy_bytes(array)
        entries.append((f"{key}.npy", _deflate(data), 8, len(data), zlib.crc32(data)))
    entries = [e for e in entries if e[0] != f"{name}.npy"]
    entries.append((f"{name}.npy", payload, 8, size, crc))
    return _zip(entries)


def _refused(path: Path, *fragments: str, **kw) -> str:
    with pytest.raises(FileFormatError) as info:
        load_trajectory(path, **kw)
    msg = str(info.value)
    assert str(path) in msg, msg
    for fragment in fragments:
        assert re.search(fragment, msg), (fragment, msg)
    return msg


# ------------------------------------------------------------- valid files still load


def test_a_valid_trajectory_still_loads_bit_identically(saved, tmp_path):
    original = _trajectory()
    ref = _members(saved)
    for path in (saved, tmp_path / "stored.npz"):
        if path != saved:  # np.savez (stored, not deflated) as another program might
            np.savez(path, **ref)
        back = load_trajectory(path)
        for name, array in ref.items():
            if name in ("meta",):
                continue
            got = getattr(back, name)
            assert got.dtype == array.dtype and got.shape == array.shape, name
            assert got.tobytes() == array.tobytes(), name
            assert np.array_equal(got, getattr(original, name)), name
        assert back.body_names == original.body_names
        assert back.body_dofs == original.body_dofs and back.stats == original.stats


def test_a_trajectory_of_no_outputs_yet_still_loads(tmp_path):
    t = _trajectory()
    empty = gmuk.Trajectory(
        **{k: getattr(t, k)[:0] for k in gmuk.trajectory._ARRAYS},
        body_names=t.body_names,
        body_kinds=t.body_kinds,
        body_dofs=t.body_dofs,
        status="interrupted",
    )
    assert len(load_trajectory(empty.save(tmp_path / "e.npz"))) == 0


# ------------------------------------------------------------ allocation and zip bombs


def test_a_npz_header_claiming_1e12_entries_is_refused_before_allocating(saved, tmp_path):
    header = _npy_header((10**12,))
    payload = header + b"\0" * (300 - len(header))  # a 300-byte member
    path = tmp_path / "claim.npz"
    path.write_bytes(
        _archive_with(saved, "t", _deflate(payload), len(payload), zlib.crc32(payload))
    )
    tracemalloc.start()
    try:
        _refused(path, "member 't.npy'", r"claims shape \(1000000000000,\)", "before allocating")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20 * 2**20


def test_a_member_declaring_more_than_deflate_can_give_is_refused_as_a_zip_bomb(saved, tmp_path):
    # the header and the declared size agree (3 GB), but 300 compressed bytes cannot hold it
    header = _npy_header((375_000_000,))
    path = tmp_path / "forged.npz"
    size = len(header) + 375_000_000 * 8
    path.write_bytes(_archive_with(saved, "V_B", _deflate(header) + b"\0" * 200, size, 0))
    _refused(path, "member 'V_B.npy'", "ratio above 1100", "zip bomb", "nothing was decompressed")


def test_a_zip_bomb_above_the_byte_budget_is_refused_before_decompressing(saved, tmp_path):
    # a genuine deflate stream of 2.4 GB of zeros (2.3 MB compressed, a ratio deflate can
    # give): the member's header says so, and the budget refuses it unread
    count = 300 * 2**20  # float64 entries: 2.4 GiB
    header = _npy_header((count,))
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    first = c.compress(header) + c.flush(zlib.Z_FULL_FLUSH)
    block = c.compress(b"\0" * 2**24) + c.flush(zlib.Z_FULL_FLUSH)
    payload = first + block * (count * 8 // 2**24) + c.flush()
    path = tmp_path / "bomb.npz"
    path.write_bytes(_archive_with(saved, "unmodeled_force", payload, len(header) + count * 8, 0))
    assert path.stat().st_size < 4 * 2**20
    start = time.perf_counter()
    tracemalloc.start()
    try:
        _refused(path, "more than the limit of 1073741824", "max_bytes", "nothing was decompressed")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20 * 2**20 and time.perf_counter() - start < 2.0
    assert gmuk.trajectory.MAX_BYTES == 2**30
    # a smaller budget refuses a valid file the same way; a large enough one reads it
    _refused(saved, "more than the limit of 1000", max_bytes=1000)
    assert len(load_trajectory(saved, max_bytes=10**6)) == 6
    for bad in (0, -1, True, 1.5, "1"):
        with pytest.raises(DefinitionError, match="max_bytes must be an integer > 0"):
            load_trajectory(saved, max_bytes=bad)


def test_a_member_with_a_compression_method_numpy_does_not_write_is_refused(saved, tmp_path):
    data = _npy_bytes(_members(saved)["t"])
    import bz2

    path = tmp_path / "bz2.npz"
    path.write_bytes(
        _zip(
            [
                (f"{k}.npy", _deflate(d), 8, len(d), zlib.crc32(d))
                for k, d in ((k, _npy_bytes(a)) for k, a in _members(saved).items())
                if k != "t"
            ]
            + [("t.npy", bz2.compress(data), 12, len(data), zlib.crc32(data))]
        )
    )
    _refused(path, "member 't.npy' uses zip compression method 12", "stored .0. or deflated .8.")


def test_a_member_whose_data_is_shorter_than_declared_is_a_format_error(saved, tmp_path):
    data = _npy_bytes(_members(saved)["residual"])
    path = tmp_path / "short.npz"
    path.write_bytes(_archive_with(saved, "residual", _deflate(data[:-8]), len(data), 0))
    _refused(path, "residual")


def test_a_member_with_a_wrong_crc_is_a_format_error(saved, tmp_path):
    data = _npy_bytes(_members(saved)["residual"])
    path = tmp_path / "crc.npz"
    path.write_bytes(_archive_with(saved, "residual", _deflate(data), len(data), 12345))
    _refused(path, "CRC|truncated or corrupted")


def test_a_npy_file_given_for_an_npz_is_a_clear_format_error(tmp_path):
    path = tmp_path / "t.npy"
    np.save(path, np.zeros(3))
    _refused(path, r"a \.npy file \(a single numpy array\), not a gmuk trajectory \.npz")
    text = tmp_path / "notes.npz"
    text.write_text("hello")
    _refused(text, "not a zip archive")


def test_object_complex_boolean_and_string_arrays_are_refused(saved, tmp_path):
    cases = {
        "V_B": np.zeros((6, 1, 6), dtype=complex),
        "residual": np.zeros(6, dtype=bool),
        "x": np.full((6, 4), "a"),
        "rank": np.full(6, 2.0),
        "t": np.zeros(6, dtype=[("a", "<f8")]),
    }
    for name, array in cases.items():
        path = _rewrite(saved, tmp_path / f"{name}.npz", **{name: array})
        _refused(path, f"member '{name}.npy'", "dtype")


def test_members_that_are_not_part_of_a_trajectory_or_given_twice_are_refused(saved, tmp_path):
    path = _rewrite(saved, tmp_path / "extra.npz", extra=np.zeros(3))
    _refused(path, "member 'extra.npy' is not part of a gmuk trajectory")
    entries = []
    for key, array in _members(saved).items():
        data = _npy_bytes(array)
        entries.append((f"{key}.npy", _deflate(data), 8, len(data), zlib.crc32(data)))
    twice = tmp_path / "twice.npz"
    twice.write_bytes(_zip([*entries, entries[0]]))
    _refused(twice, "appears twice")


# ----------------------------------------------------------------------------- poses


def test_a_pose_that_is_not_a_rotation_is_refused(saved, tmp_path):
    g = _members(saved)["g_NB"]
    g[3, 0, :3, :3] *= 5.0  # det R = 125
    path = _rewrite(saved, tmp_path / "scaled.npz", g_NB=g)
    _refused(path, "'g_NB'", "'box' at output 3", "not orthonormal", "det R = 125")


def test_a_reflection_is_refused(saved, tmp_path):
    g = _members(saved)["g_NB"]
    g[2, 0, :3, 2] *= -1.0  # orthonormal, det R = -1
    path = _rewrite(saved, tmp_path / "mirror.npz", g_NB=g)
    _refused(path, "'box' at output 2", "reflection", "det R = -1")


def test_a_pose_with_a_bad_bottom_row_is_refused(saved, tmp_path):
    g = _members(saved)["g_NB"]
    g[1, 0, 3, 0] = 0.5
    path = _rewrite(saved, tmp_path / "row.npz", g_NB=g)
    _refused(path, "output 1", r"bottom row is not \[0, 0, 0, 1\]")


def test_a_rotation_within_round_off_still_loads(saved, tmp_path):
    g = _members(saved)["g_NB"]
    g[:, 0, :3, :3] *= 1.0 + 1e-12
    path = _rewrite(saved, tmp_path / "near.npz", g_NB=g)
    assert np.array_equal(load_trajectory(path).g_NB, g)


# ---------------------------------------------------------------------- other arrays


def test_non_finite_values_are_refused(saved, tmp_path):
    for name, value in (("x", np.nan), ("multipliers", np.inf), ("t", -np.inf)):
        array = _members(saved)[name]
        array.flat[-1] = value
        path = _rewrite(saved, tmp_path / f"{name}.npz", **{name: array})
        _refused(path, f"'{name}' holds non-finite")


def test_times_that_do_not_strictly_increase_are_refused(saved, tmp_path):
    t = _members(saved)["t"]
    _refused(_rewrite(saved, tmp_path / "back.npz", t=t[::-1].copy()), "must strictly increase")
    t[3] = t[2]
    _refused(_rewrite(saved, tmp_path / "dup.npz", t=t), r"t\[3\] = 4.0 follows t\[2\] = 4.0")


def test_a_negative_residual_or_a_rank_out_of_range_is_refused(saved, tmp_path):
    residual = _members(saved)["residual"]
    residual[0] = -1.0
    _refused(_rewrite(saved, tmp_path / "res.npz", residual=residual), "'residual'.*negative")
    for bad in (-2, 11):
        rank = _members(saved)["rank"]
        rank[0] = bad
        _refused(_rewrite(saved, tmp_path / "rank.npz", rank=rank), r"'rank'.*\[-1, 10\]")


def test_point_mass_copies_that_disagree_with_x_are_refused(saved, tmp_path):
    r_N = _members(saved)["r_N"]
    r_N[0, 0, 0] += 1.0
    _refused(_rewrite(saved, tmp_path / "r.npz", r_N=r_N), "'r_N'", "columns of x")
    members = _members(saved)
    del members["v_N"]
    np.savez(tmp_path / "nov.npz", **members)
    _refused(tmp_path / "nov.npz", "format version 2 files hold 'r_N' and 'v_N'")


# -------------------------------------------------------------------------- metadata


def test_non_integer_body_dofs_are_refused(saved, tmp_path):
    for bad in (6.7, 6.0, "6", True, None, 5):
        path = _rewrite(
            saved, tmp_path / "dofs.npz", meta=lambda m, b=bad: m.update(body_dofs=[b, 3, 1])
        )
        _refused(path, "body 'box' .rigid. has body_dofs", "expected the integer 6")


def test_body_names_and_kinds_that_are_not_a_trajectorys_are_refused(saved, tmp_path):
    cases = {
        "distinct strings": dict(body_names=["box", "box", "gap"]),
        "distinct strings;": dict(body_names=["box", 7, "gap"]),
        "has kind 'wheel'": dict(body_kinds=["rigid", "wheel", "slack"]),
        "have lengths 2, 3, 3": dict(body_names=["box", "ball"]),
        "body_kinds must be a list": dict(body_kinds="rigid"),
    }
    for fragment, change in cases.items():
        path = _rewrite(saved, tmp_path / "names.npz", meta=lambda m, c=change: m.update(c))
        _refused(path, re.escape(fragment.rstrip(";")))


def test_malformed_stats_are_refused(saved, tmp_path):
    cases = {
        "stats must be an object": [1, 2],
        r"stats\['n_rhs'\] must be an integer ≥ 0": {"n_rhs": -1},
        r"stats\['n_steps'\] must be an integer ≥ 0": {"n_steps": 2.5},
        r"stats\['n_rejected'\] must be an integer ≥ 0": {"n_rejected": True},
        r"stats\['method'\] must be a string": {"method": 4},
        r"stats\['rtol'\] must be a finite number ≥ 0": {"rtol": float("nan")},
        r"stats\['compiled'\] must be true or false": {"compiled": "False"},
        r"stats\['checkpoint'\] must be an object": {"checkpoint": "x"},
    }
    for fragment, stats in cases.items():
        path = _rewrite(saved, tmp_path / "stats.npz", meta=lambda m, s=stats: m.update(stats=s))
        _refused(path, fragment)
    # entries gmuk does not know are kept as they are
    path = _rewrite(saved, tmp_path / "mine.npz", meta=lambda m: m["stats"].update(mine={"a": [1]}))
    assert load_trajectory(path).stats["mine"] == {"a": [1]}


def test_a_bad_status_or_message_is_refused(saved, tmp_path):
    for bad in ("ok", "Success", None, 1):
        path = _rewrite(saved, tmp_path / "status.npz", meta=lambda m, b=bad: m.update(status=b))
        _refused(
            path,
            "status must be one of \\['success', 'terminated', 'drifted', 'interrupted', "
            "'failed'\\]",
        )
    path = _rewrite(saved, tmp_path / "message.npz", meta=lambda m: m.update(message=["x"]))
    _refused(path, "message must be a string")
    path = _rewrite(saved, tmp_path / "nostatus.npz", meta=lambda m: m.pop("status"))
    _refused(path, "missing metadata 'status'")


def test_an_unknown_format_version_is_refused(saved, tmp_path):
    path = _rewrite(saved, tmp_path / "v3.npz", meta=lambda m: m.update(format_version=3))
    _refused(path, "format version 3 was written by a newer gmuk")
    for bad in (0, True, 1.0, "2", None):
        path = _rewrite(saved, tmp_path / "v.npz", meta=lambda m, b=bad: m.update(format_version=b))
        _refused(path, "format_version must be a positive integer")


def test_deeply_nested_or_invalid_metadata_json_is_a_format_error(saved, tmp_path):
    for text in ("[" * 100_000 + "]" * 100_000, "{not json"):
        path = _rewrite(saved, tmp_path / "deep.npz", meta=None)
        members = _members(path)
        members["meta"] = np.array(text)
        np.savez(path, **members)
        _refused(path, "metadata is not")
    members = _members(saved)
    members["meta"] = np.array(["{}", "{}"])
    np.savez(tmp_path / "two.npz", **members)
    _refused(tmp_path / "two.npz", "expected one string")


# ------------------------------------------------------------------------- gmuk view


def test_gmuk_view_out_an_existing_folder_writes_view_html_inside_it(saved, tmp_path, capsys):
    folder = tmp_path / "views"
    folder.mkdir()
    assert main(["view", str(saved), "--out", str(folder), "--max-frames", "2"]) == 0
    assert (folder / "view.html").read_text().startswith("<!doctype html>")
    assert str(folder / "view.html") in capsys.readouterr().out
    (folder / "view.html").unlink()
    (folder / "view.html").mkdir()  # a folder where the file would go: refused, no traceback
    assert main(["view", str(saved), "--out", str(folder)]) == 2
    assert "holding a folder named view.html" in capsys.readouterr().err
    with pytest.raises(DefinitionError, match=r"is a folder; give the \.html file to write"):
        gmuk.view.write_view(load_trajectory(saved), folder)


def test_gmuk_view_of_an_unwritable_output_or_a_hostile_file_exits_2_with_a_message(
    saved, tmp_path, capsys
):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["view", str(saved), "--out", str(blocker / "v.html")]) == 2
    assert "cannot write" in capsys.readouterr().err
    npy = tmp_path / "t.npy"
    np.save(npy, np.zeros(3))
    assert main(["view", str(npy)]) == 2
    assert "a .npy file" in capsys.readouterr().err
    (tmp_path / "run").mkdir()
    g = _members(saved)["g_NB"]
    g[0, 0, :3, :3] *= 5.0
    _rewrite(saved, tmp_path / "run" / "trajectory.npz", g_NB=g)
    (tmp_path / "run" / "summary.json").write_text("[" * 100_000)
    assert main(["view", str(tmp_path / "run")]) == 2
    assert "not orthonormal" in capsys.readouterr().err


# ---------------------------------------------------------------------- gravity fields

SHADR_HEAD = "1.7380000000000000E+03, 4.9028000000000000E+03, {sig}, 3, 3, 1, {lon}, {lat}"
SHADR_ROWS = [
    f"{n:5d}, {m:5d}, {1e-6 * (n + m):.16E}, {-1e-6 * m if m else 0.0:.16E}, 0.0, 0.0"
    for n in range(2, 4)
    for m in range(n + 1)
]
GFC_HEAD = [
    "earth_gravity_constant 0.3986004415E+15",
    "radius 0.63781363E+07",
    "max_degree 3",
    "end_of_head",
]
GFC_ROWS = [
    f"gfc {n} {m} {1e-6 * (n + m):.6e} {-1e-6 * m if m else 0.0:.6e}"
    for n in range(2, 4)
    for m in range(n + 1)
]


def _shadr(tmp_path: Path, head: str | None = None, **kw) -> Path:
    values = {"sig": "0.0", "lon": "0.0", "lat": "0.0", **kw}
    path = tmp_path / "field.tab"
    path.write_text("\n".join([head or SHADR_HEAD.format(**values), *SHADR_ROWS]) + "\n")
    return path


def _shadr_refused(path: Path, *fragments: str) -> None:
    with pytest.raises(FileFormatError) as info:
        load_shadr(path)
    msg = str(info.value)
    assert f"{path}: line 1" in msg, msg
    for fragment in fragments:
        assert re.search(fragment, msg), (fragment, msg)


def test_a_valid_shadr_file_still_reads_its_header(tmp_path):
    f = load_shadr(_shadr(tmp_path, sig="1.5e-4", lon="359.5", lat="-90"))
    assert f.degree == 3 and f.metadata["sigma_mu"] == 1.5e-4 * 1e9
    assert f.metadata["reference_longitude_deg"] == 359.5
    assert f.metadata["reference_latitude_deg"] == -90.0


def test_a_shadr_reference_latitude_out_of_range_is_refused(tmp_path):
    for lat in ("90.5", "-91", "1e300"):
        _shadr_refused(_shadr(tmp_path, lat=lat), r"reference latitude \(field 8\)", "-90, 90")
    _shadr_refused(_shadr(tmp_path, lat="nan"), "reference latitude", "must be finite")


def test_a_shadr_reference_longitude_out_of_range_is_refused(tmp_path):
    for lon in ("360.5", "-180.5", "-1e9"):
        _shadr_refused(_shadr(tmp_path, lon=lon), r"reference longitude \(field 7\)", "-180, 360")


def test_a_shadr_negative_or_non_finite_sigma_gm_is_refused(tmp_path):
    _shadr_refused(_shadr(tmp_path, sig="-1e-4"), "sigma GM .field 3. must be >= 0")
    _shadr_refused(_shadr(tmp_path, sig="inf"), "sigma GM", "must be finite")


def test_a_shadr_non_positive_radius_or_gm_is_refused(tmp_path):
    for head in (
        "0.0, 4902.8, 0.0, 3, 3, 1, 0.0, 0.0",
        "1738.0, -4902.8, 0.0, 3, 3, 1, 0.0, 0.0",
        "1738.0, nan, 0.0, 3, 3, 1, 0.0, 0.0",
    ):
        _shadr_refused(_shadr(tmp_path, head=head), "R_ref and GM must be > 0|must be finite")


def test_a_shadr_order_above_degree_or_negative_is_refused(tmp_path):
    for head in (
        "1738.0, 4902.8, 0.0, 3, 4, 1, 0.0, 0.0",
        "1738.0, 4902.8, 0.0, 3, -1, 1, 0.0, 0.0",
        "1738.0, 4902.8, 0.0, -3, 0, 1, 0.0, 0.0",
        "1738.0, 4902.8, 0.0, 3.5, 3, 1, 0.0, 0.0",
    ):
        _shadr_refused(_shadr(tmp_path, head=head), "order <= degree|expected an integer")


def test_a_gravity_header_claiming_an_absurd_degree_is_refused_before_allocating(tmp_path):
    huge = {
        "1e300": "1738.0, 4902.8, 0.0, 1e300, 0, 1, 0.0, 0.0",
        "4300 digits": "1738.0, 4902.8, 0.0, " + "9" * 4300 + ", 0, 1, 0.0, 0.0",
    }
    # a zonal field (order 0) needs one line per degree: 10 400 lines pass the line count,
    # but its arrays would take 5 x 8 x 10 401² bytes = 4.3 GB
    zonal = tmp_path / "zonal.tab"
    rows = (f"{n}, 0, 0.0, 0.0, 0.0, 0.0" for n in range(2, 10_401))
    zonal.write_text("\n".join(["1738.0, 4902.8, 0.0, 10400, 0, 1, 0.0, 0.0", *rows]) + "\n")
    gfc = tmp_path / "big.gfc"
    gfc.write_text("\n".join([*GFC_HEAD[:2], "max_degree 20000", "end_of_head"]) + "\n")
    tracemalloc.start()
    try:
        for head in huge.values():
            _shadr_refused(
                _shadr(tmp_path, head=head), r"needs at least about 1e(300|4300) coefficient lines"
            )
        _shadr_refused(zonal, "degree 10400 needs 4327232040 bytes", "before allocating")
        with pytest.raises(FileFormatError, match=f"{re.escape(str(gfc))}: line 3: .*needs"):
            load_gfc(gfc)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20 * 2**20


def test_icgem_non_physical_header_values_are_refused(tmp_path):
    path = tmp_path / "f.gfc"
    path.write_text("\n".join([*GFC_HEAD, *GFC_ROWS]) + "\n")
    assert load_gfc(path).degree == 3
    for line, bad in ((0, "earth_gravity_constant -1"), (1, "radius 0"), (2, "max_degree -2")):
        head = list(GFC_HEAD)
        head[line] = bad
        path.write_text("\n".join([*head, *GFC_ROWS]) + "\n")
        with pytest.raises(FileFormatError, match=f"{re.escape(str(path))}: line {line + 1}"):
            load_gfc(path)
