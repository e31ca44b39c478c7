"""SO(3) in local exponential coordinates, written once for numbers and CasADi symbols.

Within an element the attitude is ``R = R_k exp(θ^)``, R_k the attitude at the element's
start, so that ``Ṙ = R ω^`` gives ``θ̇ = J_r(θ)⁻¹ ω`` with the inverse right Jacobian

    J_r(θ)⁻¹ ω = ω + ½ θ × ω + c(θ²) θ × (θ × ω),   c = (1 − (θ/2) cot(θ/2)) / θ²,

and Rodrigues' ``exp(θ^) = I + a θ^ + b θ^²``, a = sin θ / θ, b = (1 − cos θ)/θ².
The coefficients are evaluated as power series in s = θ·θ (entire for a and b; radius
(2π)² for c): smooth at θ = 0, where the closed forms are 0/0, so CasADi differentiates them
without a branch. The series are summed to rounding error for ‖θ‖ ≤ 2.7 rad, which the
transcription guarantees by bounding each component of θ (1.5 rad by default).

References
----------
Bullo & Murray (1995), Proportional derivative control on the Euclidean group (the
exponential map and its differential on SO(3)); Iserles et al. (2000), Lie-group methods,
*Acta Numerica* 9, §2 (dexp⁻¹ as a Bernoulli series).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from scipy.special import zeta

#: Largest ‖θ‖ (rad) for which the series below are summed to rounding error.
SERIES_RADIUS = 2.7

_N_AB = 16
_N_C = 26
#: sin θ/θ = Σ (−1)^k s^k/(2k+1)!,  (1 − cos θ)/θ² = Σ (−1)^k s^k/(2k+2)!
_A = np.array([(-1) ** k / math.factorial(2 * k + 1) for k in range(_N_AB)])
_B = np.array([(-1) ** k / math.factorial(2 * k + 2) for k in range(_N_AB)])
#: c = Σ_{n≥1} |B_2n|/(2n)! s^(n−1), with |B_2n|/(2n)! = 2ζ(2n)/(2π)^(2n)
_C = np.array([2.0 * zeta(2 * n, 1) / (2.0 * math.pi) ** (2 * n) for n in range(1, _N_C + 1)])


def _horner(coeffs: np.ndarray, s: Any) -> Any:
    out: Any = float(coeffs[-1])
    for c in coeffs[-2::-1]:
        out = out * s + float(c)
    return out


def coefficients(s: Any) -> tuple[Any, Any, Any]:
    """a, b, c at s = θ·θ (numbers or CasADi expressions)."""
    if isinstance(s, (int, float, np.floating)):
        return _horner(_A, s), _horner(_B, s), _horner(_C, s)
    return tuple(_coefficients_function()(s))


@functools.cache
def _coefficients_function() -> Any:
    """The three series as one CasADi Function of s, built once: called with SX it expands
    to the same expressions as the Horner loops, without building them again in Python."""
    import casadi as ca

    s = ca.SX.sym("s")
    return ca.Function("so3_series", [s], [_horner(_A, s), _horner(_B, s), _horner(_C, s)])


def exp_numeric(theta: np.ndarray) -> np.ndarray:
    """exp(θ^) (3, 3) for ‖θ‖ ≤ SERIES_RADIUS by the series (as the transcription)."""
    th = np.asarray(theta, dtype=float)
    a, b, _ = coefficients(float(th @ th))
    W = _hat(th)
    return np.eye(3) + a * W + b * (W @ W)


def _hat(w: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def exp_casadi(theta: Any) -> Any:
    """exp(θ^) (3×3 SX) of a 3×1 CasADi column."""
    import casadi as ca

    a, b, _ = coefficients(ca.dot(theta, theta))
    W = ca.skew(theta)
    return ca.SX.eye(3) + a * W + b * (W @ W)


def theta_rate_casadi(theta: Any, omega: Any) -> Any:
    """θ̇ = J_r(θ)⁻¹ ω (3×1) for CasADi columns θ, ω."""
    import casadi as ca

    _, _, c = coefficients(ca.dot(theta, theta))
    tw = ca.cross(theta, omega)
    return omega + 0.5 * tw + c * ca.cross(theta, tw)


def theta_rate_numeric(theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """θ̇ = J_r(θ)⁻¹ ω (3,) for arrays."""
    _, _, c = coefficients(float(theta @ theta))
    tw = np.cross(theta, omega)
    return omega + 0.5 * tw + c * np.cross(theta, tw)
