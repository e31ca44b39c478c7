"""Hostile inputs and the outcome rule shared by the fuzz tests (not a test module).

The rule (issue #15): a public function either returns a result free of NaN and inf, or
raises a :class:`gmuk.errors.GmukError`; anything else (a raw ``TypeError``, a numpy
warning turned error, ``SystemExit``) fails the test, and so does a call that takes longer
than :data:`HANG_S` seconds of wall time (a hang: the call is interrupted by ``SIGALRM``).
``COUNTS`` records how many inputs each entry point received, ``HANGS`` the calls that
overran, both reported at the end of the run (see ``conftest.py``).
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import math
import os
import signal
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from gmuk.errors import GmukError, GmukWarning

#: Inputs each entry point received in this process, by entry point.
COUNTS: collections.Counter[str] = collections.Counter()

#: Calls that overran :data:`HANG_S`, by entry point.
HANGS: collections.Counter[str] = collections.Counter()

#: A call longer than this (s of wall time) is a hang (issue #25); ``GMUK_FUZZ_HANG_S``.
HANG_S = float(os.environ.get("GMUK_FUZZ_HANG_S", "60"))

#: Failures by test and class ("raw exception", "wrong result", "hang"): under
#: ``GMUK_FUZZ_TALLY=1`` a failing example is recorded here and the run goes on, so that
#: one run counts every failure instead of stopping at the first (each test still fails
#: at its end if it recorded any). Values: (input, message) of the first few.
FAILURES: dict[tuple[str, str], list[tuple[str, str]]] = collections.defaultdict(list)
FAILURE_COUNTS: collections.Counter[tuple[str, str]] = collections.Counter()
TALLY = os.environ.get("GMUK_FUZZ_TALLY", "") not in ("", "0")

#: Examples per test: a fast sample in the default suite, the bulk under ``-m slow``.
#: ``GMUK_FUZZ_SCALE`` multiplies the slow counts (e.g. 0.1 for a quick look).
SLOW_SCALE = float(os.environ.get("GMUK_FUZZ_SCALE", "1"))


class Refused(Exception):
    """Stands for "the call raised a GmukError" in :func:`outcome`."""


class Hang(BaseException):
    """Raised into a call that overran its wall-clock budget (a BaseException, so that no
    ``except Exception`` on the way can turn it into an ordinary outcome)."""


@contextlib.contextmanager
def wall_clock_guard(entry: str, seconds: float | None = None) -> Iterator[None]:
    """Fail (and count in :data:`HANGS`) a block that runs longer than ``seconds``.

    In the main thread the block is interrupted by ``SIGALRM`` (a compiled loop is
    interrupted at its next call back into Python); elsewhere it is timed only.
    """
    limit = HANG_S if seconds is None else seconds
    main = threading.current_thread() is threading.main_thread()
    previous: Any = None

    def alarm(signum: int, frame: Any) -> None:
        raise Hang(f"{entry}: no answer after {limit:g} s")

    if main:
        previous = signal.signal(signal.SIGALRM, alarm)
        signal.setitimer(signal.ITIMER_REAL, limit)
    start = time.monotonic()
    try:
        yield
    except Hang:
        HANGS[entry] += 1
        raise AssertionError(f"{entry}: a hang (over {limit:g} s)") from None
    finally:
        if main:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, previous)
    elapsed = time.monotonic() - start
    if elapsed > limit:
        HANGS[entry] += 1
        raise AssertionError(f"{entry}: a hang ({elapsed:.1f} s, over {limit:g} s)")


def outcome(
    entry: str, fn: Callable[..., Any], *args: Any, hang_s: float | None = None, **kwargs: Any
) -> Any:
    """``fn(*args, **kwargs)`` under the rule; returns the result, or :data:`REFUSED`.

    Every warning is an error here, so that a numpy overflow or a discarded imaginary
    part cannot pass as success; the call is timed by :func:`wall_clock_guard`
    (``hang_s`` seconds, default :data:`HANG_S`).
    """
    COUNTS[entry] += 1
    try:
        with wall_clock_guard(entry, hang_s), warnings.catch_warnings():
            warnings.simplefilter("error")
            warnings.simplefilter("ignore", DeprecationWarning)
            warnings.simplefilter("ignore", GmukWarning)  # gmuk's own, documented warnings
            out = fn(*args, **kwargs)
    except GmukError as exc:
        assert str(exc), f"{entry}: a GmukError without a message"
        return REFUSED
    assert_finite(out, entry)
    return out


REFUSED = Refused()


def assert_finite(x: Any, where: str, depth: int = 0) -> None:
    """Every float in ``x`` (arrays, numbers, tuples, lists, dicts, dataclasses) is finite."""
    if depth > 4 or x is None:
        return
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "fc":
            assert np.isfinite(x).all(), f"{where}: a result holds NaN or inf:\n{x!r:.400}"
        return
    if isinstance(x, (float, np.floating, complex)):
        assert math.isfinite(abs(x)), f"{where}: a result is {x!r}"
        return
    if isinstance(x, (tuple, list)):
        for item in x:
            assert_finite(item, where, depth + 1)
    elif isinstance(x, dict):
        for item in x.values():
            assert_finite(item, where, depth + 1)
    elif dataclasses.is_dataclass(x) and not isinstance(x, type):
        for f in dataclasses.fields(x):
            assert_finite(getattr(x, f.name), where, depth + 1)


def honest_real(x: Any) -> bool:
    """Whether ``x`` is honest real numeric data: no bools, complex numbers, strings, bytes,
    None or other objects anywhere (the inputs that must never be taken silently)."""
    if isinstance(x, (bool, np.bool_, str, bytes, complex, np.complexfloating)) or x is None:
        return False
    if isinstance(x, (int, float, np.integer, np.floating)):
        return True
    if isinstance(x, np.ndarray):
        if x.dtype.kind == "O":
            return all(honest_real(v) for v in x.flat)
        return x.dtype.kind in "iuf"
    if isinstance(x, (list, tuple)):
        return all(honest_real(v) for v in x)
    return False


def real_array(x: Any) -> np.ndarray | None:
    """``x`` as a float array if it is honest real data (after the conversion numpy would
    do; any shape, finite or not), else None."""
    if not honest_real(x):
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return np.asarray(x, dtype=float)
    except (TypeError, ValueError, OverflowError):
        return None


def regular_array(x: Any, shape: tuple[int, ...]) -> np.ndarray | None:
    """``x`` as a float array if it is honest real data of exactly ``shape`` (after the
    conversion numpy would do), else None."""
    a = real_array(x)
    return a if a is not None and a.shape == shape else None


# --------------------------------------------------------------------------- strategies
SPECIAL = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    math.nan,
    math.inf,
    -math.inf,
    1e308,
    -1e308,
    1.7976931348623157e308,
    5e-324,
    -5e-324,
    2.2250738585072014e-308,
    1e-300,
    1e300,
    1e154,
]

#: Numbers: ordinary, special, and the same as ints and numpy scalars.
numbers = st.one_of(
    st.floats(-10.0, 10.0),
    st.sampled_from(SPECIAL),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(10**3), 10**3),
)

junk = st.one_of(
    st.none(),
    st.text(max_size=5),
    st.sampled_from(["1.0", "nan", "", "3", "1e308", "x"]),
    st.binary(max_size=4),
    st.booleans(),
    st.complex_numbers(max_magnitude=10.0),
    st.dictionaries(st.text(max_size=2), st.integers(), max_size=2),
    st.builds(object),
    st.just(10**400),
    st.just(-(10**400)),
    st.just(Ellipsis),
)


def _wrap_scalar(x: Any) -> st.SearchStrategy[Any]:
    return st.sampled_from(
        [x, np.float64(x), np.array(x), np.float32(x) if abs(x) < 3e38 else np.float64(x)]
    )


scalars = st.one_of(numbers.flatmap(_wrap_scalar), junk)


def _shape_variants(shape: tuple[int, ...]) -> st.SearchStrategy[tuple[int, ...]]:
    wrong = [
        (),
        (0,),
        (*shape[:-1], shape[-1] + 1),
        (*shape[:-1], shape[-1] - 1),
        (1, *shape),
        (2, *shape),
        (0, *shape),
        shape[::-1],
        (shape[-1],),
        (*shape, 1),
    ]
    return st.one_of(st.just(shape), st.just(shape), st.sampled_from(wrong))


def arrays(shape: tuple[int, ...], elements: st.SearchStrategy[float] = numbers):
    """Arrays of ``shape`` or a wrong shape, of hostile numbers, as ndarrays (float, int,
    bool, complex, object), nested lists, or ragged lists; plus junk."""

    def build(draw_shape: tuple[int, ...]) -> st.SearchStrategy[Any]:
        size = int(np.prod(draw_shape)) if draw_shape else 1
        flat = st.lists(elements, min_size=size, max_size=size)

        def as_kind(values: list[Any], kind: str) -> Any:
            a = np.array([float(v) for v in values], dtype=float).reshape(draw_shape)
            if kind == "float":
                return a
            if kind == "list":
                return a.tolist()
            if kind == "f32":
                with np.errstate(over="ignore"):
                    return a.astype(np.float32)
            if kind == "int":
                return np.nan_to_num(a, posinf=7, neginf=-7).clip(-1e6, 1e6).astype(np.int64)
            if kind == "bool":
                return a != 0
            if kind == "complex":
                return a + 1j
            if kind == "str":
                return a.astype(str)
            if kind == "object":
                o = np.empty(draw_shape, dtype=object)
                o[...] = a
                if o.size:
                    o.flat[0] = None
                return o
            if kind == "ragged" and len(draw_shape) >= 1 and draw_shape[0] > 0:
                lst = a.tolist()
                lst[0] = [lst[0], lst[0]] if not isinstance(lst[0], list) else lst[0][:-1]
                return lst
            return a

        kinds = st.sampled_from(
            ["float"] * 6
            + ["list", "list", "f32", "int", "bool", "complex", "str", "object", "ragged"]
        )
        return st.tuples(flat, kinds).map(lambda vk: as_kind(*vk))

    return st.one_of(_shape_variants(shape).flatmap(build), junk, scalars)


def finite_vectors(n: int, bound: float = 10.0) -> st.SearchStrategy[np.ndarray]:
    return st.lists(st.floats(-bound, bound), min_size=n, max_size=n).map(np.array)


def rotations() -> st.SearchStrategy[np.ndarray]:
    """Rotation matrices, and near-misses: scaled, reflected, sheared, perturbed."""

    def build(w: np.ndarray, how: str, eps: float) -> np.ndarray:
        with np.errstate(all="ignore"):  # 0·inf in a near-miss is the point, not a warning
            return _near_rotation(w, how, eps)

    def _near_rotation(w: np.ndarray, how: str, eps: float) -> np.ndarray:
        from gmuk.lie import so3

        R = so3.exp(w)
        if how == "exact":
            return R
        if how == "scaled":
            return R * (1.0 + eps)
        if how == "reflected":
            return R @ np.diag([1.0, 1.0, -1.0])
        if how == "perturbed":
            P = R.copy()
            P[0, 1] += eps
            return P
        if how == "singular":
            P = R.copy()
            P[:, 2] = 0.0
            return P
        return R * 0.0 + eps  # constant

    return st.builds(
        build,
        finite_vectors(3, 4.0),
        st.sampled_from(["exact"] * 4 + ["scaled", "reflected", "perturbed", "singular", "const"]),
        st.sampled_from([1e-12, 1e-10, 1e-8, 1e-3, 1.0, 1e300, math.nan, math.inf]),
    )


def poses() -> st.SearchStrategy[Any]:
    """4×4 SE(3) elements and near-misses (bad last row, non-rotation block, NaN)."""

    def build(R: np.ndarray, r: np.ndarray, row: str) -> np.ndarray:
        g = np.eye(4)
        g[:3, :3], g[:3, 3] = R, r
        if row == "bad":
            g[3, 0] = 1e-6
        elif row == "scaled":
            g[3, 3] = 2.0
        return g

    r = st.one_of(finite_vectors(3, 1e3), st.lists(numbers, min_size=3, max_size=3).map(np.array))
    return st.one_of(
        st.builds(build, rotations(), r, st.sampled_from(["ok"] * 5 + ["bad", "scaled"])),
        arrays((4, 4)),
    )


# --------------------------------------------------------------------------- test factory
def _record(check: Callable[..., Any], kind: str, value: Any, exc: BaseException) -> None:
    key = (getattr(check, "__name__", repr(check)), kind)
    FAILURE_COUNTS[key] += 1
    if len(FAILURES[key]) < 3:
        message = f"{type(exc).__name__}: {exc}".splitlines()[0][:300]
        FAILURES[key].append((repr(value)[:300], message))


def fuzz_pair(
    strategy: st.SearchStrategy[Any],
    check: Callable[[Any], None],
    *,
    fast: int,
    slow: int,
    fast_phases: bool = True,
) -> tuple[Callable[[], None], Callable[[], None]]:
    """Two derandomized hypothesis tests of ``check`` on ``strategy``: ``fast`` examples for
    the default suite and ``slow`` examples marked ``slow``."""

    def make(n: int, quick: bool = False) -> Callable[[], None]:
        @settings(
            derandomize=True,
            deadline=None,
            max_examples=n,
            database=None,
            suppress_health_check=list(HealthCheck),
            # the default suite reports a failing example as found (shrinking a compiled
            # loop's failure takes minutes); the slow suite shrinks to a minimal reproducer
            phases=(Phase.explicit, Phase.generate) if quick else tuple(Phase),
        )
        @given(value=strategy)
        def run(value: Any) -> None:
            if not TALLY:
                check(value)
                return
            try:
                check(value)
            except AssertionError as exc:
                kind = "hang" if "a hang" in str(exc) else "wrong result"
                _record(check, kind, value, exc)
            except Exception as exc:
                _record(check, "raw exception", value, exc)

        if not TALLY:
            return run

        def tallied() -> None:
            before = sum(FAILURE_COUNTS.values())
            run()
            found = sum(FAILURE_COUNTS.values()) - before
            assert not found, f"{found} failing examples (see the fuzz summary)"

        return tallied

    return make(fast, fast_phases), pytest.mark.slow(make(max(1, round(slow * SLOW_SCALE))))
