"""Udwadia–Kalaba solve strategies, chosen once when a System is built.

A :class:`UKSolver` turns a state's loads into :class:`gmuk.Accelerations`: the free
acceleration ν̇_a = M⁻¹(ad*_V 𝕀V + Q), the constraint acceleration ν̇_c that the
Udwadia–Kalaba equation gives for the stacked rows ``A ν̇ = b`` (McCann 2020, Eqs. 2, 64) or
for ``A g̈ B = C`` on T²SE(3) (Eq. 80), the multipliers and the diagnostics. The System
picks one strategy in its constructor (as scipy's ``Rotation`` picks its backend once) and
calls it at every right-hand-side evaluation; nothing is decided per call except what the
numbers decide (whether a QR factorisation certifies full row rank).

Built in (names for ``System(..., solver=NAME)``):

``"fused"`` (:class:`FusedRigidSolver`)
    Small dense systems of rigid bodies whose loads the solve all sees: free acceleration,
    Householder-QR solve and packing in one compiled call. Falls back to ``"dense"`` for a
    call whose rows it cannot certify (more than :data:`QR_MAX_ROWS` rows, or a condition
    number above the limit).
``"dense"`` (:class:`DenseSolver`)
    QR when full row rank is certified, else the SVD (minimum-norm, rank-revealing).
``"sparse"`` (:class:`SparseSolver`)
    Sparse rows; A M⁻¹ Aᵀ λ = r by SuperLU or conjugate gradients
    (:func:`gmuk.engine.uk.solve_sparse`).
``"tree"`` (:class:`gmuk.engine.tree.TreeSolver`)
    Constraints on one or two rigid bodies forming a tree or forest with the ground (a
    robot's joints): the block LDLᵀ factorisation of the KKT system with no fill-in (Baraff
    1996), linear in the number of bodies; compiled, with the dense or sparse solve where it
    cannot certify full row rank.
``"eq80"`` (:class:`TangentBundleEq80Solver`)
    McCann (2020) Eq. 80 as printed for one :class:`~gmuk.constraints.TangentBundleConstraint`,
    with each body's block of g̈_c projected onto g·se(3).

A new strategy is a subclass with a ``name``; it registers itself and ``System(...,
solver=name)`` finds it.
"""

from __future__ import annotations

import abc
import enum
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from gmuk._numba import overload_entry
from gmuk._validation import FloatArray, all_finite
from gmuk.bodies import Body, RigidBody
from gmuk.constraints.tangent_bundle import TangentBundleConstraint
from gmuk.engine import _uk_kernels, uk
from gmuk.errors import (
    ConstraintError,
    DefinitionError,
    InconsistentConstraintsError,
    InconsistentConstraintsWarning,
)
from gmuk.lie import se3
from gmuk.state import Layout

if TYPE_CHECKING:
    from gmuk.engine.system import System
    from gmuk.state import State

__all__ = [
    "QR_COND_LIMIT",
    "QR_MAX_ROWS",
    "SOLVERS",
    "Accelerations",
    "DenseSolver",
    "FusedRigidSolver",
    "SolveStatus",
    "SparseSolver",
    "TangentBundleEq80Solver",
    "UKSolver",
]

#: Dense solves: up to this many rows, a full-row-rank A is solved by Householder QR
#: (compiled, no LAPACK set-up) when its condition number is certified ≤ QR_COND_LIMIT.
QR_MAX_ROWS = 48
QR_COND_LIMIT = 1e8
_EPS = float(np.finfo(float).eps)
_F64 = np.dtype(np.float64)
_empty = np.empty
#: The compiled entry of :func:`gmuk.engine._uk_kernels.uk_rigid` for its one shared signature
#: (:data:`gmuk.engine._uk_kernels.UK_RIGID_SIGNATURE`, the compiled loop's argument types), made by
#: :func:`_fused_entry` when the first System that takes the fused solve is built (not on
#: import).
_uk_rigid_c: Any = None
#: The multipliers of a System without constraints (shared, read-only).
_NO_MULTIPLIERS = np.zeros(0)
_NO_MULTIPLIERS.setflags(write=False)


def _fused_entry() -> Any:
    """The compiled entry of the fused solve, compiled (or loaded from the cache) once.

    The signature is the compiled loop's, so whichever of the two comes first compiles the
    kernel (and its callees ``_qr_solve``, ``rigid_free_accel``) for both. The dispatcher
    stays open to other types (arrays in other layouts take it).
    """
    global _uk_rigid_c
    if _uk_rigid_c is None:
        _uk_rigid_c = overload_entry(_uk_kernels.uk_rigid, _uk_kernels.UK_RIGID_SIGNATURE)
    return _uk_rigid_c


def _frobenius(A: Any) -> float:
    """‖A‖_F of a dense or sparse matrix."""
    values = A.data if sp.issparse(A) else A
    return float(np.sqrt(np.sum(np.square(values))))


def _writable(x: FloatArray) -> FloatArray:
    """``x``, or a copy of it when it is read-only (same values, same C layout): the compiled
    entry takes writable arrays only, the loop's types."""
    return x if x.flags.writeable else x.copy()


@dataclass(frozen=True, eq=False)
class Accelerations:
    """Accelerations and diagnostics at one state (vectors in System body order, length n_dof).

    Attributes
    ----------
    free : ndarray (n_dof,)
        ν̇_a: the unconstrained acceleration under the *modeled* forces
        (V̇_a = 𝕀⁻¹(ad*_V 𝕀V + τ) for rigid bodies, Eq. 10b).
    constraint : ndarray (n_dof,)
        ν̇_c: the Udwadia–Kalaba constraint acceleration (Eq. 64 / Eq. 2).
    extra : ndarray (n_dof,)
        Acceleration from unmodeled forces and controllers (the UK solve does not see it).
    total : ndarray (n_dof,)
        ν̇ = free + constraint + extra.
    constraint_force : ndarray (n_dof,)
        M ν̇_c = Aᵀλ: the constraint wrench [L; f] of each rigid body in its body frame (the
        thesis's "control"), the force of each point mass in N.
    control_force, unmodeled_force : ndarray (n_dof,)
        Controller wrenches u and unmodeled wrenches, same layout.
    multipliers : ndarray (s,)
        λ of Eq. 3, with constraint force Aᵀλ (Pinocchio's ``lambda_c``; −μ of the KKT form).
    residual : float
        ‖A(ν̇_a + ν̇_c) − b‖₂ (T²SE(3): relative ‖A g̈ B − C‖_F).
    rank : int or None
        Rank of A (None if not computed: sparse path with redundant rows, or T²SE(3)).
    unreachable : float
        T²SE(3) only: relative size of the part of Eq. 80's g̈_c outside g·se(3) (0 on R⁶).
    z_dot : ndarray (n_control,)
        Rates of the controllers' internal states.
    """

    layout: Layout
    free: FloatArray
    constraint: FloatArray
    extra: FloatArray
    total: FloatArray
    constraint_force: FloatArray
    control_force: FloatArray
    unmodeled_force: FloatArray
    multipliers: FloatArray
    residual: float
    rank: int | None
    unreachable: float
    z_dot: FloatArray
    #: Set (in the instance) by a compiled call that has checked every entry is finite, so
    #: that :meth:`gmuk.System.accelerations` does not scan them again.
    _finite_checked: ClassVar[bool] = False

    @classmethod
    def _from_dict(cls, fields: dict[str, Any]) -> Accelerations:
        # The frozen dataclass's __init__ sets 13 fields through object.__setattr__, a
        # noticeable share of a one-body call; the System passes every field, by name.
        obj = object.__new__(cls)
        object.__setattr__(obj, "__dict__", fields)
        return obj

    @classmethod
    def _packed(cls, out: FloatArray, n: int, s: int, shared: dict[str, Any]) -> Accelerations:
        """The Accelerations of a compiled call that wrote, in ``out``, ν̇_a, ν̇_c, ν̇ and the
        constraint wrench (n each), λ (s), then the residual (``out[-3]``), every entry
        checked finite; ``shared`` holds the fields that do not depend on the state (layout,
        extra, control_force, unmodeled_force, unreachable, z_dot). Each field is made the
        first time it is read (:meth:`_unpack`): a call costs one allocation and this object."""
        obj = object.__new__(cls)
        obj.__dict__.update(_finite_checked=True, _out=out, _ns=(n, s), _shared=shared)
        return obj

    def _unpack(self, name: str) -> Any:
        """Field ``name`` of a :meth:`_packed` object, kept once made (AttributeError for a
        name that is not one of its fields)."""
        fields = self.__dict__
        out = fields.get("_out")
        if out is None:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        n, s = fields["_ns"]
        if name == "free":
            value: Any = out[:n]
        elif name == "constraint":
            value = out[n : 2 * n]
        elif name == "total":
            value = out[2 * n : 3 * n]
        elif name == "constraint_force":
            value = out[3 * n : 4 * n]
        elif name == "multipliers":
            value = out[4 * n : 4 * n + s]
        elif name == "residual":
            value = float(out[-3])
        elif name == "rank":
            value = s
        elif name in fields["_shared"]:
            value = fields["_shared"][name]
        else:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        fields[name] = value
        return value

    if not TYPE_CHECKING:  # (mypy would otherwise accept any attribute name)

        def __getattr__(self, name: str) -> Any:
            # called only for a name missing from the instance: a packed field not read yet
            return self._unpack(name)

    def of(self, body: Body | str, field: str = "total") -> FloatArray:
        """The slice of a per-dof field (e.g. "total", "constraint_force") for one body."""
        s = self.layout.slot(body)
        return getattr(self, field)[s.offset : s.offset + s.dof]


#: Every registered strategy by name (subclasses with a ``name`` add themselves).
SOLVERS: dict[str, type[UKSolver]] = {}


class SolveStatus(enum.IntEnum):
    """Outcome of a compiled QR solve (the kernels return it as a float)."""

    #: Full row rank certified and solved.
    SOLVED = 0
    #: Rank not certified (too many rows, a zero pivot, or κ above the limit): use the SVD.
    RANK_NOT_CERTIFIED = 1
    #: A or b holds NaN or inf.
    NOT_FINITE = 2
    #: Solved, but ‖A ν̇ − b‖ is above the consistency tolerance.
    INCONSISTENT = 3


_SOLVED = float(SolveStatus.SOLVED)
_INCONSISTENT = float(SolveStatus.INCONSISTENT)

#: (ν̇_c (n,), λ (s,), rank or None, residual, unreachable)
Solution = tuple[FloatArray, FloatArray, "int | None", float, float]


class UKSolver(abc.ABC):
    """One way of solving the Udwadia–Kalaba equation for a System.

    Subclasses set ``name`` (registering the class in :data:`SOLVERS`) and ``sparse``
    (whether the System should assemble sparse rows and mass blocks), may state what they
    need of the System's parts in :meth:`problems`, and implement :meth:`solve`.

    Parameters
    ----------
    system : System
        The System being built; its mass blocks and index are in place.
    """

    name: ClassVar[str]
    #: Whether this strategy works on sparse rows (``System.constraint_rows`` returns CSR).
    sparse: ClassVar[bool] = False

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        name = cls.__dict__.get("name")
        if isinstance(name, str):
            SOLVERS[name] = cls

    def __init__(self, system: System) -> None:
        self.system = system
        # (modeled, unmodeled) generalized forces (n_dof,) of the force models at a state
        self._loads = system._generalized_forces

    @classmethod
    def problems(cls, system: System) -> list[str]:
        """What this strategy cannot solve in ``system`` (empty if it can)."""
        return []

    @classmethod
    def wants_sparse(cls, system: System) -> bool:
        """Whether the System being built should keep sparse rows and mass blocks for this
        strategy (``sparse`` unless a strategy decides by the System's size)."""
        return cls.sparse

    def accelerations(self, state: State) -> Accelerations:
        """Free, constraint and total accelerations at ``state`` (the System has checked
        that the state is one of its own)."""
        return self._general(state, *self._loads(state), None)

    def _general(
        self, state: State, modeled: FloatArray, unmodeled: FloatArray, rows: Any
    ) -> Accelerations:
        """Free acceleration, the solve, then the controllers (which may read the modeled
        acceleration ν̇_a + ν̇_c) and the plant-only loads."""
        system = self.system
        a = system._free(state, modeled)
        ac, lam, rank, residual, unreachable = self.solve(state, a, rows)
        total = a + ac
        control, z_dot = system._controls(state, total)
        if system._plant_only_loads:
            extra = system._apply_Minv(unmodeled + control)
            total = total + extra
        else:
            extra = np.zeros(a.shape[0])
        return Accelerations(
            system.layout,
            a,
            ac,
            extra,
            total,
            self._constraint_wrench(ac),
            control,
            unmodeled,
            lam,
            residual,
            rank,
            unreachable,
            z_dot,
        )

    def _constraint_wrench(self, ac: FloatArray) -> FloatArray:
        """The constraint wrenches Aᵀλ = M ν̇_c of the solve just made."""
        return self.system._apply_M(ac)

    @abc.abstractmethod
    def solve(self, state: State, a: FloatArray, rows: Any = None) -> Solution:
        """The constraint acceleration for free acceleration ``a`` (n_dof,) at ``state``.

        ``rows`` are the stacked (A, b) when the caller has them already. Returns
        (ν̇_c (n_dof,), λ (s,), rank or None, residual, unreachable). Strategies on R⁶ rows
        call :meth:`check_consistency`, whose test is scale-invariant (relative to ‖b‖ and
        ‖A‖ times the accelerations).
        """

    def check_consistency(self, state: State, residual: float, scale: float) -> None:
        """Warn (raise in strict mode) when ‖A ν̇ − b‖ exceeds consistency_tol × scale.

        The test is relative to the size of the rows: ``scale`` is
        ``‖b‖₂ + ‖A‖_F (‖ν̇_a‖₂ + ‖ν̇_c‖₂)`` (:func:`gmuk.engine._uk_kernels.consistency_scale`,
        computed by the solve kernels, the same in the compiled loop), with no absolute floor.
        Scaling every row and its right-hand side by any c > 0 leaves the decision as it is:
        contradictory rows scaled by 1e-8 still warn, consistent rows scaled by 1e-8 or 1e8
        do not."""
        system = self.system
        if residual > system.consistency_tol * scale:
            msg = (
                f"constraints are inconsistent at t = {state.t:.9g} s: ‖A ν̇ − b‖ = "
                f"{residual:.3g} (tolerance {system.consistency_tol:g} × {scale:.3g}); the "
                "least-squares constraint acceleration was used"
            )
            if system.strict:
                raise InconsistentConstraintsError(msg)
            warnings.warn(msg, InconsistentConstraintsWarning, stacklevel=4)

    def _rows(self, state: State, rows: Any) -> tuple[Any, FloatArray]:
        """The stacked rows, checked finite (naming the constraint that is not)."""
        system = self.system
        A, b = system._stack_rows(state, check_finite=False) if rows is None else rows
        values = np.asarray(A.data if sp.issparse(A) else A).reshape(-1)
        if not (all_finite(values) and all_finite(b)):
            system.constraint_rows(state)  # raises ConstraintError naming the constraint
            raise ConstraintError(f"constraint rows at t = {state.t:.9g} s are not finite")
        return A, b

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class DenseSolver(UKSolver):
    """Dense rows: Householder QR where full row rank is certified, else the SVD.

    The QR of ``(A M^{-1/2})ᵀ`` gives the same ν̇_c and λ as the SVD when A has full row
    rank; the rank is certified from R (κ₂ bound ≤ min(QR_COND_LIMIT, 0.1/rcond), so the QR
    never keeps a rank the SVD would drop). Otherwise the SVD gives the minimum-norm
    least-squares solution and the numerical rank.
    """

    name = "dense"

    def __init__(self, system: System) -> None:
        super().__init__(system)
        self._Minv_sqrt = system._Minv_sqrt
        self._unconstrained = not system.constraints

    def accelerations(self, state: State) -> Accelerations:
        """The general path, or for a System without constraints the free motion alone."""
        if not self._unconstrained:
            return self._general(state, *self._loads(state), None)
        system = self.system
        modeled, unmodeled = self._loads(state)
        a = system._free(state, modeled)
        control, z_dot = system._controls(state, a)
        if system._plant_only_loads:
            extra = system._apply_Minv(unmodeled + control)
            total = a + extra
        else:
            extra, total = system._zero_loads, a
        zero = system._zero_loads  # shared, read-only
        return Accelerations._from_dict(
            {
                "layout": system.layout,
                "free": a,
                "constraint": zero,
                "extra": extra,
                "total": total,
                "constraint_force": zero,
                "control_force": control,
                "unmodeled_force": unmodeled,
                "multipliers": _NO_MULTIPLIERS,
                "residual": 0.0,
                "rank": 0,
                "unreachable": 0.0,
                "z_dot": z_dot,
            }
        )

    def solve(self, state: State, a: FloatArray, rows: Any = None) -> Solution:
        """QR or SVD solve of the stacked dense rows."""
        if self._unconstrained and rows is None:  # nothing to stack or solve
            return np.zeros_like(a), _NO_MULTIPLIERS, 0, 0.0, 0.0
        A, b = self._rows(state, rows)
        ac, lam, rank, residual = self.solve_rows(state, a, A, b)
        return ac, lam, rank, residual, 0.0

    def solve_rows(
        self, state: State, a: FloatArray, A: FloatArray, b: FloatArray
    ) -> tuple[FloatArray, FloatArray, int | None, float]:
        """UK solve of given dense rows, with the consistency check.

        Inconsistent means ``‖A(a + ν̇_c) − b‖₂ > consistency_tol · (‖b‖₂ + ‖A‖_F (‖a‖₂ +
        ‖ν̇_c‖₂))`` (:meth:`check_consistency`): a relative test, the same in the QR and the
        SVD solve and in the compiled loop's gate (which compares the QR kernel's residual
        with ``consistency_tol`` times the scale the kernel returns)."""
        if b.size == 0:
            return np.zeros_like(a), np.zeros(0), 0, 0.0
        rcond = self.system.rcond
        if rcond is None:
            rcond = max(A.shape) * _EPS
        if A.shape[0] <= QR_MAX_ROWS:
            ac, lam, residual, scale, status = _uk_kernels.uk_qr(
                A, b, a, self._Minv_sqrt, min(QR_COND_LIMIT, 0.1 / rcond)
            )
            if status == _SOLVED:
                self.check_consistency(state, residual, scale)
                return ac, lam, b.size, residual
        ac, lam, rank, residual, scale = _uk_kernels.uk_dense(A, b, a, self._Minv_sqrt, rcond)
        self.check_consistency(state, residual, scale)
        return ac, lam, rank, residual


class FusedRigidSolver(DenseSolver):
    """Small dense systems of rigid bodies only, every load seen by the solve.

    One compiled call computes the free accelerations (Eq. 10b), the QR solve and the
    constraint wrenches, with no per-call allocation beyond the result; a call whose rank it
    cannot certify takes the :class:`DenseSolver` path with the same rows.
    """

    name = "fused"

    def __init__(self, system: System) -> None:
        super().__init__(system)
        _fused_entry()
        lay = system.layout
        self._layout = lay
        self._n = lay.n_dof
        self._V_shape = (lay.n_rigid, 6)
        self._zero_loads = system._zero_loads
        self._zero_z = system._zero_z
        self._stack_rows = system._stack_rows
        # QR-eligible rows have s ≤ n, so the SVD's default rcond would be n·ε.
        rc = system.rcond if system.rcond is not None else max(lay.n_dof, 1) * _EPS
        self._params = _uk_kernels.rigid_params(
            system._J,
            system._Jinv,
            system._m_rigid,
            system._Minv_sqrt,
            system._M_dense,
            min(QR_COND_LIMIT, 0.1 / rc),
            system.consistency_tol,
        )

    @classmethod
    def problems(cls, system: System) -> list[str]:
        """Rigid bodies only, no plant-only loads, at least one constraint."""
        out = []
        if system.layout.n_euclid:
            out.append("the fused solve takes rigid bodies only")
        if system._plant_only_loads:
            out.append("the fused solve takes no unmodeled forces or controllers")
        if not system.constraints:
            out.append("the fused solve needs at least one constraint")
        return out

    def accelerations(self, state: State) -> Accelerations:
        """The compiled path, or the dense one for rows it cannot certify."""
        modeled, unmodeled = self._loads(state)
        rows = A, b = self._stack_rows(state, check_finite=False)
        s = b.size
        if 0 < s <= QR_MAX_ROWS:
            V = state.V
            n = self._n
            out = _empty(4 * n + s + 3)
            if (
                V.dtype == _F64  # (not "is": arrays made by numba carry their own dtype object)
                and V.shape == self._V_shape
                and V.flags.c_contiguous
                and A.flags.c_contiguous
                and b.flags.c_contiguous
            ):  # exactly the declared types: the compiled entry, no dispatch
                _uk_rigid_c(
                    _writable(V), _writable(modeled), _writable(A), _writable(b), self._params, out
                )
            else:
                _uk_kernels.uk_rigid(V, modeled, A, b, self._params, out)
            status = float(out[-1])  # a Python float compares faster than a numpy scalar
            if status == _INCONSISTENT:
                self.check_consistency(state, float(out[-3]), float(out[-2]))
            if status == _SOLVED or status == _INCONSISTENT:
                return Accelerations._from_dict(
                    {
                        "layout": self._layout,
                        "free": out[:n],
                        "constraint": out[n : 2 * n],
                        "extra": self._zero_loads,  # no plant-only loads here
                        "total": out[2 * n : 3 * n],
                        "constraint_force": out[3 * n : 4 * n],
                        "control_force": self._zero_loads,  # no controllers here
                        "unmodeled_force": unmodeled,
                        "multipliers": out[4 * n : 4 * n + s],
                        "residual": float(out[-3]),
                        "rank": s,
                        "unreachable": 0.0,
                        "z_dot": self._zero_z,
                    }
                )
        return self._general(state, modeled, unmodeled, rows)


class SparseSolver(UKSolver):
    """Sparse rows (CSR): ``A M⁻¹ Aᵀ λ = b − A a`` by SuperLU (``method="lu"``) or by
    Jacobi-preconditioned conjugate gradients (``"cg"``); see
    :func:`gmuk.engine.uk.solve_sparse`."""

    name = "sparse"
    sparse = True

    def __init__(self, system: System) -> None:
        super().__init__(system)
        self.method = system.sparse_solver

    def solve(self, state: State, a: FloatArray, rows: Any = None) -> Solution:
        """Sparse solve of the stacked rows, with the consistency check."""
        A, b = self._rows(state, rows)
        if b.size == 0:
            return np.zeros_like(a), np.zeros(0), 0, 0.0, 0.0
        system = self.system
        Aa = A @ a
        ac, lam, rank = uk.solve_sparse(
            sp.csr_matrix(A), b - Aa, system._Minv_sp, system._Minv_sqrt_sp, self.method
        )
        residual = float(np.linalg.norm(A @ (a + ac) - b))
        scale = float(
            _uk_kernels.consistency_scale(
                np.sqrt(b @ b), _frobenius(A), np.linalg.norm(a), np.linalg.norm(ac)
            )
        )
        self.check_consistency(state, residual, scale)
        return ac, lam, rank, residual, 0.0


class TangentBundleEq80Solver(UKSolver):
    """McCann (2020) Eq. 80 for one ``A g̈ B = C`` constraint on T²SE(3).

    g̈_c = 𝕀̃^{-1/4} (A 𝕀̃^{-1/4})⁺ (C − A g̈_a B) (B 𝕀̃^{-1/4})⁺ 𝕀̃^{-1/4}; each body's diagonal
    block is projected onto g·se(3) and ``Accelerations.unreachable`` reports the relative
    size of what was discarded (docs/errata.rst). No multipliers (Eq. 80 has none).
    """

    name = "eq80"

    def __init__(self, system: System) -> None:
        super().__init__(system)
        (self._constraint,) = system.constraints
        idx = [system.layout.slot(b).index for b in self._constraint.bodies]
        self._idx = idx
        self._cols = system._rigid_idx[idx]
        bodies = [system._resolve(r) for r in self._constraint.bodies]
        # 𝕀̃^{-1/4} = blkdiag(J^{-1/4}, m^{-1/4}) per body (rigid: the constraint declares it)
        self._Im14 = scipy.linalg.block_diag(
            *[
                scipy.linalg.block_diag(uk.matrix_power_spd(b.inertia, -0.25), [[b.mass**-0.25]])
                for b in bodies
                if isinstance(b, RigidBody)
            ]
        )

    @classmethod
    def problems(cls, system: System) -> list[str]:
        """Exactly one constraint, with ``tangent_rows`` (a TangentBundleConstraint)."""
        cs = system.constraints
        if len(cs) == 1 and isinstance(cs[0], TangentBundleConstraint):
            return []
        kinds = [type(c).__name__ for c in cs]
        return [
            "solver 'eq80' (McCann 2020, Eq. 80) takes exactly one TangentBundleConstraint "
            f"and no other constraint (Eq. 79 does not stack); got {kinds}"
        ]

    def solve(self, state: State, a: FloatArray, rows: Any = None) -> Solution:
        """Eq. 80 with the projection onto g·se(3)."""
        c: Any = self._constraint
        A, B, C = (np.asarray(x, dtype=float) for x in c.tangent_rows(state))
        idx = self._idx
        g = state.g[idx]
        Vh = se3._hat(state.V[idx])
        gdd_a = g @ (Vh @ Vh + se3._hat(a[self._cols]))
        V_dot_c, unreachable, residual = uk.solve_tangent_bundle(A, B, C, g, gdd_a, self._Im14)
        ac = np.zeros_like(a)
        ac[self._cols] = V_dot_c
        return ac, np.zeros(0), None, residual, unreachable


def resolve(solver: object) -> type[UKSolver]:
    """The strategy class for a name or a :class:`UKSolver` subclass."""
    if isinstance(solver, type) and issubclass(solver, UKSolver):
        return solver
    if isinstance(solver, str) and solver in SOLVERS:
        return SOLVERS[solver]
    raise DefinitionError(
        f"solver must be one of {sorted(SOLVERS)} or a gmuk.engine.solvers.UKSolver subclass; "
        f"got {solver!r}"
    )


# The tree solve registers itself as "tree" (its module imports this one).
from gmuk.engine import tree as _tree  # noqa: E402, F401
