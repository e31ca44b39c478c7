"""Euler angles (3-2-1 and 3-1-3): scipy cross-check, round trips, ranges, gimbal lock.

Convention under test (gmuk/lie/euler.py): intrinsic rotations, ``"321"`` is
R₃(ψ) R₂(θ) R₁(φ) with angles [ψ, θ, φ], ``"313"`` is R₃(Ω) R₁(i) R₃(ω) with [Ω, i, ω];
scipy's intrinsic "ZYX" and "ZXZ" with the same angle order are the same maps.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from gmuk.errors import EulerSequenceError
from gmuk.lie import euler, so3

PI = np.pi
SCIPY_SEQ = {"321": "ZYX", "313": "ZXZ"}
PROPERTY = settings(max_examples=60, deadline=None)
any_angle = st.floats(-2 * PI, 2 * PI)
outer = st.floats(-PI, PI)


def wrap(a):
    """Angle difference mapped to [−π, π)."""
    return (np.asarray(a) + PI) % (2 * PI) - PI


def assert_matrix_close(A, B, tol=1e-13):
    err = np.abs(np.asarray(A) - np.asarray(B)).max()
    assert err <= tol, f"max|A − B| = {err:.3g} > {tol:g}"


#: Middle angles: regular, exactly singular, and within 1e-16 … 1e-3 of a singularity.
def _middle(seq):
    lo, hi = (-PI / 2, PI / 2) if seq == "321" else (0.0, PI)
    return st.one_of(
        st.floats(lo, hi),
        st.sampled_from([lo, hi]),
        st.builds(lambda d: lo + d, st.floats(1e-16, 1e-3)),
        st.builds(lambda d: hi - d, st.floats(1e-16, 1e-3)),
    )


def _angles(seq):
    return st.tuples(outer, _middle(seq), outer).map(np.array)


@pytest.mark.parametrize("seq", ["321", "313"])
@PROPERTY
@given(data=st.data())
def test_to_matrix_matches_scipy_intrinsic_rotations(seq, data):
    a = np.array(data.draw(st.tuples(any_angle, any_angle, any_angle)))
    expected = Rotation.from_euler(SCIPY_SEQ[seq], a).as_matrix()
    assert_matrix_close(euler.to_matrix(a, seq), expected, tol=1e-15 * 4)


def test_321_is_yaw_pitch_roll_about_body_axes():
    psi, th, phi = 0.3, -0.2, 1.1
    R = euler.to_matrix([psi, th, phi], "321")
    expected = so3.exp([0.0, 0.0, psi]) @ so3.exp([0.0, th, 0.0]) @ so3.exp([phi, 0.0, 0.0])
    assert_matrix_close(R, expected)


@pytest.mark.parametrize("seq", ["321", "313"])
@PROPERTY
@given(data=st.data())
def test_angles_round_trip_away_from_gimbal_lock(seq, data):
    lo, hi = (-PI / 2 + 1e-3, PI / 2 - 1e-3) if seq == "321" else (1e-3, PI - 1e-3)
    a = np.array(data.draw(st.tuples(outer, st.floats(lo, hi), outer)))
    b = euler.from_matrix(euler.to_matrix(a, seq), seq)
    # Conditioning of the outer angles is 1/cos θ (1/sin i) ≤ 1e3 here.
    assert np.abs(wrap(b - a)).max() <= 1e-12


@pytest.mark.parametrize("seq", ["321", "313"])
@PROPERTY
@given(data=st.data())
def test_matrix_round_trips_for_every_attitude_including_near_gimbal_lock(seq, data):
    a = data.draw(_angles(seq))
    # Compose with a random rotation and back so that every entry carries round-off, as a
    # matrix computed elsewhere would (to_matrix alone produces exact small entries).
    P = so3.exp(np.array(data.draw(st.tuples(outer, outer, outer))))
    R = (euler.to_matrix(a, seq) @ P) @ P.T
    assert_matrix_close(euler.to_matrix(euler.from_matrix(R, seq), seq), R)


@pytest.mark.parametrize("seq", ["321", "313"])
@PROPERTY
@given(w=st.tuples(outer, outer, outer))
def test_from_matrix_returns_the_documented_ranges(seq, w):
    b = euler.from_matrix(so3.exp(np.array(w)), seq)
    assert -PI < b[0] <= PI and -PI < b[2] <= PI
    if seq == "321":
        assert -PI / 2 <= b[1] <= PI / 2
    else:
        assert 0.0 <= b[1] <= PI


@pytest.mark.parametrize(
    ("seq", "middle"), [("321", PI / 2), ("321", -PI / 2), ("313", 0.0), ("313", PI)]
)
@pytest.mark.parametrize("outer_angles", [(0.0, 0.0), (0.7, -0.4), (-3.0, 2.5), (PI, PI)])
def test_gimbal_lock_gives_a_matrix_equal_round_trip_with_last_angle_zero(
    seq, middle, outer_angles
):
    R = euler.to_matrix([outer_angles[0], middle, outer_angles[1]], seq)
    b = euler.from_matrix(R, seq)
    assert b[2] == 0.0
    assert abs(wrap(b[1] - middle)) <= 1e-15
    assert_matrix_close(euler.to_matrix(b, seq), R)


def test_batched_angles_equal_a_loop_over_elements():
    rng = np.random.default_rng(4)
    a = rng.uniform(-1.5, 1.5, size=(2, 4, 3))
    a[0, 0, 1] = PI / 2
    for seq in ("321", "313"):
        R = euler.to_matrix(a, seq)
        b = euler.from_matrix(R, seq)
        assert R.shape == (2, 4, 3, 3) and b.shape == (2, 4, 3)
        for i in range(2):
            for j in range(4):
                assert_matrix_close(R[i, j], euler.to_matrix(a[i, j], seq), tol=0.0)
                assert np.abs(b[i, j] - euler.from_matrix(R[i, j], seq)).max() <= 1e-15


@pytest.mark.parametrize("seq", ["123", "ZYX", "zyx", "", "3211"])
def test_unsupported_sequence_raises_euler_sequence_error_naming_it(seq):
    with pytest.raises(EulerSequenceError, match=repr(seq)) as info:
        euler.to_matrix([0.1, 0.2, 0.3], seq)
    assert "321" in str(info.value) and "313" in str(info.value)
    with pytest.raises(EulerSequenceError, match=repr(seq)):
        euler.from_matrix(np.eye(3), seq)
    assert isinstance(info.value, ValueError)
