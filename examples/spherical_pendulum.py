"""Classical Udwadia–Kalaba (McCann 2020, Eq. 2): a point mass on a sphere under gravity.

The constraint is written as a residual only; gmuk derives A and b itself.
Run: python examples/spherical_pendulum.py
"""

import numpy as np

import gmuk


class OnSphere(gmuk.HolonomicConstraint):
    """|r|² − L² = 0."""

    def __init__(self, body, length):
        super().__init__([body])
        self.length = length

    def residual(self, q, t):
        (r,) = q
        return np.array([r @ r - self.length**2])


def main() -> dict[str, float]:
    length = 1.5  # m
    bob = gmuk.PointMass("bob", mass=0.4)
    system = gmuk.System([bob], [OnSphere(bob, length)], [gmuk.UniformGravity()])
    # Start on the sphere with a velocity tangent to it: a conical-ish swing.
    r0 = length * np.array([np.sin(0.5), 0.0, -np.cos(0.5)])
    state = system.state(r={"bob": r0}, v={"bob": [0.0, 1.0, 0.0]})
    traj = system.simulate(
        state, (0.0, 10.0), t_eval=np.linspace(0, 10, 201), rtol=1e-10, atol=1e-12
    )
    r = traj.body("bob").position
    tension = -traj.multipliers[:, 0] * 2 * length  # λ·∂φ/∂r = 2λ r: the rod force along r
    result = {
        "radius_error_m": float(np.abs(np.linalg.norm(r, axis=1) - length).max()),
        "min_height_m": float(r[:, 2].min()),
        "mean_tension_N": float(tension.mean()),
    }
    for k, v in result.items():
        print(f"{k:>15}: {v:.4g}")
    return result


if __name__ == "__main__":
    main()
