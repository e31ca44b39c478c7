"""CasADi forms of gmuk's parts: what the transcription asks of a force model or constraint.

The direct transcription needs every model as a CasADi expression of symbolic states, so that
CasADi can differentiate it exactly. gmuk finds a part's form in this order:

1. a method on the part itself (the protocol below);
2. a form registered for the part's exact class with :func:`register_casadi_form` (gmuk
   registers its built-in parts this way);
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

from gmuk.bodies import Body, BodyKind
from gmuk.constraints.holonomic import HolonomicConstraint, NonholonomicConstraint
from gmuk.constraints.inequality import InequalityConstraint, PlaneBound, TrackingErrorBound
from gmuk.errors import DefinitionError, MissingDependencyError
from gmuk.forces.base import ForceModel
from gmuk.forces.gravity import PointMassGravity
from gmuk.forces.mechanical import (
    AppliedWrench,
    LinearSpringDamper,
    SpringDamper,
    UniformGravity,
)

__all__ = ["register_casadi_form"]

_FORMS: dict[tuple[type, str], Callable[..., Any]] = {}


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

    def deco(fn: Callable[..., Any]) -> Any:
        _FORMS[(cls, method)] = fn
        return fn

    return deco


def _ca() -> Any:
    try:
        import casadi
    except ImportError:
        raise MissingDependencyError(
            'gmuk.optimize needs CasADi: pip install "gmuk[optimize]" (or pip install casadi)'
        ) from None
    return casadi


def _lookup(part: Any, method: str) -> Callable[..., Any] | None:
    own = getattr(part, method, None)
    if callable(own):
        return own
    form = _FORMS.get((type(part), method))
    if form is not None:
        return lambda *args: form(part, *args)
    return None


def _as_column(value: Any, who: str, rows: int | None) -> Any:
    """A CasADi SX column from what a part returned (SX, DM, numbers, or arrays of them)."""
    ca = _ca()
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
            f"{who} couples bodies (it overrides wrenches()) and has no CasADi form; give it "
            "casadi_wrenches(t, q, nu, bodies) or register one"
        )
    terms = []
    for qi, vi, body in zip(q, nu, bodies, strict=True):
        method = "casadi_wrench" if body.kind is BodyKind.RIGID else "casadi_force"
        fn = _lookup(model, method)
        if fn is None:
            raise DefinitionError(
                f"{who} has no CasADi form for {body.kind} body {body.name!r}; {_FORCE_FIX}"
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


# ---------------------------------------------------------------- built-in parts' forms


def _column(x: Any) -> Any:
    return _ca().DM(np.asarray(x, dtype=float).reshape(-1, 1))


@register_casadi_form(LinearSpringDamper, "casadi_force")
def _lsd_force(m: LinearSpringDamper, t: float, r_N: Any, v_N: Any, body: Body) -> Any:
    return -m.k * (r_N - _column(m.anchor)) - m.c * v_N


@register_casadi_form(LinearSpringDamper, "casadi_wrench")
def _lsd_wrench(m: LinearSpringDamper, t: float, g_NB: Any, V_B: Any, body: Body) -> Any:
    ca = _ca()
    R = g_NB[:3, :3]
    f_N = -m.k * (g_NB[:3, 3] - _column(m.anchor)) - m.c * (R @ V_B[3:])
    return ca.vertcat(ca.DM.zeros(3, 1), R.T @ f_N)


@register_casadi_form(UniformGravity, "casadi_force")
def _ug_force(m: UniformGravity, t: float, r_N: Any, v_N: Any, body: Body) -> Any:
    return body.mass * _column(m.g_N)


@register_casadi_form(UniformGravity, "casadi_wrench")
def _ug_wrench(m: UniformGravity, t: float, g_NB: Any, V_B: Any, body: Body) -> Any:
    ca = _ca()
    return ca.vertcat(ca.DM.zeros(3, 1), body.mass * (g_NB[:3, :3].T @ _column(m.g_N)))


@register_casadi_form(PointMassGravity, "casadi_force")
def _pmg_force(m: PointMassGravity, t: float, r_N: Any, v_N: Any, body: Body) -> Any:
    ca = _ca()
    rn2 = ca.sumsqr(r_N)
    return (-m.mu * body.mass) * r_N / (rn2 * ca.sqrt(rn2))


@register_casadi_form(PointMassGravity, "casadi_wrench")
def _pmg_wrench(m: PointMassGravity, t: float, g_NB: Any, V_B: Any, body: Body) -> Any:
    ca = _ca()
    f = _pmg_force(m, t, g_NB[:3, 3], None, body)
    return ca.vertcat(ca.DM.zeros(3, 1), g_NB[:3, :3].T @ f)


@register_casadi_form(AppliedWrench, "casadi_force")
def _aw_force(m: AppliedWrench, t: float, r_N: Any, v_N: Any, body: Body) -> Any:
    return _column(m.force(t, np.zeros(3), np.zeros(3), body))  # a function of t only


@register_casadi_form(AppliedWrench, "casadi_wrench")
def _aw_wrench(m: AppliedWrench, t: float, g_NB: Any, V_B: Any, body: Body) -> Any:
    ca = _ca()
    w = _column(m._fun(t))
    if m.frame == "inertial":
        Rt = g_NB[:3, :3].T
        return ca.vertcat(Rt @ w[:3], Rt @ w[3:])
    return w


@register_casadi_form(PlaneBound, "casadi_value")
def _plane_value(c: PlaneBound, q: tuple[Any, ...], nu: tuple[Any, ...], t: float) -> Any:
    qb = q[0]
    r = qb[:3, 3] if qb.shape == (4, 4) else qb
    return _column(c.normal).T @ r


@register_casadi_form(TrackingErrorBound, "casadi_value")
def _tracking_value(c: TrackingErrorBound, q: tuple[Any, ...], nu: tuple[Any, ...], t: Any) -> Any:
    ca = _ca()
    if not isinstance(t, (int, float, np.floating)):  # the reference is numeric in t
        raise DefinitionError(f"TrackingErrorBound {c.name!r} needs a numeric time")
    r_r, v_r, _ = c.reference_kinematics(float(t))
    err = q[0] - _column(r_r) if c.quantity == "position" else nu[0] - _column(v_r)
    bound = float(c.bound(float(t))[0])
    if c.form == "norm":
        return ca.norm_2(err) - bound
    return 0.5 * (ca.sumsqr(err) - bound**2)


def _spring_point(q: Any, nu: Any, body: Body, p_B: Any) -> tuple[Any, Any]:
    """World position and velocity of a body point (as SpringDamper._point)."""
    ca = _ca()
    if body.kind is BodyKind.RIGID:
        R, p = q[:3, :3], _column(p_B)
        return q[:3, 3] + R @ p, R @ (nu[3:] + ca.cross(nu[:3], p))
    return q, nu


def _spring_to_body(q: Any, body: Body, p_B: Any, f_N: Any) -> Any:
    ca = _ca()
    if body.kind is not BodyKind.RIGID:
        return f_N
    f_B = q[:3, :3].T @ f_N
    return ca.vertcat(ca.cross(_column(p_B), f_B), f_B)


@register_casadi_form(SpringDamper, "casadi_wrenches")
def _spring_wrenches(
    m: SpringDamper, t: Any, q: tuple[Any, ...], nu: tuple[Any, ...], bodies: tuple[Body, ...]
) -> list[Any]:
    ca = _ca()
    x_a, v_a = _spring_point(q[0], nu[0], bodies[0], m.point_a)
    if m.anchored:
        x_b, v_b = _column(m.point_b), ca.DM.zeros(3, 1)
    else:
        x_b, v_b = _spring_point(q[1], nu[1], bodies[1], m.point_b)
    d = x_b - x_a
    length = ca.norm_2(d)
    u = d / length
    tension = m.k * (length - m.l0) + m.c * ca.dot(u, v_b - v_a)
    f_a = tension * u
    out = [_spring_to_body(q[0], bodies[0], m.point_a, f_a)]
    if not m.anchored:
        out.append(_spring_to_body(q[1], bodies[1], m.point_b, -f_a))
    return out
