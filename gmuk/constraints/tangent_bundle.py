"""Constraints on the double tangent bundle T²SE(3): ``A g̈ B = C`` (McCann 2020, Eq. 79).

For n rigid bodies, ``g̈ = blkdiag(g̈₁, …, g̈ₙ)`` (4n × 4n), ``A`` is (m, 4n), ``B`` (4n, p) and
``C`` (m, p). Every reachable g̈ is ``g̈_i = g_i (V_i^² + V̇_i^)``, so the constraint is linear
in the body accelerations: :meth:`TangentBundleConstraint.rows` gives those rows
(:func:`gmuk.engine.uk.reachable_rows`), which the System stacks and solves like any other
constraint's. With ``System(..., tangent_bundle_method="eq80")`` the System instead solves
Eq. 80 for ``g̈_c`` and recovers ``V̇_c,i = (g_i⁻¹ g̈_c,ii)^∨``. Errata (docs/errata.rst):
for general A, B the g̈_c of Eq. 80 need not lie in g·se(3) (no control input produces it);
gmuk projects each diagonal block onto se(3) (skew rotation part, translation column) and
reports the size of what it discarded.

Stabilisation (beyond the thesis). Eq. 79 holds the constraint at the acceleration level only:
round-off and integration error that leave the constraint manifold stay off it, and grow where
the constrained motion is unstable (the LVLH attitude of docs/scenarios/chapter4.rst). With
``baumgarte=Baumgarte(alpha, beta)`` the constraints below add Baumgarte terms (McCann 2020,
Eq. 4) to C, and only to C: A and B are those of the thesis, and without ``baumgarte`` (the
default) C is too. For a tracking block ``g = g_d`` the terms act on the position-level
constraint Φ = g − g_d itself, in the 4×4 matrices of Eq. 79: ``Φ̈ + α Φ̇ + β Φ = 0``, i.e.
``g̈ = g̈_d − α (ġ − ġ_d) − β (g − g_d)``. Its translation column is the inertial error
``p̈ − p̈_d + α(ṗ − ṗ_d) + β(p − p_d) = 0`` exactly; its rotation block, projected onto the
reachable ``R (ω̇^ + ω^²)``, restores ``R_dᵀR`` through ``skew(Rᵀ R_d)`` (≈ −θ^ near the
reference). Off the constraint the stabilised C is not reachable to second order in the error
(the symmetric part of ``Rᵀ(R − R_d)`` is ``O(θ²)``): negligible while the terms keep the error
at round-off.
"""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.engine.uk import reachable_rows
from gmuk.errors import DefinitionError
from gmuk.lie import se3
from gmuk.reference import ReferenceState, ReferenceTrajectory

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["ConfigurationTrackingT2", "TangentBundleConstraint", "VirtualPairT2"]


class TangentBundleConstraint(Constraint):
    """A constraint ``A g̈ B = C`` on the rigid bodies ``self.bodies`` (Eq. 79).

    Subclasses implement :meth:`tangent_rows`. Its R⁶ rows (:meth:`rows`) restrict the
    constraint to reachable accelerations, so it stacks with any other constraint. Eq. 80
    itself (``System(..., tangent_bundle_method="eq80")``) takes exactly one such
    constraint (Eq. 79 does not stack: write one A, B, C over all the bodies).
    """

    body_kinds = frozenset({BodyKind.RIGID})

    @abc.abstractmethod
    def tangent_rows(self, state: State) -> tuple[Any, Any, Any]:
        """(A (m, 4k), B (4k, p), C (m, p)) at ``state`` for the k bodies of the constraint."""

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """``A g̈ B = C`` on reachable accelerations, as rows on the bodies' twists.

        Returns
        -------
        A6 : ndarray (m·p, 6k)
        b6 : ndarray (m·p,)
            See :func:`gmuk.engine.uk.reachable_rows`.
        """
        A, B, C = (np.asarray(x, dtype=float) for x in self.tangent_rows(state))
        idx = list(self._rigid_indices(state))
        return reachable_rows(A, B, C, state.g[idx], state.V[idx])


def _scalar_gains(baumgarte: Baumgarte | None, owner: str, label: str) -> tuple[float, float]:
    """(α, β) of ``baumgarte`` as floats (0, 0 for None); the T² terms take scalar gains."""
    if baumgarte is None:
        return 0.0, 0.0
    if not isinstance(baumgarte, Baumgarte):
        raise DefinitionError(
            f"{label} of a {owner} must be a gmuk.Baumgarte or None; got {type(baumgarte).__name__}"
        )
    alpha, beta = np.asarray(baumgarte.alpha), np.asarray(baumgarte.beta)
    if alpha.ndim or beta.ndim:
        raise DefinitionError(
            f"the {label} gains of a {owner} must be scalars (one α and one β for all the "
            f"entries of its 4×4 blocks); got alpha {alpha.shape}, beta {beta.shape}"
        )
    return float(alpha), float(beta)


def _tracking_target(
    g: FloatArray, V: FloatArray, ref: ReferenceState, gains: tuple[float, float] = (0.0, 0.0)
) -> FloatArray:
    """The g̈ that tracking ``g = g_d`` asks for: ``g̈_d = g_d (V_d^² + V̇_d^)`` (Eq. 79's C for
    A = B = I₄), minus ``α (ġ − ġ_d) + β (g − g_d)`` when the gains ``(α, β)`` are not zero.

    Parameters
    ----------
    g : ndarray (4, 4)
        The pose.
    V : ndarray (6,)
        Its body twist.
    ref : ReferenceState
        (g_d, V_d, V̇_d) at the time.
    gains : (float, float)
        α (1/s), β (1/s²).
    """
    Vd = se3._hat(ref.V)
    target: FloatArray = ref.g @ (Vd @ Vd + se3._hat(ref.V_dot))
    alpha, beta = gains
    if alpha or beta:
        target = target - alpha * (g @ se3._hat(V) - ref.g @ Vd) - beta * (g - ref.g)
    return target


class ConfigurationTrackingT2(TangentBundleConstraint):
    """Full tracking ``g̈ = g̈_d`` on T²SE(3): A = B = I₄, C = g_d (V_d^² + V̇_d^).

    Equal (to round-off) to :class:`gmuk.constraints.ConfigurationTracking` on R⁶
    (McCann 2020, Section 4.2, FCEIM). The stabilised variants differ off the reference:
    R⁶'s Baumgarte terms act on the body-frame errors, these on g − g_d.

    Parameters
    ----------
    body : Body or str
        A rigid body.
    reference : ReferenceTrajectory
    baumgarte : Baumgarte, optional
        Scalar gains (α, β): the stabilised variant ``C = g̈_d − α (ġ − ġ_d) − β (g − g_d)``,
        Eq. 4 on Φ = g − g_d (module docstring). None (the default): the thesis's rows.
    name : str, optional
    """

    _forms = Forms(
        compiled="its rows are called back from the compiled loop",
        symbolic="gives acceleration rows only: gmuk.optimize transcribes holonomic, "
        "nonholonomic and inequality constraints",
    )

    def __init__(
        self,
        body: Body | str,
        reference: ReferenceTrajectory,
        *,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__([body], name=name)
        (baumgarte,) = self._keywords(baumgarte=baumgarte)
        if not isinstance(reference, ReferenceTrajectory):
            raise DefinitionError(
                f"reference must be a gmuk.ReferenceTrajectory; got {type(reference).__name__}"
            )
        self.reference = reference
        self._gains = _scalar_gains(baumgarte, type(self).__name__, "baumgarte")
        self.baumgarte = baumgarte

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """(e_g, e_V) against the reference, weighed as for
        :meth:`gmuk.constraints.ConfigurationTracking.violation`."""
        from gmuk.constraints.tracking import relative_errors

        (i,) = self._rigid_indices(state)
        ref = self.reference.evaluate(state.t)
        return relative_errors(state.g[i], state.V[i], ref.g, ref.V)

    def tangent_rows(self, state: State) -> tuple[FloatArray, FloatArray, FloatArray]:
        """A = B = I₄ and C = g̈_d (with ``baumgarte``: minus α (ġ − ġ_d) + β (g − g_d))."""
        (i,) = self._rigid_indices(state)
        ref = self.reference.evaluate(state.t)
        return np.eye(4), np.eye(4), _tracking_target(state.g[i], state.V[i], ref, self._gains)


_X = np.eye(4)[:3]  # rows 1–3: drop the (zero) last row of g̈
_Y = np.eye(4)[:, [0, 3]]  # columns 1 and 4: E₁^ Y = 0, so roll about axis 1 drops out


class VirtualPairT2(TangentBundleConstraint):
    """The virtual-spacecraft pair of McCann (2020) Section 4.1.3, on T²SE(3).

    Beyond the thesis (its future work). With ``g̈ = blkdiag(g̈_L, g̈_B)``:

    * L tracks the reference: ``g̈_L = g̈_d``;
    * B stays at L rotated about their common first axis, ``g_B = g_L h``,
      ``h = exp(φ e₁^)``: from ``g̈_B = g̈_L h + 2 ġ_L ḣ + g_L ḧ`` and
      ``ḧ = h (V_rel^² + V̇_rel^)``, the five non-roll components of ``V̇_rel`` vanish iff
      ``X (g̈_B − g̈_L h) Y = X (2 ġ_L ḣ + g_L h V_rel^²) Y`` with ``X = [I₃ 0]`` and
      ``Y = [e₁ e₄]`` (``X g_B W^ Y = [R_B(w × e₁), R_B u]``, zero iff W is a pure roll).

    Stacked into one ``A g̈ B = C`` (Eq. 79)::

        A = [[I₄, 0], [−X, X]]        B = [[I₄, h Y], [0, Y]]
        C = [[g̈_d, g̈_d h Y], [−X g̈_d, X (2 ġ_L ḣ + g_L h V_rel^²) Y]]

    (the off-diagonal blocks of C repeat the first constraint, as A g̈ B produces them).

    Stabilised variant (beyond the thesis; A and B unchanged): ``baumgarte`` replaces g̈_d in
    every block of C by the tracking target ``g̈_d − α (ġ_L − ġ_d) − β (g_L − g_d)``
    (:class:`ConfigurationTrackingT2`), and ``relative_baumgarte`` adds
    ``−X g_B (α_r V_rel + β_r log h)^ Y`` to the last block, so that the five locked
    components of the relative motion obey ``V̇_rel + α_r V_rel + β_r log h = 0`` (the roll
    component drops out: ``X g_B e₁^ Y = 0``). With both None (the default) C is the thesis's.

    Parameters
    ----------
    body : Body or str
        The spacecraft B, free to roll about its first axis relative to L.
    relative_to : Body or str
        The virtual body L that tracks ``reference``.
    reference : ReferenceTrajectory
    baumgarte : Baumgarte, optional
        Scalar gains of L's tracking.
    relative_baumgarte : Baumgarte, optional
        Scalar gains of the lock of B to L (α_r alone: the velocity-level terms of
        :class:`gmuk.RelativeConstraint`).
    name : str, optional
    """

    _forms = Forms(
        compiled="its rows are called back from the compiled loop",
        symbolic="gives acceleration rows only: gmuk.optimize transcribes holonomic, "
        "nonholonomic and inequality constraints",
    )

    def __init__(
        self,
        body: Body | str,
        relative_to: Body | str,
        reference: ReferenceTrajectory,
        *,
        baumgarte: Baumgarte | None = None,
        relative_baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__([relative_to, body], name=name)
        (baumgarte,) = self._keywords(baumgarte=baumgarte)
        if not isinstance(reference, ReferenceTrajectory):
            raise DefinitionError(
                f"reference must be a gmuk.ReferenceTrajectory; got {type(reference).__name__}"
            )
        self.reference = reference
        owner = type(self).__name__
        self._gains = _scalar_gains(baumgarte, owner, "baumgarte")
        self._relative_gains = _scalar_gains(relative_baumgarte, owner, "relative_baumgarte")
        self.baumgarte = baumgarte
        self.relative_baumgarte = relative_baumgarte

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """L's tracking errors (e_g, e_V) against the reference followed by the five locked
        components of B relative to L: ``log(g_L⁻¹ g_B)`` and ``V_{B/L}`` without their roll
        (first) component (:meth:`Constraint.violation`); translations weighed as in
        :meth:`gmuk.constraints.ConfigurationTracking.violation` (against max(1 m, ‖r_d‖)
        and max(1 m/s, ‖v_d‖))."""
        from gmuk.constraints.tracking import relative_errors

        L, Bd = self.bodies
        g_L, V_L, g_B, V_B = state.pose(L), state.twist(L), state.pose(Bd), state.twist(Bd)
        ref = self.reference.evaluate(state.t)
        e_g, e_V = relative_errors(g_L, V_L, ref.g, ref.V)
        h = se3._inverse(g_L) @ g_B
        V_rel = V_B - se3._Ad(se3._inverse(h)) @ V_L
        log_h = se3.log(h)
        log_h[3:] /= max(1.0, float(np.linalg.norm(ref.g[:3, 3])))
        V_rel[3:] /= max(1.0, float(np.linalg.norm(ref.V[3:])))
        return np.concatenate([e_g, log_h[1:]]), np.concatenate([e_V, V_rel[1:]])

    def tangent_rows(self, state: State) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(A (7, 8), B (8, 6), C (7, 6)) for [L, B]."""
        L, Bd = self.bodies
        g_L, V_L, g_B, V_B = state.pose(L), state.twist(L), state.pose(Bd), state.twist(Bd)
        ref = self.reference.evaluate(state.t)
        gdd_d = _tracking_target(g_L, V_L, ref, self._gains)
        h = se3._inverse(g_L) @ g_B
        V_rel = V_B - se3._Ad(se3._inverse(h)) @ V_L
        Vr = se3._hat(V_rel)
        gL_dot = g_L @ se3._hat(V_L)
        h_dot = h @ Vr
        lock = 2.0 * gL_dot @ h_dot + g_L @ h @ Vr @ Vr
        alpha, beta = self._relative_gains
        if alpha or beta:
            lock = lock - g_B @ se3._hat(alpha * V_rel + beta * se3.log(h))
        Z = np.zeros((4, 4))
        A = np.block([[np.eye(4), Z], [-_X, _X]])
        B = np.block([[np.eye(4), h @ _Y], [Z, _Y]])
        C = np.block(
            [
                [gdd_d, gdd_d @ h @ _Y],
                [-_X @ gdd_d, _X @ lock @ _Y],
            ]
        )
        return A, B, C
