"""Robots from URDF: Pinocchio's parser, gmuk's bodies and joints.

:meth:`Robot.from_urdf` reads a URDF with Pinocchio (``pin.buildModelFromUrdf``, which merges
the links of fixed joints into their parent's inertia) and builds, for each of Pinocchio's
joints, one :class:`gmuk.RigidBody` and one gmuk joint (:mod:`gmuk.robots.joints`):

- the body frame B is at the link's centre of mass c (in Pinocchio's joint frame i), with the
  axes of frame i; its mass and central inertia are Pinocchio's ``model.inertias[i]``;
- the joint's child frame is frame i itself, ``X_CJ = (I, −c)``; its parent frame is
  Pinocchio's ``jointPlacement`` in the parent's body frame,
  ``X_PJ = (I, −c_parent) · jointPlacement`` (in N for a joint to the universe);
- a floating base (``base="floating"``, Pinocchio's free-flyer) is a free body: no joint.

Coordinates follow Pinocchio's conventions (:meth:`Robot.state`, :meth:`Robot.configuration`,
:meth:`Robot.velocity`), so that a cross-check with ``pin.aba`` is one line; gmuk's own twists
stay [ω; v] in the body frame (docs/robotics.rst, "Conventions beside Pinocchio's").
"""

from __future__ import annotations

import copy
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray, as_array, real_number
from gmuk.bodies import RigidBody
from gmuk.engine.system import System
from gmuk.errors import DefinitionError, GmukError
from gmuk.forces.mechanical import UniformGravity
from gmuk.lie import se3
from gmuk.robots.forces import JointEffort, JointSpringDamper
from gmuk.robots.joints import (
    Joint,
    PlanarJoint,
    PrismaticJoint,
    RevoluteJoint,
    SphericalJoint,
    unwrap_with_rates,
)

if TYPE_CHECKING:
    from gmuk.constraints.base import Baumgarte
    from gmuk.forces.base import ForceModel
    from gmuk.state import State
    from gmuk.trajectory import Trajectory

__all__ = ["SUPPORTED_JOINTS", "Robot"]

#: Pinocchio joint models that a URDF gives and gmuk builds, by short name.
SUPPORTED_JOINTS = (
    "JointModelRX",
    "JointModelRY",
    "JointModelRZ",
    "JointModelRevoluteUnaligned",
    "JointModelRUBX",
    "JointModelRUBY",
    "JointModelRUBZ",
    "JointModelRevoluteUnboundedUnaligned",
    "JointModelPX",
    "JointModelPY",
    "JointModelPZ",
    "JointModelPrismaticUnaligned",
    "JointModelSpherical",
    "JointModelPlanar",
    "JointModelFreeFlyer",
)


def _pin() -> Any:
    import pinocchio

    return pinocchio


def _se3_matrix(M: Any) -> FloatArray:
    """A pinocchio SE3 as a 4×4 array."""
    return np.array(M.homogeneous, dtype=float)


def _com_frame(c: FloatArray) -> FloatArray:
    """(I, c): the centre-of-mass frame in the joint frame."""
    g = np.eye(4)
    g[:3, 3] = c
    return g


def _quat_xyzw(R: FloatArray) -> FloatArray:
    """Pinocchio's quaternion (x, y, z, w) of a rotation matrix (w ≥ 0)."""
    from gmuk.attitude import quaternion_from_R_NB

    return np.asarray(quaternion_from_R_NB(R, scalar="last"), dtype=float)


#: A link's principal moment at or below this fraction of the robot's largest is URDF
#: round-off (iCub's zero inertias come out of Pinocchio at ±5e-20 kg·m²): it is set to zero.
ROUND_OFF = 1e-12


def _round_off_zeroed(J: FloatArray, largest: float) -> FloatArray:
    """J with the principal moments at or below ``ROUND_OFF · largest`` (kg·m²) set to zero;
    J itself when there is none."""
    w, U = np.linalg.eigh(0.5 * (J + J.T))
    small = np.abs(w) <= ROUND_OFF * largest
    if not small.any():
        return J
    w[small] = 0.0
    out = (U * w) @ U.T
    return np.asarray(0.5 * (out + out.T))


def _undetermined(model: Any) -> list[str]:
    """The joints that move no mass at all (their subtree's links are all massless): their
    acceleration is undetermined (Pinocchio's ABA gives NaN there too)."""
    subtree = [float(model.inertias[i].mass) for i in range(model.njoints)]
    for i in range(model.njoints - 1, 0, -1):  # children have larger indices
        subtree[model.parents[i]] += subtree[i]
    return [
        f"joint {model.names[i]!r} moves only links without mass: its acceleration is undetermined"
        for i in range(1, model.njoints)
        if subtree[i] == 0.0
    ]


class Robot:
    """A tree of rigid bodies and joints built from a URDF (see the module docstring).

    Build it with :meth:`from_urdf`. Its :attr:`system` is an ordinary :class:`gmuk.System`:
    add parts with :meth:`with_parts`, simulate it with ``robot.system.simulate``.

    Attributes
    ----------
    model : pinocchio.Model
        The Pinocchio model it was built from (locked joints removed).
    system : gmuk.System
    bodies : tuple of RigidBody
        One per Pinocchio joint 1 … njoints − 1, named after the joint's first link.
    joints : dict of str to Joint
        gmuk's joint for each of Pinocchio's joints but a floating base, by joint name.
    base : {"fixed", "floating"}
    """

    def __init__(
        self,
        model: Any,
        *,
        base: str,
        forces: Sequence[ForceModel] = (),
        baumgarte: Baumgarte | None = None,
        package_dirs: Sequence[str] | None = None,
        path: Path | None = None,
        **system_options: Any,
    ) -> None:
        pin = _pin()
        self.model = model
        self.base = base
        self.path = path
        self.package_dirs = tuple(package_dirs or ())
        problems: list[str] = []
        bodies: list[RigidBody] = []
        self._com: list[FloatArray] = [np.zeros(3)]
        moments = [np.linalg.eigvalsh(model.inertias[i].inertia) for i in range(1, model.njoints)]
        largest = max((float(np.max(np.abs(w))) for w in moments), default=0.0)
        for i in range(1, model.njoints):
            inertia = model.inertias[i]
            link = _first_link(model, i)
            try:
                bodies.append(
                    RigidBody(
                        link,
                        float(inertia.mass),
                        _round_off_zeroed(np.array(inertia.inertia), largest),
                        allow_singular=True,
                    )
                )
            except GmukError as exc:
                problems.append(f"joint {model.names[i]!r} (link {link!r}): {exc}")
            self._com.append(np.array(inertia.lever, dtype=float))
        problems += _undetermined(model)
        if problems:
            raise DefinitionError(
                "gmuk needs every link to have a physical inertia (mass ≥ 0, central inertia "
                "positive semidefinite) and every joint to move some mass (maximal "
                "coordinates: each link is a rigid body); " + "; ".join(problems)
            )
        self.bodies = tuple(bodies)
        self.joints: dict[str, Joint] = {}
        self._floating = None
        for i in range(1, model.njoints):
            jm = model.joints[i]
            kind = jm.shortname()
            name = model.names[i]
            parent = model.parents[i]
            if kind == "JointModelFreeFlyer":
                if parent != 0:
                    raise DefinitionError(
                        f"joint {name!r}: a free-flyer joint is supported as the floating base only"
                    )
                self._floating = i
                continue
            X_PJ = _com_frame(-self._com[parent]) @ _se3_matrix(model.jointPlacements[i])
            if parent == 0:
                X_PJ = _se3_matrix(model.jointPlacements[i])
            X_CJ = _com_frame(-self._com[i])
            self.joints[name] = _joint(
                model,
                kind,
                jm,
                None if parent == 0 else bodies[parent - 1],
                bodies[i - 1],
                parent_frame=X_PJ,
                child_frame=X_CJ,
                baumgarte=baumgarte,
                name=name,
            )
        gravity = np.array(model.gravity.linear, dtype=float)
        self._weight = UniformGravity(gravity, bodies=list(bodies)) if gravity.any() else None
        self._forces = tuple(forces)
        self._system_options = system_options
        self.system = self._build_system(())
        self._pin_data = pin.Data(model)

    # ---------------------------------------------------------------- construction
    @classmethod
    def from_urdf(
        cls,
        path: str | os.PathLike[str],
        base: str = "fixed",
        locked_joints: Sequence[str] | Mapping[str, Any] = (),
        package_dirs: Sequence[str] | None = None,
        *,
        gravity: Any = None,
        damping: float = 0.0,
        forces: Sequence[ForceModel] = (),
        baumgarte: Baumgarte | None = None,
        **system_options: Any,
    ) -> Robot:
        """Build a Robot from a URDF file.

        Parameters
        ----------
        path : str or path-like
            The URDF file.
        base : {"fixed", "floating"}
            A base fixed to the ground at the URDF's root, or floating (Pinocchio's
            free-flyer: 6 more coordinates, position then quaternion x, y, z, w).
        locked_joints : sequence of str, or mapping of str to joint coordinates
            Joints to lock (Pinocchio's ``buildReducedModel``): at their neutral coordinates,
            or at the coordinates given (Pinocchio's q of that joint).
        package_dirs : sequence of str, optional
            Where ``package://`` mesh paths resolve (kept for the view; the dynamics need no
            mesh).
        gravity : array_like (3,), optional
            g in N (m/s²); Pinocchio's default (0, 0, −9.81) if omitted; zeros for none.
        damping : float
            Viscous damping c ≥ 0 on every joint's rates (N·m·s/rad, N·s/m): a
            :class:`~gmuk.robots.JointSpringDamper` per joint when c > 0.
        forces : sequence of ForceModel
            More force models on the robot's bodies.
        baumgarte : Baumgarte, optional
            Stabilisation of every joint.
        **system_options
            Passed to :class:`gmuk.System` (``solver``, ``strict`` …).

        Raises
        ------
        DefinitionError
            For a missing file, an unknown base, a joint gmuk does not build (it lists them),
            a link whose inertia is not physical (negative mass or principal moment, moments
            against the triangle inequality) or a joint that moves no mass.

        Notes
        -----
        Links without mass or without rotational inertia (massless links between the
        revolutes of a hip, point masses) are built with ``allow_singular=True`` and solved
        by the tree solve, which eliminates each with the joint to its parent
        (docs/robotics.rst, "Links without mass or rotational inertia"). A principal moment
        at or below :data:`ROUND_OFF` times the robot's largest counts as zero.
        """
        pin = _pin()
        p = Path(path)
        if not p.is_file():
            raise DefinitionError(f"no URDF file at {str(path)!r}")
        if base not in ("fixed", "floating"):
            raise DefinitionError(f"base must be 'fixed' or 'floating'; got {base!r}")
        try:
            if base == "floating":
                model = pin.buildModelFromUrdf(str(p), pin.JointModelFreeFlyer())
            else:
                model = pin.buildModelFromUrdf(str(p))
        except (ValueError, RuntimeError) as exc:
            raise DefinitionError(f"Pinocchio could not read {str(path)!r}: {exc}") from None
        if locked_joints:
            model = _reduced(model, locked_joints)
        unsupported = sorted(
            {
                f"{model.names[i]} ({model.joints[i].shortname()})"
                for i in range(1, model.njoints)
                if model.joints[i].shortname() not in SUPPORTED_JOINTS
            }
        )
        if unsupported:
            raise DefinitionError(
                f"{p.name}: gmuk does not build these joints: {', '.join(unsupported)}; it builds "
                f"{', '.join(SUPPORTED_JOINTS)}"
            )
        if model.njoints == 1:
            raise DefinitionError(
                f"{p.name}: the model has no joint, so with a fixed base nothing moves; "
                "use base='floating' for a free body"
            )
        if gravity is not None:
            model.gravity.linear = as_array(gravity, (3,), "gravity", batch=False)
        robot = cls(
            model,
            base=base,
            forces=forces,
            baumgarte=baumgarte,
            package_dirs=package_dirs,
            path=p,
            **system_options,
        )
        c = real_number(damping, "damping", non_negative=True)
        if c > 0.0:
            robot = robot.with_forces(
                [JointSpringDamper(j, damping=c) for j in robot.joints.values()]
            )
        return robot

    def _build_system(self, extra: Sequence[ForceModel]) -> System:
        return self.with_parts(forces=extra)

    def with_forces(self, forces: Sequence[ForceModel]) -> Robot:
        """The same robot with more force models (on its bodies or joints) in its System."""
        new = copy.copy(self)
        new._forces = (*self._forces, *forces)
        new.system = new._build_system(())
        new._pin_data = _pin().Data(self.model)
        return new

    def with_parts(
        self,
        constraints: Sequence[Any] = (),
        forces: Sequence[ForceModel] = (),
        controllers: Sequence[Any] = (),
        **system_options: Any,
    ) -> System:
        """A new System: the robot's bodies, joints and weight with more parts."""
        options = {**self._system_options, **system_options}
        weight = [self._weight] if self._weight is not None else []
        return System(
            list(self.bodies),
            [*self.joints.values(), *constraints],
            [*weight, *self._forces, *forces],
            controllers,
            **options,
        )

    # ---------------------------------------------------------------- coordinates
    @property
    def nq(self) -> int:
        """Size of Pinocchio's configuration q."""
        return int(self.model.nq)

    @property
    def nv(self) -> int:
        """Size of Pinocchio's velocity v."""
        return int(self.model.nv)

    def joint(self, name: str) -> Joint:
        """The gmuk joint named ``name`` (Pinocchio's joint name, from the URDF)."""
        try:
            return self.joints[name]
        except KeyError:
            raise DefinitionError(
                f"no joint named {name!r}; the robot's joints are {list(self.joints)}"
            ) from None

    def body(self, link: str) -> RigidBody:
        """The rigid body of ``link``."""
        for b in self.bodies:
            if b.name == link:
                return b
        raise DefinitionError(f"no body {link!r}; bodies are {[b.name for b in self.bodies]}")

    def state(self, q: Any, v: Any, t: float = 0.0, *, system: System | None = None) -> State:
        """The State of Pinocchio-ordered coordinates q (nq,) and velocities v (nv,).

        Each body's pose is Pinocchio's ``oMi`` moved to the centre of mass; its twist is
        Pinocchio's ``data.v[i]`` ([v; ω] of frame i in frame i) as [ω; v] at the centre of
        mass. A floating base's q is its position then quaternion (x, y, z, w), normalised
        here; its v is [v; ω] in its own frame.
        """
        pin = _pin()
        q = as_array(q, (self.nq,), "q", batch=False)
        v = as_array(v, (self.nv,), "v", batch=False)
        q = q.copy()
        if self._floating is not None:
            iq = self.model.joints[self._floating].idx_q
            norm = np.linalg.norm(q[iq + 3 : iq + 7])
            if not norm > 0.0:
                raise DefinitionError("the floating base's quaternion q[3:7] is zero")
            q[iq + 3 : iq + 7] /= norm
        data = self._pin_data
        pin.forwardKinematics(self.model, data, q, v)
        g, V = {}, {}
        for i, body in enumerate(self.bodies, start=1):
            g_i = _se3_matrix(data.oMi[i])
            c = self._com[i]
            g[body.name] = g_i @ _com_frame(c)
            w = np.array(data.v[i].angular, dtype=float)
            lin = np.array(data.v[i].linear, dtype=float)
            V[body.name] = np.concatenate([w, lin + np.cross(w, c)])
        return (system or self.system).state(g=g, V=V, t=t)

    def _joint_frame(self, i: int) -> FloatArray:
        return _com_frame(-self._com[i])

    def _q_v(self, state: State) -> tuple[FloatArray, FloatArray]:
        """q (angles wrapped) and v of one state."""
        q, v = np.zeros(self.nq), np.zeros(self.nv)
        for i in range(1, self.model.njoints):
            jm = self.model.joints[i]
            iq, iv = jm.idx_q, jm.idx_v
            if i == self._floating:
                body = self.bodies[i - 1]
                X = self._joint_frame(i)
                g = state.pose(body) @ X
                q[iq : iq + 3] = g[:3, 3]
                q[iq + 3 : iq + 7] = _quat_xyzw(g[:3, :3])
                VJ = se3._Ad(se3._inverse(X)) @ state.twist(body)
                v[iv : iv + 6] = np.concatenate([VJ[3:], VJ[:3]])
                continue
            joint = self.joints[self.model.names[i]]
            qj, vj = _pin_coordinates(jm, joint, state)
            q[iq : iq + jm.nq] = qj
            v[iv : iv + jm.nv] = vj
        return q, v

    def configuration(self, traj: Trajectory) -> FloatArray:
        """Pinocchio's q at every output of ``traj`` (N, nq), revolute angles unwrapped with
        their rates (:func:`gmuk.robots.joints.unwrap_with_rates`; a continuous joint's
        cos/sin pair needs none)."""
        return self._along(traj)[0]

    def velocity(self, traj: Trajectory) -> FloatArray:
        """Pinocchio's v at every output of ``traj`` (N, nv)."""
        return self._along(traj)[1]

    def _along(self, traj: Trajectory) -> tuple[FloatArray, FloatArray]:
        rows = [self._q_v(traj.state(k)) for k in range(len(traj))]
        q = np.array([r[0] for r in rows]).reshape(len(rows), self.nq)
        v = np.array([r[1] for r in rows]).reshape(len(rows), self.nv)
        t = np.asarray(traj.t)
        for i in range(1, self.model.njoints):
            jm = self.model.joints[i]
            if jm.shortname() in _ANGLE_JOINTS:
                q[:, jm.idx_q : jm.idx_q + 1] = unwrap_with_rates(
                    q[:, jm.idx_q : jm.idx_q + 1], v[:, jm.idx_v : jm.idx_v + 1], t
                )
        return q, v

    def joint_accelerations(self, state: State, Vdot: FloatArray) -> FloatArray:
        """Pinocchio's joint accelerations (nv,) from the bodies' V̇ (n_bodies, 6)
        ([ω̇; v̇] of each body at its centre of mass, in its frame)."""
        a = np.zeros(self.nv)
        index = {b.name: k for k, b in enumerate(self.bodies)}
        for i in range(1, self.model.njoints):
            jm = self.model.joints[i]
            iv = jm.idx_v
            if i == self._floating:
                X = self._joint_frame(i)
                AJ = se3._Ad(se3._inverse(X)) @ Vdot[i - 1]
                a[iv : iv + 6] = np.concatenate([AJ[3:], AJ[:3]])
                continue
            joint = self.joints[self.model.names[i]]
            names = [b if isinstance(b, str) else b.name for b in joint.bodies]
            VdC = Vdot[index[names[-1]]]
            VdP = np.zeros(6) if joint.grounded else Vdot[index[names[0]]]
            Ar = joint.relative_acceleration(state, VdP, VdC)
            a[iv : iv + jm.nv] = _pin_rates(jm, joint, Ar)
        return a

    def forward_dynamics(self, q: Any, v: Any, tau: Any) -> FloatArray:
        """Joint accelerations (nv,) under joint efforts ``tau`` (nv,), in Pinocchio's
        convention: what ``pin.aba(model, data, q, v, tau)`` returns, computed by gmuk's
        Udwadia–Kalaba solve of the maximal-coordinate system (a floating base's entries of
        ``tau`` are a wrench [f; τ] on its frame, as Pinocchio's)."""
        tau = as_array(tau, (self.nv,), "tau", batch=False)
        extra: list[ForceModel] = []
        for i in range(1, self.model.njoints):
            jm = self.model.joints[i]
            t_j = tau[jm.idx_v : jm.idx_v + jm.nv]
            if not t_j.any():
                continue
            if i == self._floating:
                from gmuk.forces.mechanical import AppliedWrench

                X = self._joint_frame(i)
                W = se3._Ad(se3._inverse(X)).T @ np.concatenate([t_j[3:], t_j[:3]])
                extra.append(AppliedWrench(self.bodies[i - 1], W))
                continue
            joint = self.joints[self.model.names[i]]
            extra.append(JointEffort(joint, _pin_effort(jm, t_j)))
        system = self._build_system(extra) if extra else self.system
        state = self.state(q, v, system=system)
        acc = system.accelerations(state)
        Vdot = np.asarray(acc.total, dtype=float).reshape(len(self.bodies), 6)
        return self.joint_accelerations(state, Vdot)

    def __repr__(self) -> str:
        name = self.path.name if self.path else self.model.name
        return (
            f"Robot({name!r}, base={self.base!r}, bodies={len(self.bodies)}, "
            f"joints={len(self.joints)}, nq={self.nq}, nv={self.nv})"
        )


_ANGLE_JOINTS = (
    "JointModelRX",
    "JointModelRY",
    "JointModelRZ",
    "JointModelRevoluteUnaligned",
)


def _first_link(model: Any, i: int) -> str:
    pin = _pin()
    for f in model.frames:
        if f.parentJoint == i and f.type == pin.FrameType.BODY:
            return str(f.name)
    return str(model.names[i])


def _subspace_column(model: Any, jm: Any) -> FloatArray:
    """Pinocchio's motion subspace S (6,) [v; ω] of a one-dof joint, at the neutral q."""
    pin = _pin()
    jd = jm.createData()
    jm.calc(jd, pin.neutral(model))
    return np.array(jd.S, dtype=float).reshape(6)


def _joint(model: Any, kind: str, jm: Any, parent: Any, child: Any, **kw: Any) -> Joint:
    if kind.startswith(("JointModelR", "JointModelRevolute")):
        return RevoluteJoint(parent, child, axis=_subspace_column(model, jm)[3:], **kw)
    if kind.startswith(("JointModelP", "JointModelPrismatic")) and kind != "JointModelPlanar":
        return PrismaticJoint(parent, child, axis=_subspace_column(model, jm)[:3], **kw)
    if kind == "JointModelSpherical":
        return SphericalJoint(parent, child, **kw)
    if kind == "JointModelPlanar":
        return PlanarJoint(parent, child, normal=(0.0, 0.0, 1.0), **kw)
    raise DefinitionError(f"gmuk does not build a {kind}")  # pragma: no cover - screened


def _pin_coordinates(jm: Any, joint: Joint, state: State) -> tuple[FloatArray, FloatArray]:
    """Pinocchio's (q, v) of one joint from gmuk's."""
    kind = jm.shortname()
    rates = joint.rates(state)
    if kind in ("JointModelSpherical",):
        return _quat_xyzw(joint.relative_pose(state)[:3, :3]), joint.relative_twist(state)[:3]
    if kind == "JointModelPlanar":
        theta, x, y = joint.coordinates(state)
        w, vx, vy = rates
        return np.array([x, y, np.cos(theta), np.sin(theta)]), np.array([vx, vy, w])
    qj = joint.coordinates(state)
    if "RUB" in kind or "Unbounded" in kind:
        return np.array([np.cos(qj[0]), np.sin(qj[0])]), rates
    return qj, rates


def _pin_rates(jm: Any, joint: Joint, Vdot_rel: FloatArray) -> FloatArray:
    """Pinocchio's joint acceleration from V̇_rel (components in J_c)."""
    kind = jm.shortname()
    if kind == "JointModelSpherical":
        return Vdot_rel[:3]
    a = joint._S_pinv @ Vdot_rel
    if kind == "JointModelPlanar":
        return np.array([a[1], a[2], a[0]])
    return a


def _pin_effort(jm: Any, tau: FloatArray) -> FloatArray:
    """gmuk's generalised force of one joint from Pinocchio's τ of that joint."""
    if jm.shortname() == "JointModelPlanar":
        return np.array([tau[2], tau[0], tau[1]])
    return tau


def _reduced(model: Any, locked: Sequence[str] | Mapping[str, Any]) -> Any:
    pin = _pin()
    q_ref = pin.neutral(model)
    names = list(locked.keys()) if isinstance(locked, Mapping) else list(locked)
    ids = []
    for name in names:
        if not isinstance(name, str) or not model.existJointName(name):
            raise DefinitionError(
                f"locked_joints: no joint named {name!r}; joints are {list(model.names)[1:]}"
            )
        jid = model.getJointId(name)
        ids.append(jid)
        if isinstance(locked, Mapping):
            jm = model.joints[jid]
            value = as_array(locked[name], (jm.nq,), f"locked_joints[{name!r}]", batch=False)
            q_ref[jm.idx_q : jm.idx_q + jm.nq] = value
    return pin.buildReducedModel(model, ids, q_ref)
