"""Configuration tracking ``g = g_d(t)`` of one rigid body (McCann 2020, Eqs. 65–67).

Differentiating ``g = g_d`` twice with ``ġ = g V^`` gives ``g (V^² + V̇^) = g_d (V_d^² + V̇_d^)``,
hence ``A = I₆`` and ``b = (g⁻¹ g_d (V_d^² + V̇_d^) − V^²)^∨`` (Eq. 67).

Off the constraint (g ≠ g_d, V ≠ Ad V_d) the matrix inside the vee is not in se(3) (docs/errata.rst,
"Numerically fragile"): gmuk takes the skew part of its rotation block and its translation
column before the vee. On the constraint both forms agree exactly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from gmuk import _uk_kernels
from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.errors import ConstraintError, DefinitionError
from gmuk.lie import se3
from gmuk.reference import ReferenceTrajectory

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = ["ConfigurationTracking", "project_to_se3", "tracking_errors"]

_EYE6 = np.eye(6)
_EYE6.setflags(write=False)
_F64 = np.dtype(np.float64)
_ndarray = np.ndarray
_empty = np.empty


def project_to_se3(X: FloatArray) -> FloatArray:
    """The se(3) part of a 4×4 matrix as a twist: skew part of the rotation block, and the
    translation column; the last row is dropped.

    Parameters
    ----------
    X : ndarray (..., 4, 4)
        E.g. a pose derivative ġ or g̈ (rotation block in 1/s or 1/s², translation column
        in m/s or m/s²; the result keeps those units).

    Returns
    -------
    ndarray (..., 6)
        ``[vee(skew(X[:3, :3])); X[:3, 3]]``.
    """
    W = X[..., :3, :3]
    Ws = 0.5 * (W - np.swapaxes(W, -1, -2))
    return np.concatenate(
        [np.stack([Ws[..., 2, 1], Ws[..., 0, 2], Ws[..., 1, 0]], axis=-1), X[..., :3, 3]], axis=-1
    )


def tracking_errors(
    g: FloatArray, V: FloatArray, g_d: FloatArray, V_d: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Configuration and velocity errors of a pose against a reference.

    Parameters
    ----------
    g, g_d : ndarray (4, 4)
        The pose g_NB and the reference pose (translation in m, in N).
    V, V_d : ndarray (6,)
        Their body twists [ω; v] (rad/s, m/s), each in its own body frame.

    Returns
    -------
    e_g : ndarray (6,)
        ``log(g_d⁻¹ g)`` = [attitude error (rad); position error in the body frame (m)].
    e_V : ndarray (6,)
        ``V − Ad_{g⁻¹ g_d} V_d``: the body twist of g_d⁻¹g (rad/s, m/s).
    """
    g_err = se3._inverse(g_d) @ g
    return se3._log(g_err), V - se3._Ad(se3._inverse(g_err)) @ V_d


class ConfigurationTracking(Constraint):
    """Fully constrain a rigid body to a reference motion: ``g = g_d(t)``.

    Parameters
    ----------
    body : Body or str
        A rigid body.
    reference : ReferenceTrajectory
        Gives (g_d, V_d, V̇_d) at each time.
    baumgarte : Baumgarte, optional
        Adds ``−α e_V − β e_g`` to b (errors from :func:`tracking_errors`), so that the
        linearised error obeys ``ë + αė + βe = 0`` (McCann 2020, Eq. 4) when the reference
        turns slowly against the gains (``‖ω_d‖ ≪ α, √β``): the terms act in the body frame
        while Eq. 67 prescribes g̈, and a reference turning at a rate near √β (an orbit-rate
        design on the LVLH orbit) couples the axes; see docs/scenarios/chapter5.rst.
    name : str, optional

    References
    ----------
    McCann (2020), Eqs. (65)–(67); the errata page (docs/errata.rst) for the
    projection off the constraint.
    """

    body_kinds = frozenset({BodyKind.RIGID})

    def __init__(
        self,
        body: Body | str,
        reference: ReferenceTrajectory,
        *,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__([body], name=name)
        if not isinstance(reference, ReferenceTrajectory):
            raise DefinitionError(
                f"reference must be a gmuk.ReferenceTrajectory; got {type(reference).__name__}"
            )
        self.reference = reference
        self.baumgarte = baumgarte

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """A = I₆ and b of Eq. 67 (projected), plus Baumgarte terms."""
        (i,) = self._rigid_indices(state)
        g, V = state.g[i], state.V[i]
        ref = self.reference.evaluate(state.t)
        gd, Vd, Vd_dot = ref.g, ref.V, ref.V_dot
        # np.asarray costs more than this check when x needs no conversion; compare dtypes
        # with ==: arrays made by numba kernels carry their own float64 dtype object
        if type(gd) is not _ndarray or gd.dtype != _F64:
            gd = np.asarray(gd, dtype=np.float64)
        if type(Vd) is not _ndarray or Vd.dtype != _F64:
            Vd = np.asarray(Vd, dtype=np.float64)
        if type(Vd_dot) is not _ndarray or Vd_dot.dtype != _F64:
            Vd_dot = np.asarray(Vd_dot, dtype=np.float64)
        if gd.shape != (4, 4) or Vd.shape != (6,) or Vd_dot.shape != (6,):
            raise ConstraintError(
                f"constraint {self.name!r}: the reference returned g {gd.shape}, V {Vd.shape}, "
                f"V_dot {Vd_dot.shape}; expected (4, 4), (6,), (6,)"
            )
        b = _empty(6)  # filled by the kernel (cheaper than a kernel returning an array)
        _uk_kernels.tracking_b(g, V, gd, Vd, Vd_dot, b)
        if self.baumgarte is not None:
            e_g, e_V = tracking_errors(g, V, gd, Vd)  # the checked float64 arrays
            b = b - self.baumgarte.alpha * e_V - self.baumgarte.beta * e_g
        return _EYE6, b
