"""Built-in constants and a low-degree lunar field (typed in, never downloaded).

Point-mass constants
--------------------
:data:`MOON_MU`, :data:`MOON_RADIUS` are those of the GRAIL field GRGM660PRIM (Lemoine et
al. 2013), so that :func:`moon_low_degree` and the full GRGM660PRIM file describe one body
with one GM. McCann (2020) uses μ = 4.9028e12 m³/s² (``gmuk.celestial.MOON_MU_THESIS``) and
its Section 4.3 initial condition needs 4.9048695e12 (see the errata); neither is a GRAIL
value. :data:`EARTH_MU`, :data:`EARTH_RADIUS` are EGM2008's (Pavlis et al. 2012).

Low-degree lunar field
----------------------
:func:`moon_low_degree` returns GRGM660PRIM through degree 4: its GM and reference radius,
C̄₀₀ = 1, zero degree-1 terms (the origin is the centre of mass) and the fourteen
fully normalised coefficients of degrees 2–4 typed below, rounded to 8 significant digits
from the model's published coefficient table (the GRGM660PRIM distribution of the ICGEM
service and the PDS Geosciences Node, ``gggrx_0660pm_sha.tab``; Lemoine et al. 2013).
The formal standard deviations of these coefficients are 1e-10 (C̄₂₀) to 7e-13, so the
8-digit rounding (relative error ≤ 5e-8) is below or at their level. The test suite
checks every typed value against the GRGM660PRIM file shipped with gmuk
(``tests/gravity/test_gravity_builtin.py``).
Frame: the DE421 principal-axis frame of the Moon.

References
----------
Lemoine, F. G., et al. (2013). High-degree gravity models from GRAIL primary mission data.
*J. Geophys. Res. Planets* 118, 1676–1698, doi:10.1002/jgre.20118.
Pavlis, N. K., Holmes, S. A., Kenyon, S. C. & Factor, J. K. (2012). The development and
evaluation of the Earth Gravitational Model 2008 (EGM2008). *J. Geophys. Res.* 117,
B04406, doi:10.1029/2011JB008916.
"""

from __future__ import annotations

import numpy as np

from gmuk.gravity.field import SphericalHarmonicField

__all__ = [
    "EARTH_MU",
    "EARTH_RADIUS",
    "MOON_MU",
    "MOON_RADIUS",
    "earth_point_mass",
    "moon_low_degree",
    "moon_point_mass",
]

#: GM of the Moon (m³/s²), GRGM660PRIM (Lemoine et al. 2013; ICGEM header
#: ``gravity_constant 0.4902799806931690D+13``).
MOON_MU = 4.902799806931690e12
#: Reference radius of the GRAIL lunar fields (m) (Lemoine et al. 2013).
MOON_RADIUS = 1.738e6
#: GM of the Earth (m³/s²), EGM2008 (Pavlis et al. 2012), including the atmosphere.
EARTH_MU = 3.986004415e14
#: Reference radius (semi-major axis) of EGM2008 (m) (Pavlis et al. 2012).
EARTH_RADIUS = 6.3781363e6

_GRGM660PRIM_REFERENCE = (
    "GRGM660PRIM (Lemoine et al. 2013, J. Geophys. Res. Planets 118, 1676-1698), "
    "degrees 2-4 rounded to 8 significant digits"
)

#: GRGM660PRIM fully normalised (4π) coefficients (C̄_nm, S̄_nm), degrees 2–4, 8 digits.
_GRGM660PRIM_LOW: dict[tuple[int, int], tuple[float, float]] = {
    (2, 0): (-9.0882924e-05, 0.0),
    (2, 1): (8.4954065e-11, 9.7726994e-10),
    (2, 2): (3.4670944e-05, -2.4064245e-10),
    (3, 0): (-3.1974039e-06, 0.0),
    (3, 1): (2.6367949e-05, 5.4545622e-06),
    (3, 2): (1.4171538e-05, 4.8779444e-06),
    (3, 3): (1.2275202e-05, -1.7743748e-06),
    (4, 0): (3.2347925e-06, 0.0),
    (4, 1): (-6.0134612e-06, 1.6643328e-06),
    (4, 2): (-7.1161737e-06, -6.7770230e-06),
    (4, 3): (-1.3499174e-06, -1.3444991e-05),
    (4, 4): (-6.0069115e-06, 3.9266111e-06),
}


def moon_low_degree(degree: int = 4) -> SphericalHarmonicField:
    """GRGM660PRIM through degree 4 (or less), typed in (see the module docstring).

    Parameters
    ----------
    degree : int
        0 to 4 (default 4).

    Returns
    -------
    SphericalHarmonicField
        μ = :data:`MOON_MU`, R = :data:`MOON_RADIUS`, in the DE421 principal-axis frame.

    Raises
    ------
    DegreeError
        ``degree`` outside [0, 4].
    """
    C = np.zeros((5, 5))
    S = np.zeros((5, 5))
    C[0, 0] = 1.0
    for (n, m), (c, s) in _GRGM660PRIM_LOW.items():
        C[n, m] = c
        S[n, m] = s
    return SphericalHarmonicField(
        MOON_MU,
        MOON_RADIUS,
        C,
        S,
        degree=degree,
        name="GRGM660PRIM (degree <= 4, built in)",
        reference=_GRGM660PRIM_REFERENCE,
        tide_system="tide_free",
        metadata={"frame": "DE421 principal axes"},
    )


def moon_point_mass() -> SphericalHarmonicField:
    """The Moon as a point mass: a degree-0 field with :data:`MOON_MU`, :data:`MOON_RADIUS`."""
    return _point_mass(MOON_MU, MOON_RADIUS, "Moon point mass (GRGM660PRIM GM)")


def earth_point_mass() -> SphericalHarmonicField:
    """The Earth as a point mass: a degree-0 field with :data:`EARTH_MU`, :data:`EARTH_RADIUS`."""
    return _point_mass(EARTH_MU, EARTH_RADIUS, "Earth point mass (EGM2008 GM)")


def _point_mass(mu: float, radius: float, name: str) -> SphericalHarmonicField:
    return SphericalHarmonicField(mu, radius, np.ones((1, 1)), np.zeros((1, 1)), name=name)
