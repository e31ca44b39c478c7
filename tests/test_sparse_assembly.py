"""The sparse path stacks dense blocks through a CSR pattern made once per System."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import Rows, random_rigid_bodies, random_state

import gmuk


class Growing(gmuk.Constraint):
    """A constraint whose number of rows changes between calls (1, 2, 3, 1, …)."""

    def __init__(self, bodies, A, b):
        super().__init__(bodies)
        self.A, self.b, self.calls = A, b, 0

    def rows(self, state):
        k = 1 + self.calls % 3
        object.__setattr__(self, "calls", self.calls + 1)  # frozen in a System
        return self.A[:k], self.b[:k]


def _systems(bodies, constraints_for):
    return (
        gmuk.System(bodies, constraints_for(), sparse=True),
        gmuk.System(bodies, constraints_for(), solver="dense"),
    )


def test_dense_blocks_on_unsorted_columns_stack_to_the_dense_rows_and_solve_alike():
    rng = np.random.default_rng(5)
    bodies = random_rigid_bodies(rng, 6)
    blocks = [
        ((bodies[4], bodies[1]), rng.normal(size=(3, 12)), rng.normal(size=3)),  # descending
        ((bodies[0],), rng.normal(size=(2, 6)), rng.normal(size=2)),
        ((bodies[5], bodies[2], bodies[3]), rng.normal(size=(4, 18)), rng.normal(size=4)),
    ]
    blocks[0][1][:, 7] = 0.0  # a zero column inside a block stays a stored zero

    def make():
        return [Rows(list(bs), A, b) for bs, A, b in blocks]

    sparse_sys, dense_sys = _systems(bodies, make)
    state = random_state(sparse_sys, rng)
    for _ in range(2):  # the second call reuses the pattern
        A_sp, b_sp = sparse_sys.constraint_rows(state)
        A_de, b_de = dense_sys.constraint_rows(state)
        assert sp.issparse(A_sp) and A_sp.has_sorted_indices
        np.testing.assert_array_equal(A_sp.toarray(), A_de)
        np.testing.assert_array_equal(b_sp, b_de)
    a_sp, a_de = sparse_sys.accelerations(state), dense_sys.accelerations(state)
    np.testing.assert_allclose(a_sp.total, a_de.total, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(a_sp.multipliers, a_de.multipliers, rtol=1e-11, atol=1e-12)


def test_a_change_of_block_shape_rebuilds_the_pattern():
    rng = np.random.default_rng(6)
    bodies = random_rigid_bodies(rng, 3)
    A, b = rng.normal(size=(3, 12)), rng.normal(size=3)
    fixed_A, fixed_b = rng.normal(size=(2, 6)), rng.normal(size=2)
    system = gmuk.System(
        bodies,
        [Growing([bodies[2], bodies[0]], A, b), Rows([bodies[1]], fixed_A, fixed_b)],
        sparse=True,
    )
    state = random_state(system, rng)
    cols = np.r_[12:18, 0:6]
    for k in (1, 2, 3, 1):
        A_sp, b_sp = system.constraint_rows(state)
        expected = np.zeros((k + 2, 18))
        expected[:k, cols] = A[:k]
        expected[k:, 6:12] = fixed_A
        np.testing.assert_array_equal(A_sp.toarray(), expected)
        np.testing.assert_array_equal(b_sp, np.r_[b[:k], fixed_b])


def test_the_cached_pattern_is_not_changed_by_what_scipy_does_with_a_matrix():
    rng = np.random.default_rng(7)
    bodies = random_rigid_bodies(rng, 2)
    A, b = rng.normal(size=(2, 12)), rng.normal(size=2)
    system = gmuk.System(bodies, [Rows([bodies[1], bodies[0]], A, b)], sparse=True)
    state = random_state(system, rng)
    first, _ = system.constraint_rows(state)
    first.indices[:] = 0  # a caller scribbling on the returned matrix
    first.data[:] = np.nan
    second, _ = system.constraint_rows(state)
    np.testing.assert_array_equal(second.toarray()[:, np.r_[6:12, 0:6]], A)


@pytest.mark.parametrize("n", [2, 50])
def test_a_chain_of_links_solves_as_the_dense_path(n):
    rng = np.random.default_rng(n)
    bodies = random_rigid_bodies(rng, n)
    links = [(bodies[i], bodies[i + 1], rng.normal(size=(5, 12))) for i in range(n - 1)]
    rhs = [rng.normal(size=5) for _ in links]

    def make():
        return [Rows([a, c], A, r) for (a, c, A), r in zip(links, rhs, strict=True)]

    sparse_sys, dense_sys = _systems(bodies, make)
    state = random_state(sparse_sys, rng)
    a_sp, a_de = sparse_sys.accelerations(state), dense_sys.accelerations(state)
    np.testing.assert_allclose(a_sp.total, a_de.total, rtol=1e-10, atol=1e-10)
