"""The tennis-racket scenario: a torque-free body spun about its intermediate axis flips.

The tutorial's example of a scenario in a package of its own (``gmuk run tennis-racket``).
A rigid body with principal moments J₁ < J₂ < J₃ spun about axis 2 is unstable: a tiny
rate about the other axes grows, and the body turns over, again and again (the Dzhanibekov
effect). Nothing constrains it; the run checks that energy and angular momentum stay put.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import gmuk
from gmuk import plotting
from gmuk.dynamics import kinetic_energy, spatial_momentum
from gmuk.scenarios import Option, Scenario, ScenarioResult, positive_float

NAME = "tennis-racket"
DESCRIPTION = "torque-free body spun about its intermediate axis flips over (plugin tutorial)"
#: Principal moments of inertia (kg·m²), body frame.
MOMENTS = (1.0, 2.0, 3.0)


def run(duration: float = 60.0, spin: float = 1.0) -> ScenarioResult:
    """Spin about body axis 2 at ``spin`` rad/s, with 1e-3 of it about axes 1 and 3, for
    ``duration`` seconds."""
    body = gmuk.RigidBody("racket", mass=1.0, inertia=np.diag(MOMENTS))
    system = gmuk.System([body])
    V0 = [1e-3 * spin, spin, 1e-3 * spin, 0.0, 0.0, 0.0]  # [ω (rad/s); v (m/s)], body frame
    state = system.state(g={"racket": np.eye(4)}, V={"racket": V0})
    t = np.linspace(0.0, duration, int(40 * duration) + 1)
    traj = system.simulate(state, (0.0, duration), t_eval=t, rtol=1e-11, atol=1e-12)
    omega = traj.body("racket").omega
    I = system.mass_matrix
    E = kinetic_energy(traj.V_B[:, 0], I)
    h = spatial_momentum(traj.g_NB[:, 0], traj.V_B[:, 0], I)
    flips = int(np.count_nonzero(np.diff(np.sign(omega[:, 1])) != 0))
    summary = {
        "flips": flips,
        "energy_drift": float(np.abs(E / E[0] - 1).max()),
        "momentum_drift": float(np.abs(h - h[0]).max() / np.linalg.norm(h[0])),
    }
    return ScenarioResult(NAME, {NAME: traj}, NAME, summary)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """The body rates, which change sign at each flip."""
    traj = result.trajectories[NAME]
    return plotting.plot_components(
        traj.t,
        [("racket", traj.body("racket").omega)],
        ["ω1 (rad/s)", "ω2 (rad/s)", "ω3 (rad/s)"],
        "Body rates of a body spun about its intermediate axis",
        out / "body_rates",
        formats,
    )


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("duration", positive_float, 60.0, "simulated time (s)"),
        Option("spin", positive_float, 1.0, "initial spin about the intermediate axis (rad/s)"),
    ),
)
