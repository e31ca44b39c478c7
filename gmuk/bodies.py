"""Bodies: the parts that carry mass and degrees of freedom.

A body holds only constants (name, mass properties); its state lives in a
:class:`gmuk.State`. Three kinds are built in:

* :class:`RigidBody`, 6 dof on SE(3), twist V = [ω; v] in the body frame;
* :class:`PointMass`, 3 dof in R³ (the classical Udwadia–Kalaba particle, McCann 2020 Eq. 2);
* :class:`SlackCoordinate`, 1 dof, used by inequality constraints (slack/excess variables).
"""

from __future__ import annotations

import abc
import enum
from typing import Any, ClassVar

import numpy as np

from gmuk._validation import FloatArray
from gmuk.dynamics import check_inertia, check_mass, singular_mass
from gmuk.errors import DefinitionError, GmukError, InertiaError

__all__ = ["Body", "BodyKind", "PointMass", "RigidBody", "SlackCoordinate"]


def _check_name(name: Any) -> str:
    if not isinstance(name, str) or not name:
        raise DefinitionError(f"a body name must be a non-empty string; got {name!r}")
    return name


def _check_mass(mass: Any, name: str) -> float:
    """The mass (kg) as :func:`gmuk.dynamics.check_mass` accepts it (1/m finite too)."""
    return check_mass(mass, name)


def _physical_singular(mass: Any, inertia: Any, label: str) -> bool:
    """Whether ``allow_singular=True`` would accept this mass and inertia."""
    try:
        check_inertia(mass, inertia, name=label, allow_singular=True)
    except GmukError:
        return False
    return True


class BodyKind(str, enum.Enum):
    """What a body's coordinates are, which decides how the integrator moves it.

    The values are the short tags written in saved trajectories; a kind compares equal to
    its tag (``BodyKind.RIGID == "rigid"``).
    """

    #: 6 dof on SE(3): pose g_NB (4, 4) and body twist V_B = [ω; v] (6,).
    RIGID = "rigid"
    #: 3 dof in R³: position r_N and velocity v_N (3,), inertial frame.
    POINT = "point"
    #: 1 dof in R: a scalar coordinate s and its rate (slack and excess variables).
    SLACK = "slack"

    def __str__(self) -> str:
        return self.value

    def __hash__(self) -> int:  # hash as the tag, so that a dict keyed by tags finds a kind
        return str.__hash__(self)


class Body(abc.ABC):
    """A part with a mass and ``dof`` degrees of freedom.

    Every body has a unique :attr:`name`, a :attr:`mass` (kg, or the weight of a slack
    coordinate), a :attr:`kind` and a constant :meth:`mass_matrix`. Subclasses set the class
    attributes ``dof`` and ``kind`` and implement :meth:`mass_matrix`. Bodies are immutable
    and compare by identity; the System refers to them by their unique ``name``.

    Parameters
    ----------
    name : str
        Unique name within a System.
    mass : float
        Mass (kg): a real number (not a bool or a string) with m and 1/m finite normal
        float64 numbers, 2.2e-308 ≤ m ≤ 4.5e307 (:func:`gmuk.dynamics.check_mass`; a
        subnormal mass such as 5e-324 is refused, its reciprocal being infinite).

    Raises
    ------
    DefinitionError
        If ``name`` is not a non-empty string.
    InertiaError
        If ``mass`` is not usable.
    """

    dof: ClassVar[int]
    kind: ClassVar[BodyKind]

    __slots__ = ("_mass", "_name")
    _name: str
    _mass: float

    def __init__(self, name: str, mass: float) -> None:
        name = _check_name(name)
        object.__setattr__(self, "_name", name)
        object.__setattr__(self, "_mass", _check_mass(mass, f"{type(self).__name__} {name!r}"))

    def _set_checked(self, name: str, mass: float) -> None:
        """Name and a mass its subclass has validated already."""
        object.__setattr__(self, "_name", name)
        object.__setattr__(self, "_mass", mass)

    @property
    def name(self) -> str:
        """Unique name of the body within a System."""
        return self._name

    @property
    def mass(self) -> float:
        """Mass m (kg); for a slack coordinate, its weight in the Gauss function."""
        return self._mass

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
        Mass m (kg), 2.2e-308 ≤ m ≤ 4.5e307 (m and 1/m finite normal numbers).
    inertia : array_like, shape (3, 3)
        Central inertia tensor J in the body frame (kg·m²): finite, symmetric positive
        definite, principal moments satisfying the triangle inequality, each between
        2.2e-308 and 4.5e307 kg·m² (J⁻¹ finite), and J₃/J₁ ≤ 1e12 (J⁻¹ usable). See
        :func:`gmuk.dynamics.check_inertia`.
    allow_singular : bool, optional
        Accept a singular mass block (default False): a link without mass (m = 0, J = 0), a
        point mass (J = 0) or a rod (one zero moment), as robot descriptions have them. Such
        a body has no acceleration of its own; a System takes it only under the tree solve
        of joints that determine its motion (:class:`gmuk.engine.tree.TreeSolver`), and only
        loads that go through that solve act on it (no unmodeled force, no controller).

    Raises
    ------
    InertiaError
        Listing every problem with the mass and J (e.g. mass 5e-324 or J = 1e-320 I, whose
        inverses are infinite; entries near 1e308).

    Notes
    -----
    The mass block is ``𝕀 = blkdiag(J, m I₃)`` (McCann 2020, Eq. 11), acting on V = [ω; v].
    """

    dof = 6
    kind = BodyKind.RIGID
    __slots__ = ("_J", "_singular")
    _J: FloatArray
    _singular: bool

    def __init__(
        self, name: str, mass: float, inertia: Any, *, allow_singular: bool = False
    ) -> None:
        name = _check_name(name)
        label = f"RigidBody {name!r}"
        if not isinstance(allow_singular, (bool, np.bool_)):
            raise DefinitionError(
                f"{label}: allow_singular must be True or False; got {allow_singular!r}"
            )
        try:
            m, J = check_inertia(mass, inertia, name=label, allow_singular=bool(allow_singular))
        except InertiaError as exc:
            if allow_singular or not _physical_singular(mass, inertia, label):
                raise
            raise InertiaError(
                f"{exc} (a link without mass or rotational inertia is accepted with "
                "allow_singular=True, under the tree solve of robot joints)"
            ) from None
        self._set_checked(name, m)
        J = J.copy()
        J.setflags(write=False)
        object.__setattr__(self, "_J", J)
        object.__setattr__(self, "_singular", bool(allow_singular) and singular_mass(m, J))

    @property
    def singular(self) -> bool:
        """Whether the mass block ``blkdiag(J, m I₃)`` is singular (only with
        ``allow_singular``: m = 0, or a principal moment that is zero)."""
        return self._singular

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
    kind = BodyKind.POINT
    __slots__ = ()

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
    kind = BodyKind.SLACK
    __slots__ = ()

    def __init__(self, name: str, mass: float = 1.0) -> None:
        super().__init__(name, mass)

    def mass_matrix(self) -> FloatArray:
        """``[[mass]]``, shape (1, 1)."""
        return np.array([[self._mass]])
