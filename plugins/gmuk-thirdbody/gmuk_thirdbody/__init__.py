"""Third-body point-mass perturbation as a gmuk force model (entry point ``third_body``)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gmuk import ForceModel
from gmuk.errors import DefinitionError

__all__ = [
    "EARTH_FROM_MOON",
    "SUN_FROM_MOON",
    "CircularEphemeris",
    "ThirdBodyGravity",
    "third_body_acceleration",
]

AU = 1.495978707e11  # m (IAU 2012 Resolution B2)


@dataclass(frozen=True)
class CircularEphemeris:
    """A third body on a circular orbit about the origin of N, in N's x–y plane.

    ``d_N(t) = radius · [cos(2π t/period + phase), sin(2π t/period + phase), 0]``.

    Parameters
    ----------
    radius : float
        Distance (m).
    period : float
        Orbital period (s).
    phase : float
        Angle at t = 0 (rad).
    """

    radius: float
    period: float
    phase: float = 0.0

    def __post_init__(self) -> None:
        if not (self.radius > 0 and self.period > 0 and np.isfinite(self.phase)):
            raise DefinitionError(
                f"CircularEphemeris needs radius > 0 and period > 0; got "
                f"radius={self.radius!r}, period={self.period!r}"
            )

    def __call__(self, t: float) -> np.ndarray:
        a = 2.0 * np.pi * t / self.period + self.phase
        return self.radius * np.array([np.cos(a), np.sin(a), 0.0])


#: Earth seen from the Moon: mean distance 384 400 km, sidereal month 27.321661 d.
EARTH_FROM_MOON = CircularEphemeris(3.844e8, 27.321661 * 86400.0)
#: Sun seen from the Moon, to first order: 1 au, sidereal year 365.256363 d.
SUN_FROM_MOON = CircularEphemeris(AU, 365.256363 * 86400.0)


def third_body_acceleration(r_N: np.ndarray, d_N: np.ndarray, mu: float) -> np.ndarray:
    """Perturbing acceleration ``μ₃[(d − r)/|d − r|³ − d/|d|³]`` (m/s²) in N."""
    rho = d_N - r_N
    return mu * (rho / np.linalg.norm(rho) ** 3 - d_N / np.linalg.norm(d_N) ** 3)


class ThirdBodyGravity(ForceModel):
    """Gravity of a third body on bodies orbiting the central body at N's origin.

    Parameters
    ----------
    mu : float
        Gravitational parameter of the third body (m³/s²), e.g. 3.986004418e14 (Earth).
    ephemeris : callable t ↦ d_N (3,)
        Position of the third body relative to the central body, in N (m).
    bodies : sequence, optional
    modeled : bool
        Whether the constraint solve knows it (default True).
    """

    mass_proportional = True  # gravity: force ∝ m, torque ∝ J

    def __init__(
        self,
        mu: float,
        ephemeris: Callable[[float], Any],
        *,
        bodies: Sequence[Any] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        if not (np.isfinite(mu) and mu > 0):
            raise DefinitionError(f"mu must be > 0 (m³/s²); got {mu!r}")
        if not callable(ephemeris):
            raise DefinitionError("ephemeris must be a callable t ↦ d_N (3,) in metres")
        self.mu = float(mu)
        self.ephemeris = ephemeris

    def force(self, t: float, r_N: np.ndarray, v_N: np.ndarray, body: Any) -> np.ndarray:
        """f_N on a point mass (N)."""
        d = np.asarray(self.ephemeris(t), dtype=float)
        return body.mass * third_body_acceleration(r_N, d, self.mu)

    def wrench(self, t: float, g_NB: np.ndarray, V_B: np.ndarray, body: Any) -> np.ndarray:
        """[L; f] in the body frame for a rigid body (N·m, N)."""
        d = np.asarray(self.ephemeris(t), dtype=float)
        r = g_NB[:3, 3]
        f_N = body.mass * third_body_acceleration(r, d, self.mu)
        R = g_NB[:3, :3]
        rho_B = R.T @ (d - r)
        n = float(np.linalg.norm(rho_B))
        L = 3.0 * self.mu / n**5 * np.cross(rho_B, body.inertia @ rho_B)
        return np.concatenate([L, R.T @ f_N])
