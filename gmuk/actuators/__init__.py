"""Actuators: parts that turn a controller's command into torques and forces.

:class:`ReactionWheel` and :class:`WheelArray` describe reaction wheels;
:class:`WheelMotors` is their motor torque in the Udwadia–Kalaba form (each wheel a rigid body
on a relative constraint); :class:`MomentumWheels` flies them in the internal-momentum form
under any wheel command, and :class:`gmuk.control.MRPFeedback` with its MRP law built in
(see :mod:`gmuk.actuators.wheels`). :class:`Thruster`, :class:`ThrusterSet` and
:class:`Thrusters` are on–off thrusters with allocation, pulse-width modulation and the mass
they spend, flown by :func:`simulate_pulsed` (see :mod:`gmuk.actuators.thrusters`).
"""

from gmuk.actuators.momentum import MomentumWheels
from gmuk.actuators.thrusters import (
    G0,
    Allocation,
    Thruster,
    Thrusters,
    ThrusterSet,
    couple_thrusters,
    simulate_pulsed,
)
from gmuk.actuators.wheels import (
    ReactionWheel,
    WheelArray,
    WheelMotors,
)

__all__ = [
    "G0",
    "Allocation",
    "MomentumWheels",
    "ReactionWheel",
    "Thruster",
    "ThrusterSet",
    "Thrusters",
    "WheelArray",
    "WheelMotors",
    "couple_thrusters",
    "simulate_pulsed",
]
