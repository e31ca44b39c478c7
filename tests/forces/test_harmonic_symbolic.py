"""The symbolic (CasADi) form of the spherical-harmonic field and of SphericalHarmonicGravity.

* :meth:`SphericalHarmonicField.casadi_acceleration` is the compiled kernel's acceleration
  (one definition: the same recurrences and constants, read from the field's data) to 1e-12
  relative at random points, the poles and low altitudes, at degrees 2, 20, 50 and the
  shipped 150 of GRGM660PRIM and 70 of EGM2008, with and without the central term; SX, MX,
  DM and NumPy positions give the same numbers;
* the rotation of the central body with a symbolic time is ``R_FN(t)``;
* the Hessian and finite-size force of the rigid-body form (CasADi's exact derivatives) are
  the field's Hessian and the numeric model's central differences;
* the cases without a symbolic form raise a DefinitionError that says what is supported, and
  the optimiser takes a rotation model other than UniformRotation at numeric times.

``tests/test_part_contract.py`` compares ``casadi_force``/``casadi_wrench`` with
``force``/``wrench`` at 100 random states besides.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
import pytest

import gmuk
from gmuk.celestial import UniformRotation
from gmuk.errors import DefinitionError, ShapeError
from gmuk.gravity import _symbolic, load
from gmuk.lie import so3
from gmuk.optimize import Mesh, OptimalControlProblem, parts

RTOL = 1e-12


def _points(rng: np.random.Generator, radius: float, n: int) -> np.ndarray:
    """n random positions between 1.0 and 2.9 reference radii, then the poles, points 1e-9
    rad and 1e-4 rad from the north pole, and the three axes, at radius·1.03 (m)."""
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    random = u * rng.uniform(1.0, 2.9, size=(n, 1)) * radius
    special = np.array(
        [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [np.sin(1e-9), 0.0, np.cos(1e-9)],
            [0.0, np.sin(1e-4), -np.cos(1e-4)],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
        ]
    )
    return np.concatenate([random, 1.03 * radius * special])


def _relative(symbolic: Any, numeric: np.ndarray) -> float:
    s = np.asarray(symbolic, dtype=float).ravel()
    e = np.asarray(numeric, dtype=float).ravel()
    return float(np.abs(s - e).max() / np.abs(e).max())


@pytest.mark.parametrize(
    ("name", "degree"),
    [("GRGM660PRIM", 2), ("GRGM660PRIM", 20), ("GRGM660PRIM", 50), ("GRGM660PRIM", 150),
     ("EGM2008", 70)],
)  # fmt: skip
def test_the_symbolic_acceleration_is_the_kernels(name, degree):
    field = load(name, degree)
    rng = np.random.default_rng(degree)
    fn = _symbolic.acceleration_function(field)
    perturbation = _symbolic.acceleration_function(field, central=False)
    worst = worst_perturbation = 0.0
    for r in _points(rng, field.radius, 60):
        worst = max(worst, _relative(fn(r), field.acceleration(r)))
        worst_perturbation = max(
            worst_perturbation, _relative(perturbation(r), field.acceleration(r, central=False))
        )
    assert worst < RTOL, worst
    assert worst_perturbation < RTOL, worst_perturbation


def test_sx_mx_dm_and_numpy_positions_give_the_same_numbers():
    field = load("GRGM660PRIM", 8)
    r = np.array([1.2e6, -0.9e6, 1.1e6])
    expected = field.acceleration(r)
    sx, mx = ca.SX.sym("r", 3), ca.MX.sym("r", 3)
    a_sx, a_mx = field.casadi_acceleration(sx), field.casadi_acceleration(mx)
    assert isinstance(a_sx, ca.SX) and isinstance(a_mx, ca.MX)
    assert a_sx.shape == a_mx.shape == (3, 1)
    values = [
        ca.Function("f", [sx], [a_sx])(r),
        ca.Function("f", [mx], [a_mx])(r),
        field.casadi_acceleration(ca.DM(r)),
        field.casadi_acceleration(r),
        field.casadi_acceleration(list(r)),
        field.casadi_acceleration(ca.DM(r).T),  # a row is taken as the column
    ]
    for v in values:
        assert isinstance(v, ca.DM)
        np.testing.assert_array_equal(np.asarray(v).ravel(), np.asarray(values[0]).ravel())
    assert _relative(values[0], expected) < RTOL
    with pytest.raises(ShapeError, match="3 entries"):
        field.casadi_acceleration(np.zeros(4))


def test_the_expression_is_built_once_per_field():
    field = load("GRGM660PRIM", 5)
    again = load("GRGM660PRIM", 5)  # another object, the same data
    assert _symbolic.acceleration_function(field) is _symbolic.acceleration_function(again)
    other = load("GRGM660PRIM", 6)
    assert _symbolic.acceleration_function(field) is not _symbolic.acceleration_function(other)


def _model(rotation: UniformRotation, degree: int = 20, **kw: Any) -> Any:
    moon = gmuk.CelestialBody.moon(field=load("GRGM660PRIM", degree), rotation=rotation)
    return gmuk.SphericalHarmonicGravity(moon, **kw)


def test_a_symbolic_time_rotates_the_field_by_R_FN():
    rng = np.random.default_rng(7)
    t = ca.SX.sym("t")
    r = ca.SX.sym("r", 3)
    craft = gmuk.PointMass("craft", 250.0)
    for rate, angle0 in [(2.6617e-6, 0.0), *rng.uniform([-1e-4, -np.pi], [1e-4, np.pi], (4, 2))]:
        rotation = UniformRotation(rate, angle0)
        model = _model(rotation)
        R = ca.Function("R", [t], [model._casadi_R_FN(t)])
        force = ca.Function("f", [t, r], [model.casadi_force(t, r, None, craft)])
        for time in rng.uniform(0.0, 3e6, 5):
            np.testing.assert_allclose(np.asarray(R(time)), rotation.R_FN(time), rtol=0, atol=1e-15)
            r_N = rng.normal(size=3) * 1.1e6 + 1e6
            expected = model.force(time, r_N, np.zeros(3), craft)
            assert _relative(force(time, r_N), expected) < RTOL


@dataclass(frozen=True)
class Wobble(UniformRotation):
    """A uniform spin with a small libration about the first axis (a rotation model that is
    not UniformRotation's formula)."""

    def R_FN(self, t: Any) -> np.ndarray:  # type: ignore[override]
        return so3.exp([1e-3 * np.sin(float(t) / 1e3), 0.0, 0.0]).T @ super().R_FN(float(t))


def test_another_rotation_model_is_symbolic_only_at_numeric_times():
    model = _model(Wobble(2.6617e-6), degree=4)
    craft, sat = (
        gmuk.PointMass("craft", 250.0),
        gmuk.RigidBody("sat", 500.0, np.diag([1e3, 2e3, 2.5e3])),
    )
    with pytest.raises(DefinitionError, match=r"UniformRotation.*Wobble.*numeric times"):
        model.casadi_force(ca.SX.sym("t"), ca.SX.sym("r", 3), None, craft)
    with pytest.raises(DefinitionError, match="UniformRotation"):
        parts.force_terms(model, ca.MX.sym("t"), [ca.MX.sym("r", 3)], [None], [craft])
    r_N = np.array([1.3e6, 0.8e6, -1.0e6])
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = so3.exp([0.3, -1.0, 0.2]), r_N
    for time in (0.0, 1234.5, 8.0e5):
        f = model.casadi_force(time, ca.DM(r_N), None, craft)
        assert _relative(f, model.force(time, r_N, np.zeros(3), craft)) < RTOL
        w = np.asarray(model.casadi_wrench(time, ca.DM(g), None, sat)).ravel()
        expected = model.wrench(time, g, np.zeros(6), sat)
        assert _relative(w[:3], expected[:3]) < RTOL and _relative(w[3:], expected[3:]) < RTOL


def _orbiter(model: Any) -> tuple[gmuk.System, gmuk.State]:
    craft = gmuk.PointMass("craft", 300.0)
    system = gmuk.System([craft], forces=[model])
    r = model.field.radius + 1e5
    v = np.sqrt(model.field.mu / r)
    return system, system.state(r={"craft": [r, 0.0, 0.0]}, v={"craft": [0.0, 0.0, v]})


def test_the_optimiser_maps_a_uniform_spin_and_goes_node_by_node_otherwise():
    mesh = Mesh.uniform(0.0, 600.0, 3, 4)
    for rotation, mapped in ((UniformRotation(2.6617e-6), True), (Wobble(2.6617e-6), False)):
        system, state = _orbiter(_model(rotation, degree=6))
        transcription = OptimalControlProblem(system, state, 600.0).transcribe(mesh)
        assert transcription.mapped is mapped


class PointField:
    """A field that is not a SphericalHarmonicField (a point mass)."""

    mu = 4.9028e12
    radius = 1.738e6

    def acceleration(self, r: np.ndarray, central: bool = True) -> np.ndarray:
        return -self.mu * r / np.linalg.norm(r) ** 3

    def hessian(self, r: np.ndarray, central: bool = True) -> np.ndarray:
        n = np.linalg.norm(r)
        return self.mu * (3.0 * np.outer(r, r) / n**5 - np.eye(3) / n**3)


def test_a_field_of_another_kind_has_no_symbolic_form():
    moon = gmuk.CelestialBody("Moon", rotation=UniformRotation(2.6617e-6), field=PointField())
    model = gmuk.SphericalHarmonicGravity(moon)
    craft = gmuk.PointMass("craft", 300.0)
    with pytest.raises(
        DefinitionError, match=r"needs a gmuk\.gravity\.SphericalHarmonicField.*PointField"
    ):
        model.casadi_force(0.0, ca.DM([2e6, 0.0, 0.0]), None, craft)
    system = gmuk.System([craft], forces=[model])
    state = system.state(r={"craft": [1.838e6, 0.0, 0.0]}, v={"craft": [0.0, 0.0, 1633.0]})
    with pytest.raises(DefinitionError, match="SphericalHarmonicField"):
        OptimalControlProblem(system, state, 100.0).transcribe(Mesh.uniform(0.0, 100.0, 2, 3))


@pytest.mark.parametrize("degree", [2, 20])
def test_the_rigid_form_has_the_fields_hessian_and_finite_size_force(degree):
    """H is CasADi's derivative of the symbolic acceleration, against the kernel's Hessian;
    the finite-size force ½∇tr(HΠ) its exact third derivatives, against the numeric model's
    central differences, for a body large enough (a 200 m structure) that the term is far
    above the round-off of either."""
    field = load("GRGM660PRIM", degree)
    model = gmuk.SphericalHarmonicGravity(
        gmuk.CelestialBody.moon(field=field, rotation=gmuk.INERTIAL)
    )
    body = gmuk.RigidBody("big", 1e5, np.diag([2e8, 3e8, 4.5e8]))
    fn = _symbolic.rigid_function(field, finite_size=True)
    rng = np.random.default_rng(degree)
    for r in _points(rng, field.radius * 1.01, 10):
        g = np.eye(4)
        g[:3, :3], g[:3, 3] = so3.exp(rng.normal(size=3)), r
        J = body.inertia
        Pi = g[:3, :3] @ (0.5 * np.trace(J) * np.eye(3) - J) @ g[:3, :3].T
        a, H, s = (np.asarray(v) for v in fn(r, Pi))
        assert _relative(a, field.acceleration(r)) < RTOL
        assert _relative(H, field.hessian(r)) < RTOL
        assert np.array_equal(H, H.T)
        finite = g[:3, :3] @ model.finite_size_force(0.0, g, body)
        assert _relative(s, finite) < 1e-7  # the central differences' truncation
        assert np.abs(s).max() > 1e-11 * body.mass * np.abs(a).max()  # far above round-off


@pytest.mark.parametrize("finite", [True, False])
def test_the_rigid_wrench_is_the_numeric_one(finite):
    model = _model(UniformRotation(2.6617e-6, 0.4), degree=20, finite_size_force=finite)
    sat = gmuk.RigidBody("lm", 7063.0, np.diag([17058.9, 18801.1, 21969.7]))
    rng = np.random.default_rng(3)
    t = ca.SX.sym("t")
    g_sym = ca.SX.sym("g", 4, 4)
    wrench = ca.Function("w", [t, g_sym], [model.casadi_wrench(t, g_sym, None, sat)])
    for time in rng.uniform(0.0, 1e5, 8):
        g = np.eye(4)
        g[:3, :3] = so3.exp(rng.normal(size=3))
        g[:3, 3] = rng.normal(size=3) * 1e6 + np.array([1.2e6, 0.0, 0.0])
        g[:3, 3] *= rng.uniform(1.79e6, 2.5e6) / np.linalg.norm(g[:3, 3])
        w = np.asarray(wrench(time, g)).ravel()
        expected = model.wrench(time, g, np.zeros(6), sat)
        assert _relative(w[:3], expected[:3]) < RTOL
        assert _relative(w[3:], expected[3:]) < RTOL
