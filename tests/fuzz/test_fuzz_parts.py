"""Fuzz the compiled loop through user parts written in Python (issue #25): force models,
controllers, constraints and inequality constraints whose callbacks return hostile values
(wrong shapes, NaN, complex numbers, strings, booleans, objects), raise, or write into the
arrays they are given, from their first call or only from their k-th one.

The oracle, for every simulation:

* the outcome is a Trajectory or a :class:`gmuk.errors.GmukError` (a SimulationError
  naming what the part did); nothing else leaves ``simulate``, and nothing hangs;
* a run that reports ``success`` had parts that only ever returned honest real values
  of the right shape, finite, and never raised: its trajectory is bit-identical to the run
  of the same system whose part replays those values as float arrays (nothing was
  reinterpreted), and the caller's initial State is unchanged;
* a run whose parts were honest all along is not refused (unless the values are so large
  that the motion itself overflows).

The free rigid body's energy and angular momentum, the compiled loop against the Python
reference loop, and honest inequality constraints (the bound holds) are checked here too.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from fuzz_inputs import (
    REFUSED,
    arrays,
    fuzz_pair,
    honest_real,
    junk,
    outcome,
    regular_array,
    scalars,
)
from hypothesis import strategies as st

import gmuk
from gmuk.errors import GmukError
from gmuk.testing import reference_simulate

J_A = np.diag([1.0, 2.0, 2.5])
V_A = np.array([0.1, 0.2, 0.3, 1.0, 0.0, 0.0])
SPAN = (0.0, 1e-3)
RUN = {"method": "RK4", "step": 2.5e-4, "max_steps": 50}


class PartFailure(Exception):
    """The user's own exception, raised by a hostile part."""


def _honest(value: Any, shape: tuple[int, ...]) -> bool:
    """Honest real data of exactly ``shape``, finite and of moderate size."""
    if not honest_real(value):
        return False
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        return False
    return a.shape == shape and bool(np.isfinite(a).all()) and np.abs(a).max(initial=0) < 1e6


def _acceptable(value: Any, shape: tuple[int, ...]) -> bool:
    """What may be accepted: honest real data of ``shape`` (any finite size)."""
    a = regular_array(value, shape)
    return a is not None and bool(np.isfinite(a).all())


class Script:
    """What a hostile part does at each call: honest ``good`` values before call ``k``,
    then ``how`` ("return" ``value``, "raise", "mutate" its inputs) from call ``k`` on
    (or only at call ``k`` with ``once``). Records every value it returned."""

    def __init__(self, how: str, value: Any, k: int, once: bool, good: Any) -> None:
        self.how, self.value, self.k, self.once, self.good = how, value, k, once, good
        self.calls = 0
        self.returned: list[Any] = []
        self.raised = False
        self.mutated = False

    def hostile_now(self) -> bool:
        n = self.calls
        return n == self.k if self.once else n >= self.k

    def __call__(self, *inputs: Any) -> Any:
        hostile = self.hostile_now()
        self.calls += 1
        if hostile and self.how == "raise":
            self.raised = True
            raise PartFailure("a part that raises")
        if hostile and self.how == "mutate":
            for a in inputs:
                if isinstance(a, np.ndarray) and a.size:
                    try:
                        a[...] = 0.5  # write into what we were given
                        self.mutated = True
                    except ValueError:  # read-only: the part cannot change it
                        pass
        out = self.value if hostile and self.how == "return" else self.good
        self.returned.append(out)
        return out

    def honest(self, shape: tuple[int, ...]) -> bool:
        return not self.raised and all(_honest(v, shape) for v in self.returned)

    def acceptable(self, shape: tuple[int, ...]) -> bool:
        return not self.raised and all(_acceptable(v, shape) for v in self.returned)


class Replay:
    """Returns, call by call, float copies of what a Script returned."""

    def __init__(self, values: list[Any]) -> None:
        self.values = [np.array(v, dtype=float) for v in values]
        self.calls = 0

    def __call__(self, *inputs: Any) -> Any:
        i = min(self.calls, len(self.values) - 1)
        self.calls += 1
        return self.values[i].copy()


class ScriptedForce(gmuk.ForceModel):
    def __init__(self, script: Any) -> None:
        super().__init__(name="scripted force")
        self.script = script

    def wrench(self, t, g_NB, V_B, body):
        return self.script(g_NB, V_B)

    def force(self, t, r_N, v_N, body):
        return self.script(r_N, v_N)


class ScriptedController(gmuk.Controller):
    def __init__(self, body: str, script: Any, n_states: int) -> None:
        super().__init__([body], n_states=n_states, name="scripted controller")
        self.script = script

    def control(self, state, z):
        return self.script(z, state.x, state.V)


class ScriptedRows(gmuk.Constraint):
    def __init__(self, body: str, script: Any) -> None:
        super().__init__([body], name="scripted rows")
        self.script = script

    def rows(self, state):
        return self.script(state.x, state.V)


class ScriptedBound(gmuk.InequalityConstraint):
    """h = the body's x coordinate (or whatever the script says) ≥ -10."""

    def __init__(self, body: str, script: Any) -> None:
        super().__init__([body], lower=-10.0, name="scripted bound")
        self.script = script

    def value(self, q, nu, t):
        return self.script(*[np.asarray(x) for x in q])


def _system(kind: str, parts: dict[str, Any]) -> tuple[gmuk.System, gmuk.State]:
    if kind == "rigid":
        bodies = [gmuk.RigidBody("a", 1.0, J_A)]
    else:
        bodies = [gmuk.PointMass("a", 2.0)]
    system = gmuk.System(bodies, **parts)
    if kind == "rigid":
        state = system.state(g={"a": np.eye(4)}, V={"a": V_A})
    else:
        state = system.state(r={"a": [1.0, 0.0, 0.0]}, v={"a": [0.0, 1.0, 0.5]})
    return system, state


def _snapshot(state: gmuk.State) -> list[np.ndarray]:
    return [np.array(a, copy=True) for a in (state.g, state.V, state.x, state.xdot, state.z)]


def _same_state(state: gmuk.State, snap: list[np.ndarray]) -> bool:
    now = (state.g, state.V, state.x, state.xdot, state.z)
    return all(np.array_equal(a, b) for a, b in zip(now, snap, strict=True))


def _simulate(entry: str, system, state, on_failure: str) -> Any:
    """simulate under the rule; a PartFailure coming back unwrapped counts as a refusal."""

    def call():
        try:
            return system.simulate(state, SPAN, on_failure=on_failure, **RUN)
        except PartFailure:
            return REFUSED

    out = outcome(entry, call, hang_s=30.0)
    if out is not REFUSED and out.status == "drifted":  # flagged: off its constraint
        return REFUSED
    if out is not REFUSED and out.status != "success":
        assert on_failure == "return", f"{entry}: status {out.status!r} without on_failure"
        assert out.message, f"{entry}: a failed run without a message"
        return REFUSED
    return out


def _same_trajectory(a, b, entry: str) -> None:
    for name in ("t", "x", "g_NB", "V_B", "multipliers"):
        x, y = getattr(a, name), getattr(b, name)
        assert np.array_equal(x, y), f"{entry}: {name} differs from the honest replay"


behaviours = st.sampled_from(["return"] * 6 + ["raise", "mutate"])
calls_k = st.sampled_from([0, 0, 1, 3, 10])


def _check_scripted(entry, kind, make_parts, script, shape, on_failure, replay_parts) -> None:
    system, state = _system(kind, make_parts(script))
    snap = _snapshot(state)
    traj = _simulate(entry, system, state, on_failure)
    assert _same_state(state, snap), f"{entry}: the part changed the caller's initial State"
    if traj is REFUSED:
        assert not script.honest(shape) or script.mutated, (
            f"{entry}: refused a part that returned only honest values {script.returned!r:.300}"
        )
        return
    assert not script.raised, f"{entry}: the part raised, yet the run reports success"
    assert script.acceptable(shape), (
        f"{entry}: accepted {[v for v in script.returned if not _acceptable(v, shape)]!r:.300}"
    )
    # nothing reinterpreted: the honest replay of the same values gives the same bits
    system2, state2 = _system(kind, replay_parts(script.returned))
    again = system2.simulate(state2, SPAN, **RUN)
    _same_trajectory(traj, again, entry)


# ------------------------------------------------------------------------ force models
def check_force(args) -> None:
    kind, how, value, k, once, on_failure = args
    dof = 6 if kind == "rigid" else 3
    good = np.linspace(-0.3, 0.4, dof)
    script = Script(how, value, k, once, good)
    _check_scripted(
        f"compiled loop: ForceModel ({kind})",
        kind,
        lambda s: {"forces": [ScriptedForce(s)]},
        script,
        (dof,),
        on_failure,
        lambda r: {"forces": [ScriptedForce(Replay(r))]},
    )


force_args = st.tuples(st.sampled_from(["rigid", "point"]), behaviours).flatmap(
    lambda kb: st.tuples(
        st.just(kb[0]),
        st.just(kb[1]),
        arrays((6,) if kb[0] == "rigid" else (3,)),
        calls_k,
        st.booleans(),
        st.sampled_from(["raise", "return"]),
    )
)

(
    test_force_model_callbacks_are_checked_in_the_compiled_loop,
    test_force_model_callbacks_are_checked_in_the_compiled_loop_slow,
) = fuzz_pair(force_args, check_force, fast=40, slow=4000)


# ------------------------------------------------------------------------- controllers
def _control_value(u: Any, z_dot: Any, form: str) -> Any:
    if form == "tuple":
        return (u, z_dot)
    if form == "list":
        return [u, z_dot]
    if form == "bare":
        return u
    if form == "triple":
        return (u, z_dot, z_dot)
    return form  # junk


class ControlScript(Script):
    """A controller's (u, ż): honest is ([u] with u of the body's dof, ż of n_states)."""

    def __init__(self, how, value, k, once, dof, n_states):
        good = ([np.linspace(-0.1, 0.1, dof)], np.full(n_states, 0.25))
        super().__init__(how, value, k, once, good)
        self.dof, self.n_states = dof, n_states

    def _ok(self, out: Any, check) -> bool:
        if not isinstance(out, (tuple, list)) or len(out) != 2:
            return False
        u, z_dot = out
        if isinstance(u, np.ndarray) and u.ndim == 2 and u.shape[0] == 1:
            u = [u[0]]  # a 2-D array of one row is a sequence of one wrench
        if not isinstance(u, (tuple, list)) or len(u) != 1:
            return False
        # ż may have any shape with n_states entries (a column, or 0-d for one state), as
        # the System documents; the values must be as honest as u's
        if isinstance(z_dot, (np.ndarray, np.generic, float, int)) and np.size(z_dot) == (
            self.n_states
        ):
            z_dot = np.reshape(z_dot, -1)
        return check(u[0], (self.dof,)) and check(z_dot, (self.n_states,))

    def honest(self, shape=None) -> bool:
        return not self.raised and all(self._ok(v, _honest) for v in self.returned)

    def acceptable(self, shape=None) -> bool:
        return not self.raised and all(self._ok(v, _acceptable) for v in self.returned)


class ControlReplay(Replay):
    def __init__(self, values):
        self.values = [([np.array(v[0][0], float)], np.array(v[1], float)) for v in values]
        self.calls = 0

    def __call__(self, *inputs):
        i = min(self.calls, len(self.values) - 1)
        self.calls += 1
        u, z_dot = self.values[i]
        return [u[0].copy()], z_dot.copy()


def check_controller(args) -> None:
    kind, n_states, how, u, z_dot, form, k, once, on_failure = args
    dof = 6 if kind == "rigid" else 3
    value = _control_value(u, z_dot, form)
    script = ControlScript(how, value, k, once, dof, n_states)
    _check_scripted(
        f"compiled loop: Controller ({kind})",
        kind,
        lambda s: {"controllers": [ScriptedController("a", s, n_states)]},
        script,
        None,
        on_failure,
        lambda r: {"controllers": [ScriptedController("a", ControlReplay(r), n_states)]},
    )


def _controller_args(kind_n):
    kind, n = kind_n
    dof = 6 if kind == "rigid" else 3
    return st.tuples(
        st.just(kind),
        st.just(n),
        behaviours,
        st.one_of(
            arrays((dof,)).map(lambda a: [a]),
            arrays((dof,)),
            st.lists(arrays((dof,)), min_size=0, max_size=2),
            junk,
        ),
        arrays((n,)) if n else st.one_of(st.just(np.zeros(0)), arrays((1,)), st.just([])),
        st.sampled_from(["tuple"] * 4 + ["list", "bare", "triple", "junk"]),
        calls_k,
        st.booleans(),
        st.sampled_from(["raise", "return"]),
    )


controller_args = st.tuples(
    st.sampled_from(["rigid", "point"]), st.sampled_from([0, 1, 2])
).flatmap(_controller_args)

(
    test_controller_callbacks_are_checked_in_the_compiled_loop,
    test_controller_callbacks_are_checked_in_the_compiled_loop_slow,
) = fuzz_pair(controller_args, check_controller, fast=40, slow=3000)


# ------------------------------------------------------------------ constraints' rows
class RowsScript(Script):
    """rows() → (A, b): honest is A (1, dof), b (1,) real and finite."""

    def __init__(self, how, value, k, once, dof):
        good = (np.eye(dof)[:1], np.zeros(1))
        super().__init__(how, value, k, once, good)
        self.dof = dof

    def _ok(self, out, check) -> bool:
        if not isinstance(out, (tuple, list)) or len(out) != 2:
            return False
        A, b = out
        # as gmuk.constraints.base.as_rows documents: a 1-D A is one row, a 0-d b one entry
        if isinstance(A, np.ndarray) and A.ndim == 1:
            A = A[None, :]
        if isinstance(b, (np.ndarray, np.generic, float, int)) and np.ndim(b) == 0:
            b = np.reshape(b, (1,))
        # any number of rows s ≥ 1, the same for A and b (a run that changes it is refused)
        try:
            s = np.shape(A)[0] if np.ndim(A) == 2 else 1
        except ValueError:  # ragged nested lists: no shape at all
            return False
        return s >= 1 and check(A, (s, self.dof)) and check(b, (s,))

    def _rows(self) -> set[int]:
        """The row counts of the values returned (one for a run that keeps its count)."""
        return {int(np.shape(v[0])[0]) if np.ndim(v[0]) == 2 else 1 for v in self.returned}

    def honest(self, shape=None) -> bool:
        # honest and solvable: a zero row with b ≠ 0 may be refused as inconsistent
        return (
            not self.raised
            and all(
                self._ok(v, _honest) and np.abs(np.asarray(v[0], dtype=float)).max() > 1e-3
                for v in self.returned
            )
            and len(self._rows()) == 1  # a run keeps its number of rows
        )

    def acceptable(self, shape=None) -> bool:
        return not self.raised and all(self._ok(v, _acceptable) for v in self.returned)


class RowsReplay(Replay):
    def __init__(self, values):
        self.values = [(np.array(v[0], float), np.array(v[1], float)) for v in values]
        self.calls = 0

    def __call__(self, *inputs):
        i = min(self.calls, len(self.values) - 1)
        self.calls += 1
        A, b = self.values[i]
        return A.copy(), b.copy()


def check_rows(args) -> None:
    kind, how, A, b, form, k, once, on_failure = args
    dof = 6 if kind == "rigid" else 3
    value = (A, b) if form == "tuple" else [A, b] if form == "list" else A
    script = RowsScript(how, value, k, once, dof)
    _check_scripted(
        f"compiled loop: Constraint.rows ({kind})",
        kind,
        lambda s: {"constraints": [ScriptedRows("a", s)]},
        script,
        None,
        on_failure,
        lambda r: {"constraints": [ScriptedRows("a", RowsReplay(r))]},
    )


def _rows_args(kind):
    dof = 6 if kind == "rigid" else 3
    return st.tuples(
        st.just(kind),
        behaviours,
        st.one_of(arrays((1, dof)), st.sampled_from([np.eye(dof)[:2], np.zeros((1, dof))])),
        arrays((1,)),
        st.sampled_from(["tuple"] * 4 + ["list", "bare"]),
        calls_k,
        st.booleans(),
        st.sampled_from(["raise", "return"]),
    )


rows_args = st.sampled_from(["rigid", "point"]).flatmap(_rows_args)

(
    test_constraint_rows_callbacks_are_checked_in_the_compiled_loop,
    test_constraint_rows_callbacks_are_checked_in_the_compiled_loop_slow,
) = fuzz_pair(rows_args, check_rows, fast=30, slow=2000)


# ------------------------------------------------------- inequality constraints' h(q)
class BoundScript(Script):
    """value(q) → h, a real scalar; honest values are h = x-coordinate + c, c moderate."""

    def __init__(self, how, value, k, once):
        super().__init__(how, value, k, once, None)

    def __call__(self, *q):
        hostile = self.hostile_now()
        if not hostile or self.how != "return":
            out = super().__call__(*q)
            if out is None:  # honest: h = the x coordinate (position of the point/frame)
                q0 = q[0]
                out = float(q0[0, 3] if q0.ndim == 2 else q0[0])
                self.returned[-1] = out
            return out
        return super().__call__(*q)

    def honest(self, shape=None) -> bool:
        # honest, and feasible (h ≥ -10 with room) and unchanged: the value jumps when the
        # script starts, and a jump in h is a jump in its finite-difference rows
        values = self.returned
        return (
            not self.raised
            and all(_honest(v, ()) and v > -9.0 for v in values)
            and (self.how != "return" or not values or all(v == values[0] for v in values))
        )

    def acceptable(self, shape=None) -> bool:
        return not self.raised and all(_acceptable(v, ()) for v in self.returned)


def check_bound(args) -> None:
    kind, how, value, k, once, on_failure = args
    script = BoundScript(how, value, k, once)
    entry = f"compiled loop: InequalityConstraint.value ({kind})"
    system_state = outcome(
        entry + " [System.state]", _system, kind, {"constraints": [ScriptedBound("a", script)]}
    )
    if system_state is REFUSED:  # the initial slack is computed from h(q0)
        assert not script.honest() or script.mutated, f"{entry}: refused honest h"
        return
    system, state = system_state
    snap = _snapshot(state)
    traj = _simulate(entry, system, state, on_failure)
    assert _same_state(state, snap), f"{entry}: the part changed the caller's initial State"
    if traj is REFUSED:
        # finite differences of h may legitimately see a hostile value the state did not
        assert not script.honest() or script.mutated, f"{entry}: refused honest h"
        return
    assert not script.raised, f"{entry}: the part raised, yet the run reports success"
    assert script.acceptable(), (
        f"{entry}: accepted h = {[v for v in script.returned if not _acceptable(v, ())]!r:.300}"
    )


bound_args = st.tuples(
    st.sampled_from(["rigid", "point"]),
    behaviours,
    scalars,
    calls_k,
    st.booleans(),
    st.sampled_from(["raise", "return"]),
)

(
    test_inequality_constraint_values_are_checked_in_the_compiled_loop,
    test_inequality_constraint_values_are_checked_in_the_compiled_loop_slow,
) = fuzz_pair(bound_args, check_bound, fast=40, slow=2000)


# ----------------------------------------- built-in inequality constraints, honest bounds
def check_plane_bound(args) -> None:
    normal, lower, upper, slack_mass, damping, z0 = args
    entry = "PlaneBound + SlackDamping"
    made = outcome(
        entry,
        lambda: (
            gmuk.PlaneBound("p", normal, lower=lower, upper=upper, slack_mass=slack_mass),
            gmuk.SlackDamping(damping),
        ),
    )
    if made is REFUSED:
        return
    for name, v in (("lower", lower), ("upper", upper), ("slack_mass", slack_mass)):
        assert v is None or honest_real(v), f"{entry} took {name}={v!r:.100}"
    assert honest_real(normal) and honest_real(damping), f"{entry} took {normal!r:.100}"
    bound, slack_damping = made
    n_hat = np.asarray(normal, dtype=float)
    n_hat = n_hat / np.abs(n_hat).max()  # scaled first: the norm of 1e308s overflows
    n_hat = n_hat / np.linalg.norm(n_hat)
    system = gmuk.System(
        [gmuk.PointMass("p", 1.0)], [bound], [gmuk.UniformGravity(), slack_damping]
    )
    r0 = np.array([0.0, 0.0, z0])
    h0 = float(n_hat @ r0)
    state = outcome("PlaneBound: System.state", system.state, r={"p": r0}, v={"p": [0.3, 0.0, 0.0]})
    lo = -math.inf if lower is None else float(lower)
    hi = math.inf if upper is None else float(upper)
    moderate = max(abs(x) for x in (lo, hi, 0.0) if math.isfinite(x)) < 1e6
    # on a bound and moving (v = 0.3 along x): a slack of 0 needs dh/dt = 0, so the start is
    # refused (initial_slack: "start inside the bound by any margin")
    moving_on_bound = h0 in (lo, hi) and abs(0.3 * n_hat[0]) > 1e-9 * max(1.0, abs(h0))
    if state is REFUSED:  # only an infeasible start, or bounds so large that w² overflows
        assert not (lo <= h0 <= hi) or not moderate or moving_on_bound, (
            f"{entry}: refused a feasible start h0={h0} in [{lo}, {hi}]"
        )
        return
    assert lo - 1e-9 <= h0 <= hi + 1e-9, f"{entry}: took an infeasible start {h0} ∉ [{lo}, {hi}]"
    traj = outcome(
        "PlaneBound: simulate", system.simulate, state, (0.0, 0.5), rtol=1e-9, atol=1e-9,
        max_steps=2000, on_failure="return", hang_s=30.0,
    )  # fmt: skip
    if traj is REFUSED or traj.status != "success":
        ordinary = moderate and 1e-3 <= float(slack_mass) <= 1e3 and float(damping) <= 1e3
        assert not ordinary or traj is REFUSED, f"{entry}: {traj.message}"
        return
    h = traj.r_N[:, 0] @ n_hat
    scale = 1e-6 * (1.0 + max(abs(x) for x in (lo, hi, h0) if math.isfinite(x)))
    assert (h >= lo - scale).all() and (h <= hi + scale).all(), (
        f"{entry}: the bound [{lo}, {hi}] was left: h in [{h.min()}, {h.max()}]"
    )


def _bounds(x: float) -> st.SearchStrategy[Any]:
    return st.one_of(st.none(), st.floats(-3.0, 3.0), scalars)


plane_args = st.tuples(
    st.one_of(
        st.sampled_from([[0.0, 0.0, 1.0], [0.0, 0.0, -2.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]),
        arrays((3,)),
    ),
    _bounds(-1.0),
    _bounds(1.0),
    st.one_of(st.sampled_from([1.0, 0.5, 2.0]), scalars),
    st.one_of(st.sampled_from([0.0, 1.0, 5.0]), scalars),
    st.floats(-2.0, 2.0),
)

(
    test_plane_bounds_take_only_honest_arguments_and_hold,
    test_plane_bounds_take_only_honest_arguments_and_hold_slow,
) = fuzz_pair(plane_args, check_plane_bound, fast=30, slow=600)


# ----------------------------------------------------------- Morse–Lyapunov controller
_ML_GAINS = ["k11", "k12", "k21", "k22", "kappa", "a", "k_integral", "morse_weight", "robust"]


def check_morse_lyapunov(args) -> None:
    gain, value = args
    from gmuk.orbits import LVLHReference, fcei_orbit

    body = gmuk.RigidBody("sat", 10.0, np.diag([1.0, 2.0, 3.0]))
    reference = LVLHReference(fcei_orbit())
    law = outcome(
        f"MorseLyapunovController[{gain}]",
        gmuk.MorseLyapunovController,
        body,
        reference,
        **{gain: value},
    )
    if law is REFUSED:
        return
    if gain == "robust":
        assert isinstance(value, (bool, np.bool_)), f"robust={value!r} was taken"
    elif value is not None:
        assert honest_real(value), f"MorseLyapunovController took {gain}={value!r:.100}"
        assert np.isfinite(np.asarray(value, dtype=float)).all()


(
    test_morse_lyapunov_gains_are_real_numbers,
    test_morse_lyapunov_gains_are_real_numbers_slow,
) = fuzz_pair(
    st.tuples(
        st.sampled_from(_ML_GAINS),
        st.one_of(scalars, arrays((3,)), st.sampled_from([True, False, "False", 0, 1, None])),
    ),
    check_morse_lyapunov,
    fast=40,
    slow=1000,
)


# ------------------------------------------------------------ physics: the free body
def check_free_body(args) -> None:
    moments, theta, V, mass = args
    from gmuk.lie import so3

    R = so3.exp(theta)
    J = R @ np.diag(moments) @ R.T
    J = 0.5 * (J + J.T)
    body = gmuk.RigidBody("a", mass, J)
    system = gmuk.System([body])
    state = system.state(g={"a": np.eye(4)}, V={"a": V})
    t_eval = np.linspace(0.0, 2.0, 5)
    traj = outcome(
        "compiled loop: free rigid body",
        system.simulate,
        state,
        (0.0, 2.0),
        t_eval=t_eval,
        rtol=1e-11,
        atol=1e-12,
        hang_s=30.0,
    )
    assert traj is not REFUSED and traj.success, "a free rigid body failed to integrate"
    Vt = traj.V_B[:, 0]
    energy = 0.5 * (
        np.einsum("ni,ij,nj->n", Vt[:, :3], J, Vt[:, :3]) + mass * (Vt[:, 3:] ** 2).sum(1)
    )
    # the spatial angular momentum in N: R J ω (rotation) and the linear momentum m R v
    Rt = traj.g_NB[:, 0, :3, :3]
    L_N = np.einsum("nij,jk,nk->ni", Rt, J, Vt[:, :3])
    p_N = mass * np.einsum("nij,nj->ni", Rt, Vt[:, 3:])
    scale = energy[0] + 1e-20
    assert np.abs(energy - energy[0]).max() <= 1e-8 * scale, "energy drifts"
    # relative to the momenta, with a floor of the tolerances' (atol 1e-12 on ω and v)
    floor_L, floor_p = 1e-9 * np.abs(J).max(), 1e-9 * mass
    assert np.abs(L_N - L_N[0]).max() <= 1e-8 * np.abs(L_N[0]).max() + floor_L, "L_N drifts"
    assert np.abs(p_N - p_N[0]).max() <= 1e-8 * np.abs(p_N[0]).max() + floor_p, "p_N drifts"
    # and the compiled loop agrees with the Python reference loop
    ref = reference_simulate(system, state, (0.0, 2.0), t_eval=t_eval, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(traj.V_B, ref.V_B, rtol=0, atol=1e-9 * (1 + np.abs(V).max()))
    np.testing.assert_allclose(traj.g_NB, ref.g_NB, rtol=0, atol=1e-9 * (1 + np.abs(V).max()))


def _moments(x):
    a, b, c = x
    # a physical inertia: each moment at most the sum of the other two
    m = np.sort(np.array([a, b, c]))
    m[2] = min(m[2], m[0] + m[1])
    return m


free_args = st.tuples(
    st.tuples(st.floats(0.2, 5.0), st.floats(0.2, 5.0), st.floats(0.2, 5.0)).map(_moments),
    st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3).map(np.array),
    st.lists(st.floats(-2.0, 2.0), min_size=6, max_size=6).map(np.array),
    st.floats(0.1, 100.0),
)

(
    test_a_free_rigid_body_keeps_its_energy_and_momenta,
    test_a_free_rigid_body_keeps_its_energy_and_momenta_slow,
) = fuzz_pair(free_args, check_free_body, fast=10, slow=150)


def test_a_part_that_raises_once_never_gives_a_successful_run():
    script = Script("raise", None, 3, True, np.zeros(6))
    system, state = _system("rigid", {"forces": [ScriptedForce(script)]})
    traj = system.simulate(state, SPAN, on_failure="return", **RUN)
    assert script.raised and traj.status == "failed" and "PartFailure" in traj.message
    script.calls = 0
    with pytest.raises((GmukError, PartFailure)):
        system.simulate(state, SPAN, **RUN)


# numpy's RuntimeWarnings (overflow, invalid) are failures here; gmuk's own warnings are not:
# inconsistent rows (a zero row with b ≠ 0) are documented to warn and take least squares
pytestmark = [
    pytest.mark.filterwarnings("error::RuntimeWarning"),
    pytest.mark.filterwarnings("ignore::gmuk.errors.GmukWarning"),
]
