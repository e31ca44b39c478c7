"""Minimum-effort station keeping of a low lunar orbit in the GRAIL field (GRGM660PRIM,
degree 20) by direct collocation (gmuk.optimize), then flown open loop by the simulator.
Needs ``pip install "gmuk[optimize]"``.

A 300 kg spacecraft starts on a circular polar orbit 100 km above the Moon's mean radius.
Left alone, the field's harmonics move it 2.7 km from where a Keplerian orbit would return it
after one period. The problem: return to the initial (inertial) state after exactly one
Keplerian period T, at least cost ∫|u|²/m dt (the default cost of OptimalControlProblem, the
L2 control effort; u the thrust in N). The starting guess is the uncontrolled Keplerian arc,
found by the same transcription with a point-mass field and a free final state. The
optimal thrust is then flown by System.simulate through ``result.controller()``, in the same
degree-20 field (the compiled kernel: the optimiser used the field's CasADi form), and the
two trajectories are compared at the nodes.

Run: python examples/optimal_lunar_correction.py   (docs/optimize_lunar.rst quotes its table;
``--timings`` adds the build times the page quotes)
"""

from __future__ import annotations

import sys
import time
from typing import Any

import numpy as np

import gmuk
from gmuk.optimize import Mesh, OptimalControlProblem
from gmuk.orbits import KeplerOrbit

MASS = 300.0  # kg
ALTITUDE = 100e3  # m above the mean radius (the field's reference radius, 1738 km)
DEGREE = 20  # of GRGM660PRIM
ELEMENTS = (20, 40, 80)  # the rows of the docs' table (LGL elements of degree 4)


def setting() -> tuple[gmuk.System, gmuk.State, KeplerOrbit]:
    """The System (one point mass in the degree-20 field of the rotating Moon), its initial
    State on the circular polar orbit (at the ascending node) and that orbit."""
    gravity = gmuk.SphericalHarmonicGravity("GRGM660PRIM", degree=DEGREE)
    moon = gravity.central_body
    orbit = KeplerOrbit.from_elements(moon.radius + ALTITUDE, 0.0, np.pi / 2, 0.0, 0.0, moon.mu)
    system = gmuk.System([gmuk.PointMass("craft", MASS)], forces=[gravity])
    r0, v0 = orbit.state(0.0)
    return system, system.state(r={"craft": r0}, v={"craft": v0}), orbit


def correction(elements: int, degree: int = 4) -> dict[str, Any]:
    """Solve the station-keeping problem on ``elements`` LGL elements of ``degree`` and fly
    its control: the figures of one row of the docs' table (SI units; times in s)."""
    system, start, orbit = setting()
    T = orbit.period
    r0, v0 = np.asarray(start.position("craft")), np.asarray(start.velocity("craft"))
    mesh = Mesh.uniform(0.0, T, elements, degree)
    # the guess: the Keplerian arc (point-mass field, zero control, final state free)
    kepler = gmuk.System([gmuk.PointMass("craft", MASS)], forces=[gmuk.PointMassGravity(orbit.mu)])
    arc = OptimalControlProblem(kepler, kepler.state(r={"craft": r0}, v={"craft": v0}), T)
    guess = arc.solve(mesh)

    tic = time.perf_counter()
    problem = OptimalControlProblem(
        system, start, T, final={"r": {"craft": r0}, "v": {"craft": v0}}
    )
    plan = problem.solve(mesh, guess=guess, tol=1e-9)
    solve_s = time.perf_counter() - tic
    thrust = np.linalg.norm(plan.u, axis=1)  # N, at the nodes

    # fly the planned thrust open loop in the same field (the compiled kernel). The control
    # is a polynomial per element, its derivatives jump at the elements' ends: steps of at
    # most an eighth of an element keep DOP853's error at a micrometre there (unbounded
    # steps across those ends left up to 0.2 mm)
    flown = gmuk.System(
        list(system.bodies), forces=list(system.forces), controllers=[plan.controller()]
    )
    step = T / elements / 8
    traj = flown.simulate(start, (0.0, T), t_eval=plan.t, rtol=1e-13, atol=1e-9, max_step=step)
    finer = flown.simulate(start, (0.0, T), t_eval=plan.t, rtol=1e-13, atol=1e-9, max_step=step / 2)
    unbounded = flown.simulate(start, (0.0, T), t_eval=plan.t, rtol=1e-13, atol=1e-9)
    free = system.simulate(start, (0.0, T), t_eval=[T], rtol=1e-13, atol=1e-9)
    position_gap = np.linalg.norm(traj.r_N[:, 0] - plan.r_N[:, 0], axis=1)
    velocity_gap = np.linalg.norm(traj.v_N[:, 0] - plan.v_N[:, 0], axis=1)
    return {
        "elements": elements,
        "nodes": mesh.n_nodes,
        "period_s": T,
        "status": plan.status,
        "iterations": plan.iterations,
        "guess_iterations": guess.iterations,
        "objective": plan.objective,  # ∫|u|²/m dt, N²·s/kg
        "delta_v_m_s": float(mesh.quadrature_weights @ thrust) / MASS,  # ∫|u|/m dt
        "peak_thrust_N": float(thrust.max()),
        "free_miss_m": float(np.linalg.norm(free.r_N[-1, 0] - r0)),
        "flown_vs_plan_m": float(position_gap.max()),
        "flown_vs_plan_m_s": float(velocity_gap.max()),
        "flown_final_miss_m": float(np.linalg.norm(traj.r_N[-1, 0] - r0)),
        # the integration error of the flown trajectory: halving the step bound, and without
        "halved_steps_m": float(np.abs(finer.r_N - traj.r_N).max()),
        "unbounded_steps_m": float(np.abs(unbounded.r_N - traj.r_N).max()),
        "transcription_s": plan.timings["transcription_s"],
        "solve_s": solve_s,
    }


def rows(elements: tuple[int, ...] = ELEMENTS) -> list[dict[str, Any]]:
    """:func:`correction` on each number of ``elements`` (the docs' table)."""
    return [correction(n) for n in elements]


def build_times(elements: tuple[int, ...] = (40, 160)) -> dict[str, float]:
    """Wall times (s) of building the symbolic field and the NLP: the degree-20 (and 150)
    field's CasADi Function, five ``casadi_force`` calls (one element of degree 4) with it built,
    the transcription of :func:`correction`'s problem (NLP and IPOPT set-up) with the
    degree-20 field and with a point-mass one, and of a 600 s rigid-body arc (500 kg) with
    and without the finite-size force, on 40 elements."""
    import casadi as ca

    from gmuk.gravity import _symbolic

    system, start, orbit = setting()
    gravity = system.forces[0]
    out: dict[str, float] = {}
    _symbolic._CACHE.clear()
    tic = time.perf_counter()
    _symbolic.acceleration_function(gravity.field)
    out["field_function_s"] = time.perf_counter() - tic
    tic = time.perf_counter()
    _symbolic.acceleration_function(gmuk.gravity.load("GRGM660PRIM", 150))
    out["field_function_150_s"] = time.perf_counter() - tic
    t, r = ca.SX.sym("t", 5), ca.SX.sym("r", 3, 5)
    craft = system.bodies[0]
    tic = time.perf_counter()
    forces = [gravity.casadi_force(t[j], r[:, j], None, craft) for j in range(5)]
    ca.Function("element", [t, r], [ca.horzcat(*forces)])
    out["five_nodes_s"] = time.perf_counter() - tic
    T = orbit.period
    r0, v0 = np.asarray(start.position("craft")), np.asarray(start.velocity("craft"))
    final = {"r": {"craft": r0}, "v": {"craft": v0}}
    for name, field in (("degree_20", gravity), ("point_mass", gmuk.PointMassGravity(orbit.mu))):
        s = gmuk.System([gmuk.PointMass("craft", MASS)], forces=[field])
        problem = OptimalControlProblem(
            s, s.state(r={"craft": r0}, v={"craft": v0}), T, final=final
        )
        for n in elements:
            tic = time.perf_counter()
            problem.transcribe(Mesh.uniform(0.0, T, n, 4))
            out[f"{name}_{n}_transcription_s"] = time.perf_counter() - tic
    for finite in (False, True):
        field = gmuk.SphericalHarmonicGravity(
            "GRGM660PRIM", degree=DEGREE, finite_size_force=finite
        )
        sat = gmuk.RigidBody("sat", 500.0, np.diag([100.0, 150.0, 200.0]))
        s = gmuk.System([sat], forces=[field])
        g0 = np.eye(4)
        g0[:3, 3] = r0
        state = s.state(g={"sat": g0}, V={"sat": np.r_[0.0, 0.0, 0.0, v0]})
        tic = time.perf_counter()
        OptimalControlProblem(s, state, 600.0).transcribe(Mesh.uniform(0.0, 600.0, 40, 4))
        out[f"rigid_{'finite' if finite else 'no_finite'}_transcription_s"] = (
            time.perf_counter() - tic
        )
    return out


def main(timings: bool = False) -> dict[str, Any]:
    """Print the table (and, with ``timings``, :func:`build_times`); return the 40-element
    row."""
    tic = time.perf_counter()
    table = rows()
    print(f"GRGM660PRIM degree {DEGREE}, 100 km polar orbit, T = {table[0]['period_s']:.1f} s")
    print(f"uncontrolled, it ends {table[0]['free_miss_m']:.1f} m from its start after T")
    print(
        "elements  nodes  IPOPT it.  objective (N²·s/kg)  ΔV (m/s)  peak |u| (N)  "
        "flown vs plan (m)  solve (s)"
    )
    for r in table:
        print(
            f"{r['elements']:8d} {r['nodes']:6d} {r['iterations']:10d} {r['objective']:20.10e}"
            f" {r['delta_v_m_s']:9.6f} {r['peak_thrust_N']:13.6f} {r['flown_vs_plan_m']:18.2e}"
            f" {r['solve_s']:10.2f}"
        )
    print(f"total {time.perf_counter() - tic:.1f} s")
    if timings:
        for key, value in build_times().items():
            print(f"{key:>34}: {value:.3f} s")
    return next(r for r in table if r["elements"] == 40)


if __name__ == "__main__":
    main(timings="--timings" in sys.argv[1:])
