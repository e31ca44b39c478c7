"""A closed kinematic loop: a planar four-bar linkage of four revolute joints under gravity.

Three bars (crank, coupler, rocker) and four RevoluteJoints (axes along z) close one loop with
the ground. The loop has more rows than the bars have independent constraints (20 rows, rank
17): gmuk's Udwadia–Kalaba solve takes them as they are. The run checks the loop with
Freudenstein's equation, which ties the rocker angle θ₄ to the crank angle θ₂ at every state.
Run: python examples/closed_loop_four_bar.py
"""

import numpy as np

import gmuk
from gmuk.robots import RevoluteJoint


def bar(name, length, density=2.0):
    """A slender bar along its body x axis, its frame at its centre (kg, kg·m²)."""
    m = density * length
    J = m * length**2 / 12
    return gmuk.RigidBody(name, m, np.diag([J / 100, J, J]))


def at(x):
    """A joint frame at (x, 0, 0), axes those of the body (or of N)."""
    g = np.eye(4)
    g[0, 3] = x
    return g


def main() -> dict[str, float]:
    a, b, c, d = 0.2, 0.7, 0.5, 0.6  # crank, coupler, rocker, ground (m)
    crank, coupler, rocker = bar("crank", a), bar("coupler", b), bar("rocker", c)
    joints = [
        RevoluteJoint(None, crank, child_frame=at(-a / 2), name="O2"),  # ground at the origin
        RevoluteJoint(crank, coupler, parent_frame=at(a / 2), child_frame=at(-b / 2)),
        RevoluteJoint(coupler, rocker, parent_frame=at(b / 2), child_frame=at(c / 2)),
        RevoluteJoint(None, rocker, parent_frame=at(d), child_frame=at(-c / 2), name="O4"),
    ]
    system = gmuk.System(
        [crank, coupler, rocker], joints, [gmuk.UniformGravity((0.0, -9.80665, 0.0))]
    )
    # at rest with the crank straight up (θ₂ = 90°): place the coupler and the rocker on the loop
    A = np.array([0.0, a, 0.0])
    e = np.hypot(d, a)  # |O4 − A|
    theta3 = np.arctan2(-a, d) + np.arccos((b * b + e * e - c * c) / (2 * b * e))
    B = A + b * np.array([np.cos(theta3), np.sin(theta3), 0.0])
    theta4 = np.arctan2(B[1], B[0] - d)

    def pose(theta, centre):
        g = np.eye(4)
        g[:3, :3] = gmuk.lie.so3.exp(np.array([0.0, 0.0, theta]))
        g[:3, 3] = centre
        return g

    state = system.state(
        g={
            "crank": pose(np.pi / 2, A / 2),
            "coupler": pose(theta3, (A + B) / 2),
            "rocker": pose(theta4, (B + np.array([d, 0.0, 0.0])) / 2),
        },
        V={name: np.zeros(6) for name in ("crank", "coupler", "rocker")},
    )
    traj = system.simulate(state, (0.0, 1.0), t_eval=np.linspace(0, 1, 101), rtol=1e-12, atol=1e-12)
    th2 = joints[0].coordinates_along(traj)[:, 0]
    th4 = joints[3].coordinates_along(traj)[:, 0]
    k1, k2, k3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    freudenstein = k1 * np.cos(th4) - k2 * np.cos(th2) + k3 - np.cos(th2 - th4)
    A0 = system.constraint_rows(state)[0]
    result = {
        "constraint_rows": float(A0.shape[0]),
        "constraint_rank": float(np.linalg.matrix_rank(np.asarray(A0), tol=1e-10)),
        "crank_swing_deg": float(np.degrees(np.ptp(th2))),
        "freudenstein_residual_max": float(np.abs(freudenstein).max()),
    }
    for key, value in result.items():
        print(f"{key:>26}: {value:.4g}")
    return result


if __name__ == "__main__":
    main()
