"""MRP feedback on reaction wheels: Basilisk's ``mrpFeedback`` law in gmuk's Controller form.

The law
-------
With σ = σ_BR the attitude error as modified Rodrigues parameters (short set, ‖σ‖ ≤ 1: the
shadow set is taken whenever ‖σ‖ would exceed 1, so the error is always the shorter rotation)
of the body B relative to a constant reference R (``R_NR``; inertial pointing by default),
ω = ω_BN (rad/s, body frame) and ``H = I_B ω + Σ J_s Ω_i g_i`` the spacecraft's angular
momentum, the commanded body torque is

``L = −K σ − P ω − P K_I z + ω × H``,  ``z = ∫ K σ dt + I_B ω``  (the last term only if K_I > 0)

(Basilisk ``mrpFeedback`` with ``controlLawType = 1``, ω_R = 0 and no known external
torque), and the wheel motor commands are the minimum-norm solution of ``−G u = L``,

``u = −Gᵀ (G Gᵀ)⁻¹ L``,

which for three orthonormal axes is ``u_i = −g_iᵀ L`` (Basilisk ``rwMotorTorque``). Each
wheel's motor clips its command at its torque limit and its speed limit
(:func:`gmuk.actuators.wheels.wheel_spin_torque`). The integral ``∫ K σ dt`` is held per component
within ``±integral_limit`` (it stops integrating outward at the limit; Basilisk clips the sum).

Stability: with K_I = 0 and the motors not saturated, ``G ḣ = −L`` turns Euler's equation
``I_w ω̇ + ω × H + G ḣ = 0`` (``I_w = I_B − Σ J_s g gᵀ``) into ``I_w ω̇ = −K σ − P ω``, and
``V = 2K ln(1 + σᵀσ) + ½ ωᵀ I_w ω`` has ``V̇ = −P ωᵀω`` (σ̇ = ¼ B(σ) ω, σᵀB = (1 + σᵀσ) σᵀ;
Schaub & Junkins 2018, §8.4).

The Controller form
-------------------
:class:`MRPFeedback` is a controller on the bus with the wheels in the internal-momentum
form (:mod:`gmuk.actuators.wheels`): its internal states are the wheels' absolute spin
momenta h (n) and the integral ∫ K σ dt (3); its wrench on the bus is the wheels' torque
``−ω × G h − G ḣ``. The bus must have the inertia ``I_B − Σ J_s g gᵀ``
(:meth:`~gmuk.actuators.WheelArray.spun_down_inertia`). The same law gives the motor
commands of the Udwadia–Kalaba form through :meth:`MRPFeedback.wheel_command`.

One definition
--------------
:func:`mrp_short` (σ from a rotation matrix, inside the kernels), :func:`mrp_feedback_command`
(L and u from the state) and :func:`mrp_wheel_control` (the controller's wrench and ż,
:data:`~gmuk.control.base.CONTROL_KERNEL`) are numba kernels; :meth:`MRPFeedback.control`,
:meth:`MRPFeedback.wheel_command` and the compiled step loop call them.

References
----------
Schaub, H. and Junkins, J. L., *Analytical Mechanics of Space Systems*, 4th ed., AIAA, 2018,
§3.7 (MRPs and their shadow set), §8.4 (MRP feedback with reaction wheels).
Basilisk ``mrpFeedback`` and ``rwMotorTorque`` modules (fswAlgorithms), version 2.12.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, check_rotation, real_number, real_vector
from gmuk.actuators.wheels import (
    ReactionWheel,
    WheelArray,
    _inertia,
    wheel_array_torque,
    wheel_spin_torque,
)
from gmuk.bodies import BodyKind, RigidBody
from gmuk.control.base import Controller
from gmuk.errors import DefinitionError

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = [
    "MRPFeedback",
    "mrp_feedback_command",
    "mrp_short",
    "mrp_wheel_control",
]

#: Parameters before the wheels: [n, K, P, K_I, integral_limit, I_B (9), R_NR (9)].
_HEAD = 23
#: Parameters per wheel: [g (3), J_s, u_max, Ω_max, c, row i of Gᵀ(GGᵀ)⁻¹ (3)].
_PER_WHEEL = 10


@njit(cache=True)
def mrp_short(R, sigma):  # type: ignore[no-untyped-def]
    """The short-set MRPs σ (‖σ‖ ≤ 1) of the rotation R (3, 3), written into sigma (3,):
    R = R_NB gives σ_BN (:func:`gmuk.attitude.mrp_from_R_NB`). Shepperd's quaternion with
    q₀ ≥ 0, then σ = q / (1 + q₀)."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    if tr >= R[0, 0] and tr >= R[1, 1] and tr >= R[2, 2]:
        q0 = 0.5 * np.sqrt(1.0 + tr)
        f = 0.25 / q0
        q1 = (R[2, 1] - R[1, 2]) * f
        q2 = (R[0, 2] - R[2, 0]) * f
        q3 = (R[1, 0] - R[0, 1]) * f
    elif R[0, 0] >= R[1, 1] and R[0, 0] >= R[2, 2]:
        q1 = 0.5 * np.sqrt(1.0 + 2.0 * R[0, 0] - tr)
        f = 0.25 / q1
        q0 = (R[2, 1] - R[1, 2]) * f
        q2 = (R[0, 1] + R[1, 0]) * f
        q3 = (R[0, 2] + R[2, 0]) * f
    elif R[1, 1] >= R[2, 2]:
        q2 = 0.5 * np.sqrt(1.0 + 2.0 * R[1, 1] - tr)
        f = 0.25 / q2
        q0 = (R[0, 2] - R[2, 0]) * f
        q1 = (R[0, 1] + R[1, 0]) * f
        q3 = (R[1, 2] + R[2, 1]) * f
    else:
        q3 = 0.5 * np.sqrt(1.0 + 2.0 * R[2, 2] - tr)
        f = 0.25 / q3
        q0 = (R[1, 0] - R[0, 1]) * f
        q1 = (R[0, 2] + R[2, 0]) * f
        q2 = (R[1, 2] + R[2, 1]) * f
    if q0 < 0.0:
        q0, q1, q2, q3 = -q0, -q1, -q2, -q3
    d = 1.0 + q0
    sigma[0] = q1 / d
    sigma[1] = q2 / d
    sigma[2] = q3 / d


@njit(cache=True)
def mrp_feedback_command(R_NB, omega, h, s_int, p, sigma, L, u_cmd):  # type: ignore[no-untyped-def]
    """The law of the module docstring at one state: σ_BR into sigma (3,), the commanded
    body torque L (3,) (N·m) and the motor commands u_cmd (n,) (N·m), from R_NB (3, 3), the
    bus's ω (3,) (rad/s), the wheels' absolute spin momenta h (n,) (N·m·s), the integral
    s_int = ∫ K σ dt (3,) and the packed parameters p (:meth:`MRPFeedback._params`)."""
    n = int(p[0])
    K, P, KI = p[1], p[2], p[3]
    # R_RB = R_NRᵀ R_NB
    R_RB = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for k in range(3):
                acc += p[14 + 3 * k + i] * R_NB[k, j]
            R_RB[i, j] = acc
    mrp_short(R_RB, sigma)
    H = np.empty(3)
    for i in range(3):
        H[i] = p[5 + 3 * i] * omega[0] + p[6 + 3 * i] * omega[1] + p[7 + 3 * i] * omega[2]
    for w in range(n):
        b = _HEAD + _PER_WHEEL * w
        # J_s Ω g with Ω = h / J_s − g·ω
        gw = p[b] * omega[0] + p[b + 1] * omega[1] + p[b + 2] * omega[2]
        hs = h[w] - p[b + 3] * gw
        H[0] += hs * p[b]
        H[1] += hs * p[b + 1]
        H[2] += hs * p[b + 2]
    zI = np.zeros(3)
    if KI > 0.0:
        for i in range(3):
            zI[i] = s_int[i] + (
                p[5 + 3 * i] * omega[0] + p[6 + 3 * i] * omega[1] + p[7 + 3 * i] * omega[2]
            )
    L[0] = -K * sigma[0] - P * omega[0] - P * KI * zI[0] + (omega[1] * H[2] - omega[2] * H[1])
    L[1] = -K * sigma[1] - P * omega[1] - P * KI * zI[1] + (omega[2] * H[0] - omega[0] * H[2])
    L[2] = -K * sigma[2] - P * omega[2] - P * KI * zI[2] + (omega[0] * H[1] - omega[1] * H[0])
    for w in range(n):
        b = _HEAD + _PER_WHEEL * w + 7
        u_cmd[w] = -(p[b] * L[0] + p[b + 1] * L[1] + p[b + 2] * L[2])


@njit(cache=True)
def mrp_wheel_control(t, g, V, a_model, z, p, u, z_dot):  # type: ignore[no-untyped-def]
    """The controller's wrench u = [L_w; 0] on the bus (N·m, body frame) and ż = [ḣ; K σ]
    (:data:`~gmuk.control.base.CONTROL_KERNEL`): the law's motor commands through each wheel's
    motor (:func:`~gmuk.actuators.wheels.wheel_spin_torque`), then the wheels' torque on the bus
    (:func:`~gmuk.actuators.wheels.wheel_array_torque`). Returns 0."""
    n = int(p[0])
    K, limit = p[1], p[4]
    R_NB = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R_NB[i, j] = g[i, j]
    omega = np.empty(3)
    for i in range(3):
        omega[i] = V[i]
    h = np.empty(n)
    for w in range(n):
        h[w] = z[w]
    s_int = np.empty(3)
    for i in range(3):
        s_int[i] = z[n + i]
    sigma, L, u_cmd = np.empty(3), np.empty(3), np.empty(n)
    mrp_feedback_command(R_NB, omega, h, s_int, p, sigma, L, u_cmd)
    G = np.empty((3, n))
    h_dot = np.empty(n)
    for w in range(n):
        b = _HEAD + _PER_WHEEL * w
        G[0, w], G[1, w], G[2, w] = p[b], p[b + 1], p[b + 2]
        speed = h[w] / p[b + 3] - (p[b] * omega[0] + p[b + 1] * omega[1] + p[b + 2] * omega[2])
        h_dot[w] = wheel_spin_torque(u_cmd[w], speed, p[b + 4], p[b + 5], p[b + 6])
    Lw = np.empty(3)
    wheel_array_torque(omega, h, G, h_dot, Lw)
    for i in range(3):
        u[i] = Lw[i]
        u[3 + i] = 0.0
    for w in range(n):
        z_dot[w] = h_dot[w]
    for i in range(3):
        rate = 0.0
        if p[3] > 0.0:
            rate = K * sigma[i]
            if abs(s_int[i]) >= limit and s_int[i] * rate > 0.0:
                rate = 0.0
        z_dot[n + i] = rate
    return 0


class MRPFeedback(Controller):
    """MRP feedback (proportional–derivative, optional integral) on reaction wheels.

    The law, the wheel mapping and the internal-momentum form are in the module docstring.

    Parameters
    ----------
    body : RigidBody or str
        The bus, with the inertia ``I_B − Σ J_s g gᵀ`` (checked when a RigidBody is given).
    wheels : WheelArray or sequence of ReactionWheel
        The wheels; their axes must span R³ (G Gᵀ invertible).
    K : float
        Attitude gain (N·m, > 0).
    P : float
        Rate gain (N·m·s, > 0).
    inertia_B : array_like, shape (3, 3)
        The whole spacecraft's inertia with the wheels locked, I_B (kg·m², body frame): the
        controller's knowledge (Basilisk's vehicle configuration).
    K_I : float
        Integral gain (1/s, ≥ 0; default 0: no integral term).
    integral_limit : float
        Bound on each component of ∫ K σ dt (N·m·s, > 0; default inf).
    R_NR : array_like, shape (3, 3), optional
        The constant reference attitude (default identity: inertial pointing, σ_RN = 0).
    name : str, optional

    Notes
    -----
    Internal states z = [h (n), ∫ K σ dt (3)]: the wheels' absolute spin momenta (N·m·s)
    and the integral. :meth:`states` builds them from the bus rate and the wheel speeds. The
    compiled step loop runs this controller when it has three wheels (the loop passes each
    compiled controller six states); with other counts it is called back in Python.
    """

    body_kinds = frozenset({BodyKind.RIGID})
    _forms = Forms(compiled=True, symbolic="gmuk.optimize transcribes no controller")

    def __init__(
        self,
        body: Body | str,
        wheels: WheelArray | Sequence[ReactionWheel],
        *,
        K: float,
        P: float,
        inertia_B: Any,
        K_I: float = 0.0,
        integral_limit: float = np.inf,
        R_NR: Any = None,
        name: str | None = None,
    ) -> None:
        wheels = WheelArray(wheels)
        super().__init__([body], n_states=len(wheels) + 3, name=name)
        self.wheels = wheels
        self.K = real_number(K, "MRPFeedback K", positive=True)
        self.P = real_number(P, "MRPFeedback P", positive=True)
        self.K_I = real_number(K_I, "MRPFeedback K_I", non_negative=True)
        self.integral_limit = real_number(
            integral_limit, "MRPFeedback integral_limit", positive=True, allow_inf=True
        )
        self.inertia_B = _inertia(inertia_B, "MRPFeedback inertia_B")
        self.R_NR = np.eye(3) if R_NR is None else check_rotation(R_NR, "MRPFeedback R_NR")
        G = wheels.G
        GGt = G @ G.T
        if np.linalg.matrix_rank(GGt) < 3:
            raise DefinitionError(
                "MRPFeedback needs wheel axes that span R³ (G Gᵀ invertible); got axes "
                f"{G.T.tolist()}"
            )
        self._pinv = G.T @ np.linalg.inv(GGt)  # (n, 3): u = −pinv L
        if isinstance(body, RigidBody):
            expected = wheels.spun_down_inertia(self.inertia_B)
            if not np.allclose(
                body.inertia, expected, rtol=0.0, atol=1e-9 * np.abs(expected).max()
            ):
                raise DefinitionError(
                    f"MRPFeedback: the bus {body.name!r} must have the inertia I_B − Σ J_s g gᵀ "
                    f"= {expected.tolist()} (WheelArray.spun_down_inertia) in the "
                    f"internal-momentum form; got {body.inertia.tolist()}"
                )

    def _params(self) -> FloatArray:
        w = self.wheels
        per = [
            [*w.G[:, i], w.J_s[i], w.u_max[i], w.Omega_max[i], w.friction[i], *self._pinv[i]]
            for i in range(len(w))
        ]
        return np.array(
            [
                len(w),
                self.K,
                self.P,
                self.K_I,
                self.integral_limit,
                *np.ravel(self.inertia_B),
                *np.ravel(self.R_NR),
                *np.ravel(per),
            ],
            dtype=float,
        )

    def states(self, omega_BN_B: Any, wheel_speeds: Any, integral: Any = None) -> FloatArray:
        """Internal states z = [h (n), ∫ K σ dt (3)] for the bus rate ω_BN_B (3,) (rad/s), the
        wheel speeds relative to the bus (n,) (rad/s) and the integral (3,) (default 0)."""
        s = np.zeros(3) if integral is None else real_vector(integral, "integral", 3)
        return np.concatenate([self.wheels.momenta(omega_BN_B, wheel_speeds), s])

    def initial_state(self) -> FloatArray:
        """Zeros: wheels at rest in inertial space. Use :meth:`states` for spinning wheels."""
        return np.zeros(self.n_states)

    def control(
        self, state: State, z: FloatArray, *modeled: FloatArray
    ) -> tuple[list[FloatArray], FloatArray]:
        """The wheels' wrench [L_w; 0] on the bus (N·m, body frame) and ż = [ḣ; K σ]
        (:func:`mrp_wheel_control`)."""
        (body,) = self.bodies
        g = np.array(state.pose(body), dtype=float)
        V = np.array(state.twist(body), dtype=float)
        u, z_dot = np.empty(6), np.empty(self.n_states)
        mrp_wheel_control(
            float(state.t), g, V, np.zeros(6), np.array(z, dtype=float), self._params(), u, z_dot
        )
        return [u], z_dot

    def command(
        self, R_NB: Any, omega_BN_B: Any, momenta: Any, integral: Any = None
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The law at one state: (σ_BR (3,), commanded body torque L (3,) (N·m), motor
        commands u_cmd (n,) (N·m), before the motors' limits) from R_NB (3, 3), ω_BN_B (3,)
        (rad/s), the wheels' absolute spin momenta (n,) (N·m·s) and ∫ K σ dt (3,)."""
        n = len(self.wheels)
        R = check_rotation(R_NB, "R_NB")
        w = real_vector(omega_BN_B, "omega_BN_B", 3)
        h = real_vector(momenta, "momenta", n)
        s = np.zeros(3) if integral is None else real_vector(integral, "integral", 3)
        sigma, L, u = np.empty(3), np.empty(3), np.empty(n)
        mrp_feedback_command(np.ascontiguousarray(R), w, h, s, self._params(), sigma, L, u)
        return sigma, L, u

    def wheel_command(self, t: float, R_NB: Any, omega_BN_B: Any, wheel_speeds: Any) -> FloatArray:
        """Motor commands u_cmd (n,) (N·m) for the Udwadia–Kalaba form's
        :class:`~gmuk.actuators.WheelMotors`: the law at the bus attitude R_NB, rate
        ω_BN_B and wheel speeds relative to the bus (rad/s). The UK form carries no
        controller state, so the integral term is not available there."""
        if self.K_I > 0.0:
            raise DefinitionError(
                "MRPFeedback.wheel_command carries no integral state: use K_I = 0 with the "
                f"Udwadia–Kalaba form (got K_I = {self.K_I!r}), or the internal-momentum form"
            )
        h = self.wheels.momenta(omega_BN_B, wheel_speeds)
        return self.command(R_NB, omega_BN_B, h)[2]

    def _compiled_term(self) -> tuple[Any, FloatArray] | None:
        """:func:`mrp_wheel_control` and its parameters, when there are three wheels (the
        compiled loop passes a controller six states) and ``control`` is this class's."""
        if not self._methods_are(MRPFeedback) or len(self.wheels) != 3:
            return None
        return mrp_wheel_control, self._params()
