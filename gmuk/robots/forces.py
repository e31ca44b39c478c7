"""Generalised forces on joints: actuation and spring–dampers, as force models.

A generalised force τ (nv,) on a joint acts on its child as the wrench ``S τ`` at the child's
joint frame and on its parent as the equal and opposite wrench at the same point
(:meth:`gmuk.robots.Joint.wrenches`); its power is ``τ · q̇``. Both are *modeled* loads: the
Udwadia–Kalaba solve sees them, so the joint's constraint forces balance them exactly.
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._validation import FloatArray, as_array
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError, DomainError
from gmuk.forces.base import ForceModel

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.robots.joints import Joint
    from gmuk.state import State

__all__ = ["JointEffort", "JointSpringDamper"]

_FORMS = Forms(
    compiled="acts on the two bodies of a joint: called back from the compiled loop",
    symbolic="gmuk.optimize transcribes no joint",
)


class _OnJoint(ForceModel, abc.ABC):
    """A generalised force on one joint; subclasses give τ(state)."""

    acts_on = frozenset({BodyKind.RIGID})
    _forms = _FORMS

    def __init__(self, joint: Joint, *, name: str | None = None) -> None:
        from gmuk.robots.joints import Joint

        if not isinstance(joint, Joint):
            raise DefinitionError(
                f"{type(self).__name__} acts on a gmuk.robots Joint; got {type(joint).__name__}"
            )
        super().__init__(list(joint.bodies), name=name or f"{type(self).__name__}({joint.name})")
        self.joint = joint

    @abc.abstractmethod
    def effort(self, state: State) -> FloatArray:
        """τ (nv,) at ``state`` (N·m per rad, N per m of the joint's coordinates)."""

    def wrenches(self, state: State, bodies: Sequence[Body]) -> list[FloatArray]:
        """The wrenches of τ on the joint's bodies (parent first; the child only for a joint
        to the ground), [L; f] in each body frame (N·m, N)."""
        tau = self.effort(state)
        W_P, W_C = self.joint.wrenches(state, tau)
        return [W_C] if self.joint.grounded else [W_P, W_C]


class JointEffort(_OnJoint):
    """Actuation of a joint: a generalised force τ (torque about a revolute axis, force
    along a prismatic one …), constant or a function of the state.

    Parameters
    ----------
    joint : gmuk.robots.Joint
    effort : array_like (nv,) or callable (t, state) -> (nv,)
        τ in N·m (rotational coordinates) and N (translational ones).
    name : str, optional
    """

    acts_on = frozenset({BodyKind.RIGID})
    _forms = _FORMS

    def __init__(
        self,
        joint: Joint,
        effort: Any | Callable[[float, State], Any],
        *,
        name: str | None = None,
    ) -> None:
        super().__init__(joint, name=name)
        if callable(effort):
            self._effort: Callable[[float, State], Any] | None = effort
            self._constant = None
        else:
            self._effort = None
            self._constant = as_array(effort, (joint.nv,), f"{self.name}: effort", batch=False)

    def effort(self, state: State) -> FloatArray:
        if self._constant is not None:
            return self._constant
        assert self._effort is not None
        tau = np.asarray(self._effort(state.t, state), dtype=float)
        if tau.shape != (self.joint.nv,) or not np.isfinite(tau).all():
            raise DomainError(
                f"{self.name}: effort(t, state) must return {self.joint.nv} finite numbers; got "
                f"{tau!r:.80}"
            )
        return tau


class JointSpringDamper(_OnJoint):
    """A linear spring–damper on a joint's coordinates: ``τ = −k (q − q₀) − c q̇``.

    Parameters
    ----------
    joint : gmuk.robots.Joint
    stiffness : float or array_like (nv,)
        k (N·m/rad or N/m), ≥ 0. The spring reads the joint's coordinates at the state
        (:meth:`Joint.coordinates`: angles in (−π, π]), so a rotational spring is meant for
        joints that stay within half a turn of ``rest``.
    damping : float or array_like (nv,)
        c (N·m·s/rad or N·s/m), ≥ 0.
    rest : float or array_like (nv,)
        q₀ (rad, m); zero by default.
    """

    acts_on = frozenset({BodyKind.RIGID})
    _forms = _FORMS

    def __init__(
        self,
        joint: Joint,
        *,
        stiffness: Any = 0.0,
        damping: Any = 0.0,
        rest: Any = 0.0,
        name: str | None = None,
    ) -> None:
        super().__init__(joint, name=name)
        n = joint.nv

        def gains(value: Any, label: str, sign: bool) -> FloatArray:
            try:
                arr = np.array(np.broadcast_to(np.asarray(value, dtype=float), (n,)))
            except (TypeError, ValueError):
                raise DefinitionError(
                    f"{self.name}: {label} must be a number or {n} numbers; got {value!r:.60}"
                ) from None
            if not np.isfinite(arr).all() or (sign and (arr < 0).any()):
                raise DefinitionError(
                    f"{self.name}: {label} must be finite{' and ≥ 0' if sign else ''}; got "
                    f"{arr.tolist()}"
                )
            return arr

        self.stiffness = gains(stiffness, "stiffness", True)
        self.damping = gains(damping, "damping", True)
        self.rest = gains(rest, "rest", False)
        if joint.nq != joint.nv:
            raise DefinitionError(f"{self.name}: a {joint.kind} joint has no linear spring")

    def effort(self, state: State) -> FloatArray:
        tau = -self.damping * self.joint.rates(state)
        if self.stiffness.any():
            tau = tau - self.stiffness * (self.joint.coordinates(state) - self.rest)
        return tau
