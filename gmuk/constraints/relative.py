"""Constraints on the relative twist of one rigid body with respect to another.

For bodies L (reference) and B with ``g_B = g_L g_{B/L}``, the relative twist is
``V_{B/L} = V_B − Ad_{g_{B/L}⁻¹} V_L`` (McCann 2020, Eq. 73 and Section 4.1.3) and

``V̇_{B/L} = V̇_B − Ad_{g_{B/L}⁻¹} V̇_L + ad_{V_{B/L}} Ad_{g_{B/L}⁻¹} V_L``.

A :class:`RelativeConstraint` prescribes ``S V̇_{B/L} = S a_des(t)`` for a selection matrix S,
so that with columns ordered [V_L, V_B]:

``A = [−S Ad_{g_{B/L}⁻¹}, S]``, ``b = S (a_des − ad_{V_{B/L}} Ad_{g_{B/L}⁻¹} V_L)``,

which is the lower block of the two-body A, b at the end of Section 4.1.3 (the
virtual-spacecraft pair: S = [0₅ₓ₁ I₅] leaves B free about its first axis).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.errors import ConstraintError, DefinitionError
from gmuk.lie import se3

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State


@njit(cache=True)
def relative_rows(
    g_L: np.ndarray,
    V_L: np.ndarray,
    g_B: np.ndarray,
    V_B: np.ndarray,
    S: np.ndarray,
    a_des: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    Vr: np.ndarray,
) -> None:
    """Rows of a relative-twist constraint (McCann 2020, Eq. 73 and Section 4.1.3).

    With h = g_{B/L}⁻¹ = g_B⁻¹ g_L (R_h = R_Bᵀ R_L, p_h = R_Bᵀ (p_L − p_B)),
    Ad_h = [[R_h, 0], [p_h^ R_h, R_h]], W = Ad_h V_L and V_{B/L} = V_B − W:
    ``A = [−S Ad_h, S]`` and ``b = S (a_des − ad_{V_{B/L}} W)``, with
    ``ad_V W = [ω × ω_W; v × ω_W + ω × v_W]``. Writes A (s, 12), b (s,) and V_{B/L} (6,)
    into the arrays given.
    """
    Rh = np.empty((3, 3))
    d = np.empty(3)
    for k in range(3):
        d[k] = g_L[k, 3] - g_B[k, 3]
    ph = np.empty(3)
    for i in range(3):
        ph[i] = g_B[0, i] * d[0] + g_B[1, i] * d[1] + g_B[2, i] * d[2]
        for j in range(3):
            Rh[i, j] = g_B[0, i] * g_L[0, j] + g_B[1, i] * g_L[1, j] + g_B[2, i] * g_L[2, j]
    Ad = np.zeros((6, 6))
    for i in range(3):
        for j in range(3):
            Ad[i, j] = Rh[i, j]
            Ad[3 + i, 3 + j] = Rh[i, j]
    for j in range(3):  # p_h × (column j of R_h)
        c0, c1, c2 = Rh[0, j], Rh[1, j], Rh[2, j]
        Ad[3, j] = ph[1] * c2 - ph[2] * c1
        Ad[4, j] = ph[2] * c0 - ph[0] * c2
        Ad[5, j] = ph[0] * c1 - ph[1] * c0
    W = np.empty(6)
    for i in range(6):
        acc = 0.0
        for k in range(6):
            acc += Ad[i, k] * V_L[k]
        W[i] = acc
    for i in range(6):
        Vr[i] = V_B[i] - W[i]
    w0, w1, w2, v0, v1, v2 = Vr[0], Vr[1], Vr[2], Vr[3], Vr[4], Vr[5]
    x0, x1, x2, y0, y1, y2 = W[0], W[1], W[2], W[3], W[4], W[5]
    r = np.empty(6)
    r[0] = a_des[0] - (w1 * x2 - w2 * x1)
    r[1] = a_des[1] - (w2 * x0 - w0 * x2)
    r[2] = a_des[2] - (w0 * x1 - w1 * x0)
    r[3] = a_des[3] - (v1 * x2 - v2 * x1 + w1 * y2 - w2 * y1)
    r[4] = a_des[4] - (v2 * x0 - v0 * x2 + w2 * y0 - w0 * y2)
    r[5] = a_des[5] - (v0 * x1 - v1 * x0 + w0 * y1 - w1 * y0)
    s = S.shape[0]
    for i in range(s):
        acc_b = 0.0
        for j in range(6):
            acc = 0.0
            for k in range(6):
                acc += S[i, k] * Ad[k, j]
            A[i, j] = -acc
            A[i, 6 + j] = S[i, j]
            acc_b += S[i, j] * r[j]
        b[i] = acc_b


__all__ = ["RelativeConstraint", "relative_constraint_rows", "relative_loop_rows", "relative_twist"]

_ZERO6 = np.zeros(6)
_ZERO6.setflags(write=False)


@njit(cache=True)
def relative_constraint_rows(gL, VL, gB, VB, S, a_des, alpha, v_des, A, b):  # type: ignore[no-untyped-def]
    """The rows of a relative constraint into A (s, 12) (columns [V_L, V_B]) and b (s,):
    ``S V̇_{B/L} = S a_des`` (module docstring), minus ``α_i (S (V_{B/L} − v_des))_i`` on each
    row with a Baumgarte gain α_i ≠ 0. The one definition of :meth:`RelativeConstraint.rows`."""
    V_BL = np.empty(6)
    relative_rows(gL, VL, gB, VB, S, a_des, A, b, V_BL)
    for a in range(S.shape[0]):
        if alpha[a] != 0.0:
            q = 0.0
            for e in range(6):
                q += S[a, e] * (V_BL[e] - v_des[e])
            b[a] = b[a] - alpha[a] * q


@njit(cache=True)
def relative_loop_rows(t, gL, VL, gB, VB, p, A, b):  # type: ignore[no-untyped-def]
    """The compiled rows of a relative constraint with no desired relative motion: p holds
    the gains α (s) and S (s, 6) row by row. Returns 0."""
    s = b.shape[0]
    S = np.empty((s, 6))
    alpha = np.empty(s)
    for a in range(s):
        alpha[a] = p[a]
        for e in range(6):
            S[a, e] = p[s + 6 * a + e]
    zero = np.zeros(6)
    relative_constraint_rows(gL, VL, gB, VB, S, zero, alpha, zero, A, b)
    return 0


def relative_twist(
    g_L: FloatArray, V_L: FloatArray, g_B: FloatArray, V_B: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Relative pose and twist of B with respect to L.

    Parameters
    ----------
    g_L, g_B : ndarray (4, 4)
        Poses g_NL and g_NB of L and B in N (translation in m).
    V_L, V_B : ndarray (6,)
        Body twists [ω; v] of L (in L) and of B (in B) (rad/s, m/s).

    Returns
    -------
    g_BL : ndarray (4, 4)
        ``g_{B/L} = g_L⁻¹ g_B``.
    V_BL : ndarray (6,)
        ``V_{B/L} = V_B − Ad_{g_{B/L}⁻¹} V_L``, expressed in B.
    AdV_L : ndarray (6,)
        ``Ad_{g_{B/L}⁻¹} V_L``: L's twist expressed in B.
    """
    g_BL = se3._inverse(g_L) @ g_B
    Ad_inv = se3._Ad(se3._inverse(g_BL))
    AdV_L = Ad_inv @ V_L
    return g_BL, V_B - AdV_L, AdV_L


class RelativeConstraint(Constraint):
    """Prescribe selected components of the relative acceleration of B with respect to L.

    Parameters
    ----------
    body : Body or str
        The constrained rigid body B.
    relative_to : Body or str
        The reference rigid body L (columns of A: L first, then B).
    free_axes : sequence of int, optional
        Components of V_{B/L} = [ω; v] (0–5) left free; the others are constrained.
        ``free_axes=[0]`` is the virtual-spacecraft pair of McCann (2020), Section 4.1.3.
    S : array_like, shape (s, 6), optional
        Selection matrix, instead of ``free_axes``.
    acceleration : callable t ↦ (6,), optional
        Desired relative acceleration a_des(t) (rad/s², m/s²); zero by default.
    baumgarte : Baumgarte, optional
        ``alpha`` drives S V_{B/L} to S ∫a_des (zero by default) at rate α: velocity-level.
    name : str, optional
    """

    body_kinds = frozenset({BodyKind.RIGID})
    _forms = Forms(
        compiled=True,
        symbolic="gmuk.optimize transcribes no relative-acceleration constraint",
    )
    _kernel = staticmethod(relative_loop_rows)

    def __init__(
        self,
        body: Body | str,
        relative_to: Body | str,
        *,
        free_axes: Sequence[int] | None = None,
        S: Any = None,
        acceleration: Callable[[float], Any] | None = None,
        velocity: Callable[[float], Any] | None = None,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__([relative_to, body], name=name)
        (baumgarte,) = self._keywords(baumgarte=baumgarte)
        if (free_axes is None) == (S is None):
            raise ConstraintError("give exactly one of free_axes and S")
        if S is None:
            assert free_axes is not None
            bad = [a for a in free_axes if a not in range(6)]
            if bad or len(set(free_axes)) != len(free_axes):
                raise ConstraintError(
                    f"free_axes must be distinct integers in 0..5; got {free_axes}"
                )
            S = np.eye(6)[[i for i in range(6) if i not in free_axes]]
        S = np.asarray(S, dtype=float)
        if S.ndim != 2 or S.shape[1] != 6 or not np.isfinite(S).all():
            raise ConstraintError(f"S must be a finite (s, 6) matrix; got shape {S.shape}")
        self.S = S
        self.acceleration = acceleration
        self.velocity = velocity
        self.baumgarte = baumgarte
        self._alpha = np.zeros(S.shape[0])
        if baumgarte is not None:
            try:
                self._alpha[:] = np.broadcast_to(
                    np.asarray(baumgarte.alpha, dtype=float), (S.shape[0],)
                )
            except ValueError:
                raise DefinitionError(
                    "the Baumgarte gain alpha of a RelativeConstraint must be a scalar or one "
                    f"per row of S ({S.shape[0]}); got shape {np.shape(baumgarte.alpha)}"
                ) from None

    def _kernel_params(self) -> tuple[list[float], int] | None:
        """The gains and S, when no relative motion is prescribed (a_des = 0, and no
        v_des under Baumgarte terms); None otherwise (the rows come from Python)."""
        if self.acceleration is not None or (
            self.baumgarte is not None and self.velocity is not None
        ):
            return None
        return [*self._alpha, *self.S.ravel()], self.S.shape[0]

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """(None, S (V_{B/L} − v_des)) (:meth:`Constraint.violation`), v_des = ``velocity(t)``
        if given, else zero; (None, None) when an ``acceleration`` is prescribed without its
        ``velocity`` (the relative twist it leads to is not known). The relative pose is not
        constrained: only its accelerations are."""
        if self.acceleration is not None and self.velocity is None:
            return None, None
        iL, iB = self._rigid_indices(state)
        _, V_BL, _ = relative_twist(state.g[iL], state.V[iL], state.g[iB], state.V[iB])
        if self.velocity is not None:
            v_des = np.asarray(self.velocity(state.t), dtype=np.float64)
            if v_des.shape != (6,):
                raise ConstraintError(
                    f"constraint {self.name!r}: velocity(t) returned shape {v_des.shape}; "
                    "expected (6,)"
                )
            V_BL = V_BL - v_des
        return None, self.S @ V_BL

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A, b) with columns [V_L, V_B]."""
        iL, iB = self._rigid_indices(state)
        if self.acceleration is None:
            a_des = _ZERO6
        else:
            a_des = np.asarray(self.acceleration(state.t), dtype=np.float64)
            if a_des.shape != (6,):
                raise ConstraintError(
                    f"constraint {self.name!r}: acceleration(t) returned shape {a_des.shape}; "
                    "expected (6,)"
                )
        v_des = _ZERO6
        if self.baumgarte is not None and self.velocity is not None:
            v_des = np.asarray(self.velocity(state.t), dtype=np.float64)
            if v_des.shape != (6,):
                raise ConstraintError(
                    f"constraint {self.name!r}: velocity(t) returned shape {v_des.shape}; "
                    "expected (6,)"
                )
        s = self.S.shape[0]  # outputs allocated here: cheaper than arrays returned by numba
        A, b = np.empty((s, 12)), np.empty(s)
        relative_constraint_rows(
            state.g[iL], state.V[iL], state.g[iB], state.V[iB],
            self.S, a_des, self._alpha, v_des, A, b,
        )  # fmt: skip
        return A, b
