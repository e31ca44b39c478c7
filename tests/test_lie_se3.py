"""SE(3): exp/log, Ad, ad, ad*, dexp and dexp_inv (McCann 2020, Eqs. 12, 14–16, 20–22).

Random elements and twists put extra weight on rotation angles θ ∈ [0, 1e-8],
θ ∈ [π − 1e-9, π] and θ = π exactly, and on translations up to 1e7 m. Identities hold to
1e-12 relative to the size of the numbers involved (floor 1). ``dexp``/``dexp_inv`` are also
compared with the series Σₖ (−ad_ξ)ᵏ/(k+1)! summed in 40-digit arithmetic (mpmath), and the
coefficients F₁, F₂ with the printed Eqs. 21–22 evaluated in 100-digit arithmetic.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from gmuk.errors import NotOnGroupError
from gmuk.lie import _coeffs, _kernels, se3, so3

PI = np.pi
TOL = 1e-12
SPECIAL_AXES = [
    np.array([1.0, 0.0, 0.0]),
    np.array([0.0, 0.0, -1.0]),
    np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0),
    np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0),
]


def _unit(a):
    a = np.asarray(a, dtype=float)
    return a / np.linalg.norm(a)


unit = st.floats(-1.0, 1.0)
axes = st.one_of(
    st.sampled_from(SPECIAL_AXES),
    st.tuples(unit, unit, unit).filter(lambda a: np.linalg.norm(a) > 0.1).map(_unit),
)
angles = st.one_of(
    st.just(0.0),
    st.floats(0.0, 1e-8),
    st.floats(PI - 1e-9, PI),
    st.just(PI),
    st.floats(0.0, PI),
)
magnitudes = st.one_of(st.just(0.0), st.floats(0.0, 10.0), st.floats(10.0, 1e7))
translations = st.builds(lambda m, e: m * e, magnitudes, axes)
exp_coords = st.builds(lambda th, e, r: np.concatenate([th * e, r]), angles, axes, translations)
small_exp_coords = st.builds(
    lambda th, e, r: np.concatenate([th * e, r]),
    angles,
    axes,
    st.builds(lambda m, e: m * e, st.floats(0.0, 10.0), axes),
)


def _exact_pi_element(e, r):
    g = np.eye(4)
    g[:3, :3] = 2.0 * np.outer(e, e) - np.eye(3)
    g[:3, 3] = r
    return g


#: Group elements: exp of random coordinates, and exact rotations by π (2eeᵀ − I).
elements = st.one_of(
    exp_coords.map(se3.exp),
    st.builds(_exact_pi_element, axes, translations),
)
component = st.floats(-100.0, 100.0)
twists = st.tuples(*[component] * 6).map(np.array)
unit_twists = st.tuples(*[unit] * 6).map(np.array)
PROPERTY = settings(max_examples=60, deadline=None)


def assert_close(actual, expected, tol=TOL, scale=None):
    """max|actual − expected| ≤ tol · scale, scale = max(1, |values|) unless given."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    if scale is None:
        scale = max(1.0, np.abs(expected).max(initial=0.0), np.abs(actual).max(initial=0.0))
    err = np.abs(actual - expected).max(initial=0.0)
    assert err <= tol * scale, f"error {err:.3g} > {tol:g} × scale {scale:.3g}"


def _angle(xi):
    return float(np.linalg.norm(np.asarray(xi)[:3]))


# --- hat / vee -----------------------------------------------------------------------------


@PROPERTY
@given(twists)
def test_hat_has_the_layout_of_eq_12_and_vee_inverts_it(V):
    X = se3.hat(V)
    assert np.array_equal(X[:3, :3], so3.hat(V[:3]))
    assert np.array_equal(X[:3, 3], V[3:])
    assert np.array_equal(X[3], np.zeros(4))
    assert np.array_equal(se3.vee(X), V)


@pytest.mark.parametrize(
    ("row", "block"),
    [([0.0, 0.0, 0.0, 1.0], False), ([0.0, 1e-3, 0.0, 0.0], False), ([0.0] * 4, True)],
)
def test_vee_rejects_matrices_outside_se3(row, block):
    X = se3.hat([0.1, 0.2, 0.3, 1.0, 2.0, 3.0])
    X[3] = row
    if block:
        X[0, 0] = 0.5
    with pytest.raises(NotOnGroupError):
        se3.vee(X)


# --- exp / log -----------------------------------------------------------------------------


@PROPERTY
@given(elements)
def test_exp_of_log_recovers_the_element(g):
    assert_close(se3.exp(se3.log(g)), g)


@PROPERTY
@given(exp_coords)
def test_log_of_exp_recovers_the_coordinates_up_to_the_sign_ambiguity_at_pi(xi):
    g = se3.exp(xi)
    out = se3.log(g)
    assert _angle(out) <= PI * (1 + 1e-15)
    if PI - _angle(xi) > 1e-12:
        assert_close(out, xi)
    else:
        # Rotations by ±π about e coincide: compare the elements instead.
        assert_close(_angle(out), PI)
        assert_close(se3.exp(out), g)


@pytest.mark.parametrize("e", SPECIAL_AXES, ids=lambda e: np.array2string(e, precision=3))
@pytest.mark.parametrize("r", [np.zeros(3), np.array([1.0, -2.0, 0.5]), np.array([1e7, 0, 3e6])])
def test_log_of_rotation_by_exactly_pi_with_translation_round_trips(e, r):
    g = _exact_pi_element(e, r)
    xi = se3.log(g)
    assert_close(_angle(xi), PI)
    assert_close(abs(xi[:3] @ e), PI)
    assert_close(se3.exp(xi), g)


@PROPERTY
@given(small_exp_coords)
def test_exp_equals_the_matrix_exponential_of_hat(xi):
    assert_close(se3.exp(xi), scipy.linalg.expm(se3.hat(xi)))


@PROPERTY
@given(exp_coords)
def test_exp_of_pure_translation_and_pure_rotation(xi):
    assert_close(se3.exp(np.concatenate([np.zeros(3), xi[3:]]))[:3, 3], xi[3:], tol=0.0)
    g = se3.exp(np.concatenate([xi[:3], np.zeros(3)]))
    assert_close(g[:3, :3], so3.exp(xi[:3]), tol=1e-15)
    assert np.array_equal(g[:3, 3], np.zeros(3))


# --- inverse, Ad ---------------------------------------------------------------------------


@PROPERTY
@given(elements)
def test_inverse_composes_to_the_identity(g):
    scale = max(1.0, np.abs(g).max())
    assert_close(g @ se3.inverse(g), np.eye(4), scale=scale)
    assert_close(se3.inverse(g) @ g, np.eye(4), scale=scale)


@PROPERTY
@given(exp_coords)
def test_inverse_of_exp_is_exp_of_minus_coordinates(xi):
    assert_close(se3.inverse(se3.exp(xi)), se3.exp(-xi))


@PROPERTY
@given(elements)
def test_Ad_has_the_block_form_of_eq_16(g):
    A = se3.Ad(g)
    R, r = g[:3, :3], g[:3, 3]
    assert np.array_equal(A[:3, :3], R)
    assert np.array_equal(A[3:, 3:], R)
    assert np.array_equal(A[:3, 3:], np.zeros((3, 3)))
    assert_close(A[3:, :3], np.cross(r[:, None], R, axis=0), tol=1e-15)


@PROPERTY
@given(elements, elements)
def test_Ad_is_a_group_homomorphism(g, h):
    # Large translations may cancel in g h: the scale is that of the factors.
    scale = max(1.0, np.abs(g).max(), np.abs(h).max())
    assert_close(se3.Ad(g @ h), se3.Ad(g) @ se3.Ad(h), scale=scale)


@PROPERTY
@given(elements)
def test_Ad_of_the_inverse_is_the_inverse_of_Ad(g):
    assert_close(se3.Ad(se3.inverse(g)) @ se3.Ad(g), np.eye(6), scale=max(1.0, np.abs(g).max()))


@PROPERTY
@given(elements, twists)
def test_Ad_conjugates_hat(g, V):
    lhs = se3.hat(se3.Ad(g) @ V)
    rhs = g @ se3.hat(V) @ se3.inverse(g)
    assert_close(lhs, rhs, scale=max(1.0, np.abs(g).max()) * max(1.0, np.abs(V).max()))


@PROPERTY
@given(small_exp_coords)
def test_Ad_of_exp_is_the_exponential_of_ad(xi):
    assert_close(se3.Ad(se3.exp(xi)), scipy.linalg.expm(se3.ad(xi)))


# --- ad, ad* ---------------------------------------------------------------------------------


@PROPERTY
@given(twists)
def test_ad_and_ad_star_have_the_block_forms_of_eqs_14_and_15(V):
    W, U = so3.hat(V[:3]), so3.hat(V[3:])
    Z = np.zeros((3, 3))
    assert np.array_equal(se3.ad(V), np.block([[W, Z], [U, W]]))
    assert np.array_equal(se3.ad_star(V), np.block([[-W, -U], [Z, -W]]))


@PROPERTY
@given(twists, twists)
def test_ad_is_the_matrix_commutator(V, W):
    Vh, Wh = se3.hat(V), se3.hat(W)
    scale = max(1.0, np.abs(V).max() * np.abs(W).max())
    assert_close(se3.ad(V) @ W, se3.vee(Vh @ Wh - Wh @ Vh), scale=scale)


@PROPERTY
@given(twists, twists, twists)
def test_ad_satisfies_the_jacobi_identity(U, V, W):
    def br(a, b):
        return se3.ad(a) @ b

    total = br(U, br(V, W)) + br(V, br(W, U)) + br(W, br(U, V))
    scale = max(1.0, np.abs(U).max() * np.abs(V).max() * np.abs(W).max())
    assert_close(total, np.zeros(6), scale=scale)


@PROPERTY
@given(twists)
def test_ad_star_is_the_transpose_of_ad(V):
    assert np.array_equal(se3.ad_star(V), se3.ad(V).T)


@PROPERTY
@given(twists, twists)
def test_ad_is_antisymmetric_in_its_arguments(V, W):
    scale = max(1.0, np.abs(V).max() * np.abs(W).max())
    assert_close(se3.ad(V) @ W, -(se3.ad(W) @ V), scale=scale)


# --- dexp, dexp_inv --------------------------------------------------------------------------

# 8th-order central difference for a first derivative (offsets −4h … 4h).
FD8 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
FD_STEP = 1e-2
# Round-off of the stencil is Σ|cₖ|·ε·|g|/h ≈ 4e-14 |g| at h = 1e-2, truncation ≈ h⁸ |ξ̇|⁹/630:
# allow 50× the round-off estimate.
FD_TOL = 50 * 1.71 * np.finfo(float).eps / FD_STEP


def fd8(f, h=FD_STEP):
    return sum(c * f(k * h) for k, c in zip(range(-4, 5), FD8, strict=True) if c) / h


@PROPERTY
@given(exp_coords)
def test_dexp_times_dexp_inv_is_the_identity(xi):
    D, Di = se3.dexp(xi), se3.dexp_inv(xi)
    scale = max(1.0, np.abs(D).max(), np.abs(Di).max())
    assert_close(D @ Di, np.eye(6), scale=scale)
    assert_close(Di @ D, np.eye(6), scale=scale)


@PROPERTY
@given(exp_coords, unit_twists)
def test_dexp_is_the_derivative_of_exp_along_a_curve(xi, xi_dot):
    # exp(ξ)⁻¹ d/dt exp(ξ + t ξ̇) at t = 0 equals (dexp(ξ) ξ̇)^.
    g = se3.exp(xi)
    lhs = se3.inverse(g) @ fd8(lambda t: se3.exp(xi + t * xi_dot))
    assert_close(lhs, se3.hat(se3.dexp(xi) @ xi_dot), tol=FD_TOL, scale=max(1.0, np.abs(g).max()))


@PROPERTY
@given(exp_coords.filter(lambda xi: _angle(xi) < PI - 0.2), unit_twists)
def test_dexp_inv_gives_the_exponential_coordinate_kinematics(xi, V):
    # Along g(t) = exp(ξ) exp(tV) (body velocity V), ξ(t) = log g(t) has ξ̇ = dexp_inv(ξ) V.
    g = se3.exp(xi)
    xi_dot = fd8(lambda t: se3.log(g @ se3.exp(t * V)))
    assert_close(xi_dot, se3.dexp_inv(xi) @ V, tol=FD_TOL, scale=max(1.0, np.abs(g).max()))


@PROPERTY
@given(exp_coords)
def test_dexp_inv_is_eq_20_with_the_printed_structure(xi):
    # I + ½ad + F₁ad² + F₂ad⁴ with gmuk's F₁, F₂ (compared with the printed Eqs. 21–22 below).
    A = se3.ad(xi)
    A2 = A @ A
    f1, f2 = _coeffs.dexp_inv_f1_f2(np.array(_angle(xi)))
    expected = np.eye(6) + 0.5 * A + f1 * A2 + f2 * (A2 @ A2)
    assert_close(se3.dexp_inv(xi), expected)


def _mp_ad(xi):
    T = mpmath.matrix([[0, -xi[2], xi[1]], [xi[2], 0, -xi[0]], [-xi[1], xi[0], 0]])
    P = mpmath.matrix([[0, -xi[5], xi[4]], [xi[5], 0, -xi[3]], [-xi[4], xi[3], 0]])
    A = mpmath.zeros(6, 6)
    for i in range(3):
        for j in range(3):
            A[i, j] = A[i + 3, j + 3] = T[i, j]
            A[i + 3, j] = P[i, j]
    return A


def mp_dexp_and_inverse(xi, dps=40):
    """Σₖ (−ad_ξ)ᵏ/(k+1)! and its inverse in ``dps``-digit arithmetic, as float arrays."""
    with mpmath.workdps(dps):
        A = -_mp_ad([mpmath.mpf(float(x)) for x in xi])
        total, term, k = mpmath.eye(6), mpmath.eye(6), 0
        while True:
            k += 1
            term = term * A / (k + 1)
            total += term
            if mpmath.mnorm(term, 1) < mpmath.mpf(10) ** (-dps - 3) * mpmath.mnorm(total, 1):
                break
        inv = total**-1
        return np.array(total.tolist(), dtype=float), np.array(inv.tolist(), dtype=float)


MP_ANGLES = [0.0, 1e-8, 1e-4, 1e-2, 0.5, 0.999, 1.0, 1.001, 2.0, 3.0, PI - 1e-6]


@pytest.mark.parametrize("theta", MP_ANGLES)
@pytest.mark.parametrize("rho_norm", [1.0, 100.0])
def test_dexp_and_dexp_inv_match_the_series_in_40_digit_arithmetic(theta, rho_norm):
    rng = np.random.default_rng(int(theta * 1e6) + int(rho_norm))
    e, r = _unit(rng.normal(size=3)), _unit(rng.normal(size=3))
    xi = np.concatenate([theta * e, rho_norm * r])
    ref, ref_inv = mp_dexp_and_inverse(xi)
    assert_close(se3.dexp(xi), ref, tol=1e-14)
    assert_close(se3.dexp_inv(xi), ref_inv, tol=1e-14)


def _mp_f1_f2_printed(theta):
    """McCann (2020), Eqs. 21–22 exactly as printed, in 100-digit arithmetic."""
    with mpmath.workdps(100):
        t = mpmath.mpf(theta)
        cot, csc2 = mpmath.cot(t / 2), mpmath.csc(t / 2) ** 2
        f1 = 2 / t**2 - 3 / (4 * t) * cot - csc2 / 8
        f2 = 1 / t**4 - cot / (4 * t**3) - csc2 / (8 * t**2)
        return float(f1), float(f2)


def _kernel_f1_f2(theta):
    return _kernels._f1_f2(float(theta))


def _coeffs_f1_f2(theta):
    f1, f2 = _coeffs.dexp_inv_f1_f2(np.array([theta]))
    return f1[0], f2[0]


F_ANGLES = [
    *[1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 0.05, 0.1, 0.3, 0.5, 0.9, 0.999, 1.0 - 1e-12],
    *[1.0, 1.0 + 1e-12, 1.001, 1.01, 1.1, 1.3, 1.5, 1.8, 2.0, 2.5, 3.0, PI - 1e-6, PI, 4.0, 6.0],
]


@pytest.mark.parametrize("impl", [_coeffs_f1_f2, _kernel_f1_f2], ids=["coeffs", "kernel"])
@pytest.mark.parametrize("theta", F_ANGLES)
def test_f1_f2_match_the_printed_eqs_21_22_in_high_precision(impl, theta):
    f1, f2 = impl(theta)
    ref1, ref2 = _mp_f1_f2_printed(theta)
    assert abs(f1 - ref1) <= 1e-14 * abs(ref1)
    assert abs(f2 - ref2) <= 1e-14 * abs(ref2)


@pytest.mark.parametrize("impl", [_coeffs_f1_f2, _kernel_f1_f2], ids=["coeffs", "kernel"])
def test_f1_f2_limits_at_zero_and_the_errata_series_at_small_angles(impl):
    f1, f2 = impl(0.0)
    assert f1 == pytest.approx(1 / 12, rel=1e-15)
    assert f2 == pytest.approx(-1 / 720, rel=1e-15)
    # docs/errata.rst, "Numerically fragile": valid below θ ≈ 0.05 to 4e-16.
    for t in [1e-8, 1e-5, 1e-3, 1e-2, 0.05]:
        f1, f2 = impl(t)
        s1 = 1 / 12 - t**4 / 30240 - t**6 / 604800
        s2 = -1 / 720 - t**2 / 15120 - t**4 / 403200 - t**6 / 11975040
        assert abs(f1 - s1) <= 1e-15 * abs(s1)
        assert abs(f2 - s2) <= 1e-15 * abs(s2)


# --- batching ------------------------------------------------------------------------------


def _batch_of_coordinates():
    rng = np.random.default_rng(11)
    th = np.array([0.0, 1e-9, 0.4, 2.5, PI - 1e-9, PI]).reshape(3, 2)
    e = rng.normal(size=(3, 2, 3))
    e /= np.linalg.norm(e, axis=-1, keepdims=True)
    r = rng.normal(size=(3, 2, 3)) * np.array([1.0, 1e7])[None, :, None]
    return np.concatenate([th[..., None] * e, r], axis=-1)


@pytest.mark.parametrize(
    ("name", "make_input"),
    [
        ("exp", lambda xi: xi),
        ("log", se3.exp),
        ("inverse", se3.exp),
        ("Ad", se3.exp),
        ("ad", lambda xi: xi),
        ("ad_star", lambda xi: xi),
        ("hat", lambda xi: xi),
        ("vee", se3.hat),
        ("dexp", lambda xi: xi),
        ("dexp_inv", lambda xi: xi),
    ],
)
def test_batched_calls_equal_a_loop_over_elements(name, make_input):
    f = getattr(se3, name)
    x = make_input(_batch_of_coordinates())
    out = f(x)
    for i in range(3):
        for j in range(2):
            single = f(x[i, j])
            assert out[i, j].shape == single.shape
            assert_close(out[i, j], single, tol=1e-15)


@pytest.mark.parametrize(
    ("name", "short"),
    [("C", _kernels._C_SHORT), ("D", _kernels._D_SHORT), ("E", _kernels._E_SHORT)],
)
def test_the_short_series_drop_only_terms_below_the_last_bit(name, short):
    """Below θ² = _SHORT_BELOW the kernels sum the series' leading terms only: the dropped
    ones add less than a quarter of the last bit, so that both sums round alike (to 1 ulp)
    over the whole range, and the dropped terms' bound holds at its end."""
    full = getattr(_kernels, f"_{name}")
    assert 0 < len(short) < len(full) and full[len(full) - len(short) :] == short
    x_max = _kernels._SHORT_BELOW
    lowest_first = full[::-1]
    dropped = sum(abs(c) * x_max**k for k, c in enumerate(lowest_first) if k >= len(short))
    low = abs(lowest_first[0]) - sum(abs(c) * x_max**k for k, c in enumerate(lowest_first) if k)
    assert dropped < 2.0**-56 * low
    horner = _kernels._horner.py_func  # the kernels' sum, run in Python
    for x in np.linspace(0.0, x_max, 2001):
        a, b = horner(short, float(x)), horner(full, float(x))
        assert abs(a - b) <= np.spacing(abs(b)), (name, x)
