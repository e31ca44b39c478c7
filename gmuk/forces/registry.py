"""Force-model registry: gmuk's own models plus plugins from the entry-point group
``gmuk.force_models``.

A plugin package declares, in its ``pyproject.toml``::

    [project.entry-points."gmuk.force_models"]
    third_body = "gmuk_thirdbody:ThirdBodyGravity"

Discovery runs once and is cached (:func:`refresh` forgets it). A plugin that fails to import,
or does not name a :class:`gmuk.ForceModel` subclass, is skipped with a
:class:`gmuk.errors.PluginWarning` saying why; it never breaks gmuk. Asking for an unknown name
raises an error that lists every installed model.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

from gmuk._plugins import entry_point_plugins, load_target
from gmuk.errors import DefinitionError
from gmuk.forces.base import ForceModel

__all__ = ["ENTRY_POINT_GROUP", "ForceModelInfo", "available", "create", "get", "refresh"]

ENTRY_POINT_GROUP = "gmuk.force_models"

_BUILTIN = {
    "applied_wrench": "gmuk.forces.mechanical:AppliedWrench",
    "gravity_gradient": "gmuk.forces.gravity:GravityGradient",
    "point_mass_gravity": "gmuk.forces.gravity:PointMassGravity",
    "spherical_harmonic_gravity": "gmuk.forces.gravity:SphericalHarmonicGravity",
    "spring_damper": "gmuk.forces.mechanical:SpringDamper",
    "uniform_gravity": "gmuk.forces.mechanical:UniformGravity",
}


@dataclass(frozen=True)
class ForceModelInfo:
    """A registered force model: its name, class, and where it comes from."""

    name: str
    cls: type[ForceModel]
    source: str  # "gmuk" or the distribution name of the plugin
    target: str  # "module:attribute"


@functools.cache
def _discover() -> dict[str, ForceModelInfo]:
    found: dict[str, ForceModelInfo] = {}
    for name, target in _BUILTIN.items():
        found[name] = ForceModelInfo(name, load_target(target), "gmuk", target)

    def rejects(name: str, obj: Any) -> str | None:
        if isinstance(obj, type) and issubclass(obj, ForceModel):
            return None
        return f"it names {obj!r}, not a gmuk.ForceModel subclass"

    for name, obj, dist, target in entry_point_plugins(
        ENTRY_POINT_GROUP,
        "force-model plugin",
        lambda n: found[n].source if n in found else None,
        rejects,
    ):
        found[name] = ForceModelInfo(name, obj, dist, target)
    return found


def refresh() -> None:
    """Forget the cached discovery (after installing or removing a plugin)."""
    _discover.cache_clear()


def available() -> list[ForceModelInfo]:
    """Every usable force model, gmuk's own first, then plugins, by name."""
    return sorted(_discover().values(), key=lambda i: (i.source != "gmuk", i.name))


def get(name: str) -> type[ForceModel]:
    """The force-model class registered as ``name``.

    Raises
    ------
    DefinitionError
        If no such model is installed; the message lists the installed ones.
    """
    models = _discover()
    if name not in models:
        listing = ", ".join(f"{i.name} ({i.source})" for i in available())
        raise DefinitionError(f"no force model named {name!r}; installed: {listing}")
    return models[name].cls


def create(name: str, *args: Any, **kwargs: Any) -> ForceModel:
    """Instantiate the force model registered as ``name`` with the given arguments."""
    return get(name)(*args, **kwargs)
