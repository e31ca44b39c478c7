"""Input checks used at gmuk's public boundary (never in the integrator's hot path)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from gmuk._numba import njit
from gmuk.errors import NonFiniteError, NotOnGroupError, ShapeError

FloatArray = NDArray[np.float64]

#: Tolerance for RᵀR = I and for the homogeneous row of SE(3) elements.
GROUP_TOL = 1e-9


def as_array(x: Any, tail: tuple[int, ...], name: str, *, batch: bool = True) -> FloatArray:
    """Return ``x`` as a finite float64 array whose trailing shape is ``tail``.

    Parameters
    ----------
    x : array_like
        The input.
    tail : tuple of int
        Required trailing shape, e.g. ``(6,)`` or ``(4, 4)``.
    name : str
        Name used in error messages.
    batch : bool
        Whether leading (batch) axes are allowed.

    Raises
    ------
    ShapeError
        If the trailing shape differs (or batch axes are present when not allowed).
    NonFiniteError
        If any entry is NaN or infinite.
    """
    if type(x) is np.ndarray and x.dtype == np.float64:
        a = x
    else:
        a = _real_float64(x, tail, name, batch)
    k = len(tail)
    if a.ndim < k or a.shape[a.ndim - k :] != tail or (not batch and a.ndim != k):
        raise ShapeError(f"{name} must have shape {_fmt(tail, batch)}; got {a.shape}")
    if not all_finite(a.reshape(-1)):
        bad = int(np.size(a) - np.count_nonzero(np.isfinite(a)))
        raise NonFiniteError(
            f"{name} must be finite; got {bad} NaN/inf entr"
            f"{'y' if bad == 1 else 'ies'} in an array of shape {a.shape}"
        )
    return a


#: Python types that convert to float but are not real numbers: never taken silently.
NOT_REAL = (bool, np.bool_, complex, np.complexfloating, str, bytes, np.str_, np.bytes_)


def _real_float64(x: Any, tail: tuple[int, ...], name: str, batch: bool) -> FloatArray:
    """``x`` as float64, refusing what only pretends to be real numbers: booleans, complex
    numbers (numpy would drop the imaginary part), strings (``"1.5"`` would be parsed),
    None and other objects inside arrays, and ragged nesting."""

    def refuse(what: str) -> ShapeError:
        return ShapeError(
            f"{name} must be a numeric array of shape {_fmt(tail, batch)} of real numbers; "
            f"could not convert {type(x).__name__}: {what}"
        )

    if x is None:
        raise ShapeError(f"{name} must have shape {_fmt(tail, batch)}; got () (None)")
    if isinstance(x, NOT_REAL):
        raise refuse(f"got {x!r:.60}")
    try:
        raw = np.asarray(x)
    except (TypeError, ValueError, OverflowError) as exc:
        raise refuse(str(exc)) from None
    kind = raw.dtype.kind
    if kind == "O":  # big ints, Fractions, nested objects: only real numbers pass
        bad = next((v for v in raw.flat if isinstance(v, NOT_REAL) or v is None), raw)
        if bad is not raw:
            raise refuse(f"an element is {type(bad).__name__} {bad!r:.40}")
    elif kind not in "iuf":
        raise refuse(f"its dtype is {raw.dtype}, not real numbers")
    try:
        return np.asarray(raw, dtype=np.float64)
    except OverflowError:
        raise NonFiniteError(
            f"{name} must be finite; got an integer too large for float64"
        ) from None
    except (TypeError, ValueError) as exc:
        raise refuse(str(exc)) from None


def finite_result(out: FloatArray, func: str, arg: str, value: FloatArray) -> FloatArray:
    """``out``, or :class:`NonFiniteError` if the map ``func`` overflowed (finite input so
    large, e.g. 1e308, that the result holds NaN or inf)."""
    if not all_finite(out.reshape(-1)):
        raise NonFiniteError(
            f"{func}: {arg} is too large for a finite result in float64 (the map overflows); "
            f"got max|{arg}| = {float(np.abs(value).max(initial=0.0)):.3g}"
        )
    return out


@njit(cache=True)
def all_finite(x: np.ndarray) -> bool:
    """Whether every entry of a 1-D array is finite.

    Compiled: for the small arrays of single calls it is several times cheaper than
    ``np.isfinite(x).all()``, which allocates a temporary and dispatches twice."""
    for v in x:
        if not np.isfinite(v):
            return False
    return True


def _fmt(tail: tuple[int, ...], batch: bool) -> str:
    inner = ", ".join(str(t) for t in tail)
    return f"(..., {inner})" if batch else f"({inner}{',' if len(tail) == 1 else ''})"


def _rotation_failure(
    name: str, tol: float, err: float, R: FloatArray, batch_shape: tuple, k: int
) -> NotOnGroupError:
    where = (
        f" at index {tuple(int(j) for j in np.unravel_index(k, batch_shape))}"
        if batch_shape
        else ""
    )
    with np.errstate(all="ignore"):  # entries near 1e308: det is then inf, as reported
        det = float(np.linalg.det(R))
    return NotOnGroupError(
        f"{name} must be a rotation matrix (RᵀR = I to {tol:g}, det +1){where}; "
        f"got max|RᵀR − I| = {err:.3g}, det = {det:.6g}"
    )


def _writable_c(a: FloatArray) -> FloatArray:
    """``a`` C-contiguous and writable (a copy if needed): the group checks' kernels then
    compile once, not once more for read-only arrays (a reference's shared poses)."""
    a = np.ascontiguousarray(a)
    return a if a.flags.writeable else a.copy()


def check_rotation(R: Any, name: str = "R", tol: float = GROUP_TOL) -> FloatArray:
    """Return ``R`` as an array of rotation matrices, or raise :class:`NotOnGroupError`.

    A rotation matrix satisfies ``‖RᵀR − I‖_max ≤ tol`` and ``det R = +1`` (to ``tol``).
    Leading batch axes are allowed; the message reports the worst element.
    """
    from gmuk.lie._kernels import rotation_errors

    R = as_array(R, (3, 3), name)
    flat = _writable_c(R.reshape(-1, 3, 3))
    if flat.shape[0] == 0:
        return R
    err, det_err, k = rotation_errors(flat)
    if err > tol or det_err > tol:
        raise _rotation_failure(name, tol, err, flat[k], R.shape[:-2], k)
    return R


def check_se3(g: Any, name: str = "g", tol: float = GROUP_TOL) -> FloatArray:
    """Return ``g`` as an array of 4×4 SE(3) matrices, or raise :class:`NotOnGroupError`.

    The rotation block must be a rotation matrix (as :func:`check_rotation`) and the last
    row ``[0, 0, 0, 1]``, both to ``tol``; one compiled pass checks both.
    """
    from gmuk.lie._kernels import se3_errors

    g = as_array(g, (4, 4), name)
    flat = _writable_c(g.reshape(-1, 4, 4))
    if flat.shape[0] == 0:
        return g
    row_err, err, det_err, k, _ = se3_errors(flat)
    if row_err > tol:
        raise NotOnGroupError(
            f"{name} must be a homogeneous transform with last row [0, 0, 0, 1]; "
            f"got a last row off by {row_err:.3g}"
        )
    if err > tol or det_err > tol:
        raise _rotation_failure(
            f"rotation block of {name}", tol, err, flat[k, :3, :3], g.shape[:-2], k
        )
    return g


def real_number(
    value: Any,
    name: str,
    *,
    positive: bool = False,
    non_negative: bool = False,
    allow_inf: bool = False,
    error: type[Exception] | None = None,
) -> float:
    """``value`` as a float, refusing what is not a real number (bool, complex, str, arrays
    of more than one element, None) and, as asked, non-finite, negative or zero values.

    Raises ``error`` (default :class:`gmuk.errors.DefinitionError`) naming ``name``, what
    was expected and what came in.
    """
    from gmuk.errors import DefinitionError

    exc = error or DefinitionError
    kind = "a number > 0" if positive else "a number >= 0" if non_negative else "a real number"
    bad = isinstance(value, (bool, np.bool_, complex, np.complexfloating, str, bytes)) or (
        # a 0-d array of strings, bytes, booleans or complex numbers: float() would parse it
        isinstance(value, np.ndarray) and value.dtype.kind not in "iuf"
    )
    try:
        bad = bad or np.ndim(value) != 0
        v = float("nan") if bad else float(value)
    except OverflowError:  # an int beyond float64: infinite for our purposes
        v = float("inf") if value > 0 else float("-inf")
    except (TypeError, ValueError):
        v, bad = float("nan"), True
    if bad:
        raise exc(f"{name} must be {kind}; got {value!r}")
    if v != v or ((v in (float("inf"), float("-inf"))) and not allow_inf):
        raise exc(f"{name} must be finite; got {value!r}")
    if (positive and not v > 0) or (non_negative and not v >= 0):
        raise exc(f"{name} must be {kind}; got {value!r}")
    return v


def check_sequence(value: Any, name: str) -> tuple[Any, ...]:
    """``value`` as a tuple, refusing None, strings and other non-sequences with a clear
    :class:`gmuk.errors.DefinitionError`."""
    from collections.abc import Sequence

    from gmuk.errors import DefinitionError

    if (
        isinstance(value, (str, bytes))
        or not isinstance(value, (Sequence, np.ndarray))
        or (isinstance(value, np.ndarray) and value.ndim == 0)  # cannot be iterated
    ):
        raise DefinitionError(
            f"{name} must be a sequence (list or tuple); got {type(value).__name__} {value!r:.60}"
        )
    return tuple(value)


def strict_bool(value: Any, name: str, *, error: type[Exception] | None = None) -> bool:
    """``value`` as a bool, accepting only ``True``, ``False`` and numpy booleans.

    Truthiness is never used: the string ``"False"`` (true in Python), ``0``, ``1``, ``None``
    and arrays are refused, so that an option spelled wrongly cannot silently switch a
    feature on or off.

    Parameters
    ----------
    value : object
        The option's value.
    name : str
        Its name, for the message.
    error : type of Exception, optional
        What to raise (default :class:`gmuk.errors.DefinitionError`).

    Returns
    -------
    bool

    Raises
    ------
    DefinitionError
        (or ``error``) naming ``name``, saying that a bool was expected and what came in.
    """
    from gmuk.errors import DefinitionError

    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    exc = error or DefinitionError
    raise exc(f"{name} must be True or False (a bool); got {type(value).__name__} {value!r:.60}")


def real_vector(
    value: Any,
    name: str,
    size: int,
    *,
    scalar: bool = False,
    positive: bool = False,
    non_negative: bool = False,
    error: type[Exception] | None = None,
) -> FloatArray:
    """``value`` as a finite float64 vector of ``size`` real numbers (a new array).

    Booleans, complex numbers, strings, None and objects are refused (not converted), as are
    NaN, ±inf, the wrong shape and, as asked, values ≤ 0 or < 0.

    Parameters
    ----------
    value : array_like
        The input: ``size`` numbers, or one number when ``scalar`` is True (then repeated).
    name : str
        Its name, for the message.
    size : int
        The required length.
    scalar : bool
        Whether a single number is accepted and broadcast to ``size`` entries.
    positive, non_negative : bool
        Require every entry > 0, or ≥ 0.
    error : type of Exception, optional
        What to raise (default :class:`gmuk.errors.DefinitionError`).

    Returns
    -------
    ndarray, shape (size,)

    Raises
    ------
    DefinitionError
        (or ``error``) naming ``name``, what was expected and what came in.
    """
    from gmuk.errors import DefinitionError, GmukError

    exc = error or DefinitionError
    sign = " > 0" if positive else " ≥ 0" if non_negative else ""
    what = f"a finite number{sign} or {size} such numbers" if scalar else f"{size} finite numbers"
    if not scalar:
        what += sign
    try:
        if _holds_not_real(value):  # numpy would read (1.0, True) as (1.0, 1.0)
            raise GmukError
        v = np.array(_real_float64(value, (size,), name, batch=False), dtype=np.float64)
    except GmukError:
        raise exc(f"{name} must be {what}; got {type(value).__name__} {value!r:.60}") from None
    if scalar and v.ndim == 0:
        v = np.full(size, float(v))
    if v.shape != (size,):
        raise exc(f"{name} must be {what}; got shape {v.shape}: {value!r:.60}")
    if not all_finite(v):
        raise exc(f"{name} must be finite; got {v.tolist()}")
    if (positive and not (v > 0.0).all()) or (non_negative and not (v >= 0.0).all()):
        raise exc(f"{name} must be {what}; got {v.tolist()}")
    return v


def distinct_bodies(bodies: Any, who: str) -> tuple[Any, ...]:
    """``bodies`` (Body objects or names) as a tuple, refusing one listed twice.

    A body is identified by its name: the same Body object twice, or a Body and its name,
    are the same body. Entries that are neither (checked later by the System) are compared
    by identity.

    Parameters
    ----------
    bodies : sequence of Body or str
        The bodies a part acts on.
    who : str
        The part, for the message (e.g. ``"SpringDamper 'tether'"``).

    Returns
    -------
    tuple

    Raises
    ------
    DefinitionError
        Naming every body listed more than once and its positions.
    """
    from gmuk.errors import DefinitionError

    items = tuple(bodies)
    seen: dict[Any, list[int]] = {}
    for i, b in enumerate(items):
        name = b if isinstance(b, str) else getattr(b, "name", None)
        key = ("name", name) if isinstance(name, str) else ("id", id(b))
        seen.setdefault(key, []).append(i)
    repeated = [(key, where) for key, where in seen.items() if len(where) > 1]
    if repeated:
        listing = "; ".join(
            f"{items[where[0]] if key[0] == 'id' else key[1]!r} at positions {where}"
            for key, where in repeated
        )
        raise DefinitionError(
            f"{who} lists the same body more than once ({listing}); each body may appear "
            "once (a part acting on a body with itself has no meaning: two entries would be "
            "two columns, or two loads, for one body)"
        )
    return items


def strict_integer(
    value: Any,
    name: str,
    *,
    minimum: int | None = None,
    maximum: int | None = None,
    integral_floats: bool = False,
    error: type[Exception] | None = None,
) -> int:
    """``value`` as an int, refusing what is not an integer: bool, str, bytes, complex,
    None, arrays, NaN, inf and fractional numbers (never truncated or parsed).

    Parameters
    ----------
    value : int
        The input; ``numpy`` integers pass, and with ``integral_floats`` also floats with
        an integral value (``10.0``).
    name : str
        Name used in error messages.
    minimum, maximum : int, optional
        Inclusive bounds.
    integral_floats : bool
        Whether floats of integral value are taken.
    error : type, optional
        Exception raised (default :class:`gmuk.errors.DefinitionError`), naming ``name``,
        what was expected and what came in.
    """
    import operator

    from gmuk.errors import DefinitionError

    exc = error or DefinitionError
    if minimum is not None and maximum is not None:
        kind = f"an integer in [{minimum}, {maximum}]"
    elif minimum is not None:
        kind = f"an integer ≥ {minimum}"
    elif maximum is not None:
        kind = f"an integer ≤ {maximum}"
    else:
        kind = "an integer"
    n: int | None = None
    if not isinstance(value, NOT_REAL) and value is not None:
        try:
            n = operator.index(value)
        except TypeError:
            if (
                integral_floats
                and isinstance(value, (float, np.floating))
                and np.isfinite(value)
                and float(value).is_integer()
            ):
                n = int(value)
    if n is None:
        raise exc(f"{name} must be {kind}; got {type(value).__name__} {value!r:.60}")
    if (minimum is not None and n < minimum) or (maximum is not None and n > maximum):
        raise exc(f"{name} must be {kind}; got {n}")
    return n


def real_sequence(
    x: Any, name: str, *, min_size: int = 0, error: type[Exception] | None = None
) -> FloatArray:
    """``x`` as a finite 1-D float64 array of at least ``min_size`` entries.

    Stricter than :func:`as_array` about what it takes: a string, booleans (also inside a
    list, where numpy would read ``True`` as 1), complex numbers and arrays of more than
    one axis are refused, never flattened or converted.

    Raises ``error`` (default :class:`gmuk.errors.DefinitionError`) naming ``name``, what
    was expected and what came in.
    """
    from gmuk.errors import DefinitionError

    exc = error or DefinitionError
    count = f"at least {min_size} " if min_size > 1 else ""
    want = f"{name} must be a 1-D sequence of {count}finite real numbers"
    if isinstance(x, (list, tuple)):
        bad = next((v for v in x if isinstance(v, NOT_REAL) or v is None), x)
        if bad is not x:
            raise exc(f"{want}; an entry is {type(bad).__name__} {bad!r:.40}")
    if isinstance(x, NOT_REAL) or x is None:
        raise exc(f"{want}; got {type(x).__name__} {x!r:.60}")
    try:
        a = _real_float64(x, (), name, True)
    except (ShapeError, NonFiniteError) as e:
        raise exc(f"{want}; {e}") from None
    if a.ndim != 1 or a.size < min_size:
        raise exc(f"{want}; got an array of shape {a.shape}")
    if not all_finite(a):
        bad_n = int(a.size - np.count_nonzero(np.isfinite(a)))
        raise exc(f"{want}; got {bad_n} NaN/inf entr{'y' if bad_n == 1 else 'ies'}")
    return a


def _holds_not_real(value: Any) -> bool:
    """Whether a list or tuple (nested) holds a bool, complex number or string, which numpy
    would convert along with its real neighbours."""
    if isinstance(value, (list, tuple)):
        return any(isinstance(v, NOT_REAL) or _holds_not_real(v) for v in value)
    return False
