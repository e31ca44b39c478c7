"""Robots: a joint library (constraint kinds), generalised joint forces, and URDF import
through Pinocchio's parser.

See docs/robotics.rst.
"""

from gmuk.robots.data import example_robot_data, example_robot_urdfs
from gmuk.robots.forces import JointEffort, JointSpringDamper
from gmuk.robots.joints import (
    CylindricalJoint,
    FixedJoint,
    Joint,
    PlanarJoint,
    PrismaticJoint,
    RevoluteJoint,
    ScrewJoint,
    SphericalJoint,
    UniversalJoint,
)
from gmuk.robots.robot import SUPPORTED_JOINTS, Robot

__all__ = [
    "SUPPORTED_JOINTS",
    "CylindricalJoint",
    "FixedJoint",
    "Joint",
    "JointEffort",
    "JointSpringDamper",
    "PlanarJoint",
    "PrismaticJoint",
    "RevoluteJoint",
    "Robot",
    "ScrewJoint",
    "SphericalJoint",
    "UniversalJoint",
    "example_robot_data",
    "example_robot_urdfs",
]
