"""The bounded spring–mass–damper in GEKKO, a peer for benchmarks/bench_optimize_peers.py.

GEKKO (``pip install gekko==1.3.3``; a benchmark-only dependency, not gmuk's) writes the model
to files and solves it with its APMonitor executable, here locally (``GEKKO(remote=False)``),
as a dynamic optimisation (``IMODE = 6``) by IPOPT (``SOLVER = 3``)::

    minimise J(t_f),  J̇ = u²/m,  ẋ = v,  m v̇ = −k x − b v + u,  lower ≤ x ≤ upper,
    x(0) = x0, v(0) = v0, J(0) = 0, final state free,

with m = 2, b = 5, k = 10, x0 = 1.5, v0 = 6, 1 ≤ x ≤ 2, t_f = 30 (as
tests/optimize/handwritten_lobatto.py). The control u is a free ``Var`` (a value at every
node, like the Lobatto transcriptions), not an ``MV``: GEKKO holds an MV constant over each
time segment, a different control space (and one trial with an MV, 150 segments and
``NODES = 4``, ended in GEKKO's "Solution Not Found"). The
starting point is GEKKO's default, the initial values at every node: x = 1.5, v = 6, u = 0.

Discretisation
--------------
GEKKO collocates on each segment between consecutive ``m.time`` points with ``NODES``
Lobatto points (the segment's ends and the roots of P'_{NODES−1}, so the same nodes as LGL
of degree p = NODES − 1), a polynomial of degree p through them, and ẏ = F at the p nodes
after the segment's start (not at the start: checked against a simulation of ẏ = −y with
``IMODE = 4``). That is not Lobatto IIIA (which collocates at all p + 1 nodes with a
polynomial of degree p + 1), so the objectives differ at a given mesh; the cost J(t_f) is
integrated by the same scheme, with weights on the nodes 1 … p of a segment.

The comparable choice, the default here: the same elements and nodes as the Lobatto mesh,
``m.time`` at the n_elements + 1 element ends and ``NODES = degree + 1``, so
n_elements·degree + 1 distinct nodes at the same times. On 150 elements, degree 3
(``NODES = 4``), GEKKO gives 1551.99 against Lobatto IIIA's 1580.40 (−1.8 %); both converge
to about 1581.7 (GEKKO 1570.3, 1578.2, 1580.8 and Lobatto 1581.20, 1581.68, 1581.67 on 300,
600, 1200 elements; the active state bound makes the optimum non-smooth, so neither
converges at its nominal order).

For odd ``NODES`` (3, 5) GEKKO's scheme gives the segment's end node zero weight in the
integral over the segment, so J̇ = u²/m does not charge u there while u there still enters
the collocation at that node: the optimiser puts about 1000 N on every segment end and the
objective drops to 1169.5 (150 segments, ``NODES = 5``) or 1193.0 (``NODES = 3``), far
below the continuous optimum. Degree 4 therefore has no GEKKO analogue on the same nodes;
``nodes=2`` with ``m.time`` at all n_elements·degree + 1 node times (the same number of
unknowns per state; first order, 1519.58 for 451 and 1530.68 for 601 points) is the
alternative (``same_nodes=False``).

Tolerances: GEKKO's OTOL and RTOL (objective and equation residual) are set to 1e-8 like
the ``ipopt.tol`` of the CasADi transcriptions; GEKKO passes its own IPOPT settings
otherwise.

Run ``python benchmarks/gekko_smd.py`` for one solve at 150 elements of degree 3.
"""

from __future__ import annotations

import contextlib
import io
import re
import time
from dataclasses import dataclass

import numpy as np


@dataclass
class GekkoResult:
    """What one GEKKO solve reports.

    Attributes
    ----------
    objective : float
        J(t_f) (GEKKO's OBJFCNVAL).
    iterations : int
        IPOPT's iterations, read from the solver's output (-1 if not found).
    status : str
        "Solve_Succeeded" when GEKKO's APPSTATUS is 1, else "APPSTATUS=<value>".
    build_s : float
        Wall time (s) of building the GEKKO model in Python.
    solve_s : float
        Wall time (s) of ``m.solve``: writing the model files, APMonitor's parse and
        IPOPT, reading the results back.
    solver_s : float
        GEKKO's own SOLVETIME (s), the APMonitor run.
    n_nodes : int
        Distinct time nodes (segment ends and internal collocation nodes).
    """

    objective: float
    iterations: int
    status: str
    build_s: float
    solve_s: float
    solver_s: float
    n_nodes: int

    @property
    def total_s(self) -> float:
        """Build plus the wall time of the solve (s)."""
        return self.build_s + self.solve_s


def gekko_smd(
    n_elements: int = 150,
    degree: int = 3,
    same_nodes: bool = True,
    t_final: float = 30.0,
    x0: float = 1.5,
    v0: float = 6.0,
    lower: float = 1.0,
    upper: float = 2.0,
    m: float = 2.0,
    b: float = 5.0,
    k: float = 10.0,
) -> GekkoResult:
    """Solve the bounded spring–mass–damper with GEKKO.

    Parameters
    ----------
    n_elements, degree : int
        The Lobatto mesh to match: n_elements·degree + 1 nodes.
    same_nodes : bool
        True: the same elements and nodes (``m.time`` at the element ends,
        ``NODES = degree + 1``; degree ≤ 5). False: ``m.time`` at n_elements·degree + 1
        equally spaced points and ``NODES = 2``.
    t_final : float
        Horizon (s).
    x0, v0 : float
        Initial position (m) and velocity (m/s).
    lower, upper : float
        Bounds on x (m).
    m, b, k : float
        Mass (kg), damping (N·s/m), stiffness (N/m).

    Returns
    -------
    GekkoResult
    """
    from gekko import GEKKO  # benchmark-only dependency

    if same_nodes and not 1 <= degree <= 5:
        raise ValueError(f"GEKKO's NODES is 2 … 6, so degree is 1 … 5; got {degree}")
    tic = time.perf_counter()
    n_points = n_elements + 1 if same_nodes else n_elements * degree + 1
    model = GEKKO(remote=False)
    model.time = np.linspace(0.0, t_final, n_points)
    x = model.Var(value=float(np.clip(x0, lower, upper)), lb=lower, ub=upper, name="x")
    v = model.Var(value=v0, name="v")
    u = model.Var(value=0.0, name="u")  # free at every node (an MV would be piecewise constant)
    # GEKKO's names are parsed by APMonitor: "cost" would read as cos(…), hence "effort"
    cost = model.Var(value=0.0, name="effort")
    model.Equation(x.dt() == v)
    model.Equation(m * v.dt() == -k * x - b * v + u)
    model.Equation(cost.dt() == u**2 / m)
    final = np.zeros(n_points)
    final[-1] = 1.0  # weight only on the last time point: minimise J(t_f)
    model.Minimize(cost * model.Param(value=final, name="at_end"))
    model.options.IMODE = 6
    model.options.SOLVER = 3
    model.options.NODES = degree + 1 if same_nodes else 2
    model.options.OTOL = 1e-8
    model.options.RTOL = 1e-8
    build_s = time.perf_counter() - tic
    # disp=True only prints the output GEKKO collects anyway; captured to read the iterations
    log = io.StringIO()
    tic = time.perf_counter()
    with contextlib.redirect_stdout(log):
        model.solve(disp=True)
    solve_s = time.perf_counter() - tic
    found = re.search(r"Number of Iterations\.*:\s*(\d+)", log.getvalue())
    status = int(model.options.APPSTATUS)
    out = GekkoResult(
        objective=float(model.options.OBJFCNVAL),
        iterations=int(found.group(1)) if found else -1,
        status="Solve_Succeeded" if status == 1 else f"APPSTATUS={status}",
        build_s=build_s,
        solve_s=solve_s,
        solver_s=float(model.options.SOLVETIME),
        n_nodes=n_elements * degree + 1,
    )
    model.cleanup()  # GEKKO's temporary directory; not timed
    return out


def main() -> None:
    """One solve at 150 elements of degree 3, with the Lobatto IIIA objective for comparison."""
    from hand_transcriptions import smd_mapped

    g = gekko_smd(150, 3)
    h = smd_mapped(150, 3)
    print(
        f"GEKKO 150 × NODES=4: {g.objective:.7f} ({g.status}, {g.iterations} it, build "
        f"{g.build_s:.3f} s, solve {g.solve_s:.3f} s, SOLVETIME {g.solver_s:.3f} s); "
        f"Lobatto IIIA 150 × 3: {h.objective:.7f}; relative difference "
        f"{(g.objective - h.objective) / h.objective:+.2e}"
    )


if __name__ == "__main__":
    main()
