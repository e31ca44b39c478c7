"""The compiled small-system path of System.accelerations (QR solve, one fused call) gives the
same numbers as the general SVD path, certifies rank before trusting itself, and keeps
every input check of the general path."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import Rows, ScrewReference, random_rigid_bodies, random_state

import gmuk
from gmuk.engine import _uk_kernels
from gmuk.engine.solvers import FusedRigidSolver
from gmuk.errors import ConstraintError
from gmuk.reference import ReferenceState, ReferenceTrajectory

EPS = np.finfo(float).eps


def _spd_inverse_sqrt(rng, n):
    L = rng.normal(size=(n, n))
    w, Q = np.linalg.eigh(L @ L.T + n * np.eye(n))
    return Q @ np.diag(w**-0.5) @ Q.T


@pytest.mark.parametrize("seed", range(5))
def test_qr_solve_equals_the_svd_solve_within_the_conditioning(seed):
    rng = np.random.default_rng(seed)
    declined = 0
    for _ in range(200):
        n = int(rng.integers(1, 19))
        s = int(rng.integers(1, n + 1))
        # Rows scaled over six decades: condition numbers up to ~1e6.
        A = rng.normal(size=(s, n)) * 10.0 ** rng.uniform(-3, 3, size=(s, 1))
        b, a = rng.normal(size=s), rng.normal(size=n)
        Ms = _spd_inverse_sqrt(rng, n)
        ac_svd, lam_svd, rank, _, _ = _uk_kernels.uk_dense(A, b, a, Ms, n * EPS)
        ac, lam, res, scale, status = _uk_kernels.uk_qr(A, b, a, Ms, 1e8)
        assert rank == s
        kappa = np.linalg.cond(A @ Ms)
        if status == 1:  # the certificate √s‖R⁻¹‖₁‖R‖_F is at most s^1.5 κ
            assert s**1.5 * kappa > 1e8
            declined += 1
            continue
        assert status == 0
        assert np.abs(ac - ac_svd).max() <= 50 * EPS * kappa * np.abs(ac_svd).max()
        assert np.abs(lam - lam_svd).max() <= 50 * EPS * kappa**2 * np.abs(lam_svd).max()
        assert res <= 50 * EPS * kappa * max(np.abs(b).max(), np.abs(A @ a).max())
        # the scale-invariant consistency scale (issue #25, item 10): ‖b‖ + ‖A‖_F(‖a‖ + ‖ν̇_c‖)
        expected = np.linalg.norm(b) + np.linalg.norm(A) * (np.linalg.norm(a) + np.linalg.norm(ac))
        assert abs(scale - expected) <= 1e-12 * expected
    assert declined <= 10  # the SVD is the exception, not the rule


def test_qr_solve_declines_what_it_cannot_certify():
    I6 = np.eye(6)
    ones = np.ones(6)
    redundant = np.vstack([I6[:3], I6[:1]])  # rank 3 < 4 rows
    assert _uk_kernels.uk_qr(redundant, np.ones(4), ones, I6, 1e8)[4] == 1
    near = I6.copy()
    near[5] = near[4] * (1.0 + 1e-12)  # κ ≈ 1e12 > limit
    assert _uk_kernels.uk_qr(near, ones, ones, I6, 1e8)[4] == 1
    wide = np.vstack([I6, I6[:1]])  # more rows than dof
    assert _uk_kernels.uk_qr(wide, np.ones(7), ones, I6, 1e8)[4] == 1
    bad = I6.copy()
    bad[2, 3] = np.nan
    assert _uk_kernels.uk_qr(bad, ones, ones, I6, 1e8)[4] == 2
    assert _uk_kernels.uk_qr(I6, np.r_[ones[:5], np.inf], ones, I6, 1e8)[4] == 2


def _general_path(system):
    """The same parts in a System with the dense solve strategy instead of the fused call."""
    return gmuk.System(
        system.bodies, system.constraints, system.forces, system.controllers, solver="dense"
    )


@pytest.mark.parametrize("n", [1, 2, 3])
def test_fused_call_equals_the_general_path_field_by_field(n):
    rng = np.random.default_rng(40 + n)
    bodies = random_rigid_bodies(rng, n)
    s = int(rng.integers(1, 6 * n))
    A, b = rng.normal(size=(s, 6 * n)), rng.normal(size=s)
    fast = gmuk.System(bodies, [Rows(bodies, A, b)], forces=[gmuk.UniformGravity([0, 0, -9.8])])
    slow = _general_path(
        gmuk.System(bodies, [Rows(bodies, A, b)], forces=[gmuk.UniformGravity([0, 0, -9.8])])
    )
    assert isinstance(fast.solver, FusedRigidSolver)
    state = random_state(fast, rng)
    x, y = fast.accelerations(state), slow.accelerations(state)
    for name in ("free", "constraint", "total", "constraint_force", "multipliers"):
        u, v = getattr(x, name), getattr(y, name)
        assert np.abs(u - v).max() <= 1e-12 * max(1.0, np.abs(v).max()), name
    for name in ("extra", "control_force", "unmodeled_force", "z_dot"):
        assert np.array_equal(getattr(x, name), getattr(y, name)), name
    assert x.rank == y.rank == s
    assert x.residual <= 1e-12 * max(1.0, np.abs(b).max())


def test_tracking_one_body_fused_equals_general_path():
    rng = np.random.default_rng(5)
    (body,) = random_rigid_bodies(rng, 1)
    ref = ScrewReference(np.eye(4), np.array([0.01, -0.02, 0.03, 1.0, 2.0, -0.5]))
    make = lambda: gmuk.System([body], [gmuk.ConfigurationTracking(body, ref)])  # noqa: E731
    fast, slow = make(), _general_path(make())
    state = random_state(fast, rng).replace(t=2.5)
    x, y = fast.accelerations(state), slow.accelerations(state)
    assert np.allclose(x.total, y.total, rtol=1e-13, atol=1e-15)
    assert np.allclose(x.multipliers, y.multipliers, rtol=1e-12, atol=1e-12)


def test_fused_results_do_not_share_writable_memory():
    rng = np.random.default_rng(6)
    bodies = random_rigid_bodies(rng, 1)
    system = gmuk.System(bodies, [Rows(bodies, rng.normal(size=(3, 6)), rng.normal(size=3))])
    state = random_state(system, rng)
    acc = system.accelerations(state)
    free = acc.free.copy()
    acc.total[:] = 0.0  # a user may scribble on a result …
    assert np.array_equal(acc.free, free)  # … without changing another field
    with pytest.raises(ValueError):
        acc.extra[0] = 1.0  # the shared zero loads are read-only
    assert np.array_equal(system.accelerations(state).extra, np.zeros(6))


class _Broken(ReferenceTrajectory):
    def __init__(self, kind):
        self.kind = kind

    def evaluate(self, t):
        if self.kind == "nan":
            return ReferenceState(np.eye(4), np.array([np.nan, 0, 0, 0, 0, 0]), np.zeros(6))
        return ReferenceState(np.eye(3), np.zeros(6), np.zeros(6))


def test_fused_path_still_names_a_constraint_with_non_finite_rows():
    body = gmuk.RigidBody("a", 2.0, np.diag([1.0, 2.0, 2.5]))
    system = gmuk.System([body], [gmuk.ConfigurationTracking(body, _Broken("nan"), name="trk")])
    with pytest.raises(ConstraintError, match=r"'trk'.*NaN or inf"):
        system.accelerations(system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)}))


def test_reference_of_the_wrong_shape_is_an_error_not_a_stray_read():
    body = gmuk.RigidBody("a", 2.0, np.diag([1.0, 2.0, 2.5]))
    system = gmuk.System([body], [gmuk.ConfigurationTracking(body, _Broken("shape"), name="trk")])
    with pytest.raises(ConstraintError, match=r"'trk'.*g \(3, 3\)"):
        system.accelerations(system.state(g={"a": np.eye(4)}, V={"a": np.zeros(6)}))


@pytest.mark.parametrize("seed", range(3))
def test_compiled_relative_rows_equal_eq_73_written_with_the_lie_operators(seed):
    from gmuk.constraints.relative import relative_rows, relative_twist
    from gmuk.lie import se3

    rng = np.random.default_rng(seed)
    S = np.eye(6)[[1, 2, 3, 4, 5]]
    for _ in range(50):
        g_L, g_B = se3.exp(rng.normal(size=6) * 3), se3.exp(rng.normal(size=6) * 3)
        V_L, V_B, a_des = rng.normal(size=(3, 6))
        g_BL, V_BL, AdV_L = relative_twist(g_L, V_L, g_B, V_B)
        Ad_inv = se3.Ad(se3.inverse(g_BL))
        A_ref = np.hstack([-S @ Ad_inv, S])
        b_ref = S @ (a_des - se3.ad(V_BL) @ AdV_L)
        A, b, V_rel = np.full((5, 12), np.nan), np.full(5, np.nan), np.full(6, np.nan)
        relative_rows(g_L, V_L, g_B, V_B, S, a_des, A, b, V_rel)
        assert np.allclose(A, A_ref, rtol=0, atol=1e-13 * np.abs(A_ref).max())
        assert np.allclose(b, b_ref, rtol=0, atol=1e-13 * max(1.0, np.abs(b_ref).max()))
        assert np.allclose(V_rel, V_BL, rtol=0, atol=1e-13 * np.abs(V_BL).max())


def _values(acc):
    return np.concatenate([acc.free, acc.constraint, acc.total, acc.constraint_force])


def _count_entry_calls(monkeypatch):
    calls = []
    entry = gmuk.engine.solvers._fused_entry()

    def counted(*args):
        calls.append(1)
        entry(*args)

    monkeypatch.setattr(gmuk.engine.solvers, "_uk_rigid_c", counted)
    return calls


def test_rows_in_any_memory_layout_give_the_results_of_contiguous_rows(monkeypatch):
    # Fortran-ordered or strided rows cannot take the compiled entry (it assumes C order);
    # the System must notice and take the dispatcher, with bit-identical numbers.
    calls = _count_entry_calls(monkeypatch)
    rng = np.random.default_rng(8)
    bodies = random_rigid_bodies(rng, 2)
    A, b = rng.normal(size=(7, 12)), rng.normal(size=7)
    variants = {
        "C": (A, b),
        "Fortran A": (np.asfortranarray(A), b),
        "strided": (np.repeat(A, 2, axis=1)[:, ::2], np.repeat(b, 2)[::2]),
    }
    results = {}
    for label, (Ai, bi) in variants.items():
        system = gmuk.System(bodies, [Rows(bodies, Ai, bi)])
        assert isinstance(system.solver, FusedRigidSolver)
        state = random_state(system, np.random.default_rng(9))
        n_before = len(calls)
        results[label] = _values(system.accelerations(state))
        assert len(calls) - n_before == (1 if label == "C" else 0), label
    assert np.array_equal(results["C"], results["Fortran A"])
    assert np.array_equal(results["C"], results["strided"])


def test_twists_in_any_memory_layout_give_the_results_of_contiguous_twists(monkeypatch):
    calls = _count_entry_calls(monkeypatch)
    rng = np.random.default_rng(10)
    bodies = random_rigid_bodies(rng, 2)
    system = gmuk.System(bodies, [Rows(bodies, rng.normal(size=(5, 12)), rng.normal(size=5))])
    state = random_state(system, rng)
    strided = np.repeat(state.V, 2, axis=0)[::2]  # same values, every other row in memory
    assert not strided.flags.c_contiguous
    x = system.accelerations(state)
    # A State copies what it is given into arrays of its own (contiguous, read-only; issue
    # #25, item 4); _adopt takes the strided twists as they are, to reach the solver's other path.
    assert state.replace(V=strided).V.flags.c_contiguous
    s = state
    y = system.accelerations(type(s)._adopt(s.t, s.g.copy(), strided, s.x.copy(), s.xdot.copy(),
                                            s.z.copy(), s.layout))  # fmt: skip
    assert calls == [1]  # the contiguous state only
    assert np.array_equal(_values(x), _values(y))


class _ListReference(ReferenceTrajectory):
    """A reference giving plain lists (converted by the constraint)."""

    def __init__(self, inner):
        self.inner = inner

    def evaluate(self, t):
        r = self.inner.evaluate(t)
        return ReferenceState(r.g.tolist(), r.V.tolist(), r.V_dot.tolist())


def test_tracking_reference_as_lists_gives_the_rows_of_arrays():
    rng = np.random.default_rng(11)
    (body,) = random_rigid_bodies(rng, 1)
    ref = ScrewReference(np.eye(4), np.array([0.01, -0.02, 0.03, 1.0, 2.0, -0.5]))
    arrays = gmuk.System([body], [gmuk.ConfigurationTracking(body, ref)])
    lists = gmuk.System([body], [gmuk.ConfigurationTracking(body, _ListReference(ref))])
    state = random_state(arrays, rng).replace(t=1.5)
    A1, b1 = arrays.constraint_rows(state)
    A2, b2 = lists.constraint_rows(state)
    assert np.array_equal(A1, A2) and np.array_equal(b1, b2)


def test_one_tracking_constraint_in_two_systems_uses_each_systems_index():
    # The constraint remembers its body's index per layout; alternating between Systems
    # where the body sits at different indices must not mix them up.
    rng = np.random.default_rng(12)
    other, body = random_rigid_bodies(rng, 2)
    ref = ScrewReference(np.eye(4), np.array([0.01, -0.02, 0.03, 1.0, 2.0, -0.5]))
    c = gmuk.ConfigurationTracking(body, ref)
    alone = gmuk.System([body], [c])
    pair = gmuk.System([other, body], [c])
    s1 = random_state(alone, rng).replace(t=0.7)
    s2 = pair.state(
        g={other.name: np.eye(4), body.name: s1.g[0]},
        V={other.name: rng.normal(size=6), body.name: s1.V[0]},
        t=0.7,
    )
    b_alone = alone.constraint_rows(s1)[1]
    for _ in range(2):
        A2, b2 = pair.constraint_rows(s2)
        assert np.array_equal(b2, b_alone)
        assert np.array_equal(A2[:, 6:], np.eye(6)) and not A2[:, :6].any()
        assert np.array_equal(alone.constraint_rows(s1)[1], b_alone)


def test_one_relative_constraint_in_two_systems_uses_each_systems_indices():
    rng = np.random.default_rng(13)
    L, B, other = random_rigid_bodies(rng, 3)
    c = gmuk.RelativeConstraint(B, L, free_axes=[0])
    first = gmuk.System([L, B], [c])
    second = gmuk.System([B, other, L], [c])  # the two bodies elsewhere, in another order
    s1 = random_state(first, rng)
    s2 = second.state(
        g={B.name: s1.g[1], other.name: np.eye(4), L.name: s1.g[0]},
        V={B.name: s1.V[1], other.name: rng.normal(size=6), L.name: s1.V[0]},
    )
    A1, b1 = first.constraint_rows(s1)
    for _ in range(2):
        A2, b2 = second.constraint_rows(s2)
        assert np.array_equal(b2, b1)
        assert np.array_equal(A2[:, 12:], A1[:, :6]) and np.array_equal(A2[:, :6], A1[:, 6:])
        assert not A2[:, 6:12].any()
        assert np.array_equal(first.constraint_rows(s1)[1], b1)
