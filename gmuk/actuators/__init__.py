"""Actuators: parts that turn a controller's command into torques and forces.

:class:`ReactionWheel` and :class:`WheelArray` describe reaction wheels;
:class:`WheelMotors` is their motor torque in the Udwadia–Kalaba form (each wheel a rigid body
on a relative constraint); :class:`MomentumWheels` flies them in the internal-momentum form
under any wheel command, and :class:`gmuk.control.MRPFeedback` with its MRP law built in
(see :mod:`gmuk.actuators.wheels`).
"""

from gmuk.actuators.momentum import MomentumWheels
from gmuk.actuators.wheels import (
    ReactionWheel,
    WheelArray,
    WheelMotors,
)

__all__ = [
    "MomentumWheels",
    "ReactionWheel",
    "WheelArray",
    "WheelMotors",
]
