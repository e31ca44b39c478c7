"""Actuators: parts that turn a controller's command into torques and forces.

:class:`ReactionWheel` and :class:`WheelArray` describe reaction wheels;
:class:`WheelMotors` is their motor torque in the Udwadia–Kalaba form (each wheel a rigid body
on a relative constraint), and :class:`gmuk.control.MRPFeedback` flies them in the
internal-momentum form (see :mod:`gmuk.actuators.wheels`).
"""

from gmuk.actuators.wheels import (
    ReactionWheel,
    WheelArray,
    WheelMotors,
)

__all__ = [
    "ReactionWheel",
    "WheelArray",
    "WheelMotors",
]
