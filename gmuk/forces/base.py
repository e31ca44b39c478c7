"""The ForceModel base class.

A force model gives, for a state, the wrench τ_B = [L; f] on each rigid body it applies to
(torque about the centre of mass and force, in the body frame: N·m, N) and the force f_N
(N, inertial frame) on each point mass. It is *modeled* (the Udwadia–Kalaba solve knows it:
it enters the free acceleration V̇_a) or *unmodeled* (it acts on the plant only, as a
disturbance the constraint solve does not see; McCann 2020, Chapter 5).
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._frozen import FreezesInSystem
from gmuk._validation import FloatArray

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["ForceModel"]


class ForceModel(FreezesInSystem, abc.ABC):
    """A source of wrenches on bodies.

    Subclasses implement :meth:`wrench` for one body at a time; models that couple bodies
    (a spring between two bodies) override :meth:`wrenches` instead.

    Parameters
    ----------
    bodies : sequence of Body or str, optional
        The bodies it acts on; all rigid bodies and point masses of the System if omitted
        (slack coordinates never, unless listed).
    modeled : bool
        Whether the constraint solve knows this force (default True).
    name : str, optional
    """

    _bodies: tuple[Body | str, ...] | None
    _name: str
    modeled: bool

    def __init__(
        self,
        bodies: Sequence[Body | str] | None = None,
        *,
        modeled: bool = True,
        name: str | None = None,
    ) -> None:
        if isinstance(bodies, str):
            bodies = [bodies]
        object.__setattr__(self, "_bodies", None if bodies is None else tuple(bodies))
        object.__setattr__(self, "modeled", bool(modeled))
        object.__setattr__(self, "_name", name or type(self).__name__)

    @property
    def bodies(self) -> tuple[Body | str, ...] | None:
        """The bodies it acts on, or None for all rigid bodies and point masses."""
        return self._bodies

    @property
    def name(self) -> str:
        """Label of the force model."""
        return self._name

    @abc.abstractmethod
    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: Body) -> Any:
        """Wrench on one body.

        Parameters
        ----------
        t : float
            Time (s).
        g_NB : ndarray, shape (4, 4)
            Pose of the body. For a point mass: identity rotation and r_N.
        V_B : ndarray, shape (6,)
            Body twist [ω; v]. For a point mass: [0, 0, 0, v_N].
        body : Body

        Returns
        -------
        array_like, shape (6,) for a rigid body ([L; f] in B, N·m and N), or (3,) for a
        point mass (f_N, N).
        """

    def wrenches(self, state: State, bodies: Sequence[Body]) -> list[FloatArray]:
        """Wrenches on each of ``bodies`` at ``state`` (6 per rigid body, 3 per point mass)."""
        out: list[FloatArray] = []
        for body in bodies:
            if body.kind == "rigid":
                w = self.wrench(state.t, state.pose(body), state.twist(body), body)
            else:
                g = np.eye(4)
                g[:3, 3] = state.position(body)
                V = np.zeros(6)
                V[3:] = state.velocity(body)
                w = self.wrench(state.t, g, V, body)
            out.append(np.asarray(w, dtype=float))
        return out

    def __repr__(self) -> str:
        who = (
            "all"
            if self.bodies is None
            else [b if isinstance(b, str) else b.name for b in self.bodies]
        )
        return f"{type(self).__name__}(bodies={who}, modeled={self.modeled})"
