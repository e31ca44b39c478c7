"""Joints: constraint kinds that tie a child body to a parent body (or to the ground).

A joint has two frames: ``J_p``, fixed in the parent at ``X_PJ`` (its pose in the parent's
body frame; in the inertial frame N for a joint to the ground), and ``J_c``, fixed in the
child at ``X_CJ``. At the joint's zero the two frames coincide; the joint lets the relative
pose ``h = g_{J_p}⁻¹ g_{J_c}`` move along its *motion subspace* S (6 × k, [ω; v] components in
J_c) and nowhere else. With the joint frames' twists ``V_{J_p} = Ad_{X_PJ⁻¹} V_P`` and
``V_{J_c} = Ad_{X_CJ⁻¹} V_C`` the relative twist is (McCann 2020, Eq. 73 and Section 4.1.3)

``V_rel = V_{J_c} − Ad_{h⁻¹} V_{J_p}``,

and a joint with a constant S holds ``T V̇_rel = 0`` for the rows T (6 − k, orthonormal) that
annihilate S: the rows of a :class:`~gmuk.RelativeConstraint` between the joint frames
(:func:`gmuk.constraints.relative.relative_rows`), mapped back to the bodies' twists by the
constant ``Ad_{X⁻¹}``. Baumgarte terms stabilise the rows with the velocity residual
``T V_rel`` and the position residual ``T log(h)``, which is zero exactly when the joint holds
(:func:`joint_residuals`). The universal joint, whose constrained rotation direction moves
with it, and the screw joint, whose log is not single-valued past half a turn, have their
own residuals (see their classes).

The joints' numbers are written once, in :func:`joint_rows` and :func:`joint_residuals`;
the Python ``rows`` and the compiled loop call the same kernel.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, as_array, check_se3, real_number
from gmuk.bodies import BodyKind
from gmuk.constraints.base import Baumgarte, Constraint
from gmuk.errors import DefinitionError
from gmuk.lie import se3
from gmuk.lie._kernels import _se3_exp, _se3_log_into

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State
    from gmuk.trajectory import Trajectory

__all__ = [
    "CylindricalJoint",
    "FixedJoint",
    "Joint",
    "PlanarJoint",
    "PrismaticJoint",
    "RevoluteJoint",
    "ScrewJoint",
    "SphericalJoint",
    "UniversalJoint",
    "joint_residuals",
    "joint_rows",
    "unwrap_with_rates",
]

# kinds of residual (the parameters' second entry)
_CONSTANT, _UNIVERSAL, _SCREW = 0, 1, 2
# layout of the packed parameters: [grounded, kind, s, X_PJ (16), X_CJ (16),
# Ad_{X_PJ⁻¹} (36), Ad_{X_CJ⁻¹} (36), T (s × 6), α (s), β (s), extra (6), G (s × 6)]:
# G = T Ad_{X_CJ⁻¹}, the rows on the child, constant but for a universal joint's last row
_HEAD = 3 + 16 + 16 + 36 + 36


@njit(cache=True, inline="always")
def _frame_row(g, i, p, o):  # type: ignore[no-untyped-def]
    """Row i of g X, the rotation's three entries then the translation's (4-tuple), for the
    rigid transform g (4, 4) and X (4, 4) stored row by row at ``p[o : o + 16]``."""
    a0, a1, a2 = g[i, 0], g[i, 1], g[i, 2]
    return (
        a0 * p[o] + a1 * p[o + 4] + a2 * p[o + 8],
        a0 * p[o + 1] + a1 * p[o + 5] + a2 * p[o + 9],
        a0 * p[o + 2] + a1 * p[o + 6] + a2 * p[o + 10],
        a0 * p[o + 3] + a1 * p[o + 7] + a2 * p[o + 11] + g[i, 3],
    )


@njit(cache=True, inline="always")
def _stored_row(p, i, o):  # type: ignore[no-untyped-def]
    """Row i of the (4, 4) matrix stored row by row at ``p[o : o + 16]`` (4-tuple)."""
    return p[o + 4 * i], p[o + 4 * i + 1], p[o + 4 * i + 2], p[o + 4 * i + 3]


@njit(cache=True, inline="always")
def _dot6(p, o, V):  # type: ignore[no-untyped-def]
    """``p[o : o + 6] · V``."""
    return (
        p[o] * V[0] + p[o + 1] * V[1] + p[o + 2] * V[2]
        + p[o + 3] * V[3] + p[o + 4] * V[4] + p[o + 5] * V[5]
    )  # fmt: skip


@njit(cache=True, inline="always")
def _apply(p, o, V):  # type: ignore[no-untyped-def]
    """Ad V (6-tuple) for Ad (6, 6) stored row by row at ``p[o : o + 36]``."""
    return (
        _dot6(p, o, V), _dot6(p, o + 6, V), _dot6(p, o + 12, V),
        _dot6(p, o + 18, V), _dot6(p, o + 24, V), _dot6(p, o + 30, V),
    )  # fmt: skip


@njit(cache=True, inline="always")
def _h_row(P0, P1, P2, C0, C1, C2, i):  # type: ignore[no-untyped-def]
    """Row i of h = g_Jp⁻¹ g_Jc (4-tuple) from the rows of g_Jp (P) and g_Jc (C)."""
    return (
        P0[i] * C0[0] + P1[i] * C1[0] + P2[i] * C2[0],
        P0[i] * C0[1] + P1[i] * C1[1] + P2[i] * C2[1],
        P0[i] * C0[2] + P1[i] * C1[2] + P2[i] * C2[2],
        P0[i] * (C0[3] - P0[3]) + P1[i] * (C1[3] - P1[3]) + P2[i] * (C2[3] - P2[3]),
    )


@njit(cache=True, inline="always")
def _column_dot(x, p, o, j):  # type: ignore[no-untyped-def]
    """``x · M[:, j]`` for a 6-tuple x and M (6, 6) stored row by row at ``p[o : o + 36]``."""
    return (
        x[0] * p[o + j] + x[1] * p[o + 6 + j] + x[2] * p[o + 12 + j]
        + x[3] * p[o + 18 + j] + x[4] * p[o + 24 + j] + x[5] * p[o + 30 + j]
    )  # fmt: skip


@njit(cache=True, inline="always")
def _joint_pose(g1, g2, p):  # type: ignore[no-untyped-def]
    """The relative pose h = g_Jp⁻¹ g_Jc: its three rows (4-tuples)."""
    if p[0] != 0.0:  # to the ground: J_p is fixed in N
        P0, P1, P2 = _stored_row(p, 0, 3), _stored_row(p, 1, 3), _stored_row(p, 2, 3)
        C0, C1, C2 = _frame_row(g1, 0, p, 19), _frame_row(g1, 1, p, 19), _frame_row(g1, 2, p, 19)
    else:
        P0, P1, P2 = _frame_row(g1, 0, p, 3), _frame_row(g1, 1, p, 3), _frame_row(g1, 2, p, 3)
        C0, C1, C2 = _frame_row(g2, 0, p, 19), _frame_row(g2, 1, p, 19), _frame_row(g2, 2, p, 19)
    return (
        _h_row(P0, P1, P2, C0, C1, C2, 0),
        _h_row(P0, P1, P2, C0, C1, C2, 1),
        _h_row(P0, P1, P2, C0, C1, C2, 2),
    )


@njit(cache=True, inline="always")
def _joint_state(g1, V1, g2, V2, p):  # type: ignore[no-untyped-def]
    """X = Ad_{g_C⁻¹ g_P} as R = R_Cᵀ R_P (9-tuple, row by row) and r = R_Cᵀ (p_P − p_C)
    (3-tuple; g_P = I for a joint to the ground), the twists W = Ad_{X_CJ⁻¹} X V_P (J_p's
    twist in J_c, = Ad_{h⁻¹} V_Jp) and V_rel = Ad_{X_CJ⁻¹} V_C − W (6-tuples), and
    a₁ = R_hᵀ a₁ᵖ = R_{X_CJ}ᵀ R R_{X_PJ} a₁ᵖ (a universal joint's first axis in J_c; zero for
    another kind), with no array built. Through X the rows on the parent are −G X, with G the
    constant rows on the child (h⁻¹ X_PJ⁻¹ = X_CJ⁻¹ g_C⁻¹ g_P)."""
    grounded = p[0] != 0.0
    gc = g1 if grounded else g2
    Vc = V1 if grounded else V2
    if grounded:  # g_P = I: R = R_Cᵀ, r = −R_Cᵀ p_C, and the parent does not move
        R = (gc[0, 0], gc[1, 0], gc[2, 0], gc[0, 1], gc[1, 1], gc[2, 1],
             gc[0, 2], gc[1, 2], gc[2, 2])  # fmt: skip
        d0, d1, d2 = -gc[0, 3], -gc[1, 3], -gc[2, 3]
    else:
        R = (
            gc[0, 0] * g1[0, 0] + gc[1, 0] * g1[1, 0] + gc[2, 0] * g1[2, 0],
            gc[0, 0] * g1[0, 1] + gc[1, 0] * g1[1, 1] + gc[2, 0] * g1[2, 1],
            gc[0, 0] * g1[0, 2] + gc[1, 0] * g1[1, 2] + gc[2, 0] * g1[2, 2],
            gc[0, 1] * g1[0, 0] + gc[1, 1] * g1[1, 0] + gc[2, 1] * g1[2, 0],
            gc[0, 1] * g1[0, 1] + gc[1, 1] * g1[1, 1] + gc[2, 1] * g1[2, 1],
            gc[0, 1] * g1[0, 2] + gc[1, 1] * g1[1, 2] + gc[2, 1] * g1[2, 2],
            gc[0, 2] * g1[0, 0] + gc[1, 2] * g1[1, 0] + gc[2, 2] * g1[2, 0],
            gc[0, 2] * g1[0, 1] + gc[1, 2] * g1[1, 1] + gc[2, 2] * g1[2, 1],
            gc[0, 2] * g1[0, 2] + gc[1, 2] * g1[1, 2] + gc[2, 2] * g1[2, 2],
        )
        d0, d1, d2 = g1[0, 3] - gc[0, 3], g1[1, 3] - gc[1, 3], g1[2, 3] - gc[2, 3]
    r = (
        gc[0, 0] * d0 + gc[1, 0] * d1 + gc[2, 0] * d2,
        gc[0, 1] * d0 + gc[1, 1] * d1 + gc[2, 1] * d2,
        gc[0, 2] * d0 + gc[1, 2] * d1 + gc[2, 2] * d2,
    )
    XV = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    if not grounded:  # X V_P = [R ω_P; R v_P + r × R ω_P]
        w0 = R[0] * V1[0] + R[1] * V1[1] + R[2] * V1[2]
        w1 = R[3] * V1[0] + R[4] * V1[1] + R[5] * V1[2]
        w2 = R[6] * V1[0] + R[7] * V1[1] + R[8] * V1[2]
        XV = (
            w0, w1, w2,
            R[0] * V1[3] + R[1] * V1[4] + R[2] * V1[5] + (r[1] * w2 - r[2] * w1),
            R[3] * V1[3] + R[4] * V1[4] + R[5] * V1[5] + (r[2] * w0 - r[0] * w2),
            R[6] * V1[3] + R[7] * V1[4] + R[8] * V1[5] + (r[0] * w1 - r[1] * w0),
        )  # fmt: skip
    W = _apply(p, 71, XV)
    VJc = _apply(p, 71, Vc)
    Vr = (VJc[0] - W[0], VJc[1] - W[1], VJc[2] - W[2], VJc[3] - W[3], VJc[4] - W[4], VJc[5] - W[5])
    a1 = (0.0, 0.0, 0.0)
    if p[1] == _UNIVERSAL:
        e = _HEAD + 8 * int(p[2])
        u0 = p[3] * p[e] + p[4] * p[e + 1] + p[5] * p[e + 2]  # R_{X_PJ} a₁ᵖ
        u1 = p[7] * p[e] + p[8] * p[e + 1] + p[9] * p[e + 2]
        u2 = p[11] * p[e] + p[12] * p[e + 1] + p[13] * p[e + 2]
        x0 = R[0] * u0 + R[1] * u1 + R[2] * u2
        x1 = R[3] * u0 + R[4] * u1 + R[5] * u2
        x2 = R[6] * u0 + R[7] * u1 + R[8] * u2
        a1 = (
            p[19] * x0 + p[23] * x1 + p[27] * x2,
            p[20] * x0 + p[24] * x1 + p[28] * x2,
            p[21] * x0 + p[25] * x1 + p[29] * x2,
        )
    return R, r, W, Vr, a1


@njit(cache=True, inline="always")
def _row_entry(p, s, a1, i, k):  # type: ignore[no-untyped-def]
    """T[i, k]: the stored rows, but for a universal joint's last row [n; 0], n = a₁ × a₂."""
    if p[1] == _UNIVERSAL and i == s - 1:
        if k >= 3:
            return 0.0
        e = _HEAD + 8 * s
        if k == 0:
            return a1[1] * p[e + 5] - a1[2] * p[e + 4]
        if k == 1:
            return a1[2] * p[e + 3] - a1[0] * p[e + 5]
        return a1[0] * p[e + 4] - a1[1] * p[e + 3]
    return p[_HEAD + 6 * i + k]


@njit(cache=True, inline="always")
def _row_dot(p, s, a1, i, x):  # type: ignore[no-untyped-def]
    """``T[i] · x`` for a 6-tuple x."""
    acc = 0.0
    for k in range(6):
        acc += _row_entry(p, s, a1, i, k) * x[k]
    return acc


@njit(cache=True)
def _log_residual(p, h0, h1, h2, scratch):  # type: ignore[no-untyped-def]
    """log(h) (6-tuple) from the rows of h, or for a screw joint log(h exp(−θ_d S)), unscrewed
    by the turn θ_d = a·p_h / pitch its slide implies. ``scratch`` (≥ 44 float64,
    C-contiguous) holds the arrays that the exponential and the log take."""
    hh = scratch[0:16].reshape((1, 4, 4))
    xi = scratch[16:22].reshape((1, 6))
    for j in range(4):
        hh[0, 0, j], hh[0, 1, j], hh[0, 2, j], hh[0, 3, j] = h0[j], h1[j], h2[j], 0.0
    hh[0, 3, 3] = 1.0
    if p[1] == _SCREW:
        e = _HEAD + 8 * int(p[2])
        pitch = p[e + 3]
        theta = (p[e] * h0[3] + p[e + 1] * h1[3] + p[e + 2] * h2[3]) / pitch
        back = scratch[22:28]
        u = scratch[28:44].reshape((4, 4))
        for k in range(3):
            back[k] = -theta * p[e + k]
            back[3 + k] = -theta * pitch * p[e + k]
        _se3_exp(back, u)
        for i in range(3):
            r = h0 if i == 0 else (h1 if i == 1 else h2)
            for j in range(4):
                hh[0, i, j] = r[0] * u[0, j] + r[1] * u[1, j] + r[2] * u[2, j]
            hh[0, i, 3] += r[3]
    _se3_log_into(hh, xi)
    return xi[0, 0], xi[0, 1], xi[0, 2], xi[0, 3], xi[0, 4], xi[0, 5]


@njit(cache=True, inline="always")
def _position_residual(p, s, a1, i, xi):  # type: ignore[no-untyped-def]
    """Φ_i: zero exactly when the joint holds, with Φ̇ = T V_rel to first order: ``T[i] · ξ``
    (ξ from :func:`_log_residual`), and for a universal joint's last row −a₁·a₂, whose rate
    is n·ω_rel."""
    if p[1] == _UNIVERSAL and i == s - 1:
        e = _HEAD + 8 * s
        return -(a1[0] * p[e + 3] + a1[1] * p[e + 4] + a1[2] * p[e + 5])
    return _row_dot(p, s, a1, i, xi)


@njit(cache=True)
def _child_rows(p):  # type: ignore[no-untyped-def]
    """G = T Ad_{X_CJ⁻¹} (s × 6), the rows on the child, into the end of the parameters p
    (the universal joint's last row, which moves, is left zero and computed at each call)."""
    s = int(p[2])
    G = _HEAD + 8 * s + 6
    for i in range(s):
        T = (
            p[_HEAD + 6 * i], p[_HEAD + 6 * i + 1], p[_HEAD + 6 * i + 2],
            p[_HEAD + 6 * i + 3], p[_HEAD + 6 * i + 4], p[_HEAD + 6 * i + 5],
        )  # fmt: skip
        if p[1] == _UNIVERSAL and i == s - 1:
            continue
        for j in range(6):
            p[G + 6 * i + j] = _column_dot(T, p, 71, j)


@njit(cache=True)
def joint_residuals(g1, V1, g2, V2, p, pos, vel):  # type: ignore[no-untyped-def]
    """A joint's position residual Φ (s,) and velocity residual T V_rel (s,), written into
    ``pos`` and ``vel`` (module docstring; p packed by :meth:`Joint._kernel_params`)."""
    s = int(p[2])
    _R, _r, _W, Vr, a1 = _joint_state(g1, V1, g2, V2, p)
    h0, h1, h2 = _joint_pose(g1, g2, p)
    xi = _log_residual(p, h0, h1, h2, np.empty(44))
    for i in range(s):
        pos[i] = _position_residual(p, s, a1, i, xi)
        vel[i] = _row_dot(p, s, a1, i, Vr)


@njit(cache=True)
def joint_rows(t, g1, V1, g2, V2, p, A, b):  # type: ignore[no-untyped-def]
    """The rows of a joint into A (s, 12) and b (s,): columns [V_P, V_C] (a joint to the
    ground: [V_C, 0]); ``T V̇_rel = −α T V_rel − β Φ`` (module docstring). Returns 0.

    The rows of a relative constraint between the joint frames (the math of
    :func:`gmuk.constraints.relative.relative_rows` with a_des = 0),
    ``[−T Ad_{h⁻¹}, T]`` and ``T r`` with ``r = −ad_{V_rel} W``, ``W = Ad_{h⁻¹} V_Jp``, mapped
    to the bodies' twists by ``Ad_{X_PJ⁻¹}`` and ``Ad_{X_CJ⁻¹}``: ``[−G X, G]`` with the
    constant G = T Ad_{X_CJ⁻¹} and X = Ad_{g_C⁻¹ g_P} (:func:`_joint_state`). Written entry
    by entry into A and b with no array allocated: A serves as scratch for the log of the
    position residual before its rows are written (12 s ≥ 36 entries; ≥ 44 for the screw
    joint's s = 5)."""
    s = int(p[2])
    R, rr, W, Vr, a1 = _joint_state(g1, V1, g2, V2, p)
    w0, w1, w2, v0, v1, v2 = Vr
    x0, x1, x2, y0, y1, y2 = W
    r = (
        -(w1 * x2 - w2 * x1),
        -(w2 * x0 - w0 * x2),
        -(w0 * x1 - w1 * x0),
        -(v1 * x2 - v2 * x1 + w1 * y2 - w2 * y1),
        -(v2 * x0 - v0 * x2 + w2 * y0 - w0 * y2),
        -(v0 * x1 - v1 * x0 + w0 * y1 - w1 * y0),
    )
    for i in range(s):
        b[i] = _row_dot(p, s, a1, i, r)
    if p[1] == _UNIVERSAL:  # d/dt (n·ω_rel) = n·ω̇_rel + ṅ·ω_rel, ṅ = (−ω_rel × a₁) × a₂
        e = _HEAD + 8 * s
        d0 = -(w1 * a1[2] - w2 * a1[1])
        d1 = -(w2 * a1[0] - w0 * a1[2])
        d2 = -(w0 * a1[1] - w1 * a1[0])
        q0, q1, q2 = p[e + 3], p[e + 4], p[e + 5]
        nd0 = d1 * q2 - d2 * q1
        nd1 = d2 * q0 - d0 * q2
        nd2 = d0 * q1 - d1 * q0
        b[s - 1] -= nd0 * w0 + nd1 * w1 + nd2 * w2
    ga = _HEAD + 6 * s  # the gains α (s), then β (s)
    stabilised = False
    for i in range(s):
        if p[ga + i] != 0.0 or p[ga + s + i] != 0.0:
            stabilised = True
    if stabilised:
        h0, h1, h2 = _joint_pose(g1, g2, p)
        xi = _log_residual(p, h0, h1, h2, A.reshape(A.size))
        for i in range(s):
            vel = _row_dot(p, s, a1, i, Vr)
            phi = _position_residual(p, s, a1, i, xi)
            b[i] -= p[ga + i] * vel + p[ga + s + i] * phi
    grounded = p[0] != 0.0
    child = 0 if grounded else 6
    G = _HEAD + 8 * s + 6  # the constant rows on the child, G = T Ad_{X_CJ⁻¹}
    for i in range(s):
        T = (
            _row_entry(p, s, a1, i, 0), _row_entry(p, s, a1, i, 1), _row_entry(p, s, a1, i, 2),
            _row_entry(p, s, a1, i, 3), _row_entry(p, s, a1, i, 4), _row_entry(p, s, a1, i, 5),
        )  # fmt: skip
        if p[1] == _UNIVERSAL and i == s - 1:
            for j in range(6):
                A[i, child + j] = _column_dot(T, p, 71, j)
        else:
            for j in range(6):
                A[i, child + j] = p[G + 6 * i + j]
        if grounded:
            for j in range(6):
                A[i, 6 + j] = 0.0
            continue
        # −G_i X = −[(G_ω + G_v × r)ᵀ R, G_vᵀ R] for the row G_i = [G_ω, G_v] on the child
        G0, G1, G2 = A[i, child], A[i, child + 1], A[i, child + 2]
        G3, G4, G5 = A[i, child + 3], A[i, child + 4], A[i, child + 5]
        z0 = G0 + (G4 * rr[2] - G5 * rr[1])
        z1 = G1 + (G5 * rr[0] - G3 * rr[2])
        z2 = G2 + (G3 * rr[1] - G4 * rr[0])
        for j in range(3):
            A[i, j] = -(z0 * R[j] + z1 * R[3 + j] + z2 * R[6 + j])
            A[i, 3 + j] = -(G3 * R[j] + G4 * R[3 + j] + G5 * R[6 + j])
    return 0


@njit(cache=True)
def _residuals_along(g1, V1, g2, V2, p, pos, vel):  # type: ignore[no-untyped-def]
    """:func:`joint_residuals` at N states: g1, g2 (N, 4, 4), V1, V2 (N, 6), into pos and
    vel (N, s)."""
    for n in range(g1.shape[0]):
        joint_residuals(g1[n], V1[n], g2[n], V2[n], p, pos[n], vel[n])


def unwrap_with_rates(q: FloatArray, qd: FloatArray, t: FloatArray) -> FloatArray:
    """Angles (N, k) in (−π, π] made continuous: output i takes the branch ``q_i + 2π n``
    nearest ``q_{i−1} + ½ (q̇_{i−1} + q̇_i)(t_i − t_{i−1})`` (the trapezoid rule on the rates,
    rad/s, at times t (N,), s). Unlike ``np.unwrap`` it follows a joint that turns more than
    π between outputs, as long as the trapezoid rule is within π of the true turn."""
    out = np.array(q, dtype=float, copy=True)
    for i in range(1, len(out)):
        predicted = out[i - 1] + 0.5 * (qd[i - 1] + qd[i]) * (t[i] - t[i - 1])
        out[i] = q[i] + 2.0 * np.pi * np.round((predicted - q[i]) / (2.0 * np.pi))
    return out


def _unit(axis: Any, name: str) -> FloatArray:
    a = as_array(axis, (3,), name, batch=False)
    norm = float(np.linalg.norm(a))
    if not norm > 0.0:
        raise DefinitionError(f"{name} must be a nonzero 3-vector; got {a.tolist()}")
    return a / norm


def _perpendiculars(a: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Two unit vectors (e₁, e₂) with (e₁, e₂, a) right-handed and orthonormal: e₁ is the
    coordinate axis least aligned with ``a``, made perpendicular to it (a = z gives x, y)."""
    helper = np.eye(3)[int(np.argmin(np.abs(a)))]
    e1 = helper - (helper @ a) * a
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1)


def _annihilator(S: FloatArray) -> FloatArray:
    """Orthonormal rows T (6 − k, 6) with T S = 0, for S (6, k) of rank k."""
    if S.shape[1] == 0:
        return np.eye(6)
    u, _, _ = np.linalg.svd(S, full_matrices=True)
    T = u[:, S.shape[1] :].T
    T[np.abs(T) < 1e-15] = 0.0
    return np.ascontiguousarray(T)


#: The forms of every joint kind: the compiled kernel :func:`joint_rows`.
_JOINT_FORMS = Forms(
    compiled=True,
    symbolic="gmuk.optimize transcribes no joint (its rows are acceleration-level)",
)


class Joint(Constraint):
    """A joint between a parent body (or the ground) and a child body.

    Subclasses give the motion subspace; see the module docstring for the frames and the
    rows. Columns of A: [V_P, V_C] (6 + 6), or [V_C] for a joint to the ground.

    Parameters
    ----------
    parent : Body, str or None
        The parent rigid body, or None for the ground (the inertial frame N).
    child : Body or str
        The child rigid body.
    parent_frame : array_like (4, 4), optional
        X_PJ: the pose of the joint frame J_p in the parent's body frame (in N for the
        ground); identity by default (m).
    child_frame : array_like (4, 4), optional
        X_CJ: the pose of the joint frame J_c in the child's body frame; identity by default.
    baumgarte : Baumgarte, optional
        Gains α (1/s) and β (1/s²) on the velocity and position residuals.
    name : str, optional

    Attributes
    ----------
    nq, nv : int
        Number of joint coordinates and rates (:meth:`coordinates`, :meth:`rates`).
    motion_subspace : ndarray (6, nv)
        S: the relative twist [ω; v] (in J_c) that a unit rate of each coordinate gives.
    """

    body_kinds = frozenset({BodyKind.RIGID})
    _forms = _JOINT_FORMS
    _kernel = staticmethod(joint_rows)
    _residual_kind: ClassVar[int] = _CONSTANT
    kind: ClassVar[str] = "joint"

    def __init__(
        self,
        parent: Body | str | None,
        child: Body | str,
        *,
        parent_frame: Any = None,
        child_frame: Any = None,
        baumgarte: Baumgarte | None = None,
        name: str | None = None,
    ) -> None:
        bodies = [child] if parent is None else [parent, child]
        super().__init__(bodies, name=name)
        (baumgarte,) = self._keywords(baumgarte=baumgarte)
        who = f"{type(self).__name__} {self.name!r}"
        X_PJ = np.eye(4) if parent_frame is None else check_se3(parent_frame, f"{who} parent_frame")
        X_CJ = np.eye(4) if child_frame is None else check_se3(child_frame, f"{who} child_frame")
        self.grounded = parent is None
        self.parent_frame = np.array(X_PJ, dtype=float)
        self.child_frame = np.array(X_CJ, dtype=float)
        self.baumgarte = baumgarte
        # Ad_{X_PJ⁻¹}, Ad_{X_CJ⁻¹}: the joint frames' twists from the bodies' (constant)
        self._AdP = se3._Ad(se3._inverse(self.parent_frame))
        self._AdC = se3._Ad(se3._inverse(self.child_frame))
        S = self._subspace()
        self.motion_subspace = S
        self.nv = S.shape[1]
        self.nq = self.nv
        self._T = self._constraint_rows(S)
        s = self._T.shape[0]
        self._alpha = self._gain(baumgarte.alpha if baumgarte else 0.0, s, "alpha")
        self._beta = self._gain(baumgarte.beta if baumgarte else 0.0, s, "beta")
        self._params = np.concatenate(
            [
                [float(self.grounded), float(self._residual_kind), float(s)],
                self.parent_frame.ravel(),
                self.child_frame.ravel(),
                self._AdP.ravel(),
                self._AdC.ravel(),
                self._T.ravel(),
                self._alpha,
                self._beta,
                self._extra(),
                np.zeros(6 * s),
            ]
        )
        _child_rows(self._params)
        self._S_pinv = np.linalg.pinv(S) if S.shape[1] else np.zeros((0, 6))

    # -- what a kind defines
    @abc.abstractmethod
    def _subspace(self) -> FloatArray:
        """S (6, k)."""

    def _constraint_rows(self, S: FloatArray) -> FloatArray:
        """T (s, 6), the constant rows (the universal joint's last row is set at each call)."""
        return _annihilator(S)

    def _extra(self) -> FloatArray:
        """Six numbers a kind's residual needs (axes, pitch)."""
        return np.zeros(6)

    def _gain(self, value: Any, s: int, label: str) -> FloatArray:
        try:
            return np.array(np.broadcast_to(np.asarray(value, dtype=float), (s,)))
        except ValueError:
            raise DefinitionError(
                f"the Baumgarte gain {label} of {type(self).__name__} {self.name!r} must be a "
                f"scalar or one per row ({s}); got shape {np.shape(value)}"
            ) from None

    # -- the constraint
    def _kernel_params(self) -> tuple[FloatArray, int]:
        return self._params, self._T.shape[0]

    def _pair(self, state: State) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        idx = self._rigid_indices(state)
        if self.grounded:
            (i,) = idx
            return state.g[i], state.V[i], state.g[i], state.V[i]
        i, j = idx
        return state.g[i], state.V[i], state.g[j], state.V[j]

    def rows(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(A, b): columns [V_P, V_C], or [V_C] for a joint to the ground."""
        s = self._T.shape[0]
        A, b = np.empty((s, 12)), np.empty(s)
        joint_rows(state.t, *self._pair(state), self._params, A, b)
        return (A[:, :6] if self.grounded else A), b

    def violation(self, state: State) -> tuple[FloatArray, FloatArray]:
        """(Φ, T V_rel): position residual (rad, m) and velocity residual (rad/s, m/s)."""
        s = self._T.shape[0]
        pos, vel = np.empty(s), np.empty(s)
        joint_residuals(*self._pair(state), self._params, pos, vel)
        return pos, vel

    def _tree_subspace(self) -> Any:
        """The rows on the child, ``T Ad_{X_CJ⁻¹}``, are constant (but for the universal
        joint's last row), with G⁺ = Ad_{X_CJ} Tᵀ (T Tᵀ = I) and S_C = Ad_{X_CJ} S in the
        child's frame; the rows on the parent are ``−T Ad_{h⁻¹} Ad_{X_PJ⁻¹} = −G Ad_{g_C⁻¹ g_P}``.
        Only for the compiled kernel's rows (a subclass with its own ``rows`` has none)."""
        from gmuk.engine.tree import JointSubspace

        term = self._compiled_term()
        if term is None or term[0] is not joint_rows or self._residual_kind == _UNIVERSAL:
            return None
        Ad_CJ = se3._Ad(self.child_frame)
        return JointSubspace(
            0 if self.grounded else 1,
            np.ascontiguousarray(Ad_CJ @ self._T.T),
            np.ascontiguousarray(Ad_CJ @ self.motion_subspace),
        )

    def _violation_along(
        self,
        states: Sequence[State],
        stacked: tuple[FloatArray, FloatArray] | None = None,
    ) -> tuple[FloatArray, FloatArray] | None:
        """:meth:`violation` at each of ``states`` (one System's), (N, s) each, in one compiled
        loop (the drift check of a run evaluates up to 65 outputs); None for a subclass with
        its own ``violation``. ``stacked``: the states' poses (N, n_rigid, 4, 4) and twists
        (N, n_rigid, 6), when the caller has them (else stacked here)."""
        if type(self).violation is not Joint.violation or not states:
            return None
        if stacked is None:  # (stacked from one trajectory, they share its layout)
            layout = states[0].layout
            if any(st.layout is not layout and st.layout != layout for st in states):
                return None
            stacked = (np.array([st.g for st in states]), np.array([st.V for st in states]))
        idx = self._rigid_indices(states[0])
        i, j = (idx[0], idx[0]) if self.grounded else idx
        g = np.asarray(stacked[0], dtype=float)
        V = np.asarray(stacked[1], dtype=float)
        s = self._T.shape[0]
        pos, vel = np.empty((len(states), s)), np.empty((len(states), s))
        _residuals_along(
            np.ascontiguousarray(g[:, i]), np.ascontiguousarray(V[:, i]),
            np.ascontiguousarray(g[:, j]), np.ascontiguousarray(V[:, j]),
            self._params, pos, vel,
        )  # fmt: skip
        return pos, vel

    # -- reading the joint
    def relative_pose(self, state: State) -> FloatArray:
        """h = g_{J_p}⁻¹ g_{J_c} (4, 4): J_c in J_p (m)."""
        gP, _, gC, _ = self._pair(state)
        gJp = self.parent_frame if self.grounded else gP @ self.parent_frame
        return se3._inverse(gJp) @ (gC @ self.child_frame)

    def relative_twist(self, state: State) -> FloatArray:
        """V_rel = V_{J_c} − Ad_{h⁻¹} V_{J_p} (6,), [ω; v] in J_c (rad/s, m/s)."""
        _gP, VP, _gC, VC = self._pair(state)
        VJc = self._AdC @ VC
        if self.grounded:
            return VJc
        return VJc - se3._Ad(se3._inverse(self.relative_pose(state))) @ (self._AdP @ VP)

    def relative_acceleration(self, state: State, Vdot_P: Any, Vdot_C: Any) -> FloatArray:
        """V̇_rel (6,), the rate of V_rel's components in J_c, from the bodies' V̇ (rad/s², m/s²).

        ``V̇_rel = Ad_{X_CJ⁻¹} V̇_C − Ad_{h⁻¹} Ad_{X_PJ⁻¹} V̇_P + ad_{V_rel} Ad_{h⁻¹} V_{J_p}``.
        """
        _gP, VP, _gC, VC = self._pair(state)
        out = self._AdC @ np.asarray(Vdot_C, dtype=float)
        if self.grounded:
            return out
        Ad_h_inv = se3._Ad(se3._inverse(self.relative_pose(state)))
        W = Ad_h_inv @ (self._AdP @ VP)  # V_Jp expressed in J_c
        V_rel = self._AdC @ VC - W
        return out - Ad_h_inv @ (self._AdP @ np.asarray(Vdot_P, dtype=float)) + se3._ad(V_rel) @ W

    def rates(self, state: State) -> FloatArray:
        """Joint rates q̇ (nv,): ``S⁺ V_rel`` (rad/s, m/s)."""
        return self._S_pinv @ self.relative_twist(state)

    def coordinates(self, state: State) -> FloatArray:
        """Joint coordinates (nq,) at ``state`` (rad, m); angles in (−π, π] (see
        :meth:`coordinates_along` for a trajectory's, unwrapped)."""
        return self._S_pinv @ se3._log(self.relative_pose(state))

    def coordinates_along(self, traj: Trajectory) -> FloatArray:
        """Joint coordinates at every output of ``traj`` (N, nq), angles unwrapped: each
        output takes the branch nearest the angle the rates predict from the one before
        (:func:`unwrap_with_rates`), so that a joint may turn more than π between outputs."""
        states = [traj.state(i) for i in range(len(traj))]
        q = np.array([self.coordinates(s) for s in states]).reshape(len(states), self.nq)
        if not self._angular.any():
            return q
        qd = np.array([self.rates(s) for s in states]).reshape(len(states), self.nv)
        out = q.copy()
        out[:, self._angular] = unwrap_with_rates(
            q[:, self._angular], qd[:, self._angular], np.asarray(traj.t)
        )
        return out

    def rates_along(self, traj: Trajectory) -> FloatArray:
        """Joint rates at every output of ``traj`` (N, nv)."""
        rows = [self.rates(traj.state(i)) for i in range(len(traj))]
        return np.array(rows).reshape(len(rows), self.nv)

    @property
    def _angular(self) -> np.ndarray:
        """Which coordinates are angles that wrap (and whose rates are their derivatives)."""
        return np.linalg.norm(self.motion_subspace[:3], axis=0) > 0.0

    def wrenches(self, state: State, tau: Any) -> tuple[FloatArray, FloatArray]:
        """The body-frame wrenches [L; f] on the parent and the child of generalised joint
        forces ``tau`` (nv,) (N·m, N): ``W_C = Ad_{X_CJ⁻¹}ᵀ S τ``,
        ``W_P = −(Ad_{h⁻¹} Ad_{X_PJ⁻¹})ᵀ S τ`` (zero for a joint to the ground). Their power
        is ``τ · q̇``."""
        F = self._subspace_at(state) @ np.asarray(tau, dtype=float)
        W_C = self._AdC.T @ F
        if self.grounded:
            return np.zeros(6), W_C
        Ad_h_inv = se3._Ad(se3._inverse(self.relative_pose(state)))
        return -(Ad_h_inv @ self._AdP).T @ F, W_C

    def _subspace_at(self, state: State) -> FloatArray:
        """S at ``state`` (constant but for the universal joint)."""
        return self.motion_subspace

    @property
    def parent(self) -> Body | str | None:
        """The parent body (None: the ground)."""
        return None if self.grounded else self.bodies[0]

    @property
    def child(self) -> Body | str:
        """The child body."""
        return self.bodies[-1]


def _axis_subspace(angular: Sequence[FloatArray], linear: Sequence[FloatArray]) -> FloatArray:
    cols = [np.concatenate([a, np.zeros(3)]) for a in angular]
    cols += [np.concatenate([np.zeros(3), a]) for a in linear]
    return np.array(cols, dtype=float).T.reshape(6, len(cols))


class FixedJoint(Joint):
    """Welds the child to the parent: no relative motion (6 rows)."""

    kind = "fixed"
    _forms = _JOINT_FORMS

    def _subspace(self) -> FloatArray:
        return np.zeros((6, 0))


class _AxisJoint(Joint):
    """A joint whose motion is about or along one ``axis`` (unit, in both joint frames)."""

    def __init__(
        self, parent: Body | str | None, child: Body | str, *, axis: Any = (0, 0, 1), **kw: Any
    ) -> None:
        self.axis = _unit(axis, "axis")
        super().__init__(parent, child, **kw)


class RevoluteJoint(_AxisJoint):
    """Rotation about ``axis`` (unit, in the joint frames; default z) through their common
    origin: 5 rows; coordinate the angle (rad).

    Parameters
    ----------
    axis : array_like (3,), optional
        The rotation axis, in both joint frames (normalised here).
    **kw
        ``parent_frame``, ``child_frame``, ``baumgarte``, ``name``, as for :class:`Joint`.
    """

    kind = "revolute"
    _forms = _JOINT_FORMS

    def _subspace(self) -> FloatArray:
        return _axis_subspace([self.axis], [])


class PrismaticJoint(_AxisJoint):
    """Translation along ``axis`` (default z): 5 rows; coordinate the displacement (m)."""

    kind = "prismatic"
    _forms = _JOINT_FORMS

    def _subspace(self) -> FloatArray:
        return _axis_subspace([], [self.axis])


class CylindricalJoint(_AxisJoint):
    """Rotation about and translation along ``axis``: 4 rows; coordinates (angle, slide)."""

    kind = "cylindrical"
    _forms = _JOINT_FORMS

    def _subspace(self) -> FloatArray:
        return _axis_subspace([self.axis], [self.axis])


class ScrewJoint(Joint):
    """A helical joint: rotation θ about ``axis`` with the slide ``pitch · θ`` along it
    (pitch in m/rad): 5 rows; coordinate the angle (rad).

    Its position residual unscrews h by the angle its slide implies,
    ``Φ = T log(h exp(−(a·p_h / pitch) S))``: ``T log(h)`` would not be single-valued once
    the joint turns past half a turn.
    """

    kind = "screw"
    _forms = _JOINT_FORMS
    _residual_kind = _SCREW

    def __init__(
        self,
        parent: Body | str | None,
        child: Body | str,
        *,
        axis: Any = (0, 0, 1),
        pitch: float,
        **kw: Any,
    ) -> None:
        self.axis = _unit(axis, "axis")
        self.pitch = real_number(pitch, "pitch")
        if self.pitch == 0.0:
            raise DefinitionError("a ScrewJoint needs a nonzero pitch; use a RevoluteJoint")
        super().__init__(parent, child, **kw)

    def _subspace(self) -> FloatArray:
        return np.concatenate([self.axis, self.pitch * self.axis])[:, None]

    def _extra(self) -> FloatArray:
        return np.array([*self.axis, self.pitch, 0.0, 0.0])

    def coordinates(self, state: State) -> FloatArray:
        """The angle θ = slide / pitch (rad): single-valued, so it needs no unwrapping."""
        h = self.relative_pose(state)
        return np.array([float(self.axis @ h[:3, 3]) / self.pitch])

    @property
    def _angular(self) -> np.ndarray:
        return np.zeros(1, dtype=bool)  # its angle is slide / pitch: single-valued


class SphericalJoint(Joint):
    """A ball joint: the joint frames' origins coincide (3 rows). Coordinates: the rotation
    vector of J_c in J_p (rad, (3,)); rates: ω_rel in J_c (rad/s)."""

    kind = "spherical"
    _forms = _JOINT_FORMS

    def _subspace(self) -> FloatArray:
        return _axis_subspace(list(np.eye(3)), [])

    @property
    def _angular(self) -> np.ndarray:
        return np.zeros(3, dtype=bool)  # a rotation vector: not unwrapped


class PlanarJoint(Joint):
    """Motion in the plane normal to ``normal`` (default z): rotation about the normal and
    translation in the plane (3 rows). Coordinates: (θ, x, y) with x, y along the plane's
    two in-plane axes ``in_plane`` (rad, m)."""

    kind = "planar"
    _forms = _JOINT_FORMS

    def __init__(
        self, parent: Body | str | None, child: Body | str, *, normal: Any = (0, 0, 1), **kw: Any
    ) -> None:
        self.normal = _unit(normal, "normal")
        self.in_plane = _perpendiculars(self.normal)
        super().__init__(parent, child, **kw)

    def _subspace(self) -> FloatArray:
        return _axis_subspace([self.normal], list(self.in_plane))

    def coordinates(self, state: State) -> FloatArray:
        """(θ, x, y): the angle about the normal and J_c's origin in J_p's plane axes."""
        h = self.relative_pose(state)
        theta = float(self.normal @ se3._log(h)[:3])
        e1, e2 = self.in_plane
        return np.array([theta, float(e1 @ h[:3, 3]), float(e2 @ h[:3, 3])])


class UniversalJoint(Joint):
    """A Cardan (Hooke) joint: rotation about ``axis1`` (fixed in J_p, default x) then about
    ``axis2`` (fixed in J_c, default y), perpendicular, through a common point (4 rows).

    Its rotation row is ``n · ω̇_rel = −ṅ · ω_rel`` with ``n = a₁ × a₂`` in J_c, which moves with
    the joint; the position residual is ``−a₁ · a₂`` (zero while the axes stay perpendicular).
    Coordinates (q₁, q₂) with ``R_h = Rot(axis1, q₁) Rot(axis2, q₂)`` (rad).
    """

    kind = "universal"
    _forms = _JOINT_FORMS
    _residual_kind = _UNIVERSAL

    def __init__(
        self,
        parent: Body | str | None,
        child: Body | str,
        *,
        axis1: Any = (1, 0, 0),
        axis2: Any = (0, 1, 0),
        **kw: Any,
    ) -> None:
        self.axis1 = _unit(axis1, "axis1")
        self.axis2 = _unit(axis2, "axis2")
        if abs(float(self.axis1 @ self.axis2)) > 1e-12:
            raise DefinitionError(
                f"a UniversalJoint's axes must be perpendicular; got axis1·axis2 = "
                f"{float(self.axis1 @ self.axis2):.3g}"
            )
        super().__init__(parent, child, **kw)

    def _subspace(self) -> FloatArray:
        # at the joint's zero; the first column moves with the joint (see rates)
        return _axis_subspace([self.axis1, self.axis2], [])

    def _constraint_rows(self, S: FloatArray) -> FloatArray:
        T = np.zeros((4, 6))
        T[:3, 3:] = np.eye(3)
        return T  # the last row, [n; 0], is set at each call

    def _extra(self) -> FloatArray:
        return np.concatenate([self.axis1, self.axis2])

    def _axes_now(self, state: State) -> FloatArray:
        R = self.relative_pose(state)[:3, :3]
        return np.column_stack([R.T @ self.axis1, self.axis2])

    def _subspace_at(self, state: State) -> FloatArray:
        return np.vstack([self._axes_now(state), np.zeros((3, 2))])

    def rates(self, state: State) -> FloatArray:
        """(q̇₁, q̇₂): ``ω_rel = q̇₁ R_hᵀ a₁ + q̇₂ a₂`` (rad/s)."""
        w = self.relative_twist(state)[:3]
        return np.asarray(np.linalg.lstsq(self._axes_now(state), w, rcond=None)[0], dtype=float)

    def coordinates(self, state: State) -> FloatArray:
        """(q₁, q₂) with ``R_h = Rot(a₁, q₁) Rot(a₂, q₂)`` (rad)."""
        R = self.relative_pose(state)[:3, :3]
        a1, a2 = self.axis1, self.axis2
        a3 = np.cross(a1, a2)
        # in the basis (a1, a2, a3), R = Rx(q1) Ry(q2)
        B = np.column_stack([a1, a2, a3])
        Rb = B.T @ R @ B
        return np.array([math.atan2(Rb[2, 1], Rb[1, 1]), math.atan2(Rb[0, 2], Rb[0, 0])])
