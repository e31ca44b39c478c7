"""``print(traj)`` is one screen (issue #26, item 8): a summary of the run, not its arrays."""

from __future__ import annotations

import dataclasses

import numpy as np

import gmuk
from gmuk.trajectory import _ARRAYS


class Distance(gmuk.HolonomicConstraint):
    def __init__(self, a, b, d):
        super().__init__([a, b])
        self.d = d

    def residual(self, q, t):
        g_a, g_b = q
        e = g_a[:3, 3] - g_b[:3, 3]
        return np.array([e @ e - self.d**2])


def dumbbell_run(**options):
    a = gmuk.RigidBody("a", mass=2.0, inertia=np.diag([1.0, 2.0, 3.0]))
    b = gmuk.RigidBody("b", mass=1.0, inertia=np.eye(3))
    p = gmuk.PointMass("probe", mass=0.5)
    rod = Distance(a, b, 1.0, baumgarte=gmuk.Baumgarte.critical(10.0), name="rod")
    system = gmuk.System([a, b, p], [rod], [gmuk.UniformGravity()])
    g_b = np.eye(4)
    g_b[0, 3] = 1.0
    state = system.state(
        g={"a": np.eye(4), "b": g_b},
        V={"a": np.zeros(6), "b": [0.0, 0.0, 0.3, 0.0, 1.0, 0.0]},
        r={"probe": [0.0, 0.0, 5.0]},
        v={"probe": [1.0, 0.0, 0.0]},
    )
    return system.simulate(state, (0.0, 2.0), t_eval=np.linspace(0.0, 2.0, 41), **options)


def test_the_summary_is_one_screen_and_states_the_run():
    traj = dumbbell_run()
    text = str(traj)
    lines = text.splitlines()
    assert len(lines) <= 15 and max(map(len, lines)) <= 100, text
    assert repr(traj) == text == traj.summary()
    assert lines[0] == "<gmuk.Trajectory: success, 41 samples, t = 0 … 2 s>"
    assert "Bodies (3):   a, b (rigid); probe (point)" in lines
    assert f"Constraints:  1 row, largest residual ‖A ν̇ − b‖ {traj.residual.max():.2e}" in lines
    check = traj.stats["constraint_violation"]
    assert (
        f"Drift check:  position ≤ {check['position']:.2e}, velocity ≤ {check['velocity']:.2e} "
        "(1 checked; drift_tol 1e-06: held)"
    ) in lines
    st = traj.stats
    assert "Integration:  DOP853, rtol 1e-10, atol 1e-10, compiled loop" in lines
    assert (
        f"Steps:        {st['n_steps']} ({st['n_rejected']} rejected), {st['n_rhs']} evaluations "
        "of the dynamics"
    ) in lines
    nbytes = sum(getattr(traj, k).nbytes for k in _ARRAYS)
    assert 5_000 < nbytes < 50_000
    assert f"Size:         {nbytes / 1e3:.1f} kB in 14 arrays" in lines
    assert "array(" not in text and "Message" not in text
    assert repr(traj.body("probe")) == "<gmuk.BodyTrajectory 'probe' (point), 41 samples>"


def test_a_loaded_run_prints_the_same(tmp_path):
    traj = dumbbell_run(drift_tol=None)
    assert "(1 checked; not judged)" in str(traj)
    back = gmuk.load_trajectory(traj.save(tmp_path / "run.npz"))
    assert str(back) == str(traj)


def test_many_bodies_a_long_message_and_no_samples_stay_on_one_screen():
    bodies = [gmuk.PointMass(f"p{i:02d}", mass=1.0) for i in range(40)]
    system = gmuk.System(bodies)
    state = system.state(r={b.name: [i, 0.0, 0.0] for i, b in enumerate(bodies)},
                         v={b.name: [0.0, 1.0, 0.0] for b in bodies})  # fmt: skip
    traj = system.simulate(state, (0.0, 1.0), t_eval=[0.0, 1.0])
    failed = dataclasses.replace(traj, status="failed", message="step-size underflow " * 40)
    text = str(failed)
    lines = text.splitlines()
    assert len(lines) <= 15 and max(map(len, lines)) <= 200
    assert lines[0] == "<gmuk.Trajectory: failed, 2 samples, t = 0 … 1 s>"
    assert "Bodies (40):  p00, p01, p02, p03, p04, p05, p06, p07 (point); … +32 more" in lines
    assert "Constraints:  none" in lines
    (message,) = [line for line in lines if line.startswith("Message:")]
    assert message.endswith("…") and len(message) == 14 + 160
    empty = dataclasses.replace(traj, **{k: getattr(traj, k)[:0] for k in _ARRAYS})
    assert str(empty).splitlines()[0] == "<gmuk.Trajectory: success, 0 samples, no samples>"
    assert "Size:         0 B in 14 arrays" in str(empty)
