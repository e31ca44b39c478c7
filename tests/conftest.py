"""Session set-up: the compiled step loop is compiled (or loaded from numba's cache) before
the first test, so that the first test that simulates does not carry its compile time."""

from __future__ import annotations

import pytest

from gmuk.engine.integrators import _compiled


@pytest.fixture(autouse=True, scope="session")
def _compiled_loop_ready():
    _compiled.compile_loop()
    yield
