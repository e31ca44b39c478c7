"""Session set-up and what the tests need from the machine.

The compiled step loop is compiled (or loaded from numba's cache) before the first test, so that
the first test that simulates does not carry its compile time. Under pytest-xdist each worker
runs this; the loop's compile lock (:func:`gmuk.engine.integrators._compiled.compile_loop`) lets
one worker compile while the other waits and then loads what it compiled.

Headless Chromium (Debian's ``chromium``, outside pip) is the one thing the tests need that the
README's set-up cannot install: the :func:`chromium` fixture skips a test with the command that
installs it, and fails it instead when ``GMUK_REQUIRE_CHROMIUM=1`` (``.ci/run`` sets it, so CI
never passes without running those tests). The plugins the tests use are installed by the
README's first command; :func:`machine.require_distribution` fails a test that needs a missing one
with the ``pip install`` command that installs it.
"""

from __future__ import annotations

import os

import pytest
from machine import chromium_or_skip, find_chromium

from gmuk.engine.integrators import _compiled


@pytest.fixture(autouse=True, scope="session")
def _compiled_loop_ready():
    _compiled.compile_loop()
    yield


@pytest.fixture(scope="session")
def chromium() -> str:
    """The Chromium executable (see the module's docstring: skips or fails without one)."""
    return chromium_or_skip(find_chromium(), os.environ)
