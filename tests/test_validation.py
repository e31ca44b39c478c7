"""Input checks at the public boundary of gmuk.lie and gmuk.dynamics.

Every bad input raises the matching :mod:`gmuk.errors` class (ShapeError, NonFiniteError,
NotOnGroupError, EulerSequenceError), which is also a ``ValueError``, with a message that
states what was expected and what came in (``docs/conventions.rst``, Errors).
"""

from __future__ import annotations

import numpy as np
import pytest

from gmuk import dynamics
from gmuk._validation import GROUP_TOL, as_array, check_rotation, check_se3
from gmuk.errors import GmukError, NonFiniteError, NotOnGroupError, ShapeError
from gmuk.lie import euler, se3, so3

I6 = np.eye(6)


def _se3_with_last_row(row):
    g = np.eye(4)
    g[3] = row
    return g


def _se3_with_rotation(R):
    g = np.eye(4)
    g[:3, :3] = R
    return g


REFLECTION = np.diag([1.0, 1.0, -1.0])
SCALED = 2.0 * np.eye(3)

BAD_SHAPES = [
    (so3.hat, (np.zeros(4),), ["w", "(..., 3)", "(4,)"]),
    (so3.exp, (np.zeros((2, 2)),), ["(..., 3)", "(2, 2)"]),
    (so3.log, (np.zeros((3, 4)),), ["(..., 3, 3)", "(3, 4)"]),
    (so3.vee, (np.zeros(9),), ["(..., 3, 3)", "(9,)"]),
    (se3.exp, (np.zeros((2, 5)),), ["xi", "(..., 6)", "(2, 5)"]),
    (se3.log, (np.eye(3),), ["g", "(..., 4, 4)", "(3, 3)"]),
    (se3.Ad, (np.eye(6),), ["(..., 4, 4)", "(6, 6)"]),
    (se3.inverse, (np.zeros(16),), ["(..., 4, 4)", "(16,)"]),
    (se3.ad, (np.zeros(3),), ["(..., 6)", "(3,)"]),
    (se3.ad_star, (np.zeros((6, 1)),), ["(..., 6)", "(6, 1)"]),
    (se3.dexp, (np.zeros(7),), ["(..., 6)", "(7,)"]),
    (se3.dexp_inv, (5.0,), ["(..., 6)", "()"]),
    (so3.hat, (None,), ["(..., 3)", "got ()"]),
    (se3.hat, (np.zeros((4, 4)),), ["(..., 6)", "(4, 4)"]),
    (se3.vee, (np.zeros((3, 3)),), ["(..., 4, 4)", "(3, 3)"]),
    (euler.to_matrix, (np.zeros(2),), ["angles", "(..., 3)", "(2,)"]),
    (euler.from_matrix, (np.zeros((3, 2)),), ["(..., 3, 3)", "(3, 2)"]),
    (dynamics.free_acceleration, (np.zeros(5), I6), ["V", "(..., 6)", "(5,)"]),
    (dynamics.free_acceleration, (np.zeros(6), np.eye(5)), ["inertia", "(..., 6, 6)", "(5, 5)"]),
    (dynamics.free_acceleration, (np.zeros(6), I6, np.zeros(3)), ["wrench", "(3,)"]),
    (dynamics.kinetic_energy, (np.zeros(6), np.eye(3)), ["inertia", "(3, 3)"]),
    (dynamics.g_ddot, (np.eye(4), np.zeros(6), np.zeros(5)), ["V_dot", "(5,)"]),
    (dynamics.spatial_momentum, (np.eye(3), np.zeros(6), I6), ["g", "(3, 3)"]),
    (dynamics.spatial_inertia, (1.0, np.eye(3)[None]), ["(3, 3)", "(1, 3, 3)"]),
]


def _id(case):
    return getattr(case, "__name__", None)


@pytest.mark.parametrize(("func", "args", "fragments"), BAD_SHAPES, ids=_id)
def test_wrong_shape_raises_shape_error_stating_expected_and_received(func, args, fragments):
    with pytest.raises(ShapeError) as info:
        func(*args)
    for fragment in fragments:
        assert fragment in str(info.value)
    assert isinstance(info.value, ValueError) and isinstance(info.value, GmukError)


@pytest.mark.parametrize(
    ("func", "arg"),
    [(so3.log, "abc"), (se3.exp, [[1.0, 2.0], [3.0]]), (se3.Ad, {"g": 1})],
)
def test_non_numeric_input_raises_shape_error_naming_its_type(func, arg):
    with pytest.raises(ShapeError, match="could not convert " + type(arg).__name__):
        func(arg)


BAD_VALUES = [
    (so3.exp, [np.nan, 0.0, 0.0], "1 NaN/inf entry in an array of shape (3,)"),
    (se3.exp, np.full((2, 6), np.inf), "12 NaN/inf entries in an array of shape (2, 6)"),
    (so3.log, np.diag([1.0, np.nan, 1.0]), "shape (3, 3)"),
    (se3.log, np.where(np.eye(4) > 0, -np.inf, 0.0), "shape (4, 4)"),
    (se3.dexp_inv, [0.0, 0.0, 0.0, np.nan, 1.0, 1.0], "shape (6,)"),
    (euler.to_matrix, [0.1, np.inf, 0.0], "1 NaN/inf entry"),
]


@pytest.mark.parametrize(("func", "arg", "fragment"), BAD_VALUES, ids=_id)
def test_nan_or_inf_raises_non_finite_error_counting_the_entries(func, arg, fragment):
    with pytest.raises(NonFiniteError) as info:
        func(arg)
    assert "must be finite" in str(info.value) and fragment in str(info.value)
    assert isinstance(info.value, ValueError) and isinstance(info.value, GmukError)


def test_non_finite_wrench_raises_non_finite_error():
    with pytest.raises(NonFiniteError, match="wrench"):
        dynamics.free_acceleration(np.zeros(6), I6, [0.0, 0.0, 0.0, 0.0, 0.0, np.nan])


NOT_ROTATIONS = [
    (so3.log, REFLECTION, "det = -1"),
    (so3.log, SCALED, "max|RᵀR − I| = 3, det = 8"),
    (so3.log, np.array([[1.0, 1e-6, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), "1e-06"),
    (euler.from_matrix, REFLECTION, "det = -1"),
    (se3.log, _se3_with_rotation(REFLECTION), "rotation block of g"),
    (se3.Ad, _se3_with_rotation(SCALED), "det = 8"),
    (se3.inverse, _se3_with_rotation(-np.eye(3)), "det = -1"),
    (se3.log, _se3_with_last_row([0.0, 0.0, 0.0, 2.0]), "last row [0, 0, 0, 1]"),
    (se3.Ad, _se3_with_last_row([1.0, 0.0, 0.0, 1.0]), "off by 1"),
    (se3.inverse, _se3_with_last_row([0.0, 0.0, 1e-6, 1.0]), "off by 1e-06"),
]


@pytest.mark.parametrize(("func", "arg", "fragment"), NOT_ROTATIONS, ids=_id)
def test_matrices_off_the_group_raise_not_on_group_error_with_what_came_in(func, arg, fragment):
    with pytest.raises(NotOnGroupError) as info:
        func(arg)
    assert fragment in str(info.value)
    assert isinstance(info.value, ValueError) and isinstance(info.value, GmukError)


def test_dynamics_rejects_a_pose_off_the_group():
    with pytest.raises(NotOnGroupError, match="last row"):
        dynamics.g_ddot(_se3_with_last_row([0.0, 0.0, 0.0, 2.0]), np.zeros(6), np.zeros(6))
    with pytest.raises(NotOnGroupError, match="det = -1"):
        dynamics.spatial_momentum(_se3_with_rotation(REFLECTION), np.zeros(6), I6)


def test_batched_rotation_check_reports_the_index_of_the_bad_element():
    R = np.stack([np.eye(3), np.diag([1.0, -1.0, -1.0]), REFLECTION, np.eye(3)]).reshape(2, 2, 3, 3)
    with pytest.raises(NotOnGroupError, match=r"at index \(1, 0\)"):
        so3.log(R)


def test_rotation_tolerance_accepts_round_off_and_rejects_larger_errors():
    R = so3.exp([0.3, -0.2, 1.0])
    R_ok = R * (1.0 + 0.1 * GROUP_TOL)
    R_bad = R * (1.0 + 10.0 * GROUP_TOL)
    assert check_rotation(R_ok) is not None
    with pytest.raises(NotOnGroupError):
        check_rotation(R_bad)


def test_checks_return_the_input_values_unrepaired():
    R = so3.exp([0.3, -0.2, 1.0]) * (1.0 + 0.1 * GROUP_TOL)
    assert np.array_equal(check_rotation(R), R)
    g = se3.exp([0.3, -0.2, 1.0, 4.0, 5.0, 6.0])
    g[3, 3] += 0.1 * GROUP_TOL
    assert np.array_equal(check_se3(g), g)


def test_as_array_can_forbid_batch_axes():
    assert as_array([1, 2, 3], (3,), "x", batch=False).dtype == np.float64
    with pytest.raises(ShapeError, match=r"x must have shape \(3,\); got \(1, 3\)"):
        as_array([[1, 2, 3]], (3,), "x", batch=False)
