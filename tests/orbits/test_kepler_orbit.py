"""KeplerOrbit: two-body motion at time t on every conic (gmuk.orbits.conics)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from orbit_cases import CLOSED, MU, ORBITS, central_difference, local_step, sample_times
from scipy.integrate import solve_ivp

from gmuk.errors import NonFiniteError, OrbitError
from gmuk.orbits import KeplerOrbit, state_to_elements


def _two_body(_t, y, mu):
    r = y[:3]
    return np.concatenate([y[3:], -mu * r / np.linalg.norm(r) ** 3])


@pytest.mark.parametrize("name", list(ORBITS))
def test_state_matches_an_independent_two_body_integration(name):
    orbit = ORBITS[name]
    t = sample_times(orbit, 41)
    r0, v0 = orbit.state(t[0])
    sol = solve_ivp(
        _two_body,
        (t[0], t[-1]),
        np.concatenate([r0, v0]),
        method="DOP853",
        t_eval=t,
        rtol=1e-13,
        atol=1e-9,
        args=(orbit.mu,),
    )
    assert sol.success
    r, v = orbit.state(t)
    r_err = np.linalg.norm(sol.y[:3].T - r, axis=1) / np.linalg.norm(r, axis=1)
    v_err = np.linalg.norm(sol.y[3:].T - v, axis=1) / np.linalg.norm(v, axis=1)
    assert r_err.max() < 1e-9
    assert v_err.max() < 1e-9


@pytest.mark.parametrize("name", list(ORBITS))
def test_velocity_and_acceleration_are_the_time_derivatives(name):
    orbit = ORBITS[name]
    t = sample_times(orbit)
    h = local_step(orbit, t)
    r, v = orbit.state(t)
    a = orbit.acceleration(t)
    v_fd = central_difference(orbit.position, t, h)
    a_fd = central_difference(orbit.velocity, t, h)
    vn = np.linalg.norm(v, axis=1, keepdims=True)
    an = np.linalg.norm(a, axis=1, keepdims=True)
    assert (np.abs(v_fd - v) / vn).max() < 1e-9
    assert (np.abs(a_fd - a) / an).max() < 1e-9
    rn = np.linalg.norm(r, axis=1, keepdims=True)
    np.testing.assert_allclose(a, -orbit.mu * r / rn**3, rtol=0, atol=1e-14 * an.max())


@pytest.mark.parametrize("name", list(ORBITS))
def test_true_anomaly_rates_match_finite_differences_and_the_thesis_formulas(name):
    orbit = ORBITS[name]
    t = sample_times(orbit)
    h = local_step(orbit, t)
    f, f_dot, f_ddot = orbit.anomaly_rates(t)
    fd1 = central_difference(orbit.true_anomaly, t, h)
    fd2 = central_difference(lambda s: orbit.anomaly_rates(s)[1], t, h)
    assert (np.abs(fd1 - f_dot) / f_dot).max() < 1e-10
    # f̈ vanishes at periapsis and apoapsis: compare with its natural size ḟ².
    assert (np.abs(fd2 - f_ddot) / f_dot**2).max() < 1e-9
    # McCann (2020), Section 4.1.2 as printed (h = √(μp)).
    mu, e, hh = orbit.mu, orbit.e, orbit.h
    w = 1 + e * np.cos(f)
    np.testing.assert_allclose(f_dot, mu**2 / hh**3 * w**2, rtol=1e-14)
    np.testing.assert_allclose(
        f_ddot, -2 * mu**4 / hh**6 * w**3 * e * np.sin(f), rtol=1e-13, atol=1e-16 * f_dot.max() ** 2
    )
    # v̇_{d/P} = −μ³/h⁴ (1 + e cos f)² [cos f, sin f, 0] (printed, correct).
    a_P = orbit.perifocal_state(t)[2]
    printed = (
        -(mu**3)
        / hh**4
        * (w**2)[:, None]
        * np.stack([np.cos(f), np.sin(f), np.zeros_like(f)], axis=1)
    )
    np.testing.assert_allclose(a_P, printed, rtol=1e-13, atol=1e-15 * np.abs(a_P).max())


@pytest.mark.parametrize("name", CLOSED)
def test_ellipse_periapsis_apoapsis_and_continuity_over_revolutions(name):
    orbit = ORBITS[name]
    T = orbit.period
    assert T == pytest.approx(2 * math.pi * math.sqrt(orbit.a**3 / orbit.mu), rel=1e-14)
    f = orbit.true_anomaly([0.0, T / 2, T, 3 * T, -T])
    np.testing.assert_allclose(f, [0, math.pi, 2 * math.pi, 6 * math.pi, -2 * math.pi], atol=1e-12)
    r = np.linalg.norm(orbit.position([0.0, T / 2]), axis=1)
    np.testing.assert_allclose(r, [orbit.a * (1 - orbit.e), orbit.a * (1 + orbit.e)], rtol=1e-14)
    tt = np.linspace(-1.5 * T, 2.5 * T, 4001)
    assert np.all(np.diff(orbit.true_anomaly(tt)) > 0)
    np.testing.assert_allclose(orbit.position(tt + T), orbit.position(tt), atol=1e-8 * orbit.a)


@pytest.mark.parametrize("name", list(ORBITS))
def test_from_state_recovers_the_orbit_and_the_time(name):
    orbit = ORBITS[name]
    for t in sample_times(orbit, 9)[:-1]:
        r, v = orbit.state(t)
        again, t2 = KeplerOrbit.from_state(r, v, orbit.mu)
        r2, v2 = again.state(t2)
        np.testing.assert_allclose(r2, r, rtol=0, atol=1e-12 * np.linalg.norm(r))
        np.testing.assert_allclose(v2, v, rtol=0, atol=1e-11 * np.linalg.norm(v))
        assert again.p == pytest.approx(orbit.p, rel=1e-12)
        assert again.e == pytest.approx(orbit.e, abs=1e-12)


@pytest.mark.parametrize("name", list(ORBITS))
def test_time_from_true_anomaly_inverts_true_anomaly(name):
    orbit = ORBITS[name]
    t = sample_times(orbit)
    np.testing.assert_allclose(
        orbit.time_from_true_anomaly(orbit.true_anomaly(t)), t, rtol=1e-12, atol=1e-9
    )


@pytest.mark.parametrize("name", list(ORBITS))
def test_energy_and_angular_momentum_are_constant(name):
    orbit = ORBITS[name]
    r, v = orbit.state(sample_times(orbit))
    energy = 0.5 * np.sum(v * v, axis=1) - orbit.mu / np.linalg.norm(r, axis=1)
    scale = orbit.mu / orbit.p
    np.testing.assert_allclose(energy, orbit.energy, rtol=0, atol=1e-13 * scale)
    h = np.cross(r, v)
    np.testing.assert_allclose(
        h, np.broadcast_to(orbit.h * orbit.R_NP[:, 2], h.shape), rtol=0, atol=1e-13 * orbit.h
    )
    el = state_to_elements(r, v, orbit.mu)
    np.testing.assert_allclose(el.e, orbit.e, atol=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.floats(-2e5, 2e5, allow_nan=False))
def test_scalar_fast_path_equals_the_vectorised_anomalies(t):
    for orbit in ORBITS.values():
        f, fd, fdd = orbit._scalar_anomaly(t)
        fv, fdv, fddv = orbit.anomaly_rates(t)
        assert f == pytest.approx(float(fv), rel=1e-15, abs=1e-15)
        assert fd == pytest.approx(float(fdv), rel=1e-14)
        # f̈ = −2(μ/p³) e w³ sin f: near sin f = 0 its rounding is the rounding of f (an ulp of
        # the angle) times ∂f̈/∂f, which the relative part cannot cover
        k2, e = orbit.mu / orbit.p**3, orbit.e
        w = 1.0 + e * math.cos(f)
        slope = 2.0 * k2 * e * abs(w**3 * math.cos(f) - 3.0 * w**2 * e * math.sin(f) ** 2)
        ulp_f = np.spacing(max(abs(f), 2.0 * math.pi))
        assert fdd == pytest.approx(float(fddv), rel=1e-13, abs=4.0 * ulp_f * slope)


def test_mean_motions_and_kinds():
    assert ORBITS["fcei_thesis"].kind == "ellipse"
    assert ORBITS["circular_equatorial"].kind == "ellipse"
    par, hyp = ORBITS["parabola"], ORBITS["hyperbola"]
    assert par.kind == "parabola" and par.a == math.inf and par.period == math.inf
    assert par.mean_motion == pytest.approx(2 * math.sqrt(par.mu / par.p**3), rel=1e-15)
    assert hyp.kind == "hyperbola" and hyp.a == pytest.approx(-3.0e6, rel=1e-15)
    assert hyp.mean_motion == pytest.approx(math.sqrt(hyp.mu / 3.0e6**3), rel=1e-14)


def test_orbit_is_immutable_and_validated():
    orbit = ORBITS["fcei_thesis"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        orbit.e = 0.3  # type: ignore[misc]
    with pytest.raises(ValueError, match="read-only"):
        orbit.R_NP[0, 0] = 2.0
    with pytest.raises(OrbitError, match="e must be ≥ 0"):
        KeplerOrbit(4e6, -0.2, 0.0, 0.0, 0.0, MU)
    with pytest.raises(OrbitError, match="p must be > 0"):
        KeplerOrbit(0.0, 0.2, 0.0, 0.0, 0.0, MU)
    with pytest.raises(OrbitError, match="mu must be > 0"):
        KeplerOrbit(4e6, 0.2, 0.0, 0.0, 0.0, -1.0)
    with pytest.raises(OrbitError, match=r"ellipse .* needs a > 0"):
        KeplerOrbit.from_elements(-4e6, 0.2, 0.0, 0.0, 0.0, MU)
    with pytest.raises(OrbitError, match="parabola"):
        KeplerOrbit.from_elements(4e6, 1.0, 0.0, 0.0, 0.0, MU)
    with pytest.raises(NonFiniteError, match="i must be finite"):
        KeplerOrbit(4e6, 0.2, float("nan"), 0.0, 0.0, MU)
    with pytest.raises(NonFiniteError, match="t must be finite"):
        orbit.position([0.0, float("nan")])
    with pytest.raises(OrbitError, match="asymptote"):
        ORBITS["hyperbola"].time_from_true_anomaly(3.0)


@pytest.mark.parametrize("name", list(ORBITS))
def test_scalar_kinematics_equal_the_array_position_velocity_and_acceleration(name):
    orbit = ORBITS[name]
    for t in sample_times(orbit, 9):
        r, v, a = orbit.kinematics(float(t))
        for got, want in (
            (r, orbit.position(t)),
            (v, orbit.velocity(t)),
            (a, orbit.acceleration(t)),
        ):
            assert got.shape == (3,)
            np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-12 * np.linalg.norm(want))
