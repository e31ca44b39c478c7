"""Reaction wheels: a spin axis, a spin inertia, a motor with torque and speed limits and
viscous friction, in two forms that give the same motion.

The wheel
---------
A :class:`ReactionWheel` spins about its unit axis ``g_B`` (fixed in the bus frame B) at
``Ω`` (rad/s) *relative to the bus*. Its spin inertia is ``J_s`` and its transverse inertia
``J_t`` (kg·m²); it is balanced (its centre of mass on the axis, at the bus's centre of mass:
it does not move the composite centre of mass, and its offset would only add a constant
parallel-axis term to the locked inertia). Its absolute spin momentum is
``h = J_s (g·ω + Ω)`` (N·m·s), with ω the bus's angular velocity. The motor's torque on the
wheel is the command ``u_cmd`` clipped to ``±u_max``, set to zero when ``|Ω| ≥ Ω_max`` and the
torque would spin the wheel faster (Basilisk's ``ReactionWheelStateEffector`` rules); viscous
friction adds ``−c Ω``. The net spin torque is therefore

``ḣ = sat(u_cmd, Ω) − c Ω``      (:func:`wheel_spin_torque`).

With ``I_B`` the inertia of the whole spacecraft with its wheels locked (each wheel's spin
inertia included), the total angular momentum about the centre of mass is
``H_B = I_B ω + Σ J_s Ω_i g_i = I_w ω + Σ h_i g_i`` with ``I_w = I_B − Σ J_s g_i g_iᵀ``.

Two forms
---------
*Udwadia–Kalaba form* (:class:`WheelMotors` with :meth:`WheelArray.uk_parts`): each wheel is
a :class:`~gmuk.RigidBody` of inertia ``diag(J_s, J_t, J_t)`` in a frame whose first axis is
g, tied to the bus by a :class:`~gmuk.RelativeConstraint` that leaves only the relative spin
about that axis free; the bus is a RigidBody of inertia
``I_B − Σ (J_s g gᵀ + J_t (I − g gᵀ))``. The motor torque is a modeled force: the pair
``+ḣ`` about the wheel's axis on the wheel and ``−ḣ g`` on the bus, so the Udwadia–Kalaba
solve sees it and returns the exact internal (bearing) torques that keep the wheel on its
axis. Nothing in this form knows of gyroscopic coupling: it comes out of the constrained
rigid-body equations.

*Internal-momentum form* (:class:`gmuk.actuators.MomentumWheels` under any wheel command,
:class:`gmuk.control.MRPFeedback` with its law compiled in): the bus alone is a
RigidBody of inertia ``I_w`` and the wheels' momenta h are internal states of a controller;
the wheels act on the bus through the torque

``L_w = −ω × Σ h_i g_i − Σ g_i ḣ_i``      (:func:`wheel_array_torque`),

which is Euler's equation of the whole spacecraft, ``d/dt(I_w ω + G h) + ω × (I_w ω + G h) = 0``,
solved for the bus. Three bodies fewer and no constraint rows: the fast form.

Why the motor torque is a force model in the UK form: a controller's wrench in gmuk acts on
the plant after the Udwadia–Kalaba solve, which does not see it (McCann 2020, Chapter 5). A
torque pair between two constrained bodies applied there would push them off the
constraint; as a modeled force it is part of the solve. The command itself is still a
controller's output (:meth:`gmuk.control.MRPFeedback.wheel_command`).

References
----------
Schaub, H. and Junkins, J. L., *Analytical Mechanics of Space Systems*, 4th ed., AIAA, 2018,
§4.5 (spacecraft with reaction wheels: ``H = [I_RW] ω + [G_s] h_s``, Eq. 4.146 ff.).
Basilisk ``ReactionWheelStateEffector`` (balanced wheels: torque and speed saturation).
McCann (2020), Eq. (73) and Section 4.1.3 (the relative-twist constraint).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, real_number, real_vector
from gmuk.bodies import BodyKind, RigidBody
from gmuk.constraints.relative import RelativeConstraint
from gmuk.errors import DefinitionError, ShapeError
from gmuk.forces.base import ForceModel

if TYPE_CHECKING:
    from gmuk.bodies import Body
    from gmuk.state import State

__all__ = [
    "AXIS_TOL",
    "ReactionWheel",
    "WheelArray",
    "WheelMotors",
    "wheel_array_torque",
    "wheel_spin_torque",
]

#: How far from 1 the norm of a wheel's spin axis may be (it is then normalised).
AXIS_TOL = 1e-9


@njit(cache=True)
def wheel_spin_torque(u_cmd, Omega, u_max, Omega_max, c):  # type: ignore[no-untyped-def]
    """Net spin torque ḣ (N·m) on a wheel: the motor command ``u_cmd`` (N·m) clipped to
    ``±u_max``, zero when ``|Ω| ≥ Ω_max`` and ``Ω u ≥ 0`` (the torque would spin it past its
    speed limit), minus viscous friction ``c Ω`` (Ω relative to the bus, rad/s). The one
    definition of the wheel's motor, used by both forms."""
    u = u_cmd
    if u > u_max:
        u = u_max
    elif u < -u_max:
        u = -u_max
    if abs(Omega) >= Omega_max and Omega * u >= 0.0:
        u = 0.0
    return u - c * Omega


@njit(cache=True)
def wheel_array_torque(omega, h, G, h_dot, L):  # type: ignore[no-untyped-def]
    """The wheels' torque on the bus in the internal-momentum form,
    ``L = −ω × (G h) − G ḣ`` (N·m, bus frame), written into L (3,): ω (3,) the bus's angular
    velocity (rad/s), h (n,) the wheels' absolute spin momenta and ḣ (n,) their rates, G
    (3, n) the spin axes in B."""
    hw0 = 0.0
    hw1 = 0.0
    hw2 = 0.0
    d0 = 0.0
    d1 = 0.0
    d2 = 0.0
    for i in range(h.shape[0]):
        hw0 += G[0, i] * h[i]
        hw1 += G[1, i] * h[i]
        hw2 += G[2, i] * h[i]
        d0 += G[0, i] * h_dot[i]
        d1 += G[1, i] * h_dot[i]
        d2 += G[2, i] * h_dot[i]
    L[0] = -(omega[1] * hw2 - omega[2] * hw1) - d0
    L[1] = -(omega[2] * hw0 - omega[0] * hw2) - d1
    L[2] = -(omega[0] * hw1 - omega[1] * hw0) - d2


class ReactionWheel:
    """One balanced reaction wheel (a description; it holds no state).

    Parameters
    ----------
    axis_B : array_like, shape (3,)
        Spin axis g in the bus frame B, unit to :data:`AXIS_TOL` (then normalised).
    spin_inertia : float
        J_s about the spin axis (kg·m², > 0).
    max_torque : float
        Motor torque limit u_max (N·m, > 0; default inf: no limit).
    max_speed : float
        Speed limit Ω_max relative to the bus (rad/s, > 0; default inf): beyond it the motor
        gives no torque that would spin the wheel faster.
    friction : float
        Viscous friction coefficient c (N·m·s/rad, ≥ 0; default 0): torque −c Ω.
    transverse_inertia : float, optional
        J_t about any axis ⟂ g through its centre (kg·m², > 0; default J_s / 2, a thin
        disc). Only the Udwadia–Kalaba form sees it (the internal-momentum form locks it to
        the bus, where it is part of I_B).
    mass : float
        Mass (kg, > 0; default 1): the Udwadia–Kalaba form's wheel body needs one; it does
        not enter the attitude motion (the wheel sits at the bus's centre of mass).
    name : str, optional

    Examples
    --------
    >>> import numpy as np
    >>> w = ReactionWheel([1, 0, 0], 50 / (6000 * 2 * np.pi / 60), max_torque=0.2)
    >>> round(w.spin_inertia, 6)
    0.079577
    """

    def __init__(
        self,
        axis_B: Any,
        spin_inertia: float,
        *,
        max_torque: float = np.inf,
        max_speed: float = np.inf,
        friction: float = 0.0,
        transverse_inertia: float | None = None,
        mass: float = 1.0,
        name: str | None = None,
    ) -> None:
        g = real_vector(axis_B, "ReactionWheel axis_B", 3)
        norm = float(np.linalg.norm(g))
        if abs(norm - 1.0) > AXIS_TOL:
            raise DefinitionError(
                f"ReactionWheel axis_B must be a unit vector (|g| = 1 to {AXIS_TOL:g}); got "
                f"{g.tolist()} with |g| = {norm!r}"
            )
        self.axis_B: FloatArray = g / norm
        self.axis_B.setflags(write=False)
        self.spin_inertia = real_number(spin_inertia, "ReactionWheel spin_inertia", positive=True)
        self.max_torque = real_number(
            max_torque, "ReactionWheel max_torque", positive=True, allow_inf=True
        )
        self.max_speed = real_number(
            max_speed, "ReactionWheel max_speed", positive=True, allow_inf=True
        )
        self.friction = real_number(friction, "ReactionWheel friction", non_negative=True)
        self.transverse_inertia = (
            0.5 * self.spin_inertia
            if transverse_inertia is None
            else real_number(transverse_inertia, "ReactionWheel transverse_inertia", positive=True)
        )
        self.mass = real_number(mass, "ReactionWheel mass", positive=True)
        self.name = name
        self._frozen = True

    def __setattr__(self, key: str, value: Any) -> None:
        if getattr(self, "_frozen", False):
            raise AttributeError(
                f"a ReactionWheel is immutable; build a new one instead of setting {key!r}"
            )
        object.__setattr__(self, key, value)

    def spin_torque(self, command: float, speed: float) -> float:
        """Net spin torque ḣ (N·m) for a motor ``command`` (N·m) at relative ``speed`` Ω
        (rad/s): :func:`wheel_spin_torque`."""
        u = real_number(command, "command")
        w = real_number(speed, "speed")
        return float(wheel_spin_torque(u, w, self.max_torque, self.max_speed, self.friction))

    def frame_B(self) -> FloatArray:
        """R_BW (3, 3): a wheel frame W whose first axis is g, the other two completing a
        right-handed orthonormal triad (the Udwadia–Kalaba form's wheel body frame at Ω t = 0)."""
        g = self.axis_B
        trial = np.eye(3)[int(np.argmin(np.abs(g)))]
        y = np.cross(g, trial)
        y /= np.linalg.norm(y)
        return np.column_stack([g, y, np.cross(g, y)])

    def __repr__(self) -> str:
        return (
            f"ReactionWheel(axis_B={self.axis_B.tolist()}, spin_inertia={self.spin_inertia!r}, "
            f"max_torque={self.max_torque!r}, max_speed={self.max_speed!r}, "
            f"friction={self.friction!r})"
        )


class WheelArray(Sequence[ReactionWheel]):
    """The wheels of one spacecraft, with the arrays both forms use.

    Parameters
    ----------
    wheels : sequence of ReactionWheel
        At least one.

    Attributes
    ----------
    G : ndarray (3, n)
        Spin axes g_i in B, one column per wheel.
    J_s, u_max, Omega_max, friction : ndarray (n,)
        Spin inertias (kg·m²), torque limits (N·m), speed limits (rad/s), viscous
        coefficients (N·m·s/rad).
    """

    def __init__(self, wheels: Sequence[ReactionWheel] | WheelArray) -> None:
        wheels = tuple(wheels)
        if not wheels or not all(isinstance(w, ReactionWheel) for w in wheels):
            raise DefinitionError(
                "a WheelArray takes one or more gmuk.actuators.ReactionWheel; got "
                f"{[type(w).__name__ for w in wheels]}"
            )
        self._wheels = wheels
        self.G = np.column_stack([w.axis_B for w in wheels])
        self.J_s = np.array([w.spin_inertia for w in wheels])
        self.u_max = np.array([w.max_torque for w in wheels])
        self.Omega_max = np.array([w.max_speed for w in wheels])
        self.friction = np.array([w.friction for w in wheels])
        for a in (self.G, self.J_s, self.u_max, self.Omega_max, self.friction):
            a.setflags(write=False)

    def __len__(self) -> int:
        return len(self._wheels)

    def __getitem__(self, i: Any) -> Any:
        return self._wheels[i]

    def __iter__(self) -> Iterator[ReactionWheel]:
        return iter(self._wheels)

    def _speeds(self, wheel_speeds: Any) -> FloatArray:
        return real_vector(wheel_speeds, "wheel_speeds", len(self))

    def momenta(self, omega_B: Any, wheel_speeds: Any) -> FloatArray:
        """Absolute spin momenta ``h_i = J_s,i (g_i·ω + Ω_i)`` (n,) (N·m·s) from the bus's
        angular velocity ω_B (3,) (rad/s) and the speeds Ω (n,) relative to the bus (rad/s)."""
        w = real_vector(omega_B, "omega_B", 3)
        return self.J_s * (self.G.T @ w + self._speeds(wheel_speeds))

    def speeds(self, omega_B: Any, momenta: Any) -> FloatArray:
        """Speeds relative to the bus ``Ω_i = h_i / J_s,i − g_i·ω`` (n,) (rad/s)."""
        w = real_vector(omega_B, "omega_B", 3)
        h = real_vector(momenta, "momenta", len(self))
        return h / self.J_s - self.G.T @ w

    def spun_down_inertia(self, inertia_B: Any) -> FloatArray:
        """``I_w = I_B − Σ J_s g gᵀ`` (3, 3) (kg·m²): the bus inertia of the internal-momentum
        form, from the locked inertia I_B of the whole spacecraft."""
        I_B = _inertia(inertia_B, "inertia_B")
        return I_B - (self.G * self.J_s) @ self.G.T

    def uk_bus_inertia(self, inertia_B: Any) -> FloatArray:
        """``I_B − Σ (J_s g gᵀ + J_t (I − g gᵀ))`` (3, 3) (kg·m²): the bus body's own inertia in
        the Udwadia–Kalaba form, every wheel's whole inertia taken out of the locked I_B."""
        I_B = _inertia(inertia_B, "inertia_B")
        out = I_B.copy()
        for w in self:
            gg = np.outer(w.axis_B, w.axis_B)
            out -= w.spin_inertia * gg + w.transverse_inertia * (np.eye(3) - gg)
        return out

    def angular_momentum_B(self, inertia_B: Any, omega_B: Any, wheel_speeds: Any) -> FloatArray:
        """``H_B = I_B ω + Σ J_s Ω_i g_i`` (3,) (N·m·s, bus frame) about the centre of mass."""
        I_B = _inertia(inertia_B, "inertia_B")
        w = real_vector(omega_B, "omega_B", 3)
        return I_B @ w + self.G @ (self.J_s * self._speeds(wheel_speeds))

    # ------------------------------------------------------------ the Udwadia–Kalaba form

    def uk_parts(
        self, bus: RigidBody, *, prefix: str | None = None
    ) -> tuple[list[RigidBody], list[RelativeConstraint]]:
        """The wheel bodies and their constraints for the Udwadia–Kalaba form.

        Parameters
        ----------
        bus : RigidBody
            The bus, whose inertia should be :meth:`uk_bus_inertia` of the locked I_B.
        prefix : str, optional
            Wheel body names are ``f"{prefix}{i}"`` (default ``f"{bus.name}.wheel"``).

        Returns
        -------
        wheels : list of RigidBody
            Inertia ``diag(J_s, J_t, J_t)`` in the wheel frame of :meth:`ReactionWheel.frame_B`.
        constraints : list of RelativeConstraint
            Each wheel relative to the bus, free about its first axis only (``free_axes=[0]``).
        """
        if not isinstance(bus, RigidBody):
            raise DefinitionError(f"bus must be a gmuk.RigidBody; got {type(bus).__name__}")
        prefix = f"{bus.name}.wheel" if prefix is None else prefix
        bodies = [
            RigidBody(
                f"{prefix}{i}",
                w.mass,
                np.diag([w.spin_inertia, w.transverse_inertia, w.transverse_inertia]),
            )
            for i, w in enumerate(self)
        ]
        constraints = [
            RelativeConstraint(b, bus, free_axes=[0], name=f"{b.name} bearing") for b in bodies
        ]
        return bodies, constraints

    def uk_state(
        self,
        wheel_bodies: Sequence[RigidBody],
        g_NB: Any,
        V_B: Any,
        wheel_speeds: Any,
    ) -> tuple[dict[str, FloatArray], dict[str, FloatArray]]:
        """Poses and twists of the Udwadia–Kalaba form's wheel bodies for a bus at pose g_NB
        (4, 4) with twist V_B (6,), wheels at relative speeds Ω (n,) (rad/s): (g, V) dicts
        by body name for :meth:`gmuk.System.state`. Each wheel sits at the bus's origin
        with its frame :meth:`ReactionWheel.frame_B`; its twist is
        ``[R_BWᵀ ω + Ω e₁; R_BWᵀ v]``."""
        g_NB = np.asarray(g_NB, dtype=float)
        V_B = real_vector(V_B, "V_B", 6)
        speeds = self._speeds(wheel_speeds)
        if g_NB.shape != (4, 4):
            raise ShapeError(f"g_NB must have shape (4, 4); got {g_NB.shape}")
        if len(wheel_bodies) != len(self):
            raise DefinitionError(
                f"uk_state needs one wheel body per wheel ({len(self)}); got {len(wheel_bodies)}"
            )
        g, V = {}, {}
        for w, body, speed in zip(self, wheel_bodies, speeds, strict=True):
            R_BW = w.frame_B()
            pose = np.eye(4)
            pose[:3, :3] = g_NB[:3, :3] @ R_BW
            pose[:3, 3] = g_NB[:3, 3]
            twist = np.concatenate([R_BW.T @ V_B[:3], R_BW.T @ V_B[3:]])
            twist[0] += speed
            g[body.name], V[body.name] = pose, twist
        return g, V


def _inertia(value: Any, name: str) -> FloatArray:
    """A finite symmetric (3, 3) matrix."""
    J = np.asarray(value, dtype=float)
    if J.shape != (3, 3) or not np.isfinite(J).all():
        raise DefinitionError(f"{name} must be a finite (3, 3) matrix (kg·m²); got {value!r}")
    if not np.allclose(J, J.T, rtol=0.0, atol=1e-12 * max(1.0, float(np.abs(J).max()))):
        raise DefinitionError(f"{name} must be symmetric; got {J.tolist()}")
    return J


#: A wheel command: ``(t, R_NB (3, 3), ω_BN_B (3,), Ω (n,)) -> u_cmd (n,)`` (N·m).
WheelCommand = Callable[[float, FloatArray, FloatArray, FloatArray], Any]


class WheelMotors(ForceModel):
    """The motor torques of the Udwadia–Kalaba form: on each wheel ``+ḣ_i`` about its spin
    axis, on the bus ``−ḣ_i g_i``, with ``ḣ_i`` = :func:`wheel_spin_torque` of the command.

    A modeled force, so the Udwadia–Kalaba solve accounts for it and returns the bearing
    torques that keep each wheel on its axis (module docstring). The wheel's axis on the bus
    and its speed relative to the bus are read from the actual poses and twists, so the pair
    is equal and opposite at every state and the total angular momentum is conserved
    whatever the constraint drift.

    Parameters
    ----------
    bus : RigidBody or str
    wheel_bodies : sequence of RigidBody or str
        The wheel bodies of :meth:`WheelArray.uk_parts`, one per wheel, in order.
    wheels : WheelArray or sequence of ReactionWheel
    command : callable
        The wheel command, ``command(t, R_NB, omega_BN_B, wheel_speeds) -> u_cmd (n,)``
        (N·m): a controller's output, e.g. :meth:`gmuk.control.MRPFeedback.wheel_command`;
        None for motors that give no torque (friction only).
    name : str, optional
    """

    acts_on = frozenset({BodyKind.RIGID})
    _forms = Forms(
        compiled="couples the bus and its wheels: called back from the compiled loop",
        symbolic="gmuk.optimize transcribes no reaction wheel",
    )

    def __init__(
        self,
        bus: Body | str,
        wheel_bodies: Sequence[Body | str],
        wheels: WheelArray | Sequence[ReactionWheel],
        command: WheelCommand | None = None,
        *,
        name: str | None = None,
    ) -> None:
        wheels = WheelArray(wheels)
        if isinstance(wheel_bodies, str) or len(wheel_bodies) != len(wheels):
            raise DefinitionError(
                f"WheelMotors needs one wheel body per wheel ({len(wheels)}); got {wheel_bodies!r}"
            )
        if command is not None and not callable(command):
            raise DefinitionError(
                "WheelMotors command must be callable (t, R_NB, omega_BN_B, wheel_speeds) -> "
                f"(n,) torques, or None; got {type(command).__name__}"
            )
        super().__init__([bus, *wheel_bodies], name=name)
        self.wheels = wheels
        self.command = command

    def wheel_speeds(self, state: State) -> FloatArray:
        """Speeds Ω (n,) of the wheels relative to the bus (rad/s) at ``state``."""
        return self._geometry(state)[2]

    def _geometry(self, state: State) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """(R_NB, ω_B, Ω (n,), axes (3, n): each wheel's first axis in B) at ``state``."""
        bus, *wheels = self.bodies  # type: ignore[misc]
        g_NB = state.pose(bus)
        R_NB, omega_B = g_NB[:3, :3], state.twist(bus)[:3]
        n = len(self.wheels)
        speeds, axes = np.empty(n), np.empty((3, n))
        for i, wb in enumerate(wheels):
            R_BW = R_NB.T @ state.pose(wb)[:3, :3]
            axes[:, i] = R_BW[:, 0]
            speeds[i] = state.twist(wb)[0] - axes[:, i] @ omega_B
        return R_NB, omega_B, speeds, axes

    def spin_torques(self, state: State) -> FloatArray:
        """Net spin torques ḣ (n,) (N·m) on the wheels at ``state``."""
        R_NB, omega_B, speeds, _ = self._geometry(state)
        return self._spin_torques(state.t, R_NB, omega_B, speeds)

    def _spin_torques(
        self, t: float, R_NB: FloatArray, omega_B: FloatArray, speeds: FloatArray
    ) -> FloatArray:
        n = len(self.wheels)
        if self.command is None:
            u = np.zeros(n)
        else:
            u = np.asarray(self.command(t, R_NB, omega_B, speeds), dtype=float)
            if u.shape != (n,):
                raise ShapeError(
                    f"{self.name}: the wheel command returned shape {u.shape}; expected ({n},)"
                )
        w = self.wheels
        return np.array(
            [
                wheel_spin_torque(
                    float(u[i]), float(speeds[i]), w.u_max[i], w.Omega_max[i], w.friction[i]
                )
                for i in range(n)
            ]
        )

    def wrenches(self, state: State, bodies: Sequence[Body]) -> list[FloatArray]:
        """[L; 0] on the bus (−Σ ḣ_i g_i) and on each wheel (ḣ_i e₁), body frames (N·m)."""
        R_NB, omega_B, speeds, axes = self._geometry(state)
        h_dot = self._spin_torques(state.t, R_NB, omega_B, speeds)
        out = [np.zeros(6) for _ in bodies]
        out[0][:3] = -(axes @ h_dot)
        for i in range(len(self.wheels)):
            out[1 + i][0] = h_dot[i]
        return out
