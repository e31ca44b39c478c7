"""The gravity fields shipped in the package: files, checksums, packaging and ``load``."""

from __future__ import annotations

import ast
import hashlib
import re
from fnmatch import fnmatch
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import gmuk
import gmuk.gravity
from gmuk.errors import DefinitionError, DegreeError, GmukError
from gmuk.gravity import available, field_path, load, load_gfc

DATA = Path(gmuk.__file__).resolve().parent / "gravity" / "data"
PYPROJECT = Path(__file__).resolve().parents[2] / "pyproject.toml"
SHIPPED = {"GRGM660PRIM": ("GRGM660PRIM_to150.gfc", 150), "EGM2008": ("EGM2008_to70.gfc", 70)}


def _readme_sums() -> dict[str, str]:
    """File name -> sha256 from the table of ``gmuk/gravity/data/README.md``."""
    text = (DATA / "README.md").read_text(encoding="utf-8")
    sums = {}
    for line in text.splitlines():
        m = re.match(r"\| `([^`]+\.gfc)` \|.*\| ([0-9a-f]{64}) \|$", line)
        if m:
            sums[m.group(1)] = m.group(2)
    return sums


def test_the_catalogue_lists_every_shipped_file_and_nothing_else():
    assert {i.name: (i.filename, i.max_degree) for i in available()} == SHIPPED
    assert sorted(p.name for p in DATA.glob("*.gfc")) == sorted(f for f, _ in SHIPPED.values())
    assert set(_readme_sums()) == {f for f, _ in SHIPPED.values()}


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_sha256_of_each_file_is_the_one_in_the_data_readme(name):
    path = field_path(name)
    assert hashlib.sha256(path.read_bytes()).hexdigest() == _readme_sums()[path.name]


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_files_are_package_data_found_through_importlib_resources(name):
    filename, max_degree = SHIPPED[name]
    res = resources.files("gmuk.gravity").joinpath("data", filename)
    assert res.is_file()
    path = field_path(name)
    assert path == Path(str(res)) and path.parent.resolve() == DATA
    assert res.read_bytes() == path.read_bytes()
    # the header agrees with the catalogue
    assert load_gfc(path).degree == max_degree


def test_pyproject_package_data_covers_the_data_folder():
    text = PYPROJECT.read_text(encoding="utf-8")
    section = text.split("[tool.setuptools.package-data]", 1)[1].split("\n[", 1)[0]
    m = re.search(r"^gmuk\s*=\s*(\[.*?\])\s*$", section, flags=re.MULTILINE)
    assert m, "no package-data line for gmuk in pyproject.toml"
    globs = ast.literal_eval(m.group(1))
    for p in sorted(DATA.iterdir()):
        rel = f"gravity/data/{p.name}"
        assert any(fnmatch(rel, g) for g in globs), f"{rel} is not package data"


def test_load_by_name_any_case_is_the_file_and_is_cached():
    moon = load("GRGM660PRIM")
    assert moon.degree == 150 and moon.name == "GRGM660PRIM"
    assert load("grgm660prim") is moon and load("GrGm660Prim", degree=None) is moon
    ref = load_gfc(field_path("GRGM660PRIM"))
    assert moon.mu == ref.mu and moon.radius == ref.radius
    np.testing.assert_array_equal(moon.C, ref.C)
    np.testing.assert_array_equal(moon.S, ref.S)
    earth = load("egm2008")
    assert earth.degree == 70 and earth.mu == 3.986004415e14 and earth.radius == 6.3781363e6


def test_load_with_degree_truncates_and_is_cached_per_degree():
    f20 = load("EGM2008", degree=20)
    assert f20.degree == 20
    np.testing.assert_array_equal(f20.C, load("EGM2008").C[:21, :21])
    np.testing.assert_array_equal(f20.S, load("EGM2008").S[:21, :21])
    assert load("egm2008", 20) is f20 and load("EGM2008", degree=np.int64(20)) is f20
    assert load("EGM2008", degree=21) is not f20 and load("EGM2008", degree=21).degree == 21
    assert load("EGM2008", degree=0).degree == 0
    assert load("EGM2008", degree=70).degree == 70


@pytest.mark.parametrize("bad", ["GRGM660", "moon", "", None, 3, "EGM2008_to70.gfc"])
def test_unknown_name_lists_the_shipped_names(bad):
    for call in (lambda: load(bad), lambda: field_path(bad)):
        with pytest.raises(DefinitionError, match="unknown gravity field") as info:
            call()
        msg = str(info.value)
        assert repr(bad) in msg and "'GRGM660PRIM'" in msg and "'EGM2008'" in msg


@pytest.mark.parametrize(("name", "degree"), [("GRGM660PRIM", 151), ("EGM2008", 71)])
def test_degree_above_the_file_maximum(name, degree):
    top = SHIPPED[name][1]
    with pytest.raises(DegreeError) as info:
        load(name, degree=degree)
    assert f"asked for degree {degree}, but the file's max_degree is {top}" in str(info.value)
    assert SHIPPED[name][0] in str(info.value)  # names the file


def test_negative_degree():
    with pytest.raises(DegreeError, match="integer >= 0; got -1"):
        load("EGM2008", degree=-1)


@pytest.mark.parametrize("bad", [2.5, 10.0, "10", True, False, np.float64(3.0), [3]])
def test_non_integer_degree_is_a_gmuk_error(bad):
    with pytest.raises(GmukError, match="degree must be an integer") as info:
        load("EGM2008", degree=bad)
    assert isinstance(info.value, ValueError)


def test_package_namespace():
    assert gmuk.gravity.load is load and gmuk.gravity.field_path is field_path
    for info in available():
        assert info.body in ("Moon", "Earth") and info.description
