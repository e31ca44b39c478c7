"""The rest-to-rest rigid-body slews the optimiser's tests pose (not a test module): one
free body of 100 kg, at rest at the identity, to rest at a given rotation."""

from __future__ import annotations

from typing import Any

import numpy as np

import gmuk
from gmuk.lie import so3
from gmuk.optimize import OptimalControlProblem

#: Inertia (kg m², body axes) with products of inertia: docs/optimize.rst's slew.
GENERAL_INERTIA = np.array([[10.0, 1.0, -0.5], [1.0, 12.0, 0.3], [-0.5, 0.3, 15.0]])

#: docs/optimize.rst's slew: 90° about (1, 1, 1)/√3 (rotation vector, rad).
DOCS_ROTATION = 0.5 * np.pi * np.ones(3) / np.sqrt(3.0)


def slew_problem(
    inertia: np.ndarray = GENERAL_INERTIA,
    rotation: Any = DOCS_ROTATION,
    t_final: float = 60.0,
    **options: Any,
) -> OptimalControlProblem:
    """The slew of body "sat" (``inertia``) by the rotation vector ``rotation`` (rad), rest
    to rest, in ``t_final`` s (the guess of the final time when ``options`` free it);
    ``options`` go to OptimalControlProblem."""
    body = gmuk.RigidBody("sat", 100.0, inertia)
    system = gmuk.System([body])
    state = system.state(g={"sat": np.eye(4)}, V={"sat": np.zeros(6)})
    g_final = np.eye(4)
    g_final[:3, :3] = so3.exp(np.asarray(rotation, dtype=float))
    final = {"g": {"sat": g_final}, "V": {"sat": np.zeros(6)}}
    return OptimalControlProblem(system, state, t_final, final=final, **options)
