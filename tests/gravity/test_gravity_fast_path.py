"""The single-point fast path of SphericalHarmonicField equals the general path bit for bit.

Single positions of shape (3,) and dtype float64 go to dedicated compiled entries
(``gmuk.gravity._kernels.*_at``) called without numba's type dispatch; every other input goes
through the batch kernel. Both run the same per-point code, so their numbers must agree
exactly, and the fast path must not touch the caller's array.
"""

from __future__ import annotations

import numpy as np
import pytest

from gmuk.errors import DomainError, NonFiniteError, ShapeError
from gmuk.gravity import _kernels, moon_low_degree

from .refs import kaula_field


def _fields():
    return [
        kaula_field(0, seed=1),
        kaula_field(1, seed=1),
        kaula_field(2, seed=2, amplitude=1e-4),
        moon_low_degree(),
        kaula_field(10, seed=5, amplitude=1e-4),
        kaula_field(60, seed=6),
        kaula_field(400, seed=7),
    ]


def _points(radius):
    rng = np.random.default_rng(11)
    u = rng.normal(size=(12, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    pts = u * radius * rng.uniform(1.01, 1.6, size=(12, 1))
    special = radius * np.array(
        [
            [0.0, 0.0, 1.1],  # north pole
            [0.0, 0.0, -1.05],  # south pole
            [1e-9, 0.0, 1.2],  # next to a pole
            [3e-4, -2e-4, -1.02],
            [1.1, 0.0, 0.0],  # equator, on the axes
            [0.0, -1.3, 0.0],
        ]
    )
    return np.vstack([pts, special])


@pytest.mark.parametrize("field", _fields(), ids=lambda f: f"degree{f.degree}")
def test_single_point_equals_batch_of_one_bit_for_bit(field):
    for r in _points(field.radius):
        one = r[None, :]
        for central in (True, False):
            a = field.acceleration(r, central=central)
            assert a.shape == (3,) and a.dtype == np.float64
            np.testing.assert_array_equal(a, field.acceleration(one, central=central)[0])
            U = field.potential(r, central=central)
            assert isinstance(U, float)
            assert U == field.potential(one, central=central)[0]
            H = field.hessian(r, central=central)
            np.testing.assert_array_equal(H, field.hessian(one, central=central)[0])
            a2, H2 = field.acceleration_hessian(r, central=central)
            np.testing.assert_array_equal(a2, a)
            np.testing.assert_array_equal(H2, H)
            ev = field.evaluate(r, potential=False, hessian=True, central=central)
            assert ev.potential is None
            np.testing.assert_array_equal(ev.acceleration, a)
            np.testing.assert_array_equal(ev.hessian, H)
            full = field.evaluate(r, hessian=True, central=central)
            assert full.potential == U
            np.testing.assert_array_equal(full.acceleration, a)
            np.testing.assert_array_equal(full.hessian, H)


def test_fast_path_leaves_the_input_alone_and_returns_a_new_array():
    field = kaula_field(8, seed=3, amplitude=1e-4)
    r = np.array([1.2e6, -0.9e6, 1.1e6])
    keep = r.copy()
    a = field.acceleration(r)
    b = field.acceleration(r)
    np.testing.assert_array_equal(r, keep)
    assert a is not r and not np.shares_memory(a, r)
    assert a is not b and not np.shares_memory(a, b)
    assert a.flags.writeable and a.flags.c_contiguous
    a[0] = 0.0  # the caller owns it
    np.testing.assert_array_equal(field.acceleration(r), b)
    ev = field.evaluate(r, potential=False, hessian=True)
    np.testing.assert_array_equal(r, keep)
    assert not np.shares_memory(ev.acceleration, r)
    ro = r.copy()
    ro.setflags(write=False)
    np.testing.assert_array_equal(field.acceleration(ro), b)


def test_inputs_that_take_the_general_path_give_the_same_numbers():
    field = kaula_field(8, seed=3, amplitude=1e-4)
    r = np.array([1_200_000.0, -900_000.0, 1_100_000.0])  # exact in every dtype below
    ref = field.acceleration(r)
    for other in (
        [1_200_000.0, -900_000.0, 1_100_000.0],
        (1_200_000, -900_000, 1_100_000),  # integers
        r.astype(np.float32),
        r.astype(">f8"),  # not native byte order
        r.astype(object),
        np.stack([r, r], axis=1)[:, 0],  # a non-contiguous view
    ):
        np.testing.assert_array_equal(field.acceleration(other), ref)
        np.testing.assert_array_equal(
            field.evaluate(other, potential=False, hessian=True).acceleration, ref
        )
        assert field.potential(other) == field.potential(r)


def test_fast_path_errors_name_the_position_and_leave_the_input_alone():
    field = kaula_field(300, seed=3)
    bad = np.array([1e6, np.nan, 0.0])
    with pytest.raises(NonFiniteError, match=r"r_F must be finite; got \[.*nan"):
        field.acceleration(bad)
    with pytest.raises(DomainError, match="is the origin"):
        field.evaluate(np.zeros(3), potential=False, hessian=True)
    inside = np.array([1.0, 2.0, 3.0])
    with pytest.raises(DomainError, match=r"r_F = \[1\., 2\., 3\.\] m"):
        field.acceleration(inside, central=False)
    with pytest.raises(DomainError, match=r"r_F = \[1\., 2\., 3\.\] m"):
        field.potential(inside)
    np.testing.assert_array_equal(inside, [1.0, 2.0, 3.0])
    for method in (field.acceleration, field.potential, field.acceleration_hessian):
        for wrong in (np.ones(4), np.ones(2), np.ones(0)):
            with pytest.raises(ShapeError, match=rf"got \({len(wrong)},\)"):
                method(wrong)  # float64, one dimension, but not a position
    with pytest.raises(ShapeError, match=r"got \(4,\)"):
        field.evaluate(np.ones(4), potential=False, hessian=True)
    with pytest.raises(ShapeError, match="could not convert"):
        field.evaluate(["a", "b", "c"], potential=False, hessian=True)
    with pytest.raises(NonFiniteError, match="r_F must be finite"):
        field.evaluate([np.inf, 0.0, 1e6], potential=False, hessian=True, central=False)


def test_entry_falls_back_to_the_dispatcher():
    class NotCompiled:
        def __init__(self):
            self.overloads = {}

    k = NotCompiled()
    assert _kernels.entry(k) is k
    assert callable(_kernels.ENTRIES.acceleration_at)


def _padded(field, N):
    """The same field written with degree N > field.degree (zero coefficients above)."""
    C = np.zeros((N + 1, N + 1))
    S = np.zeros((N + 1, N + 1))
    n = field.degree + 1
    C[:n, :n] = field.C
    S[:n, :n] = field.S
    return type(field)(field.mu, field.radius, C, S)


@pytest.mark.parametrize(
    "N",
    [
        _kernels.FLAT_WIDTH - 3,  # largest degree whose workspaces are all flat
        (_kernels.STACK_FLOATS - 26) // 8 - 3,  # largest degree whose workspaces all fit
        _kernels.WEIGHTED,  # largest degree with stored gradient weights
    ],
)
def test_degrees_on_either_side_of_the_kernel_thresholds_agree(N):
    # One more degree crosses to a ring workspace, to a heap workspace (with the Hessian) or
    # to gradient sums that multiply their weights themselves; the numbers must not notice
    # beyond round-off.
    low = kaula_field(N, seed=9, amplitude=1e-4)
    high = _padded(low, N + 1)
    if N == _kernels.FLAT_WIDTH - 3:
        assert _kernels.layout(N, 6)[0] and not _kernels.layout(N + 1, 6)[0]
    elif N != _kernels.WEIGHTED:
        assert _kernels.workspace_size(N, 6) <= _kernels.STACK_FLOATS
        assert _kernels.workspace_size(N + 1, 6) > _kernels.STACK_FLOATS
    for r in _points(low.radius):
        a = low.acceleration(r)
        np.testing.assert_allclose(high.acceleration(r), a, rtol=1e-14, atol=0)
        np.testing.assert_array_equal(high.acceleration(r[None, :])[0], high.acceleration(r))
        ev, evh = (f.evaluate(r, potential=False, hessian=True) for f in (low, high))
        scale = np.abs(ev.hessian).max()
        np.testing.assert_allclose(evh.hessian, ev.hessian, rtol=0, atol=1e-14 * scale)
        np.testing.assert_allclose(high.potential(r), low.potential(r), rtol=1e-15)


def _in_layout(field, r, mode, flat):
    """The ten results of the per-point kernel at ``r`` with the workspace laid out as told."""
    lead = 2 if mode & 4 else (1 if mode & 2 else 0)
    W = field.degree + lead + 1
    Q = np.zeros((W + 2) * (W if flat else 8) + 10)
    code = _kernels._point(field._data, r[0], r[1], r[2], mode, Q, flat)
    return code, Q[-10:]


@pytest.mark.parametrize("N", [0, 1, 2, 7, 20, _kernels.FLAT_WIDTH - 3])
def test_flat_and_ring_layouts_give_the_same_numbers_bit_for_bit(N):
    # Up to FLAT_WIDTH the workspace is flat (every column first, then every sum), above it
    # a ring of eight columns made as needed. The arithmetic is the same, so the numbers
    # must be too: in every mode, off and on the polar axis, very near it (seeds renormalised
    # as extended-exponent numbers), far away and below the reference sphere.
    field = kaula_field(N, seed=3, amplitude=1e-3)
    R = field.radius
    special = np.array(
        [
            [1e-300, 0.0, 1.2 * R],
            [0.0, -5e-324, -1.1 * R],
            [3e-160, 2e-160, 1.3 * R],
            [4e10, -3e10, 1e10],
            [0.3 * R, 0.2 * R, -0.1 * R],
        ]
    )
    points = np.vstack([_points(R), special])
    for mode in range(1, 16):
        if not mode & 7:
            continue
        for r in points:
            flat = _in_layout(field, r, mode, True)
            ring = _in_layout(field, r, mode, False)
            assert flat[0] == ring[0]
            np.testing.assert_array_equal(flat[1], ring[1])


def test_central_is_keyword_only():
    field = kaula_field(10, seed=5, amplitude=1e-4)
    r = np.array([1.2e6, -0.9e6, 1.0e6])
    methods = (field.potential, field.acceleration, field.hessian, field.acceleration_hessian)
    for method in methods:
        for pts in (r, r[None, :], list(r)):
            with pytest.raises(TypeError, match="positional argument"):
                method(pts, False)
    assert not np.array_equal(field.acceleration(r, central=False), field.acceleration(r))


def test_float64_vectors_of_any_stride_read_in_place_give_the_same_numbers():
    # The single-point entries read the caller's float64 vector where it lies (strided,
    # reversed or read-only); the numbers are those of a contiguous copy, bit for bit.
    field = kaula_field(12, seed=4, amplitude=1e-4)
    r = np.array([1.2e6, -0.9e6, 1.1e6])
    a, H = field.acceleration(r), field.hessian(r)
    U = field.potential(r)
    block = np.zeros((3, 4))
    block[:, 2] = r
    views = [
        block[:, 2],  # a column: stride 32 bytes
        r[::-1].copy()[::-1],  # negative stride
        np.repeat(r, 3)[::3],
    ]
    ro = r.copy()
    ro.setflags(write=False)
    views.append(ro)
    for v in views:
        np.testing.assert_array_equal(v, r)
        keep = v.copy()
        np.testing.assert_array_equal(field.acceleration(v), a)
        np.testing.assert_array_equal(field.acceleration_hessian(v)[1], H)
        assert field.potential(v) == U
        np.testing.assert_array_equal(v, keep)


def test_central_flag_is_read_by_truth_value_on_every_path():
    field = kaula_field(6, seed=2, amplitude=1e-4)
    r = np.array([1.2e6, -0.9e6, 1.1e6])
    one = r[None, :]
    for flag in (True, False, 1, 0, np.bool_(True), np.bool_(False), None, 2.0):
        want = bool(flag)
        a_one = field.acceleration(one, central=want)[0]
        np.testing.assert_array_equal(field.acceleration(r, central=flag), a_one)
        a, H = field.acceleration_hessian(r, central=flag)
        np.testing.assert_array_equal(a, a_one)
        np.testing.assert_array_equal(H, field.hessian(one, central=want)[0])
        assert field.potential(r, central=flag) == field.potential(one, central=want)[0]


def test_acceleration_hessian_of_batches_and_lists():
    field = kaula_field(9, seed=8, amplitude=1e-4)
    pts = _points(field.radius)
    a, H = field.acceleration_hessian(pts)
    assert a.shape == (len(pts), 3) and H.shape == (len(pts), 3, 3)
    np.testing.assert_array_equal(a, field.acceleration(pts))
    np.testing.assert_array_equal(H, field.hessian(pts))
    a1, H1 = field.acceleration_hessian(list(pts[3]))
    np.testing.assert_array_equal(a1, a[3])
    np.testing.assert_array_equal(H1, H[3])
    grid = pts[:6].reshape(2, 3, 3)
    ag, Hg = field.acceleration_hessian(grid, central=False)
    assert ag.shape == (2, 3, 3) and Hg.shape == (2, 3, 3, 3)
    np.testing.assert_array_equal(ag.reshape(6, 3), field.acceleration(pts[:6], central=False))
    a2, H2 = field.acceleration_hessian(pts[0])
    assert not np.shares_memory(a2, H2) and a2.flags.writeable and H2.flags.writeable
