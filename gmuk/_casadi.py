"""CasADi for the parts' symbolic forms, imported only when a form is asked for.

The symbolic forms sit on the parts' classes (``casadi_force``, ``casadi_wrench`` …; the
protocol is in :mod:`gmuk.optimize.parts`); they reach CasADi through :func:`casadi`, so that
gmuk imports without it and says how to install it when it is needed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmuk.errors import MissingDependencyError

__all__ = ["casadi", "column"]


def casadi() -> Any:
    """The ``casadi`` module, or a :class:`~gmuk.errors.MissingDependencyError` saying how to
    install it."""
    try:
        import casadi as ca
    except ImportError:
        raise MissingDependencyError(
            'gmuk.optimize needs CasADi: pip install "gmuk[optimize]" (or pip install casadi)'
        ) from None
    return ca


def column(x: Any) -> Any:
    """Numbers as a CasADi ``DM`` column (n×1)."""
    return casadi().DM(np.asarray(x, dtype=float).reshape(-1, 1))
