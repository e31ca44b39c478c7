"""Compiled kernels of the built-in controllers (the compiled step loop's controller terms).

:func:`apply_control` evaluates a controller term the way :mod:`gmuk.forces._kernels`
evaluates a force term: a code, the controller's packed parameters, the body's pose, twist,
modeled acceleration and internal state in, the wrench and the state rate out. The Python
implementations (:meth:`gmuk.MorseLyapunovController.control`) stay the reference; the tests
compare the two at random states.
"""

from __future__ import annotations

import numpy as np

from gmuk._numba import njit
from gmuk.orbits._kernels import lvlh_state

__all__ = ["MORSE_LYAPUNOV_LVLH", "N_PARAMS", "apply_control", "morse_lyapunov_lvlh"]

#: The corrected Morse–Lyapunov law (McCann 2020, Eqs. 81–90 as corrected in
#: docs/errata.rst) tracking an LVLHReference, with or without Eq. 90's κ₂ bound.
MORSE_LYAPUNOV_LVLH = 0

#: Parameters of a MORSE_LYAPUNOV_LVLH term: the orbit [n, e, μ, p, R_NP (9)], then
#: [k11, k12, k21 (3), k22 (3), κ, a (3), k_integral, robust, κ₂, 𝕀 (36)].
N_PARAMS = 13 + 51


@njit(cache=True)
def apply_control(code, t, g, V, a_model, z, p, u, z_dot):  # type: ignore[no-untyped-def]
    """The wrench ``u`` (6,) and state rate ``z_dot`` of controller term ``code`` with
    parameters ``p`` on a body at pose g (4, 4), twist V (6,), modeled acceleration
    ``a_model`` (6,) and internal state z. Returns 0 (or 1 for an unknown code)."""
    if code == MORSE_LYAPUNOV_LVLH:
        morse_lyapunov_lvlh(t, g, V, a_model, z, p, u, z_dot)
        return 0
    return 1


@njit(cache=True)
def morse_lyapunov_lvlh(t, g, V, a_model, z, p, u, psi):  # type: ignore[no-untyped-def]
    """:meth:`gmuk.MorseLyapunovController.control` (variant "corrected") for an
    LVLHReference: u = 𝕀 (V̇_cmd − a_model) (− 𝕀 κ₂/‖r‖⁴ when robust) and ż = ψ, with

    ``E_R = R_nᵀ R``, ``q = Rᵀ(r − r_n)``, ``E_V = V − Ad_{E_g⁻¹} V_n``,
    ``ψ = E_V + K₁ [s(E_R); q]``, ``l̇ = [Q E_ω; E_v − E_ω × q]``,
    ``V̇_cmd = Ad_{E_g⁻¹} V̇_n − ad_{E_V} Ad_{E_g⁻¹} V_n − K₁ l̇ − K₂ ψ − [0; κ q] − k_I z``.
    """
    R_NP = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R_NP[i, j] = p[4 + 3 * i + j]
    gn = np.empty((4, 4))
    Vn = np.empty(6)
    Vdn = np.empty(6)
    lvlh_state(t, p[0], p[1], p[2], p[3], R_NP, gn, Vn, Vdn)
    k11, k12 = p[13], p[14]
    k21, k22 = p[15:18], p[18:21]
    kappa = p[21]
    a = p[22:25]
    k_int, robust, kappa2 = p[25], p[26], p[27]
    inertia = p[28:64]
    # E_R = R_nᵀ R, q = Rᵀ (r − r_n)
    E_R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            E_R[i, j] = gn[0, i] * g[0, j] + gn[1, i] * g[1, j] + gn[2, i] * g[2, j]
    dr = np.empty(3)
    for i in range(3):
        dr[i] = g[i, 3] - gn[i, 3]
    q = np.empty(3)
    for i in range(3):
        q[i] = g[0, i] * dr[0] + g[1, i] * dr[1] + g[2, i] * dr[2]
    # E_g⁻¹ = g⁻¹ g_n = (Rᵀ R_n, −Rᵀ dr); Ad = [[Rₑ, 0], [pₑ^ Rₑ, Rₑ]]
    Re = E_R.T.copy()
    pe = -q
    Vn_B = np.empty(6)
    Vdn_B = np.empty(6)
    _Ad_apply(Re, pe, Vn, Vn_B)
    _Ad_apply(Re, pe, Vdn, Vdn_B)
    E_V = np.empty(6)
    for i in range(6):
        E_V[i] = V[i] - Vn_B[i]
    # s(E_R) = Σ aᵢ (E_Rᵀ eᵢ)^× eᵢ, and Q = tr(A E_Rᵀ) I − E_Rᵀ A
    s = np.empty(3)
    s[0] = E_R[2, 1] * a[2] - E_R[1, 2] * a[1]
    s[1] = E_R[0, 2] * a[0] - E_R[2, 0] * a[2]
    s[2] = E_R[1, 0] * a[1] - E_R[0, 1] * a[0]
    tr = E_R[0, 0] * a[0] + E_R[1, 1] * a[1] + E_R[2, 2] * a[2]
    K1 = np.empty(6)
    K2 = np.empty(6)
    for i in range(3):
        K1[i], K1[3 + i] = k11, k12
        K2[i], K2[3 + i] = k21[i], k22[i]
    for i in range(3):
        psi[i] = E_V[i] + K1[i] * s[i]
        psi[3 + i] = E_V[3 + i] + K1[3 + i] * q[i]
    l_dot = np.empty(6)
    for i in range(3):
        acc = tr * E_V[i]
        for j in range(3):
            acc -= E_R[j, i] * a[j] * E_V[j]
        l_dot[i] = acc
    w, v = E_V[:3], E_V[3:]
    l_dot[3] = v[0] - (w[1] * q[2] - w[2] * q[1])
    l_dot[4] = v[1] - (w[2] * q[0] - w[0] * q[2])
    l_dot[5] = v[2] - (w[0] * q[1] - w[1] * q[0])
    # ad_{E_V} Vn_B = [E_ω × ω_n; E_v × ω_n + E_ω × v_n]
    ad = np.empty(6)
    _cross(w, Vn_B[:3], ad[:3])
    c1 = np.empty(3)
    c2 = np.empty(3)
    _cross(v, Vn_B[:3], c1)
    _cross(w, Vn_B[3:], c2)
    for i in range(3):
        ad[3 + i] = c1[i] + c2[i]
    dv = np.empty(6)
    for i in range(6):
        dv[i] = Vdn_B[i] - ad[i] - K1[i] * l_dot[i] - K2[i] * psi[i] - k_int * z[i] - a_model[i]
    for i in range(3):
        dv[3 + i] -= kappa * q[i]
    if robust != 0.0:
        r2 = g[0, 3] ** 2 + g[1, 3] ** 2 + g[2, 3] ** 2
        bound = kappa2 / (r2 * r2)
        for i in range(6):
            dv[i] -= bound
    for i in range(6):
        acc = 0.0
        for j in range(6):
            acc += inertia[6 * i + j] * dv[j]
        u[i] = acc


@njit(cache=True)
def _cross(x, y, out):  # type: ignore[no-untyped-def]
    out[0] = x[1] * y[2] - x[2] * y[1]
    out[1] = x[2] * y[0] - x[0] * y[2]
    out[2] = x[0] * y[1] - x[1] * y[0]


@njit(cache=True)
def _Ad_apply(R, p, V, out):  # type: ignore[no-untyped-def]
    """out = Ad_(R, p) V = [R ω; p × (R ω) + R v] for V = [ω; v]."""
    Rw = np.empty(3)
    for i in range(3):
        Rw[i] = R[i, 0] * V[0] + R[i, 1] * V[1] + R[i, 2] * V[2]
    pRw = np.empty(3)
    _cross(p, Rw, pRw)
    for i in range(3):
        out[i] = Rw[i]
        out[3 + i] = pRw[i] + R[i, 0] * V[3] + R[i, 1] * V[4] + R[i, 2] * V[5]
