"""``System.simulate`` states its options (issue #26, item 8): an explicit keyword-only
signature, typed and documented, the same as :func:`gmuk.engine.integrate.simulate`'s, and an
unknown keyword that names the valid ones."""

from __future__ import annotations

import inspect
import re

import numpy as np
import pytest

import gmuk
from gmuk.engine import integrate

OPTIONS = [
    "t_eval", "method", "rtol", "atol", "step", "first_step", "max_step", "max_steps",
    "progress", "on_failure", "compiled", "drift_tol", "events",
]  # fmt: skip


def test_the_signature_lists_every_option_keyword_only_with_its_default_and_type():
    params = inspect.signature(gmuk.System.simulate).parameters
    assert list(params) == ["self", "state0", "t_span", *OPTIONS]
    engine = inspect.signature(integrate.simulate).parameters
    assert list(engine) == ["system", "state0", "t_span", *OPTIONS]
    for name in OPTIONS:
        mine, theirs = params[name], engine[name]
        assert mine.kind is inspect.Parameter.KEYWORD_ONLY, name
        assert mine.default == theirs.default, name
        assert mine.annotation is not inspect.Parameter.empty, name
    assert params["rtol"].default == 1e-10 and params["drift_tol"].default == 1e-6
    assert params["method"].default == "DOP853" and params["max_step"].default == np.inf


def test_the_docstring_documents_every_option_with_its_unit():
    doc = inspect.getdoc(gmuk.System.simulate)
    section = doc.split("Parameters\n----------\n")[1].split("Returns\n-------")[0]
    entries = dict(re.findall(r"^(\w+(?:, \w+)*) : (.*)$", section, re.M))
    documented = {n for names in entries for n in names.split(", ")}
    assert documented == {"state0", "t_span", *OPTIONS}
    for name in ("t_span", "t_eval", "step", "first_step", "max_step"):  # times, in s
        entry = section.split(f"\n{name} :")[1].split("\n")[:3]
        assert "(s)" in " ".join(entry), name
    assert "rad/s" in section and "m/s" in section  # what the tolerances weigh


def _system():
    a = gmuk.RigidBody("a", mass=2.0, inertia=np.diag([1.0, 2.0, 3.0]))
    system = gmuk.System(bodies=[a])
    return system, system.state(g={"a": np.eye(4)}, V={"a": [0.1, 0.2, 0.3, 1.0, 0.0, 0.0]})


def test_an_unknown_keyword_is_a_type_error_that_names_the_options():
    system, state = _system()
    with pytest.raises(TypeError) as info:
        system.simulate(state, (0.0, 1.0), rtl=1e-8)
    message = str(info.value)
    assert "System.simulate() got an unexpected keyword argument 'rtl'" in message
    assert "did you mean 'rtol'?" in message
    assert all(name in message for name in OPTIONS)
    with pytest.raises(TypeError, match=r"'colour'; its options are t_eval, method"):
        system.simulate(state, (0.0, 1.0), colour="red")
    with pytest.raises(TypeError, match="positional"):
        system.simulate(state, (0.0, 1.0), None)  # the options are keyword-only


def test_the_options_reach_the_engine_unchanged():
    system, state = _system()
    t = np.linspace(0.0, 1.0, 5)
    traj = system.simulate(state, (0.0, 1.0), t_eval=t, method="rk4", step=0.01, drift_tol=None)
    assert np.array_equal(traj.t, t) and traj.stats["method"] == "RK4"
    direct = integrate.simulate(system, state, (0.0, 1.0), t_eval=t, method="rk4", step=0.01)
    assert np.array_equal(traj.V_B, direct.V_B)
    # the engine's validation and errors are the same as before
    with pytest.raises(gmuk.errors.DefinitionError, match="method must be one of"):
        system.simulate(state, (0.0, 1.0), method="nope")
    with pytest.raises(gmuk.errors.DefinitionError, match="on_failure"):
        system.simulate(state, (0.0, 1.0), on_failure="ignore")  # type: ignore[arg-type]
