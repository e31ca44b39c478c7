"""Dispersions: small immutable distributions of one campaign parameter each.

A dispersion draws one value from a :class:`numpy.random.Generator`. It checks its own
domain when it is made (a cone wider than π, a negative standard deviation, low > high: a
:class:`gmuk.errors.DefinitionError`), and says what it can produce — its :attr:`kind`
(``"real"``, ``"integer"``, ``"vector3"``, ``"rotation"`` or ``"scale3"``) and, for scalars,
its :meth:`~Dispersion.support` — so that a campaign can refuse a dispersion that could leave
its parameter's domain (a mass scale that can be negative) before any run starts.

Kinds and what the values are
-----------------------------
``real``, ``integer``
    A float or an int.
``vector3``
    A tuple of three floats, e.g. a position error (m) or velocity error (m/s) in the
    inertial frame N.
``rotation``
    A rotation vector θ·n̂ (rad), a tuple of three floats with ‖θ n̂‖ ≤ π: the attitude error
    ``R_err = exp(θ n̂^)``.
``scale3``
    Three positive factors, e.g. of a body's second moments of mass about its principal axes
    (see :class:`SecondMomentScale`).

The uniform distribution on SO(3) within a cone
-----------------------------------------------
:class:`AttitudeCone` draws ``R_err`` from the Haar (uniform) measure of SO(3) restricted to
the rotations of angle θ ≤ θ_max: the geodesic ball of radius θ_max about the identity. In
axis–angle coordinates the Haar measure is ``dμ = (1 − cos θ)/π dθ · dA(n̂)/(4π)`` on
θ ∈ [0, π], n̂ ∈ S²: the axis is uniform on the sphere, independent of the angle, and the angle
has density ∝ ``1 − cos θ = 2 sin²(θ/2)`` — small angles are rare, unlike a uniform angle,
which would crowd the identity. Truncated to [0, θ_max] the angle's distribution function is
``F(θ) = (θ − sin θ)/(θ_max − sin θ_max)``; it is inverted numerically (``θ − sin θ`` from its
Taylor series below 0.1 rad, so that cones of micro-radians keep full precision). With
θ_max = π this is the uniform distribution on all of SO(3). Every body axis then points within
θ_max of its nominal direction.

References
----------
Miles, R. E. (1965), On random rotations in R³, *Biometrika* 52, 636–639 (the Haar measure in
axis–angle form).
"""

from __future__ import annotations

import abc
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from gmuk.errors import DefinitionError

__all__ = [
    "KINDS",
    "AttitudeCone",
    "Choice",
    "Dispersion",
    "GaussianVector",
    "IntegerRange",
    "Normal",
    "SecondMomentScale",
    "Uniform",
    "UniformBall",
    "dispersion_from_dict",
    "magnitude",
]

#: The kinds of value a parameter takes and a dispersion produces.
KINDS = ("real", "integer", "vector3", "rotation", "scale3")


def _real(value: Any, label: str, owner: str) -> float:
    """A finite real number (never a bool or a string)."""
    if isinstance(value, (bool, np.bool_, str, bytes)) or not isinstance(
        value, (int, float, np.integer, np.floating)
    ):
        raise DefinitionError(f"{owner}: {label} must be a real number; got {value!r}")
    try:
        out = float(value)
    except OverflowError:  # an integer beyond float64
        out = math.inf
    if not math.isfinite(out):
        raise DefinitionError(f"{owner}: {label} must be finite; got {value!r:.60}")
    return out


def _integer(value: Any, label: str, owner: str) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise DefinitionError(f"{owner}: {label} must be an integer; got {value!r}")
    return int(value)


@dataclass(frozen=True)
class Dispersion(abc.ABC):
    """A distribution of one parameter's value (subclasses are frozen dataclasses)."""

    #: What :meth:`sample` returns (one of :data:`KINDS`).
    kind: ClassVar[str]

    @abc.abstractmethod
    def sample(self, rng: np.random.Generator) -> Any:
        """One value drawn with ``rng`` (the same generator state gives the same value)."""

    def support(self) -> tuple[float, float]:
        """Smallest and largest value a scalar dispersion can produce (for vectors: of each
        component); ``(-inf, inf)`` when unbounded."""
        return (-math.inf, math.inf)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-serialisable description; :func:`dispersion_from_dict` inverts it."""
        out: dict[str, Any] = {"type": type(self).__name__}
        for f in fields(self):
            value = getattr(self, f.name)
            out[f.name] = list(value) if isinstance(value, tuple) else value
        return out


@dataclass(frozen=True)
class Uniform(Dispersion):
    """A real number uniform on [low, high] (low ≤ high, both finite)."""

    low: float
    high: float
    kind: ClassVar[str] = "real"

    def __post_init__(self) -> None:
        lo, hi = _real(self.low, "low", "Uniform"), _real(self.high, "high", "Uniform")
        if lo > hi:
            raise DefinitionError(f"Uniform: low must be ≤ high; got low={lo!r}, high={hi!r}")
        object.__setattr__(self, "low", lo)
        object.__setattr__(self, "high", hi)

    def sample(self, rng: np.random.Generator) -> float:
        return float(rng.uniform(self.low, self.high))

    def support(self) -> tuple[float, float]:
        return (self.low, self.high)


@dataclass(frozen=True)
class Normal(Dispersion):
    """A real number from the normal distribution N(mean, std²) (std ≥ 0; unbounded unless
    std = 0, so it cannot disperse a parameter with a bounded domain such as a mass scale)."""

    mean: float
    std: float
    kind: ClassVar[str] = "real"

    def __post_init__(self) -> None:
        mean, std = _real(self.mean, "mean", "Normal"), _real(self.std, "std", "Normal")
        if std < 0:
            raise DefinitionError(f"Normal: std must be ≥ 0; got {std!r}")
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "std", std)

    def sample(self, rng: np.random.Generator) -> float:
        return float(self.mean + self.std * rng.standard_normal())

    def support(self) -> tuple[float, float]:
        return (self.mean, self.mean) if self.std == 0 else (-math.inf, math.inf)


@dataclass(frozen=True)
class Choice(Dispersion):
    """One of ``values``, each equally likely: integers (e.g. gravity degrees) or reals."""

    values: tuple[Any, ...]
    kind: ClassVar[str] = "integer"

    def __post_init__(self) -> None:
        try:
            values = tuple(self.values)
        except TypeError:
            raise DefinitionError(
                f"Choice: values must be a sequence; got {self.values!r}"
            ) from None
        if not values:
            raise DefinitionError("Choice: values must not be empty")
        if all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in values):
            values = tuple(int(v) for v in values)
        else:
            values = tuple(_real(v, "each value", "Choice") for v in values)
            object.__setattr__(self, "kind", "real")
        object.__setattr__(self, "values", values)

    def sample(self, rng: np.random.Generator) -> Any:
        return self.values[int(rng.integers(len(self.values)))]

    def support(self) -> tuple[float, float]:
        return (float(min(self.values)), float(max(self.values)))


@dataclass(frozen=True)
class IntegerRange(Dispersion):
    """An integer uniform on low, low + 1, …, high (both included)."""

    low: int
    high: int
    kind: ClassVar[str] = "integer"

    def __post_init__(self) -> None:
        lo = _integer(self.low, "low", "IntegerRange")
        hi = _integer(self.high, "high", "IntegerRange")
        if lo > hi:
            raise DefinitionError(f"IntegerRange: low must be ≤ high; got {lo} > {hi}")
        object.__setattr__(self, "low", lo)
        object.__setattr__(self, "high", hi)

    def sample(self, rng: np.random.Generator) -> int:
        return int(rng.integers(self.low, self.high + 1))

    def support(self) -> tuple[float, float]:
        return (float(self.low), float(self.high))


def _unit_vector(rng: np.random.Generator) -> np.ndarray:
    """A direction uniform on S² (a normalised standard normal 3-vector)."""
    while True:
        u = rng.standard_normal(3)
        n = float(np.linalg.norm(u))
        if n > 1e-300:
            return u / n


def _theta_minus_sin(theta: float) -> float:
    """θ − sin θ without cancellation (Taylor series below 0.1 rad, error < 1e-18 relative)."""
    if theta < 0.1:
        t2 = theta * theta
        return theta**3 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0)))
    return theta - math.sin(theta)


@dataclass(frozen=True)
class AttitudeCone(Dispersion):
    """An attitude error uniform on SO(3) within angle ``max_angle_rad`` of the identity.

    Parameters
    ----------
    max_angle_rad : float
        θ_max (rad), 0 ≤ θ_max ≤ π. π gives the uniform distribution on SO(3).

    Notes
    -----
    The value is the rotation vector θ n̂ (rad) of ``R_err``; n̂ is uniform on S² and θ has
    density ``(1 − cos θ)/(θ_max − sin θ_max)`` on [0, θ_max] — the Haar measure of SO(3)
    restricted to the ball (module docstring).
    """

    max_angle_rad: float
    kind: ClassVar[str] = "rotation"

    def __post_init__(self) -> None:
        theta = _real(self.max_angle_rad, "max_angle_rad", "AttitudeCone")
        if not 0.0 <= theta <= math.pi:
            raise DefinitionError(
                f"AttitudeCone: max_angle_rad must be in [0, π] (a cone of at most 180°); got "
                f"{theta!r} rad = {math.degrees(theta):.6g}°"
            )
        object.__setattr__(self, "max_angle_rad", theta)

    def angle(self, u: float) -> float:
        """The angle θ (rad) with F(θ) = u: the inverse of the angle's distribution function
        ``F(θ) = (θ − sin θ)/(θ_max − sin θ_max)`` (bisection to the last bit)."""
        top = self.max_angle_rad
        if top == 0.0:
            return 0.0
        target = u * _theta_minus_sin(top)
        lo, hi = 0.0, top
        for _ in range(200):  # θ − sin θ increases on [0, π]
            mid = 0.5 * (lo + hi)
            if mid in (lo, hi):
                break
            if _theta_minus_sin(mid) < target:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    def sample(self, rng: np.random.Generator) -> tuple[float, float, float]:
        axis = _unit_vector(rng)
        theta = self.angle(float(rng.uniform()))
        return tuple(float(c) for c in theta * axis)  # type: ignore[return-value]

    def support(self) -> tuple[float, float]:
        return (-self.max_angle_rad, self.max_angle_rad)


def _sigma3(value: Any, owner: str) -> tuple[float, ...]:
    arr = np.atleast_1d(np.asarray(value, dtype=object))
    if arr.ndim != 1 or arr.size not in (1, 3):
        raise DefinitionError(f"{owner}: give one value or three (per axis); got {value!r}")
    out = tuple(_real(v, "each value", owner) for v in arr)
    if min(out) < 0:
        raise DefinitionError(f"{owner}: values must be ≥ 0; got {value!r}")
    return out * 3 if len(out) == 1 else out


@dataclass(frozen=True)
class GaussianVector(Dispersion):
    """A 3-vector with independent normal components, mean 0, standard deviation ``sigma``
    (one value for every axis or three, ≥ 0; units of the parameter, e.g. m or m/s)."""

    sigma: Any
    kind: ClassVar[str] = "vector3"

    def __post_init__(self) -> None:
        object.__setattr__(self, "sigma", _sigma3(self.sigma, "GaussianVector"))

    def sample(self, rng: np.random.Generator) -> tuple[float, float, float]:
        u = rng.standard_normal(3) * np.asarray(self.sigma)
        return (float(u[0]), float(u[1]), float(u[2]))

    def support(self) -> tuple[float, float]:
        return (0.0, 0.0) if max(self.sigma) == 0 else (-math.inf, math.inf)


@dataclass(frozen=True)
class UniformBall(Dispersion):
    """A 3-vector uniform in the ball of radius ``radius`` (≥ 0): uniform direction, length
    ``radius · U^(1/3)``."""

    radius: float
    kind: ClassVar[str] = "vector3"

    def __post_init__(self) -> None:
        r = _real(self.radius, "radius", "UniformBall")
        if r < 0:
            raise DefinitionError(f"UniformBall: radius must be ≥ 0; got {r!r}")
        object.__setattr__(self, "radius", r)

    def sample(self, rng: np.random.Generator) -> tuple[float, float, float]:
        axis = _unit_vector(rng)
        u = self.radius * float(rng.uniform()) ** (1.0 / 3.0) * axis
        return (float(u[0]), float(u[1]), float(u[2]))

    def support(self) -> tuple[float, float]:
        return (-self.radius, self.radius)


@dataclass(frozen=True)
class SecondMomentScale(Dispersion):
    """Three independent factors uniform on [low, high] (0 < low ≤ high) scaling a rigid
    body's second moments of mass about its principal axes.

    With principal moments J₁, J₂, J₃, the second moments are ``Aᵢ = (J₁ + J₂ + J₃)/2 − Jᵢ``
    (Aᵢ = ∫ xᵢ² dm ≥ 0 in principal axes) and ``Jᵢ = Σⱼ Aⱼ − Aᵢ``. Scaling each Aᵢ by a positive
    factor keeps every Aᵢ ≥ 0, so the dispersed principal moments satisfy the triangle
    inequality ``Jᵢ + Jⱼ ≥ Jₖ`` (``Jᵢ + Jⱼ − Jₖ = 2Aₖ``) and are positive: the inertia stays
    that of a physical body, whatever the draw (:func:`gmuk.campaign.models.scaled_inertia`).
    """

    low: float
    high: float
    kind: ClassVar[str] = "scale3"

    def __post_init__(self) -> None:
        lo = _real(self.low, "low", "SecondMomentScale")
        hi = _real(self.high, "high", "SecondMomentScale")
        if not 0 < lo <= hi:
            raise DefinitionError(
                f"SecondMomentScale: need 0 < low ≤ high (positive scale factors); got "
                f"low={lo!r}, high={hi!r}"
            )
        object.__setattr__(self, "low", lo)
        object.__setattr__(self, "high", hi)

    def sample(self, rng: np.random.Generator) -> tuple[float, float, float]:
        u = rng.uniform(self.low, self.high, 3)
        return (float(u[0]), float(u[1]), float(u[2]))

    def support(self) -> tuple[float, float]:
        return (self.low, self.high)


_TYPES: dict[str, type[Dispersion]] = {
    cls.__name__: cls
    for cls in (
        Uniform,
        Normal,
        Choice,
        IntegerRange,
        AttitudeCone,
        GaussianVector,
        UniformBall,
        SecondMomentScale,
    )
}


def dispersion_from_dict(data: dict[str, Any]) -> Dispersion:
    """The dispersion described by ``data`` (from :meth:`Dispersion.to_dict`)."""
    if not isinstance(data, dict) or data.get("type") not in _TYPES:
        raise DefinitionError(
            f"a dispersion must be a dict with 'type' one of {', '.join(_TYPES)}; got {data!r}"
        )
    kwargs = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items() if k != "type"}
    try:
        return _TYPES[data["type"]](**kwargs)
    except TypeError as exc:
        raise DefinitionError(f"dispersion {data!r}: {exc}") from None


def magnitude(kind: str, value: Any) -> float:
    """A scalar size of a parameter value: the angle (rad) of a rotation vector, the norm of
    a vector, the largest |factor − 1| of a scale3, the value of a scalar."""
    if kind in ("vector3", "rotation"):
        return float(np.linalg.norm(np.asarray(value, dtype=float)))
    if kind == "scale3":
        return float(np.abs(np.asarray(value, dtype=float) - 1.0).max())
    return float(value)


def check_sequence(values: Sequence[Any], owner: str, limit: int | None = None) -> tuple[Any, ...]:
    """``values`` as a non-empty tuple (grid sweeps) of at most ``limit`` values: a longer
    sequence (a ``range(10**20)``, an endless iterator) is refused before it is stored."""
    if isinstance(values, (str, bytes)):
        raise DefinitionError(f"{owner}: expected a sequence of values; got {values!r}")
    too_many = DefinitionError(
        f"{owner}: the sweep has more than {limit} values (the most a campaign runs: "
        "gmuk.campaign.core.MAX_RUNS)"
    )
    if limit is not None and hasattr(values, "__len__"):
        try:
            if len(values) > limit:
                raise too_many
        except OverflowError:  # len(range(10**20)): beyond an index
            raise too_many from None
        except TypeError:
            pass
    try:
        out = tuple(values if limit is None else itertools.islice(values, limit + 1))
    except TypeError:
        raise DefinitionError(f"{owner}: expected a sequence of values; got {values!r}") from None
    if limit is not None and len(out) > limit:
        raise too_many
    if not out:
        raise DefinitionError(f"{owner}: the sweep has no values")
    return out
