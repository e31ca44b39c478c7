"""ThesisRadialHarmonicGravity: McCann (2020) Eqs. 42 and 59 as printed, and how wrong they are.

* against an independent evaluation of the printed equations (Legendre functions by
  Rodrigues' formula, Eqs. 26a–b, with exact integer coefficients and factorials, in
  30-digit mpmath, term by term in the inertial frame with J_N = R J Rᵀ);
* its limits: degree 0 is Eq. 23 (GravityGradient) exactly; a point mass gets the printed
  Eq. 25; the torque is always along r × J r;
* its error against brute-force point-cloud quadrature of the real (4π) field, at degrees
  2, 10, 50, 150, relative to the harmonic perturbation (force) and to the harmonic part of
  the torque;
* the one-orbit position change behind the default normalisation (the thesis's Figure 3.1
  reports "almost four kilometers").

Run with ``-s`` to print the measured figures quoted in docs/theory/chapter3.rst.
"""

from __future__ import annotations

from math import comb, factorial

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from test_harmonic_bodies import (
    LM_J,
    LM_MASS,
    pair_sums,
    plain_sums,
    position,
    principal_cloud,
)

import gmuk
from gmuk.errors import DefinitionError, DomainError
from gmuk.forces import ThesisRadialHarmonicGravity
from gmuk.gravity import SphericalHarmonicField, load
from gmuk.gravity.thesis import thesis_eq25_radial_acceleration
from gmuk.lie import so3

NORMS = ("thesis_eq26c_intended", "thesis_eq26c", "4pi")


@pytest.fixture(scope="module")
def grail():
    """GRGM660PRIM to degree 150, shipped with gmuk."""
    return load("GRGM660PRIM")


def lm():
    return gmuk.RigidBody("lm", LM_MASS, LM_J)


def pose(moon, t, r_F, R_NB):
    g = np.eye(4)
    g[:3, :3] = R_NB
    g[:3, 3] = moon.rotation.R_FN(t).T @ r_F
    return g


# --------------------------------------------------------------------------- printed formulas


def _legendre_eq26ab(n, p, theta):
    """P_np(sin θ) by Eqs. 26a–b literally: (1 − t²)^{p/2} dᵖ/dtᵖ of Rodrigues'
    (1/(2ⁿ n!)) dⁿ/dtⁿ (t² − 1)ⁿ, with exact integer polynomial coefficients (no phase)."""
    t = mp.sin(theta)
    total = mp.mpf(0)
    for k in range(n + 1):  # (t² − 1)ⁿ = Σ C(n, k) (−1)^(n−k) t^(2k)
        j = 2 * k
        if j < n + p:
            continue
        total += (
            comb(n, k) * (-1) ** (n - k) * factorial(j) // factorial(j - n - p) * t ** (j - n - p)
        )
    return mp.cos(theta) ** p * total / (2**n * factorial(n))


def _pbar(n, p, theta, normalization):
    """P̄_np(sin θ) with the chosen normalisation, from exact factorials."""
    ratio = mp.mpf(factorial(n - p)) / factorial(n + p)
    if normalization == "thesis_eq26c":  # √(n + ½ (n−p)!/(n+p)!), as printed
        N = mp.sqrt(n + ratio / 2)
    elif normalization == "thesis_eq26c_intended":  # √((n + ½)(n−p)!/(n+p)!)
        N = mp.sqrt((n + mp.mpf(1) / 2) * ratio)
    else:
        N = mp.sqrt((2 - (p == 0)) * (2 * n + 1) * ratio)
    return N * _legendre_eq26ab(n, p, theta)


def printed_eq42_eq59(field, degree, normalization, r_N, R_NB, R_FN, m, J_B):
    """Eqs. 42 and 59 term by term as printed, in N with J_N = R J Rᵀ; returns body-frame
    [L; f]. Latitude and longitude by Eqs. 60–62 from r_F = R_FN r_N."""
    with mp.workdps(30):
        r_F = R_FN @ r_N
        rn = float(np.linalg.norm(r_N))
        theta = mp.asin(mp.mpf(float(r_F[2])) / rn)
        phi = mp.atan2(float(r_F[1]), float(r_F[0]))
        J = R_NB @ J_B @ R_NB.T
        r = r_N
        rr = float(r @ r)
        mu, RM = field.mu, field.radius
        I3 = np.eye(3)
        rJr = float(r @ J @ r)
        F = (
            -mu * m / rr**1.5 * (I3 + 3 / (m * rr) * (J + 0.5 * (np.trace(J) - 5 * rJr / rr) * I3))
        ) @ r
        bracket = mp.mpf(3)
        for n in range(1, degree + 1):
            for p in range(n + 1):
                trig = field.C[n, p] * mp.cos(p * phi) + field.S[n, p] * mp.sin(p * phi)
                Pnp = _pbar(n, p, theta, normalization)
                Q = (n + 1) * mp.mpf(RM) ** n * Pnp * trig  # Eq. 28
                coef = float(mu * m * Q / mp.mpf(rr) ** (mp.mpf(n + 3) / 2))
                inner = I3 + (n + 3) / (m * rr) * (
                    J + (n + 2) / 4 * (np.trace(J) - (n + 5) * rJr / rr) * I3
                )
                F = F + coef * (inner @ r)
                bracket -= (n + 1) * (n + 3) * (mp.mpf(RM) / rn) ** n * Pnp * trig
        L = mu / rr**2.5 * float(bracket) * np.cross(r, J @ r)
    return np.concatenate([R_NB.T @ L, R_NB.T @ F])


@pytest.mark.parametrize("normalization", NORMS)
@pytest.mark.parametrize("degree", [2, 7, 16])
def test_matches_the_printed_equations_evaluated_independently(grail, normalization, degree):
    moon = gmuk.CelestialBody.moon(field=grail)
    model = ThesisRadialHarmonicGravity(moon, degree, normalization=normalization)
    rng = np.random.default_rng(degree)
    for lat in (90.0, -33.0, 71.0):
        t = float(rng.uniform(0, 1e6))
        r_F = position(grail.radius + rng.uniform(50e3, 500e3), lat, rng.uniform(-180, 180))
        R_NB = so3.exp(rng.normal(size=3))
        g = pose(moon, t, r_F, R_NB)
        want = printed_eq42_eq59(
            grail, degree, normalization, g[:3, 3], R_NB, moon.rotation.R_FN(t), LM_MASS, LM_J
        )
        got = model.wrench(t, g, np.zeros(6), lm())
        assert np.linalg.norm(got[3:] - want[3:]) <= 1e-12 * np.linalg.norm(want[3:])
        assert np.linalg.norm(got[:3] - want[:3]) <= 1e-11 * np.linalg.norm(want[:3])


# --------------------------------------------------------------------------- limits


@pytest.mark.parametrize("normalization", NORMS)
def test_degree_zero_is_eq_23(grail, normalization):
    """The harmonic sums start at n = 1: degree 0 leaves Eq. 33 + Eq. 52 = Eq. 23 exactly
    (GRGM660PRIM has C̄₁ₘ = S̄₁ₘ = 0, so degree 1 does too)."""
    moon = gmuk.CelestialBody.moon(field=grail)
    gg = gmuk.GravityGradient(grail.mu)
    rng = np.random.default_rng(0)
    for degree in (0, 1):
        model = ThesisRadialHarmonicGravity(moon, degree, normalization=normalization)
        for _ in range(5):
            g = np.eye(4)
            g[:3, :3] = so3.exp(rng.normal(size=3))
            g[:3, 3] = position(grail.radius + 1e5, rng.uniform(-90, 90), rng.uniform(-180, 180))
            w_t = model.wrench(3.0e4, g, np.zeros(6), lm())
            w_g = gg.wrench(3.0e4, g, np.zeros(6), lm())
            # Equal to rounding. The torque 3μ/r⁵ r_B × J r_B cancels (r_B nearly along
            # J r_B), so its rounding is relative to the size of the factors, not of L.
            r_B = g[:3, :3].T @ g[:3, 3]
            r = np.linalg.norm(r_B)
            size_L = 3.0 * grail.mu / r**5 * r * np.linalg.norm(lm().inertia @ r_B)
            assert np.linalg.norm(w_t[:3] - w_g[:3]) <= 1e-14 * size_L
            assert np.linalg.norm(w_t[3:] - w_g[3:]) <= 1e-14 * np.linalg.norm(w_g[3:])


@pytest.mark.parametrize("normalization", ["thesis_eq26c", "4pi"])
def test_point_mass_gets_the_printed_eq_25(grail, normalization):
    moon = gmuk.CelestialBody.moon(field=grail)
    model = ThesisRadialHarmonicGravity(moon, 30, normalization=normalization)
    pm = gmuk.PointMass("p", 12.0)
    g = np.eye(4)
    t = 7.7e4
    for lat in (90.0, 10.0, -90.0):
        r_F = position(grail.radius + 8e4, lat, 140.0)
        g[:3, 3] = moon.rotation.R_FN(t).T @ r_F
        a_F = thesis_eq25_radial_acceleration(grail.truncate(30), r_F, normalization=normalization)
        want = 12.0 * (moon.rotation.R_FN(t).T @ a_F)
        assert np.allclose(model.force(t, g[:3, 3], np.zeros(3), pm), want, rtol=1e-13, atol=0)


def test_torque_is_the_gravity_gradient_torque_times_the_printed_bracket(grail):
    """Eq. 59 = Eq. 23a × [3 − Σ (n+1)(n+3) ρⁿ T_n]/3: always along r_B × J r_B (the
    frozen angular factor keeps only the radial-radial curvature of each degree)."""
    moon = gmuk.CelestialBody.moon(field=grail)
    model = ThesisRadialHarmonicGravity(moon, 150)
    gg = gmuk.GravityGradient(grail.mu)
    rng = np.random.default_rng(4)
    for _ in range(4):
        g = np.eye(4)
        g[:3, :3] = so3.exp(rng.normal(size=3))
        g[:3, 3] = position(grail.radius + 5e4, rng.uniform(-90, 90), rng.uniform(-180, 180))
        L_t = model.wrench(0.0, g, np.zeros(6), lm())[:3]
        L_g = gg.wrench(0.0, g, np.zeros(6), lm())[:3]
        r_N = g[:3, 3]
        T = model.degree_terms(r_N)  # F = N at t = 0
        n = np.arange(1, 151)
        bracket = 3.0 - np.sum(
            (n + 1) * (n + 3) * (grail.radius / np.linalg.norm(r_N)) ** n * T[1:]
        )
        assert np.allclose(L_t, L_g * bracket / 3.0, rtol=1e-12, atol=0)
        assert abs(bracket / 3.0 - 1.0) > 1e-6  # the harmonics do change it (~2e-5 here)


def test_printed_eq_41_bracket_differs_from_eq_40_by_a_negligible_amount(grail):
    """Eq. 40 combines to (n+2)/4 tr J − (n+5)/2 r̂ᵀJr̂, Eq. 41/42 print (n+2)/4 [tr J −
    (n+5) r̂ᵀJr̂]; the model keeps the print. The difference is a finite-size term."""
    moon = gmuk.CelestialBody.moon(field=grail)
    model = ThesisRadialHarmonicGravity(moon, 150)
    worst = 0.0
    for lat in (90.0, 20.0, -45.0):
        g = np.eye(4)
        g[:3, :3] = so3.exp(np.array([0.3, 1.0, -0.4]))
        r = position(grail.radius + 5e4, lat, 60.0)
        g[:3, 3] = r
        T = model.degree_terms(r)
        n = np.arange(1, 151)
        rn = np.linalg.norm(r)
        r_B = g[:3, :3].T @ r
        q = r_B @ LM_J @ r_B / rn**2
        c = (n + 1) * (grail.radius / rn) ** n * T[1:]
        k = (n + 3) / (LM_MASS * rn**2)
        printed = np.sum(c * k * (n + 2) / 4 * (np.trace(LM_J) - (n + 5) * q))
        from_eq40 = np.sum(c * k * ((n + 2) / 4 * np.trace(LM_J) - (n + 5) / 2 * q))
        dF = grail.mu * LM_MASS / rn**3 * abs(printed - from_eq40) * rn
        harmonic = LM_MASS * np.linalg.norm(grail.acceleration(r, central=False))
        worst = max(worst, dF / harmonic)
    print(f"\nEq. 41 printed vs combined from Eq. 40: {worst:.1e} of the harmonic force")
    assert 0 < worst < 1e-8


def test_constructor_errors(grail):
    with pytest.raises(DefinitionError, match="needs a CelestialBody"):
        ThesisRadialHarmonicGravity(gmuk.CelestialBody.moon())
    with pytest.raises(DefinitionError, match="normalization must be one of"):
        ThesisRadialHarmonicGravity(gmuk.CelestialBody.moon(field=grail), normalization="x")
    with pytest.raises(gmuk.errors.DegreeError):
        ThesisRadialHarmonicGravity(gmuk.CelestialBody.moon(field=grail), 151)


def test_printed_normalization_overflows_past_degree_150():
    """The printed Eq. 26c factor exceeds the range of doubles past (n, p) ≈ (150, 150):
    evaluation raises instead of returning inf/NaN."""
    N = 170
    rng = np.random.default_rng(1)
    C = np.tril(rng.normal(0, 1e-9, (N + 1, N + 1)))
    S = np.tril(rng.normal(0, 1e-9, (N + 1, N + 1)))
    C[0, 0], S[:, 0] = 1.0, 0.0
    field = SphericalHarmonicField(4.9e12, 1.738e6, C, S)
    moon = gmuk.CelestialBody.moon(field=field)
    g = np.eye(4)
    g[:3, 3] = position(1.838e6, 10.0, 20.0)
    with pytest.raises(DomainError, match="not finite"):
        ThesisRadialHarmonicGravity(moon, normalization="thesis_eq26c").wrench(
            0.0, g, np.zeros(6), lm()
        )
    w = ThesisRadialHarmonicGravity(moon).wrench(0.0, g, np.zeros(6), lm())
    assert np.all(np.isfinite(w))


# --------------------------------------------------------------------------- error vs truth


def _error_samples(grail, degree, normalization, k=120, seed=0):
    """Ratios |Eq. 42 − truth| / |harmonic force| and |Eq. 59 − truth| / |harmonic torque|
    at k random positions (50–500 km, uniform on the sphere) and attitudes; truth by
    quadrature over the LM's six-point cloud: force Σ mᵢ∇U (plain double sums: the
    perturbation is ≥ 1e-5 of the total), torque by the exact pair sums."""
    field = grail.truncate(degree)
    point = grail.truncate(0)
    moon = gmuk.CelestialBody.moon(field=field)
    model = ThesisRadialHarmonicGravity(moon, normalization=normalization)
    p, w = principal_cloud(LM_MASS, LM_J)
    cloud = np.concatenate([p, -p])
    rng = np.random.default_rng(seed)
    ef, eL, sf, sL = [], [], [], []
    for _ in range(k):
        u = rng.normal(size=3)
        r_F = (grail.radius + rng.uniform(50e3, 500e3)) * u / np.linalg.norm(u)
        R_NB = so3.exp(rng.normal(size=3))
        g = pose(moon, 0.0, r_F, R_NB)
        F, _ = plain_sums(field, r_F, R_NB, cloud, w)
        F0, _ = plain_sums(point, r_F, R_NB, cloud, w)
        _, L, _ = pair_sums(field, r_F, R_NB, p, w)
        _, L0, _ = pair_sums(point, r_F, R_NB, p, w)
        wr = model.wrench(0.0, g, np.zeros(6), lm())
        ef.append(np.linalg.norm(wr[3:] - F) / np.linalg.norm(F - F0))
        eL.append(np.linalg.norm(wr[:3] - L) / np.linalg.norm(L - L0))
        sf.append(np.linalg.norm(F - F0) / np.linalg.norm(F))
        sL.append(np.linalg.norm(L - L0) / np.linalg.norm(L))
    return np.array(ef), np.array(eL), np.median(sf), np.median(sL)


def _summary(x):
    q5, q50, q95 = np.percentile(x, [5, 50, 95])
    return q5, q50, q95, x.min(), x.max()


#: Measured with seed 0, 120 samples (median of force ratio, median of torque ratio):
#: the figures quoted in docs/theory/chapter3.rst.
MEASURED = {
    ("4pi", 2): (1.59, 1.41),
    ("4pi", 10): (1.57, 1.31),
    ("4pi", 50): (1.51, 1.33),
    ("4pi", 150): (1.51, 1.33),
    ("thesis_eq26c_intended", 2): (1.40, 1.27),
    ("thesis_eq26c_intended", 10): (1.35, 1.18),
    ("thesis_eq26c_intended", 50): (1.34, 1.18),
    ("thesis_eq26c_intended", 150): (1.34, 1.18),
}


@pytest.mark.parametrize("degree", [2, 10, 50, 150])
@pytest.mark.parametrize("normalization", ["4pi", "thesis_eq26c_intended"])
def test_error_against_quadrature(grail, normalization, degree):
    ef, eL, share_f, share_L = _error_samples(grail, degree, normalization)
    f5, f50, f95, fmin, fmax = _summary(ef)
    L5, L50, L95, Lmin, Lmax = _summary(eL)
    print(
        f"\n{normalization:22s} degree {degree:3d}: force error / harmonic force: median "
        f"{f50:.2f} (5–95 %: {f5:.2f}–{f95:.2f}, range {fmin:.2f}–{fmax:.2f}); torque error / "
        f"harmonic torque: median {L50:.2f} (5–95 %: {L5:.2f}–{L95:.2f}, range "
        f"{Lmin:.2f}–{Lmax:.2f}); median harmonic share of the force {share_f:.1e}, of the "
        f"torque {share_L:.1e}"
    )
    if normalization == "4pi":
        # at the centre of mass the error is a_t + 2 a_r of the perturbation (radial only,
        # sign flipped): between 1 and 2 times it, exactly; the finite-size parts are ~1e-9
        assert fmin >= 1.0 - 1e-6 and fmax <= 2.0 + 1e-6
    want_f, want_L = MEASURED[(normalization, degree)]
    assert f50 == pytest.approx(want_f, rel=0.02)
    assert L50 == pytest.approx(want_L, rel=0.02)


# --------------------------------------------------------------------------- one orbit

#: McCann (2020) §3.4 initial condition: r = 1824 km on axis 1, body velocity −1648.63 m/s
#: on body axis 2 with the printed attitude.
R0 = np.array([[-1.0, 0.0, 0.0], [0.0, -0.98163, -0.19081], [0.0, -0.19081, 0.98163]])
r0 = np.array([1.824e6, 0.0, 0.0])
v0 = R0 @ np.array([0.0, -1.64863e3, 0.0])


def one_orbit_deviation(moon, force):
    """Max |r − r_uniform| (m) over one osculating period of a point mass under ``force``
    (a ForceModel on a unit PointMass) against the central field alone."""
    pm = gmuk.PointMass("p", 1.0)
    mu = moon.mu
    a = 1.0 / (2.0 / np.linalg.norm(r0) - v0 @ v0 / mu)
    T = 2 * np.pi * np.sqrt(a**3 / mu)
    ts = np.linspace(0.0, T, 400)

    def rhs(t, y, acc):
        return np.concatenate([y[3:], acc(t, y[:3])])

    def model_acc(t, r):
        return force.force(t, r, np.zeros(3), pm)

    def kepler(t, r):
        return -mu * r / np.linalg.norm(r) ** 3

    y0 = np.concatenate([r0, v0])
    out = []
    for acc in (model_acc, kepler):
        sol = solve_ivp(rhs, (0, T), y0, "DOP853", t_eval=ts, rtol=1e-10, atol=1e-6, args=(acc,))
        assert sol.status == 0
        out.append(sol.y[:3])
    return float(np.max(np.linalg.norm(out[0] - out[1], axis=0)))


#: Measured one-orbit deviations (km), quoted in docs/theory/chapter3.rst. The printed
#: Eq. 26c at degree 10 sends the orbit off the Moon (5.7e5 km); only "> 1e4 km" is checked.
ORBIT_KM = {
    ("thesis_eq26c_intended", 2): 4.28,
    ("thesis_eq26c_intended", 10): 4.80,
    ("thesis_eq26c_intended", 50): 4.18,
    ("thesis_eq26c_intended", 150): 4.19,
    ("4pi", 2): 6.06,
    ("4pi", 10): 7.07,
    ("4pi", 50): 5.86,
    ("4pi", 150): 5.88,
    ("thesis_eq26c", 2): 4.34,
    ("correct", 2): 8.44,
    ("correct", 10): 8.09,
    ("correct", 50): 7.20,
    ("correct", 150): 7.24,
}


def _orbit_case(grail, degree, kind):
    field = grail.truncate(degree)
    moon = gmuk.CelestialBody.moon(field=field)
    if kind == "correct":
        force = gmuk.forces.SphericalHarmonicGravity(moon)
    else:
        force = ThesisRadialHarmonicGravity(moon, normalization=kind)
    return one_orbit_deviation(moon, force) / 1e3


@pytest.mark.parametrize(
    ("degree", "kind"),
    [(d, k) for d in (2, 10) for k in ("thesis_eq26c_intended", "4pi", "thesis_eq26c", "correct")],
)
def test_one_orbit_position_change(grail, degree, kind):
    km = _orbit_case(grail, degree, kind)
    print(f"\none orbit, {kind}, degree {degree}: max |Δr| = {km:.2f} km")
    if (kind, degree) == ("thesis_eq26c", 10):
        assert km > 1e4
    else:
        assert km == pytest.approx(ORBIT_KM[(kind, degree)], rel=0.02)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("degree", "kind"),
    [(d, k) for d in (50, 150) for k in ("thesis_eq26c_intended", "4pi", "correct")],
)
def test_one_orbit_position_change_high_degree(grail, degree, kind):
    km = _orbit_case(grail, degree, kind)
    print(f"\none orbit, {kind}, degree {degree}: max |Δr| = {km:.2f} km")
    assert km == pytest.approx(ORBIT_KM[(kind, degree)], rel=0.02)
