"""The Panda in gmuk beside MuJoCo RK4 at equal accuracy (issue #28, speed acceptance).

    python benchmarks/bench_robots_mujoco.py [--repeat N]

MuJoCo is a benchmark-only dependency (``pip install mujoco``; not in pyproject.toml). The
script sets OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1 itself, before numpy is imported.

The Panda of example-robot-data (fingers locked at their neutral 0, as in
``benchmarks/bench_robots.py``) is loaded into MuJoCo from the same URDF, rewritten without
what MuJoCo cannot read or what gmuk's run does not have: the visual and collision elements
(.dae meshes; no geom is left, so no contact), the ``<dynamics>`` elements (joint damping and
friction: gmuk's ``Robot.from_urdf`` leaves them out), the mimic element, and the finger joints,
made fixed. MuJoCo's constraints (joint limits, contacts) are disabled: gmuk's run has none.
The inertias are the URDF's: MuJoCo fuses the fixed links as Pinocchio does.

Four measurements, in one run:

1. **the same physics**: MuJoCo's ``qacc`` after ``mj_forward`` against ``pin.aba`` (and gmuk's
   ``robot.forward_dynamics``) at seeded random states (q, v, τ), relative to max |q̈|;
2. one ``robot.system.accelerations`` call against one ``mj_forward`` (and one ``pin.aba``);
3. a 1 s Panda run from bench_robots' random state, with the joint angles output at the same
   ``--outputs`` + 1 equally spaced times by every run (default every 10 ms; 10 gives
   bench_robots' grid): a reference (Pinocchio ABA + scipy DOP853 at rtol = atol =
   1e-13, checked against gmuk at 1e-12), gmuk's error at rtol = atol = 1e-10 (max over the
   outputs and joints, rad), then MuJoCo RK4's largest step dt = (output spacing) / k reaching
   that error (k doubled, then bisected), so that MuJoCo's steps land on the outputs;
4. the time of that MuJoCo run, ``mj_step`` called once a step from a Python loop and
   ``mujoco.rollout`` (the loop in C), beside gmuk's ``simulate`` and Pinocchio + DOP853 at
   1e-10; and MuJoCo's default semi-implicit Euler at the same dt and at its 2 ms default, for
   information.

Each time is the median over ``--repeat`` runs; ratios are gmuk / the other (above 1: gmuk is
slower).
"""

from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import statistics
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path
from typing import Any

try:
    import mujoco
    import mujoco.rollout
except ImportError:
    sys.exit("bench_robots_mujoco.py needs MuJoCo, a benchmark-only dependency: pip install mujoco")

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from gmuk.robots import Robot, example_robot_data

PANDA = "panda_description/urdf/panda.urdf"
FINGERS = ("panda_finger_joint1", "panda_finger_joint2")
SPAN = 1.0  # s
TOL = 1e-10  # gmuk's rtol = atol, and Pinocchio + DOP853's
REF_TOL = 1e-13  # the reference's (Pinocchio + DOP853)
CHECK_TOL = 1e-12  # gmuk's run that checks the reference


def _medians_s(fns: dict[str, tuple[Callable[[], Any], int]], repeat: int) -> dict[str, float]:
    """Median time (s) of one call of each function: ``repeat`` rounds, each timing ``inner``
    calls of every function in turn, so that all see the same machine load."""
    times: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(repeat):
        for name, (fn, inner) in fns.items():
            t0 = time.perf_counter()
            for _ in range(inner):
                fn()
            times[name].append((time.perf_counter() - t0) / inner)
    return {name: statistics.median(ts) for name, ts in times.items()}


# ------------------------------------------------------------------------- the MuJoCo model
def mujoco_urdf(path: Path, locked: tuple[str, ...]) -> str:
    """The URDF at ``path`` as text MuJoCo compiles to gmuk's model: no visual or collision
    element, no joint dynamics (damping, friction), no mimic, the ``locked`` joints fixed (at
    coordinate 0, Pinocchio's neutral for a prismatic or revolute joint)."""
    root = ET.parse(path).getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for element in link.findall(tag):
                link.remove(element)
    for joint in root.iter("joint"):
        for tag in ("dynamics", "mimic", "safety_controller"):
            for element in joint.findall(tag):
                joint.remove(element)
        if joint.get("name") in locked:
            joint.set("type", "fixed")
            for tag in ("axis", "limit"):
                for element in joint.findall(tag):
                    joint.remove(element)
    return ET.tostring(root, encoding="unicode")


def mujoco_panda(robot: Robot, integrator: int, dt: float) -> tuple[Any, Any]:
    """MuJoCo's model and data of ``robot``'s Panda: the same URDF, gravity and inertias, no
    constraint, the given integrator and step dt (s)."""
    assert robot.path is not None
    m = mujoco.MjModel.from_xml_string(mujoco_urdf(robot.path, FINGERS))
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    m.opt.gravity[:] = robot.model.gravity.linear
    m.opt.integrator = integrator
    m.opt.timestep = dt
    names = [m.joint(i).name for i in range(m.njnt)]
    assert names == list(robot.model.names)[1:], (names, list(robot.model.names))
    assert m.ngeom == 0 and not m.dof_damping.any() and not m.dof_armature.any()
    assert not m.dof_frictionloss.any() and not m.jnt_stiffness.any()
    masses = [robot.model.inertias[i].mass for i in range(1, robot.model.njoints)]
    np.testing.assert_allclose(m.body_mass[1:], masses, rtol=1e-15)
    return m, mujoco.MjData(m)


# ----------------------------------------------------------------------------- measurements
def same_physics(robot: Robot, n_states: int) -> None:
    model, pin_data = robot.model, robot.model.createData()
    m, d = mujoco_panda(robot, mujoco.mjtIntegrator.mjINT_RK4, 0.002)
    rng = np.random.default_rng(0)
    pin.seed(0)
    e_mj, e_gmuk, e_mass = 0.0, 0.0, 0.0
    mass = np.zeros((m.nv, m.nv))
    for _ in range(n_states):
        q = pin.randomConfiguration(model, -np.pi * np.ones(7), np.pi * np.ones(7))
        v, tau = rng.normal(size=7), rng.normal(scale=10.0, size=7)
        d.qpos[:], d.qvel[:], d.qfrc_applied[:] = q, v, tau
        mujoco.mj_forward(m, d)
        assert d.nefc == 0
        a = pin.aba(model, pin_data, q, v, tau)
        scale = np.abs(a).max()
        e_mj = max(e_mj, np.abs(d.qacc - a).max() / scale)
        e_gmuk = max(e_gmuk, np.abs(robot.forward_dynamics(q, v, tau) - a).max() / scale)
        mujoco.mj_fullM(m, d, mass)
        M = pin.crba(model, pin_data, q)
        M = np.triu(M) + np.triu(M, 1).T
        e_mass = max(e_mass, np.abs(mass - M).max() / np.abs(M).max())
    print(f"the same physics, {n_states} seeded random states (q, v, τ); max |Δq̈| / max |q̈|:")
    print(f"  MuJoCo mj_forward qacc against pin.aba   {e_mj:.1e}")
    print(f"  gmuk forward_dynamics against pin.aba    {e_gmuk:.1e}")
    print(f"  MuJoCo mass matrix against pin.crba      {e_mass:.1e} (relative to max |M|)")


def one_call(robot: Robot, repeat: int) -> None:
    model, pin_data = robot.model, robot.model.createData()
    m, d = mujoco_panda(robot, mujoco.mjtIntegrator.mjINT_RK4, 0.002)
    rng = np.random.default_rng(0)
    pin.seed(0)
    q = pin.randomConfiguration(model, -np.ones(7), np.ones(7))
    v, tau = rng.normal(size=7), np.zeros(7)
    state = robot.state(q, v)
    d.qpos[:], d.qvel[:] = q, v
    robot.system.accelerations(state)
    med = _medians_s(
        {
            "gmuk": (lambda: robot.system.accelerations(state), 2000),
            "mujoco": (lambda: mujoco.mj_forward(m, d), 2000),
            "pin": (lambda: pin.aba(model, pin_data, q, v, tau), 2000),
        },
        repeat,
    )
    t_g, t_m, t_p = med["gmuk"], med["mujoco"], med["pin"]
    print("one evaluation on the Panda (medians)")
    print(f"  gmuk system.accelerations {t_g * 1e6:8.1f} µs")
    print(f"  MuJoCo mj_forward         {t_m * 1e6:8.2f} µs, ratio gmuk / MuJoCo {t_g / t_m:.1f}")
    print(f"  pin.aba                   {t_p * 1e6:8.2f} µs, ratio gmuk / pin.aba {t_g / t_p:.1f}")


class MujocoRun:
    """The 1 s run in MuJoCo from (q0, v0): q at ``n_out`` + 1 equally spaced outputs, k steps
    of dt = SPAN / (n_out k) apart."""

    def __init__(self, robot: Robot, integrator: int, k: int, n_out: int, q0: Any, v0: Any):
        self.k, self.n_out = k, n_out
        self.m, self.d = mujoco_panda(robot, integrator, SPAN / (n_out * k))
        self.q0, self.v0 = q0, v0
        self._start()
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self.initial = np.empty(mujoco.mj_stateSize(self.m, spec))
        mujoco.mj_getState(self.m, self.d, self.initial, spec)
        self.nstep = self.k * self.n_out
        self.states = np.empty((1, self.nstep, self.initial.size))
        self.rollout_data = mujoco.MjData(self.m)

    def _start(self) -> None:
        mujoco.mj_resetData(self.m, self.d)
        self.d.qpos[:], self.d.qvel[:] = self.q0, self.v0

    def python_loop(self) -> np.ndarray:
        """``mj_step`` once a step from Python; q (rad) at the outputs."""
        m, d = self.m, self.d
        self._start()
        q = np.empty((self.n_out + 1, m.nq))
        q[0] = d.qpos
        for i in range(1, self.n_out + 1):
            for _ in range(self.k):
                mujoco.mj_step(m, d)
            q[i] = d.qpos
        return q

    def rollout(self) -> np.ndarray:
        """``mujoco.rollout`` (the step loop in C, every step's state written); q (rad) at the
        outputs. The state's first entry is the time, then qpos (mjSTATE_FULLPHYSICS)."""
        mujoco.rollout.rollout(self.m, self.rollout_data, self.initial, nstep=self.nstep,
                               state=self.states)  # fmt: skip
        q = np.empty((self.n_out + 1, self.m.nq))
        q[0] = self.q0
        q[1:] = self.states[0, self.k - 1 :: self.k, 1 : 1 + self.m.nq]
        return q


def panda_run(robot: Robot, repeat: int, n_out: int) -> None:
    model, pin_data = robot.model, robot.model.createData()
    rng = np.random.default_rng(12)
    pin.seed(12)  # bench_robots' state
    q0 = pin.randomConfiguration(model, -2.0 * np.ones(7), 2.0 * np.ones(7))
    v0 = rng.normal(size=7)
    output_dt = SPAN / n_out
    t = np.linspace(0.0, SPAN, n_out + 1)

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        return np.concatenate([y[7:], pin.aba(model, pin_data, y[:7], y[7:], np.zeros(7))])

    def pin_run(tol: float) -> Any:
        return solve_ivp(rhs, (0.0, SPAN), np.concatenate([q0, v0]), method="DOP853",
                         t_eval=t, rtol=tol, atol=tol)  # fmt: skip

    ref = pin_run(REF_TOL).y[:7].T
    state = robot.state(q0, v0)

    def gmuk_run(tol: float) -> Any:
        return robot.system.simulate(state, (0.0, SPAN), t_eval=t, rtol=tol, atol=tol)

    e_check = np.abs(robot.configuration(gmuk_run(CHECK_TOL)) - ref).max()
    out = {"gmuk": gmuk_run(TOL), "pin": pin_run(TOL)}
    e_g = np.abs(robot.configuration(out["gmuk"]) - ref).max()
    e_p = np.abs(out["pin"].y[:7].T - ref).max()

    def error(run: MujocoRun) -> float:
        return float(np.abs(run.rollout() - ref).max())

    rk4 = mujoco.mjtIntegrator.mjINT_RK4
    sweep: dict[int, float] = {}  # k: MuJoCo RK4's error (rad) at dt = output_dt / k

    def reaches(k: int) -> bool:
        sweep[k] = error(MujocoRun(robot, rk4, k, n_out, q0, v0))
        return sweep[k] <= e_g

    hi = 1
    while not reaches(hi):
        hi *= 2
    lo = hi // 2  # the error at lo exceeds gmuk's (or lo = 0), at hi it does not
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if reaches(mid) else (mid, hi)
    k = hi
    run = MujocoRun(robot, rk4, k, n_out, q0, v0)
    q_loop, q_roll = run.python_loop(), run.rollout()
    assert np.array_equal(q_loop, q_roll), np.abs(q_loop - q_roll).max()
    e_m = float(np.abs(q_loop - ref).max())
    euler = mujoco.mjtIntegrator.mjINT_EULER
    euler_same = MujocoRun(robot, euler, k, n_out, q0, v0)
    e_euler = float(np.abs(euler_same.rollout() - ref).max())
    med = _medians_s(
        {
            "gmuk": (lambda: gmuk_run(TOL), 1),
            "pin": (lambda: pin_run(TOL), 1),
            "loop": (run.python_loop, 1),
            "rollout": (run.rollout, 1),
            "euler": (euler_same.rollout, 1),
        },
        repeat,
    )
    t_g, t_p, t_loop, t_roll = med["gmuk"], med["pin"], med["loop"], med["rollout"]
    t_euler = med["euler"]
    k_default = max(1, round(output_dt / 0.002))  # MuJoCo's default step, 2 ms
    e_euler_default = error(MujocoRun(robot, euler, k_default, n_out, q0, v0))

    dt = output_dt / k
    print(f"1 s Panda run from bench_robots' random state, q every {output_dt * 1e3:g} ms")
    print(f"  reference: Pinocchio ABA + DOP853 at {REF_TOL:.0e}; gmuk at {CHECK_TOL:.0e} "
          f"differs from it by {e_check:.1e} rad")  # fmt: skip
    print(f"  MuJoCo RK4 error (rad) against dt = {output_dt * 1e3:g} ms / k:")
    for kk in sorted(sweep):
        mark = "  <- largest dt at gmuk's error" if kk == k else ""
        print(f"    k = {kk:5d}, dt = {output_dt / kk * 1e3:8.5f} ms: {sweep[kk]:.2e}{mark}")
    print(f"  (medians of {repeat})")
    print(f"  gmuk simulate, rtol = atol = {TOL:.0e}  {t_g:8.4f} s, error {e_g:.2e} rad, "
          f"{out['gmuk'].stats['n_rhs']} evaluations")  # fmt: skip
    print(f"  Pinocchio ABA + DOP853, {TOL:.0e}       {t_p:8.4f} s, error {e_p:.2e} rad, "
          f"{out['pin'].nfev} evaluations")  # fmt: skip
    print(f"  MuJoCo RK4 dt = {dt * 1e3:.5f} ms, mj_step loop {t_loop:8.4f} s, error {e_m:.2e} "
          f"rad, {run.nstep} steps, {4 * run.nstep} evaluations")  # fmt: skip
    print(f"  MuJoCo RK4 dt = {dt * 1e3:.5f} ms, rollout     {t_roll:8.4f} s")
    print(f"  ratio gmuk / MuJoCo RK4: {t_g / t_loop:.2f} (mj_step loop), "
          f"{t_g / t_roll:.2f} (rollout); gmuk / Pinocchio + DOP853: {t_g / t_p:.2f}")  # fmt: skip
    n_g, n_m = out["gmuk"].stats["n_rhs"], 4 * run.nstep
    e_g_s, e_m_s = t_g / n_g, t_loop / n_m  # s per evaluation
    print(f"  per evaluation: gmuk {e_g_s * 1e6:.1f} µs, MuJoCo RK4 {e_m_s * 1e6:.2f} µs (loop), "
          f"ratio {e_g_s / e_m_s:.1f}; MuJoCo takes {n_m / n_g:.2f}× gmuk's evaluations"
          )  # fmt: skip
    dt_default = output_dt / k_default
    print(f"  for information, MuJoCo's semi-implicit Euler: at dt = {dt * 1e3:.5f} ms "
          f"{t_euler:.4f} s (rollout), error {e_euler:.1e} rad; at dt = {dt_default * 1e3:g} ms "
          f"error {e_euler_default:.1e} rad")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--states", type=int, default=20, help="states of the physics check")
    parser.add_argument("--outputs", type=int, default=100, help="output intervals in the 1 s")
    args = parser.parse_args(argv)
    print(f"MuJoCo {mujoco.__version__}, Pinocchio {pin.__version__}")
    robot = Robot.from_urdf(example_robot_data(PANDA), locked_joints=FINGERS)
    same_physics(robot, args.states)
    one_call(robot, args.repeat)
    panda_run(robot, args.repeat, args.outputs)


if __name__ == "__main__":
    main()
