"""An independent, hand-written CasADi + IPOPT transcription of the bounded spring–mass–damper
(not a test module): the reference that gmuk.optimize is checked and timed against.

Written straightforwardly and separately from gmuk.optimize, sharing none of its code:

    minimise ∫ u²/m dt  subject to  ẋ = v,  m v̇ = −k x − b v + u,  l ≤ x ≤ h,
    x(0) = x0, v(0) = v0, final state free,

on ``n_elements`` equal elements, each with the p + 1 Legendre–Gauss–Lobatto nodes (the ends
and the roots of P'_p from numpy's Legendre module), states and controls at every node
(shared between neighbouring elements), the dynamics in integral form (Lobatto IIIA):
``z_j = z_0 + Σ_l a_jl f_l`` with ``a_jl = ∫_{t_k}^{t_j} ℓ_l(t) dt`` of the Lagrange
polynomials ℓ_l built with numpy's Polynomial class, and the cost by the same quadrature
(``a_pl``). The bound on x is a bound on the x variables of every node but the first.
"""

from __future__ import annotations

import time

import casadi as ca
import numpy as np
from numpy.polynomial import Polynomial
from numpy.polynomial import legendre as npleg


def lobatto_nodes(p: int) -> np.ndarray:
    """The LGL nodes on [−1, 1]: the ends and the roots of P'_p."""
    c = np.zeros(p + 1)
    c[p] = 1.0
    inner = np.sort(npleg.legroots(npleg.legder(c))) if p > 1 else np.zeros(0)
    return np.concatenate([[-1.0], inner, [1.0]])


def integration_weights(tau: np.ndarray) -> np.ndarray:
    """a[j, l] = ∫_{τ_0}^{τ_j} ℓ_l, ℓ_l the Lagrange polynomials of the nodes τ."""
    n = tau.size
    a = np.zeros((n, n))
    for l in range(n):
        others = np.delete(tau, l)
        ell = Polynomial.fromroots(others) / np.prod(tau[l] - others)
        L = ell.integ()
        a[:, l] = L(tau) - L(tau[0])
    return a


def solve_smd(
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
) -> dict:
    """Solve the bounded SMD; returns the objective, the node times and values, IPOPT's
    status and the times of the transcription and of the solve (s)."""
    tic = time.perf_counter()
    p = degree
    tau = lobatto_nodes(p)
    h = t_final / n_elements
    a = integration_weights(tau) * (h / 2.0)  # on an element of length h
    n_nodes = n_elements * p + 1
    x = ca.SX.sym("x", n_nodes)
    v = ca.SX.sym("v", n_nodes)
    u = ca.SX.sym("u", n_nodes)
    f_x = v
    f_v = (-k * x - b * v + u) / m
    eqs = []
    cost = 0
    for e in range(n_elements):
        i0 = e * p
        for j in range(1, p + 1):
            eqs.append(x[i0 + j] - x[i0] - sum(a[j, l] * f_x[i0 + l] for l in range(p + 1)))
            eqs.append(v[i0 + j] - v[i0] - sum(a[j, l] * f_v[i0 + l] for l in range(p + 1)))
        cost += sum(a[p, l] * u[i0 + l] ** 2 / m for l in range(p + 1))
    w = ca.vertcat(x, v, u)
    g = ca.vertcat(*eqs)
    lbx = np.full(3 * n_nodes, -np.inf)
    ubx = np.full(3 * n_nodes, np.inf)
    lbx[1:n_nodes] = lower
    ubx[1:n_nodes] = upper
    lbx[0] = ubx[0] = x0
    lbx[n_nodes] = ubx[n_nodes] = v0
    solver = ca.nlpsol(
        "smd",
        "ipopt",
        {"x": w, "f": cost, "g": g},
        {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.tol": 1e-8},
    )
    guess = np.concatenate([np.full(n_nodes, x0), np.full(n_nodes, v0), np.zeros(n_nodes)])
    guess[:n_nodes] = np.clip(guess[:n_nodes], lower, upper)
    built = time.perf_counter() - tic
    tic = time.perf_counter()
    sol = solver(x0=guess, lbx=lbx, ubx=ubx, lbg=0.0, ubg=0.0)
    solve_s = time.perf_counter() - tic
    out = np.asarray(sol["x"]).reshape(-1)
    times = np.concatenate([[0.0]] + [e * h + (tau[1:] + 1.0) * h / 2.0 for e in range(n_elements)])
    return {
        "objective": float(sol["f"]),
        "status": solver.stats()["return_status"],
        "t": times,
        "x": out[:n_nodes],
        "v": out[n_nodes : 2 * n_nodes],
        "u": out[2 * n_nodes :],
        "transcription_s": built,
        "solve_s": solve_s,
        "total_s": built + solve_s,
    }
