"""The Constraint base class and Baumgarte gains.

A constraint involves some bodies and, at a :class:`gmuk.State`, returns its rows (A, b) of
``A ν̇ = b`` (McCann 2020, Eqs. 1 and 63), where the columns of A are the velocities of
``self.bodies`` in the order given (6 per rigid body [ω; v], 3 per point mass, 1 per slack
coordinate). The System places the columns into the global A.
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
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

__all__ = ["ROWS_KERNEL", "Baumgarte", "Constraint"]

#: The signature of a constraint's rows kernel, as the compiled loop calls it:
#: ``(t, g_1 (4, 4), V_1 (6,), g_2, V_2, p, A (s, 12), b (s,)) -> status``, writing the rows
#: of the constraint on its first body (columns 0–5) and its second one (columns 6–11; zero,
#: and ``g_2, V_2`` ignored, for a one-body constraint); status 0 or a failure code.
ROWS_KERNEL = numba_types.int64(numba_types.float64, C2, C1, C2, C1, C1, C2, C1)


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
    """

    #: The kinds of body this constraint can act on (default: every kind).
    body_kinds: ClassVar[frozenset[BodyKind]] = frozenset(BodyKind)
    _numeric_methods: ClassVar[tuple[str, ...]] = ("rows",)
    _bodies: tuple[Body | str, ...]
    _name: str
    _cached_indices: tuple[object, tuple[int, ...]] | None = None

    def __init__(self, bodies: Sequence[Body | str], *, name: str | None = None) -> None:
        if isinstance(bodies, str) or not isinstance(bodies, Sequence):
            bodies = [bodies]
        if len(bodies) == 0:
            raise DefinitionError(f"{type(self).__name__} needs at least one body")
        who = type(self).__name__ + (f" {name!r}" if name else "")
        bodies = distinct_bodies(bodies, who)
        object.__setattr__(self, "_bodies", bodies)
        object.__setattr__(self, "_name", name or type(self).__name__)

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
        return kernel, tuple(float(v) for v in params), int(n_rows)

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
