"""Attitude I/O: rotation matrices, quaternions, MRPs and Euler angles, to and from ``R_NB``.

gmuk's attitude of a body B is ``R_NB`` (3×3): it maps body (B) components of a vector to
inertial (N) components, ``v_N = R_NB v_B``; it is the rotation block of ``g_NB``. This module
converts it to and from the parameterisations other tools use, with every convention named:

* **DCM** ``dcm_BN`` (Basilisk's and Schaub & Junkins's ``[BN]``) maps N components to B
  components: ``dcm_BN = R_NBᵀ``.
* **Quaternions** describe the rotation of B relative to N, Hamilton's convention, so that
  ``R_NB = (q₀² − qᵀq) I + 2 q qᵀ + 2 q₀ [q̃]``. The component order is never implicit: every
  function takes ``scalar="first"`` (``[q₀, q₁, q₂, q₃]``: Basilisk's Euler parameters
  ``β_BN``, Pinocchio's ``Quaternion(w, x, y, z)`` constructor) or ``scalar="last"``
  (``[q₁, q₂, q₃, q₀]``: scipy's ``Rotation.as_quat()``, Eigen's and Pinocchio's
  ``coeffs()``). Quaternions returned have ``q₀ ≥ 0``. Quaternions taken in must have a norm
  within :data:`QUATERNION_NORM_TOL` of 1; they are then normalised (others are refused).
* **MRPs** ``σ_BN = ê tan(Φ/4)`` for the principal rotation of B relative to N by Φ about ê
  (Schaub & Junkins 2018, §3.7). σ and its shadow ``σˢ = −σ/|σ|²`` are the same attitude;
  functions here return the short set ``|σ| ≤ 1`` (Basilisk's choice), and accept either.
* **Euler angles** of the 12 body-axis (intrinsic) sequences, named in upper case as scipy
  names intrinsic rotations: ``"ZYX"`` is the 3-2-1 (yaw, pitch, roll) set,
  ``R_NB = R_z(ψ) R_y(θ) R_x(φ)``, ``dcm_BN = M₁(φ) M₂(θ) M₃(ψ)``.

Every function takes one value or a batch (leading axes ``...``) and returns float64 arrays.
Inputs are checked at the boundary: wrong shapes raise :class:`gmuk.errors.ShapeError`,
NaN or inf :class:`gmuk.errors.NonFiniteError`, matrices that are not rotations and
quaternions that are not unit :class:`gmuk.errors.NotOnGroupError`, unknown sequences
:class:`gmuk.errors.EulerSequenceError` and a ``scalar`` other than ``"first"``/``"last"``
:class:`gmuk.errors.DefinitionError` (all are ``ValueError``).

References
----------
Schaub, H. and Junkins, J. L., *Analytical Mechanics of Space Systems*, 4th ed., AIAA, 2018:
§3.3 (Euler angles), §3.5 (Euler parameters), §3.7 (modified Rodrigues parameters: [BN](σ),
the shadow set, the kinematic differential equation).
Shepperd, S. W., "Quaternion from rotation matrix", *Journal of Guidance and Control* 1(3),
223–224, 1978 (the matrix-to-quaternion method).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from gmuk._validation import FloatArray, as_array, check_rotation
from gmuk.errors import DefinitionError, DomainError, EulerSequenceError, NotOnGroupError

__all__ = [
    "EULER_SEQUENCES",
    "QUATERNION_NORM_TOL",
    "R_NB_from_dcm_BN",
    "R_NB_from_euler",
    "R_NB_from_mrp",
    "R_NB_from_quaternion",
    "axis_rotation",
    "dcm_BN_from_R_NB",
    "euler_from_R_NB",
    "mrp_from_R_NB",
    "mrp_from_quaternion",
    "mrp_rate",
    "mrp_shadow",
    "mrp_switch",
    "quaternion_from_R_NB",
    "quaternion_from_mrp",
    "quaternion_multiply",
]

ScalarOrder = Literal["first", "last"]

#: The 12 body-axis (intrinsic) Euler sequences: six Tait–Bryan, six proper Euler.
EULER_SEQUENCES: tuple[str, ...] = (
    "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX",
    "XYX", "XZX", "YXY", "YZY", "ZXZ", "ZYZ",
)  # fmt: skip

#: Largest accepted ``| ‖q‖ − 1 |`` of a quaternion given as input (dimensionless).
QUATERNION_NORM_TOL: float = 1e-6

# Below this cos θ (Tait–Bryan) or sin θ (proper Euler) the attitude is treated as gimbal
# lock. The angles returned there reproduce R to a few times this value.
_GIMBAL_TOL = 1e-14


# --------------------------------------------------------------------------- helpers


def _scalar_order(scalar: Any) -> str:
    if not isinstance(scalar, str) or scalar not in ("first", "last"):
        raise DefinitionError(
            "scalar must be 'first' (q = [q0, q1, q2, q3], Basilisk's β_BN) or 'last' "
            f"(q = [q1, q2, q3, q0], scipy's as_quat()); got {scalar!r}"
        )
    return scalar


def _to_first(q: FloatArray, scalar: str) -> FloatArray:
    return q if scalar == "first" else np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def _from_first(q: FloatArray, scalar: str) -> FloatArray:
    return q if scalar == "first" else np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


def _unit_quaternion(q: Any, scalar: Any, name: str = "q") -> FloatArray:
    """``q`` checked (shape (..., 4), finite, norm within the tolerance of 1), normalised and
    put scalar-first."""
    order = _scalar_order(scalar)
    a = as_array(q, (4,), name)
    norm = _norm(a)[..., 0]
    err = np.abs(norm - 1.0)
    if err.size and float(err.max()) > QUATERNION_NORM_TOL:
        k = int(np.argmax(err))
        where = f" at index {np.unravel_index(k, err.shape)}" if err.ndim else ""
        raise NotOnGroupError(
            f"{name} must be a unit quaternion (| |q| - 1 | <= {QUATERNION_NORM_TOL:g}){where}; "
            f"got |q| = {float(norm.reshape(-1)[k]):.9g}"
        )
    return _to_first(a / norm[..., None], order)


def _canonical(q: FloatArray) -> FloatArray:
    """Scalar-first quaternions with the sign chosen so that q₀ ≥ 0."""
    return np.where(q[..., :1] < 0.0, -q, q)


def _norm(a: FloatArray) -> FloatArray:
    """Euclidean norms over the last axis (..., 1), without overflow for entries near 1e308."""
    m = np.max(np.abs(a), axis=-1, keepdims=True)
    safe = np.where(m > 0.0, m, 1.0)
    return m * np.linalg.norm(a / safe, axis=-1, keepdims=True)


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("...i,...i->...", a, b)


def _skew(w: FloatArray) -> FloatArray:
    W = np.zeros((*w.shape[:-1], 3, 3))
    W[..., 0, 1], W[..., 0, 2] = -w[..., 2], w[..., 1]
    W[..., 1, 0], W[..., 1, 2] = w[..., 2], -w[..., 0]
    W[..., 2, 0], W[..., 2, 1] = -w[..., 1], w[..., 0]
    return W


def _matrix_of_quaternion(q: FloatArray) -> FloatArray:
    """R_NB of unit scalar-first quaternions (..., 4)."""
    q0, v = q[..., 0], q[..., 1:]
    eye = np.eye(3)
    return (
        (q0**2 - _dot(v, v))[..., None, None] * eye
        + 2.0 * v[..., :, None] * v[..., None, :]
        + 2.0 * q0[..., None, None] * _skew(v)
    )


def _quaternion_of_matrix(R: FloatArray) -> FloatArray:
    """Scalar-first quaternions (q₀ ≥ 0) of rotation matrices R_NB, by Shepperd's method:
    of 4q₀², 4q₁², 4q₂², 4q₃² (from the trace and the diagonal) the largest is taken by a
    square root and the other three components from sums and differences of off-diagonal
    entries divided by it, so that nothing is divided by a small number."""
    t = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    diag = np.stack([t, R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]], axis=-1)
    k = np.argmax(diag, axis=-1)
    d21 = R[..., 2, 1] - R[..., 1, 2]
    d02 = R[..., 0, 2] - R[..., 2, 0]
    d10 = R[..., 1, 0] - R[..., 0, 1]
    s01 = R[..., 0, 1] + R[..., 1, 0]
    s02 = R[..., 0, 2] + R[..., 2, 0]
    s12 = R[..., 1, 2] + R[..., 2, 1]
    # Row c holds 4 q_c · q for candidate c (4 q_c² on the diagonal).
    rows = np.stack(
        [
            np.stack([1.0 + t, d21, d02, d10], axis=-1),
            np.stack([d21, 1.0 + 2.0 * R[..., 0, 0] - t, s01, s02], axis=-1),
            np.stack([d02, s01, 1.0 + 2.0 * R[..., 1, 1] - t, s12], axis=-1),
            np.stack([d10, s02, s12, 1.0 + 2.0 * R[..., 2, 2] - t], axis=-1),
        ],
        axis=-2,
    )
    q = np.take_along_axis(rows, k[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return _canonical(q)


def _switch(s: FloatArray) -> FloatArray:
    """MRPs with |σ| > 1 replaced by their shadow set (computed without overflow)."""
    n = _norm(s)
    long = n > 1.0
    safe = np.where(long, n, 1.0)
    return np.where(long, -(s / safe) / safe, s)


# --------------------------------------------------------------------------- DCMs


def dcm_BN_from_R_NB(R_NB: Any) -> FloatArray:
    """The direction-cosine matrix ``[BN]`` (Basilisk, Schaub & Junkins) of gmuk's ``R_NB``.

    ``dcm_BN = R_NBᵀ``: it maps N components to B components, ``v_B = dcm_BN v_N``.

    Parameters
    ----------
    R_NB : array_like, shape (..., 3, 3)
        Rotation matrices mapping body components to N components (dimensionless; checked:
        RᵀR = I to 1e-9, det +1).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``dcm_BN``.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        ``R_NB`` is not a rotation matrix.
    """
    return np.swapaxes(check_rotation(R_NB, "R_NB"), -1, -2).copy()


def R_NB_from_dcm_BN(dcm_BN: Any) -> FloatArray:
    """gmuk's ``R_NB`` of a direction-cosine matrix ``[BN]``: ``R_NB = dcm_BNᵀ``.

    Parameters
    ----------
    dcm_BN : array_like, shape (..., 3, 3)
        Direction-cosine matrices mapping N components to B components (dimensionless;
        checked: a rotation matrix to 1e-9).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``R_NB``: maps body components to N components.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        ``dcm_BN`` is not a rotation matrix.
    """
    return np.swapaxes(check_rotation(dcm_BN, "dcm_BN"), -1, -2).copy()


# --------------------------------------------------------------------------- quaternions


def quaternion_from_R_NB(R_NB: Any, *, scalar: ScalarOrder) -> FloatArray:
    """The unit quaternion of B relative to N, of gmuk's ``R_NB``, with q₀ ≥ 0.

    Computed by Shepperd's (1978) method, accurate to round-off at every attitude
    (including rotations by π). At q₀ = 0 (rotations by π) q and −q are both canonical;
    either may be returned.

    Parameters
    ----------
    R_NB : array_like, shape (..., 3, 3)
        Rotation matrices mapping body components to N components (dimensionless; checked:
        RᵀR = I to 1e-9, det +1).
    scalar : {"first", "last"}
        Component order of the result: ``[q₀, q₁, q₂, q₃]`` or ``[q₁, q₂, q₃, q₀]``.

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions (dimensionless), ``R_NB = (q₀² − qᵀq) I + 2 q qᵀ + 2 q₀ [q̃]``.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        ``R_NB`` is not a rotation matrix.
    gmuk.errors.DefinitionError
        ``scalar`` is not ``"first"`` or ``"last"``.
    """
    order = _scalar_order(scalar)
    R = check_rotation(R_NB, "R_NB")
    return _from_first(_quaternion_of_matrix(R), order)


def R_NB_from_quaternion(q: Any, *, scalar: ScalarOrder) -> FloatArray:
    """gmuk's ``R_NB`` of the unit quaternion of B relative to N.

    ``R_NB = (q₀² − qᵀq) I + 2 q qᵀ + 2 q₀ [q̃]`` (Schaub & Junkins 2018, §3.5, transposed:
    their [BN](β) is ``dcm_BN``). q and −q give the same matrix.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions (dimensionless) in the order ``scalar`` names; each norm must be within
        :data:`QUATERNION_NORM_TOL` of 1, and q is normalised before use.
    scalar : {"first", "last"}
        Component order of ``q``.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``R_NB``: maps body components to N components.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        Some ``|q|`` differs from 1 by more than the tolerance.
    gmuk.errors.DefinitionError
        ``scalar`` is not ``"first"`` or ``"last"``.
    """
    return _matrix_of_quaternion(_unit_quaternion(q, scalar))


def quaternion_multiply(p: Any, q: Any, *, scalar: ScalarOrder) -> FloatArray:
    """Hamilton product ``p ⊗ q`` of unit quaternions: the rotation of p composed with q.

    With ``R(·)`` as in :func:`R_NB_from_quaternion`, ``R(p ⊗ q) = R(p) R(q)``: for
    ``p = q_NA`` (A relative to N) and ``q = q_AB`` (B relative to A), ``p ⊗ q = q_NB``.
    The sign is not canonicalised (q₀ of the product may be negative). The arguments
    broadcast against each other.

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        Unit quaternions (dimensionless; norms within :data:`QUATERNION_NORM_TOL` of 1,
        normalised before use) in the order ``scalar`` names.
    scalar : {"first", "last"}
        Component order of ``p``, ``q`` and of the result.

    Returns
    -------
    ndarray, shape (..., 4)
        ``p ⊗ q`` (dimensionless, unit), in the order ``scalar`` names.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        Some ``|p|`` or ``|q|`` differs from 1 by more than the tolerance.
    gmuk.errors.DefinitionError
        ``scalar`` is not ``"first"`` or ``"last"``.
    """
    a = _unit_quaternion(p, scalar, "p")
    b = _unit_quaternion(q, scalar, "q")
    a0, av = a[..., :1], a[..., 1:]
    b0, bv = b[..., :1], b[..., 1:]
    w = a0 * b0 - _dot(av, bv)[..., None]
    v = a0 * bv + b0 * av + np.cross(av, bv)
    return _from_first(np.concatenate([w, v], axis=-1), scalar)


# --------------------------------------------------------------------------- MRPs


def mrp_from_R_NB(R_NB: Any) -> FloatArray:
    """The modified Rodrigues parameters ``σ_BN`` of ``R_NB``: the short set, ``|σ| ≤ 1``.

    ``σ = ê tan(Φ/4)`` for the principal rotation of B relative to N by Φ ∈ [0, π] about ê;
    computed as ``σ = q / (1 + q₀)`` from the quaternion with q₀ ≥ 0. At Φ = π, σ and its
    shadow both have ``|σ| = 1``; either may be returned.

    Parameters
    ----------
    R_NB : array_like, shape (..., 3, 3)
        Rotation matrices mapping body components to N components (dimensionless; checked:
        RᵀR = I to 1e-9, det +1).

    Returns
    -------
    ndarray, shape (..., 3)
        σ_BN (dimensionless), ``|σ| ≤ 1``.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        ``R_NB`` is not a rotation matrix.
    """
    q = _quaternion_of_matrix(check_rotation(R_NB, "R_NB"))
    return q[..., 1:] / (1.0 + q[..., :1])


def R_NB_from_mrp(sigma_BN: Any) -> FloatArray:
    """gmuk's ``R_NB`` of the modified Rodrigues parameters ``σ_BN`` (either set).

    Schaub & Junkins (2018, §3.7) give ``[BN](σ) = I + (8[σ̃]² − 4(1 − σ²)[σ̃]) / (1 + σ²)²``
    with ``σ² = σᵀσ``; that matrix is ``dcm_BN``, so
    ``R_NB = [BN]ᵀ = I + (8[σ̃]² + 4(1 − σ²)[σ̃]) / (1 + σ²)²``. A long set (``|σ| > 1``) gives the
    same matrix as its shadow; it is switched first, so that huge σ do not overflow.

    Parameters
    ----------
    sigma_BN : array_like, shape (..., 3)
        MRPs of B relative to N (dimensionless).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``R_NB``: maps body components to N components.
    """
    s = _switch(as_array(sigma_BN, (3,), "sigma_BN"))
    S = _skew(s)
    s2 = _dot(s, s)[..., None, None]
    return np.eye(3) + (8.0 * S @ S + 4.0 * (1.0 - s2) * S) / (1.0 + s2) ** 2


def mrp_shadow(sigma: Any) -> FloatArray:
    """The shadow set ``σˢ = −σ / |σ|²``: the same attitude, principal angle Φ − 2π.

    Parameters
    ----------
    sigma : array_like, shape (..., 3)
        MRPs (dimensionless), each nonzero (σ = 0 has its shadow at infinity).

    Returns
    -------
    ndarray, shape (..., 3)
        σˢ (dimensionless).

    Raises
    ------
    gmuk.errors.DomainError
        Some σ is zero.
    """
    s = as_array(sigma, (3,), "sigma")
    n = _norm(s)
    if np.any(n == 0.0):
        raise DomainError("sigma = 0 (no rotation) has no shadow set: it would be at infinity")
    return -(s / n) / n


def mrp_switch(sigma: Any) -> FloatArray:
    """MRPs with every long set (``|σ| > 1``) replaced by its shadow set; others unchanged.

    This is Basilisk's switching rule: the result has ``|σ| ≤ 1`` and describes the same
    attitude as ``sigma``.

    Parameters
    ----------
    sigma : array_like, shape (..., 3)
        MRPs (dimensionless).

    Returns
    -------
    ndarray, shape (..., 3)
        MRPs with ``|σ| ≤ 1`` (dimensionless).
    """
    return _switch(as_array(sigma, (3,), "sigma"))


def mrp_from_quaternion(q: Any, *, scalar: ScalarOrder) -> FloatArray:
    """The short-set MRPs (``|σ| ≤ 1``) of a unit quaternion: ``σ = q / (1 + q₀)`` with the
    sign of q chosen so that q₀ ≥ 0.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions of B relative to N (dimensionless; norms within
        :data:`QUATERNION_NORM_TOL` of 1, normalised before use), in the order ``scalar``
        names.
    scalar : {"first", "last"}
        Component order of ``q``.

    Returns
    -------
    ndarray, shape (..., 3)
        σ_BN (dimensionless), ``|σ| ≤ 1``.

    Raises
    ------
    gmuk.errors.NotOnGroupError
        Some ``|q|`` differs from 1 by more than the tolerance.
    gmuk.errors.DefinitionError
        ``scalar`` is not ``"first"`` or ``"last"``.
    """
    b = _canonical(_unit_quaternion(q, scalar))
    return b[..., 1:] / (1.0 + b[..., :1])


def quaternion_from_mrp(sigma_BN: Any, *, scalar: ScalarOrder) -> FloatArray:
    """The unit quaternion (q₀ ≥ 0) of MRPs of either set.

    ``q₀ = (1 − σ²)/(1 + σ²)``, ``q = 2σ/(1 + σ²)`` of the short set (a long set is switched
    to its shadow first, which gives q₀ ≥ 0).

    Parameters
    ----------
    sigma_BN : array_like, shape (..., 3)
        MRPs of B relative to N (dimensionless).
    scalar : {"first", "last"}
        Component order of the result.

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions (dimensionless) of B relative to N, q₀ ≥ 0.

    Raises
    ------
    gmuk.errors.DefinitionError
        ``scalar`` is not ``"first"`` or ``"last"``.
    """
    order = _scalar_order(scalar)
    s = _switch(as_array(sigma_BN, (3,), "sigma_BN"))
    s2 = _dot(s, s)[..., None]
    q = np.concatenate([(1.0 - s2) / (1.0 + s2), 2.0 * s / (1.0 + s2)], axis=-1)
    # |σ| = 1 to rounding can give q₀ = −1e-16: the sign is then flipped like any other
    return _from_first(_canonical(q), order)


def mrp_rate(sigma_BN: Any, omega_BN_B: Any) -> FloatArray:
    """The MRP kinematic differential equation: ``σ̇ = ¼ [(1 − σ²) I + 2[σ̃] + 2σσᵀ] ω``.

    Schaub & Junkins (2018), §3.7. ω is the angular velocity of B relative to N in body
    components (the first half of gmuk's body twist ``V_B``). It holds for either set.

    Parameters
    ----------
    sigma_BN : array_like, shape (..., 3)
        MRPs of B relative to N (dimensionless).
    omega_BN_B : array_like, shape (..., 3)
        Angular velocity of B relative to N (rad/s), in B components. Broadcasts against
        ``sigma_BN``.

    Returns
    -------
    ndarray, shape (..., 3)
        dσ/dt (1/s).
    """
    s = as_array(sigma_BN, (3,), "sigma_BN")
    w = as_array(omega_BN_B, (3,), "omega_BN_B")
    s2 = _dot(s, s)[..., None]
    return 0.25 * ((1.0 - s2) * w + 2.0 * np.cross(s, w) + 2.0 * s * _dot(s, w)[..., None])


# --------------------------------------------------------------------------- Euler angles


def _sequence(sequence: Any) -> tuple[int, int, int]:
    if not isinstance(sequence, str) or sequence not in EULER_SEQUENCES:
        hint = ""
        if isinstance(sequence, str) and sequence.upper() in EULER_SEQUENCES:
            hint = (
                " (upper case names body-axis, intrinsic, sequences; for an extrinsic "
                "sequence such as 'xyz', use the reversed intrinsic one, 'ZYX', with the "
                "angles reversed)"
            )
        raise EulerSequenceError(
            f"sequence must be one of {EULER_SEQUENCES}{hint}; got {sequence!r}"
        )
    i, j, k = ("XYZ".index(c) for c in sequence)
    return i, j, k


def _atan2(y: FloatArray, x: FloatArray) -> FloatArray:
    """atan2 with values in (−π, π]: −π becomes π."""
    a = np.arctan2(y, x)
    return np.where(a <= -np.pi, np.pi, a)


def axis_rotation(axis: int, angle: Any) -> FloatArray:
    """The rotation ``R_NB`` of a body turned by ``angle`` about coordinate axis ``axis``
    (0, 1, 2 for x, y, z), right-handed: the elementary rotation of the Euler sequences
    (Schaub & Junkins's ``M_i(angle)ᵀ``).

    Parameters
    ----------
    axis : int
        0, 1 or 2.
    angle : float or ndarray, shape (...)
        Rotation angle (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    if not isinstance(axis, (int, np.integer)) or isinstance(axis, bool) or axis not in (0, 1, 2):
        raise DefinitionError(f"axis must be 0, 1 or 2 (x, y, z); got {axis!r:.40}")
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    R = np.zeros((*np.shape(a), 3, 3))
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R[..., axis, axis] = 1.0
    R[..., i, i] = c
    R[..., j, j] = c
    R[..., j, i] = s
    R[..., i, j] = -s
    return R


def _axis_angle(axis: int, M: FloatArray) -> FloatArray:
    """The angle of a rotation ``M`` about coordinate axis ``axis``."""
    i, j = (axis + 1) % 3, (axis + 2) % 3
    return _atan2(M[..., j, i], M[..., i, i])


def R_NB_from_euler(angles: Any, sequence: str) -> FloatArray:
    """gmuk's ``R_NB`` of Euler angles of a body-axis (intrinsic) sequence.

    For ``sequence = "ABC"`` and ``angles = [α, β, γ]``, B is reached from N by rotating by α
    about the first axis A, then by β about the new (body) axis B, then by γ about the newest
    axis C: ``R_NB = R_A(α) R_B(β) R_C(γ)``, with ``R_k`` the active rotation about
    coordinate axis k; equivalently ``dcm_BN = M_C(γ) M_B(β) M_A(α)`` in Schaub & Junkins's
    notation (their 3-2-1 set is ``"ZYX"``, their 3-1-3 set ``"ZXZ"``). This is what scipy
    calls intrinsic rotations (``Rotation.from_euler("ZYX", angles).as_matrix()``).

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Angles (rad), in the order of ``sequence``; any real values.
    sequence : str
        One of :data:`EULER_SEQUENCES` (upper case, e.g. ``"ZYX"``, ``"ZXZ"``).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``R_NB``: maps body components to N components.

    Raises
    ------
    gmuk.errors.EulerSequenceError
        ``sequence`` is not one of the 12.
    """
    i, j, k = _sequence(sequence)
    a = as_array(angles, (3,), "angles")
    return axis_rotation(i, a[..., 0]) @ axis_rotation(j, a[..., 1]) @ axis_rotation(k, a[..., 2])


def euler_from_R_NB(R_NB: Any, sequence: str) -> FloatArray:
    """Euler angles of a body-axis (intrinsic) sequence of gmuk's ``R_NB``.

    The inverse of :func:`R_NB_from_euler`. Ranges of ``[α, β, γ]``: α, γ ∈ (−π, π]; β ∈
    [−π/2, π/2] for the Tait–Bryan sequences (three distinct axes, e.g. ``"ZYX"``) and β ∈
    [0, π] for the proper Euler sequences (first axis repeated, e.g. ``"ZXZ"``).

    Gimbal lock (β = ±π/2 for Tait–Bryan, β = 0 or π for proper Euler; detected when cos β,
    resp. sin β, is below 1e-14): only α ± γ is defined. The result is then finite with
    γ = 0 and α carrying the whole rotation about the first axis (the choice scipy makes).
    Near gimbal lock γ is computed from the residual ``(R_A(α) R_B(β))ᵀ R_NB``, so that the
    three angles reproduce ``R_NB`` to round-off even where α and γ are each
    ill-conditioned.

    Parameters
    ----------
    R_NB : array_like, shape (..., 3, 3)
        Rotation matrices mapping body components to N components (dimensionless; checked:
        RᵀR = I to 1e-9, det +1).
    sequence : str
        One of :data:`EULER_SEQUENCES` (upper case, e.g. ``"ZYX"``, ``"ZXZ"``).

    Returns
    -------
    ndarray, shape (..., 3)
        Angles (rad) ``[α, β, γ]`` about the axes of ``sequence``, in order.

    Raises
    ------
    gmuk.errors.EulerSequenceError
        ``sequence`` is not one of the 12.
    gmuk.errors.NotOnGroupError
        ``R_NB`` is not a rotation matrix.
    """
    i, j, k = _sequence(sequence)
    R = check_rotation(R_NB, "R_NB")
    if i != k:  # Tait–Bryan: R[i,k] = ε sin β with ε the sign of the permutation (i, j, k)
        eps = 1.0 if (j - i) % 3 == 1 else -1.0
        cos_b = np.hypot(R[..., i, i], R[..., i, j])
        beta = np.arctan2(eps * R[..., i, k], cos_b)
        alpha_regular = _atan2(-eps * R[..., j, k], R[..., k, k])
        regular = cos_b > _GIMBAL_TOL
    else:  # proper Euler: R[i,i] = cos β, R[j,i] = sin α sin β, R[l,i] = −ε cos α sin β
        m = 3 - i - j
        eps = 1.0 if (j - i) % 3 == 1 else -1.0
        sin_b = np.hypot(R[..., j, i], R[..., m, i])
        beta = np.arctan2(sin_b, R[..., i, i])
        alpha_regular = _atan2(R[..., j, i], -eps * R[..., m, i])
        regular = sin_b > _GIMBAL_TOL
    Rb_T = np.swapaxes(axis_rotation(j, beta), -1, -2)
    # At gimbal lock, γ = 0 and R = R_A(α) R_B(β): α from R R_B(β)ᵀ.
    alpha_lock = _axis_angle(i, R @ Rb_T)
    alpha = np.where(regular, alpha_regular, alpha_lock)
    M = Rb_T @ np.swapaxes(axis_rotation(i, alpha), -1, -2) @ R
    gamma = np.where(regular, _axis_angle(k, M), 0.0)
    return np.stack([alpha, beta, gamma], axis=-1)
