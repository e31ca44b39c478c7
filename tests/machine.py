"""What the tests need from the machine beyond the README's set-up, and how a test says so.

Headless Chromium (Debian's ``chromium``) is outside pip: a test that needs it skips with the
command that installs it, or fails under ``GMUK_REQUIRE_CHROMIUM=1`` (``.ci/run`` sets it). The
repository's plugins are installed by the README's first command: a test that needs one and
does not find it fails with the ``pip install`` command.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Mapping
from importlib import metadata

import pytest

#: The command that installs headless Chromium on Debian (what .ci/run runs).
CHROMIUM_INSTALL = "apt-get install -y --no-install-recommends chromium"


def find_chromium() -> str | None:
    """The path of a headless-capable Chromium on PATH, or None."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


def chromium_or_skip(path: str | None, env: Mapping[str, str] = os.environ) -> str:
    """``path`` if Chromium was found; else skip naming the install command, or fail under
    ``GMUK_REQUIRE_CHROMIUM=1`` (CI)."""
    if path:
        return path
    reason = f"headless Chromium is not installed; install it with: {CHROMIUM_INSTALL}"
    if env.get("GMUK_REQUIRE_CHROMIUM") == "1":
        pytest.fail(f"GMUK_REQUIRE_CHROMIUM=1 (CI) but {reason}", pytrace=False)
    pytest.skip(reason)


def require_distribution(name: str, path: str) -> None:
    """Fail, saying what is missing and how to install it, unless the distribution ``name``
    (a plugin of this repository at ``path``) is installed."""
    try:
        metadata.distribution(name)
    except metadata.PackageNotFoundError:
        pytest.fail(
            f"the plugin {name} is not installed; install it with: pip install -e {path} "
            "(the README's first set-up command installs it)",
            pytrace=False,
        )
