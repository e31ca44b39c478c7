"""One FCEI orbit: gmuk's Lie-group DOP853 against scipy's solve_ivp(DOP853) on a flattened
state, at equal accuracy (position error against the analytic Kepler orbit).

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_fcei.py

The flattened problem integrates y = [R (9), r (3), V (6)] with Ṙ = R ω^, ṙ = R v and
V̇ from the same System.accelerations; R is re-orthonormalised (polar projection) before
each evaluation. For each method the script scans tolerances and reports the cheapest run
whose maximum position error over the orbit is ≤ 1e-6 m (issue #5).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import time

import numpy as np
from scipy.integrate import solve_ivp

import gmuk
from gmuk.lie import so3
from gmuk.orbits import LVLHReference, fcei_orbit
from gmuk.scenarios import _lvlh as common

TARGET = 1e-6  # m


def setup():
    orbit = fcei_orbit(common.MU)
    sc = common.spacecraft()
    ref = LVLHReference(orbit)
    system = gmuk.System(
        [sc], [gmuk.ConfigurationTracking(sc, ref)], [gmuk.GravityGradient(orbit.mu)]
    )
    r0 = ref.evaluate(0.0)
    return orbit, ref, system, system.state(g={sc.name: r0.g}, V={sc.name: r0.V})


def gmuk_run(system, state, orbit, ref, rtol, dense):
    t = np.linspace(0.0, orbit.period, 721) if dense else None
    t0 = time.perf_counter()
    traj = system.simulate(state, (0.0, orbit.period), t_eval=t, rtol=rtol, atol=1e-12)
    wall = time.perf_counter() - t0
    err = np.linalg.norm(traj.g_NB[:, 0, :3, 3] - ref.evaluate_many(traj.t).g[:, :3, 3], axis=1)
    return err.max(), traj.stats["n_rhs"], wall


def scipy_run(system, state, orbit, ref, rtol, dense):
    layout = system.layout

    def rhs(t, y):
        R = y[:9].reshape(3, 3)
        U, _, Vt = np.linalg.svd(R)
        R = U @ Vt  # polar projection onto SO(3)
        g = np.eye(4)
        g[:3, :3], g[:3, 3] = R, y[9:12]
        V = y[12:]
        st = gmuk.State(t, g[None], V[None].copy(), np.zeros(0), np.zeros(0), np.zeros(0), layout)
        acc = system.accelerations(st).total
        return np.concatenate([(R @ so3.hat(V[:3])).ravel(), R @ V[3:], acc])

    y0 = np.concatenate([state.g[0, :3, :3].ravel(), state.g[0, :3, 3], state.V[0]])
    t = np.linspace(0.0, orbit.period, 721) if dense else None
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, orbit.period), y0, method="DOP853", t_eval=t, rtol=rtol, atol=1e-12)
    wall = time.perf_counter() - t0
    err = np.linalg.norm(sol.y[9:12].T - ref.evaluate_many(sol.t).g[:, :3, 3], axis=1)
    return err.max(), sol.nfev, wall


def main() -> None:
    gmuk.compile_loop()  # timings of the compiled loop, not of its one-time compilation
    orbit, ref, system, state = setup()
    best = {}
    for dense in (False, True):
        where = "721 dense outputs" if dense else "the integrator's own steps"
        print(f"\nPosition error measured at {where}:\n")
        print("| method | rtol | max position error (m) | RHS evaluations | wall (s) |")
        print("|---|---:|---:|---:|---:|")
        for label, fn in (("gmuk RKMK-DOP853", gmuk_run), ("scipy DOP853, flattened", scipy_run)):
            for rtol in (1e-12, 1e-13, 5e-14, 1e-14, 3e-15):
                err, nfev, wall = fn(system, state, orbit, ref, rtol, dense)
                print(f"| {label} | {rtol:g} | {err:.2e} | {nfev} | {wall:.2f} |")
                if err <= TARGET and (label, dense) not in best:
                    best[label, dense] = (rtol, err, nfev, wall)
    print()
    for (label, dense), (rtol, err, nfev, wall) in best.items():
        print(
            f"cheapest with error ≤ {TARGET:g} m ({'dense' if dense else 'at steps'}) — "
            f"{label}: rtol {rtol:g}, error {err:.2e} m, {nfev} RHS evaluations, "
            f"{wall:.2f} s"
        )


if __name__ == "__main__":
    main()
