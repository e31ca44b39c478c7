"""The compiled step loop's entry to the built-in controllers' kernels.

:func:`apply_control` evaluates a controller term the way :mod:`gmuk.forces._kernels`
evaluates a force term: a code, the controller's packed parameters, the body's pose, twist,
modeled acceleration and internal state in, the wrench and the state rate out. The laws
themselves are written once, beside their classes (:func:`gmuk.control.morse_lyapunov.
morse_lyapunov_lvlh`), and the Python methods call the same kernels.
"""

from __future__ import annotations

from gmuk._numba import njit
from gmuk.control.morse_lyapunov import N_LVLH_PARAMS, morse_lyapunov_lvlh

__all__ = ["MORSE_LYAPUNOV_LVLH", "N_PARAMS", "apply_control", "morse_lyapunov_lvlh"]

#: The corrected Morse–Lyapunov law (McCann 2020, Eqs. 81–90 as corrected in
#: docs/errata.rst) tracking an LVLHReference, with or without Eq. 90's κ₂ bound.
MORSE_LYAPUNOV_LVLH = 0

#: Parameters of a MORSE_LYAPUNOV_LVLH term: the orbit [n, e, μ, p, R_NP (9)], then
#: [k11, k12, k21 (3), k22 (3), κ, a (3), k_integral, robust, κ₂, 𝕀 (36)].
N_PARAMS = N_LVLH_PARAMS


@njit(cache=True)
def apply_control(code, t, g, V, a_model, z, p, u, z_dot):  # type: ignore[no-untyped-def]
    """The wrench ``u`` (6,) and state rate ``z_dot`` of controller term ``code`` with
    parameters ``p`` on a body at pose g (4, 4), twist V (6,), modeled acceleration
    ``a_model`` (6,) and internal state z. Returns 0 (or 1 for an unknown code)."""
    if code == MORSE_LYAPUNOV_LVLH:
        morse_lyapunov_lvlh(t, g, V, a_model, z, p, u, z_dot)
        return 0
    return 1
