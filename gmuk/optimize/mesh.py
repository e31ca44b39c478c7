"""The collocation mesh: elements of a time span, each with its LGL degree."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gmuk._validation import FloatArray, check_sequence, real_number, real_sequence, strict_integer
from gmuk.errors import DefinitionError
from gmuk.optimize.lgl import _degree, lgl_nodes

__all__ = ["MAX_NODES", "Mesh"]


#: Default upper bound on a mesh's distinct nodes (Σ p_k + 1). The NLP has 9 to 15
#: unknowns per node and body; building it for one point mass on 1.5·10⁵ nodes took 100 s
#: and 4.8 GB (CasADi's derivatives and IPOPT's set-up). A larger mesh is refused unless
#: asked for with ``max_nodes=`` (see :class:`Mesh`).
MAX_NODES = 200_000


@dataclass(frozen=True, eq=False)
class Mesh:
    """Elements ``[t_k, t_{k+1}]`` of a time span, element k carrying ``p_k + 1`` LGL nodes.

    Neighbouring elements share their boundary node, so a mesh of K elements of degree p
    has ``K p + 1`` distinct nodes. A single element of degree 4 is the thesis's 5-point
    Lobatto element (McCann 2020, §6.4).

    Parameters
    ----------
    breaks : array_like (K + 1,)
        Strictly increasing, finite element boundaries (s): a 1-D sequence of real
        numbers (strings, booleans, complex numbers and arrays of more than one axis are
        refused, not converted). Each element must be wide enough for its LGL nodes to be
        distinct times in float64.
    degrees : int or sequence of int (K,)
        LGL degree p of each element, an integer in [1, 400].
    max_nodes : int
        Largest number of distinct nodes accepted (default :data:`MAX_NODES`, 2·10⁵): a
        guard against meshes too large to transcribe in memory. Raise it explicitly for a
        larger mesh; :meth:`OptimalControlProblem.solve
        <gmuk.optimize.OptimalControlProblem.solve>` still keeps to its time budget.

    Raises
    ------
    DefinitionError
        For breaks or degrees that are not as above, or a mesh of more than ``max_nodes``
        nodes (the message says how to allow it).
    """

    breaks: FloatArray
    degrees: tuple[int, ...]

    def __init__(
        self, breaks: Any, degrees: int | Sequence[int] = 3, *, max_nodes: int = MAX_NODES
    ) -> None:
        limit = _max_nodes(max_nodes)
        b = real_sequence(breaks, "mesh breaks (s)", min_size=2).copy()
        k = b.size - 1
        with np.errstate(over="ignore"):  # a span beyond float64 is refused just below
            widths = np.diff(b)
        if not np.all(widths > 0.0) or not np.all(np.isfinite(widths)):
            j = int(np.argmin(np.where(np.isfinite(widths), widths, -np.inf)))
            raise DefinitionError(
                "mesh breaks (s) must be strictly increasing with a finite span; got "
                f"breaks[{j}] = {b[j]!r}, breaks[{j + 1}] = {b[j + 1]!r}"
            )
        if isinstance(degrees, (Sequence, np.ndarray)) and not isinstance(degrees, (str, bytes)):
            seq = check_sequence(degrees, "mesh degrees")
            if len(seq) != k:
                raise DefinitionError(f"a mesh of {k} elements needs {k} degrees; got {len(seq)}")
            degs = tuple(_degree(p) for p in seq)
        else:
            degs = (_degree(degrees),) * k
        n_nodes = sum(degs) + 1
        if n_nodes > limit:
            raise DefinitionError(_too_many(k, n_nodes, limit))
        _check_node_spacing(b, widths, degs)
        b.setflags(write=False)
        object.__setattr__(self, "breaks", b)
        object.__setattr__(self, "degrees", degs)
        first = np.zeros(k + 1, dtype=np.int64)
        np.cumsum(degs, out=first[1:])
        first.setflags(write=False)
        object.__setattr__(self, "_first", first)  # element k's first node: O(1) look-ups

    @classmethod
    def uniform(
        cls,
        t0: float,
        tf: float,
        n_elements: int,
        degree: int = 3,
        *,
        max_nodes: int = MAX_NODES,
    ) -> Mesh:
        """``n_elements`` equal elements of ``degree`` on [t0, tf] (s).

        ``n_elements`` is an integer ≥ 1 (an integral float such as ``10.0`` is taken),
        ``degree`` an integer in [1, 400], and the mesh may have at most ``max_nodes``
        distinct nodes ``n_elements · degree + 1`` (default :data:`MAX_NODES`; checked
        before anything is allocated). Raises :class:`DefinitionError` otherwise.
        """
        t0 = real_number(t0, "t0")
        tf = real_number(tf, "tf")
        n = strict_integer(n_elements, "n_elements", minimum=1, integral_floats=True)
        p = _degree(degree)
        limit = _max_nodes(max_nodes)
        if n * p + 1 > limit:
            raise DefinitionError(_too_many(n, n * p + 1, limit))
        if not tf > t0:
            raise DefinitionError(f"the time span must have tf > t0; got [{t0}, {tf}]")
        with np.errstate(over="ignore"):
            span = tf - t0
        if not np.isfinite(span):
            raise DefinitionError(f"the time span tf − t0 must be finite; got [{t0}, {tf}]")
        return cls(np.linspace(t0, tf, n + 1), p, max_nodes=limit)

    @property
    def n_elements(self) -> int:
        """Number of elements K."""
        return len(self.degrees)

    @property
    def n_nodes(self) -> int:
        """Number of distinct nodes, ``Σ p_k + 1``."""
        return sum(self.degrees) + 1

    @property
    def t0(self) -> float:
        """Start of the span (s)."""
        return float(self.breaks[0])

    @property
    def tf(self) -> float:
        """End of the span (s)."""
        return float(self.breaks[-1])

    def first_node(self, k: int) -> int:
        """Index of element k's first node among the distinct nodes."""
        return int(self._first[k])  # type: ignore[attr-defined]

    def element_times(self, k: int) -> FloatArray:
        """The LGL node times of element k (p_k + 1,) (s)."""
        x, _ = lgl_nodes(self.degrees[k])
        a, b = self.breaks[k], self.breaks[k + 1]
        return 0.5 * (a + b) + 0.5 * (b - a) * x

    def _by_degree(self) -> list[tuple[int, np.ndarray, np.ndarray]]:
        """(p, the elements of degree p, their node indices (n, p + 1)) per degree."""
        degs = np.asarray(self.degrees)
        first = self._first[:-1]  # type: ignore[attr-defined]
        out = []
        for p in sorted(set(self.degrees)):
            ks = np.flatnonzero(degs == p)
            out.append((p, ks, first[ks][:, None] + np.arange(p + 1)[None, :]))
        return out

    @property
    def times(self) -> FloatArray:
        """All distinct node times (n_nodes,) (s), increasing (a node shared by two
        elements as the earlier one computes it; the last node is tf exactly)."""
        t = np.empty(self.n_nodes)
        a, b = self.breaks[:-1], self.breaks[1:]
        for p, ks, idx in self._by_degree():
            x, _ = lgl_nodes(p)
            tk = 0.5 * (a[ks] + b[ks])[:, None] + 0.5 * (b[ks] - a[ks])[:, None] * x[None, :]
            t[idx[:, 1:]] = tk[:, 1:]
            if ks[0] == 0:
                t[0] = tk[0, 0]
        t[-1] = self.breaks[-1]
        return t

    @property
    def quadrature_weights(self) -> FloatArray:
        """Weights W (n_nodes,) (s) of ``∫ f dt ≈ Σ W_i f(t_i)``: each element's
        ``(h_k/2) w_j`` summed at the shared boundary nodes."""
        W = np.zeros(self.n_nodes)
        h = np.diff(self.breaks)
        for p, ks, idx in self._by_degree():
            _, w = lgl_nodes(p)
            np.add.at(W, idx, 0.5 * h[ks][:, None] * w[None, :])
        return W

    def element_of(self, t: Any) -> np.ndarray:
        """Index of the element holding each time t (s), finite and within [t0, tf] to a
        relative 1e-9 (the last element holds tf)."""
        tt = self.check_times(t)
        k = np.searchsorted(self.breaks, tt, side="right") - 1
        out: np.ndarray = np.clip(k, 0, self.n_elements - 1)
        return out[0] if np.ndim(t) == 0 else out

    def check_times(self, t: Any) -> FloatArray:
        """``t`` (a number or a 1-D sequence) as a 1-D float array, or a
        :class:`DefinitionError` if it is not finite real numbers within [t0, tf] (to a
        relative 1e-9)."""
        if np.ndim(t) == 0 and not isinstance(t, (str, bytes)):
            tt = np.array([real_number(t, "t (s)")])
        else:
            tt = real_sequence(t, "times t (s)")
        lo = self.t0 - 1e-9 * max(1.0, abs(self.t0))
        hi = self.tf + 1e-9 * max(1.0, abs(self.tf))
        if tt.size and (tt.min() < lo or tt.max() > hi):
            raise DefinitionError(
                f"times must lie in [{self.t0:g}, {self.tf:g}] s; got [{tt.min():g}, {tt.max():g}]"
            )
        return tt

    def split(self, parts: Sequence[int], *, max_nodes: int = MAX_NODES) -> Mesh:
        """A mesh with element k split into ``parts[k]`` equal elements (an integer ≥ 1)
        of its degree; at most ``max_nodes`` distinct nodes (checked before building)."""
        counts = check_sequence(parts, "split counts")
        if len(counts) != self.n_elements:
            raise DefinitionError(
                f"split needs one count per element ({self.n_elements}); got {len(counts)}"
            )
        ns = [
            strict_integer(n, f"split count of element {k}", minimum=1)
            for k, n in enumerate(counts)
        ]
        limit = _max_nodes(max_nodes)
        n_nodes = sum(n * p for n, p in zip(ns, self.degrees, strict=True)) + 1
        if n_nodes > limit:
            raise DefinitionError(_too_many(sum(ns), n_nodes, limit))
        breaks = [self.breaks[0]]
        degrees: list[int] = []
        for k, n in enumerate(ns):
            a, b = self.breaks[k], self.breaks[k + 1]
            breaks += list(a + (b - a) * np.arange(1, n + 1) / n)
            degrees += [self.degrees[k]] * n
        breaks[-1] = self.breaks[-1]
        return Mesh(np.array(breaks), degrees, max_nodes=limit)

    def __repr__(self) -> str:
        degs = set(self.degrees)
        deg = str(degs.pop()) if len(degs) == 1 else "mixed"
        return (
            f"Mesh({self.n_elements} elements of degree {deg} on "
            f"[{self.t0:g}, {self.tf:g}] s, {self.n_nodes} nodes)"
        )


def _max_nodes(value: Any) -> int:
    return strict_integer(value, "max_nodes", minimum=2)


def _too_many(n_elements: int, n_nodes: int, limit: int) -> str:
    return (
        f"a mesh of {n_elements} elements has {n_nodes} nodes, more than max_nodes = {limit} "
        f"(each node adds 9 to 15 NLP unknowns per body); pass max_nodes={n_nodes} "
        "explicitly to allow it"
    )


def _check_node_spacing(b: FloatArray, widths: FloatArray, degrees: tuple[int, ...]) -> None:
    """Every element wide enough that its LGL node times are distinct in float64."""
    gap = {p: float(np.diff(lgl_nodes(p)[0]).min()) for p in set(degrees)}
    g = np.array([gap[p] for p in degrees]) if len(gap) > 1 else gap[degrees[0]]
    spacing = 0.5 * widths * g  # smallest distance between two nodes of each element (s)
    scale = np.maximum(np.abs(b[:-1]), np.abs(b[1:]))
    ok = spacing > np.maximum(64.0 * np.finfo(float).eps * scale, 1e3 * np.finfo(float).tiny)
    if not np.all(ok):
        k = int(np.argmin(ok))
        raise DefinitionError(
            f"mesh element {k}, [{b[k]!r}, {b[k + 1]!r}] s of degree {degrees[k]}, is too "
            f"narrow: its LGL nodes, {spacing[k]:.3g} s "
            "apart, are not distinct times in float64"
        )


def split_counts(errors: FloatArray, tol: float, degree: Sequence[int], most: int = 4) -> list[int]:
    """How many pieces each element is cut into: ``⌈(e/tol)^(1/(p+1))⌉`` (≥ 2, ≤ ``most``)
    where the error estimate e exceeds tol, 1 elsewhere (the local error of a degree-p
    element falls like h^(p+1))."""
    out = []
    for e, p in zip(errors, degree, strict=True):
        if e > tol:
            out.append(int(min(most, max(2, math.ceil((e / tol) ** (1.0 / (p + 1)))))))
        else:
            out.append(1)
    return out
