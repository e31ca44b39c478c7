"""Hostile definitions (issue #25, items 7 and 10): mass properties, gains and option types,
bodies listed twice, and the domain of ``dexp_inv``.

Each test is named after the behaviour it pins down and also checks that honest input still
works, so that a check refusing everything would fail too.
"""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk import dynamics
from gmuk.campaign import scaled_inertia
from gmuk.constraints.base import Constraint
from gmuk.control import MorseLyapunovController
from gmuk.errors import DefinitionError, DomainError, GmukError, InertiaError
from gmuk.forces.gravity import PointMassGravity, SphericalHarmonicGravity
from gmuk.forces.mechanical import (
    AppliedWrench,
    LinearSpringDamper,
    SpringDamper,
    UniformGravity,
)
from gmuk.lie import se3
from gmuk.orbits import LVLHReference, fcei_orbit
from gmuk.scenarios import _lvlh as common

J_OK = np.diag([1.0, 2.0, 2.5])
I_OK = dynamics.spatial_inertia(3.0, J_OK)
V = np.array([0.1, -0.2, 0.3, 1.0, 2.0, 3.0])


# --- item 7: 6×6 mass–inertia tensors in gmuk.dynamics -----------------------------------------


@pytest.mark.parametrize("fn", ["kinetic_energy", "free_acceleration", "spatial_momentum"])
def test_a_negative_definite_spatial_inertia_is_refused_not_given_a_negative_energy(fn):
    call = {
        "kinetic_energy": lambda I: dynamics.kinetic_energy(V, I),
        "free_acceleration": lambda I: dynamics.free_acceleration(V, I),
        "spatial_momentum": lambda I: dynamics.spatial_momentum(np.eye(4), V, I),
    }[fn]
    with pytest.raises(InertiaError, match="positive definite"):
        call(-I_OK)
    assert np.isfinite(call(I_OK)).all()


def test_kinetic_energy_of_an_honest_inertia_is_still_half_v_i_v():
    assert dynamics.kinetic_energy(V, I_OK) == pytest.approx(0.5 * V @ I_OK @ V, rel=1e-15)


@pytest.mark.parametrize("fn", ["kinetic_energy", "free_acceleration"])
def test_a_zero_spatial_inertia_is_an_inertia_error_not_a_linalg_error(fn):
    with pytest.raises(InertiaError):
        getattr(dynamics, fn)(V, np.zeros((6, 6)))


def test_a_non_symmetric_spatial_inertia_is_refused():
    I = I_OK.copy()
    I[0, 1] = 0.5
    with pytest.raises(InertiaError, match="symmetric"):
        dynamics.kinetic_energy(V, I)


@pytest.mark.parametrize("size", [1e308, 1e-320])
def test_a_spatial_inertia_without_a_finite_inverse_is_refused(size):
    with pytest.raises(InertiaError, match="finite inverse"):
        dynamics.free_acceleration(V, size * np.eye(6))
    with pytest.raises(InertiaError, match="finite inverse"):
        dynamics.kinetic_energy(V, size * np.eye(6))


def test_a_nearly_singular_spatial_inertia_is_refused_as_ill_conditioned():
    I = np.eye(6)
    I[0, 1] = I[1, 0] = 1.0 - 1e-14  # positive definite, condition number 2e14
    with pytest.raises(InertiaError, match="ill-conditioned"):
        dynamics.kinetic_energy(V, I)


def test_a_bad_element_of_a_batch_of_spatial_inertias_is_named_by_its_index():
    with pytest.raises(InertiaError, match=r"index \(1,\)"):
        dynamics.kinetic_energy(V, np.stack([I_OK, -I_OK]))
    assert dynamics.kinetic_energy(V, np.stack([I_OK, 2 * I_OK])).shape == (2,)


def test_a_non_finite_spatial_inertia_is_a_gmuk_error():
    with pytest.raises(GmukError, match="finite"):
        dynamics.kinetic_energy(V, np.full((6, 6), np.nan))


def test_an_overflowing_kinetic_energy_is_refused_not_returned_as_inf():
    with pytest.raises(GmukError, match="too large"):
        dynamics.kinetic_energy(1e200 * np.ones(6), I_OK)


# --- item 7: bodies -------------------------------------------------------------------------------


@pytest.mark.parametrize("make", [gmuk.PointMass, gmuk.SlackCoordinate])
def test_a_body_whose_mass_has_no_finite_inverse_is_refused(make):
    with pytest.raises(InertiaError, match="1/m"):
        make("b", 5e-324)
    with pytest.raises(InertiaError, match="1/m"):
        gmuk.RigidBody("b", 5e-324, J_OK)
    assert make("b", 1e-300).mass == 1e-300  # small but normal: 1/m is finite


def test_a_rigid_body_whose_inertia_has_no_finite_inverse_is_refused():
    with pytest.raises(InertiaError, match="J⁻¹ is finite"):
        gmuk.RigidBody("b", 1.0, 1e-320 * np.eye(3))
    assert gmuk.RigidBody("b", 1.0, 1e-300 * J_OK).inertia[0, 0] == 1e-300


@pytest.mark.parametrize(
    "J", [1e308 * np.eye(3), np.full((3, 3), 1e308) + np.eye(3), np.diag([1e308, 1e308, 1.7e308])]
)
def test_inertia_entries_near_1e308_are_an_inertia_error_not_a_linalg_error(J):
    with pytest.raises(InertiaError):
        gmuk.RigidBody("b", 1.0, J)
    with pytest.raises(InertiaError):
        dynamics.spatial_inertia(1.0, J)


def test_a_rigid_body_with_a_too_ill_conditioned_inertia_is_refused():
    with pytest.raises(InertiaError, match="ill-conditioned"):
        gmuk.RigidBody("rod", 1.0, np.diag([1e-13, 1.0, 1.0]))
    gmuk.RigidBody("rod", 1.0, np.diag([1e-11, 1.0, 1.0]))  # J₃/J₁ = 1e11: accepted


@pytest.mark.parametrize("mass", [True, "2.0", 1 + 0j, np.array([1.0, 2.0])])
def test_a_mass_that_is_not_a_real_number_is_refused(mass):
    with pytest.raises(InertiaError):
        gmuk.PointMass("p", mass)


# --- item 7: MorseLyapunovController gains and options --------------------------------------------


@pytest.fixture(scope="module")
def craft():
    return gmuk.RigidBody("sc", 500.0, np.diag([100.0, 120.0, 150.0]))


@pytest.fixture(scope="module")
def reference():
    return LVLHReference(fcei_orbit(common.MU))


@pytest.mark.parametrize("robust", ["False", "True", "", 0, 1, None, np.array([True])])
def test_the_controller_refuses_a_robust_option_that_is_not_a_bool(craft, reference, robust):
    with pytest.raises(DefinitionError, match="robust must be True or False"):
        MorseLyapunovController(craft, reference, robust=robust)


def test_the_controller_takes_real_bools_for_robust(craft, reference):
    assert MorseLyapunovController(craft, reference, robust=False).robust is False
    assert MorseLyapunovController(craft, reference, robust=True).robust is True
    assert MorseLyapunovController(craft, reference, robust=np.bool_(True)).robust is True


@pytest.mark.parametrize(
    ("gain", "value"),
    [
        ("k11", True),
        ("k11", "0.1"),
        ("k11", 0.1 + 0j),
        ("k12", np.nan),
        ("k11", -0.1),
        ("k21", True),
        ("k21", "1.1"),
        ("k21", (1.0, True, 1.0)),
        ("k21", ("1", "1", "1")),
        ("k22", (1.0, 2.0)),
        ("k22", (1e-6, -1e-6, 1e-5)),
        ("kappa", False),
        ("kappa", "2e-4"),
        ("k_integral", True),
        ("k_integral", -1.0),
        ("morse_weight", "0.2"),
        ("kappa2", True),
        ("kappa2", "-19.5"),
        ("kappa2", np.inf),
        ("a", (3.0, 2.0, True)),
        ("a", "321"),
        ("a", (3.0, 2.0, 1.0 + 1j)),
    ],
)
def test_the_controller_refuses_boolean_string_and_ill_signed_gains(craft, reference, gain, value):
    with pytest.raises(DefinitionError, match=gain):
        MorseLyapunovController(craft, reference, **{gain: value})


def test_the_controller_still_takes_real_gains_as_numbers_or_arrays(craft, reference):
    ctl = MorseLyapunovController(
        craft, reference, k11=np.float32(0.1), k21=np.array([1.1, 1.2, 1.3]), k_integral=0,
        kappa2=-19, a=[3, 2, 1],
    )  # fmt: skip
    assert ctl.k11 == pytest.approx(0.1) and ctl.k21.tolist() == [1.1, 1.2, 1.3]
    assert ctl.k_integral == 0.0 and ctl.kappa2 == -19.0 and ctl.a.tolist() == [3.0, 2.0, 1.0]


@pytest.mark.parametrize("variant", [np.array(["thesis"]), 1, None])
def test_the_controller_refuses_a_variant_that_is_not_a_name(craft, reference, variant):
    with pytest.raises(DefinitionError, match="variant"):
        MorseLyapunovController(craft, reference, variant=variant)


# --- item 7: option types of force models ---------------------------------------------------------


@pytest.mark.parametrize("modeled", ["False", 0, None])
def test_a_force_model_refuses_a_modeled_option_that_is_not_a_bool(modeled):
    with pytest.raises(DefinitionError, match="modeled must be True or False"):
        UniformGravity(modeled=modeled)
    with pytest.raises(DefinitionError, match="modeled must be True or False"):
        PointMassGravity(1.0, modeled=modeled)
    assert UniformGravity(modeled=False).modeled is False


def test_spherical_harmonic_gravity_refuses_a_finite_size_force_option_that_is_not_a_bool():
    with pytest.raises(DefinitionError, match="finite_size_force must be True or False"):
        SphericalHarmonicGravity("GRGM660PRIM", degree=2, finite_size_force="False")
    model = SphericalHarmonicGravity("GRGM660PRIM", degree=2, finite_size_force=False)
    assert model.include_finite_size_force is False


@pytest.mark.parametrize("frame", [np.array(["body", "inertial"]), 1, None])
def test_an_applied_wrench_refuses_a_frame_that_is_not_a_name(frame):
    with pytest.raises(DefinitionError, match="frame"):
        AppliedWrench("b", np.zeros(6), frame=frame)


@pytest.mark.parametrize("value", [True, "10.0", -1.0])
def test_a_spring_refuses_boolean_string_and_negative_stiffness(value):
    with pytest.raises(DefinitionError, match="stiffness"):
        LinearSpringDamper(value)
    assert LinearSpringDamper(10.0).k == 10.0


# --- item 7: scaled_inertia -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "J",
    [np.zeros((3, 3)), np.diag([1.0, 1.0, 3.0]), -J_OK, np.diag([1e-320] * 3)],
    ids=["zero", "triangle", "negative", "subnormal"],
)
def test_scaled_inertia_refuses_zero_and_triangle_violating_inertias(J):
    with pytest.raises(InertiaError):
        scaled_inertia(J, (1.0, 1.0, 1.0))


@pytest.mark.parametrize(
    ("factors", "mass_scale"),
    [((1.0, 0.0, 1.0), 1.0), ((1.0, True, 1.0), 1.0), ("111", 1.0), ((1.0, 1.0), 1.0),
     ((1.0, 1.0, 1.0), 0.0), ((1.0, 1.0, 1.0), "2"), ((1.0, 1.0, 1.0), np.nan)],
)  # fmt: skip
def test_scaled_inertia_refuses_non_positive_or_non_real_factors(factors, mass_scale):
    with pytest.raises(DefinitionError):
        scaled_inertia(J_OK, factors, mass_scale)


def test_scaled_inertia_of_an_honest_inertia_stays_physical():
    out = scaled_inertia(J_OK, (0.5, 2.0, 1.0), 3.0)
    moments = np.linalg.eigvalsh(out)
    assert moments.min() > 0 and moments[0] + moments[1] >= moments[2] * (1 - 1e-12)
    np.testing.assert_allclose(scaled_inertia(J_OK, (1.0, 1.0, 1.0), 2.0), 2 * J_OK, rtol=1e-14)


# --- item 10: a body listed twice -----------------------------------------------------------------


class _Rows(Constraint):
    def __init__(self, bodies, **kwargs):
        super().__init__(bodies, **kwargs)

    def rows(self, state):
        return np.zeros((1, 6 * len(self.bodies))), np.zeros(1)


def test_a_constraint_listing_the_same_body_twice_is_refused():
    a = gmuk.RigidBody("a", 1.0, J_OK)
    for bodies in ([a, a], ["a", "a"], [a, "a"]):
        with pytest.raises(DefinitionError, match="same body more than once"):
            _Rows(bodies, name="pair")
    assert _Rows([a, "b"]).body_names == ("a", "b")


def test_a_force_model_listing_the_same_body_twice_is_refused():
    a = gmuk.RigidBody("a", 1.0, J_OK)
    with pytest.raises(DefinitionError, match="same body more than once"):
        UniformGravity(bodies=[a, "a"])
    with pytest.raises(DefinitionError, match="same body more than once"):
        SpringDamper(a, np.zeros(3), "a", np.ones(3), stiffness=1.0)
    assert SpringDamper(a, np.zeros(3), "b", np.ones(3), stiffness=1.0).bodies == (a, "b")


def test_a_force_model_refuses_bodies_that_are_not_a_sequence():
    with pytest.raises(DefinitionError, match="sequence"):
        UniformGravity(bodies=gmuk.PointMass("p", 1.0))  # type: ignore[arg-type]


# --- item 10: the domain of dexp_inv --------------------------------------------------------------


@pytest.mark.parametrize("theta", [2 * np.pi, 2 * np.pi + 1e-9, 7.0, 100.0, 1e300])
def test_dexp_inv_refuses_rotation_angles_of_2_pi_and_beyond(theta):
    xi = np.array([theta, 0.0, 0.0, 1.0, 2.0, 3.0])
    with pytest.raises(DomainError, match="2π"):
        se3.dexp_inv(xi)
    with pytest.raises(DomainError):  # one bad element of a batch is enough
        se3.dexp_inv(np.stack([np.zeros(6), xi]))


def test_dexp_inv_still_inverts_dexp_just_below_2_pi():
    just_below = np.array([0.0, 0.0, np.nextafter(2 * np.pi, 0.0), 1.0, 2.0, 3.0])
    assert se3.dexp_inv(just_below).shape == (6, 6)  # in the domain: no DomainError
    xi = np.array([0.0, 0.0, 6.2, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(se3.dexp_inv(xi) @ se3.dexp(xi), np.eye(6), atol=1e-9)
    xi = np.array([0.3, -1.0, 2.0, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(se3.dexp_inv(xi) @ se3.dexp(xi), np.eye(6), atol=1e-12)
