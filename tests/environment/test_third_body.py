"""gmuk.environment.ThirdBodyPerturbation and tidal_acceleration."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

import gmuk
from gmuk.environment import MU, Epoch, ThirdBodyPerturbation, position, tidal_acceleration
from gmuk.environment.third_body import third_body_load
from gmuk.errors import DefinitionError
from gmuk.forces.gravity import gravity_gradient_wrench
from gmuk.lie import so3

EPOCH = Epoch("2024-03-20T03:06:00")


@mpmath.workdps(50)  # local to the call: mpmath's precision is global to the process
def _tidal_mp(r, d, mu) -> np.ndarray:
    """μ[(d − r)/|d − r|³ − d/|d|³] in 50-digit arithmetic (mpmath): the reference."""
    r = [mpmath.mpf(float(x)) for x in r]
    d = [mpmath.mpf(float(x)) for x in d]
    rho = [d[i] - r[i] for i in range(3)]
    nr = mpmath.sqrt(sum(x * x for x in rho)) ** 3
    nd = mpmath.sqrt(sum(x * x for x in d)) ** 3
    return np.array([float(mpmath.mpf(mu) * (rho[i] / nr - d[i] / nd)) for i in range(3)])


@pytest.mark.parametrize("perturber", ["sun", "moon"])
def test_battin_form_matches_the_tidal_difference_in_extended_precision(perturber):
    rng = np.random.default_rng(1)
    d = position(perturber, EPOCH)
    for _ in range(20):
        r = rng.normal(size=3)
        r *= rng.uniform(6.6e6, 4.3e7) / np.linalg.norm(r)
        ref = _tidal_mp(r, d, MU[perturber])
        a = tidal_acceleration(r, d, MU[perturber])
        assert np.linalg.norm(a - ref) <= 4e-16 * np.linalg.norm(ref) * 10
        # the direct difference loses digits to cancellation (Sun: ~1e4 times more error)
        if perturber == "sun":
            rho = d - r
            naive = MU["sun"] * (rho / np.linalg.norm(rho) ** 3 - d / np.linalg.norm(d) ** 3)
            assert np.linalg.norm(naive - ref) > np.linalg.norm(a - ref)


def test_point_mass_force_is_mass_times_tidal_acceleration_at_the_ephemeris_position():
    sat = gmuk.PointMass("sat", 250.0)
    model = ThirdBodyPerturbation("moon", EPOCH)
    r, t = np.array([7.0e6, -1.0e6, 2.0e6]), 1234.5
    d = position("moon", EPOCH + t)
    np.testing.assert_allclose(
        model.force(t, r, np.zeros(3), sat),
        250.0 * tidal_acceleration(r, d, MU["moon"]),
        rtol=1e-15,
    )


def test_the_plugin_third_body_gravity_agrees_through_the_same_ephemeris():
    plugin = pytest.importorskip("gmuk_thirdbody")
    from gmuk.environment import Ephemeris

    sat = gmuk.PointMass("sat", 100.0)
    ours = ThirdBodyPerturbation("moon", EPOCH)
    theirs = plugin.ThirdBodyGravity(MU["moon"], Ephemeris("moon", EPOCH))
    r = np.array([4.2e7, 1.0e6, -3.0e5])
    # the plugin's direct difference agrees to its cancellation error (~1e-13 relative here)
    np.testing.assert_allclose(
        ours.force(60.0, r, np.zeros(3), sat), theirs.force(60.0, r, np.zeros(3), sat), rtol=1e-11
    )


def _cloud(rng: np.random.Generator, n: int = 400, size: float = 5.0):
    """A centrally symmetric rigid body as 2n point masses (pairs at ±δr): (masses (2n,),
    offsets δr_B (2n, 3) about their centre of mass, central inertia J_B). Symmetry removes
    Eq. 23's third-order error, leaving the fourth."""
    m = np.tile(rng.uniform(0.5, 2.0, n), 2)
    x = rng.normal(size=(n, 3)) * size * np.array([1.0, 0.6, 0.3])
    x = np.concatenate([x, -x])
    J = sum(mi * (xi @ xi * np.eye(3) - np.outer(xi, xi)) for mi, xi in zip(m, x, strict=True))
    return m, x, J


@mpmath.workdps(40)  # local to the call: mpmath's precision is global to the process
def _cloud_wrench_mp(m, x_B, R, r, d, mu) -> tuple[list, list]:
    """Torque about the centre of mass and total tidal force (in N) of the point cloud,
    summed particle by particle in 40-digit arithmetic."""
    L_N = [mpmath.mpf(0)] * 3
    F_N = [mpmath.mpf(0)] * 3
    dm = [mpmath.mpf(float(v)) for v in d]
    nd3 = mpmath.sqrt(sum(v * v for v in dm)) ** 3
    for mi, xb in zip(m, x_B, strict=True):
        off = R @ xb
        p = [mpmath.mpf(float(r[k])) + mpmath.mpf(float(off[k])) for k in range(3)]
        rho = [dm[k] - p[k] for k in range(3)]
        n3 = mpmath.sqrt(sum(v * v for v in rho)) ** 3
        f = [mpmath.mpf(float(mi)) * mu * (rho[k] / n3 - dm[k] / nd3) for k in range(3)]
        o = [mpmath.mpf(float(v)) for v in off]
        L_N = [L_N[0] + o[1] * f[2] - o[2] * f[1], L_N[1] + o[2] * f[0] - o[0] * f[2],
               L_N[2] + o[0] * f[1] - o[1] * f[0]]  # fmt: skip
        F_N = [F_N[k] + f[k] for k in range(3)]
    return L_N, F_N


def test_rigid_body_wrench_matches_point_cloud_quadrature():
    """Torque about the centre of mass and total tidal force of a point cloud, summed
    particle by particle in extended precision, against the kernel (Eq. 23 at r − d plus
    Battin's force). The perturber is put close (ρ = 2 km for a ~10 m body) so that the
    finite-size terms are well above round-off; for this symmetric body the neglected terms
    are of relative order (size/ρ)² ~ 5e-5 of the finite-size parts."""
    rng = np.random.default_rng(7)
    m, x_B, J = _cloud(rng)
    M = float(m.sum())
    R = so3.exp(np.array([0.3, -1.1, 0.7]))
    r = np.array([7.0e6, 1.0e6, -2.0e6])
    d = r + np.array([1.2e3, -1.5e3, 0.4e3])
    mu = 3.0e11
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = R, r
    out = np.empty(6)
    third_body_load(True, 0.0, g, np.zeros(6), M, J, np.array([mu, *d]), np.zeros(1), out)

    L_N, F_N = _cloud_wrench_mp(m, x_B, R, r, d, mu)
    L_ref = R.T @ np.array([float(v) for v in L_N])
    F_ref = R.T @ np.array([float(v) for v in F_N])
    F_cm = R.T @ (M * tidal_acceleration(r, d, mu))
    assert np.linalg.norm(out[:3] - L_ref) < 1e-4 * np.linalg.norm(L_ref)
    # the finite-size part of the force (total minus the centre-of-mass force)
    fin_ref, fin = F_ref - F_cm, out[3:] - F_cm
    assert np.linalg.norm(fin - fin_ref) < 1e-4 * np.linalg.norm(fin_ref)


def test_rigid_torque_is_eq23_at_the_position_relative_to_the_perturber():
    rng = np.random.default_rng(3)
    _, _, J = _cloud(rng)
    body = gmuk.RigidBody("sc", 500.0, J)
    model = ThirdBodyPerturbation("sun", EPOCH)
    g = np.eye(4)
    g[:3, :3] = so3.exp(np.array([0.1, 0.2, -0.4]))
    g[:3, 3] = [4.2e7, 0.0, 1.0e5]
    w = model.wrench(10.0, g, np.zeros(6), body)
    gs = g.copy()
    gs[:3, 3] -= position("sun", EPOCH + 10.0)
    ref = np.empty(6)
    gravity_gradient_wrench(gs, MU["sun"], 500.0, J, ref)
    np.testing.assert_array_equal(w[:3], ref[:3])
    # the force is the tidal one to the finite-size terms' size (~1e-28 of the Sun's pull)
    d = position("sun", EPOCH + 10.0)
    f_cm = g[:3, :3].T @ (500.0 * tidal_acceleration(g[:3, 3], d, MU["sun"]))
    np.testing.assert_allclose(w[3:], f_cm, rtol=1e-12)


def test_bad_definitions_are_refused():
    with pytest.raises(DefinitionError, match="perturber must be one of"):
        ThirdBodyPerturbation("jupiter", EPOCH)
    with pytest.raises(DefinitionError, match="other than its centre"):
        ThirdBodyPerturbation("earth", EPOCH)
    with pytest.raises(DefinitionError, match="Epoch"):
        ThirdBodyPerturbation("sun", "2024-01-01")


def test_symbolic_form_needs_a_numeric_time():
    ca = pytest.importorskip("casadi")
    model = ThirdBodyPerturbation("sun", EPOCH)
    sat = gmuk.PointMass("sat", 10.0)
    with pytest.raises(DefinitionError, match="numeric times only"):
        model.casadi_force(ca.SX.sym("t"), ca.SX.sym("r", 3), ca.SX.sym("v", 3), sat)
    r = np.array([7.0e6, 0.0, 1.0e6])
    f = np.asarray(ca.DM(model.casadi_force(30.0, ca.DM(r), None, sat))).ravel()
    np.testing.assert_allclose(f, model.force(30.0, r, np.zeros(3), sat), rtol=1e-13)
