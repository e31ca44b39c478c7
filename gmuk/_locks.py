"""Folders owned by one live process at a time: ``gmuk run``'s output folder and a campaign's
folder.

:func:`folder_lock` takes an exclusive :func:`fcntl.flock` lock on ``FOLDER/.gmuk-lock`` and
writes into that file who holds it (process id, host name, start time, what for). The lock
belongs to the open file, which belongs to the process: the kernel releases it when the
process ends, however it ends (SIGKILL, a crash, a power cut of the machine), so a killed run
never blocks anyone. A lock is never judged by the file's age or by whether the file exists:
a file left behind by a killed process is not a lock, and the next process takes it over. A
second process that asks for a held lock is refused at once with a
:class:`FolderInUseError` naming the holder; nothing waits.

The lock file is removed when the lock is released. Taking a lock checks, after locking, that
the file locked is still the one at the path (an other process may have just removed it on
release), and tries again if not.

Limits: ``flock`` locks are advisory (they stop other gmuk processes, not other programs);
on a network file system that does not support them, or on a platform without
:mod:`fcntl`, the folder is used unlocked with a :class:`~gmuk.errors.GmukWarning`. Worker
processes started by ``fork`` would share the lock; gmuk starts its workers with ``spawn``
and opens the lock file non-inheritable.
"""

from __future__ import annotations

import errno
import json
import os
import socket
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from gmuk.errors import GmukError, GmukWarning

__all__ = ["LOCK_NAME", "FolderInUseError", "folder_lock", "holder"]

#: The lock file's name inside the folder it guards.
LOCK_NAME = ".gmuk-lock"

#: Times a lock is taken again when the file locked was removed meanwhile (see module doc).
_ATTEMPTS = 20


class FolderInUseError(GmukError, RuntimeError):
    """The folder is in use by another live gmuk process (run or campaign)."""


def holder(folder: str | Path) -> dict[str, Any] | None:
    """What the lock file in ``folder`` says about its holder (``pid``, ``host``,
    ``started_utc``, ``what``), or None when there is no readable record. The record says who
    took the lock last; whether it is held is only known by trying to take it."""
    try:
        data = json.loads((Path(folder) / LOCK_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _describe(info: dict[str, Any] | None) -> str:
    if not info:
        return "a process that has not written its name yet"
    what = f"{info.get('what')} " if info.get("what") else ""
    return (
        f"{what}process {info.get('pid', '?')} on host {info.get('host', '?')}, started "
        f"{info.get('started_utc', '?')}"
    )


@contextmanager
def folder_lock(folder: str | Path, what: str, *, hint: str = "") -> Iterator[Path]:
    """Hold ``folder``'s lock inside the ``with`` block (the folder must exist).

    Parameters
    ----------
    folder : str or Path
        The folder to own.
    what : str
        What owns it, for the holder record and messages (e.g. ``"gmuk run fcei"``).
    hint : str
        Advice appended to the refusal (e.g. "choose another --out").

    Yields
    ------
    Path
        The lock file.

    Raises
    ------
    FolderInUseError
        Another live process holds the folder's lock; the message names it (pid, host, start
        time).
    """
    folder = Path(folder)
    path = folder / LOCK_NAME
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        warnings.warn(
            f"{folder}: cannot lock the folder on this platform (no fcntl); two gmuk processes "
            "writing into it at once are not prevented",
            GmukWarning,
            stacklevel=3,
        )
        yield path
        return
    fd = _acquire(fcntl, folder, path, what, hint)
    if fd is None:
        yield path
        return
    try:
        yield path
    finally:
        # remove the file while still holding the lock, then let go: a process that opened the
        # old file meanwhile sees that it is no longer the one at the path and tries again
        try:
            path.unlink(missing_ok=True)
        except OSError:
            pass
        os.close(fd)  # releases the flock


def _acquire(fcntl: Any, folder: Path, path: Path, what: str, hint: str) -> int | None:
    """The open, locked descriptor of the lock file (None: locking unsupported here)."""
    for _ in range(_ATTEMPTS):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise GmukError(f"{folder}: cannot make the lock file {path.name}: {exc}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                more = f"; {hint}" if hint else ""
                raise FolderInUseError(
                    f"{folder} is in use by another gmuk process ({_describe(holder(folder))}); "
                    f"two processes writing into one folder would lose data{more}"
                ) from None
            warnings.warn(
                f"{folder}: cannot lock the folder ({exc.strerror}); two gmuk processes writing "
                "into it at once are not prevented",
                GmukWarning,
                stacklevel=4,
            )
            return None
        try:
            same = os.fstat(fd).st_ino == os.stat(path).st_ino
        except FileNotFoundError:
            same = False
        if not same:  # the holder removed the file between our open and our lock
            os.close(fd)
            continue
        record = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "started_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "what": what,
        }
        os.ftruncate(fd, 0)
        os.write(fd, (json.dumps(record) + "\n").encode())
        return fd
    raise FolderInUseError(  # pragma: no cover - a folder locked and released in a tight loop
        f"{folder}: could not take its lock in {_ATTEMPTS} attempts (other processes keep "
        "taking and releasing it)"
    )
