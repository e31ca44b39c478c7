"""Bodies: the parts that carry mass and degrees of freedom.

A body holds only constants (name, mass properties); its state lives in a
:class:`gmuk.State`. Three kinds are built in:

* :class:`RigidBody`, 6 dof on SE(3), twist V = [ω; v] in the body frame;
* :class:`PointMass`, 3 dof in R³ (the classical Udwadia–Kalaba particle, McCann 2020 Eq. 2);
* :class:`SlackCoordinate`, 1 dof, used by inequality constraints (slack/excess variables).
"""

from __future__ import annotations

import abc
from typing import Any, ClassVar

import numpy as np

from gmuk._validation import FloatArray
from gmuk.dynamics import check_inertia
from gmuk.errors import DefinitionError, InertiaError

__all__ = ["Body", "PointMass", "RigidBody", "SlackCoordinate"]


def _check_name(name: Any) -> str:
    if not isinstance(name, str) or not name:
        raise DefinitionError(f"a body name must be a non-empty string; got {name!r}")
    return name


def _check_mass(mass: Any, name: str) -> float:
    try:
        m = float(mass)
    except (TypeError, ValueError):
        raise InertiaError(f"{name}: mass must be a positive number (kg); got {mass!r}") from None
    if not np.isfinite(m) or m <= 0.0:
        raise InertiaError(f"{name}: mass must be finite and > 0 (kg); got {m!r}")
    return m


class Body(abc.ABC):
    """A part with mass and ``dof`` degrees of freedom.

    Subclasses define ``dof`` and :meth:`mass_matrix`. Bodies are immutable and compare
    by identity; the System refers to them by their unique ``name``.
    """

    dof: ClassVar[int]
    #: Short tag used in saved trajectories: "rigid", "point" or "slack".
    kind: ClassVar[str]

    __slots__ = ("_name",)
    _name: str

    def __init__(self, name: str) -> None:
        object.__setattr__(self, "_name", _check_name(name))

    @property
    def name(self) -> str:
        """Unique name of the body within a System."""
        return self._name

    @abc.abstractmethod
    def mass_matrix(self) -> FloatArray:
        """Constant mass block, shape (dof, dof), SI units (kg, kg·m²)."""

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable; build a new one instead")

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._name!r})"


class RigidBody(Body):
    """A rigid body on SE(3) with its body frame at the centre of mass.

    Parameters
    ----------
    name : str
        Unique name.
    mass : float
        Mass m (kg), > 0.
    inertia : array_like, shape (3, 3)
        Central inertia tensor J in the body frame (kg·m²): symmetric positive definite,
        principal moments satisfying the triangle inequality.

    Notes
    -----
    The mass block is ``𝕀 = blkdiag(J, m I₃)`` (McCann 2020, Eq. 11), acting on V = [ω; v].
    """

    dof = 6
    kind = "rigid"
    __slots__ = ("_J", "_mass")
    _mass: float
    _J: FloatArray

    def __init__(self, name: str, mass: float, inertia: Any) -> None:
        super().__init__(name)
        m, J = check_inertia(mass, inertia, name=f"RigidBody {name!r}")
        J = J.copy()
        J.setflags(write=False)
        object.__setattr__(self, "_mass", m)
        object.__setattr__(self, "_J", J)

    @property
    def mass(self) -> float:
        """Mass (kg)."""
        return self._mass

    @property
    def inertia(self) -> FloatArray:
        """Central inertia tensor J in the body frame (kg·m²), read-only (3, 3)."""
        return self._J

    def mass_matrix(self) -> FloatArray:
        """``blkdiag(J, m I₃)``, shape (6, 6)."""
        out = np.zeros((6, 6))
        out[:3, :3] = self._J
        out[3:, 3:] = self._mass * np.eye(3)
        return out


class PointMass(Body):
    """A particle in R³: position r_N and velocity v_N in the inertial frame.

    Parameters
    ----------
    name : str
    mass : float
        Mass (kg), > 0.
    """

    dof = 3
    kind = "point"
    __slots__ = ("_mass",)
    _mass: float

    def __init__(self, name: str, mass: float) -> None:
        super().__init__(name)
        object.__setattr__(self, "_mass", _check_mass(mass, f"PointMass {name!r}"))

    @property
    def mass(self) -> float:
        """Mass (kg)."""
        return self._mass

    def mass_matrix(self) -> FloatArray:
        """``m I₃``, shape (3, 3)."""
        return self._mass * np.eye(3)


class SlackCoordinate(Body):
    """A scalar coordinate with a unit (or given) "mass", for slack and excess variables.

    Inequality constraints ``h(q) ≥ 0`` become equalities ``h(q) − s² = 0`` with a slack
    coordinate s; the slack's mass weights how much of the constraint force it takes in
    the Udwadia–Kalaba minimisation (McCann 2020, Chapter 6).

    Parameters
    ----------
    name : str
    mass : float, optional
        Weight of the coordinate in the Gauss function (default 1; units those of the
        constraint that uses it).
    """

    dof = 1
    kind = "slack"
    __slots__ = ("_mass",)
    _mass: float

    def __init__(self, name: str, mass: float = 1.0) -> None:
        super().__init__(name)
        object.__setattr__(self, "_mass", _check_mass(mass, f"SlackCoordinate {name!r}"))

    @property
    def mass(self) -> float:
        """Weight of the coordinate."""
        return self._mass

    def mass_matrix(self) -> FloatArray:
        """``[[mass]]``, shape (1, 1)."""
        return np.array([[self._mass]])
