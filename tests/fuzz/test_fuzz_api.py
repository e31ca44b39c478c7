"""Fuzz the array functions of the public API not covered elsewhere (issue #25):
:mod:`gmuk.dynamics`, :mod:`gmuk.orbits`, :mod:`gmuk.gravity`'s fields, the adjoint
identities of :mod:`gmuk.lie.se3`, celestial bodies, and :func:`gmuk.check`.

Oracles: what is accepted is honest real data and the result means what it says —
``Ad_g Ad_{g⁻¹} = I`` and ``exp(Ad_g ξ) = g exp(ξ) g⁻¹``; the spatial inertia is
``diag(J, m I)``, the kinetic energy ``½ Vᵀ𝕀V ≥ 0``, the free acceleration solves
``𝕀 V̇ = ad*_V 𝕀V + τ``, ``g̈ = g(V̇^ + V^V^)``; Kepler's equation and its inverses round-trip,
elements → state → elements round-trips; a degree-0 field is a point mass.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fuzz_inputs import (
    REFUSED,
    arrays,
    fuzz_pair,
    honest_real,
    numbers,
    outcome,
    poses,
    real_array,
    scalars,
)
from hypothesis import strategies as st

import gmuk
from gmuk import dynamics, orbits
from gmuk.gravity import SphericalHarmonicField, legendre_4pi, normalization_4pi
from gmuk.lie import se3


def _regular(x, tail):
    """``x`` as float if honest real with trailing shape ``tail``, finite; else None."""
    a = real_array(x)
    if a is None:
        return None
    k = len(tail)
    if a.ndim < k or a.shape[a.ndim - k :] != tail or not np.isfinite(a).all():
        return None
    return a


# ------------------------------------------------------------------- SE(3) adjoints
def check_adjoint_identities(args) -> None:
    g, xi = args
    Ad = outcome("se3.Ad", se3.Ad, g)
    Ginv = outcome("se3.inverse", se3.inverse, g)
    assert (Ad is REFUSED) == (Ginv is REFUSED), "Ad and inverse disagree on what a pose is"
    if Ad is REFUSED:
        return
    G = _regular(g, (4, 4))
    assert G is not None, f"se3.Ad took {g!r:.200}"
    if np.abs(G).max(initial=0.0) > 1e6:  # (an empty batch of poses has no maximum)
        return  # the identities hold to a tolerance relative to |r|² there
    Ad_inv = se3.Ad(Ginv)
    np.testing.assert_allclose(Ad @ Ad_inv, np.broadcast_to(np.eye(6), Ad.shape), atol=1e-9)
    np.testing.assert_allclose(G @ Ginv, np.broadcast_to(np.eye(4), G.shape), atol=1e-9)
    x = _regular(xi, (6,))
    if x is None or x.ndim != 1 or G.ndim != 2 or np.abs(x).max() > 3.0:
        return
    lhs = outcome("se3.exp", se3.exp, Ad @ x)
    np.testing.assert_allclose(lhs, G @ se3.exp(x) @ Ginv, atol=1e-8 * (1 + np.abs(G).max() ** 2))
    # the coadjoint pairs with the adjoint: ⟨ad*_ξ μ, η⟩ = ⟨μ, ad_ξ η⟩
    mu, eta = np.arange(1.0, 7.0), np.linspace(-1, 1, 6)
    assert abs(se3.ad_star(x) @ mu @ eta - mu @ (se3.ad(x) @ eta)) < 1e-9 * (1 + np.abs(x).max())


(
    test_adjoint_identities_hold_for_every_accepted_pose,
    test_adjoint_identities_hold_for_every_accepted_pose_slow,
) = fuzz_pair(st.tuples(poses(), arrays((6,))), check_adjoint_identities, fast=60, slow=1500)


# ----------------------------------------------------------------------- dynamics
masses = st.one_of(st.floats(0.1, 100.0), scalars)
inertias3 = st.one_of(
    st.sampled_from([np.diag([1.0, 2.0, 2.5]), np.diag([1.0, 1.0, 3.0]), -np.eye(3)]),
    arrays((3, 3)),
)


def check_spatial_inertia(args) -> None:
    mass, J, V, tau, g = args
    inertia = outcome("dynamics.spatial_inertia", dynamics.spatial_inertia, mass, J)
    if inertia is REFUSED:
        return
    m, Jf = _regular(mass, ()), _regular(J, (3, 3))
    assert m is not None and Jf is not None and Jf.ndim == 2, f"took {mass!r:.50} {J!r:.100}"
    assert m > 0 and np.linalg.eigvalsh(Jf / np.abs(Jf).max()).min() > 0, "took a bad inertia"
    expected = np.zeros((6, 6))
    expected[:3, :3], expected[3:, 3:] = Jf, m * np.eye(3)
    np.testing.assert_array_equal(inertia, expected)
    for entry, fn, fargs in (
        ("dynamics.kinetic_energy", dynamics.kinetic_energy, (V, inertia)),
        ("dynamics.free_acceleration", dynamics.free_acceleration, (V, inertia, tau)),
        ("dynamics.spatial_momentum", dynamics.spatial_momentum, (g, V, inertia)),
    ):
        out = outcome(entry, fn, *fargs)
        Vf = _regular(V, (6,))
        if out is REFUSED:
            assert (
                Vf is None
                or np.abs(Vf).max() > 1e100
                or entry.endswith(("free_acceleration", "spatial_momentum"))
            ), f"{entry} refused honest {V!r:.100}"
            continue
        assert Vf is not None, f"{entry} took V = {V!r:.100}"
        if entry.endswith("kinetic_energy"):
            np.testing.assert_allclose(
                out, 0.5 * np.einsum("...i,ij,...j->...", Vf, inertia, Vf), rtol=1e-12
            )
            assert (np.asarray(out) >= 0).all()
        elif entry.endswith("free_acceleration"):
            t = np.zeros(6) if tau is None else _regular(tau, (6,))
            assert t is not None, f"{entry} took τ = {tau!r:.100}"
            if Vf.ndim == 1 and t.ndim == 1 and np.abs(Vf).max() < 1e3 and np.abs(t).max() < 1e3:
                res = inertia @ out - (se3.ad_star(Vf) @ inertia @ Vf + t)
                assert np.abs(res).max() < 1e-9 * (1 + np.abs(Vf).max() ** 2 + np.abs(t).max())
                gdd = outcome("dynamics.g_ddot", dynamics.g_ddot, np.eye(4), Vf, out)
                np.testing.assert_allclose(
                    gdd, se3.hat(out) + se3.hat(Vf) @ se3.hat(Vf), atol=1e-12
                )
        else:
            G = _regular(g, (4, 4))
            assert G is not None, f"{entry} took g = {g!r:.100}"
            if G.ndim == 2 and Vf.ndim == 1 and np.abs(G).max() < 1e3 and np.abs(Vf).max() < 1e3:
                expected_p = se3.Ad(se3.inverse(G)).T @ inertia @ Vf
                np.testing.assert_allclose(out, expected_p, atol=1e-9 * (1 + np.abs(Vf).max()))


(
    test_dynamics_takes_physical_inertias_and_computes_eq_10,
    test_dynamics_takes_physical_inertias_and_computes_eq_10_slow,
) = fuzz_pair(
    st.tuples(masses, inertias3, arrays((6,)), st.one_of(st.none(), arrays((6,))), poses()),
    check_spatial_inertia,
    fast=60,
    slow=1500,
)


def check_dynamics_raw_inertia(args) -> None:
    """A 6×6 given straight to the dynamics: checked there too (issue #25 item 7)."""
    inertia, V = args
    out = outcome("dynamics.kinetic_energy (6×6)", dynamics.kinetic_energy, V, inertia)
    if out is REFUSED:
        return
    if isinstance(inertia, np.ndarray) and inertia.shape[-2:] == (6, 6) and inertia.size == 0:
        assert np.asarray(out).size == 0  # an empty batch gives an empty result, as in numpy
        return
    I6 = _regular(inertia, (6, 6))
    assert I6 is not None and I6.ndim == 2, f"took {inertia!r:.200}"
    assert np.allclose(I6, I6.T) and np.linalg.eigvalsh(I6).min() > 0, "took a non-SPD inertia"
    assert (np.asarray(out) >= 0).all()


(
    test_dynamics_refuse_unphysical_six_by_six_inertias,
    test_dynamics_refuse_unphysical_six_by_six_inertias_slow,
) = fuzz_pair(
    st.tuples(
        st.one_of(
            st.sampled_from([np.eye(6), -np.eye(6), np.zeros((6, 6)), np.diag([1.0] * 5 + [0])]),
            arrays((6, 6)),
        ),
        arrays((6,)),
    ),
    check_dynamics_raw_inertia,
    fast=40,
    slow=1000,
)


# ------------------------------------------------------------------------- orbits
eccentricities = st.one_of(
    st.sampled_from([0.0, 0.1, 0.5, 0.9, 0.999, 1.0, 1.001, 1.5, 3.0]), st.floats(0.0, 5.0), scalars
)
angles = st.one_of(st.floats(-20.0, 20.0), scalars, arrays((3,)))


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def check_kepler(args) -> None:
    M, e = args
    Mf, ef = _regular(M, ()), _regular(e, ())
    for entry, fwd, back, ok in (
        ("orbits.eccentric_from_mean", orbits.eccentric_from_mean, orbits.mean_from_eccentric,
         lambda e: 0 <= e < 1),
        ("orbits.hyperbolic_from_mean", orbits.hyperbolic_from_mean, orbits.mean_from_hyperbolic,
         lambda e: e > 1),
        ("orbits.true_from_mean", orbits.true_from_mean, orbits.mean_from_true,
         lambda e: 0 <= e < 1),
    ):  # fmt: skip
        X = outcome(entry, fwd, M, e)
        if X is REFUSED:
            continue
        assert ef is not None and ok(float(ef)), f"{entry} took e = {e!r:.80}"
        Mf_ = _regular(M, ())
        assert Mf_ is not None or _regular(M, (3,)) is not None, f"{entry} took M = {M!r:.80}"
        M_back = back(X, e)
        M_arr = np.asarray(M, dtype=float)
        if np.abs(M_arr).max(initial=0) < 1e3:
            if "hyperbolic" in entry and float(ef) > 1.01:
                np.testing.assert_allclose(M_back, M_arr, rtol=1e-9, atol=1e-9)
            elif "hyperbolic" not in entry and float(ef) < 0.99:
                np.testing.assert_allclose(_wrap(M_back - M_arr), 0.0, atol=1e-9)
    P = outcome("orbits.parabolic_from_mean", orbits.parabolic_from_mean, M)
    if P is not REFUSED:
        assert Mf is not None or _regular(M, (3,)) is not None, f"took M = {M!r:.80}"
        Ma = np.asarray(M, dtype=float)
        if np.abs(Ma).max(initial=0) < 1e6:
            np.testing.assert_allclose(orbits.mean_from_parabolic(P), Ma, rtol=1e-10, atol=1e-10)


(
    test_keplers_equation_and_its_inverses_round_trip,
    test_keplers_equation_and_its_inverses_round_trip_slow,
) = fuzz_pair(st.tuples(angles, eccentricities), check_kepler, fast=60, slow=1500)


def check_elements(args) -> None:
    p, e, i, raan, argp, nu, mu = args
    out = outcome(
        "orbits.elements_to_state", orbits.elements_to_state, None, e, i, raan, argp, nu, mu, p=p
    )
    if out is REFUSED:
        return
    vals = [_regular(x, ()) for x in (p, e, i, raan, argp, nu, mu)]
    assert all(v is not None for v in vals), f"elements_to_state took {args!r:.300}"
    pf, ef, i_f, _, _, nuf, muf = (float(v) for v in vals)
    assert pf > 0 and ef >= 0 and 0 <= i_f <= math.pi and muf > 0
    r, v = out
    back = outcome("orbits.state_to_elements", orbits.state_to_elements, r, v, mu)
    ordinary = 1e3 < pf < 1e9 and 1e3 < muf < 1e16 and 0.05 < ef < 0.95
    ordinary = ordinary and 0.1 < i_f < math.pi - 0.1
    if not ordinary:
        return
    assert back is not REFUSED, "state_to_elements refused a state elements_to_state made"
    np.testing.assert_allclose(back.p, pf, rtol=1e-8)
    np.testing.assert_allclose(back.e, ef, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(back.i, i_f, atol=1e-8)
    np.testing.assert_allclose(_wrap(back.nu - nuf), 0.0, atol=1e-7)
    # and the energy is the conic's: v²/2 − μ/r = −μ(1 − e²)/(2p)
    energy = 0.5 * v @ v - muf / np.linalg.norm(r)
    assert abs(energy + muf * (1 - ef**2) / (2 * pf)) <= 1e-8 * abs(muf / pf)


elements = st.tuples(
    st.one_of(st.floats(1e3, 1e8), scalars),
    eccentricities,
    st.one_of(st.floats(0.0, 3.2), scalars),
    st.one_of(st.floats(-7.0, 7.0), scalars),
    st.one_of(st.floats(-7.0, 7.0), scalars),
    st.one_of(st.floats(-3.0, 3.0), scalars),
    st.one_of(st.sampled_from([3.986e14, 4.9e12, 1e5]), scalars),
)

(
    test_orbital_elements_round_trip_through_states,
    test_orbital_elements_round_trip_through_states_slow,
) = fuzz_pair(elements, check_elements, fast=60, slow=1500)


def check_wrap(angle) -> None:
    for entry, fn, lo, hi in (
        ("orbits.wrap_to_pi", orbits.wrap_to_pi, -math.pi, math.pi),
        ("orbits.wrap_to_2pi", orbits.wrap_to_2pi, 0.0, 2 * math.pi),
    ):
        out = outcome(entry, fn, angle)
        if out is REFUSED:
            continue
        a = _regular(angle, ()) if np.ndim(angle) == 0 else _regular(angle, np.shape(angle)[-1:])
        assert a is not None, f"{entry} took {angle!r:.100}"
        assert ((out >= lo) & (out <= hi)).all(), f"{entry}: {out} outside [{lo}, {hi}]"
        if np.abs(a).max(initial=0) < 1e6:
            d = np.asarray(out) - a
            np.testing.assert_allclose(_wrap(d), 0.0, atol=1e-9)


(
    test_angle_wrapping_stays_in_range_and_keeps_the_angle,
    test_angle_wrapping_stays_in_range_and_keeps_the_angle_slow,
) = fuzz_pair(st.one_of(angles, arrays((4,))), check_wrap, fast=60, slow=1000)


def check_kepler_orbit(args) -> None:
    p, e, i, mu, t = args
    orbit = outcome("orbits.KeplerOrbit", orbits.KeplerOrbit, p, e, i, 0.3, 0.2, mu)
    if orbit is REFUSED:
        return
    assert all(_regular(x, ()) is not None for x in (p, e, i, mu)), f"took {args!r:.200}"
    ref = outcome("orbits.LVLHReference", orbits.LVLHReference, orbit)
    if ref is REFUSED:
        return
    state = outcome("LVLHReference.evaluate", ref.evaluate, t)
    if state is REFUSED:
        return
    assert _regular(t, ()) is not None, f"LVLHReference.evaluate took t = {t!r:.80}"
    R = state.g[:3, :3]
    assert np.abs(R.T @ R - np.eye(3)).max() < 1e-9 and np.linalg.det(R) > 0


(
    test_kepler_orbits_and_lvlh_references_are_on_the_group,
    test_kepler_orbits_and_lvlh_references_are_on_the_group_slow,
) = fuzz_pair(
    st.tuples(
        st.one_of(st.floats(1e5, 1e8), scalars),
        st.one_of(st.floats(0.0, 0.9), scalars),
        st.one_of(st.floats(0.0, 3.0), scalars),
        st.one_of(st.just(4.9e12), scalars),
        st.one_of(st.floats(0.0, 1e4), scalars),
    ),
    check_kepler_orbit,
    fast=40,
    slow=1000,
)


# ------------------------------------------------------------------------ gravity
def check_field(args) -> None:
    mu, radius, C, S, r = args
    field = outcome("gravity.SphericalHarmonicField", SphericalHarmonicField, mu, radius, C, S)
    if field is REFUSED:
        return
    muf, Rf = _regular(mu, ()), _regular(radius, ())
    assert muf is not None and Rf is not None and muf > 0 and Rf > 0, f"took μ={mu!r}, R={radius!r}"
    Cf, Sf = _regular(C, np.shape(C)[-2:]), _regular(S, np.shape(S)[-2:])
    assert Cf is not None and Sf is not None, f"took C={C!r:.100}, S={S!r:.100}"
    a = outcome("SphericalHarmonicField.acceleration", field.acceleration, r)
    U = outcome("SphericalHarmonicField.potential", field.potential, r)
    if a is REFUSED or U is REFUSED:
        return
    rf = _regular(r, (3,))
    assert rf is not None, f"acceleration took r = {r!r:.100}"
    n = np.linalg.norm(rf)
    if field.degree == 0 and rf.ndim == 1 and 1e-3 < n / Rf < 1e3 and abs(Cf[0, 0] - 1) < 1e-15:
        np.testing.assert_allclose(a, -muf * rf / n**3, rtol=1e-12)


def _coeffs(n):
    C = np.zeros((n + 1, n + 1))
    C[0, 0] = 1.0
    if n >= 2:
        C[2, 0] = -1e-3
    return C


field_args = st.tuples(
    st.one_of(st.just(4.9e12), scalars),
    st.one_of(st.just(1.738e6), scalars),
    st.one_of(st.sampled_from([_coeffs(0), _coeffs(2), _coeffs(3)]), arrays((3, 3))),
    st.one_of(
        st.sampled_from([np.zeros((1, 1)), np.zeros((3, 3)), np.zeros((4, 4))]), arrays((3, 3))
    ),
    st.one_of(
        st.sampled_from([np.array([2e6, 0.0, 1e5]), np.array([0.0, 0.0, 3e6])]), arrays((3,))
    ),
)

(
    test_spherical_harmonic_fields_take_honest_coefficients_and_points,
    test_spherical_harmonic_fields_take_honest_coefficients_and_points_slow,
) = fuzz_pair(field_args, check_field, fast=60, slow=1500)


def check_legendre(args) -> None:
    nmax, t = args
    P = outcome("gravity.legendre_4pi", legendre_4pi, nmax, t)
    if P is not REFUSED:
        assert isinstance(nmax, (int, np.integer)) and not isinstance(nmax, bool), f"nmax={nmax!r}"
        tf = _regular(t, np.shape(t)[-1:] if np.ndim(t) else ())
        assert tf is not None and (np.abs(tf) <= 1).all(), f"legendre_4pi took t = {t!r:.80}"
        P = np.asarray(P)
        np.testing.assert_allclose(P[..., 0, 0], 1.0, rtol=0, atol=1e-15)
        if nmax >= 1:
            np.testing.assert_allclose(P[..., 1, 0], math.sqrt(3) * tf, atol=1e-12)
    N = outcome("gravity.normalization_4pi", normalization_4pi, nmax, 0)
    if N is not REFUSED:
        assert honest_real(nmax) and float(N) > 0


(
    test_legendre_functions_take_degrees_and_cosines,
    test_legendre_functions_take_degrees_and_cosines_slow,
) = fuzz_pair(
    st.tuples(
        st.one_of(st.integers(-2, 30), scalars),
        st.one_of(st.floats(-1.0, 1.0), scalars, arrays((3,))),
    ),
    check_legendre,
    fast=60,
    slow=1000,
)


# --------------------------------------------------------- celestial bodies and check()
def check_celestial(args) -> None:
    name, mu, radius, rate = args
    rotation = outcome("UniformRotation", gmuk.UniformRotation, rate)
    if rotation is not REFUSED:
        assert _regular(rate, ()) is not None, f"UniformRotation took {rate!r:.80}"
    body = outcome(
        "CelestialBody",
        gmuk.CelestialBody,
        name,
        mu,
        radius,
        rotation=None if rotation is REFUSED else rotation,
    )
    if body is REFUSED:
        return
    assert isinstance(name, str) and name, f"CelestialBody took name {name!r}"
    for v in (mu, radius):
        assert v is None or (_regular(v, ()) is not None and float(v) > 0), f"took {v!r:.80}"


(
    test_celestial_bodies_take_positive_constants,
    test_celestial_bodies_take_positive_constants_slow,
) = fuzz_pair(
    st.tuples(
        st.one_of(st.sampled_from(["Moon", "x"]), scalars),
        st.one_of(st.none(), st.just(4.9e12), scalars),
        st.one_of(st.none(), st.just(1.7e6), scalars),
        st.one_of(st.just(2.66e-6), numbers, scalars),
    ),
    check_celestial,
    fast=40,
    slow=1000,
)


def check_crosscheck(args) -> None:
    seed, n = args
    report = outcome("gmuk.check", gmuk.check, seed, n, hang_s=60.0)
    if report is REFUSED:
        return
    assert isinstance(seed, (int, np.integer)) and not isinstance(seed, bool), f"seed={seed!r}"
    assert isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 1, f"n={n!r}"
    assert report.ok, f"gmuk.check({seed}, {n}) disagrees with Pinocchio:\n{report}"


@pytest.fixture(scope="module")
def _pinocchio():
    pytest.importorskip("pinocchio")


_check_fast, _check_slow = fuzz_pair(
    st.tuples(st.one_of(st.integers(0, 2**63), scalars), st.one_of(st.integers(1, 5), scalars)),
    check_crosscheck,
    fast=15,
    slow=150,
)


def test_check_takes_integer_seeds_and_sample_counts_and_agrees(_pinocchio):
    _check_fast()


@pytest.mark.slow
def test_check_takes_integer_seeds_and_sample_counts_and_agrees_slow(_pinocchio):
    _check_slow()


pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")
