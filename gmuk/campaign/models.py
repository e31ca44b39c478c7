"""Campaign models: what one run of a campaign simulates, from its parameter values.

A :class:`CampaignModel` declares its :class:`Parameter` s (name, kind, nominal value, domain,
help) and turns one set of values into a run: :meth:`CampaignModel.run` returns the
trajectory and the run's headline metrics (floats, SI units in the names). gmuk's scenarios
with campaign support each have one (:data:`MODELS`, :func:`get_model`):

``fcei``
    The FCEI spacecraft (McCann 2020, §4.3.1.2) tracking the modified-LVLH reference with
    critically damped Baumgarte stabilisation (Eq. 4), from a dispersed start: attitude
    error, position and velocity errors, mass and inertia, Baumgarte gains.
``ucei``
    The UCEI virtual-spacecraft pair (§4.1.3): the virtual body tracks the reference with
    Baumgarte stabilisation from a dispersed start, the spacecraft starts with it, free to
    roll about axis 1 (roll-rate error dispersed), its relative velocity held by a
    velocity-level Baumgarte term.
``fccl``
    The Chapter 5 closed loop: the corrected Morse–Lyapunov controller returns the
    spacecraft to the FCEI reference from a dispersed start (attitude errors up to 179° by
    default, position, velocity and body-rate errors, the integral gain): the
    almost-global convergence study.
``apollo16``
    The Chapter 3 orbit (§3.4): the free LM in the GRAIL field GRGM660PRIM truncated at
    ``degree`` (gmuk's correct model), compared with the uniform-field run — the gravity-
    degree sensitivity study.

A user function becomes a model with :class:`FunctionModel`.
"""

from __future__ import annotations

import abc
import functools
import importlib
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gmuk.campaign.dispersions import KINDS, Dispersion
from gmuk.errors import DefinitionError
from gmuk.trajectory import Trajectory

__all__ = [
    "MODELS",
    "CampaignModel",
    "FunctionModel",
    "Parameter",
    "RunSetup",
    "get_model",
    "scaled_inertia",
    "supported",
]


def _as_float(value: Any) -> float:
    """``float(value)``, or ±inf for an integer beyond float64 (refused as not finite)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


@dataclass(frozen=True)
class Parameter:
    """A parameter of a campaign model.

    Parameters
    ----------
    name : str
        Keyword of the model (a Python identifier).
    kind : {"real", "integer", "vector3", "rotation", "scale3"}
        What its values are (:mod:`gmuk.campaign.dispersions`).
    default : object
        The nominal value, used when the campaign neither fixes nor disperses it.
    help : str
        One line, with the unit and frame.
    low, high : float, optional
        Domain of a scalar (or of each component of a scale3): ``low < value`` if
        ``low_open`` else ``low ≤ value``; ``value ≤ high``.
    low_open : bool
        Whether ``low`` itself is excluded.
    """

    name: str
    kind: str
    default: Any
    help: str
    low: float | None = None
    high: float | None = None
    low_open: bool = False

    def __post_init__(self) -> None:
        if not self.name.isidentifier():
            raise DefinitionError(f"parameter name must be an identifier; got {self.name!r}")
        if self.kind not in KINDS:
            raise DefinitionError(
                f"parameter {self.name!r}: kind must be one of {', '.join(KINDS)}; got "
                f"{self.kind!r}"
            )
        object.__setattr__(self, "default", self.check(self.default))

    def domain(self) -> str:
        """The domain in words, e.g. ``"> 0"`` or ``"in [2, 150]"``."""
        lo = None if self.low is None else f"{'>' if self.low_open else '≥'} {self.low:g}"
        hi = None if self.high is None else f"≤ {self.high:g}"
        return " and ".join(p for p in (lo, hi) if p) or "any finite value"

    def _inside(self, x: float) -> bool:
        if self.low is not None and (x <= self.low if self.low_open else x < self.low):
            return False
        return self.high is None or x <= self.high

    def check(self, value: Any) -> Any:
        """``value`` in the canonical form of the kind (int, float or tuple of 3 floats).

        Raises
        ------
        DefinitionError
            A value of the wrong kind, not finite, or outside the domain.
        """
        what = f"parameter {self.name!r}"
        if self.kind == "integer":
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
                raise DefinitionError(f"{what} must be an integer; got {value!r}")
            out: Any = int(value)
            comps = [_as_float(out)]
        elif self.kind == "real":
            if isinstance(value, (bool, np.bool_, str, bytes)) or not isinstance(
                value, (int, float, np.integer, np.floating)
            ):
                raise DefinitionError(f"{what} must be a real number; got {value!r}")
            out = _as_float(value)
            comps = [out]
        else:
            try:
                arr = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                arr = np.zeros(0)
            except OverflowError:  # an integer beyond float64
                raise DefinitionError(f"{what} must be finite; got {value!r:.80}") from None
            if arr.shape != (3,) or isinstance(value, (str, bytes)):
                raise DefinitionError(f"{what} must be three real numbers; got {value!r}")
            out = (float(arr[0]), float(arr[1]), float(arr[2]))
            comps = list(out) if self.kind == "scale3" else []
            if self.kind == "rotation" and float(np.linalg.norm(arr)) > math.pi + 1e-12:
                raise DefinitionError(
                    f"{what} is a rotation vector of angle ≤ π; got angle "
                    f"{float(np.linalg.norm(arr))!r} rad"
                )
        if not all(math.isfinite(c) for c in ([*comps, *np.ravel(out)])):
            raise DefinitionError(f"{what} must be finite; got {value!r:.80}")
        bad = [c for c in comps if not self._inside(c)]
        if bad:
            raise DefinitionError(f"{what} must be {self.domain()} ({self.help}); got {value!r}")
        return out

    def check_dispersion(self, dispersion: Dispersion) -> None:
        """Refuse a dispersion of another kind or one that can leave the domain."""
        if not isinstance(dispersion, Dispersion):
            raise DefinitionError(
                f"the dispersion of {self.name!r} must be a gmuk.campaign Dispersion; got "
                f"{dispersion!r}"
            )
        fits = dispersion.kind == self.kind or (
            dispersion.kind == "integer" and self.kind == "real"
        )
        if not fits:
            raise DefinitionError(
                f"parameter {self.name!r} takes {self.kind} values; {dispersion!r} gives "
                f"{dispersion.kind} values"
            )
        if self.kind in ("real", "integer", "scale3"):
            lo, hi = dispersion.support()
            bad = [x for x in (lo, hi) if not self._inside(x)]
            if bad:
                raise DefinitionError(
                    f"the dispersion of {self.name!r} ({self.help}) must stay {self.domain()}; "
                    f"{dispersion!r} reaches {bad[0]!r}"
                )


@dataclass(frozen=True)
class RunSetup:
    """What a :class:`FunctionModel`'s function may return instead of metrics: a System, its
    initial State and the span to simulate.

    Parameters
    ----------
    system : gmuk.System
    state : gmuk.State
    t_span : (float, float)
        Start and end times (s).
    options : dict
        Further keywords of :meth:`gmuk.System.simulate` (``t_eval``, ``rtol``, …).
    metrics : callable, optional
        ``metrics(trajectory) -> dict[str, float]``: the run's headline metrics. The largest
        constraint residual ``max_constraint_residual`` and the step and right-hand-side counts
        are always recorded.
    """

    system: Any
    state: Any
    t_span: tuple[float, float]
    options: dict[str, Any] = field(default_factory=dict)
    metrics: Callable[[Trajectory], Mapping[str, float]] | None = None


def _basic_metrics(traj: Trajectory) -> dict[str, float]:
    """Metrics every simulated run records."""
    residual = traj.residual[np.isfinite(traj.residual)]
    return {
        "t_reached_s": float(traj.t[-1]) if len(traj.t) else math.nan,
        "max_constraint_residual": float(residual.max()) if residual.size else math.nan,
        "steps": float(traj.stats.get("n_steps", math.nan)),
        "rhs_evaluations": float(traj.stats.get("n_rhs", math.nan)),
    }


class CampaignModel(abc.ABC):
    """What one run of a campaign simulates: declared parameters → (trajectory, metrics).

    Subclasses set :attr:`name`, :attr:`description`, :attr:`parameters`,
    :attr:`headline` (the metrics the summary scatters against the dispersions) and
    implement :meth:`run`. A model must be picklable (it is sent to worker processes): keep
    it a module-level object.
    """

    name: str = ""
    description: str = ""
    parameters: tuple[Parameter, ...] = ()
    headline: tuple[str, ...] = ()
    #: Dispersions and sweep of ``gmuk campaign NAME`` when none is given.
    default_dispersions: Mapping[str, Dispersion] = {}
    default_grid: Mapping[str, tuple[Any, ...]] = {}

    def parameter(self, name: str) -> Parameter:
        """The declared parameter ``name``."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise DefinitionError(
            f"campaign model {self.name!r} has no parameter {name!r}; it takes "
            f"{', '.join(p.name for p in self.parameters) or 'none'}"
        )

    @abc.abstractmethod
    def run(self, params: Mapping[str, Any]) -> tuple[Trajectory | None, dict[str, float]]:
        """Simulate one run with every declared parameter's value in ``params``; return its
        trajectory (None if there is none) and metrics."""

    def to_dict(self) -> dict[str, Any]:
        """How the manifest names the model (:func:`model_from_dict` inverts it)."""
        return {"scenario": self.name}


def model_from_dict(data: Mapping[str, Any]) -> CampaignModel:
    """The model a manifest names."""
    if "function" in data:
        return FunctionModel.from_dict(data)
    return get_model(str(data.get("scenario")))


# --- gmuk's scenario adapters --------------------------------------------------------------------


def scaled_inertia(J: Any, factors: Any, mass_scale: float = 1.0) -> np.ndarray:
    """The inertia ``J`` (3, 3) (kg·m², body frame) with its second moments of mass about its
    principal axes scaled by ``factors`` (3,) (> 0), times ``mass_scale`` (> 0).

    ``Aᵢ = (tr J)/2 − Jᵢ`` in principal axes, ``Aᵢ ← sᵢ Aᵢ``, ``Jᵢ = Σ A − Aᵢ``, same axes: the
    result satisfies the triangle inequality whenever J does
    (:class:`~gmuk.campaign.dispersions.SecondMomentScale`).

    Parameters
    ----------
    J : array_like, shape (3, 3)
        A physical central inertia (kg·m²), as :func:`gmuk.dynamics.check_inertia` accepts
        it: symmetric positive definite, triangle inequality, usable inverse.
    factors : array_like, shape (3,)
        Finite real scale factors > 0 of the second moments A₁, A₂, A₃.
    mass_scale : float
        Finite real factor > 0 on the whole tensor.

    Returns
    -------
    ndarray, shape (3, 3)
        The dispersed inertia (kg·m²), itself checked by :func:`~gmuk.dynamics.check_inertia`.

    Raises
    ------
    InertiaError
        If J is zero, not symmetric positive definite, violates the triangle inequality or
        has no usable inverse, or if the scaled result has no usable inverse.
    DefinitionError
        If ``factors`` is not 3 finite numbers > 0 or ``mass_scale`` not a finite number
        > 0 (booleans and strings are refused).
    """
    from gmuk._validation import real_number, real_vector
    from gmuk.dynamics import check_inertia

    _, J = check_inertia(1.0, J, name="scaled_inertia: J")
    s = real_vector(factors, "scaled_inertia: factors", 3, positive=True)
    k = real_number(mass_scale, "scaled_inertia: mass_scale", positive=True)
    moments, axes = np.linalg.eigh(0.5 * (J + J.T))
    A = np.maximum(0.5 * moments.sum() - moments, 0.0)  # ≥ 0 by the triangle inequality
    A = s * A
    dispersed = A.sum() - A
    with np.errstate(over="ignore", invalid="ignore"):
        out = k * (axes * dispersed) @ axes.T
        out = np.asarray(0.5 * (out + out.T))
    _, out = check_inertia(1.0, out, name="scaled_inertia: the scaled inertia")
    return out


def _attitude_pose(g_ref: np.ndarray, rotation: Any, dr_N: Any) -> np.ndarray:
    """Reference pose with R_NB = R_NL exp(θ̂) (attitude error in the body frame) and
    r_N = r_ref + dr_N."""
    from gmuk.lie import so3

    g = np.array(g_ref, dtype=float)
    g[:3, :3] = g_ref[:3, :3] @ so3.exp(np.asarray(rotation, dtype=float))
    g[:3, 3] = g_ref[:3, 3] + np.asarray(dr_N, dtype=float)
    return g


def _dispersed_twist(g_ref: np.ndarray, V_ref: np.ndarray, g: np.ndarray, dv_N: Any) -> np.ndarray:
    """Body twist with the reference's body rates and the reference's inertial velocity plus
    ``dv_N``, expressed in the dispersed body frame."""
    v_N = g_ref[:3, :3] @ V_ref[3:] + np.asarray(dv_N, dtype=float)
    return np.concatenate([V_ref[:3], g[:3, :3].T @ v_N])


def _error_metrics(t: np.ndarray, pos: np.ndarray, att: np.ndarray) -> dict[str, float]:
    """Initial, final and largest position (m) and attitude (rad) errors against the
    reference, and their settling times (s), at output times ``t``."""
    return {
        "initial_position_error_m": float(pos[0]),
        "initial_attitude_error_rad": float(att[0]),
        "final_position_error_m": float(pos[-1]),
        "final_attitude_error_rad": float(att[-1]),
        "max_position_error_m": float(pos.max()),
        "max_attitude_error_rad": float(att.max()),
        "position_settling_time_s": _settling_time(t, pos),
        "attitude_settling_time_s": _settling_time(t, att),
    }


def _settling_time(t: np.ndarray, err: np.ndarray, fraction: float = 0.02) -> float:
    """First time after which ``err`` stays ≤ ``fraction`` of its initial value (s); NaN if it
    never settles within the run."""
    bound = fraction * err[0]
    above = np.nonzero(err > bound)[0]
    if above.size == 0:
        return float(t[0])
    last = int(above[-1])
    return float(t[last + 1]) if last + 1 < len(t) else math.nan


def _span(orbits: float, samples: int) -> tuple[Parameter, Parameter]:
    """The duration (in FCEI periods) and output-count parameters, with these defaults."""
    return (
        Parameter(
            "orbits",
            "real",
            orbits,
            "duration, in periods of the FCEI orbit",
            low=0.0,
            low_open=True,
            high=1e3,
        ),
        Parameter("samples", "integer", samples, "output times per run", low=2, high=1e6),
    )


_ERRORS = (
    Parameter("attitude_error", "rotation", (0.0, 0.0, 0.0), "initial attitude error θn̂ (rad)"),
    Parameter("position_error_m", "vector3", (0.0, 0.0, 0.0), "initial position error (m, N)"),
    Parameter("velocity_error_m_s", "vector3", (0.0, 0.0, 0.0), "initial velocity error (m/s, N)"),
    Parameter(
        "mass_scale", "real", 1.0, "factor on the LM's mass and inertia", low=0.0, low_open=True
    ),
    Parameter(
        "inertia_scale",
        "scale3",
        (1.0, 1.0, 1.0),
        "factors on the LM's principal second moments of mass",
        low=0.0,
        low_open=True,
    ),
    Parameter(
        "baumgarte_omega_n",
        "real",
        0.05,
        "Baumgarte natural frequency ω_n (rad/s): α = 2ζω_n, β = ω_n²; 0: none",
        low=0.0,
    ),
    Parameter("baumgarte_zeta", "real", 1.0, "Baumgarte damping ratio ζ", low=0.0),
    *_span(orbits=0.01, samples=201),
    Parameter("rtol", "real", 1e-12, "integrator rtol", low=0.0, low_open=True),
    Parameter("atol", "real", 1e-9, "integrator atol", low=0.0, low_open=True),
)


def _default_fcei_dispersions() -> dict[str, Dispersion]:
    from gmuk.campaign.dispersions import AttitudeCone, GaussianVector, Uniform, UniformBall

    return {
        "attitude_error": AttitudeCone(math.radians(10.0)),
        "position_error_m": UniformBall(100.0),
        "velocity_error_m_s": GaussianVector(0.1),
        "baumgarte_omega_n": Uniform(0.03, 0.1),
    }


class _LVLHModel(CampaignModel):
    """Shared set-up of the Chapter 4 adapters."""

    parameters: tuple[Parameter, ...] = _ERRORS
    headline = ("final_position_error_m", "final_attitude_error_rad")

    @property
    def default_dispersions(self) -> Mapping[str, Dispersion]:  # type: ignore[override]
        return _default_fcei_dispersions()

    def _common(self, p: Mapping[str, Any]) -> tuple[Any, ...]:
        import gmuk
        from gmuk.orbits import LVLHReference, fcei_orbit
        from gmuk.scenarios import _lvlh as common

        orbit = fcei_orbit(common.MU)
        ref = LVLHReference(orbit)
        omega, zeta = p["baumgarte_omega_n"], p["baumgarte_zeta"]
        # ω_n = 0: no stabilisation terms at all (the thesis's FCEI/UCEI, faster)
        gains = None if omega == 0 else gmuk.Baumgarte(alpha=2.0 * zeta * omega, beta=omega**2)
        mass = common.LM_MASS * p["mass_scale"]
        J = scaled_inertia(common.LM_INERTIA, p["inertia_scale"], p["mass_scale"])
        r0 = ref.evaluate(0.0)
        g0 = _attitude_pose(r0.g, p["attitude_error"], p["position_error_m"])
        V0 = _dispersed_twist(r0.g, r0.V, g0, p["velocity_error_m_s"])
        t = np.linspace(0.0, p["orbits"] * orbit.period, p["samples"])
        options = {"t_eval": t, "rtol": p["rtol"], "atol": p["atol"], "on_failure": "return"}
        return orbit, ref, gains, mass, J, g0, V0, t, options

    @staticmethod
    def _tracking_metrics(traj: Trajectory, orbit: Any, body: str) -> dict[str, float]:
        from gmuk.scenarios import _lvlh as common

        pos, att = common.reference_errors(traj, orbit, body)
        view = traj.body(body)
        f = np.linalg.norm(view.constraint_force[:, 3:], axis=1)
        L = np.linalg.norm(view.constraint_force[:, :3], axis=1)
        return {
            **_error_metrics(traj.t, pos, att),
            "peak_constraint_force_N": float(f.max()),
            "peak_constraint_torque_N_m": float(L.max()),
        }


class FCEIModel(_LVLHModel):
    """FCEI with Baumgarte stabilisation from a dispersed start (module docstring)."""

    name = "fcei"
    description = "FCEI tracking with Baumgarte stabilisation from a dispersed start"

    def run(self, params: Mapping[str, Any]) -> tuple[Trajectory | None, dict[str, float]]:
        import gmuk

        orbit, ref, gains, mass, J, g0, V0, t, options = self._common(params)
        sc = gmuk.RigidBody("spacecraft", mass, J)
        system = gmuk.System(
            [sc],
            [gmuk.ConfigurationTracking(sc, ref, baumgarte=gains)],
            [gmuk.GravityGradient(orbit.mu)],
        )
        state = system.state(g={"spacecraft": g0}, V={"spacecraft": V0})
        traj = system.simulate(state, (0.0, float(t[-1])), **options)
        return traj, {**self._tracking_metrics(traj, orbit, "spacecraft"), **_basic_metrics(traj)}


class UCEIModel(_LVLHModel):
    """The UCEI pair with Baumgarte stabilisation from a dispersed start (module docstring)."""

    name = "ucei"
    description = "UCEI virtual-spacecraft pair with Baumgarte stabilisation, dispersed start"
    parameters: tuple[Parameter, ...] = (
        *_ERRORS,
        Parameter("roll_rate_error_rad_s", "real", 0.0, "spacecraft's initial ω₁ − virtual's"),
    )

    def run(self, params: Mapping[str, Any]) -> tuple[Trajectory | None, dict[str, float]]:
        import gmuk
        from gmuk.scenarios import _lvlh as common

        orbit, ref, gains, mass, J, g0, V0, t, options = self._common(params)
        virtual = gmuk.RigidBody("virtual", mass, J)
        sc = gmuk.RigidBody("spacecraft", mass, J)
        system = gmuk.System(
            [virtual, sc],
            [
                gmuk.ConfigurationTracking(virtual, ref, baumgarte=gains),
                gmuk.RelativeConstraint(
                    sc,
                    virtual,
                    free_axes=[0],
                    baumgarte=None if gains is None else gmuk.Baumgarte(alpha=gains.alpha),
                ),
            ],
            [gmuk.GravityGradient(orbit.mu)],
        )
        V_sc = V0.copy()
        V_sc[0] += params["roll_rate_error_rad_s"]
        state = system.state(
            g={"virtual": g0, "spacecraft": g0}, V={"virtual": V0, "spacecraft": V_sc}
        )
        traj = system.simulate(state, (0.0, float(t[-1])), **options)
        rel = common.relative_pose(traj)
        metrics = self._tracking_metrics(traj, orbit, "virtual")
        sc_force = traj.body("spacecraft").constraint_force
        metrics |= {
            "max_locked_rotation_rad": float(np.abs(rel[:, 1:3]).max()),
            "max_locked_translation_m": float(np.linalg.norm(rel[:, 3:], axis=1).max()),
            "final_roll_rad": float(rel[-1, 0]),
            "peak_spacecraft_constraint_force_N": float(
                np.linalg.norm(sc_force[:, 3:], axis=1).max()
            ),
            "peak_spacecraft_constraint_torque_N_m": float(
                np.linalg.norm(sc_force[:, :3], axis=1).max()
            ),
        }
        return traj, {**metrics, **_basic_metrics(traj)}


def _apollo16_run(degree: int, orbits: float, samples: int, rtol: float) -> tuple[Trajectory, Any]:
    """The Chapter 3 orbit in the uniform field (``degree`` < 0) or GRGM660PRIM truncated at
    ``degree`` (gmuk's correct model); also returns the field's Moon and the times."""
    import gmuk
    from gmuk.forces import SphericalHarmonicGravity
    from gmuk.scenarios import apollo16

    sh, _, _ = apollo16.load_field(apollo16.DEFAULT_FIELD, (max(degree, 0),))
    moon = gmuk.CelestialBody.moon(field=sh)
    g0, V0, period = apollo16.initial_state("elements", moon.mu, moon.radius)
    t = np.linspace(0.0, orbits * period, samples)
    force: gmuk.ForceModel = (
        gmuk.GravityGradient(moon.mu) if degree < 0 else SphericalHarmonicGravity(moon, degree)
    )
    return apollo16._simulate(force, g0, V0, t, rtol), t


#: The comparison run of each process, by (degree, orbits, samples, rtol): computed once.
_apollo16_reference = functools.lru_cache(maxsize=8)(_apollo16_run)


class Apollo16Model(CampaignModel):
    """The Chapter 3 orbit at one GRAIL degree against a reference run (module docstring).

    The reference is the uniform-field run (``reference_degree = -1``, default: the thesis's
    Figures 3.1–3.4) or the run at ``reference_degree`` (e.g. 150: the truncation error of
    each degree), with the same duration, output times and tolerance; each worker process
    computes it once. Metrics are the differences run − reference: position (m, N) — maximum,
    final, its largest radial part and its along-track part at the end (RSW of the
    reference) —, velocity (m/s), attitude (rad: angle of R_refᵀ R) and body rate (rad/s).
    """

    name = "apollo16"
    description = "Ch. 3 orbit at a GRAIL degree vs the uniform field (degree sweep)"
    parameters = (
        Parameter("degree", "integer", 150, "GRGM660PRIM degree (correct model)", 0, 150),
        Parameter(
            "reference_degree",
            "integer",
            -1,
            "degree of the comparison run; -1: the uniform field",
            -1,
            150,
        ),
        Parameter(
            "orbits",
            "real",
            1.0,
            "duration, in periods of the initial orbit",
            0.0,
            1e3,
            low_open=True,
        ),
        Parameter("samples", "integer", 361, "output times per run", 2, 1e6),
        Parameter("rtol", "real", 1e-11, "integrator rtol = atol", 0.0, low_open=True),
    )
    headline = ("max_position_difference_m", "max_attitude_difference_rad")

    @property
    def default_grid(self) -> Mapping[str, tuple[Any, ...]]:  # type: ignore[override]
        return {"degree": tuple(range(2, 151))}

    def run(self, params: Mapping[str, Any]) -> tuple[Trajectory | None, dict[str, float]]:
        from gmuk.lie import so3
        from gmuk.scenarios import apollo16

        settings = (params["orbits"], params["samples"], params["rtol"])
        reference, _ = _apollo16_reference(params["reference_degree"], *settings)
        traj, _ = _apollo16_run(params["degree"], *settings)
        d = apollo16.differences(traj, reference)
        a, b = traj.body(apollo16.BODY), reference.body(apollo16.BODY)
        att = np.linalg.norm(so3.log(np.swapaxes(b.R, 1, 2) @ a.R), axis=1)
        dr = np.linalg.norm(d["position_m"], axis=1)
        rsw = apollo16.rsw(reference, d["position_m"])
        metrics = {
            "max_position_difference_m": float(dr.max()),
            "final_position_difference_m": float(dr[-1]),
            "final_along_track_difference_m": float(rsw[-1, 1]),
            "max_radial_difference_m": float(np.abs(rsw[:, 0]).max()),
            "max_velocity_difference_m_s": float(np.linalg.norm(d["velocity_m_s"], axis=1).max()),
            "max_attitude_difference_rad": float(att.max()),
            "max_angular_velocity_difference_rad_s": float(
                np.linalg.norm(d["omega_rad_s"], axis=1).max()
            ),
        }
        return traj, {**metrics, **_basic_metrics(traj)}


def _default_fccl_dispersions() -> dict[str, Dispersion]:
    from gmuk.campaign.dispersions import AttitudeCone, GaussianVector, UniformBall

    return {
        "attitude_error": AttitudeCone(math.radians(179.0)),
        "position_error_m": UniformBall(1000.0),
        "velocity_error_m_s": GaussianVector(0.1),
        "rate_error_rad_s": GaussianVector(0.01),
    }


class FCCLModel(CampaignModel):
    """The Chapter 5 closed loop: the corrected Morse–Lyapunov tracking law (Eq. 81) takes
    the spacecraft back to the FCEI reference from a dispersed start — the almost-global
    convergence study (McCann 2020, §5.1; ``gmuk run fccl``)."""

    name = "fccl"
    description = "FCCL: the corrected tracking controller from dispersed starts (Ch. 5)"
    parameters: tuple[Parameter, ...] = (
        *_ERRORS[:3],  # attitude, position and velocity errors
        Parameter(
            "rate_error_rad_s", "vector3", (0.0, 0.0, 0.0), "initial body-rate error (rad/s, B)"
        ),
        Parameter("k_integral", "real", 0.0, "the controller's integral gain k_I (1/s²)", low=0.0),
        *_span(orbits=0.1, samples=101),
        Parameter("rtol", "real", 1e-9, "integrator rtol = atol (DOPRI5)", low=0.0, low_open=True),
    )
    headline = ("final_attitude_error_rad", "final_position_error_m")

    @property
    def default_dispersions(self) -> Mapping[str, Dispersion]:  # type: ignore[override]
        return _default_fccl_dispersions()

    def run(self, params: Mapping[str, Any]) -> tuple[Trajectory | None, dict[str, float]]:
        from gmuk.orbits import LVLHReference
        from gmuk.scenarios import _lvlh as common
        from gmuk.scenarios import fccl

        system, _, orbit = fccl.build(k_integral=params["k_integral"])
        r0 = LVLHReference(orbit).evaluate(0.0)
        g0 = _attitude_pose(r0.g, params["attitude_error"], params["position_error_m"])
        V0 = _dispersed_twist(r0.g, r0.V, g0, params["velocity_error_m_s"])
        V0[:3] += np.asarray(params["rate_error_rad_s"], dtype=float)
        state = system.state(g={fccl.BODY: g0}, V={fccl.BODY: V0})
        t = np.linspace(0.0, params["orbits"] * orbit.period, params["samples"])
        traj = system.simulate(
            state,
            (0.0, float(t[-1])),
            t_eval=t,
            rtol=params["rtol"],
            atol=params["rtol"],
            method=fccl.METHOD,
            max_step=fccl.MAX_STEP,
            on_failure="return",
        )
        pos, att = common.reference_errors(traj, orbit, fccl.BODY)
        u = traj.body(fccl.BODY).control_force
        metrics = {
            **_error_metrics(traj.t, pos, att),
            "peak_control_torque_N_m": float(np.linalg.norm(u[:, :3], axis=1).max()),
            "peak_control_force_N": float(np.linalg.norm(u[:, 3:], axis=1).max()),
        }
        return traj, {**metrics, **_basic_metrics(traj)}


#: gmuk's scenarios with campaign support: name → model.
MODELS: dict[str, CampaignModel] = {
    m.name: m for m in (FCEIModel(), UCEIModel(), FCCLModel(), Apollo16Model())
}


def supported() -> list[str]:
    """Names of the scenarios with campaign support."""
    return list(MODELS)


def get_model(name: str) -> CampaignModel:
    """The campaign model of scenario ``name`` (case-insensitive).

    Raises
    ------
    DefinitionError
        An unknown scenario, or one without campaign support; the message lists the
        supported ones.
    """
    key = str(name).lower()
    if key in MODELS:
        return MODELS[key]
    from gmuk import scenarios

    known = {s.name for s, _ in scenarios.available()}
    why = (
        f"scenario {name!r} has no campaign support"
        if key in known
        else f"unknown scenario {name!r}"
    )
    raise DefinitionError(
        f"{why}; campaigns support: {', '.join(MODELS)} (or give a function: "
        "gmuk.campaign.Campaign.from_function)"
    )


# --- user functions ------------------------------------------------------------------------------


def _infer(name: str, value: Any) -> Parameter:
    if isinstance(value, Parameter):
        if value.name != name:
            raise DefinitionError(f"parameters[{name!r}] is a Parameter named {value.name!r}")
        return value
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        return Parameter(name, "integer", value, name)
    if isinstance(value, (float, np.floating)):
        return Parameter(name, "real", value, name)
    return Parameter(name, "vector3", value, name)


class FunctionModel(CampaignModel):
    """A campaign model from a user function.

    Parameters
    ----------
    function : callable
        ``function(params) -> RunSetup | dict``: ``params`` maps every parameter name to its
        value. Return a :class:`RunSetup` (gmuk simulates it and records its metrics) or the
        metrics themselves (``{name: float}``; no trajectory). It must be importable by name
        (a module-level function), so that worker processes and ``--resume`` find it.
    parameters : mapping of str to Parameter or default value
        The parameters: a :class:`Parameter`, or a nominal value whose type gives the kind
        (int → integer, float → real, three numbers → vector3).
    headline : sequence of str
        Metrics the summary scatters against the dispersions.
    """

    def __init__(
        self,
        function: Callable[[dict[str, Any]], Any],
        parameters: Mapping[str, Any],
        headline: tuple[str, ...] = (),
    ) -> None:
        if not callable(function):
            raise DefinitionError(f"function must be callable; got {function!r}")
        module = getattr(function, "__module__", None)
        qualname = getattr(function, "__qualname__", "")
        if not module or "<" in qualname:
            raise DefinitionError(
                f"function must be a module-level function (importable by name, for worker "
                f"processes and --resume); got {function!r}"
            )
        self.function = function
        self.target = f"{module}:{qualname}"
        self.name = f"function:{self.target}"
        self.description = (function.__doc__ or "").strip().split("\n")[0]
        self.parameters = tuple(_infer(k, v) for k, v in parameters.items())
        self.headline = tuple(headline)

    def run(self, params: Mapping[str, Any]) -> tuple[Trajectory | None, dict[str, float]]:
        out = self.function(dict(params))
        if isinstance(out, RunSetup):
            traj = out.system.simulate(out.state, out.t_span, **out.options)
            extra = dict(out.metrics(traj)) if out.metrics is not None else {}
            return traj, {**{k: float(v) for k, v in extra.items()}, **_basic_metrics(traj)}
        if isinstance(out, Mapping):
            return None, {str(k): float(v) for k, v in out.items()}
        raise DefinitionError(
            f"{self.target} must return a gmuk.campaign.RunSetup or a dict of metrics; got "
            f"{type(out).__name__}"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "function": self.target,
            "parameters": [
                {
                    "name": p.name,
                    "kind": p.kind,
                    "default": p.default,
                    "help": p.help,
                    "low": p.low,
                    "high": p.high,
                    "low_open": p.low_open,
                }
                for p in self.parameters
            ],
            "headline": list(self.headline),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> FunctionModel:
        """The model a manifest describes (imports its function)."""
        target = str(data["function"])
        module, _, qualname = target.partition(":")
        try:
            obj: Any = importlib.import_module(module)
            for part in qualname.split("."):
                obj = getattr(obj, part)
        except (ImportError, AttributeError) as exc:
            raise DefinitionError(f"cannot import the campaign function {target}: {exc}") from None
        params = {
            p["name"]: Parameter(
                p["name"],
                p["kind"],
                tuple(p["default"]) if isinstance(p["default"], list) else p["default"],
                p["help"],
                p["low"],
                p["high"],
                p["low_open"],
            )
            for p in data["parameters"]
        }
        return cls(obj, params, tuple(data.get("headline", ())))
