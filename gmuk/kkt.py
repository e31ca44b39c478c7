"""Karush–Kuhn–Tucker diagnostics of inequality constraints along a trajectory.

McCann (2020) Table 6.1 states the KKT conditions of ``min J(x)`` subject to ``d(x) = 0``
and ``g(x) ≤ 0``. For an :class:`~gmuk.constraints.InequalityConstraint` each bound is one
``g ≤ 0`` (``h − u`` for an upper bound, ``l − h`` for a lower one) and its multiplier is
read from the Udwadia–Kalaba solve: the row of ``h − bound + σw² = 0`` has multiplier λ
(constraint force ``A_hᵀλ`` on the bodies, Eq. 3), and the force ``−μ∇g`` of the KKT form
gives ``μ = −σλ``. Along a :class:`gmuk.Trajectory` :func:`kkt_diagnostics` reports, per
bound and output time:

primal feasibility
    ``g ≤ 0``; ``primal_violation = max(g, 0)`` in the unit of h.
dual feasibility
    ``μ ≥ 0``; ``dual_violation = max(−μ, 0)``.
complementary slackness
    ``μ g = 0``; ``complementarity = μ g``.

and, for the whole System, the stationarity of the one optimisation problem defined at an
instant, Gauss's principle ``min ½(ν̇ − ν̇_a)ᵀM(ν̇ − ν̇_a)`` subject to ``A ν̇ = b``:
``M ν̇_c − Aᵀλ = 0`` (``stationarity``, relative to ‖Aᵀλ‖). The slack formulation makes the
equalities hold by construction; whether μ ≥ 0 and μg = 0 hold is what tells an optimal
motion from a feasible one (the thesis finds them violated in transients, §6.5.1).

Units: μ is a generalized force per unit of h. At the position level ``μ δh`` is virtual
work, so μ is in J per unit of h (N for a bound in metres); at the velocity level A_h is
∂h/∂ν and μ is in ``J/(unit·s)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.constraints.inequality import InequalityConstraint
from gmuk.errors import DefinitionError

if TYPE_CHECKING:
    from gmuk.engine.system import System
    from gmuk.trajectory import Trajectory

__all__ = ["BoundConditions", "InequalityKKT", "KKTDiagnostics", "kkt_diagnostics"]


class BoundConditions:
    """The KKT conditions of one bound, from its KKT form ``g ≤ 0`` and multiplier ``μ``
    (attributes ``g`` and ``mu`` of the class it is mixed into): shared by the simulated
    (:class:`InequalityKKT`) and the optimised (:class:`gmuk.optimize.BoundKKT`) bounds."""

    g: FloatArray
    mu: FloatArray

    @property
    def primal_violation(self) -> FloatArray:
        """max(g, 0): by how much the bound is exceeded (unit of h)."""
        return np.maximum(self.g, 0.0)

    @property
    def dual_violation(self) -> FloatArray:
        """max(−μ, 0): how far the multiplier is on the wrong side of zero."""
        return np.maximum(-self.mu, 0.0)

    @property
    def complementarity(self) -> FloatArray:
        """μ g (unit of μ times unit of h): zero at a KKT point."""
        return self.mu * self.g

    def summary(self) -> dict[str, float]:
        """Maxima over the outputs: primal violation (unit of h), dual violation (unit of μ),
        and the largest abs(μ g) (JSON-serialisable)."""
        return {
            "primal_violation_max": float(self.primal_violation.max(initial=0.0)),
            "dual_violation_max": float(self.dual_violation.max(initial=0.0)),
            "complementarity_abs_max": float(np.abs(self.complementarity).max(initial=0.0)),
        }


@dataclass(frozen=True, eq=False)
class InequalityKKT(BoundConditions):
    """KKT quantities of one bound along a trajectory (arrays of shape (N,)).

    Attributes
    ----------
    name : str
        The bound's slack coordinate, ``"<constraint>.upper"`` or ``"<constraint>.lower"``.
    constraint, side : str
    bound : float
        u or l (unit of h).
    t : ndarray (N,)
        Output times (s).
    h : ndarray (N,)
        The constrained function (``unit``).
    g : ndarray (N,)
        The KKT form ``g ≤ 0``: ``h − u`` or ``l − h`` (``unit``).
    mu : ndarray (N,)
        The KKT multiplier μ = −σλ (``multiplier_unit``).
    slack, slack_rate : ndarray (N,)
        The slack or excess coordinate w and its rate.
    unit, multiplier_unit : str
    """

    name: str
    constraint: str
    side: str
    bound: float
    t: FloatArray
    h: FloatArray
    g: FloatArray
    mu: FloatArray
    slack: FloatArray
    slack_rate: FloatArray
    unit: str
    multiplier_unit: str


@dataclass(frozen=True, eq=False)
class KKTDiagnostics:
    """KKT diagnostics of every inequality of a System along a trajectory.

    Attributes
    ----------
    t : ndarray (N,)
        Output times (s).
    inequalities : dict of str → InequalityKKT
        One entry per bound, keyed by its slack coordinate's name.
    stationarity : ndarray (N,)
        ``‖M ν̇_c − Aᵀλ‖ / ‖Aᵀλ‖`` (0 where there is no constraint force): the stationarity
        of Gauss's function at each instant.
    """

    t: FloatArray
    inequalities: dict[str, InequalityKKT]
    stationarity: FloatArray

    def __getitem__(self, name: str) -> InequalityKKT:
        try:
            return self.inequalities[name]
        except KeyError:
            raise DefinitionError(
                f"no bound named {name!r}; bounds are {sorted(self.inequalities)}"
            ) from None

    def summary(self) -> dict[str, Any]:
        """Per bound maxima and the largest stationarity residual."""
        return {
            "bounds": {k: v.summary() for k, v in self.inequalities.items()},
            "stationarity_max": float(self.stationarity.max(initial=0.0)),
        }


def _row_offsets(system: System, trajectory: Trajectory) -> list[int]:
    """The first multiplier row of each constraint (rows counted at the first output)."""
    state = trajectory.state(0)
    offsets, r = [], 0
    for c in system.constraints:
        offsets.append(r)
        r += int(np.asarray(c.rows(state)[1]).reshape(-1).size)
    if r != trajectory.multipliers.shape[1]:
        raise DefinitionError(
            f"the trajectory has {trajectory.multipliers.shape[1]} multipliers per output; "
            f"the System's constraints give {r} rows: is it the System that produced it?"
        )
    return offsets


def kkt_diagnostics(system: System, trajectory: Trajectory) -> KKTDiagnostics:
    """KKT diagnostics (Table 6.1 of McCann 2020) of ``system``'s inequalities along
    ``trajectory``.

    Parameters
    ----------
    system : System
        The System that produced the trajectory.
    trajectory : Trajectory

    Returns
    -------
    KKTDiagnostics

    Raises
    ------
    DefinitionError
        If the trajectory does not belong to the System (bodies or rows differ) or is empty.
    """
    if tuple(trajectory.body_names) != tuple(system.layout.names):
        raise DefinitionError(
            f"the trajectory's bodies {list(trajectory.body_names)} are not the System's "
            f"{list(system.layout.names)}"
        )
    if len(trajectory) == 0:
        raise DefinitionError("the trajectory has no outputs")
    offsets = _row_offsets(system, trajectory)
    states = [trajectory.state(i) for i in range(len(trajectory))]
    lay = system.layout
    entries: dict[str, InequalityKKT] = {}
    for c, r0 in zip(system.constraints, offsets, strict=True):
        if not isinstance(c, InequalityConstraint):
            continue
        h = np.array([c.h(s) for s in states])
        per_time = "" if c.level == "position" else "·s"
        unit = c.unit or "unit of h"
        for k, bd in enumerate(c.bounds):
            idx = lay.slot(bd.coordinate).index
            lam = trajectory.multipliers[:, r0 + k]
            entries[bd.coordinate.name] = InequalityKKT(
                name=bd.coordinate.name,
                constraint=c.name,
                side=bd.side,
                bound=bd.value,
                t=trajectory.t,
                h=h,
                g=bd.g(h),
                mu=-bd.sign * lam,
                slack=trajectory.x[:, idx].copy(),
                slack_rate=trajectory.xdot[:, idx].copy(),
                unit=c.unit,
                multiplier_unit=f"J/({unit}{per_time})" if per_time or c.unit != "m" else "N",
            )
    stationarity = np.zeros(len(trajectory))
    for i, s in enumerate(states):
        A, _ = system.constraint_rows(s)
        force = A.T @ trajectory.multipliers[i]
        scale = float(np.linalg.norm(force))
        if scale > 0.0:
            residual = trajectory.constraint_force[i] - force
            stationarity[i] = float(np.linalg.norm(residual)) / scale
    return KKTDiagnostics(trajectory.t, entries, stationarity)
