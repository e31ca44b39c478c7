"""Fuzz bodies, System, System.state, a user constraint's rows(), System.accelerations and
System.simulate's options with hostile inputs (issue #15)."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import scipy.sparse as sp
from fuzz_inputs import REFUSED, arrays, fuzz_pair, honest_real, junk, outcome, poses, scalars
from helpers import Returns
from hypothesis import strategies as st

import gmuk

# ------------------------------------------------------------------------------- bodies
names = st.one_of(st.sampled_from(["a", "body 1", "é"]), junk, st.just(""))
inertias = st.one_of(
    st.sampled_from([np.eye(3), np.diag([1.0, 2.0, 2.5]), np.eye(3) * 1e308, np.eye(3) * 5e-324]),
    arrays((3, 3)),
)


def check_bodies(args) -> None:
    name, mass, inertia = args
    honest_mass = honest_real(mass) and np.ndim(mass) == 0
    for entry, make in (
        ("RigidBody", lambda: gmuk.RigidBody(name, mass, inertia)),
        ("PointMass", lambda: gmuk.PointMass(name, mass)),
        ("SlackCoordinate", lambda: gmuk.SlackCoordinate(name, mass)),
    ):
        body = outcome(entry, make)
        if body is REFUSED:
            continue
        # accepted: exactly what was given, nothing reinterpreted
        assert isinstance(name, str) and name and body.name == name
        assert honest_mass, f"{entry} took mass {mass!r}"
        assert body.mass == float(mass) and 0 < body.mass < math.inf
        M = body.mass_matrix()
        assert np.isfinite(M).all()
        if entry == "RigidBody":
            assert honest_real(inertia), f"RigidBody took inertia {inertia!r:.200}"
            np.testing.assert_array_equal(body.inertia, np.asarray(inertia, dtype=float))
            moments = np.linalg.eigvalsh(body.inertia / body.inertia.max())
            assert moments.min() > 0


(
    test_bodies_take_only_physical_masses_and_inertias,
    test_bodies_take_only_physical_masses_and_inertias_slow,
) = fuzz_pair(st.tuples(names, scalars, inertias), check_bodies, fast=60, slow=1500)


# ----------------------------------------------------------------------- System + state
@functools.cache
def _bodies():
    return (gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 2.5])), gmuk.PointMass("p", 2.0))


@functools.cache
def _system():
    return gmuk.System(list(_bodies()))


def check_system_constructor(args) -> None:
    bodies, option, value = args
    kwargs = {option: value} if option else {}
    sys_ = outcome("System", gmuk.System, bodies, **kwargs)
    if sys_ is not REFUSED:
        assert isinstance(bodies, (list, tuple))
        assert all(isinstance(b, gmuk.Body) for b in bodies)
        if option in ("consistency_tol", "rcond") and value is not None:
            assert honest_real(value), f"System took {option}={value!r}"
            assert getattr(sys_, option) == float(value) > 0


system_args = st.tuples(
    st.one_of(
        st.just(list(_bodies())),
        st.just(_bodies()),
        st.just([]),
        st.just([_bodies()[0], _bodies()[0]]),  # duplicate names
        st.lists(st.one_of(junk, st.just(_bodies()[1])), max_size=3),
        junk,
    ),
    st.sampled_from(
        [
            *(None, "constraints", "forces", "controllers", "solver", "sparse"),
            *("sparse_solver", "tangent_bundle_method", "strict", "consistency_tol", "rcond"),
        ]
    ),
    st.one_of(scalars, st.just(()), st.lists(junk, max_size=2)),
)

(
    test_system_constructor_refuses_bad_parts_and_options,
    test_system_constructor_refuses_bad_parts_and_options_slow,
) = fuzz_pair(system_args, check_system_constructor, fast=60, slow=1500)


def check_state(args) -> None:
    g, V, r, v, t, wrap = args
    system = _system()

    def m(x, key):
        return {"a": x} if key in "gV" else {"p": x} if wrap else x

    st_ = outcome(
        "System.state", system.state, g=m(g, "g"), V=m(V, "V"), r=m(r, "r"), v=m(v, "v"), t=t
    )
    if st_ is REFUSED:
        return
    for given, got in ((g, st_.g[0]), (V, st_.V[0])):
        assert honest_real(given), f"System.state took {given!r:.200}"
        np.testing.assert_array_equal(got, np.asarray(given, dtype=float))
    assert honest_real(t) and st_.t == float(t)
    assert honest_real(r) and honest_real(v)
    acc = outcome("System.accelerations", system.accelerations, st_)
    assert acc is not REFUSED or np.abs(st_.V).max() > 1e150  # only overflow may refuse


state_args = st.tuples(
    poses(),
    arrays((6,)),
    arrays((3,)),
    arrays((3,)),
    scalars,
    st.sampled_from([True, True, True, False]),
)

(
    test_state_takes_only_valid_poses_twists_and_times,
    test_state_takes_only_valid_poses_twists_and_times_slow,
) = fuzz_pair(state_args, check_state, fast=60, slow=1500)


# ------------------------------------------------------------ a constraint's rows()
def _sparse(x):
    try:
        return sp.csr_matrix(np.asarray(x))
    except Exception:  # whatever scipy refuses stays as it was
        return x


rows_out = st.one_of(
    junk,
    st.tuples(arrays((1, 6)), arrays((1,))),
    st.tuples(arrays((2, 6)), arrays((2,))),
    st.lists(arrays((1, 6)), min_size=0, max_size=3),
    st.tuples(arrays((1, 6)).map(_sparse), arrays((1,))),
    st.tuples(st.just(np.eye(6)[:1] + 0j), st.just(np.zeros(1))),
    st.tuples(st.just(sp.csr_matrix(np.eye(6)[:1] * (1 + 1j))), st.just(np.zeros(1))),
)


@functools.cache
def _rigid_state():
    s = gmuk.System([gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 2.5]))])
    return s.state(g={"a": np.eye(4)}, V={"a": np.array([0.1, 0.2, 0.3, 1.0, 0.0, 0.0])})


def test_accelerations_refuse_rows_whose_solve_overflows():
    system = gmuk.System(
        [gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 2.5]))],
        [Returns((np.eye(6)[2:3], np.array([1e308])))],
    )
    state = system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)})
    with pytest.raises(gmuk.errors.GmukError):
        acc = system.accelerations(state)
        assert np.isfinite(acc.total).all()  # if it returns, it must at least be finite


def check_constraint_rows(out) -> None:
    system = gmuk.System([gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 2.5]))], [Returns(out)])
    state = system.state(g={"a": np.eye(4)}, V={"a": np.array([0.1, 0.2, 0.3, 1.0, 0.0, 0.0])})
    acc = outcome("Constraint.rows -> accelerations", system.accelerations, state)
    if acc is REFUSED:
        return
    A, b = out[0], out[1]
    A = A.toarray() if sp.issparse(A) else A
    assert honest_real(A) or (isinstance(A, np.ndarray) and A.dtype == bool), f"took A {A!r:.200}"
    assert honest_real(b) or (isinstance(b, np.ndarray) and b.dtype == bool), f"took b {b!r:.80}"
    A = np.atleast_2d(np.asarray(A, dtype=float))
    # accepted rows mean what they say: A V̇ = b holds where it can
    res = A @ acc.total - np.asarray(b, dtype=float).reshape(-1)
    if np.abs(A).max(initial=0) < 1e6 and np.abs(b).max(initial=0) < 1e6:
        assert np.abs(res).max(initial=0) < 1e-6 * (1 + np.abs(b).max(initial=0)) or (
            np.linalg.matrix_rank(A) < A.shape[0]
        )


(
    test_user_constraint_rows_of_any_structure_are_checked,
    test_user_constraint_rows_of_any_structure_are_checked_slow,
) = fuzz_pair(rows_out, check_constraint_rows, fast=60, slow=1500)


# ------------------------------------------------------------------ simulate options
OPTIONS = [
    *("t_span", "t_eval", "method", "rtol", "atol", "step", "first_step", "max_step"),
    *("max_steps", "progress", "on_failure"),
]

option_values = st.one_of(
    scalars,
    st.tuples(scalars, scalars),
    arrays((3,)),
    st.sampled_from(["RK4", "DOP853", "dopri5", "euler", "raise", "return", "x"]),
)


def check_simulate(args) -> None:
    option, value = args
    system = _rigid_system()
    state = _rigid_state()
    span = (0.0, 1e-3)
    kw = {"max_steps": 50}
    if option == "t_span":
        span = value
    else:
        kw[option] = value
    if (isinstance(value, str) and value.lower() == "rk4") or option == "step":
        kw.setdefault("method", "RK4")
        kw.setdefault("step", 1e-4)
    traj = outcome(f"System.simulate[{option}]", system.simulate, state, span, **kw)
    if traj is REFUSED:
        return
    assert traj.t.size >= 1 and np.isfinite(traj.t).all()
    assert np.isfinite(traj.V_B).all() and np.isfinite(traj.g_NB).all()
    if option in ("rtol", "atol", "first_step", "max_step", "step") and value is not None:
        assert honest_real(value), f"simulate took {option}={value!r}"


def test_simulate_refuses_a_ragged_t_span():
    system, state = _rigid_system(), _rigid_state()
    with pytest.raises(gmuk.errors.DefinitionError, match="t_span must be a pair"):
        system.simulate(state, [[0.0, 0.0], 0.0])


def test_simulate_refuses_an_int_t_eval_beyond_float():
    system, state = _rigid_system(), _rigid_state()
    with pytest.raises(gmuk.errors.DefinitionError, match="t_eval"):
        system.simulate(state, (0.0, 1e-3), t_eval=[0.0, 10**400])


def test_simulate_refuses_an_array_on_failure():
    system, state = _rigid_system(), _rigid_state()
    with pytest.raises(gmuk.errors.DefinitionError, match="on_failure"):
        system.simulate(state, (0.0, 1e-3), on_failure=np.zeros(3))


@pytest.mark.parametrize("t_eval", [np.array([0.0, 1e-3]) + 1j, np.array([0.0, np.inf, np.inf])])
@pytest.mark.filterwarnings("error")
def test_simulate_refuses_complex_or_infinite_t_eval_without_warning(t_eval):
    system, state = _rigid_system(), _rigid_state()
    with pytest.raises(gmuk.errors.DefinitionError, match="t_eval"):
        system.simulate(state, (0.0, 1e-3), t_eval=t_eval)


@functools.cache
def _rigid_system():
    return gmuk.System([gmuk.RigidBody("a", 1.0, np.diag([1.0, 2.0, 2.5]))])


(
    test_simulate_options_are_checked_and_runs_stay_finite,
    test_simulate_options_are_checked_and_runs_stay_finite_slow,
) = fuzz_pair(
    st.tuples(st.sampled_from(OPTIONS), option_values), check_simulate, fast=60, slow=1500
)

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")
