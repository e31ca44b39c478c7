"""Constraints on the double tangent bundle T²SE(3): ``A g̈ B = C`` (McCann 2020, Eq. 79).

For n rigid bodies, ``g̈ = blkdiag(g̈₁, …, g̈ₙ)`` (4n × 4n), ``A`` is (m, 4n), ``B`` (4n, p) and
``C`` (m, p). The System solves Eq. 80 for ``g̈_c`` and recovers the body accelerations
``V̇_c,i = (g_i⁻¹ g̈_c,ii)^∨``. ERRATA: for general A, B the g̈_c of Eq. 80 need not lie in
g·se(3) (no control input produces it); gmuk projects each diagonal block onto se(3) (skew
rotation part, translation column) and reports the size of what it discarded.
"""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.constraints.base import Constraint
from gmuk.errors import DefinitionError
from gmuk.lie import se3
from gmuk.reference import ReferenceTrajectory

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["ConfigurationTrackingT2", "TangentBundleConstraint"]


class TangentBundleConstraint(Constraint):
    """A constraint ``A g̈ B = C`` on the rigid bodies ``self.bodies`` (Eq. 79).

    Subclasses implement :meth:`tangent_rows`. A System whose constraints are tangent-bundle
    constraints is solved with Eq. 80 instead of Eq. 64; it takes exactly one such
    constraint (Eq. 79 does not stack: write one A, B, C over all the bodies).
    """

    @abc.abstractmethod
    def tangent_rows(self, state: State) -> tuple[Any, Any, Any]:
        """(A (m, 4k), B (4k, p), C (m, p)) at ``state`` for the k bodies of the constraint."""

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """Not defined: a tangent-bundle constraint has no R⁶ rows (use the T²SE(3) solve)."""
        raise DefinitionError(
            f"{self.name} is a T²SE(3) constraint: it has no R⁶ rows A ν̇ = b; put it in a "
            "System on its own (the System then solves McCann (2020) Eq. 80)"
        )


class ConfigurationTrackingT2(TangentBundleConstraint):
    """Full tracking ``g̈ = g̈_d`` on T²SE(3): A = B = I₄, C = g_d (V_d^² + V̇_d^).

    Equal (to round-off) to :class:`gmuk.constraints.ConfigurationTracking` on R⁶
    (McCann 2020, Section 4.2, FCEIM).

    Parameters
    ----------
    body : Body or str
        A rigid body.
    reference : ReferenceTrajectory
    name : str, optional
    """

    def __init__(
        self, body: Body | str, reference: ReferenceTrajectory, *, name: str | None = None
    ) -> None:
        super().__init__([body], name=name)
        if not isinstance(reference, ReferenceTrajectory):
            raise DefinitionError(
                f"reference must be a gmuk.ReferenceTrajectory; got {type(reference).__name__}"
            )
        self.reference = reference

    def tangent_rows(self, state: State) -> tuple[FloatArray, FloatArray, FloatArray]:
        """A = B = I₄ and C = g̈_d."""
        ref = self.reference.evaluate(state.t)
        Vd = se3._hat(ref.V)
        return np.eye(4), np.eye(4), ref.g @ (Vd @ Vd + se3._hat(ref.V_dot))
