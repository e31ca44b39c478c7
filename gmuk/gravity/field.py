"""Spherical-harmonic gravity field of a central body, evaluated in its body-fixed frame F.

See the package docstring (:mod:`gmuk.gravity`) for the formulation, the conventions and the
measured accuracy and speed.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any, NamedTuple

import numpy as np

from gmuk._validation import FloatArray
from gmuk.errors import (
    DefinitionError,
    DegreeError,
    DomainError,
    NonFiniteError,
    ShapeError,
)
from gmuk.gravity import _kernels

__all__ = ["FieldValues", "SphericalHarmonicField"]

#: The compiled kernels, called without numba's type dispatch and compiled on first use
#: (see :class:`gmuk._numba.LazyEntries`): every call below passes float64 arrays of the
#: declared number of dimensions, C-contiguous except the single-point position (positions
#: pass through :func:`_points`, or are checked to be a float64 vector: the ``*_at`` entries
#: check the length themselves).
_kernel = _kernels.ENTRIES

# mode bits of the kernel
_POT = 1
_ACC = 2
_HES = 4
_NO_CENTRAL = 8
#: values per point in the kernel's first output for each combination of the first two bits
_STRIDE = (0, 1, 3, 4, 0, 1, 3, 4)
#: placeholders for an output the kernel does not write (zero-length, never written to)
_NO_OUT = np.empty(0)
_NO_HESS = np.empty((0, 3))
_new_values = tuple.__new__  # FieldValues without the NamedTuple constructor's overhead
_array = np.array  # np.array(r_F): always a new array, so the kernel may write into it
_F64 = np.dtype(np.float64)
_SHAPE3 = (3,)
_SHAPE33 = (3, 3)
_empty = np.empty

_NORMALIZATIONS = ("4pi", "unnormalized")


class FieldValues(NamedTuple):
    """What :meth:`SphericalHarmonicField.evaluate` returns (``None`` where not requested).

    Attributes
    ----------
    potential : float or ndarray, shape (k,)
        U (m²/s²).
    acceleration : ndarray, shape (3,) or (k, 3)
        ∇U (m/s², frame F).
    hessian : ndarray, shape (3, 3) or (k, 3, 3)
        ∇∇U (1/s², frame F), symmetric and traceless.
    """

    potential: float | FloatArray | None
    acceleration: FloatArray | None
    hessian: FloatArray | None


class SphericalHarmonicField:
    """Gravity field ``U = (μ/r) Σ_n (R/r)ⁿ Σ_m P̄_nm(sin φ)(C̄_nm cos mλ + S̄_nm sin mλ)``.

    Immutable: its arrays are read-only copies and its attributes cannot be set;
    :meth:`truncate` returns a new field.

    Parameters
    ----------
    mu : float
        Gravitational parameter GM of the body (m³/s²), the one the coefficients go with.
    radius : float
        Reference radius R of the coefficients (m).
    C, S : array_like, shape (N+1, N+1)
        Cosine and sine coefficients ``C[n, m]``, ``S[n, m]`` (dimensionless), lower
        triangular (entries with m > n must be 0), ``S[n, 0] = 0``. ``C[0, 0]`` is the
        central term (1 for a field whose μ is the body's GM).
    degree : int, optional
        Keep degrees ≤ ``degree`` only (default: all, N).
    name : str
        Model name, e.g. ``"GRGM660PRIM"``.
    normalization : {"4pi", "unnormalized"}
        ``"4pi"`` (default): fully normalised, geodesy convention, no Condon–Shortley phase
        (GRAIL, EGM2008, ICGEM ``fully_normalized``). ``"unnormalized"`` coefficients are
        converted to 4π on construction (C̄ = C / N_nm, :func:`normalization_4pi`).
    reference : str
        Citation of the model.
    tide_system : str
        As given by the source (``"tide_free"``, ``"zero_tide"``, ...; informational).
    sigma_C, sigma_S : array_like, shape (N+1, N+1), optional
        Standard deviations of the coefficients (in the same normalisation as C and S).
    metadata : mapping, optional
        Anything else worth keeping from the source (read-only once stored).

    Attributes
    ----------
    mu : float
        GM (m³/s²).
    radius : float
        Reference radius (m).
    degree : int
        Highest degree N.
    C, S : ndarray, shape (N+1, N+1)
        4π-normalised coefficients (read-only).
    sigma_C, sigma_S : ndarray (N+1, N+1) or None
    name, reference, tide_system : str
    metadata : mapping

    Raises
    ------
    DefinitionError
        μ or R not finite and positive, a non-zero entry above the diagonal or in
        ``S[:, 0]``, an unknown normalisation, a negative sigma.
    ShapeError
        C and S not square 2-D arrays of one shape (or sigmas of another shape).
    NonFiniteError
        NaN or infinity in C, S or the sigmas.
    DegreeError
        ``degree`` outside [0, N].

    Notes
    -----
    Positions ``r_F`` are in metres in the body-fixed frame F of the field (origin at the
    body's centre of mass, axes those of the model, e.g. the DE421 principal axes for
    GRGM660PRIM); accelerations and Hessians come out in the same frame. The sign
    convention is U > 0 with acceleration ``+∇U``; the central term alone gives
    ``a = −μ r/r³``.
    """

    __slots__ = (
        "_C",
        "_S",
        "_data",
        "_degree",
        "_frozen",
        "_metadata",
        "_mu",
        "_name",
        "_radius",
        "_reference",
        "_sigma_C",
        "_sigma_S",
        "_tide_system",
    )
    _mu: float
    _radius: float
    _C: FloatArray
    _S: FloatArray
    _degree: int
    _sigma_C: FloatArray | None
    _sigma_S: FloatArray | None
    _name: str
    _reference: str
    _tide_system: str
    _metadata: Mapping[str, Any]
    _data: FloatArray
    _frozen: bool

    def __init__(
        self,
        mu: float,
        radius: float,
        C: Any,
        S: Any,
        *,
        degree: int | None = None,
        name: str = "",
        normalization: str = "4pi",
        reference: str = "",
        tide_system: str = "unknown",
        sigma_C: Any = None,
        sigma_S: Any = None,
        metadata: Mapping[str, Any] | None = None,
    ) -> None:
        label = f"SphericalHarmonicField {name!r}" if name else "SphericalHarmonicField"
        mu_f = _positive(mu, "mu", "m³/s²", label)
        r_f = _positive(radius, "radius", "m", label)
        Ca = _coefficients(C, "C", label)
        Sa = _coefficients(S, "S", label)
        if Ca.shape != Sa.shape:
            raise ShapeError(f"{label}: C and S must have one shape; got {Ca.shape} and {Sa.shape}")
        N = Ca.shape[0] - 1
        problems = []
        for nm, a in (("C", Ca), ("S", Sa)):
            upper = np.argwhere(np.triu(a, 1) != 0)
            if upper.size:
                n, m = (int(v) for v in upper[0])
                problems.append(
                    f"{nm}[{n}, {m}] must be 0 (order m > degree n); got {float(a[n, m])!r}"
                    f" ({len(upper)} such entr{'y' if len(upper) == 1 else 'ies'})"
                )
        bad_s0 = np.flatnonzero(Sa[:, 0] != 0)
        if bad_s0.size:
            n = int(bad_s0[0])
            problems.append(
                f"S[{n}, 0] must be 0 (no sine term at order 0); got {float(Sa[n, 0])!r}"
            )
        if normalization not in _NORMALIZATIONS:
            problems.append(
                f"normalization must be one of {_NORMALIZATIONS}; got {normalization!r}"
            )
        if problems:
            raise DefinitionError([f"{label}: {p}" for p in problems])
        sig: list[FloatArray | None] = []
        for nm, s in (("sigma_C", sigma_C), ("sigma_S", sigma_S)):
            if s is None:
                sig.append(None)
                continue
            sa = _coefficients(s, nm, label)
            if sa.shape != Ca.shape:
                raise ShapeError(f"{label}: {nm} must have shape {Ca.shape}; got {sa.shape}")
            if np.any(sa < 0):
                raise DefinitionError(f"{label}: {nm} must be >= 0 (standard deviations)")
            sig.append(sa)
        if degree is None:
            deg = N
        else:
            if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)):
                raise DegreeError(f"{label}: degree must be an integer; got {degree!r}")
            if not 0 <= degree <= N:
                raise DegreeError(
                    f"{label}: degree must be between 0 and the coefficients' degree {N}; "
                    f"got {degree}"
                )
            deg = int(degree)
        k = deg + 1
        Ca, Sa = Ca[:k, :k].copy(), Sa[:k, :k].copy()
        sig = [None if s is None else s[:k, :k].copy() for s in sig]
        if normalization == "unnormalized":
            from gmuk.gravity.legendre import normalization_4pi

            n_idx, m_idx = np.tril_indices(k)
            scale = np.zeros((k, k))
            scale[n_idx, m_idx] = 1.0 / normalization_4pi(n_idx, m_idx)
            if not np.all(np.isfinite(scale)):
                raise DefinitionError(
                    f"{label}: unnormalized coefficients of degree {deg} cannot be converted "
                    "to 4π normalisation in double precision (factor overflow); give 4π "
                    "normalised coefficients"
                )
            Ca, Sa = Ca * scale, Sa * scale
            sig = [None if s is None else s * scale for s in sig]
        for a in (Ca, Sa, *[s for s in sig if s is not None]):
            a.setflags(write=False)
        meta = MappingProxyType(dict(metadata or {}))
        for slot, value in (
            ("_mu", mu_f),
            ("_radius", r_f),
            ("_C", Ca),
            ("_S", Sa),
            ("_degree", deg),
            ("_sigma_C", sig[0]),
            ("_sigma_S", sig[1]),
            ("_name", str(name)),
            ("_reference", str(reference)),
            ("_tide_system", str(tide_system)),
            ("_metadata", meta),
            ("_data", _kernels.field_data(mu_f, r_f, Ca, Sa)),
            ("_frozen", True),
        ):
            object.__setattr__(self, slot, value)

    # ------------------------------------------------------------------ immutability

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError(
            f"SphericalHarmonicField is immutable; cannot set {key!r} (use truncate() or "
            "build a new field)"
        )

    def __delattr__(self, key: str) -> None:
        raise AttributeError(f"SphericalHarmonicField is immutable; cannot delete {key!r}")

    def __reduce__(self) -> tuple[Any, ...]:
        kwargs = {
            "name": self._name,
            "reference": self._reference,
            "tide_system": self._tide_system,
            "sigma_C": self._sigma_C,
            "sigma_S": self._sigma_S,
            "metadata": dict(self._metadata),
        }
        return (_rebuild, (self._mu, self._radius, self._C, self._S, kwargs))

    # ------------------------------------------------------------------ attributes

    @property
    def mu(self) -> float:
        """GM (m³/s²)."""
        return self._mu

    @property
    def radius(self) -> float:
        """Reference radius R (m)."""
        return self._radius

    @property
    def degree(self) -> int:
        """Highest degree N of the field."""
        return self._degree

    @property
    def C(self) -> FloatArray:
        """Cosine coefficients C̄[n, m], shape (N+1, N+1), 4π normalised (read-only)."""
        return self._C

    @property
    def S(self) -> FloatArray:
        """Sine coefficients S̄[n, m], shape (N+1, N+1), 4π normalised (read-only)."""
        return self._S

    @property
    def sigma_C(self) -> FloatArray | None:
        """Standard deviations of C̄ (read-only), or None."""
        return self._sigma_C

    @property
    def sigma_S(self) -> FloatArray | None:
        """Standard deviations of S̄ (read-only), or None."""
        return self._sigma_S

    @property
    def name(self) -> str:
        """Model name."""
        return self._name

    @property
    def reference(self) -> str:
        """Citation of the model."""
        return self._reference

    @property
    def tide_system(self) -> str:
        """Tide system of the coefficients, as given by the source."""
        return self._tide_system

    @property
    def metadata(self) -> Mapping[str, Any]:
        """Read-only mapping of what the source said (file, header keys, ...)."""
        return self._metadata

    @property
    def normalization(self) -> str:
        """Always ``"4pi"``: coefficients are stored fully normalised."""
        return "4pi"

    def __repr__(self) -> str:
        nm = f"{self._name!r}, " if self._name else ""
        return (
            f"SphericalHarmonicField({nm}degree={self._degree}, mu={self._mu:.16g} m³/s², "
            f"radius={self._radius:.16g} m)"
        )

    def truncate(self, degree: int) -> SphericalHarmonicField:
        """The same field with degrees ≤ ``degree`` only (a new field).

        Raises
        ------
        DegreeError
            If ``degree`` is not an integer in [0, self.degree].
        """
        if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)):
            raise DegreeError(f"truncate: degree must be an integer; got {degree!r}")
        if not 0 <= degree <= self._degree:
            raise DegreeError(
                f"truncate: cannot truncate {self._describe()} to degree {degree}; "
                f"the field's degree is {self._degree} (expected 0 <= degree <= {self._degree})"
            )
        return SphericalHarmonicField(
            self._mu,
            self._radius,
            self._C,
            self._S,
            degree=int(degree),
            name=self._name,
            reference=self._reference,
            tide_system=self._tide_system,
            sigma_C=self._sigma_C,
            sigma_S=self._sigma_S,
            metadata={**self._metadata, "truncated_from_degree": self._degree},
        )

    # ------------------------------------------------------------------ evaluation

    def potential(self, r_F: Any, *, central: bool = True) -> float | FloatArray:
        """Gravitational potential U at body-fixed positions (m²/s²; U > 0, a = +∇U).

        Parameters
        ----------
        r_F : array_like, shape (3,) or (k, 3)
            Position(s) in the body-fixed frame F (m); any leading batch shape works.
        central : bool
            Include the central term ``C̄₀₀ μ/r`` (default). ``False`` gives the
            perturbation potential only.

        Returns
        -------
        float or ndarray, shape (k,)
        """
        if _is_vector(r_F):  # fast path: one point
            out = _empty(1)
            code = _kernel.potential_at(self._data, r_F, out, central)
            if not code:
                return float(out[0])
            if code > 0:
                raise self._failure(code, r_F)
        return self._batch(_points(r_F), _POT, central).potential  # type: ignore[return-value]

    def acceleration(self, r_F: Any, *, central: bool = True) -> FloatArray:
        """Gravitational acceleration ∇U (full gradient) at body-fixed positions.

        Parameters
        ----------
        r_F : array_like, shape (3,) or (k, 3)
            Position(s) in the body-fixed frame F (m); any leading batch shape works.
        central : bool
            Include the central term (default): ``a ≈ −μ r/r³ + perturbation``. ``False``
            returns the perturbation only (all terms but C̄₀₀), computed without the
            cancellation of subtracting −μ r/r³ afterwards.

        Returns
        -------
        ndarray, shape (3,) or (k, 3)
            Acceleration in frame F (m/s²).

        Raises
        ------
        ShapeError, NonFiniteError
            Bad positions.
        DomainError
            A position at the origin, or where the series does not give a finite value.
        """
        try:
            one = r_F.dtype is _F64 and r_F.ndim == 1  # fast path: one point
        except AttributeError:  # a list, a tuple
            one = False
        if one:
            out = _empty(3)
            code = _kernel.acceleration_at(self._data, r_F, out, central)
            if not code:
                return out
            if code > 0:
                raise self._failure(code, r_F)
        return self._batch(_points(r_F), _ACC, central).acceleration  # type: ignore[return-value]

    def hessian(self, r_F: Any, *, central: bool = True) -> FloatArray:
        """Gravity-gradient tensor ∇∇U at body-fixed positions (1/s², frame F).

        Parameters
        ----------
        r_F : array_like, shape (3,) or (k, 3)
            Position(s) in the body-fixed frame F (m).
        central : bool
            Include the central term's ``μ (3 r rᵀ/r⁵ − I/r³)`` (default).

        Returns
        -------
        ndarray, shape (3, 3) or (k, 3, 3)
            Symmetric; its trace is zero (Laplace) to round-off.
        """
        try:
            r = _array(r_F)
        except (TypeError, ValueError):
            r = _points(r_F)
        if r.dtype is _F64 and r.shape == _SHAPE3:
            H = np.empty((3, 3))
            code = _kernel.evaluate(
                self._data, r, _NO_OUT, H, _HES if central else _HES | _NO_CENTRAL
            )
            if code:
                raise self._failure(code, r)
            return H
        return self._batch(_points(r_F), _HES, central).hessian  # type: ignore[return-value]

    def acceleration_hessian(
        self, r_F: Any, *, central: bool = True
    ) -> tuple[FloatArray, FloatArray]:
        """Acceleration ∇U and gravity-gradient tensor ∇∇U in one pass over the coefficients.

        What rigid-body gravity needs at every step (force and torque); the same numbers,
        bit for bit, as :meth:`acceleration` and :meth:`hessian`, for less than the two
        calls cost (measured in ``benchmarks/README.md``, Gravity).

        Parameters
        ----------
        r_F : array_like, shape (3,) or (k, 3)
            Position(s) in the body-fixed frame F (m).
        central : bool
            Include the central term (default) or return perturbations only.

        Returns
        -------
        acceleration : ndarray, shape (3,) or (k, 3)
            ∇U in frame F (m/s²).
        hessian : ndarray, shape (3, 3) or (k, 3, 3)
            ∇∇U in frame F (1/s²).
        """
        try:
            one = r_F.dtype is _F64 and r_F.ndim == 1  # fast path: one point
        except AttributeError:
            one = False
        if one:
            a = _empty(3)
            H = _empty(_SHAPE33)
            code = _kernel.acceleration_hessian_at(self._data, r_F, a, H, central)
            if not code:
                return a, H
            if code > 0:
                raise self._failure(code, r_F)
        v = self._batch(_points(r_F), _ACC | _HES, central)
        return v.acceleration, v.hessian  # type: ignore[return-value]

    def casadi_acceleration(self, r_F: Any, *, central: bool = True) -> Any:
        """The symbolic (CasADi) form of :meth:`acceleration`, for :mod:`gmuk.optimize`.

        The same recurrences, normalisation and constants as the compiled kernel (read from
        this field's data), written in CasADi operations (:mod:`gmuk.gravity._symbolic`):
        CasADi can differentiate it exactly. The expression is built once per field and
        kept (a cache of recently used fields).

        Parameters
        ----------
        r_F : casadi.SX, casadi.MX, casadi.DM or array_like, 3 entries
            One position in the body-fixed frame F (m).
        central : bool
            Include the central term (default) or give the perturbation only.

        Returns
        -------
        casadi.SX, casadi.MX or casadi.DM, shape (3, 1)
            ∇U in frame F (m/s²): SX for an SX position (the expression itself), MX for MX (a
            call of the field's CasADi Function), DM for numbers.

        Raises
        ------
        MissingDependencyError
            Without CasADi.
        ShapeError
            If ``r_F`` does not have 3 entries.

        Notes
        -----
        Plain double precision, without the kernel's extended exponents (where the seeds
        underflow, near the poles at high order, their terms are negligible; see
        :mod:`gmuk.gravity._symbolic`). It agrees with :meth:`acceleration` to about 1e-15
        relative up to the shipped degree 150, poles included
        (``tests/forces/test_harmonic_symbolic.py``).
        """
        from gmuk.gravity import _symbolic

        return _symbolic.acceleration(self, r_F, central=central)

    def evaluate(
        self,
        r_F: Any,
        *,
        potential: bool = True,
        acceleration: bool = True,
        hessian: bool = False,
        central: bool = True,
    ) -> FieldValues:
        """Potential, acceleration and/or Hessian in one pass over the coefficients.

        One recursion of the solid harmonics serves every requested quantity, so asking for
        acceleration and Hessian together costs less than the two calls
        :meth:`acceleration` and :meth:`hessian` (measured ratios to the acceleration alone
        are in ``benchmarks/README.md``). A single position with ``potential=False,
        acceleration=True, hessian=True`` is :meth:`acceleration_hessian`.

        Parameters
        ----------
        r_F : array_like, shape (3,) or (k, 3)
            Position(s) in the body-fixed frame F (m).
        potential, acceleration, hessian : bool
            What to compute (at least one).
        central : bool
            Include the central term (default) or return perturbations only.

        Returns
        -------
        FieldValues
            ``(potential, acceleration, hessian)``, ``None`` for what was not requested.
        """
        if hessian and acceleration and not potential:  # the rigid-body request
            both = self.acceleration_hessian(r_F, central=central)
            return _new_values(FieldValues, (None, *both))
        mode = (_POT if potential else 0) | (_ACC if acceleration else 0)
        mode |= _HES if hessian else 0
        if not mode:
            raise DefinitionError(
                "evaluate: request at least one of potential, acceleration, hessian"
            )
        try:
            r = _array(r_F)
        except (TypeError, ValueError):
            r = _points(r_F)
        if r.dtype is _F64 and r.shape == _SHAPE3:
            out = np.empty(_STRIDE[mode])
            H = np.empty((3, 3)) if mode & _HES else _NO_HESS
            code = _kernel.evaluate(self._data, r, out, H, mode if central else mode | _NO_CENTRAL)
            if code:
                raise self._failure(code, r)
            pot = float(out[0]) if mode & _POT else None
            acc = (out[1:] if mode & _POT else out) if mode & _ACC else None
            return _new_values(FieldValues, (pot, acc, H if mode & _HES else None))
        return self._batch(_points(r_F), mode, central)

    # ------------------------------------------------------------------ helpers

    def _batch(self, r: FloatArray, mode: int, central: bool) -> FieldValues:
        """Evaluate ``mode`` at r of shape (3,) or (..., 3)."""
        lead = r.shape[:-1]
        flat = r.reshape(-1)
        k = flat.shape[0] // 3
        stride = _STRIDE[mode]
        out = np.empty(k * stride)
        H = np.empty((3 * k, 3)) if mode & _HES else _NO_HESS
        if k:
            code = _kernel.evaluate(
                self._data, flat, out, H, mode if central else mode | _NO_CENTRAL
            )
            if code:
                raise self._failure(code, flat.reshape(k, 3))
        table = out.reshape(k, stride)
        pot = acc = hes = None
        if mode & _POT:
            pot_a = table[:, 0].reshape(lead)
            pot = float(pot_a) if not lead else pot_a.copy()
        if mode & _ACC:
            i = 1 if mode & _POT else 0
            acc = table[:, i : i + 3].reshape(*lead, 3)
            if mode & _POT:
                acc = acc.copy()
        if mode & _HES:
            hes = H.reshape(*lead, 3, 3)
        return FieldValues(pot, acc, hes)

    def _describe(self) -> str:
        nm = f" {self._name!r}" if self._name else ""
        return f"field{nm} (degree {self._degree})"

    def _failure(self, code: int, r: FloatArray) -> Exception:
        """The error for a kernel status code (see :func:`gmuk.gravity._kernels.evaluate`)."""
        kind, i = code % 4, code // 4
        pts = r.reshape(-1, 3)
        p = pts[i]
        where = f" at index {i}" if pts.shape[0] > 1 else ""
        shown = np.array2string(p, precision=10, separator=", ")
        if kind == _kernels.BAD_INPUT:
            return NonFiniteError(f"r_F must be finite{where}; got {shown}")
        if kind == _kernels.AT_ORIGIN:
            return DomainError(
                f"r_F{where} is the origin (r = 0), where the {self._describe()} is singular"
            )
        rn = float(np.sqrt(p @ p))
        return DomainError(
            f"the {self._describe()} has no finite value at r_F{where} = {shown} m "
            f"(|r| = {rn:.6g} m, reference radius {self._radius:.6g} m); the series converges "
            "only outside the body's mass and overflows well inside the reference sphere"
        )


def _rebuild(
    mu: float, radius: float, C: FloatArray, S: FloatArray, kwargs: dict[str, Any]
) -> SphericalHarmonicField:
    """Unpickle a field."""
    return SphericalHarmonicField(mu, radius, C, S, **kwargs)


def _positive(x: Any, name: str, unit: str, label: str) -> float:
    """``x`` as a finite float > 0, or raise DefinitionError."""
    try:
        if isinstance(x, (bool, np.bool_, str, bytes)):  # refused, not read as 1.0 or parsed
            raise TypeError
        v = float(x)
    except OverflowError:  # an int beyond float64
        v = math.inf
    except (TypeError, ValueError):
        raise DefinitionError(f"{label}: {name} must be a number > 0 ({unit}); got {x!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise DefinitionError(f"{label}: {name} must be finite and > 0 ({unit}); got {x!r}")
    return v


def _coefficients(a: Any, name: str, label: str) -> FloatArray:
    """A finite square 2-D float array, or raise ShapeError / NonFiniteError."""
    try:
        arr = np.array(a, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ShapeError(
            f"{label}: {name} must be a numeric array of shape (N+1, N+1); "
            f"could not convert {type(a).__name__}: {exc}"
        ) from None
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or arr.shape[0] == 0:
        raise ShapeError(
            f"{label}: {name} must be a square array of shape (N+1, N+1); got {arr.shape}"
        )
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        n, m = (int(v) for v in bad[0])
        raise NonFiniteError(
            f"{label}: {name} must be finite; got {float(arr[n, m])!r} at [{n}, {m}] "
            f"({len(bad)} non-finite entr{'y' if len(bad) == 1 else 'ies'})"
        )
    return arr


def _is_vector(r_F: Any) -> bool:
    """Whether ``r_F`` is a float64 ndarray of one dimension (what the ``*_at`` entries take).

    :meth:`SphericalHarmonicField.acceleration` and ``acceleration_hessian``, the calls of
    propagation loops, have this test written out instead, to save a function call.
    """
    try:
        return r_F.dtype is _F64 and r_F.ndim == 1
    except AttributeError:
        return False


def _points(r_F: Any) -> FloatArray:
    """Positions as a C-contiguous float64 array of shape (3,) or (..., 3)."""
    try:
        r = np.ascontiguousarray(r_F, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ShapeError(
            f"r_F must be a numeric array of shape (3,) or (k, 3) (m); could not convert "
            f"{type(r_F).__name__}: {exc}"
        ) from None
    if r.ndim == 0 or r.shape[-1] != 3:
        raise ShapeError(f"r_F must have shape (3,) or (k, 3) (m); got {np.shape(r_F)}")
    return r
