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
body twist V = [ω; v] of the columns of A. With ``h(τ) = φ(q ⊕ τν, t + τ)`` (each rigid body
moved along ``g exp(τ V^)``, Euclidean ones along ``x + τ ẋ``):

* ``A = ∂φ/∂ε`` at ε = 0, over the degrees of freedom of ``self.bodies`` in column order;
* ``φ̇ = h'(0)``, and ``b = −h''(0)``, because the true motion ``g exp(τV + τ²V̇/2 + …)``
  differs from the path only by the ``A ν̇`` term at second order.

For a nonholonomic ψ, ``A = ∂ψ/∂ν`` and ``b = −(d/dτ) ψ(q ⊕ τν, ν, t + τ)``: ν is held along
the path.

**Exact, by default** (``derivatives="jets"``). The residual is called once, on jets
(``gmuk/constraints/_jet.py``): each pose is the truncated series of
``g exp(Σ εₖ eₖ^ + τ V^)`` — value g, ``∂/∂εₖ = g eₖ^``, ``∂/∂τ = g V^``,
``∂²/∂τ² = g V^ V^`` — each Euclidean coordinate ``x + Σ εₖ eₖ + τ ẋ``, and time ``t + τ``
(for ψ, the velocities are ``ν + Σ εₖ eₖ`` and the poses move along τ only). The residual's
numpy operations carry the derivatives by the chain rule, so A, φ̇ and b come out of that one
call exact to round-off, at about the cost of hand-written rows. Comparisons act on values,
so a residual may branch on them. The operations supported are those of
:class:`gmuk.constraints._jet.Jet` (indexing, the arithmetic operators and ``@``, numpy's
elementary functions, ``dot``, ``cross``, ``linalg.norm``, ``sum``, ``trace``, joining and
reshaping, ``where``); anything else — ``float()``, ``np.linalg.inv``, scipy, an in-place
write into a float array — stops the jets. The rows then come from finite differences, for
this constraint from then on: :attr:`jet_fallback` says why, and a :class:`GmukWarning` says so
once. Where the derivatives are not finite at a state (``|x|`` at x = 0), that state's rows
come from finite differences.

**Finite differences** (``derivatives="fd"``, and the fallback): fifth-order-accurate
five-point central differences, about four residual calls per degree of freedom and five
along the path. Steps: rotations 1e-3 rad, translations 1e-3·``fd_length`` m, and along the
path τ such that no coordinate moves more than 2e-3 (in rad, or in units of ``fd_length``)
and τ ≤ 2e-3·``fd_time``. Set ``fd_length`` (m) and ``fd_time`` (s) to the scales on which
the residual varies; agreement with analytic rows is typically 1e-9 relative (tested ≤ 1e-7).
The rows then carry round-off noise of about eps/τ² ≈ 1e-10 of the residual's scale:
integrate with ``rtol`` ≳ 1e-10 (tighter tolerances make the step controller chase the
noise), and expect an unstabilised constraint to drift like ½·1e-10·t² (use
:class:`Baumgarte`, or override :meth:`jacobian` and :meth:`bias` with exact forms).

Overrides of :meth:`HolonomicConstraint.jacobian` / :meth:`HolonomicConstraint.bias` (and the
nonholonomic ones) take precedence over both.

References
----------
McCann (2020), Eqs. (1), (4). Taylor propagation of derivatives: Griewank & Walther,
*Evaluating Derivatives* (2nd ed., SIAM 2008), Ch. 13.
"""

from __future__ import annotations

import abc
import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.constraints import _jet
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.errors import ConstraintError, GmukWarning
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


def _n_dof(q: Config) -> int:
    return sum(6 if qi.shape == (4, 4) else qi.size for qi in q)


def _seed_configs(q: Config, nu: Config | None, n_parts: int, in_eps: bool) -> tuple[Any, ...]:
    """Jets of the configurations ``q ⊕ (Σ εₖ eₖ + τ ν)``: each pose ``g exp(… + τ V^)``, each
    Euclidean ``x + … + τ ẋ``; the ε (one per degree of freedom, in column order) only when
    ``in_eps``, and no motion along τ when ``nu`` is None."""
    jets: list[_jet.Jet] = []
    first = 0
    for i, qi in enumerate(q):
        vi = None if nu is None else nu[i]
        if qi.shape == (4, 4):
            jets.append(_jet.seed_pose(qi, vi, n_parts, first if in_eps else -1))
            first += 6
        else:
            jets.append(_jet.seed_vector(qi, vi, n_parts, first if in_eps else -1))
            first += qi.size
    return tuple(jets)


def _seed_velocities(nu: Config, n_parts: int) -> tuple[Any, ...]:
    """Jets of the velocities ``ν + Σ εₖ eₖ``, held along τ."""
    jets: list[_jet.Jet] = []
    first = 0
    for vi in nu:
        jets.append(_jet.seed_vector(vi, None, n_parts, first))
        first += vi.size
    return tuple(jets)


def _columns(jet: _jet.Jet, n: int) -> FloatArray:
    """The ε-derivatives of a jet as the columns of A: shape S + (n,)."""
    d = jet.data[1 : n + 1]
    return d.transpose((*range(1, d.ndim), 0))


class _Differentiable(Constraint):
    """Shared construction and finite-difference machinery for residual-based constraints."""

    fd_length: float
    fd_time: float
    baumgarte: Baumgarte | None
    derivatives: str
    jet_fallback: str | None

    def __init__(
        self,
        bodies: Sequence[Body | str],
        *,
        baumgarte: Baumgarte | None = None,
        fd_length: float = 1.0,
        fd_time: float = 1.0,
        derivatives: str = "jets",
        name: str | None = None,
    ) -> None:
        super().__init__(bodies, name=name)
        baumgarte, fd_length, fd_time, derivatives = self._keywords(
            baumgarte=baumgarte, fd_length=fd_length, fd_time=fd_time, derivatives=derivatives
        )
        if not (fd_length > 0 and fd_time > 0):
            raise ConstraintError(f"fd_length and fd_time must be > 0; got {fd_length}, {fd_time}")
        if derivatives not in ("jets", "fd"):
            raise ConstraintError(f"derivatives must be 'jets' or 'fd'; got {derivatives!r}")
        self.baumgarte = baumgarte
        self.fd_length = float(fd_length)
        self.fd_time = float(fd_time)
        self.derivatives = derivatives
        self.jet_fallback = None

    def _trace(self, call: Callable[[], Any], n_parts: int) -> tuple[_jet.Jet | None, str | None]:
        """The jet ``call()`` returns, or (None, why) when the rows must come from finite
        differences: (None, None) when jets are off or their derivatives are not finite at
        this state, (None, reason) when the residual cannot be traced with jets at all."""
        if self.derivatives != "jets" or self.jet_fallback is not None:
            return None, None
        try:
            with np.errstate(all="ignore"):
                result = call()
                jet = _jet.as_jet(result, n_parts)
        except Exception as exc:  # any failure while tracing: the floats decide (_settle)
            return None, f"{type(exc).__name__}: {exc}{_jet.where_raised(exc, __file__)}"
        if jet is None:
            return None, f"a result without derivatives ({type(result).__name__})"
        if not np.isfinite(jet.data).all():
            return None, None  # a singular point of the derivatives: differences, this once
        return jet, None

    def _settle(self, reason: str | None) -> None:
        """After finite differences succeeded where the jets failed for ``reason``: use them
        from now on, and say so once."""
        if reason is None or self.jet_fallback is not None:
            return
        object.__setattr__(self, "jet_fallback", reason)  # the part may be frozen
        warnings.warn(
            f"{self.name}: exact derivatives of the residual stopped at {reason}; its rows "
            "come from finite differences from now on (about 1e-9 relative, and slower). "
            "Pass derivatives='fd' to choose them, or override jacobian and bias.",
            GmukWarning,
            stacklevel=4,
        )

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

    Subclasses implement :meth:`residual`; gmuk derives the rows exactly from one call of it
    with derivative jets (module docstring). Optionally override :meth:`jacobian` and
    :meth:`bias` with analytic forms: they take precedence.

    Parameters
    ----------
    bodies : sequence of Body or str
    baumgarte : Baumgarte, optional
        Stabilisation ``φ̈ + αφ̇ + βφ = 0`` (off by default).
    fd_length : float
        Length scale (m) on which φ varies, for the finite-difference steps (default 1).
    fd_time : float
        Time scale (s) on which φ varies explicitly in t (default 1).
    derivatives : {"jets", "fd"}
        How the rows are derived: exactly with jets (default; finite differences where the
        residual uses an operation jets do not support), or by finite differences.
    name : str, optional

    Attributes
    ----------
    jet_fallback : str or None
        None while the rows come from jets; once a residual could not be traced, the reason
        (e.g. the unsupported operation), and the rows come from finite differences.

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

    def _jets(self, q: Config, nu: Config | None, t: float) -> tuple[_jet.Jet | None, str | None]:
        """φ along ``q ⊕ (Σ εₖ eₖ + τ ν)`` at time t + τ as one jet (see :meth:`_trace`)."""
        n_parts = _n_dof(q) + 3
        qj = _seed_configs(q, nu, n_parts, in_eps=True)
        tj: Any = _jet.seed_scalar(t, n_parts)  # the residual sees t + τ as a float would be
        return self._trace(lambda: self.residual(qj, tj), n_parts)

    def jacobian(self, q: Config, t: float) -> FloatArray:
        """A = ∂φ/∂q along body-frame directions, shape (s, Σ dof). Override for speed."""
        jet, reason = self._jets(q, None, t)
        if jet is not None:
            return _columns(jet, _n_dof(q))
        A = self._jacobian_fd(lambda qq: self.residual(qq, t), q, _kinds_of(q))
        self._settle(reason)
        return A

    def bias(self, q: Config, nu: Config, t: float) -> FloatArray:
        """b = −(d²/dτ²) φ(q ⊕ τν, t + τ) at τ = 0, shape (s,). Override for speed."""
        return -self._path_derivatives(q, nu, t)[1]

    def rate(self, q: Config, nu: Config, t: float) -> FloatArray:
        """φ̇ = A ν + ∂φ/∂t, shape (s,) (used by Baumgarte stabilisation)."""
        return self._path_derivatives(q, nu, t)[0]

    def _path_derivatives(self, q: Config, nu: Config, t: float) -> tuple[FloatArray, FloatArray]:
        """(h'(0), h''(0)) of ``h(τ) = φ(q ⊕ τν, t + τ)``."""
        jet, reason = self._jets(q, nu, t)
        if jet is not None:
            return jet.data[-2], jet.data[-1]
        d = self._path_fd(lambda qq, tt: self.residual(qq, tt), q, nu, t)
        self._settle(reason)
        return d

    def _rows_from_residual(self, q: Config, nu: Config, t: float) -> tuple[Any, ...]:
        """(φ, A, φ̇, h''(0)): from one jet, or from finite differences."""
        jet, reason = self._jets(q, nu, t)
        if jet is not None:
            return jet.data[0], _columns(jet, _n_dof(q)), jet.data[-2], jet.data[-1]
        A = self._jacobian_fd(lambda qq: self.residual(qq, t), q, _kinds_of(q))
        d1, d2 = self._path_fd(lambda qq, tt: self.residual(qq, tt), q, nu, t)
        phi = None if self.baumgarte is None else np.asarray(self.residual(q, t), dtype=float)
        self._settle(reason)
        return phi, A, d1, d2

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """(φ(q, t), φ̇) at ``state`` (:meth:`Constraint.violation`)."""
        q, nu, _ = body_configs(state, self.bodies)
        phi = np.asarray(self.residual(q, state.t), dtype=float).reshape(-1)
        return phi, np.asarray(self.rate(q, nu, state.t), dtype=float).reshape(-1)

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A, b) at ``state``, with Baumgarte terms when gains are set."""
        q, nu, _ = body_configs(state, self.bodies)
        cls = type(self)
        if cls.jacobian is HolonomicConstraint.jacobian and cls.bias is HolonomicConstraint.bias:
            phi, A, rate, d2 = self._rows_from_residual(q, nu, state.t)
            b = -d2
            if self.baumgarte is not None:
                b = b - self.baumgarte.alpha * rate - self.baumgarte.beta * phi
            return A, b
        A = np.asarray(self.jacobian(q, state.t), dtype=float)
        b = np.asarray(self.bias(q, nu, state.t), dtype=float)
        if self.baumgarte is not None:
            phi = np.asarray(self.residual(q, state.t), dtype=float)
            b = b - self.baumgarte.alpha * self.rate(q, nu, state.t) - self.baumgarte.beta * phi
        return A, b


class NonholonomicConstraint(_Differentiable):
    """A velocity-level constraint ``ψ(q, ν, t) = 0`` given by its residual.

    ``A = ∂ψ/∂ν`` and ``b = −(d/dτ) ψ(q ⊕ τν, ν, t + τ)`` at τ = 0, derived exactly from one
    call of :meth:`residual` with derivative jets unless :meth:`jacobian` / :meth:`bias` are
    overridden. Baumgarte: ``ψ̇ + αψ = 0``.

    Parameters
    ----------
    bodies : sequence of Body or str
    baumgarte : Baumgarte, optional
        Only ``alpha`` is used.
    fd_length, fd_time : float
        Scales for the finite-difference steps, as for :class:`HolonomicConstraint`.
    derivatives : {"jets", "fd"}
        As for :class:`HolonomicConstraint`.
    name : str, optional

    Attributes
    ----------
    jet_fallback : str or None
        As for :class:`HolonomicConstraint`.
    """

    _numeric_methods = ("rows", "residual")

    @abc.abstractmethod
    def residual(self, q: Config, nu: Config, t: float) -> Any:
        """ψ(q, ν, t), shape (s,)."""

    def _jets(self, q: Config, nu: Config, t: float) -> tuple[_jet.Jet | None, str | None]:
        """ψ at (q ⊕ τν, ν + Σ εₖ eₖ, t + τ) as one jet (see :meth:`_trace`)."""
        n_parts = _n_dof(q) + 3
        qj = _seed_configs(q, nu, n_parts, in_eps=False)
        nuj = _seed_velocities(nu, n_parts)
        tj: Any = _jet.seed_scalar(t, n_parts)
        return self._trace(lambda: self.residual(qj, nuj, tj), n_parts)

    def jacobian(self, q: Config, nu: Config, t: float) -> FloatArray:
        """A = ∂ψ/∂ν, shape (s, Σ dof). Override for speed."""
        return self._rows_from_residual(q, nu, t)[1]

    def bias(self, q: Config, nu: Config, t: float) -> FloatArray:
        """b = −(d/dτ) ψ(q ⊕ τν, ν, t + τ) at τ = 0, shape (s,). Override for speed."""
        return self._rows_from_residual(q, nu, t, need_a=False)[2]

    def _rows_from_residual(
        self, q: Config, nu: Config, t: float, need_a: bool = True
    ) -> tuple[Any, ...]:
        """(ψ, A, b): from one jet, or from finite differences (ψ only with Baumgarte, A
        only when ``need_a``)."""
        jet, reason = self._jets(q, nu, t)
        if jet is not None:
            return jet.data[0], _columns(jet, _n_dof(q)), -jet.data[-2]
        A = self._velocity_jacobian_fd(self.residual, q, nu, t) if need_a else None
        b = self._velocity_bias_fd(self.residual, q, nu, t)
        psi = None if self.baumgarte is None else np.asarray(self.residual(q, nu, t), dtype=float)
        self._settle(reason)
        return psi, A, b

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """(None, ψ(q, ν, t)) at ``state`` (:meth:`Constraint.violation`)."""
        q, nu, _ = body_configs(state, self.bodies)
        return None, np.asarray(self.residual(q, nu, state.t), dtype=float).reshape(-1)

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A, b) at ``state``, with the Baumgarte term when a gain is set."""
        q, nu, _ = body_configs(state, self.bodies)
        cls = type(self)
        if (
            cls.jacobian is NonholonomicConstraint.jacobian
            and cls.bias is NonholonomicConstraint.bias
        ):
            psi, A, b = self._rows_from_residual(q, nu, state.t)
        else:
            A = np.asarray(self.jacobian(q, nu, state.t), dtype=float)
            b = np.asarray(self.bias(q, nu, state.t), dtype=float)
            psi = None
        if self.baumgarte is not None:
            if psi is None:
                psi = np.asarray(self.residual(q, nu, state.t), dtype=float)
            b = b - self.baumgarte.alpha * psi
        return A, b
