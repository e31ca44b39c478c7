"""Peer transcriptions for benchmarks/bench_optimize_peers.py: direct CasADi + IPOPT, written
as a CasADi user would write them by hand, sharing no code with gmuk.optimize.

Both problems use gmuk's discretisation: uniform elements of degree p, each with the p + 1
Legendre–Gauss–Lobatto (LGL) nodes τ (the ends and the roots of P'_p), states and controls at
every distinct node (the end node of an element is the start node of the next), the dynamics
ẏ = F(y, u) in integral form (Lobatto IIIA),

    y_j − y_0 − (h/2) Σ_l A_jl F(y_l, u_l) = 0,   j = 1 … p,   A_jl = ∫_{τ_0}^{τ_j} ℓ_l,

and the running cost by the same quadrature (row p of A, the LGL weights).

How it is built (the "expert" pattern):

* ONE element function, written with SX symbols (the dynamics are a few dozen scalar
  operations, where SX's scalar graph is much cheaper to evaluate and differentiate than MX);
  it returns the element's p·n_y collocation residuals and its share of the cost;
* ``Function.map(n_elements)`` applies it to the whole mesh with MX symbols for the NLP's
  decision vector, so CasADi differentiates one element (the derivatives of the map are
  maps of the element's derivatives), not n_elements unrolled copies. ``symbols="SX"``
  calls the same map with SX symbols instead, which inlines it: one flat SX NLP, cheaper to
  evaluate but slower to build and differentiate. On the benchmark's meshes MX is the faster
  in total (SMD 150 × 3: build 0.02 s + solve 0.08 s with MX, 0.12 s + 0.03 s with SX;
  slew 40 × 4: 0.08 s + 0.08 s against 0.46 s + 0.04 s; ``nlpsol``'s ``expand`` option
  gives the same figures as SX), so MX is the default;
* the decision vector is node-major, ``w = [y_0, u_0, y_1, u_1, …]`` (a banded KKT matrix);
  the elements see it through two strided slices and no gather: the start nodes
  ``W[:, 0:K p:p]`` and the other nodes ``W[:, 1:]`` (n_z × K p, exactly the K blocks of p
  columns the mapped function expects);
* one ``nlpsol`` with exact Hessian and the options every solver of this benchmark uses.

Build time is everything up to and including creating the solver and the starting point;
solve time is the solver call.

Run ``python benchmarks/hand_transcriptions.py`` for the agreement checks (against
tests/optimize/handwritten_lobatto.py for the SMD and against gmuk for the slew).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.polynomial import legendre as npleg

#: The IPOPT options of every solver in this benchmark (exact Hessian is IPOPT's default).
IPOPT_OPTIONS: dict[str, Any] = {
    "print_time": False,
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-8,
}


@dataclass
class HandResult:
    """What one hand-transcribed solve reports.

    Attributes
    ----------
    objective : float
        The NLP's objective at the solution.
    iterations : int
        IPOPT's iteration count (``solver.stats()["iter_count"]``).
    status : str
        IPOPT's return status.
    build_s, solve_s : float
        Wall time (s) of building (NLP, solver, starting point) and of the solver call.
    t : ndarray
        Node times (n_nodes,).
    y, u : ndarray
        States (n_nodes, n_y) and controls (n_nodes, n_u) at the nodes.
    """

    objective: float
    iterations: int
    status: str
    build_s: float
    solve_s: float
    t: np.ndarray = field(repr=False)
    y: np.ndarray = field(repr=False)
    u: np.ndarray = field(repr=False)

    @property
    def total_s(self) -> float:
        """Build plus solve (s)."""
        return self.build_s + self.solve_s


# ---------------------------------------------------------------------- LGL
def lgl_nodes(p: int) -> np.ndarray:
    """The p + 1 LGL nodes on [−1, 1]: ±1 and the roots of P'_p, ascending."""
    coef = np.zeros(p + 1)
    coef[p] = 1.0
    inner = npleg.legroots(npleg.legder(coef)) if p > 1 else np.zeros(0)
    return np.concatenate(([-1.0], np.sort(np.real(inner)), [1.0]))


def lgl_integration_matrix(tau: np.ndarray) -> np.ndarray:
    """A[j, l] = ∫_{τ_0}^{τ_j} ℓ_l(s) ds for the Lagrange polynomials ℓ_l of the nodes τ.

    The Lagrange basis is expanded in Legendre polynomials (coefficients: the inverse of the
    Legendre–Vandermonde matrix), which is well conditioned on LGL nodes, then integrated
    term by term.
    """
    n = tau.size
    coeffs = np.linalg.inv(npleg.legvander(tau, n - 1))  # column l: ℓ_l in P_0 … P_{n−1}
    antider = npleg.legint(coeffs, lbnd=tau[0], axis=0)  # ∫_{τ_0}^{s} ℓ_l
    return npleg.legval(tau, antider).T  # legval over axis 0 gives (l, j); A is (j, l)


# ---------------------------------------------------------------------- generic transcription
@dataclass
class _Collocation:
    """A Lobatto IIIA transcription on a uniform mesh, node-major decision vector."""

    n_y: int
    n_u: int
    n_elements: int
    degree: int
    t_final: float
    tau: np.ndarray = field(init=False, repr=False)
    a: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.tau = lgl_nodes(self.degree)
        self.a = lgl_integration_matrix(self.tau)

    @property
    def h(self) -> float:
        return self.t_final / self.n_elements

    @property
    def n_nodes(self) -> int:
        return self.n_elements * self.degree + 1

    @property
    def n_z(self) -> int:
        return self.n_y + self.n_u

    def times(self) -> np.ndarray:
        """Node times, element after element, shared ends once."""
        inner = (self.tau[1:] + 1.0) * (0.5 * self.h)
        t = (np.arange(self.n_elements)[:, None] * self.h + inner[None, :]).reshape(-1)
        return np.concatenate(([0.0], t))

    def element_function(
        self,
        rhs: Callable[[Any, Any], Any],
        running_cost: Callable[[Any, Any], Any],
    ) -> ca.Function:
        """The SX element function ``(z0 (n_z), Z (n_z × p)) → (residuals (n_y p), cost)``.

        ``rhs(y, u)`` and ``running_cost(y, u)`` take SX columns of one node.
        """
        p, ny = self.degree, self.n_y
        z0 = ca.SX.sym("z0", self.n_z)
        Z = ca.SX.sym("Z", self.n_z, p)
        nodes = [z0] + [Z[:, j] for j in range(p)]
        F = ca.horzcat(*[rhs(z[:ny], z[ny:]) for z in nodes])  # n_y × (p + 1)
        L = ca.horzcat(*[running_cost(z[:ny], z[ny:]) for z in nodes])  # 1 × (p + 1)
        half_h = 0.5 * self.h
        # column j − 1 of the residual: y_j − y_0 − (h/2) Σ_l A_jl F_l, as one matrix product
        res = Z[:ny, :] - ca.repmat(z0[:ny], 1, p) - F @ ca.DM(half_h * self.a[1:, :].T)
        cost = L @ ca.DM(half_h * self.a[p, :])  # the LGL quadrature over the element
        return ca.Function("element", [z0, Z], [ca.vec(res), cost], ["z0", "Z"], ["res", "cost"])

    def nlp(self, element: ca.Function, symbols: str = "MX") -> tuple[Any, Any, Any]:
        """The decision vector (``symbols``: "MX" or "SX"), the mapped collocation residuals
        and the total cost."""
        K, p = self.n_elements, self.degree
        kind = {"MX": ca.MX, "SX": ca.SX}[symbols]
        w = kind.sym("w", self.n_z * self.n_nodes)
        W = ca.reshape(w, self.n_z, self.n_nodes)  # node-major: column i is node i
        res, cost = element.map(K)(W[:, 0 : K * p : p], W[:, 1:])
        return w, ca.vec(res), ca.sum2(cost)


def _solve(
    name: str,
    col: _Collocation,
    w: Any,
    f: Any,
    g: Any,
    bounds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    guess: np.ndarray,
    tic: float,
) -> HandResult:
    """Create the solver (counted in the build), call it (the solve), unpack the result."""
    solver = ca.nlpsol(name, "ipopt", {"x": w, "f": f, "g": g}, IPOPT_OPTIONS)
    lbw, ubw, lbg, ubg = bounds
    build_s = time.perf_counter() - tic
    tic = time.perf_counter()
    sol = solver(x0=guess, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
    solve_s = time.perf_counter() - tic
    stats = solver.stats()
    Z = np.asarray(sol["x"]).reshape(col.n_nodes, col.n_z)
    return HandResult(
        objective=float(sol["f"]),
        iterations=int(stats["iter_count"]),
        status=str(stats["return_status"]),
        build_s=build_s,
        solve_s=solve_s,
        t=col.times(),
        y=Z[:, : col.n_y],
        u=Z[:, col.n_y :],
    )


# ---------------------------------------------------------------------- (a) spring–mass–damper
def smd_mapped(
    n_elements: int = 150,
    degree: int = 3,
    t_final: float = 30.0,
    x0: float = 1.5,
    v0: float = 6.0,
    lower: float = 1.0,
    upper: float = 2.0,
    m: float = 2.0,
    b: float = 5.0,
    k: float = 10.0,
    symbols: str = "MX",
    dim: int = 1,
) -> HandResult:
    """The bounded spring–mass–damper of tests/optimize/handwritten_lobatto.py, mapped.

    minimise ∫ u²/m dt subject to ẋ = v, m v̇ = −k x − b v + u, ``lower ≤ x ≤ upper`` at
    every node but the first (variable bounds), x(0) = x0, v(0) = v0, final state free.
    State y = (x, v), control u (N). Starting point: x = clip(x0, lower, upper), v = v0,
    u = 0 at every node.

    Parameters
    ----------
    n_elements, degree : int
        The uniform mesh: number of elements and their degree p.
    t_final : float
        Horizon (s).
    x0, v0 : float
        Initial position (m) and velocity (m/s).
    lower, upper : float
        Bounds on x (m).
    m, b, k : float
        Mass (kg), damping (N·s/m), stiffness (N/m).
    symbols : {"MX", "SX"}
        The symbols of the mesh-level NLP (module docstring).
    dim : {1, 3}
        1: the 1-D problem above. 3: the NLP gmuk poses for the ``smd-bi`` System, a point
        mass in R³ with the isotropic spring–damper (−k r − b v), a control force on each
        axis, the bound on the first coordinate, at rest at the origin in the other two;
        y = (r, v), u (3,), cost ∫ |u|²/m dt. The optimum is the same (the other axes stay
        at rest with zero control); the NLP is three times the size.

    Returns
    -------
    HandResult
    """
    tic = time.perf_counter()
    if dim not in (1, 3):
        raise ValueError(f"dim must be 1 or 3; got {dim!r}")
    col = _Collocation(2 * dim, dim, n_elements, degree, t_final)

    def rhs(y: Any, u: Any) -> Any:
        return ca.vertcat(y[dim:], (u - k * y[:dim] - b * y[dim:]) / m)

    def running_cost(y: Any, u: Any) -> Any:
        return ca.sumsqr(u) / m

    w, g, f = col.nlp(col.element_function(rhs, running_cost), symbols)
    N = col.n_nodes
    lbw = np.full((N, 3 * dim), -np.inf)
    ubw = np.full((N, 3 * dim), np.inf)
    lbw[1:, 0], ubw[1:, 0] = lower, upper
    start = np.zeros(3 * dim)
    start[0], start[dim] = x0, v0
    lbw[0, : 2 * dim] = ubw[0, : 2 * dim] = start[: 2 * dim]  # the initial state, by bounds
    start[0] = np.clip(x0, lower, upper)
    guess = np.tile(start, (N, 1))
    zeros = np.zeros(g.shape[0])
    bounds = (lbw.reshape(-1), ubw.reshape(-1), zeros, zeros)
    return _solve("smd_mapped", col, w, f, g, bounds, guess.reshape(-1), tic)


# ---------------------------------------------------------------------- (b) rigid-body slew
#: The slew's rigid body: inertia about its centre of mass (kg m², body axes) and mass (kg).
SLEW_INERTIA = np.array([[10.0, 1.0, -0.5], [1.0, 12.0, 0.3], [-0.5, 0.3, 15.0]])
SLEW_MASS = 100.0


def _quat_mul(p: Any, q: Any) -> Any:
    """Hamilton product p ⊗ q of scalar-first quaternions (SX or numpy columns)."""
    pw, pv = p[0], p[1:4]
    qw, qv = q[0], q[1:4]
    return ca.vertcat(pw * qw - ca.dot(pv, qv), pw * qv + qw * pv + ca.cross(pv, qv))


def slew_mapped(
    n_elements: int = 40,
    degree: int = 4,
    t_final: float = 60.0,
    angle: float = 0.5 * np.pi,
    axis: tuple[float, float, float] = (1.0, 1.0, 1.0),
    inertia: np.ndarray = SLEW_INERTIA,
    symbols: str = "MX",
    translation: bool = False,
) -> HandResult:
    """Minimum-effort rest-to-rest slew of one free rigid body, mapped.

    minimise ∫ Lᵀ J⁻¹ L dt subject to J ω̇ = −ω × Jω + L (Euler's equations, body frame),
    q̇ = ½ q ⊗ (0, ω), from rest at the identity to rest at the rotation by ``angle`` about
    ``axis``.

    gmuk's cost for a rigid body is ∫ uᵀ M⁻¹ u dt with u = [L; f] (body torque and force) and
    M = diag(J, m I): the translational part decouples (the body starts and ends at rest, at
    no prescribed position), its optimum is f = 0 and adds nothing to the objective, so it is
    omitted here and the mass plays no part.

    Attitude: a unit quaternion q = (q_w, q_x, q_y, q_z), scalar first, body to inertial,
    collocated like the other states; it is polynomial (no chart, no singularity, no series).
    The exact flow keeps ‖q‖ = 1 and the collocation determines q at every node from the
    fixed q(0), so no unit-norm constraint is imposed: it would be a second equation per node
    for a quantity the collocation already fixes, an over-determined NLP (infeasible by the
    O(h^2p) drift of Lobatto IIIA, which does not conserve quadratic invariants exactly; the
    largest | ‖q‖ − 1 | of the solution is about 1e-10 on 40 elements of degree 4, see
    ``main``). For the same reason the final
    attitude is three equations, not four bounds: the vector part of q_f* ⊗ q(t_f) is zero
    (q(t_f) = ±‖q(t_f)‖ q_f; the starting point selects +). The final ω is 0 by bounds.

    Starting point (as gmuk's): the geodesic q(s) = exp(s φ/2) at the nodes, s = t/t_f, with
    φ = angle · axis/‖axis‖, the constant body rate ω = φ/t_f, and zero torque.

    Parameters
    ----------
    n_elements, degree : int
        The uniform mesh.
    t_final : float
        Slew time (s).
    angle : float
        Slew angle (rad).
    axis : tuple of float
        Slew axis (any length; normalised).
    inertia : ndarray
        J (3 × 3, kg m²).
    symbols : {"MX", "SX"}
        The symbols of the mesh-level NLP (module docstring).
    translation : bool
        Also the translational part, as gmuk poses it: the position r_N (m) and the
        body-frame velocity v_B (m/s) as states, ṙ_N = R(q) v_B and
        v̇_B = v_B × ω + f_B/m, the body-frame force f_B (N) as a control with cost
        ∫ f_Bᵀ f_B/m dt, at rest at the origin at both ends (gmuk's final pose fixes the
        position too). The optimum is the same (f = 0); the NLP is about twice the size.

    Returns
    -------
    HandResult
        States y = (q_w, q_x, q_y, q_z, ω_x, ω_y, ω_z[, r_N, v_B]) and controls
        u = L (N m)[, f_B (N)] at the nodes.
    """
    tic = time.perf_counter()
    n_y, n_u = (13, 6) if translation else (7, 3)
    col = _Collocation(n_y, n_u, n_elements, degree, t_final)
    J = ca.DM(inertia)
    J_inv = ca.DM(np.linalg.inv(inertia))

    def rhs(y: Any, u: Any) -> Any:
        q, omega = y[:4], y[4:7]
        q_dot = 0.5 * _quat_mul(q, ca.vertcat(0.0, omega))
        omega_dot = J_inv @ (u[:3] - ca.cross(omega, J @ omega))
        if not translation:
            return ca.vertcat(q_dot, omega_dot)
        v = y[10:13]
        # R(q) v = v + 2 q_w (q_v × v) + 2 q_v × (q_v × v) for a unit quaternion
        qv_x_v = ca.cross(q[1:4], v)
        r_dot = v + 2.0 * q[0] * qv_x_v + 2.0 * ca.cross(q[1:4], qv_x_v)
        v_dot = ca.cross(v, omega) + u[3:] / SLEW_MASS
        return ca.vertcat(q_dot, omega_dot, r_dot, v_dot)

    def running_cost(y: Any, u: Any) -> Any:
        cost = u[:3].T @ (J_inv @ u[:3])
        return cost + ca.sumsqr(u[3:]) / SLEW_MASS if translation else cost

    w, g_dyn, f = col.nlp(col.element_function(rhs, running_cost), symbols)
    n_hat = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    phi = angle * n_hat
    q_final = np.concatenate(([np.cos(0.5 * angle)], np.sin(0.5 * angle) * n_hat))
    q_conj = ca.DM(q_final * np.array([1.0, -1.0, -1.0, -1.0]))
    N, nz = col.n_nodes, col.n_z
    q_end = w[(N - 1) * nz : (N - 1) * nz + 4]
    g = ca.vertcat(g_dyn, _quat_mul(q_conj, q_end)[1:])
    lbw = np.full((N, nz), -np.inf)
    ubw = np.full((N, nz), np.inf)
    lbw[0, :n_y] = ubw[0, :n_y] = 0.0
    lbw[0, 0] = ubw[0, 0] = 1.0  # at rest, identity (and at the origin)
    lbw[-1, 4:n_y] = ubw[-1, 4:n_y] = 0.0  # at rest at the end (and at the origin)
    s = col.times() / t_final
    guess = np.zeros((N, nz))
    guess[:, 0] = np.cos(0.5 * angle * s)
    guess[:, 1:4] = np.sin(0.5 * angle * s)[:, None] * n_hat
    guess[:, 4:7] = phi / t_final
    guess[-1, 4:7] = 0.0  # inside the bounds (r, v and f: 0)
    zeros = np.zeros(g.shape[0])
    bounds = (lbw.reshape(-1), ubw.reshape(-1), zeros, zeros)
    return _solve("slew_mapped", col, w, f, g, bounds, guess.reshape(-1), tic)


# ---------------------------------------------------------------------- checks
def main() -> None:
    """Print the agreement of the mapped transcriptions with their references."""
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    sys.path.insert(0, str(root / "tests" / "optimize"))
    sys.path.insert(0, str(root / "benchmarks"))
    from handwritten_lobatto import solve_smd

    for p in (3, 4):
        ours = smd_mapped(150, p)
        ref = solve_smd(n_elements=150, degree=p)
        rel = abs(ours.objective - ref["objective"]) / abs(ref["objective"])
        print(
            f"SMD 150 × p={p}: mapped {ours.objective:.12f} ({ours.status}, {ours.iterations} "
            f"it), handwritten_lobatto {ref['objective']:.12f}: relative difference {rel:.1e}"
        )
    from bench_optimize import slew_rows

    ours = slew_mapped(40, 4)
    norm_drift = np.abs(np.linalg.norm(ours.y[:, :4], axis=1) - 1.0).max()
    gmuk_objective = slew_rows((40,))[0]["objective"]
    rel = abs(ours.objective - gmuk_objective) / gmuk_objective
    print(
        f"slew 40 × p=4: mapped {ours.objective:.12e} ({ours.status}, {ours.iterations} it, "
        f"max | ‖q‖ − 1 | = {norm_drift:.1e}), gmuk {gmuk_objective:.12e}: relative "
        f"difference {rel:.1e}"
    )


if __name__ == "__main__":
    main()
