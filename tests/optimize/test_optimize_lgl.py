"""LGL nodes, weights, differentiation and integration matrices (gmuk.optimize.lgl)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.polynomial import legendre as npleg

from gmuk.errors import DefinitionError
from gmuk.optimize import (
    interpolation_matrix,
    lgl_differentiation_matrix,
    lgl_integration_matrix,
    lgl_nodes,
)


@pytest.mark.parametrize("p", [2, 3, 4, 5, 8, 13, 21, 30])
def test_interior_nodes_are_the_roots_of_the_legendre_derivative(p):
    c = np.zeros(p + 1)
    c[p] = 1.0
    roots = np.sort(npleg.legroots(npleg.legder(c)))
    x, _ = lgl_nodes(p)
    assert x[0] == -1.0 and x[-1] == 1.0
    np.testing.assert_allclose(x[1:-1], roots, atol=1e-14)
    np.testing.assert_array_equal(x, -x[::-1])


@pytest.mark.parametrize("p", [1, 2, 3, 4, 7, 16, 50, 200])
def test_quadrature_is_exact_to_degree_2p_minus_1(p):
    x, w = lgl_nodes(p)
    assert np.all(w > 0.0)
    for k in range(0, 2 * p, max(1, (2 * p) // 12)):
        exact = (1.0 - (-1.0) ** (k + 1)) / (k + 1)
        assert abs(w @ x**k - exact) < 1e-13, k
    # degree 2p is not: the discrete norm of P_p is 2/p, the continuous one 2/(2p + 1)
    c = np.zeros(p + 1)
    c[p] = 1.0
    assert abs(w @ npleg.legval(x, c) ** 2 - 2.0 / p) < 1e-12


@pytest.mark.parametrize("p", [1, 2, 3, 6, 12, 40])
def test_differentiation_and_integration_matrices_are_exact_on_polynomials_of_degree_p(p):
    x, w = lgl_nodes(p)
    D = lgl_differentiation_matrix(p)
    A = lgl_integration_matrix(p)
    rng = np.random.default_rng(p)
    c = rng.normal(size=p + 1)  # a Legendre series of degree p
    f = npleg.legval(x, c)
    np.testing.assert_allclose(D @ f, npleg.legval(x, npleg.legder(c)), atol=1e-11 * p**2)
    np.testing.assert_allclose(A @ f, npleg.legval(x, npleg.legint(c, lbnd=-1.0)), atol=1e-13)
    np.testing.assert_allclose(A[-1], w, atol=1e-15)
    assert np.all(A[0] == 0.0)
    np.testing.assert_allclose(D.sum(axis=1), 0.0, atol=1e-12 * p**2)


def test_interpolation_matrix_reproduces_polynomials_and_node_values():
    x, _ = lgl_nodes(6)
    y = np.concatenate([np.linspace(-1, 1, 11), x[2:4]])
    L = interpolation_matrix(x, y)
    np.testing.assert_allclose(L @ (x**6 - 2 * x**3), y**6 - 2 * y**3, atol=1e-13)
    np.testing.assert_array_equal(L[-2:], np.eye(7)[2:4])


@pytest.mark.parametrize("bad", [0, -1, 2.5, True, "3", 10_000])
def test_a_degree_that_is_not_a_positive_integer_is_refused(bad):
    with pytest.raises(DefinitionError, match="LGL degree"):
        lgl_nodes(bad)
