"""Constraints: the rows (A, b) of A ν̇ = b, or (A, B, C) of A g̈ B = C on T²SE(3);
inequalities through slack and excess coordinates."""

from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.constraints.holonomic import HolonomicConstraint, NonholonomicConstraint
from gmuk.constraints.inequality import (
    Bound,
    InequalityConstraint,
    PlaneBound,
    TrackingErrorBound,
)
from gmuk.constraints.relative import RelativeConstraint, relative_twist
from gmuk.constraints.tangent_bundle import (
    ConfigurationTrackingT2,
    TangentBundleConstraint,
    VirtualPairT2,
)
from gmuk.constraints.tracking import ConfigurationTracking, project_to_se3, tracking_errors

__all__ = [
    "Baumgarte",
    "Bound",
    "ConfigurationTracking",
    "ConfigurationTrackingT2",
    "Constraint",
    "HolonomicConstraint",
    "InequalityConstraint",
    "NonholonomicConstraint",
    "PlaneBound",
    "RelativeConstraint",
    "TangentBundleConstraint",
    "TrackingErrorBound",
    "VirtualPairT2",
    "project_to_se3",
    "relative_twist",
    "tracking_errors",
]
