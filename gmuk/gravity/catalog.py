"""Gravity fields shipped with gmuk, loadable by name.

The package carries two real fields in ICGEM ``.gfc`` format (``gmuk/gravity/data/``, with
their provenance and licence in the README beside them):

* ``"GRGM660PRIM"``: the Moon, GRAIL primary mission (Lemoine et al. 2013), to degree 150;
* ``"EGM2008"``: the Earth (Pavlis et al. 2012), to degree 70.

>>> import gmuk.gravity
>>> moon = gmuk.gravity.load("GRGM660PRIM", degree=50)
>>> moon.degree
50
"""

from __future__ import annotations

import functools
import operator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from gmuk.errors import DefinitionError
from gmuk.gravity.field import SphericalHarmonicField
from gmuk.gravity.io import load_gfc

__all__ = ["FieldInfo", "available", "field_path", "load"]


@dataclass(frozen=True)
class FieldInfo:
    """A shipped field: its name for :func:`load`, central body, model and degree kept."""

    name: str
    body: str
    description: str
    max_degree: int
    filename: str


_FIELDS: dict[str, FieldInfo] = {
    info.name.upper(): info
    for info in (
        FieldInfo(
            "GRGM660PRIM",
            "Moon",
            "GRAIL primary-mission lunar field (NASA GSFC; Lemoine et al. 2013), 150 of 660",
            150,
            "GRGM660PRIM_to150.gfc",
        ),
        FieldInfo(
            "EGM2008",
            "Earth",
            "Earth Gravitational Model 2008 (NGA; Pavlis et al. 2012), 70 of 2190",
            70,
            "EGM2008_to70.gfc",
        ),
    )
}


def available() -> list[FieldInfo]:
    """The fields shipped with gmuk."""
    return list(_FIELDS.values())


def _info(name: object) -> FieldInfo:
    if not isinstance(name, str) or name.upper() not in _FIELDS:
        names = ", ".join(repr(i.name) for i in _FIELDS.values())
        raise DefinitionError(
            f"unknown gravity field {name!r}; shipped fields are {names} "
            "(read other files with gmuk.gravity.load_gfc or load_shadr)"
        )
    return _FIELDS[name.upper()]


def field_path(name: str) -> Path:
    """Path of the shipped ``.gfc`` file of field ``name`` (case-insensitive)."""
    info = _info(name)
    return Path(str(resources.files("gmuk.gravity") / "data" / info.filename))


def load(name: str, degree: int | None = None) -> SphericalHarmonicField:
    """A shipped gravity field by name, optionally truncated.

    Parameters
    ----------
    name : str
        ``"GRGM660PRIM"`` (Moon) or ``"EGM2008"`` (Earth), case-insensitive; see
        :func:`available`.
    degree : int, optional
        Keep degrees ≤ ``degree`` (default: every degree the file has).

    Returns
    -------
    SphericalHarmonicField
        μ (m³/s²), reference radius (m) and 4π-normalised coefficients from the file. Fields
        are immutable, and each (name, degree) is read once per process.

    Raises
    ------
    DefinitionError
        Unknown name.
    DegreeError
        ``degree`` negative or above the shipped file's maximum.
    """
    info = _info(name)
    return _load(info.name, None if degree is None else _check_int(degree))


def _check_int(degree: object) -> int:
    if not isinstance(degree, bool):
        try:
            return operator.index(degree)  # type: ignore[arg-type]
        except TypeError:
            pass
    raise DefinitionError(
        f"degree must be an integer ≥ 0; got {degree!r} ({type(degree).__name__})"
    )


@functools.lru_cache(maxsize=16)
def _load(name: str, degree: int | None) -> SphericalHarmonicField:
    return load_gfc(field_path(name), degree=degree)
