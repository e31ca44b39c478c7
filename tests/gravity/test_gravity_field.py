"""SphericalHarmonicField: construction, validation, immutability, shapes, flags, errors."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from gmuk.errors import (
    DefinitionError,
    DegreeError,
    DomainError,
    GmukError,
    NonFiniteError,
    ShapeError,
)
from gmuk.gravity import (
    MOON_MU,
    MOON_RADIUS,
    FieldValues,
    SphericalHarmonicField,
    moon_low_degree,
)
from gmuk.gravity.legendre import normalization_4pi

from .refs import kaula_field


def _coeffs(N=3):
    C = np.zeros((N + 1, N + 1))
    S = np.zeros((N + 1, N + 1))
    C[0, 0] = 1.0
    C[2, 0] = -9e-5
    C[2, 2] = 3.5e-5
    S[2, 2] = 1e-6
    if N >= 3:
        C[3, 1] = 2.6e-5
        S[3, 3] = -1.8e-6
    return C, S


@pytest.fixture(scope="module")
def field():
    return kaula_field(20, seed=4, amplitude=1e-4)


R0 = np.array([1.2e6, 0.9e6, 1.1e6])


# --------------------------------------------------------------------- construction


def test_attributes_and_copies():
    C, S = _coeffs()
    f = SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S, name="toy", reference="made up")
    assert (f.mu, f.radius, f.degree, f.name, f.reference) == (
        MOON_MU,
        MOON_RADIUS,
        3,
        "toy",
        "made up",
    )
    assert f.normalization == "4pi"
    np.testing.assert_array_equal(f.C, C)
    C[2, 0] = 0.0  # the field holds its own copy
    assert f.C[2, 0] == -9e-5
    assert not f.C.flags.writeable and not f.S.flags.writeable
    with pytest.raises(ValueError):
        f.C[2, 0] = 1.0
    assert "toy" in repr(f) and "degree=3" in repr(f)


def test_immutable():
    f = SphericalHarmonicField(MOON_MU, MOON_RADIUS, *_coeffs())
    with pytest.raises(AttributeError, match="immutable"):
        f.mu = 1.0
    with pytest.raises(AttributeError, match="immutable"):
        f.extra = 1
    with pytest.raises(AttributeError, match="immutable"):
        del f.name
    assert isinstance(f.metadata, type(moon_low_degree().metadata))
    with pytest.raises(TypeError):
        f.metadata["x"] = 1


def test_degree_argument_truncates():
    C, S = _coeffs()
    f = SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S, degree=2)
    assert f.degree == 2 and f.C.shape == (3, 3)
    np.testing.assert_array_equal(f.C, C[:3, :3])


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"mu": -1.0}, DefinitionError, r"mu must be finite and > 0 \(m³/s²\); got -1.0"),
        ({"mu": float("nan")}, DefinitionError, "mu must be finite"),
        ({"mu": "big"}, DefinitionError, "mu must be a number"),
        ({"radius": 0.0}, DefinitionError, r"radius must be finite and > 0 \(m\); got 0.0"),
        (
            {"C": np.zeros((3, 4))},
            ShapeError,
            r"square array of shape \(N\+1, N\+1\); got \(3, 4\)",
        ),
        ({"C": np.zeros(4)}, ShapeError, r"got \(4,\)"),
        (
            {"S": np.zeros((3, 3))},
            ShapeError,
            r"C and S must have one shape; got \(4, 4\) and \(3, 3\)",
        ),
        ({"C": [["a"]]}, ShapeError, "could not convert"),
        ({"degree": 7}, DegreeError, "between 0 and the coefficients' degree 3; got 7"),
        ({"degree": -1}, DegreeError, "got -1"),
        ({"degree": 2.0}, DegreeError, "degree must be an integer"),
        ({"normalization": "schmidt"}, DefinitionError, r"one of \('4pi', 'unnormalized'\)"),
    ],
)
def test_construction_errors(kwargs, error, match):
    C, S = _coeffs()
    args = {"mu": MOON_MU, "radius": MOON_RADIUS, "C": C, "S": S, **kwargs}
    with pytest.raises(error, match=match) as info:
        SphericalHarmonicField(
            args.pop("mu"), args.pop("radius"), args.pop("C"), args.pop("S"), **args
        )
    assert isinstance(info.value, GmukError)


def test_coefficient_content_errors():
    C, S = _coeffs()
    bad = C.copy()
    bad[1, 3] = 1e-9
    with pytest.raises(
        DefinitionError, match=r"C\[1, 3\] must be 0 \(order m > degree n\); got 1e-09"
    ):
        SphericalHarmonicField(MOON_MU, MOON_RADIUS, bad, S)
    bad = S.copy()
    bad[2, 0] = 1e-7
    with pytest.raises(DefinitionError, match=r"S\[2, 0\] must be 0.*got 1e-07"):
        SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, bad)
    bad = C.copy()
    bad[3, 2] = np.nan
    with pytest.raises(NonFiniteError, match=r"C must be finite; got nan at \[3, 2\]"):
        SphericalHarmonicField(MOON_MU, MOON_RADIUS, bad, S)
    with pytest.raises(DefinitionError, match="sigma_C must be >= 0"):
        SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S, sigma_C=-np.ones((4, 4)))
    with pytest.raises(ShapeError, match=r"sigma_S must have shape \(4, 4\)"):
        SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S, sigma_S=np.ones((2, 2)))


def test_several_problems_reported_together():
    C, S = _coeffs()
    C[0, 2] = 1.0
    S[3, 0] = 1.0
    with pytest.raises(DefinitionError) as info:
        SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S, normalization="x")
    assert len(info.value.problems) == 3


def test_unnormalized_coefficients_are_converted():
    """Unnormalised C₂₀ = −J₂ etc. give the same field as their 4π-normalised values."""
    C, S = _coeffs()
    n, m = np.tril_indices(4)
    N = np.zeros((4, 4))
    N[n, m] = normalization_4pi(n, m)
    f4 = SphericalHarmonicField(MOON_MU, MOON_RADIUS, C, S)
    fu = SphericalHarmonicField(MOON_MU, MOON_RADIUS, C * N, S * N, normalization="unnormalized")
    np.testing.assert_allclose(fu.C, C, rtol=1e-14, atol=0)
    np.testing.assert_allclose(fu.acceleration(R0), f4.acceleration(R0), rtol=1e-15)
    assert abs(N[2, 2] - np.sqrt(5 / 12)) <= 2e-16  # √((2)(5) 0!/4!)


# --------------------------------------------------------------------- truncate


def test_truncate(field):
    t = field.truncate(7)
    assert t.degree == 7 and field.degree == 20
    np.testing.assert_array_equal(t.C, field.C[:8, :8])
    assert t.metadata["truncated_from_degree"] == 20
    ref = SphericalHarmonicField(field.mu, field.radius, field.C[:8, :8], field.S[:8, :8])
    np.testing.assert_array_equal(t.acceleration(R0), ref.acceleration(R0))
    assert field.truncate(20).degree == 20


@pytest.mark.parametrize("bad", [21, -1, 3.0, "2", True])
def test_truncate_errors(field, bad):
    with pytest.raises(DegreeError) as info:
        field.truncate(bad)
    if bad == 21:
        assert "the field's degree is 20" in str(info.value)
        assert "expected 0 <= degree <= 20" in str(info.value)


# --------------------------------------------------------------------- evaluation API


def test_shapes_and_batch_equals_loop(field):
    rng = np.random.default_rng(7)
    pts = rng.normal(size=(6, 3))
    pts *= (field.radius + rng.uniform(20e3, 800e3, 6))[:, None] / np.linalg.norm(pts, axis=1)[
        :, None
    ]
    pts[0] = [0.0, 0.0, field.radius + 1e5]  # a pole in the batch
    a = field.acceleration(pts)
    H = field.hessian(pts)
    U = field.potential(pts)
    assert a.shape == (6, 3) and H.shape == (6, 3, 3) and U.shape == (6,)
    for i, r in enumerate(pts):
        np.testing.assert_array_equal(a[i], field.acceleration(r))
        np.testing.assert_array_equal(H[i], field.hessian(r))
        assert U[i] == field.potential(r)
    # lists, other batch shapes, read-only and non-contiguous inputs
    np.testing.assert_array_equal(field.acceleration(list(pts[1])), a[1])
    grid = pts.reshape(2, 3, 3)
    np.testing.assert_array_equal(field.acceleration(grid), a.reshape(2, 3, 3))
    ro = pts.copy()
    ro.setflags(write=False)
    np.testing.assert_array_equal(field.acceleration(ro[2]), a[2])
    np.testing.assert_array_equal(field.hessian(ro), H)
    strided = np.asfortranarray(pts)
    np.testing.assert_array_equal(field.acceleration(strided), a)
    empty = field.acceleration(np.zeros((0, 3)))
    assert empty.shape == (0, 3)


def test_evaluate_is_one_pass_of_the_same_numbers(field):
    rng = np.random.default_rng(8)
    pts = rng.normal(size=(4, 3)) * 1e6 + 1.9e6
    for r in (pts[0], pts):
        both = field.evaluate(r, potential=True, acceleration=True, hessian=True)
        assert isinstance(both, FieldValues)
        np.testing.assert_array_equal(both.acceleration, field.acceleration(r))
        np.testing.assert_array_equal(both.hessian, field.hessian(r))
        np.testing.assert_array_equal(both.potential, field.potential(r))
        only = field.evaluate(r, potential=False, acceleration=True, hessian=True)
        assert only.potential is None
        np.testing.assert_array_equal(only.hessian, both.hessian)
        np.testing.assert_array_equal(only.acceleration, both.acceleration)
        pot = field.evaluate(r, acceleration=False)
        assert pot.acceleration is None and pot.hessian is None
        np.testing.assert_array_equal(pot.potential, both.potential)
    single = field.evaluate(pts[0], hessian=True)
    assert isinstance(single.potential, float)
    assert single.acceleration.shape == (3,) and single.hessian.shape == (3, 3)
    with pytest.raises(DefinitionError, match="at least one"):
        field.evaluate(pts[0], potential=False, acceleration=False)


def test_perturbation_flag_removes_exactly_the_central_term(field):
    r = np.array([0.4e6, -1.1e6, 1.6e6])
    rn = np.linalg.norm(r)
    central_a = -field.mu * r / rn**3
    central_H = field.mu * (3 * np.outer(r, r) / rn**5 - np.eye(3) / rn**3)
    pert = field.acceleration(r, central=False)
    np.testing.assert_allclose(
        field.acceleration(r) - central_a,
        pert,
        rtol=0,
        atol=1e-15 * np.linalg.norm(central_a),
    )
    np.testing.assert_allclose(
        field.hessian(r) - central_H,
        field.hessian(r, central=False),
        rtol=0,
        atol=1e-15 * np.abs(central_H).max(),
    )
    assert abs(field.potential(r) - field.mu / rn - field.potential(r, central=False)) <= (
        1e-15 * field.mu / rn
    )
    ev = field.evaluate(r, hessian=True, central=False)
    np.testing.assert_array_equal(ev.acceleration, pert)
    # a degree-0 field has no perturbation
    pm = field.truncate(0)
    assert np.all(pm.acceleration(r, central=False) == 0.0)


def test_pickle_round_trip(field):
    g = pickle.loads(pickle.dumps(field))
    assert g.degree == field.degree and g.name == field.name
    np.testing.assert_array_equal(g.acceleration(R0), field.acceleration(R0))


# --------------------------------------------------------------------- input errors


@pytest.mark.parametrize("method", ["acceleration", "hessian", "potential", "evaluate"])
def test_position_errors(field, method):
    fn = getattr(field, method)
    with pytest.raises(ShapeError, match=r"shape \(3,\) or \(k, 3\) \(m\); got \(4,\)"):
        fn(np.ones(4))
    with pytest.raises(ShapeError, match=r"got \(2, 2\)"):
        fn(np.ones((2, 2)))
    with pytest.raises(ShapeError, match=r"got \(\)"):
        fn(1.0)
    with pytest.raises(ShapeError, match="could not convert"):
        fn(["a", "b", "c"])
    with pytest.raises(NonFiniteError, match=r"r_F must be finite; got \[.*nan"):
        fn([1e6, np.nan, 0.0])
    with pytest.raises(NonFiniteError, match="at index 1"):
        fn([[1e6, 0, 0], [np.inf, 0, 0]])
    with pytest.raises(DomainError, match="is the origin"):
        fn([0.0, 0.0, 0.0])
    with pytest.raises(DomainError, match="at index 2 is the origin"):
        fn([[1e6, 0, 0], [2e6, 0, 0], [0, 0, 0]])


def test_overflow_deep_inside_the_reference_sphere_is_an_error():
    f = kaula_field(300, seed=3)
    with pytest.raises(DomainError, match=r"no finite value .*reference radius 1\.738e\+06 m"):
        f.acceleration([1.0, 2.0, 3.0])  # (R/r)^301 overflows
    # just below the reference sphere the series is still evaluated (it is the user's call)
    assert np.all(np.isfinite(f.acceleration([0.0, 0.0, 0.99 * f.radius])))
