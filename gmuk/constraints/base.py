"""The Constraint base class and Baumgarte gains.

A constraint involves some bodies and, at a :class:`gmuk.State`, returns its rows (A, b) of
``A ν̇ = b`` (McCann 2020, Eqs. 1 and 63), where the columns of A are the velocities of
``self.bodies`` in the order given (6 per rigid body [ω; v], 3 per point mass, 1 per slack
coordinate). The System places the columns into the global A.
"""

from __future__ import annotations

import abc
import functools
import inspect
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import scipy.sparse as sp
from numba import types as numba_types

from gmuk._forms import DeclaresForms
from gmuk._frozen import FreezesInSystem
from gmuk._numba import C1, C2
from gmuk._validation import FloatArray, distinct_bodies
from gmuk.bodies import BodyKind
from gmuk.errors import ConstraintError, DefinitionError

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["BASE_KEYWORDS", "ROWS_KERNEL", "Baumgarte", "Constraint"]

#: The signature of a constraint's rows kernel, as the compiled loop calls it:
#: ``(t, g_1 (4, 4), V_1 (6,), g_2, V_2, p, A (s, 12), b (s,)) -> status``, writing the rows
#: of the constraint on its first body (columns 0–5) and its second one (columns 6–11; zero,
#: and ``g_2, V_2`` ignored, for a one-body constraint); status 0 or a failure code.
ROWS_KERNEL = numba_types.int64(numba_types.float64, C2, C1, C2, C1, C1, C2, C1)

#: The keywords of gmuk's constraint kinds that a subclass takes whether or not its own
#: ``__init__`` names them (:meth:`Constraint.__init_subclass__`), with the default of every
#: kind that takes them: ``name`` (every kind); ``baumgarte`` (the residual kinds — holonomic,
#: nonholonomic, inequality — and the tracking and relative constraints); ``fd_length`` and
#: ``fd_time`` (the residual kinds); ``derivatives`` (holonomic and nonholonomic).
BASE_KEYWORDS: dict[str, Any] = {
    "name": None,
    "baumgarte": None,
    "fd_length": 1.0,
    "fd_time": 1.0,
    "derivatives": "jets",
}


@dataclass(frozen=True)
class Baumgarte:
    """Baumgarte stabilisation gains, ``Φ̈ + α Φ̇ + β Φ = 0`` (McCann 2020, Eq. 4).

    Parameters
    ----------
    alpha : float or array_like, shape (s,)
        Velocity gain(s) α (1/s), ≥ 0.
    beta : float or array_like, shape (s,)
        Position gain(s) β (1/s²), ≥ 0. Critical damping: α = 2√β.

    Nonholonomic (velocity-level) constraints use α only: ``Ψ̇ + α Ψ = 0``.
    """

    alpha: Any = 0.0
    beta: Any = 0.0

    def __post_init__(self) -> None:
        for label in ("alpha", "beta"):
            raw = getattr(self, label)
            try:
                v = np.asarray(raw)
                real = v.dtype.kind in "iuf"
                v = v.astype(float) if real else v
            except (TypeError, ValueError, OverflowError):
                real = False
            if not real or v.ndim > 1 or not np.all(np.isfinite(v)) or np.any(v < 0.0):
                raise DefinitionError(
                    f"Baumgarte {label} must be a finite scalar or 1-D array ≥ 0; got {raw!r}"
                )
            object.__setattr__(self, label, v)

    @staticmethod
    def critical(omega_n: float) -> Baumgarte:
        """Critically damped gains for natural frequency ``omega_n`` (rad/s)."""
        return Baumgarte(alpha=2.0 * omega_n, beta=omega_n**2)


class Constraint(FreezesInSystem, DeclaresForms, abc.ABC):
    """A set of s constraint rows ``A ν̇ = b`` on some bodies.

    Subclass it and implement :meth:`rows`: every constraint, whatever its kind, gives its
    rows of ``A ν̇ = b`` (the System stacks them and solves them with its strategy). A kind
    that needs more states it as class attributes, which the System checks once:
    :attr:`body_kinds`, the kinds of body it can act on. The bodies are given as
    :class:`gmuk.Body` objects or names; the System checks that they exist. A constraint is
    frozen once it is handed to a System (its attributes can no longer be set).

    **Keywords of the base class.** A subclass takes the keywords of the gmuk kind it builds
    on (:data:`BASE_KEYWORDS`: ``name`` for every kind; ``baumgarte`` where the kind applies
    Baumgarte gains; ``fd_length``, ``fd_time`` for the residual kinds, ``derivatives`` for
    the holonomic and nonholonomic ones) even when its own
    ``__init__`` does not name them: the class holds them back from that ``__init__`` and hands
    them to the kind's ``__init__`` when ``super().__init__(...)`` reaches it, so the instance
    has them from then on, exactly as if they had been forwarded. A keyword that the
    subclass's ``__init__`` names is its own and passes through untouched (it is never applied
    twice). A keyword the kind does not take (``baumgarte`` on a kind that gives its rows
    directly) is a :class:`~gmuk.errors.DefinitionError` naming the kinds that take it, as is
    one that the subclass also sets itself in its ``super().__init__`` call to another value.
    ``inspect.signature`` (``help``, IDEs) lists them after the subclass's own parameters.

    Parameters
    ----------
    bodies : sequence of Body or str
        The bodies whose velocities make the columns of A, in this order; each at most
        once (a Body and its name count as the same body).
    name : str, optional
        Label used in error messages and diagnostics.

    Raises
    ------
    DefinitionError
        If ``bodies`` is empty or lists a body more than once.

    Examples
    --------
    >>> class Rows(Constraint):
    ...     def __init__(self, bodies, A, b):
    ...         super().__init__(bodies)
    ...         self.A, self.b = A, b
    ...     def rows(self, state):
    ...         return self.A, self.b
    >>> Rows(["a"], np.eye(6)[:3], np.zeros(3), name="lock").name
    'lock'
    """

    #: The kinds of body this constraint can act on (default: every kind).
    body_kinds: ClassVar[frozenset[BodyKind]] = frozenset(BodyKind)
    _numeric_methods: ClassVar[tuple[str, ...]] = ("rows",)
    _bodies: tuple[Body | str, ...]
    _name: str
    _cached_indices: tuple[object, tuple[int, ...]] | None = None

    def __init__(self, bodies: Sequence[Body | str], *, name: str | None = None) -> None:
        (name,) = self._keywords(name=name)
        if isinstance(bodies, str) or not isinstance(bodies, Sequence):
            bodies = [bodies]
        if len(bodies) == 0:
            raise DefinitionError(f"{type(self).__name__} needs at least one body")
        who = type(self).__name__ + (f" {name!r}" if name else "")
        bodies = distinct_bodies(bodies, who)
        object.__setattr__(self, "_bodies", bodies)
        object.__setattr__(self, "_name", name or type(self).__name__)

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Let a subclass outside gmuk take the keywords of its kind (:data:`BASE_KEYWORDS`)
        that its own ``__init__`` does not name (see the class docstring)."""
        super().__init_subclass__(**kwargs)
        init = cls.__dict__.get("__init__")
        if init is not None and not _in_gmuk(cls):
            cls.__init__ = _taking_base_keywords(cls, init)  # type: ignore[method-assign]

    def _keywords(self, **values: Any) -> tuple[Any, ...]:
        """The values of keywords of :data:`BASE_KEYWORDS`, in the order given, as a kind's
        ``__init__`` is to use them: each as it came in, or the one the caller gave a subclass
        whose ``__init__`` does not name it (held back by :meth:`__init_subclass__`). A
        ``baumgarte`` is checked to be a :class:`Baumgarte` or None.

        Raises
        ------
        DefinitionError
            When the subclass sets a keyword itself that its caller gave too, to another
            value; for a ``baumgarte`` that is not a Baumgarte.
        """
        held = self.__dict__.get("_held_keywords")
        out: list[Any] = []
        for key, value in values.items():
            if held and key in held:
                given = held.pop(key)
                if not _is_default(value, BASE_KEYWORDS[key]) and value is not given:
                    raise DefinitionError(
                        f"{type(self).__name__} sets {key}={value!r} itself and was given "
                        f"{key}={given!r} too: give it in one place"
                    )
                value = given
            if key == "baumgarte" and value is not None and not isinstance(value, Baumgarte):
                raise DefinitionError(
                    f"baumgarte of {type(self).__name__} must be a gmuk.Baumgarte or None; "
                    f"got {type(value).__name__}"
                )
            out.append(value)
        return tuple(out)

    def _compiled_term(self) -> tuple[Any, tuple[float, ...], int] | None:
        """How the compiled step loop computes this constraint's rows: (its kernel, with the
        signature :data:`ROWS_KERNEL`; parameters; number of rows), or None when its rows
        come from Python. A constraint has the compiled form of the class that defines its
        ``_kernel`` when its ``rows`` is that class's (a subclass that overrides ``rows`` has
        none), and when ``_kernel_params()`` packs parameters for it."""
        kernel = self._declared_form("_kernel")
        packed = self._kernel_params() if kernel is not None else None
        if packed is None:
            return None
        params, n_rows = packed
        if isinstance(params, np.ndarray) and params.dtype == np.float64 and params.ndim == 1:
            return kernel, tuple(params.tolist()), int(n_rows)  # the common case, at once
        return kernel, tuple(float(v) for v in params), int(n_rows)

    def _tree_subspace(self) -> Any:
        """For a constraint on the relative pose of two bodies whose rows on one of them are
        constant (a joint), the :class:`gmuk.engine.tree.JointSubspace` that lets the tree
        solve eliminate that body with it; None (the default) for any other."""
        return None

    def _kernel_params(self) -> tuple[Any, int] | None:
        """The parameters of ``_kernel`` and the number of rows; None when the kernel cannot
        compute this constraint's rows."""
        raise DefinitionError(f"{type(self).__name__} has no compiled kernel")

    @property
    def bodies(self) -> tuple[Body | str, ...]:
        """The bodies (objects or names) this constraint acts on, in column order."""
        return self._bodies

    @property
    def body_names(self) -> tuple[str, ...]:
        """Names of :attr:`bodies`."""
        return tuple(b if isinstance(b, str) else b.name for b in self.bodies)

    @property
    def name(self) -> str:
        """Label of the constraint."""
        return self._name

    def _rigid_indices(self, state: State) -> tuple[int, ...]:
        """Indices into ``state.g`` and ``state.V`` of :attr:`bodies` (all rigid), looked up
        once per layout (a constraint shared by several Systems keeps the last one's)."""
        cached = self._cached_indices
        if cached is not None and cached[0] is state.layout:
            return cached[1]
        indices = tuple(state._slot(b, "rigid", "pose").index for b in self.bodies)
        # one tuple, set in one step, so that layout and indices always belong together
        object.__setattr__(self, "_cached_indices", (state.layout, indices))
        return indices

    @property
    def owned_bodies(self) -> tuple[Body, ...]:
        """Bodies this constraint brings with it (e.g. an inequality's slack coordinates);
        the System adds them after its own bodies. None by default."""
        return ()

    def initial_owned_state(
        self, state: State, free_acceleration: FloatArray
    ) -> list[tuple[float, float]]:
        """Value and rate of each of :attr:`owned_bodies` consistent with ``state``.

        :meth:`gmuk.System.state` calls it once, with the free acceleration (modeled forces)
        of this constraint's columns; only constraints that own bodies implement it.
        """
        raise NotImplementedError(f"{type(self).__name__} owns no bodies")

    @abc.abstractmethod
    def rows(self, state: State) -> tuple[Any, Any]:
        """Rows of the constraint at ``state``.

        Returns
        -------
        A : array_like, shape (s, Σ dof of self.bodies)
        b : array_like, shape (s,)
            In SI units of acceleration (rad/s², m/s², …) times those of A.
        """

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """How far ``state`` is off this constraint: the residuals its rows hold at zero.

        :func:`gmuk.engine.integrate.simulate` evaluates them at the output times of a run to
        check that the constraint did not drift (``drift_tol``; docs/reliability.rst,
        "Constraint drift").

        Returns
        -------
        position : ndarray (p,) or None
            The position-level residual (e.g. φ(q, t), or log(g_d⁻¹ g)), in the residual's
            own units; None when the constraint states none.
        velocity : ndarray (q,) or None
            The velocity-level residual (e.g. φ̇, ψ(q, ν, t), or a twist error); None when
            the constraint states none.

        A residual on an orbital scale may be weighed as the integrator weighs the state
        (translations against the distance, rotations in rad): the tracking constraints do.
        The default, (None, None), is for a constraint given only by its acceleration rows:
        the drift check passes over it. Subclasses that hold a residual at zero override it.
        """
        return None, None

    def __repr__(self) -> str:
        return f"{type(self).__name__}(bodies={list(self.body_names)}, name={self.name!r})"


def _in_gmuk(cls: type) -> bool:
    """Whether ``cls`` is one of gmuk's own classes (which name their keywords)."""
    return cls.__module__ == "gmuk" or cls.__module__.startswith("gmuk.")


def _is_default(value: Any, default: Any) -> bool:
    """Whether a kind's ``__init__`` got ``value`` as the default ``default`` of its keyword."""
    if value is default:
        return True
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    return number and isinstance(default, float) and value == default


def _taking_base_keywords(cls: type[Constraint], init: Callable[..., None]) -> Callable[..., None]:
    """``cls``'s own ``init``, taking the keywords of :data:`BASE_KEYWORDS` it does not name.

    The returned ``__init__`` holds such keywords back from ``init``, in the instance's
    ``_held_keywords`` for the time of the call; the kind's ``__init__`` takes them from there
    (:meth:`Constraint._keywords`). It refuses a keyword the kind does not take, and one that
    no gmuk ``__init__`` took by the end of the call (``init`` did not call
    ``super().__init__``). Its signature lists the keywords the kind takes after ``init``'s
    own parameters.
    """
    own = inspect.signature(init)
    named = {
        k
        for k, p in own.parameters.items()
        if p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    }
    caught = tuple(k for k in BASE_KEYWORDS if k not in named)
    if not caught:
        return init
    kind = next(c for c in cls.__mro__ if _in_gmuk(c) and "__init__" in c.__dict__)
    offered = inspect.signature(kind.__init__).parameters  # type: ignore[misc]
    taken = [k for k in caught if k in offered]

    @functools.wraps(init)
    def __init__(self: Constraint, *args: Any, **kwargs: Any) -> None:
        given = {k: kwargs.pop(k) for k in caught if k in kwargs}
        if not given:
            init(self, *args, **kwargs)
            return
        refused = [k for k in given if k not in offered]
        if refused:
            raise DefinitionError(_refusal(type(self), kind, refused[0], list(offered)))
        held: dict[str, Any] | None = self.__dict__.get("_held_keywords")
        outermost = held is None
        if held is None:
            held = {}
            object.__setattr__(self, "_held_keywords", held)
        for key, value in given.items():
            if key in held:
                raise DefinitionError(
                    f"{type(self).__name__} was given {key} twice ({held[key]!r} and {value!r})"
                )
            held[key] = value
        try:
            init(self, *args, **kwargs)
            if outermost and held:
                raise DefinitionError(
                    f"{type(self).__name__} was given {', '.join(held)}, but its __init__ did "
                    f"not call super().__init__(...), whose {kind.__name__} takes them"
                )
        finally:
            if outermost:
                self.__dict__.pop("_held_keywords", None)

    params = list(own.parameters.values())
    at = len(params) - (params[-1].kind is inspect.Parameter.VAR_KEYWORD if params else 0)
    extra = [
        inspect.Parameter(
            k,
            inspect.Parameter.KEYWORD_ONLY,
            default=offered[k].default,
            annotation=offered[k].annotation,
        )
        for k in taken
    ]
    __init__.__signature__ = own.replace(  # type: ignore[attr-defined]
        parameters=[*params[:at], *extra, *params[at:]]
    )
    return __init__


def _refusal(cls: type, kind: type, key: str, offered: list[str]) -> str:
    """Why ``cls`` (built on the gmuk class ``kind``) cannot take the keyword ``key``."""
    takes = ", ".join(f"{k}=" for k in BASE_KEYWORDS if k in offered)
    base = next(c for c in cls.__mro__ if _in_gmuk(c)).__name__
    if key == "baumgarte":
        why = (
            f"a {base} gives its rows itself and gmuk knows no residual of it to stabilise; "
            "add the terms −α Φ̇ − β Φ to its b yourself (McCann 2020, Eq. 4), with gains "
            "your __init__ takes, or build on a kind that applies baumgarte=: "
            "gmuk.HolonomicConstraint, gmuk.NonholonomicConstraint, gmuk.InequalityConstraint, "
            "gmuk.ConfigurationTracking(T2), gmuk.VirtualPairT2 or gmuk.RelativeConstraint"
        )
    else:
        why = f"a {base} has no such option"
    return f"{cls.__name__} takes no {key}=: {why} (from {base} it takes {takes})"


def as_rows(A: Any, b: Any, n_cols: int, who: str) -> tuple[Any, FloatArray]:
    """Check and convert a constraint's (A, b); raise ConstraintError with details.

    A may be dense (array_like) or a scipy.sparse matrix (kept sparse, as CSR).
    """
    try:
        if type(A) is np.ndarray and A.dtype == np.float64 and A.ndim == 2:
            finite_A = bool(np.isfinite(A).all())
        elif sp.issparse(A):
            if A.dtype.kind not in "biuf":  # astype(float) would drop an imaginary part
                raise ValueError(f"dtype {A.dtype} is not real")
            A = sp.csr_matrix(A, dtype=float)
            finite_A = bool(np.isfinite(A.data).all())
        else:
            A = _real_array(A)
            if A.ndim == 1:
                A = A[None, :]
            finite_A = bool(np.isfinite(A).all())
        if type(b) is not np.ndarray or b.dtype != np.float64:
            b = _real_array(b)
    except (TypeError, ValueError) as exc:
        raise ConstraintError(
            f"{who}: rows() must return A (s, {n_cols}) and b (s,) as arrays of real numbers; "
            f"got A {type(A).__name__}, b {type(b).__name__} ({exc})"
        ) from None
    if b.ndim == 0:
        b = b[None]
    if A.ndim != 2 or A.shape[1] != n_cols or b.shape != (A.shape[0],):
        raise ConstraintError(
            f"{who}: rows() must return A of shape (s, {n_cols}) and b of shape (s,); "
            f"got A {A.shape} and b {b.shape}"
        )
    if not (finite_A and np.isfinite(b).all()):
        raise ConstraintError(f"{who}: rows() returned NaN or inf in A or b")
    return A, b


def _real_array(x: Any) -> FloatArray:
    """``x`` as a float64 array; complex, string or object data is a ValueError."""
    if isinstance(x, (bool, np.bool_)):  # a lone True/False is no row value
        raise ValueError(f"{x!r} is a bool, not a real number")
    arr = np.asarray(x)
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"dtype {arr.dtype} is not real")
    return arr.astype(float, copy=False)
