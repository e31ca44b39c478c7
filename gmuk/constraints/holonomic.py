"""Holonomic φ(q, t) = 0 and nonholonomic ψ(q, ν, t) = 0 constraints written as residuals.

The user writes the residual; gmuk derives A and b of ``A ν̇ = b`` (McCann 2020, Eq. 1)
automatically by differentiation along the group, unless the subclass overrides
:meth:`HolonomicConstraint.jacobian` / :meth:`HolonomicConstraint.bias` with analytic forms.

Configurations ``q`` are given per body, in the order of ``self.bodies``: a pose g_NB
(4, 4) for a rigid body, a position r_N (3,) for a point mass, a (1,) array for a slack
coordinate. Velocities ``nu`` likewise: V_B (6,), v_N (3,), ṡ (1,).

Differentiation
---------------
Rigid-body directions are body-frame (right) perturbations ``g exp(ε eₖ^)``, matching the
body twist V = [ω; v] of the columns of A. Derivatives are fifth-order-accurate five-point
central differences. With ``h(τ) = φ(q ⊕ τν, t + τ)`` (each rigid body moved along
``g exp(τ V^)``, Euclidean ones along ``x + τ ẋ``):

* ``A = ∂φ/∂q`` (one stencil per degree of freedom),
* ``φ̇ = h'(0)``, and ``b = −h''(0)``, because the true motion ``g exp(τV + τ²V̇/2 + …)``
  differs from the path only by the ``A ν̇`` term at second order.

Steps: rotations 1e-3 rad, translations 1e-3·``fd_length`` m, and along the path τ such that
no coordinate moves more than 2e-3 (in rad, or in units of ``fd_length``) and
τ ≤ 2e-3·``fd_time``. Set ``fd_length`` (m) and ``fd_time`` (s) to the scales on which the
residual varies; agreement with analytic rows is typically 1e-9 relative (tested ≤ 1e-7).
The rows then carry round-off noise of about eps/τ² ≈ 1e-10 of the residual's scale: integrate
with ``rtol`` ≳ 1e-10 (tighter tolerances make the step controller chase the noise), and
expect an unstabilised constraint to drift like ½·1e-10·t² (use :class:`Baumgarte`, or
override :meth:`jacobian` and :meth:`bias` with exact forms, for long or very tight runs).
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.errors import ConstraintError
from gmuk.lie import se3

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["HolonomicConstraint", "NonholonomicConstraint"]

Config = tuple[FloatArray, ...]

_JAC_STEP = 1e-3
_PATH_STEP = 2e-3


def body_configs(
    state: State, bodies: Sequence[Body | str]
) -> tuple[Config, Config, tuple[str, ...]]:
    """Per-body configurations, velocities and kinds at ``state``."""
    qs: list[FloatArray] = []
    vs: list[FloatArray] = []
    kinds: list[str] = []
    for b in bodies:
        s = state.layout.slot(b)
        kinds.append(s.kind)
        if s.kind == "rigid":
            qs.append(state.g[s.index])
            vs.append(state.V[s.index])
        else:
            qs.append(state.x[s.index : s.index + s.dof])
            vs.append(state.xdot[s.index : s.index + s.dof])
    return tuple(qs), tuple(vs), tuple(kinds)


def _move(q: FloatArray, kind: str, delta: FloatArray) -> FloatArray:
    """q ⊕ δ: right perturbation on SE(3), addition otherwise."""
    if kind == "rigid":
        return q @ se3._exp(delta)
    return q + delta


def _along(q: Config, nu: Config, kinds: tuple[str, ...], tau: float) -> Config:
    """Every body moved by τ along its velocity: ``q ⊕ τν``."""
    return tuple(_move(qi, k, tau * vi) for qi, vi, k in zip(q, nu, kinds, strict=True))


def _kinds_of(q: Config) -> tuple[str, ...]:
    """Body kinds from configuration shapes: a (4, 4) pose is rigid, anything else Euclidean."""
    return tuple("rigid" if qi.shape == (4, 4) else "euclid" for qi in q)


def _stencil1(f: Callable[[float], FloatArray], h: float) -> FloatArray:
    return (f(-2 * h) - 8.0 * f(-h) + 8.0 * f(h) - f(2 * h)) / (12.0 * h)


class _Differentiable(Constraint):
    """Shared construction and finite-difference machinery for residual-based constraints."""

    fd_length: float
    fd_time: float
    baumgarte: Baumgarte | None

    def __init__(
        self,
        bodies: Sequence[Body | str],
        *,
        baumgarte: Baumgarte | None = None,
        fd_length: float = 1.0,
        fd_time: float = 1.0,
        name: str | None = None,
    ) -> None:
        super().__init__(bodies, name=name)
        baumgarte, fd_length, fd_time = self._keywords(
            baumgarte=baumgarte, fd_length=fd_length, fd_time=fd_time
        )
        if not (fd_length > 0 and fd_time > 0):
            raise ConstraintError(f"fd_length and fd_time must be > 0; got {fd_length}, {fd_time}")
        self.baumgarte = baumgarte
        self.fd_length = float(fd_length)
        self.fd_time = float(fd_time)

    def _steps(self, kind: str, dof: int) -> FloatArray:
        if kind == "rigid":
            return np.array([_JAC_STEP] * 3 + [_JAC_STEP * self.fd_length] * 3)
        return np.full(dof, _JAC_STEP * self.fd_length)

    def _path_step(self, vs: Config, kinds: tuple[str, ...]) -> float:
        rate = 1.0 / self.fd_time
        for v, kind in zip(vs, kinds, strict=True):
            if kind == "rigid":
                rate = max(
                    rate, float(np.abs(v[:3]).max()), float(np.abs(v[3:]).max()) / self.fd_length
                )
            elif v.size:
                rate = max(rate, float(np.abs(v).max()) / self.fd_length)
        return _PATH_STEP / rate

    def _jacobian_fd(
        self, fun: Callable[[Config], FloatArray], qs: Config, kinds: tuple[str, ...]
    ) -> FloatArray:
        cols: list[FloatArray] = []
        for i, (q, kind) in enumerate(zip(qs, kinds, strict=True)):
            dof = 6 if kind == "rigid" else q.size
            steps = self._steps(kind, dof)
            for k in range(dof):
                e = np.zeros(dof)
                e[k] = 1.0

                def f(
                    eps: float, i: int = i, e: FloatArray = e, q: FloatArray = q, kind: str = kind
                ) -> FloatArray:
                    moved = list(qs)
                    moved[i] = _move(q, kind, eps * e)
                    return np.asarray(fun(tuple(moved)), dtype=float)

                cols.append(_stencil1(f, float(steps[k])))
        return np.stack(cols, axis=-1)

    def _path_fd(
        self, fun: Callable[[Config, float], Any], q: Config, nu: Config, t: float
    ) -> tuple[FloatArray, FloatArray]:
        """First and second derivatives of ``fun(q ⊕ τν, t + τ)`` at τ = 0."""
        kinds = _kinds_of(q)
        tau = self._path_step(nu, kinds)

        def h(s: float) -> FloatArray:
            return np.asarray(fun(_along(q, nu, kinds, s), t + s), dtype=float)

        hm2, hm1, h0, hp1, hp2 = h(-2 * tau), h(-tau), h(0.0), h(tau), h(2 * tau)
        d1 = (hm2 - 8.0 * hm1 + 8.0 * hp1 - hp2) / (12.0 * tau)
        d2 = (-hm2 + 16.0 * hm1 - 30.0 * h0 + 16.0 * hp1 - hp2) / (12.0 * tau * tau)
        return d1, d2

    @staticmethod
    def _velocity_jacobian_fd(
        fun: Callable[[Config, Config, float], Any], q: Config, nu: Config, t: float
    ) -> FloatArray:
        """∂fun/∂ν by central differences in each velocity component."""
        cols: list[FloatArray] = []
        for i, v in enumerate(nu):
            for k in range(v.size):
                step = _JAC_STEP * max(1.0, abs(float(v[k])))

                def f(eps: float, i: int = i, k: int = k, v: FloatArray = v) -> FloatArray:
                    moved = list(nu)
                    vv = v.copy()
                    vv[k] += eps
                    moved[i] = vv
                    return np.asarray(fun(q, tuple(moved), t), dtype=float)

                cols.append(_stencil1(f, step))
        return np.stack(cols, axis=-1)

    def _velocity_bias_fd(
        self, fun: Callable[[Config, Config, float], Any], q: Config, nu: Config, t: float
    ) -> FloatArray:
        """−(d/dτ) fun(q ⊕ τν, ν, t + τ) at τ = 0: the rate of ``fun`` with ν held."""
        kinds = _kinds_of(q)
        tau = self._path_step(nu, kinds)

        def h(s: float) -> FloatArray:
            return np.asarray(fun(_along(q, nu, kinds, s), nu, t + s), dtype=float)

        return -_stencil1(h, tau)


class HolonomicConstraint(_Differentiable):
    """A holonomic constraint ``φ(q, t) = 0`` given by its residual.

    Subclasses implement :meth:`residual`; optionally :meth:`jacobian` and :meth:`bias`
    with analytic forms (then no finite differences are taken).

    Parameters
    ----------
    bodies : sequence of Body or str
    baumgarte : Baumgarte, optional
        Stabilisation ``φ̈ + αφ̇ + βφ = 0`` (off by default).
    fd_length : float
        Length scale (m) on which φ varies, for the finite-difference steps (default 1).
    fd_time : float
        Time scale (s) on which φ varies explicitly in t (default 1).
    name : str, optional

    Examples
    --------
    A fixed distance d between points p_a, p_b (body frames) of rigid bodies a and b:

    >>> class Distance(HolonomicConstraint):
    ...     def __init__(self, a, b, p_a, p_b, d):
    ...         super().__init__([a, b])
    ...         self.p_a, self.p_b, self.d = p_a, p_b, d
    ...     def residual(self, q, t):
    ...         g_a, g_b = q
    ...         x_a = g_a[:3, :3] @ self.p_a + g_a[:3, 3]
    ...         x_b = g_b[:3, :3] @ self.p_b + g_b[:3, 3]
    ...         return np.array([np.dot(x_a - x_b, x_a - x_b) - self.d**2])
    """

    _numeric_methods = ("rows", "residual")

    @abc.abstractmethod
    def residual(self, q: Config, t: float) -> Any:
        """φ(q, t), shape (s,): zero when the constraint holds."""

    def jacobian(self, q: Config, t: float) -> FloatArray:
        """A = ∂φ/∂q along body-frame directions, shape (s, Σ dof). Override for speed."""
        return self._jacobian_fd(lambda qq: self.residual(qq, t), q, _kinds_of(q))

    def bias(self, q: Config, nu: Config, t: float) -> FloatArray:
        """b = −(d²/dτ²) φ(q ⊕ τν, t + τ) at τ = 0, shape (s,). Override for speed."""
        return -self._path_derivatives(q, nu, t)[1]

    def rate(self, q: Config, nu: Config, t: float) -> FloatArray:
        """φ̇ = A ν + ∂φ/∂t, shape (s,) (used by Baumgarte stabilisation)."""
        return self._path_derivatives(q, nu, t)[0]

    def _path_derivatives(self, q: Config, nu: Config, t: float) -> tuple[FloatArray, FloatArray]:
        return self._path_fd(lambda qq, tt: self.residual(qq, tt), q, nu, t)

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """(φ(q, t), φ̇) at ``state`` (:meth:`Constraint.violation`)."""
        q, nu, _ = body_configs(state, self.bodies)
        phi = np.asarray(self.residual(q, state.t), dtype=float).reshape(-1)
        return phi, np.asarray(self.rate(q, nu, state.t), dtype=float).reshape(-1)

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A, b) at ``state``, with Baumgarte terms when gains are set."""
        q, nu, _ = body_configs(state, self.bodies)
        A = np.asarray(self.jacobian(q, state.t), dtype=float)
        b = np.asarray(self.bias(q, nu, state.t), dtype=float)
        if self.baumgarte is not None:
            phi = np.asarray(self.residual(q, state.t), dtype=float)
            b = b - self.baumgarte.alpha * self.rate(q, nu, state.t) - self.baumgarte.beta * phi
        return A, b


class NonholonomicConstraint(_Differentiable):
    """A velocity-level constraint ``ψ(q, ν, t) = 0`` given by its residual.

    ``A = ∂ψ/∂ν`` and ``b = −(d/dτ) ψ(q ⊕ τν, ν, t + τ)`` at τ = 0, by finite differences
    unless :meth:`jacobian` / :meth:`bias` are overridden. Baumgarte: ``ψ̇ + αψ = 0``.

    Parameters
    ----------
    bodies : sequence of Body or str
    baumgarte : Baumgarte, optional
        Only ``alpha`` is used.
    fd_length, fd_time : float
        Scales for the finite-difference steps, as for :class:`HolonomicConstraint`.
    name : str, optional
    """

    _numeric_methods = ("rows", "residual")

    @abc.abstractmethod
    def residual(self, q: Config, nu: Config, t: float) -> Any:
        """ψ(q, ν, t), shape (s,)."""

    def jacobian(self, q: Config, nu: Config, t: float) -> FloatArray:
        """A = ∂ψ/∂ν, shape (s, Σ dof). Override for speed."""
        return self._velocity_jacobian_fd(self.residual, q, nu, t)

    def bias(self, q: Config, nu: Config, t: float) -> FloatArray:
        """b = −(d/dτ) ψ(q ⊕ τν, ν, t + τ) at τ = 0, shape (s,). Override for speed."""
        return self._velocity_bias_fd(self.residual, q, nu, t)

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """(None, ψ(q, ν, t)) at ``state`` (:meth:`Constraint.violation`)."""
        q, nu, _ = body_configs(state, self.bodies)
        return None, np.asarray(self.residual(q, nu, state.t), dtype=float).reshape(-1)

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A, b) at ``state``, with the Baumgarte term when a gain is set."""
        q, nu, _ = body_configs(state, self.bodies)
        A = np.asarray(self.jacobian(q, nu, state.t), dtype=float)
        b = np.asarray(self.bias(q, nu, state.t), dtype=float)
        if self.baumgarte is not None:
            b = b - self.baumgarte.alpha * np.asarray(self.residual(q, nu, state.t), dtype=float)
        return A, b
