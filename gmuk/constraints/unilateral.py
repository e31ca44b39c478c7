"""Unilateral constraints: contacts that satisfy the KKT conditions exactly.

A unilateral constraint has gaps ``φ_k(q) ≥ 0`` (a point above a plane). While a gap is open
it exerts nothing; while it is *closed* (``φ_k ≈ 0`` and ``|φ̇_k| ≈ 0``: in contact, neither
separating nor striking) its row ``a_k ν̇ ≥ b_k``
(``φ̈_k ≥ −α φ̇_k − β φ_k``) enters the Udwadia–Kalaba solve as an inequality, and the
accelerations are Gauss's principle with inequalities:

``min ½ (ν̇ − ν̇_a)ᵀ M (ν̇ − ν̇_a)``  subject to  ``A ν̇ = b`` (the bilateral rows),
``a_k ν̇ ≥ b_k`` (the closed unilateral rows),

whose KKT conditions are ``M ν̇_c = Aᵀλ + Σ a_kᵀ λ_k``, ``λ_k ≥ 0``, ``a_k ν̇ − b_k ≥ 0`` and
``λ_k (a_k ν̇ − b_k) = 0``: an exact complementarity problem at each right-hand-side
evaluation, solved by :class:`gmuk.engine.contact.ContactSolver` to round-off. This is the
alternative to the thesis's slack form (:class:`~gmuk.InequalityConstraint`), whose KKT
conditions fail by design in transients (McCann 2020, Section 6.5.1).

A gap that closes with a velocity (an impact) needs an impulse: see
:func:`gmuk.engine.contact.simulate_with_impacts` (impulsive Udwadia–Kalaba with Newton's
restitution law).
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from gmuk._forms import Forms
from gmuk._validation import FloatArray, as_array, real_number
from gmuk.bodies import BodyKind
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.errors import DefinitionError

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["CLOSED_GAP", "CLOSED_RATE", "PointPlaneContact", "UnilateralConstraint"]

#: A gap counts as closed below this (m or rad) …
CLOSED_GAP = 1e-9
#: … when it is neither opening nor closing faster than this (m/s or rad/s): slower
#: approaches are absorbed by the contact's stabilised row, faster ones are impacts.
CLOSED_RATE = 1e-6

_FORMS = Forms(
    compiled="a complementarity problem: the contact solve runs in Python",
    symbolic="gmuk.optimize transcribes no unilateral contact",
)


class UnilateralConstraint(Constraint):
    """Gaps φ (k,) ≥ 0 whose closed rows enter the solve as inequalities (module docstring).

    Subclasses implement :meth:`gaps` and :meth:`rows`: ``rows`` returns the k rows
    ``a ν̇ ≥ b`` of every gap (open or closed; the solve keeps the closed ones), so the row
    count never changes along a run.

    Parameters
    ----------
    bodies : sequence of Body or str
    restitution : float
        Newton's coefficient e ∈ [0, 1] of an impact on a closing gap
        (:func:`gmuk.engine.contact.simulate_with_impacts`).
    baumgarte : Baumgarte, optional
        Gains on the gap and its rate in a closed row: ``φ̈ ≥ −α φ̇ − β φ``. By default
        critical gains of 100 rad/s (a penetration decays as ``e^{−100 t}``).
    name : str, optional
    """

    #: Marks the kind for the System, which then takes the contact solve.
    unilateral: ClassVar[bool] = True
    _forms = _FORMS

    def __init__(
        self,
        bodies: Sequence[Body | str],
        *,
        restitution: float = 0.0,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(bodies, name=name)
        (baumgarte,) = self._keywords(baumgarte=baumgarte)
        self.restitution = real_number(restitution, "restitution", non_negative=True)
        if self.restitution > 1.0:
            raise DefinitionError(f"restitution must be in [0, 1]; got {restitution!r}")
        self.baumgarte = baumgarte if baumgarte is not None else Baumgarte.critical(100.0)

    @abc.abstractmethod
    def gaps(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(φ (k,), φ̇ (k,)): the gaps (m or rad, ≥ 0 when feasible) and their rates."""

    def closed(self, state: State) -> np.ndarray:
        """Which gaps are closed, (k,): φ ≤ :data:`CLOSED_GAP` and ``|φ̇|`` ≤
        :data:`CLOSED_RATE`. A gap closing faster is an impact, which no finite force can
        stop: the impulse of :func:`gmuk.engine.contact.impulse` handles it, and until then
        (the trial states of the step that crosses it) the row stays out of the solve."""
        g, gd = self.gaps(state)
        return (g <= CLOSED_GAP) & (np.abs(gd) <= CLOSED_RATE)

    def _stabilised(self, state: State, b: FloatArray) -> FloatArray:
        g, gd = self.gaps(state)
        alpha = np.broadcast_to(np.asarray(self.baumgarte.alpha, dtype=float), g.shape)
        beta = np.broadcast_to(np.asarray(self.baumgarte.beta, dtype=float), g.shape)
        return np.asarray(b - alpha * gd - beta * g, dtype=float)

    def violation(self, state: State) -> tuple[FloatArray, None]:
        """(max(−φ, 0), None): the penetration of each gap; an open gap is no violation."""
        g, _ = self.gaps(state)
        return np.maximum(-g, 0.0), None


class PointPlaneContact(UnilateralConstraint):
    """Points of a rigid body that may not go below a fixed plane (frictionless contact).

    The plane is ``{x : n·x = h}`` in N with unit normal n pointing to the free side; point
    k at ``p_k`` in the body frame has gap ``φ_k = n·(r + R p_k) − h`` (m), rate
    ``φ̇_k = n·R(v + ω × p_k)`` and acceleration
    ``φ̈_k = mᵀ v̇ + (p_k × m)ᵀ ω̇ + mᵀ (ω × (v + ω × p_k))`` with ``m = Rᵀn``: the row
    ``a_k = [(p_k × m)ᵀ, mᵀ]``, ``b_k = −mᵀ(ω × (v + ω × p_k)) − α φ̇_k − β φ_k``.

    Parameters
    ----------
    body : Body or str
    points : array_like (k, 3)
        The contact points in the body frame (m).
    normal : array_like (3,)
        n in N (normalised here); default +z.
    height : float
        h (m).
    restitution, baumgarte, name
        See :class:`UnilateralConstraint`.
    """

    body_kinds = frozenset({BodyKind.RIGID})
    _forms = _FORMS

    def __init__(
        self,
        body: Body | str,
        points: Any,
        *,
        normal: Any = (0.0, 0.0, 1.0),
        height: float = 0.0,
        restitution: float = 0.0,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__([body], restitution=restitution, baumgarte=baumgarte, name=name)
        pts = np.asarray(points, dtype=float)
        if pts.ndim == 1:
            pts = pts[None, :]
        self.points = as_array(pts, (3,), "points")
        if self.points.shape[0] == 0:
            raise DefinitionError("a PointPlaneContact needs at least one point")
        n = as_array(normal, (3,), "normal", batch=False)
        norm = float(np.linalg.norm(n))
        if not norm > 0.0:
            raise DefinitionError(f"normal must be a nonzero 3-vector; got {n.tolist()}")
        self.normal = n / norm
        self.height = real_number(height, "height")

    def _body_state(self, state: State) -> tuple[FloatArray, FloatArray]:
        (i,) = self._rigid_indices(state)
        return state.g[i], state.V[i]

    def gaps(self, state: State) -> tuple[FloatArray, FloatArray]:
        g, V = self._body_state(state)
        R, r = g[:3, :3], g[:3, 3]
        w, v = V[:3], V[3:]
        phi = (r + self.points @ R.T) @ self.normal - self.height
        m = R.T @ self.normal
        rate = (v + np.cross(w, self.points)) @ m
        return phi, rate

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A (k, 6), b (k,)): ``φ̈_k ≥ −α φ̇_k − β φ_k`` for each point, open or closed."""
        g, V = self._body_state(state)
        m = g[:3, :3].T @ self.normal
        w, v = V[:3], V[3:]
        A = np.empty((self.points.shape[0], 6))
        A[:, :3] = np.cross(self.points, m)
        A[:, 3:] = m
        u = v + np.cross(w, self.points)
        b = -(np.cross(w, u) @ m)
        return A, self._stabilised(state, b)
