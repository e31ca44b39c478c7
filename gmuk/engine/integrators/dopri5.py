"""DOPRI5: the Dormand–Prince 5(4) pair (Dormand & Prince, "A family of embedded Runge–Kutta
formulae", J. Comput. Appl. Math. 6 (1980), Table 2, RK5(4)7M)."""

from __future__ import annotations

import numpy as np

from gmuk.engine.integrators._base import RungeKuttaMethod

__all__ = ["DOPRI5"]

_A = np.zeros((7, 7))
_A[1, :1] = [1 / 5]
_A[2, :2] = [3 / 40, 9 / 40]
_A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
_A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
_A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
_A[6, :6] = [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
# The 7th stage is f(t + h, y₁) (first same as last): its row is the weight vector b.
_B_HAT = np.array([5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])


class DOPRI5(RungeKuttaMethod):
    """Dormand–Prince 5(4): order 5, 6 stages plus f(t + h, y₁), adaptive; steps exactly
    onto output times (no continuous extension)."""

    name = "DOPRI5"
    A = _A[:6, :6]
    b = _A[6, :6]
    c = np.array([0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1])
    order = 5
    E = _A[6] - _B_HAT
    fsal = True
