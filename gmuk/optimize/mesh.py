"""The collocation mesh: elements of a time span, each with its LGL degree."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gmuk._validation import FloatArray, real_number
from gmuk.errors import DefinitionError
from gmuk.optimize.lgl import _degree, lgl_nodes

__all__ = ["Mesh"]


@dataclass(frozen=True, eq=False)
class Mesh:
    """Elements ``[t_k, t_{k+1}]`` of a time span, element k carrying ``p_k + 1`` LGL nodes.

    Neighbouring elements share their boundary node, so a mesh of K elements of degree p
    has ``K p + 1`` distinct nodes. A single element of degree 4 is the thesis's 5-point
    Lobatto element (McCann 2020, §6.4).

    Parameters
    ----------
    breaks : array_like (K + 1,)
        Strictly increasing element boundaries (s).
    degrees : int or sequence of int (K,)
        LGL degree p ≥ 1 of each element.
    """

    breaks: FloatArray
    degrees: tuple[int, ...]

    def __init__(self, breaks: Any, degrees: int | Sequence[int] = 3) -> None:
        b = np.array(breaks, dtype=float).reshape(-1)
        if b.size < 2 or not np.all(np.isfinite(b)) or not np.all(np.diff(b) > 0.0):
            raise DefinitionError(
                f"mesh breaks must be ≥ 2 finite, strictly increasing times (s); got {breaks!r:.80}"
            )
        k = b.size - 1
        if isinstance(degrees, (int, np.integer)) and not isinstance(degrees, bool):
            degs = (_degree(degrees),) * k
        else:
            degs = tuple(_degree(p) for p in degrees)  # type: ignore[union-attr]
            if len(degs) != k:
                raise DefinitionError(f"a mesh of {k} elements needs {k} degrees; got {len(degs)}")
        b.setflags(write=False)
        object.__setattr__(self, "breaks", b)
        object.__setattr__(self, "degrees", degs)

    @classmethod
    def uniform(cls, t0: float, tf: float, n_elements: int, degree: int = 3) -> Mesh:
        """``n_elements`` equal elements of ``degree`` on [t0, tf] (s)."""
        t0 = real_number(t0, "t0")
        tf = real_number(tf, "tf")
        if isinstance(n_elements, bool) or int(n_elements) != n_elements or n_elements < 1:
            raise DefinitionError(f"n_elements must be an integer ≥ 1; got {n_elements!r}")
        if not tf > t0:
            raise DefinitionError(f"the time span must have tf > t0; got [{t0}, {tf}]")
        return cls(np.linspace(t0, tf, int(n_elements) + 1), degree)

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
        return sum(self.degrees[:k])

    def element_times(self, k: int) -> FloatArray:
        """The LGL node times of element k (p_k + 1,) (s)."""
        x, _ = lgl_nodes(self.degrees[k])
        a, b = self.breaks[k], self.breaks[k + 1]
        return 0.5 * (a + b) + 0.5 * (b - a) * x

    @property
    def times(self) -> FloatArray:
        """All distinct node times (n_nodes,) (s), increasing."""
        parts = [self.element_times(0)]
        parts += [self.element_times(k)[1:] for k in range(1, self.n_elements)]
        t = np.concatenate(parts)
        t[-1] = self.breaks[-1]
        return t

    @property
    def quadrature_weights(self) -> FloatArray:
        """Weights W (n_nodes,) (s) of ``∫ f dt ≈ Σ W_i f(t_i)``: each element's
        ``(h_k/2) w_j`` summed at the shared boundary nodes."""
        W = np.zeros(self.n_nodes)
        for k, p in enumerate(self.degrees):
            _, w = lgl_nodes(p)
            i0 = self.first_node(k)
            W[i0 : i0 + p + 1] += 0.5 * (self.breaks[k + 1] - self.breaks[k]) * w
        return W

    def element_of(self, t: FloatArray) -> np.ndarray:
        """Index of the element holding each time (the last element holds tf)."""
        k = np.searchsorted(self.breaks, np.asarray(t, dtype=float), side="right") - 1
        return np.clip(k, 0, self.n_elements - 1)

    def split(self, parts: Sequence[int]) -> Mesh:
        """A mesh with element k split into ``parts[k]`` equal elements (≥ 1) of its degree."""
        if len(parts) != self.n_elements:
            raise DefinitionError(f"split needs one count per element ({self.n_elements})")
        breaks = [self.breaks[0]]
        degrees: list[int] = []
        for k, n in enumerate(parts):
            n = int(n)
            if n < 1:
                raise DefinitionError(f"split counts must be ≥ 1; got {n} for element {k}")
            a, b = self.breaks[k], self.breaks[k + 1]
            breaks += list(a + (b - a) * np.arange(1, n + 1) / n)
            degrees += [self.degrees[k]] * n
        breaks[-1] = self.breaks[-1]
        return Mesh(np.array(breaks), degrees)

    def __repr__(self) -> str:
        degs = set(self.degrees)
        deg = str(degs.pop()) if len(degs) == 1 else "mixed"
        return (
            f"Mesh({self.n_elements} elements of degree {deg} on "
            f"[{self.t0:g}, {self.tf:g}] s, {self.n_nodes} nodes)"
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
