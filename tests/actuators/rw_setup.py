"""The rw-pointing spacecraft (gmuk/scenarios/rw_pointing.py) in both wheel forms, with
friction and the motors as options, for the actuator tests.

Issue #29, item 7: I_B = diag(900, 800, 600) kg·m² with the wheels locked, three wheels on
the body axes with J_s = 50 / (6000 rpm) kg·m², motor limit 0.2 N·m, speeds 100, 200,
300 rpm relative to the bus, σ_BN = (0.1, 0.2, −0.3), ω_BN = (0.001, −0.01, 0.03) rad/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

import gmuk
from gmuk.actuators import ReactionWheel, WheelArray, WheelMotors
from gmuk.attitude import R_NB_from_mrp
from gmuk.scenarios import rw_pointing

RPM = rw_pointing.RPM
I_B = rw_pointing.INERTIA_B
J_S = rw_pointing.SPIN_INERTIA
SIGMA0 = rw_pointing.SIGMA0
OMEGA0 = rw_pointing.OMEGA0
SPEEDS0 = rw_pointing.SPEEDS0
MASS = rw_pointing.MASS


def wheels(friction: float = 0.0, max_torque: float = 0.2) -> WheelArray:
    return WheelArray(
        [
            ReactionWheel(e, J_S, max_torque=max_torque, max_speed=6000 * RPM, friction=friction)
            for e in np.eye(3)
        ]
    )


def g0() -> np.ndarray:
    g = np.eye(4)
    g[:3, :3] = R_NB_from_mrp(SIGMA0)
    return g


@dataclass
class Setup:
    system: gmuk.System
    state: gmuk.State
    wheels: WheelArray
    law: gmuk.MRPFeedback
    bodies: list[Any]


def internal(w: WheelArray, omega0: Any = OMEGA0, **gains: float) -> Setup:
    """The internal-momentum form: the bus and the MRPFeedback controller."""
    bus = gmuk.RigidBody("bus", MASS, w.spun_down_inertia(I_B))
    law = gmuk.MRPFeedback(bus, w, inertia_B=I_B, **{"K": 3.5, "P": 30.0, **gains})
    system = gmuk.System([bus], controllers=[law])
    V0 = np.r_[omega0, 0.0, 0.0, 0.0]
    state = system.state(g={"bus": g0()}, V={"bus": V0}, z=law.states(omega0, SPEEDS0))
    return Setup(system, state, w, law, [bus])


def uk(w: WheelArray, *, motors: bool = True, omega0: Any = OMEGA0, **gains: float) -> Setup:
    """The Udwadia–Kalaba form: bus and wheel bodies, bearing constraints, WheelMotors
    driven by the same law's wheel_command (no motors: free wheels, all compiled)."""
    bus = gmuk.RigidBody("bus", MASS, w.uk_bus_inertia(I_B))
    wheel_bodies, constraints = w.uk_parts(bus)
    law = gmuk.MRPFeedback("bus", w, inertia_B=I_B, **{"K": 3.5, "P": 30.0, **gains})
    forces = [WheelMotors(bus, wheel_bodies, w, law.wheel_command)] if motors else []
    system = gmuk.System([bus, *wheel_bodies], constraints=constraints, forces=forces)
    V0 = np.r_[omega0, 0.0, 0.0, 0.0]
    g_w, V_w = w.uk_state(wheel_bodies, g0(), V0, SPEEDS0)
    state = system.state(g={"bus": g0(), **g_w}, V={"bus": V0, **V_w})
    return Setup(system, state, w, law, [bus, *wheel_bodies])


def momentum_N_internal(setup: Setup, traj: gmuk.Trajectory) -> np.ndarray:
    """H_N = R_NB (I_w ω + G h) (N·m·s) at every sample, (k, 3)."""
    b = traj.body("bus")
    I_w = setup.bodies[0].inertia
    n = len(setup.wheels)
    H_B = b.omega @ I_w.T + traj.z[:, :n] @ setup.wheels.G.T
    return np.einsum("kij,kj->ki", b.R, H_B)


def momentum_N_uk(setup: Setup, traj: gmuk.Trajectory) -> np.ndarray:
    """H_N = Σ R_NX J_X ω_X over the bus and wheel bodies (all at the origin, at rest)."""
    H = np.zeros((len(traj.t), 3))
    for body in setup.bodies:
        bt = traj.body(body.name)
        H += np.einsum("kij,kj->ki", bt.R, bt.omega @ body.inertia.T)
    return H


def uk_wheel_speeds(setup: Setup, traj: gmuk.Trajectory) -> np.ndarray:
    """Speeds (k, n) of the UK form's wheels relative to the bus (rad/s)."""
    bus = traj.body("bus")
    out = np.empty((len(traj.t), len(setup.wheels)))
    for i, body in enumerate(setup.bodies[1:]):
        wt = traj.body(body.name)
        axis_B = np.einsum("kji,kj->ki", bus.R, wt.R[:, :, 0])  # R_NBᵀ (R_NW e₁)
        out[:, i] = wt.omega[:, 0] - np.einsum("ki,ki->k", axis_B, bus.omega)
    return out
