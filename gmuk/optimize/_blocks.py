"""The NLP of a mapped transcription as blocks, and its derivatives assembled from the
blocks' own.

A *block* is one small CasADi SX function ``(w, a) → (o, c)`` applied to K instances: w the
instance's decision variables (a gather of entries of the NLP's x), a its other inputs
(parameters, node times), o its outputs that are rows of the constraint vector g, c its
share of the cost. A collocation element is a block; so are the attitude-continuity rows
between two elements and the final-attitude rows.

Every row of g and the whole cost come from blocks, so the NLP's derivatives are sums of
the blocks' derivatives:

    ∂g/∂x = Σ_k S_k ∂o/∂w (w_k) G_k,     ∇f = Σ_k G_kᵀ ∂c/∂w (w_k),
    ∇²_xx (σ f + λᵀ g) = Σ_k G_kᵀ ∇²_ww (σ c + λ_kᵀ o)(w_k) G_k,

with G_k the 0/1 gather of w_k from x, S_k the scatter of o_k into g and λ_k the
multipliers of the instance's rows. The blocks' Jacobian, gradient and Hessian are
differentiated once, symbolically, on one instance (SX: a flat scalar graph of a few
hundred operations), mapped over the K instances, and their nonzeros summed into the NLP's
sparse matrices by one constant 0/1 matrix. This is what a hand-written transcription
gains by writing the derivative of one element; CasADi's own derivatives of the mapped
NLP sweep the whole mesh once per colour of the sparsity pattern instead (measured on the
benchmarks of ``benchmarks/bench_optimize_peers.py``: ``benchmarks/README.md``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

FloatArray = np.ndarray


@dataclass
class Block:
    """One SX function over K instances.

    Attributes
    ----------
    fn : casadi.Function
        ``(w (n_w), a (n_a)) → (o (n_o), c (1))``, SX.
    w_index : ndarray (K, n_w) of int
        Index in x of each entry of w, per instance (no index twice in one instance).
    a_values : casadi.MX or DM (n_a, K)
        The other inputs, per instance.
    rows : ndarray (K, n_o) of int
        Row of g of each output, per instance; −1 for an output that is not a row.
    """

    fn: Any
    w_index: np.ndarray
    a_values: Any
    rows: np.ndarray

    @property
    def K(self) -> int:
        return int(self.w_index.shape[0])

    def gathered(self, x: Any) -> Any:
        """w of every instance (n_w × K) from the NLP's x (MX)."""
        import casadi as ca

        return ca.reshape(x[self.w_index.reshape(-1).tolist()], self.w_index.shape[1], self.K)


def _nonzeros(M: Any) -> tuple[Any, np.ndarray, np.ndarray]:
    """The nonzeros of an SX matrix as a column, with their rows and columns."""
    import casadi as ca

    rows, cols = M.sparsity().get_triplet()
    return ca.vertcat(*M.nonzeros()) if M.nnz() else ca.SX(0, 1), np.array(rows), np.array(cols)


def _assembled(
    n_rows: int, n_cols: int, rows: list[np.ndarray], cols: list[np.ndarray], values: list[Any]
) -> Any:
    """The sparse n_rows × n_cols MX matrix with each entry of the concatenated ``values``
    added at its (row, column) of the concatenated ``rows`` and ``cols``."""
    import casadi as ca

    r = np.concatenate(rows) if rows else np.zeros(0, dtype=int)
    c = np.concatenate(cols) if cols else np.zeros(0, dtype=int)
    key = c.astype(np.int64) * n_rows + r
    unique, position = np.unique(key, return_inverse=True)  # sorted: column-major order
    columns = unique // n_rows
    colind = np.searchsorted(columns, np.arange(n_cols + 1))
    sp = ca.Sparsity(n_rows, n_cols, colind.tolist(), (unique % n_rows).tolist())
    nonzeros = ca.vertcat(*values) if values else ca.MX(0, 1)
    if unique.size == key.size:  # no entry shared: a permutation
        order = np.empty(key.size, dtype=int)
        order[position] = np.arange(key.size)
        return ca.MX(sp, nonzeros[order.tolist()])
    # entry e of the values adds to nonzero position[e]: one nonzero per column
    summing = ca.DM(
        ca.Sparsity(unique.size, key.size, list(range(key.size + 1)), position.tolist()), 1.0
    )
    return ca.MX(sp, ca.densify(summing @ nonzeros))


def derivative_functions(
    blocks: list[Block], x: Any, p: Any, n_g: int
) -> tuple[Any, Any, dict[str, Any]]:
    """f and g of the NLP, and the functions ``grad_f``, ``jac_g`` and ``hess_lag`` of
    CasADi's ``nlpsol`` assembled from the blocks' derivatives (module docstring).

    Parameters
    ----------
    blocks : list of Block
        Together they produce every row of g (each row once) and the whole cost.
    x, p : casadi.MX
        The NLP's variables and parameters (symbols).
    n_g : int
        Rows of g.
    """
    import casadi as ca

    n_x = int(x.shape[0])
    lam_f = ca.MX.sym("lam_f")
    lam_g = ca.MX.sym("lam_g", n_g)
    lam_padded = ca.vertcat(lam_g, 0.0)  # index n_g: the multiplier of an output not in g

    g_rows: list[np.ndarray] = []
    g_values: list[Any] = []
    f: Any = ca.MX(0.0)
    jac: tuple[list[Any], list[Any], list[Any]] = ([], [], [])
    grad: tuple[list[Any], list[Any]] = ([], [])
    hess: tuple[list[Any], list[Any], list[Any]] = ([], [], [])
    for b in blocks:
        K, n_w = b.w_index.shape
        n_o = b.rows.shape[1]
        w = ca.SX.sym("w", n_w)
        a = ca.SX.sym("a", b.fn.size1_in(1))
        o, c = b.fn(w, a)
        W = b.gathered(x)
        O, C = b.fn.map(K)(W, b.a_values)
        f = f + ca.sum2(C)
        flat = b.rows.reshape(-1)  # instance-major, as vec(O)
        kept = np.flatnonzero(flat >= 0)
        g_rows.append(flat[kept])
        g_values.append(ca.vec(O)[kept.tolist()])

        # ∂o/∂w per instance → rows of g, columns of x
        J, jr, jc = _nonzeros(ca.jacobian(o, w))
        if jr.size:
            Jnz = ca.Function("block_jac", [w, a], [J]).map(K)(W, b.a_values)
            gr = b.rows[:, jr]  # (K, nnz)
            gc = b.w_index[:, jc]
            keep = (gr >= 0).reshape(-1)
            jac[0].append(gr.reshape(-1)[keep])
            jac[1].append(gc.reshape(-1)[keep])
            jac[2].append(ca.vec(Jnz)[np.flatnonzero(keep).tolist()])
        # ∂c/∂w
        G, gi, _ = _nonzeros(ca.gradient(c, w))
        if gi.size:
            Gnz = ca.Function("block_grad", [w, a], [G]).map(K)(W, b.a_values)
            grad[0].append(b.w_index[:, gi].reshape(-1))
            grad[1].append(ca.vec(Gnz))
        # ∇²(σ c + λᵀ o), upper triangle in x's numbering
        sigma = ca.SX.sym("sigma")
        lam_o = ca.SX.sym("lam_o", n_o)
        H, hr, hc = _nonzeros(ca.hessian(sigma * c + ca.dot(lam_o, o), w)[0])
        if hr.size:
            index = np.where(b.rows >= 0, b.rows, n_g)
            Lam = ca.reshape(lam_padded[index.reshape(-1).tolist()], n_o, K)
            Hnz = ca.Function("block_hess", [w, a, sigma, lam_o], [H]).map(K)(
                W, b.a_values, ca.repmat(lam_f, 1, K), Lam
            )
            xr, xc = b.w_index[:, hr], b.w_index[:, hc]
            upper = (xr <= xc).reshape(-1)
            hess[0].append(xr.reshape(-1)[upper])
            hess[1].append(xc.reshape(-1)[upper])
            hess[2].append(ca.vec(Hnz)[np.flatnonzero(upper).tolist()])

    order = np.argsort(np.concatenate(g_rows), kind="stable")
    rows_all = np.concatenate(g_rows)
    if rows_all.size != n_g or not np.array_equal(rows_all[order], np.arange(n_g)):
        raise AssertionError("the blocks must produce every row of g once")
    g = ca.vertcat(*g_values)[order.tolist()] if n_g else ca.MX(0, 1)

    jac_g = _assembled(n_g, n_x, *jac)
    grad_f = ca.densify(
        _assembled(n_x, 1, grad[0], [np.zeros(len(r), dtype=int) for r in grad[0]], grad[1])
    )
    hess_l = _assembled(n_x, n_x, *hess)
    functions = {
        "grad_f": ca.Function("nlp_grad_f", [x, p], [f, grad_f]),
        "jac_g": ca.Function("nlp_jac_g", [x, p], [g, jac_g]),
        "hess_lag": ca.Function("nlp_hess_l", [x, p, lam_f, lam_g], [hess_l]),
    }
    return f, g, functions
