"""The contract of every built-in part (docs/architecture.rst, "The forms of a part").

Every ForceModel, Controller and Constraint subclass defined in gmuk is discovered by walking
``__subclasses__`` after importing every gmuk module. Each concrete one must declare its forms
in its own body (``_forms = Forms(compiled=..., symbolic=...)``: True, or the reason it has
none) and have a factory of random valid instances here. Then, at 100 random states each:

* its Python form (``wrenches``, ``control``, ``rows``/``value``) runs and is finite;
* a declared compiled form exists for the case and gives the Python numbers: the kernel of
  ``_compiled_term`` is called through its address with the compiled loop's own callers
  (``_call_force``, ``_call_control``; ``gmuk.engine.tree._call_rows`` for constraint rows,
  which the loop's dense rows and tree blocks both call) and the parameters of
  ``_compiled_term``, arguments laid out as the compiled loop lays them out;
* a declared symbolic form exists and gives the Python numbers when evaluated on numbers
  (CasADi ``DM``): force models through ``gmuk.optimize.parts.force_terms``, inequalities
  through ``parts.inequality_value``;
* a form declared absent is absent (the loop would get None, the optimiser a
  DefinitionError).

Tolerances. Python and compiled forms run the same kernel on the same numbers: they are
compared to 1e-14 of each 3-vector block's size (they are equal in practice; the margin
allows for a future loop that packs a parameter through a different float path). Symbolic
forms are the same formulas in CasADi's own arithmetic (different association and libm
calls): 1e-12 of each block's size.

A class that cannot declare its forms yet is listed in :data:`PENDING` with the reason
(none is); that list fails as soon as the class declares them, so that it is removed then.
"""

from __future__ import annotations

import copy
import gc
import importlib
import inspect
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache
from typing import Any

import casadi as ca
import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gmuk
from gmuk._forms import FORMS, Forms
from gmuk._numba import kernel_address
from gmuk.constraints.base import ROWS_KERNEL, Constraint
from gmuk.control.base import CONTROL_KERNEL, Controller
from gmuk.engine.integrators._compiled import _call_control, _call_force
from gmuk.engine.tree import _call_rows
from gmuk.errors import DefinitionError
from gmuk.forces.base import FORCE_KERNEL, ForceModel
from gmuk.lie import se3, so3
from gmuk.optimize import parts
from gmuk.orbits import KeplerOrbit, LVLHReference

PYTHON_COMPILED_RTOL = 1e-14
SYMBOLIC_RTOL = 1e-12
CONTRACT = settings(max_examples=100, deadline=None)
BASES = (ForceModel, Controller, Constraint)

#: Built-in classes whose forms are declared in a file being rewritten (issue 24, items 1
#: and 5: the constraints' compiled forms), with the reason.
PENDING: dict[str, str] = {}


# ---------------------------------------------------------------- discovery


@cache
def _import_all() -> None:
    for info in pkgutil.walk_packages(gmuk.__path__, "gmuk."):
        importlib.import_module(info.name)


def _subclasses(base: type) -> list[type]:
    out, todo = [], list(base.__subclasses__())
    while todo:
        cls = todo.pop()
        out.append(cls)
        todo.extend(cls.__subclasses__())
    return out


def _qualname(cls: type) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"


def discover() -> list[type]:
    """Every concrete ForceModel, Controller and Constraint subclass defined in gmuk."""
    _import_all()
    found = {
        cls
        for base in BASES
        for cls in _subclasses(base)
        if cls.__module__.split(".")[0] == "gmuk" and not inspect.isabstract(cls)
    }
    return sorted(found, key=_qualname)


def problems(classes: list[type]) -> list[str]:
    """What the contract finds missing: a class that declares no forms in its own body, or
    has no factory here, or a PENDING entry that no longer applies."""
    out = []
    for cls in classes:
        name = _qualname(cls)
        declared = "_forms" in vars(cls)
        if name in PENDING:
            if declared:
                out.append(f"{name} declares its forms now: remove it from PENDING")
        elif not declared:
            out.append(
                f"{name} declares no forms: give it `_forms = Forms(compiled=..., "
                "symbolic=...)` in its class body (True, or why it has none)"
            )
        elif not isinstance(vars(cls)["_forms"], Forms):
            out.append(f"{name}._forms is not a gmuk._forms.Forms")
        if cls not in FACTORIES:
            out.append(f"{name} has no factory in tests/test_part_contract.py (FACTORIES)")
    for name in PENDING:
        if name not in {_qualname(c) for c in classes}:
            out.append(f"PENDING names {name}, which is no longer a gmuk part")
    return out


# ---------------------------------------------------------------- random valid parts


@dataclass
class Case:
    """A part in a System at a random state; ``modeled`` and ``z`` for controllers."""

    part: Any
    system: gmuk.System
    state: gmuk.State
    modeled: np.ndarray | None = None
    extra: dict[str, Any] = field(default_factory=dict)


def _rotation(rng: np.random.Generator) -> np.ndarray:
    return so3.exp(rng.uniform(-np.pi, np.pi, 3))


def _inertia(rng: np.random.Generator) -> np.ndarray:
    R = _rotation(rng)
    a, b = rng.uniform(0.5, 5.0, 2)
    c = rng.uniform(abs(a - b), a + b)  # the triangle inequality
    return R @ np.diag([a, b, max(c, 0.1)]) @ R.T


def _direction(rng: np.random.Generator) -> np.ndarray:
    u = rng.normal(size=3)
    return u / np.linalg.norm(u)


def _pose(rng: np.random.Generator, r: np.ndarray) -> np.ndarray:
    g = np.eye(4)
    g[:3, :3] = _rotation(rng)
    g[:3, 3] = r
    return g


def _bodies(rng: np.random.Generator) -> tuple[gmuk.RigidBody, gmuk.PointMass]:
    return (
        gmuk.RigidBody("rigid", rng.uniform(10.0, 1e4), _inertia(rng) * rng.uniform(1.0, 1e3)),
        gmuk.PointMass("point", rng.uniform(1.0, 1e3)),
    )


def _case(
    rng: np.random.Generator,
    part: Any,
    bodies: tuple[Any, ...],
    radius: tuple[float, float],
    speed: float,
    **system: Any,
) -> Case:
    """``part`` in a System of ``bodies``, each at a random distance in ``radius`` (m) from
    the origin with random attitudes, velocities of order ``speed`` (m/s) and angular rates
    of order 0.1 rad/s, at a random time."""
    kind = "forces" if isinstance(part, ForceModel) else "constraints"
    if isinstance(part, Controller):
        kind = "controllers"
    sys = gmuk.System(list(bodies), **{kind: [part]}, **system)  # type: ignore[arg-type]
    g, V, r, v = {}, {}, {}, {}
    for b in bodies:
        pos = rng.uniform(*radius) * _direction(rng)
        if b.kind == "rigid":
            g[b.name] = _pose(rng, pos)
            V[b.name] = np.concatenate([0.1 * rng.normal(size=3), speed * rng.normal(size=3)])
        else:
            r[b.name], v[b.name] = pos, speed * rng.normal(size=3)
    state = sys.state(g=g, V=V, r=r, v=v, t=float(rng.uniform(0.0, 1e4)))
    return Case(part, sys, state)


@cache
def _moon_field(degree: int) -> Any:
    return gmuk.gravity.load("GRGM660PRIM", degree)


def _moon(rng: np.random.Generator, degree: int) -> gmuk.CelestialBody:
    rotation = gmuk.UniformRotation(rng.uniform(-1e-5, 1e-5), rng.uniform(-np.pi, np.pi))
    return gmuk.CelestialBody.moon(field=_moon_field(degree), rotation=rotation)


def _orbit(rng: np.random.Generator) -> KeplerOrbit:
    return KeplerOrbit(
        p=rng.uniform(2.0e6, 5.0e6),
        e=rng.uniform(0.0, 0.6),
        i=rng.uniform(0.0, np.pi),
        raan=rng.uniform(-np.pi, np.pi),
        argp=rng.uniform(-np.pi, np.pi),
        mu=4.9028e12,
    )


def _point_mass_gravity(rng: np.random.Generator) -> Case:
    model = gmuk.PointMassGravity(rng.uniform(1e12, 4e14))
    return _case(rng, model, _bodies(rng), (1.8e6, 4e7), 1e3)


def _gravity_gradient(rng: np.random.Generator) -> Case:
    model = gmuk.GravityGradient(rng.uniform(1e12, 4e14))
    return _case(rng, model, _bodies(rng), (1.8e6, 4e7), 1e3)


def _spherical_harmonic_gravity(rng: np.random.Generator) -> Case:
    # the symbolic form builds one CasADi function per field (cached), so a few degrees up
    # to 20, orbital radii (30 km above the mean lunar radius to 4000 km from the centre)
    degree = (0, 2, 3, 8, 20)[int(rng.integers(0, 5))]
    finite = bool(rng.integers(0, 2))
    model = gmuk.SphericalHarmonicGravity(_moon(rng, degree), finite_size_force=finite)
    return _case(rng, model, _bodies(rng), (1.768e6, 4e6), 1e3)


def _thesis_gravity(rng: np.random.Generator) -> Case:
    normalization = ("thesis_eq26c_intended", "4pi")[int(rng.integers(0, 2))]
    model = gmuk.forces.ThesisRadialHarmonicGravity(
        _moon(rng, int(rng.integers(0, 7))), normalization=normalization
    )
    return _case(rng, model, _bodies(rng), (1.8e6, 4e6), 1e3)


def _harmonic_perturbation(rng: np.random.Generator) -> Case:
    from gmuk.scenarios.unmodeled import HarmonicPerturbation

    model = HarmonicPerturbation(_moon(rng, int(rng.integers(2, 9))))
    return _case(rng, model, _bodies(rng), (1.8e6, 4e6), 1e3)


def _uniform_gravity(rng: np.random.Generator) -> Case:
    return _case(rng, gmuk.UniformGravity(rng.normal(size=3) * 10.0), _bodies(rng), (0, 100), 10)


def _epoch(rng: np.random.Generator) -> Any:
    from gmuk.environment import Epoch

    return Epoch.from_tdb_seconds(rng.uniform(-1.5e9, 1.5e9))  # 1952-2047


def _third_body(rng: np.random.Generator) -> Case:
    from gmuk.environment import ThirdBodyPerturbation

    perturber, centre = (("sun", "earth"), ("moon", "earth"), ("earth", "moon"))[rng.integers(3)]
    model = ThirdBodyPerturbation(perturber, _epoch(rng), centre=centre)
    return _case(rng, model, _bodies(rng), (1.8e6, 4.3e7), 3e3)


def _cannonball_srp(rng: np.random.Generator) -> Case:
    from gmuk.environment import CannonballSRP

    model = CannonballSRP(_epoch(rng), rng.uniform(0.1, 50.0), rng.uniform(1.0, 2.0))
    return _case(rng, model, _bodies(rng), (6.6e6, 4.3e7), 3e3)


def _flat_plate_srp(rng: np.random.Generator) -> Case:
    from gmuk.environment import FlatPlateSRP, Plate

    plates = []
    for _ in range(int(rng.integers(1, 7))):
        c = rng.dirichlet([1.0, 1.0, 1.0])
        plates.append(
            Plate(rng.uniform(0.1, 20.0), _direction(rng), c[0], c[1], 1.0 - c[0] - c[1],
                  rng.normal(size=3))
        )  # fmt: skip
    model = FlatPlateSRP(_epoch(rng), plates)
    return _case(rng, model, _bodies(rng), (6.6e6, 4.3e7), 3e3)


def _atmospheric_drag(rng: np.random.Generator) -> Case:
    from gmuk.environment import EARTH_RADIUS, AtmosphericDrag

    model = AtmosphericDrag(rng.uniform(1.5, 2.5), rng.uniform(0.1, 20.0))
    return _case(rng, model, _bodies(rng), (EARTH_RADIUS + 1e5, EARTH_RADIUS + 1.5e6), 7e3)


def _linear_spring_damper(rng: np.random.Generator) -> Case:
    model = gmuk.LinearSpringDamper(
        rng.uniform(0.0, 1e3), rng.uniform(0.0, 1e2), anchor=rng.normal(size=3) * 10.0
    )
    return _case(rng, model, _bodies(rng), (0.0, 100.0), 10.0)


def _applied_wrench(rng: np.random.Generator) -> Case:
    bodies = _bodies(rng)
    body = bodies[int(rng.integers(0, 2))]
    a, b = rng.normal(size=(2, 6 if body.kind == "rigid" else 3))
    constant = bool(rng.integers(0, 2))
    wrench = a if constant else (lambda t: a + np.sin(t) * b)
    frame = "inertial" if body.kind == "point" or rng.integers(0, 2) else "body"
    return _case(rng, gmuk.AppliedWrench(body, wrench, frame=frame), bodies, (0.0, 100.0), 10.0)


def _spring_damper(rng: np.random.Generator) -> Case:
    bodies = _bodies(rng)
    i = int(rng.integers(0, 2))
    a = bodies[i]
    b = None if rng.integers(0, 3) == 0 else bodies[1 - i]
    model = gmuk.SpringDamper(
        a,
        rng.normal(size=3) if a.kind == "rigid" else np.zeros(3),
        b,
        rng.normal(size=3) * (10.0 if b is None else 1.0),
        stiffness=rng.uniform(0.0, 1e3),
        damping=rng.uniform(0.0, 10.0),
        rest_length=rng.uniform(0.0, 5.0),
    )
    return _case(rng, model, bodies, (1.0, 100.0), 10.0)


def _slack_damping(rng: np.random.Generator) -> Case:
    w = gmuk.SlackCoordinate("w", rng.uniform(0.1, 10.0))
    model = gmuk.SlackDamping(rng.uniform(0.0, 10.0))
    sys = gmuk.System([w], forces=[model])
    state = sys.state(s={"w": rng.normal()}, s_dot={"w": rng.normal()}, t=rng.uniform(0, 10))
    return Case(model, sys, state)


def _morse_lyapunov(rng: np.random.Generator) -> Case:
    body = gmuk.RigidBody("rigid", rng.uniform(10.0, 1e4), _inertia(rng) * rng.uniform(1, 1e3))
    ref = LVLHReference(_orbit(rng))
    a = np.sort(rng.uniform(0.5, 5.0, 3))[::-1] + np.array([2.0, 1.0, 0.0])  # distinct
    k11, k21 = rng.uniform(0.05, 1.0), rng.uniform(0.5, 2.0, 3)
    ctl = gmuk.MorseLyapunovController(
        body,
        ref,
        k11=k11,
        k12=rng.uniform(0.05, 1.0),
        k21=k21,
        k22=rng.uniform(1e-6, 1e-3, 3),
        kappa=rng.uniform(1e-5, 1e-2),
        a=a,
        k_integral=rng.uniform(0.0, 1e-6) if rng.integers(0, 2) else 0.0,
        morse_weight=2.0 * k11 * float(k21.min()),
        robust=bool(rng.integers(0, 2)),
        kappa2=rng.uniform(-1e25, 1e25),
    )
    sys = gmuk.System([body], controllers=[ctl])
    t = float(rng.uniform(0.0, 2e4))
    nominal = ref.evaluate(t)
    near = nominal.g @ se3.exp(np.concatenate([rng.normal(size=3), 1e3 * rng.normal(size=3)]))
    V = nominal.V + np.concatenate([0.01 * rng.normal(size=3), rng.normal(size=3)])
    state = sys.state(g={"rigid": near}, V={"rigid": V}, z=rng.normal(size=6), t=t)
    return Case(ctl, sys, state, modeled=rng.normal(size=6))


def _plan(rng: np.random.Generator, names: tuple[str, ...], dofs: tuple[int, ...]) -> Any:
    """An OptimalControlResult standing for a solved problem with what OpenLoopControl reads:
    body names and dofs, and the control u(t) (a smooth random function here)."""
    from gmuk.optimize.result import OptimalControlResult

    c = rng.normal(size=(3, sum(dofs)))

    class Plan(OptimalControlResult):
        def __init__(self) -> None:  # a stand-in: none of the solved fields
            object.__setattr__(self, "body_names", names)
            object.__setattr__(self, "body_dofs", dofs)

        def control(self, t: float) -> np.ndarray:  # type: ignore[override]
            return c[0] + c[1] * np.sin(t) + c[2] * t

    return Plan()


def _open_loop(rng: np.random.Generator) -> Case:
    from gmuk.optimize.result import OpenLoopControl

    bodies = _bodies(rng)
    ctl = OpenLoopControl(_plan(rng, ("rigid", "point"), (6, 3)))
    case = _case(rng, ctl, bodies, (0.0, 100.0), 10.0)
    case.modeled = rng.normal(size=9)
    return case


def _plane_bound(rng: np.random.Generator) -> Case:
    bodies = _bodies(rng)
    body = bodies[int(rng.integers(0, 2))]
    normal = rng.normal(size=3)
    # a bound the random state satisfies: |n̂ · r| ≤ 100 m < 200 m
    bound = gmuk.PlaneBound(body, normal, upper=200.0, lower=-200.0 if rng.integers(0, 2) else None)
    return _case(rng, bound, bodies, (0.0, 100.0), 10.0)


def _tracking_error_bound(rng: np.random.Generator) -> Case:
    orbit = _orbit(rng)
    quantity = ("position", "velocity")[int(rng.integers(0, 2))]
    form = ("norm", "squared")[int(rng.integers(0, 2))]
    point = gmuk.PointMass("point", rng.uniform(1.0, 1e3))
    t = float(rng.uniform(0.0, 1e4))
    dr, dv = 1e3 * rng.normal(size=3), rng.normal(size=3)
    # a bound of the error's own size (the state inside it), so that the value is of the
    # size of the error and the comparison sees it
    size = float(np.linalg.norm(dr if quantity == "position" else dv))
    bound = gmuk.TrackingErrorBound(
        point, orbit, size * rng.uniform(1.1, 3.0), quantity=quantity, form=form
    )
    sys = gmuk.System([point], [bound])
    r, v = orbit.position(t), orbit.velocity(t)
    state = sys.state(r={"point": r + dr}, v={"point": v + dv}, t=t)
    return Case(bound, sys, state)


def _configuration_tracking(rng: np.random.Generator) -> Case:
    body = _bodies(rng)[0]
    c = gmuk.ConfigurationTracking(body, LVLHReference(_orbit(rng)), baumgarte=_baumgarte(rng))
    return _case(rng, c, (body,), (1.8e6, 4e6), 1e3)


def _configuration_tracking_t2(rng: np.random.Generator) -> Case:
    body = _bodies(rng)[0]
    c = gmuk.ConfigurationTrackingT2(body, LVLHReference(_orbit(rng)))
    return _case(rng, c, (body,), (1.8e6, 4e6), 1e3)


def _virtual_pair_t2(rng: np.random.Generator) -> Case:
    lead = gmuk.RigidBody("lead", 1.0, np.eye(3))
    body = _bodies(rng)[0]
    c = gmuk.VirtualPairT2(body, lead, LVLHReference(_orbit(rng)))
    return _case(rng, c, (lead, body), (1.8e6, 4e6), 1e3)


def _relative_constraint(rng: np.random.Generator) -> Case:
    lead = gmuk.RigidBody("lead", rng.uniform(1.0, 10.0), _inertia(rng))
    body = _bodies(rng)[0]
    free = [int(i) for i in rng.choice(6, size=int(rng.integers(0, 4)), replace=False)]
    c = gmuk.RelativeConstraint(body, lead, free_axes=free, baumgarte=_baumgarte(rng))
    return _case(rng, c, (lead, body), (0.0, 100.0), 10.0)


def _joint(cls: type) -> Callable[[np.random.Generator], Case]:
    """A joint of kind ``cls`` between two random bodies, or to the ground, at random joint
    frames and random (not necessarily consistent) states."""

    def make(rng: np.random.Generator) -> Case:
        from gmuk import robots

        parent = gmuk.RigidBody("parent", rng.uniform(1.0, 10.0), _inertia(rng))
        child = _bodies(rng)[0]
        grounded = bool(rng.integers(0, 2))
        kw: dict[str, Any] = {
            "parent_frame": _pose(rng, rng.normal(size=3)),
            "child_frame": _pose(rng, 0.3 * rng.normal(size=3)),
            "baumgarte": _baumgarte(rng),
        }
        if cls in (robots.RevoluteJoint, robots.PrismaticJoint, robots.CylindricalJoint):
            kw["axis"] = _direction(rng)
        elif cls is robots.ScrewJoint:
            kw.update(axis=_direction(rng), pitch=rng.uniform(-0.1, 0.1) or 0.05)
        elif cls is robots.PlanarJoint:
            kw["normal"] = _direction(rng)
        elif cls is robots.UniversalJoint:
            a1 = _direction(rng)
            a2 = np.cross(a1, _direction(rng))
            kw.update(axis1=a1, axis2=a2 / np.linalg.norm(a2))
        joint = cls(None if grounded else parent, child, **kw)
        bodies = (child,) if grounded else (parent, child)
        return _case(rng, joint, bodies, (0.0, 10.0), 1.0)

    return make


def _joint_force(cls: type) -> Callable[[np.random.Generator], Case]:
    """A generalised force of kind ``cls`` on a random revolute or prismatic joint."""

    def make(rng: np.random.Generator) -> Case:
        from gmuk import robots

        parent = gmuk.RigidBody("parent", rng.uniform(1.0, 10.0), _inertia(rng))
        child = _bodies(rng)[0]
        kind = robots.RevoluteJoint if rng.integers(0, 2) else robots.PrismaticJoint
        joint = kind(parent, child, axis=_direction(rng), parent_frame=_pose(rng, np.ones(3)))
        if cls is robots.JointEffort:
            force = cls(joint, rng.normal(size=1))
        else:
            force = cls(joint, stiffness=rng.uniform(0, 10), damping=rng.uniform(0, 1))
        return _case(rng, force, (parent, child), (0.0, 10.0), 1.0)

    return make


def _mrp_feedback(rng: np.random.Generator) -> Case:
    from gmuk.actuators import ReactionWheel

    n = 3  # the compiled form's case (other counts run in Python: tests/control/test_mrp.py)
    axes = list(_rotation(rng).T)
    wheels = [
        ReactionWheel(
            g,
            rng.uniform(0.01, 0.2),
            max_torque=rng.uniform(0.05, 1.0) if rng.integers(0, 2) else np.inf,
            max_speed=rng.uniform(50.0, 700.0),
            friction=rng.uniform(0.0, 1e-3),
        )
        for g in axes
    ]
    I_B = _inertia(rng) * rng.uniform(100.0, 1e3)
    ctl = gmuk.MRPFeedback(
        "bus",
        wheels,
        K=rng.uniform(0.1, 10.0),
        P=rng.uniform(1.0, 50.0),
        inertia_B=I_B,
        K_I=rng.uniform(0.0, 0.01) if rng.integers(0, 2) else 0.0,
        integral_limit=rng.uniform(0.01, 1.0),
        R_NR=_rotation(rng),
    )
    bus = gmuk.RigidBody("bus", 750.0, I_B)  # the contract compares forms, not the plant
    sys = gmuk.System([bus], controllers=[ctl])
    state = sys.state(
        g={"bus": _pose(rng, np.zeros(3))},
        V={"bus": np.r_[0.1 * rng.normal(size=3), 0.0, 0.0, 0.0]},
        z=np.r_[rng.normal(size=n) * 5.0, rng.normal(size=3) * 0.5],
        t=float(rng.uniform(0.0, 1e3)),
    )
    return Case(ctl, sys, state, modeled=rng.normal(size=6))


def _momentum_wheels(rng: np.random.Generator) -> Case:
    from gmuk.actuators import MomentumWheels, ReactionWheel

    n = int(rng.integers(1, 5))
    wheels = [
        ReactionWheel(_direction(rng), rng.uniform(0.01, 0.2), friction=rng.uniform(0.0, 1e-3))
        for _ in range(n)
    ]
    torques = rng.normal(size=n)
    ctl = MomentumWheels("bus", wheels, lambda t, R, w, s: torques)
    bus = gmuk.RigidBody("bus", 750.0, _inertia(rng) * 1e3)
    sys = gmuk.System([bus], controllers=[ctl])
    state = sys.state(
        g={"bus": _pose(rng, np.zeros(3))},
        V={"bus": np.r_[0.1 * rng.normal(size=3), 0.0, 0.0, 0.0]},
        z=rng.normal(size=n) * 5.0,
    )
    return Case(ctl, sys, state)


def _thrusters(rng: np.random.Generator) -> Case:
    from gmuk.actuators import Thruster, Thrusters

    n = int(rng.integers(1, 6))
    thrusters = [
        Thruster(rng.normal(size=3), _direction(rng), rng.uniform(1.0, 50.0), rng.uniform(100, 400))
        for _ in range(n)
    ]
    body = gmuk.RigidBody("sc", rng.uniform(100.0, 1000.0), _inertia(rng) * 1e2)
    ctl = Thrusters(body, thrusters, dry_mass=0.5 * body.mass)
    sys = gmuk.System([body], controllers=[ctl])
    state = sys.state(
        g={"sc": _pose(rng, np.zeros(3))},
        V={"sc": 0.1 * rng.normal(size=6)},
        z=np.r_[body.mass * rng.uniform(0.6, 1.0), rng.uniform(0.0, 1.0, size=n)],
    )
    return Case(ctl, sys, state)


def _wheel_motors(rng: np.random.Generator) -> Case:
    from gmuk.actuators import ReactionWheel, WheelArray, WheelMotors

    wheels = WheelArray(
        [
            ReactionWheel(g, rng.uniform(0.01, 0.2), friction=rng.uniform(0.0, 1e-3))
            for g in _rotation(rng).T
        ]
    )
    bus = gmuk.RigidBody("bus", 750.0, _inertia(rng) * 1e3)
    bodies, cons = wheels.uk_parts(bus)
    torques = rng.normal(size=3)
    model = WheelMotors(bus, bodies, wheels, lambda t, R, w, s: torques)
    return _case(rng, model, (bus, *bodies), (0, 10), 1.0, constraints=cons)


def _point_plane_contact(rng: np.random.Generator) -> Case:
    from gmuk.constraints.unilateral import PointPlaneContact

    body = _bodies(rng)[0]
    points = rng.normal(size=(int(rng.integers(1, 5)), 3))
    mu = float(rng.uniform(0.0, 1.0)) if rng.integers(0, 2) else 0.0  # with friction or not
    c = PointPlaneContact(body, points, normal=_direction(rng), height=rng.normal(), friction=mu)
    return _case(rng, c, (body,), (0.0, 10.0), 1.0)


def _joint_limit(rng: np.random.Generator) -> Case:
    from gmuk.constraints.unilateral import JointLimit
    from gmuk.robots import PrismaticJoint, RevoluteJoint

    parent = gmuk.RigidBody("parent", rng.uniform(1.0, 10.0), _inertia(rng))
    child = _bodies(rng)[0]
    kind = RevoluteJoint if rng.integers(0, 2) else PrismaticJoint
    joint = kind(parent, child, axis=_direction(rng), parent_frame=_pose(rng, np.ones(3)))
    lower = rng.uniform(-3.0, 0.0)
    c = JointLimit(joint, lower, lower + rng.uniform(0.1, 3.0), restitution=rng.uniform(0, 1))
    return _case(rng, c, (parent, child), (0.0, 10.0), 1.0)


def _baumgarte(rng: np.random.Generator) -> gmuk.Baumgarte | None:
    return None if rng.integers(0, 2) else gmuk.Baumgarte.critical(rng.uniform(0.01, 1.0))


def _factories() -> dict[type, Callable[[np.random.Generator], Case]]:
    from gmuk import robots
    from gmuk.actuators import MomentumWheels, Thrusters, WheelMotors
    from gmuk.constraints.unilateral import JointLimit, PointPlaneContact
    from gmuk.forces.thesis_gravity import ThesisRadialHarmonicGravity
    from gmuk.optimize.result import OpenLoopControl
    from gmuk.scenarios.unmodeled import HarmonicPerturbation

    return {
        gmuk.PointMassGravity: _point_mass_gravity,
        gmuk.GravityGradient: _gravity_gradient,
        gmuk.SphericalHarmonicGravity: _spherical_harmonic_gravity,
        ThesisRadialHarmonicGravity: _thesis_gravity,
        HarmonicPerturbation: _harmonic_perturbation,
        gmuk.UniformGravity: _uniform_gravity,
        gmuk.LinearSpringDamper: _linear_spring_damper,
        gmuk.AppliedWrench: _applied_wrench,
        gmuk.SpringDamper: _spring_damper,
        gmuk.SlackDamping: _slack_damping,
        gmuk.MorseLyapunovController: _morse_lyapunov,
        OpenLoopControl: _open_loop,
        gmuk.PlaneBound: _plane_bound,
        gmuk.TrackingErrorBound: _tracking_error_bound,
        gmuk.ConfigurationTracking: _configuration_tracking,
        gmuk.ConfigurationTrackingT2: _configuration_tracking_t2,
        gmuk.VirtualPairT2: _virtual_pair_t2,
        gmuk.RelativeConstraint: _relative_constraint,
        gmuk.MRPFeedback: _mrp_feedback,
        WheelMotors: _wheel_motors,
        MomentumWheels: _momentum_wheels,
        Thrusters: _thrusters,
        **_environment_factories(),
        **{cls: _joint(cls) for cls in _joint_kinds()},
        robots.JointEffort: _joint_force(robots.JointEffort),
        robots.JointSpringDamper: _joint_force(robots.JointSpringDamper),
        PointPlaneContact: _point_plane_contact,
        JointLimit: _joint_limit,
    }


def _joint_kinds() -> list[type]:
    from gmuk import robots

    return [
        robots.FixedJoint,
        robots.RevoluteJoint,
        robots.PrismaticJoint,
        robots.CylindricalJoint,
        robots.ScrewJoint,
        robots.SphericalJoint,
        robots.PlanarJoint,
        robots.UniversalJoint,
    ]


def _environment_factories() -> dict[type, Callable[[np.random.Generator], Case]]:
    from gmuk import environment as env

    return {
        env.ThirdBodyPerturbation: _third_body,
        env.CannonballSRP: _cannonball_srp,
        env.FlatPlateSRP: _flat_plate_srp,
        env.AtmosphericDrag: _atmospheric_drag,
    }


FACTORIES = _factories()


# ---------------------------------------------------------------- the forms, evaluated


def _blocks_close(actual: Any, expected: Any, rtol: float, what: str) -> None:
    """Equal to ``rtol`` of each 3-vector block's size (torques and forces, or ω and v
    rates, have their own scales); smaller vectors as one block."""
    a = np.asarray(actual, dtype=float).ravel()
    e = np.asarray(expected, dtype=float).ravel()
    assert a.shape == e.shape, f"{what}: shape {a.shape} against {e.shape}"
    assert np.isfinite(e).all(), f"{what}: not finite: {e}"
    size = 3 if e.size % 3 == 0 else e.size
    for k in range(0, e.size, size):
        scale = max(float(np.abs(e[k : k + size]).max()), np.finfo(float).tiny)
        err = float(np.abs(a[k : k + size] - e[k : k + size]).max())
        assert err <= rtol * scale, (
            f"{what}, components {k}–{k + size - 1}: {a[k : k + size]} against "
            f"{e[k : k + size]} (error {err:.3g} > {rtol:g} × {scale:.3g})"
        )


def _model_bodies(case: Case) -> list[Any]:
    model = case.part
    if model.bodies is None:
        return [b for b in case.system.bodies if b.kind in model.acts_on]
    names = [b if isinstance(b, str) else b.name for b in model.bodies]
    return [next(b for b in case.system.bodies if b.name == n) for n in names]


_NO_INERTIA = np.zeros((3, 3))


@numba.njit
def _force_at(address, rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    return _call_force(address, (rigid, t, g, V, m, J, p, field, out))


@numba.njit
def _control_at(address, t, g, V, a_model, z, p, u, z_dot):  # type: ignore[no-untyped-def]
    return _call_control(address, (t, g, V, a_model, z, p, u, z_dot))


@numba.njit
def _rows_at(address, t, g1, V1, g2, V2, p, A, b):  # type: ignore[no-untyped-def]
    return _call_rows(address, (t, g1, V1, g2, V2, p, A, b))


def _apply_term(term: tuple[Any, Any, Any], body: Any, state: gmuk.State) -> np.ndarray:
    """A force kernel called through its address as the compiled loop calls it."""
    kernel, values, data = term
    params = np.array([*values, 0.0])
    field = np.zeros(1) if data is None else np.asarray(data, dtype=float)
    field.setflags(write=False)
    if body.kind == "rigid":
        g, V = np.array(state.pose(body)), np.array(state.twist(body))
        m, J, out = float(body.mass), np.array(body.inertia, dtype=float), np.empty(6)
    else:
        g, V = np.zeros((4, 4)), np.zeros(6)
        g[:3, 3], V[:3] = state.position(body), state.velocity(body)
        m, J, out = float(body.mass), _NO_INERTIA, np.empty(3)
    address = kernel_address(kernel, FORCE_KERNEL)
    status = _force_at(address, body.kind == "rigid", state.t, g, V, m, J, params, field, out)
    assert status == 0, f"the force kernel returned status {status}"
    return out


def _dm(state: gmuk.State, body: Any) -> tuple[Any, Any]:
    if body.kind == "rigid":
        return ca.DM(state.pose(body)), ca.DM(state.twist(body))
    return ca.DM(state.position(body)), ca.DM(state.velocity(body))


def check_force_model(case: Case, forms: Forms) -> None:
    model, state = case.part, case.state
    bodies = _model_bodies(case)
    python = model.wrenches(state, bodies)
    for w, b in zip(python, bodies, strict=True):
        assert np.asarray(w).shape == (b.dof,) and np.isfinite(w).all()
    terms = [model._compiled_term(b) for b in bodies]
    if forms.has("compiled"):
        assert any(t is not None for t in terms), "declared compiled, but no term here"
        for term, w, b in zip(terms, python, bodies, strict=True):
            if term is not None:
                compiled = _apply_term(term, b, state)
                _blocks_close(compiled, w, PYTHON_COMPILED_RTOL, f"compiled on {b.name}")
    else:
        assert all(t is None for t in terms), "declared without a compiled form, but has one"
    q, nu = zip(*[_dm(state, b) for b in bodies], strict=True)
    if forms.has("symbolic"):
        symbolic = parts.force_terms(model, state.t, list(q), list(nu), bodies)
        for s, w, b in zip(symbolic, python, bodies, strict=True):
            _blocks_close(np.asarray(ca.DM(s)), w, SYMBOLIC_RTOL, f"symbolic on {b.name}")
    else:
        with pytest.raises(DefinitionError):
            parts.force_terms(model, state.t, list(q), list(nu), bodies)


def check_controller(case: Case, forms: Forms) -> None:
    ctl, state = case.part, case.state
    z = np.array(state.z, dtype=float)
    modeled = case.modeled if ctl.uses_modeled_acceleration else None
    u, z_dot = ctl.control(state, z, *([] if modeled is None else [modeled]))
    u = [np.asarray(x, dtype=float) for x in u]
    assert all(np.isfinite(x).all() for x in u) and np.isfinite(z_dot).all()
    term = ctl._compiled_term()
    if forms.has("compiled"):
        assert term is not None, "declared compiled, but no term here"
        (body,) = ctl.bodies
        slot = state.layout.slot(body)
        kernel, params = term
        a_model = (
            np.zeros(6) if modeled is None else np.array(modeled[slot.offset : slot.offset + 6])
        )
        out, zd = np.empty(6), np.empty(6)
        status = _control_at(
            kernel_address(kernel, CONTROL_KERNEL), state.t, np.array(state.pose(body)),
            np.array(state.twist(body)), a_model, z, np.asarray(params, dtype=float), out, zd,
        )  # fmt: skip
        assert status == 0
        _blocks_close(out, u[0], PYTHON_COMPILED_RTOL, "compiled u")
        _blocks_close(zd, z_dot, PYTHON_COMPILED_RTOL, "compiled ż")
    else:
        assert term is None, "declared without a compiled form, but has one"
    assert forms.has("symbolic") is False, "no symbolic comparison for controllers exists"
    assert not [n for n in dir(ctl) if n.startswith("casadi_")]


def check_constraint(case: Case, forms: Forms) -> None:
    c, state = case.part, case.state
    A, b = c.rows(state)
    A = A.toarray() if hasattr(A, "toarray") else np.asarray(A)
    assert np.isfinite(A).all() and np.isfinite(b).all()
    named = {b.name: b for b in case.system.bodies}
    bodies = [named[x] if isinstance(x, str) else x for x in c.bodies]
    term = c._compiled_term()
    if forms.has("compiled"):
        assert term is not None, "declared compiled, but no term here"
        kernel, params, n_rows = term
        ends = [(np.array(state.pose(x)), np.array(state.twist(x))) for x in bodies]
        (g1, V1), (g2, V2) = ends[0], ends[-1]
        Ak, bk = np.empty((n_rows, 12)), np.empty(n_rows)
        p = np.asarray(params, dtype=float)
        address = kernel_address(kernel, ROWS_KERNEL)
        status = _rows_at(address, state.t, g1, V1, g2, V2, p, Ak, bk)
        assert status == 0
        _blocks_close(Ak[:, : 6 * len(bodies)].ravel(), A.ravel(), PYTHON_COMPILED_RTOL, "A")
        _blocks_close(bk, b, PYTHON_COMPILED_RTOL, "compiled b")
        assert not Ak[:, 6 * len(bodies) :].any()
    else:
        assert term is None, "declared without a compiled form, but has one"
    q = tuple(state.pose(x) if x.kind == "rigid" else state.position(x) for x in bodies)
    nu = tuple(state.twist(x) if x.kind == "rigid" else state.velocity(x) for x in bodies)
    q_dm, nu_dm = zip(*[_dm(state, x) for x in bodies], strict=True)
    if forms.has("symbolic"):
        kind = parts.constraint_kind(c)
        if kind == "inequality":
            python = c.value(q, nu, state.t)
            symbolic = parts.inequality_value(c, q_dm, nu_dm, state.t)
        else:
            python = c.residual(q, state.t) if kind == "holonomic" else c.residual(q, nu, state.t)
            symbolic = parts.equality_residual(c, q_dm, nu_dm, state.t)
        _blocks_close(np.asarray(ca.DM(symbolic)), python, SYMBOLIC_RTOL, "symbolic value")
    else:
        with pytest.raises(DefinitionError):
            parts.constraint_kind(c)


CHECKS = (
    (ForceModel, check_force_model),
    (Controller, check_controller),
    (Constraint, check_constraint),
)


def check(case: Case) -> None:
    cls = type(case.part)
    forms = vars(cls)["_forms"]
    for base, fn in CHECKS:
        if isinstance(case.part, base):
            fn(case, forms)
            return
    raise AssertionError(f"{cls} is no part")


CHECKED = [c for c in discover() if _qualname(c) not in PENDING]


# ---------------------------------------------------------------- the tests


def test_every_built_in_part_declares_its_forms_and_has_a_factory():
    assert problems(discover()) == []


def test_discovery_catches_a_part_that_declares_nothing():
    # A new built-in model, controller and constraint that declare nothing and have no
    # factory: the contract names each of them twice.
    def make(base: type, **body: Any) -> type:
        return type("Undeclared" + base.__name__, (base,), {"__module__": "gmuk.new", **body})

    new = [
        make(ForceModel, force=lambda self, t, r, v, body: np.zeros(3)),
        make(Controller, control=lambda self, state, z: ([], np.zeros(0))),
        make(Constraint, rows=lambda self, state: (np.zeros((1, 3)), np.zeros(1))),
    ]
    try:
        found = problems(discover())
        for cls in new:
            name = f"gmuk.new.{cls.__qualname__}"
            assert f"{name} declares no forms" in "\n".join(found)
            assert f"{name} has no factory" in "\n".join(found)
        # declaring the forms in the class body is what the contract asks for
        new[0]._forms = Forms(compiled="test", symbolic="test")
        found = problems(discover())
        assert not any("UndeclaredForceModel declares no forms" in p for p in found)
    finally:
        del new, found, cls
        gc.collect()
    assert not any(c.__module__ == "gmuk.new" for c in discover())


def test_an_inherited_declaration_does_not_count():
    sub = type("Sub", (gmuk.PointMassGravity,), {"__module__": "gmuk.new"})
    try:
        assert any("gmuk.new.Sub declares no forms" in p for p in problems(discover()))
    finally:
        del sub
        gc.collect()


def test_forms_are_true_or_a_reason():
    for bad in (False, "", "  ", None):
        with pytest.raises(TypeError, match="True or the reason"):
            Forms(compiled=bad, symbolic=True)
    assert Forms(compiled=True, symbolic="why").has("compiled")
    assert not Forms(compiled=True, symbolic="why").has("symbolic")
    assert FORMS == ("compiled", "symbolic")


_KERNEL_SIGNATURES = {ForceModel: FORCE_KERNEL, Constraint: ROWS_KERNEL}


def test_every_declared_kernel_compiles_for_its_kind_of_part():
    """A class that names a ``_kernel`` declares a compiled form, and its kernel compiles for
    the signature the loop calls its kind with (nothing else lists it)."""
    declared = [c for c in CHECKED if "_kernel" in vars(c)]
    assert declared
    for c in declared:
        assert vars(c)["_forms"].has("compiled"), c
        (signature,) = [s for base, s in _KERNEL_SIGNATURES.items() if issubclass(c, base)]
        assert kernel_address(c._kernel, signature) > 0, c


@pytest.mark.parametrize("cls", CHECKED, ids=lambda c: c.__name__)
@CONTRACT
@given(seed=st.integers(0, 2**32 - 1))
def test_python_compiled_and_symbolic_forms_agree(cls, seed):
    case = FACTORIES[cls](np.random.default_rng(seed))
    assert type(case.part) is cls
    check(case)


def _overriding(cls: type) -> type:
    """A subclass that overrides the first of the class's numeric methods (calling it):
    the same numbers, but gmuk cannot know that."""
    name = next(m for m in cls._numeric_methods if callable(getattr(cls, m, None)))
    method = getattr(cls, name)
    return type(f"Overriding{cls.__name__}", (cls,), {name: lambda self, *a: method(self, *a)})


def _as(part: Any, sub: type) -> Any:
    out = copy.copy(part)
    object.__setattr__(out, "__class__", sub)
    return out


@pytest.mark.parametrize("cls", CHECKED, ids=lambda c: c.__name__)
def test_a_subclass_keeps_the_forms_until_it_overrides_a_numeric_method(cls):
    case = FACTORIES[cls](np.random.default_rng(0))
    forms = vars(cls)["_forms"]
    same = _as(case.part, type(f"Same{cls.__name__}", (cls,), {}))
    changed = _as(case.part, _overriding(cls))
    symbolic = [n for n in dir(cls) if n.startswith("casadi_")]
    assert bool(symbolic) == forms.has("symbolic") or isinstance(case.part, Constraint)
    for name in symbolic:
        assert callable(same._declared_form(name)), name
        assert changed._declared_form(name) is None, name
        assert changed._cut_off_form(name) is not None
    if forms.has("compiled"):
        if isinstance(case.part, ForceModel):
            bodies = _model_bodies(case)
            assert [same._compiled_term(b) for b in bodies] == [
                case.part._compiled_term(b) for b in bodies
            ]
            assert all(changed._compiled_term(b) is None for b in bodies)
        else:
            term, same_term = case.part._compiled_term(), same._compiled_term()
            assert term[0] == same_term[0] and np.array_equal(term[1], same_term[1])
            assert changed._compiled_term() is None
