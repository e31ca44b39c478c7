"""Events of a simulation: functions of (t, state) whose sign changes
:func:`~gmuk.engine.integrate.simulate` (and :meth:`gmuk.System.simulate`) locates in time.

An :class:`Event` wraps a function ``g(t, state) -> float``. After every accepted step the
loop evaluates each event at the step's end; where ``g`` changes sign over the step (in the
event's ``direction``), the crossing time is found by Brent's method
(:func:`scipy.optimize.brentq`, ``xtol`` = :data:`XTOL` s) on the step's continuous
extension: DOP853's dense output of order 7, or, for a method without one (DOPRI5, RK4),
a step of the method itself from the step's start to each trial time. A *recorded* event
is added to :attr:`gmuk.Trajectory.events` and the run goes on, its other numbers
unchanged; a *terminal* event ends the run there: the event's state is the trajectory's
last output and its status is ``"terminated"``.

The crossing rule: the sign change is counted in the step whose end first reaches or passes
zero, ``g(t₀) < 0 ≤ g(t₁)`` rising and ``g(t₀) > 0 ≥ g(t₁)`` falling. A function that is
exactly zero at the start time therefore does not trigger there (nor when it leaves zero),
and a zero that a step lands on exactly is reported once, not again at the next step. Two
sign changes within one step cancel and are not seen: keep ``max_step`` below the shortest
time between crossings when that can happen.

Built in: :class:`AltitudeEvent` (a body's distance to a sphere: impact, or an altitude
crossed) and :class:`ApsisEvent` (periapsis and apoapsis, the zeros of r·v).

References
----------
Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., §II.6
(dense output and event location). Shampine & Thompson, "Event location for ordinary
differential equations", Comput. Math. Appl. 39 (2000).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from gmuk._validation import FloatArray, as_array, real_number, strict_bool
from gmuk.errors import DefinitionError, NonFiniteError
from gmuk.state import State
from gmuk.trajectory import EventRecord

if TYPE_CHECKING:
    from gmuk.bodies import Body

__all__ = ["XTOL", "AltitudeEvent", "ApsisEvent", "Event", "EventRecord", "check_events"]

#: Brent's method stops when the bracket of the crossing time is this small (s), or at the
#: resolution of a double near t (4 ε abs(t)) for large times.
XTOL = 1e-13


class Event:
    """A scalar function of (t, state) whose zero crossings a simulation locates.

    Parameters
    ----------
    function : callable, optional
        ``function(t, state) -> float``: ``t`` in s, ``state`` a :class:`gmuk.State`; it
        must return one finite real number. Required unless a subclass overrides
        :meth:`value`.
    terminal : bool
        True: the run stops at the first crossing (the event's state is the last output,
        status ``"terminated"``). False (default): the crossing is recorded and the run
        goes on.
    direction : {-1, 0, 1}
        Which crossings count: +1 rising (from negative to positive), -1 falling, 0 both
        (default).
    name : str, optional
        The name in :attr:`gmuk.Trajectory.events` (default: the function's ``__name__``,
        or the class's name for a subclass).

    Attributes
    ----------
    terminal : bool
    direction : int
    name : str

    Raises
    ------
    DefinitionError
        For a function that is not callable, a direction other than -1, 0 or 1, a
        ``terminal`` that is not a bool or a name that is not a non-empty string.

    Examples
    --------
    >>> import gmuk
    >>> below_1km = gmuk.Event(lambda t, s: s.position("ball")[2] - 1000.0,
    ...                        terminal=True, direction=-1, name="below 1 km")
    """

    def __init__(
        self,
        function: Callable[[float, State], float] | None = None,
        *,
        terminal: bool = False,
        direction: int = 0,
        name: str | None = None,
    ) -> None:
        overridden = type(self).value is not Event.value
        if function is None and not overridden:
            raise DefinitionError(
                "Event needs a function(t, state) -> float (or a subclass that overrides "
                "value); got None"
            )
        if function is not None and not callable(function):
            raise DefinitionError(
                f"Event function must be callable as function(t, state) -> float; got "
                f"{type(function).__name__} {function!r:.60}"
            )
        self.function = function
        self.terminal = strict_bool(terminal, "Event terminal")
        if (
            isinstance(direction, (bool, np.bool_))
            or not isinstance(direction, (int, np.integer))
            or direction not in (-1, 0, 1)
        ):
            raise DefinitionError(
                f"Event direction must be -1 (falling), 0 (both) or 1 (rising); got {direction!r}"
            )
        self.direction = int(direction)
        if name is None:
            name = getattr(function, "__name__", None) if function is not None else None
            if not name or name == "<lambda>":
                name = type(self).__name__ if overridden or function is None else "event"
        if not isinstance(name, str) or not name:
            raise DefinitionError(f"Event name must be a non-empty string; got {name!r}")
        self.name = name

    def value(self, t: float, state: State) -> float:
        """The event function at time ``t`` (s) and ``state``: ``function(t, state)``."""
        assert self.function is not None  # checked in __init__ unless overridden
        return self.function(t, state)

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}(name={self.name!r}, terminal={self.terminal}, "
            f"direction={self.direction})"
        )


def _body_name(body: Body | str, who: str) -> str:
    name = body if isinstance(body, str) else getattr(body, "name", None)
    if not isinstance(name, str) or not name:
        raise DefinitionError(f"{who}: body must be a Body or a body name; got {body!r:.60}")
    return name


def _position_velocity(state: State, name: str) -> tuple[FloatArray, FloatArray]:
    """Position r_N (m) and inertial velocity v_N (m/s) of a point mass or of a rigid body's
    origin (R_NB v_B)."""
    slot = state.layout.slot(name)
    if slot.kind == "rigid":
        g = state.g[slot.index]
        return g[:3, 3], g[:3, :3] @ state.V[slot.index, 3:]
    if slot.kind != "point":
        raise DefinitionError(
            f"body {name!r} is a {slot.kind} body; expected a rigid or point body"
        )
    i = slot.index
    return state.x[i : i + 3], state.xdot[i : i + 3]


class AltitudeEvent(Event):
    """A body's altitude above a sphere crossing a level: ``‖r − c‖ − radius − altitude``.

    Parameters
    ----------
    body : Body or str
        A point mass or a rigid body (its origin, the position of ``g_NB``).
    radius : float
        The sphere's radius (m), > 0.
    altitude : float
        The level (m) above the sphere (default 0: the surface, an impact).
    center : array_like, shape (3,)
        The sphere's centre in N (m), default the origin.
    terminal : bool
        Default True: the run stops at the crossing.
    direction : {-1, 0, 1}
        Default -1: descending through the level (impact).
    name : str, optional
        Default ``"altitude"``.
    """

    def __init__(
        self,
        body: Body | str,
        radius: float,
        altitude: float = 0.0,
        center: Sequence[float] | FloatArray = (0.0, 0.0, 0.0),
        *,
        terminal: bool = True,
        direction: int = -1,
        name: str | None = None,
    ) -> None:
        super().__init__(terminal=terminal, direction=direction, name=name or "altitude")
        self.body = _body_name(body, "AltitudeEvent")
        self.radius = real_number(radius, "AltitudeEvent radius (m)", positive=True)
        self.altitude = real_number(altitude, "AltitudeEvent altitude (m)")
        self.center = as_array(center, (3,), "AltitudeEvent center (m)", batch=False).copy()

    def value(self, t: float, state: State) -> float:
        """``‖r_N − center‖ − radius − altitude`` (m)."""
        r, _ = _position_velocity(state, self.body)
        return float(np.linalg.norm(r - self.center)) - self.radius - self.altitude


class ApsisEvent(Event):
    """Periapsis and apoapsis of a body about a centre: the zeros of ``(r − c)·v``.

    ``(r − c)·v = r ṙ`` rises through zero at periapsis and falls at apoapsis, so ``kind``
    only sets the direction.

    Parameters
    ----------
    body : Body or str
        A point mass or a rigid body (its origin; its velocity is ``R_NB v_B``).
    mu : float, optional
        The central body's gravitational parameter (m³/s²). When given, the value is
        scaled to the dimensionless ``ṙ / √(μ/‖r‖)`` (radial over circular speed); the
        crossing times do not depend on it.
    kind : {"periapsis", "apoapsis", "both"}
        Which apsides (default periapsis).
    center : array_like, shape (3,)
        The centre in N (m), at rest; default the origin.
    terminal : bool
        Default False: recorded.
    name : str, optional
        Default ``kind``.
    """

    _DIRECTIONS: ClassVar[dict[str, int]] = {"periapsis": 1, "apoapsis": -1, "both": 0}

    def __init__(
        self,
        body: Body | str,
        mu: float | None = None,
        kind: str = "periapsis",
        *,
        center: Sequence[float] | FloatArray = (0.0, 0.0, 0.0),
        terminal: bool = False,
        name: str | None = None,
    ) -> None:
        if kind not in self._DIRECTIONS:
            raise DefinitionError(
                f"ApsisEvent kind must be 'periapsis', 'apoapsis' or 'both'; got {kind!r}"
            )
        super().__init__(terminal=terminal, direction=self._DIRECTIONS[kind], name=name or kind)
        self.kind = kind
        self.body = _body_name(body, "ApsisEvent")
        self.mu = None if mu is None else real_number(mu, "ApsisEvent mu (m³/s²)", positive=True)
        self.center = as_array(center, (3,), "ApsisEvent center (m)", batch=False).copy()

    def value(self, t: float, state: State) -> float:
        """``(r − c)·v`` (m²/s), or ``ṙ/√(μ/‖r − c‖)`` with ``mu``."""
        r, v = _position_velocity(state, self.body)
        d = r - self.center
        rv = float(d @ v)
        if self.mu is None:
            return rv
        dist = float(np.linalg.norm(d))
        return rv / dist / math.sqrt(self.mu / dist)


def check_events(events: Any) -> tuple[Event, ...]:
    """``events`` (None, an Event or a sequence of them) as a tuple of Events with distinct
    names, or a DefinitionError saying what came in."""
    if events is None:
        return ()
    if isinstance(events, Event):
        return (events,)
    if isinstance(events, (str, bytes)) or not isinstance(events, Sequence):
        raise DefinitionError(
            f"events must be a list of gmuk.Event; got {type(events).__name__} {events!r:.60}"
        )
    out = tuple(events)
    bad = [f"{i}: {type(e).__name__}" for i, e in enumerate(out) if not isinstance(e, Event)]
    if bad:
        raise DefinitionError(
            f"events must be gmuk.Event objects (wrap a function as gmuk.Event(f)); got "
            f"{', '.join(bad)}"
        )
    names = [e.name for e in out]
    dups = sorted({n for n in names if names.count(n) > 1})
    if dups:
        raise DefinitionError(
            f"events must have distinct names (pass name=...); {', '.join(map(repr, dups))} "
            "given twice"
        )
    return out


def event_value(event: Event, t: float, state: State) -> float:
    """``event.value(t, state)`` as a float, or a DefinitionError (a result that is not one
    real number) or NonFiniteError (NaN or infinity) that names the event and the time."""
    raw = event.value(t, state)
    if isinstance(raw, (bool, np.bool_)) or not (
        isinstance(raw, (int, float, np.integer, np.floating))
        or (isinstance(raw, np.ndarray) and raw.shape == () and raw.dtype.kind in "iuf")
    ):
        shape = f" of shape {raw.shape}" if isinstance(raw, np.ndarray) else ""
        raise DefinitionError(
            f"event {event.name!r} must return one real number at t = {t:.9g} s; got "
            f"{type(raw).__name__}{shape} {raw!r:.60}"
        )
    value = float(raw)
    if not math.isfinite(value):
        raise NonFiniteError(
            f"event {event.name!r} returned {value} at t = {t:.9g} s; expected a finite number"
        )
    return value
