"""Inequality constraints through slack and excess variables (McCann 2020, §6.3).

An inequality on a scalar function ``h(q, ν, t)`` of some bodies becomes an equality on
those bodies and one new scalar coordinate per bound, which the System adds for it:

* upper bound ``h ≤ u`` with a slack s:   ``h − u + s² = 0`` (Eqs. 94–95),
* lower bound ``h ≥ l`` with an excess p: ``h − l − p² = 0`` (Eqs. 96–97),
* both, ``l ≤ h ≤ u``: two rows, two coordinates.

Writing σ = +1 for a slack and σ = −1 for an excess, and w for the coordinate:

``position`` level (h depends on q and t only): differentiated twice (Eqs. 95c, 97c),
    ``A_h ν̇ + 2σ w ẅ = b_h − 2σ ẇ²``,
``velocity`` level (h depends on ν): the coordinate enters through its rate,
    ``h − bound + σ ẇ² = 0`` (the form of the thesis's Eq. 102), differentiated once:
    ``A_h ν̇ + 2σ ẇ ẅ = b_h``,

with ``A_h = ∂h/∂q`` (position; body-frame directions for rigid bodies, as
:class:`~gmuk.constraints.HolonomicConstraint`) or ``∂h/∂ν`` (velocity) and ``b_h`` the rest
of ``−ḧ`` (or ``−ḣ``). The coordinates carry a mass (``slack_mass``), so the Udwadia–Kalaba
solve shares the constraint force between the bodies and the slack as Gauss's principle
weights them: far from the bound the slack takes almost all of it, at the bound (w = 0) all
of it goes to the bodies.

The singular points
-------------------
* ``w = 0`` is where the bound is active. The slack column of A is then 0 but the row keeps
  rank through ``A_h`` (the coordinate has its own velocity state: Eq. 95b is never solved
  for ẇ, so the thesis's singularity of §6.3.3 does not arise during a run). It loses rank
  only if ``A_h = 0`` on the bound too, where the inequality has no normal; the System's
  rank-revealing solve then keeps what is consistent and warns
  (:class:`~gmuk.errors.InconsistentConstraintsWarning`) about what is not.
* ``w = ẇ = 0`` is invariant: a bound that is active with zero slack rate stays active.
  gmuk never reaches it from an inactive bound (the slack crosses zero with a non-zero
  rate), and chooses it at the start only when the free motion presses outward
  (see :meth:`InequalityConstraint.initial_slack`).

References
----------
McCann (2020), §6.3, Eqs. (94)–(97); Griva & Nash (2017) for slack and excess variables.
"""

from __future__ import annotations

import abc
import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from gmuk._casadi import casadi, column
from gmuk._forms import Forms
from gmuk._validation import NOT_REAL, FloatArray, as_array, real_number
from gmuk.bodies import BodyKind, SlackCoordinate
from gmuk.constraints.base import Baumgarte
from gmuk.constraints.holonomic import Config, _Differentiable, _kinds_of, body_configs
from gmuk.errors import ConstraintError, DefinitionError, GmukError

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["Bound", "InequalityConstraint", "PlaneBound", "TrackingErrorBound"]

LEVELS = ("position", "velocity")


@dataclass(frozen=True)
class Bound:
    """One side of an inequality: ``h ≤ value`` (side "upper", slack) or ``h ≥ value``
    (side "lower", excess), with the coordinate that turns it into an equality.

    Attributes
    ----------
    side : {"upper", "lower"}
    value : float
        u or l, in the unit of h.
    coordinate : SlackCoordinate
        The slack s (upper) or excess p (lower).
    sign : float
        σ = +1 (slack, ``h − u + s² = 0``) or −1 (excess, ``h − l − p² = 0``).
    """

    side: str
    value: float
    coordinate: SlackCoordinate
    sign: float

    @property
    def label(self) -> str:
        """``"h ≤ u"`` or ``"h ≥ l"`` with the number."""
        return f"h {'≤' if self.side == 'upper' else '≥'} {self.value:g}"

    def margin(self, h: float) -> float:
        """σ(bound − h): how far inside the bound h is (negative when violated)."""
        return self.sign * (self.value - h)

    def g(self, h: Any) -> Any:
        """The KKT form ``g ≤ 0`` of this side: σ(h − bound), i.e. ``h − u`` or ``l − h``."""
        return self.sign * (np.asarray(h, dtype=float) - self.value)


def _bound_value(value: Any, label: str, who: str) -> float | None:
    if value is None:
        return None
    return real_number(value, f"{who}: {label}")


class InequalityConstraint(_Differentiable):
    """An inequality ``h(q, ν, t) ≤ upper``, ``≥ lower``, or both, by slack/excess variables.

    Subclass it and implement :meth:`value` (h); optionally :meth:`jacobian`, :meth:`bias`
    and :meth:`rate` with analytic forms, otherwise they are taken by finite differences as
    for :class:`~gmuk.constraints.HolonomicConstraint` (``level="position"``) or
    :class:`~gmuk.constraints.NonholonomicConstraint` (``level="velocity"``).

    The constraint owns one :class:`gmuk.SlackCoordinate` per bound, named
    ``"<name>.upper"`` / ``"<name>.lower"``; the System adds them to its bodies, and
    :meth:`gmuk.System.state` sets their values and rates from the initial state of the other
    bodies (:meth:`initial_slack`).

    Parameters
    ----------
    bodies : sequence of Body or str
        The bodies h depends on; their configurations ``q`` and velocities ``ν`` are passed
        to :meth:`value` in this order (as for HolonomicConstraint: g_NB (4, 4) or r_N (3,)).
    upper, lower : float, optional
        The bounds u and l, in the unit of h; at least one, and ``lower < upper``.
    level : {"position", "velocity"}
        Whether h depends on the configurations and time only ("position", Eqs. 95/97) or
        also on the velocities ("velocity": the slack enters as ẇ², as in Eq. 102).
    slack_mass : float
        Gauss's weight m_w of each slack coordinate (w² has the unit of h, so m_w is in
        kg·m² per unit of h at the position level — kg·m for a bound in metres — and in
        kg·m²/s² per unit of h at the velocity level — kg·m/s for a bound in m/s). It sets
        how the constraint force is shared between the bodies and the slack: the bodies get
        half of it at the margin ``m_w A_h M⁻¹ A_hᵀ / 4`` from the bound (in the unit of h),
        so a smaller m_w makes the contact with the bound thinner and more abrupt.
    baumgarte : Baumgarte, optional
        Stabilisation of each equality ``φ = h − bound + σw² = 0`` (α, β for the position
        level; α only for the velocity level). Off by default.
    fd_length, fd_time : float
        Scales for the finite-difference derivatives (see HolonomicConstraint).
    unit : str
        The unit of h, for labels (e.g. "m", "rad/s").
    name : str, optional
        Also names the slack coordinates; distinct inequalities need distinct names.

    Examples
    --------
    A point mass kept above the plane z = 0:

    >>> class AbovePlane(InequalityConstraint):
    ...     def value(self, q, nu, t):
    ...         return q[0][2]
    >>> above = AbovePlane(["probe"], lower=0.0, unit="m", name="above")
    """

    #: Bodies of every kind may carry an inequality (its own coordinates are slack bodies).
    body_kinds: ClassVar[frozenset[BodyKind]] = frozenset(BodyKind)
    _numeric_methods: ClassVar[tuple[str, ...]] = ("rows", "value")
    _physical: tuple[Body | str, ...]
    _bounds: tuple[Bound, ...]
    _slack_cache: tuple[object, tuple[int, ...]] | None = None

    def __init__(
        self,
        bodies: Sequence[Body | str],
        *,
        upper: float | None = None,
        lower: float | None = None,
        level: str = "position",
        slack_mass: float = 1.0,
        baumgarte: Baumgarte | None = None,
        fd_length: float = 1.0,
        fd_time: float = 1.0,
        unit: str = "",
        name: str | None = None,
    ) -> None:
        (name,) = self._keywords(name=name)  # names the slack coordinates before super()
        if isinstance(bodies, str) or not isinstance(bodies, Sequence):
            bodies = [bodies]
        label = name or type(self).__name__
        who = f"inequality {label!r}"
        u = _bound_value(upper, "upper", who)
        lo = _bound_value(lower, "lower", who)
        if u is None and lo is None:
            raise DefinitionError(f"{who}: give upper=, lower= or both")
        if u is not None and lo is not None and not lo < u:
            raise DefinitionError(
                f"{who}: needs lower < upper; got lower = {lo!r}, upper = {u!r}"
                + (" (an equality: use a HolonomicConstraint)" if lo == u else "")
            )
        if level not in LEVELS:
            raise DefinitionError(f"{who}: level must be one of {LEVELS}; got {level!r}")
        bounds: list[Bound] = []
        for side, value, sign in (("upper", u, 1.0), ("lower", lo, -1.0)):
            if value is not None:
                coordinate = SlackCoordinate(f"{label}.{side}", mass=slack_mass)
                bounds.append(Bound(side, value, coordinate, sign))
        object.__setattr__(self, "_physical", tuple(bodies))
        object.__setattr__(self, "_bounds", tuple(bounds))
        super().__init__(
            [*bodies, *(b.coordinate for b in bounds)],
            baumgarte=baumgarte,
            fd_length=fd_length,
            fd_time=fd_time,
            name=label,
        )
        self.level = level
        self.unit = str(unit)

    # ------------------------------------------------------------------ description
    @property
    def physical_bodies(self) -> tuple[Body | str, ...]:
        """The bodies h depends on (the constraint's bodies without its slack coordinates)."""
        return self._physical

    @property
    def bounds(self) -> tuple[Bound, ...]:
        """The bounds, upper first."""
        return self._bounds

    @property
    def owned_bodies(self) -> tuple[SlackCoordinate, ...]:
        """The slack coordinates this constraint adds to a System."""
        return tuple(b.coordinate for b in self._bounds)

    # ------------------------------------------------------------------ user's function
    @abc.abstractmethod
    def value(self, q: Config, nu: Config, t: float) -> Any:
        """h(q, ν, t), a scalar in :attr:`unit` (``ν`` is ignored at the position level)."""

    def jacobian(self, q: Config, nu: Config, t: float) -> FloatArray:
        """A_h, shape (Σ dof,): ∂h/∂q along body-frame directions (position level) or
        ∂h/∂ν (velocity level). Override for speed."""
        if self.level == "position":
            fun = lambda qq: np.array([self._value(qq, nu, t)])  # noqa: E731
            return self._jacobian_fd(fun, q, _kinds_of(q))[0]
        fun2 = lambda qq, vv, tt: np.array([self._value(qq, vv, tt)])  # noqa: E731
        return self._velocity_jacobian_fd(fun2, q, nu, t)[0]

    def bias(self, q: Config, nu: Config, t: float) -> float:
        """b_h: ``A_h ν̇ − ḧ`` (position level) or ``A_h ν̇ − ḣ`` (velocity level), i.e. minus
        the part of the derivative that does not involve the accelerations. Override for
        speed."""
        if self.level == "position":
            return -float(self._path_fd(lambda qq, tt: self._value(qq, nu, tt), q, nu, t)[1])
        fun = lambda qq, vv, tt: np.array([self._value(qq, vv, tt)])  # noqa: E731
        return float(self._velocity_bias_fd(fun, q, nu, t)[0])

    def rate(self, q: Config, nu: Config, t: float) -> float:
        """ḣ at the position level (for the initial slack rate and Baumgarte). Override for
        speed."""
        return float(self._path_fd(lambda qq, tt: self._value(qq, nu, tt), q, nu, t)[0])

    # ------------------------------------------------------------------ checked evaluation
    def _who(self) -> str:
        return f"inequality {self.name!r}"

    def _scalar(self, v: Any, what: str, t: float) -> float:
        """``v``, what the user's ``what`` returned at time ``t``, as a finite float.

        Only real numbers pass (Python and numpy ints and floats, and arrays of one such
        element): booleans, strings, bytes, complex numbers, None and other objects are
        refused, never converted (``"1.0"`` would be parsed, ``True`` read as 1).
        """
        if type(v) is float:  # the common case: no conversion to check
            x = v
        else:
            where = f"{self._who()} at t = {t!r}"
            if isinstance(v, np.ndarray):
                if v.size != 1:
                    raise ConstraintError(f"{where}: {what} must be a scalar; got shape {v.shape}")
                if v.dtype.kind not in "iufO":
                    raise ConstraintError(
                        f"{where}: {what} must be a real number; got an array of dtype "
                        f"{v.dtype}: {v!r:.60}"
                    )
                v = v.reshape(())[()]
            if isinstance(v, NOT_REAL) or not isinstance(v, numbers.Real):
                raise ConstraintError(
                    f"{where}: {what} must be a real number (a float); got "
                    f"{type(v).__name__} {v!r:.60}"
                )
            try:
                x = float(v)
            except OverflowError:  # an int beyond float64
                raise ConstraintError(
                    f"{where}: {what} is not finite; got an integer too large for float64"
                ) from None
        if not math.isfinite(x):
            raise ConstraintError(f"{self._who()} at t = {t!r}: {what} is not finite; got {x!r}")
        return x

    def _value(self, q: Config, nu: Config, t: float) -> float:
        """:meth:`value`, checked to be a finite real scalar."""
        return self._scalar(self.value(q, nu, t), "value()", t)

    def _row(self, q: Config, nu: Config, t: float, n: int) -> FloatArray:
        A_h = np.asarray(self.jacobian(q, nu, t), dtype=float).reshape(-1)
        if A_h.shape != (n,):
            raise ConstraintError(
                f"{self._who()}: jacobian() must have shape ({n},); got {A_h.shape}"
            )
        if not np.isfinite(A_h).all():
            raise ConstraintError(f"{self._who()}: jacobian() is not finite: {A_h}")
        return A_h

    def _configs(self, state: State) -> tuple[Config, Config]:
        q, nu, _ = body_configs(state, self._physical)
        return q, nu

    def _slack_indices(self, state: State) -> tuple[int, ...]:
        cached = self._slack_cache
        if cached is not None and cached[0] is state.layout:
            return cached[1]
        idx = tuple(state.layout.slot(b.coordinate.name).index for b in self._bounds)
        object.__setattr__(self, "_slack_cache", (state.layout, idx))
        return idx

    def h(self, state: State) -> float:
        """h at ``state`` (checked: a finite scalar)."""
        q, nu = self._configs(state)
        return self._value(q, nu, state.t)

    # ------------------------------------------------------------------ rows
    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A, b) of the equalities ``h − bound + σw² = 0`` at acceleration level, one row per
        bound; columns: the bodies' velocities, then each bound's coordinate."""
        q, nu = self._configs(state)
        t = state.t
        n = sum(v.size for v in nu)
        k = len(self._bounds)
        A_h = self._row(q, nu, t, n)
        b_h = self._scalar(self.bias(q, nu, t), "bias()", t)
        A = np.zeros((k, n + k))
        A[:, :n] = A_h
        b = np.full(k, b_h)
        position = self.level == "position"
        gains = self.baumgarte
        if gains is not None:
            h = self._value(q, nu, t)
            h_dot = self._scalar(self.rate(q, nu, t), "rate()", t) if position else 0.0
        for i, (bd, j) in enumerate(zip(self._bounds, self._slack_indices(state), strict=True)):
            w, w_dot = float(state.x[j]), float(state.xdot[j])
            two_sigma = 2.0 * bd.sign
            if position:
                A[i, n + i] = two_sigma * w
                b[i] -= two_sigma * w_dot * w_dot
            else:
                A[i, n + i] = two_sigma * w_dot
            if gains is not None:
                alpha, beta = _gain(gains.alpha, i), _gain(gains.beta, i)
                if position:
                    phi = h - bd.value + bd.sign * w * w
                    b[i] -= alpha * (h_dot + two_sigma * w * w_dot) + beta * phi
                else:
                    b[i] -= alpha * (h - bd.value + bd.sign * w_dot * w_dot)
        return A, b

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """The residuals of the equalities ``h − bound + σw² = 0``, one per bound
        (:meth:`Constraint.violation`): at the position level (φ, φ̇); at the velocity level
        (None, h − bound + σẇ²). Each is divided by max(1, abs(bound) + the size of h's own terms,
        e.g. a TrackingErrorBound's bound) (in the unit of h): the
        equality balances quantities of the bound's size, and its finite-difference rows
        carry noise in proportion (a position bound of 1000 m on an orbit holds its
        equality to 1e-5 m under Baumgarte terms, 1e-8 of the bound)."""
        q, nu = self._configs(state)
        t = state.t
        h = self._value(q, nu, t)
        idx = self._slack_indices(state)
        w = np.array([float(state.x[j]) for j in idx])
        w_dot = np.array([float(state.xdot[j]) for j in idx])
        sign = np.array([bd.sign for bd in self._bounds], dtype=float)
        value = np.array([bd.value for bd in self._bounds], dtype=float)
        scale = np.maximum(1.0, np.abs(value) + self._violation_scale(t))
        if self.level == "position":
            h_dot = self._scalar(self.rate(q, nu, t), "rate()", t)
            return (h - value + sign * w * w) / scale, (h_dot + 2.0 * sign * w * w_dot) / scale
        return None, (h - value + sign * w_dot * w_dot) / scale

    def _violation_scale(self, t: float) -> float:
        """A size of h at time t beyond the bounds (0 here), to weigh :meth:`violation`."""
        return 0.0

    # ------------------------------------------------------------------ initial slack
    def initial_slack(
        self, state: State, free_acceleration: FloatArray
    ) -> list[tuple[float, float]]:
        """Values and rates ``(w, ẇ)`` of the coordinates, one pair per bound, consistent with
        the bodies' state (``φ = 0`` and ``φ̇ = 0``).

        Parameters
        ----------
        state : State
            The bodies' state (the slack entries are ignored).
        free_acceleration : ndarray (Σ dof of :attr:`physical_bodies`,)
            The bodies' unconstrained acceleration under the modeled forces; used only when a
            bound is exactly active at the start.

        Position level: ``w = √(σ(bound − h))`` and ``ẇ = −σḣ / (2w)``. On the bound (w = 0)
        the rate relation needs ḣ = 0; then ẇ is chosen so that the initial constraint force
        is the KKT one: ``ẇ = √(−σḧ_free / 2)`` when the free motion moves inside (no force),
        0 when it presses outward (the bound holds). Velocity level: ``ẇ = √(σ(bound − h))``,
        ``w = 0``.

        A bound held from the start (w = ẇ = 0) stays held for the rest of the run, even if
        the forces later pull the bodies inside (then μ < 0): ``w = ẇ = 0`` is invariant. Near
        it a bound releases slowly (w grows like exp(λt) with λ = √(2|μ|/m_w)); start inside
        the bound by a margin if the forces may reverse.

        Raises
        ------
        ConstraintError
            When the state violates a bound (saying by how much), starts on a bound moving
            out of it or, at the position level, into it (ḣ ≠ 0 cannot be represented with
            w = 0: start inside by any margin), or, at the velocity level, starts on a bound
            the free motion would leave (the slack rate 0 would hold it).
        """
        q, nu = self._configs(state)
        t = state.t
        h = self._value(q, nu, t)
        out: list[tuple[float, float]] = []
        position = self.level == "position"
        h_dot = self._scalar(self.rate(q, nu, t), "rate()", t) if position else 0.0
        for bd in self._bounds:
            margin = bd.margin(h)
            unit = f" {self.unit}" if self.unit else ""
            if margin < 0.0:
                raise ConstraintError(
                    f"{self._who()}: the initial state violates {bd.label}{unit}: "
                    f"h = {h!r}{unit}, outside by {-margin:.6g}{unit}"
                )
            if margin > 0.0:
                root = math.sqrt(margin)
                out.append((root, -bd.sign * h_dot / (2.0 * root)) if position else (0.0, root))
                continue
            # exactly on the bound: the free motion decides whether it holds
            n = free_acceleration.size
            A_h = self._row(q, nu, t, n)
            b_h = self._scalar(self.bias(q, nu, t), "bias()", t)
            free_rate = float(A_h @ free_acceleration) - b_h  # ḧ_free or ḣ_free
            if position:
                tol = 1e-9 * max(1.0, abs(bd.value)) / self.fd_time
                if abs(h_dot) > tol:
                    direction = "out of" if bd.sign * h_dot > 0 else "into"
                    raise ConstraintError(
                        f"{self._who()}: the initial state is on the bound {bd.label}{unit} "
                        f"moving {direction} it (dh/dt = {h_dot:.6g}); a slack of 0 needs "
                        f"dh/dt = 0: start inside the bound by any margin"
                    )
                inward = -bd.sign * free_rate
                out.append((0.0, math.sqrt(inward / 2.0) if inward > 0.0 else 0.0))
            else:
                if bd.sign * free_rate < 0.0:
                    raise ConstraintError(
                        f"{self._who()}: the initial state is on the bound {bd.label}{unit} "
                        f"and the free motion leaves it (dh/dt = {free_rate:.6g}); a "
                        f"velocity-level slack rate of 0 would hold it there: start inside "
                        f"the bound by any margin"
                    )
                out.append((0.0, 0.0))
        return out

    def initial_owned_state(
        self, state: State, free_acceleration: FloatArray
    ) -> list[tuple[float, float]]:
        """:meth:`initial_slack`, given the free acceleration of all the columns.

        An exception of the user's own that :meth:`value` (or :meth:`jacobian`, :meth:`bias`,
        :meth:`rate`) raises here, where :meth:`gmuk.System.state` computes the initial
        slack, becomes a :class:`~gmuk.errors.ConstraintError` naming the constraint (the
        original is its ``__cause__``)."""
        n = free_acceleration.size - len(self._bounds)
        try:
            return self.initial_slack(state, free_acceleration[:n])
        except GmukError:
            raise
        except Exception as exc:
            raise ConstraintError(
                f"{self._who()}: computing the initial slack at t = {state.t!r} raised "
                f"{type(exc).__name__}: {exc}"
            ) from exc

    def __repr__(self) -> str:
        bounds = ", ".join(f"{b.side}={b.value:g}" for b in self._bounds)
        return (
            f"{type(self).__name__}(bodies={list(self.body_names[: len(self._physical)])}, "
            f"{bounds}, level={self.level!r}, name={self.name!r})"
        )


def _gain(g: Any, i: int) -> float:
    arr = np.asarray(g, dtype=float)
    return float(arr) if arr.ndim == 0 else float(arr[i])


class PlaneBound(InequalityConstraint):
    """The position of a body along a fixed inertial direction, ``h = n̂ · r_N`` (m).

    For a rigid body r_N is its centre of mass, with ``ṙ_N = R v`` and
    ``r̈_N = R(v̇ + ω × v)``, so ``A_h = [0, Rᵀn̂]`` and ``b_h = −n̂ · R(ω × v)``; for a point
    mass ``A_h = n̂`` and ``b_h = 0``. Analytic rows, no finite differences.

    Parameters
    ----------
    body : Body or str
        A point mass or a rigid body.
    normal : array_like (3,)
        Direction n in N (normalised here).
    upper, lower : float, optional
        Bounds on n̂ · r_N (m): ``lower`` keeps the body on the side n̂ points to.
    slack_mass, baumgarte, name
        As for :class:`InequalityConstraint`.

    Examples
    --------
    The spring–mass–damper of McCann (2020) §6.5.1 kept at x ≥ 5 m:

    >>> gt = PlaneBound("mass", [1.0, 0.0, 0.0], lower=5.0, name="x_min")
    """

    body_kinds: ClassVar[frozenset[BodyKind]] = frozenset({BodyKind.RIGID, BodyKind.POINT})
    _forms = Forms(compiled="its rows are called back from the compiled loop", symbolic=True)

    def __init__(
        self,
        body: Body | str,
        normal: Any,
        *,
        upper: float | None = None,
        lower: float | None = None,
        slack_mass: float = 1.0,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        try:
            n = np.array(as_array(normal, (3,), "PlaneBound: normal", batch=False))
        except GmukError:
            raise DefinitionError(
                f"PlaneBound: normal must be a non-zero 3-vector; got {normal!r}"
            ) from None
        largest = float(np.abs(n).max())
        if largest > 0.0:  # scaled first: the norm of entries near 1e308 would overflow
            n = n / largest
        norm = float(np.linalg.norm(n))
        if not (math.isfinite(norm) and norm > 0.0):
            raise DefinitionError(f"PlaneBound: normal must be a non-zero 3-vector; got {normal!r}")
        super().__init__(
            [body],
            upper=upper,
            lower=lower,
            slack_mass=slack_mass,
            baumgarte=baumgarte,
            unit="m",
            name=name,
        )
        self.normal = n / norm

    def value(self, q: Config, nu: Config, t: float) -> float:
        """n̂ · r_N (m)."""
        qb = q[0]
        return float(self.normal @ (qb[:3, 3] if qb.shape == (4, 4) else qb))

    def casadi_value(self, q: tuple[Any, ...], nu: tuple[Any, ...], t: Any) -> Any:
        """The symbolic form of :meth:`value` (CasADi scalar)."""
        qb = q[0]
        return column(self.normal).T @ (qb[:3, 3] if qb.shape == (4, 4) else qb)

    def jacobian(self, q: Config, nu: Config, t: float) -> FloatArray:
        """n̂ (point mass) or [0, Rᵀn̂] (rigid body, [ω; v] columns)."""
        qb = q[0]
        if qb.shape == (4, 4):
            return np.concatenate([np.zeros(3), qb[:3, :3].T @ self.normal])
        return self.normal.copy()

    def bias(self, q: Config, nu: Config, t: float) -> float:
        """0 (point mass) or −n̂ · R(ω × v) (rigid body)."""
        qb, V = q[0], nu[0]
        if qb.shape == (4, 4):
            return -float(self.normal @ (qb[:3, :3] @ np.cross(V[:3], V[3:])))
        return 0.0

    def rate(self, q: Config, nu: Config, t: float) -> float:
        """n̂ · ṙ_N (m/s)."""
        qb, V = q[0], nu[0]
        if qb.shape == (4, 4):
            return float(self.normal @ (qb[:3, :3] @ V[3:]))
        return float(self.normal @ V)


def _bound_profile(bound: Any, who: str) -> Any:
    """A constant bound or a function of t returning (value, rate, second rate)."""
    if callable(bound):
        return bound
    value = _bound_value(bound, "bound", who)
    if value is None or value <= 0.0:
        raise DefinitionError(f"{who}: bound must be > 0 (or a function of t); got {bound!r}")
    return lambda t: (value, 0.0, 0.0)


class TrackingErrorBound(InequalityConstraint):
    """A point mass kept near a reference motion: ``‖r − r_r(t)‖ ≤ δ(t)`` or
    ``‖ṙ − ṙ_r(t)‖ ≤ γ(t)`` (McCann 2020, §6.5.2).

    With the errors ``e = r − r_r`` and ``ė = ṙ − ṙ_r`` (N frame):

    ``quantity="position"`` (Eqs. 101, 103, 105, 107–108; Eq. 105's z term corrected to
        (z − z_r)(z̈ − z̈_r)): ``h = ‖e‖ − δ``, ``A_h = eᵀ/‖e‖``,
        ``b_h = (r̈_rᵀe − ėᵀė)/‖e‖ + (ėᵀe)²/‖e‖³ + δ̈``;
    ``quantity="velocity"`` (Eqs. 102 (labelled g₁ in print), 104, 106, 109–110, Eq. 109's
        denominators corrected to ‖ė‖): ``h = ‖ė‖ − γ``, ``A_h = ėᵀ/‖ė‖``,
        ``b_h = r̈_rᵀė/‖ė‖ + γ̇``.

    The norm has no derivative at zero error, so these rows are undefined there (an error,
    not a NaN). ``form="squared"`` uses ``h = ½(‖e‖² − δ²)`` (m²) or ``½(‖ė‖² − γ²)``
    (m²/s²) instead: the same inequality, smooth everywhere, with
    ``A_h = eᵀ``, ``b_h = r̈_rᵀe − ėᵀė + δ̇² + δδ̈`` (or ``A_h = ėᵀ``, ``b_h = r̈_rᵀė + γγ̇``).

    Parameters
    ----------
    body : Body or str
        A point mass.
    reference : object
        With ``kinematics(t)`` returning (r_r, ṙ_r, r̈_r), or ``position(t)``,
        ``velocity(t)`` and ``acceleration(t)``, each a (3,) array in N (m, m/s, m/s²); e.g.
        a :class:`gmuk.orbits.KeplerOrbit` (two-body motion).
    bound : float or callable
        δ (m) or γ (m/s), > 0; or a function ``t -> (value, rate, second rate)``.
    quantity : {"position", "velocity"}
    form : {"norm", "squared"}
    slack_mass, baumgarte, name
        As for :class:`InequalityConstraint`.
    """

    body_kinds: ClassVar[frozenset[BodyKind]] = frozenset({BodyKind.POINT})
    _numeric_methods = ("rows", "value", "errors", "reference_kinematics")
    _forms = Forms(compiled="its rows are called back from the compiled loop", symbolic=True)
    _ref_cache: tuple[float, tuple[FloatArray, FloatArray, FloatArray]] | None = None

    def __init__(
        self,
        body: Body | str,
        reference: Any,
        bound: Any,
        *,
        quantity: str = "position",
        form: str = "norm",
        slack_mass: float = 1.0,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        who = f"TrackingErrorBound {name or ''}".rstrip()
        if quantity not in ("position", "velocity"):
            raise DefinitionError(
                f"{who}: quantity must be 'position' or 'velocity'; got {quantity!r}"
            )
        if form not in ("norm", "squared"):
            raise DefinitionError(f"{who}: form must be 'norm' or 'squared'; got {form!r}")
        if not callable(getattr(reference, "kinematics", None)):
            for method in ("position", "velocity", "acceleration"):
                if not callable(getattr(reference, method, None)):
                    raise DefinitionError(
                        f"{who}: reference needs kinematics(t) or position(t), velocity(t) "
                        f"and acceleration(t); it has no {method}(t)"
                    )
        base = "m" if quantity == "position" else "m/s"
        super().__init__(
            [body],
            upper=0.0,
            level=quantity,
            slack_mass=slack_mass,
            baumgarte=baumgarte,
            unit=base if form == "norm" else f"{base}²",
            name=name,
        )
        self.reference = reference
        self.bound = _bound_profile(bound, who)
        self.quantity = quantity
        self.form = form

    def reference_kinematics(self, t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """r_r, ṙ_r, r̈_r (N; m, m/s, m/s²) at t, evaluated once per time (the rows ask for
        them several times at the same t)."""
        cached = self._ref_cache
        if cached is not None and cached[0] == t:
            return cached[1]
        ref = self.reference
        if callable(getattr(ref, "kinematics", None)):
            r, v, a = ref.kinematics(t)
        else:
            r, v, a = ref.position(t), ref.velocity(t), ref.acceleration(t)
        out = tuple(np.asarray(x, dtype=float).reshape(3) for x in (r, v, a))
        object.__setattr__(self, "_ref_cache", (t, out))
        return out  # type: ignore[return-value]

    def errors(self, q: Config, nu: Config, t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """e = r − r_r, ė = ṙ − ṙ_r (N) and the reference acceleration r̈_r at t."""
        r_r, v_r, a_r = self.reference_kinematics(t)
        return q[0] - r_r, nu[0] - v_r, a_r

    def _error_and_bound(self, q: Config, nu: Config, t: float) -> tuple[FloatArray, Any]:
        e, e_dot, _ = self.errors(q, nu, t)
        return (e if self.quantity == "position" else e_dot), self.bound(t)

    def _norm(self, err: FloatArray) -> float:
        n = float(np.linalg.norm(err))
        if not n > 0.0:
            raise ConstraintError(
                f"{self._who()}: the {self.quantity} error is zero, where the norm form "
                f"(‖error‖ − bound) has no derivative (its rows are not finite); start off "
                f"the reference, or use form='squared'"
            )
        return n

    def _violation_scale(self, t: float) -> float:
        """The bound (norm form) or ½ bound² (squared form): h is a difference of these."""
        d = abs(float(self.bound(float(t))[0]))
        return d if self.form == "norm" else 0.5 * d * d

    def value(self, q: Config, nu: Config, t: float) -> float:
        """‖error‖ − bound, or ½(‖error‖² − bound²) for the squared form."""
        err, (d, _, _) = self._error_and_bound(q, nu, t)
        if self.form == "norm":
            return float(np.linalg.norm(err)) - float(d)
        return 0.5 * (float(err @ err) - float(d) ** 2)

    def casadi_value(self, q: tuple[Any, ...], nu: tuple[Any, ...], t: Any) -> Any:
        """The symbolic form of :meth:`value` (CasADi scalar), at a numeric time t (the
        reference is evaluated numerically: the transcription then goes element by
        element)."""
        ca = casadi()
        if not isinstance(t, (int, float, np.floating)):
            raise DefinitionError(f"TrackingErrorBound {self.name!r} needs a numeric time")
        r_r, v_r, _ = self.reference_kinematics(float(t))
        err = q[0] - column(r_r) if self.quantity == "position" else nu[0] - column(v_r)
        bound = float(self.bound(float(t))[0])
        if self.form == "norm":
            return ca.norm_2(err) - bound
        return 0.5 * (ca.sumsqr(err) - bound**2)

    def jacobian(self, q: Config, nu: Config, t: float) -> FloatArray:
        """errorᵀ/‖error‖ (Eqs. 107, 109), or errorᵀ for the squared form."""
        err, _ = self._error_and_bound(q, nu, t)
        if self.form == "norm":
            return err / self._norm(err)
        return err.copy()

    def bias(self, q: Config, nu: Config, t: float) -> float:
        """b_h of Eqs. 108b / 110b (or of the squared form), without the slack terms."""
        e, e_dot, a_r = self.errors(q, nu, t)
        d, d_dot, d_ddot = (float(x) for x in self.bound(t))
        if self.quantity == "velocity":
            if self.form == "norm":
                return float(a_r @ e_dot) / self._norm(e_dot) + d_dot
            return float(a_r @ e_dot) + d * d_dot
        if self.form == "norm":
            n = self._norm(e)
            ede = float(e_dot @ e)
            return (float(a_r @ e) - float(e_dot @ e_dot)) / n + ede * ede / n**3 + d_ddot
        return float(a_r @ e) - float(e_dot @ e_dot) + d_dot * d_dot + d * d_ddot

    def rate(self, q: Config, nu: Config, t: float) -> float:
        """ḣ at the position level: ėᵀe/‖e‖ − δ̇ (or ėᵀe − δδ̇)."""
        e, e_dot, _ = self.errors(q, nu, t)
        d, d_dot, _ = (float(x) for x in self.bound(t))
        if self.form == "norm":
            return float(e_dot @ e) / self._norm(e) - d_dot
        return float(e_dot @ e) - d * d_dot
