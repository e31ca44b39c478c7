"""DOP853: Dormand–Prince 8(5,3) with a continuous extension of order 7 and control of its
error (Hairer, Nørsett & Wanner, *Solving ODEs I*, 2nd ed., §II.10; coefficients in
:mod:`gmuk.engine.integrators._dop853_tableau`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import numpy as np

from gmuk._validation import FloatArray
from gmuk.engine.integrators import _dop853_tableau as _tab
from gmuk.engine.integrators._base import RHS, RungeKuttaMethod

__all__ = ["DOP853"]


class _Interpolant:
    """u(s) = y₀ + s(F₀ + (1−s)(F₁ + s(F₂ + …))), s = (t − t₀)/h: DOP853's dense output."""

    def __init__(self, t: float, h: float, y0: FloatArray, F: FloatArray) -> None:
        self.t, self.h, self.Y0, self.F = t, h, y0, F

    def __call__(self, tt: float) -> FloatArray:
        s = (tt - self.t) / self.h
        out = np.zeros(self.Y0.size)
        for i, Fi in enumerate(self.F[::-1]):
            out = (out + Fi) * (s if i % 2 == 0 else 1.0 - s)
        return self.Y0 + out

    def value_and_derivative(self, s: float) -> tuple[FloatArray, FloatArray]:
        """u(s) and du/ds."""
        out = np.zeros(self.Y0.size)
        dout = np.zeros(self.Y0.size)
        for i, Fi in enumerate(self.F[::-1]):
            q = out + Fi
            if i % 2 == 0:
                out, dout = q * s, dout * s + q
            else:
                out, dout = q * (1.0 - s), dout * (1.0 - s) - q
        return self.Y0 + out, dout


class DOP853(RungeKuttaMethod):
    """Dormand–Prince 8(5,3): order 8, 12 stages plus f(t + h, y₁), adaptive, with a
    continuous extension of order 7 (3 more evaluations per step that has outputs inside).

    The error estimate combines the embedded formulas of orders 5 and 3 as in Hairer's
    ``dop853.f``: ``err = |h| ‖e₅‖² / √(‖e₅‖² + w ‖e₃‖²)`` (weighted RMS norms), with
    w = :attr:`e3_weight` = 0.01. A step with output times inside it is accepted only if the
    continuous extension also meets the tolerance, estimated from its defect (one more
    evaluation, :meth:`interpolant_error`): Runge–Kutta–Munthe-Kaas step ends are often far
    more accurate than the extension between them, which the step-end estimate cannot see.
    """

    name = "DOP853"
    A = _tab.A[: _tab.N_STAGES, : _tab.N_STAGES]
    b = _tab.B
    c = _tab.C[: _tab.N_STAGES]
    order = 8
    E = _tab.E5
    fsal = True
    dense_output = True

    #: Weights of the order-3 error estimate (over the 12 stages and f(t + h, y₁)).
    E3: ClassVar[FloatArray] = _tab.E3
    #: Stages 13–15 of the continuous extension: full matrix and nodes, and its coefficients.
    A_extended: ClassVar[FloatArray] = _tab.A
    c_extended: ClassVar[FloatArray] = _tab.C
    D: ClassVar[FloatArray] = _tab.D
    #: Where the extension's defect is sampled (fraction of the step), and the factor taking
    #: its norm to a bound on the extension's error (see :meth:`interpolant_error`).
    defect_node: ClassVar[float] = 0.95
    defect_gain: ClassVar[float] = 0.18
    #: Weight of the order-3 estimate in the combined error (Hairer's ``dop853.f``).
    e3_weight: ClassVar[float] = 0.01

    def error_norm(self, K: FloatArray, h: float, scale: FloatArray) -> float:
        E5 = self.E
        assert E5 is not None
        e5 = (K.T @ E5) / scale
        e3 = (K.T @ self.E3) / scale
        n5, n3 = float(e5 @ e5), float(e3 @ e3)
        if n5 == 0.0 and n3 == 0.0:
            return 0.0
        return float(abs(h) * n5 / np.sqrt((n5 + self.e3_weight * n3) * scale.size))

    def interpolant(
        self, f: RHS, t: float, y: FloatArray, h: float, K: FloatArray, y1: FloatArray
    ) -> _Interpolant:
        """DOP853's continuous extension on [t, t + h] (three more evaluations of ``f``)."""
        n, n_ext = _tab.N_STAGES, _tab.N_STAGES_EXTENDED
        A, C = self.A_extended, self.c_extended
        Kx = np.empty((n_ext, y.size))
        Kx[: n + 1] = K[: n + 1]
        for i in range(n + 1, n_ext):
            Kx[i] = f(t + C[i] * h, y + h * (A[i, :i] @ Kx[:i]))
        dy = y1 - y
        F = np.empty((_tab.INTERPOLATOR_POWER, y.size))
        F[0] = dy
        F[1] = h * K[0] - dy
        F[2] = 2.0 * dy - h * (K[n] + K[0])
        F[3:] = h * (self.D @ Kx)
        return _Interpolant(t, h, y, F)

    def interpolant_error(
        self, f: RHS, interpolant: Callable[[float], FloatArray], scale: FloatArray
    ) -> float:
        """Estimated maximum error of the continuous extension over the step, in the norm
        of the step error (≤ 1: within tolerance). One evaluation of ``f``.

        The extension u(s), s ∈ [0, 1], has order 7: its error is
        e(s) = h⁸ Σ_τ e_τ(s) F(τ)(y₀) + O(h⁹) over the trees τ of order 8, and its defect
        δ(s) = h f(u(s)) − u′(s) = e′(s) + O(h e). The defect is sampled at s* = 0.95, near
        where the e_τ′ peak. For every one of the 115 trees, ``max|e_τ| / |e_τ′(s*)|`` lies
        between 0.112 and 0.179 with DOP853's coefficients, so 0.18 ‖δ(s*)‖ bounds the
        error of any single elementary differential. (Sampling the defect is the idea of
        defect control: W. H. Enright, "A new error-control for initial value solvers",
        Appl. Math. Comput. 31 (1989); here the defect serves as an error estimate.)
        """
        assert isinstance(interpolant, _Interpolant)
        s_star = self.defect_node
        u, du = interpolant.value_and_derivative(s_star)
        fu = f(interpolant.t + s_star * interpolant.h, u)
        dev = (interpolant.h * fu - du) / scale
        return self.defect_gain * float(np.sqrt(dev @ dev / scale.size))
