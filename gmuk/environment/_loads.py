"""Calling a force kernel (signature :data:`gmuk.forces.base.FORCE_KERNEL`) from Python with
parameters that depend on the time, as the environment's models do: their perturber, Sun and
occulter positions come from the ephemerides at ``epoch + t`` and are passed in ``p``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.errors import DomainError
from gmuk.forces.base import kernel_arguments

if TYPE_CHECKING:
    from gmuk.bodies import Body

_NO_FIELD = np.zeros(1)
_NO_FIELD.setflags(write=False)


def call_load(
    kernel: Any,
    rigid: bool,
    t: float,
    x: Any,
    v: Any,
    body: Body,
    params: Any,
    data: Any = None,
    who: str = "",
) -> FloatArray:
    """``kernel`` on one body: the body-frame wrench [L; f] (6,) of a rigid body at pose
    ``x`` = g_NB (4, 4) with twist ``v`` = V_B, or the force f_N (3,) on a point mass at
    ``x`` = r_N with velocity ``v`` = v_N; arguments laid out as the compiled loop lays them
    out (:meth:`gmuk.forces.base.ForceModel._kernel_load`). A nonzero status raises a
    DomainError naming ``who``."""
    g, V, J, out = kernel_arguments(rigid, x, v, body)
    p = np.array(params, dtype=float)
    field = _NO_FIELD if data is None else data
    status = kernel(rigid, float(t), g, V, float(body.mass), J, p, field, out)
    if status != 0:
        raise DomainError(
            f"{who}: the force has no finite value at r_N = {g[:3, 3].tolist()} m, "
            f"t = {t!r} s (kernel status {status})"
        )
    return out
