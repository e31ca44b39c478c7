"""Truncated Taylor jets: exact derivatives of a residual from one call of it.

A :class:`Jet` stands for an array-valued quantity x(ε, τ) of shape S near ε = 0, τ = 0,
where ε = (ε₁ … ε_m) are perturbation coordinates (a constraint's degrees of freedom) and τ
is the time along a path. Its ``data`` of shape ``(K + 2,) + S``, with K = m + 1, holds

* ``data[0]``: the value x(0, 0);
* ``data[1 + k]``, k = 0 … K − 1: the first derivatives ∂x/∂εₖ, the last (k = m) being ∂x/∂τ;
* ``data[K + 1]``: the second derivative ∂²x/∂τ² along the path only.

Every operation propagates the three parts by the chain rule, exactly: for a product
``(ab)ₖ = aₖ b + a bₖ`` and ``(ab)'' = a'' b + 2a'b' + a b''``; for a function of one
argument ``f(a)ₖ = f'(a) aₖ`` and ``f(a)'' = f'(a) a'' + f''(a) a'²``, with ' = ∂/∂τ.
Linear operations (indexing, sums, transposes, products with constants) act on all parts at
once. A jet behaves like a float ndarray for the operations residuals use (the operators,
numpy's ufuncs through ``__array_ufunc__`` and a list of numpy functions through
``__array_function__``); anything else raises :class:`JetUnsupported`, naming the
operation, so that the caller can fall back to finite differences: a jet is never turned
into plain floats silently (``float(jet)`` raises). Comparisons compare the values, so a
residual may branch on them.

This module is private: :class:`gmuk.HolonomicConstraint` and
:class:`gmuk.NonholonomicConstraint` seed the jets (:func:`seed_pose`, :func:`seed_vector`)
and read the rows from the result (:func:`as_jet`).

References
----------
Griewank & Walther, *Evaluating Derivatives* (2nd ed., SIAM 2008), Ch. 13 (univariate
Taylor propagation); the seeds on SE(3) are the series of ``g exp(Σ εₖ eₖ^ + τ V^)``.
"""

from __future__ import annotations

import itertools
import os
import traceback
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.lie import se3

__all__ = [
    "Jet",
    "JetUnsupported",
    "as_jet",
    "seed_pose",
    "seed_scalar",
    "seed_vector",
    "where_raised",
]


_ALL = slice(None)
_BASIC_INDEX = (int, slice)


class JetUnsupported(TypeError):
    """An operation gmuk's jets do not differentiate (the message names it)."""


def _unsupported(what: str) -> JetUnsupported:
    return JetUnsupported(f"{what} is not supported on gmuk's derivative jets")


# --------------------------------------------------------------------------------------
# seeds


def seed_pose(g: FloatArray, V: FloatArray | None, n_parts: int, first: int) -> Jet:
    """The pose ``g exp(Σ εₖ eₖ^ + τ V^)`` as a jet, for a rigid body.

    Parameters
    ----------
    g : ndarray, shape (4, 4)
        Pose g_NB.
    V : ndarray, shape (6,), or None
        Body twist V_B = [ω; v] (rad/s, m/s) of the path direction τ; None for a pose that
        does not move along the path.
    n_parts : int
        K + 2, the length of the jet's first axis.
    first : int
        Index of the body's first degree of freedom among the ε; -1 when the pose is not
        differentiated in ε (e.g. a nonholonomic residual's q, differentiated in ν only).

    Returns
    -------
    Jet, shape (4, 4)
        Value g, ∂/∂εₖ = g eₖ^ (body-frame directions [ω; v]), ∂/∂τ = g V^ and
        ∂²/∂τ² = g V^ V^.
    """
    data = np.zeros((n_parts, 4, 4))
    data[0] = g
    if first >= 0:
        data[1 + first : 7 + first] = g @ se3._HAT_GEN
    if V is not None:
        V_hat = se3._hat(V)
        data[-2] = g @ V_hat
        data[-1] = data[-2] @ V_hat
    return Jet(data)


def seed_vector(x: FloatArray, xdot: FloatArray | None, n_parts: int, first: int) -> Jet:
    """The Euclidean coordinates ``x + Σ εₖ eₖ + τ ẋ`` as a jet.

    Parameters
    ----------
    x : ndarray, shape (m,)
        Coordinates (e.g. r_N in m, or a velocity ν).
    xdot : ndarray, shape (m,), or None
        Rate along the path direction τ; None when x is held along the path.
    n_parts : int
        K + 2, the length of the jet's first axis.
    first : int
        Index of x's first component among the ε; -1 when x is not differentiated in ε.

    Returns
    -------
    Jet, shape (m,)
    """
    m = x.shape[0]
    data = np.zeros((n_parts, m))
    data[0] = x
    if first >= 0:
        data[1 + first : 1 + first + m] = np.eye(m)
    if xdot is not None:
        data[-2] = xdot
    return Jet(data)


def seed_scalar(t: float, n_parts: int) -> Jet:
    """Time ``t + τ`` as a jet: value t (s), ∂/∂τ = 1, every other derivative 0."""
    data = np.zeros(n_parts)
    data[0] = t
    data[-2] = 1.0
    return Jet(data)


def where_raised(exc: BaseException, caller: str) -> str:
    """`` (in name, file:line: code)`` of the frame of ``exc``'s traceback just inside the
    module ``caller`` (a file path): the line of the residual that stopped the jets; empty
    when there is none."""
    caller = os.path.abspath(caller)
    frames = traceback.extract_tb(exc.__traceback__)
    for outer, inner in itertools.pairwise(frames):
        if os.path.abspath(outer.filename) == caller != os.path.abspath(inner.filename):
            where = f"{os.path.basename(inner.filename)}:{inner.lineno}"
            return f" (in {inner.name}, {where}: {inner.line})"
    return ""


def as_jet(result: Any, n_parts: int) -> Jet | None:
    """A residual's result as one jet: a jet as it is, a list or object array of jets and
    numbers stacked; None when no jet is in it (the residual returned plain numbers)."""
    if isinstance(result, Jet):
        return result
    if isinstance(result, np.ndarray) and result.dtype != object:
        return None
    if isinstance(result, (list, tuple)) or (
        isinstance(result, np.ndarray) and result.dtype == object
    ):
        arr = np.asarray(result)
        if arr.dtype == object:
            return _from_objects(arr, n_parts)
    return None


# --------------------------------------------------------------------------------------
# the jet


class Jet:
    """An array-valued jet: value, first derivatives in K directions, second along τ.

    Parameters
    ----------
    data : ndarray, shape (K + 2,) + S
        The parts (see the module docstring); S is the shape of the value.
    """

    __slots__ = ("data",)
    __hash__ = None  # type: ignore[assignment]

    def __init__(self, data: FloatArray) -> None:
        self.data = data

    # -- array attributes ------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        """Shape S of the value."""
        return self.data.shape[1:]

    @property
    def ndim(self) -> int:
        """Number of dimensions of the value."""
        return self.data.ndim - 1

    @property
    def size(self) -> int:
        """Number of entries of the value."""
        return int(np.prod(self.shape))

    @property
    def dtype(self) -> np.dtype[Any]:
        """float64, as the arrays it stands for."""
        return self.data.dtype

    @property
    def T(self) -> Jet:
        """Transpose of the value's axes."""
        return self.transpose()

    def __repr__(self) -> str:
        return f"Jet(value={self.data[0]!r}, directions={self.data.shape[0] - 2})"

    def __len__(self) -> int:
        if self.data.ndim == 1:
            raise TypeError("len() of unsized object")
        return int(self.data.shape[1])

    def __iter__(self) -> Any:
        if self.data.ndim == 1:
            raise TypeError("iteration over a 0-d array")
        return (Jet(self.data[:, i]) for i in range(self.data.shape[1]))

    def __bool__(self) -> bool:
        return bool(self.data[0])

    def _to_float(self, what: str) -> Any:
        raise _unsupported(f"{what}() of a jet (it would drop the derivatives)")

    def __float__(self) -> float:
        return self._to_float("float")

    def __int__(self) -> int:
        return self._to_float("int")

    def __complex__(self) -> complex:
        return self._to_float("complex")

    def __index__(self) -> int:
        return self._to_float("index")

    # -- indexing ----------------------------------------------------------------------
    @staticmethod
    def _key(key: Any) -> tuple[Any, ...]:
        """``key`` for ``data``: the parts axis kept in front."""
        return (_ALL, *key) if type(key) is tuple else (_ALL, key)

    @staticmethod
    def _basic(key: tuple[Any, ...]) -> bool:
        """Whether ``key`` (for ``data``) holds basic indices only (no arrays, no jets)."""
        for k in key:
            if type(k) not in _BASIC_INDEX and k is not None and k is not Ellipsis:
                if isinstance(k, Jet):
                    raise _unsupported("indexing with a jet")
                if not isinstance(k, (int, np.integer)) or isinstance(k, (bool, np.bool_)):
                    return False
        return True

    def __getitem__(self, key: Any) -> Jet:
        full = self._key(key)
        if self._basic(full):
            return Jet(self.data[full])
        # array indices: index the value axes with the parts axis moved to the end, so that
        # numpy's placement of advanced-index axes is the one of the value alone
        key = (*full[1:], _ALL)
        last = np.moveaxis(self.data, 0, -1)[key]
        return Jet(np.moveaxis(last, -1, 0))

    def __setitem__(self, key: Any, value: Any) -> None:
        full = self._key(key)
        self._basic(full)  # rejects a jet as an index
        last = np.moveaxis(self.data, 0, -1)  # a view: writes go to self.data
        v = _operand(value)
        if isinstance(v, Jet):
            target_ndim = np.ndim(self.data[0][full[1:]])
            key = (*full[1:], _ALL)
            last[key] = np.moveaxis(_align(v.data, target_ndim), 0, -1)
        else:
            value_key, derivatives_key = (*full[1:], 0), (*full[1:], slice(1, None))
            last[value_key] = v
            last[derivatives_key] = 0.0

    # -- shape methods -------------------------------------------------------------------
    def copy(self) -> Jet:
        """A jet with its own data."""
        return Jet(self.data.copy())

    def transpose(self, *axes: Any) -> Jet:
        """The value's axes permuted (reversed by default), as ndarray.transpose."""
        if len(axes) == 1 and (axes[0] is None or isinstance(axes[0], (tuple, list))):
            axes = () if axes[0] is None else tuple(axes[0])
        nd = self.ndim
        order = tuple(range(nd - 1, -1, -1)) if not axes else tuple(a % nd for a in axes)
        return Jet(self.data.transpose((0, *(a + 1 for a in order))))

    def reshape(self, *shape: Any, order: str = "C") -> Jet:
        """The value reshaped, as ndarray.reshape (C order only)."""
        if order != "C":
            raise _unsupported(f"reshape(order={order!r})")
        if len(shape) == 1 and isinstance(shape[0], (tuple, list)):
            shape = tuple(shape[0])
        return Jet(self.data.reshape((self.data.shape[0], *shape)))

    def ravel(self) -> Jet:
        """The value flattened to 1-D."""
        return self.reshape(-1)

    flatten = ravel

    def squeeze(self, axis: Any = None) -> Jet:
        """The value without its length-1 axes."""
        if axis is None:
            axis = tuple(i for i, n in enumerate(self.shape) if n == 1)
        return Jet(np.squeeze(self.data, axis=_shift_axes(axis, self.ndim)))

    def sum(self, axis: Any = None, keepdims: bool = False) -> Jet:
        """Sum over ``axis`` (all axes by default), as ndarray.sum."""
        return _sum(self, axis=axis, keepdims=keepdims)

    def mean(self, axis: Any = None, keepdims: bool = False) -> Jet:
        """Mean over ``axis`` (all axes by default)."""
        total = _sum(self, axis=axis, keepdims=keepdims)
        return Jet(total.data * (total.size / self.size))

    def dot(self, other: Any) -> Jet:
        """As :func:`numpy.dot`."""
        return _dot(self, other)

    def trace(self, offset: int = 0, axis1: int = 0, axis2: int = 1) -> Jet:
        """As :func:`numpy.trace`."""
        return _trace(self, offset, axis1, axis2)

    def diagonal(self, offset: int = 0, axis1: int = 0, axis2: int = 1) -> Jet:
        """As :func:`numpy.diagonal`."""
        nd = self.ndim
        return Jet(np.diagonal(self.data, offset, axis1 % nd + 1, axis2 % nd + 1))

    # -- operators -------------------------------------------------------------------------
    def __neg__(self) -> Jet:
        return Jet(-self.data)

    def __pos__(self) -> Jet:
        return Jet(self.data.copy())

    def __abs__(self) -> Jet:
        return _unary(np.absolute, self)

    def __add__(self, other: Any) -> Jet:
        return _add(self, _operand(other))

    def __radd__(self, other: Any) -> Jet:
        return _add(_operand(other), self)

    def __sub__(self, other: Any) -> Jet:
        return _subtract(self, _operand(other))

    def __rsub__(self, other: Any) -> Jet:
        return _subtract(_operand(other), self)

    def __mul__(self, other: Any) -> Jet:
        return _multiply(self, _operand(other))

    def __rmul__(self, other: Any) -> Jet:
        return _multiply(_operand(other), self)

    def __truediv__(self, other: Any) -> Jet:
        return _divide(self, _operand(other))

    def __rtruediv__(self, other: Any) -> Jet:
        return _divide(_operand(other), self)

    def __pow__(self, other: Any) -> Jet:
        return _power(self, _operand(other))

    def __rpow__(self, other: Any) -> Jet:
        return _power(_operand(other), self)

    def __matmul__(self, other: Any) -> Jet:
        return _matmul(self, _operand(other))

    def __rmatmul__(self, other: Any) -> Jet:
        return _matmul(_operand(other), self)

    def __lt__(self, other: Any) -> Any:
        return self.data[0] < _value(_operand(other))

    def __le__(self, other: Any) -> Any:
        return self.data[0] <= _value(_operand(other))

    def __gt__(self, other: Any) -> Any:
        return self.data[0] > _value(_operand(other))

    def __ge__(self, other: Any) -> Any:
        return self.data[0] >= _value(_operand(other))

    def __eq__(self, other: Any) -> Any:
        return self.data[0] == _value(_operand(other))

    def __ne__(self, other: Any) -> Any:
        return self.data[0] != _value(_operand(other))

    # -- numpy protocols -------------------------------------------------------------------
    def __array_ufunc__(self, ufunc: np.ufunc, method: str, *inputs: Any, **kwargs: Any) -> Any:
        name = f"numpy.{ufunc.__name__}"
        if method != "__call__":
            raise _unsupported(f"{name}.{method}")
        if kwargs:
            raise _unsupported(f"{name} with keyword arguments {sorted(kwargs)}")
        args = [_operand(x) for x in inputs]
        if ufunc in _ON_VALUES:
            return ufunc(*(_value(a) for a in args))
        rule = _BINARY.get(ufunc)
        if rule is not None:
            return rule(*args)
        if ufunc in _UNARY_RULES or ufunc in (np.negative, np.positive):
            return _unary(ufunc, args[0])
        raise _unsupported(name)

    def __array_function__(
        self, func: Any, types: Any, args: Sequence[Any], kwargs: dict[str, Any]
    ) -> Any:
        impl = _FUNCTIONS.get(func)
        if impl is None:
            module = getattr(func, "__module__", "numpy") or "numpy"
            raise _unsupported(f"{module}.{getattr(func, '__name__', func)}")
        return impl(*args, **kwargs)


# --------------------------------------------------------------------------------------
# helpers


def _value(x: Any) -> Any:
    return x.data[0] if isinstance(x, Jet) else x


def _operand(x: Any) -> Any:
    """``x`` as a Jet (a jet, or an object array holding jets) or a float constant."""
    if isinstance(x, (Jet, float, int)):
        return x
    if isinstance(x, np.ndarray) and x.dtype.kind in "fiub":
        return x
    arr = np.asarray(x)
    if arr.dtype == object:
        parts = _n_parts_of(arr)
        if parts is None:
            raise _unsupported(f"an operand of type {type(x).__name__} holding no numbers")
        return _from_objects(arr, parts)
    if arr.dtype.kind not in "fiub":
        raise _unsupported(f"an operand of dtype {arr.dtype}")
    return arr


def _n_parts_of(arr: Any) -> int | None:
    for e in arr.flat:
        if isinstance(e, Jet):
            return int(e.data.shape[0])
    return None


def _from_objects(arr: Any, n_parts: int) -> Jet:
    """An object array of 0-d jets and real numbers as one jet."""
    data = np.zeros((n_parts, *arr.shape))
    for index, e in np.ndenumerate(arr):
        if isinstance(e, Jet):
            if e.data.shape != (n_parts,):
                raise _unsupported("an object array holding jets that are not 0-d")
            key = (_ALL, *index)
            data[key] = e.data
        elif isinstance(e, (float, int, np.floating, np.integer)) and not isinstance(e, bool):
            key = (0, *index)
            data[key] = e
        else:
            raise _unsupported(f"an object array holding {type(e).__name__}")
    return Jet(data)


def _const(c: Any, n_parts: int) -> Jet:
    c = np.asarray(c, dtype=float)
    data = np.zeros((n_parts, *c.shape))
    data[0] = c
    return Jet(data)


def _align(data: FloatArray, ndim: int) -> FloatArray:
    """``data`` (parts first) with length-1 axes after the parts axis up to value ``ndim``."""
    missing = ndim - (data.ndim - 1)
    if missing <= 0:
        return data
    return data.reshape((data.shape[0],) + (1,) * missing + data.shape[1:])


def _ndim(x: Any) -> int:
    return x.ndim if isinstance(x, (Jet, np.ndarray)) else 0


def _shift_axes(axis: Any, ndim: int) -> Any:
    """Value axes → data axes (one more, the parts axis in front)."""
    if isinstance(axis, (tuple, list)):
        return tuple(int(a) % ndim + 1 for a in axis)
    return int(axis) % ndim + 1


# --------------------------------------------------------------------------------------
# arithmetic


def _add(a: Any, b: Any) -> Jet:
    if isinstance(a, Jet) and isinstance(b, Jet):
        nd = max(a.ndim, b.ndim)
        return Jet(_align(a.data, nd) + _align(b.data, nd))
    jet, c = (a, b) if isinstance(a, Jet) else (b, a)
    return _plus_const(jet, c)


def _plus_const(jet: Jet, c: Any) -> Jet:
    nd = max(jet.ndim, _ndim(c))
    data = _align(jet.data, nd)
    if nd == jet.ndim and np.shape(c) in ((), jet.shape):
        data = data.copy()
    else:
        shape = np.broadcast_shapes(jet.shape, np.shape(c))
        data = np.broadcast_to(data, (data.shape[0], *shape)).copy()
    data[0] += c
    return Jet(data)


def _subtract(a: Any, b: Any) -> Jet:
    if isinstance(b, Jet):
        return _add(a, Jet(-b.data))
    return _plus_const(a, -np.asarray(b))


def _chain2(a: Jet, b: Jet, f: Any, fa: Any, fb: Any, faa: Any, fab: Any, fbb: Any) -> Jet:
    """F(a, b) from its value f and partial derivatives fa, fb, faa, fab, fbb at (a, b)."""
    nd = max(a.ndim, b.ndim)
    ad, bd = _align(a.data, nd), _align(b.data, nd)
    data = fa * ad + fb * bd
    data[0] = f
    a1, b1 = ad[-2], bd[-2]
    data[-1] += faa * a1 * a1 + 2.0 * fab * a1 * b1 + fbb * b1 * b1
    return Jet(data)


def _multiply(a: Any, b: Any) -> Jet:
    if isinstance(a, Jet) and isinstance(b, Jet):
        nd = max(a.ndim, b.ndim)
        ad, bd = _align(a.data, nd), _align(b.data, nd)
        a0, b0 = ad[0], bd[0]
        data = ad * b0 + a0 * bd
        data[0] = a0 * b0
        data[-1] += 2.0 * ad[-2] * bd[-2]
        return Jet(data)
    jet, c = (a, b) if isinstance(a, Jet) else (b, a)
    return Jet(_align(jet.data, _ndim(c)) * c)


def _divide(a: Any, b: Any) -> Jet:
    if isinstance(b, Jet):
        return _multiply(a, _unary(np.reciprocal, b))
    return Jet(_align(a.data, _ndim(b)) / b)


def _power(a: Any, b: Any) -> Jet:
    if not isinstance(b, Jet):  # a^p, p constant
        p = np.asarray(b, dtype=float)
        x = a.data[0]
        if p.ndim == 0 and float(p) in (0.0, 1.0, 2.0):
            if float(p) == 0.0:
                return _const(np.ones(np.broadcast_shapes(a.shape, p.shape)), a.data.shape[0])
            if float(p) == 1.0:
                return a.copy()
            return _unary(np.square, a)
        f = x**p
        d1 = p * x ** (p - 1.0)
        d2 = p * (p - 1.0) * x ** (p - 2.0)
        return _apply(a, f, d1, d2)
    if not isinstance(a, Jet):  # c^b = exp(b ln c), c constant
        lnc = np.log(np.asarray(a, dtype=float))
        f = np.asarray(a, dtype=float) ** b.data[0]
        return _apply(b, f, f * lnc, f * lnc * lnc)
    x, y = a.data[0], b.data[0]
    f = x**y
    lnx = np.log(x)
    xm1 = x ** (y - 1.0)
    return _chain2(
        a, b, f, y * xm1, f * lnx, y * (y - 1.0) * x ** (y - 2.0), xm1 * (1.0 + y * lnx),
        f * lnx * lnx,
    )  # fmt: skip


def _arctan2(y: Any, x: Any) -> Jet:
    y = y if isinstance(y, Jet) else _const(y, x.data.shape[0])
    x = x if isinstance(x, Jet) else _const(x, y.data.shape[0])
    y0, x0 = y.data[0], x.data[0]
    r2 = x0 * x0 + y0 * y0
    r4 = r2 * r2
    # F = atan2(y, x): F_y = x/r², F_x = −y/r², F_yy = −2xy/r⁴, F_yx = (y² − x²)/r⁴, F_xx = 2xy/r⁴
    return _chain2(
        y, x, np.arctan2(y0, x0), x0 / r2, -y0 / r2, -2.0 * x0 * y0 / r4,
        (y0 * y0 - x0 * x0) / r4, 2.0 * x0 * y0 / r4,
    )  # fmt: skip


def _hypot(a: Any, b: Any) -> Jet:
    return _unary(np.sqrt, _add(_multiply(a, a), _multiply(b, b)))


def _select(pick_a: Any, a: Any, b: Any) -> Jet:
    """Entrywise a where ``pick_a``, else b (a piecewise function: its derivatives too)."""
    n = a.data.shape[0] if isinstance(a, Jet) else b.data.shape[0]
    a = a if isinstance(a, Jet) else _const(a, n)
    b = b if isinstance(b, Jet) else _const(b, n)
    nd = max(a.ndim, b.ndim, np.ndim(pick_a))
    return Jet(np.where(pick_a, _align(a.data, nd), _align(b.data, nd)))


def _maximum(a: Any, b: Any) -> Jet:
    return _select(_value(a) >= _value(b), a, b)


def _minimum(a: Any, b: Any) -> Jet:
    return _select(_value(a) <= _value(b), a, b)


# matrix products ----------------------------------------------------------------------


def _mm_jet_const(data: FloatArray, ndim: int, c: Any) -> FloatArray:
    """``x @ c`` on all parts of a jet x (value ndim ``ndim``), c constant."""
    c = np.asarray(c, dtype=float)
    if ndim == 1:
        if c.ndim > 2:
            raise _unsupported("matmul of a 1-D jet with a stack of matrices")
        return data @ c
    return _align(data, c.ndim) @ c


def _mm_const_jet(c: Any, data: FloatArray, ndim: int) -> FloatArray:
    """``c @ x`` on all parts of a jet x (value ndim ``ndim``), c constant."""
    c = np.asarray(c, dtype=float)
    if ndim == 1:
        if c.ndim == 1:
            return data @ c
        if c.ndim == 2:
            return data @ c.T
        raise _unsupported("matmul of a stack of matrices with a 1-D jet")
    return c @ _align(data, c.ndim)


def _matmul(a: Any, b: Any) -> Jet:
    if isinstance(a, Jet) and isinstance(b, Jet):
        a0, b0 = a.data[0], b.data[0]
        data = _mm_jet_const(a.data, a.ndim, b0) + _mm_const_jet(a0, b.data, b.ndim)
        data[0] = a0 @ b0
        data[-1] += 2.0 * (a.data[-2] @ b.data[-2])
        return Jet(data)
    if isinstance(a, Jet):
        return Jet(_mm_jet_const(a.data, a.ndim, b))
    return Jet(_mm_const_jet(a, b.data, b.ndim))


def _dot(a: Any, b: Any) -> Jet:
    a, b = _operand(a), _operand(b)
    if _ndim(a) == 0 or _ndim(b) == 0:
        return _multiply(a, b)
    if _ndim(a) <= 2 and _ndim(b) <= 2:
        return _matmul(a, b)
    raise _unsupported("numpy.dot of arrays with more than 2 dimensions")


def _cross_parts(x: Any, y: Any) -> Any:
    """x × y along the last axis of length 3, written out (broadcasting leading axes)."""
    x0, x1, x2 = x[..., 0], x[..., 1], x[..., 2]
    y0, y1, y2 = y[..., 0], y[..., 1], y[..., 2]
    return np.stack([x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0], axis=-1)


def _cross(
    a: Any, b: Any, axisa: int = -1, axisb: int = -1, axisc: int = -1, axis: Any = None
) -> Jet:
    if (axisa, axisb, axisc, axis) != (-1, -1, -1, None):
        raise _unsupported("numpy.cross with axis arguments")
    a, b = _operand(a), _operand(b)
    if np.shape(_value(a))[-1:] != (3,) or np.shape(_value(b))[-1:] != (3,):
        raise _unsupported("numpy.cross of vectors that are not 3-vectors")
    nd = max(_ndim(a), _ndim(b))
    if isinstance(a, Jet) and isinstance(b, Jet):
        ad, bd = _align(a.data, nd), _align(b.data, nd)
        data = _cross_parts(ad, bd[0]) + _cross_parts(ad[0], bd)
        data[0] = _cross_parts(ad[0], bd[0])
        data[-1] += 2.0 * _cross_parts(ad[-2], bd[-2])
        return Jet(data)
    if isinstance(a, Jet):
        return Jet(_cross_parts(_align(a.data, nd), np.asarray(b, dtype=float)))
    return Jet(_cross_parts(np.asarray(a, dtype=float), _align(b.data, nd)))


# reductions and shapes -----------------------------------------------------------------


def _sum(a: Any, axis: Any = None, dtype: Any = None, out: Any = None, keepdims: bool = False,
         **kwargs: Any) -> Jet:  # fmt: skip
    if dtype is not None or out is not None or kwargs:
        raise _unsupported("numpy.sum with dtype, out, initial or where")
    a = _operand(a)
    if not isinstance(a, Jet):
        raise _unsupported("numpy.sum without a jet")
    axes = tuple(range(1, a.ndim + 1)) if axis is None else _shift_axes(axis, a.ndim)
    return Jet(a.data.sum(axis=axes, keepdims=keepdims))


def _trace(a: Any, offset: int = 0, axis1: int = 0, axis2: int = 1, dtype: Any = None,
           out: Any = None) -> Jet:  # fmt: skip
    if dtype is not None or out is not None:
        raise _unsupported("numpy.trace with dtype or out")
    a = _operand(a)
    nd = a.ndim
    return Jet(np.trace(a.data, offset, axis1 % nd + 1, axis2 % nd + 1))


def _norm(x: Any, ord: Any = None, axis: Any = None, keepdims: bool = False) -> Jet:
    x = _operand(x)
    vector = (axis is not None and not isinstance(axis, (tuple, list))) or x.ndim == 1
    if not (ord is None or (ord == 2 and vector) or (ord == "fro" and not vector)):
        raise _unsupported(f"numpy.linalg.norm with ord={ord!r}")
    return _unary(np.sqrt, _sum(_multiply(x, x), axis=axis, keepdims=keepdims))


def _jets(arrays: Sequence[Any]) -> list[Jet]:
    items = [_operand(x) for x in arrays]
    n = next((x.data.shape[0] for x in items if isinstance(x, Jet)), None)
    if n is None:
        raise _unsupported("joining arrays without a jet")
    return [x if isinstance(x, Jet) else _const(x, n) for x in items]


def _concatenate(arrays: Sequence[Any], axis: Any = 0, out: Any = None, **kwargs: Any) -> Jet:
    if out is not None or kwargs:
        raise _unsupported("numpy.concatenate with out, dtype or casting")
    jets = _jets(arrays)
    if axis is None:
        return Jet(np.concatenate([j.data.reshape(j.data.shape[0], -1) for j in jets], axis=1))
    nd = jets[0].ndim
    return Jet(np.concatenate([j.data for j in jets], axis=_shift_axes(axis, nd)))


def _stack(arrays: Sequence[Any], axis: int = 0, out: Any = None, **kwargs: Any) -> Jet:
    if out is not None or kwargs:
        raise _unsupported("numpy.stack with out, dtype or casting")
    jets = _jets(arrays)
    return Jet(np.stack([j.data for j in jets], axis=_shift_axes(axis, jets[0].ndim + 1)))


def _reshape(a: Any, *args: Any, **kwargs: Any) -> Jet:
    """As :func:`numpy.reshape` (``shape`` or ``newshape``; C order)."""
    shape = args[0] if args else kwargs.pop("shape", None)
    if shape is None:
        shape = kwargs.pop("newshape", None)
    order = args[1] if len(args) > 1 else kwargs.pop("order", "C")
    if kwargs.pop("copy", None) is not None or kwargs:
        raise _unsupported("numpy.reshape with copy or other keywords")
    return _operand(a).reshape(shape, order=order)


def _atleast_1d(j: Jet) -> Jet:
    return j.reshape(1) if j.ndim == 0 else j


def _atleast_2d(j: Jet) -> Jet:
    return j.reshape(1, -1) if j.ndim <= 1 else j


def _hstack(tup: Sequence[Any], **kwargs: Any) -> Jet:
    jets = [_atleast_1d(j) for j in _jets(tup)]
    return _concatenate(jets, axis=0 if jets[0].ndim == 1 else 1, **kwargs)


def _vstack(tup: Sequence[Any], **kwargs: Any) -> Jet:
    return _concatenate([_atleast_2d(j) for j in _jets(tup)], axis=0, **kwargs)


def _column_stack(tup: Sequence[Any]) -> Jet:
    jets = [j.reshape(-1, 1) if j.ndim <= 1 else j for j in _jets(tup)]
    return _concatenate(jets, axis=1)


def _outer(a: Any, b: Any, out: Any = None) -> Jet:
    if out is not None:
        raise _unsupported("numpy.outer with out")
    a, b = _operand(a), _operand(b)
    a = a.ravel() if isinstance(a, Jet) else np.ravel(a)
    b = b.ravel() if isinstance(b, Jet) else np.ravel(b)
    return _multiply(a[:, None], b[None, :])


def _where(condition: Any, *xy: Any) -> Any:
    if len(xy) != 2:
        raise _unsupported("numpy.where with one argument")
    x, y = (_operand(v) for v in xy)
    return _select(np.asarray(_value(_operand(condition)), dtype=bool), x, y)


def _clip(a: Any, a_min: Any, a_max: Any, out: Any = None, **kwargs: Any) -> Jet:
    if out is not None or kwargs:
        raise _unsupported("numpy.clip with out or keywords")
    a = _operand(a)
    if a_min is not None:
        a = _maximum(a, _operand(a_min))
    if a_max is not None:
        a = _minimum(a, _operand(a_max))
    return a


def _on_values(func: Callable[..., Any]) -> Callable[..., Any]:
    """``func`` applied to the values only (for functions whose result holds no derivative:
    shapes, tests and constant arrays)."""

    def apply(*args: Any, **kwargs: Any) -> Any:
        return func(*(_value(a) for a in args), **kwargs)

    return apply


def _like(func: Callable[..., Any]) -> Callable[..., Any]:
    def apply(a: Any, *args: Any, **kwargs: Any) -> Any:
        return func(np.empty(_operand(a).shape), *args, **kwargs)

    return apply


# --------------------------------------------------------------------------------------
# functions of one argument: (f, f', f'') at the value x


def _rules() -> dict[np.ufunc, Callable[[FloatArray], tuple[Any, Any, Any]]]:
    def sin(x: Any) -> tuple[Any, Any, Any]:
        s, c = np.sin(x), np.cos(x)
        return s, c, -s

    def cos(x: Any) -> tuple[Any, Any, Any]:
        s, c = np.sin(x), np.cos(x)
        return c, -s, -c

    def tan(x: Any) -> tuple[Any, Any, Any]:
        f = np.tan(x)
        d1 = 1.0 + f * f
        return f, d1, 2.0 * f * d1

    def arcsin(x: Any) -> tuple[Any, Any, Any]:
        w = 1.0 / np.sqrt(1.0 - x * x)
        return np.arcsin(x), w, x * w**3

    def arccos(x: Any) -> tuple[Any, Any, Any]:
        w = 1.0 / np.sqrt(1.0 - x * x)
        return np.arccos(x), -w, -x * w**3

    def arctan(x: Any) -> tuple[Any, Any, Any]:
        w = 1.0 / (1.0 + x * x)
        return np.arctan(x), w, -2.0 * x * w * w

    def sinh(x: Any) -> tuple[Any, Any, Any]:
        s = np.sinh(x)
        return s, np.cosh(x), s

    def cosh(x: Any) -> tuple[Any, Any, Any]:
        c = np.cosh(x)
        return c, np.sinh(x), c

    def tanh(x: Any) -> tuple[Any, Any, Any]:
        f = np.tanh(x)
        d1 = 1.0 - f * f
        return f, d1, -2.0 * f * d1

    def exp(x: Any) -> tuple[Any, Any, Any]:
        f = np.exp(x)
        return f, f, f

    def expm1(x: Any) -> tuple[Any, Any, Any]:
        e = np.exp(x)
        return np.expm1(x), e, e

    def log(x: Any) -> tuple[Any, Any, Any]:
        r = 1.0 / x
        return np.log(x), r, -r * r

    def log1p(x: Any) -> tuple[Any, Any, Any]:
        r = 1.0 / (1.0 + x)
        return np.log1p(x), r, -r * r

    def log10(x: Any) -> tuple[Any, Any, Any]:
        r = 1.0 / (x * np.log(10.0))
        return np.log10(x), r, -r / x

    def log2(x: Any) -> tuple[Any, Any, Any]:
        r = 1.0 / (x * np.log(2.0))
        return np.log2(x), r, -r / x

    def sqrt(x: Any) -> tuple[Any, Any, Any]:
        f = np.sqrt(x)
        d1 = 0.5 / f
        return f, d1, -0.5 * d1 / x

    def cbrt(x: Any) -> tuple[Any, Any, Any]:
        f = np.cbrt(x)
        d1 = 1.0 / (3.0 * f * f)
        return f, d1, -2.0 * d1 / (3.0 * x)

    def square(x: Any) -> tuple[Any, Any, Any]:
        return x * x, 2.0 * x, 2.0

    def reciprocal(x: Any) -> tuple[Any, Any, Any]:
        r = 1.0 / x
        return r, -r * r, 2.0 * r * r * r

    def absolute(x: Any) -> tuple[Any, Any, Any]:
        return np.absolute(x), np.sign(x), 0.0

    def deg2rad(x: Any) -> tuple[Any, Any, Any]:
        k = np.pi / 180.0
        return x * k, k, 0.0

    def rad2deg(x: Any) -> tuple[Any, Any, Any]:
        k = 180.0 / np.pi
        return x * k, k, 0.0

    return {
        np.sin: sin, np.cos: cos, np.tan: tan, np.arcsin: arcsin, np.arccos: arccos,
        np.arctan: arctan, np.sinh: sinh, np.cosh: cosh, np.tanh: tanh, np.exp: exp,
        np.expm1: expm1, np.log: log, np.log1p: log1p, np.log10: log10, np.log2: log2,
        np.sqrt: sqrt, np.cbrt: cbrt, np.square: square, np.reciprocal: reciprocal,
        np.absolute: absolute, np.deg2rad: deg2rad, np.radians: deg2rad,
        np.rad2deg: rad2deg, np.degrees: rad2deg,
    }  # fmt: skip


_UNARY_RULES = _rules()


def _apply(a: Jet, f: Any, d1: Any, d2: Any) -> Jet:
    """f(a) from f, f' and f'' at a's value: f(a)ₖ = f' aₖ, f(a)'' = f' a'' + f'' a'²."""
    ad = _align(a.data, np.ndim(f))
    data = d1 * ad
    data[0] = f
    data[-1] += d2 * ad[-2] * ad[-2]
    return Jet(data)


def _unary(ufunc: np.ufunc, a: Any) -> Any:
    if not isinstance(a, Jet):
        return ufunc(a)
    if ufunc is np.negative:
        return Jet(-a.data)
    if ufunc is np.positive:
        return a.copy()
    return _apply(a, *_UNARY_RULES[ufunc](a.data[0]))


_BINARY: dict[np.ufunc, Callable[..., Any]] = {
    np.add: _add,
    np.subtract: _subtract,
    np.multiply: _multiply,
    np.divide: _divide,
    np.power: _power,
    np.float_power: _power,
    np.matmul: _matmul,
    np.arctan2: _arctan2,
    np.hypot: _hypot,
    np.maximum: _maximum,
    np.minimum: _minimum,
    np.fmax: _maximum,
    np.fmin: _minimum,
}

#: Ufuncs applied to the values alone: comparisons and tests (their results are booleans, so
#: that a residual may branch on values), and functions that are constant between jumps
#: (their derivatives are zero wherever they exist).
_ON_VALUES = frozenset(
    {np.less, np.less_equal, np.greater, np.greater_equal, np.equal, np.not_equal,
     np.isfinite, np.isnan, np.isinf, np.signbit,
     np.sign, np.floor, np.ceil, np.rint, np.trunc}
)  # fmt: skip

_FUNCTIONS: dict[Any, Callable[..., Any]] = {
    np.dot: _dot,
    np.matmul: _matmul,
    np.cross: _cross,
    np.linalg.norm: _norm,
    np.sum: _sum,
    np.trace: _trace,
    np.concatenate: _concatenate,
    np.stack: _stack,
    np.hstack: _hstack,
    np.vstack: _vstack,
    np.column_stack: _column_stack,
    np.outer: _outer,
    np.where: _where,
    np.clip: _clip,
    np.transpose: lambda a, axes=None: _operand(a).transpose(axes),
    np.reshape: _reshape,
    np.ravel: lambda a, order="C": _operand(a).reshape(-1, order=order),
    np.squeeze: lambda a, axis=None: _operand(a).squeeze(axis),
    np.diagonal: lambda a, offset=0, axis1=0, axis2=1: _operand(a).diagonal(offset, axis1, axis2),
    np.mean: lambda a, axis=None, keepdims=False: _operand(a).mean(axis, keepdims),
    np.copy: lambda a, **kw: _operand(a).copy(),
    np.atleast_1d: lambda a: _atleast_1d(_operand(a)),
    np.atleast_2d: lambda a: _atleast_2d(_operand(a)),
    np.shape: lambda a: _operand(a).shape,
    np.ndim: lambda a: _operand(a).ndim,
    np.size: lambda a, axis=None: _operand(a).size if axis is None else _operand(a).shape[axis],
    np.zeros_like: _like(np.zeros_like),
    np.ones_like: _like(np.ones_like),
    np.full_like: _like(np.full_like),
    np.isclose: _on_values(np.isclose),
    np.allclose: _on_values(np.allclose),
    np.all: _on_values(np.all),
    np.any: _on_values(np.any),
}
