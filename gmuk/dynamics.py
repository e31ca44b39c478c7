"""Rigid-body dynamics on SE(3) as pure functions (McCann 2020, Eqs. 10–11, 17–19).

The body frame B sits at the centre of mass. Twists ``V_B = [ω; v]`` are the velocity of B
relative to N expressed in B (rad/s, m/s); wrenches ``τ_B = [L; f]`` are torques about the
centre of mass and forces, expressed in B (N·m, N).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gmuk._numba import njit
from gmuk._validation import NOT_REAL, FloatArray, as_array, check_se3, finite_result
from gmuk.errors import InertiaError
from gmuk.lie import se3

__all__ = [
    "check_inertia",
    "check_mass",
    "check_spatial_inertia",
    "free_acceleration",
    "g_ddot",
    "inertia_pinv",
    "kinetic_energy",
    "singular_mass",
    "spatial_inertia",
    "spatial_momentum",
    "zero_moments",
]

#: Relative tolerance for symmetry of J and for the triangle inequalities of its moments.
INERTIA_TOL = 1e-9

#: Smallest usable mass (kg) or principal moment (kg·m²): the smallest normal float64,
#: 2.2e-308. Below it (5e-324, 1e-320) the number is subnormal and its reciprocal is inf.
USABLE_MIN = float(np.finfo(np.float64).tiny)
#: Largest usable mass or principal moment, 1/USABLE_MIN ≈ 4.5e307: its reciprocal is then
#: still a normal number, and sums of three moments (the triangle inequality, tr J) are finite.
USABLE_MAX = 1.0 / USABLE_MIN
#: Largest condition number accepted for J (J₃/J₁) and for the 6×6 mass–inertia tensor
#: scaled to a unit diagonal: the inverse then keeps about 4 significant digits
#: (relative error ≈ cond · ε ≈ 2e-4).
MAX_CONDITION = 1e12


def check_mass(mass: Any, name: str = "body") -> float:
    """Validate a mass (kg): a real number m with m and 1/m finite normal float64 numbers.

    Parameters
    ----------
    mass : float
        Mass m (kg); :data:`USABLE_MIN` (2.2e-308) ≤ m ≤ :data:`USABLE_MAX` (4.5e307).
        Booleans, strings and complex numbers are refused, not converted.
    name : str
        Used in error messages.

    Returns
    -------
    float

    Raises
    ------
    InertiaError
        If ``mass`` is not a real number, not finite, ≤ 0, or outside the usable range
        (a subnormal mass such as 5e-324 has 1/m = inf).
    """
    m = _real_mass(mass, name)
    problem = _mass_problem(m)
    if problem:
        raise InertiaError(f"{name}: {problem}")
    return m


def _real_mass(mass: Any, name: str) -> float:
    """``mass`` as a float, refusing what is not a real number (bool, str, complex, arrays)."""
    try:
        if isinstance(mass, NOT_REAL) or np.ndim(mass) != 0:  # float() would take True, "2"
            raise TypeError
        return float(mass)
    except (TypeError, ValueError, OverflowError):
        msg = f"{name}: mass must be a positive number (kg); got {mass!r:.60}"
        raise InertiaError(msg) from None


def _mass_problem(m: float) -> str:
    if not np.isfinite(m) or m <= 0.0:
        return f"mass must be finite and > 0 (kg); got {m!r}"
    if not USABLE_MIN <= m <= USABLE_MAX:
        return (
            f"mass must be between {USABLE_MIN:.3g} and {USABLE_MAX:.3g} kg so that m and 1/m "
            f"are finite normal numbers; got {m!r} (1/m = {_reciprocal(m)!r})"
        )
    return ""


def _reciprocal(x: float) -> float:
    with np.errstate(all="ignore"):
        return float(np.float64(1.0) / np.float64(x))


@njit(cache=True, inline="always")
def body_moment(
    V: np.ndarray, J: np.ndarray, k: int, q0: float, q1: float, q2: float
) -> tuple[float, float, float]:
    """Jω × ω + τ of body k (N·m): the rotational part of ad*_V 𝕀V + Q (McCann 2020,
    Eq. 10b), for twists V (n, 6), inertias J (n, 3, 3) and the applied moment τ = (q0, q1,
    q2)."""
    w0, w1, w2 = V[k, 0], V[k, 1], V[k, 2]
    h0 = J[k, 0, 0] * w0 + J[k, 0, 1] * w1 + J[k, 0, 2] * w2
    h1 = J[k, 1, 0] * w0 + J[k, 1, 1] * w1 + J[k, 1, 2] * w2
    h2 = J[k, 2, 0] * w0 + J[k, 2, 1] * w1 + J[k, 2, 2] * w2
    return h1 * w2 - h2 * w1 + q0, h2 * w0 - h0 * w2 + q1, h0 * w1 - h1 * w0 + q2


@njit(cache=True)
def rigid_free_accel(
    V: np.ndarray, J: np.ndarray, Jinv: np.ndarray, m: np.ndarray, Q: np.ndarray
) -> np.ndarray:
    """V̇ = 𝕀⁻¹(ad*_V 𝕀V + Q) for n rigid bodies: (n, 6) twists and wrenches → (n, 6)
    (:func:`rigid_free_accel_into` into a new array)."""
    out = np.empty((V.shape[0], 6))
    rigid_free_accel_into(V, J, Jinv, m, Q, out)
    return out


@njit(cache=True)
def rigid_free_accel_into(
    V: np.ndarray, J: np.ndarray, Jinv: np.ndarray, m: np.ndarray, Q: np.ndarray, out: np.ndarray
) -> None:
    """V̇ = 𝕀⁻¹(ad*_V 𝕀V + Q) for n rigid bodies, (n, 6) twists and wrenches, into ``out``
    (n, 6) (rad/s², m/s²; body frames).

    ad*_V 𝕀V = [Jω × ω; m v × ω] (McCann 2020, Eq. 10b, written out); 𝕀⁻¹ takes J⁺ and
    1/m = 0 for a body with a singular mass block (its solve supplies the rest).
    """
    n = V.shape[0]
    for k in range(n):
        w0, w1, w2 = V[k, 0], V[k, 1], V[k, 2]
        v0, v1, v2 = V[k, 3], V[k, 4], V[k, 5]
        L0, L1, L2 = body_moment(V, J, k, Q[k, 0], Q[k, 1], Q[k, 2])
        for i in range(3):
            out[k, i] = Jinv[k, i, 0] * L0 + Jinv[k, i, 1] * L1 + Jinv[k, i, 2] * L2
        im = 1.0 / m[k] if m[k] > 0.0 else 0.0  # a body without mass: M⁺ (its solve decides)
        out[k, 3] = v1 * w2 - v2 * w1 + Q[k, 3] * im
        out[k, 4] = v2 * w0 - v0 * w2 + Q[k, 4] * im
        out[k, 5] = v0 * w1 - v1 * w0 + Q[k, 5] * im


def check_inertia(
    mass: Any, J: Any, name: str = "body", *, allow_singular: bool = False
) -> tuple[float, FloatArray]:
    """Validate a mass and a central inertia tensor.

    Parameters
    ----------
    mass : float
        Mass m (kg), as :func:`check_mass`: finite, > 0, with m and 1/m normal float64
        numbers (2.2e-308 ≤ m ≤ 4.5e307).
    J : array_like, shape (3, 3)
        Inertia tensor about the centre of mass in the body frame (kg·m²): finite, symmetric
        (to 1e-9 relative), positive definite, principal moments J₁ ≤ J₂ ≤ J₃ satisfying the
        triangle inequality ``J₁ + J₂ ≥ J₃`` (to 1e-9 relative), each moment between
        2.2e-308 and 4.5e307 kg·m² (so that J⁻¹ is finite), and ``J₃/J₁ ≤ 1e12``
        (:data:`MAX_CONDITION`: J⁻¹ then keeps about 4 significant digits).
    name : str
        Used in error messages.
    allow_singular : bool, optional
        Accept a singular mass block ``blkdiag(J, m I)`` (default False): m = 0 (then J must
        be exactly zero: a body without mass has no rotational inertia), and J positive
        semidefinite, a principal moment at or below ``J₃ / MAX_CONDITION`` counting as zero
        (:func:`zero_moments`); the other conditions hold for the moments that are not zero.
        Such a body has no acceleration of its own: only a solve in which its constraints
        determine it (the tree solve) takes it (McCann 2020's UK equation needs M⁻¹;
        Udwadia & Phohomsiri 2006 give the singular-M form).

    Returns
    -------
    (float, ndarray (3, 3))
        The mass and J as float64.

    Raises
    ------
    InertiaError
        Listing every violated condition with the values that came in.
    ShapeError, NonFiniteError
        If J is not (3, 3), or holds NaN or inf.

    Notes
    -----
    The usable range and the condition bound are gmuk's, not the thesis's: a subnormal mass
    (5e-324) or moment (1e-320) is positive but its reciprocal is infinite, and the
    integrator divides by both.
    """
    problems: list[str] = []
    m = _real_mass(mass, name)
    if problem := _mass_problem(m):
        if not (allow_singular and m == 0.0):
            problems.append(problem)
    Jm = as_array(J, (3, 3), f"{name}: inertia", batch=False)
    scale = max(float(np.abs(Jm).max()), np.finfo(float).tiny)
    asym = float(np.abs(Jm / scale - Jm.T / scale).max()) * scale  # no overflow near 1e308
    if asym > INERTIA_TOL * scale:
        problems.append(f"inertia must be symmetric; got max|J − Jᵀ| = {asym:.3g} kg·m²")
    elif allow_singular:
        problems += _singular_inertia_problems(m, Jm, scale)
    else:
        # eigenvalues of J / scale, then scaled back: no overflow for entries near 1e308
        scaled = np.linalg.eigvalsh(0.5 * (Jm / scale + Jm.T / scale))
        with np.errstate(over="ignore"):  # a moment beyond 1.8e308 is shown as inf
            moments = scaled * scale
        shown = np.array2string(moments, precision=6)
        if moments[0] <= 0.0:
            problems.append(
                f"inertia must be positive definite; got principal moments {shown} kg·m²"
            )
        elif scaled[0] + scaled[1] < scaled[2] * (1.0 - INERTIA_TOL):
            problems.append(
                f"principal moments must satisfy the triangle inequality J₁ + J₂ ≥ J₃; got "
                f"{shown} kg·m² ({moments[0] + moments[1]:.6g} < {moments[2]:.6g})"
            )
        elif not (USABLE_MIN <= moments[0] and moments[2] <= USABLE_MAX):
            problems.append(
                f"principal moments must be between {USABLE_MIN:.3g} and {USABLE_MAX:.3g} "
                f"kg·m² so that J⁻¹ is finite; got {shown} kg·m² "
                f"(1/J₁ = {_reciprocal(moments[0])!r})"
            )
        elif scaled[2] > MAX_CONDITION * scaled[0]:
            problems.append(
                f"inertia is too ill-conditioned to invert: J₃/J₁ must be ≤ {MAX_CONDITION:g}; "
                f"got principal moments {shown} kg·m² (J₃/J₁ = {scaled[2] / scaled[0]:.3g})"
            )
    if problems:
        raise InertiaError(f"{name}: " + "; ".join(problems))
    return m, Jm


def zero_moments(J: FloatArray) -> tuple[FloatArray, FloatArray]:
    """J's principal moments and axes, a moment at or below ``J₃ / MAX_CONDITION`` in
    magnitude set to zero: the moments J⁻¹ could not resolve (:data:`MAX_CONDITION`), and
    round-off such as the 5e-20 kg·m² a URDF's zero inertia picks up when it is moved to the
    centre of mass.

    Parameters
    ----------
    J : ndarray (3, 3)
        A symmetric central inertia (kg·m², body frame).

    Returns
    -------
    (ndarray (3,), ndarray (3, 3))
        The moments, ascending (kg·m²), and the principal axes as columns (body frame).
    """
    scale = max(float(np.abs(J).max()), np.finfo(float).tiny)
    scaled, axes = np.linalg.eigh(0.5 * (J / scale + J.T / scale))
    scaled[np.abs(scaled) <= max(scaled[2], 0.0) / MAX_CONDITION] = 0.0
    with np.errstate(over="ignore"):
        return scaled * scale, axes


def inertia_pinv(J: FloatArray) -> FloatArray:
    """J⁺, the Moore–Penrose pseudo-inverse of a central inertia, leaving out the moments
    :func:`zero_moments` sets to zero (J⁻¹ when it sets none).

    Parameters
    ----------
    J : ndarray (3, 3)
        A symmetric positive-semidefinite central inertia (kg·m², body frame).

    Returns
    -------
    ndarray (3, 3)
        J⁺ (kg⁻¹·m⁻², body frame).
    """
    moments, axes = zero_moments(J)
    inv = np.zeros(3)
    nz = moments != 0.0
    inv[nz] = 1.0 / moments[nz]
    return np.asarray((axes * inv) @ axes.T)


def _singular_inertia_problems(m: float, J: FloatArray, scale: float) -> list[str]:
    """What :func:`check_inertia` with ``allow_singular`` refuses in a symmetric J."""
    moments, _ = zero_moments(J)
    shown = np.array2string(moments, precision=6)
    if m == 0.0 and np.any(J != 0.0):
        return [
            "a body without mass has no rotational inertia: J must be zero when m = 0; got "
            f"principal moments {shown} kg·m²"
        ]
    if moments[0] < 0.0:
        return [f"inertia must be positive semidefinite; got principal moments {shown} kg·m²"]
    nonzero = moments[moments != 0.0]
    if nonzero.size and not (USABLE_MIN <= nonzero[0] and nonzero[-1] <= USABLE_MAX):
        return [
            f"principal moments must be zero or between {USABLE_MIN:.3g} and "
            f"{USABLE_MAX:.3g} kg·m²; got {shown} kg·m²"
        ]
    if moments[0] + moments[1] < moments[2] * (1.0 - INERTIA_TOL):  # finite: ≤ 4.5e307 each
        return [
            f"principal moments must satisfy the triangle inequality J₁ + J₂ ≥ J₃; got "
            f"{shown} kg·m² ({moments[0] + moments[1]:.6g} < {moments[2]:.6g})"
        ]
    return []


def singular_mass(m: float, J: FloatArray) -> bool:
    """Whether the mass block ``blkdiag(J, m I)`` is singular.

    Parameters
    ----------
    m : float
        Mass (kg).
    J : ndarray (3, 3)
        Central inertia (kg·m², body frame).

    Returns
    -------
    bool
        m = 0, or a moment of :func:`zero_moments` is zero.
    """
    return m == 0.0 or bool(zero_moments(J)[0][0] == 0.0)


def check_spatial_inertia(inertia: Any, name: str = "inertia") -> FloatArray:
    """Validate 6×6 mass–inertia tensors 𝕀 (kg·m², kg·m, kg; body frame).

    Each 𝕀 must be finite, symmetric (to 1e-9 relative to its largest entry), positive
    definite, have each diagonal entry between 2.2e-308 and 4.5e307 (a normal float64 with a
    normal reciprocal), be well-conditioned (the condition number of ``D^-½ 𝕀 D^-½``, D its
    diagonal, at most :data:`MAX_CONDITION` = 1e12: a unit-free measure, 𝕀 mixing kg·m² and
    kg), and have a finite inverse. :func:`spatial_inertia` of a mass and J accepted by
    :func:`check_inertia` passes (J₃/J₁ ≤ 1e12 bounds the scaled condition).

    Parameters
    ----------
    inertia : array_like, shape (6, 6) or (..., 6, 6)
        Mass–inertia tensors acting on twists [ω; v].
    name : str
        Used in error messages.

    Returns
    -------
    ndarray, shape (..., 6, 6)
        ``inertia`` as float64.

    Raises
    ------
    InertiaError
        Naming the first failing tensor (its batch index) and what is wrong with it.
    ShapeError, NonFiniteError
        If the trailing shape is not (6, 6), or an entry is NaN or inf.
    """
    I = as_array(inertia, (6, 6), name)
    flat = I.reshape(-1, 6, 6)
    if flat.shape[0] == 0:
        return I
    scale = np.maximum(np.abs(flat).max(axis=(1, 2)), USABLE_MIN)[:, None, None]
    S = flat / scale  # entries in [-1, 1]: nothing below overflows
    asym = np.abs(S - np.swapaxes(S, 1, 2)).max(axis=(1, 2))
    diag = np.diagonal(flat, axis1=1, axis2=2)
    d = np.diagonal(S, axis1=1, axis2=2)
    with np.errstate(all="ignore"):
        root = np.sqrt(np.where(d > 0.0, d, np.nan))
        C = 0.5 * (S + np.swapaxes(S, 1, 2)) / (root[:, :, None] * root[:, None, :])
        C = np.where(np.isfinite(C), C, 0.0)
        lam = np.linalg.eigvalsh(C)
        usable = (lam[:, 0] > 0.0) & (d > 0.0).all(axis=1)
        C_inv = np.linalg.inv(np.where(usable[:, None, None], C, np.eye(6)))
        inv = C_inv / (root[:, :, None] * root[:, None, :]) / scale
    for k in range(flat.shape[0]):
        where = (
            f" at index {tuple(int(j) for j in np.unravel_index(k, I.shape[:-2]))}"
            if I.ndim > 2
            else ""
        )
        problem = ""
        if asym[k] > INERTIA_TOL:
            problem = f"must be symmetric; got max|𝕀 − 𝕀ᵀ| = {asym[k] * scale[k, 0, 0]:.3g}"
        elif not (d[k] > 0.0).all() or not lam[k, 0] > 0.0:
            problem = (
                "must be positive definite (a negative or zero direction gives a negative "
                f"or zero kinetic energy); got diagonal {diag[k].tolist()}"
            )
        elif not ((diag[k] >= USABLE_MIN) & (diag[k] <= USABLE_MAX)).all():
            problem = (
                f"must have diagonal entries between {USABLE_MIN:.3g} and {USABLE_MAX:.3g} "
                f"(a finite inverse); got {diag[k].tolist()}"
            )
        elif lam[k, -1] > MAX_CONDITION * lam[k, 0]:
            problem = (
                f"is too ill-conditioned to invert: the condition number of 𝕀 scaled to a unit "
                f"diagonal must be ≤ {MAX_CONDITION:g}; got {lam[k, -1] / lam[k, 0]:.3g}"
            )
        elif not np.isfinite(inv[k]).all():
            problem = "must have a finite inverse; its inverse overflows float64"
        if problem:
            raise InertiaError(f"{name}{where} {problem}")
    return I


def spatial_inertia(mass: Any, J: Any) -> FloatArray:
    """The mass–inertia tensor ``𝕀 = blkdiag(J, m I₃)`` (McCann 2020, Eq. 11).

    Parameters
    ----------
    mass : float
        Mass (kg).
    J : array_like, shape (3, 3)
        Central inertia tensor in the body frame (kg·m²).

    Returns
    -------
    ndarray, shape (6, 6)
        Ordered to act on [ω; v] and return [h; p] (kg·m²/s, kg·m/s).

    Raises
    ------
    InertiaError
        See :func:`check_inertia`.
    """
    m, Jm = check_inertia(mass, J)
    out = np.zeros((6, 6))
    out[:3, :3] = Jm
    out[3:, 3:] = m * np.eye(3)
    return out


def free_acceleration(V: Any, inertia: Any, wrench: Any = None) -> FloatArray:
    """Body acceleration of a free rigid body, ``V̇ = 𝕀⁻¹(ad*_V 𝕀 V + τ)`` (Eq. 10b).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Body twist [ω; v] (rad/s, m/s).
    inertia : array_like, shape (6, 6) or (..., 6, 6)
        Mass–inertia tensor 𝕀 = blkdiag(J, m I₃) from :func:`spatial_inertia` (the body
        frame at the centre of mass).
    wrench : array_like, shape (..., 6), optional
        Total applied wrench [L; f] in the body frame (N·m, N): external plus control
        (τ + u in the thesis). Zero if omitted.

    Returns
    -------
    ndarray, shape (..., 6)
        ``V̇ = [ω̇; v̇]`` (rad/s², m/s²): the rate of the body-frame components of V.
        For 𝕀 = blkdiag(J, mI) this is Euler's equation ``J ω̇ = Jω × ω + L`` and
        ``v̇ = v × ω + f/m``, evaluated by the kernel the System and the compiled loop use
        (:func:`rigid_free_accel`), which writes ad*_V 𝕀V out without the
        term m v × v (zero, but of order ε m|v|² when evaluated: 1e-5 N·m for 500 kg at
        7 km/s).

    Raises
    ------
    InertiaError
        If 𝕀 fails :func:`check_spatial_inertia` (not symmetric positive definite, or no
        usable inverse), or is not of the form blkdiag(J, m I₃) (its off-diagonal blocks
        zero and its lower block m times the identity, exactly as :func:`spatial_inertia`
        builds it).
    NonFiniteError
        If the result overflows float64.
    """
    V = as_array(V, (6,), "V")
    I = check_spatial_inertia(inertia)
    tau = np.zeros(6) if wrench is None else as_array(wrench, (6,), "wrench")
    m = I[..., 3, 3]
    lower = I[..., 3:, 3:]
    if (
        np.any(I[..., :3, 3:] != 0.0)
        or np.any(I[..., 3:, :3] != 0.0)
        or np.any(lower != m[..., None, None] * np.eye(3))
        or not np.all(m > 0.0)
    ):
        raise InertiaError(
            "inertia must be blkdiag(J, m I₃) with m > 0, the mass–inertia tensor about the "
            "centre of mass (gmuk.dynamics.spatial_inertia); got off-diagonal blocks, a lower "
            f"block that is not m times the identity, or m ≤ 0 (m = {m.ravel()[:3].tolist()})"
        )
    shape = np.broadcast_shapes(V.shape[:-1], I.shape[:-2], tau.shape[:-1])
    n = int(np.prod(shape))
    # fresh C-contiguous float64 arrays: the types the kernel is compiled for
    J = np.array(np.broadcast_to(I[..., :3, :3], (*shape, 3, 3)), dtype=np.float64).reshape(n, 3, 3)
    out = rigid_free_accel(
        np.array(np.broadcast_to(V, (*shape, 6)), dtype=np.float64).reshape(n, 6),
        J,
        np.linalg.inv(J),
        np.array(np.broadcast_to(m, shape), dtype=np.float64).reshape(n),
        np.array(np.broadcast_to(tau, (*shape, 6)), dtype=np.float64).reshape(n, 6),
    )
    return finite_result(out.reshape(*shape, 6), "free_acceleration", "V", V)


def g_ddot(g: Any, V: Any, V_dot: Any) -> FloatArray:
    """Second time derivative of the configuration, ``g̈ = g (V^² + V̇^)`` (Eqs. 17–19).

    With ``V̇ = V̇_a + V̇_c`` this is ``g̈_a + g̈_c`` of Eqs. 18–19.

    Parameters
    ----------
    g : array_like, shape (..., 4, 4)
        Pose g_NB.
    V : array_like, shape (..., 6)
        Body twist (rad/s, m/s).
    V_dot : array_like, shape (..., 6)
        Body acceleration (rad/s², m/s²).

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``g̈`` (an element of T²SE(3); its last row is zero).
    """
    g = check_se3(g, "g")
    Vh = se3._hat(as_array(V, (6,), "V"))
    return g @ (Vh @ Vh + se3._hat(as_array(V_dot, (6,), "V_dot")))


def kinetic_energy(V: Any, inertia: Any) -> FloatArray:
    """Kinetic energy ``½ Vᵀ 𝕀 V`` (J).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Body twists [ω; v] (rad/s, m/s), body frame.
    inertia : array_like, shape (6, 6) or (..., 6, 6)
        Mass–inertia tensor 𝕀 (kg·m², kg), body frame (:func:`spatial_inertia`).

    Returns
    -------
    ndarray, shape (...)
        ≥ 0.

    Raises
    ------
    InertiaError
        If 𝕀 fails :func:`check_spatial_inertia` (e.g. not positive definite: a negative
        kinetic energy would follow).
    NonFiniteError
        If the energy overflows float64.
    """
    V = as_array(V, (6,), "V")
    I = check_spatial_inertia(inertia)
    with np.errstate(over="ignore", invalid="ignore"):
        T = 0.5 * np.einsum("...i,...i->...", V, (I @ V[..., None])[..., 0])
    return finite_result(T, "kinetic_energy", "V", V)


def spatial_momentum(g: Any, V: Any, inertia: Any) -> FloatArray:
    """Momentum in the inertial frame, ``h_N = Ad_{g⁻¹}ᵀ 𝕀 V`` = [r × p + R J ω; R m v].

    Conserved for a free body with no applied wrench.

    Parameters
    ----------
    g : array_like, shape (..., 4, 4)
        Pose g_NB.
    V : array_like, shape (..., 6)
        Body twist.
    inertia : array_like, shape (6, 6) or (..., 6, 6)
        Mass–inertia tensor 𝕀, body frame (:func:`spatial_inertia`).

    Returns
    -------
    ndarray, shape (..., 6)
        [angular momentum about the origin of N; linear momentum], in N (kg·m²/s, kg·m/s).

    Raises
    ------
    InertiaError
        If 𝕀 fails :func:`check_spatial_inertia`.
    """
    g = check_se3(g, "g")
    V = as_array(V, (6,), "V")
    I = check_spatial_inertia(inertia)
    AdT = np.swapaxes(se3._Ad(se3._inverse(g)), -1, -2)
    return (AdT @ (I @ V[..., None]))[..., 0]
