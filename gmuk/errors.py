"""Exceptions raised by gmuk.

Every error gmuk raises on bad input is a :class:`GmukError`. Each subclass also derives
from the matching built-in exception (``ValueError`` or ``TypeError``), so code that
already catches those keeps working. Messages state what was expected and what came in.
"""

from __future__ import annotations

__all__ = [
    "ConstraintError",
    "DefinitionError",
    "DegreeError",
    "DomainError",
    "EulerSequenceError",
    "FileFormatError",
    "GmukError",
    "GmukWarning",
    "InconsistentConstraintsError",
    "InconsistentConstraintsWarning",
    "InertiaError",
    "MissingDependencyError",
    "NonFiniteError",
    "NotOnGroupError",
    "OptimizationError",
    "OrbitError",
    "PluginWarning",
    "ShapeError",
    "SimulationError",
]


class GmukError(Exception):
    """Base class of every error raised by gmuk."""


class ShapeError(GmukError, ValueError):
    """An array has the wrong shape (message gives the expected and received shapes)."""


class NonFiniteError(GmukError, ValueError):
    """An array holds NaN or infinity where finite numbers are required."""


class NotOnGroupError(GmukError, ValueError):
    """A matrix is not a rotation matrix or not a homogeneous SE(3) transformation."""


class EulerSequenceError(GmukError, ValueError):
    """An unsupported Euler-angle sequence was requested."""


class InertiaError(GmukError, ValueError):
    """A mass or inertia tensor is not physical (m <= 0, J not SPD, triangle inequality)."""


class DefinitionError(GmukError, ValueError):
    """A system definition is invalid; ``problems`` lists every problem found."""

    def __init__(self, problems: list[str] | str) -> None:
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        if len(self.problems) == 1:
            msg = self.problems[0]
        else:
            msg = f"{len(self.problems)} problems in the definition:\n" + "\n".join(
                f"  - {p}" for p in self.problems
            )
        super().__init__(msg)


class ConstraintError(GmukError, ValueError):
    """A constraint returned rows of the wrong shape or non-finite values."""


class InconsistentConstraintsError(GmukError, ValueError):
    """The constraint equations A V̇ = b have no solution (residual above tolerance)."""


class FileFormatError(GmukError, ValueError):
    """A data file is malformed; the message names the file, the line and what was expected."""


class SimulationError(GmukError, RuntimeError):
    """A simulation failed; ``trajectory`` holds every step computed before the failure."""

    def __init__(self, message: str, trajectory: object | None = None) -> None:
        super().__init__(message)
        self.trajectory = trajectory


class OrbitError(GmukError, ValueError):
    """Orbital elements or conic parameters are invalid or inconsistent (e < 0, a ≤ 0 for an
    ellipse, a with a parabola, a true anomaly beyond a hyperbola's asymptote, ...)."""


class DegreeError(GmukError, ValueError):
    """A spherical-harmonic degree or order is out of range (the message gives the range)."""


class DomainError(GmukError, ValueError):
    """A model was evaluated where it is not defined (a gravity field at its origin, or where
    its series does not give a finite value)."""


class MissingDependencyError(GmukError, ImportError):
    """An optional dependency is not installed (the message gives the pip command)."""


class OptimizationError(GmukError, RuntimeError):
    """An optimal-control problem (:mod:`gmuk.optimize`) could not be solved.

    Attributes
    ----------
    status : str
        IPOPT's return status (e.g. ``"Infeasible_Problem_Detected"``,
        ``"Maximum_Iterations_Exceeded"``, ``"Maximum_CpuTime_Exceeded"``), or
        ``"Infeasible_Bounds"`` when gmuk found the bounds or boundary conditions infeasible
        before solving.
    result : object or None
        The :class:`gmuk.optimize.OptimalControlResult` of the last iterate, when the solver
        ran (its ``log`` holds IPOPT's iteration log when it was asked for).
    """

    def __init__(self, message: str, status: str, result: object | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.result = result


class GmukWarning(UserWarning):
    """Base class of gmuk's warnings."""


class InconsistentConstraintsWarning(GmukWarning, RuntimeWarning):
    """A ν̇ = b had no exact solution; the least-squares constraint acceleration was used."""


class PluginWarning(GmukWarning):
    """A force-model plugin could not be used and was skipped (the message says why)."""
