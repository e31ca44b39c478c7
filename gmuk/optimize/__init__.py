"""Optimal control from the same model: Legendre–Gauss–Lobatto direct collocation.

Transcribes a :class:`gmuk.System` (point masses and rigid bodies, force models, inequality,
holonomic and nonholonomic constraints as path constraints, boundary conditions) into a
nonlinear program and solves it with IPOPT through CasADi (exact derivatives). The default
cost is the Gauss-principle cost ``∫ uᵀM⁻¹u dt`` of McCann (2020) §6.4, so the optimum can be
set beside the Udwadia–Kalaba answer (``gmuk run smd-compare``).

Needs CasADi: ``pip install "gmuk[optimize]"``. ``import gmuk`` does not import this package,
and this package imports CasADi only when a problem is transcribed.

Example
-------
>>> from gmuk.optimize import Mesh, OptimalControlProblem  # doctest: +SKIP
>>> problem = OptimalControlProblem(system, state0, t_final=30.0)  # doctest: +SKIP
>>> result = problem.solve(Mesh.uniform(0.0, 30.0, 150, degree=3))  # doctest: +SKIP
>>> result.objective, result.status  # doctest: +SKIP

References
----------
McCann (2020), §6.4, Eqs. (98)–(100); see :mod:`gmuk.optimize.lgl` and
:mod:`gmuk.optimize.problem` for the discretisation and its sources.
"""

from gmuk.optimize.lgl import (
    interpolation_matrix,
    lgl_differentiation_matrix,
    lgl_integration_matrix,
    lgl_nodes,
)
from gmuk.optimize.mesh import Mesh
from gmuk.optimize.parts import register_casadi_form
from gmuk.optimize.problem import OptimalControlProblem
from gmuk.optimize.result import (
    BoundKKT,
    OpenLoopControl,
    OptimalControlResult,
    PathConstraintResult,
    RefinementStep,
)

__all__ = [
    "BoundKKT",
    "Mesh",
    "OpenLoopControl",
    "OptimalControlProblem",
    "OptimalControlResult",
    "PathConstraintResult",
    "RefinementStep",
    "interpolation_matrix",
    "lgl_differentiation_matrix",
    "lgl_integration_matrix",
    "lgl_nodes",
    "register_casadi_form",
]
