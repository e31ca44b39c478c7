"""Robots from URDF: gmuk's maximal-coordinate solve beside Pinocchio's ABA (issue #28).

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_robots.py [--repeat N]

Three measurements, each side by side in the same run:

1. one ``robot.system.accelerations(state)`` call against one ``pin.aba`` call (C++, through
   its Python binding) on the Panda (fingers locked), Solo12 (floating base) and UR5: medians
   and ratios;
2. a 1 s Panda run from a random state at rtol = atol = 1e-10: gmuk's ``simulate`` against
   Pinocchio's ABA driven by scipy's DOP853 at the same tolerances, with each one's error
   against a reference at 1e-13 (Pinocchio + DOP853);
3. the cost of one accelerations call on a chain of n revolute links, n = 5 … 160, and the
   exponent of its growth (a least-squares fit of log time against log n).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

import gmuk
from gmuk.robots import RevoluteJoint, Robot, example_robot_data

FINGERS = ("panda_finger_joint1", "panda_finger_joint2")
ROBOTS = {
    "panda": ("panda_description/urdf/panda.urdf", "fixed", FINGERS),
    "solo12": ("solo_description/robots/solo12.urdf", "floating", ()),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "fixed", ()),
}  # fmt: skip


def _median_s(fn, repeat: int, inner: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        times.append((time.perf_counter() - t0) / inner)
    return statistics.median(times)


def one_call(repeat: int) -> None:
    print("one accelerations call against pin.aba (medians)")
    for name, (path, base, locked) in ROBOTS.items():
        robot = Robot.from_urdf(example_robot_data(path), base=base, locked_joints=locked)
        model, data = robot.model, robot.model.createData()
        rng = np.random.default_rng(0)
        pin.seed(0)  # Pinocchio's own generator: the same states in every run
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, tau = rng.normal(size=model.nv), np.zeros(model.nv)
        state = robot.state(q, v)
        robot.system.accelerations(state)
        t_g = _median_s(lambda r=robot, s=state: r.system.accelerations(s), repeat, 50)
        t_p = _median_s(
            lambda m=model, d=data, q=q, v=v, u=tau: pin.aba(m, d, q, v, u), repeat, 2000
        )
        rows = sum(j._T.shape[0] for j in robot.joints.values())
        print(f"  {name:7s} nv={model.nv:2d} rows={rows:3d}: gmuk {t_g * 1e6:8.1f} µs, "
              f"pin.aba {t_p * 1e6:6.2f} µs, ratio {t_g / t_p:7.1f}")  # fmt: skip


def panda_run(repeat: int) -> None:
    path, _, locked = ROBOTS["panda"]
    robot = Robot.from_urdf(example_robot_data(path), locked_joints=locked)
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(12)
    pin.seed(12)
    q0 = pin.randomConfiguration(model, -2.0 * np.ones(7), 2.0 * np.ones(7))
    v0 = rng.normal(size=7)
    t = np.linspace(0.0, 1.0, 11)

    def rhs(_t, y):
        return np.concatenate([y[7:], pin.aba(model, data, y[:7], y[7:], np.zeros(7))])

    def pin_run(tol: float):
        return solve_ivp(rhs, (0, 1), np.concatenate([q0, v0]), method="DOP853", t_eval=t,
                         rtol=tol, atol=tol)  # fmt: skip

    ref = pin_run(1e-13).y[:7].T
    state = robot.state(q0, v0)
    robot.system.simulate(state, (0.0, 1.0), t_eval=t)
    out = {}

    def gmuk_run():
        out["traj"] = robot.system.simulate(state, (0.0, 1.0), t_eval=t, rtol=1e-10, atol=1e-10)

    def pinocchio_run():
        out["pin"] = pin_run(1e-10)

    t_g = _median_s(gmuk_run, repeat, 1)
    t_p = _median_s(pinocchio_run, repeat, 1)
    e_g = np.abs(robot.configuration(out["traj"]) - ref).max()
    e_p = np.abs(out["pin"].y[:7].T - ref).max()
    print("1 s Panda run, rtol = atol = 1e-10 (medians)")
    print(
        f"  gmuk      {t_g:7.3f} s, error {e_g:.1e} rad, {out['traj'].stats['n_rhs']} evaluations"
    )
    print(f"  pin+DOP853 {t_p:6.3f} s, error {e_p:.1e} rad, {out['pin'].nfev} evaluations")
    print(f"  ratio gmuk / Pinocchio {t_g / t_p:.2f}")


def chain(n: int) -> tuple[gmuk.System, gmuk.State]:
    links = [gmuk.RigidBody(f"l{i}", 1.0, np.diag([0.01, 0.09, 0.09])) for i in range(n)]
    half = np.eye(4)
    half[0, 3] = 0.15
    joints = [RevoluteJoint(None, links[0], child_frame=np.linalg.inv(half) @ np.eye(4))]
    joints += [
        RevoluteJoint(links[i - 1], links[i], parent_frame=half, child_frame=np.linalg.inv(half))
        for i in range(1, n)
    ]
    system = gmuk.System(links, joints, [gmuk.UniformGravity((0.0, -9.81, 0.0))])
    g, V = {}, {}
    for i, body in enumerate(links):
        pose = np.eye(4)
        pose[0, 3] = 0.3 * i + 0.15
        g[body.name], V[body.name] = pose, np.zeros(6)
    return system, system.state(g=g, V=V)


def scaling(repeat: int, sizes: tuple[int, ...]) -> None:
    print("one accelerations call on a chain of n revolute links (medians)")
    times = []
    for n in sizes:
        system, state = chain(n)
        system.accelerations(state)
        t_g = _median_s(lambda y=system, s=state: y.accelerations(s), max(3, repeat // 2), 5)
        times.append(t_g)
        print(f"  n = {n:4d}: {t_g * 1e3:9.3f} ms  ({type(system.solver).__name__})")
    for k in range(1, len(sizes)):
        slope = np.log(times[k] / times[k - 1]) / np.log(sizes[k] / sizes[k - 1])
        print(f"  exponent from n = {sizes[k - 1]} to {sizes[k]}: {slope:.2f}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--sizes", default="5,10,20,40,80,160")
    args = parser.parse_args(argv)
    one_call(args.repeat)
    panda_run(args.repeat)
    scaling(args.repeat, tuple(int(s) for s in args.sizes.split(",")))


if __name__ == "__main__":
    main()
