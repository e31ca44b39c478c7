"""Tutorial 4: a real gravity field, loaded by name, against the point-mass orbit.

``gmuk.gravity.load("GRGM660PRIM", degree=N)`` reads the GRAIL lunar field shipped with
gmuk; ``gmuk.SphericalHarmonicGravity(...)`` turns it into a force model on every body
(force and torque, with the Moon spinning under the orbit). The same spacecraft is flown
from the same state in the field and under point-mass gravity with the field's own GM; the
difference is what the harmonics do. The point-mass run is also checked against Kepler's
solution, so the difference is known to be physics, not integration error.

Run: python examples/tutorials/t4_gravity_field.py [--quick]
"""

from __future__ import annotations

import argparse

import numpy as np

import gmuk
from gmuk.orbits import KeplerOrbit


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a short run (for the tests)")
    args = parser.parse_args(argv)
    degree, orbits = (10, 0.25) if args.quick else (50, 2.0)

    field = gmuk.gravity.load("GRGM660PRIM", degree=degree)
    moon = gmuk.CelestialBody.moon(field, mu=field.mu)
    print(f"{field.name}: degree {field.degree}, GM {field.mu:.6e} m³/s², R {field.radius:.0f} m")

    # a 100 km circular polar orbit
    a = field.radius + 100e3
    orbit = KeplerOrbit.from_elements(a, 0.0, np.pi / 2, 0.0, 0.0, field.mu)
    r0, v0 = orbit.state(0.0)
    R0 = np.eye(3)
    craft = gmuk.RigidBody("craft", 1000.0, np.diag([800.0, 900.0, 1000.0]))  # kg, kg·m²
    t_end = orbits * orbit.period
    t = np.linspace(0.0, t_end, 201)
    runs = {}
    for label, gravity in (
        ("field", gmuk.SphericalHarmonicGravity(moon)),
        ("point_mass", gmuk.PointMassGravity(field.mu)),
    ):
        system = gmuk.System([craft], [], [gravity])
        g0 = np.eye(4)
        g0[:3, :3], g0[:3, 3] = R0, r0
        state = system.state(g={"craft": g0}, V={"craft": np.concatenate([[0, 0, 0], v0])})
        runs[label] = system.simulate(state, (0.0, t_end), t_eval=t, rtol=1e-11, atol=1e-9)
    r_field = runs["field"].body("craft").position
    r_point = runs["point_mass"].body("craft").position
    r_kepler, _ = orbit.state(t)
    altitude = np.linalg.norm(r_field, axis=1) - field.radius
    result = {
        "point_mass_vs_kepler_m": float(np.linalg.norm(r_point - r_kepler, axis=1).max()),
        "field_vs_point_mass_m": float(np.linalg.norm(r_field - r_point, axis=1).max()),
        "field_altitude_min_km": float(altitude.min() / 1e3),
        "field_altitude_max_km": float(altitude.max() / 1e3),
    }
    for k, v in result.items():
        print(f"{k:>24}: {v:.4g}")
    return result


if __name__ == "__main__":
    main()
