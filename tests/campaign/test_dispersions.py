"""Dispersions: domains checked at construction, the SO(3) cone's distribution, physical
inertias, and run values that depend on (seed, k) alone."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gmuk.campaign import (
    AttitudeCone,
    Campaign,
    Choice,
    GaussianVector,
    IntegerRange,
    Normal,
    SecondMomentScale,
    Uniform,
    UniformBall,
    scaled_inertia,
)
from gmuk.campaign.dispersions import _theta_minus_sin, dispersion_from_dict
from gmuk.errors import DefinitionError, GmukError
from gmuk.lie import so3

PROPERTY = settings(max_examples=60, deadline=None)


@PROPERTY
@given(st.floats(0.0, math.pi), st.integers(0, 2**32 - 1))
def test_attitude_cone_never_exceeds_its_angle(theta_max, seed):
    rng = np.random.default_rng(seed)
    cone = AttitudeCone(theta_max)
    for _ in range(5):
        v = np.array(cone.sample(rng))
        assert np.linalg.norm(v) <= theta_max * (1 + 4e-16) + 1e-300
        # every body axis stays within θ_max of its nominal direction
        R = so3.exp(v)
        assert np.all(np.diag(R) >= math.cos(theta_max) - 1e-12)


def test_attitude_cone_angle_follows_the_haar_density_within_the_cone():
    """Kolmogorov–Smirnov against F(θ) = (θ − sin θ)/(θmax − sin θmax); a uniform angle
    (the common mistake) fails the same test."""
    rng = np.random.default_rng(12345)
    top = math.radians(60.0)
    cone = AttitudeCone(top)
    angles = np.sort([np.linalg.norm(cone.sample(rng)) for _ in range(4000)])
    F = (angles - np.sin(angles)) / (top - math.sin(top))
    ecdf = np.arange(1, angles.size + 1) / angles.size
    ks = np.abs(F - ecdf).max()
    assert ks < 1.63 / math.sqrt(angles.size)  # 1 % level
    uniform = np.sort(rng.uniform(0, top, 4000))
    F_u = (uniform - np.sin(uniform)) / (top - math.sin(top))
    assert np.abs(F_u - ecdf).max() > 1.63 / math.sqrt(angles.size)


def test_attitude_cone_of_pi_is_uniform_on_so3():
    """For the Haar measure, E[R] = 0 and E[tr R] = 0."""
    rng = np.random.default_rng(7)
    cone = AttitudeCone(math.pi)
    Rs = np.array([so3.exp(cone.sample(rng)) for _ in range(6000)])
    assert np.abs(Rs.mean(axis=0)).max() < 0.04
    axes = np.array([v / np.linalg.norm(v) for v in (cone.sample(rng) for _ in range(3000))])
    assert np.abs(axes.mean(axis=0)).max() < 0.05


def test_theta_minus_sin_series_matches_the_direct_form_where_both_are_accurate():
    for t in (0.05, 0.0999, 0.1, 0.2):
        assert _theta_minus_sin(t) == pytest.approx(t - math.sin(t), rel=1e-12)
    assert _theta_minus_sin(1e-6) == pytest.approx(1e-18 / 6, rel=1e-12)


@PROPERTY
@given(st.floats(0.0, 1e4), st.integers(0, 2**32 - 1))
def test_uniform_ball_stays_in_its_ball(radius, seed):
    rng = np.random.default_rng(seed)
    ball = UniformBall(radius)
    assert np.linalg.norm(ball.sample(rng)) <= radius * (1 + 1e-15)


@st.composite
def physical_inertias(draw):
    """Principal moments from non-negative second moments (at most one zero), random axes."""
    A = np.array([draw(st.floats(1e-3, 1e4)) for _ in range(3)])
    R = so3.exp(np.array([draw(st.floats(-3.0, 3.0)) for _ in range(3)]))
    J = A.sum() - A
    return R @ np.diag(J) @ R.T


@PROPERTY
@given(physical_inertias(), st.floats(0.05, 1.0), st.floats(1.0, 20.0), st.integers(0, 2**31))
def test_second_moment_scaling_keeps_the_inertia_physical(J, low, high, seed):
    rng = np.random.default_rng(seed)
    factors = SecondMomentScale(low, high).sample(rng)
    mass_scale = float(rng.uniform(0.1, 10.0))
    Jd = scaled_inertia(J, factors, mass_scale)
    moments = np.linalg.eigvalsh(Jd)
    assert moments.min() > 0
    scale = moments.max()
    for i in range(3):
        others = moments.sum() - moments[i]
        assert others >= moments[i] - 1e-9 * scale  # triangle inequality
    # unit factors and mass scale give J back
    assert np.allclose(scaled_inertia(J, (1.0, 1.0, 1.0)), J, rtol=1e-12, atol=1e-9 * scale)


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (lambda: AttitudeCone(math.radians(181.0)), "at most 180°"),
        (lambda: AttitudeCone(-0.1), "[0, π]"),
        (lambda: AttitudeCone(float("nan")), "finite"),
        (lambda: Uniform(2.0, 1.0), "low must be ≤ high"),
        (lambda: Normal(0.0, -1.0), "std must be ≥ 0"),
        (lambda: UniformBall(-1.0), "radius must be ≥ 0"),
        (lambda: GaussianVector((1.0, 2.0)), "one value or three"),
        (lambda: SecondMomentScale(0.0, 1.0), "0 < low"),
        (lambda: IntegerRange(3, 2), "low must be ≤ high"),
        (lambda: IntegerRange(1.5, 2), "integer"),
        (lambda: Choice(()), "must not be empty"),
        (lambda: Uniform(True, 2.0), "real number"),
    ],
)
def test_dispersions_refuse_values_outside_their_domain(make, words):
    with pytest.raises(DefinitionError, match=None) as info:
        make()
    assert words in str(info.value)
    assert isinstance(info.value, GmukError)


def test_campaign_refuses_a_dispersion_that_can_leave_its_parameter_domain():
    with pytest.raises(DefinitionError, match="must stay > 0"):
        Campaign("fcei", runs=2, dispersions={"mass_scale": Uniform(-0.5, 1.2)})
    with pytest.raises(DefinitionError, match="must stay > 0"):
        Campaign("fcei", runs=2, dispersions={"mass_scale": Normal(1.0, 0.1)})
    with pytest.raises(DefinitionError, match="takes rotation values"):
        Campaign("fcei", runs=2, dispersions={"attitude_error": UniformBall(0.1)})
    with pytest.raises(DefinitionError, match="must be > 0"):
        Campaign("fcei", runs=2, fixed={"mass_scale": -1.0})
    with pytest.raises(DefinitionError, match="in both fixed and dispersions"):
        Campaign("fcei", runs=2, fixed={"orbits": 0.1}, dispersions={"orbits": Uniform(0.1, 1)})
    with pytest.raises(DefinitionError, match="no parameter 'nope'"):
        Campaign("fcei", runs=2, fixed={"nope": 1.0})
    with pytest.raises(DefinitionError, match="runs must be an integer ≥ 1"):
        Campaign("fcei", runs=0)
    with pytest.raises(DefinitionError, match="seed must be an integer ≥ 0"):
        Campaign("fcei", runs=2, seed=-1)
    with pytest.raises(DefinitionError, match="≤ 150"):
        Campaign("apollo16", grid={"degree": [2, 151]})


def test_unknown_or_unsupported_scenarios_list_the_supported_ones():
    with pytest.raises(
        DefinitionError, match=r"unknown scenario 'nosuch'.*fcei, ucei, fccl, apollo16"
    ):
        Campaign("nosuch", runs=2)
    with pytest.raises(DefinitionError, match=r"'smd-gt' has no campaign support.*fcei"):
        Campaign("smd-gt", runs=2)


@PROPERTY
@given(st.integers(0, 2**63), st.lists(st.integers(0, 49), min_size=1, max_size=8))
def test_run_values_depend_on_seed_and_run_index_only(seed, order):
    disp = {
        "attitude_error": AttitudeCone(0.3),
        "position_error_m": UniformBall(10.0),
        "baumgarte_omega_n": Uniform(0.01, 0.1),
        "inertia_scale": SecondMomentScale(0.8, 1.2),
    }
    a = Campaign("fcei", runs=50, seed=seed, dispersions=disp)
    b = Campaign("fcei", runs=50, seed=seed, dispersions=disp)
    reference = {k: a.parameters(k) for k in sorted(set(order))}
    for k in order:  # any order, any repetition, another object: the same values
        assert b.parameters(k) == reference[k]
    # another dispersion added: the values drawn for the others do not change
    c = Campaign("fcei", runs=50, seed=seed, dispersions={**disp, "mass_scale": Uniform(0.9, 1.1)})
    for k in set(order):
        values = c.parameters(k)
        assert all(values[n] == reference[k][n] for n in disp)


def test_different_runs_and_seeds_draw_different_values():
    c = Campaign("fcei", runs=3, seed=1)
    d = Campaign("fcei", runs=3, seed=2)
    assert c.parameters(0)["attitude_error"] != c.parameters(1)["attitude_error"]
    assert c.parameters(0)["attitude_error"] != d.parameters(0)["attitude_error"]


def test_grid_runs_take_points_in_product_order_last_fastest():
    c = Campaign("apollo16", grid={"degree": [2, 10], "samples": [11, 21, 31]}, dispersions={})
    assert c.n_runs == 6
    points = [(c.parameters(k)["degree"], c.parameters(k)["samples"]) for k in range(6)]
    assert points == [(2, 11), (2, 21), (2, 31), (10, 11), (10, 21), (10, 31)]
    assert Campaign("apollo16").n_runs == 149  # the default sweep: degrees 2…150


@pytest.mark.parametrize(
    "d",
    [
        AttitudeCone(0.5),
        Uniform(1.0, 2.0),
        Normal(0.0, 1.0),
        Choice((2, 10, 50)),
        Choice((0.5, 1.5)),
        IntegerRange(2, 150),
        GaussianVector((1.0, 2.0, 3.0)),
        UniformBall(5.0),
        SecondMomentScale(0.9, 1.1),
    ],
)
def test_dispersions_round_trip_through_their_dict(d):
    assert dispersion_from_dict(d.to_dict()) == d
    rng1, rng2 = np.random.default_rng(3), np.random.default_rng(3)
    assert dispersion_from_dict(d.to_dict()).sample(rng1) == d.sample(rng2)
