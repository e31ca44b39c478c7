"""The modified-LVLH reference of McCann (2020), Section 4.1.2, corrected (docs/errata.rst)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from orbit_cases import ORBITS, central_difference, local_step, sample_times

from gmuk.errors import DefinitionError, NonFiniteError
from gmuk.lie import se3, so3
from gmuk.orbits import (
    MU_MOON_THESIS_CONSISTENT,
    R_PD,
    LVLHReference,
    compose_motion,
    fcei_orbit,
    section43_initial_state,
    thesis_eq69_R_dP_as_printed,
)
from gmuk.reference import ReferenceTrajectory

MU_MOON_USUAL = 4.9028e12  # m³/s², the value docs/errata.rst contrasts with the consistent one


def _body_twist_from_pose_fd(g_fun, t, h):
    """Body twist of t ↦ g(t) from an eighth-order central difference of g: (g⁻¹ġ)^∨."""
    g_dot = central_difference(g_fun, t, h)
    return se3.vee(se3.inverse(g_fun(t)) @ g_dot)


def _relative_errors(V_fd, V, scale_ang, scale_lin):
    ang = np.linalg.norm(V_fd[:, :3] - V[:, :3], axis=1) / scale_ang
    lin = np.linalg.norm(V_fd[:, 3:] - V[:, 3:], axis=1) / scale_lin
    return ang.max(), lin.max()


@pytest.mark.parametrize("name", list(ORBITS))
def test_pose_twist_and_twist_rate_are_consistent_by_finite_differences(name):
    """ġ_d = g_d V_d^ and d/dt V_d = V̇_d along the whole orbit (≥ 200 samples, including
    periapsis and apoapsis), to 1e-9 relative."""
    orbit = ORBITS[name]
    ref = LVLHReference(orbit)
    t = sample_times(orbit)
    assert t.size >= 200
    h = local_step(orbit, t)
    st_ = ref.evaluate_many(t)
    w = np.linalg.norm(st_.V[:, :3], axis=1)  # = ḟ
    v = np.linalg.norm(st_.V[:, 3:], axis=1)
    # ġ_d = g_d V_d^: angular part relative to |ω|, linear part relative to |v|.
    V_fd = _body_twist_from_pose_fd(lambda s: ref.evaluate_many(s).g, t, h)
    err_w, err_v = _relative_errors(V_fd, st_.V, w, v)
    assert err_w < 1e-9
    assert err_v < 1e-9
    # d/dt V_d = V̇_d: relative to the natural size of a rate over one radian of anomaly
    # (|ω|·ḟ and |v|·ḟ; the angular acceleration f̈ itself vanishes at the apsides).
    V_dot_fd = central_difference(lambda s: ref.evaluate_many(s).V, t, h)
    err_wd, err_vd = _relative_errors(V_dot_fd, st_.V_dot, w * w, v * w)
    assert err_wd < 1e-9
    assert err_vd < 1e-9


@pytest.mark.parametrize("name", list(ORBITS))
def test_single_time_evaluation_equals_the_matrix_form_of_eqs_69_to_74(name):
    orbit = ORBITS[name]
    ref = LVLHReference(orbit)
    t = sample_times(orbit, 41)
    many = ref.evaluate_many(t)
    one = [ref.evaluate(float(s)) for s in t]
    for k, o in enumerate(one):
        assert o.g.shape == (4, 4) and o.V.shape == (6,) and o.V_dot.shape == (6,)
        w, v = many.V[k, 2], np.linalg.norm(many.V[k, 3:])
        r = np.linalg.norm(many.g[k, :3, 3])
        # Errors relative to the size of each quantity (a few units in the last place).
        assert np.abs(o.g[:3, :3] - many.g[k, :3, :3]).max() <= 1e-14
        # (4e-15: near a parabola's asymptote 1 + e cos f ≈ 0.2 amplifies the last-place
        # differences of the two paths' anomaly solutions about fourfold.)
        assert np.linalg.norm(o.g[:3, 3] - many.g[k, :3, 3]) <= 4e-15 * r
        assert o.g[3].tolist() == [0.0, 0.0, 0.0, 1.0]
        assert np.linalg.norm(o.V[:3] - many.V[k, :3]) <= 1e-14 * w
        assert np.linalg.norm(o.V[3:] - many.V[k, 3:]) <= 1e-14 * v
        wd = max(np.linalg.norm(many.V_dot[k, :3]), w * w)
        vd = max(np.linalg.norm(many.V_dot[k, 3:]), v * w)
        assert np.linalg.norm(o.V_dot[:3] - many.V_dot[k, :3]) <= 1e-14 * wd
        assert np.linalg.norm(o.V_dot[3:] - many.V_dot[k, 3:]) <= 1e-14 * vd


@pytest.mark.parametrize("name", list(ORBITS))
def test_translation_is_the_kepler_position_and_the_attitude_points_at_the_body(name):
    orbit = ORBITS[name]
    ref = LVLHReference(orbit)
    t = sample_times(orbit)
    g = ref.evaluate_many(t).g
    r, v = orbit.state(t)
    np.testing.assert_array_equal(g[:, :3, 3], r)
    R = g[:, :3, :3]
    np.testing.assert_allclose(
        R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-15
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-15)
    r_hat = r / np.linalg.norm(r, axis=1, keepdims=True)
    h = np.cross(r, v)
    np.testing.assert_allclose(R[:, :, 0], -r_hat, atol=1e-15)  # b̂₁ = −r̂
    np.testing.assert_allclose(
        R[:, :, 2], h / np.linalg.norm(h, axis=1, keepdims=True), atol=1e-15
    )  # b̂₃ along the angular momentum
    # The one-time path: translation within a few units in the last place of it.
    for k in range(0, t.size, 20):
        d = np.linalg.norm(ref.evaluate(float(t[k])).g[:3, 3] - r[k])
        assert d <= 2e-15 * np.linalg.norm(r[k])


@pytest.mark.parametrize("name", list(ORBITS))
def test_reference_acceleration_is_two_body_gravity(name):
    """R_d (v̇_d + ω_d × v_d) = −μ r / r³: a point mass in the central field follows the
    reference with no constraint force; and ω_d = [0, 0, ḟ] (only the third axis turns)."""
    orbit = ORBITS[name]
    ref = LVLHReference(orbit)
    t = sample_times(orbit)
    s = ref.evaluate_many(t)
    R = s.g[:, :3, :3]
    w, v = s.V[:, :3], s.V[:, 3:]
    a_N = (R @ (s.V_dot[:, 3:] + np.cross(w, v))[..., None])[..., 0]
    r = s.g[:, :3, 3]
    gravity = -orbit.mu * r / np.linalg.norm(r, axis=1, keepdims=True) ** 3
    np.testing.assert_allclose(a_N, gravity, rtol=0, atol=1e-14 * np.abs(gravity).max())
    # The velocity in N is the Kepler velocity.
    np.testing.assert_allclose(
        (R @ v[..., None])[..., 0], orbit.velocity(t), rtol=0, atol=1e-12 * np.abs(v).max()
    )
    _f, f_dot, f_ddot = orbit.anomaly_rates(t)
    assert np.all(w[:, :2] == 0.0) and np.all(s.V_dot[:, :2] == 0.0)
    np.testing.assert_allclose(w[:, 2], f_dot, rtol=1e-15)
    np.testing.assert_allclose(s.V_dot[:, 2], f_ddot, rtol=1e-15)


def test_thesis_eq69_as_printed_breaks_the_kinematics():
    """Errata (docs/errata.rst): with the printed R_{d/P}, ġ = g V^ fails (relative error
    2.0 in ω)."""
    orbit = fcei_orbit()
    t = sample_times(orbit)
    h = local_step(orbit, t)
    ref = LVLHReference(orbit)
    _, V_PD, _ = ref.relative_to_perifocal(t)

    def g_printed(s):
        g = ref.relative_to_perifocal(s)[0].copy()
        g[:, :3, :3] = thesis_eq69_R_dP_as_printed(orbit.true_anomaly(s))
        return g

    def g_corrected(s):
        return ref.relative_to_perifocal(s)[0]

    # The printed matrix is the transpose of the corrected one.
    f = orbit.true_anomaly(t)
    np.testing.assert_array_equal(thesis_eq69_R_dP_as_printed(f), np.swapaxes(R_PD(f), 1, 2))
    # Same V_{d/P} (Eq. 71 with each R): ω from the pose must equal [0, 0, ḟ].
    V_printed = V_PD.copy()
    R_pr = thesis_eq69_R_dP_as_printed(f)
    v_P = orbit.perifocal_state(t)[1]
    V_printed[:, 3:] = (np.swapaxes(R_pr, 1, 2) @ v_P[..., None])[..., 0]
    fd_printed = _body_twist_from_pose_fd(g_printed, t, h)
    fd_corrected = _body_twist_from_pose_fd(g_corrected, t, h)
    w = V_PD[:, 2]
    err_printed = np.linalg.norm(fd_printed[:, :3] - V_printed[:, :3], axis=1) / w
    err_corrected = np.linalg.norm(fd_corrected[:, :3] - V_PD[:, :3], axis=1) / w
    np.testing.assert_allclose(err_printed, 2.0, rtol=1e-9)  # the pose turns at −ḟ
    assert err_corrected.max() < 1e-9
    # And body axis 1 of the printed matrix is not −r̂ away from the apsides.
    r_hat = orbit.perifocal_state(t)[0]
    r_hat /= np.linalg.norm(r_hat, axis=1, keepdims=True)
    miss = np.linalg.norm(R_pr[:, :, 0] + r_hat, axis=1)
    assert miss.max() > 1.9
    np.testing.assert_allclose(np.linalg.norm(R_PD(f)[:, :, 0] + r_hat, axis=1), 0, atol=1e-15)


def test_thesis_eq72_translational_part_as_printed_is_not_the_derivative():
    """Errata (docs/errata.rst): Eq. 72's translational part is
    R_{d/P}ᵀ v̇_{d/P} − ω^× R_{d/P}ᵀ v_{d/P}; the printed R_{d/P}ᵀ v̇_{d/P} + R_{d/P}ᵀ ω^× v_{d/P}
    does not match d/dt of V_{d/P}."""
    orbit = fcei_orbit()
    ref = LVLHReference(orbit)
    t = sample_times(orbit)
    h = local_step(orbit, t)
    f, f_dot, _ = orbit.anomaly_rates(t)
    _, V_PD, V_PD_dot = ref.relative_to_perifocal(t)
    _, v_P, a_P = orbit.perifocal_state(t)
    Rt = np.swapaxes(R_PD(f), 1, 2)
    omega = np.stack([0 * f, 0 * f, f_dot], axis=1)
    printed = (Rt @ a_P[..., None])[..., 0] + (Rt @ np.cross(omega, v_P)[..., None])[..., 0]
    fd = central_difference(lambda s: ref.relative_to_perifocal(s)[1], t, h)[:, 3:]
    scale = np.linalg.norm(V_PD[:, 3:], axis=1) * f_dot
    err_corrected = np.linalg.norm(fd - V_PD_dot[:, 3:], axis=1) / scale
    err_printed = np.linalg.norm(fd - printed, axis=1) / scale
    assert err_corrected.max() < 1e-9
    assert err_printed.min() > 1.0


def _moving_frame(t):
    """A non-inertial frame P: g_P(t) = exp(t ξ₁) g₀ exp(t ξ₂), with body twist
    V_P = Ad_{(g₀ exp(tξ₂))⁻¹} ξ₁ + ξ₂ and V̇_P = −ad_{ξ₂} (V_P − ξ₂)."""
    xi1 = np.array([0.3, -0.2, 0.5, 40.0, -10.0, 25.0]) * 1e-3
    xi2 = np.array([-0.1, 0.4, 0.2, 5.0, 30.0, -20.0]) * 1e-3
    g0 = se3.exp(np.array([0.4, -1.1, 0.7, 1e5, -2e5, 3e5]))
    t = np.asarray(t, float)
    inner = g0 @ se3.exp(t[..., None] * xi2)
    g = se3.exp(t[..., None] * xi1) @ inner
    W = (se3.Ad(se3.inverse(inner)) @ xi1[:, None])[..., 0]
    V = W + xi2
    V_dot = -(se3.ad(np.broadcast_to(xi2, W.shape)) @ W[..., None])[..., 0]
    return g, V, V_dot


def test_composition_eqs_70_73_74_hold_for_a_moving_frame():
    """Corrected Eq. 74 (V̇_d = V̇_{d/P} + Ad V̇_P − ad_{V_{d/P}} Ad V_P) matches finite
    differences of V_d when P rotates and translates; the printed signs do not."""
    orbit = ORBITS["retrograde_inclined"]
    ref = LVLHReference(orbit)
    t = sample_times(orbit)
    h = local_step(orbit, t)

    def composed(s):
        g_P, V_P, V_P_dot = _moving_frame(s)
        return compose_motion(g_P, V_P, V_P_dot, *ref.relative_to_perifocal(s))

    # The frame's own twist and rate are right (so the check below tests Eq. 74 only).
    _gP, VP, VP_dot = _moving_frame(t)
    wP, vP = np.linalg.norm(VP[:, :3], axis=1), np.linalg.norm(VP[:, 3:], axis=1)
    VP_fd = _body_twist_from_pose_fd(lambda s: _moving_frame(s)[0], t, h)
    assert max(_relative_errors(VP_fd, VP, wP, vP)) < 1e-9
    VP_dot_fd = central_difference(lambda s: _moving_frame(s)[1], t, h)
    assert max(_relative_errors(VP_dot_fd, VP_dot, wP * wP, vP * wP)) < 1e-9
    _g_d, V_d, V_d_dot = composed(t)
    V_fd = _body_twist_from_pose_fd(lambda s: composed(s)[0], t, h)
    V_dot_fd = central_difference(lambda s: composed(s)[1], t, h)
    scale_w = np.linalg.norm(V_d[:, :3], axis=1)
    scale_v = np.linalg.norm(V_d[:, 3:], axis=1)
    err = _relative_errors(V_fd, V_d, scale_w, scale_v)
    assert max(err) < 1e-9
    rate = np.maximum(scale_w, orbit.anomaly_rates(t)[1])
    err_dot = _relative_errors(V_dot_fd, V_d_dot, scale_w * rate, scale_v * rate)
    assert max(err_dot) < 1e-9
    # Eq. 74 as printed: V̇_{d/P} − Ad V̇_P + ad_{V_{d/P}} Ad V_P.
    _, V_PD, V_PD_dot = ref.relative_to_perifocal(t)
    Ad_inv = se3.Ad(se3.inverse(ref.relative_to_perifocal(t)[0]))
    W = (Ad_inv @ VP[..., None])[..., 0]
    printed = (
        V_PD_dot - (Ad_inv @ VP_dot[..., None])[..., 0] + (se3.ad(V_PD) @ W[..., None])[..., 0]
    )
    err_printed = _relative_errors(V_dot_fd, printed, scale_w * rate, scale_v * rate)
    assert min(err_printed) > 1e-3


def test_compose_motion_with_an_inertial_frame_is_the_relative_motion():
    orbit = fcei_orbit()
    ref = LVLHReference(orbit)
    t = np.linspace(0, 5000.0, 7)
    g_PD, V_PD, V_PD_dot = ref.relative_to_perifocal(t)
    g_P = np.eye(4)
    g_P[:3, :3] = orbit.R_NP
    g, V, V_dot = compose_motion(g_P, np.zeros(6), np.zeros(6), g_PD, V_PD, V_PD_dot)
    np.testing.assert_allclose(g, g_P @ g_PD, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(V, V_PD)
    np.testing.assert_array_equal(V_dot, V_PD_dot)


@settings(max_examples=100, deadline=None)
@given(f=st.floats(-50.0, 50.0))
def test_corrected_eq69_is_a_third_axis_rotation_by_f_plus_pi(f):
    np.testing.assert_allclose(R_PD(f), so3.exp([0.0, 0.0, f + math.pi]), atol=1e-13)


# ------------------------------------------------------------------------ Section 4.3


def test_section43_initial_condition_reproduces_the_printed_numbers():
    """McCann (2020), Section 4.3: V = [0, 0, 4.23818e-4, 0, −1.35622e3, 0],
    g = [[−1, 0, 0, 3.20e6], [0, −0.81915, −0.57358, 0], [0, −0.57358, 0.81915, 0]]."""
    g0, V0 = section43_initial_state(MU_MOON_THESIS_CONSISTENT)
    printed_R = np.array([[-1, 0, 0], [0, -0.81915, -0.57358], [0, -0.57358, 0.81915]])
    np.testing.assert_allclose(g0[:3, :3], printed_R, rtol=0, atol=5e-6)  # 5 printed digits
    np.testing.assert_allclose(g0[:3, 3], [3.20e6, 0, 0], rtol=0, atol=1e-9)
    assert V0[[0, 1, 3, 5]].tolist() == [0.0, 0.0, 0.0, 0.0]
    assert abs(V0[2] - 4.23818e-4) <= 0.5e-9  # half a unit in the last printed digit
    assert abs(V0[4] - (-1.35622e3)) <= 0.005
    # And it is the reference at t = 0 (periapsis) of the FCEI orbit.
    ref0 = LVLHReference(fcei_orbit()).evaluate(0.0)
    np.testing.assert_array_equal(g0, ref0.g)
    np.testing.assert_array_equal(V0, ref0.V)


def test_section43_numbers_are_not_reproduced_with_the_usual_lunar_mu():
    """Errata (docs/errata.rst): μ = 4.9028e12 gives ḟ = 4.2373e-4 and v₂ = −1355.93, not
    the printed values."""
    _, V0 = section43_initial_state(MU_MOON_USUAL)
    assert round(V0[2], 8) == 4.2373e-4
    assert round(V0[4], 2) == -1355.93
    assert abs(V0[2] - 4.23818e-4) > 50 * 0.5e-9
    assert abs(V0[4] - (-1.35622e3)) > 50 * 0.005


def test_section43_orbit_parameters():
    orbit = fcei_orbit()
    assert orbit.mu == MU_MOON_THESIS_CONSISTENT == 4.9048695e12
    assert orbit.a == pytest.approx(4.0e6, rel=1e-15)
    assert (orbit.e, orbit.raan, orbit.argp) == (0.2, 0.0, 0.0)
    assert orbit.i == pytest.approx(math.radians(35.0), rel=1e-15)


# ------------------------------------------------------------------------ interface


def test_reference_implements_the_tracking_interface_and_validates_input():
    ref = LVLHReference(fcei_orbit())
    assert isinstance(ref, ReferenceTrajectory)
    s = ref.evaluate(np.float64(12.5))
    assert s.g.dtype == s.V.dtype == s.V_dot.dtype == np.float64
    with pytest.raises(NonFiniteError, match="t must be finite"):
        ref.evaluate(float("nan"))
    with pytest.raises(DefinitionError, match="KeplerOrbit"):
        LVLHReference("fcei")  # type: ignore[arg-type]
    assert ref.orbit is not None and "LVLHReference" in repr(ref)
