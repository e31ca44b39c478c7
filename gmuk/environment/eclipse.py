"""The eclipse event: a body entering or leaving the shadow of the Earth or the Moon.

:class:`EclipseEvent` is a :class:`gmuk.Event` whose value is the signed angular margin of
the body to the shadow cone (:func:`~gmuk.environment.shadow.shadow_margin`, the same
angles as :func:`~gmuk.environment.shadow_fraction`): ``c − (b − a)`` for the umbra,
``c − (a + b)`` for the penumbra, with a and b the apparent radii of the Sun and the
occulter seen from the body and c the angle between their centres. It is positive outside
the shadow and negative inside, and smooth through the crossings (the fraction itself has
kinks there), so the entry is a falling crossing (``direction=-1``), the exit a rising one.

References
----------
Montenbruck & Gill (2000), §3.4.2.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from gmuk._validation import FloatArray
from gmuk.engine.events import Event, _body_name, _position_velocity
from gmuk.environment.ephemeris import RADIUS, _body, position
from gmuk.environment.shadow import margin_from_angles, shadow_angles
from gmuk.environment.time import Epoch
from gmuk.errors import DefinitionError, DomainError

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["EclipseEvent"]


class EclipseEvent(Event):
    """A body crossing the umbra or penumbra cone of the Earth or the Moon.

    Parameters
    ----------
    body : Body or str
        A point mass or a rigid body (its centre of mass, the position of ``g_NB``).
    epoch : Epoch
        The instant of simulation time t = 0 (t in TDB seconds).
    occulter : {"earth", "moon"}
        The shadowing body (default the Earth).
    kind : {"umbra", "penumbra"}
        Which cone (default the umbra).
    centre : {"earth", "moon"}
        The central body at N's origin (ICRF-aligned axes), default the Earth.
    terminal : bool
        Default False: crossings are recorded and the run goes on.
    direction : {-1, 0, 1}
        -1 entries only, +1 exits only, 0 both (default -1: entries).
    name : str, optional
        Default ``"<occulter> <kind>"``, e.g. ``"earth umbra"``.

    Examples
    --------
    >>> from gmuk.environment import EclipseEvent, Epoch
    >>> EclipseEvent("sat", Epoch("2024-03-20T00:00:00"), kind="penumbra").name
    'earth penumbra'
    """

    def __init__(
        self,
        body: Body | str,
        epoch: Epoch,
        occulter: str = "earth",
        kind: str = "umbra",
        *,
        centre: str = "earth",
        terminal: bool = False,
        direction: int = -1,
        name: str | None = None,
    ) -> None:
        occ = _body(occulter, "occulter")
        if occ == "sun":
            raise DefinitionError("EclipseEvent occulter must be 'earth' or 'moon'; got 'sun'")
        if kind not in ("umbra", "penumbra"):
            raise DefinitionError(f"EclipseEvent kind must be 'umbra' or 'penumbra'; got {kind!r}")
        if not isinstance(epoch, Epoch):
            raise DefinitionError(f"epoch must be a gmuk.environment.Epoch; got {epoch!r}")
        super().__init__(terminal=terminal, direction=direction, name=name or f"{occ} {kind}")
        self.body = _body_name(body, "EclipseEvent")
        self.epoch = epoch
        self.occulter = occ
        self.kind = kind
        self.centre = _body(centre, "centre")
        if self.centre == "sun":
            raise DefinitionError("EclipseEvent centre must be 'earth' or 'moon'; got 'sun'")

    def margin(self, t: float, r_N: FloatArray) -> float:
        """The signed margin (rad) at simulation time t of a point at r_N (m)."""
        e = self.epoch + t
        s = position("sun", e, self.centre)
        o = position(self.occulter, e, self.centre)
        a, b, c = shadow_angles(r_N, s, o, RADIUS["sun"], RADIUS[self.occulter])
        if b < 0.0:
            raise DomainError(
                f"{self.name}: r_N = {list(r_N)} m is inside the {self.occulter} at t = {t!r} s"
            )
        return margin_from_angles(a, b, c, self.kind)

    def value(self, t: float, state: State) -> float:
        """The signed margin (rad): > 0 outside the shadow, < 0 inside."""
        r, _ = _position_velocity(state, self.body)
        return self.margin(t, r)

    def __repr__(self) -> Any:
        return (
            f"EclipseEvent({self.body!r}, {self.epoch!r}, occulter={self.occulter!r}, "
            f"kind={self.kind!r}, direction={self.direction})"
        )
