"""Thesis scenarios, one module each, runnable from Python or ``gmuk run NAME``.

Each scenario module defines ``NAME``, ``DESCRIPTION`` and
``run(orbits: float = 1.0, **options) -> ScenarioResult``, and ``figures(result, out_dir,
formats) -> list[Path]``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

from gmuk.errors import DefinitionError
from gmuk.trajectory import Trajectory

__all__ = ["SCENARIOS", "ScenarioResult", "describe", "load"]

#: Scenario names and the modules implementing them, in the thesis's order.
SCENARIOS: dict[str, str] = {
    "apollo16": "gmuk.scenarios.apollo16",
    "fccn": "gmuk.scenarios.fccn",
    "fcei": "gmuk.scenarios.fcei",
    "fceim": "gmuk.scenarios.fceim",
    "ucei": "gmuk.scenarios.ucei",
    "uceis": "gmuk.scenarios.uceis",
    "uceim": "gmuk.scenarios.uceim",
}


@dataclass(frozen=True)
class ScenarioResult:
    """What a scenario run produces.

    Attributes
    ----------
    name : str
    trajectories : dict of str → Trajectory
        Every run of the scenario (e.g. "fcei" and "fceim" for a comparison).
    primary : str
        The key of the trajectory saved as ``trajectory.npz``.
    summary : dict
        Headline figures (JSON-serialisable), with units in the keys.
    """

    name: str
    trajectories: dict[str, Trajectory]
    primary: str
    summary: dict[str, Any] = field(default_factory=dict)


def load(name: str) -> ModuleType:
    """The module of scenario ``name``; unknown names list the available ones."""
    key = name.lower()
    if key not in SCENARIOS:
        raise DefinitionError(f"unknown scenario {name!r}; available: {', '.join(SCENARIOS)}")
    return importlib.import_module(SCENARIOS[key])


def describe() -> list[tuple[str, str]]:
    """(name, one-line description) of every scenario."""
    return [(name, load(name).DESCRIPTION) for name in SCENARIOS]


FigureFn = Callable[[ScenarioResult, Path, tuple[str, ...]], list[Path]]
