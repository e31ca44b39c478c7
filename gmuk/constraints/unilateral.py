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

A :class:`PointPlaneContact` may carry Coulomb friction (``friction=μ``): each closed point then
also has two tangential rows, whose multipliers are the friction force, ``‖f_t‖ ≤ μ f_n``
(:func:`gmuk.engine.contact.solve_with_friction`).
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

__all__ = [
    "CLOSED_GAP",
    "CLOSED_RATE",
    "SLIP_SPEED",
    "JointLimit",
    "PointPlaneContact",
    "UnilateralConstraint",
]

#: A gap counts as closed below this (m or rad) …
CLOSED_GAP = 1e-9
#: … when it is neither opening nor closing faster than this (m/s or rad/s): slower
#: approaches are absorbed by the contact's stabilised row, faster ones are impacts.
CLOSED_RATE = 1e-6
#: A closed point with friction slides when its tangential speed exceeds this (m/s): the
#: friction is then kinetic, ``−μ f_n v_t/‖v_t‖``; at or below it the point sticks unless the
#: friction it needs leaves the cone.
SLIP_SPEED = 1e-6

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
    #: Coulomb's friction coefficient μ of the closed gaps (0: frictionless; only
    #: :class:`PointPlaneContact` takes one).
    friction: float = 0.0
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
        """``b − α φ̇ − β φ``; a gap at infinity (a stop not set) contributes no term."""
        g, gd = self.gaps(state)
        g = np.where(np.isfinite(g), g, 0.0)
        alpha = np.broadcast_to(np.asarray(self.baumgarte.alpha, dtype=float), g.shape)
        beta = np.broadcast_to(np.asarray(self.baumgarte.beta, dtype=float), g.shape)
        return np.asarray(b - alpha * gd - beta * g, dtype=float)

    def violation(self, state: State) -> tuple[FloatArray, None]:
        """(max(−φ, 0), None): the penetration of each gap; an open gap is no violation."""
        g, _ = self.gaps(state)
        return np.maximum(-g, 0.0), None


class PointPlaneContact(UnilateralConstraint):
    """Points of a rigid body that may not go below a fixed plane, with or without Coulomb
    friction.

    The plane is ``{x : n·x = h}`` in N with unit normal n pointing to the free side; point
    k at ``p_k`` in the body frame has gap ``φ_k = n·(r + R p_k) − h`` (m), rate
    ``φ̇_k = n·R(v + ω × p_k)`` and acceleration
    ``φ̈_k = mᵀ v̇ + (p_k × m)ᵀ ω̇ + mᵀ (ω × (v + ω × p_k))`` with ``m = Rᵀn``: the row
    ``a_k = [(p_k × m)ᵀ, mᵀ]``, ``b_k = −mᵀ(ω × (v + ω × p_k)) − α φ̇_k − β φ_k``.

    With ``friction=μ > 0`` the constraint has 3k rows: the k normal rows first, then two
    tangential rows per point, along the plane's fixed tangents ``t₁, t₂`` (:attr:`tangents`,
    with ``t₁ × t₂ = n``): ``[(p_k × m_j)ᵀ, m_jᵀ] ν̇ = −m_jᵀ(ω × (v + ω × p_k)) − γ u_j``,
    ``m_j = Rᵀt_j``, the point's tangential acceleration held at ``−γ u`` (u (2,) its tangential
    velocity :meth:`tangential_velocities`, γ = √β of the Baumgarte gains, 100 1/s by
    default), which is what a sticking point needs. Their multipliers are the friction force
    ``f_t`` (N, in t₁, t₂) at each closed point, which the contact solve keeps in Coulomb's
    cone ``‖f_t‖ ≤ μ f_n``: sticking while the cone can hold the point, kinetic
    ``−μ f_n u/‖u‖`` while it slides (:func:`gmuk.engine.contact.solve_with_friction`); an open
    point has none. The cone is the exact (circular) one, not a polyhedral approximation.

    Parameters
    ----------
    body : Body or str
    points : array_like (k, 3)
        The contact points in the body frame (m).
    normal : array_like (3,)
        n in N (normalised here); default +z.
    height : float
        h (m).
    friction : float
        Coulomb's coefficient μ ≥ 0 (dimensionless), static and kinetic alike; 0 (the
        default) is the frictionless contact, with its k rows.
    restitution, baumgarte, name
        See :class:`UnilateralConstraint`. Impacts are frictionless: the impulse acts
        along the normal only.
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
        friction: float = 0.0,
        restitution: float = 0.0,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__([body], restitution=restitution, baumgarte=baumgarte, name=name)
        self.friction = real_number(friction, "friction", non_negative=True)
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
        # t₁ ⟂ n from the axis least along n, t₂ = n × t₁: a right-handed (t₁, t₂, n)
        t1 = np.cross(np.eye(3)[int(np.argmin(np.abs(self.normal)))], self.normal)
        t1 /= np.linalg.norm(t1)
        #: (2, 3): the plane's tangents t₁, t₂ in N (rows), the axes of the friction force.
        self.tangents = np.array([t1, np.cross(self.normal, t1)])

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
        """(A (k, 6), b (k,)): ``φ̈_k ≥ −α φ̇_k − β φ_k`` for each point, open or closed; with
        friction (A (3k, 6), b (3k,)), point i's tangential rows at k + 2i and k + 2i + 1 (class
        docstring)."""
        g, V = self._body_state(state)
        m = g[:3, :3].T @ self.normal
        w, v = V[:3], V[3:]
        k = self.points.shape[0]
        A = np.empty((k, 6))
        A[:, :3] = np.cross(self.points, m)
        A[:, 3:] = m
        u = v + np.cross(w, self.points)
        b = -(np.cross(w, u) @ m)
        if self.friction == 0.0:
            return A, self._stabilised(state, b)
        mt = self.tangents @ g[:3, :3]  # (2, 3): m_j = Rᵀ t_j as rows
        At = np.empty((k, 2, 6))
        At[:, :, :3] = np.cross(self.points[:, None, :], mt[None, :, :])
        At[:, :, 3:] = mt[None, :, :]
        bt = -(np.cross(w, u) @ mt.T) - self._slip_gain() * (u @ mt.T)
        return np.vstack([A, At.reshape(2 * k, 6)]), np.concatenate(
            [self._stabilised(state, b), bt.reshape(2 * k)]
        )

    def _slip_gain(self) -> FloatArray:
        """γ (k, 1) (1/s): the tangential rows' velocity gain, √β of the Baumgarte gains."""
        beta = np.broadcast_to(np.asarray(self.baumgarte.beta, dtype=float), (len(self.points),))
        return np.sqrt(beta)[:, None]

    def tangential_velocities(self, state: State) -> FloatArray:
        """u (k, 2) (m/s): each point's velocity along the plane's tangents t₁, t₂."""
        g, V = self._body_state(state)
        u_N = (V[3:] + np.cross(V[:3], self.points)) @ g[:3, :3].T
        return np.asarray(u_N @ self.tangents.T, dtype=float)


class JointLimit(UnilateralConstraint):
    """Stops on a one-coordinate joint (revolute, prismatic): ``lower ≤ q ≤ upper``.

    Two gaps, ``φ₁ = q − lower`` and ``φ₂ = upper − q`` (rad or m), read with the joint's
    :meth:`~gmuk.robots.Joint.coordinates` (angles in (−π, π], so an angular range must lie
    within it). The joint coordinate's acceleration is linear in the bodies' ``ν̇``,
    ``q̈ = a ν̇ + c`` with ``a = S⁺ [−Ad_{h⁻¹} Ad_{X_PJ⁻¹}, Ad_{X_CJ⁻¹}]`` and
    ``c = S⁺ ad_{V_rel} Ad_{h⁻¹} V_{J_p}`` (:meth:`~gmuk.robots.Joint.relative_acceleration`), so
    the rows are ``±a ν̇ ≥ ∓c − α φ̇ − β φ``.

    Parameters
    ----------
    joint : gmuk.robots.Joint
        A joint with one coordinate.
    lower, upper : float
        The stops (rad or m), lower < upper; ``-inf`` or ``inf`` for none on that side.
    restitution, baumgarte, name
        See :class:`UnilateralConstraint`.
    """

    body_kinds = frozenset({BodyKind.RIGID})
    _forms = _FORMS

    def __init__(
        self,
        joint: Any,
        lower: float = -np.inf,
        upper: float = np.inf,
        *,
        restitution: float = 0.0,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        from gmuk.robots.joints import Joint

        if not isinstance(joint, Joint) or joint.nv != 1:
            raise DefinitionError(
                f"a JointLimit takes a gmuk.robots joint with one coordinate; got {joint!r:.80}"
            )
        super().__init__(
            list(joint.bodies),
            restitution=restitution,
            baumgarte=baumgarte,
            name=name or f"{joint.name} limits",
        )
        lo = float(lower)
        hi = float(upper)
        if np.isnan(lo) or np.isnan(hi) or not lo < hi:
            raise DefinitionError(f"a JointLimit needs lower < upper; got {lower!r}, {upper!r}")
        self.joint, self.lower, self.upper = joint, lo, hi

    def gaps(self, state: State) -> tuple[FloatArray, FloatArray]:
        q = float(self.joint.coordinates(state)[0])
        qd = float(self.joint.rates(state)[0])
        return np.array([q - self.lower, self.upper - q]), np.array([qd, -qd])

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A (2, 6 or 12), b (2,)): ``q̈ ≥ …`` and ``−q̈ ≥ …`` on the joint's bodies."""
        joint = self.joint
        S_pinv = joint._S_pinv[0]
        zero = np.zeros(6)
        c = float(S_pinv @ joint.relative_acceleration(state, zero, zero))
        a_C = S_pinv @ _Ad_inverse(joint.child_frame)
        if joint.grounded:
            a = a_C
        else:
            h_inv = _Ad_inverse(joint.relative_pose(state))
            a = np.concatenate([-(S_pinv @ (h_inv @ _Ad_inverse(joint.parent_frame))), a_C])
        A = np.vstack([a, -a])
        b = np.array([-c, c])
        return A, self._stabilised(state, b)


def _Ad_inverse(g: FloatArray) -> FloatArray:
    """Ad_{g⁻¹} (6, 6)."""
    from gmuk.lie import se3

    return np.asarray(se3._Ad(se3._inverse(g)), dtype=float)
