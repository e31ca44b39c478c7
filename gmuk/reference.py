"""Reference (desired) motions of a rigid body, consumed by tracking constraints and controllers."""

from __future__ import annotations

import abc
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

__all__ = ["ReferenceState", "ReferenceTrajectory"]


class ReferenceState(NamedTuple):
    """A desired pose and its first two derivatives at one instant.

    Attributes
    ----------
    g : ndarray, shape (4, 4)
        Desired pose g_d = g_NB_d (m for the translation).
    V : ndarray, shape (6,)
        Desired body twist V_d = [ω_d; v_d] in the desired body frame (rad/s, m/s),
        so that ġ_d = g_d V_d^.
    V_dot : ndarray, shape (6,)
        Rate of the body-frame components of V_d (rad/s², m/s²).
    """

    g: NDArray[np.float64]
    V: NDArray[np.float64]
    V_dot: NDArray[np.float64]


class ReferenceTrajectory(abc.ABC):
    """A desired rigid-body motion t ↦ (g_d, V_d, V̇_d).

    Subclasses implement :meth:`evaluate`; they hold no simulation state (pure functions of t).
    """

    @abc.abstractmethod
    def evaluate(self, t: float) -> ReferenceState:
        """Desired pose, twist and acceleration at time ``t`` (s)."""
