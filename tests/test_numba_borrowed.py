"""gmuk._numba.borrowed: an array without reference counting, for the compiled kernels' views."""

from __future__ import annotations

import sys
from typing import NamedTuple

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from gmuk._numba import borrowed


@njit
def _sum_rows_and_mark(a, mark):
    b = borrowed(a)
    total = 0.0
    for i in range(b.shape[0]):
        row = b[i]  # a view of the borrowed array
        for j in range(row.shape[0]):
            total += row[j]
    b[0, 0] = mark
    return total, b.shape[0], b.shape[1], b.strides[0], b.strides[1]


@pytest.mark.parametrize("layout", ["C", "F", "strided"])
def test_a_borrowed_array_reads_and_writes_the_same_memory_with_its_layout(layout):
    base = np.arange(24.0).reshape(4, 6)
    a = {"C": base, "F": np.asfortranarray(base), "strided": base[::2, ::3]}[layout]
    expected = float(a.sum())
    total, n0, n1, s0, s1 = _sum_rows_and_mark(a, -1.0)
    assert total == expected
    assert (n0, n1) == a.shape and (s0, s1) == a.strides
    assert a[0, 0] == -1.0  # written through


def test_a_borrowed_array_leaves_its_owner_alive_and_whole():
    a = np.ones((3, 3))
    for _ in range(1000):  # a count gone wrong would free or leak the owner
        _sum_rows_and_mark(a, 1.0)
    assert a.sum() == 9.0 and a.flags.owndata


def test_only_arrays_can_be_borrowed():
    @njit
    def bad(x):
        return borrowed(x)

    with pytest.raises(TypingError):
        bad(1.0)


class _Record(NamedTuple):
    rows: np.ndarray
    scale: float
    inner: tuple[np.ndarray, int]


@njit
def _sum_record(rec):
    b = borrowed(rec)  # every array of the record, borrowed; the other members as they were
    total = 0.0
    for i in range(b.rows.shape[0]):
        row = b.rows[i]
        for j in range(row.shape[0]):
            total += row[j]
    b.inner[0][0] = b.scale
    return total * b.scale + b.inner[1]


def test_a_record_is_borrowed_array_by_array_and_its_owners_stay_whole():
    rows, inner = np.arange(12.0).reshape(3, 4).copy(), np.zeros(2)
    rec = _Record(rows, 2.0, (inner, 5))
    counts = sys.getrefcount(rows), sys.getrefcount(inner)
    for _ in range(1000):  # a count gone wrong would free or leak an owner
        assert _sum_record(rec) == 66.0 * 2.0 + 5
    assert (sys.getrefcount(rows), sys.getrefcount(inner)) == counts
    assert inner[0] == 2.0  # written through the borrowed member
    assert rows.flags.owndata and inner.flags.owndata and rows.sum() == 66.0


def test_a_tuple_without_arrays_cannot_be_borrowed():
    @njit
    def bad(x):
        return borrowed(x)

    with pytest.raises(TypingError):
        bad((1.0, 2))
