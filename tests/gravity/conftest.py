"""Fixtures of the gravity tests: the shared GRAIL and EGM2008 files (skipped if absent)."""

from __future__ import annotations

import pytest

from gmuk.gravity import load_gfc

from .refs import DATA_DIR, EGM_FILE, GRAIL_FILE


def _need(path):
    if not DATA_DIR.is_dir():
        pytest.skip(f"shared gravity data folder {DATA_DIR.resolve()} is absent")
    if not path.is_file():
        pytest.skip(f"shared gravity file {path.resolve()} is absent")


@pytest.fixture(scope="session")
def grail():
    """GRGM660PRIM to degree 150 (Moon), from the shared data folder."""
    _need(GRAIL_FILE)
    return load_gfc(GRAIL_FILE)


@pytest.fixture(scope="session")
def egm():
    """EGM2008 to degree 70 (Earth), from the shared data folder."""
    _need(EGM_FILE)
    return load_gfc(EGM_FILE)
