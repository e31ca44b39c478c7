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

from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray
from gmuk.bodies import BodyKind
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.errors import ConstraintError, DefinitionError
from gmuk.lie._kernels import _se3_Ad_into, _se3_inverse_into, _se3_log_into
from gmuk.orbits._kernels import lvlh_state_packed
from gmuk.reference import ReferenceTrajectory

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State


@njit(cache=True, inline="always")
def _hat4(x: np.ndarray, M: np.ndarray) -> None:
    M[0, 0] = M[1, 1] = M[2, 2] = 0.0
    M[0, 1], M[0, 2], M[1, 2] = -x[2], x[1], -x[0]
    M[1, 0], M[2, 0], M[2, 1] = x[2], -x[1], x[0]
    M[0, 3], M[1, 3], M[2, 3] = x[3], x[4], x[5]
    M[3, 0] = M[3, 1] = M[3, 2] = M[3, 3] = 0.0


@njit(cache=True, inline="always")
def _mul4(A: np.ndarray, B: np.ndarray, out: np.ndarray) -> None:
    for i in range(4):
        for j in range(4):
            out[i, j] = (
                A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j] + A[i, 3] * B[3, j]
            )


@njit(cache=True)
def tracking_b(
    g: np.ndarray,
    V: np.ndarray,
    gd: np.ndarray,
    Vd: np.ndarray,
    Vd_dot: np.ndarray,
    out: np.ndarray,
) -> None:
    """b of Eq. 67, projected: se(3) part of g⁻¹ g_d (V_d^² + V̇_d^) − V^² as a twist,
    written into ``out`` (6,).

    Explicit 4×4 loops: BLAS calls on such small matrices cost more than the arithmetic.
    """
    H = np.empty((4, 4))
    Hd = np.empty((4, 4))
    T1 = np.empty((4, 4))
    T2 = np.empty((4, 4))
    ginv = np.zeros((4, 4))
    for i in range(3):
        for j in range(3):
            ginv[i, j] = g[j, i]
        ginv[i, 3] = -(g[0, i] * g[0, 3] + g[1, i] * g[1, 3] + g[2, i] * g[2, 3])
    ginv[3, 3] = 1.0
    _hat4(Vd, Hd)
    _mul4(Hd, Hd, T1)  # V_d^²
    _hat4(Vd_dot, H)
    for i in range(4):
        for j in range(4):
            T1[i, j] += H[i, j]  # V_d^² + V̇_d^
    _mul4(ginv, gd, T2)  # g⁻¹ g_d
    _mul4(T2, T1, Hd)  # g⁻¹ g_d (V_d^² + V̇_d^)
    _hat4(V, H)
    _mul4(H, H, T1)  # V^²
    out[0] = 0.5 * ((Hd[2, 1] - T1[2, 1]) - (Hd[1, 2] - T1[1, 2]))
    out[1] = 0.5 * ((Hd[0, 2] - T1[0, 2]) - (Hd[2, 0] - T1[2, 0]))
    out[2] = 0.5 * ((Hd[1, 0] - T1[1, 0]) - (Hd[0, 1] - T1[0, 1]))
    out[3] = Hd[0, 3] - T1[0, 3]
    out[4] = Hd[1, 3] - T1[1, 3]
    out[5] = Hd[2, 3] - T1[2, 3]


__all__ = [
    "ConfigurationTracking",
    "lvlh_tracking_rows",
    "project_to_se3",
    "tracking_errors",
    "tracking_rows",
]

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
    e_g, e_V = np.empty(6), np.empty(6)
    # writable copies: a read-only array (a State's) would make numba compile the kernel once
    # more, for that type, beside the writable one the compiled loop uses
    _errors(
        np.array(g, dtype=np.float64),
        np.array(V, dtype=np.float64),
        np.array(g_d, dtype=np.float64),
        np.array(V_d, dtype=np.float64),
        e_g,
        e_V,
    )
    return e_g, e_V


def relative_errors(
    g: FloatArray, V: FloatArray, g_d: FloatArray, V_d: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """:func:`tracking_errors` with the translational parts divided by max(1 m, ‖r_d‖) and
    max(1 m/s, ‖v_d‖) (dimensionless there; rotations in rad and rad/s)."""
    e_g, e_V = tracking_errors(g, V, g_d, V_d)
    e_g[3:] /= max(1.0, float(np.linalg.norm(np.asarray(g_d, dtype=float)[:3, 3])))
    e_V[3:] /= max(1.0, float(np.linalg.norm(np.asarray(V_d, dtype=float)[3:])))
    return e_g, e_V


@njit(cache=True)
def _errors(g, V, gd, Vd, e_g, e_V):  # type: ignore[no-untyped-def]
    """:func:`tracking_errors` into ``e_g`` and ``e_V`` (6,): e_g = log(g_d⁻¹ g),
    e_V = V − Ad_{(g_d⁻¹ g)⁻¹} V_d."""
    gd1 = np.empty((1, 4, 4))
    for a in range(4):
        for e in range(4):
            gd1[0, a, e] = gd[a, e]
    gd_inv = np.zeros((1, 4, 4))
    _se3_inverse_into(gd1, gd_inv)
    g_err = np.zeros((1, 4, 4))
    for a in range(4):
        for e in range(4):
            q = 0.0
            for m in range(4):
                q += gd_inv[0, a, m] * g[m, e]
            g_err[0, a, e] = q
    log = np.empty((1, 6))
    _se3_log_into(g_err, log)
    g_err_inv = np.zeros((1, 4, 4))
    _se3_inverse_into(g_err, g_err_inv)
    Ad = np.zeros((1, 6, 6))
    _se3_Ad_into(g_err_inv, Ad)
    for a in range(6):
        q = 0.0
        for e in range(6):
            q += Ad[0, a, e] * Vd[e]
        e_V[a] = V[a] - q
        e_g[a] = log[0, a]


@njit(cache=True)
def tracking_rows(g, V, gd, Vd, Vd_dot, baumgarte, alpha, beta, b):  # type: ignore[no-untyped-def]
    """b (6,) of configuration tracking (A = I₆): Eq. 67 projected onto se(3), minus
    ``α e_V + β e_g`` row by row when ``baumgarte`` (gains α, β (6,); errors of
    :func:`tracking_errors`). The one definition of :meth:`ConfigurationTracking.rows`."""
    tracking_b(g, V, gd, Vd, Vd_dot, b)
    if baumgarte:
        e_g = np.empty(6)
        e_V = np.empty(6)
        _errors(g, V, gd, Vd, e_g, e_V)
        for a in range(6):
            b[a] = b[a] - alpha[a] * e_V[a] - beta[a] * e_g[a]


@njit(cache=True)
def lvlh_tracking_rows(t, g, V, g2, V2, p, A, b):  # type: ignore[no-untyped-def]
    """The compiled rows of configuration tracking of an LVLH reference at time t: A (6, 12)
    = [I₆ 0], b (6,). Parameters p: the orbit's n, e, μ, p, R_NP (9, row-major), the Baumgarte
    flag, α (6), β (6). (g2, V2: no second body.) Returns 0."""
    gd = np.empty((4, 4))
    Vd = np.empty(6)
    Vd_dot = np.empty(6)
    lvlh_state_packed(t, p, gd, Vd, Vd_dot)
    tracking_rows(g, V, gd, Vd, Vd_dot, p[13] != 0.0, p[14:20], p[20:26], b)
    for r in range(6):
        for c in range(12):
            A[r, c] = 1.0 if r == c else 0.0
    return 0


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
    _forms = Forms(
        compiled=True,
        symbolic="gmuk.optimize transcribes tracking through the reference's own states",
    )
    _kernel = staticmethod(lvlh_tracking_rows)

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
        self.baumgarte = baumgarte
        self._gains = np.zeros((2, 6))
        if baumgarte is not None:
            try:
                self._gains[0] = np.broadcast_to(np.asarray(baumgarte.alpha, dtype=float), (6,))
                self._gains[1] = np.broadcast_to(np.asarray(baumgarte.beta, dtype=float), (6,))
            except ValueError:
                raise DefinitionError(
                    "the Baumgarte gains of a ConfigurationTracking must be scalars or 6-vectors "
                    f"(one per row); got alpha {np.shape(baumgarte.alpha)}, beta "
                    f"{np.shape(baumgarte.beta)}"
                ) from None

    def _kernel_params(self) -> tuple[list[float], int] | None:
        """The LVLH reference's orbit and frame, and the Baumgarte gains; None for another
        reference (its rows come from Python)."""
        orbit = getattr(self.reference, "_compiled_orbit", lambda: None)()
        if orbit is None:
            return None
        flag = 0.0 if self.baumgarte is None else 1.0
        return [*orbit, flag, *self._gains[0], *self._gains[1]], 6

    def violation(self, state: State) -> tuple[FloatArray | None, FloatArray | None]:
        """(e_g, e_V) of :func:`tracking_errors` at ``state`` (:meth:`Constraint.violation`),
        weighed as the integrator weighs the state: [attitude error (rad); position error
        / max(1 m, ‖r_d‖)] and [ω error (rad/s); v error / max(1 m/s, ‖v_d‖)]. A position
        error of 1e-5 m on an orbit of 3e6 m radius is integration error at rtol 1e-12, not
        drift; an attitude error keeps its radians."""
        (i,) = self._rigid_indices(state)
        ref = self.reference.evaluate(state.t)
        return relative_errors(state.g[i], state.V[i], ref.g, ref.V)

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """A = I₆ and b of Eq. 67 (projected), plus Baumgarte terms."""
        (i,) = self._rigid_indices(state)
        g, V = state.g[i].copy(), state.V[i].copy()  # writable, as below: a State's are not
        ref = self.reference.evaluate(state.t)
        gd, Vd, Vd_dot = ref.g, ref.V, ref.V_dot
        # The kernel takes writable float64 arrays, as the compiled loop passes them (one
        # compiled signature: a read-only reference array would make numba compile another).
        # np.array costs more than this check when x needs no conversion; compare dtypes with
        # ==: arrays made by numba kernels carry their own float64 dtype object.
        if type(gd) is not _ndarray or gd.dtype != _F64 or not gd.flags.writeable:
            gd = np.array(gd, dtype=np.float64)
        if type(Vd) is not _ndarray or Vd.dtype != _F64 or not Vd.flags.writeable:
            Vd = np.array(Vd, dtype=np.float64)
        if type(Vd_dot) is not _ndarray or Vd_dot.dtype != _F64 or not Vd_dot.flags.writeable:
            Vd_dot = np.array(Vd_dot, dtype=np.float64)
        if gd.shape != (4, 4) or Vd.shape != (6,) or Vd_dot.shape != (6,):
            raise ConstraintError(
                f"constraint {self.name!r}: the reference returned g {gd.shape}, V {Vd.shape}, "
                f"V_dot {Vd_dot.shape}; expected (4, 4), (6,), (6,)"
            )
        b = _empty(6)  # filled by the kernel (cheaper than a kernel returning an array)
        gains = self._gains.copy()  # writable: frozen in a System, the attribute is not
        tracking_rows(g, V, gd, Vd, Vd_dot, self.baumgarte is not None, gains[0], gains[1], b)
        return _EYE6, b
