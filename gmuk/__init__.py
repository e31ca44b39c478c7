"""gmuk: geometric-mechanics Udwadia–Kalaba constrained motion of rigid bodies on SE(3).

Implements McCann (2020), *Constrained Motion of Rigid Bodies in the Geometric Mechanics
Framework with Udwadia–Kalaba Formulation* (master's thesis), with the corrections listed
in the documentation's errata page.

The flow: parts (bodies, constraints, force models, controllers) → :class:`System` →
:meth:`System.accelerations` → Lie-group integrator (:meth:`System.simulate`) →
:class:`Trajectory`.
"""

import sys as _sys

from gmuk import (
    actuators,
    attitude,
    constraints,
    control,
    crosscheck,
    dynamics,
    engine,
    environment,
    errors,
    forces,
    gravity,
    kkt,
    lie,
    orbits,
    reference,
)
from gmuk.bodies import Body, BodyKind, PointMass, RigidBody, SlackCoordinate
from gmuk.celestial import INERTIAL, CelestialBody, UniformRotation
from gmuk.constraints import (
    Baumgarte,
    ConfigurationTracking,
    ConfigurationTrackingT2,
    Constraint,
    HolonomicConstraint,
    InequalityConstraint,
    NonholonomicConstraint,
    PlaneBound,
    RelativeConstraint,
    TangentBundleConstraint,
    TrackingErrorBound,
    VirtualPairT2,
)
from gmuk.control import Controller, MorseLyapunovController, MRPFeedback
from gmuk.crosscheck import check
from gmuk.dynamics import spatial_inertia
from gmuk.engine import integrate, integrators, solvers, uk
from gmuk.engine.events import AltitudeEvent, ApsisEvent, Event
from gmuk.engine.integrate import compile_loop
from gmuk.engine.solvers import UKSolver
from gmuk.engine.system import Accelerations, System
from gmuk.forces import (
    AppliedWrench,
    ForceModel,
    GravityGradient,
    LinearSpringDamper,
    PointMassGravity,
    SlackDamping,
    SphericalHarmonicGravity,
    SpringDamper,
    ThesisRadialHarmonicGravity,
    UniformGravity,
)
from gmuk.gravity import SphericalHarmonicField
from gmuk.reference import ReferenceState, ReferenceTrajectory
from gmuk.state import Layout, State
from gmuk.trajectory import BodyTrajectory, EventRecord, Trajectory, load_trajectory

__version__ = "0.1.0"

__all__ = [
    "INERTIAL",
    "Accelerations",
    "AltitudeEvent",
    "AppliedWrench",
    "ApsisEvent",
    "Baumgarte",
    "Body",
    "BodyKind",
    "BodyTrajectory",
    "CelestialBody",
    "ConfigurationTracking",
    "ConfigurationTrackingT2",
    "Constraint",
    "Controller",
    "Event",
    "EventRecord",
    "ForceModel",
    "GravityGradient",
    "HolonomicConstraint",
    "InequalityConstraint",
    "Layout",
    "LinearSpringDamper",
    "MRPFeedback",
    "MorseLyapunovController",
    "NonholonomicConstraint",
    "PlaneBound",
    "PointMass",
    "PointMassGravity",
    "ReferenceState",
    "ReferenceTrajectory",
    "RelativeConstraint",
    "RigidBody",
    "SlackCoordinate",
    "SlackDamping",
    "SphericalHarmonicField",
    "SphericalHarmonicGravity",
    "SpringDamper",
    "State",
    "System",
    "TangentBundleConstraint",
    "ThesisRadialHarmonicGravity",
    "TrackingErrorBound",
    "Trajectory",
    "UKSolver",
    "UniformGravity",
    "UniformRotation",
    "VirtualPairT2",
    "__version__",
    "actuators",
    "attitude",
    "check",
    "compile_loop",
    "constraints",
    "control",
    "crosscheck",
    "dynamics",
    "engine",
    "environment",
    "errors",
    "forces",
    "gravity",
    "integrate",
    "integrators",
    "kkt",
    "lie",
    "load_trajectory",
    "orbits",
    "reference",
    "solvers",
    "spatial_inertia",
    "uk",
]

# The engine's modules under the names they had before gmuk.engine: the same module objects,
# so ``import gmuk.system`` and pickles naming ``gmuk.integrate`` keep working.
for _name in ("integrate", "integrators", "solvers", "system", "uk"):
    _sys.modules[f"gmuk.{_name}"] = _sys.modules[f"gmuk.engine.{_name}"]
del _name

#: Submodules imported on first use (they pull in matplotlib, Pinocchio, the CLI or campaigns).
_LAZY = ("cli", "plotting", "scenarios", "view", "campaign")


def __getattr__(name: str) -> object:
    if name in _LAZY:
        import importlib

        return importlib.import_module(f"gmuk.{name}")
    raise AttributeError(f"module 'gmuk' has no attribute {name!r}")
