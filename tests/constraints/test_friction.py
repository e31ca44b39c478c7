"""Coulomb friction at point–plane contacts (PointPlaneContact(friction=μ)): a box on a tilted
plane sticks below the friction angle and slides with g (sin θ − μ cos θ) above it, a box
sliding on a flat plane stops where and when the closed form says and stays, friction=0 is the
frictionless contact bit for bit, and bad coefficients are refused."""

from __future__ import annotations

import numpy as np
import pytest

import gmuk
from gmuk.constraints.unilateral import SLIP_SPEED, PointPlaneContact
from gmuk.engine.contact import contact_kkt
from gmuk.errors import DefinitionError
from gmuk.lie import so3

M, A, B, C, G0 = 2.0, 0.2, 0.15, 0.1, 9.81


def _box() -> gmuk.RigidBody:
    return gmuk.RigidBody("box", M, M / 12 * np.diag([B * B + C * C, A * A + C * C, A * A + B * B]))


def _bottom() -> list[tuple[float, float, float]]:
    return [(sx * A / 2, sy * B / 2, -C / 2) for sx in (-1, 1) for sy in (-1, 1)]


def _on_slope(theta: float, mu: float) -> tuple[gmuk.System, PointPlaneContact, gmuk.State]:
    """The box resting on its bottom face on a plane tilted by θ about y, at rest."""
    box = _box()
    n = np.array([np.sin(theta), 0.0, np.cos(theta)])
    floor = PointPlaneContact(box, _bottom(), normal=n, friction=mu, name="floor")
    system = gmuk.System([box], [floor], [gmuk.UniformGravity((0.0, 0.0, -G0))])
    g = np.eye(4)
    g[:3, :3] = so3.exp(np.array([0.0, theta, 0.0]))
    g[:3, 3] = n * C / 2
    return system, floor, system.state(g={"box": g}, V={"box": np.zeros(6)})


def _cone(floor: PointPlaneContact, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(f_n (…, k), ‖f_t‖ (…, k)) from a contact's multipliers."""
    k = len(floor.points)
    fn = lam[..., :k]
    ft = lam[..., k : 3 * k].reshape(*lam.shape[:-1], k, 2)
    return fn, np.linalg.norm(ft, axis=-1)


def test_a_box_on_a_slope_below_the_friction_angle_is_held_in_the_cone():
    theta, mu = 0.3, 0.5  # tan θ = 0.31 < μ
    system, floor, state = _on_slope(theta, mu)
    acc = system.accelerations(state)
    np.testing.assert_allclose(acc.total, 0.0, atol=1e-10)
    fn, ft = _cone(floor, acc.multipliers)
    assert (fn >= 0.0).all() and (ft <= mu * fn * (1 + 1e-9)).all()
    # the forces balance the weight: normal m g cos θ, friction m g sin θ up the slope
    assert fn.sum() == pytest.approx(M * G0 * np.cos(theta), rel=1e-12)
    ft_N = acc.multipliers[4:].reshape(4, 2) @ floor.tangents
    np.testing.assert_allclose(ft_N.sum(axis=0), M * G0 * np.sin(theta) * np.array(
        [-np.cos(theta), 0.0, np.sin(theta)]), atol=1e-12)  # fmt: skip


@pytest.mark.slow
def test_a_box_on_a_slope_below_the_friction_angle_stays_at_rest_for_a_second():
    theta, mu = 0.3, 0.5
    system, floor, state = _on_slope(theta, mu)
    traj = system.simulate(
        state, (0.0, 1.0), t_eval=np.linspace(0.0, 1.0, 11), rtol=1e-10, atol=1e-10
    )
    assert traj.success, traj.message
    end = traj.state(-1)
    assert np.abs(end.V).max() <= 1e-9
    fn, ft = _cone(floor, traj.multipliers)
    assert (fn >= 0.0).all() and (ft <= mu * fn * (1 + 1e-9)).all()


def test_a_box_on_a_slope_above_the_friction_angle_slides_with_the_closed_form_acceleration():
    theta, mu = 0.3, 0.2  # tan θ = 0.31 > μ
    system, floor, state = _on_slope(theta, mu)
    T = 1.0
    traj = system.simulate(state, (0.0, T), t_eval=[0.0, T], rtol=1e-10, atol=1e-10)
    assert traj.success, traj.message
    expected = G0 * (np.sin(theta) - mu * np.cos(theta))
    down = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    travelled = (traj.state(-1).pose("box")[:3, 3] - state.pose("box")[:3, 3]) @ down
    assert travelled == pytest.approx(0.5 * expected * T**2, rel=1e-9)
    assert traj.state(-1).V[0, 3:] @ so3.exp(np.array([0.0, theta, 0.0])).T @ down == (
        pytest.approx(expected * T, rel=1e-9)
    )
    fn, ft = _cone(floor, traj.multipliers[-1])
    np.testing.assert_allclose(ft, mu * fn, rtol=1e-9)  # kinetic: on the cone
    kkt = contact_kkt(system, traj)["floor"].summary()
    assert kkt["penetration"] <= 1e-9 and kkt["negative_multiplier"] == 0.0
    assert kkt["complementarity"] <= 1e-9


def test_a_box_sliding_on_a_flat_plane_stops_at_the_closed_form_time_and_place_and_stays():
    """v(t) = v₀ − μ g t until t* = v₀/(μ g), after x* = v₀²/(2 μ g); then at rest. The
    kinetic phase is exact; the point sticks once its speed is below SLIP_SPEED, and the
    sticking row's velocity gain γ (100 1/s) stops the rest, SLIP_SPEED/γ = 1e-8 m further."""
    mu, v0 = 0.4, 1.0
    box = _box()
    floor = PointPlaneContact(box, _bottom(), friction=mu, name="floor")
    system = gmuk.System([box], [floor], [gmuk.UniformGravity((0.0, 0.0, -G0))])
    g = np.eye(4)
    g[2, 3] = C / 2
    state = system.state(g={"box": g}, V={"box": [0.0, 0.0, 0.0, v0, 0.0, 0.0]})
    t_stop, x_stop = v0 / (mu * G0), v0**2 / (2 * mu * G0)
    times = [0.0, t_stop - 0.01, t_stop + 0.01, 0.5]
    traj = system.simulate(state, (0.0, 0.5), t_eval=times, rtol=1e-10, atol=1e-10)
    assert traj.success, traj.message
    before = traj.state(1)
    assert before.V[0, 3] == pytest.approx(v0 - mu * G0 * times[1], rel=1e-9)
    x_before = v0 * times[1] - 0.5 * mu * G0 * times[1] ** 2
    assert before.pose("box")[0, 3] == pytest.approx(x_before, rel=1e-9)
    after = traj.state(2)  # stuck: the last μm/s decays as exp(−γ t)
    assert np.abs(after.V).max() <= SLIP_SPEED * np.exp(-100.0 * 0.01) * 1.01
    end = traj.state(3)
    assert np.abs(end.V).max() <= 1e-9
    assert -2e-9 <= after.pose("box")[0, 3] - x_stop <= SLIP_SPEED / 100.0 + 2e-9
    assert end.pose("box")[0, 3] - x_stop == pytest.approx(SLIP_SPEED / 100.0, abs=2e-9)
    fn, ft = _cone(floor, traj.multipliers)
    assert (ft <= mu * fn * (1 + 1e-9)).all()
    kkt = contact_kkt(system, traj)["floor"].summary()
    assert kkt["penetration"] <= 1e-9 and kkt["complementarity"] <= 1e-9


def test_friction_zero_is_the_frictionless_contact_bit_for_bit():
    box = _box()
    corners = [(sx * A / 2, sy * B / 2, sz * C / 2) for sx in (-1, 1) for sy in (-1, 1)
               for sz in (-1, 1)]  # fmt: skip
    plain = PointPlaneContact(box, corners, restitution=0.5)
    zero = PointPlaneContact(box, corners, restitution=0.5, friction=0.0)
    assert zero.friction == 0.0 and plain.friction == 0.0
    rng = np.random.default_rng(3)
    sys_plain = gmuk.System([box], [plain], [gmuk.UniformGravity((0.0, 0.0, -G0))])
    sys_zero = gmuk.System([box], [zero], [gmuk.UniformGravity((0.0, 0.0, -G0))])
    for _ in range(20):
        g = np.eye(4)
        g[:3, :3] = so3.exp(rng.normal(size=3))
        g[:3, 3] = rng.normal(size=3)
        V = rng.normal(size=6)
        s1 = sys_plain.state(g={"box": g}, V={"box": V})
        s2 = sys_zero.state(g={"box": g}, V={"box": V})
        r1, r2 = plain.rows(s1), zero.rows(s2)
        assert np.array_equal(r1[0], r2[0]) and np.array_equal(r1[1], r2[1])
        assert r1[0].shape == (8, 6)
    # a box resting on a face: the same accelerations and multipliers, bit for bit
    g = np.eye(4)
    g[2, 3] = C / 2
    a1 = sys_plain.accelerations(sys_plain.state(g={"box": g}, V={"box": np.zeros(6)}))
    a2 = sys_zero.accelerations(sys_zero.state(g={"box": g}, V={"box": np.zeros(6)}))
    assert np.array_equal(a1.total, a2.total)
    assert np.array_equal(a1.multipliers, a2.multipliers)


def test_friction_adds_two_tangential_rows_per_point_along_the_planes_tangents():
    box = _box()
    n = np.array([0.3, -0.2, 0.9])
    floor = PointPlaneContact(box, _bottom(), normal=n, friction=0.7)
    frame = np.vstack([floor.tangents, floor.normal])
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(frame) == pytest.approx(1.0)
    system = gmuk.System([box], [floor])
    rng = np.random.default_rng(5)
    g = np.eye(4)
    g[:3, :3] = so3.exp(rng.normal(size=3))
    V = rng.normal(size=6)
    state = system.state(g={"box": g}, V={"box": V})
    Arows, _ = floor.rows(state)
    assert Arows.shape == (12, 6)
    # the tangential rows are the Jacobian of the points' tangential velocities
    u = floor.tangential_velocities(state)
    np.testing.assert_allclose(Arows[4:] @ V, u.reshape(-1), atol=1e-13)


def test_bad_friction_coefficients_are_refused():
    box = _box()
    for bad in (-0.1, float("nan"), float("inf"), "0.5", True):
        with pytest.raises(DefinitionError, match="friction"):
            PointPlaneContact(box, [0.0, 0.0, 0.0], friction=bad)
