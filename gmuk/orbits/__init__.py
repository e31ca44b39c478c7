"""Orbits: Kepler's equation for every conic, orbital elements ↔ state, Keplerian motion and
the modified-LVLH reference trajectory of McCann (2020), Section 4.1.2 (corrected, errata).

Modules
-------
kepler
    Mean, eccentric/parabolic/hyperbolic and true anomalies (Eqs. 75–78), vectorised.
elements
    Classical elements ↔ inertial position and velocity (any conic).
conics
    :class:`KeplerOrbit`: position, velocity, acceleration, f, ḟ, f̈ at time t.
lvlh
    :class:`LVLHReference` (a :class:`gmuk.reference.ReferenceTrajectory`), the corrected
    Eq. 69 attitude, the Section 4.3 orbits and initial condition.
"""

from gmuk.orbits.conics import KeplerOrbit
from gmuk.orbits.elements import (
    CIRCULAR_TOL,
    EQUATORIAL_TOL,
    R_NP,
    OrbitalElements,
    elements_to_state,
    perifocal_state,
    semi_latus_rectum,
    state_to_elements,
)
from gmuk.orbits.kepler import (
    eccentric_from_mean,
    eccentric_from_true,
    hyperbolic_from_mean,
    hyperbolic_from_true,
    mean_from_eccentric,
    mean_from_hyperbolic,
    mean_from_parabolic,
    mean_from_true,
    parabolic_from_mean,
    parabolic_from_true,
    true_from_eccentric,
    true_from_hyperbolic,
    true_from_mean,
    true_from_parabolic,
    wrap_to_2pi,
    wrap_to_pi,
)
from gmuk.orbits.lvlh import (
    MU_MOON_THESIS_CONSISTENT,
    R_PD,
    LVLHReference,
    compose_motion,
    fccn_orbit,
    fcei_orbit,
    section43_initial_state,
    thesis_eq69_R_dP_as_printed,
)

__all__ = [
    "CIRCULAR_TOL",
    "EQUATORIAL_TOL",
    "MU_MOON_THESIS_CONSISTENT",
    "R_NP",
    "R_PD",
    "KeplerOrbit",
    "LVLHReference",
    "OrbitalElements",
    "compose_motion",
    "eccentric_from_mean",
    "eccentric_from_true",
    "elements_to_state",
    "fccn_orbit",
    "fcei_orbit",
    "hyperbolic_from_mean",
    "hyperbolic_from_true",
    "mean_from_eccentric",
    "mean_from_hyperbolic",
    "mean_from_parabolic",
    "mean_from_true",
    "parabolic_from_mean",
    "parabolic_from_true",
    "perifocal_state",
    "section43_initial_state",
    "semi_latus_rectum",
    "state_to_elements",
    "thesis_eq69_R_dP_as_printed",
    "true_from_eccentric",
    "true_from_hyperbolic",
    "true_from_mean",
    "true_from_parabolic",
    "wrap_to_2pi",
    "wrap_to_pi",
]
