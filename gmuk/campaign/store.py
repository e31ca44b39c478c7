"""A campaign's folder: manifest, results table, attempt log, trajectories.

::

    DIR/manifest.json          the campaign definition, seed, run count, gmuk version
    DIR/runs.parquet           compacted results: one row per finished run
    DIR/parts/part-*.parquet   results not yet compacted (one file per batch of finished runs)
    DIR/attempts.log           "start K PID" / "end K PID STATUS" lines written by the workers
    DIR/trajectories/run-K.npz each run's trajectory, when asked for

Every file is written to a temporary name and renamed into place, so each is whole or absent:
a campaign killed at any instant leaves a readable table. :func:`read_table` reads the
compacted table and the parts together, keeping one row per run (a crash between writing the
compacted table and removing the parts it absorbed leaves duplicates, which it drops).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk.errors import FileFormatError, GmukError
from gmuk.trajectory import atomic_write, write_text_atomic

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = ["MANIFEST", "TABLE", "ResultStore", "read_table"]

MANIFEST = "manifest.json"
TABLE = "runs.parquet"
PARTS = "parts"
ATTEMPTS = "attempts.log"
TRAJECTORIES = "trajectories"
FORMAT = "gmuk-campaign"
FORMAT_VERSION = 1


def _pyarrow() -> Any:
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - exercised only without the extra
        raise GmukError(
            "campaign results are stored with pyarrow; install it with pip install 'gmuk[campaign]'"
        ) from None
    return pa, pq


def _concat(tables: list[pa.Table]) -> pa.Table:
    pa, _ = _pyarrow()
    return pa.concat_tables(tables, promote_options="permissive")


def _unique_runs(table: pa.Table) -> pa.Table:
    """One row per run (the first), sorted by run."""
    if table.num_rows == 0:
        return table
    runs = np.asarray(table.column("run").to_numpy(zero_copy_only=False))
    _, first = np.unique(runs, return_index=True)
    return table.take(first)


def read_table(out: str | Path) -> pa.Table:
    """The results of the campaign in ``out``: one row per finished run, sorted by ``run``.

    Returns
    -------
    pyarrow.Table
        Columns ``run``, ``status`` ("success" or "failed"), ``error``, ``traceback``,
        ``wall_time_s``, ``worker``, ``trajectory`` (path relative to ``out`` or null), the
        parameters as ``p_NAME`` (vectors as ``p_NAME_1`` … ``p_NAME_3`` and their magnitude
        ``p_NAME_mag``) and the metrics as ``m_NAME``. ``.to_pandas()`` gives a DataFrame when
        pandas is installed.
    """
    _, pq = _pyarrow()
    out = Path(out)
    files = []
    if (out / TABLE).exists():
        files.append(out / TABLE)
    files += sorted((out / PARTS).glob("part-*.parquet")) if (out / PARTS).is_dir() else []
    tables = []
    for f in files:
        try:
            tables.append(pq.read_table(f))
        except Exception as exc:  # pyarrow raises its own ArrowInvalid, OSError
            raise FileFormatError(f"{f}: not a readable Parquet file ({exc})") from None
    if not tables:
        import pyarrow as pa

        return pa.table({"run": pa.array([], pa.int64()), "status": pa.array([], pa.string())})
    return _unique_runs(_concat(tables))


class ResultStore:
    """Writer of a campaign folder (module docstring)."""

    def __init__(self, out: str | Path) -> None:
        self.out = Path(out)
        self.parts = self.out / PARTS
        self._next = 0

    def create(self, manifest: dict[str, Any]) -> None:
        """Make the folder and write the manifest (refusing a folder that holds a campaign)."""
        if (self.out / MANIFEST).exists():
            raise GmukError(
                f"{self.out} already holds a campaign ({MANIFEST}); continue it with "
                f"--resume {self.out}, or choose another folder"
            )
        try:
            self.parts.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise GmukError(f"cannot make the campaign folder {self.out}: {exc}") from None
        write_text_atomic(self.out / MANIFEST, json.dumps(manifest, indent=2) + "\n")

    def manifest(self) -> dict[str, Any]:
        """The manifest of the campaign in the folder."""
        path = self.out / MANIFEST
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise GmukError(
                f"{self.out}: no campaign to resume or summarise ({path} is missing or "
                f"unreadable: {type(exc).__name__})"
            ) from None
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise FileFormatError(f"{path}: not a gmuk campaign manifest")
        if data.get("version") != FORMAT_VERSION:
            raise FileFormatError(
                f"{path}: campaign format version {data.get('version')!r}; this gmuk reads "
                f"{FORMAT_VERSION}"
            )
        self.parts.mkdir(parents=True, exist_ok=True)
        return data

    def finished(self) -> set[int]:
        """Indices of the runs already recorded."""
        table = read_table(self.out)
        return {int(k) for k in table.column("run").to_pylist()}

    def append(self, records: list[dict[str, Any]]) -> Path | None:
        """Write ``records`` as one new part file (atomically)."""
        if not records:
            return None
        pa, pq = _pyarrow()
        keys = list(dict.fromkeys(k for r in records for k in r))  # every column, first-seen order
        table = pa.table({k: [r.get(k) for r in records] for k in keys})
        while True:
            path = self.parts / f"part-{self._next:08d}-{os.getpid()}.parquet"
            self._next += 1
            if not path.exists():
                break
        with atomic_write(path) as tmp:
            pq.write_table(table, tmp)
        return path

    def compact(self) -> None:
        """Merge the parts into ``runs.parquet`` (written atomically), then remove them."""
        if not self.parts.is_dir():
            return
        parts = sorted(self.parts.glob("part-*.parquet"))
        if not parts:
            return
        _, pq = _pyarrow()
        table = read_table(self.out)
        with atomic_write(self.out / TABLE) as tmp:
            pq.write_table(table, tmp)
        for p in parts:
            p.unlink(missing_ok=True)

    def attempts(self) -> list[tuple[str, int]]:
        """("start" | "end", run) of every line of the attempt log, in order."""
        path = self.out / ATTEMPTS
        if not path.exists():
            return []
        out = []
        for line in path.read_text(encoding="utf-8").splitlines():
            words = line.split()
            if len(words) >= 2 and words[0] in ("start", "end") and words[1].isdigit():
                out.append((words[0], int(words[1])))
        return out


def log_attempt(out: str | Path | None, line: str) -> None:
    """Append ``line`` to the attempt log in ``out`` (one write of a short line with O_APPEND:
    whole lines from concurrent workers). A worker that cannot reach the folder (a remote
    Dask worker without the shared file system) logs nothing."""
    if out is None:
        return
    try:
        fd = os.open(Path(out) / ATTEMPTS, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    except OSError:
        return
    try:
        os.write(fd, (line + "\n").encode())
    finally:
        os.close(fd)
