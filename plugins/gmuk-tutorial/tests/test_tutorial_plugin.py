"""The tutorial plugin: found through its entry points, its drag and its scenario correct."""

from __future__ import annotations

import numpy as np
import pytest
from gmuk_tutorial import LinearDrag

import gmuk
from gmuk import scenarios
from gmuk.errors import DefinitionError
from gmuk.forces import registry


def test_entry_points_name_the_plugin_objects():
    registry.refresh()
    scenarios.refresh()
    assert registry.get("linear_drag") is LinearDrag
    found = {s.name: src for s, src in scenarios.available()}
    assert found["tennis-racket"] == "gmuk-tutorial"


def test_drag_opposes_velocity_and_refuses_bad_coefficients():
    drag = LinearDrag(2.0)
    body = gmuk.RigidBody("b", 1.0, np.eye(3))
    w = drag.wrench(0.0, np.eye(4), np.array([1.0, 0, 0, 3.0, -1.0, 0]), body)
    assert np.allclose(w, [0, 0, 0, -6.0, 2.0, 0])
    assert np.allclose(drag.force(0.0, np.zeros(3), np.array([1.0, 2, 3]), body), [-2, -4, -6])
    for bad in (-1.0, float("nan"), True, "1"):
        with pytest.raises(DefinitionError, match="coefficient must be a finite number"):
            LinearDrag(bad)


def test_tennis_racket_flips_and_keeps_energy_and_momentum():
    result = scenarios.get("tennis-racket").run(duration=30.0)
    assert result.summary["flips"] >= 1
    assert result.summary["energy_drift"] < 1e-9 and result.summary["momentum_drift"] < 1e-9
