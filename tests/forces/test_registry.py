"""Force-model plugins: discovery, caching, broken plugins, unknown names."""

from __future__ import annotations

from importlib import metadata

import pytest

import gmuk
from gmuk import _plugins
from gmuk.errors import DefinitionError, PluginWarning
from gmuk.forces import registry

GROUP = registry.ENTRY_POINT_GROUP


@pytest.fixture
def fake_plugins(monkeypatch):
    """Replace the installed entry points by the given ones (and restore the cache after)."""

    def install(*eps):
        monkeypatch.setattr(
            _plugins.metadata, "entry_points", lambda group: [ep for ep in eps if ep.group == group]
        )
        registry.refresh()

    yield install
    registry.refresh()


def test_builtin_models_are_always_available(fake_plugins):
    fake_plugins()
    names = {i.name for i in registry.available()}
    assert {"gravity_gradient", "point_mass_gravity", "uniform_gravity"} <= names
    assert registry.get("gravity_gradient") is gmuk.GravityGradient
    assert isinstance(registry.create("point_mass_gravity", 4.9e12), gmuk.PointMassGravity)


def test_unknown_name_lists_installed_models(fake_plugins):
    fake_plugins()
    with pytest.raises(DefinitionError, match=r"no force model named 'nope'.*gravity_gradient"):
        registry.get("nope")


def test_a_working_plugin_is_found(fake_plugins):
    fake_plugins(metadata.EntryPoint("uniform_g2", "gmuk.forces.mechanical:UniformGravity", GROUP))
    assert registry.get("uniform_g2") is gmuk.UniformGravity


def test_broken_plugins_warn_and_are_skipped(fake_plugins):
    fake_plugins(
        metadata.EntryPoint("broken", "gmuk_no_such_module:Model", GROUP),
        metadata.EntryPoint("not_a_model", "gmuk.lie.se3:exp", GROUP),
        metadata.EntryPoint("gravity_gradient", "gmuk.forces.mechanical:UniformGravity", GROUP),
    )
    with pytest.warns(PluginWarning) as record:
        names = {i.name for i in registry.available()}
    text = " | ".join(str(w.message) for w in record)
    assert "'broken'" in text and "ModuleNotFoundError" in text
    assert "'not_a_model'" in text and "not a gmuk.ForceModel subclass" in text
    assert "name is taken" in text
    assert "broken" not in names and "not_a_model" not in names
    assert registry.get("gravity_gradient") is gmuk.GravityGradient  # the built-in kept it


def test_discovery_is_cached(fake_plugins, monkeypatch):
    calls = []

    def counting(group):
        calls.append(group)
        return []

    fake_plugins()
    monkeypatch.setattr(_plugins.metadata, "entry_points", counting)
    registry.refresh()
    registry.available()
    registry.get("gravity_gradient")
    assert calls == [GROUP]
