"""A step of the compiled loop's method taken again, for locating events
(:mod:`gmuk.engine.events`).

The loop (:func:`gmuk.engine.integrators._compiled.advance`) keeps no stages of its accepted
steps. When an event changes sign over a step, the driver takes that step once more from its
start with these functions, which are the loop's own helpers (the same stage sums, right-hand
side and continuous extension, nothing written twice):

* :func:`dense_step`: the step's stages and DOP853's continuous extension ``F`` (the loop's
  ``_extension``), evaluated at any point of the step by :func:`interpolate`;
* :func:`method_step`: one step of the method of any length ``h`` from the step's start,
  for methods without a continuous extension (DOPRI5, RK4): the state at ``t + h`` as that
  method computes it, to its order.

Each is compiled once per machine into numba's cache, on first use, apart from the loop (4.6 s
on the shared 2-core box, then 0.23 s to load in a new process: benchmarks/README.md,
"Events in simulate").
"""

from __future__ import annotations

import numpy as np

from gmuk._numba import njit
from gmuk.engine.integrators._compiled import (
    DONE,
    I_RHS,
    I_RHS_KERNEL,
    _call_rhs,
    _extension,
    _fail,
    _interpolate,
    _stage_state,
    aux_size_of,
)

__all__ = ["dense_step", "interpolate", "method_step"]


@njit(cache=True)
def method_step(parts, m, fs, ints, t, h, Y, G0, f0, K, Y1):  # type: ignore[no-untyped-def]
    """One step of size h from (t, Y, G0) with f0 = f(t, Y): the stages into K (rows 0 to
    n_stages − 1) and the new state into Y1 (ξ about G0). Returns the loop's status."""
    n = Y.shape[0]
    for j in range(n):
        K[0, j] = f0[j]
    aux = np.empty(aux_size_of(parts.dims))
    Yt = np.empty(n)
    for i in range(1, m.n_stages):
        _stage_state(Y, h, m.A[i], K, i, Yt)
        ints[I_RHS] += 1
        status = _call_rhs(ints[I_RHS_KERNEL], (t + m.c[i] * h, Yt, G0, parts, K[i], aux, ints))
        if status != DONE:
            return _fail(status, t + m.c[i] * h, fs, ints)
    _stage_state(Y, h, m.b, K, m.n_stages, Y1)
    return DONE


@njit(cache=True)
def dense_step(parts, m, fs, ints, t, h, Y, G0, f0, K, Y1, F):  # type: ignore[no-untyped-def]
    """The step of size h from (t, Y, G0) (:func:`method_step`), f at its end into
    K[n_stages], and DOP853's continuous extension into F. Returns the loop's status."""
    status = method_step(parts, m, fs, ints, t, h, Y, G0, f0, K, Y1)
    if status != DONE:
        return status
    aux = np.empty(aux_size_of(parts.dims))
    ints[I_RHS] += 1
    status = _call_rhs(ints[I_RHS_KERNEL], (t + h, Y1, G0, parts, K[m.n_stages], aux, ints))
    if status != DONE:
        return _fail(status, t + h, fs, ints)
    return _extension(t, h, Y, Y1, K, G0, parts, m, fs, ints, F)


@njit(cache=True)
def interpolate(F, Y0, s, out):  # type: ignore[no-untyped-def]
    """DOP853's continuous extension at s = (t − t₀)/h into ``out`` (the loop's)."""
    _interpolate(F, Y0, s, out)
