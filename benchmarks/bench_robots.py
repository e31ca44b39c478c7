"""Robots from URDF: gmuk's maximal-coordinate solve beside Pinocchio's ABA (issue #28).

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_robots.py [--repeat N]

Three measurements, each side by side in the same run, for gmuk's solve strategies ``SOLVERS``
(the tree solve, :mod:`gmuk.engine.tree`, and the dense fused one it replaces on trees):

1. one ``robot.system.accelerations(state)`` call against one ``pin.aba`` call (C++, through
   its Python binding) on the Panda (fingers locked), Solo12 (floating base) and UR5, timed in
   turn round by round (``--repeat`` rounds, each the median of three loops): medians, and the
   median of the rounds' ratios;
2. a 1 s Panda run from a random state at rtol = atol = 1e-10: gmuk's ``simulate`` against
   Pinocchio's ABA driven by scipy's DOP853 at the same tolerances, with each one's error
   against a reference at 1e-13 (Pinocchio + DOP853), and the time per evaluation;
3. the cost of one accelerations call, and of one evaluation inside the compiled loop (a
   short run's time over its evaluations), on a chain of n revolute links, n = 5 … 1000
   (``--sizes``; the dense fused solve up to ``--dense-max`` links), and the exponent of its
   growth between successive n and by a least-squares fit of log time against log n.
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
#: gmuk's strategies side by side: the tree solve and the dense fused one (QR up to 48 rows,
#: then the SVD), the default on these robots before the tree solve.
SOLVERS = ("tree", "fused")
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
        for solver in SOLVERS:
            robot = Robot.from_urdf(
                example_robot_data(path), base=base, locked_joints=locked, solver=solver
            )
            model, data = robot.model, robot.model.createData()
            rng = np.random.default_rng(0)
            pin.seed(0)  # Pinocchio's own generator: the same states in every run
            q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
            v, tau = rng.normal(size=model.nv), np.zeros(model.nv)
            state = robot.state(q, v)
            robot.system.accelerations(state)
            inner = 2000 if solver == "tree" else 50
            t_gs, t_ps = [], []
            for _ in range(repeat):  # in turn, round by round: the same load on both
                t_ps.append(_median_s(
                    lambda m=model, d=data, q=q, v=v, u=tau: pin.aba(m, d, q, v, u), 3, 2000
                ))  # fmt: skip
                t_gs.append(_median_s(lambda r=robot, s=state: r.system.accelerations(s), 3, inner))
            t_g, t_p = statistics.median(t_gs), statistics.median(t_ps)
            ratio = statistics.median([a / b for a, b in zip(t_gs, t_ps, strict=True)])
            rows = sum(j._T.shape[0] for j in robot.joints.values())
            print(f"  {name:7s} nv={model.nv:2d} rows={rows:3d} {solver:5s}: gmuk "
                  f"{t_g * 1e6:8.1f} µs, pin.aba {t_p * 1e6:6.2f} µs, "
                  f"ratio {ratio:7.2f} (median of the rounds' ratios)")  # fmt: skip


def panda_run(repeat: int) -> None:
    path, _, locked = ROBOTS["panda"]
    robots = {
        s: Robot.from_urdf(example_robot_data(path), locked_joints=locked, solver=s)
        for s in SOLVERS
    }
    model = robots[SOLVERS[0]].model
    data = model.createData()
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
    out = {}
    runs = {}
    for solver, robot in robots.items():
        state = robot.state(q0, v0)
        robot.system.simulate(state, (0.0, 1.0), t_eval=t)  # the loop compiled or loaded

        def gmuk_run(r=robot, s=state, key=solver):
            out[key] = r.system.simulate(s, (0.0, 1.0), t_eval=t, rtol=1e-10, atol=1e-10)

        runs[solver] = gmuk_run

    def pinocchio_run():
        out["pin"] = pin_run(1e-10)

    times = {key: [] for key in (*SOLVERS, "pin")}
    for _ in range(repeat):  # each round times every contender in turn: the same load
        for key, fn in (*runs.items(), ("pin", pinocchio_run)):
            times[key].append(_median_s(fn, 1, 1))
    t_p = statistics.median(times["pin"])
    e_p = np.abs(out["pin"].y[:7].T - ref).max()
    print("1 s Panda run, rtol = atol = 1e-10 (medians)")
    for solver, robot in robots.items():
        t_g = statistics.median(times[solver])
        e_g = np.abs(robot.configuration(out[solver]) - ref).max()
        n = out[solver].stats["n_rhs"]
        print(f"  gmuk {solver:5s} {t_g:7.3f} s, error {e_g:.1e} rad, {n} evaluations "
              f"({t_g / n * 1e6:.1f} µs each), ratio gmuk / Pinocchio {t_g / t_p:.2f}")  # fmt: skip
    n_p = out["pin"].nfev
    print(f"  pin+DOP853 {t_p:6.3f} s, error {e_p:.1e} rad, {n_p} evaluations "
          f"({t_p / n_p * 1e6:.1f} µs each)")  # fmt: skip


def breakdown(repeat: int) -> None:
    """Where one evaluation's time goes (compiled pieces timed in a compiled loop of 200 calls,
    as the step loop calls them; Python pieces as ``accelerations`` calls them)."""
    from numba import njit

    from gmuk.robots.joints import joint_rows

    @njit
    def rows_loop(gp, Vp, gc, Vc, p, A, b, k):
        for _ in range(k):
            joint_rows(0.0, gp, Vp, gc, Vc, p, A, b)

    @njit
    def solve_loop(kernel, V, Q, A, b, P, out, k):
        for _ in range(k):
            kernel(V, Q, A, b, P, out)

    @njit
    def tree_loop(kernel, g, V, Q, A, b, P, out, k):
        for _ in range(k):
            kernel(g, V, Q, A, b, P, out)

    print("one evaluation, piece by piece (medians; compiled pieces per call in a compiled loop)")
    for name, (path, base, locked) in ROBOTS.items():
        _pieces(name, path, base, locked, repeat, rows_loop, solve_loop, tree_loop)


def _pieces(name, path, base, locked, repeat, rows_loop, solve_loop, tree_loop) -> None:
    from gmuk.engine._uk_kernels import uk_rigid
    from gmuk.engine.tree import tree_params, tree_rigid

    robots = {
        s: Robot.from_urdf(example_robot_data(path), base=base, locked_joints=locked, solver=s)
        for s in SOLVERS
    }
    tree, fused = robots["tree"], robots["fused"]
    pin.seed(0)
    model = tree.model
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v = np.random.default_rng(0).normal(size=model.nv)
    state = tree.state(q, v)
    sys_t = tree.system
    modeled = np.array(sys_t._generalized_forces(state)[0])
    A, b = sys_t.solver._blocks(state)
    V = np.array(state.V)
    n = V.size
    out = np.empty(4 * n + b.size + 3)
    args = []
    for j in tree.joints.values():
        s = j._T.shape[0]
        args.append((*(np.array(x) for x in j._pair(state)), j._params, np.empty((s, 12)),
                     np.empty(s)))  # fmt: skip
    for a in args:
        rows_loop(*a, 1)
    t_rows = _median_s(lambda: [rows_loop(*a, 200) for a in args], repeat, 1) / 200
    solver = sys_t.solver
    P = solver._P
    g = np.array(state.g)
    tree_loop(tree_rigid, g, V, modeled, A, b, P, out, 1)
    t_tree = _median_s(lambda: tree_loop(tree_rigid, g, V, modeled, A, b, P, out, 200), repeat, 1)
    # the same solve with every node eliminated as Baraff's (no joint eliminated with its child)
    Pb = tree_params(
        sys_t._J, sys_t._Jinv, sys_t._m_rigid, solver._order, solver._parent, solver._pairs,
        solver._rows_n, sys_t.consistency_tol, sys_t._singular,
    )  # fmt: skip
    tree_loop(tree_rigid, g, V, modeled, A, b, Pb, out, 1)
    t_baraff = _median_s(
        lambda: tree_loop(tree_rigid, g, V, modeled, A, b, Pb, out, 200), repeat, 1
    )
    sys_f = fused.system
    Af, bf = sys_f._stack_rows(fused.state(q, v), check_finite=False)
    Af = np.ascontiguousarray(Af)
    out_f = np.empty(4 * n + bf.size + 3)
    Pf = sys_f.solver._params
    solve_loop(uk_rigid, V, modeled, Af, bf, Pf, out_f, 1)
    t_qr = _median_s(lambda: solve_loop(uk_rigid, V, modeled, Af, bf, Pf, out_f, 200), repeat, 1)
    t_loads = _median_s(lambda: sys_t._generalized_forces(state), repeat, 50)
    t_blocks = _median_s(lambda: sys_t.solver._blocks(state), repeat, 50)
    note = " (beyond its 48-row QR)" if bf.size > 48 else ""
    print(f"  {name:7s}: joint rows (all {len(args)} kernels) {t_rows * 1e6:6.1f} µs, "
          f"tree solve {t_tree / 200 * 1e6:6.1f} µs (nodes one by one, Baraff's: "
          f"{t_baraff / 200 * 1e6:6.1f} µs), fused dense QR "
          f"{t_qr / 200 * 1e6:7.1f} µs{note}; in Python: loads {t_loads * 1e6:6.1f} µs, "
          f"rows {t_blocks * 1e6:6.1f} µs")  # fmt: skip


def chain(n: int, solver: str | None = None) -> tuple[gmuk.System, gmuk.State]:
    links = [gmuk.RigidBody(f"l{i}", 1.0, np.diag([0.01, 0.09, 0.09])) for i in range(n)]
    half = np.eye(4)
    half[0, 3] = 0.15
    joints = [RevoluteJoint(None, links[0], child_frame=np.linalg.inv(half) @ np.eye(4))]
    joints += [
        RevoluteJoint(links[i - 1], links[i], parent_frame=half, child_frame=np.linalg.inv(half))
        for i in range(1, n)
    ]
    system = gmuk.System(links, joints, [gmuk.UniformGravity((0.0, -9.81, 0.0))], solver=solver)
    g, V = {}, {}
    for i, body in enumerate(links):
        pose = np.eye(4)
        pose[0, 3] = 0.3 * i + 0.15
        g[body.name], V[body.name] = pose, np.zeros(6)
    return system, system.state(g=g, V=V)


def _loop_evaluation_s(system: gmuk.System, state: gmuk.State, repeat: int) -> float:
    """The time of one evaluation inside the compiled loop: a short run (0.01 s of the chain
    falling from rest, outputs at its ends only) over its number of evaluations (medians)."""
    per = []
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        traj = system.simulate(state, (0.0, 0.01), t_eval=[0.0, 0.01])
        per.append((time.perf_counter() - t0) / traj.stats["n_rhs"])
    return statistics.median(per)


def scaling(repeat: int, sizes: tuple[int, ...], dense_max: int) -> None:
    print("a chain of n revolute links: one accelerations call, one loop evaluation (medians)")
    fits = {}
    for solver in SOLVERS:
        times, loop_times, ns = [], [], []
        for n in sizes:
            if solver != "tree" and n > dense_max:
                continue
            system, state = chain(n, solver)
            system.accelerations(state)
            system.simulate(state, (0.0, 0.001))  # the loop compiled or loaded
            inner = max(1, 200 // n)
            t_g = _median_s(
                lambda y=system, s=state: y.accelerations(s), max(3, repeat // 2), inner
            )
            t_l = _loop_evaluation_s(system, state, max(3, repeat // 2))
            times.append(t_g)
            loop_times.append(t_l)
            ns.append(n)
            print(f"  {solver:5s} n = {n:4d}: call {t_g * 1e3:9.3f} ms, loop evaluation "
                  f"{t_l * 1e3:9.3f} ms  ({type(system.solver).__name__})")  # fmt: skip
        for k in range(1, len(ns)):
            slope = np.log(times[k] / times[k - 1]) / np.log(ns[k] / ns[k - 1])
            slope_l = np.log(loop_times[k] / loop_times[k - 1]) / np.log(ns[k] / ns[k - 1])
            print(f"  {solver:5s} exponent from n = {ns[k - 1]} to {ns[k]}: call {slope:.2f}, "
                  f"loop {slope_l:.2f}")  # fmt: skip
        if len(ns) > 1:
            fits[solver] = (
                np.polyfit(np.log(ns), np.log(times), 1)[0],
                np.polyfit(np.log(ns), np.log(loop_times), 1)[0],
            )
    for solver, (call, loop) in fits.items():
        print(f"  {solver:5s} least-squares exponent over all n: call {call:.2f}, loop {loop:.2f}")


def _panda_at_seed_0() -> tuple[Robot, gmuk.State]:
    """The Panda (tree solve) and its random state of seed 0 (Pinocchio's and numpy's)."""
    path, base, locked = ROBOTS["panda"]
    robot = Robot.from_urdf(example_robot_data(path), base=base, locked_joints=locked)
    pin.seed(0)
    model = robot.model
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    return robot, robot.state(q, np.random.default_rng(0).normal(size=model.nv))


def loop_rhs(repeat: int) -> None:
    """The compiled right-hand side of the Panda's step loop alone (the tree solve), and the
    poses by exp and dexp⁻¹ it takes, each called 20 000 times from a compiled loop."""
    from numba import njit

    from gmuk.engine.integrators import _compiled, get_method
    from gmuk.lie._kernels import _compose_exp_into, _dexp_inv_apply_into

    @njit
    def rhs_loop(n, Y, G0, parts, dY, aux, ints):
        for _ in range(n):
            _compiled.rhs(0.0, Y, G0, parts, dY, aux, ints)

    @njit
    def exp_loop(n, G0, xi, g):
        for _ in range(n):
            _compose_exp_into(G0, xi, g)

    @njit
    def dexp_loop(n, xi, V, out):
        for _ in range(n):
            _dexp_inv_apply_into(xi, V, out)

    robot, state = _panda_at_seed_0()
    prog = robot.system.compiled_program(get_method("DOP853"), state)
    _compiled.compile_loop()
    nr = len(robot.system.bodies)
    Y = np.zeros(prog.n)
    Y[: 6 * nr] = 1e-3  # ξ ≠ 0: the poses by exp and dexp⁻¹ are computed
    Y[6 * nr : 12 * nr] = np.asarray(state.V).ravel()
    G0 = np.array(state.g)
    xi, V = Y[: 6 * nr].reshape(nr, 6).copy(), Y[6 * nr : 12 * nr].reshape(nr, 6).copy()
    ints = np.zeros(_compiled.N_INTS, np.int64)
    cases = {
        "the right-hand side": (rhs_loop, (Y, G0, prog.parts, np.empty(prog.n),
                                           np.empty(prog.n_aux), ints)),
        "poses by exp": (exp_loop, (G0, xi, np.empty((nr, 4, 4)))),
        "dexp⁻¹": (dexp_loop, (xi, V, np.empty((nr, 6)))),
    }  # fmt: skip
    print("the Panda's compiled right-hand side, per call (medians of 20 000 calls)")
    for label, (loop, args) in cases.items():
        loop(10, *args)
        t = _median_s(lambda f=loop, a=args: f(20_000, *a), repeat, 1) / 20_000
        print(f"  {label:20s} {t * 1e6:6.2f} µs")


def drift_check(repeat: int) -> None:
    """A 1 s Panda run (tree solve, rtol = atol = 1e-10) with 101 and with 2 outputs, and the
    drift check at the end of each (:func:`gmuk.engine.integrate.check_drift`, up to 65
    sampled outputs) timed alone, batched and with each state through ``Joint.violation``."""
    from gmuk.engine.integrate import check_drift
    from gmuk.robots import Joint

    robot, state = _panda_at_seed_0()
    system = robot.system
    print("1 s Panda run and its drift check (medians)")
    for n in (101, 2):
        t = np.linspace(0.0, 1.0, n)
        traj = system.simulate(state, (0.0, 1.0), t_eval=t, rtol=1e-10, atol=1e-10)
        t_run = _median_s(
            lambda te=t: system.simulate(state, (0.0, 1.0), t_eval=te, rtol=1e-10, atol=1e-10),
            repeat,
            1,
        )
        t_check = _median_s(lambda tr=traj: check_drift(system, tr, 1e-6), repeat, 1)
        along = Joint._violation_along
        Joint._violation_along = lambda self, states: None  # each state through violation()
        try:
            t_one = _median_s(lambda tr=traj: check_drift(system, tr, 1e-6), repeat, 1)
        finally:
            Joint._violation_along = along
        print(f"  {n:3d} outputs: run {t_run * 1e3:6.1f} ms ({traj.stats['n_rhs']} "
              f"evaluations), drift check {t_check * 1e3:5.2f} ms (state by state: "
              f"{t_one * 1e3:5.2f} ms)")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--sizes", default="5,10,20,40,80,160,320,640,1000")
    parser.add_argument("--dense-max", type=int, default=40)
    parser.add_argument("--only", default="call,parts,rhs,run,chain", help="which measurements")
    args = parser.parse_args(argv)
    only = set(args.only.split(","))
    if "call" in only:
        one_call(args.repeat)
    if "parts" in only:
        breakdown(args.repeat)
    if "rhs" in only:
        loop_rhs(args.repeat)
    if "run" in only:
        panda_run(args.repeat)
    if "drift" in only:
        drift_check(args.repeat)
    if "chain" in only:
        scaling(args.repeat, tuple(int(s) for s in args.sizes.split(",")), args.dense_max)


if __name__ == "__main__":
    main()
