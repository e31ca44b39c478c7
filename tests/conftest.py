"""Session set-up: the compiled step loop is ready before the first test.

``simulate(compiled=None)`` takes the compiled loop only once it is compiled on the machine
(gmuk.integrators._compiled); compiling it here, once, keeps every test's choice of loop the
same whatever ran before, and no test run starts a background compilation of its own.
"""

from __future__ import annotations

import os

import pytest

from gmuk.integrators import _compiled


@pytest.fixture(autouse=True, scope="session")
def _compiled_loop_ready():
    os.environ[_compiled.BACKGROUND_ENV] = "0"  # inherited by the CLI tests' processes too
    _compiled.compile_loop()
    yield
