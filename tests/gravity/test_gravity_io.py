"""Readers: ICGEM .gfc and PDS SHADR .tab, real files and malformed ones."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gmuk.errors import DegreeError, FileFormatError
from gmuk.gravity import load_gfc, load_shadr

from .refs import GRAIL_FILE

# --------------------------------------------------------------------- real files


def test_grail_file(grail):
    assert grail.name == "GRGM660PRIM"
    assert grail.mu == 4.902799806931690e12  # 0.4902799806931690D+13
    assert grail.radius == 1.738e6
    assert grail.degree == 150
    assert grail.tide_system == "tide_free"
    assert grail.C[0, 0] == 1.0 and grail.C[2, 0] == -9.0882923650771e-05
    assert grail.S[4, 3] == -1.3444991147298e-05
    assert grail.sigma_C is not None and grail.sigma_C[2, 0] == 1.53e-10
    assert grail.metadata["format"] == "icgem"
    assert grail.metadata["header"]["errors"] == "formal"
    assert grail.metadata["source"].endswith("GRGM660PRIM_to150.gfc")


def test_egm2008_file(egm):
    assert egm.mu == 3.986004415e14 and egm.radius == 6.3781363e6
    assert egm.degree == 70 and egm.sigma_C is None  # no sigma columns, no 'errors' key
    assert egm.C[0, 0] == 1.0  # written '1.0d0'
    assert egm.C[2, 0] == -0.484165143790815e-03
    assert egm.C[70, 70] == 0.298214665798648e-09


def test_degree_on_reading_and_path_types(grail):
    f = load_gfc(str(GRAIL_FILE), degree=20)
    assert f.degree == 20
    np.testing.assert_array_equal(f.C, grail.C[:21, :21])
    with pytest.raises(DegreeError, match="asked for degree 151, but the file's max_degree is 150"):
        load_gfc(GRAIL_FILE, degree=151)
    with pytest.raises(FileFormatError, match=r"nope\.gfc: no such file"):
        load_gfc(GRAIL_FILE.with_name("nope.gfc"))
    with pytest.raises(FileFormatError, match="not a regular file"):
        load_gfc(GRAIL_FILE.parent)
    with pytest.raises(FileFormatError, match=r"path must be a str or os\.PathLike; got None"):
        load_gfc(None)


@pytest.mark.parametrize("reader", ["gfc", "shadr"])
def test_a_header_degree_the_file_cannot_fill_is_refused_before_allocating(tmp_path, reader):
    # A hostile header (degree 1e6 would ask for 5 arrays of 8 TB); the file has 3 lines.
    if reader == "gfc":
        p = tmp_path / "huge.gfc"
        head = HEADER.replace("max_degree     3", "max_degree     1000000")
        p.write_text(head + "gfc 2 0 1e-4 0\ngfc 2 1 0 0\ngfc 2 2 0 0\n")
        load = load_gfc
    else:
        p = tmp_path / "huge.tab"
        p.write_text("1738.0, 4902.8, 0.0, 1000000, 1000000, 1, 0.0, 0.0\n2, 0, 1e-4, 0\n")
        load = load_shadr
    with pytest.raises(FileFormatError, match="needs at least 500001499998 coefficient lines"):
        load(p)


def test_truncated_copy_of_the_real_file(tmp_path):
    lines = GRAIL_FILE.read_text(encoding="latin-1").splitlines()
    p = tmp_path / "cut.gfc"
    p.write_text("\n".join(lines[:-5]) + "\n")
    with pytest.raises(FileFormatError) as info:
        load_gfc(p)
    msg = str(info.value)
    assert str(p) in msg and f"line {len(lines) - 5}" in msg
    assert "after (150, 145) with 5 coefficient(s) missing, the first (150, 146)" in msg


# --------------------------------------------------------------------- small gfc files

GM = "0.4902799806931690D+13"
HEADER = f"""free text before the header
product_type   gravity_field
modelname      TOY
gravity_constant {GM}
radius         0.1738000D+07
max_degree     3
norm           fully_normalized
tide_system    tide_free
errors         formal
key n m C S sigmaC sigmaS
end_of_head ========
"""
ROWS = [
    (0, 0, "1.0D+00", "0.0", "0.0", "0.0"),
    (2, 0, "-9.08829E-05", "0.0", "1e-10", "0.0"),
    (2, 1, "8.5E-11", "9.8E-10", "1e-12", "1e-12"),
    (2, 2, "3.467094d-05", "-2.4E-10", "1e-12", "1e-12"),
    (3, 0, "-3.19E-06", "0.0", "1e-12", "0.0"),
    (3, 1, "2.63E-05", "5.45E-06", "1e-12", "1e-12"),
    (3, 2, "1.41E-05", "4.87E-06", "1e-12", "1e-12"),
    (3, 3, "1.22E-05", "-1.77E-06", "1e-12", "1e-12"),
]


def _gfc(tmp_path, header=HEADER, rows=ROWS, extra="", name="toy.gfc"):
    body = "".join("gfc " + " ".join(str(v) for v in row) + "\n" for row in rows)
    p = tmp_path / name
    p.write_text(header + body + extra)
    return p


def _line_of(p, needle):
    for i, line in enumerate(Path(p).read_text().splitlines(), start=1):
        if needle in line:
            return i
    raise AssertionError(needle)


def test_small_gfc_reads(tmp_path):
    f = load_gfc(_gfc(tmp_path))
    assert f.name == "TOY" and f.degree == 3 and f.mu == 4.902799806931690e12
    assert f.C[2, 2] == 3.467094e-05 and f.S[3, 3] == -1.77e-06
    assert f.sigma_S[2, 1] == 1e-12
    # degree 1 absent: zero; C00 given
    assert f.C[1, 0] == 0.0 and f.C[0, 0] == 1.0
    # without the 0,0 line C00 defaults to 1
    g = load_gfc(_gfc(tmp_path, rows=ROWS[1:], name="no00.gfc"))
    assert g.C[0, 0] == 1.0


def test_unnormalized_gfc_is_converted(tmp_path):
    n22 = np.sqrt(5 / 12)  # N_22 = √((2)(5) 0!/4!)
    header = HEADER.replace("fully_normalized", "unnormalized")
    rows = [list(r) for r in ROWS]
    rows[3][2] = repr(float(3.467094e-05 * n22))
    f = load_gfc(_gfc(tmp_path, header=header, rows=rows))
    assert abs(f.C[2, 2] - 3.467094e-05) <= 1e-20


def _expect(p, *fragments):
    with pytest.raises(FileFormatError) as info:
        load_gfc(p)
    msg = str(info.value)
    assert str(p) in msg
    for frag in fragments:
        assert frag in msg, msg
    return msg


def test_gfc_truncated(tmp_path):
    p = _gfc(tmp_path, rows=ROWS[:-1])
    _expect(p, f"line {_line_of(p, 'gfc 3 2')}", "missing", "the first (3, 3)", "truncated")


def test_gfc_wrong_number_of_columns(tmp_path):
    rows = [*ROWS[:4], (3, 0, "-3.19E-06", "0.0", "1e-12"), *ROWS[5:]]
    p = _gfc(tmp_path, rows=rows)
    _expect(p, f"line {_line_of(p, 'gfc 3 0')}", "expected 7 columns", "got 6")


def test_gfc_columns_disagree_with_errors_key(tmp_path):
    rows = [r[:4] for r in ROWS]
    p = _gfc(tmp_path, rows=rows)
    _expect(p, f"line {_line_of(p, 'gfc 0 0')}", "expected 7 columns", "'errors' key", "got 5")


@pytest.mark.parametrize(
    ("key", "expected"),
    [
        ("gravity_constant", "earth_gravity_constant or gravity_constant"),
        ("radius", "radius"),
        ("max_degree", "max_degree"),
    ],
)
def test_gfc_missing_header_key(tmp_path, key, expected):
    header = "\n".join(ln for ln in HEADER.splitlines() if not ln.startswith(key)) + "\n"
    p = _gfc(tmp_path, header=header)
    _expect(p, f"line {_line_of(p, 'end_of_head')}", f"required key(s) {expected}")


def test_gfc_without_end_of_head(tmp_path):
    p = tmp_path / "nohead.gfc"
    p.write_text("modelname X\nradius 1\n")
    _expect(p, "line 2", "no 'end_of_head' line")


@pytest.mark.parametrize("bad", ["NaN", "nan", "Infinity", "-inf"])
def test_gfc_non_finite_value(tmp_path, bad):
    rows = [list(r) for r in ROWS]
    rows[5][2] = bad
    p = _gfc(tmp_path, rows=rows)
    _expect(p, f"line {_line_of(p, 'gfc 3 1')}", "C[3, 1] must be finite", repr(bad))


def test_gfc_non_numeric_value_and_degree(tmp_path):
    rows = [list(r) for r in ROWS]
    rows[2][3] = "9.8E-1O"
    p = _gfc(tmp_path, rows=rows)
    _expect(p, f"line {_line_of(p, 'gfc 2 1')}", "expected a number for S[2, 1]", "'9.8E-1O'")
    rows = [list(r) for r in ROWS]
    rows[2][0] = "two"
    p = _gfc(tmp_path, rows=rows, name="deg.gfc")
    _expect(p, f"line {_line_of(p, 'gfc two')}", "expected a number for degree n", "'two'")
    header = HEADER.replace("radius         0.1738000D+07", "radius         big")
    p = _gfc(tmp_path, header=header, name="rad.gfc")
    _expect(p, f"line {_line_of(p, 'radius         big')}", "expected a number for radius (m)")


@pytest.mark.parametrize(
    ("row", "fragment"),
    [
        ((4, 0, "1e-6", "0.0", "0", "0"), "(4, 0) out of range; expected 0 <= m <= n <= 3"),
        ((2, 3, "1e-6", "0.0", "0", "0"), "(2, 3) out of range"),
        ((-1, 0, "1e-6", "0.0", "0", "0"), "(-1, 0) out of range"),
    ],
)
def test_gfc_degree_or_order_out_of_range(tmp_path, row, fragment):
    p = _gfc(tmp_path, rows=[*ROWS, row])
    _expect(p, f"line {_line_of(p, 'gfc ' + ' '.join(map(str, row[:2])) + ' ')}", fragment)


def test_gfc_duplicate_entry(tmp_path):
    p = _gfc(tmp_path, rows=[*ROWS, ROWS[3]])
    first = _line_of(p, "gfc 2 2")
    msg = _expect(p, "duplicate coefficient (2, 2)", f"first given on line {first}")
    assert f"line {first + len(ROWS) - 3}:" in msg


def test_gfc_other_format_problems(tmp_path):
    p = _gfc(tmp_path, extra="gfct 3 3 1e-6 0 0 0 20000101\n", name="tv.gfc")
    _expect(p, f"line {_line_of(p, 'gfct')}", "time-variable 'gfct' terms are not supported")
    p = _gfc(tmp_path, extra="hello world\n", name="junk.gfc")
    _expect(p, f"line {_line_of(p, 'hello')}", "expected a coefficient line")
    p = _gfc(tmp_path, header=HEADER.replace("fully_normalized", "schmidt"), name="norm.gfc")
    _expect(
        p, f"line {_line_of(p, 'schmidt')}", "norm must be 'fully_normalized' or 'unnormalized'"
    )
    rows = [list(r) for r in ROWS]
    rows[4][3] = "1e-9"
    p = _gfc(tmp_path, rows=rows, name="s0.gfc")
    _expect(p, f"line {_line_of(p, 'gfc 3 0')}", "S[3, 0] must be 0")
    p = _gfc(tmp_path, header=HEADER.replace("0.1738000D+07", "-1.0"), name="neg.gfc")
    _expect(p, "radius must be > 0")
    p = _gfc(tmp_path, header=HEADER.replace("errors         formal", "errors maybe"), name="e.gfc")
    _expect(p, "errors must be one of 'no'")
    dup = HEADER.replace("max_degree     3", "max_degree     3\nmax_degree 4")
    p = _gfc(tmp_path, header=dup, name="dupkey.gfc")
    _expect(p, "header key 'max_degree' given twice")


# --------------------------------------------------------------------- SHADR


def _write_shadr(path, field, *, degree=None, order=None, state=1, rows=None, head=None):
    N = field.degree if degree is None else degree
    M = N if order is None else order
    sC = field.sigma_C if field.sigma_C is not None else np.zeros_like(field.C)
    sS = field.sigma_S if field.sigma_S is not None else np.zeros_like(field.S)
    lines = [
        head
        or (
            f"{field.radius / 1e3:.16E}, {field.mu / 1e9:.16E}, {0.0:.16E}, "
            f"{N:5d}, {M:5d}, {state:5d}, {0.0:.16E}, {0.0:.16E}"
        )
    ]
    if rows is None:
        rows = [
            f"{n:5d}, {m:5d}, {field.C[n, m]:.16E}, {field.S[n, m]:.16E}, "
            f"{sC[n, m]:.16E}, {sS[n, m]:.16E}"
            for n in range(1, N + 1)
            for m in range(min(n, M) + 1)
        ]
    path.write_text("\n".join([*lines, *rows]) + "\n")
    return path


def test_shadr_written_from_the_grail_file_reads_back_the_same_field(grail, tmp_path):
    p = _write_shadr(tmp_path / "jggrx_like_sha.tab", grail)
    f = load_shadr(p)
    assert f.degree == 150 and f.metadata["format"] == "shadr"
    np.testing.assert_array_equal(f.C, grail.C)
    np.testing.assert_array_equal(f.S, grail.S)
    np.testing.assert_array_equal(f.sigma_C, grail.sigma_C)
    assert abs(f.mu - grail.mu) <= 1e-15 * grail.mu  # km³/s² → m³/s²
    assert abs(f.radius - grail.radius) <= 1e-15 * grail.radius
    r = np.array([[1.1e6, -0.8e6, 1.2e6], [0.0, 0.0, -1.8e6]])
    np.testing.assert_allclose(f.acceleration(r), grail.acceleration(r), rtol=2e-15)
    g = load_shadr(str(p), degree=40)
    np.testing.assert_array_equal(g.C, grail.C[:41, :41])
    with pytest.raises(DegreeError, match="file's degree is 150"):
        load_shadr(p, degree=200)


def test_shadr_order_below_degree(grail, tmp_path):
    p = _write_shadr(tmp_path / "o.tab", grail.truncate(10), order=6)
    f = load_shadr(p)
    assert f.metadata["order"] == 6
    assert np.all(f.C[7:, 7:] == 0) and f.C[10, 6] == grail.C[10, 6]


def _expect_shadr(p, *fragments):
    with pytest.raises(FileFormatError) as info:
        load_shadr(p)
    msg = str(info.value)
    assert str(p) in msg
    for frag in fragments:
        assert frag in msg, msg


def test_shadr_malformed(grail, tmp_path):
    f = grail.truncate(6)
    good = _write_shadr(tmp_path / "good.tab", f)
    lines = good.read_text().splitlines()
    # truncated
    p = tmp_path / "cut.tab"
    p.write_text("\n".join(lines[:-2]) + "\n")
    _expect_shadr(p, f"line {len(lines) - 2}", "the first (6, 5)", "truncated")
    # header with a missing field
    p = tmp_path / "head.tab"
    p.write_text("\n".join([lines[0].rsplit(",", 1)[0], *lines[1:]]) + "\n")
    _expect_shadr(p, "line 1", "header record of 8 comma-separated fields", "got 7")
    # unknown normalisation state
    p = _write_shadr(tmp_path / "state.tab", f, state=2)
    _expect_shadr(p, "line 1", "normalization state must be 1 (normalized) or 0")
    # wrong number of columns on a row
    p = tmp_path / "cols.tab"
    bad = [*lines[:5], lines[5].rsplit(",", 1)[0], *lines[6:]]
    p.write_text("\n".join(bad) + "\n")
    _expect_shadr(p, "line 6", "expected 6 comma-separated columns", "got 5")
    # NaN, non-numeric
    for text, frag in (("NaN", "must be finite"), ("1.0E-O5", "expected a number")):
        p = tmp_path / f"val{len(text)}.tab"
        fields = lines[3].split(",")
        fields[2] = f" {text}"
        p.write_text("\n".join([*lines[:3], ",".join(fields), *lines[4:]]) + "\n")
        _expect_shadr(p, "line 4", frag)
    # degree out of range, duplicate
    p = tmp_path / "range.tab"
    p.write_text("\n".join([*lines, "    7,     0,  1.0E-06,  0.0,  0.0,  0.0"]) + "\n")
    _expect_shadr(p, f"line {len(lines) + 1}", "(7, 0) out of range")
    p = tmp_path / "dup.tab"
    p.write_text("\n".join([*lines, lines[4]]) + "\n")
    _expect_shadr(p, f"line {len(lines) + 1}", "duplicate coefficient", "first given on line 5")
    # empty file
    p = tmp_path / "empty.tab"
    p.write_text("\n\n")
    _expect_shadr(p, "empty file")


def test_shadr_unnormalized_state_is_converted(tmp_path):
    from gmuk.gravity import SphericalHarmonicField

    C = np.zeros((3, 3))
    S = np.zeros((3, 3))
    C[0, 0] = 1.0
    C[2, 0] = -2.03e-4  # J₂-like, unnormalised
    f = SphericalHarmonicField(4.9e12, 1.738e6, C, S)
    p = _write_shadr(tmp_path / "u.tab", f, state=0)
    g = load_shadr(p)
    assert abs(g.C[2, 0] - (-2.03e-4 / np.sqrt(5.0))) <= 1e-19  # N_20 = √5
