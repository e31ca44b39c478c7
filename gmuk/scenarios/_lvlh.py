"""Shared set-up of the Chapter 4 scenarios (McCann 2020, Sections 4.1.2–4.3).

The spacecraft has the mass properties printed in Section 3.4; the central body is the Moon
with μ = 4.9048695e12 m³/s² (the value that makes Section 4.3's printed initial condition
consistent, docs/errata.rst); the force model is the uniform-field gravity gradient (Eq. 23). The
initial state is the reference's own at periselene (t = 0), computed from Eqs. 69–71 as
corrected (it reproduces the printed numbers to all their digits with this μ).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.celestial import MOON_RADIUS
from gmuk.errors import DefinitionError
from gmuk.lie import se3
from gmuk.orbits import MU_MOON_THESIS_CONSISTENT, KeplerOrbit, LVLHReference
from gmuk.scenarios import Option, ScenarioResult, positive_float
from gmuk.trajectory import Trajectory

#: Mass (kg) and central inertia (kg·m², body frame) of McCann (2020), Section 3.4.
LM_MASS = 7063.0
LM_INERTIA = np.array(
    [
        [17058.9014, 246.758867, 752.478961],
        [246.758867, 18801.1275, 100.330528],
        [752.478961, 100.330528, 21969.674],
    ]
)
MU = MU_MOON_THESIS_CONSISTENT
#: Radius of the Moon (m), the central body of every orbit scenario (drawn by the 3-D views).
CENTRAL_RADIUS = MOON_RADIUS
#: Integration tolerances for every Chapter 4 scenario: tight enough that FCEI's position error
#: over one orbit stays well below the 1e-6 m target (rtol 1e-13 comes too close to it; the
#: figures and the command that measures them are in docs/scenarios/chapter4.rst and
#: benchmarks/README.md).
RTOL, ATOL = 3e-15, 1e-12
SAMPLES_PER_ORBIT = 721
#: Natural frequency (rad/s) of the Baumgarte terms that keep the R⁶ tracking constraints on
#: the reference over long runs. Unstabilised, FCEI's attitude error grows like e^{2.8 per
#: orbit} (≈ e^{t/8000 s}: the LVLH attitude of this spacecraft is an unstable equilibrium of
#: its constrained error dynamics) from round-off, 6e-14 rad after one orbit, 2e-8 after three,
#: π rad by the sixth. Critical gains at ω_n = 1e-3 s⁻¹ (α = 2e-3 s⁻¹, β = 1e-6 s⁻²) damp
#: errors eight times faster than that growth and stay 2–4 times above the reference's turn
#: rate (2.8e-4 to 4.5e-4 rad/s), below which Baumgarte terms acting in the body frame couple
#: the axes (:class:`gmuk.ConfigurationTracking`). Stiffer gains cost steps without gain: at
#: rtol 3e-15 the terms feed the round-off of the errors back into the accelerations, so the
#: step count grows with ω_n (12 orbits: 1635 steps unstabilised, 4153 at 1e-3, 15 010 at
#: 3e-3, 75 008 at 1e-2). docs/scenarios/chapter4.rst gives the figures.
TRACKING_BAUMGARTE = gmuk.Baumgarte.critical(1e-3)
#: The velocity-level gain α (1/s) of the virtual pair's relative constraint, the same rate.
RELATIVE_BAUMGARTE = gmuk.Baumgarte(alpha=2e-3)
#: The one option of every Chapter 4 scenario.
ORBITS = Option(
    "orbits", positive_float, 1.0, "orbits to simulate, in periods of the reference orbit"
)


def spacecraft(name: str = "spacecraft") -> gmuk.RigidBody:
    """A rigid body with the Section 3.4 mass properties."""
    return gmuk.RigidBody(name, LM_MASS, LM_INERTIA)


#: The most output times a scenario run writes (8 bytes each per stored quantity).
MAX_OUTPUT_TIMES = 10_000_000


def output_count(orbits: float, per_orbit: int) -> int:
    """``max(2, round(per_orbit · orbits))`` output times, refused beyond MAX_OUTPUT_TIMES
    (a span of, say, 1e300 orbits is a typo, not a run)."""
    n = per_orbit * orbits
    if not n <= MAX_OUTPUT_TIMES:
        raise DefinitionError(
            f"orbits = {orbits!r} asks for {n:.3g} output times ({per_orbit} per orbit); at most "
            f"{MAX_OUTPUT_TIMES:.0e} ({MAX_OUTPUT_TIMES / per_orbit:.6g} orbits) are written"
        )
    return max(2, round(n))


def time_grid(orbit: KeplerOrbit, orbits: float) -> FloatArray:
    """Output times (s from periselene): SAMPLES_PER_ORBIT per orbit, both ends included."""
    return np.linspace(0.0, orbits * orbit.period, output_count(orbits, SAMPLES_PER_ORBIT))


def fully_constrained(
    orbit: KeplerOrbit,
    orbits: float,
    *,
    tangent: bool = False,
    baumgarte: gmuk.Baumgarte | None = TRACKING_BAUMGARTE,
) -> Trajectory:
    """One spacecraft tracking the modified-LVLH reference: R⁶ (Eq. 67) or, with ``tangent``,
    T²SE(3) (Eq. 79, A = B = I₄), with ``baumgarte`` terms (:data:`TRACKING_BAUMGARTE` by
    default; None for the thesis's bare rows). On T²SE(3) the terms are those of the
    stabilised :class:`gmuk.ConfigurationTrackingT2`, ``C = g̈_d − α (ġ − ġ_d) − β (g − g_d)``
    (A and B unchanged)."""
    sc = spacecraft()
    ref = LVLHReference(orbit)
    con: gmuk.Constraint = (
        gmuk.ConfigurationTrackingT2(sc, ref, baumgarte=baumgarte)
        if tangent
        else gmuk.ConfigurationTracking(sc, ref, baumgarte=baumgarte)
    )
    system = gmuk.System([sc], [con], [gmuk.GravityGradient(orbit.mu)])
    r0 = ref.evaluate(0.0)
    state = system.state(g={sc.name: r0.g}, V={sc.name: r0.V})
    t = time_grid(orbit, orbits)
    return system.simulate(state, (0.0, t[-1]), t_eval=t, rtol=RTOL, atol=ATOL)


def virtual_pair(
    orbit: KeplerOrbit, orbits: float, torque: Callable[[float], Any] | None = None
) -> Trajectory:
    """The under-constrained pair of Section 4.1.3: "virtual" tracks the reference, and
    "spacecraft" is held to it in five relative directions, free to roll about axis 1.
    Stabilised as :func:`fully_constrained` (:data:`TRACKING_BAUMGARTE` on the tracking,
    :data:`RELATIVE_BAUMGARTE` on the relative twist)."""
    virtual, sc = spacecraft("virtual"), spacecraft()
    ref = LVLHReference(orbit)
    forces: list[gmuk.ForceModel] = [gmuk.GravityGradient(orbit.mu)]
    if torque is not None:
        forces.append(gmuk.AppliedWrench(sc, torque))
    system = gmuk.System(
        [virtual, sc],
        [
            gmuk.ConfigurationTracking(virtual, ref, baumgarte=TRACKING_BAUMGARTE),
            gmuk.RelativeConstraint(sc, virtual, free_axes=[0], baumgarte=RELATIVE_BAUMGARTE),
        ],
        forces,
    )
    r0 = ref.evaluate(0.0)
    state = system.state(
        g={"virtual": r0.g, "spacecraft": r0.g}, V={"virtual": r0.V, "spacecraft": r0.V}
    )
    t = time_grid(orbit, orbits)
    return system.simulate(state, (0.0, t[-1]), t_eval=t, rtol=RTOL, atol=ATOL)


def reference_errors(
    traj: Trajectory, orbit: KeplerOrbit, body: str = "spacecraft"
) -> tuple[FloatArray, FloatArray]:
    """Position error (m) against the analytic Kepler orbit and attitude error (rad) against
    the reference attitude, at every output time."""
    ref = LVLHReference(orbit).evaluate_many(traj.t)
    view = traj.body(body)
    pos = np.linalg.norm(view.position - ref.g[:, :3, 3], axis=1)
    R_err = np.swapaxes(ref.g[:, :3, :3], 1, 2) @ view.R
    att = np.linalg.norm(gmuk.lie.so3.log(R_err), axis=1)
    return pos, att


def relative_pose(
    traj: Trajectory, body: str = "spacecraft", relative_to: str = "virtual"
) -> FloatArray:
    """log(g_L⁻¹ g_B) (N, 6): [rotation (rad); translation (m)] of B relative to L."""
    g_L = traj.g_NB[:, traj.body_names.index(relative_to)]
    g_B = traj.g_NB[:, traj.body_names.index(body)]
    return se3.log(se3.inverse(g_L) @ g_B)


def nominal_constraint_wrench(orbit: KeplerOrbit, t: FloatArray) -> FloatArray:
    """Constraint wrench [L; f] (N, 6) (body frame) of the fully constrained spacecraft
    evaluated *on* the reference states: what the constraint must supply on the constraint
    manifold, free of integration error.

    Its translational part is only the finite-size term of Eq. 23b (~5e-10 N on FCEI), the
    remainder of gravity terms of ~3e3 N that cancel, so its relative shape is resolved only to
    round-off (the summary's ``max_constraint_force_deviation_from_nominal_N`` gives how far
    the simulated force is from it: ~1e-10 N on FCEI).
    """
    sc = spacecraft()
    ref = LVLHReference(orbit)
    system = gmuk.System(
        [sc], [gmuk.ConfigurationTracking(sc, ref)], [gmuk.GravityGradient(orbit.mu)]
    )
    out = np.empty((len(t), 6))
    for k, tk in enumerate(t):
        r = ref.evaluate(float(tk))
        out[k] = system.accelerations(
            system.state(g={sc.name: r.g}, V={sc.name: r.V}, t=float(tk))
        ).constraint_force
    return out


def fully_constrained_summary(traj: Trajectory, orbit: KeplerOrbit) -> dict[str, Any]:
    """Headline figures of a fully constrained run (acceptance of issue #5)."""
    pos, att = reference_errors(traj, orbit)
    view = traj.body("spacecraft")
    nominal = nominal_constraint_wrench(orbit, traj.t)
    f_c = np.linalg.norm(nominal[:, 3:], axis=1)
    i_min = int(np.argmin(f_c))
    sim = np.linalg.norm(view.constraint_force[:, 3:], axis=1)
    return {
        "max_position_error_m": float(pos.max()),
        "max_attitude_error_rad": float(att.max()),
        "max_abs_omega1_omega2_rad_s": float(np.abs(view.omega[:, :2]).max()),
        "nominal_translational_constraint_force_min_N": float(f_c[i_min]),
        "nominal_translational_constraint_force_max_N": float(f_c.max()),
        "time_of_min_nominal_constraint_force_s": float(traj.t[i_min]),
        # Eq. 23b's finite-size force ∝ |r|⁻⁴ with r̂ fixed in the LVLH body frame:
        "nominal_force_r4_law_max_relative_deviation": float(
            np.abs(
                f_c
                * np.linalg.norm(view.position, axis=1) ** 4
                / np.mean(f_c * np.linalg.norm(view.position, axis=1) ** 4)
                - 1.0
            ).max()
        ),
        "simulated_translational_constraint_force_max_N": float(sim.max()),
        "max_constraint_force_deviation_from_nominal_N": float(
            np.linalg.norm(view.constraint_force[:, 3:] - nominal[:, 3:], axis=1).max()
        ),
        "max_constraint_torque_deviation_from_nominal_N_m": float(
            np.abs(view.constraint_force[:, :3] - nominal[:, :3]).max()
        ),
        "max_constraint_torque_N_m": float(np.abs(nominal[:, :3]).max()),
        "aposelene_time_s": float(orbit.period / 2),
        "rhs_evaluations": int(traj.stats["n_rhs"]),
        "steps": int(traj.stats["n_steps"]),
    }


def figures_for(
    result: ScenarioResult,
    out: Path,
    formats: Sequence[str],
    comparisons: Sequence[tuple[str, str, bool]] = (),
) -> list[Path]:
    """The thesis figure groups of the primary run, and for each (a, b, difference) in
    ``comparisons`` the difference a − b (or both overlaid) of the spacecraft, and the 3-D
    orbit with attitude triads (``orbit_3d``)."""
    trajs = result.trajectories
    paths = plotting.plot_body(
        trajs[result.primary], "spacecraft", out, formats, label=result.primary.upper()
    )
    paths += orbit_figure(result, "spacecraft", out, formats)
    for a, b, difference in comparisons:
        paths += plotting.compare_body(
            trajs[a],
            trajs[b],
            "spacecraft",
            out / f"{a}_vs_{b}",
            formats,
            labels=(a.upper(), b.upper()),
            difference=difference,
        )
    return paths


def orbit_figure(
    result: ScenarioResult, body: str, out: Path, formats: Sequence[str]
) -> list[Path]:
    """``orbit_3d``: the primary run's orbit of ``body`` about the Moon, in 3-D, with its
    attitude triads at eight instants (:func:`gmuk.plotting.plot_orbit_3d`)."""
    return plotting.plot_orbit_3d(
        result.trajectories[result.primary],
        body,
        out / "orbit_3d",
        formats,
        central_radius=CENTRAL_RADIUS,
        title=f"{result.name.upper()}: orbit and attitude triads (N frame)",
    )
