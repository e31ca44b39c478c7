"""The Controller base class.

A controller adds a wrench u to each of its bodies from the state (McCann 2020, Eq. 10b,
the "u" beside τ), and may carry internal states z (e.g. the integral of an error) that the
integrator advances with ż from :meth:`Controller.control`. Control wrenches act on the
plant: the Udwadia–Kalaba solve does not see them (it computes the constraint acceleration of
the nominal, modeled system; Chapter 5). The System evaluates controllers after that solve,
so a controller that declares ``uses_modeled_acceleration = True`` is also handed the modeled
acceleration ν̇_a + ν̇_c (free plus constraint, under the modeled forces) that its wrench adds
to.
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numba import types as numba_types

from gmuk._forms import DeclaresForms
from gmuk._frozen import FreezesInSystem
from gmuk._numba import C1, C2
from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.engine.system import System
    from gmuk.state import State

__all__ = ["CONTROL_KERNEL", "Controller"]

#: The signature of a controller's kernel, as the compiled loop calls it on one rigid body:
#: ``(t, g (4, 4), V (6,), a_model (6,), z, p, u (6,), z_dot) -> status``: the modeled
#: acceleration ν̇_a + ν̇_c and the internal state z in, the wrench u = [u_L; u_f] (body frame,
#: N·m, N) and the state rate ż out; status 0 or a failure code.
CONTROL_KERNEL = numba_types.int64(numba_types.float64, C2, C1, C1, C1, C1, C1, C1)


class Controller(FreezesInSystem, DeclaresForms, abc.ABC):
    """A feedback law producing control wrenches.

    Parameters
    ----------
    bodies : sequence of Body or str
        The bodies it acts on.
    n_states : int
        Number of internal states (default 0).
    name : str, optional
    """

    #: Whether :meth:`control` takes the modeled acceleration as a third argument.
    uses_modeled_acceleration: ClassVar[bool] = False
    #: The kinds of body this controller can act on (default: every kind).
    body_kinds: ClassVar[frozenset[BodyKind]] = frozenset(BodyKind)
    _numeric_methods: ClassVar[tuple[str, ...]] = ("control",)
    _bodies: tuple[Body | str, ...]
    _name: str
    n_states: int

    def __init__(
        self, bodies: Sequence[Body | str], *, n_states: int = 0, name: str | None = None
    ) -> None:
        if isinstance(bodies, str):
            bodies = [bodies]
        if int(n_states) != n_states or n_states < 0:
            raise DefinitionError(f"n_states must be an integer ≥ 0; got {n_states!r}")
        object.__setattr__(self, "_bodies", tuple(bodies))
        object.__setattr__(self, "n_states", int(n_states))
        object.__setattr__(self, "_name", name or type(self).__name__)

    @property
    def bodies(self) -> tuple[Body | str, ...]:
        """The bodies it acts on."""
        return self._bodies

    @property
    def name(self) -> str:
        """Label of the controller."""
        return self._name

    def _compiled_term(self) -> tuple[Any, FloatArray] | None:
        """How the compiled step loop evaluates this controller on its one rigid body: its
        kernel (signature :data:`CONTROL_KERNEL`) and packed parameters, or None when it is
        called in Python (the default). A
        built-in controller returns its term only when its ``control`` is not overridden
        (:meth:`_methods_are`)."""
        return None

    def _system_problems(self, system: System) -> list[str]:
        """What this controller cannot work with in ``system`` (checked once the System's
        parts are valid; none by default), one message each."""
        return []

    def initial_state(self) -> FloatArray:
        """Initial internal state z(0), shape (n_states,); zeros unless overridden."""
        return np.zeros(self.n_states)

    @abc.abstractmethod
    def control(
        self, state: State, z: FloatArray, *modeled: FloatArray
    ) -> tuple[Sequence[Any], Any]:
        """Control wrenches and internal-state rates.

        Parameters
        ----------
        state : State
        z : ndarray, shape (n_states,)
        modeled : ndarray, shape (n_dof,)
            Only for a controller with ``uses_modeled_acceleration = True``: the modeled
            acceleration ν̇_a + ν̇_c of every body (System order, read-only; slice a body's
            with ``state.layout.slot(body)``), to which the control acceleration adds.

        Returns
        -------
        u : sequence of arrays
            One per body of :attr:`bodies`: [u_L; u_f] (6,) in the body frame for a rigid
            body (N·m, N), f_N (3,) for a point mass.
        z_dot : array_like, shape (n_states,)
        """
