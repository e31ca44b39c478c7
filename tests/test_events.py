"""Events in ``simulate`` (gmuk.engine.events): located crossings, terminal and recorded
events, their direction filter, their place in the Trajectory, files and resumed runs."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gmuk
from gmuk import runs
from gmuk.engine.events import AltitudeEvent, ApsisEvent, Event
from gmuk.errors import DefinitionError, NonFiniteError, SimulationError
from gmuk.orbits import KeplerOrbit
from gmuk.trajectory import _ARRAYS

G = 9.80665
MU = 3.986004418e14


def _ball(h0=100.0, vz0=3.0):
    ball = gmuk.PointMass("ball", mass=2.0)
    system = gmuk.System(bodies=[ball], forces=[gmuk.UniformGravity(bodies=[ball])])
    state = system.state(r={"ball": [0.0, 0.0, h0]}, v={"ball": [1.0, 0.0, vz0]})
    return system, state


def _impact_time(h0=100.0, vz0=3.0):
    """The root t > 0 of h0 + vz0 t − g t²/2 = 0."""
    return (vz0 + math.sqrt(vz0 * vz0 + 2.0 * G * h0)) / G


def _ground(**kw):
    return Event(lambda t, s: s.position("ball")[2], name="impact", **kw)


@pytest.mark.parametrize("t_eval", [None, np.linspace(0.0, 10.0, 21)])
def test_a_falling_ball_stops_at_the_analytic_impact_time(t_eval):
    system, state = _ball()
    traj = system.simulate(state, (0.0, 10.0), t_eval=t_eval, events=[_ground(terminal=True)])
    t_hit = _impact_time()
    assert traj.status == "terminated" and traj.success
    assert "impact" in traj.message
    assert abs(traj.t[-1] - t_hit) <= 1e-12 * t_hit
    (event,) = traj.events
    assert (event.name, event.direction, event.terminal) == ("impact", -1, True)
    assert event.t == traj.t[-1]
    # the last output is the event's state: on the ground, with the analytic velocity
    np.testing.assert_array_equal(traj.x[-1], event.state.x)
    assert abs(traj.x[-1, 2]) < 1e-11
    np.testing.assert_allclose(traj.xdot[-1], [1.0, 0.0, 3.0 - G * t_hit], rtol=0, atol=1e-12)
    np.testing.assert_allclose(traj.acceleration[-1], [0.0, 0.0, -G], rtol=0, atol=1e-12)
    if t_eval is not None:  # the outputs before the impact, then the impact
        np.testing.assert_array_equal(traj.t[:-1], t_eval[t_eval < t_hit])


@pytest.mark.parametrize(("method", "step"), [("DOPRI5", None), ("RK4", 0.01)])
def test_methods_without_a_dense_output_locate_events_by_stepping(method, step):
    system, state = _ball()
    ground = AltitudeEvent("ball", radius=1e3, center=(0.0, 0.0, -1e3))  # a 1 km dome
    traj = system.simulate(state, (0.0, 10.0), method=method, step=step, events=[ground])
    assert traj.status == "terminated"
    r = traj.x[-1] - np.array([0.0, 0.0, -1e3])
    assert abs(np.linalg.norm(r) - 1e3) < 1e-9  # on the dome
    # each method is exact on this parabola: the step to the event is too
    flat = system.simulate(state, (0.0, 10.0), method=method, step=step,
                           events=[_ground(terminal=True)])  # fmt: skip
    assert abs(flat.t[-1] - _impact_time()) <= 1e-12 * _impact_time()


def _kepler(e=0.3, a=7.0e6, tau0_periods=-0.3):
    orbit = KeplerOrbit.from_elements(a, e, 0.4, 0.2, 1.1, MU)
    period = orbit.period
    r_N, v_N = orbit.state(tau0_periods * period)
    sat = gmuk.PointMass("sat", mass=10.0)
    system = gmuk.System(bodies=[sat], forces=[gmuk.PointMassGravity(MU)])
    state = system.state(r={"sat": r_N}, v={"sat": v_N})
    return system, state, orbit, -tau0_periods * period


def test_kepler_apsis_times_match_keplers_equation():
    system, state, orbit, _ = _kepler()
    period = orbit.period
    # the reference: the start's time since periapsis by Kepler's equation (gmuk.orbits)
    _, tau0 = KeplerOrbit.from_state(state.position("sat"), state.velocity("sat"), MU)
    t_peri = -tau0
    events = [ApsisEvent("sat", kind="periapsis"), ApsisEvent("sat", MU, kind="apoapsis")]
    traj = system.simulate(state, (0.0, 2.6 * period), rtol=1e-13, atol=1e-13, events=events)
    assert traj.status == "success"
    got = [(e.name, e.direction, e.t) for e in traj.events]
    expected = sorted(
        [("periapsis", 1, t_peri + k * period) for k in range(3)]
        + [("apoapsis", -1, t_peri + (k + 0.5) * period) for k in range(2)],
        key=lambda x: x[2],
    )
    assert [g[:2] for g in got] == [x[:2] for x in expected]
    for (_, _, t), (_, _, t_ref) in zip(got, expected, strict=True):
        assert abs(t - t_ref) < 2e-12 * period  # measured: 5e-13 at most
    for e in traj.events:  # the recorded states are at the apsides
        r = e.state.position("sat")
        expect = orbit.periapsis_radius if e.name == "periapsis" else orbit.a * (1 + orbit.e)
        assert abs(np.linalg.norm(r) - expect) < 1e-12 * expect  # the integration's error


def test_a_terminal_periapsis_ends_the_orbit_there():
    system, state, orbit, t_peri = _kepler()
    traj = system.simulate(
        state, (0.0, 2.0 * orbit.period), events=ApsisEvent("sat", terminal=True)
    )
    assert traj.status == "terminated"
    assert abs(traj.t[-1] - t_peri) < 1e-9 * orbit.period
    assert abs(np.linalg.norm(traj.x[-1]) - orbit.periapsis_radius) < 1e-9 * orbit.a


def _sine(direction, name="sine"):
    return Event(lambda t, s: math.sin(t), direction=direction, name=name)


@pytest.mark.parametrize(
    ("direction", "zeros"),
    [(1, [2 * math.pi]), (-1, [math.pi, 3 * math.pi]), (0, [math.pi, 2 * math.pi, 3 * math.pi])],
)
def test_the_direction_filter_keeps_rising_falling_or_both(direction, zeros):
    system, state = _ball(h0=1e3, vz0=0.0)
    # max_step below the time between crossings: a step holding two would cancel them
    traj = system.simulate(state, (0.5, 11.0), max_step=1.0, events=[_sine(direction)])
    assert [e.t for e in traj.events] == pytest.approx(zeros, rel=0, abs=1e-12)
    assert all(e.direction == (1 if abs(e.t - 2 * math.pi) < 1 else -1) for e in traj.events)
    assert traj.status == "success" and traj.t[-1] == 11.0


def test_two_events_in_one_step_are_both_located_in_time_order():
    system, state = _ball()
    first = Event(lambda t, s: t - 1.0, name="first")
    second = Event(lambda t, s: t - (1.0 + 1e-7), name="second")
    # given in the other order; the steps of this run are far longer than 1e-7 s
    traj = system.simulate(state, (0.0, 3.0), events=[second, first])
    assert [e.name for e in traj.events] == ["first", "second"]
    assert traj.events[0].t == pytest.approx(1.0, abs=1e-13)
    assert traj.events[1].t == pytest.approx(1.0 + 1e-7, abs=1e-13)
    assert not np.any((traj.t >= 1.0) & (traj.t <= 1.0 + 1e-7))  # one step held both
    # a terminal event keeps the recorded ones before it in its step, none after it
    later = Event(lambda t, s: t - (1.0 + 2e-7), name="later")
    stop = Event(lambda t, s: t - (1.0 + 1e-7), terminal=True, name="stop")
    traj = system.simulate(state, (0.0, 3.0), events=[later, stop, first])
    assert [e.name for e in traj.events] == ["first", "stop"]
    assert traj.t[-1] == traj.events[-1].t == pytest.approx(1.0 + 1e-7, abs=1e-13)


def test_an_event_exactly_at_the_start_is_not_triggered():
    system, state = _ball()
    at_start = Event(lambda t, s: t - 0.25, terminal=True, name="at start")
    leaves = Event(lambda t, s: math.sin(8 * (t - 0.25)), name="leaves zero")
    traj = system.simulate(state, (0.25, 1.0), events=[at_start, leaves])
    assert traj.status == "success"
    assert [e.name for e in traj.events] == ["leaves zero"]  # at π/8 after the start only
    assert traj.events[0].t == pytest.approx(0.25 + math.pi / 8, abs=1e-12)


@pytest.mark.parametrize("t_eval", [None, np.linspace(0.0, 4.0, 9)])
def test_recorded_events_change_none_of_the_trajectorys_numbers(t_eval):
    system, state = _ball()
    plain = system.simulate(state, (0.0, 4.0), t_eval=t_eval)
    watched = system.simulate(
        state, (0.0, 4.0), t_eval=t_eval,
        events=[_ground(), Event(lambda t, s: s.velocity("ball")[2], name="top")],
    )  # fmt: skip
    assert [e.name for e in watched.events] == ["top"]
    assert watched.events[0].t == pytest.approx(3.0 / G, abs=1e-12)
    for name in _ARRAYS:
        a, b = getattr(plain, name), getattr(watched, name)
        assert a.shape == b.shape and a.tobytes() == b.tobytes(), name
    for key in ("n_rhs", "n_steps", "n_rejected"):
        assert plain.stats[key] == watched.stats[key]
    assert watched.stats["n_event_rhs"] > 0 and "n_event_rhs" not in plain.stats


def test_events_on_a_rigid_body_use_its_origin_and_inertial_velocity():
    body = gmuk.RigidBody("sc", mass=5.0, inertia=np.diag([1.0, 2.0, 3.0]))
    system = gmuk.System(bodies=[body], forces=[gmuk.PointMassGravity(MU)])
    orbit = KeplerOrbit.from_elements(7.0e6, 0.2, 0.3, 0.0, 0.5, MU)
    r_N, v_N = orbit.state(-0.1 * orbit.period)
    R_NB = gmuk.lie.so3.exp(np.array([0.3, -0.2, 0.5]))
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = R_NB, r_N
    V_B = np.concatenate([[0.01, 0.02, -0.01], R_NB.T @ v_N])
    state = system.state(g={"sc": g}, V={"sc": V_B})
    low = orbit.periapsis_radius + 1e3  # 1 km above periapsis: crossed down, then up
    traj = system.simulate(
        state, (0.0, 0.5 * orbit.period),
        events=[ApsisEvent(body), AltitudeEvent(body, low, direction=0, terminal=False)],
    )  # fmt: skip
    names = [e.name for e in traj.events]
    assert names == ["altitude", "periapsis", "altitude"]
    assert traj.events[1].t == pytest.approx(0.1 * orbit.period, abs=1e-6)
    assert [e.direction for e in traj.events] == [-1, 1, 1]
    for e in (traj.events[0], traj.events[2]):
        assert abs(np.linalg.norm(e.state.position("sc")) - low) < 1e-6


def test_events_are_saved_and_loaded_with_their_states(tmp_path):
    system, state = _ball()
    top = Event(lambda t, s: s.velocity("ball")[2], name="top")
    traj = system.simulate(state, (0.0, 10.0), events=[top, _ground(terminal=True)])
    assert [e.name for e in traj.events] == ["top", "impact"]
    assert "Events:" in traj.summary() and "'impact'" in traj.summary()
    loaded = gmuk.load_trajectory(traj.save(tmp_path / "ball.npz"))
    assert loaded.status == "terminated"
    assert [e.to_dict() for e in loaded.events] == [e.to_dict() for e in traj.events]
    for a, b in zip(loaded.events, traj.events, strict=True):
        for key in ("g", "V", "x", "xdot", "z"):
            assert getattr(a.state, key).tobytes() == getattr(b.state, key).tobytes()
        assert a.state.t == b.t
    plain = system.simulate(state, (0.0, 1.0))
    assert gmuk.load_trajectory(plain.save(tmp_path / "plain.npz")).events == ()


def test_a_file_with_broken_events_is_refused(tmp_path):
    import zipfile

    system, state = _ball()
    traj = system.simulate(state, (0.0, 10.0), events=[_ground(terminal=True)])
    path = traj.save(tmp_path / "ball.npz")
    with np.load(path) as f:
        members = {k: f[k] for k in f.files}
    meta = json.loads(str(members["meta"][()]))
    for edit, words in [
        (lambda m: m["events"][0].update(direction=2), "direction must be -1 or 1"),
        (lambda m: m["events"][0].update(t=1.0), "must be the last output's time"),
        (lambda m: m["events"][0]["state"].update(x=[1.0, float("nan"), 0.0]), "finite"),
        (lambda m: m.update(events={"a": 1}), "events must be a list"),
    ]:
        bad = json.loads(json.dumps(meta))
        edit(bad)
        out = tmp_path / "bad.npz"
        np.savez(out, **{**members, "meta": np.array(json.dumps(bad))})
        with pytest.raises(gmuk.errors.FileFormatError, match=words):
            gmuk.load_trajectory(out)
    assert zipfile.is_zipfile(path)


def test_bad_events_are_refused_with_what_came_in():
    system, state = _ball()
    with pytest.raises(DefinitionError, match=r"must be callable.*got int"):
        Event(3)
    with pytest.raises(DefinitionError, match="needs a function"):
        Event()
    with pytest.raises(DefinitionError, match=r"direction must be -1 .* got 2"):
        Event(lambda t, s: t, direction=2)
    with pytest.raises(DefinitionError, match="direction"):
        Event(lambda t, s: t, direction=True)
    with pytest.raises(DefinitionError, match="terminal"):
        Event(lambda t, s: t, terminal=1)
    with pytest.raises(DefinitionError, match="kind must be"):
        ApsisEvent("ball", kind="perigee")
    with pytest.raises(DefinitionError, match=r"events must be gmuk.Event.*0: function"):
        system.simulate(state, (0.0, 1.0), events=[lambda t, s: t])
    with pytest.raises(DefinitionError, match=r"distinct names.*'x'"):
        system.simulate(state, (0.0, 1.0), events=[Event(math.sin, name="x")] * 2)
    with pytest.raises(
        DefinitionError, match=r"event 'arr' must return one real number .* shape \(3,\)"
    ):
        system.simulate(state, (0.0, 1.0), events=Event(lambda t, s: s.x, name="arr"))
    with pytest.raises(DefinitionError, match="'flag' must return one real number"):
        system.simulate(state, (0.0, 1.0), events=Event(lambda t, s: True, name="flag"))
    with pytest.raises(NonFiniteError, match="event 'nan' returned nan at t = 0 s"):
        system.simulate(state, (0.0, 1.0), events=Event(lambda t, s: math.nan, name="nan"))
    late_nan = Event(lambda t, s: math.nan if t > 0.5 else 1.0, name="late")
    with pytest.raises(SimulationError, match="event 'late' returned nan at t = "):
        system.simulate(state, (0.0, 1.0), events=late_nan)
    traj = system.simulate(state, (0.0, 1.0), events=late_nan, on_failure="return")
    assert traj.status == "failed" and traj.t[-1] > 0.5  # the step that met the NaN is kept
    assert "event 'late' returned nan" in traj.message


class _StoppingApsides(ApsisEvent):
    """Periapsis and apoapsis; asks the enclosing run to stop once t passes ``t_stop``."""

    t_stop = 1e99

    def value(self, t, state):
        control = runs.current()
        if control is not None and t > self.t_stop:
            control.request_stop()
        return super().value(t, state)


def test_a_resumed_run_neither_loses_nor_repeats_recorded_events(tmp_path):
    system, state, orbit, _ = _kepler()
    span = (0.0, 3.2 * orbit.period)
    t_eval = np.linspace(*span, 50)
    plain = system.simulate(state, span, t_eval=t_eval, events=_StoppingApsides("sat", kind="both"))
    assert len(plain.events) == 6
    stopping = _StoppingApsides("sat", kind="both")
    stopping.t_stop = 1.6 * orbit.period  # between the third and fourth apsis
    with runs.run_control(tmp_path, every_s=3600.0):
        cut = system.simulate(state, span, t_eval=t_eval, events=stopping)
    assert cut.status == "interrupted" and len(cut.events) == 3
    saved = gmuk.load_trajectory(tmp_path / "run-0.npz")
    assert [e.t for e in saved.events] == [e.t for e in cut.events]
    with runs.run_control(tmp_path, resume=True):
        resumed = system.simulate(state, span, t_eval=t_eval,
                                  events=_StoppingApsides("sat", kind="both"))  # fmt: skip
    assert resumed.status == "success"
    assert [e.name for e in resumed.events] == [e.name for e in plain.events]
    np.testing.assert_allclose(
        [e.t for e in resumed.events], [e.t for e in plain.events], rtol=0, atol=1e-6
    )
    # other events: another simulation, refused
    with runs.run_control(tmp_path, resume=True), pytest.raises(runs.CheckpointError):
        system.simulate(state, span, t_eval=t_eval, events=ApsisEvent("sat", kind="both"))


def test_a_terminated_run_checkpoints_complete_and_resumes_without_integrating(tmp_path):
    system, state = _ball()
    t_eval = np.linspace(0.0, 10.0, 21)
    with runs.run_control(tmp_path, every_s=1e-9, events=[_ground(terminal=True)]):
        first = system.simulate(state, (0.0, 10.0), t_eval=t_eval)
    assert first.status == "terminated"
    record = gmuk.load_trajectory(tmp_path / "run-0.npz").stats["checkpoint"]
    assert record["complete"] is True and record["t"] == first.t[-1]
    with runs.run_control(tmp_path, resume=True, events=[_ground(terminal=True)]):
        again = system.simulate(state, (0.0, 10.0), t_eval=t_eval)
    assert again.status == "terminated" and again.t.tobytes() == first.t.tobytes()
    assert [e.to_dict() for e in again.events] == [e.to_dict() for e in first.events]


# --- the command line: --stop-at and summary.json ------------------------------------------


def _throw_run(duration: float = 5.0):
    """A ball thrown up at 3 m/s from 100 m, its top recorded (a scenario of this test)."""
    from gmuk.scenarios import ScenarioResult

    system, state = _ball()
    top = Event(lambda t, s: s.velocity("ball")[2], name="top")
    traj = system.simulate(state, (0.0, duration), t_eval=np.linspace(0.0, duration, 11),
                           events=[top])  # fmt: skip
    return ScenarioResult("throw", {"throw": traj}, "throw", {"height_m": float(traj.x[-1, 2])})


def _throw_scenario():
    from gmuk.scenarios import Option, Scenario

    return Scenario(
        "throw", "a ball thrown up", _throw_run, lambda result, out, formats: [],
        options=(Option("duration", float, 5.0, "simulated time (s)"),),
    )  # fmt: skip


THROW = _throw_scenario()


@pytest.fixture
def throw(monkeypatch):
    from gmuk import scenarios

    monkeypatch.setitem(scenarios.SCENARIOS, "throw", f"{__name__}:THROW")
    scenarios.refresh()
    yield
    scenarios.refresh()


def test_gmuk_run_stop_at_ends_the_run_there_and_summary_json_lists_the_events(
    throw, tmp_path, capsys
):
    from gmuk import cli

    out = tmp_path / "run"
    assert cli.main(["run", "throw", "--stop-at", "1.5", "--no-plots", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "terminated" and summary["t_reached_s"] == pytest.approx(1.5)
    top, stop = summary["events"]["throw"]
    assert (top["name"], top["direction"], top["terminal"]) == ("top", -1, False)
    assert top["t"] == pytest.approx(3.0 / G, abs=1e-12)
    assert (stop["name"], stop["direction"], stop["terminal"]) == ("stop_at", 1, True)
    assert abs(stop["t"] - 1.5) <= 1e-13
    traj = gmuk.load_trajectory(out / "trajectory.npz")
    assert traj.status == "terminated" and traj.t[-1] == stop["t"]
    assert not (out / ".checkpoints").exists()  # complete: the checkpoints are spent
    # without --stop-at: the whole span, the scenario's own event only
    assert cli.main(["run", "throw", "--no-plots", "--out", str(tmp_path / "full")]) == 0
    full = json.loads((tmp_path / "full" / "summary.json").read_text())
    assert full["status"] == "success" and [e["name"] for e in full["events"]["throw"]] == ["top"]
    # --resume takes the stop time the run was started with (its run.json), never a new one
    out.mkdir(exist_ok=True)
    (out / ".checkpoints").mkdir()
    (out / ".checkpoints" / "run.json").write_text(json.dumps({"scenario": "throw",
                                                               "options": {}}))  # fmt: skip
    assert cli.main(["run", "--resume", str(out), "--stop-at", "2"]) == 2
    assert "give no --stop-at" in capsys.readouterr().err
    killed = tmp_path / "killed"  # a run killed before its first checkpoint
    (killed / ".checkpoints").mkdir(parents=True)
    record = {"scenario": "throw", "options": {"duration": "5"}, "stop_at": 1.5}
    (killed / ".checkpoints" / "run.json").write_text(json.dumps(record))
    assert cli.main(["run", "--resume", str(killed), "--no-plots"]) == 0
    again = json.loads((killed / "summary.json").read_text())
    assert again["status"] == "terminated" and again["events"] == summary["events"]


def test_the_docs_page_runs_as_written_and_prints_what_it_says(capsys):
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "events.rst").read_text()
    blocks = re.findall(r"^\.\. code-block:: python\n\n((?:(?: {3}.*)?\n)+)", page, re.M)
    assert blocks
    namespace: dict = {}
    for i, block in enumerate(blocks):
        code = "\n".join(line[3:] for line in block.splitlines())
        exec(compile(code, f"docs/events.rst, block {i}", "exec"), namespace)
    printed = capsys.readouterr().out.strip()
    assert f"which prints ``{printed}``" in " ".join(page.split())
    assert namespace["traj"].status == "terminated"


class _PythonWeight(gmuk.ForceModel):
    """m g_N written in Python (no compiled form): the loop calls it back, also while an
    event is located."""

    def force(self, t, r_N, v_N, body):
        return body.mass * np.array([0.0, 0.0, -G])


def test_events_are_located_with_parts_evaluated_in_python():
    ball = gmuk.PointMass("ball", mass=2.0)
    system = gmuk.System(bodies=[ball], forces=[_PythonWeight()])
    state = system.state(r={"ball": [0.0, 0.0, 100.0]}, v={"ball": [1.0, 0.0, 3.0]})
    traj = system.simulate(state, (0.0, 10.0), events=[_ground(terminal=True, direction=-1)])
    assert traj.status == "terminated"
    assert abs(traj.t[-1] - _impact_time()) <= 1e-12 * _impact_time()
    assert traj.stats["n_event_rhs"] > 0


class _FailingWeight(_PythonWeight):
    """Fails at any time that is not a multiple of 0.5 s: never in the steps of RK4 with a
    step of 1 s (stages at t, t + 0.5, t + 1), always when an event is located in one."""

    def force(self, t, r_N, v_N, body):
        if 2.0 * t != round(2.0 * t):
            raise RuntimeError(f"no force at t = {t} s")
        return super().force(t, r_N, v_N, body)


def test_a_part_failing_while_an_event_is_located_fails_the_run_with_its_error():
    ball = gmuk.PointMass("ball", mass=2.0)
    system = gmuk.System(bodies=[ball], forces=[_FailingWeight()])
    state = system.state(r={"ball": [0.0, 0.0, 100.0]}, v={"ball": [1.0, 0.0, 3.0]})
    plain = system.simulate(state, (0.0, 6.0), method="RK4", step=1.0)
    assert plain.status == "success"
    with pytest.raises(SimulationError, match=r"no force at t = 4\.") as info:
        system.simulate(state, (0.0, 6.0), method="RK4", step=1.0,
                        events=[_ground(terminal=True)])  # fmt: skip
    partial = info.value.trajectory
    assert partial.status == "failed" and partial.t[-1] == 5.0  # the step is kept


class _OffsetWall(gmuk.HolonomicConstraint):
    """x = 0 for a point mass with a bias off by ``error`` (m/s²): φ = ½·error·t², a drift."""

    def __init__(self, body, error):
        super().__init__([body])
        self.error = error

    def residual(self, q, t):
        return np.array([q[0][0]])

    def jacobian(self, q, t):
        return np.array([[1.0, 0.0, 0.0]])

    def bias(self, q, nu, t):
        return np.array([self.error])

    def rate(self, q, nu, t):
        return np.array([nu[0][0]])


def test_a_run_ended_by_its_event_off_its_constraint_is_drifted_not_terminated():
    p = gmuk.PointMass("p", 2.0)
    system = gmuk.System([p], [_OffsetWall(p, 1e-3)], [gmuk.UniformGravity((0, 0, -1.0))])
    state = system.state(r={"p": [0.0, 0.0, 1.0]}, v={"p": [0.0, 1.0, 0.0]})
    floor = Event(lambda t, s: s.position("p")[2], terminal=True, direction=-1, name="floor")
    with pytest.warns(gmuk.errors.GmukWarning, match="drifted off"):
        traj = system.simulate(state, (0.0, 5.0), events=[floor])
    assert traj.status == "drifted" and not traj.success
    assert traj.message.startswith("terminal event 'floor' at t = ")
    assert traj.t[-1] == pytest.approx(math.sqrt(2.0), abs=1e-12)  # z = 1 − t²/2
    assert traj.events[-1].terminal
