"""Calling numba kernels without the dispatcher.

Numba's dispatcher resolves the types of a kernel's arguments on every call (≈ 0.3–0.8 µs
here, growing with the number of arguments), more than the arithmetic of a small kernel.
:func:`entry` returns the compiled function of a kernel that has one explicit signature;
it skips that resolution and checks nothing beyond the Python type of each argument: arrays
must be exactly the declared types (dtype, number of dimensions, C-contiguity), or the
kernel reads memory wrongly. Callers check that before taking such a path.
"""

from __future__ import annotations

from typing import Any

__all__ = ["entry"]


def entry(kernel: Any) -> Any:
    """The compiled function of a single-signature kernel, callable without dispatch.

    Falls back to the dispatcher itself (safe, slower) if numba does not expose the
    compiled function or the kernel has more than one signature.
    """
    overloads = list(getattr(kernel, "overloads", {}).values())
    if len(overloads) == 1:
        fn = getattr(overloads[0], "entry_point", None)
        if callable(fn):
            return fn
    return kernel
