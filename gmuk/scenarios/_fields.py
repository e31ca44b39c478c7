"""The lunar gravity field a scenario takes with ``--field``: a shipped name, a file, or a
field object."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from gmuk import gravity
from gmuk.errors import DefinitionError
from gmuk.gravity import MOON_MU, SphericalHarmonicField, load_gfc

__all__ = ["DEFAULT_FIELD", "harmonic_degree", "lunar_field"]

#: The field scenarios use unless told otherwise (shipped with gmuk, to degree 150).
DEFAULT_FIELD = "GRGM660PRIM"


def harmonic_degree(text: str) -> int:
    """A ``--degree`` option: an integer ≥ 2 (the lowest degree with harmonics)."""
    value = int(text)
    if value < 2:
        raise ValueError("must be an integer >= 2")
    return value


def lunar_field(field: Any, who: str) -> tuple[SphericalHarmonicField, str]:
    """The field and a note saying where it came from.

    Parameters
    ----------
    field : str, path-like or SphericalHarmonicField
        A field shipped with gmuk (by name, any case), the path of an ICGEM ``.gfc`` file, or
        a field.
    who : str
        The scenario's name, for error messages.

    Raises
    ------
    DefinitionError
        A name that is neither shipped nor a file; a field that is not the Moon's (GM not
        within 1e-3 of the Moon's).
    """
    if isinstance(field, SphericalHarmonicField):
        sh, note = field, f"{field.name} (given as a field, degree {field.degree})"
    else:
        text = os.fspath(field)
        shipped = {info.name.upper(): info.name for info in gravity.available()}
        if isinstance(field, str) and text.upper() in shipped:
            sh = gravity.load(shipped[text.upper()])
            note = f"{sh.name} (shipped with gmuk, degree {sh.degree})"
        elif Path(text).is_file():
            sh = load_gfc(text)
            note = f"{sh.name} (from {text}, degree {sh.degree})"
        else:
            raise DefinitionError(
                f"{who}: field {text!r} (--field) is neither a field shipped with gmuk "
                f"({', '.join(shipped.values())}) nor an existing file; give a shipped name "
                "or the path of a lunar ICGEM .gfc file"
            )
    if not math.isclose(sh.mu, MOON_MU, rel_tol=1e-3):
        raise DefinitionError(
            f"{who}: field {note} is not lunar (GM {sh.mu:.6g} m³/s², the Moon's is "
            f"{MOON_MU:.6g}); give a lunar field such as {DEFAULT_FIELD}"
        )
    return sh, note
