"""UNMODELED: FCEI under unmodeled lunar gravity harmonics (McCann 2020, Section 5.2).

The FCEI orbit and LVLH reference of Chapter 4 (a = 4000 km, e = 0.2, i = 35°), starting on
the constraint (the reference's own state at periselene). The Udwadia–Kalaba model knows the
uniform-field gravity gradient only (Eq. 23, :class:`gmuk.GravityGradient`, μ of Chapter 4);
the plant also feels the lunar field's harmonics of degree ≥ 2 (:class:`HarmonicPerturbation`,
GRGM660PRIM to degree :data:`DEGREE` by default) as an **unmodeled** force: the perturbation
only — the central term is already the modeled one and is not counted twice, and the degree-1
terms (zero for a field referred to the centre of mass, as GRGM660PRIM is) are dropped too.

Three runs, sampled at the same times:

* ``"controlled"`` (primary): UK plus :class:`gmuk.control.MorseLyapunovController` with
  ``robust=True`` (Eq. 90, κ₂ = −39/2, other gains their defaults);
* ``"uncontrolled"``: UK alone. The UK solve prescribes the modeled acceleration of the
  reference, so the unmodeled acceleration accumulates into a drift;
* ``"nominal"``: UK alone without the perturbation (the dashed lines of the thesis).

The robust term is negligible
-----------------------------
Eq. 90 adds ``−𝕀 κ₂ O/‖r‖⁴`` (O a 6-vector of ones). As printed, with κ₂ = −39/2 and r in
metres, it is 19.5/(3.2e6)⁴ ≈ 1.9e-25 m/s² at periselene, some twenty orders of magnitude
below the perturbation it is meant to bound (≈ 7e-5 m/s² here; the units of κ₂ are not
stated). It is kept as printed (``robust=True``); ``--robust false`` changes the figures in
the seventh digit. What rejects the perturbation is the feedback of the law itself: the
modeled acceleration is fed forward, so the unmodeled one appears in ``ψ̇`` and is met within
seconds by the K₁, K₂ and κ terms, the Morse–Lyapunov force settling on minus the unmodeled
force. Over one orbit (degree 10) the position deviation stays below 0.100 m with the
default gains (no integral term; a constant unmodeled acceleration d would leave ≈ d/κ), and
below 0.086 m with an integral term k_I = 1e-8 s⁻² (``--k-integral 1e-8``).

Integration
-----------
The controlled loop has the controller's fast stable modes (≈ 1 s⁻¹), so its explicit steps
are stability-limited (≈ 2 s): DOPRI5 with steps ≤ 2 s at rtol = atol = :data:`RTOL` = 1e-11,
the loosest tolerance at which the attitude deviation (1.6e-11 rad, the same at 1e-12) is
resolved; at 1e-10 integration noise makes it 5e-11 rad, at 1e-9 4e-10 rad. The
Morse–Lyapunov torque is an acceleration-level quantity and noisier still: its residual
against minus the unmodeled torque (≤ 1.3e-7 N·m) is 1.4e-7 N·m at 1e-11 and 1.3e-8 N·m at
1e-12 (twice the cost; ``--rtol 1e-12``). The runs without a controller are not stiff: DOP853
at the Chapter 4 tolerances (rtol 3e-15, atol 1e-12); the nominal is kept on the constraint
as in :func:`gmuk.scenarios.fccl.simulate_nominal`.

Figures
-------
5.11–5.14: position and velocity in N, 3-2-1 Euler angles, body angular velocity of the
controlled run against the nominal (dashed), each with the norm of its deviation from the
reference on a log axis; 5.15/5.17: UK translational/rotational wrench against the nominal;
5.16/5.18: the Morse–Lyapunov force/torque against minus the unmodeled force/torque (what a
perfect rejection would supply); and the position and attitude deviation from the reference of
the controlled and the uncontrolled run.

Command line
------------
``gmuk run unmodeled`` (one orbit of degree-10 harmonics), ``gmuk run unmodeled --degree 50
--field PATH.gfc``, ``gmuk run unmodeled --help``.

References
----------
McCann (2020), Section 5.2, Eq. (90), Figures 5.11–5.18; Lemoine, F. G., et al. (2013),
High-degree gravity models from GRAIL primary mission data, *J. Geophys. Res. Planets* 118,
1676–1698.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

import gmuk
from gmuk import plotting
from gmuk._forms import Forms
from gmuk._validation import FloatArray
from gmuk.celestial import CelestialBody
from gmuk.control import MorseLyapunovController
from gmuk.errors import DefinitionError
from gmuk.forces import ForceModel
from gmuk.forces.gravity import field_wrench
from gmuk.gravity import SphericalHarmonicField
from gmuk.orbits import LVLHReference, fcei_orbit
from gmuk.scenarios import Option, Scenario, ScenarioResult, boolean, fccl, positive_float
from gmuk.scenarios import _lvlh as common
from gmuk.scenarios._fields import DEFAULT_FIELD, harmonic_degree, lunar_field
from gmuk.trajectory import Trajectory

if TYPE_CHECKING:
    from gmuk.bodies import Body, RigidBody

__all__ = [
    "DEFAULT_FIELD",
    "DEGREE",
    "DESCRIPTION",
    "NAME",
    "RTOL",
    "SCENARIO",
    "HarmonicPerturbation",
    "figures",
    "load_field",
    "run",
]

NAME = "unmodeled"
DESCRIPTION = (
    "Ch. 5: FCEI with unmodeled lunar harmonics (degree >= 2), UK + robust Morse-Lyapunov "
    "control vs UK alone (Figs 5.11-5.18)"
)
BODY = fccl.BODY
#: The lunar field used unless ``field`` says otherwise (shipped with gmuk, degree 150).
#: Default truncation degree of the perturbation.
DEGREE = 10
#: Controlled-run integration (DOPRI5), rtol = atol.
RTOL = 1e-11
METHOD = "DOPRI5"


class HarmonicPerturbation(ForceModel):
    """The non-central part (degrees ≥ 2) of a central body's spherical-harmonic field on
    rigid bodies and point masses; unmodeled by default.

    With U₂ the potential of the field's terms of degree ≥ 2, H₂ = ∇∇U₂ and R_FB the body's
    attitude in the central body's fixed frame F (``R_FN(t) R_NB``):

    * force ``f = m R_FBᵀ ∇U₂(r_F)`` (body frame, N);
    * torque ``L = (J H_B − H_B J)^∨`` with ``H_B = R_FBᵀ H₂ R_FB`` (body frame, N·m).

    The second-order finite-size force ``½ ∇³U₂ : Π`` is left out: relative to ``m ∇U₂`` it is
    of order (body size × degree / distance)², below 1e-9 for a spacecraft on a lunar orbit.
    The degree-0 (central) and degree-1 terms are left out: the central term belongs to the
    modeled gravity (e.g. :class:`gmuk.GravityGradient`), and the degree-1 terms vanish for
    a field referred to the centre of mass.

    Parameters
    ----------
    central_body : CelestialBody
        With a ``field`` (:class:`gmuk.gravity.SphericalHarmonicField`) and its rotation.
    degree : int, optional
        Truncate the field to this degree (≥ 2; default the field's own).
    bodies : sequence, optional
    modeled : bool
        Default False: a disturbance the constraint solve does not know.
    """

    _forms = Forms(
        compiled="a scenario's disturbance (the field's degrees ≥ 2): called back from "
        "the compiled loop",
        symbolic="a disturbance of the simulations only; no CasADi form of a field",
    )

    def __init__(
        self,
        central_body: CelestialBody,
        degree: int | None = None,
        *,
        bodies: Sequence[Body | str] | None = None,
        modeled: bool = False,
    ) -> None:
        super().__init__(bodies, modeled=modeled)
        field = getattr(central_body, "field", None)
        if not isinstance(field, SphericalHarmonicField):
            raise DefinitionError(
                "HarmonicPerturbation needs a CelestialBody with a SphericalHarmonicField "
                f"(e.g. CelestialBody.moon(field=gmuk.gravity.load('GRGM660PRIM'))); got "
                f"{central_body!r}"
            )
        deg = field.degree if degree is None else degree
        if isinstance(deg, bool) or not isinstance(deg, (int, np.integer)) or deg < 2:
            raise DefinitionError(
                f"HarmonicPerturbation: degree must be an integer >= 2; got {degree!r}"
            )
        if deg > field.degree:
            raise DefinitionError(
                f"HarmonicPerturbation: degree {deg} requested but field {field.name!r} "
                f"stops at {field.degree}"
            )
        C = np.array(field.C[: deg + 1, : deg + 1])
        S = np.array(field.S[: deg + 1, : deg + 1])
        C[:2], S[:2] = 0.0, 0.0  # degrees 0 and 1
        self.central_body = central_body
        self.field = SphericalHarmonicField(
            field.mu,
            field.radius,
            C,
            S,
            name=f"{field.name} degrees 2-{deg}",
            reference=field.reference,
            tide_system=field.tide_system,
        )

    def wrench(self, t: float, g_NB: FloatArray, V_B: FloatArray, body: RigidBody) -> FloatArray:
        """[L; f] in the body frame (N·m, N)."""
        R_FN = self.central_body.rotation.R_FN(t)
        r_F = R_FN @ g_NB[:3, 3]
        R_FB = R_FN @ g_NB[:3, :3]
        a_F, H_F = self.field.acceleration_hessian(r_F, central=False)
        return field_wrench(a_F, H_F, R_FB, body.mass, body.inertia)

    def force(self, t: float, r_N: FloatArray, v_N: FloatArray, body: Body) -> FloatArray:
        """``m ∇U₂`` at r_N, in N (N)."""
        R_FN = self.central_body.rotation.R_FN(t)
        return np.asarray(body.mass * (R_FN.T @ self.field.acceleration(R_FN @ r_N, central=False)))


def load_field(
    field: str | os.PathLike[str] | SphericalHarmonicField = DEFAULT_FIELD,
    degree: int = DEGREE,
) -> tuple[SphericalHarmonicField, str]:
    """The lunar field truncated to ``degree`` and a note saying which it is.

    Parameters
    ----------
    field : str, path-like or SphericalHarmonicField
        The name of a field shipped with gmuk (:func:`gmuk.gravity.available`; a shipped
        name wins over a file of that name), the path of an ICGEM ``.gfc`` file, or a field.
    degree : int
        Truncation degree, ≥ 2 and ≤ the field's degree.

    Raises
    ------
    DefinitionError
        A degree < 2 or above the field's; a name that is neither shipped nor a file; a field
        that is not the Moon's (GM not within 1e-3 of the Moon's).
    """
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 2:
        raise DefinitionError(f"{NAME}: degree (--degree) must be an integer >= 2; got {degree!r}")
    sh, note = lunar_field(field, NAME)
    if degree > sh.degree:
        raise DefinitionError(
            f"{NAME}: degree {degree} requested but field {note} stops at {sh.degree}"
        )
    return sh.truncate(int(degree)), f"{note}, truncated to degree {degree}"


def _system(
    perturbation: HarmonicPerturbation | None, controller: dict[str, Any] | None
) -> tuple[gmuk.System, MorseLyapunovController | None]:
    """The spacecraft on the FCEI reference, gravity gradient modeled, with the unmodeled
    ``perturbation`` and a controller made with the keywords ``controller``, if given."""
    orbit = fcei_orbit(common.MU)
    sc = common.spacecraft(BODY)
    ref = LVLHReference(orbit)
    forces: list[gmuk.ForceModel] = [gmuk.GravityGradient(orbit.mu)]
    if perturbation is not None:
        forces.append(perturbation)
    ctl = None if controller is None else MorseLyapunovController(sc, ref, **controller)
    system = gmuk.System(
        [sc], [gmuk.ConfigurationTracking(sc, ref)], forces, [ctl] if ctl is not None else []
    )
    return system, ctl


def _from_nominal(system: gmuk.System, t: FloatArray, **options: Any) -> Trajectory:
    r0 = LVLHReference(fcei_orbit(common.MU)).evaluate(0.0)
    state = system.state(g={BODY: r0.g}, V={BODY: r0.V})
    return system.simulate(state, (0.0, float(t[-1])), t_eval=t, **options)


def _deviation_summary(prefix: str, traj: Trajectory) -> dict[str, float]:
    e = fccl.tracking_norms(traj, fcei_orbit(common.MU))
    return {
        f"{prefix}_max_position_deviation_m": float(e["position_m"].max()),
        f"{prefix}_final_position_deviation_m": float(e["position_m"][-1]),
        f"{prefix}_max_velocity_deviation_m_s": float(e["velocity_m_s"].max()),
        f"{prefix}_max_attitude_deviation_rad": float(e["attitude_rad"].max()),
        f"{prefix}_final_attitude_deviation_rad": float(e["attitude_rad"][-1]),
        f"{prefix}_max_angular_velocity_deviation_rad_s": float(e["omega_rad_s"].max()),
    }


def run(
    orbits: float = 1.0,
    field: str | os.PathLike[str] | SphericalHarmonicField = DEFAULT_FIELD,
    degree: int = DEGREE,
    robust: bool = True,
    k_integral: float = fccl.K_INTEGRAL,
    rtol: float = RTOL,
) -> ScenarioResult:
    """Simulate the controlled, uncontrolled and nominal runs over ``orbits`` orbits.

    Parameters
    ----------
    orbits : float
        Span, in periods of the FCEI orbit (22 696 s).
    field : str, path-like or SphericalHarmonicField
        Lunar field (:func:`load_field`); default GRGM660PRIM, shipped with gmuk.
    degree : int
        Highest degree of the unmodeled harmonics (≥ 2).
    robust : bool
        Eq. 90's robust term in the controller (as printed; negligible, see the module).
    k_integral : float
        The controller's integral gain k_I (1/s², ≥ 0); default its own, 0 (off).
    rtol : float
        rtol = atol of the controlled DOPRI5 run.

    Raises
    ------
    DefinitionError
        An unknown or non-lunar field, or a degree out of range.
    """
    sh, note = load_field(field, degree)
    moon = CelestialBody.moon(field=sh)
    orbit = fcei_orbit(common.MU)
    t = common.time_grid(orbit, orbits)
    system, ctl = _system(HarmonicPerturbation(moon), {"robust": robust, "k_integral": k_integral})
    assert ctl is not None
    # The unmodeled force moves the plant off the UK constraint by design (what these two
    # runs measure): their constraint violation is recorded, not judged (drift_tol=None).
    controlled = _from_nominal(
        system, t, rtol=rtol, atol=rtol, method=METHOD, max_step=fccl.MAX_STEP, drift_tol=None
    )
    quiet = {"rtol": common.RTOL, "atol": common.ATOL, "drift_tol": None}
    uncontrolled = _from_nominal(_system(HarmonicPerturbation(moon), None)[0], t, **quiet)
    nominal = fccl.simulate_nominal(orbit, t)
    view = controlled.body(BODY)
    u = view.control_force
    d = controlled.unmodeled_force
    robust_term = abs(ctl.kappa2) / float(np.linalg.norm(view.position, axis=1).min()) ** 4
    summary: dict[str, Any] = {
        "field": note,
        "degree": int(degree),
        "robust": bool(robust),
        "k_integral_1_s2": ctl.k_integral,
        **_deviation_summary("controlled", controlled),
        **_deviation_summary("uncontrolled", uncontrolled),
        "nominal_max_position_deviation_m": float(
            fccl.tracking_norms(nominal, orbit)["position_m"].max()
        ),
        "peak_unmodeled_force_N": float(np.linalg.norm(d[:, 3:], axis=1).max()),
        "peak_unmodeled_torque_N_m": float(np.linalg.norm(d[:, :3], axis=1).max()),
        "peak_control_force_N": float(np.linalg.norm(u[:, 3:], axis=1).max()),
        "peak_control_torque_N_m": float(np.linalg.norm(u[:, :3], axis=1).max()),
        "control_effort_force_N_s": fccl.integral_norm(t, u[:, 3:]),
        "control_effort_torque_N_m_s": fccl.integral_norm(t, u[:, :3]),
        "final_force_rejection_residual_N": float(np.linalg.norm(u[-1, 3:] + d[-1, 3:])),
        "max_robust_term_m_s2": robust_term if robust else 0.0,
        "rhs_evaluations": int(controlled.stats["n_rhs"]),
        "steps": int(controlled.stats["n_steps"]),
    }
    return ScenarioResult(
        NAME,
        {"controlled": controlled, "uncontrolled": uncontrolled, "nominal": nominal},
        "controlled",
        summary,
    )


def figures(result: ScenarioResult, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """Figures 5.11–5.18 and the deviations of the controlled and uncontrolled runs."""
    out.mkdir(parents=True, exist_ok=True)
    trajs = result.trajectories
    ctl, unc, nom = trajs["controlled"], trajs["uncontrolled"], trajs["nominal"]
    orbit = fcei_orbit(common.MU)
    t = ctl.t
    a, n = ctl.body(BODY), nom.body(BODY)
    e, e_unc = fccl.tracking_norms(ctl, orbit), fccl.tracking_norms(unc, orbit)
    u, d = a.control_force, ctl.unmodeled_force
    axes = ("1", "2", "3")
    label = "controlled, unmodeled harmonics"
    paths: list[Path] = []

    def fig(
        key: str,
        y: FloatArray,
        y_n: FloatArray,
        ylabels: list[str],
        title: str,
        norm: tuple[str, FloatArray] | None,
        nominal_label: str = "nominal (no unmodeled force)",
    ) -> None:
        paths.extend(
            plotting.plot_against_nominal(
                t,
                y,
                y_n,
                ylabels,
                title,
                out / key,
                formats,
                label=label,
                nominal_label=nominal_label,
                norm=norm,
            )
        )

    fccl.state_figures(
        fig,
        ctl,
        nom,
        e,
        first=11,
        titles=(
            "Fig. 5.11 Position under unmodeled dynamics, in N",
            "Fig. 5.12 Velocity under unmodeled dynamics, in N",
            "Fig. 5.13 Attitude under unmodeled dynamics: 3-2-1 Euler angles",
            "Fig. 5.14 Angular velocity under unmodeled dynamics, body frame",
        ),
        attitude_label="attitude deviation (rad)",
    )
    fig(
        "fig5_15_uk_translational_control",
        a.constraint_force[:, 3:],
        n.constraint_force[:, 3:],
        [f"f{i} (N)" for i in axes],
        "Fig. 5.15 UK translational control under unmodeled dynamics, body frame",
        None,
    )
    fig(
        "fig5_16_ml_translational_control",
        u[:, 3:],
        -d[:, 3:],
        [f"u_f{i} (N)" for i in axes],
        "Fig. 5.16 M–L translational control under unmodeled dynamics, body frame",
        ("‖u_f + f_unmodeled‖ (N)", np.linalg.norm(u[:, 3:] + d[:, 3:], axis=1)),
        nominal_label="− unmodeled force",
    )
    fig(
        "fig5_17_uk_rotational_control",
        a.constraint_force[:, :3],
        n.constraint_force[:, :3],
        [f"L{i} (N·m)" for i in axes],
        "Fig. 5.17 UK rotational control under unmodeled dynamics, body frame",
        None,
    )
    fig(
        "fig5_18_ml_rotational_control",
        u[:, :3],
        -d[:, :3],
        [f"u_L{i} (N·m)" for i in axes],
        "Fig. 5.18 M–L rotational control under unmodeled dynamics, body frame",
        ("‖u_L + L_unmodeled‖ (N·m)", np.linalg.norm(u[:, :3] + d[:, :3], axis=1)),
        nominal_label="− unmodeled torque",
    )
    for key, ylabel, what in (
        ("position_m", "‖r − r_n‖ (m)", "Position"),
        ("attitude_rad", "attitude deviation (rad)", "Attitude"),
    ):
        paths += plotting.plot_log_lines(
            t,
            [
                ("UK + Morse–Lyapunov (robust)", e[key], {"color": "C0"}),
                ("UK alone", e_unc[key], {"color": "C3", "ls": "--"}),
            ],
            ylabel,
            f"{what} deviation from the reference under unmodeled lunar harmonics",
            out / f"unmodeled_{key.split('_')[0]}_deviation",
            formats,
        )
    paths += common.orbit_figure(result, BODY, out, formats)
    return paths


SCENARIO = Scenario(
    NAME,
    DESCRIPTION,
    run,
    figures,
    options=(
        Option("orbits", positive_float, 1.0, "span, in periods of the FCEI orbit (22696 s)"),
        Option(
            "field",
            str,
            DEFAULT_FIELD,
            "lunar gravity field: the name of a field shipped with gmuk (GRGM660PRIM, to "
            "degree 150) or the path of an ICGEM .gfc file",
        ),
        Option(
            "degree", harmonic_degree, DEGREE, "highest degree of the unmodeled harmonics (>= 2)"
        ),
        Option("robust", boolean, True, "Eq. 90's robust term in the controller"),
        Option(
            "k_integral",
            fccl.non_negative_float,
            fccl.K_INTEGRAL,
            "integral gain k_I of the controller (1/s²); 0 removes the integral term",
        ),
        Option("rtol", positive_float, RTOL, "controlled-run DOPRI5 tolerance, rtol = atol"),
    ),
    central_radius=common.CENTRAL_RADIUS,
)
