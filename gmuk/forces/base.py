"""The ForceModel base class.

A force model gives, for a state, the wrench τ_B = [L; f] on each rigid body it applies to
(torque about the centre of mass and force, in the body frame: N·m, N) through
:meth:`ForceModel.wrench`, and the force f_N (N, inertial frame) on each point mass through
:meth:`ForceModel.force`. It is *modeled* (the Udwadia–Kalaba solve knows it: it enters the
free acceleration V̇_a) or *unmodeled* (it acts on the plant only, as a disturbance the
constraint solve does not see; McCann 2020, Chapter 5).

A model declares the kinds of body it acts on in :attr:`ForceModel.acts_on`; by default the
kinds whose method it implements (``wrench`` → rigid bodies, ``force`` → point masses). The
System checks that declaration once, when it is built.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar, cast

import numpy as np

from gmuk._frozen import FreezesInSystem
from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody
    from gmuk.state import State

__all__ = ["ForceModel"]


class ForceModel(FreezesInSystem):
    """A source of wrenches on bodies.

    Subclasses implement :meth:`wrench` for rigid bodies and/or :meth:`force` for point
    masses (one body at a time); models that couple bodies (a spring between two bodies)
    override :meth:`wrenches` instead and declare :attr:`acts_on`.

    Parameters
    ----------
    bodies : sequence of Body or str, optional
        The bodies it acts on; default: every body of the System whose kind is in
        :attr:`acts_on`.
    modeled : bool
        Whether the constraint solve knows this force (default True).
    name : str, optional

    Attributes
    ----------
    acts_on : frozenset of BodyKind
        Class attribute: the kinds of body this model can act on. Derived from the
        methods a subclass implements unless the subclass sets it.
    """

    acts_on: ClassVar[frozenset[BodyKind]] = frozenset()
    _bodies: tuple[Body | str, ...] | None
    _name: str
    modeled: bool

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "acts_on" in cls.__dict__:
            cls.acts_on = frozenset(BodyKind(k) for k in cls.__dict__["acts_on"])
            return
        kinds = set()
        if cls.wrench is not ForceModel.wrench:
            kinds.add(BodyKind.RIGID)
        if cls.force is not ForceModel.force:
            kinds.add(BodyKind.POINT)
        cls.acts_on = frozenset(kinds)

    def __init__(
        self,
        bodies: Sequence[Body | str] | None = None,
        *,
        modeled: bool = True,
        name: str | None = None,
    ) -> None:
        if isinstance(bodies, str):
            bodies = [bodies]
        if type(self).wrenches is ForceModel.wrenches and not self.acts_on:
            raise DefinitionError(
                f"{type(self).__name__} implements neither wrench() (rigid bodies) nor "
                "force() (point masses), nor wrenches(); a ForceModel needs at least one"
            )
        object.__setattr__(self, "_bodies", None if bodies is None else tuple(bodies))
        object.__setattr__(self, "modeled", bool(modeled))
        object.__setattr__(self, "_name", name or type(self).__name__)

    @property
    def bodies(self) -> tuple[Body | str, ...] | None:
        """The bodies it acts on, or None for every body of a kind in :attr:`acts_on`."""
        return self._bodies

    @property
    def name(self) -> str:
        """Label of the force model."""
        return self._name

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> Any:
        """Wrench on one rigid body.

        Parameters
        ----------
        t : float
            Time (s).
        g_NB : ndarray, shape (4, 4)
            Pose of the body in N (rotation R_NB, position r_N in m).
        V_B : ndarray, shape (6,)
            Body twist [ω; v] in B (rad/s, m/s).
        body : Body
            The rigid body (its ``mass`` and ``inertia``).

        Returns
        -------
        array_like, shape (6,)
            [L; f] in the body frame: torque about the centre of mass (N·m) and force (N).
        """
        raise DefinitionError(f"{self.name} does not act on rigid bodies")

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> Any:
        """Force on one point mass.

        Parameters
        ----------
        t : float
            Time (s).
        r_N, v_N : ndarray, shape (3,)
            Position (m) and velocity (m/s) in the inertial frame N.
        body : Body
            The point mass (its ``mass``).

        Returns
        -------
        array_like, shape (3,)
            f_N, the force in N (N).
        """
        raise DefinitionError(f"{self.name} does not act on point masses")

    def _compiled_term(self, body: Body) -> tuple[int, tuple[float, ...], Any] | None:
        """How the compiled step loop evaluates this model on ``body``: (code of
        :mod:`gmuk.forces._kernels`, parameters, field data vector or None), or None when
        the model has no compiled form and is called in Python. Built-in models return their
        term only when their ``force``/``wrench``/``wrenches`` are not overridden."""
        return None

    def _methods_are(self, cls: type) -> bool:
        """Whether this object's wrench, force and wrenches are those of ``cls`` (a
        subclass that overrides any of them gets no compiled term)."""
        t = type(self)
        return all(getattr(t, k) is getattr(cls, k) for k in ("wrench", "force", "wrenches"))

    def wrenches(self, state: State, bodies: Sequence[Body]) -> list[FloatArray]:
        """Wrenches on each of ``bodies`` at ``state``: [L; f] (6,) in B per rigid body,
        f_N (3,) per point mass (and (dof,) per other Euclidean body)."""
        out: list[FloatArray] = []
        t = state.t
        for body in bodies:
            if body.kind is BodyKind.RIGID:
                w = self.wrench(t, state.pose(body), state.twist(body), cast("RigidBody", body))
            else:
                w = self.force(t, state.position(body), state.velocity(body), body)
            out.append(np.asarray(w, dtype=float))
        return out

    def __repr__(self) -> str:
        who = (
            "all"
            if self.bodies is None
            else [b if isinstance(b, str) else b.name for b in self.bodies]
        )
        return f"{type(self).__name__}(bodies={who}, modeled={self.modeled})"
