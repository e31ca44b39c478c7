"""lunar-flyby: a rigid spacecraft on a hyperbolic approach to the Moon, stopped at periapsis
by a terminal event and compared with the two-body (Kepler) conic (issue #29, item 7).

Physics
-------
* The spacecraft is a rigid body with the mass properties of McCann (2020), Section 3.4
  (the Lunar Module: 7063 kg, the central inertia of :data:`gmuk.scenarios._lvlh.LM_INERTIA`),
  its body axes along the conic's perifocal frame at the start (axis 1 towards periapsis,
  axis 3 along the orbit normal), at rest in N.
* The Moon's GM and reference radius are GRGM660PRIM's (μ = 4.902799806931690e12 m³/s²,
  R = 1738 km) in every run, the point-mass one included, so that a difference between the
  runs is the harmonics' effect alone.
* The approach is the hyperbola of hyperbolic excess speed v∞ (``--vinf``) and periapsis
  radius r_p = R + h_p (``--periapsis-altitude``): semi-major axis a = −μ/v∞², eccentricity
  e = 1 + r_p v∞²/μ, semi-latus rectum p = a(1 − e²); inclination 30° to N's equator,
  Ω = ω = 0. The run starts on the incoming branch at the radius r₀ (``--start-radius``),
  true anomaly ν₀ = −arccos((p/r₀ − 1)/e), from :func:`gmuk.orbits.elements_to_state`; the
  Kepler solution puts periapsis a time t_p = −t(ν₀) after the start
  (:meth:`gmuk.orbits.KeplerOrbit.time_from_true_anomaly`).
* Gravity: ``--degree 0`` (default) the point-mass field on the finite body, McCann (2020)
  Eq. 23 (:class:`gmuk.GravityGradient`: central force, its finite-size correction and the
  gravity-gradient torque); ``--degree N`` (2 ≤ N ≤ 150) the GRAIL field GRGM660PRIM
  truncated at degree N (:class:`gmuk.forces.SphericalHarmonicGravity`, force and torque to
  second order in the body's size), the Moon spinning at its sidereal rate with its fixed
  frame F = N at the start.
* The run stops at the first periapsis: a terminal :class:`gmuk.ApsisEvent` (the rising zero
  of r·v, located by Brent's method on DOP853's dense output). DOP853 at rtol = atol = 1e-13,
  outputs every 10 s and at the event.

With the point-mass field the spacecraft's centre of mass follows the conic up to the
integrator's error and the Eq. 23 finite-size force (of second order in the body's size over
its distance from the Moon's centre), so the event's time, radius and speed equal the Kepler
prediction to that level (``docs/scenarios/lunar_flyby.rst`` gives the figures). With harmonics the
summary reports their difference from it.

Summary (``summary.json``)
--------------------------
The conic (``eccentricity``, ``semi_major_axis_m``, ``start_true_anomaly_deg``), the Kepler
prediction (``kepler_periapsis_time_s`` from the start, ``kepler_periapsis_radius_m``,
``kepler_periapsis_altitude_m``, ``kepler_periapsis_speed_m_s``), the event's
(``periapsis_time_s``, ``periapsis_radius_m``, ``periapsis_altitude_m``,
``periapsis_speed_m_s``; null when the run ended first) and their differences (event minus
Kepler: ``periapsis_time_diff_s``, ``periapsis_radius_diff_m``, ``periapsis_speed_diff_m_s``),
the radial speed at the event (``periapsis_radial_speed_m_s``), the largest distance from the
Kepler conic over the run (``max_position_diff_m``) and the largest relative change of the
two-body energy v²/2 − μ/r (``energy_rel_change``, conserved only by the point-mass field).

Figures: altitude with the periapsis marked; speed; the position's difference from the Kepler
conic (components in N and its norm).

Command line: ``gmuk run lunar-flyby``, ``gmuk run lunar-flyby --degree 150 --vinf 1500``.

References
----------
Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed. (2013), §2.2 and §4.2
(hyperbolic orbits: a = −μ/v∞², r_p = a(1 − e)); McCann (2020), Section 3.4 (mass
properties) and Eq. 23; Lemoine, F. G., et al. (2013), High-degree gravity models from GRAIL
primary mission data, *J. Geophys. Res. Planets* 118, 1676–1698.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.errors import DefinitionError
from gmuk.forces import SphericalHarmonicGravity
from gmuk.gravity import SphericalHarmonicField
from gmuk.orbits import KeplerOrbit, elements_to_state
from gmuk.scenarios import Option, Scenario, ScenarioResult, positive_float
from gmuk.scenarios import _lvlh as common
from gmuk.scenarios._fields import DEFAULT_FIELD, lunar_field
from gmuk.trajectory import EventRecord, Trajectory

__all__ = [
    "DESCRIPTION",
    "NAME",
    "SCENARIO",
    "approach",
    "build",
    "figures",
    "periapsis_record",
    "run",
]

NAME = "lunar-flyby"
DESCRIPTION = (
    "rigid spacecraft on a hyperbolic lunar flyby, stopped at periapsis vs the Kepler conic"
)

BODY = "spacecraft"
#: Inclination (rad) of the approach to N's equator; Ω = ω = 0.
INCLINATION = math.radians(30.0)
#: Integration tolerances (rtol = atol): the point-mass periapsis then matches the Kepler
#: conic to about 1e-10 s and 1e-8 m (docs/scenarios/lunar_flyby.rst).
RTOL = ATOL = 1e-13
#: Spacing (s) of the output times; the event's state is the last output.
OUTPUT_STEP = 10.0


def _degree(text: str) -> int:
    """A ``--degree`` option: 0 (point mass) or an integer ≥ 2 (the GRAIL field's degree)."""
    value = int(text)
    if value < 0 or value == 1:
        raise ValueError("must be 0 (point mass) or an integer >= 2")
    return value


def _field() -> SphericalHarmonicField:
    return lunar_field(DEFAULT_FIELD, NAME)[0]


def approach(
    vinf: float, periapsis_altitude: float, start_radius: float, field: SphericalHarmonicField
) -> tuple[KeplerOrbit, float]:
    """The hyperbola of the flyby and the start's time since periapsis.

    Parameters
    ----------
    vinf : float
        Hyperbolic excess speed v∞ (m/s), > 0.
    periapsis_altitude : float
        Periapsis altitude h_p (m) above the field's reference radius, > 0.
    start_radius : float
        Distance r₀ (m) from the Moon's centre at the start, > R + h_p.
    field : SphericalHarmonicField
        Gives μ (m³/s²) and R (m).

    Returns
    -------
    orbit : KeplerOrbit
        a = −μ/v∞², e = 1 + r_p v∞²/μ, i = 30°, Ω = ω = 0.
    t0 : float
        Time since periapsis (s) at r₀ on the incoming branch (< 0).

    Raises
    ------
    DefinitionError
        A non-finite or non-positive value, or r₀ ≤ r_p.
    """
    for name, value in (
        ("vinf (m/s)", vinf),
        ("periapsis_altitude (m)", periapsis_altitude),
        ("start_radius (m)", start_radius),
    ):
        if not (isinstance(value, (int, float)) and 0.0 < value < math.inf):
            raise DefinitionError(f"{NAME}: {name} must be a finite number > 0; got {value!r}")
    mu, rp = field.mu, field.radius + periapsis_altitude
    if not start_radius > rp:
        raise DefinitionError(
            f"{NAME}: start_radius must exceed the periapsis radius R + h_p = {rp:.6g} m, to "
            f"start on the incoming branch; got {start_radius!r} m"
        )
    e = 1.0 + rp * vinf**2 / mu
    orbit = KeplerOrbit.from_elements(-mu / vinf**2, e, INCLINATION, 0.0, 0.0, mu)
    nu0 = -math.acos((orbit.p / start_radius - 1.0) / e)
    return orbit, float(orbit.time_from_true_anomaly(nu0))


def build(
    orbit: KeplerOrbit, t0: float, degree: int, field: SphericalHarmonicField
) -> tuple[gmuk.System, gmuk.State]:
    """The System (the spacecraft in the point-mass or GRAIL field) and its state at the start.

    Parameters
    ----------
    orbit : KeplerOrbit
    t0 : float
        Time since periapsis (s) of the start.
    degree : int
        0: :class:`gmuk.GravityGradient` with the field's μ; N ≥ 2: the field to degree N.
    field : SphericalHarmonicField
    """
    if degree > field.degree:
        raise DefinitionError(
            f"{NAME}: degree {degree} requested but {field.name} stops at {field.degree}; "
            f"ask for --degree ≤ {field.degree}"
        )
    force: gmuk.ForceModel
    if degree == 0:
        force = gmuk.GravityGradient(field.mu)
    else:
        force = SphericalHarmonicGravity(gmuk.CelestialBody.moon(field=field.truncate(degree)))
    system = gmuk.System([common.spacecraft(BODY)], [], [force])
    f0 = float(orbit.true_anomaly(t0))
    r_N, v_N = elements_to_state(
        None, orbit.e, orbit.i, orbit.raan, orbit.argp, f0, orbit.mu, p=orbit.p
    )
    g = np.eye(4)
    g[:3, :3] = orbit.R_NP
    g[:3, 3] = r_N
    V = np.r_[0.0, 0.0, 0.0, orbit.R_NP.T @ v_N]
    return system, system.state(g={BODY: g}, V={BODY: V})


def periapsis_record(traj: Trajectory) -> EventRecord | None:
    """The periapsis event of a run, or None if the run ended before it."""
    found = [e for e in traj.events if e.name == "periapsis"]
    return found[0] if found else None


def _position_velocity(state: gmuk.State) -> tuple[FloatArray, FloatArray]:
    g = state.g[state.layout.slot(BODY).index]
    return g[:3, 3], g[:3, :3] @ state.velocity(BODY)[3:]


def run(
    vinf: float = 1000.0,
    periapsis_altitude: float = 100e3,
    degree: int = 0,
    start_radius: float = 10e6,
    duration: float = 20000.0,
) -> ScenarioResult:
    """Fly the approach from ``start_radius`` until periapsis (or ``duration`` seconds).

    Parameters
    ----------
    vinf : float
        Hyperbolic excess speed (m/s).
    periapsis_altitude : float
        Periapsis altitude of the conic above R = 1738 km (m).
    degree : int
        0 for the point-mass field, else the GRAIL field's degree (2–150).
    start_radius : float
        Distance from the Moon's centre at the start (m).
    duration : float
        Longest span (s); the periapsis event normally ends the run before it.
    """
    if not (isinstance(duration, (int, float)) and 0.0 < duration < math.inf):
        raise DefinitionError(f"{NAME}: duration (s) must be a finite number > 0; got {duration!r}")
    field = _field()
    orbit, t0 = approach(vinf, periapsis_altitude, start_radius, field)
    system, state = build(orbit, t0, degree, field)
    mu, R = field.mu, field.radius
    n_out = common.output_count(duration / OUTPUT_STEP, 1) + 1
    t_eval = np.linspace(0.0, duration, n_out)
    event = gmuk.ApsisEvent(BODY, mu=mu, kind="periapsis", terminal=True)
    traj = system.simulate(
        state, (0.0, duration), rtol=RTOL, atol=ATOL, t_eval=t_eval, events=[event]
    )

    body = traj.body(BODY)
    r, v = body.position, body.velocity
    r_kepler = orbit.position(traj.t + t0)
    rn = np.linalg.norm(r, axis=1)
    energy = 0.5 * np.einsum("ki,ki->k", v, v) - mu / rn
    kepler_time = -t0
    kepler_rp = orbit.periapsis_radius
    kepler_vp = math.sqrt(mu * (2.0 / kepler_rp - 1.0 / orbit.a))
    summary: dict[str, Any] = {
        "degree": degree,
        "field": field.name,
        "mu_m3_s2": mu,
        "reference_radius_m": R,
        "vinf_m_s": float(vinf),
        "start_radius_m": float(start_radius),
        "eccentricity": orbit.e,
        "semi_major_axis_m": orbit.a,
        "start_true_anomaly_deg": math.degrees(float(orbit.true_anomaly(t0))),
        "kepler_periapsis_time_s": kepler_time,
        "kepler_periapsis_radius_m": kepler_rp,
        "kepler_periapsis_altitude_m": kepler_rp - R,
        "kepler_periapsis_speed_m_s": kepler_vp,
        "periapsis_reached": False,
        "periapsis_time_s": None,
        "periapsis_radius_m": None,
        "periapsis_altitude_m": None,
        "periapsis_speed_m_s": None,
        "periapsis_time_diff_s": None,
        "periapsis_radius_diff_m": None,
        "periapsis_speed_diff_m_s": None,
        "periapsis_radial_speed_m_s": None,
        "max_position_diff_m": float(np.linalg.norm(r - r_kepler, axis=1).max()),
        "energy_rel_change": float(np.abs(energy / energy[0] - 1.0).max()),
        "final_omega_rad_s": float(np.linalg.norm(body.omega[-1])),
        "n_steps": int(traj.stats["n_steps"]),
        "rtol": RTOL,
        "atol": ATOL,
    }
    record = periapsis_record(traj)
    if record is not None:
        rp_N, vp_N = _position_velocity(record.state)
        rp, vp = float(np.linalg.norm(rp_N)), float(np.linalg.norm(vp_N))
        summary.update(
            {
                "periapsis_reached": True,
                "periapsis_time_s": record.t,
                "periapsis_radius_m": rp,
                "periapsis_altitude_m": rp - R,
                "periapsis_speed_m_s": vp,
                "periapsis_time_diff_s": record.t - kepler_time,
                "periapsis_radius_diff_m": rp - kepler_rp,
                "periapsis_speed_diff_m_s": vp - kepler_vp,
                "periapsis_radial_speed_m_s": float(rp_N @ vp_N) / rp,
            }
        )
    data = {"orbit": orbit, "t0": t0, "system": system, "r_kepler_N": r_kepler, "energy": energy}
    return ScenarioResult(NAME, {NAME: traj}, NAME, summary, data)


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Altitude (periapsis marked), speed, and the position's difference from the conic."""
    out.mkdir(parents=True, exist_ok=True)
    s = result.summary
    traj = result.trajectories[result.primary]
    body = traj.body(BODY)
    t = traj.t
    altitude = np.linalg.norm(body.position, axis=1) - s["reference_radius_m"]
    speed = np.linalg.norm(body.velocity, axis=1)
    kepler_t = t + result.data["t0"]
    orbit: KeplerOrbit = result.data["orbit"]
    kepler_altitude = np.linalg.norm(orbit.position(kepler_t), axis=-1) - s["reference_radius_m"]
    kepler_speed = np.linalg.norm(orbit.velocity(kepler_t), axis=-1)
    model = "point mass" if s["degree"] == 0 else f"GRAIL degree {s['degree']}"
    label = f"lunar-flyby (v∞ = {s['vinf_m_s']:g} m/s, {model})"
    marker = np.full(len(t), np.nan)
    if s["periapsis_reached"]:
        marker[-1] = s["periapsis_altitude_m"] / 1e3
    kepler_style = {"linestyle": "--", "color": "C1"}
    paths = plotting.plot_panels(
        t,
        [
            (
                "altitude (km)",
                [
                    ("flown", altitude / 1e3, {"color": "C0"}),
                    ("Kepler conic", kepler_altitude / 1e3, kepler_style),
                    (
                        "periapsis (event)",
                        marker,
                        {"marker": "o", "linestyle": "none", "color": "C3"},
                    ),
                ],
            )
        ],
        f"{label}: altitude",
        out / "altitude",
        formats,
    )
    paths += plotting.plot_panels(
        t,
        [
            (
                "speed (m/s)",
                [("flown", speed, {"color": "C0"}), ("Kepler conic", kepler_speed, kepler_style)],
            )
        ],
        f"{label}: speed",
        out / "speed",
        formats,
    )
    d = body.position - result.data["r_kepler_N"]
    scale, unit = plotting.length_unit(d)
    lines = [(f"Δr_N{i + 1}", d[:, i] / scale, {"color": f"C{i}"}) for i in range(3)]
    lines.append(("‖Δr‖", np.linalg.norm(d, axis=1) / scale, {"color": "k"}))
    paths += plotting.plot_panels(
        t,
        [(f"r − r_Kepler ({unit})", lines)],
        f"{label}: minus the Kepler conic",
        out / "kepler_difference",
        formats,
    )
    return paths


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("vinf", positive_float, 1000.0, "hyperbolic excess speed v∞ (m/s)"),
        Option(
            "periapsis_altitude",
            positive_float,
            100e3,
            "periapsis altitude of the conic above R = 1738 km (m)",
        ),
        Option(
            "degree",
            _degree,
            0,
            "GRAIL field GRGM660PRIM degree, 2-150; 0 = point-mass field (Eq. 23)",
        ),
        Option(
            "start_radius", positive_float, 10e6, "distance from the Moon's centre at the start (m)"
        ),
        Option(
            "duration",
            positive_float,
            20000.0,
            "longest simulated span (s); the periapsis event normally ends the run first",
        ),
    ),
    central_radius=common.CENTRAL_RADIUS,
)
