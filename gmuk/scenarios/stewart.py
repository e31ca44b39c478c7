"""STEWART: a Stewart–Gough platform (6-UPS) held under gravity by its six leg actuators, six
closed loops of gmuk.robots joints (issue #28).

Geometry (all in N, z up): the base attachment points ``b_i`` on a circle of radius
:data:`BASE_RADIUS` at azimuths 0°, 120°, 240° ± :data:`BASE_HALF_ANGLE_DEG`; the platform's
``p_i`` (in its body frame, at its centre of mass) on a circle of :data:`PLATFORM_RADIUS` at
60°, 180°, 300° ∓ :data:`PLATFORM_HALF_ANGLE_DEG`, each leg joining ``b_i`` to the platform
point of the neighbouring pair. Each leg is

- a lower leg (:data:`LOWER_MASS`, length :data:`LOWER_LENGTH`), tied to the ground by a
  :class:`gmuk.robots.UniversalJoint` at ``b_i`` (axis x of N, then the leg's own y); its
  body frame at its centre with z along the leg;
- an upper leg (:data:`UPPER_MASS`, :data:`UPPER_LENGTH`), on a
  :class:`gmuk.robots.PrismaticJoint` along the lower leg's z between the two centres
  (coordinate s, m: the leg length is ``L = s + (l₁ + l₂)/2``);
- a :class:`gmuk.robots.SphericalJoint` from the upper leg's tip to ``p_i``.

13 bodies (78 coordinates), 6 × (4 + 5 + 3) = 72 rows: six degrees of freedom, the platform's,
with no redundant row. The closed-form inverse kinematics (:func:`leg_coordinates`) gives
every leg's (q₁, q₂, s) and rates from the platform's pose and twist, and :func:`state_at`
the consistent state.

``gmuk run stewart``: the platform starts at rest at its nominal pose (:data:`HEIGHT` above
the base) and is held by a PD on each leg's slide, ``τ = −k (s − s₀) − c ṡ`` (a
:class:`gmuk.robots.JointSpringDamper` on the prismatic joint, k = :data:`LEG_STIFFNESS`,
c = :data:`LEG_DAMPING`), with no gravity feed-forward: it sags under its weight and the legs'
and settles. summary.json: the platform's final sag and tilt, the largest loop-closure
residual, the leg forces at the end.

Its constrained accelerations agree with Pinocchio's ``constraintDynamics`` on the same
mechanism built as a tree with six loop-closure constraints
(tests/robots/test_closed_loops.py; docs/robotics_loops.rst).

References
----------
D. Stewart, "A platform with six degrees of freedom", Proc. IMechE 180 (1965) 371–386.
J.-P. Merlet, *Parallel Robots* (2nd ed., Springer 2006), Ch. 3 (the 6-UPS inverse
kinematics). McCann (2020), Eq. (2) and Eq. (73). J. Carpentier et al., "The Pinocchio C++
library", IEEE/SICE SII (2019) (the cross-check's constraint dynamics).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.lie import so3
from gmuk.robots import JointSpringDamper, PrismaticJoint, SphericalJoint, UniversalJoint
from gmuk.scenarios import Option, Scenario, ScenarioResult, positive_float
from gmuk.view import with_joint_frames

NAME = "stewart"
DESCRIPTION = "Stewart–Gough platform (6-UPS) held under gravity by PD leg actuators: six loops"

BASE_RADIUS, PLATFORM_RADIUS = 0.5, 0.3  # m
BASE_HALF_ANGLE_DEG, PLATFORM_HALF_ANGLE_DEG = 15.0, 10.0
HEIGHT = 0.6  # m, platform centre above the base plane at the nominal pose
PLATFORM_MASS = 10.0  # kg
PLATFORM_INERTIA = np.diag([0.25, 0.25, 0.45])  # kg·m², central
LOWER_MASS, LOWER_LENGTH = 1.0, 0.4  # kg, m
UPPER_MASS, UPPER_LENGTH = 0.5, 0.4
GRAVITY = 9.81  # m/s², along −z
LEG_STIFFNESS = 2.0e4  # N/m
LEG_DAMPING = 1.0e3  # N·s/m
RTOL = ATOL = 1e-10


def rod_inertia(mass: float, length: float) -> FloatArray:
    """Central inertia (kg·m²) of a rod along z of radius 2 cm."""
    r = 0.02
    side = mass * (3 * r * r + length * length) / 12
    return np.diag([side, side, mass * r * r / 2])


def _pose(R: FloatArray, r: Any) -> FloatArray:
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = R, r
    return g


def base_points() -> FloatArray:
    """b_i (6, 3) in N (m)."""
    out = []
    for k in range(3):
        for sgn in (-1, 1):
            a = math.radians(120 * k + sgn * BASE_HALF_ANGLE_DEG)
            out.append([BASE_RADIUS * math.cos(a), BASE_RADIUS * math.sin(a), 0.0])
    return np.array(out)


def platform_points() -> FloatArray:
    """p_i (6, 3) in the platform's body frame (m): leg i ends at the platform point nearest
    its base point's neighbour pair (the classic 6-6 zig-zag)."""
    out = []
    for k in range(3):
        for sgn in (-1, 1):
            a = math.radians(120 * k + sgn * (60 - PLATFORM_HALF_ANGLE_DEG))
            out.append([PLATFORM_RADIUS * math.cos(a), PLATFORM_RADIUS * math.sin(a), 0.0])
    return np.array(out)


def nominal_pose() -> FloatArray:
    """The platform's nominal pose g_NP (4, 4): level, HEIGHT above the base."""
    return _pose(np.eye(3), [0.0, 0.0, HEIGHT])


def _z(length: float) -> FloatArray:
    return _pose(np.eye(3), [0.0, 0.0, length])


def build(
    stiffness: float = LEG_STIFFNESS, damping: float = LEG_DAMPING, gravity: bool = True
) -> tuple[gmuk.System, dict[str, Any]]:
    """The platform's System and its parts: ``parts["universal"|"prismatic"|"spherical"]``
    (lists of six joints), ``parts["legs"]`` (the PD on each slide, or none with both gains
    zero)."""
    platform = gmuk.RigidBody("platform", PLATFORM_MASS, PLATFORM_INERTIA)
    bodies: list[gmuk.RigidBody] = []
    U: list[UniversalJoint] = []
    P: list[PrismaticJoint] = []
    S: list[SphericalJoint] = []
    b, p = base_points(), platform_points()
    for i in range(6):
        lower = gmuk.RigidBody(f"lower{i}", LOWER_MASS, rod_inertia(LOWER_MASS, LOWER_LENGTH))
        upper = gmuk.RigidBody(f"upper{i}", UPPER_MASS, rod_inertia(UPPER_MASS, UPPER_LENGTH))
        bodies += [lower, upper]
        U.append(
            UniversalJoint(
                None,
                lower,
                parent_frame=_pose(np.eye(3), b[i]),
                child_frame=_z(-LOWER_LENGTH / 2),
                name=f"U{i}",
            )
        )
        P.append(PrismaticJoint(lower, upper, axis=(0, 0, 1), name=f"P{i}"))
        S.append(
            SphericalJoint(
                upper,
                platform,
                parent_frame=_z(UPPER_LENGTH / 2),
                child_frame=_pose(np.eye(3), p[i]),
                name=f"S{i}",
            )
        )
    bodies.append(platform)
    rest = leg_coordinates(nominal_pose(), np.zeros(6))[0][:, 2]
    legs = (
        [
            JointSpringDamper(P[i], stiffness=stiffness, damping=damping, rest=rest[i])
            for i in range(6)
        ]
        if stiffness or damping
        else []
    )
    forces: list[gmuk.ForceModel] = list(legs)
    if gravity:
        forces.append(gmuk.UniformGravity((0.0, 0.0, -GRAVITY)))
    system = gmuk.System(bodies, [*U, *P, *S], forces)
    return system, {"universal": U, "prismatic": P, "spherical": S, "legs": legs, "rest": rest}


def leg_coordinates(g_NP: FloatArray, V_P: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Closed-form inverse kinematics: each leg's (q₁, q₂, s) (6, 3) (rad, rad, m) and rates
    (6, 3) for the platform at pose g_NP with body twist V_P = [ω; v] (rad/s, m/s).

    The leg's direction is ``u = Rx(q₁) Ry(q₂) e_z`` (the universal joint's coordinates), its
    length ``L = |p_i^N − b_i|`` and ``s = L − (l₁ + l₂)/2``. The rates solve
    ``q̇₁ x × Lu + q̇₂ (Rx(q₁) y) × Lu + L̇ u = v_{p_i}``, the velocity of the platform point.
    """
    R, r = g_NP[:3, :3], g_NP[:3, 3]
    w_N, v_N = R @ V_P[:3], R @ V_P[3:]
    q, qd = np.empty((6, 3)), np.empty((6, 3))
    for i, (b, p) in enumerate(zip(base_points(), platform_points(), strict=True)):
        d = r + R @ p - b
        L = float(np.linalg.norm(d))
        u = d / L
        q1, q2 = math.atan2(-u[1], u[2]), math.asin(u[0])
        q[i] = (q1, q2, L - 0.5 * (LOWER_LENGTH + UPPER_LENGTH))
        v_p = v_N + np.cross(w_N, R @ p)
        a2 = so3.exp(np.array([q1, 0.0, 0.0])) @ np.array([0.0, 1.0, 0.0])
        J = np.column_stack([np.cross([1.0, 0.0, 0.0], L * u), np.cross(a2, L * u), u])
        qd[i] = np.linalg.solve(J, v_p)
    return q, qd


def state_at(system: gmuk.System, g_NP: FloatArray, V_P: FloatArray) -> gmuk.State:
    """The consistent state with the platform at pose g_NP and body twist V_P (every leg from
    :func:`leg_coordinates`)."""
    q, qd = leg_coordinates(g_NP, V_P)
    g = {"platform": g_NP}
    V = {"platform": np.asarray(V_P, dtype=float)}
    x, y, _ = np.eye(3)
    for i, b in enumerate(base_points()):
        q1, q2, s = q[i]
        q1d, q2d, sd = qd[i]
        R = so3.exp(q1 * x) @ so3.exp(q2 * y)
        w_N = q1d * x + q2d * (so3.exp(q1 * x) @ y)
        for name, arm, slide in (
            (f"lower{i}", LOWER_LENGTH / 2, 0.0),
            (f"upper{i}", LOWER_LENGTH / 2 + s, sd),
        ):
            g[name] = _pose(R, b + arm * R[:, 2])
            v_N = np.cross(w_N, arm * R[:, 2]) + slide * R[:, 2]
            V[name] = np.concatenate([R.T @ w_N, R.T @ v_N])
    return system.state(g=g, V=V)


def simulate(
    duration: float = 1.0, stiffness: float = LEG_STIFFNESS, damping: float = LEG_DAMPING
) -> tuple[gmuk.System, dict[str, Any], gmuk.Trajectory]:
    """The platform released at rest at its nominal pose; outputs every 5 ms."""
    system, parts = build(stiffness, damping)
    state = state_at(system, nominal_pose(), np.zeros(6))
    t_eval = np.linspace(0.0, duration, round(duration / 0.005) + 1)
    traj = system.simulate(state, (0.0, duration), t_eval=t_eval, rtol=RTOL, atol=ATOL)
    return system, parts, traj


def loop_residuals(parts: dict[str, Any], traj: gmuk.Trajectory) -> tuple[float, float]:
    """The largest position (m, rad) and velocity (m/s, rad/s) residual of all 18 joints."""
    joints = [*parts["universal"], *parts["prismatic"], *parts["spherical"]]
    pos = vel = 0.0
    for i in range(len(traj)):
        s = traj.state(i)
        for j in joints:
            p, v = j.violation(s)
            pos, vel = max(pos, float(np.abs(p).max())), max(vel, float(np.abs(v).max()))
    return pos, vel


def run(
    duration: float = 1.0, stiffness: float = LEG_STIFFNESS, damping: float = LEG_DAMPING
) -> ScenarioResult:
    """Release the platform at rest at its nominal pose under gravity, legs on PD."""
    system, parts, traj = simulate(duration, stiffness, damping)
    traj = with_joint_frames(traj, system)  # the 3-D view draws the legs and joints
    plat = traj.body("platform")
    sag = HEIGHT - plat.position[:, 2]
    tilt = np.array([np.linalg.norm(so3.log(R)) for R in plat.R])
    slides = np.array([j.coordinates_along(traj)[:, 0] for j in parts["prismatic"]]).T
    rates = np.array([j.rates_along(traj)[:, 0] for j in parts["prismatic"]]).T
    force = -stiffness * (slides - parts["rest"]) - damping * rates
    pos, vel = loop_residuals(parts, traj)
    summary = {
        "duration_s": float(traj.t[-1]),
        "leg_stiffness_N_per_m": stiffness,
        "leg_damping_N_s_per_m": damping,
        "platform_sag_final_m": float(sag[-1]),
        "platform_sag_max_m": float(sag.max()),
        "platform_tilt_max_rad": float(tilt.max()),
        "platform_horizontal_max_m": float(np.abs(plat.position[:, :2]).max()),
        "leg_force_final_N": [float(f) for f in force[-1]],
        "leg_force_final_mean_N": float(force[-1].mean()),
        "loop_position_residual_max": pos,
        "loop_velocity_residual_max": vel,
        "n_rhs": int(traj.stats.get("n_rhs", 0)),
    }
    data = {"system": system, "parts": parts, "sag": sag, "force": force, "slides": slides}
    return ScenarioResult(NAME, {NAME: traj}, NAME, summary, data=data)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """The platform's sag and the leg forces."""
    out.mkdir(parents=True, exist_ok=True)
    traj = result.trajectories[result.primary]
    d = result.data
    legs = [(f"leg {i}", d["force"][:, i], {"color": f"C{i}"}) for i in range(6)]
    return plotting.plot_panels(
        traj.t,
        [
            ("sag (mm)", [("platform sag", 1e3 * d["sag"], {"color": "C0"})]),
            ("leg force (N)", legs),
        ],
        "Stewart platform under gravity, PD legs",
        out / "sag_forces",
        formats,
    )


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("duration", positive_float, 1.0, "simulated time (s)"),
        Option("stiffness", positive_float, LEG_STIFFNESS, "PD stiffness of each leg (N/m)"),
        Option("damping", positive_float, LEG_DAMPING, "PD damping of each leg (N·s/m)"),
    ),
)
