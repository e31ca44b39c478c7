"""Classical Udwadia–Kalaba for particles (McCann 2020, Section 2.1, Eq. 2) against
analytic solutions."""

from __future__ import annotations

import numpy as np

import gmuk


class Sphere(gmuk.HolonomicConstraint):
    """|r|² = L²: a spherical pendulum."""

    def __init__(self, body, length):
        super().__init__([body])
        self.length = length

    def residual(self, q, t):
        (r,) = q
        return np.array([r @ r - self.length**2])


class RotatingWire(gmuk.HolonomicConstraint):
    """A bead on a straight wire through the origin spinning at Ω about z."""

    def __init__(self, body, rate):
        super().__init__([body])
        self.spin = rate

    def residual(self, q, t):
        (r,) = q
        c, s = np.cos(self.spin * t), np.sin(self.spin * t)
        return np.array([-r[0] * s + r[1] * c, r[2]])


def test_spherical_pendulum_small_oscillation_period():
    length, g0, theta0 = 2.0, 9.81, 0.01
    bob = gmuk.PointMass("bob", 0.7)
    system = gmuk.System([bob], [Sphere(bob, length)], [gmuk.UniformGravity((0, 0, -g0))])
    r0 = length * np.array([np.sin(theta0), 0.0, -np.cos(theta0)])
    state = system.state(r={"bob": r0}, v={"bob": np.zeros(3)})
    w = np.sqrt(g0 / length)
    period = (
        2 * np.pi / w * (1 + theta0**2 / 16 + 11 * theta0**4 / 3072)
    )  # elliptic-integral series
    t = np.linspace(0.0, 3.2 * period, 4001)
    traj = system.simulate(state, (0.0, t[-1]), t_eval=t, rtol=1e-12, atol=1e-13)
    x = traj.body("bob").position[:, 0]
    # Upward crossings of x = 0 by linear interpolation of the dense output.
    i = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    crossings = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    measured = np.diff(crossings).mean()
    assert abs(measured / period - 1.0) < 2e-7  # interpolation error ~ (Δt ω)² θ-curvature
    # No stabilisation: the finite-difference b (error ≈ eps/τ² of φ's scale, ~1e-10 m²/s²)
    # integrates twice into a drift of ~½·1e-10·t² / (2L) ≈ 4e-9 m over 9 s.
    drift = np.abs(np.linalg.norm(traj.body("bob").position, axis=1) - length)
    assert drift.max() < 1e-8


def test_bead_on_rotating_wire_follows_cosh_law():
    rate = 0.8
    bead = gmuk.PointMass("bead", 0.2)
    system = gmuk.System([bead], [RotatingWire(bead, rate)])
    state = system.state(r={"bead": [0.5, 0.0, 0.0]}, v={"bead": [0.0, 0.5 * rate, 0.0]})
    t = np.linspace(0.0, 3.0, 31)
    # Automatic rows carry finite-difference noise of ~1e-10: tolerances below that only
    # make the step controller chase noise (see HolonomicConstraint's docstring).
    traj = system.simulate(state, (0.0, 3.0), t_eval=t, rtol=1e-10, atol=1e-12)
    r = traj.body("bead").position
    expected = (
        0.5
        * np.cosh(rate * t)[:, None]
        * np.stack([np.cos(rate * t), np.sin(rate * t), 0 * t], axis=1)
    )
    assert np.abs(r - expected).max() < 1e-8 * np.abs(expected).max()
