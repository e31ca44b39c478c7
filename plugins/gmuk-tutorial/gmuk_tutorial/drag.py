"""A linear drag force model: the tutorial's example of a force-model plugin."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from gmuk import ForceModel
from gmuk.errors import DefinitionError


class LinearDrag(ForceModel):
    """Drag ``f = −c v`` against the velocity of each body's origin (no torque).

    Parameters
    ----------
    coefficient : float
        c (N·s/m), finite and ≥ 0.
    bodies : sequence of Body or str, optional
        Bodies it acts on (default: every rigid body and point mass).
    modeled : bool
        Whether the constraint solve knows it (default True).

    Notes
    -----
    A body of mass m starting at speed v₀ with no other force slows as
    ``v(t) = v₀ exp(−c t / m)``: the tutorial checks the plugin against that.
    """

    def __init__(
        self,
        coefficient: float,
        *,
        bodies: Sequence[Any] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        if (
            isinstance(coefficient, bool)
            or not (isinstance(coefficient, (int, float)) and math.isfinite(coefficient))
            or coefficient < 0
        ):
            raise DefinitionError(
                f"LinearDrag coefficient must be a finite number >= 0 (N·s/m); got {coefficient!r}"
            )
        self.coefficient = float(coefficient)

    def wrench(self, t: float, g_NB: np.ndarray, V_B: np.ndarray, body: Any) -> np.ndarray:
        """[L; f] (N·m, N) in the body frame: no torque, ``f = −c v_B``."""
        return np.concatenate([np.zeros(3), -self.coefficient * V_B[3:]])

    def force(self, t: float, r_N: np.ndarray, v_N: np.ndarray, body: Any) -> np.ndarray:
        """f_N (N) on a point mass: ``−c v_N``."""
        return -self.coefficient * v_N
