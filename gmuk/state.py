"""The State of a System at one instant, and the Layout that indexes it.

A :class:`State` is an immutable snapshot: time, the poses and twists of the rigid bodies,
the positions and velocities of the Euclidean bodies (point masses and slack coordinates),
and the controllers' internal states. A :class:`Layout` (made once by the System) says where
each body's numbers are. Nothing here is mutated by the System or the integrator.

A State's arrays are read-only (``flags.writeable`` is False), and they are its own: a
part (force model, constraint, controller) that writes into the state it is given fails
with numpy's ``ValueError: assignment destination is read-only`` (the run names the part),
and the arrays a caller passed in are copied, never frozen or shared, so the caller's
data cannot change behind its back either.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Union

import numpy as np

from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError

if TYPE_CHECKING:
    from gmuk.bodies import Body

__all__ = ["Layout", "State"]

BodyRef = Union["Body", str]

_F64 = np.dtype(np.float64)
_ARRAYS = ("g", "V", "x", "xdot", "z")


def _frozen(a: np.ndarray) -> bool:
    """Whether no one can write ``a``'s values: it and every array it views are read-only.

    (An array owning its data could be made writable again by whoever holds it; the engine
    and the State never do that.)"""
    while True:
        if a.flags.writeable:
            return False
        base = a.base
        if base is None:
            return True
        if type(base) is not np.ndarray:  # a buffer (bytes, mmap, ...): copy to be sure
            return False
        a = base


@dataclass(frozen=True)
class _Slot:
    kind: BodyKind
    index: int  # rigid: index into g/V; euclidean: offset into x/xdot
    dof: int
    offset: int  # offset in the generalized velocity vector ν


@dataclass(frozen=True)
class Layout:
    """Where each body's coordinates live in a :class:`State` and in ν.

    Attributes
    ----------
    names : tuple of str
        Body names in System order (the order of ν, A's columns and accelerations).
    kinds : tuple of BodyKind
        The kind of each body (given as BodyKind or its tag "rigid", "point", "slack").
    n_dof : int
        Σ dof: length of the generalized velocity ν.
    n_rigid, n_euclid, n_control : int
        Number of rigid bodies, of Euclidean coordinates (3 per point mass, 1 per slack),
        and of controller internal states.
    """

    names: tuple[str, ...]
    kinds: tuple[BodyKind, ...]
    dofs: tuple[int, ...]
    n_control: int = 0
    _slots: dict[str, _Slot] = field(init=False, repr=False, compare=False)
    n_dof: int = field(init=False)
    n_rigid: int = field(init=False)
    n_euclid: int = field(init=False)
    rigid_offsets: FloatArray = field(init=False, repr=False, compare=False)
    euclid_offsets: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        try:
            kinds = tuple(BodyKind(k) for k in self.kinds)
        except ValueError:
            raise DefinitionError(
                f"body kinds must be among {[k.value for k in BodyKind]}; got {list(self.kinds)}"
            ) from None
        object.__setattr__(self, "kinds", kinds)
        slots: dict[str, _Slot] = {}
        offset = n_rigid = n_euclid = 0
        rigid_off: list[int] = []
        euclid_off: list[int] = []
        for name, kind, dof in zip(self.names, kinds, self.dofs, strict=True):
            if kind is BodyKind.RIGID:
                slots[name] = _Slot(kind, n_rigid, dof, offset)
                rigid_off.append(offset)
                n_rigid += 1
            else:
                slots[name] = _Slot(kind, n_euclid, dof, offset)
                euclid_off.extend(range(offset, offset + dof))
                n_euclid += dof
            offset += dof
        object.__setattr__(self, "_slots", slots)
        object.__setattr__(self, "n_dof", offset)
        object.__setattr__(self, "n_rigid", n_rigid)
        object.__setattr__(self, "n_euclid", n_euclid)
        object.__setattr__(self, "rigid_offsets", np.array(rigid_off, dtype=np.intp))
        object.__setattr__(self, "euclid_offsets", np.array(euclid_off, dtype=np.intp))

    def slot(self, body: BodyRef) -> _Slot:
        """The slot of a body given by object or name."""
        name = body if isinstance(body, str) else body.name
        try:
            return self._slots[name]
        except KeyError:
            raise DefinitionError(
                f"no body named {name!r} in this system; bodies are {list(self.names)}"
            ) from None

    def columns(self, bodies: tuple[BodyRef, ...]) -> np.ndarray:
        """Indices into ν of the given bodies' velocities, concatenated in the given order."""
        cols: list[int] = []
        for b in bodies:
            s = self.slot(b)
            cols.extend(range(s.offset, s.offset + s.dof))
        return np.array(cols, dtype=np.intp)


@dataclass(frozen=True, eq=False)
class State:
    """A snapshot of a System at time ``t``.

    Use the accessors (:meth:`pose`, :meth:`twist`, :meth:`position`, :meth:`velocity`)
    with a body or its name rather than indexing the arrays.

    Attributes
    ----------
    t : float
        Time (s).
    g : ndarray, shape (n_rigid, 4, 4)
        Poses g_NB of the rigid bodies, in System order.
    V : ndarray, shape (n_rigid, 6)
        Body twists V_B = [ω; v] (rad/s, m/s).
    x : ndarray, shape (n_euclid,)
        Point-mass positions r_N (m, 3 each) and slack coordinates, in System order.
    xdot : ndarray, shape (n_euclid,)
        Their rates (m/s, …).
    z : ndarray, shape (n_control,)
        Controllers' internal states.
    layout : Layout
        Index of the bodies.

    Notes
    -----
    The arrays are read-only float64 arrays owned by the State (or shared with another
    State): the constructor copies any array that someone could still write, so neither a
    part that is handed the State nor the caller who built it can change it afterwards.
    The accessors return read-only views.
    """

    t: float
    g: FloatArray
    V: FloatArray
    x: FloatArray
    xdot: FloatArray
    z: FloatArray
    layout: Layout

    def __post_init__(self) -> None:
        # Read-only arrays of its own: a copy of each array unless it is already read-only
        # all the way down (another State's, or one this module froze), which is shared.
        for name in _ARRAYS:
            a = getattr(self, name)
            if not (type(a) is np.ndarray and a.dtype == _F64 and _frozen(a)):
                a = np.array(a, dtype=np.float64)
                a.setflags(write=False)
                object.__setattr__(self, name, a)

    @classmethod
    def _adopt(
        cls,
        t: float,
        g: FloatArray,
        V: FloatArray,
        x: FloatArray,
        xdot: FloatArray,
        z: FloatArray,
        layout: Layout,
    ) -> State:
        """A State that takes over fresh float64 arrays no one else holds (they are made
        read-only here, not copied or checked): for the engine's own copies, which it hands
        over. Cheaper than the constructor (the compiled loop's callback makes one per call,
        as read-only views of one frozen copy)."""
        for a in (g, V, x, xdot, z):
            if a.flags.writeable:
                a.setflags(write=False)
        obj = object.__new__(cls)
        obj.__dict__.update(t=t, g=g, V=V, x=x, xdot=xdot, z=z, layout=layout)
        return obj

    def pose(self, body: BodyRef) -> FloatArray:
        """Pose g_NB (4, 4) of a rigid body."""
        s = self._slot(body, "rigid", "pose")
        return self.g[s.index]

    def twist(self, body: BodyRef) -> FloatArray:
        """Body twist V_B = [ω; v] (6,) of a rigid body (rad/s, m/s)."""
        s = self._slot(body, "rigid", "twist")
        return self.V[s.index]

    def position(self, body: BodyRef) -> FloatArray:
        """Position r_N (3,) of a point mass or a rigid body (m), or a slack value (1,)."""
        s = self.layout.slot(body)
        if s.kind == "rigid":
            return self.g[s.index, :3, 3]
        return self.x[s.index : s.index + s.dof]

    def velocity(self, body: BodyRef) -> FloatArray:
        """Velocity of a body's coordinates: v_N (3,) of a point mass, the rate (1,) of a
        slack coordinate, or the twist V_B (6,) of a rigid body."""
        s = self.layout.slot(body)
        if s.kind == "rigid":
            return self.V[s.index]
        return self.xdot[s.index : s.index + s.dof]

    def nu(self) -> FloatArray:
        """Generalized velocity ν (n_dof,): every body's velocity in System order."""
        out = np.empty(self.layout.n_dof)
        lay = self.layout
        if lay.n_rigid:
            out[(lay.rigid_offsets[:, None] + np.arange(6)).ravel()] = self.V.ravel()
        if lay.n_euclid:
            out[lay.euclid_offsets] = self.xdot
        return out

    def _slot(self, body: BodyRef, kind: str, what: str) -> _Slot:
        s = self.layout.slot(body)
        if s.kind != kind:
            name = body if isinstance(body, str) else body.name
            raise DefinitionError(f"{what}() needs a {kind} body; {name!r} is a {s.kind} body")
        return s

    def replace(self, **changes: object) -> State:
        """A copy with some fields replaced (the State itself is immutable)."""
        from dataclasses import replace

        return replace(self, **changes)  # type: ignore[arg-type]
