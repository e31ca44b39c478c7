"""dask, distributed and pyarrow are imported only when a campaign runs or is read."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_importing_gmuk_and_gmuk_campaign_imports_neither_dask_nor_pyarrow():
    code = (
        "import sys, gmuk, gmuk.campaign\n"
        "heavy = [m for m in sys.modules if m.split('.')[0] in "
        "('dask', 'distributed', 'pyarrow', 'matplotlib')]\n"
        "print(','.join(sorted(heavy)))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert done.stdout.strip() == ""
