"""The compiled step loop's entry to the built-in force models' kernels.

Each built-in model's formula is written once, as a numba kernel beside its class
(:mod:`gmuk.forces.gravity`, :mod:`gmuk.forces.mechanical`), with the signature
``kernel(rigid, t, g, V, m, J, p, field, out) -> status``; the model's ``wrench``/``force``
call it, and the compiled loop (:mod:`gmuk.engine.integrators._compiled`) calls it through
:func:`apply_term`, which only dispatches on the code that :data:`CODES` gives each kernel.
A model's :meth:`~gmuk.forces.ForceModel._compiled_term` finds its code there; adding a model
with a compiled form adds its kernel to :data:`CODES` and one branch to :func:`apply_term`.
"""

from __future__ import annotations

from gmuk._numba import njit
from gmuk.forces.gravity import (
    gravity_gradient_load,
    gravity_gradient_wrench,
    harmonic_point_load,
    point_mass_load,
)
from gmuk.forces.mechanical import spring_load, uniform_load

__all__ = [
    "CODES",
    "GRAVITY_GRADIENT",
    "HARMONIC_POINT",
    "POINT_MASS",
    "SPRING",
    "UNIFORM",
    "UNKNOWN_CODE",
    "apply_term",
    "gravity_gradient_wrench",
]

#: PointMassGravity (GravityGradient's point masses go through it too).
POINT_MASS = 0
#: GravityGradient: McCann (2020) Eq. 23 on rigid bodies, the point-mass force on particles.
GRAVITY_GRADIENT = 1
#: SphericalHarmonicGravity on a point mass about a uniformly spinning central body.
HARMONIC_POINT = 2
#: UniformGravity.
UNIFORM = 3
#: LinearSpringDamper.
SPRING = 4
#: The status :func:`apply_term` returns for a code it does not know (no kernel status is
#: this large: the field kernels return 1 to 3).
UNKNOWN_CODE = 99

#: The code of each kernel: what a model's ``_compiled_term`` hands to :func:`apply_term`.
CODES = {
    point_mass_load: POINT_MASS,
    gravity_gradient_load: GRAVITY_GRADIENT,
    harmonic_point_load: HARMONIC_POINT,
    uniform_load: UNIFORM,
    spring_load: SPRING,
}


@njit(cache=True)
def apply_term(code, rigid, t, g, V, m, J, p, field, out):  # type: ignore[no-untyped-def]
    """Write one built-in force model's load on one body into ``out``: the body-frame
    wrench [L; f] (6,) of a rigid body at pose ``g`` (4, 4) with twist ``V`` (6,), or the
    force f_N (3,) on a point mass, then at ``g[:3, 3]`` with velocity ``V[:3]`` (both N).
    ``p`` holds the model's parameters, ``field`` its field data (if any), m and J the body's
    mass and central inertia.

    Returns 0, the kernel's nonzero status (a spherical-harmonic field's), or
    :data:`UNKNOWN_CODE`.
    """
    if code == POINT_MASS:
        return point_mass_load(rigid, t, g, V, m, J, p, field, out)
    if code == GRAVITY_GRADIENT:
        return gravity_gradient_load(rigid, t, g, V, m, J, p, field, out)
    if code == HARMONIC_POINT:
        return harmonic_point_load(rigid, t, g, V, m, J, p, field, out)
    if code == UNIFORM:
        return uniform_load(rigid, t, g, V, m, J, p, field, out)
    if code == SPRING:
        return spring_load(rigid, t, g, V, m, J, p, field, out)
    return UNKNOWN_CODE
