"""FOUR-BAR: a planar four-bar linkage swinging under gravity, a closed kinematic loop built
from four :class:`gmuk.robots.RevoluteJoint` (issue #28).

Ground pivots O₂ = (0, 0, 0) and O₄ = (d, 0, 0) in N; crank O₂A (length a), coupler AB (b),
rocker O₄B (c), all slender bars of linear density :data:`DENSITY` in the x–y plane, every
joint axis along z, gravity −9.80665 m/s² along y. With a = 0.2 m, b = 0.7 m, c = 0.5 m,
d = 0.6 m it is a Grashof crank–rocker (s + l = 0.9 m ≤ p + q = 1.1 m, the crank the shortest
link): the crank turns all the way round and the rocker swings. The coupler point B is taken
on the "open" branch (B to the left of A→O₄).

Each bar is one :class:`gmuk.RigidBody` at its centre, its x axis along the bar; a joint
frame sits at each end (``(∓L/2, 0, 0)`` in the bar). One loop, four revolute joints: 20 rows
for 18 coordinates, of which only 17 are independent — three of the out-of-plane rows repeat
the others in a planar linkage (Grübler in the plane: 3·3 − 2·4 = 1 degree of freedom; in
space 6·3 − 5·4 = −2, impossible without redundancy). ``A`` is rank-deficient at every state;
the System's dense Udwadia–Kalaba solve, ``(A M^{-1/2})⁺``, takes the minimum-norm
multipliers and the motion is the one the unique, consistent accelerations give.

Analytic references (tests/robots/test_closed_loops.py): Freudenstein's equation
(:func:`freudenstein_residual`) ties the rocker angle to the crank angle at every state, and
the mechanism's one-degree-of-freedom energy integral (:func:`crank_time`) gives the time at
which the crank reaches each angle.

``gmuk run four-bar`` releases the crank at θ₂ = 0 with θ̇₂ = 8 rad/s for 3 s (DOP853,
rtol = atol = 1e-12) and writes summary.json: the final crank angle (unwrapped), the largest
loop-closure residual of the four joints (position and velocity), Freudenstein's residual, the
relative energy drift, and the rows and rank of A. docs/robotics_loops.rst explains the
redundant rows.

References
----------
McCann (2020), Eq. (2) (the Udwadia–Kalaba solve with the pseudo-inverse) and Eq. (73) (the
relative twist of the joints). F. Freudenstein, "Approximate synthesis of four-bar
linkages", Trans. ASME 77 (1955) 853–861. R. L. Norton, *Design of Machinery* (5th ed.,
McGraw-Hill 2012), §4.5 (position) and §6.7 (velocity) of the four-bar; §2.4 (Grashof).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.errors import DomainError
from gmuk.lie import so3
from gmuk.robots import RevoluteJoint
from gmuk.scenarios import Option, Scenario, ScenarioResult, positive_float
from gmuk.view import with_joint_frames

NAME = "four-bar"
DESCRIPTION = "planar four-bar linkage under gravity: one closed loop of revolute joints"

#: link lengths (m): ground O₂O₄, crank O₂A, coupler AB, rocker O₄B
GROUND, CRANK, COUPLER, ROCKER = 0.6, 0.2, 0.7, 0.5
#: linear density of the bars (kg/m)
DENSITY = 2.0
#: gravitational acceleration along y (m/s²)
GRAVITY = 9.80665
RTOL = ATOL = 1e-12
BARS = ("crank", "coupler", "rocker")


def bar(name: str, length: float) -> gmuk.RigidBody:
    """A slender bar along its x axis: m = ρL, central inertia diag(mL²/1200, mL²/12, mL²/12)
    (kg·m²; the small axial moment keeps the inertia positive definite)."""
    m = DENSITY * length
    return gmuk.RigidBody(
        name, m, np.diag([m * length**2 / 1200, m * length**2 / 12, m * length**2 / 12])
    )


def _at(x: float, y: float = 0.0) -> FloatArray:
    g = np.eye(4)
    g[:2, 3] = (x, y)
    return g


def angles(theta2: Any, a: float = CRANK, b: float = COUPLER, c: float = ROCKER,
           d: float = GROUND) -> tuple[Any, Any]:  # fmt: skip
    """Coupler and rocker angles (θ₃, θ₄) (rad, from the x axis) at crank angles θ₂ (scalar or
    array), on the open branch: B where the circles about A (radius b) and O₄ (radius c)
    meet, to the left of A→O₄."""
    theta2 = np.asarray(theta2, dtype=float)
    ax, ay = a * np.cos(theta2), a * np.sin(theta2)
    dx, dy = d - ax, -ay
    e = np.hypot(dx, dy)
    cos_alpha = (b * b + e * e - c * c) / (2.0 * b * e)
    if np.any(np.abs(cos_alpha) > 1.0):
        raise DomainError(
            f"the linkage does not close at every crank angle given (a={a}, b={b}, c={c}, d={d} m)"
        )
    theta3 = np.arctan2(dy, dx) + np.arccos(cos_alpha)
    bx, by = ax + b * np.cos(theta3), ay + b * np.sin(theta3)
    return theta3, np.arctan2(by, bx - d)


def coefficients(theta2: Any, a: float = CRANK, b: float = COUPLER, c: float = ROCKER,
                 d: float = GROUND) -> tuple[Any, Any]:  # fmt: skip
    """First-order kinematic coefficients (dθ₃/dθ₂, dθ₄/dθ₂) of the loop
    ``a e^{iθ₂} + b e^{iθ₃} = d + c e^{iθ₄}`` differentiated once (Cramer's rule on its real
    and imaginary parts)."""
    t3, t4 = angles(theta2, a, b, c, d)
    theta2 = np.asarray(theta2, dtype=float)
    # −b sinθ₃ h₃ + c sinθ₄ h₄ = a sinθ₂;  b cosθ₃ h₃ − c cosθ₄ h₄ = −a cosθ₂
    det = b * c * (np.sin(t3) * np.cos(t4) - np.cos(t3) * np.sin(t4))
    r1, r2 = a * np.sin(theta2), -a * np.cos(theta2)
    h3 = (-r1 * c * np.cos(t4) - c * np.sin(t4) * r2) / det
    h4 = (-b * np.sin(t3) * r2 - b * np.cos(t3) * r1) / det
    return h3, h4


def freudenstein_residual(theta2: Any, theta4: Any, a: float = CRANK, b: float = COUPLER,
                          c: float = ROCKER, d: float = GROUND) -> Any:  # fmt: skip
    """``K₁ cos θ₄ − K₂ cos θ₂ + K₃ − cos(θ₂ − θ₄)`` with K₁ = d/a, K₂ = d/c,
    K₃ = (a² − b² + c² + d²)/(2ac): zero exactly when the loop closes (Freudenstein 1955)."""
    k1, k2, k3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2.0 * a * c)
    return k1 * np.cos(theta4) - k2 * np.cos(theta2) + k3 - np.cos(theta2 - theta4)


def build(
    theta2: float = 0.0, rate: float = 8.0, gravity: bool = True
) -> tuple[gmuk.System, gmuk.State, dict[str, RevoluteJoint]]:
    """The linkage's System, a state on the loop at crank angle θ₂ (rad) and rate θ̇₂ (rad/s),
    and its joints by name ("O2", "A", "B", "O4")."""
    a, b, c, d = CRANK, COUPLER, ROCKER, GROUND
    bodies = [bar("crank", a), bar("coupler", b), bar("rocker", c)]
    crank, coupler, rocker = bodies
    R = RevoluteJoint  # every axis along z
    joints = {
        "O2": R(None, crank, child_frame=_at(-a / 2), name="O2"),
        "A": R(crank, coupler, parent_frame=_at(a / 2), child_frame=_at(-b / 2), name="A"),
        "B": R(coupler, rocker, parent_frame=_at(b / 2), child_frame=_at(c / 2), name="B"),
        "O4": R(None, rocker, parent_frame=_at(d), child_frame=_at(-c / 2), name="O4"),
    }
    forces = [gmuk.UniformGravity((0.0, -GRAVITY, 0.0))] if gravity else []
    system = gmuk.System(bodies, list(joints.values()), forces)
    return system, state_at(system, theta2, rate), joints


def state_at(system: gmuk.System, theta2: float, rate: float) -> gmuk.State:
    """The state of the linkage at crank angle θ₂ (rad) and rate θ̇₂ (rad/s)."""
    a, b, c, d = CRANK, COUPLER, ROCKER, GROUND
    t3, t4 = angles(theta2)
    h3, h4 = coefficients(theta2)
    e = lambda th: np.array([math.cos(th), math.sin(th), 0.0])  # noqa: E731
    n = lambda th: np.array([-math.sin(th), math.cos(th), 0.0])  # noqa: E731
    A = a * e(theta2)
    centres = {
        "crank": (theta2, a / 2 * e(theta2), a / 2 * n(theta2)),
        "coupler": (t3, A + b / 2 * e(t3), a * n(theta2) + b / 2 * h3 * n(t3)),
        "rocker": (t4, np.array([d, 0, 0]) + c / 2 * e(t4), c / 2 * h4 * n(t4)),
    }
    rates = {"crank": 1.0, "coupler": h3, "rocker": h4}
    g, V = {}, {}
    for name, (th, r_N, dr_N) in centres.items():
        R = so3.exp(np.array([0.0, 0.0, th]))
        g[name] = _pose(R, r_N)
        V[name] = np.concatenate([[0.0, 0.0, rates[name] * rate], R.T @ dr_N * rate])
    return system.state(g=g, V=V)


def _pose(R: FloatArray, r: FloatArray) -> FloatArray:
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = R, r
    return g


def energy(system: gmuk.System, traj: gmuk.Trajectory) -> FloatArray:
    """Kinetic plus potential energy (J) at every output (N,)."""
    out = np.zeros(len(traj))
    for body in system.bodies:
        bt = traj.body(body.name)
        w, v = bt.omega, bt.v
        out += 0.5 * np.einsum("ni,ij,nj->n", w, body.inertia, w)
        out += 0.5 * body.mass * np.einsum("ni,ni->n", v, v)
        out += body.mass * GRAVITY * bt.position[:, 1]
    return out


def loop_residuals(joints: dict[str, RevoluteJoint], traj: gmuk.Trajectory) -> tuple[float, float]:
    """The largest position (m, rad) and velocity (m/s, rad/s) residual of the joints over
    the outputs (:meth:`gmuk.robots.Joint.violation`)."""
    pos = vel = 0.0
    for i in range(len(traj)):
        s = traj.state(i)
        for j in joints.values():
            p, v = j.violation(s)
            pos, vel = max(pos, float(np.abs(p).max())), max(vel, float(np.abs(v).max()))
    return pos, vel


def generalised_mass_and_potential(theta2: Any) -> tuple[Any, Any]:
    """The linkage's generalised mass ``m(θ₂) = Σ mᵢ |∂rᵢ/∂θ₂|² + Jᵢ (∂θᵢ/∂θ₂)²`` (kg·m²) and
    potential energy U(θ₂) (J) from the kinematic coefficients (:func:`coefficients`):
    written from the loop equation alone, independent of gmuk's bodies and joints."""
    a, b, c = CRANK, COUPLER, ROCKER
    th = np.asarray(theta2, dtype=float)
    t3, t4 = angles(th)
    h3, h4 = coefficients(th)
    ms = [DENSITY * L for L in (a, b, c)]
    Js = [m * L * L / 12 for m, L in zip(ms, (a, b, c), strict=True)]
    # centre velocities per unit θ̇₂ (x, y)
    vx = [-a / 2 * np.sin(th), -a * np.sin(th) - b / 2 * h3 * np.sin(t3), -c / 2 * h4 * np.sin(t4)]
    vy = [a / 2 * np.cos(th), a * np.cos(th) + b / 2 * h3 * np.cos(t3), c / 2 * h4 * np.cos(t4)]
    w = [np.ones_like(th), h3, h4]
    y = [a / 2 * np.sin(th), a * np.sin(th) + b / 2 * np.sin(t3), c / 2 * np.sin(t4)]
    mass = sum(
        m * (u * u + v * v) + J * o * o for m, u, v, J, o in zip(ms, vx, vy, Js, w, strict=True)
    )
    return mass, sum(m * GRAVITY * yy for m, yy in zip(ms, y, strict=True))


def crank_time(theta2: Any, theta2_0: float, rate0: float, panels_per_rad: int = 40) -> FloatArray:
    """The times (s) at which the free linkage under gravity, started at crank angle θ₂₀ with
    rate θ̇₂₀ > 0, reaches the increasing angles ``theta2`` (> θ₂₀), from its energy integral
    ``½ m(θ₂) θ̇₂² + U(θ₂) = E``: ``t = ∫ dθ / θ̇(θ)`` by 8-point Gauss–Legendre on panels of at
    most 1/``panels_per_rad`` rad (:func:`generalised_mass_and_potential`)."""
    m0, U0 = generalised_mass_and_potential(theta2_0)
    E = 0.5 * m0 * rate0**2 + U0
    x, w = np.polynomial.legendre.leggauss(8)
    ends = np.concatenate([[theta2_0], np.atleast_1d(np.asarray(theta2, dtype=float))])
    if np.any(np.diff(ends) <= 0.0):
        raise DomainError("crank_time needs increasing angles beyond theta2_0")
    out = np.empty(len(ends) - 1)
    total = 0.0
    for k in range(len(ends) - 1):
        n = max(1, math.ceil((ends[k + 1] - ends[k]) * panels_per_rad))
        edges = np.linspace(ends[k], ends[k + 1], n + 1)
        half = 0.5 * np.diff(edges)[:, None]
        th = half * x[None, :] + 0.5 * (edges[1:] + edges[:-1])[:, None]
        m, U = generalised_mass_and_potential(th)
        total += float(np.sum(half * w[None, :] / np.sqrt(2.0 * (E - U) / m)))
        out[k] = total
    return out


def simulate(
    duration: float = 3.0, rate: float = 8.0
) -> tuple[gmuk.System, dict[str, RevoluteJoint], gmuk.Trajectory]:
    """The free linkage under gravity, released at θ₂ = 0 with θ̇₂ = ``rate``; outputs every
    0.01 s."""
    system, state, joints = build(0.0, rate)
    t_eval = np.linspace(0.0, duration, round(duration / 0.01) + 1)
    traj = system.simulate(state, (0.0, duration), t_eval=t_eval, rtol=RTOL, atol=ATOL)
    return system, joints, traj


def run(duration: float = 3.0, crank_rate: float = 8.0) -> ScenarioResult:
    """Release the crank at θ₂ = 0 with θ̇₂ = ``crank_rate`` (rad/s) for ``duration`` s."""
    system, joints, traj = simulate(duration, crank_rate)
    traj = with_joint_frames(traj, system)  # the 3-D view draws the bars and joints
    E = energy(system, traj)
    pos, vel = loop_residuals(joints, traj)
    theta2 = joints["O2"].coordinates_along(traj)[:, 0]
    theta4 = joints["O4"].coordinates_along(traj)[:, 0]
    A0 = system.constraint_rows(traj.state(0))[0]
    A0 = A0.toarray() if hasattr(A0, "toarray") else np.asarray(A0)
    summary = {
        "duration_s": float(traj.t[-1]),
        "crank_rate0_rad_per_s": crank_rate,
        "crank_angle_final_rad": float(theta2[-1]),
        "crank_turns": float(theta2[-1] / (2 * math.pi)),
        "loop_position_residual_max": pos,
        "loop_velocity_residual_max": vel,
        "freudenstein_residual_max": float(np.abs(freudenstein_residual(theta2, theta4)).max()),
        "energy_J": float(E[0]),
        "energy_drift_rel": float(np.abs(E - E[0]).max() / abs(E[0])),
        "constraint_rows": int(A0.shape[0]),
        "constraint_rank": int(np.linalg.matrix_rank(A0, tol=1e-10)),
        "n_rhs": int(traj.stats.get("n_rhs", 0)),
    }
    data = {"system": system, "joints": joints, "energy": E, "theta2": theta2, "theta4": theta4}
    return ScenarioResult(NAME, {NAME: traj}, NAME, summary, data=data)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Crank and rocker angles, Freudenstein's residual, energy drift."""
    out.mkdir(parents=True, exist_ok=True)
    traj = result.trajectories[result.primary]
    t = traj.t
    d = result.data
    E = d["energy"]
    paths = plotting.plot_panels(
        t,
        [
            ("θ₂ (deg)", [("crank θ₂", np.degrees(d["theta2"]), {"color": "C0"})]),
            ("θ₄ (deg)", [("rocker θ₄", np.degrees(d["theta4"]), {"color": "C1"})]),
        ],
        "Four-bar under gravity: joint angles",
        out / "angles",
        formats,
    )
    paths += plotting.plot_panels(
        t,
        [
            (
                "Freudenstein residual",
                [
                    (
                        "K₁cosθ₄ − K₂cosθ₂ + K₃ − cos(θ₂−θ₄)",
                        freudenstein_residual(d["theta2"], d["theta4"]),
                        {"color": "C2"},
                    )
                ],
            ),
            ("(E − E₀)/E₀", [("energy drift", (E - E[0]) / abs(E[0]), {"color": "C3"})]),
        ],
        "Four-bar: loop closure and energy",
        out / "closure_energy",
        formats,
    )
    return paths


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("duration", positive_float, 3.0, "simulated time (s)"),
        Option("crank_rate", positive_float, 8.0, "initial crank rate θ̇₂ (rad/s)"),
    ),
)
