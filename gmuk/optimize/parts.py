"""CasADi forms of gmuk's parts: what the transcription asks of a force model or constraint.

The direct transcription needs every model as a CasADi expression of symbolic states, so that
CasADi can differentiate it exactly. gmuk finds a part's form in this order:

1. a method on the part's class (the protocol below; gmuk's built-in parts have theirs), when
   the class that defines it also defines the part's numeric methods: a subclass that does
   not override ``wrench``/``force``/``wrenches`` (force models), ``value`` (inequalities),
   ``residual`` (holonomic and nonholonomic constraints) or ``rows`` inherits the form; one
   that overrides any of them does not, until it defines its own (it changed the physics the
   form describes; :class:`gmuk._forms.DeclaresForms`);
2. a form registered for the part's exact class with :func:`register_casadi_form`;
3. for :class:`~gmuk.constraints.InequalityConstraint`,
   :class:`~gmuk.constraints.HolonomicConstraint` and
   :class:`~gmuk.constraints.NonholonomicConstraint` subclasses, the part's numeric
   ``value`` / ``residual`` called with CasADi symbols — which works when it is written
   with operations CasADi supports (indexing, ``+ − * /``, ``@`` between CasADi objects,
   ``casadi.sin`` …; not ``float()``, ``np.linalg`` or ``if`` on a state);
4. otherwise a :class:`gmuk.errors.DefinitionError` naming the part and what it lacks.

Protocol (all arguments CasADi ``SX`` column vectors or matrices, ``t`` a float in s):

==========================================  ================================================
method                                      returns
==========================================  ================================================
``casadi_force(t, r_N, v_N, body)``         f_N (3×1), N: force on a point mass
``casadi_wrench(t, g_NB, V_B, body)``       [L; f] (6×1) in B: wrench on a rigid body
``casadi_wrenches(t, q, nu, bodies)``       list, one per body: a coupling force model
``casadi_value(q, nu, t)``                  h (scalar): an inequality ``l ≤ h ≤ u``
``casadi_residual(q, t)``                   φ (s×1): a holonomic ``φ(q, t) = 0``
``casadi_residual(q, nu, t)``               ψ (s×1): a nonholonomic ``ψ(q, ν, t) = 0``
==========================================  ================================================

``q`` and ``nu`` are tuples in the order of the part's bodies, as for the numeric methods:
g_NB (4×4) or r_N (3×1), and V_B (6×1) or v_N (3×1).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from gmuk._casadi import casadi
from gmuk.bodies import Body, BodyKind
from gmuk.constraints.holonomic import HolonomicConstraint, NonholonomicConstraint
from gmuk.constraints.inequality import InequalityConstraint
from gmuk.errors import DefinitionError
from gmuk.forces.base import ForceModel

__all__ = ["register_casadi_form"]

_FORMS: dict[tuple[type, str], Callable[..., Any]] = {}

#: The protocol's method names (the table above).
_PROTOCOL = frozenset(
    ("casadi_force", "casadi_wrench", "casadi_wrenches", "casadi_value", "casadi_residual")
)


def register_casadi_form(cls: type, method: str) -> Callable[[Callable[..., Any]], Any]:
    """Register the CasADi form of ``method`` for the parts of exactly class ``cls``.

    Parameters
    ----------
    cls : type
        A ForceModel or Constraint class (subclasses are not covered: they may change the
        model).
    method : str
        One of the protocol's names (``"casadi_force"``, ``"casadi_wrench"``,
        ``"casadi_value"``, ``"casadi_residual"``, ``"casadi_wrenches"``).

    Raises
    ------
    DefinitionError
        For a ``cls`` that is not a ForceModel or Constraint class, another ``method``, or
        a decorated object that is not callable.

    Returns
    -------
    decorator
        Taking ``fn(part, *args)`` with the protocol's arguments.

    Examples
    --------
    >>> import casadi as ca
    >>> @register_casadi_form(MyDrag, "casadi_force")  # doctest: +SKIP
    ... def _drag(model, t, r_N, v_N, body):
    ...     return -model.c * ca.norm_2(v_N) * v_N
    """

    from gmuk.constraints.base import Constraint

    if not isinstance(cls, type) or not issubclass(cls, (ForceModel, Constraint)):
        raise DefinitionError(
            "register_casadi_form needs a ForceModel or Constraint class; got "
            f"{type(cls).__name__} {cls!r:.60}"
        )
    if method not in _PROTOCOL:
        raise DefinitionError(
            f"register_casadi_form: method must be one of {sorted(_PROTOCOL)}; got {method!r:.60}"
        )

    def deco(fn: Callable[..., Any]) -> Any:
        if not callable(fn):
            raise DefinitionError(
                f"register_casadi_form({cls.__name__}, {method!r}) decorates a function "
                f"fn(part, *args); got {type(fn).__name__}"
            )
        _FORMS[(cls, method)] = fn
        return fn

    return deco


def _lookup(part: Any, method: str) -> Callable[..., Any] | None:
    """The part's form ``method``: declared on its class (and not cut off by an overridden
    numeric method), else registered for its exact class; None if neither."""
    declared = getattr(part, "_declared_form", None)
    own = declared(method) if declared is not None else getattr(part, method, None)
    if callable(own):
        return own
    form = _FORMS.get((type(part), method))
    if form is not None:
        return lambda *args: form(part, *args)
    return None


def _cut_off(part: Any, method: str) -> str:
    """A sentence for an error message when ``part`` has ``method`` only from a class whose
    numeric methods it overrides; empty otherwise."""
    cut = getattr(part, "_cut_off_form", None)
    owner = cut(method) if cut is not None else None
    if owner is None:
        return ""
    return (
        f" ({type(part).__name__} overrides a numeric method of {owner.__name__}, so it does "
        f"not inherit {owner.__name__}.{method}: the form would describe the old physics)"
    )


def _as_column(value: Any, who: str, rows: int | None) -> Any:
    """A CasADi SX column from what a part returned (SX, DM, numbers, or arrays of them)."""
    ca = casadi()
    try:
        if isinstance(value, (ca.SX, ca.DM)):
            out = ca.SX(value)
        elif isinstance(value, np.ndarray) and value.dtype == object:
            out = ca.vertcat(*[ca.SX(v) for v in value.ravel()])
        elif isinstance(value, (list, tuple)):
            out = ca.vertcat(*[ca.SX(v) for v in value])
        else:
            out = ca.SX(value)
    except (TypeError, NotImplementedError, RuntimeError) as exc:
        raise DefinitionError(
            f"{who} returned {type(value).__name__}, not a CasADi expression ({exc})"
        ) from None
    if out.shape[1] != 1 and out.shape[0] == 1:
        out = out.T
    if out.shape[1] != 1 or (rows is not None and out.shape[0] != rows):
        want = f"({rows}, 1)" if rows is not None else "a column"
        raise DefinitionError(f"{who} returned shape {out.shape}; expected {want}")
    return out


def _call(fn: Callable[..., Any], args: tuple[Any, ...], who: str, fix: str) -> Any:
    try:
        return fn(*args)
    except DefinitionError:
        raise
    except Exception as exc:  # a numeric method that cannot take symbols
        raise DefinitionError(
            f"{who} cannot be evaluated with CasADi symbols ({type(exc).__name__}: {exc}); {fix}"
        ) from None


_FORCE_FIX = (
    "give it a casadi_force(t, r_N, v_N, body) / casadi_wrench(t, g_NB, V_B, body) method, "
    "or register one with gmuk.optimize.register_casadi_form (see docs/optimize)"
)


def force_terms(
    model: ForceModel, t: Any, q: Sequence[Any], nu: Sequence[Any], bodies: Sequence[Body]
) -> list[Any]:
    """The model's generalized forces on ``bodies`` as CasADi columns (3×1 or 6×1); ``t`` a
    float or a CasADi symbol."""
    who = f"force model {model.name!r} ({type(model).__name__})"
    coupled = _lookup(model, "casadi_wrenches")
    if coupled is not None:
        out = _call(coupled, (t, tuple(q), tuple(nu), tuple(bodies)), who, _FORCE_FIX)
        if len(out) != len(bodies):
            raise DefinitionError(
                f"{who}: casadi_wrenches returned {len(out)} terms for {len(bodies)} bodies"
            )
        return [_as_column(w, who, b.dof) for w, b in zip(out, bodies, strict=True)]
    if type(model).wrenches is not ForceModel.wrenches:
        raise DefinitionError(
            f"{who} couples bodies (it overrides wrenches()) and has no CasADi form"
            f"{_cut_off(model, 'casadi_wrenches')}; give it casadi_wrenches(t, q, nu, bodies) "
            "or register one"
        )
    terms = []
    for qi, vi, body in zip(q, nu, bodies, strict=True):
        method = "casadi_wrench" if body.kind is BodyKind.RIGID else "casadi_force"
        fn = _lookup(model, method)
        if fn is None:
            raise DefinitionError(
                f"{who} has no CasADi form for {body.kind} body {body.name!r}"
                f"{_cut_off(model, method)}; {_FORCE_FIX}"
            )
        terms.append(_as_column(_call(fn, (t, qi, vi, body), who, _FORCE_FIX), who, body.dof))
    return terms


def inequality_value(
    c: InequalityConstraint, q: tuple[Any, ...], nu: tuple[Any, ...], t: Any
) -> Any:
    """h(q, ν, t) of an inequality as a CasADi scalar."""
    who = f"inequality constraint {c.name!r} ({type(c).__name__})"
    fn = _lookup(c, "casadi_value") or c.value
    fix = "give it a casadi_value(q, nu, t) method written with CasADi operations"
    return _as_column(_call(fn, (q, nu, t), who, fix), who, 1)


def equality_residual(c: Any, q: tuple[Any, ...], nu: tuple[Any, ...], t: Any) -> Any:
    """φ(q, t) or ψ(q, ν, t) of an equality constraint as a CasADi column."""
    who = f"constraint {c.name!r} ({type(c).__name__})"
    fix = "give it a casadi_residual method written with CasADi operations"
    holonomic = isinstance(c, HolonomicConstraint)
    fn = _lookup(c, "casadi_residual") or c.residual
    args = (q, t) if holonomic else (q, nu, t)
    return _as_column(_call(fn, args, who, fix), who, None)


def constraint_kind(c: Any) -> str:
    """ "inequality", "holonomic" or "nonholonomic"; a DefinitionError for any other kind."""
    if isinstance(c, InequalityConstraint):
        return "inequality"
    if isinstance(c, HolonomicConstraint):
        return "holonomic"
    if isinstance(c, NonholonomicConstraint):
        return "nonholonomic"
    raise DefinitionError(
        f"constraint {c.name!r} is a {type(c).__name__}, a kind gmuk.optimize cannot "
        "transcribe: it gives only acceleration rows (A, b). Path constraints must be an "
        "InequalityConstraint (h(q, ν, t) between bounds), a HolonomicConstraint "
        "(φ(q, t) = 0) or a NonholonomicConstraint (ψ(q, ν, t) = 0)"
    )
