"""Entry-point discovery shared by gmuk's registries (force models, scenarios).

A plugin package names objects under an entry-point group; a registry asks
:func:`entry_point_plugins` for the usable ones. A plugin whose name is taken, that fails to
load, or that names the wrong kind of object is skipped with a
:class:`gmuk.errors.PluginWarning` saying why: a broken plugin never breaks gmuk.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator
from importlib import metadata
from typing import Any

from gmuk.errors import PluginWarning

__all__ = ["entry_point_plugins", "load_target"]


def load_target(target: str) -> Any:
    """The object a ``"module:attribute"`` target names (attribute may be dotted)."""
    module, _, attr = target.partition(":")
    obj: Any = __import__(module, fromlist=[attr])
    for part in attr.split("."):
        obj = getattr(obj, part)
    return obj


def entry_point_plugins(
    group: str,
    label: str,
    taken_by: Callable[[str], str | None],
    rejects: Callable[[str, Any], str | None],
) -> Iterator[tuple[str, Any, str, str]]:
    """The loadable plugins of an entry-point group, each as (name, object, distribution,
    target).

    Parameters
    ----------
    group : str
        Entry-point group, e.g. ``"gmuk.force_models"``.
    label : str
        What a plugin is, for the warnings (``"force-model plugin"``).
    taken_by : callable name → str or None
        Who already holds a name (``None`` if nobody); consulted as plugins are yielded, so
        the caller's registry can grow meanwhile.
    rejects : callable (name, object) → str or None
        Why a loaded object is not acceptable (``"it names …"``), or ``None`` if it is.
    """
    for ep in metadata.entry_points(group=group):
        dist = getattr(getattr(ep, "dist", None), "name", None) or "unknown distribution"
        where = f"{label} {ep.name!r} ({ep.value}, from {dist})"
        holder = taken_by(ep.name)
        if holder is not None:
            warnings.warn(
                f"{where} is ignored: the name is taken by {holder}", PluginWarning, stacklevel=4
            )
            continue
        try:
            obj = ep.load()
        except Exception as exc:
            warnings.warn(
                f"{where} failed to load and is skipped: {type(exc).__name__}: {exc}",
                PluginWarning,
                stacklevel=4,
            )
            continue
        reason = rejects(ep.name, obj)
        if reason is not None:
            warnings.warn(f"{where} is skipped: {reason}", PluginWarning, stacklevel=4)
            continue
        yield ep.name, obj, dist, ep.value
