"""The base class of gmuk's Runge–Kutta methods, and the registry of methods by name."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, ClassVar

import numpy as np

from gmuk._validation import FloatArray
from gmuk.errors import DefinitionError

__all__ = ["METHODS", "RungeKuttaMethod", "get_method", "method_names"]

#: A right-hand side ``f(t, y) -> dy/dt`` of the local problem (t in s, y a 1-D array).
RHS = Callable[[float, FloatArray], FloatArray]

#: Registered methods by case-folded name, in registration order.
_REGISTRY: dict[str, type[RungeKuttaMethod]] = {}


class RungeKuttaMethod:
    """An explicit Runge–Kutta method: its Butcher tableau and its method-specific behaviour.

    gmuk applies the method to the local problem of each Runge–Kutta–Munthe-Kaas step
    (exponential coordinates about the step's base poses, see :mod:`gmuk.engine.integrate`), which
    is an ordinary differential equation y′ = f(t, y) on a vector space; the method sees only
    ``f``, the state vector ``y`` and the error weights.

    The class is abstract: a subclass supplies the tableau as class attributes, and becomes
    selectable by name in :func:`gmuk.engine.integrate.simulate` (``method="name"``,
    case-insensitive) as soon as it sets its own ``name``::

        class Ralston(RungeKuttaMethod):
            name = "Ralston"
            A = ((0, 0), (2 / 3, 0))
            b = (1 / 4, 3 / 4)
            c = (0, 2 / 3)
            order = 2

    A subclass without its own ``name`` is not registered but can still be passed as a class
    or an instance. Registering a name that another class already holds raises
    :class:`~gmuk.errors.DefinitionError` (a class redefined under the same module and
    qualified name, as when a notebook cell is run again, replaces its earlier version).

    Attributes
    ----------
    name : str
        Registry name (class attribute).
    A : ndarray, shape (s, s)
        Runge–Kutta matrix, strictly lower triangular (explicit methods only).
    b : ndarray, shape (s,)
        Weights of the solution: y₁ = y₀ + h Σ bᵢ kᵢ.
    c : ndarray, shape (s,)
        Nodes (fractions of the step), with c₀ = 0: stage i is evaluated at t + cᵢ h.
    order : int
        Order of the solution y₁. The step-size controller scales the step by
        ``0.9 err^(−1/order)`` (clipped to [0.2, 10]), which presumes an error estimate of
        order ``order − 1``.
    E : ndarray, shape (s,) or (s + 1,) with ``fsal``, or None
        b − b̂ of the embedded formula: the local error estimate is h Σ Eᵢ kᵢ. None for a
        fixed-step method.
    fsal : bool
        "First same as last": the error estimate (and the continuous extension) also use
        k_s = f(t + h, y₁), which the integrator evaluates at every step end anyway (it is
        the next step's first stage), so ``E`` has s + 1 entries.
    adaptive : bool
        Whether the method controls its step size (derived: ``E`` is given).
    dense_output : bool
        Whether the method has a continuous extension (:meth:`interpolant`). Methods with
        one reach output times between steps by interpolation; the others step exactly
        onto them (:attr:`steps_onto_outputs`).
    n_stages : int
        s, the number of stages of one step (derived).
    safety, min_factor, max_factor, max_factor_rejected, error_floor : float
        The step-size controller (adaptive methods): after a step with scaled error
        estimate err (1: at tolerance) the step is scaled by
        ``safety · max(err, error_floor)^(−1/order)``, clipped to [min_factor, max_factor]
        after an accepted step and to [min_factor, max_factor_rejected] for the retry of a
        rejected one (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4). A subclass may set
        its own.
    """

    name: ClassVar[str]
    A: ClassVar[FloatArray]
    b: ClassVar[FloatArray]
    c: ClassVar[FloatArray]
    order: ClassVar[int]
    E: ClassVar[FloatArray | None] = None
    fsal: ClassVar[bool] = False
    dense_output: ClassVar[bool] = False
    adaptive: ClassVar[bool] = False
    n_stages: ClassVar[int] = 0
    safety: ClassVar[float] = 0.9
    min_factor: ClassVar[float] = 0.2
    max_factor: ClassVar[float] = 10.0
    max_factor_rejected: ClassVar[float] = 0.9
    error_floor: ClassVar[float] = 1e-10
    # (A[i, :i], c[i]) for the stages i ≥ 1, and the number of rows of the stage array.
    _rows: ClassVar[tuple[tuple[FloatArray, float], ...] | None] = None
    _n_rows: ClassVar[int] = 0

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if all(hasattr(cls, key) for key in ("A", "b", "c", "order")):
            cls._prepare()
        if "name" in cls.__dict__:
            if cls._rows is None:
                raise DefinitionError(
                    f"integrator method {cls.__qualname__} sets a name but no complete "
                    "tableau (A, b, c, order)"
                )
            _register(cls)

    @classmethod
    def _prepare(cls) -> None:
        """Check the tableau, freeze it as float arrays and precompute the stage rows."""

        def frozen(value: Any, what: str) -> FloatArray:
            try:
                arr = np.array(value, dtype=float)
            except (TypeError, ValueError):
                raise DefinitionError(f"{cls.__qualname__}.{what} is not numeric") from None
            if not np.isfinite(arr).all():
                raise DefinitionError(f"{cls.__qualname__}.{what} has non-finite entries")
            arr.flags.writeable = False
            return arr

        A, b, c = frozen(cls.A, "A"), frozen(cls.b, "b"), frozen(cls.c, "c")
        s = b.size
        if b.shape != (s,) or s == 0 or c.shape != (s,) or A.shape != (s, s):
            raise DefinitionError(
                f"{cls.__qualname__}: the tableau's shapes must be b (s,), c (s,) and A (s, s) "
                f"with s ≥ 1; got b {b.shape}, c {c.shape}, A {A.shape}"
            )
        if np.any(np.triu(A) != 0.0) or c[0] != 0.0:
            raise DefinitionError(
                f"{cls.__qualname__}: only explicit methods are supported (A strictly lower "
                "triangular, c₀ = 0)"
            )
        if isinstance(cls.order, bool) or not isinstance(cls.order, (int, np.integer)):
            raise DefinitionError(f"{cls.__qualname__}.order must be an int")
        if cls.order < 1:
            raise DefinitionError(f"{cls.__qualname__}.order must be ≥ 1; got {cls.order}")
        n_rows = s + (1 if cls.fsal else 0)
        E = None if cls.E is None else frozen(cls.E, "E")
        if E is not None and E.shape != (n_rows,):
            raise DefinitionError(
                f"{cls.__qualname__}.E must have shape ({n_rows},) (s = {s} stages"
                f"{' + the FSAL stage' if cls.fsal else ''}); got {E.shape}"
            )
        cls.A, cls.b, cls.c, cls.E = A, b, c, E
        cls.order = int(cls.order)
        cls.adaptive = E is not None
        cls.n_stages = s
        cls._n_rows = n_rows
        cls._rows = tuple((A[i, :i].copy(), float(c[i])) for i in range(1, s))

    def __init__(self) -> None:
        if type(self)._rows is None:
            raise DefinitionError(
                f"{type(self).__qualname__} is abstract: subclass it with a tableau "
                "(A, b, c, order)"
            )

    def __repr__(self) -> str:
        return f"{type(self).__qualname__}()"

    @property
    def steps_onto_outputs(self) -> bool:
        """Whether the integrator must end steps exactly on output times (no dense output)."""
        return not self.dense_output

    def stages(self, f: RHS, t: float, y: FloatArray, h: float, k0: FloatArray) -> FloatArray:
        """The stage derivatives of one step from (t, y) with step h (s).

        Parameters
        ----------
        f : callable
            ``f(t, y) -> dy/dt``.
        t : float
            Start of the step (s).
        y : ndarray, shape (n,)
            State at ``t``.
        h : float
            Step size (s).
        k0 : ndarray, shape (n,)
            f(t, y), known from the previous step's end.

        Returns
        -------
        ndarray, shape (s, n), or (s + 1, n) with ``fsal``
            Row i is kᵢ = f(t + cᵢ h, y + h Σⱼ aᵢⱼ kⱼ). With ``fsal`` the last row is left
            for the caller to fill with f(t + h, y₁).
        """
        K = np.empty((self._n_rows, y.size))
        K[0] = k0
        rows = self._rows
        assert rows is not None
        for i, (a, ci) in enumerate(rows, 1):
            K[i] = f(t + ci * h, y + h * (a @ K[:i]))
        return K

    def error_norm(self, K: FloatArray, h: float, scale: FloatArray) -> float:
        """Norm of the local error estimate, relative to the weights (≤ 1: step accepted).

        Parameters
        ----------
        K : ndarray, shape (s, n) or (s + 1, n)
            The step's stages (with f(t + h, y₁) last when ``fsal``).
        h : float
            Step size (s).
        scale : ndarray, shape (n,)
            Error weight of each entry of y (``atol + rtol·|y|``-like, same units as y).

        Returns
        -------
        float
            RMS over the entries of ``(h Σ Eᵢ kᵢ) / scale``.
        """
        if self.E is None:
            raise DefinitionError(f"method {label(self)!r} has no error estimate (fixed step)")
        err = h * (K.T @ self.E) / scale
        return float(np.sqrt(err @ err / scale.size))

    def interpolant(
        self, f: RHS, t: float, y: FloatArray, h: float, K: FloatArray, y1: FloatArray
    ) -> Callable[[float], FloatArray]:
        """The continuous extension over the step [t, t + h]: a function of time (s) that
        returns the state. Only for methods with ``dense_output``.

        Parameters
        ----------
        f : callable
            ``f(t, y) -> dy/dt``, for any extra stages the extension needs.
        t, h : float
            Start and size of the step (s).
        y, y1 : ndarray, shape (n,)
            States at t and t + h.
        K : ndarray
            The step's stages as returned by :meth:`stages`, with f(t + h, y₁) last when
            ``fsal``.
        """
        raise NotImplementedError(f"method {label(self)!r} has no continuous extension")

    def interpolant_error(
        self, f: RHS, interpolant: Callable[[float], FloatArray], scale: FloatArray
    ) -> float:
        """Estimated error of the continuous extension over the step, in the norm of
        :meth:`error_norm` (≤ 1: within tolerance). A step whose extension is used for output
        times is accepted only if this is ≤ 1 too. The default, 0, leaves the extension
        unchecked.
        """
        return 0.0


def _register(cls: type[RungeKuttaMethod]) -> None:
    name = cls.__dict__["name"]
    if not isinstance(name, str) or not name.strip():
        raise DefinitionError(f"{cls.__qualname__}.name must be a nonempty str; got {name!r}")
    key = name.casefold()
    old = _REGISTRY.get(key)
    if old is not None and (old.__module__, old.__qualname__) != (
        cls.__module__,
        cls.__qualname__,
    ):
        raise DefinitionError(
            f"an integrator method named {old.name!r} is already registered "
            f"({old.__module__}.{old.__qualname__}); choose another name"
        )
    _REGISTRY[key] = cls


def label(method: RungeKuttaMethod) -> str:
    """The method's name, or its class's qualified name when it has none."""
    name = getattr(method, "name", None)
    return name if isinstance(name, str) else type(method).__qualname__


def method_names() -> tuple[str, ...]:
    """The names of the registered methods, in registration order."""
    return tuple(cls.name for cls in _REGISTRY.values())


def get_method(method: str | type[RungeKuttaMethod] | RungeKuttaMethod) -> RungeKuttaMethod:
    """The method instance for a registered name (case-insensitive), a class or an instance.

    Raises
    ------
    DefinitionError
        For an unknown name (the message lists the registered ones) or another type.
    """
    if isinstance(method, RungeKuttaMethod):
        return method
    if isinstance(method, type) and issubclass(method, RungeKuttaMethod):
        return method()
    if isinstance(method, str):
        cls = _REGISTRY.get(method.casefold())
        if cls is not None:
            return cls()
    raise DefinitionError(
        f"method must be one of {method_names()} (case-insensitive), a RungeKuttaMethod "
        f"subclass or an instance of one; got {method!r}"
    )


class _MethodNames(Sequence[str]):
    """Names of the registered methods, in registration order, as a live read-only sequence
    (methods registered later appear in it; ``in`` ignores case)."""

    def __getitem__(self, index: Any) -> Any:
        return method_names()[index]

    def __len__(self) -> int:
        return len(_REGISTRY)

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name.casefold() in _REGISTRY

    def __repr__(self) -> str:
        return repr(method_names())


#: Names of the registered methods, a live read-only sequence (``in`` ignores case).
METHODS: Sequence[str] = _MethodNames()
