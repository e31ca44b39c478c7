"""Thrusters: on–off valves with a thrust, a specific impulse, a minimum impulse bit and an
on-time quantum, the propellant they spend, and the wrench they give a spacecraft whose mass
goes down as they fire.

The thruster
------------
A :class:`Thruster` sits at ``r`` (m, body frame B, from the centre of mass) and pushes the
spacecraft along the unit vector ``d`` (B; the exhaust leaves along −d) with its full thrust
``F_max`` (N) while its valve is open, nothing while it is shut. Its wrench on the spacecraft
per newton is the column ``b = [r × d; d]`` (torque; force), so a set of n thrusters at
thrusts f (n,) gives ``W = B f`` with ``B = [b_1 … b_n]`` (6, n) (:class:`ThrusterSet`). It
spends propellant at ``ṁ = F / (I_sp g₀)`` (kg/s) with its specific impulse I_sp (s) and
g₀ = 9.80665 m/s² (:data:`G0`).

From a commanded wrench to valve times
--------------------------------------
Flight software does it in three steps, once per control period Δt
(:func:`simulate_pulsed`):

1. *allocation* (:meth:`ThrusterSet.allocate`): the thrusts ``0 ≤ f ≤ F_max`` whose wrench
   is closest to the command, ``min ‖D (B f − W_cmd)‖`` (a bounded least-squares problem,
   scipy's ``lsq_linear``), and among those that give the same wrench the ones that spend
   the least propellant, ``min Σ f_i / (I_sp,i g₀)`` (a linear program, scipy's HiGHS);
2. *pulse-width modulation* (:meth:`ThrusterSet.on_times`): each thruster fires at full
   thrust from the start of the period for ``t_on = Δt f / F_max``, rounded to a whole number
   of the valve's on-time quantum, and not at all when that impulse ``F_max t_on`` would be
   below its minimum impulse bit;
3. the valves open and shut at those times (:class:`Thrusters`), the run integrated piece by
   piece between the switching times, so that no step straddles a discontinuity.

Every thrust the spacecraft feels is therefore 0 or F_max, every firing a whole number of
quanta and at least one minimum impulse bit.

A mass that goes down
---------------------
Gauss's principle — hence the Udwadia–Kalaba equation ``M ν̇ = Q + Q_c``, ``A ν̇ = b`` — is
a statement about one instant: with a varying mass it holds with the mass matrix of that
instant, ``M(t)``. gmuk's System assembles a constant M₀ (the bodies' masses when the run
starts), so :class:`Thrusters` models the mass loss in the form in which M₀ stays exact:
the spacecraft's mass distribution scales uniformly, ``M(t) = μ M₀`` with
``μ = m(t) / m₀`` (mass and inertia both, the centre of mass fixed in B). Then, on that body,

* every force proportional to its mass and inertia (gravity of every model: point mass,
  gravity gradient, spherical harmonics, third bodies; and the gyroscopic ``ad*`` terms)
  gives the same acceleration with M₀ as with M(t): ``(μ M₀)⁻¹ (μ Q₀) = M₀⁻¹ Q₀``;
* a constraint on that body alone gives the same constraint acceleration: with
  ``M = μ M₀``, ``M^{-1/2} (A M^{-1/2})⁺ = M₀^{-1/2} (A M₀^{-1/2})⁺`` (the factors μ^{∓1/2}
  cancel);
* the thrust's acceleration is ``M(t)⁻¹ W = M₀⁻¹ (W / μ)``: :class:`Thrusters` applies
  ``W m₀ / m``.

* a force not proportional to the mass (solar radiation pressure, drag, a user's wrench)
  should give ``M(t)⁻¹ Q = M₀⁻¹ (Q / μ)``: :class:`Thrusters` adds ``(1/μ − 1) Q`` for each
  such model named in its ``scaled_forces``. That correction acts after the solve, so it is
  exact on a body that no constraint touches.

So the run is the variable-mass motion exactly, under the stated model, and the System
refuses what would make it inexact: a force model on the thrusting body that is neither
proportional to its mass (``ForceModel.mass_proportional``) nor named in ``scaled_forces``,
scaled forces on a constrained body, a constraint tying the body to another, or a second
controller on it. The mass
m(t) is the controller's first internal state, ``ṁ = −Σ_open F_max,i / (I_sp,i g₀)``.
Neglected, as in most attitude and orbit simulations: the jet-damping and relative-flow
terms of the variable-mass equations (the momentum the propellant carries inside the
spacecraft) and the motion of the centre of mass as the tanks empty.

References
----------
Wie, B., *Space Vehicle Dynamics and Control*, 2nd ed., AIAA, 2008, §7.3 (thruster
pulse-width modulation, minimum impulse bit).
Udwadia, F. E. and Kalaba, R. E., *Analytical Dynamics*, Cambridge University Press, 1996
(the equation holds at each instant with that instant's mass matrix).
Sutton, G. P. and Biblarz, O., *Rocket Propulsion Elements*, 9th ed., Wiley, 2017, Ch. 2
(thrust, specific impulse, g₀).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.optimize

from gmuk._forms import Forms
from gmuk._validation import FloatArray, check_sequence, real_number, real_vector
from gmuk.actuators.wheels import AXIS_TOL
from gmuk.bodies import BodyKind, RigidBody
from gmuk.control.base import Controller
from gmuk.errors import DefinitionError, ShapeError, SimulationError
from gmuk.forces.base import ForceModel

if TYPE_CHECKING:
    from gmuk.engine.system import System
    from gmuk.state import State
    from gmuk.trajectory import Trajectory

__all__ = [
    "G0",
    "Allocation",
    "Thruster",
    "ThrusterSet",
    "Thrusters",
    "couple_thrusters",
    "simulate_pulsed",
]

#: Standard gravity g₀ (m/s²), the constant of the specific impulse (3rd CGPM, 1901).
G0 = 9.80665

#: How far a valve's opening may be outside [0, 1] (a state the integrator carries).
VALVE_TOL = 1e-12

#: ``law(t, state, mass) -> W (6,)``: the commanded wrench [τ; F] on the spacecraft (N·m, N,
#: body frame) at time t (s) and mass m (kg).
WrenchLaw = Callable[[float, "State", float], Any]


class Thruster:
    """One on–off thruster fixed to a spacecraft (a description; it holds no state).

    Parameters
    ----------
    position_B : array_like, shape (3,)
        Where its force acts, r (m, body frame B, from the centre of mass).
    direction_B : array_like, shape (3,)
        The unit direction d of its force on the spacecraft (B), unit to :data:`AXIS_TOL`
        (then normalised); the exhaust leaves along −d.
    max_thrust : float
        Thrust F_max while the valve is open (N, > 0).
    isp : float
        Specific impulse I_sp (s, > 0): the propellant flow is F_max / (I_sp g₀) (kg/s).
    min_impulse_bit : float
        The smallest impulse one firing may give (N·s, ≥ 0; default 0): shorter firings are
        not commanded.
    on_time_quantum : float
        The valve's timing resolution (s, ≥ 0; default 0, any on-time): every on-time is a
        whole number of quanta.
    name : str, optional

    Examples
    --------
    >>> t = Thruster([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 22.0, 220.0)
    >>> t.column.tolist()
    [0.0, 0.0, 1.0, 0.0, 1.0, 0.0]
    """

    def __init__(
        self,
        position_B: Any,
        direction_B: Any,
        max_thrust: float,
        isp: float,
        *,
        min_impulse_bit: float = 0.0,
        on_time_quantum: float = 0.0,
        name: str | None = None,
    ) -> None:
        who = "Thruster" + (f" {name!r}" if name else "")
        d = real_vector(direction_B, f"{who} direction_B", 3)
        norm = float(np.linalg.norm(d))
        if abs(norm - 1.0) > AXIS_TOL:
            raise DefinitionError(
                f"{who} direction_B must be a unit vector (|d| = 1 to {AXIS_TOL:g}); got "
                f"{d.tolist()} with |d| = {norm!r}"
            )
        self.position_B: FloatArray = real_vector(position_B, f"{who} position_B", 3)
        self.direction_B: FloatArray = d / norm
        self.position_B.setflags(write=False)
        self.direction_B.setflags(write=False)
        self.max_thrust = real_number(max_thrust, f"{who} max_thrust", positive=True)
        self.isp = real_number(isp, f"{who} isp", positive=True)
        self.min_impulse_bit = real_number(
            min_impulse_bit, f"{who} min_impulse_bit", non_negative=True
        )
        self.on_time_quantum = real_number(
            on_time_quantum, f"{who} on_time_quantum", non_negative=True
        )
        self.name = name
        self._frozen = True

    def __setattr__(self, key: str, value: Any) -> None:
        if getattr(self, "_frozen", False):
            raise AttributeError(
                f"a Thruster is immutable; build a new one instead of setting {key!r}"
            )
        object.__setattr__(self, key, value)

    @property
    def column(self) -> FloatArray:
        """Its wrench per newton of thrust, b = [r × d; d] (m; 1), body frame (6,)."""
        return np.r_[np.cross(self.position_B, self.direction_B), self.direction_B]

    @property
    def mass_flow(self) -> float:
        """Propellant flow while firing, F_max / (I_sp g₀) (kg/s)."""
        return self.max_thrust / (self.isp * G0)

    def __repr__(self) -> str:
        return (
            f"Thruster(position_B={self.position_B.tolist()}, "
            f"direction_B={self.direction_B.tolist()}, max_thrust={self.max_thrust!r}, "
            f"isp={self.isp!r}, min_impulse_bit={self.min_impulse_bit!r}, "
            f"on_time_quantum={self.on_time_quantum!r})"
        )


@dataclass(frozen=True)
class Allocation:
    """What :meth:`ThrusterSet.allocate` found.

    Attributes
    ----------
    thrusts : ndarray (n,)
        f, each in [0, F_max,i] (N).
    wrench : ndarray (6,)
        The wrench they give, B f = [τ; F] (N·m, N, body frame).
    error : float
        ‖D (B f − W_cmd)‖ (weighted units): zero when the command is within reach.
    """

    thrusts: FloatArray
    wrench: FloatArray
    error: float


class ThrusterSet(Sequence[Thruster]):
    """The thrusters of one spacecraft, with the arrays allocation and modulation use.

    Parameters
    ----------
    thrusters : sequence of Thruster
        At least one.

    Attributes
    ----------
    B : ndarray (6, n)
        Wrench per newton of each thruster, one column b_i = [r_i × d_i; d_i] each.
    max_thrust, isp, min_impulse_bit, on_time_quantum : ndarray (n,)
        N, s, N·s, s.
    mass_flow : ndarray (n,)
        Propellant flow of each while firing (kg/s).
    """

    def __init__(self, thrusters: Sequence[Thruster] | ThrusterSet) -> None:
        thrusters = tuple(thrusters)
        if not thrusters or not all(isinstance(t, Thruster) for t in thrusters):
            raise DefinitionError(
                "a ThrusterSet takes one or more gmuk.actuators.Thruster; got "
                f"{[type(t).__name__ for t in thrusters]}"
            )
        self._thrusters = thrusters
        self.B = np.column_stack([t.column for t in thrusters])
        self.max_thrust = np.array([t.max_thrust for t in thrusters])
        self.isp = np.array([t.isp for t in thrusters])
        self.min_impulse_bit = np.array([t.min_impulse_bit for t in thrusters])
        self.on_time_quantum = np.array([t.on_time_quantum for t in thrusters])
        self.mass_flow = np.array([t.mass_flow for t in thrusters])
        for a in (self.B, self.max_thrust, self.isp, self.min_impulse_bit):
            a.setflags(write=False)
        self.on_time_quantum.setflags(write=False)
        self.mass_flow.setflags(write=False)

    def __len__(self) -> int:
        return len(self._thrusters)

    def __getitem__(self, i: Any) -> Any:
        return self._thrusters[i]

    def __iter__(self) -> Iterator[Thruster]:
        return iter(self._thrusters)

    def __repr__(self) -> str:
        return f"ThrusterSet({len(self)} thrusters)"

    def _thrusts(self, f: Any, name: str = "thrusts") -> FloatArray:
        return real_vector(f, name, len(self), error=ShapeError)

    def wrench(self, thrusts: Any) -> FloatArray:
        """The wrench B f = [τ; F] (N·m, N, body frame) of thrusts f (n,) (N)."""
        return self.B @ self._thrusts(thrusts)

    def mass_rate(self, thrusts: Any) -> float:
        """ṁ = −Σ f_i / (I_sp,i g₀) (kg/s) at thrusts f (n,) (N)."""
        return -float(np.sum(self._thrusts(thrusts) / (self.isp * G0)))

    def allocate(self, wrench: Any, *, weights: Any = None) -> Allocation:
        """Thrusts 0 ≤ f ≤ F_max for a commanded wrench, the closest within reach and the
        most frugal among those.

        Parameters
        ----------
        wrench : array_like (6,)
            W_cmd = [τ; F] (N·m, N, body frame).
        weights : array_like (6,), optional
            D's diagonal (> 0; default ones): how much each component's error counts,
            e.g. to trade newton-metres against newtons.

        Returns
        -------
        Allocation
            ``thrusts`` minimise ‖D (B f − W_cmd)‖ over the box; among all thrusts that
            give their wrench, the ones of least propellant flow Σ f_i / (I_sp,i g₀).
        """
        W = real_vector(wrench, "commanded wrench", 6, error=ShapeError)
        D = np.ones(6) if weights is None else real_vector(weights, "weights", 6, positive=True)
        fmax = np.asarray(self.max_thrust)
        fit = scipy.optimize.lsq_linear(
            D[:, None] * self.B, D * W, bounds=(np.zeros(len(self)), fmax), method="bvls"
        )
        f = np.clip(fit.x, 0.0, fmax)
        target = self.B @ f
        if not f.any():  # nothing to fire (a zero command): no program to solve
            return Allocation(f, target, float(np.linalg.norm(D * (target - W))))
        # Among the thrusts with the same wrench, the least propellant (a linear program;
        # the fit is one feasible point, so it only fails on round-off, and then keeps it).
        lp = scipy.optimize.linprog(
            1.0 / (self.isp * G0),
            A_eq=self.B,
            b_eq=target,
            bounds=list(zip(np.zeros(len(self)), fmax, strict=True)),
            method="highs",
        )
        if lp.status == 0:
            frugal = np.clip(lp.x, 0.0, fmax)
            scale = max(1.0, float(np.abs(target).max()))
            if np.abs(self.B @ frugal - target).max() <= 1e-9 * scale:
                f = frugal
        achieved = self.B @ f
        return Allocation(f, achieved, float(np.linalg.norm(D * (achieved - W))))

    def on_times(self, thrusts: Any, period: float) -> FloatArray:
        """The valves' on-times (s) that deliver thrusts f over one control period.

        Each thruster fires from the start of the period for ``Δt f / F_max`` (clipped to
        [0, Δt]), rounded to the nearest whole number of its on-time quantum (down when that
        would pass Δt), and not at all when ``F_max t_on`` is below its minimum impulse bit.

        Parameters
        ----------
        thrusts : array_like (n,)
            f (N), each in [0, F_max,i].
        period : float
            Δt (s, > 0).
        """
        f = self._thrusts(thrusts)
        dt = real_number(period, "period", positive=True)
        fmax = np.asarray(self.max_thrust)
        if np.any(f < 0.0) or np.any(f > fmax):
            raise DefinitionError(
                f"thrusts must lie in [0, max_thrust]; got {f.tolist()} with max_thrust "
                f"{fmax.tolist()}"
            )
        t_on = dt * f / fmax
        q = np.asarray(self.on_time_quantum)
        quantised = q > 0.0
        qq = q[quantised]
        k = np.floor(t_on[quantised] / qq + 0.5)
        t_on[quantised] = np.minimum(k, np.floor(dt / qq)) * qq
        t_on[fmax * t_on < self.min_impulse_bit] = 0.0
        return t_on


def couple_thrusters(
    arm: float,
    max_thrust: float,
    isp: float,
    *,
    min_impulse_bit: float = 0.0,
    on_time_quantum: float = 0.0,
) -> ThrusterSet:
    """Twelve identical thrusters in six pure couples: for each body axis k and sense
    s = ±1, two thrusters at ±arm along axis k+1 pushing along ±s times axis k+2, whose
    wrenches sum to the torque 2 s arm F e_k and no force (axes cyclic, body frame).

    Parameters
    ----------
    arm : float
        Distance of each thruster from the centre of mass (m, > 0).
    max_thrust, isp, min_impulse_bit, on_time_quantum
        As for :class:`Thruster`, the same for all twelve.

    Examples
    --------
    >>> ts = couple_thrusters(1.0, 10.0, 220.0)
    >>> ts.wrench([10.0, 10.0] + [0.0] * 10).tolist()
    [20.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    """
    a = real_number(arm, "arm", positive=True)
    out = []
    for k in range(3):
        e_r, e_d = np.eye(3)[(k + 1) % 3], np.eye(3)[(k + 2) % 3]
        for sense in (1.0, -1.0):
            for side in (1.0, -1.0):
                out.append(
                    Thruster(
                        side * a * e_r,
                        sense * side * e_d,
                        max_thrust,
                        isp,
                        min_impulse_bit=min_impulse_bit,
                        on_time_quantum=on_time_quantum,
                        name=f"{'xyz'[k]}{'+' if sense > 0 else '-'}{1 if side > 0 else 2}",
                    )
                )
    return ThrusterSet(out)


class Thrusters(Controller):
    """A thruster set on one rigid body: the wrench of its open valves and the mass it spends.

    The valves are internal states, set by :func:`simulate_pulsed` at each switching time
    (or by a user between runs): ``z = [m, v_1, …, v_n]`` with m the spacecraft's mass (kg)
    and v_i ∈ [0, 1] the opening of valve i (1 open, 0 shut; in between, a throttle). The
    wrench on the body is ``(m₀ / m) Σ v_i F_max,i b_i`` and ``ṁ = −Σ v_i F_max,i /
    (I_sp,i g₀)``, the valves constant (see the module docstring for why m₀ / m, and what
    the System then refuses).

    Parameters
    ----------
    body : RigidBody
        The spacecraft; its ``mass`` is m₀, the mass when the run starts (kg).
    thrusters : ThrusterSet or sequence of Thruster
    dry_mass : float, optional
        The mass with empty tanks (kg, 0 ≤ dry_mass ≤ m₀; default 0):
        :func:`simulate_pulsed` cuts the on-times so that the mass never goes below it.
    scaled_forces : sequence of ForceModel, optional
        Force models of the System acting on the body that are not proportional to its mass
        (solar radiation pressure, drag, a user's wrench), whose acceleration this
        controller rescales to the current mass by adding ``(m₀/m − 1) Q`` for each model's
        wrench Q: exact on a body that no constraint touches (the solve would not see the
        correction), which the System then checks.
    name : str, optional

    Notes
    -----
    ``traj.control_force`` holds the wrench this controller adds: the thrust over μ = m/m₀
    plus the scaled forces' corrections.
    """

    body_kinds = frozenset({BodyKind.RIGID})
    _forms = Forms(
        compiled="valve states switched between segments: called back from the compiled loop",
        symbolic="gmuk.optimize transcribes no controller",
    )

    def __init__(
        self,
        body: RigidBody,
        thrusters: ThrusterSet | Sequence[Thruster],
        *,
        dry_mass: float = 0.0,
        scaled_forces: Sequence[ForceModel] = (),
        name: str | None = None,
    ) -> None:
        if not isinstance(body, RigidBody):
            raise DefinitionError(
                "Thrusters needs the spacecraft's RigidBody itself (its mass is m₀); got "
                f"{type(body).__name__}"
            )
        thrusters = ThrusterSet(thrusters)
        dry = real_number(dry_mass, "Thrusters dry_mass", non_negative=True)
        if dry > body.mass:
            raise DefinitionError(
                f"Thrusters dry_mass {dry!r} kg exceeds the body's mass {body.mass!r} kg"
            )
        scaled = tuple(check_sequence(scaled_forces, "Thrusters scaled_forces"))
        if not all(isinstance(f, ForceModel) for f in scaled):
            raise DefinitionError(
                "Thrusters scaled_forces must be gmuk.ForceModel instances; got "
                f"{[type(f).__name__ for f in scaled]}"
            )
        super().__init__([body], n_states=1 + len(thrusters), name=name)
        self.scaled_forces = scaled
        self.thrusters = thrusters
        self.dry_mass = dry
        self.initial_mass = body.mass

    def initial_state(self) -> FloatArray:
        """z(0) = [m₀, 0, …, 0]: the body's mass, every valve shut."""
        return np.r_[self.initial_mass, np.zeros(len(self.thrusters))]

    def control(
        self, state: State, z: FloatArray, *modeled: FloatArray
    ) -> tuple[list[FloatArray], FloatArray]:
        """The thrust wrench (m₀/m) B (v ∘ F_max) on the body (N·m, N, body frame) and
        ż = [ṁ, 0, …, 0]."""
        m, valves = float(z[0]), np.asarray(z[1:], dtype=float)
        if not m > 0.0:
            raise SimulationError(f"{self.name}: the spacecraft's mass is {m!r} kg")
        if not (valves.min() >= -VALVE_TOL and valves.max() <= 1.0 + VALVE_TOL):
            raise SimulationError(
                f"{self.name}: valve openings must lie in [0, 1]; got {valves.tolist()}"
            )
        f = valves * self.thrusters.max_thrust
        z_dot = np.zeros(len(z))
        z_dot[0] = -float(valves @ self.thrusters.mass_flow)  # ṁ = −Σ v_i F_max,i / (I_sp,i g₀)
        ratio = self.initial_mass / m
        u = ratio * (self.thrusters.B @ f)
        (body,) = self.bodies
        for model in self.scaled_forces:  # M(t)⁻¹ Q = M₀⁻¹ (Q + (m₀/m − 1) Q)
            u = u + (ratio - 1.0) * np.asarray(model.wrenches(state, [body])[0], dtype=float)
        return [u], z_dot

    def _system_problems(self, system: System) -> list[str]:
        """What in ``system`` would make the uniform-scaling mass model inexact."""
        (body,) = self.bodies
        name = body if isinstance(body, str) else body.name
        problems = []
        for f in system.forces:
            on_it = (
                BodyKind.RIGID in f.acts_on
                if f.bodies is None
                else any((b if isinstance(b, str) else b.name) == name for b in f.bodies)
            )
            scaled = any(f is g for g in self.scaled_forces)
            if on_it and not f.mass_proportional and not scaled:
                problems.append(
                    f"{self.name}: force model {f.name!r} ({type(f).__name__}) acts on "
                    f"{name!r} and is not proportional to its mass; with the mass varying "
                    "(Thrusters) its acceleration would be wrong by m₀/m. Name it in "
                    "Thrusters(scaled_forces=...) to rescale it (an unconstrained body), or "
                    "act on the body with mass-proportional models only "
                    "(ForceModel.mass_proportional)"
                )
        for g in self.scaled_forces:
            if not any(g is f for f in system.forces):
                problems.append(
                    f"{self.name}: scaled force {g.name!r} is not one of the System's forces"
                )
        for c in system.constraints:
            names = {b if isinstance(b, str) else b.name for b in c.bodies}
            if name in names and self.scaled_forces:
                problems.append(
                    f"{self.name}: constraint {c.name!r} acts on {name!r}, whose "
                    "scaled_forces are rescaled after the constraint solve; with scaled "
                    "forces the thrusting body must be unconstrained"
                )
            elif name in names and len(names) > 1:
                problems.append(
                    f"{self.name}: constraint {c.name!r} ties {name!r} to "
                    f"{sorted(names - {name})}; with its mass varying (Thrusters) the "
                    "constraint force would be wrong. Only constraints on the thrusting body "
                    "alone are exact"
                )
        for other in system.controllers:
            if other is not self and any(
                (b if isinstance(b, str) else b.name) == name for b in other.bodies
            ):
                problems.append(
                    f"{self.name}: controller {other.name!r} also acts on {name!r}; its "
                    "wrench would act on the initial mass. Fold it into the thrusters' law"
                )
        return problems


def _controller_slice(system: System, thrusters: Thrusters) -> slice:
    """Where the thrusters' internal states sit in a State's z."""
    start = 0
    for c in system.controllers:
        if c is thrusters:
            return slice(start, start + c.n_states)
        start += c.n_states
    raise DefinitionError(f"{thrusters.name!r} is not one of the System's controllers")


def simulate_pulsed(
    system: System,
    state0: State,
    t_span: tuple[float, float],
    thrusters: Thrusters,
    law: WrenchLaw,
    period: float,
    *,
    t_eval: Any = None,
    weights: Any = None,
    **options: Any,
) -> Trajectory:
    """Fly a System whose thrusters fire under a sampled control law.

    At the start of each control period t_k (s) the law gives a commanded wrench from the
    state; :meth:`ThrusterSet.allocate` turns it into thrusts, :meth:`ThrusterSet.on_times`
    into valve on-times (limited to the propellant left above the dry mass); the valves open
    at t_k and each shuts at t_k + t_on,i. The run is integrated piece by piece between
    those switching times (:meth:`gmuk.System.simulate` on each), so the thrust is constant
    within every step.

    Parameters
    ----------
    system : System
        With ``thrusters`` among its controllers.
    state0 : State
        The initial state (its valves are shut at t_span[0] and set from then on).
    t_span : (float, float)
        Start and end (s).
    thrusters : Thrusters
    law : callable
        ``law(t, state, mass) -> W_cmd (6,)``: the commanded wrench [τ; F] (N·m, N, body
        frame) at the period's start.
    period : float
        The control period Δt (s, > 0).
    t_eval : array_like, shape (k,), optional
        Output times (s); default every accepted step (one output per time: the state after
        a switch).
    weights : array_like (6,), optional
        Allocation weights (:meth:`ThrusterSet.allocate`).
    **options
        Passed to :meth:`gmuk.System.simulate` (rtol, atol, method, events, drift_tol …).

    Returns
    -------
    Trajectory
        The joined run; ``traj.z`` carries m and the valve openings at each output.
        ``stats["firings"]`` holds each period's start ``t`` (s), ``on_times`` (s, one per
        thruster), ``commanded`` wrench and allocation ``error``; ``stats["propellant"]``
        the mass spent (kg). A terminal event or a failure ends it early, with the segments
        so far (and that segment's status and message).
    """
    from gmuk.engine import segments
    from gmuk.engine.integrate import check_drift

    if not any(c is thrusters for c in system.controllers):
        raise DefinitionError(f"{thrusters.name!r} is not one of the System's controllers")
    if not callable(law):
        raise DefinitionError(f"law must be callable (t, state, mass) -> (6,); got {law!r}")
    dt = real_number(period, "period", positive=True)
    t, t1 = (real_number(x, "t_span") for x in t_span)
    if not t1 > t:
        raise DefinitionError(f"t_span must be increasing; got {tuple(t_span)}")
    times = None if t_eval is None else np.asarray(t_eval, dtype=float)
    zs = _controller_slice(system, thrusters)
    ts = thrusters.thrusters
    z = np.array(state0.z, dtype=float)
    z[zs.start + 1 : zs.stop] = 0.0
    state = state0.replace(t=t, z=z)
    parts: list[Trajectory] = []
    firings: dict[str, list[Any]] = {"t": [], "on_times": [], "commanded": [], "error": []}
    first = True
    done = False
    while not done:
        t_next = min(t + dt, t1)
        m = float(state.z[zs.start])
        W = real_vector(law(t, state, m), "the law's wrench", 6, error=ShapeError)
        alloc = ts.allocate(W, weights=weights)
        on = np.minimum(ts.on_times(alloc.thrusts, dt), t_next - t)
        on = _within_propellant(ts, on, m - thrusters.dry_mass)
        firings["t"].append(t)
        firings["on_times"].append(on.tolist())
        firings["commanded"].append(W.tolist())
        firings["error"].append(alloc.error)
        ends = t + on
        cuts = np.unique(np.r_[ends[(ends > t) & (ends < t_next)], t_next])
        a = t
        for b in cuts:
            z = np.array(state.z, dtype=float)
            z[zs.start + 1 : zs.stop] = (ends >= b).astype(float)
            last = bool(b == t1)
            seg = system.simulate(
                state.replace(t=a, z=z),
                (a, float(b)),
                t_eval=segments.segment_times(times, a, float(b), first),
                **options,
            )
            first = False
            stopped = seg.status not in ("success", "drifted")
            # Every step output: the next segment's first output is the state after the
            # switch; requested times: each segment keeps those in (a, b].
            drop = times is None and not (last or stopped)
            parts.append(segments.trimmed(seg, times, drop_last=drop))
            if stopped:  # the state it reached (the propellant spent up to there)
                state = seg.state(len(seg) - 1) if len(seg) else state
                done = True
                break
            state = seg.state(len(seg) - 1)
            a = float(b)
        t = t_next
        done = done or t >= t1
    spent = float(state0.z[zs.start] - state.z[zs.start])
    joined = segments.join(parts, stats={"firings": firings, "propellant": spent})
    return check_drift(system, joined, options.get("drift_tol", 1e-6))


def _within_propellant(ts: ThrusterSet, on: FloatArray, available: float) -> FloatArray:
    """On-times cut to what the propellant above the dry mass allows: all scaled by the same
    factor, each then rounded down to its quantum and dropped below its minimum impulse
    bit."""
    need = float(np.sum(on * ts.mass_flow))
    if need <= available:
        return on
    scaled = on * max(available, 0.0) / need
    q = np.asarray(ts.on_time_quantum)
    quantised = q > 0.0
    scaled[quantised] = np.floor(scaled[quantised] / q[quantised]) * q[quantised]
    scaled[ts.max_thrust * scaled < ts.min_impulse_bit] = 0.0
    return scaled
