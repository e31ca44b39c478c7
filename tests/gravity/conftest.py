"""Fixtures of the gravity tests: the GRAIL and EGM2008 fields shipped with gmuk."""

from __future__ import annotations

import pytest

from gmuk.gravity import load_gfc

from .refs import EGM_FILE, GRAIL_FILE


@pytest.fixture(scope="session")
def grail():
    """GRGM660PRIM to degree 150 (Moon), read from the shipped file."""
    return load_gfc(GRAIL_FILE)


@pytest.fixture(scope="session")
def egm():
    """EGM2008 to degree 70 (Earth), read from the shipped file."""
    return load_gfc(EGM_FILE)
