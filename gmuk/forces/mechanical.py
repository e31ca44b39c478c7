"""Simple mechanical force models: applied wrenches, springs and dampers, uniform gravity.

:class:`UniformGravity` and :class:`LinearSpringDamper` are written once each, in the numba
kernel beside the class (:func:`uniform_load`, :func:`spring_load`) that their Python methods
and the compiled step loop (through :data:`~gmuk.forces.base.FORCE_KERNEL`) both call; their CasADi
forms, and those of the other models here, are methods of the classes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._casadi import casadi, column
from gmuk._forms import Forms
from gmuk._numba import njit
from gmuk._validation import FloatArray, as_array, real_number
from gmuk.bodies import BodyKind
from gmuk.errors import DefinitionError, GmukError
from gmuk.forces.base import ForceModel, com_load

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody
    from gmuk.state import State

__all__ = [
    "AppliedWrench",
    "LinearSpringDamper",
    "SlackDamping",
    "SpringDamper",
    "UniformGravity",
    "spring_load",
    "uniform_load",
]

STANDARD_GRAVITY = 9.80665  # m/s², CGPM 1901


class AppliedWrench(ForceModel):
    """A given wrench on one body: constant or a function of time.

    Parameters
    ----------
    body : Body or str
    wrench : array_like (6,) or (3,), or callable t ↦ array
        [L; f] for a rigid body (N·m, N), f for a point mass (N).
    frame : {"body", "inertial"}
        Frame of the given components. Inertial components of a rigid body's wrench are
        rotated into the body frame (torque about the centre of mass).
    modeled : bool
        Whether the constraint solve knows it (default True); exactly True or False.
    name : str, optional

    Raises
    ------
    DefinitionError
        If ``wrench`` is not a finite (6,) or (3,) array of real numbers or a callable,
        ``frame`` is not one of the two names, or ``modeled`` is not a bool.
    """

    _forms = Forms(
        compiled="a function of time given in Python: called back from the compiled loop",
        symbolic=True,
    )

    def __init__(
        self,
        body: Body | str,
        wrench: Any,
        *,
        frame: str = "body",
        modeled: bool = True,
        name: str | None = None,
    ) -> None:
        super().__init__([body], modeled=modeled, name=name)
        if not isinstance(frame, str) or frame not in ("body", "inertial"):
            raise DefinitionError(f"frame must be 'body' or 'inertial'; got {frame!r}")
        if callable(wrench):
            self._fun: Callable[[float], Any] = wrench
        else:
            try:
                size = np.shape(wrench)[0] if np.ndim(wrench) == 1 else 6
                w = np.array(as_array(wrench, (size,), "wrench", batch=False))
            except (GmukError, ValueError):
                raise DefinitionError(
                    f"wrench must be a finite (6,) or (3,) array of real numbers or a "
                    f"callable; got {wrench!r:.60}"
                ) from None
            if w.shape not in ((6,), (3,)):
                raise DefinitionError(
                    f"wrench must be a finite (6,) or (3,) array or a callable; got shape {w.shape}"
                )
            w.setflags(write=False)
            self._fun = lambda t: w
        self.frame = frame

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """The wrench [L; f] at time t, in the body frame (N·m, N)."""
        w = np.asarray(self._fun(t), dtype=float)
        if self.frame == "inertial":
            Rt = g_NB[:3, :3].T
            return np.concatenate([Rt @ w[:3], Rt @ w[3:]])
        return w

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """The force f_N at time t on a point mass (N); ``frame`` must be "inertial" or the
        force is taken as given in N (a point mass has no body frame)."""
        return np.asarray(self._fun(t), dtype=float)

    def casadi_force(self, t: float, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force`: the given force at the (numeric) time t."""
        return column(AppliedWrench.force(self, t, np.zeros(3), np.zeros(3), body))

    def casadi_wrench(self, t: float, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` (CasADi, 6×1) at the (numeric) time t."""
        ca = casadi()
        w = column(self._fun(t))
        if self.frame == "inertial":
            Rt = g_NB[:3, :3].T
            return ca.vertcat(Rt @ w[:3], Rt @ w[3:])
        return w


@njit(cache=True)
def uniform_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`UniformGravity`'s kernel: ``f_N = m g_N`` at the centre of mass, written into
    ``out`` as a force kernel does (:func:`~gmuk.forces.base.com_load`). Parameters
    ``p = g_N`` (3 values, m/s²). Returns 0."""
    com_load(rigid, g, m * p[0], m * p[1], m * p[2], out)
    return 0


class UniformGravity(ForceModel):
    """Weight in a uniform field: f_N = m g_N (no torque about the centre of mass).

    Parameters
    ----------
    g_N : array_like, shape (3,)
        Gravitational acceleration in N (m/s²); default (0, 0, −9.80665).
    bodies : sequence, optional
    """

    mass_proportional = True  # gravity: force ∝ m, torque ∝ J

    _kernel = staticmethod(uniform_load)
    _forms = Forms(compiled=True, symbolic=True)

    def __init__(
        self,
        g_N: Any = (0.0, 0.0, -STANDARD_GRAVITY),
        *,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        self.g_N = as_array(g_N, (3,), "g_N", batch=False)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[0; Rᵀ m g_N] in the body frame (N·m, N) (:func:`uniform_load`)."""
        return self._kernel_load(True, t, g_NB, V_B, body)

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """m g_N (N) (:func:`uniform_load`)."""
        return self._kernel_load(False, t, r_N, v_N, body)

    def _kernel_params(self, body: Body) -> tuple[FloatArray, None]:
        return self.g_N, None

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force` (CasADi, 3×1)."""
        return body.mass * column(self.g_N)

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` (CasADi, 6×1)."""
        ca = casadi()
        return ca.vertcat(ca.DM.zeros(3, 1), g_NB[:3, :3].T @ (body.mass * column(self.g_N)))


@njit(cache=True)
def spring_load(rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """:class:`LinearSpringDamper`'s kernel: ``f_N = −k (r_N − r_a) − c v_N`` at the centre of
    mass (``v_N = R v_B`` on a rigid body), written into ``out`` as a force kernel does
    (:func:`~gmuk.forces.base.com_load`). Parameters ``p = (k, c, r_a)`` (N/m, N·s/m, 3 values
    in m). Returns 0."""
    if rigid:  # v_N = R v_B
        vx = g[0, 0] * V[3] + g[0, 1] * V[4] + g[0, 2] * V[5]
        vy = g[1, 0] * V[3] + g[1, 1] * V[4] + g[1, 2] * V[5]
        vz = g[2, 0] * V[3] + g[2, 1] * V[4] + g[2, 2] * V[5]
    else:
        vx, vy, vz = V[0], V[1], V[2]
    fx = -p[0] * (g[0, 3] - p[2]) - p[1] * vx
    fy = -p[0] * (g[1, 3] - p[3]) - p[1] * vy
    fz = -p[0] * (g[2, 3] - p[4]) - p[1] * vz
    com_load(rigid, g, fx, fy, fz, out)
    return 0


class LinearSpringDamper(ForceModel):
    """A linear spring and damper from a fixed anchor: ``f_N = −k (r_N − r_a) − c v_N``.

    Isotropic, with zero rest length, so it is defined everywhere (also at the anchor, where
    :class:`SpringDamper` has no direction). On a rigid body it acts at the centre of mass
    (no torque); ``v_N = R v_B``. In one dimension this is the spring–mass–damper
    ``m ẍ + c ẋ + k x = 0`` of McCann (2020) §6.5.1.

    Parameters
    ----------
    stiffness : float
        k (N/m), ≥ 0.
    damping : float
        c (N·s/m), ≥ 0.
    anchor : array_like (3,)
        r_a in N (m); the origin by default.
    bodies : sequence of Body or str, optional
        The bodies it acts on (default: every point mass and rigid body).
    modeled : bool
    name : str, optional

    Notes
    -----
    The force is :func:`spring_load` (the compiled loop's kernel too); its CasADi form is
    :meth:`casadi_force` / :meth:`casadi_wrench`.
    """

    _kernel = staticmethod(spring_load)
    _forms = Forms(compiled=True, symbolic=True)

    def __init__(
        self,
        stiffness: float,
        damping: float = 0.0,
        anchor: Any = (0.0, 0.0, 0.0),
        *,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = True,
        name: str | None = None,
    ) -> None:
        super().__init__(bodies, modeled=modeled, name=name)
        self.k = real_number(stiffness, "stiffness (N/m)", non_negative=True)
        self.c = real_number(damping, "damping (N·s/m)", non_negative=True)
        self.anchor = as_array(anchor, (3,), "anchor", batch=False)

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """−k(r_N − r_a) − c v_N (N) (:func:`spring_load`)."""
        return self._kernel_load(False, t, r_N, v_N, body)

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[0; Rᵀ f_N] at the centre of mass (N·m, N) (:func:`spring_load`)."""
        return self._kernel_load(True, t, g_NB, V_B, body)

    def _kernel_params(self, body: Body) -> tuple[tuple[float, ...], None]:
        return (self.k, self.c, *(float(v) for v in self.anchor)), None

    def casadi_force(self, t: Any, r_N: Any, v_N: Any, body: Body) -> Any:
        """The symbolic form of :meth:`force` (CasADi, 3×1)."""
        return -self.k * (r_N - column(self.anchor)) - self.c * v_N

    def casadi_wrench(self, t: Any, g_NB: Any, V_B: Any, body: RigidBody) -> Any:
        """The symbolic form of :meth:`wrench` (CasADi, 6×1)."""
        ca = casadi()
        R = g_NB[:3, :3]
        f_N = LinearSpringDamper.casadi_force(self, t, g_NB[:3, 3], R @ V_B[3:], body)
        return ca.vertcat(ca.DM.zeros(3, 1), R.T @ f_N)


class SlackDamping(ForceModel):
    """Viscous damping of slack and excess coordinates, ``f = −c ẇ``: a choice of slack
    dynamics (McCann 2020, §6.3.3).

    Without it an inequality's slack keeps the energy the bodies hand it when they reach the
    bound and gives it back: the contact is elastic, and a body pressed onto a bound
    oscillates off it with an amplitude that decays only like 1/√t. Damping the slack makes
    the contact inelastic, so the bodies settle on the bound. The force is applied to the
    slack coordinates only, but the bodies feel it through the equality that ties them to
    the slack (away from the bound too).

    Parameters
    ----------
    coefficient : float
        c, ≥ 0, in the unit of the slack mass per second (kg·m/s for a position bound in
        metres). A slack of mass m_w at a bound held with multiplier μ obeys
        ``m_w ẅ = −2μw − cẇ`` (stiffness 2μ), so ``c = 2√(2μ m_w)`` damps it critically.
    bodies : sequence of SlackCoordinate or str, optional
        Default: every slack coordinate of the System.
    name : str, optional
    """

    acts_on = frozenset({BodyKind.SLACK})
    _forms = Forms(
        compiled="acts on slack coordinates, whose loads the compiled loop calls back",
        symbolic="gmuk.optimize transcribes no slack coordinates",
    )

    def __init__(
        self,
        coefficient: float,
        *,
        bodies: Sequence[Body | str] | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(bodies, name=name)
        self.c = real_number(coefficient, "coefficient", non_negative=True)

    def wrenches(self, state: State, bodies: Sequence[Body]) -> list[FloatArray]:
        """−c ẇ (1,) for each slack coordinate."""
        return [-self.c * state.velocity(b) for b in bodies]


class SpringDamper(ForceModel):
    """A linear spring–damper between a point of body a and a point of body b (or a fixed
    point of N).

    The tension is ``T = k (ℓ − ℓ₀) + c ℓ̇`` along the line between the attachment points;
    it pulls them together when positive. Forces act at the attachment points, so rigid
    bodies also get the torque ``p × f`` about their centre of mass.

    Parameters
    ----------
    body_a : Body or str
    point_a : array_like (3,)
        Attachment in a's body frame (m); ignored (use zeros) for a point mass.
    body_b : Body or str or None
        None to anchor at ``point_b`` given in N.
    point_b : array_like (3,)
        Attachment in b's body frame, or the anchor in N (m).
    stiffness : float
        k (N/m), ≥ 0.
    damping : float
        c (N·s/m), ≥ 0.
    rest_length : float
        ℓ₀ (m), ≥ 0.
    """

    acts_on = frozenset({BodyKind.RIGID, BodyKind.POINT})
    _forms = Forms(compiled="couples two bodies: called back from the compiled loop", symbolic=True)

    def __init__(
        self,
        body_a: Body | str,
        point_a: Any,
        body_b: Body | str | None,
        point_b: Any,
        *,
        stiffness: float,
        damping: float = 0.0,
        rest_length: float = 0.0,
        modeled: bool = True,
        name: str | None = None,
    ) -> None:
        bodies = [body_a] if body_b is None else [body_a, body_b]
        super().__init__(bodies, modeled=modeled, name=name)
        self.k = real_number(stiffness, "stiffness (N/m)", non_negative=True)
        self.c = real_number(damping, "damping (N·s/m)", non_negative=True)
        self.l0 = real_number(rest_length, "rest_length (m)", non_negative=True)
        self.point_a = as_array(point_a, (3,), "point_a", batch=False)
        self.point_b = as_array(point_b, (3,), "point_b", batch=False)
        self.anchored = body_b is None

    @staticmethod
    def _point(
        state: State, body: Body, p_B: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """World position and velocity of a body point, and its lever arm in N."""
        if body.kind is BodyKind.RIGID:
            g, V = state.pose(body), state.twist(body)
            R = g[:3, :3]
            arm = R @ p_B
            return g[:3, 3] + arm, R @ (V[3:] + np.cross(V[:3], p_B)), arm
        return state.position(body).copy(), state.velocity(body).copy(), np.zeros(3)

    def wrenches(self, state: State, bodies: Sequence[Body]) -> list[FloatArray]:
        """Equal and opposite forces at the attachment points (with their torques)."""
        x_a, v_a, _ = self._point(state, bodies[0], self.point_a)
        if self.anchored:
            x_b, v_b = self.point_b, np.zeros(3)
        else:
            x_b, v_b, _ = self._point(state, bodies[1], self.point_b)
        d = x_b - x_a
        length = float(np.linalg.norm(d))
        if length == 0.0:
            raise DefinitionError(f"{self.name}: attachment points coincide; direction undefined")
        u = d / length
        tension = self.k * (length - self.l0) + self.c * float(u @ (v_b - v_a))
        f_a_N = tension * u
        out = [self._to_body(state, bodies[0], self.point_a, f_a_N)]
        if not self.anchored:
            out.append(self._to_body(state, bodies[1], self.point_b, -f_a_N))
        return out

    @staticmethod
    def _to_body(state: State, body: Body, p_B: FloatArray, f_N: FloatArray) -> FloatArray:
        if body.kind is not BodyKind.RIGID:
            return f_N
        f_B = state.pose(body)[:3, :3].T @ f_N
        return np.concatenate([np.cross(p_B, f_B), f_B])

    def casadi_wrenches(
        self, t: Any, q: tuple[Any, ...], nu: tuple[Any, ...], bodies: tuple[Body, ...]
    ) -> list[Any]:
        """The symbolic form of :meth:`wrenches` (CasADi columns, one per body)."""
        ca = casadi()
        x_a, v_a = _casadi_point(q[0], nu[0], bodies[0], self.point_a)
        if self.anchored:
            x_b, v_b = column(self.point_b), ca.DM.zeros(3, 1)
        else:
            x_b, v_b = _casadi_point(q[1], nu[1], bodies[1], self.point_b)
        d = x_b - x_a
        length = ca.norm_2(d)
        u = d / length
        tension = self.k * (length - self.l0) + self.c * ca.dot(u, v_b - v_a)
        f_a = tension * u
        out = [_casadi_to_body(q[0], bodies[0], self.point_a, f_a)]
        if not self.anchored:
            out.append(_casadi_to_body(q[1], bodies[1], self.point_b, -f_a))
        return out


def _casadi_point(q: Any, nu: Any, body: Body, p_B: Any) -> tuple[Any, Any]:
    """World position and velocity of a body point (as SpringDamper._point), in CasADi."""
    if body.kind is BodyKind.RIGID:
        R, p = q[:3, :3], column(p_B)
        return q[:3, 3] + R @ p, R @ (nu[3:] + casadi().cross(nu[:3], p))
    return q, nu


def _casadi_to_body(q: Any, body: Body, p_B: Any, f_N: Any) -> Any:
    """A force f_N at a body point as that body's load (as SpringDamper._to_body), in CasADi."""
    if body.kind is not BodyKind.RIGID:
        return f_N
    ca = casadi()
    f_B = q[:3, :3].T @ f_N
    return ca.vertcat(ca.cross(column(p_B), f_B), f_B)
