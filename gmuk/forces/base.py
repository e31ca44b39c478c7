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

A model with a compiled form writes its physics once, as a numba kernel beside its class with
the signature :data:`FORCE_KERNEL`: ``kernel(rigid, t, g, V, m, J, p, field, out) -> status``.
The class names it ``_kernel`` and packs its parameters in ``_kernel_params(body)``; its
``wrench``/``force`` call it through :meth:`ForceModel._kernel_load`, and the compiled step loop
calls the same compiled function through its address (:func:`gmuk._numba.kernel_address`):
nothing else lists the kernel, so a new model with a compiled form touches its own module
only. Such a kernel writes a force at the centre of mass with :func:`com_load`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar, cast

import numpy as np
from numba import types as numba_types

from gmuk._forms import DeclaresForms
from gmuk._frozen import FreezesInSystem
from gmuk._numba import C1, C1_READONLY, C2, njit
from gmuk._validation import FloatArray, check_sequence, distinct_bodies, strict_bool
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError, DomainError

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody
    from gmuk.state import State

__all__ = ["FORCE_KERNEL", "ForceModel", "com_load", "kernel_arguments"]

#: The signature of a force model's kernel, as the compiled loop calls it:
#: ``(rigid, t, g (4, 4), V (6,), m, J (3, 3), p, field (read-only), out) -> status``, with
#: ``out`` the body-frame wrench [L; f] (6,) of a rigid body or the force f_N (3,) on a point
#: mass (then at ``g[:3, 3]`` with velocity ``V[:3]``), and status 0 or a nonzero failure code.
FORCE_KERNEL = numba_types.int64(
    numba_types.boolean, numba_types.float64, C2, C1, numba_types.float64, C2, C1, C1_READONLY, C1
)

# the kernels' arguments that a body or a model does not have (read-only, as the compiled
# loop passes its field data: the Python calls then use the loop's compiled kernels)
_NO_INERTIA = np.zeros((3, 3))
_NO_FIELD = np.zeros(1)
_NO_FIELD.setflags(write=False)


def kernel_arguments(
    rigid: bool, x: Any, v: Any, body: Body
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(g, V, J, out): a force kernel's body arguments laid out as the compiled loop lays them
    out — a rigid body's pose ``x`` = g_NB (4, 4), twist ``v`` = V_B and central inertia, with
    room for its wrench (6,); a point mass's position ``x`` = r_N in a pose's translation and
    velocity ``v`` = v_N in a twist's first three entries, no inertia, room for its force (3,)."""
    if rigid:
        g = np.array(x, dtype=float)
        V = np.array(v, dtype=float)
        J = np.array(cast("RigidBody", body).inertia, dtype=float)
        return g, V, J, np.empty(6)
    g = np.eye(4)
    g[:3, 3] = x
    V = np.zeros(6)
    V[:3] = v
    return g, V, _NO_INERTIA, np.empty(3)


def _read_only(data: Any) -> FloatArray:
    """A read-only float64 view of field data: the type the loop passes the kernel."""
    view = np.asarray(data, dtype=float).view()
    view.setflags(write=False)
    return view


@njit(cache=True)
def com_load(rigid, g, fx, fy, fz, out):  # type: ignore[no-untyped-def]
    """Write a force f_N = (fx, fy, fz) (N, frame N) acting at the centre of mass into a force
    kernel's ``out``: the body-frame wrench ``[0; Rᵀ f_N]`` (6,) of a rigid body at pose
    ``g`` (4, 4), or f_N itself (3,) for a point mass."""
    if rigid:
        out[0] = out[1] = out[2] = 0.0
        out[3] = g[0, 0] * fx + g[1, 0] * fy + g[2, 0] * fz
        out[4] = g[0, 1] * fx + g[1, 1] * fy + g[2, 1] * fz
        out[5] = g[0, 2] * fx + g[1, 2] * fy + g[2, 2] * fz
    else:
        out[0] = fx
        out[1] = fy
        out[2] = fz


class ForceModel(FreezesInSystem, DeclaresForms):
    """A source of wrenches on bodies.

    Subclasses implement :meth:`wrench` for rigid bodies and/or :meth:`force` for point
    masses (one body at a time); models that couple bodies (a spring between two bodies)
    override :meth:`wrenches` instead and declare :attr:`acts_on`.

    Parameters
    ----------
    bodies : sequence of Body or str, optional
        The bodies it acts on, each at most once (a Body and its name count as the same
        body); default: every body of the System whose kind is in :attr:`acts_on`.
    modeled : bool
        Whether the constraint solve knows this force (default True); exactly True or
        False (``"False"``, 0 or None are refused, not read by their truthiness).
    name : str, optional

    Raises
    ------
    DefinitionError
        If ``bodies`` is not a sequence or lists a body twice, or ``modeled`` is not a bool.

    Attributes
    ----------
    acts_on : frozenset of BodyKind
        Class attribute: the kinds of body this model can act on. Derived from the
        methods a subclass implements unless the subclass sets it.
    mass_proportional : bool
        Class attribute: whether its force and torque scale with the body's mass and
        inertia (the gravity models: True; default False).
    """

    acts_on: ClassVar[frozenset[BodyKind]] = frozenset()
    #: Whether its force and torque on a body scale with the body's mass and inertia
    #: (gravity), so that the acceleration they give does not change when the body's mass
    #: distribution scales: what a thrusting body of varying mass
    #: (:class:`gmuk.actuators.Thrusters`) accepts. False unless a model says so.
    mass_proportional: ClassVar[bool] = False
    _numeric_methods = ("wrench", "force", "wrenches")
    #: A built-in model's compiled kernel (see the module docstring); none by default.
    _kernel: ClassVar[Any]
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
        who = type(self).__name__ + (f" {name!r}" if name else "")
        if bodies is not None:
            bodies = distinct_bodies(check_sequence(bodies, f"{who}: bodies"), who)
        object.__setattr__(self, "_bodies", bodies)
        object.__setattr__(self, "modeled", strict_bool(modeled, f"{who}: modeled"))
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

    def _compiled_term(self, body: Body) -> tuple[Any, tuple[float, ...], Any] | None:
        """How the compiled step loop evaluates this model on ``body``: (its kernel, with the
        signature :data:`FORCE_KERNEL`; parameters; field data vector or None), or None when
        the model has no compiled form and is called in Python. A model has the compiled form
        of the class that defines its ``_kernel`` when its ``wrench``, ``force`` and
        ``wrenches`` are that class's (a subclass that overrides one of them has none), and
        when ``_kernel_params(body)`` packs parameters for the body."""
        kernel = self._declared_form("_kernel")
        packed = self._kernel_params(body) if kernel is not None else None
        if packed is None:
            return None
        params, data = packed
        return kernel, tuple(float(v) for v in params), data

    def _kernel_params(self, body: Body) -> tuple[Any, Any] | None:
        """The parameters of :attr:`_kernel` for ``body`` and the field data vector (or
        None); None when the kernel cannot evaluate this model on ``body``."""
        raise DefinitionError(f"{type(self).__name__} has no compiled kernel")

    def _kernel_load(self, rigid: bool, t: float, x: Any, v: Any, body: Body) -> FloatArray:
        """This model's kernel on one body, as the compiled loop calls it: the body-frame
        wrench [L; f] (6,) of a rigid body at pose ``x`` = g_NB with twist ``v`` = V_B, or
        the force f_N (3,) on a point mass at ``x`` = r_N with velocity ``v`` = v_N.

        Raises
        ------
        DomainError
            When the kernel returns a nonzero status (see :meth:`_kernel_failure`).
        """
        packed = self._kernel_params(body)
        if packed is None:
            raise DefinitionError(
                f"{self.name}: the compiled kernel of {type(self).__name__} cannot evaluate "
                f"{body.kind} body {body.name!r}"
            )
        params, data = packed
        g, V, J, out = kernel_arguments(rigid, x, v, body)
        p = np.array(params, dtype=float)
        field = _NO_FIELD if data is None else _read_only(data)
        status = self._kernel(rigid, float(t), g, V, float(body.mass), J, p, field, out)
        if status != 0:
            raise self._kernel_failure(int(status), float(t), g)
        return out

    def _kernel_failure(self, status: int, t: float, g: FloatArray) -> Exception:
        """The error for a nonzero status of :attr:`_kernel` at time t and pose g."""
        return DomainError(
            f"{self.name}: the force has no finite value at r_N = {g[:3, 3].tolist()} m, "
            f"t = {t!r} s (kernel status {status})"
        )

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
