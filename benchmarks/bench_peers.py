"""Whole-run propagation: gmuk beside Basilisk, same physics, same initial state, same run.

Run on demand (not a test; Basilisk is a benchmark-only peer, never a gmuk dependency):

    python benchmarks/bench_peers.py [--quick] [--repeat N] [--show-scan]

The script sets OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1 itself, before numpy is
imported. ``--quick`` skips the degree-150 case and times 3 rounds instead of 7.

Orbit (all cases): r0 = (1838 km, 0, 0), circular speed for an orbit inclined 80°,
v0 = √(μ/r0) (0, cos 80°, sin 80°), propagated for 7200 s (about one revolution), μ the
GM of GRGM660PRIM (4.9028e12 m³/s²) in every case. The Moon does not rotate in either
library: gmuk's central body carries ``gmuk.INERTIAL``; Basilisk without SPICE (no
planet-orientation message) keeps the planet frame equal to N (it warns that it does so
for an orientation-dependent field; the warning is silenced here).

Cases:

1. a 300 kg point mass in GRGM660PRIM truncated to degree 50, adaptive integrators:
   gmuk DOP853 on ``SphericalHarmonicGravity``; Basilisk ``spacecraft.Spacecraft`` with the
   same coefficients (written to a temporary JPL-format CSV for ``loadGravFromFile``) and
   ``svIntegratorRKF78``;
2. the same at degree 150;
3. the same as 1 with fixed-step RK4 at 5 s in both (Basilisk: its RK4 integrator and a
   5 s task);
4. a 500 kg rigid body, J = diag(100, 200, 300) kg·m², initial attitude identity, body rate
   (0.001, 0.002, 0.003) rad/s, point-mass Moon plus gravity-gradient torque, adaptive:
   gmuk ``GravityGradient`` (McCann 2020 Eq. 23: the torque and a force that includes the
   second-order finite-size term); Basilisk a hub with that mass and inertia, a point-mass
   Moon and ``GravityGradientEffector`` (the torque only; the force stays point-mass).

Equal accuracy. Each library gets one tolerance number ``tol`` for every state:
gmuk ``rtol = atol = tol``; Basilisk ``relTol = absTol = tol``. Both weigh the local error
estimate of each 3-vector of the state against ``atol + rtol·‖u‖``. Each library's
reference is its own run at a tight tolerance (gmuk 1e-15, Basilisk 1e-17: Basilisk's
RKF78 needs the smaller number to converge at degree 150; each reference's change from a
3× looser run is printed).
On the grid 1e-8, 3.2e-9, …, 1e-14 the chosen tolerance is the loosest one that, together
with every tighter grid value, ends within 1 mm of the library's own reference (and, for
case 4, within 1e-8 rad in attitude). The two references are compared with each other:
that is the "agreement" column. Basilisk's adaptive integrator restarts at every task
step with the task step as its first trial, so the adaptive runs use a 1800 s task
(a quarter revolution, far above the steps the tolerances allow; with a 3600 s or 7200 s
task, case 4's first trial step yields NaN, which Basilisk's step control does not recover
from: the run ends with a NaN state).

Timing: wall time of the propagation call only — gmuk ``System.simulate`` with output at
the final time only (``t_eval=[7200]``), Basilisk ``ExecuteSimulation`` (no loggers) —
with the System, the state, the Basilisk simulation, its integrator and its
``InitializeSimulation`` built outside the timing. After one untimed warm-up run each,
the two libraries run alternately (gmuk first in even rounds, Basilisk first in odd ones)
and each figure is the median over the rounds. gmuk's RHS count is
``Trajectory.stats["n_rhs"]``; Basilisk does not expose its count (its RK4 makes 4 per
step: 5760 in case 3).
"""

from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import math
import platform
import statistics
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np
from Basilisk import __version__ as BSK_VERSION
from Basilisk.architecture import bskLogging
from Basilisk.simulation import GravityGradientEffector, spacecraft, svIntegrators
from Basilisk.simulation.sphericalHarmonicsGravityModel import SphericalHarmonicsGravityModel
from Basilisk.utilities import (
    RigidBodyKinematics,
    SimulationBaseClass,
    macros,
    simIncludeGravBody,
)

import gmuk
from gmuk.forces.base import ForceModel

T_END = 7200.0  # s
R0 = 1838e3  # m
INCLINATION = math.radians(80.0)
SC_MASS = 300.0  # kg, point mass of cases 1-3
RB_MASS = 500.0  # kg, rigid body of case 4
RB_INERTIA = np.diag([100.0, 200.0, 300.0])  # kg·m²
RB_RATE = np.array([0.001, 0.002, 0.003])  # rad/s, body frame
RK4_STEP = 5.0  # s
BSK_TASK = 1800.0  # s, Basilisk task step of the adaptive runs
TOLS = tuple(10.0 ** (-k / 2) for k in range(16, 29))  # 1e-8, 3.2e-9, …, 1e-14
REF_TOL = {"gmuk": 1e-15, "Basilisk": 1e-17}
POS_TARGET = 1e-3  # m
ATT_TARGET = 1e-8  # rad
LIBS = ("gmuk", "Basilisk")


@dataclass(frozen=True)
class Case:
    label: str
    degree: int | None  # None: point-mass Moon + gravity gradient on a rigid body
    fixed_step: bool = False


@dataclass
class Run:
    r: np.ndarray  # final position in N (m)
    R: np.ndarray | None  # final R_NB (rigid body), else None
    seconds: float
    n_rhs: int | None  # gmuk only


def initial_state(mu: float) -> tuple[np.ndarray, np.ndarray]:
    r0 = np.array([R0, 0.0, 0.0])
    v0 = math.sqrt(mu / R0) * np.array([0.0, math.cos(INCLINATION), math.sin(INCLINATION)])
    return r0, v0


def rotation_angle(A: np.ndarray, B: np.ndarray) -> float:
    """Angle (rad) of the rotation AᵀB, accurate when small: ‖A − B‖_F = 2√2 sin(θ/2)."""
    return 2.0 * math.asin(min(1.0, float(np.linalg.norm(A - B)) / (2.0 * math.sqrt(2.0))))


# ---------------------------------------------------------------------------- gmuk side


class PointForceGradientTorque(ForceModel):
    """Basilisk's rigid-body model in gmuk: point-mass force, gravity-gradient torque
    (Eq. 23a) — gmuk.GravityGradient without the finite-size force term. Used only to
    attribute the case-4 difference between the libraries; never timed."""

    def __init__(self, mu: float) -> None:
        super().__init__()
        self.mu = float(mu)

    def wrench(self, t, g_NB, V_B, body):  # type: ignore[no-untyped-def]
        r_B = g_NB[:3, :3].T @ g_NB[:3, 3]
        rn = float(np.linalg.norm(r_B))
        torque = 3.0 * self.mu / rn**5 * np.cross(r_B, body.inertia @ r_B)
        return np.concatenate([torque, -self.mu * body.mass / rn**3 * r_B])


def gmuk_problem(
    case: Case, field: gmuk.SphericalHarmonicField, torque_only: bool = False
) -> tuple[gmuk.System, gmuk.State]:
    r0, v0 = initial_state(field.mu)
    if case.degree is not None:
        moon = gmuk.CelestialBody.moon(field=field, rotation=gmuk.INERTIAL)
        system = gmuk.System(
            [gmuk.PointMass("sc", SC_MASS)], [], [gmuk.SphericalHarmonicGravity(moon)]
        )
        return system, system.state(r={"sc": r0}, v={"sc": v0})
    model = PointForceGradientTorque(field.mu) if torque_only else gmuk.GravityGradient(field.mu)
    system = gmuk.System([gmuk.RigidBody("sc", RB_MASS, RB_INERTIA)], [], [model])
    g0 = np.eye(4)
    g0[:3, 3] = r0
    # body twist [ω; v_B], v_B = R_NBᵀ v_N = v_N at the identity attitude
    return system, system.state(g={"sc": g0}, V={"sc": np.concatenate([RB_RATE, v0])})


def run_gmuk(system: gmuk.System, state: gmuk.State, tol: float | None) -> Run:
    """tol None: fixed-step RK4 at RK4_STEP; else DOP853 with rtol = atol = tol."""
    options = {"method": "RK4", "step": RK4_STEP} if tol is None else {"rtol": tol, "atol": tol}
    t0 = time.perf_counter()
    traj = system.simulate(state, (0.0, T_END), t_eval=[T_END], **options)
    seconds = time.perf_counter() - t0
    if not traj.success:
        raise RuntimeError(f"gmuk run failed: {traj.message}")
    if traj.g_NB.shape[1]:
        g = traj.g_NB[-1, 0]
        return Run(g[:3, 3].copy(), g[:3, :3].copy(), seconds, traj.stats["n_rhs"])
    return Run(traj.r_N[-1, 0].copy(), None, seconds, traj.stats["n_rhs"])


# ------------------------------------------------------------------------- Basilisk side


def write_jpl_csv(field: gmuk.SphericalHarmonicField, path: Path) -> Path:
    """The field in the JPL CSV layout Basilisk's loadGravFromFileToList reads: a header
    row (radius, μ, σ_μ, max degree, max order, normalised flag 1, ref. longitude 0,
    ref. latitude 0), then one row per (n, m): n, m, C̄, S̄, σ_C, σ_S."""
    N = field.degree
    lines = [f"{field.radius:.17g},{field.mu:.17g},0.0,{N},{N},1,0.0,0.0"]
    for n in range(N + 1):
        for m in range(n + 1):
            lines.append(f"{n},{m},{float(field.C[n, m]):.17g},{float(field.S[n, m]):.17g},0,0")
    path.write_text("\n".join(lines) + "\n")
    return path


def field_agreement(field: gmuk.SphericalHarmonicField, csv: Path, n: int = 20) -> float:
    """Largest relative difference of the two libraries' accelerations, 50-500 km up."""
    model = SphericalHarmonicsGravityModel().loadFromFile(str(csv), field.degree)
    model.initializeParameters()
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(n):
        u = rng.normal(size=3)
        p = u / np.linalg.norm(u) * (field.radius + rng.uniform(50e3, 500e3))
        a_bsk = np.asarray(model.computeField(p.tolist()), dtype=float).reshape(3)
        a_gmuk = field.acceleration(p)
        worst = max(worst, float(np.linalg.norm(a_bsk - a_gmuk) / np.linalg.norm(a_gmuk)))
    return worst


def bsk_problem(case: Case, field: gmuk.SphericalHarmonicField, csv: Path | None, tol):
    """A Basilisk simulation ready to execute (set-up and InitializeSimulation done)."""
    r0, v0 = initial_state(field.mu)
    task = RK4_STEP if case.fixed_step else BSK_TASK
    sim = SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("dynamics").addTask(sim.CreateNewTask("task", macros.sec2nano(task)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "sc"
    sim.AddModelToTask("task", sc)
    factory = simIncludeGravBody.gravBodyFactory()
    moon = factory.createCustomGravObject("moon", field.mu, radEquator=field.radius)
    moon.isCentralBody = True
    if case.degree is not None:
        sc.hub.mHub = SC_MASS
        moon.useSphericalHarmonicsGravityModel(str(csv), case.degree)
    else:
        sc.hub.mHub = RB_MASS
        sc.hub.IHubPntBc_B = RB_INERTIA.tolist()
        sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
        sc.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
        sc.hub.omega_BN_BInit = RB_RATE.reshape(3, 1).tolist()
    factory.addBodiesTo(sc)
    extras = [factory, moon]
    if case.degree is None:
        gg = GravityGradientEffector.GravityGradientEffector()
        gg.ModelTag = "gravityGradient"
        gg.addPlanetName(moon.planetName)
        sc.addDynamicEffector(gg)
        sim.AddModelToTask("task", gg)
        extras.append(gg)
    sc.hub.r_CN_NInit = r0.tolist()
    sc.hub.v_CN_NInit = v0.tolist()
    if tol is None:
        integrator = svIntegrators.svIntegratorRK4(sc)
    else:
        integrator = svIntegrators.svIntegratorRKF78(sc)
        integrator.relTol = tol
        integrator.absTol = tol
    sc.setIntegrator(integrator)
    extras.append(integrator)  # keep the SWIG objects alive as long as the simulation
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(T_END))
    return sim, sc, extras


def run_bsk(case: Case, field: gmuk.SphericalHarmonicField, csv: Path | None, tol) -> Run:
    sim, sc, _keep = bsk_problem(case, field, csv, tol)
    t0 = time.perf_counter()
    sim.ExecuteSimulation()
    seconds = time.perf_counter() - t0
    out = sc.scStateOutMsg.read()
    r = np.array(out.r_BN_N, dtype=float)
    if not np.isfinite(r).all():
        raise RuntimeError(f"Basilisk run returned {r} ({case.label}, tol {tol})")
    R = None
    if case.degree is None:
        R = np.asarray(RigidBodyKinematics.MRP2C(np.array(out.sigma_BN)), dtype=float).T
    return Run(r, R, seconds, None)


# ----------------------------------------------------------------------------- driver


def errors(run: Run, ref: Run) -> tuple[float, float]:
    dr = float(np.linalg.norm(run.r - ref.r))
    da = rotation_angle(run.R, ref.R) if run.R is not None and ref.R is not None else 0.0
    return dr, da


def passes(run: Run, ref: Run) -> bool:
    dr, da = errors(run, ref)
    return dr <= POS_TARGET and da <= ATT_TARGET


def choose_tolerance(runs: dict[float, Run], ref: Run) -> tuple[float, bool]:
    """The loosest grid tolerance that passes together with every tighter one."""
    chosen, ok = TOLS[-1], False
    for tol in reversed(TOLS):  # tightest first
        if not passes(runs[tol], ref):
            break
        chosen, ok = tol, True
    return chosen, ok


def fmt_err(run: Run, ref: Run) -> str:
    dr, da = errors(run, ref)
    return f"{dr:.1e} m" + (f", {da:.1e} rad" if run.R is not None else "")


def machine_line() -> str:
    here = Path(__file__).resolve().parent

    def git(*argv: str) -> str:
        return subprocess.run(
            ["git", *argv], capture_output=True, text=True, check=True, cwd=here
        ).stdout.strip()

    try:
        commit = git("rev-parse", "--short", "HEAD")
        if git("status", "--porcelain", "--", "../gmuk"):
            commit += " + uncommitted changes under gmuk/"
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    return (
        f"gmuk {gmuk.__version__} (commit {commit}), Basilisk {BSK_VERSION}, numpy "
        f"{np.__version__}, numba {numba.__version__}, Python {platform.python_version()}, "
        f"{os.cpu_count()} CPUs"
    )


@dataclass
class Outcome:
    case: Case
    tol: dict[str, float | None]  # None: RK4 at RK4_STEP
    ref: dict[str, Run]
    seconds: dict[str, float]  # medians
    last: dict[str, Run]  # the last timed run of each library
    scans: dict[str, dict[float, Run]]
    notes: list[str]


def measure(
    case: Case,
    field: gmuk.SphericalHarmonicField,
    csv: Path | None,
    ref: dict[str, Run] | None,
    repeat: int,
) -> Outcome:
    """References (unless given), tolerance scan, then the alternating timed rounds."""
    system, state = gmuk_problem(case, field)
    run_gmuk(system, state, TOLS[0])  # load (or compile) the kernels
    notes: list[str] = []
    if ref is None:
        ref = {
            "gmuk": run_gmuk(system, state, REF_TOL["gmuk"]),
            "Basilisk": run_bsk(case, field, csv, REF_TOL["Basilisk"]),
        }
        looser = {
            "gmuk": run_gmuk(system, state, 3 * REF_TOL["gmuk"]),
            "Basilisk": run_bsk(case, field, csv, 3 * REF_TOL["Basilisk"]),
        }
        notes.extend(
            f"{lib} reference: {fmt_err(looser[lib], ref[lib])} from the run at "
            f"{3 * REF_TOL[lib]:g}"
            for lib in LIBS
        )
    scans: dict[str, dict[float, Run]] = {}
    tol: dict[str, float | None] = {"gmuk": None, "Basilisk": None}
    if not case.fixed_step:
        scans = {
            "gmuk": {t: run_gmuk(system, state, t) for t in TOLS},
            "Basilisk": {t: run_bsk(case, field, csv, t) for t in TOLS},
        }
        for lib in LIBS:
            tol[lib], ok = choose_tolerance(scans[lib], ref[lib])
            if not ok:
                notes.append(f"{lib} misses the target even at tol {tol[lib]:g}")

    def one(lib: str) -> Run:
        if lib == "gmuk":
            return run_gmuk(system, state, tol["gmuk"])
        return run_bsk(case, field, csv, tol["Basilisk"])

    one("Basilisk")  # warm-up (gmuk's ran above)
    timed: dict[str, list[Run]] = {lib: [] for lib in LIBS}
    for k in range(repeat):
        for lib in LIBS if k % 2 == 0 else LIBS[::-1]:
            timed[lib].append(one(lib))
    seconds = {lib: statistics.median(r.seconds for r in timed[lib]) for lib in LIBS}
    last = {lib: timed[lib][-1] for lib in LIBS}

    if case.degree is None:  # attribute the difference between the two models
        alt_system, alt_state = gmuk_problem(case, field, torque_only=True)
        alt = run_gmuk(alt_system, alt_state, REF_TOL["gmuk"])
        dr, da = errors(alt, ref["Basilisk"])
        dr_eq23, _ = errors(alt, ref["gmuk"])
        notes.append(
            f"gmuk with Basilisk's model (point-mass force + gradient torque; a Python force "
            f"model defined here, not timed) against Basilisk's reference: {dr:.1e} m, "
            f"{da:.1e} rad; Eq. 23's finite-size force moves gmuk's final position by "
            f"{dr_eq23:.1e} m"
        )
    if case.fixed_step:
        bsk_rhs = 4 * round(T_END / RK4_STEP)
        notes.append(
            f"Basilisk RK4 makes {bsk_rhs} RHS evaluations: "
            f"{seconds['Basilisk'] / bsk_rhs * 1e6:.1f} µs per RHS"
        )
    return Outcome(case, tol, ref, seconds, last, scans, notes)


def print_scan(out: Outcome) -> None:
    print(f"scan, case {out.case.label} (error against the library's own reference)\n")
    print("| tol | gmuk error | gmuk RHS | gmuk (s) | Basilisk error | Basilisk (s) |")
    print("|---:|---:|---:|---:|---:|---:|")
    for t in TOLS:
        g, b = out.scans["gmuk"][t], out.scans["Basilisk"][t]
        print(
            f"| {t:.2g} | {fmt_err(g, out.ref['gmuk'])} | {g.n_rhs} | {g.seconds:.4f} | "
            f"{fmt_err(b, out.ref['Basilisk'])} | {b.seconds:.4f} |"
        )
    print()


def main() -> None:
    gmuk.compile_loop()  # timings of the compiled loop, not of its one-time compilation
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="skip degree 150; 3 rounds")
    parser.add_argument("--repeat", type=int, default=None, help="timed rounds (≥ 3)")
    parser.add_argument("--show-scan", action="store_true", help="print every scanned run")
    args = parser.parse_args()
    repeat = max(3, args.repeat or (3 if args.quick else 7))
    bskLogging.setDefaultLogLevel(bskLogging.BSK_ERROR)

    cases = [Case("1: point mass, degree 50, adaptive", 50)]
    if not args.quick:
        cases.append(Case("2: point mass, degree 150, adaptive", 150))
    cases += [
        Case("3: point mass, degree 50, RK4 5 s", 50, fixed_step=True),
        Case("4: rigid body, point mass + gravity gradient, adaptive", None),
    ]

    print(machine_line())
    print("OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 (set by this script)")
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    print(f"median of {repeat} alternating rounds; propagation call only\n")

    grail = gmuk.gravity.load("GRGM660PRIM")
    outcomes: list[Outcome] = []
    refs: dict[int | None, dict[str, Run]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        csvs: dict[int, Path] = {}
        for degree in sorted({c.degree for c in cases if c.degree is not None}):
            field = grail.truncate(degree) if degree < grail.degree else grail
            csvs[degree] = write_jpl_csv(field, Path(tmp) / f"grgm660prim_{degree}.csv")
            print(
                f"degree {degree}: largest relative difference between the two libraries' "
                f"accelerations at 20 points 50-500 km up: "
                f"{field_agreement(field, csvs[degree]):.1e}"
            )
        print()
        for case in cases:
            degree = 0 if case.degree is None else case.degree  # case 4 takes only μ
            field = grail.truncate(degree) if degree < grail.degree else grail
            csv = None if case.degree is None else csvs[case.degree]
            out = measure(case, field, csv, refs.get(case.degree), repeat)
            refs[case.degree] = out.ref  # case 3 shares case 1's references
            outcomes.append(out)
            if args.show_scan and out.scans:
                print_scan(out)

    rigid = " rad"
    print(
        "| case | gmuk (s, RHS count, µs/RHS) | Basilisk (s) | gmuk / Basilisk | "
        "agreement between libraries |"
    )
    print("|---|---:|---:|---:|---|")
    for out in outcomes:
        sec, n_rhs = out.seconds, out.last["gmuk"].n_rhs
        assert n_rhs is not None
        if out.case.fixed_step:
            dr, _ = errors(out.last["gmuk"], out.last["Basilisk"])
            agree = f"{dr:.1e} m (the RK4 runs)"
        else:
            dr, da = errors(out.ref["gmuk"], out.ref["Basilisk"])
            agree = f"{dr:.1e} m" + (f", {da:.1e}{rigid}" if out.case.degree is None else "")
        print(
            f"| {out.case.label} | {sec['gmuk']:.4f} s, {n_rhs}, "
            f"{sec['gmuk'] / n_rhs * 1e6:.1f} µs | {sec['Basilisk']:.4f} s | "
            f"{sec['gmuk'] / sec['Basilisk']:.2f} | {agree} |"
        )
    print(
        f"\nAgreement: the two references (gmuk rtol = atol = {REF_TOL['gmuk']:g}, Basilisk "
        f"relTol = absTol = {REF_TOL['Basilisk']:g}) at 7200 s; for RK4, the two timed runs."
    )

    print("\nAccuracy of the timed runs (final position, and attitude for case 4):\n")
    print(
        "| case | gmuk tol | gmuk vs own reference | Basilisk tol | Basilisk vs own "
        "reference | timed runs vs each other |"
    )
    print("|---|---:|---:|---:|---:|---:|")
    for out in outcomes:
        tol = {lib: "RK4 5 s" if out.tol[lib] is None else f"{out.tol[lib]:.2g}" for lib in LIBS}
        dr, da = errors(out.last["gmuk"], out.last["Basilisk"])
        both = f"{dr:.1e} m" + (f", {da:.1e}{rigid}" if out.case.degree is None else "")
        print(
            f"| {out.case.label.split(':')[0]} | {tol['gmuk']} | "
            f"{fmt_err(out.last['gmuk'], out.ref['gmuk'])} | {tol['Basilisk']} | "
            f"{fmt_err(out.last['Basilisk'], out.ref['Basilisk'])} | {both} |"
        )
    print()
    for out in outcomes:
        for note in out.notes:
            print(f"- case {out.case.label.split(':')[0]}: {note}")
    print(f"\nload average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
