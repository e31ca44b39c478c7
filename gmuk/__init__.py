"""gmuk: geometric-mechanics Udwadia–Kalaba constrained motion of rigid bodies on SE(3).

Implements McCann (2020), *Constrained Motion of Rigid Bodies in the Geometric Mechanics
Framework with Udwadia–Kalaba Formulation* (master's thesis), with the corrections listed
in the documentation's errata page.

The flow: parts (bodies, constraints, force models, controllers) → :class:`System` →
:meth:`System.accelerations` → Lie-group integrator (:meth:`System.simulate`) →
:class:`Trajectory`.
"""

from gmuk import errors, lie
from gmuk.bodies import Body, PointMass, RigidBody, SlackCoordinate
from gmuk.celestial import CelestialBody, UniformRotation
from gmuk.constraints import (
    Baumgarte,
    ConfigurationTracking,
    ConfigurationTrackingT2,
    Constraint,
    HolonomicConstraint,
    NonholonomicConstraint,
    RelativeConstraint,
    TangentBundleConstraint,
)
from gmuk.control import Controller
from gmuk.dynamics import spatial_inertia
from gmuk.forces import (
    AppliedWrench,
    ForceModel,
    GravityGradient,
    PointMassGravity,
    SpringDamper,
    UniformGravity,
)
from gmuk.reference import ReferenceState, ReferenceTrajectory
from gmuk.state import Layout, State
from gmuk.system import Accelerations, System
from gmuk.trajectory import BodyTrajectory, Trajectory, load_trajectory

__version__ = "0.1.0"

__all__ = [
    "Accelerations",
    "AppliedWrench",
    "Baumgarte",
    "Body",
    "BodyTrajectory",
    "CelestialBody",
    "ConfigurationTracking",
    "ConfigurationTrackingT2",
    "Constraint",
    "Controller",
    "ForceModel",
    "GravityGradient",
    "HolonomicConstraint",
    "Layout",
    "NonholonomicConstraint",
    "PointMass",
    "PointMassGravity",
    "ReferenceState",
    "ReferenceTrajectory",
    "RelativeConstraint",
    "RigidBody",
    "SlackCoordinate",
    "SpringDamper",
    "State",
    "System",
    "TangentBundleConstraint",
    "Trajectory",
    "UniformGravity",
    "UniformRotation",
    "__version__",
    "errors",
    "lie",
    "load_trajectory",
    "spatial_inertia",
]
