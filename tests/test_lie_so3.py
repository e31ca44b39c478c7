"""SO(3): hat/vee, exp/log round trips at every angle, rotations by π, batching.

Angles are drawn with extra weight on the numerically delicate ranges: θ ∈ [0, 1e-8],
θ ∈ [π − 1e-9, π] and θ = π exactly. Identities hold to 1e-12 (relative to the size of the
numbers involved, floor 1).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from gmuk.errors import NotOnGroupError
from gmuk.lie import so3

PI = np.pi
TOL = 1e-12
SPECIAL_AXES = [
    np.array([1.0, 0.0, 0.0]),
    np.array([0.0, 1.0, 0.0]),
    np.array([0.0, 0.0, 1.0]),
    np.array([0.0, 0.0, -1.0]),
    np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0),
    np.array([1.0, -1.0, 0.0]) / np.sqrt(2.0),
    np.array([0.0, 1.0, 1.0]) / np.sqrt(2.0),
    np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0),
    np.array([-1.0, 2.0, -3.0]) / np.sqrt(14.0),
]

angles = st.one_of(
    st.just(0.0),
    st.floats(0.0, 1e-8),
    st.floats(PI - 1e-9, PI),
    st.just(PI),
    st.floats(0.0, PI),
)
axes = st.one_of(
    st.sampled_from(SPECIAL_AXES),
    arrays(np.float64, 3, elements=st.floats(-1.0, 1.0))
    .filter(lambda a: np.linalg.norm(a) > 0.1)
    .map(lambda a: a / np.linalg.norm(a)),
)
rotation_vectors = st.builds(lambda th, e: th * e, angles, axes)
vectors = arrays(np.float64, 3, elements=st.floats(-1e3, 1e3))
PROPERTY = settings(max_examples=80, deadline=None)


def assert_close(actual, expected, tol=TOL, scale=None):
    """max|actual − expected| ≤ tol · max(1, |values|)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    if scale is None:
        scale = max(1.0, np.abs(expected).max(initial=0.0), np.abs(actual).max(initial=0.0))
    err = np.abs(actual - expected).max(initial=0.0)
    assert err <= tol * scale, f"error {err:.3g} > {tol:g} × scale {scale:.3g}"


def rotation_by_pi(e):
    """The exact rotation by π about unit axis e, 2 e eᵀ − I (not exp of a float π)."""
    return 2.0 * np.outer(e, e) - np.eye(3)


# --- hat / vee -----------------------------------------------------------------------------


@PROPERTY
@given(vectors, vectors)
def test_hat_is_the_cross_product_matrix(w, x):
    assert_close(so3.hat(w) @ x, np.cross(w, x), scale=max(1.0, np.abs(w).max() * np.abs(x).max()))


@PROPERTY
@given(vectors)
def test_hat_is_skew_and_vee_inverts_it(w):
    W = so3.hat(w)
    assert np.array_equal(W, -W.T)
    assert np.array_equal(so3.vee(W), w)


def test_hat_matches_eq_13_entries():
    w = np.array([1.0, 2.0, 3.0])
    assert np.array_equal(so3.hat(w), [[0, -3, 2], [3, 0, -1], [-2, 1, 0]])


@pytest.mark.parametrize(
    "W",
    [
        np.eye(3),  # symmetric
        np.array([[0.0, -3.0, 2.0], [3.0, 0.0, -1.0], [-2.0, 1.1, 0.0]]),  # one entry off
        np.array([[1e-3, -3.0, 2.0], [3.0, 0.0, -1.0], [-2.0, 1.0, 0.0]]),  # diagonal entry
    ],
)
def test_vee_rejects_matrices_that_are_not_skew_symmetric(W):
    with pytest.raises(NotOnGroupError, match="skew-symmetric"):
        so3.vee(W)


def test_vee_accepts_skew_matrices_with_round_off_asymmetry():
    W = so3.hat([1.0, 2.0, 3.0])
    W[0, 1] += 1e-12
    assert np.array_equal(so3.vee(W), [1.0, 2.0, 3.0])


# --- exp -----------------------------------------------------------------------------------


@PROPERTY
@given(rotation_vectors)
def test_exp_is_orthogonal_with_determinant_one(w):
    R = so3.exp(w)
    assert_close(R.T @ R, np.eye(3), tol=1e-15 * 4)
    assert abs(np.linalg.det(R) - 1.0) <= 1e-15 * 4


@PROPERTY
@given(rotation_vectors, vectors)
def test_exp_rotates_about_its_axis_by_its_angle(w, x):
    # Rodrigues, written independently: x cos θ + (e × x) sin θ + e (e·x)(1 − cos θ).
    th = np.linalg.norm(w)
    e = w / th if th > 0 else np.array([1.0, 0.0, 0.0])
    expected = x * np.cos(th) + np.cross(e, x) * np.sin(th) + e * (e @ x) * (1 - np.cos(th))
    assert_close(so3.exp(w) @ x, expected)


def test_exp_of_zero_is_exactly_the_identity():
    assert np.array_equal(so3.exp(np.zeros(3)), np.eye(3))


# --- log -----------------------------------------------------------------------------------


@PROPERTY
@given(rotation_vectors)
def test_exp_of_log_recovers_the_rotation(w):
    R = so3.exp(w)
    assert_close(so3.exp(so3.log(R)), R)


@PROPERTY
@given(rotation_vectors)
def test_log_of_exp_recovers_the_rotation_vector_up_to_the_sign_ambiguity_at_pi(w):
    out = so3.log(so3.exp(w))
    th = np.linalg.norm(w)
    assert np.linalg.norm(out) <= PI * (1 + 1e-15)
    if PI - th > 1e-12:
        assert_close(out, w)
    else:
        # Within round-off of π the rotation by +θe and −θe are the same matrix.
        assert_close(abs(out @ w), th * th, scale=PI * PI)
        assert_close(so3.exp(out), so3.exp(w))


@pytest.mark.parametrize("e", SPECIAL_AXES, ids=lambda e: np.array2string(e, precision=3))
def test_log_of_rotation_by_pi_recovers_axis(e):
    R = rotation_by_pi(e)
    w = so3.log(R)
    assert_close(np.linalg.norm(w), PI)
    assert_close(abs(w @ e), PI)  # parallel to e, either sign
    assert_close(so3.exp(w), R)


@pytest.mark.parametrize(
    "e",
    [
        np.array([0.0, 0.0, -1.0]),
        np.array([-1.0, 2.0, -3.0]) / np.sqrt(14.0),
        np.array([0.6, -0.8, 0.0]),
    ],
)
def test_log_at_exactly_pi_makes_the_largest_axis_component_positive(e):
    w = so3.log(rotation_by_pi(e))
    k = np.argmax(np.abs(e))
    assert w[k] > 0
    assert_close(w, PI * e * np.sign(e[k]))


@pytest.mark.parametrize("delta", [1e-6, 1e-9, 1e-12])
def test_log_just_below_pi_keeps_the_sign_of_the_axis(delta):
    for e in SPECIAL_AXES:
        for s in (1.0, -1.0):
            w = (PI - delta) * s * e
            assert_close(so3.log(so3.exp(w)), w)


@pytest.mark.parametrize("th", [0.0, 1e-300, 1e-200, 1e-16, 1e-8, 1e-4])
def test_log_at_tiny_angles_is_accurate_to_round_off(th):
    e = np.array([2.0, -1.0, 2.0]) / 3.0
    out = so3.log(so3.exp(th * e))
    assert np.all(np.isfinite(out))
    assert_close(out, th * e, tol=1e-15, scale=max(th, np.finfo(float).tiny))


def test_log_of_identity_is_zero():
    assert np.array_equal(so3.log(np.eye(3)), np.zeros(3))


# --- batching ------------------------------------------------------------------------------


def test_batched_calls_equal_a_loop_over_elements():
    rng = np.random.default_rng(3)
    th = np.array([0.0, 1e-9, 0.3, 2.0, PI - 1e-9, PI]).reshape(2, 3)
    e = rng.normal(size=(2, 3, 3))
    e /= np.linalg.norm(e, axis=-1, keepdims=True)
    w = th[..., None] * e
    R, W, L = so3.exp(w), so3.hat(w), so3.log(so3.exp(w))
    assert R.shape == W.shape == (2, 3, 3, 3) and L.shape == (2, 3, 3)
    for i in range(2):
        for j in range(3):
            assert np.array_equal(R[i, j], so3.exp(w[i, j]))
            assert np.array_equal(W[i, j], so3.hat(w[i, j]))
            assert np.array_equal(so3.vee(W)[i, j], so3.vee(W[i, j]))
            assert np.array_equal(L[i, j], so3.log(R[i, j]))


def test_empty_batches_keep_their_shape():
    assert so3.exp(np.zeros((0, 3))).shape == (0, 3, 3)
    assert so3.log(np.zeros((0, 3, 3))).shape == (0, 3)
