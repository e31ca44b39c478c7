"""Force models: body-frame wrenches from gravity, springs, applied loads, plugins."""

from gmuk.forces.base import ForceModel
from gmuk.forces.gravity import GravityGradient, PointMassGravity, SphericalHarmonicGravity
from gmuk.forces.mechanical import (
    AppliedWrench,
    LinearSpringDamper,
    SlackDamping,
    SpringDamper,
    UniformGravity,
)
from gmuk.forces.thesis_gravity import ThesisRadialHarmonicGravity

__all__ = [
    "AppliedWrench",
    "ForceModel",
    "GravityGradient",
    "LinearSpringDamper",
    "PointMassGravity",
    "SlackDamping",
    "SphericalHarmonicGravity",
    "SpringDamper",
    "ThesisRadialHarmonicGravity",
    "UniformGravity",
]
