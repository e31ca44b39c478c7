"""Morse–Lyapunov backstepping tracking control on TSE(3) (McCann 2020, Section 5).

A :class:`MorseLyapunovController` drives one rigid body onto a nominal motion
(g_n, V_n, V̇_n) given by any :class:`gmuk.reference.ReferenceTrajectory`, from disturbed
initial states and against forces the Udwadia–Kalaba model does not know. Its wrench acts
on the plant beside the UK constraint wrench, which the System computes from the modeled
dynamics; the controller is handed that modeled acceleration and adds to it.

The corrected law (default)
---------------------------
Errors are those of the configuration error ``E_g = g_n⁻¹ g`` on SE(3):

* ``E_R = R_nᵀ R`` and the position error in the **body** frame ``q = Rᵀ(r − r_n)``;
* ``E_V = V − Ad_{E_g⁻¹} V_n = [E_ω; E_v]``, the body twist of E_g (``Ė_g = E_g E_V^``),
  so that ``Ė_R = E_R E_ω^`` and ``q̇ = −E_ω × q + E_v``;
* ``s(E_R) = Σᵢ aᵢ (E_Rᵀ eᵢ)^× eᵢ`` (Eq. 84), ``l = [s; q]`` (Eq. 83) and
  ``ψ = E_V + K₁ l`` (Eq. 82) with ``K₁ = blkdiag(k₁₁ I₃, k₁₂ I₃)``;
* ``ṡ = (tr(A E_Rᵀ) I − E_Rᵀ A) E_ω``, so ``l̇ = [ṡ; −E_ω × q + E_v]``.

The control assigns the error dynamics

``ψ̇ = −K₂ ψ − κ [0; q] − k_I z``,  ``ż = ψ``  (z: the integral of ψ, the controller's state)

through ``u = 𝕀 (V̇_cmd − V̇_model)`` with
``V̇_cmd = Ad_{E_g⁻¹} V̇_n − ad_{E_V} Ad_{E_g⁻¹} V_n − K₁ l̇ − K₂ ψ − κ [0; q] − k_I z``
and V̇_model the modeled acceleration (free plus UK constraint). With

``W = c tr(A − A E_R) + (κ/2) |q|² + ½ |ψ|² + (k_I/2) |z|²``,

``Ẇ = −ψᵀ K₂ ψ + c ψ_ω·s − c k₁₁ |s|² − κ k₁₂ |q|²``, which is ≤ 0 whenever
``c < 4 k₁₁ λ_min(K₂₁)`` (the rotational block is then a positive definite quadratic form in
``‖ψ_ω‖`` and ``‖s‖``); c is an analysis weight only (it is not in u). By LaSalle, the closed loop
tends to ψ = 0, q = 0, z = 0, s(E_R) = 0; with distinct aᵢ the last holds only at
E_R = I (the minimum of the Morse function) and at E_R = diag(1, −1, −1), diag(−1, 1, −1)
(its saddles) and diag(−1, −1, 1) (its maximum): unstable equilibria of the closed loop whose
stable manifolds have zero measure, so (E_g, E_V) = (I, 0) is almost globally asymptotically
stable. The derivation is in the documentation's
Chapter 5 theory page.

Departures from McCann (2020), Eq. 81 (errata, "Section 5.1 controller")
------------------------------------------------------------------------
* The printed law takes the inertial position error r − r_n beside a body-frame velocity
  error V − V_n; its proof's ``Ė_r = E_R E_v`` is false, and on the LVLH orbit (whose
  nominal attitude flips an axis) the translational loop diverges. Here the position error is
  body-frame, q = Rᵀ(r − r_n), in ψ and in the κ term alike, and E_V is the twist of E_g.
* The printed k₃ = 1000 is both the integral gain and the Morse weight; as an integral gain
  it leaves an almost undamped oscillation. The integral gain is its own parameter k_I,
  **off by default**: with the Section 5.1 gains any k_I > 0 adds a translational mode near
  k_I/κ, slower than the convergence it is meant to help unless k_I ≳ 1e-8 s⁻² (critical
  damping), where the position error overshoots (at two FCEI orbits from the Section 5.1
  start: 0.56 m with k_I = 0, 12 m with 1e-10, 189 m with 1e-8, per-axis linear model).
  Without it a constant unmodeled acceleration d leaves a steady position error ≈ d/κ.
  The Morse weight c of W is an analysis parameter (default 0.2).
* The printed ``−(ad*_V 𝕀V − ad*_{V_n} 𝕀V_n)`` cancels the gyroscopic terms of a plant driven
  by the *nominal* UK wrench; gmuk's UK wrench is computed at the actual state, so the law
  uses the modeled acceleration instead (the exact feedforward in either case).

The printed law is kept as ``variant="thesis"`` (with its k₃ = 1000) for reproducing the
thesis and showing its divergence.

One definition
--------------
The corrected law is written once, as numba kernels in this module:
:func:`morse_lyapunov_errors` (E_R, q, E_V, Ad_{E_g⁻¹} V_n, s, ψ), :func:`morse_lyapunov_law`
(u and ż from them, for any nominal motion) and :func:`morse_lyapunov_lvlh` (the law on an
:class:`~gmuk.orbits.LVLHReference`, the nominal evaluated in the kernel). The Python methods
(:meth:`MorseLyapunovController.control`, :meth:`~MorseLyapunovController.errors`,
:func:`morse_s`, :func:`morse_s_rate_matrix`) call them, and so does the compiled step loop
(through :data:`~gmuk.control.base.CONTROL_KERNEL`); the printed law reuses :func:`morse_s` and Eq.
90's bound.

References
----------
McCann (2020), Eqs. (81)–(90); Nazari, Maadani, Butcher & Yucelen (2018), "Morse–Lyapunov-
based control of rigid body motion on TSE(3) via backstepping", AIAA SciTech,
doi:10.2514/6.2018-0602; Khalil (2002), *Nonlinear Systems*, §14.3 (backstepping).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, real_number, real_vector, strict_bool
from gmuk.bodies import BodyKind, RigidBody
from gmuk.control.base import Controller
from gmuk.errors import DefinitionError
from gmuk.lie import se3, so3
from gmuk.lie._kernels import _ad_apply, _cross
from gmuk.orbits._kernels import lvlh_state_packed
from gmuk.reference import ReferenceTrajectory

if TYPE_CHECKING:
    from gmuk.state import State
    from gmuk.trajectory import Trajectory

__all__ = [
    "N_LAW_PARAMS",
    "MorseLyapunovController",
    "TrackingErrors",
    "morse_lyapunov_errors",
    "morse_lyapunov_law",
    "morse_lyapunov_lvlh",
    "morse_s",
    "morse_s_rate_matrix",
]

#: Eq. 90's printed robust gain κ₂ (with its O/‖r‖⁴ bound).
KAPPA2_THESIS = -39.0 / 2.0

#: Parameters of :func:`morse_lyapunov_law`: [k11, k12, k21 (3), k22 (3), κ, a (3), k_I,
#: robust, κ₂, 𝕀 (36, row-major)].
N_LAW_PARAMS = 51
#: Parameters of :func:`morse_lyapunov_lvlh`: the orbit [n, e, μ, p, R_NP (9, row-major)],
#: then those of the law.
N_LVLH_PARAMS = 13 + N_LAW_PARAMS


# ---------------------------------------------------------------- the kernels: the law, once


@njit(cache=True, inline="always")
def _morse_s_into(E_R, a, s):  # type: ignore[no-untyped-def]
    """Write s(E_R) of Eq. 84 into ``s`` (3,): row i of E_R is E_Rᵀ eᵢ, and
    ``Σ aᵢ (E_Rᵀ eᵢ)^× eᵢ`` written out per component."""
    s[0] = E_R[2, 1] * a[2] - E_R[1, 2] * a[1]
    s[1] = E_R[0, 2] * a[0] - E_R[2, 0] * a[2]
    s[2] = E_R[1, 0] * a[1] - E_R[0, 1] * a[0]


@njit(cache=True, inline="always")
def _morse_q_into(E_R, a, Q):  # type: ignore[no-untyped-def]
    """Write ``Q = tr(A E_Rᵀ) I − E_Rᵀ A`` (ṡ = Q E_ω) into ``Q`` (3, 3)."""
    tr = E_R[0, 0] * a[0] + E_R[1, 1] * a[1] + E_R[2, 2] * a[2]
    for i in range(3):
        for j in range(3):
            Q[i, j] = -E_R[j, i] * a[j]
        Q[i, i] += tr


@njit(cache=True, inline="always")
def _eq90_bound(g, kappa2):  # type: ignore[no-untyped-def]
    """Eq. 90's bound ``κ₂/‖r‖⁴`` (each of the six components of κ₂ O/‖r‖⁴) at pose g."""
    r2 = g[0, 3] * g[0, 3] + g[1, 3] * g[1, 3] + g[2, 3] * g[2, 3]
    return kappa2 / (r2 * r2)


@njit(cache=True, inline="always")
def _Ad_apply(R, p, V, out):  # type: ignore[no-untyped-def]
    """out = Ad_(R, p) V = [R ω; p × (R ω) + R v] for V = [ω; v]."""
    w0 = R[0, 0] * V[0] + R[0, 1] * V[1] + R[0, 2] * V[2]
    w1 = R[1, 0] * V[0] + R[1, 1] * V[1] + R[1, 2] * V[2]
    w2 = R[2, 0] * V[0] + R[2, 1] * V[1] + R[2, 2] * V[2]
    c0, c1, c2 = _cross(p[0], p[1], p[2], w0, w1, w2)
    out[0], out[1], out[2] = w0, w1, w2
    out[3] = c0 + R[0, 0] * V[3] + R[0, 1] * V[4] + R[0, 2] * V[5]
    out[4] = c1 + R[1, 0] * V[3] + R[1, 1] * V[4] + R[1, 2] * V[5]
    out[5] = c2 + R[2, 0] * V[3] + R[2, 1] * V[4] + R[2, 2] * V[5]


@njit(cache=True)
def _Ad_error_inverse(E_R, q, v, out):  # type: ignore[no-untyped-def]
    """``Ad_{E_g⁻¹} v`` into ``out`` (6,) for the error E_g with rotation E_R and position
    error q (body frame): the nominal's twist or twist rate seen from the body."""
    Re = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            Re[i, j] = E_R[j, i]
    pe = np.empty(3)
    for i in range(3):
        pe[i] = -q[i]
    _Ad_apply(Re, pe, v, out)


@njit(cache=True)
def morse_lyapunov_errors(g, V, gn, Vn, a, k11, k12, E_R, q, E_V, Vn_B, s, psi):  # type: ignore[no-untyped-def]
    """The corrected law's errors of pose g (4, 4) and twist V (6,) against the nominal
    (gn, Vn), written into E_R (3, 3), q (3,), E_V, Vn_B (6,), s (3,) and ψ (6,):

    ``E_R = R_nᵀ R``, ``q = Rᵀ(r − r_n)``, ``Vn_B = Ad_{E_g⁻¹} V_n`` with
    ``E_g⁻¹ = (E_Rᵀ, −q)``, ``E_V = V − Vn_B``, ``s = s(E_R)`` (Eq. 84) and
    ``ψ = E_V + K₁ [s; q]`` (Eq. 82), ``K₁ = blkdiag(k₁₁ I₃, k₁₂ I₃)``.
    """
    for i in range(3):
        for j in range(3):
            E_R[i, j] = gn[0, i] * g[0, j] + gn[1, i] * g[1, j] + gn[2, i] * g[2, j]
    d0, d1, d2 = g[0, 3] - gn[0, 3], g[1, 3] - gn[1, 3], g[2, 3] - gn[2, 3]
    for i in range(3):
        q[i] = g[0, i] * d0 + g[1, i] * d1 + g[2, i] * d2
    _Ad_error_inverse(E_R, q, Vn, Vn_B)
    for i in range(6):
        E_V[i] = V[i] - Vn_B[i]
    _morse_s_into(E_R, a, s)
    for i in range(3):
        psi[i] = E_V[i] + k11 * s[i]
        psi[3 + i] = E_V[3 + i] + k12 * q[i]


@njit(cache=True)
def morse_lyapunov_law(g, V, a_model, z, gn, Vn, Vdn, p, u, psi):  # type: ignore[no-untyped-def]
    """The corrected law (module docstring): the wrench ``u`` (6,) and ż = ψ (6,) for a body at
    pose g, twist V, modeled acceleration ``a_model`` (6,) and internal state z (6,), tracking
    the nominal (gn, Vn, Vdn); ``p`` as :data:`N_LAW_PARAMS` describes. With the errors of
    :func:`morse_lyapunov_errors` and ``l̇ = [Q E_ω; E_v − E_ω × q]``,

    ``V̇_cmd = Ad_{E_g⁻¹} V̇_n − ad_{E_V} Ad_{E_g⁻¹} V_n − K₁ l̇ − K₂ ψ − [0; κ q] − k_I z``
    and ``u = 𝕀 (V̇_cmd − a_model)``, less ``𝕀 κ₂ O/‖r‖⁴`` (Eq. 90) when robust.
    """
    k11, k12 = p[0], p[1]
    kappa = p[8]
    a = p[9:12]
    k_int, robust, kappa2 = p[12], p[13], p[14]
    E_R = np.empty((3, 3))
    q = np.empty(3)
    E_V = np.empty(6)
    Vn_B = np.empty(6)
    s = np.empty(3)
    morse_lyapunov_errors(g, V, gn, Vn, a, k11, k12, E_R, q, E_V, Vn_B, s, psi)
    Vdn_B = np.empty(6)
    _Ad_error_inverse(E_R, q, Vdn, Vdn_B)
    Q = np.empty((3, 3))
    _morse_q_into(E_R, a, Q)
    l_dot = np.empty(6)
    for i in range(3):
        l_dot[i] = Q[i, 0] * E_V[0] + Q[i, 1] * E_V[1] + Q[i, 2] * E_V[2]
    c0, c1, c2 = _cross(E_V[0], E_V[1], E_V[2], q[0], q[1], q[2])
    l_dot[3] = E_V[3] - c0
    l_dot[4] = E_V[4] - c1
    l_dot[5] = E_V[5] - c2
    ad = np.empty(6)
    _ad_apply(E_V, Vn_B, ad)
    dv = np.empty(6)
    for i in range(6):
        k1 = k11 if i < 3 else k12
        dv[i] = Vdn_B[i] - ad[i] - k1 * l_dot[i] - p[2 + i] * psi[i] - k_int * z[i] - a_model[i]
    for i in range(3):
        dv[3 + i] -= kappa * q[i]
    if robust != 0.0:
        bound = _eq90_bound(g, kappa2)
        for i in range(6):
            dv[i] -= bound
    for i in range(6):
        acc = 0.0
        for j in range(6):
            acc += p[15 + 6 * i + j] * dv[j]
        u[i] = acc


@njit(cache=True)
def morse_lyapunov_lvlh(t, g, V, a_model, z, p, u, psi):  # type: ignore[no-untyped-def]
    """:func:`morse_lyapunov_law` tracking an :class:`~gmuk.orbits.LVLHReference`, its nominal
    at time t evaluated here (:func:`gmuk.orbits._kernels.lvlh_state`); ``p`` as
    :data:`N_LVLH_PARAMS` describes."""
    gn = np.empty((4, 4))
    Vn = np.empty(6)
    Vdn = np.empty(6)
    lvlh_state_packed(t, p, gn, Vn, Vdn)
    morse_lyapunov_law(g, V, a_model, z, gn, Vn, Vdn, p[13:], u, psi)
    return 0


def _f64(x: Any) -> FloatArray:
    """A fresh C-contiguous float64 array (what the kernels are compiled for)."""
    return np.array(x, dtype=np.float64)


def morse_s(E_R: FloatArray, a: FloatArray) -> FloatArray:
    """``s(E_R) = Σᵢ aᵢ (E_Rᵀ eᵢ)^× eᵢ`` (McCann 2020, Eq. 84), shape (3,) (dimensionless).

    Zero exactly at the critical points of the Morse function ``tr(A − A E_R)``: E_R = I and,
    for distinct aᵢ, the three rotations by π about the axes eᵢ.

    Parameters
    ----------
    E_R : ndarray (3, 3)
        Attitude error R_nᵀ R (dimensionless rotation matrix).
    a : ndarray (3,)
        Morse weights, the diagonal of A (dimensionless, distinct and > 0).
    """
    out = np.empty(3)
    _morse_s_into(_f64(E_R), _f64(a), out)
    return out


def morse_s_rate_matrix(E_R: FloatArray, a: FloatArray) -> FloatArray:
    """Q with ``ṡ = Q E_ω`` when ``Ė_R = E_R E_ω^``: ``Q = tr(A E_Rᵀ) I − E_Rᵀ A``, (3, 3)
    (dimensionless; E_ω in rad/s gives ṡ in 1/s).

    Parameters
    ----------
    E_R : ndarray (3, 3)
        Attitude error R_nᵀ R (dimensionless rotation matrix).
    a : ndarray (3,)
        Morse weights, the diagonal of A (dimensionless).
    """
    Q = np.empty((3, 3))
    _morse_q_into(_f64(E_R), _f64(a), Q)
    return Q


@dataclass(frozen=True)
class TrackingErrors:
    """The errors of one pose and twist against the nominal, as the corrected law uses them.

    Attributes
    ----------
    E_R : ndarray (3, 3)
        R_nᵀ R.
    q : ndarray (3,)
        Rᵀ(r − r_n): position error in the body frame (m).
    E_V : ndarray (6,)
        V − Ad_{E_g⁻¹} V_n: twist of the configuration error (rad/s, m/s), body frame.
    Vn_B : ndarray (6,)
        Ad_{E_g⁻¹} V_n: the nominal twist in the body frame.
    Ad_inv : ndarray (6, 6)
        Ad_{E_g⁻¹}.
    s : ndarray (3,)
        s(E_R) of Eq. 84.
    psi : ndarray (6,)
        ψ = E_V + K₁ [s; q] (Eq. 82).
    """

    E_R: FloatArray
    q: FloatArray
    E_V: FloatArray
    Vn_B: FloatArray
    Ad_inv: FloatArray
    s: FloatArray
    psi: FloatArray

    @property
    def attitude_error(self) -> float:
        """Rotation angle of E_R (rad), in [0, π] (from so3.log: exact at small angles too)."""
        return float(np.linalg.norm(so3.log(self.E_R)))


def _gain_vector(value: Any, name: str, *, positive: bool = True) -> FloatArray:
    """A scalar or (3,) gain as a finite (3,) vector, > 0 (or ≥ 0); booleans, strings and
    complex numbers are refused (:func:`gmuk._validation.real_vector`)."""
    return real_vector(value, name, 3, scalar=True, positive=positive, non_negative=not positive)


def _gain_scalar(value: Any, name: str, *, positive: bool = True) -> float:
    """A finite real gain, > 0 (or ≥ 0); booleans, strings and complex numbers are refused
    (:func:`gmuk._validation.real_number`)."""
    return real_number(value, name, positive=positive, non_negative=not positive)


class MorseLyapunovController(Controller):
    """Morse–Lyapunov backstepping tracking of a nominal motion (McCann 2020, Eqs. 81–90).

    Parameters
    ----------
    body : RigidBody
        The controlled rigid body (the object: the law needs its mass properties).
    reference : ReferenceTrajectory
        The nominal motion (g_n, V_n, V̇_n), e.g. :class:`gmuk.orbits.LVLHReference`.
    k11, k12 : float
        Virtual-control gains of K₁ (1/s): rotation and translation. Defaults as in
        Section 5.1: 0.099999, 0.999999.
    k21, k22 : float or array_like (3,)
        Diagonal gains of K₂ (1/s): rotation and translation. Defaults as in Section 5.1:
        1.1 and (0.05, 0.05, 1)·1e-5.
    kappa : float
        κ (1/s²), the translational coupling of ψ̇ and the weight of ½|q|² in W. Default as
        in Section 5.1: 0.0002.
    a : array_like (3,)
        Morse weights A = diag(a), distinct and > 0. Default (3, 2, 1) as in Section 5.1.
    k_integral : float
        Integral gain k_I (1/s², ≥ 0) of ``−k_I ∫ψ``. Default 0 (off), **not** the printed
        k₃ = 1000 (errata: an almost undamped 31.6 rad/s oscillation). With the default
        gains a k_I > 0 adds a slow mode near k_I/κ (see the module docstring); about 1e-8
        critically damps the slow translational mode and removes constant biases.
    morse_weight : float
        c, the weight of the Morse function in W (analysis only, not in u). Must satisfy
        c < 4 k₁₁ min(k₂₁) for Ẇ ≤ 0. Default 0.2.
    robust : bool
        Add Eq. 90's term ``−𝕀 κ₂ O/‖r‖⁴`` (O a 6-vector of ones); exactly True or False
        (a string such as ``"False"`` is refused, not read by its truthiness). As printed, with
        κ₂ = −39/2, it is of order 1e-25 m/s² on a lunar orbit (the units of κ₂ are not
        stated; the term is kept as printed for reproduction); pass ``bound`` for a bound of
        your own.
    kappa2 : float
        κ₂ of Eq. 90 (default −39/2).
    bound : callable (t, g, V) → (6,), optional
        Replaces ``κ₂ O/‖r‖⁴`` in the robust term by a user bound (rad/s², m/s²); implies
        ``robust=True``.
    variant : {"corrected", "thesis"}
        "thesis" is Eq. 81 as printed (inertial position error, V − V_n, the printed
        ``−(ad*_V 𝕀V − ad*_{V_n} 𝕀V_n)`` and integral gain k₃ = ``k_integral``, default then
        1000); it diverges on the LVLH orbit and is kept to show it.
    name : str, optional

    Raises
    ------
    DefinitionError
        If a gain is not a finite real number (or, for k21, k22, a, 3 of them) of the
        stated sign: booleans, strings and complex numbers are refused, not converted; if
        ``robust`` is not a bool, ``variant`` not one of the two names, ``bound`` not
        callable, or ``a`` not 3 distinct numbers.

    Notes
    -----
    The internal state z (6,) is ∫ψ dt, starting at zero. The wrench returned is
    ``[u_L; u_f]`` in the body frame (N·m, N).
    """

    uses_modeled_acceleration = True
    body_kinds = frozenset({BodyKind.RIGID})
    _numeric_methods = ("control", "_errors")
    _forms = Forms(compiled=True, symbolic="gmuk.optimize transcribes no controller")

    def __init__(
        self,
        body: RigidBody,
        reference: ReferenceTrajectory,
        *,
        k11: float = 0.099999,
        k12: float = 0.999999,
        k21: Any = 1.1,
        k22: Any = (0.05e-5, 0.05e-5, 1e-5),
        kappa: float = 0.0002,
        a: Sequence[float] = (3.0, 2.0, 1.0),
        k_integral: float | None = None,
        morse_weight: float = 0.2,
        robust: bool = False,
        kappa2: float = KAPPA2_THESIS,
        bound: Callable[[float, FloatArray, FloatArray], Any] | None = None,
        variant: str = "corrected",
        name: str | None = None,
    ) -> None:
        if not isinstance(body, RigidBody):
            raise DefinitionError(
                "MorseLyapunovController controls a gmuk.RigidBody (pass the body object: "
                f"the law needs its mass properties); got {type(body).__name__}: {body!r}"
            )
        super().__init__([body], n_states=6, name=name)
        if not isinstance(reference, ReferenceTrajectory):
            raise DefinitionError(
                "reference must be a gmuk.ReferenceTrajectory (e.g. gmuk.orbits.LVLHReference); "
                f"got {type(reference).__name__}: {reference!r}"
            )
        if not isinstance(variant, str) or variant not in ("corrected", "thesis"):
            raise DefinitionError(f"variant must be 'corrected' or 'thesis'; got {variant!r}")
        if bound is not None and not callable(bound):
            raise DefinitionError(f"bound must be a callable (t, g, V) -> (6,); got {bound!r}")
        robust = strict_bool(robust, "robust")
        aa = real_vector(a, "a", 3, positive=True)
        if len(set(aa.tolist())) != 3:
            raise DefinitionError(
                f"a must be 3 distinct numbers (else s(E_R) vanishes on whole circles of "
                f"rotations, not at isolated saddles); got {aa.tolist()}"
            )
        self.reference = reference
        self.variant = variant
        self.k11 = _gain_scalar(k11, "k11")
        self.k12 = _gain_scalar(k12, "k12")
        self.k21 = _gain_vector(k21, "k21")
        self.k22 = _gain_vector(k22, "k22")
        self.kappa = _gain_scalar(kappa, "kappa")
        self.a = aa
        default_ki = 1000.0 if variant == "thesis" else 0.0
        self.k_integral = _gain_scalar(
            default_ki if k_integral is None else k_integral, "k_integral", positive=False
        )
        self.morse_weight = _gain_scalar(morse_weight, "morse_weight")
        limit = 4.0 * self.k11 * float(self.k21.min())
        if variant == "corrected" and not self.morse_weight < limit:
            raise DefinitionError(
                f"morse_weight must be < 4 k11 min(k21) = {limit:.6g} for the Lyapunov rate "
                f"to be ≤ 0; got {self.morse_weight!r}"
            )
        self.robust = robust or bound is not None
        self.kappa2 = real_number(kappa2, "kappa2")
        self.bound = bound
        self._K1 = np.concatenate([np.full(3, self.k11), np.full(3, self.k12)])
        self._K2 = np.concatenate([self.k21, self.k22])
        self._I = body.mass_matrix()  # 𝕀 = blkdiag(J, m I₃)

    # ------------------------------------------------------------------ errors
    def errors(self, t: float, g: FloatArray, V: FloatArray) -> TrackingErrors:
        """The corrected law's errors at time t (s) for pose g (4, 4) and body twist V (6,)."""
        ref = self.reference.evaluate(t)
        return self._errors(g, V, np.asarray(ref.g, float), np.asarray(ref.V, float))

    def _errors(
        self, g: FloatArray, V: FloatArray, g_n: FloatArray, V_n: FloatArray
    ) -> TrackingErrors:
        E_R, q, s = np.empty((3, 3)), np.empty(3), np.empty(3)
        E_V, Vn_B, psi = np.empty(6), np.empty(6), np.empty(6)
        morse_lyapunov_errors(
            _f64(g), _f64(V), _f64(g_n), _f64(V_n), _f64(self.a), self.k11, self.k12,
            E_R, q, E_V, Vn_B, s, psi,
        )  # fmt: skip
        E_g_inv = np.eye(4)
        E_g_inv[:3, :3] = E_R.T
        E_g_inv[:3, 3] = -q
        return TrackingErrors(E_R, q, E_V, Vn_B, se3._Ad(E_g_inv), s, psi)

    # ------------------------------------------------------------------ the law
    def control(
        self, state: State, z: FloatArray, *modeled: FloatArray
    ) -> tuple[list[FloatArray], FloatArray]:
        """The wrench [u_L; u_f] (body frame, N·m, N) and ż = ψ
        (:func:`morse_lyapunov_law`, or the printed law for ``variant="thesis"``)."""
        (body,) = self.bodies
        slot = state.layout.slot(body)
        g, V = _f64(state.g[slot.index]), _f64(state.V[slot.index])
        a_model = _f64(modeled[0][slot.offset : slot.offset + 6])
        ref = self.reference.evaluate(state.t)
        g_n, V_n, Vd_n = _f64(ref.g), _f64(ref.V), _f64(ref.V_dot)
        if self.variant == "thesis":
            u, psi = self._thesis_law(g, V, g_n, V_n, Vd_n, z, self._I)
            if self.robust:
                u = u - self._I @ self._robust_bound(state.t, g, V)
            return [u], psi
        u, psi = np.empty(6), np.empty(6)
        morse_lyapunov_law(g, V, a_model, _f64(z), g_n, V_n, Vd_n, self._law_params(), u, psi)
        if self.bound is not None:
            u = u - self._I @ self._robust_bound(state.t, g, V)
        return [u], psi

    def _law_params(self) -> FloatArray:
        """The parameters of :func:`morse_lyapunov_law` (:data:`N_LAW_PARAMS`); Eq. 90's bound
        is left to the kernel unless the user gave one (then :meth:`control` subtracts it)."""
        robust = self.robust and self.bound is None
        return np.concatenate(
            [
                [self.k11, self.k12],
                self.k21,
                self.k22,
                [self.kappa],
                self.a,
                [self.k_integral, float(robust), self.kappa2],
                np.ravel(self._I),
            ]
        ).astype(float)

    def _compiled_term(self) -> tuple[Any, FloatArray] | None:
        """How the compiled step loop evaluates this law: its kernel
        (:func:`morse_lyapunov_lvlh`) and the packed parameters (:data:`N_LVLH_PARAMS`), or
        None (the thesis variant, a user's bound, a reference other than an LVLHReference, an
        overridden ``control``) when it is called in Python."""
        from gmuk.orbits.lvlh import LVLHReference

        if (
            not self._methods_are(MorseLyapunovController)
            or type(self.reference) is not LVLHReference
            or self.variant != "corrected"
            or self.bound is not None
        ):
            return None
        o = self.reference.orbit
        orbit = [o.mean_motion, o.e, o.mu, o.p, *np.ravel(self.reference._R_NP)]
        params = np.concatenate([orbit, self._law_params()]).astype(float)
        return morse_lyapunov_lvlh, params

    def _robust_bound(self, t: float, g: FloatArray, V: FloatArray) -> FloatArray:
        """Eq. 90's κ₂ O/‖r‖⁴, or the user's bound (6,)."""
        if self.bound is not None:
            b = np.asarray(self.bound(t, g, V), dtype=float)
            if b.shape != (6,) or not np.isfinite(b).all():
                raise DefinitionError(
                    f"controller {self.name!r}: bound(t, g, V) must return 6 finite numbers; "
                    f"got shape {b.shape}"
                )
            return b
        return np.full(6, _eq90_bound(_f64(g), self.kappa2))

    def _thesis_law(
        self,
        g: FloatArray,
        V: FloatArray,
        g_n: FloatArray,
        V_n: FloatArray,
        Vd_n: FloatArray,
        z: FloatArray,
        I: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Eq. 81 as printed: E_r = r − r_n (inertial), E_V = V − V_n, the printed
        gyroscopic difference, integral gain k₃ = k_integral. l̇ is the exact time derivative
        of l along the motion."""
        R, R_n = g[:3, :3], g_n[:3, :3]
        E_R = R_n.T @ R
        E_r = g[:3, 3] - g_n[:3, 3]
        E_V = V - V_n
        s = morse_s(E_R, self.a)
        psi = E_V + self._K1 * np.concatenate([s, E_r])
        # Ė_R = E_R ω^ − ω_n^ E_R; ṡ = Σ aᵢ (Ė_Rᵀ eᵢ)^× eᵢ = morse_s(Ė_R) (s is linear in E_R)
        E_R_dot = E_R @ se3._hat(np.r_[V[:3], 0, 0, 0])[:3, :3] - (
            se3._hat(np.r_[V_n[:3], 0, 0, 0])[:3, :3] @ E_R
        )
        E_r_dot = R @ V[3:] - R_n @ V_n[3:]
        l_dot = np.concatenate([morse_s(E_R_dot, self.a), E_r_dot])
        gyro = se3._ad(V).T @ (I @ V) - se3._ad(V_n).T @ (I @ V_n)
        coupling = np.concatenate([np.zeros(3), self.kappa * (E_R @ E_r)])
        u = (
            -I @ (self._K1 * l_dot)
            - gyro
            - I @ (self._K2 * psi)
            - I @ coupling
            - self.k_integral * (I @ z)
        )
        return u, psi

    # ------------------------------------------------------------------ Lyapunov function
    def lyapunov(self, traj: Trajectory) -> tuple[FloatArray, FloatArray]:
        """W and its closed-loop rate Ẇ along a Trajectory of the corrected law.

        ``W = c tr(A − A E_R) + (κ/2)|q|² + ½|ψ|² + (k_I/2)|z|²`` and
        ``Ẇ = −ψᵀK₂ψ + c ψ_ω·s − c k₁₁|s|² − κ k₁₂|q|²`` (the rate when no unmodeled force
        acts), at every output time.

        Returns
        -------
        W : ndarray (N,)
        W_dot : ndarray (N,)
        """
        if self.variant != "corrected":
            raise DefinitionError("lyapunov() is defined for variant='corrected' only")
        (body,) = self.bodies
        name = body if isinstance(body, str) else body.name
        i = traj.body_names.index(name)
        c = self.morse_weight
        W = np.empty(len(traj.t))
        W_dot = np.empty(len(traj.t))
        z_all = self._states_of(traj)
        for k, t in enumerate(traj.t):
            e = self.errors(float(t), traj.g_NB[k, i], traj.V_B[k, i])
            z = z_all[k]
            W[k] = (
                c * float(np.sum(self.a * (1.0 - np.diag(e.E_R))))
                + 0.5 * self.kappa * float(e.q @ e.q)
                + 0.5 * float(e.psi @ e.psi)
                + 0.5 * self.k_integral * float(z @ z)
            )
            W_dot[k] = (
                -float(e.psi @ (self._K2 * e.psi))
                + c * float(e.psi[:3] @ e.s)
                - c * self.k11 * float(e.s @ e.s)
                - self.kappa * self.k12 * float(e.q @ e.q)
            )
        return W, W_dot

    def _states_of(self, traj: Trajectory) -> FloatArray:
        """This controller's z (N, 6) in a Trajectory (controllers' states are concatenated
        in System order; a System with this controller alone has exactly these)."""
        if traj.z.shape[1] != 6:
            raise DefinitionError(
                "the trajectory carries controller states of several controllers; "
                "pass one made by a System whose only controller is this one"
            )
        return traj.z
