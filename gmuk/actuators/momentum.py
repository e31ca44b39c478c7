"""The internal-momentum form of a wheel array driven by any wheel command.

:class:`MomentumWheels` is the controller half of :mod:`gmuk.actuators.wheels`' fast form
for a command written in Python: the bus alone (inertia ``I_B − Σ J_s g gᵀ``), the wheels'
absolute spin momenta h as its internal states, and the wheels' torque on the bus
``−ω × G h − G ḣ`` as its wrench, with ``ḣ = sat(u_cmd, Ω) − c Ω`` from the command. It takes
the same command as the Udwadia–Kalaba form's :class:`~gmuk.actuators.WheelMotors`, so one
command flies either form. :class:`gmuk.MRPFeedback` is this controller with its law built in
(and compiled).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._validation import FloatArray
from gmuk.actuators.wheels import (
    ReactionWheel,
    WheelArray,
    WheelCommand,
    wheel_array_torque,
    wheel_spin_torque,
)
from gmuk.bodies import BodyKind
from gmuk.control.base import Controller
from gmuk.errors import DefinitionError, ShapeError

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["MomentumWheels"]


class MomentumWheels(Controller):
    """Reaction wheels in the internal-momentum form, driven by a wheel command.

    Parameters
    ----------
    body : RigidBody or str
        The bus, of inertia ``I_B − Σ J_s g gᵀ``
        (:meth:`~gmuk.actuators.WheelArray.spun_down_inertia`).
    wheels : WheelArray or sequence of ReactionWheel
    command : callable
        ``command(t, R_NB, omega_BN_B, wheel_speeds) -> u_cmd (n,)`` (N·m): the motor
        commands at the bus attitude R_NB (3, 3), rate ω_BN_B (3,) (rad/s) and wheel speeds
        relative to the bus (n,) (rad/s), e.g. :meth:`gmuk.MRPFeedback.wheel_command`.
    name : str, optional

    Notes
    -----
    Internal states z = h (n,), the wheels' absolute spin momenta (N·m·s); :meth:`states`
    builds them from the bus rate and the wheel speeds.
    """

    body_kinds = frozenset({BodyKind.RIGID})
    _forms = Forms(
        compiled="drives a command written in Python: called back from the compiled loop "
        "(MRPFeedback is its compiled case)",
        symbolic="gmuk.optimize transcribes no controller",
    )

    def __init__(
        self,
        body: Body | str,
        wheels: WheelArray | Sequence[ReactionWheel],
        command: WheelCommand,
        *,
        name: str | None = None,
    ) -> None:
        wheels = WheelArray(wheels)
        if not callable(command):
            raise DefinitionError(
                "MomentumWheels command must be callable (t, R_NB, omega_BN_B, wheel_speeds) "
                f"-> (n,) torques; got {type(command).__name__}"
            )
        super().__init__([body], n_states=len(wheels), name=name)
        self.wheels = wheels
        self.command = command

    def states(self, omega_BN_B: Any, wheel_speeds: Any) -> FloatArray:
        """Internal states z = h (n,) (N·m·s) for the bus rate ω_BN_B (3,) (rad/s) and the
        wheel speeds relative to the bus (n,) (rad/s)."""
        return self.wheels.momenta(omega_BN_B, wheel_speeds)

    def control(
        self, state: State, z: FloatArray, *modeled: FloatArray
    ) -> tuple[list[FloatArray], FloatArray]:
        """The wheels' wrench [−ω × G h − G ḣ; 0] on the bus (N·m, body frame) and ż = ḣ."""
        (body,) = self.bodies
        g, V = state.pose(body), state.twist(body)
        omega = np.array(V[:3], dtype=float)
        w = self.wheels
        h = np.array(z, dtype=float)
        speeds = h / w.J_s - w.G.T @ omega
        u = np.asarray(self.command(state.t, g[:3, :3], omega, speeds), dtype=float)
        if u.shape != (len(w),):
            raise ShapeError(
                f"{self.name}: the wheel command returned shape {u.shape}; expected ({len(w)},)"
            )
        h_dot = np.array(
            [
                wheel_spin_torque(
                    float(u[i]), float(speeds[i]), w.u_max[i], w.Omega_max[i], w.friction[i]
                )
                for i in range(len(w))
            ]
        )
        L = np.empty(3)
        wheel_array_torque(omega, h, np.ascontiguousarray(w.G), h_dot, L)
        return [np.r_[L, 0.0, 0.0, 0.0]], h_dot
