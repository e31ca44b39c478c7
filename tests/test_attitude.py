"""gmuk.attitude: round trips (hypothesis), scipy's Rotation and Pinocchio as references,
Schaub & Junkins's formulas for the DCM and the MRP kinematics, and the boundary checks."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from gmuk import attitude as at
from gmuk.errors import (
    DefinitionError,
    DomainError,
    EulerSequenceError,
    GmukError,
    NonFiniteError,
    NotOnGroupError,
    ShapeError,
)
from gmuk.lie import euler, so3

PI = np.pi
SEQUENCES = at.EULER_SEQUENCES
TAIT_BRYAN = [s for s in SEQUENCES if s[0] != s[2]]
PROPER = [s for s in SEQUENCES if s[0] == s[2]]
ROT = Rotation.random(3000, random_state=29)
R_RANDOM = ROT.as_matrix()

# Rotation vectors: small, generic, and near and at π (where q₀ = 0 and |σ| = 1).
angles = st.one_of(st.just(0.0), st.floats(0.0, 1e-8), st.floats(0.0, PI), st.floats(PI - 1e-9, PI))
axes = arrays(np.float64, 3, elements=st.floats(-1.0, 1.0)).filter(
    lambda e: np.linalg.norm(e) > 1e-3
)
rotations = st.builds(lambda th, e: so3.exp(th * e / np.linalg.norm(e)), angles, axes)
orders = st.sampled_from(["first", "last"])


def first(q: np.ndarray, scalar: str) -> np.ndarray:
    """q scalar-first, whatever its order."""
    return q if scalar == "first" else np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def dcm_BN_principal(e: np.ndarray, phi: float) -> np.ndarray:
    """Schaub & Junkins's [BN] of the principal rotation (ê, Φ) of B relative to N:
    cos Φ I + (1 − cos Φ) ê êᵀ − sin Φ [ẽ]."""
    return np.cos(phi) * np.eye(3) + (1 - np.cos(phi)) * np.outer(e, e) - np.sin(phi) * so3.hat(e)


# ----------------------------------------------------------------- round trips (hypothesis)


@settings(max_examples=300)
@given(rotations, orders)
def test_matrix_to_quaternion_and_back_with_a_canonical_sign(R, scalar):
    q = at.quaternion_from_R_NB(R, scalar=scalar)
    assert q.dtype == np.float64 and q.shape == (4,)
    assert abs(np.linalg.norm(q) - 1.0) < 1e-15 * 4
    assert first(q, scalar)[0] >= 0.0
    np.testing.assert_allclose(at.R_NB_from_quaternion(q, scalar=scalar), R, atol=1e-14)
    np.testing.assert_allclose(at.R_NB_from_quaternion(-q, scalar=scalar), R, atol=1e-14)


@settings(max_examples=300)
@given(rotations)
def test_matrix_to_mrp_and_back_the_short_set_and_its_shadow(R):
    sigma = at.mrp_from_R_NB(R)
    assert np.linalg.norm(sigma) <= 1.0 + 1e-15
    np.testing.assert_allclose(at.R_NB_from_mrp(sigma), R, atol=1e-14)
    if np.linalg.norm(sigma) > 1e-6:
        shadow = at.mrp_shadow(sigma)
        np.testing.assert_allclose(at.R_NB_from_mrp(shadow), R, atol=1e-13)
        if np.linalg.norm(sigma) < 1.0 - 1e-9:  # at Φ = π, |σ| = |σˢ| = 1: no switch
            np.testing.assert_allclose(at.mrp_switch(shadow), sigma, atol=1e-13)
        np.testing.assert_allclose(at.mrp_shadow(shadow), sigma, atol=1e-15)


@settings(max_examples=200)
@given(rotations, orders)
def test_quaternion_and_mrp_agree_both_ways(R, scalar):
    q = at.quaternion_from_R_NB(R, scalar=scalar)
    sigma = at.mrp_from_quaternion(q, scalar=scalar)
    np.testing.assert_allclose(sigma, at.mrp_from_R_NB(R), atol=1e-15)
    back = at.quaternion_from_mrp(sigma, scalar=scalar)
    assert first(back, scalar)[0] >= 0.0
    np.testing.assert_allclose(at.R_NB_from_quaternion(back, scalar=scalar), R, atol=1e-14)
    np.testing.assert_allclose(
        at.R_NB_from_mrp(at.mrp_from_quaternion(-q, scalar=scalar)), R, atol=1e-14
    )
    if first(q, scalar)[0] > 1e-9:  # below Φ = π the canonical sign makes both unique
        np.testing.assert_allclose(at.mrp_from_quaternion(-q, scalar=scalar), sigma, atol=1e-15)
        if np.linalg.norm(sigma) > 1e-6:  # the shadow set gives the same canonical quaternion
            np.testing.assert_allclose(
                at.quaternion_from_mrp(at.mrp_shadow(sigma), scalar=scalar), back, atol=1e-13
            )


@settings(max_examples=100)
@given(arrays(np.float64, 3, elements=st.floats(-PI, PI)), st.sampled_from(SEQUENCES))
def test_matrix_to_euler_and_back_for_all_twelve_sequences(a, sequence):
    R = at.R_NB_from_euler(a, sequence)
    angles = at.euler_from_R_NB(R, sequence)
    assert np.all(np.isfinite(angles))
    assert np.all((angles[[0, 2]] > -PI) & (angles[[0, 2]] <= PI))
    if sequence in TAIT_BRYAN:
        assert -PI / 2 <= angles[1] <= PI / 2
    else:
        assert 0.0 <= angles[1] <= PI
    np.testing.assert_allclose(at.R_NB_from_euler(angles, sequence), R, atol=1e-13)


@settings(max_examples=100)
@given(
    st.floats(-PI, PI),
    st.floats(-PI, PI),
    st.sampled_from([-1.0, 1.0]),
    st.floats(0.0, 1e-9),
    st.sampled_from(SEQUENCES),
)
def test_euler_at_and_near_gimbal_lock_is_finite_and_reproduces_the_matrix(
    a, c, side, offset, sequence
):
    if sequence in TAIT_BRYAN:
        beta = side * (PI / 2 - offset)
    else:
        beta = offset if side > 0 else PI - offset
    R = at.R_NB_from_euler([a, beta, c], sequence)
    angles = at.euler_from_R_NB(R, sequence)
    assert np.all(np.isfinite(angles))
    np.testing.assert_allclose(at.R_NB_from_euler(angles, sequence), R, atol=1e-13)


@pytest.mark.parametrize("sequence", SEQUENCES)
def test_exact_gimbal_lock_puts_the_whole_rotation_in_the_first_angle(sequence):
    beta = PI / 2 if sequence in TAIT_BRYAN else 0.0
    for b in (beta, -beta if beta else PI):
        R = at.R_NB_from_euler([0.7, b, -0.4], sequence)
        angles = at.euler_from_R_NB(R, sequence)
        assert angles[2] == 0.0
        np.testing.assert_allclose(angles[1], b, atol=1e-7)
        np.testing.assert_allclose(at.R_NB_from_euler(angles, sequence), R, atol=1e-14)


def test_batches_keep_their_leading_axes():
    R = R_RANDOM[:24].reshape(2, 3, 4, 3, 3)
    q = at.quaternion_from_R_NB(R, scalar="first")
    assert q.shape == (2, 3, 4, 4)
    assert at.R_NB_from_quaternion(q, scalar="first").shape == R.shape
    assert at.mrp_from_R_NB(R).shape == (2, 3, 4, 3)
    assert at.euler_from_R_NB(R, "ZYX").shape == (2, 3, 4, 3)
    assert at.R_NB_from_euler(np.zeros((5, 3)), "XYX").shape == (5, 3, 3)
    assert at.dcm_BN_from_R_NB(R).shape == R.shape
    p = at.quaternion_multiply(q[:1], q, scalar="first")
    assert p.shape == (2, 3, 4, 4)
    assert at.mrp_rate(np.zeros(3), np.ones((7, 3))).shape == (7, 3)
    np.testing.assert_allclose(at.R_NB_from_mrp(at.mrp_from_R_NB(R)), R, atol=1e-14)


# ----------------------------------------------------------------- scipy's Rotation


def test_quaternions_against_scipy_scalar_last_and_first():
    q_last = at.quaternion_from_R_NB(R_RANDOM, scalar="last")
    np.testing.assert_allclose(q_last, ROT.as_quat(canonical=True), atol=1e-12)
    q_first = at.quaternion_from_R_NB(R_RANDOM, scalar="first")
    np.testing.assert_allclose(q_first, ROT.as_quat(canonical=True, scalar_first=True), atol=1e-12)
    np.testing.assert_allclose(
        at.R_NB_from_quaternion(ROT.as_quat(), scalar="last"), R_RANDOM, atol=1e-12
    )


def test_quaternion_product_against_scipy_composition():
    other = Rotation.random(3000, random_state=30)
    for scalar in ("first", "last"):
        p = at.quaternion_from_R_NB(R_RANDOM, scalar=scalar)
        q = at.quaternion_from_R_NB(other.as_matrix(), scalar=scalar)
        pq = at.quaternion_multiply(p, q, scalar=scalar)
        np.testing.assert_allclose(
            at.R_NB_from_quaternion(pq, scalar=scalar), (ROT * other).as_matrix(), atol=1e-12
        )
    # the Hamilton product itself, sign included
    i = np.array([0.0, 1.0, 0.0, 0.0])
    j = np.array([0.0, 0.0, 1.0, 0.0])
    np.testing.assert_allclose(at.quaternion_multiply(i, j, scalar="first"), [0, 0, 0, 1])
    np.testing.assert_allclose(at.quaternion_multiply(j, i, scalar="first"), [0, 0, 0, -1])


def test_mrps_against_scipy():
    sigma = at.mrp_from_R_NB(R_RANDOM)
    ref = ROT.as_mrp()  # scipy's set also has |σ| ≤ 1
    np.testing.assert_allclose(sigma, ref, atol=1e-12)
    np.testing.assert_allclose(at.R_NB_from_mrp(ref), R_RANDOM, atol=1e-12)
    np.testing.assert_allclose(at.R_NB_from_mrp(at.mrp_shadow(ref)), R_RANDOM, atol=1e-12)


@pytest.mark.parametrize("sequence", SEQUENCES)
def test_euler_angles_against_scipy_intrinsic(sequence):
    angles = at.euler_from_R_NB(R_RANDOM, sequence)
    np.testing.assert_allclose(angles, ROT.as_euler(sequence), atol=1e-12)
    np.testing.assert_allclose(
        at.R_NB_from_euler(angles, sequence),
        Rotation.from_euler(sequence, angles).as_matrix(),
        atol=1e-12,
    )


def test_321_and_313_agree_with_gmuk_lie_euler():
    for seq, old in (("ZYX", "321"), ("ZXZ", "313")):
        np.testing.assert_allclose(
            at.euler_from_R_NB(R_RANDOM, seq), euler.from_matrix(R_RANDOM, old), atol=1e-12
        )


# ----------------------------------------------------------------- Pinocchio


def test_quaternions_against_pinocchio():
    for R in R_RANDOM[:300]:
        pq = pin.Quaternion(R)
        xyzw = pq.coeffs()  # Eigen's storage: x, y, z, w
        if xyzw[3] < 0:
            xyzw = -xyzw
        np.testing.assert_allclose(at.quaternion_from_R_NB(R, scalar="last"), xyzw, atol=1e-12)
        w, x, y, z = at.quaternion_from_R_NB(R, scalar="first")
        np.testing.assert_allclose(pin.Quaternion(w, x, y, z).toRotationMatrix(), R, atol=1e-12)


def test_rpy_against_pinocchio():
    # Pinocchio's rpy = [roll, pitch, yaw], R = R_z(yaw) R_y(pitch) R_x(roll): "ZYX" reversed
    for R in R_RANDOM[:300]:
        ypr = at.euler_from_R_NB(R, "ZYX")
        np.testing.assert_allclose(ypr[::-1], pin.rpy.matrixToRpy(R), atol=1e-12)
        np.testing.assert_allclose(
            at.R_NB_from_euler(ypr, "ZYX"), pin.rpy.rpyToMatrix(ypr[::-1]), atol=1e-12
        )


# ----------------------------------------------------------------- Schaub & Junkins


def test_mrp_dcm_is_schaubs_BN_transposed():
    rng = np.random.default_rng(29)
    for _ in range(200):
        e = rng.normal(size=3)
        e /= np.linalg.norm(e)
        phi = rng.uniform(0.0, PI)
        sigma = e * np.tan(phi / 4)
        S = so3.hat(sigma)
        s2 = sigma @ sigma
        BN = np.eye(3) + (8 * S @ S - 4 * (1 - s2) * S) / (1 + s2) ** 2  # Schaub's [BN](σ)
        np.testing.assert_allclose(BN, dcm_BN_principal(e, phi), atol=1e-14)
        np.testing.assert_allclose(at.R_NB_from_mrp(sigma), BN.T, atol=1e-14)
        np.testing.assert_allclose(at.mrp_from_R_NB(BN.T), sigma, atol=1e-14)
        np.testing.assert_allclose(at.dcm_BN_from_R_NB(BN.T), BN, atol=0)
        np.testing.assert_allclose(at.R_NB_from_dcm_BN(BN), BN.T, atol=0)
        # Euler parameters β_BN (scalar first) of the same rotation
        beta = np.r_[np.cos(phi / 2), e * np.sin(phi / 2)]
        np.testing.assert_allclose(at.quaternion_from_R_NB(BN.T, scalar="first"), beta, atol=1e-14)


def test_schaub_321_is_ZYX():
    # [BN] = M1(φ) M2(θ) M3(ψ) with Schaub's frame rotations M_k(a) = R_k(a)ᵀ
    psi, theta, phi = 0.3, -0.6, 1.1
    M = [so3.exp(a * np.eye(3)[k]).T for k, a in ((0, phi), (1, theta), (2, psi))]
    BN = M[0] @ M[1] @ M[2]
    np.testing.assert_allclose(at.R_NB_from_euler([psi, theta, phi], "ZYX"), BN.T, atol=1e-15)


@pytest.mark.parametrize("case", range(6))
def test_mrp_rate_against_a_finite_difference_of_the_attitude(case):
    rng = np.random.default_rng(100 + case)
    sigma0 = rng.normal(size=3)
    sigma0 *= rng.uniform(0.05, 0.8) / np.linalg.norm(sigma0)
    R0 = at.R_NB_from_mrp(sigma0)
    omega_B = rng.normal(size=3)
    h = 1e-5
    plus = at.mrp_from_R_NB(R0 @ so3.exp(omega_B * h))
    minus = at.mrp_from_R_NB(R0 @ so3.exp(-omega_B * h))
    np.testing.assert_allclose(at.mrp_rate(sigma0, omega_B), (plus - minus) / (2 * h), atol=1e-7)
    # the same equation holds on the shadow set, for the shadow's rate
    shadow = at.mrp_shadow(sigma0)
    s2 = sigma0 @ sigma0
    sdot = at.mrp_rate(sigma0, omega_B)
    shadow_dot = -sdot / s2 + 2 * (sigma0 @ sdot) * sigma0 / s2**2
    np.testing.assert_allclose(at.mrp_rate(shadow, omega_B), shadow_dot, atol=1e-12)


def test_mrp_switch_only_touches_long_sets_and_survives_huge_values():
    s = np.array([[0.1, 0.2, -0.3], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1e200, 0.0, 0.0]])
    out = at.mrp_switch(s)
    np.testing.assert_array_equal(out[0], s[0])
    np.testing.assert_allclose(out[1], [-0.5, 0, 0])
    np.testing.assert_array_equal(out[2], s[2])
    np.testing.assert_allclose(out[3], [-1e-200, 0, 0])
    np.testing.assert_allclose(at.R_NB_from_mrp(s[1]), at.R_NB_from_mrp(out[1]), atol=1e-15)
    assert np.all(np.isfinite(at.R_NB_from_mrp(s)))
    assert np.all(np.isfinite(at.quaternion_from_mrp(s, scalar="last")))


# ----------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (
            lambda: at.quaternion_from_R_NB(np.eye(4), scalar="first"),
            ShapeError,
            r"\(\.\.\., 3, 3\)",
        ),
        (lambda: at.R_NB_from_quaternion([1, 0, 0], scalar="first"), ShapeError, r"\(\.\.\., 4\)"),
        (lambda: at.R_NB_from_mrp([np.nan, 0, 0]), NonFiniteError, "finite"),
        (lambda: at.mrp_rate([0, 0, 0], [np.inf, 0, 0]), NonFiniteError, "omega_BN_B"),
        (
            lambda: at.R_NB_from_quaternion([1, 0, 0, 0.01], scalar="first"),
            NotOnGroupError,
            "unit quaternion",
        ),
        (
            lambda: at.quaternion_multiply([1, 0, 0, 0], [2, 0, 0, 0], scalar="first"),
            NotOnGroupError,
            "q must be a unit",
        ),
        (lambda: at.mrp_from_R_NB(np.diag([1.0, 1.0, -1.0])), NotOnGroupError, "det"),
        (lambda: at.euler_from_R_NB(np.eye(3), "ZZY"), EulerSequenceError, "ZZY"),
        (lambda: at.euler_from_R_NB(np.eye(3), "zyx"), EulerSequenceError, "intrinsic"),
        (lambda: at.R_NB_from_euler([0, 0, 0], "321"), EulerSequenceError, "one of"),
        (
            lambda: at.R_NB_from_quaternion([1, 0, 0, 0], scalar="scalar-first"),
            DefinitionError,
            "'first'",
        ),
        (lambda: at.quaternion_from_R_NB(np.eye(3), scalar=None), DefinitionError, "None"),
        (lambda: at.mrp_from_quaternion([1, 0, 0, 0], scalar="wxyz"), DefinitionError, "wxyz"),
        (lambda: at.mrp_shadow([0, 0, 0]), DomainError, "no shadow"),
    ],
)
def test_bad_input_is_refused_with_the_problem_named(call, error, match):
    with pytest.raises(error, match=match) as info:
        call()
    assert isinstance(info.value, GmukError) and isinstance(info.value, ValueError)


def test_scalar_order_is_a_required_keyword():
    with pytest.raises(TypeError, match="scalar"):
        at.quaternion_from_R_NB(np.eye(3))  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        at.R_NB_from_quaternion([1, 0, 0, 0], "first")  # type: ignore[misc]


def test_nearly_unit_quaternions_are_normalised():
    q = np.array([1.0 + 5e-7, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(at.R_NB_from_quaternion(q, scalar="first"), np.eye(3))
    assert at.R_NB_from_quaternion(np.array([[1, 0, 0, 0]]), scalar="last").dtype == np.float64


@pytest.mark.parametrize("axis", [3, -1, 1.0, True, "z"])
def test_axis_rotation_takes_only_the_axes_0_1_2(axis):
    with pytest.raises(DefinitionError, match="axis must be 0, 1 or 2"):
        at.axis_rotation(axis, 0.3)


def test_axis_rotation_is_the_exponential_of_the_axis():
    angles = np.array([-2.0, 0.0, 0.4, 3.0])
    for axis in range(3):
        e = np.zeros(3)
        e[axis] = 1.0
        expected = so3.exp(angles[:, None] * e)
        np.testing.assert_allclose(at.axis_rotation(axis, angles), expected, atol=1e-15)
