"""Apollo 16 subsatellite orbit: the free LM in a uniform field and in the GRAIL field.

McCann (2020), Section 3.4 and Figures 3.1–3.4. A rigid body with the Lunar Module's mass
properties (Section 3.4) starts at periselene of the Apollo 16 subsatellite orbit —
periselene altitude 90 km, aposelene altitude 130 km, inclination 11°, Ω = ω = 0 — with the
modified-LVLH attitude and rate (axis 1 at the Moon, axis 3 along the orbit normal, body
rate ḟ about axis 3), and moves freely (no constraint, no control) for one orbital period
under

* ``"uniform"``: the point-mass field on the finite body, Eq. 23
  (:class:`gmuk.GravityGradient`), and
* the GRAIL field GRGM660PRIM truncated at degrees 2, 10, 50 and 150, in one or both of two
  models:

  - ``"correct"``: :class:`gmuk.forces.SphericalHarmonicGravity` (full gradient for the
    force, the Hessian for the torque, correct to second order in the body's size);
  - ``"thesis"``: :class:`gmuk.forces.ThesisRadialHarmonicGravity`, the thesis's Eqs. 42
    and 59 as printed (radial-only, sign of the harmonic sum flipped, angular factor frozen;
    see the errata).

The figures are the differences of each run from the uniform-field run: position and
velocity in N (Figures 3.1, 3.2), 3-2-1 Euler angles of R_NB (Figure 3.3, wrapped to
[−180°, 180°)) and body angular velocity (Figure 3.4).

One GM, one radius
------------------
Every run of one call, the uniform one included, uses the field's own GM and reference
radius (GRGM660PRIM: μ = 4.902799806931690e12 m³/s², R = 1738 km): the orbit's size, its
period and the uniform reference are built from them, so a difference between two runs is
the harmonics' effect alone. (The thesis's μ = 4.9028e12 m³/s² differs by 4e-8.)

Initial condition
-----------------
``initial="elements"`` (default) builds the state from the stated orbit: periselene radius
R + 90 km = 1828 km, aposelene radius R + 130 km = 1868 km (a = 1848 km, e = 0.010823),
i = 11°, and the attitude and rate of the LVLH reference at periselene
(:class:`gmuk.orbits.LVLHReference`; with GRGM660PRIM's GM: v = 1646.537 m/s along −b₂,
ω₃ = ḟ = 9.007313e-4 rad/s, period 7128.71 s). ``initial="printed"`` uses the numbers
printed in Section 3.4 instead: r = [1.824e6, 0, 0] m, V = [0, 0, 9.03813e-4, 0,
−1.64863e3, 0], and the printed attitude, whose entries are cos 11° and sin 11° to five
digits (it is not orthonormal to 6e-6 as printed, so the exact rotation R₁(11°)·diag(−1, −1,
1) is used). The printed state is *not* the stated orbit: r = 1824 km is 86 km above the
1738 km sphere, and with that r and v the osculating orbit is 86.0 × 127.2 km (period
7109.14 s). Nor is ω₃ the orbit rate at periselene, v/r = 9.03854e-4 rad/s, whatever the
GM (ω₃ r / v = 1 − 4.5e-5; they agree only for r = 1824.083 km). A 90 × 130 km orbit
over a 1734 km sphere would start at r = 1824 km, but with v = 1648.36 m/s (μ = 4.9028e12)
or 1648.71 m/s (μ = 4.9048695e12), not 1648.63 (measured; see
``docs/scenarios/chapter3.rst``). The headline differences of the two initial conditions
agree to better than 1 % (same page).

Gravity field
-------------
``field`` names the lunar field: a field shipped with gmuk (default ``"GRGM660PRIM"``, the
GRAIL primary-mission field to degree 150, :func:`gmuk.gravity.load`), the path of an ICGEM
``.gfc`` file of the Moon of degree ≥ the highest degree requested, or a
:class:`gmuk.gravity.SphericalHarmonicField`. A name of a shipped field wins over a file of
the same name in the working directory. A field of another body (GM not the Moon's to 1e-3)
is refused.

Command line
------------
``gmuk run apollo16`` runs :func:`run` with its defaults; every keyword of :func:`run` is a
flag (:data:`SCENARIO`), e.g. ``gmuk run apollo16 --degrees 2,10 --model correct --field
PATH``; ``gmuk run apollo16 --help`` lists them with their defaults.

References
----------
McCann (2020), Section 3.4, Eqs. (23), (42), (59), Figures 3.1–3.4; Lemoine, F. G., et al.
(2013), High-degree gravity models from GRAIL primary mission data, *J. Geophys. Res.
Planets* 118, 1676–1698; errata (``docs/errata.rst``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._validation import FloatArray
from gmuk.errors import DefinitionError
from gmuk.forces import SphericalHarmonicGravity, ThesisRadialHarmonicGravity
from gmuk.gravity import SphericalHarmonicField
from gmuk.orbits import KeplerOrbit, LVLHReference
from gmuk.scenarios import Option, Scenario, ScenarioResult, comma_separated, positive_float
from gmuk.scenarios import _lvlh as common
from gmuk.scenarios._fields import DEFAULT_FIELD, lunar_field
from gmuk.trajectory import Trajectory

__all__ = [
    "DEFAULT_FIELD",
    "DEGREES",
    "DESCRIPTION",
    "MODELS",
    "NAME",
    "SCENARIO",
    "differences",
    "figures",
    "initial_state",
    "load_field",
    "rsw",
    "run",
    "write_data",
]

NAME = "apollo16"
DESCRIPTION = (
    "Ch. 3: free LM on the Apollo 16 subsatellite orbit, GRAIL field at degrees 2-150 "
    "vs uniform field (Figs 3.1-3.4)"
)

#: Degrees of the thesis's Figures 3.1–3.4.
DEGREES: tuple[int, ...] = (2, 10, 50, 150)
#: Harmonic-gravity models: gmuk's correct one and the thesis's Eqs. 42/59 as printed.
MODELS: tuple[str, ...] = ("correct", "thesis")
#: Thesis-model P̄ normalisations (:class:`~gmuk.forces.ThesisRadialHarmonicGravity`).
THESIS_NORMALIZATIONS: tuple[str, ...] = ("thesis_eq26c_intended", "thesis_eq26c", "4pi")
#: The lunar field used unless ``field`` says otherwise: shipped with gmuk, to degree 150.
#: Periselene and aposelene altitudes (m) and inclination (rad) of Section 3.4.
PERISELENE_ALTITUDE = 90e3
APOSELENE_ALTITUDE = 130e3
INCLINATION = math.radians(11.0)
#: The initial state printed in Section 3.4: position (m, N) and body twist [ω; v].
PRINTED_POSITION_N = np.array([1.824e6, 0.0, 0.0])
PRINTED_V_B = np.array([0.0, 0.0, 9.03813e-4, 0.0, -1.64863e3, 0.0])
#: Integration tolerance (rtol = atol): 5e-4 m and 6e-10 rad from rtol 1e-13 over one orbit
#: at degree 150 (docs/scenarios/chapter3.rst), against differences of kilometres and 1e-3 rad.
RTOL = 1e-11
SAMPLES_PER_ORBIT = common.SAMPLES_PER_ORBIT
BODY = "spacecraft"

_QUANTITIES = (
    # difference key, label, unit
    ("position_m", "position", "m"),
    ("velocity_m_s", "velocity", "m/s"),
    ("euler321_deg", "3-2-1 Euler angles", "deg"),
    ("omega_rad_s", "angular velocity", "rad/s"),
)


def _check_degrees(degrees: Sequence[int]) -> tuple[int, ...]:
    given = tuple(degrees)
    integral = all(isinstance(d, (int, np.integer)) and not isinstance(d, bool) for d in given)
    degs = tuple(int(d) for d in given) if integral else ()
    if not degs or min(degs) < 0 or len(set(degs)) != len(degs):
        raise DefinitionError(f"{NAME}: degrees must be distinct integers ≥ 0; got {given!r}")
    return degs


def load_field(
    field: str | os.PathLike[str] | SphericalHarmonicField = DEFAULT_FIELD,
    degrees: Sequence[int] = DEGREES,
) -> tuple[SphericalHarmonicField, tuple[int, ...], str]:
    """The lunar field to use, the degrees to run and a note saying which field it is.

    Parameters
    ----------
    field : str, path-like or SphericalHarmonicField
        A shipped field's name (:func:`gmuk.gravity.available`), the path of an ICGEM
        ``.gfc`` file, or a field.
    degrees : sequence of int
        Requested degrees.

    Returns
    -------
    field : SphericalHarmonicField
    degrees : tuple of int
    note : str
        The field's name, where it came from and its degree.

    Raises
    ------
    DefinitionError
        A degree that is not an integer, < 0, repeated, or above the field's degree; a
        name that is neither a shipped field nor a file; a field that is not the Moon's.
    """
    degs = _check_degrees(degrees)
    sh, note = lunar_field(field, NAME)
    if max(degs) > sh.degree:
        raise DefinitionError(
            f"{NAME}: degree {max(degs)} requested but field {note} stops at {sh.degree}; "
            f"ask for degrees ≤ {sh.degree} or give a field of higher degree"
        )
    return sh, degs, note


def initial_state(kind: str, mu: float, radius: float) -> tuple[FloatArray, FloatArray, float]:
    """Initial pose, body twist and orbital period.

    Parameters
    ----------
    kind : {"elements", "printed"}
        The stated 90 × 130 km, i = 11° orbit at periselene with the LVLH attitude and rate,
        or the numbers printed in Section 3.4 (module docstring).
    mu : float
        GM (m³/s²) of the field.
    radius : float
        Reference radius (m) of the field.

    Returns
    -------
    g_NB : ndarray (4, 4)
    V_B : ndarray (6,)
        [ω; v] (rad/s, m/s), body frame.
    period : float
        Keplerian period (s) of the osculating orbit of that state with ``mu``.
    """
    if kind == "elements":
        rp, ra = radius + PERISELENE_ALTITUDE, radius + APOSELENE_ALTITUDE
        orbit = KeplerOrbit.from_elements(
            0.5 * (rp + ra), (ra - rp) / (ra + rp), INCLINATION, 0.0, 0.0, mu
        )
        ref = LVLHReference(orbit).evaluate(0.0)
        return np.array(ref.g), np.array(ref.V), float(orbit.period)
    if kind == "printed":
        c, s = math.cos(INCLINATION), math.sin(INCLINATION)
        g = np.eye(4)
        g[:3, :3] = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]) @ np.diag(
            [-1.0, -1.0, 1.0]
        )
        g[:3, 3] = PRINTED_POSITION_N
        V = PRINTED_V_B.copy()
        orbit, _ = KeplerOrbit.from_state(g[:3, 3], g[:3, :3] @ V[3:], mu)
        return g, V, float(orbit.period)
    raise DefinitionError(f"{NAME}: initial must be 'elements' or 'printed'; got {kind!r}")


def _force(
    model: str, moon: gmuk.CelestialBody, degree: int, thesis_normalization: str
) -> gmuk.ForceModel:
    if model == "correct":
        return SphericalHarmonicGravity(moon, degree)
    return ThesisRadialHarmonicGravity(moon, degree, normalization=thesis_normalization)


def _simulate(
    force: gmuk.ForceModel, g: FloatArray, V: FloatArray, t: FloatArray, rtol: float
) -> Trajectory:
    sc = common.spacecraft(BODY)
    system = gmuk.System([sc], [], [force])
    state = system.state(g={BODY: g}, V={BODY: V})
    return system.simulate(state, (0.0, float(t[-1])), t_eval=t, rtol=rtol, atol=rtol)


def differences(traj: Trajectory, uniform: Trajectory) -> dict[str, FloatArray]:
    """Differences run − uniform at every output time.

    Returns
    -------
    dict
        ``position_m`` (N, 3) in N (m); ``velocity_m_s`` (N, 3) in N (m/s);
        ``euler321_deg`` (N, 3): ψ, θ, φ of R_NB (deg), wrapped to [−180, 180);
        ``omega_rad_s`` (N, 3): body angular velocity (rad/s), body frame.
    """
    a, b = traj.body(BODY), uniform.body(BODY)
    d_euler = np.degrees(a.euler("321") - b.euler("321"))
    return {
        "position_m": a.position - b.position,
        "velocity_m_s": a.velocity - b.velocity,
        "euler321_deg": (d_euler + 180.0) % 360.0 - 180.0,
        "omega_rad_s": a.omega - b.omega,
    }


def _norms(d: dict[str, FloatArray]) -> dict[str, FloatArray]:
    """‖Δr‖, ‖Δv‖, largest absolute Euler-angle difference, ‖Δω‖ at each time."""
    return {
        "position_m": np.linalg.norm(d["position_m"], axis=1),
        "velocity_m_s": np.linalg.norm(d["velocity_m_s"], axis=1),
        "euler321_deg": np.abs(d["euler321_deg"]).max(axis=1),
        "omega_rad_s": np.linalg.norm(d["omega_rad_s"], axis=1),
    }


def rsw(traj: Trajectory, dr_N: FloatArray) -> FloatArray:
    """Components (N, 3) (m) of position differences ``dr_N`` (N, 3) along the radial,
    along-track and cross-track directions of the run ``traj`` (r̂, ĥ × r̂, ĥ with
    ĥ = r × v / ‖r × v‖): the satellite RSW frame (Vallado 2013, §3.3)."""
    view = traj.body(BODY)
    r, v = view.position, view.velocity
    R = r / np.linalg.norm(r, axis=1, keepdims=True)
    W = np.cross(r, v)
    W /= np.linalg.norm(W, axis=1, keepdims=True)
    S = np.cross(W, R)
    return np.stack([np.einsum("ni,ni->n", dr_N, e) for e in (R, S, W)], axis=1)


def _headline(prefix: str, d: dict[str, FloatArray], frame: Trajectory) -> dict[str, float]:
    n = _norms(d)
    dr = rsw(frame, d["position_m"])
    return {
        f"{prefix}_max_position_difference_m": float(n["position_m"].max()),
        f"{prefix}_max_position_component_difference_m": float(np.abs(d["position_m"]).max()),
        f"{prefix}_max_radial_difference_m": float(np.abs(dr[:, 0]).max()),
        f"{prefix}_final_along_track_difference_m": float(dr[-1, 1]),
        f"{prefix}_max_cross_track_difference_m": float(np.abs(dr[:, 2]).max()),
        f"{prefix}_max_velocity_difference_m_s": float(n["velocity_m_s"].max()),
        f"{prefix}_max_euler321_difference_deg": float(n["euler321_deg"].max()),
        f"{prefix}_max_angular_velocity_difference_rad_s": float(n["omega_rad_s"].max()),
    }


def run(
    orbits: float = 1.0,
    *,
    degrees: Sequence[int] = DEGREES,
    model: str = "both",
    field: str | os.PathLike[str] | SphericalHarmonicField = DEFAULT_FIELD,
    initial: str = "elements",
    thesis_normalization: str = "thesis_eq26c_intended",
    rtol: float = RTOL,
) -> ScenarioResult:
    """Simulate the uniform field and each degree over ``orbits`` orbital periods.

    Parameters
    ----------
    orbits : float
        Duration in Keplerian periods of the initial osculating orbit (> 0).
    degrees : sequence of int
        Harmonic degrees (default :data:`DEGREES`, those of the thesis's figures). Degree 0
        (central term only) reproduces the uniform run: a check of the set-up.
    model : {"both", "correct", "thesis"}
        Harmonic-gravity model(s) to run.
    field : str, path-like or SphericalHarmonicField
        Lunar field: a shipped field's name (default ``"GRGM660PRIM"``), the path of an
        ICGEM ``.gfc`` file, or a field; see the module docstring.
    initial : {"elements", "printed"}
        Initial condition (module docstring).
    thesis_normalization : {"thesis_eq26c_intended", "thesis_eq26c", "4pi"}
        P̄ normalisation of the thesis model (see
        :class:`~gmuk.forces.ThesisRadialHarmonicGravity`); the default, Eq. 26c with its
        parentheses restored, is the reading closest to the thesis's figures. As printed
        (``"thesis_eq26c"``) the sums overflow past degree ~4.
    rtol : float
        Integrator rtol = atol.

    Returns
    -------
    ScenarioResult
        Trajectories ``"uniform"`` and ``"{model}_deg{n}"`` (spacecraft body
        ``"spacecraft"``), primary ``"uniform"``; summary with the set-up and, per model and
        degree, the maximum over the run of ‖Δr‖ (m), of its largest N component, of its
        radial and cross-track parts (m), the along-track part at the end (m, > 0 ahead),
        the maximum ‖Δv‖ (m/s), the largest absolute difference of the three Euler angles
        (deg) and the maximum ‖Δω‖ (rad/s), all from the uniform run (RSW of the uniform
        run), and with both models the same for thesis − correct (RSW of the correct run).

    Raises
    ------
    DefinitionError
        Bad ``orbits``, ``model``, ``initial``, ``thesis_normalization`` or degrees, or a
        field that is unknown, not lunar, or of lower degree than requested.
    """
    if not (math.isfinite(orbits) and orbits > 0):
        raise DefinitionError(f"{NAME}: orbits must be finite and > 0; got {orbits!r}")
    if model not in ("both", *MODELS):
        raise DefinitionError(f"{NAME}: model must be 'both', 'correct' or 'thesis'; got {model!r}")
    if thesis_normalization not in THESIS_NORMALIZATIONS:
        raise DefinitionError(
            f"{NAME}: thesis_normalization must be one of {', '.join(THESIS_NORMALIZATIONS)}; "
            f"got {thesis_normalization!r}"
        )
    models = MODELS if model == "both" else (model,)
    sh, degs, note = load_field(field, degrees)
    moon = gmuk.CelestialBody.moon(field=sh)
    g0, V0, period = initial_state(initial, moon.mu, moon.radius)
    t = np.linspace(0.0, orbits * period, common.output_count(orbits, SAMPLES_PER_ORBIT))

    trajs = {"uniform": _simulate(gmuk.GravityGradient(moon.mu), g0, V0, t, rtol)}
    for m in models:
        for n in degs:
            force = _force(m, moon, n, thesis_normalization)
            trajs[f"{m}_deg{n}"] = _simulate(force, g0, V0, t, rtol)

    r0 = float(np.linalg.norm(g0[:3, 3]))
    v0 = float(np.linalg.norm(V0[3:]))
    summary: dict[str, Any] = {
        "field": note,
        "mu_m3_s2": moon.mu,
        "reference_radius_m": moon.radius,
        "initial_condition": initial,
        "initial_radius_m": r0,
        "initial_speed_m_s": v0,
        "initial_omega3_rad_s": float(V0[2]),
        "period_s": period,
        "duration_s": float(t[-1]),
        "degrees": list(degs),
        "models": list(models),
        "thesis_normalization": thesis_normalization if "thesis" in models else None,
        "rtol": rtol,
    }
    uniform = trajs["uniform"]
    for m in models:
        for n in degs:
            summary |= _headline(f"{m}_deg{n}", differences(trajs[f"{m}_deg{n}"], uniform), uniform)
    if len(models) == 2:
        for n in degs:
            summary |= _headline(
                f"thesis_vs_correct_deg{n}",
                differences(trajs[f"thesis_deg{n}"], trajs[f"correct_deg{n}"]),
                trajs[f"correct_deg{n}"],
            )
    summary["rhs_evaluations"] = {k: int(v.stats["n_rhs"]) for k, v in trajs.items()}
    return ScenarioResult(NAME, trajs, "uniform", summary)


def _runs(result: ScenarioResult) -> dict[str, list[tuple[int, str]]]:
    """(degree, key) of each harmonic run, grouped by model, in degree order."""
    out: dict[str, list[tuple[int, str]]] = {}
    for key in result.trajectories:
        if key == "uniform":
            continue
        m, _, deg = key.partition("_deg")
        out.setdefault(m, []).append((int(deg), key))
    return {m: sorted(v) for m, v in out.items()}


_FIGURES = (
    (
        "fig3_1_position",
        "position_m",
        [f"Δr{a} (m)" for a in "123"],
        "Position difference from the uniform field, in N (Fig. 3.1)",
    ),
    (
        "fig3_2_velocity",
        "velocity_m_s",
        [f"Δv{a} (m/s)" for a in "123"],
        "Velocity difference from the uniform field, in N (Fig. 3.2)",
    ),
    (
        "fig3_3_euler321",
        "euler321_deg",
        ["Δψ (deg)", "Δθ (deg)", "Δφ (deg)"],
        "3-2-1 Euler-angle difference from the uniform field (Fig. 3.3)",
    ),
    (
        "fig3_4_angular_velocity",
        "omega_rad_s",
        [f"Δω{a} (rad/s)" for a in "123"],
        "Angular-velocity difference from the uniform field, body frame (Fig. 3.4)",
    ),
)

_MODEL_TITLES = {
    "correct": "correct field model",
    "thesis": "thesis Eqs. 42/59 as printed",
}


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Figures 3.1–3.4 for each model (``fig3_N_QUANTITY_MODEL``), one curve per degree, and
    with both models ``magnitudes_correct_vs_thesis`` (‖Δr‖, ‖Δv‖, largest Euler-angle
    difference, ‖Δω‖; correct solid, thesis dashed)."""
    out.mkdir(parents=True, exist_ok=True)
    uniform = result.trajectories["uniform"]
    t = uniform.t
    runs = _runs(result)
    diffs = {
        key: differences(result.trajectories[key], uniform)
        for group in runs.values()
        for _, key in group
    }
    paths: list[Path] = []
    for m, group in runs.items():
        for stem, q, ylabels, title in _FIGURES:
            series = [(f"degree {n}", diffs[key][q]) for n, key in group]
            paths += plotting.plot_components(
                t,
                series,
                ylabels,
                f"{title}\n{_MODEL_TITLES.get(m, m)}",
                out / f"{stem}_{m}",
                formats,
            )
    if len(runs) > 1:
        styles = {"correct": "-", "thesis": "--"}
        panels = []
        for q, label, unit in _QUANTITIES:
            name = "max |Δ angle|" if q == "euler321_deg" else f"|Δ {label}|"
            # Colour and marker per degree (the degree-50 curve lies close to the
            # degree-150 one: its markers keep it visible), line style per model.
            lines = [
                (
                    f"{m} deg {n}",
                    _norms(diffs[key])[q],
                    {
                        **plotting.distinct_styles(len(group), len(t))[i],
                        "linestyle": styles.get(m, ":"),
                    },
                )
                for m, group in runs.items()
                for i, (n, key) in enumerate(group)
            ]
            panels.append((f"{name} ({unit})", lines))
        paths += plotting.plot_panels(
            t,
            panels,
            "Differences from the uniform field: correct model (solid) and thesis "
            "Eqs. 42/59 (dashed)",
            out / "magnitudes_correct_vs_thesis",
            formats,
        )
    paths += common.orbit_figure(result, BODY, out, formats)
    return paths


def write_data(result: ScenarioResult, out: Path) -> list[Path]:
    """Every run as ``runs/KEY.npz`` (:func:`gmuk.load_trajectory`) and the plotted
    differences as ``differences.npz``: ``t_s`` and ``KEY__QUANTITY`` arrays (N, 3) with
    QUANTITY one of ``position_m``, ``velocity_m_s`` (N frame), ``euler321_deg``,
    ``omega_rad_s`` (body frame)."""
    (out / "runs").mkdir(parents=True, exist_ok=True)
    paths = [traj.save(out / "runs" / f"{key}.npz") for key, traj in result.trajectories.items()]
    uniform = result.trajectories["uniform"]
    arrays: dict[str, FloatArray] = {"t_s": uniform.t}
    for group in _runs(result).values():
        for _, key in group:
            for q, value in differences(result.trajectories[key], uniform).items():
                arrays[f"{key}__{q}"] = value
    path = out / "differences.npz"
    np.savez_compressed(path, **arrays)  # type: ignore[arg-type]
    return [*paths, path]


def _degree_list(text: str) -> tuple[int, ...]:
    """Command-line degrees: distinct integers ≥ 0, comma-separated."""
    degs = comma_separated(int)(text)
    if min(degs) < 0 or len(set(degs)) != len(degs):
        raise ValueError("must be distinct integers ≥ 0, comma-separated, e.g. 2,10,50")
    return degs


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("orbits", positive_float, 1.0, "duration, in periods of the initial orbit"),
        Option(
            "field",
            str,
            DEFAULT_FIELD,
            "lunar gravity field: the name of a field shipped with gmuk (GRGM660PRIM, to "
            "degree 150) or the path of an ICGEM .gfc file",
        ),
        Option("degrees", _degree_list, DEGREES, "harmonic degrees, comma-separated"),
        Option("model", str, "both", "gravity model(s) to run", ("both", *MODELS)),
        Option(
            "initial",
            str,
            "elements",
            "initial state: the stated 90 x 130 km orbit, or the numbers printed in §3.4",
            ("elements", "printed"),
        ),
        Option(
            "thesis_normalization",
            str,
            "thesis_eq26c_intended",
            "P̄ normalisation of the thesis model",
            THESIS_NORMALIZATIONS,
        ),
        Option("rtol", positive_float, RTOL, "integrator tolerance, rtol = atol"),
    ),
    write_data=write_data,
    central_radius=common.CENTRAL_RADIUS,
)
