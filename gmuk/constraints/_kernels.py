"""The compiled step loop's entry to the built-in constraints' kernels.

Each built-in constraint with a compiled form has its rows written once, as a numba kernel
beside its class (:mod:`gmuk.constraints.tracking`, :mod:`gmuk.constraints.relative`), with
the signature ``kernel(t, g_1, V_1, g_2, V_2, p, A, b) -> status``: the rows A (s, 12), b (s,)
of the constraint on its first body (columns 0–5) and its second one (columns 6–11; zero and
``g_2, V_2`` ignored for a one-body constraint). Its ``rows`` calls the same definition, and the
compiled loop (:mod:`gmuk.engine.integrators._compiled`) calls it through :func:`apply_rows`, which
only dispatches on the code :data:`CODES` gives each kernel. A constraint's
:meth:`~gmuk.Constraint._compiled_term` finds its code there.
"""

from __future__ import annotations

from gmuk._numba import njit
from gmuk.constraints.relative import relative_loop_rows
from gmuk.constraints.tracking import lvlh_tracking_rows

__all__ = ["CODES", "RELATIVE", "TRACKING_LVLH", "UNKNOWN_CODE", "apply_rows"]

#: ConfigurationTracking of an LVLHReference (McCann 2020, Eq. 67), Baumgarte terms optional.
TRACKING_LVLH = 0
#: RelativeConstraint with no desired relative motion (Eq. 73).
RELATIVE = 1
#: The status :func:`apply_rows` returns for a code it does not know.
UNKNOWN_CODE = 99

#: The code of each kernel: what a constraint's ``_compiled_term`` hands to :func:`apply_rows`.
CODES = {lvlh_tracking_rows: TRACKING_LVLH, relative_loop_rows: RELATIVE}


@njit(cache=True)
def apply_rows(code, t, g1, V1, g2, V2, p, A, b):  # type: ignore[no-untyped-def]
    """Write one built-in constraint's rows into A (s, 12) and b (s,); returns its kernel's
    status, or :data:`UNKNOWN_CODE`."""
    if code == TRACKING_LVLH:
        return lvlh_tracking_rows(t, g1, V1, g2, V2, p, A, b)
    if code == RELATIVE:
        return relative_loop_rows(t, g1, V1, g2, V2, p, A, b)
    return UNKNOWN_CODE
