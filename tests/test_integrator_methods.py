"""Integrator methods as objects: DOP853's tableau, order conditions, the registry, methods
defined outside the package, and the error-weight rule."""

from __future__ import annotations

import functools

import numpy as np
import pytest

import gmuk
from gmuk import testing
from gmuk.engine import integrate
from gmuk.engine.integrators import (
    DOP853,
    DOPRI5,
    METHODS,
    RK4,
    RungeKuttaMethod,
    get_method,
    method_names,
)
from gmuk.engine.integrators import _dop853_tableau as tab
from gmuk.errors import DefinitionError
from gmuk.lie import se3

J = np.diag([1.0, 2.0, 3.0])


# -- methods defined outside the package: registered by subclassing ---------------------


class Kutta38(RungeKuttaMethod):
    """Kutta's 3/8 rule: order 4, fixed step."""

    name = "Kutta38-test"
    A = ((0, 0, 0, 0), (1 / 3, 0, 0, 0), (-1 / 3, 1, 0, 0), (1, -1, 1, 0))
    b = (1 / 8, 3 / 8, 3 / 8, 1 / 8)
    c = (0, 1 / 3, 2 / 3, 1)
    order = 4


class BogackiShampine(RungeKuttaMethod):
    """Bogacki–Shampine 3(2) (Appl. Math. Lett. 2 (1989)): order 3, adaptive, FSAL."""

    name = "BS32-test"
    A = ((0, 0, 0), (1 / 2, 0, 0), (0, 3 / 4, 0))
    b = (2 / 9, 1 / 3, 4 / 9)
    c = (0, 1 / 2, 3 / 4)
    order = 3
    fsal = True
    E = np.array([2 / 9, 1 / 3, 4 / 9, 0]) - np.array([7 / 24, 1 / 4, 1 / 3, 1 / 8])


def free_body(V0=(0.9, 2.0, 0.4, 1.0, -0.5, 0.3)):
    body = gmuk.RigidBody("a", 2.0, J)
    system = gmuk.System([body])
    return system, system.state(g={"a": np.eye(4)}, V={"a": np.array(V0)})


def pose_error(g, ref):
    return np.abs(se3.log(se3.inverse(ref) @ g)).max()


# -- DOP853's coefficients ---------------------------------------------------------------


def test_dop853_tableau_equals_scipys_bit_for_bit():
    from scipy.integrate._ivp import dop853_coefficients as sp

    for name in ("A", "B", "C", "E3", "E5", "D"):
        ours, theirs = getattr(tab, name), getattr(sp, name)
        assert ours.shape == theirs.shape, name
        assert np.array_equal(ours, theirs), name
    assert (tab.N_STAGES, tab.N_STAGES_EXTENDED, tab.INTERPOLATOR_POWER) == (
        sp.N_STAGES,
        sp.N_STAGES_EXTENDED,
        sp.INTERPOLATOR_POWER,
    )


def test_gmuk_does_not_import_scipys_private_integrator_modules():
    import pathlib

    root = pathlib.Path(gmuk.__file__).parent
    offenders = [
        str(p.relative_to(root))
        for p in root.rglob("*.py")
        if "scipy.integrate._ivp" in p.read_text(encoding="utf-8")
    ]
    assert offenders == []


# -- order conditions over rooted trees --------------------------------------------------


@functools.cache
def trees(n):
    """Rooted trees with n nodes, each a sorted tuple of its subtrees (a leaf is ())."""
    if n == 1:
        return ((),)
    return tuple(sorted({tuple(sorted(f)) for f in forests(n - 1)}))


def forests(n):
    """Sequences of rooted trees with n nodes in all."""
    if n == 0:
        yield ()
        return
    for k in range(1, n + 1):
        for t in trees(k):
            for rest in forests(n - k):
                yield (t, *rest)


def order_residuals(A, b, n):
    """|b·Φ(τ) − 1/γ(τ)| for every tree τ with n nodes (Butcher's order conditions)."""

    def weights(t):  # Φ(τ) per stage, and γ(τ)
        phi, gamma = np.ones(len(b)), 1
        for child in t:
            phi_c, gamma_c = weights(child)
            phi, gamma = phi * (A @ phi_c), gamma * gamma_c
        return phi, gamma * (1 + sum(size(c) for c in t))

    def size(t):
        return 1 + sum(size(c) for c in t)

    out = []
    for t in trees(n):
        phi, gamma = weights(t)
        out.append(abs(b @ phi - 1.0 / gamma))
    return np.array(out)


def test_tree_enumeration_counts():
    assert [len(trees(n)) for n in range(1, 10)] == [1, 1, 2, 4, 9, 20, 48, 115, 286]


def fsal_tableau(m):
    """A and b over the stages and f(t + h, y₁) (whose row is b)."""
    s = m.n_stages
    A = np.zeros((s + 1, s + 1))
    A[:s, :s] = m.A
    A[s, :s] = m.b
    return A, np.r_[m.b, 0.0]


@pytest.mark.parametrize(
    ("method", "order", "embedded"),
    [(DOP853, 8, None), (DOPRI5, 5, 4), (RK4, 4, None), (Kutta38, 4, None)],
)
def test_order_conditions(method, order, embedded):
    m = method()
    assert np.allclose(m.A.sum(axis=1), m.c, rtol=0, atol=1e-15)  # row sums = nodes
    assert np.sum(m.b) == pytest.approx(1.0, abs=1e-15)
    assert m.b @ m.c == pytest.approx(0.5, abs=1e-15)
    for n in range(1, order + 1):
        assert order_residuals(m.A, m.b, n).max() < 2e-14, n
    # the order is exact: some condition of the next order fails
    assert order_residuals(m.A, m.b, order + 1).max() > 1e-6
    if embedded is not None:
        A, b = fsal_tableau(m)
        b_hat = b - m.E
        for n in range(1, embedded + 1):
            assert order_residuals(A, b_hat, n).max() < 2e-14, n
        assert order_residuals(A, b_hat, embedded + 1).max() > 1e-6


def test_dop853_embedded_formulas_have_orders_5_and_3_and_extra_stages_are_consistent():
    A, b = fsal_tableau(DOP853())
    for E, p in ((tab.E5, 5), (tab.E3, 3)):
        b_hat = b - E
        for n in range(1, p + 1):
            assert order_residuals(A, b_hat, n).max() < 2e-14, (p, n)
        assert order_residuals(A, b_hat, p + 1).max() > 1e-6
    # every stage of the extended tableau (incl. the 3 dense-output stages): Σⱼ aᵢⱼ = cᵢ
    np.testing.assert_allclose(tab.A.sum(axis=1), tab.C, rtol=0, atol=2e-15)
    assert np.array_equal(tab.A[tab.N_STAGES, : tab.N_STAGES], tab.B)


# -- the registry and simulate(method=...) -----------------------------------------------


def test_builtin_methods_are_registered_and_method_names_keep_working():
    assert method_names()[:3] == ("DOP853", "DOPRI5", "RK4")
    assert "DOP853" in METHODS and "DOPRI5" in METHODS and "RK4" in METHODS
    assert "dop853" in METHODS and "Euler" not in METHODS
    assert tuple(METHODS) == method_names() and len(METHODS) == len(method_names())
    # the view is live: methods defined in this module appear in it
    assert "Kutta38-test" in METHODS and "BS32-test" in METHODS
    assert integrate.METHODS is METHODS
    assert integrate.DOP853 is DOP853 and integrate.RungeKuttaMethod is RungeKuttaMethod
    assert isinstance(get_method("rk4"), RK4)
    assert isinstance(get_method(DOPRI5), DOPRI5)
    m = DOP853()
    assert get_method(m) is m


def test_method_attributes_say_how_each_method_behaves():
    dop, dp5, rk4 = DOP853(), DOPRI5(), RK4()
    assert (dop.adaptive, dop.dense_output, dop.steps_onto_outputs, dop.fsal) == (
        True,
        True,
        False,
        True,
    )
    assert (dp5.adaptive, dp5.dense_output, dp5.steps_onto_outputs) == (True, False, True)
    assert (rk4.adaptive, rk4.dense_output, rk4.steps_onto_outputs) == (False, False, True)
    assert (dop.n_stages, dp5.n_stages, rk4.n_stages) == (12, 6, 4)
    with pytest.raises(NotImplementedError, match="continuous extension"):
        rk4.interpolant(lambda t, y: y, 0.0, np.zeros(1), 0.1, np.zeros((4, 1)), np.zeros(1))
    with pytest.raises(DefinitionError, match="fixed step"):
        rk4.error_norm(np.zeros((4, 1)), 0.1, np.ones(1))


def test_unknown_method_name_lists_the_registered_ones():
    system, state = free_body()
    with pytest.raises(DefinitionError, match="Euler") as info:
        system.simulate(state, (0.0, 1.0), method="Euler")
    for name in ("DOP853", "DOPRI5", "RK4", "Kutta38-test"):
        assert name in str(info.value)
    with pytest.raises(DefinitionError, match="method"):
        system.simulate(state, (0.0, 1.0), method=3)  # type: ignore[arg-type]


def test_name_class_and_instance_give_the_same_run():
    system, state = free_body()
    t = np.linspace(0.0, 3.0, 13)
    runs = [
        system.simulate(state, (0.0, 3.0), t_eval=t, method=m)
        for m in ("DOP853", "dop853", DOP853, DOP853())
    ]
    for r in runs[1:]:
        assert np.array_equal(r.g_NB, runs[0].g_NB) and np.array_equal(r.V_B, runs[0].V_B)
        assert r.stats == runs[0].stats
    assert runs[0].stats["method"] == "DOP853"


def test_tableaux_are_checked_and_names_are_unique():
    with pytest.raises(DefinitionError, match="explicit"):

        class Implicit(RungeKuttaMethod):  # implicit midpoint
            name = "implicit-midpoint-test"
            A = ((0.5,),)
            b = (1.0,)
            c = (0.5,)
            order = 2

    with pytest.raises(DefinitionError, match="shape"):

        class Short(RungeKuttaMethod):
            name = "short-test"
            A = ((0, 0), (1, 0))
            b = (0.5, 0.5)
            c = (0, 1, 2)
            order = 2

    with pytest.raises(DefinitionError, match="E must have shape"):

        class BadE(RungeKuttaMethod):
            name = "bad-e-test"
            A = ((0, 0), (1, 0))
            b = (0.5, 0.5)
            c = (0, 1)
            order = 2
            E = (0.5, -0.5, 0.0)  # 3 entries without fsal

    with pytest.raises(DefinitionError, match="no complete tableau"):

        class NoTableau(RungeKuttaMethod):
            name = "no-tableau-test"

    with pytest.raises(DefinitionError, match="already registered"):

        class Impostor(RungeKuttaMethod):
            name = "dop853"
            A, b, c, order = ((0,),), (1.0,), (0,), 1

    assert get_method("DOP853").__class__ is DOP853
    with pytest.raises(DefinitionError, match="abstract"):
        RungeKuttaMethod()
    for name in ("implicit-midpoint-test", "short-test", "bad-e-test", "no-tableau-test"):
        assert name not in METHODS


def test_an_unnamed_subclass_is_usable_as_a_class_but_not_registered():
    class Euler(RungeKuttaMethod):
        A, b, c, order = ((0,),), (1.0,), (0,), 1

    assert "Euler" not in METHODS
    system, state = free_body()
    traj = system.simulate(state, (0.0, 0.1), method=Euler, step=0.01)
    assert traj.stats["method"].endswith("Euler") and traj.stats["n_steps"] == 10


def _end_error(method, h, system, state, ref, T=4.0):
    kw = (
        {"step": h}
        if not get_method(method).adaptive
        else {"first_step": h, "max_step": h, "rtol": 1.0, "atol": 1.0}
    )
    traj = system.simulate(state, (0.0, T), method=method, t_eval=[T], **kw)
    assert traj.stats["n_rejected"] == 0 and traj.stats["method"] == method
    return pose_error(traj.g_NB[-1, 0], ref)


@pytest.mark.parametrize(
    ("method", "order", "steps"), [("Kutta38-test", 4, (0.2, 0.1)), ("BS32-test", 3, (0.1, 0.05))]
)
def test_a_method_defined_outside_the_package_runs_by_name_to_its_order(method, order, steps):
    system, state = free_body()
    ref = system.simulate(state, (0.0, 4.0), t_eval=[4.0], rtol=1e-14, atol=1e-14).g_NB[-1, 0]
    e1, e2 = (_end_error(method, h, system, state, ref) for h in steps)
    assert np.log2(e1 / e2) == pytest.approx(order, abs=0.35), (e1, e2)


def test_a_user_defined_adaptive_method_controls_its_error():
    # Bogacki–Shampine by name, adaptive: the end error follows the tolerance, and rejected
    # steps (if any) come from its own error estimate.
    system, state = free_body()
    ref = system.simulate(state, (0.0, 4.0), t_eval=[4.0], rtol=1e-14, atol=1e-14).g_NB[-1, 0]
    errs, n_rhs = [], []
    for tol in (1e-6, 1e-8):
        traj = system.simulate(state, (0.0, 4.0), method="bs32-test", rtol=tol, atol=tol)
        errs.append(pose_error(traj.g_NB[-1, 0], ref))
        n_rhs.append(traj.stats["n_rhs"])
        assert errs[-1] < 1e3 * tol
    assert errs[1] < errs[0] / 10 and n_rhs[1] > 3 * n_rhs[0]


# -- the error-weight rule ---------------------------------------------------------------


def _rotation(seed):
    rng = np.random.default_rng(seed)
    return se3.exp(np.r_[rng.normal(size=3), 0, 0, 0])[:3, :3]


def test_error_weights_of_a_point_mass_are_norms_and_do_not_depend_on_the_axes():
    body = gmuk.RigidBody("a", 2.0, J)
    pm, sl = gmuk.PointMass("p", 1.0), gmuk.SlackCoordinate("s", mass=0.5)
    system = gmuk.System([body, pm, sl])
    r, v = np.array([3.0, 0.0, -0.2]), np.array([0.0, 1.5, 0.1])
    rtol, atol = 1e-6, 1e-9
    weights = []
    for Q in (np.eye(3), _rotation(3)):
        state = system.state(
            g={"a": np.eye(4)},
            V={"a": np.zeros(6)},
            r={"p": Q @ r},
            v={"p": Q @ v},
            s={"s": -0.25},
            s_dot={"s": 0.5},
        )
        prob = testing._ReferenceProblem(system)
        Y = prob.pack(state)
        sc = prob.scale(Y, Y, state.g, rtol, atol)
        weights.append(sc)
        # Euclidean entries of Y in body order: x = [r (3), s], then ẋ = [v (3), ṡ]
        x, xd = sc[prob.s_x], sc[prob.s_xd]
        np.testing.assert_allclose(x[:3], atol + rtol * np.linalg.norm(r), rtol=1e-15)
        np.testing.assert_allclose(xd[:3], atol + rtol * np.linalg.norm(v), rtol=1e-15)
        assert x[3] == atol + rtol * 0.25 and xd[3] == atol + rtol * 0.5  # scalars
    np.testing.assert_allclose(weights[1], weights[0], rtol=1e-15, atol=0)


def test_error_weights_take_the_larger_norm_at_the_two_ends_of_the_step():
    pm = gmuk.PointMass("p", 1.0)
    system = gmuk.System([pm])
    prob = testing._ReferenceProblem(system)
    s0 = system.state(r={"p": [1.0, 0.0, 0.0]}, v={"p": [0.0, 2.0, 0.0]})
    s1 = system.state(r={"p": [0.0, 0.0, -3.0]}, v={"p": [0.0, 0.0, 0.5]})
    sc = prob.scale(prob.pack(s0), prob.pack(s1), s0.g, 1e-3, 1e-9)
    np.testing.assert_array_equal(sc, [1e-9 + 3e-3] * 3 + [1e-9 + 2e-3] * 3)


def test_point_mass_step_sequence_does_not_depend_on_the_choice_of_axes():
    # An eccentric Kepler orbit of a point mass, described in rotated inertial axes: the
    # same motion, so the same steps (710 evaluations each). Component-wise weights on r and
    # v, which drop to atol whenever a coordinate crosses zero, gave 758 and 806.
    mu, r0, v0 = 1.0, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.2, 0.1])
    runs = []
    for Q in (np.eye(3), _rotation(7)):
        pm = gmuk.PointMass("p", 1.0)
        system = gmuk.System([pm], [], [gmuk.PointMassGravity(mu)])
        state = system.state(r={"p": Q @ r0}, v={"p": Q @ v0})
        traj = system.simulate(state, (0.0, 20.0), rtol=1e-10, atol=1e-12)
        runs.append((traj.t, traj.stats["n_rhs"]))
    assert runs[1][1] == runs[0][1]
    np.testing.assert_allclose(runs[1][0], runs[0][0], rtol=0, atol=1e-6)
