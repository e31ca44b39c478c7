"""Where the robot descriptions of the ``example-robot-data`` package are.

``pip install example-robot-data`` (or ``pip install "gmuk[robots]"``) installs the URDFs
that the robotics community shares (Pinocchio's examples and benchmarks); it is not a
dependency of gmuk. :func:`example_robot_data` finds them in the installed distribution.
"""

from __future__ import annotations

import importlib.metadata as metadata
from functools import cache
from pathlib import Path

from gmuk.errors import MissingDependencyError

__all__ = ["example_robot_data", "example_robot_urdfs"]

_SHARE = "share/example-robot-data/robots"


@cache
def _robots_dir() -> Path:
    try:
        dist = metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        raise MissingDependencyError(
            "the robot descriptions need the package example-robot-data: "
            'pip install example-robot-data (or pip install "gmuk[robots]")'
        ) from None
    for f in dist.files or ():
        text = str(f).replace("\\", "/")
        if _SHARE in text:
            root = text[: text.index(_SHARE) + len(_SHARE)]
            return Path(str(dist.locate_file(root)))
    raise MissingDependencyError(
        f"example-robot-data {dist.version} is installed but holds no {_SHARE} folder"
    )


def example_robot_data(relative: str = "") -> Path:
    """The path of ``relative`` (e.g. ``"panda_description/urdf/panda.urdf"``) in
    example-robot-data's ``robots`` folder; the folder itself for ``""``.

    Raises
    ------
    MissingDependencyError
        When example-robot-data is not installed.
    FileNotFoundError
        When it holds no such file.
    """
    path = _robots_dir() / relative
    if not path.exists():
        raise FileNotFoundError(f"example-robot-data has no {relative!r} (looked in {path})")
    return path


def example_robot_urdfs() -> list[Path]:
    """Every URDF file example-robot-data ships, sorted."""
    return sorted(_robots_dir().rglob("*.urdf"))
