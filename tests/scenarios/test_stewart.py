"""gmuk run stewart: the Stewart–Gough platform held by PD legs (gmuk/scenarios/stewart.py)."""

from __future__ import annotations

import json
import math

import numpy as np
from scipy.optimize import brentq

from gmuk import scenarios
from gmuk.cli import main
from gmuk.scenarios import stewart as st


def static_height() -> tuple[float, float]:
    """The platform's equilibrium height (m) and each leg's actuator force (N), from the
    potential energy of the symmetric mechanism as a function of the platform's height z
    (platform level and centred: every leg the same length L(z) = √(ρ² + z²)):
    ``U = m_P g z + 6 [m₁ g (l₁/2) z/L + m₂ g (l₁/2 + s) z/L + ½ k (s − s₀)²]``,
    s = L − (l₁ + l₂)/2; dU/dz (written out) = 0 by Brent's method."""
    b, p = st.base_points(), st.platform_points()
    rho = float(np.hypot(*(p[0, :2] - b[0, :2])))
    lbar = 0.5 * (st.LOWER_LENGTH + st.UPPER_LENGTH)
    s0 = math.hypot(rho, st.HEIGHT) - lbar
    g, k = st.GRAVITY, st.LEG_STIFFNESS

    def dU(z: float) -> float:
        L = math.hypot(rho, z)
        dL = z / L
        s = L - lbar
        u = z / L  # the legs' vertical direction cosine
        du = rho * rho / L**3
        lower = st.LOWER_MASS * g * (st.LOWER_LENGTH / 2) * du
        upper = st.UPPER_MASS * g * ((st.LOWER_LENGTH / 2 + s) * du + dL * u)
        return st.PLATFORM_MASS * g + 6 * (lower + upper + k * (s - s0) * dL)

    z = brentq(dU, st.HEIGHT - 0.05, st.HEIGHT, xtol=1e-15)
    return z, -k * (math.hypot(rho, z) - lbar - s0)


def test_stewart_settles_at_the_static_equilibrium():
    """After 1 s (the PD's time constant is about 0.04 s) the platform hangs level at the
    height where the potential energy is stationary, and each leg pushes with the force that
    holds it, to 1e-9 m and 1e-6 N."""
    result = scenarios.get("stewart").run(duration=1.0)
    s = result.summary
    z_eq, force = static_height()
    assert abs((st.HEIGHT - s["platform_sag_final_m"]) - z_eq) < 1e-9
    np.testing.assert_allclose(s["leg_force_final_N"], force, rtol=0, atol=1e-6)
    assert s["platform_tilt_max_rad"] < 1e-8 and s["platform_horizontal_max_m"] < 1e-8
    assert s["loop_position_residual_max"] < 1e-10 and s["loop_velocity_residual_max"] < 1e-10


def test_gmuk_run_stewart_writes_its_summary_and_figure(tmp_path):
    out = tmp_path / "st"
    assert main(["run", "stewart", "--duration", "0.05", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert 0.0 < summary["platform_sag_final_m"] < 2e-3
    assert len(summary["leg_force_final_N"]) == 6
    assert (out / "sag_forces.png").is_file()
