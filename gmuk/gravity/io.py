"""Readers for gravity-field coefficient files: ICGEM ``.gfc`` and PDS SHADR ``.tab``.

Both return a :class:`~gmuk.gravity.SphericalHarmonicField` in SI units with the file's
metadata. Every problem in a file raises :class:`gmuk.errors.FileFormatError` naming the
file, the line and what was expected there; nothing is repaired silently.

Formats
-------
ICGEM ``.gfc`` (Barthelmes & Förste, *The ICGEM-format*, GFZ Potsdam, 2011): free text, then
``key value`` header lines up to a line starting with ``end_of_head``, then one line per
coefficient ``gfc n m C S [sigma_C sigma_S]``. Header keys: ``earth_gravity_constant`` or
``gravity_constant`` (GM, m³/s²), ``radius`` (m), ``max_degree`` (all three required),
``norm`` (``fully_normalized``, the default, or ``unnormalized``), ``tide_system``,
``errors`` (``no``, ``formal``, ``calibrated``, ``calibrated_and_formal``: whether the sigma
columns are present; inferred from the first coefficient line when absent), ``modelname``,
``product_type``. Numbers may use Fortran ``D``/``d`` exponents. Time-variable models
(``gfct``, ``trnd``, ``acos``, ``asin`` lines) are not supported.

PDS SHADR ``.tab`` (Spherical Harmonics ASCII Data Record, as distributed for GRAIL by the
PDS Geosciences Node): a first, comma-separated header record
``R_ref (km), GM (km³/s²), sigma GM (km³/s²), degree, order, normalization state,
reference longitude (deg), reference latitude (deg)`` (normalization state 1: fully
normalised, 0: unnormalized), then rows ``n, m, C, S, sigma_C, sigma_S``. Kilometres are
converted to metres.

In both formats, degrees 0 and 1 may be absent (then C̄₀₀ = 1 and the degree-1 terms are 0);
every coefficient of degree 2 up to the stated maximum must be present exactly once.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from gmuk.errors import DegreeError, FileFormatError
from gmuk.gravity.field import SphericalHarmonicField

__all__ = ["load_gfc", "load_shadr"]

_GM_KEYS = ("earth_gravity_constant", "gravity_constant")
_HEADER_KEYS = (
    *_GM_KEYS,
    "radius",
    "max_degree",
    "norm",
    "tide_system",
    "errors",
    "modelname",
    "product_type",
    "body",
    "format",
)
_ERRORS_WITH_SIGMAS = ("formal", "calibrated", "calibrated_and_formal")
_TIME_VARIABLE = ("gfct", "trnd", "acos", "asin", "dot")


def load_gfc(path: str | os.PathLike[str], *, degree: int | None = None) -> SphericalHarmonicField:
    """Read an ICGEM ``.gfc`` gravity-field file.

    Parameters
    ----------
    path : str or path-like
        The file.
    degree : int, optional
        Keep degrees ≤ ``degree`` only (the whole file is still checked).

    Returns
    -------
    SphericalHarmonicField
        ``mu`` and ``radius`` from the header (SI), 4π-normalised coefficients, sigmas when
        the file has them, ``name`` = ``modelname`` (or the file name), ``metadata`` with the
        file path, the format and every recognised header key.

    Raises
    ------
    FileFormatError
        Malformed file: missing ``end_of_head`` or a required header key, a number that does
        not parse, NaN or infinity, a wrong number of columns, a degree or order out of
        range, a duplicate or missing coefficient, a truncated file. Non-physical header
        values are refused too: GM or radius ≤ 0, a negative ``max_degree``. A
        ``max_degree`` whose arrays would exceed :data:`MAX_ARRAY_BYTES`, or that the file's
        lines cannot fill, is refused before anything is allocated for it.
    DegreeError
        ``degree`` above the file's ``max_degree``.
    FileNotFoundError
        No such file.

    Examples
    --------
    The lunar field shipped with gmuk (:func:`gmuk.gravity.field_path` gives its path):

    >>> from gmuk.gravity import field_path, load_gfc
    >>> moon = load_gfc(field_path("GRGM660PRIM"), degree=50)
    >>> moon.name, moon.degree, moon.mu, moon.radius
    ('GRGM660PRIM', 50, 4902799806931.69, 1738000.0)
    """
    p = _file(path, "load_gfc")
    lines = _read_lines(p)
    header: dict[str, tuple[str, int]] = {}
    end_line = 0
    for no, line in lines:
        tokens = line.split()
        if not tokens:
            continue
        key = tokens[0].lower()
        if key.startswith("end_of_head"):
            end_line = no
            break
        if key in _HEADER_KEYS and len(tokens) >= 2:
            if key in header and header[key][0] != tokens[1]:
                raise FileFormatError(
                    f"{p}: line {no}: header key {key!r} given twice with different values "
                    f"({header[key][0]!r} on line {header[key][1]}, {tokens[1]!r} here)"
                )
            header[key] = (tokens[1], no)
    if not end_line:
        raise FileFormatError(
            f"{p}: line {len(lines)}: no 'end_of_head' line; expected an ICGEM header ending "
            "with a line starting 'end_of_head'"
        )
    gm_keys = [k for k in _GM_KEYS if k in header]
    missing = [
        name
        for name, present in (
            ("earth_gravity_constant or gravity_constant", bool(gm_keys)),
            ("radius", "radius" in header),
            ("max_degree", "max_degree" in header),
        )
        if not present
    ]
    if missing:
        raise FileFormatError(
            f"{p}: line {end_line}: header ends without required key(s) {', '.join(missing)}"
        )
    gm_text, gm_line = header[gm_keys[0]]
    mu = _number(gm_text, p, gm_line, f"{gm_keys[0]} (GM, m³/s²)")
    radius = _number(header["radius"][0], p, header["radius"][1], "radius (m)")
    for val, name, no in ((mu, gm_keys[0], gm_line), (radius, "radius", header["radius"][1])):
        if not val > 0:
            raise FileFormatError(f"{p}: line {no}: {name} must be > 0; got {val!r}")
    nmax = _integer(header["max_degree"][0], p, header["max_degree"][1], "max_degree")
    if nmax < 0:
        raise FileFormatError(
            f"{p}: line {header['max_degree'][1]}: max_degree must be >= 0; got {nmax}"
        )
    norm_text = header.get("norm", ("fully_normalized", 0))[0].lower()
    if norm_text not in ("fully_normalized", "unnormalized"):
        raise FileFormatError(
            f"{p}: line {header['norm'][1]}: norm must be 'fully_normalized' or "
            f"'unnormalized'; got {norm_text!r}"
        )
    ncols: int | None = None
    if "errors" in header:
        err = header["errors"][0].lower()
        if err == "no":
            ncols = 5
        elif err in _ERRORS_WITH_SIGMAS:
            ncols = 7
        else:
            raise FileFormatError(
                f"{p}: line {header['errors'][1]}: errors must be one of 'no', "
                f"{', '.join(repr(e) for e in _ERRORS_WITH_SIGMAS)}; got {err!r}"
            )
    _check_degree_request(degree, nmax, p, "max_degree")
    _check_size(
        p,
        header["max_degree"][1],
        "max_degree",
        nmax,
        nmax,
        sum(1 for no, line in lines if no > end_line and line.strip()),
    )
    store = _Store(p, nmax, nmax)
    data_lines = ((no, line) for no, line in lines if no > end_line)
    for no, line in data_lines:
        tokens = line.split()
        if not tokens:
            continue
        key = tokens[0].lower()
        if key != "gfc":
            if key in _TIME_VARIABLE:
                raise FileFormatError(
                    f"{p}: line {no}: time-variable '{tokens[0]}' terms are not supported; "
                    "expected static 'gfc' coefficient lines"
                )
            raise FileFormatError(
                f"{p}: line {no}: expected a coefficient line 'gfc n m C S [sigma_C sigma_S]'; "
                f"got {line.strip()[:60]!r}"
            )
        if ncols is None:
            if len(tokens) not in (5, 7):
                raise FileFormatError(
                    f"{p}: line {no}: expected 5 columns (gfc n m C S) or 7 (with sigmas); "
                    f"got {len(tokens)}"
                )
            ncols = len(tokens)
        elif len(tokens) != ncols:
            raise FileFormatError(
                f"{p}: line {no}: expected {ncols} columns"
                f"{' (gfc n m C S sigma_C sigma_S)' if ncols == 7 else ' (gfc n m C S)'}, "
                f"as the header's 'errors' key or the first coefficient line says; "
                f"got {len(tokens)}"
            )
        store.add(no, tokens[1:])
    C, S, sC, sS = store.finish(lines[-1][0] if lines else 0, sigmas=ncols == 7)
    model = header.get("modelname", (p.stem, 0))[0]
    meta: dict[str, Any] = {
        "source": str(p),
        "format": "icgem",
        "header": {k: v for k, (v, _) in header.items()},
        "file_max_degree": nmax,
    }
    return SphericalHarmonicField(
        mu,
        radius,
        C,
        S,
        degree=degree,
        name=model,
        normalization="4pi" if norm_text == "fully_normalized" else "unnormalized",
        reference=f"{model}, ICGEM file {p.name}",
        tide_system=header.get("tide_system", ("unknown", 0))[0],
        sigma_C=sC,
        sigma_S=sS,
        metadata=meta,
    )


def load_shadr(
    path: str | os.PathLike[str], *, degree: int | None = None
) -> SphericalHarmonicField:
    """Read a PDS SHADR ``.tab`` gravity-field file (the format GRAIL fields are archived in).

    Parameters
    ----------
    path : str or path-like
        The file.
    degree : int, optional
        Keep degrees ≤ ``degree`` only (the whole file is still checked).

    Returns
    -------
    SphericalHarmonicField
        ``mu`` (km³/s² × 1e9) and ``radius`` (km × 1e3) in SI, 4π-normalised coefficients
        and their sigmas; ``metadata`` holds the file path, the order, the sigma of GM
        (m³/s²) and the reference longitude and latitude (degrees).

    Raises
    ------
    FileFormatError
        Malformed file: a header record without its eight fields, an unknown normalisation
        state, a number that does not parse, NaN or infinity, a wrong number of columns, a
        degree or order out of range, a duplicate or missing coefficient, a truncated file.
        Non-physical header values are refused too: R_ref or GM ≤ 0, a negative sigma GM,
        a reference latitude outside [−90°, 90°] or longitude outside [−180°, 360°], a
        negative degree or an order outside [0, degree]. A header degree whose arrays would
        exceed :data:`MAX_ARRAY_BYTES`, or that the file's lines cannot fill, is refused
        before anything is allocated for it.
    DegreeError
        ``degree`` above the file's degree.
    """
    p = _file(path, "load_shadr")
    lines = [(no, line) for no, line in _read_lines(p) if line.strip()]
    if not lines:
        raise FileFormatError(f"{p}: line 1: empty file; expected a SHADR header record")
    no, head = lines[0]
    fields = _csv(head)
    expected = (
        "R_ref (km), GM (km³/s²), sigma GM, degree, order, normalization state, "
        "reference longitude, reference latitude"
    )
    if len(fields) != 8:
        raise FileFormatError(
            f"{p}: line {no}: expected a header record of 8 comma-separated fields "
            f"({expected}); got {len(fields)}"
        )
    r_km = _number(fields[0], p, no, "R_ref (km)")
    gm_km = _number(fields[1], p, no, "GM (km³/s²)")
    sig_gm = _number(fields[2], p, no, "sigma GM (km³/s²)")
    nmax = _integer(fields[3], p, no, "degree")
    mmax = _integer(fields[4], p, no, "order")
    state = _integer(fields[5], p, no, "normalization state")
    ref_lon = _number(fields[6], p, no, "reference longitude (deg)")
    ref_lat = _number(fields[7], p, no, "reference latitude (deg)")
    if not (r_km > 0 and gm_km > 0):
        raise FileFormatError(
            f"{p}: line {no}: R_ref and GM must be > 0; got R_ref = {r_km!r} km, "
            f"GM = {gm_km!r} km³/s²"
        )
    if not sig_gm >= 0:
        raise FileFormatError(
            f"{p}: line {no}: sigma GM (field 3) must be >= 0 (a standard deviation); got "
            f"{sig_gm!r} km³/s²"
        )
    if not -90.0 <= ref_lat <= 90.0:
        raise FileFormatError(
            f"{p}: line {no}: reference latitude (field 8) must be within [-90, 90] deg; got "
            f"{ref_lat!r}"
        )
    if not -180.0 <= ref_lon <= 360.0:
        raise FileFormatError(
            f"{p}: line {no}: reference longitude (field 7) must be within [-180, 360] deg "
            f"(east, either convention); got {ref_lon!r}"
        )
    if nmax < 0 or not 0 <= mmax <= nmax:
        raise FileFormatError(
            f"{p}: line {no}: expected 0 <= order <= degree; got degree {nmax}, order {mmax}"
        )
    if state not in (0, 1):
        raise FileFormatError(
            f"{p}: line {no}: normalization state must be 1 (normalized) or 0 "
            f"(unnormalized); got {state}"
        )
    _check_degree_request(degree, nmax, p, "degree")
    _check_size(p, no, "degree", nmax, mmax, len(lines) - 1)
    store = _Store(p, nmax, mmax)
    ncols: int | None = None
    for no, line in lines[1:]:
        row = _csv(line)
        if ncols is None:
            if len(row) not in (4, 6):
                raise FileFormatError(
                    f"{p}: line {no}: expected 6 comma-separated columns "
                    f"(n, m, C, S, sigma C, sigma S) or 4 (n, m, C, S); got {len(row)}"
                )
            ncols = len(row)
        elif len(row) != ncols:
            raise FileFormatError(
                f"{p}: line {no}: expected {ncols} comma-separated columns, as on the first "
                f"coefficient row; got {len(row)}"
            )
        store.add(no, row)
    C, S, sC, sS = store.finish(lines[-1][0], sigmas=ncols == 6)
    meta: dict[str, Any] = {
        "source": str(p),
        "format": "shadr",
        "order": mmax,
        "sigma_mu": sig_gm * 1e9,
        "reference_longitude_deg": ref_lon,
        "reference_latitude_deg": ref_lat,
        "file_max_degree": nmax,
    }
    return SphericalHarmonicField(
        gm_km * 1e9,
        r_km * 1e3,
        C,
        S,
        degree=degree,
        name=p.stem,
        normalization="4pi" if state == 1 else "unnormalized",
        reference=f"PDS SHADR file {p.name}",
        tide_system="unknown",
        sigma_C=sC,
        sigma_S=sS,
        metadata=meta,
    )


class _Store:
    """Collects coefficients line by line, checking range, duplicates and values."""

    def __init__(self, path: Path, nmax: int, mmax: int) -> None:
        self.path = path
        self.nmax = nmax
        self.mmax = mmax
        k = nmax + 1
        self.C = np.zeros((k, k))
        self.S = np.zeros((k, k))
        self.sC = np.zeros((k, k))
        self.sS = np.zeros((k, k))
        self.seen = np.zeros((k, k), dtype=np.int64)  # line number of each entry, 0 = absent
        self.last: tuple[int, int] | None = None

    def add(self, no: int, fields: list[str]) -> None:
        p = self.path
        n = _integer(fields[0], p, no, "degree n")
        m = _integer(fields[1], p, no, "order m")
        if not (0 <= m <= n <= self.nmax and m <= self.mmax):
            raise FileFormatError(
                f"{p}: line {no}: degree/order ({n}, {m}) out of range; expected "
                f"0 <= m <= n <= {self.nmax}"
                f"{f' and m <= {self.mmax}' if self.mmax < self.nmax else ''} "
                "(the maximum degree/order in the header)"
            )
        if self.seen[n, m]:
            raise FileFormatError(
                f"{p}: line {no}: duplicate coefficient ({n}, {m}); first given on line "
                f"{self.seen[n, m]}"
            )
        names = ("C", "S", "sigma_C", "sigma_S")
        vals = [_number(t, p, no, f"{names[i]}[{n}, {m}]") for i, t in enumerate(fields[2:])]
        if m == 0 and vals[1] != 0.0:
            raise FileFormatError(
                f"{p}: line {no}: S[{n}, 0] must be 0 (no sine term at order 0); got {vals[1]!r}"
            )
        for i, v in enumerate(vals[2:]):
            if v < 0:
                raise FileFormatError(f"{p}: line {no}: {names[2 + i]} must be >= 0; got {v!r}")
        self.C[n, m], self.S[n, m] = vals[0], vals[1]
        if len(vals) == 4:
            self.sC[n, m], self.sS[n, m] = vals[2], vals[3]
        self.seen[n, m] = no
        self.last = (n, m)

    def finish(
        self, last_line: int, *, sigmas: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
        k = self.nmax + 1
        n_idx, m_idx = np.tril_indices(k)
        need = (n_idx >= 2) & (m_idx <= self.mmax)
        absent = need & (self.seen[n_idx, m_idx] == 0)
        if absent.any():
            first = (int(n_idx[absent][0]), int(m_idx[absent][0]))
            after = f" after ({self.last[0]}, {self.last[1]})" if self.last else ""
            raise FileFormatError(
                f"{self.path}: line {last_line}: file ends{after} with {int(absent.sum())} "
                f"coefficient(s) missing, the first ({first[0]}, {first[1]}); expected every "
                f"degree 2..{self.nmax} (order <= {self.mmax}), i.e. a truncated or incomplete "
                "file"
            )
        if not self.seen[0, 0]:
            self.C[0, 0] = 1.0
        if sigmas:
            return self.C, self.S, self.sC, self.sS
        return self.C, self.S, None, None


def _file(path: Any, who: str) -> Path:
    """``path`` as a Path to an existing regular file, or a clear error."""
    if not isinstance(path, (str, os.PathLike)):
        raise FileFormatError(f"{who}: path must be a str or os.PathLike; got {path!r}")
    p = Path(path)
    if not p.exists():
        raise FileFormatError(f"{p}: no such file")
    if not p.is_file():
        raise FileFormatError(f"{p}: not a regular file (a directory?)")
    return p


#: Up to this many bytes of coefficient arrays are allocated before the lines are read (a
#: truncated file then gets the reader's precise message naming the first missing term).
_SMALL_ALLOCATION = 64 * 2**20
#: Most bytes of coefficient arrays a reader allocates (5 arrays of (n + 1)² 8-byte numbers
#: for degree n: 4 GiB is degree 10 360, above every published gravity field's 2190 to
#: 5540). A header claiming more is refused before any allocation, whatever the file holds.
MAX_ARRAY_BYTES = 4 * 2**30


def _check_size(path: Path, no: int, key: str, nmax: int, mmax: int, lines: int) -> None:
    """Refuse a header degree whose arrays would exceed :data:`MAX_ARRAY_BYTES`, or that
    the file's own lines cannot fill, before allocating for it (5 arrays of (nmax + 1)²
    floats): a complete field of degree nmax (order ≤ mmax) has one line per coefficient of
    degrees 2..nmax (degrees 0 and 1 may be left out)."""
    size = 5 * 8 * (nmax + 1) ** 2
    if size <= _SMALL_ALLOCATION:
        return
    full = min(nmax, mmax)
    # Σ_{n=2}^{nmax} (min(n, mmax) + 1), in closed form (a hostile header may say 1e18)
    up_to_full = (full + 1) * (full + 2) // 2 - 3 if full >= 2 else 0
    needed = up_to_full + max(0, nmax - max(full, 1)) * (mmax + 1)
    if lines < needed:
        raise FileFormatError(
            f"{path}: line {no}: the header's {key} {_short(nmax)} needs at least "
            f"{_short(needed)} coefficient lines (degrees 2..{_short(nmax)}); the file has "
            f"{lines}: a wrong header or a truncated file"
        )
    if size > MAX_ARRAY_BYTES:  # e.g. a zonal field (order 0): few lines, (n + 1)² floats
        raise FileFormatError(
            f"{path}: line {no}: the header's {key} {_short(nmax)} needs {_short(size)} bytes "
            f"of coefficient arrays, above the limit of {MAX_ARRAY_BYTES} bytes "
            "(gmuk.gravity.io.MAX_ARRAY_BYTES); refused before allocating"
        )


def _short(value: int) -> str:
    """An integer for a message: as is below 10¹², else its order of magnitude (a hostile
    header's degree squared may have more digits than Python prints)."""
    if value < 10**12:
        return str(value)
    return f"about 1e{math.floor(math.log10(value))}"


def _read_lines(path: Path) -> list[tuple[int, str]]:
    """(line number, text) for every line; latin-1 never fails to decode."""
    with path.open("r", encoding="latin-1") as fh:
        return list(_numbered(fh))


def _numbered(fh: Any) -> Iterator[tuple[int, str]]:
    for i, line in enumerate(fh, start=1):
        yield i, line.rstrip("\r\n")


def _csv(line: str) -> list[str]:
    """Comma-separated fields, stripped (a single trailing comma is allowed)."""
    fields = [f.strip() for f in line.split(",")]
    if len(fields) > 1 and fields[-1] == "":
        fields.pop()
    return fields


def _number(text: str, path: Path, no: int, what: str) -> float:
    """A finite float (Fortran D exponents allowed) or FileFormatError."""
    try:
        v = float(text.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise FileFormatError(
            f"{path}: line {no}: expected a number for {what}; got {text!r}"
        ) from None
    if not math.isfinite(v):
        raise FileFormatError(f"{path}: line {no}: {what} must be finite; got {text!r}")
    return v


def _integer(text: str, path: Path, no: int, what: str) -> int:
    """An integer (an integral float such as '2.0' is accepted) or FileFormatError."""
    try:
        return int(text)
    except ValueError:
        pass
    v = _number(text, path, no, what)
    if v != int(v):
        raise FileFormatError(f"{path}: line {no}: expected an integer for {what}; got {text!r}")
    return int(v)


def _check_degree_request(degree: int | None, nmax: int, path: Path, key: str) -> None:
    if degree is None:
        return
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 0:
        raise DegreeError(f"degree must be an integer >= 0; got {degree!r}")
    if degree > nmax:
        raise DegreeError(
            f"{path}: asked for degree {degree}, but the file's {key} is {nmax} "
            f"(expected degree <= {nmax})"
        )
