"""RK4: the classical Runge–Kutta method of order 4 with a fixed step."""

from __future__ import annotations

import numpy as np

from gmuk.engine.integrators._base import RungeKuttaMethod

__all__ = ["RK4"]


class RK4(RungeKuttaMethod):
    """Classical Runge–Kutta of order 4 (Kutta 1901), fixed step: ``simulate`` needs
    ``step=...``; steps exactly onto output times."""

    name = "RK4"
    A = np.array([[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1.0, 0]])
    b = np.array([1, 2, 2, 1]) / 6
    c = np.array([0, 0.5, 0.5, 1])
    order = 4
