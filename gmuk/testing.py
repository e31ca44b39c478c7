"""gmuk's reference integrator loop in Python: a test oracle, not a runtime path.

:func:`gmuk.engine.integrate.simulate` runs one loop, the compiled one
(:mod:`gmuk.engine.integrators._compiled`). This module keeps the same Runge–Kutta–Munthe-Kaas loop
written in numpy, statement by statement, with the System's own Python ``accelerations`` as
the right-hand side and the method object's Python ``stages``, ``error_norm``,
``interpolant`` and ``interpolant_error``. Tests compare the two: the compiled loop must
agree with :func:`reference_simulate` to rounding on every built-in part (sums are taken in
another order, so the embedded error estimate, which cancels to ~1e-4 of its size, can move a
step-size decision in its last digits; the results then agree to ~1e-13 relative, not bit
for bit).

It has no checkpoints, no run control and no progress bar, and it is slow: 15–20 µs of
Python per evaluation.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any

import numpy as np

from gmuk._validation import FloatArray
from gmuk.engine.integrate import _Packing, _Recorder, check_run
from gmuk.engine.integrators import RungeKuttaMethod
from gmuk.engine.integrators._base import label
from gmuk.errors import GmukWarning, SimulationError
from gmuk.lie import _kernels
from gmuk.state import State
from gmuk.trajectory import Trajectory

if TYPE_CHECKING:
    from gmuk.engine.system import Accelerations, System

__all__ = ["StepFailure", "reference_simulate"]


class StepFailure(RuntimeError):
    """Step-size underflow or too many steps (the reference loop's failures)."""


def reference_simulate(
    system: System,
    state0: State,
    t_span: tuple[float, float],
    *,
    t_eval: Any = None,
    method: Any = "DOP853",
    rtol: float = 1e-10,
    atol: float = 1e-10,
    step: float | None = None,
    first_step: float | None = None,
    max_step: float = np.inf,
    max_steps: int = 1_000_000,
    on_failure: str = "raise",
) -> Trajectory:
    """:func:`gmuk.engine.integrate.simulate` by the reference Python loop (same arguments, checked
    the same way; no checkpoints or progress bar). ``stats["compiled"]`` is False."""
    run = check_run(
        system, state0, t_span, t_eval=t_eval, method=method, rtol=rtol, atol=atol, step=step,
        first_step=first_step, max_step=max_step, max_steps=max_steps, on_failure=on_failure,
    )  # fmt: skip
    prob = _ReferenceProblem(system)
    rec = _Recorder(prob)
    stepper = _ReferenceLoop(prob, run.method, run.rtol, run.atol, run.step, run.first_step,
                             run.max_step)  # fmt: skip
    status, message = "success", ""
    try:
        stepper.run(run.state0, run.t1, run.outs, rec, run.max_steps)
    except KeyboardInterrupt:
        status, message = "interrupted", f"interrupted by the user at t = {stepper.t:.9g} s"
        warnings.warn(message + "; returning the trajectory so far", GmukWarning, stacklevel=2)
    except Exception as exc:
        status = "failed"
        message = f"failed at t = {stepper.t:.9g} s: {type(exc).__name__}: {exc}"
        if run.on_failure == "raise":
            raise SimulationError(message, rec.build(status, message, stepper.stats())) from exc
    return rec.build(status, message, stepper.stats())


def _step_factor(m: RungeKuttaMethod, err: float) -> float:
    """The method's step-size factor for a scaled error estimate ``err`` (1: at tolerance)."""
    return m.safety * (max(err, m.error_floor) ** (-1.0 / m.order))


class _ReferenceProblem(_Packing):
    """The RKMK vector field on Y about base poses ``G0``, in numpy."""

    def __init__(self, system: System) -> None:
        super().__init__(system)
        self.system = system
        self.G0: FloatArray = np.zeros((self.nr, 4, 4))
        self.acc: Accelerations | None = None
        self.n_rhs = 0

    def deriv(self, Y: FloatArray, acc: Accelerations) -> FloatArray:
        dY = np.empty(self.size)
        xi = Y[self.s_xi].reshape(-1, 6)
        V = Y[self.s_V].reshape(-1, 6)
        if self.nr:
            dY[self.s_xi] = _kernels.dexp_inv_apply(xi, V).ravel() if xi.any() else V.ravel()
            dY[self.s_V] = acc.total[self.rigid_idx].ravel()
        e = self.layout.euclid_offsets
        dY[self.s_x] = Y[self.s_xd]
        dY[self.s_xd] = acc.total[e]
        dY[self.s_z] = acc.z_dot
        return dY

    def rhs(self, t: float, Y: FloatArray) -> FloatArray:
        """dY/dt at (t, Y) about ``G0``: the method's ``f``. The System's accelerations of
        the latest call are kept in ``acc`` (the step end records them)."""
        self.n_rhs += 1
        # the System's unchecked entry: simulate checked the layout once, and dY and the
        # outputs are checked for NaN and inf below, as the compiled loop checks them
        self.acc = acc = self.system._accelerations(self.state(t, Y, self.G0))
        dY = self.deriv(Y, acc)
        outputs = (acc.constraint_force, acc.multipliers, acc.control_force, acc.unmodeled_force)
        if not (
            np.isfinite(dY).all()
            and all(np.isfinite(x).all() for x in outputs)
            and np.isfinite(acc.residual)
        ):
            raise FloatingPointError(
                f"non-finite derivative or output (accelerations, constraint forces, "
                f"multipliers or the solve's residual) at t = {t:.9g} s"
            )
        return dY

    def scale(
        self, Y0: FloatArray, Y1: FloatArray, G0: FloatArray, rtol: float, atol: float
    ) -> FloatArray:
        """Error weights, one per entry of Y (the larger of the values at both ends).

        Every 3-vector is weighed by its norm, so that no weight depends on how the
        inertial or body axes are chosen: ξ's rotation part against 1 rad, its translation
        part (body-frame components) against the distance ‖r‖ of the base pose, the twist's
        ω and v and a point mass's position and velocity by their norms. Scalars (slack
        coordinates, controller states) by their absolute values.
        """
        sc = atol + rtol * np.maximum(np.abs(Y0), np.abs(Y1))
        if self.nr:
            r = np.linalg.norm(G0[:, :3, 3], axis=1)
            xi_sc = np.empty((self.nr, 2, 3))
            xi_sc[:, 0] = atol + rtol
            xi_sc[:, 1] = (atol + rtol * r)[:, None]
            sc[self.s_xi] = xi_sc.ravel()
            V = np.maximum(
                np.linalg.norm(Y0[self.s_V].reshape(-1, 2, 3), axis=2),
                np.linalg.norm(Y1[self.s_V].reshape(-1, 2, 3), axis=2),
            )
            sc[self.s_V] = np.repeat(atol + rtol * V, 3)
        idx = self.point_idx
        if idx is not None:
            n = np.maximum(np.linalg.norm(Y0[idx], axis=1), np.linalg.norm(Y1[idx], axis=1))
            sc[idx] = (atol + rtol * n)[:, None]
        return sc

    def advance_base(self, Y: FloatArray, G0: FloatArray) -> tuple[FloatArray, FloatArray]:
        """G₁ = G₀ exp(ξ₁), re-orthonormalised; returns (G₁, Y with ξ reset to 0)."""
        if not self.nr:
            return G0, Y
        G1 = _kernels.compose_exp(G0, Y[self.s_xi].reshape(-1, 6))
        R = G1[:, :3, :3]
        G1[:, :3, :3] = 0.5 * R @ (3.0 * np.eye(3) - np.swapaxes(R, -1, -2) @ R)
        Y = Y.copy()
        Y[self.s_xi] = 0.0
        return G1, Y


class _ReferenceLoop:
    """The RKMK step loop: step-size control, output times, base-pose updates; everything
    that depends on the Runge–Kutta method is asked of the method object."""

    def __init__(
        self,
        prob: _ReferenceProblem,
        method: RungeKuttaMethod,
        rtol: float,
        atol: float,
        step: float | None,
        first_step: float | None,
        max_step: float,
    ) -> None:
        self.p = prob
        self.method = method
        self.rtol, self.atol = rtol, atol
        self.fixed = step
        self.first_step = first_step
        self.max_step = max_step
        self.t = 0.0
        self.n_steps = self.n_rejected = 0

    def stats(self) -> dict[str, Any]:
        return {
            "n_rhs": self.p.n_rhs,
            "n_steps": self.n_steps,
            "n_rejected": self.n_rejected,
            "method": label(self.method),
            "rtol": self.rtol,
            "atol": self.atol,
            "compiled": False,
        }

    def _initial_step(self, t: float, Y: FloatArray, f0: FloatArray, t_end: float) -> float:
        if self.first_step is not None:
            return min(self.first_step, t_end - t)
        sc = self.p.scale(Y, Y, self.p.G0, self.rtol, self.atol)
        d0 = np.sqrt(np.mean((Y / sc) ** 2))
        d1 = np.sqrt(np.mean((f0 / sc) ** 2))
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, t_end - t)
        f1 = self.p.rhs(t + h0, Y + h0 * f0)
        d2 = np.sqrt(np.mean(((f1 - f0) / sc) ** 2)) / h0
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1.0 / (self.method.order + 1))
        return float(min(100 * h0, h1, self.max_step, t_end - t))

    def run(
        self,
        state0: State,
        t_end: float,
        outs: FloatArray | None,
        rec: _Recorder,
        max_steps: int,
    ) -> None:
        p, m = self.p, self.method
        f = p.rhs
        b, s = m.b, m.n_stages
        fsal, adaptive = m.fsal, m.adaptive
        dense = m.dense_output and outs is not None
        step_to_outputs = m.steps_onto_outputs and outs is not None
        rtol, atol = self.rtol, self.atol
        G0: FloatArray
        Y: FloatArray
        t = self.t = state0.t
        G0 = p.G0 = state0.g.copy()
        Y = p.pack(state0)
        f0 = f(t, Y)
        acc0 = p.acc
        assert acc0 is not None
        out_i = 0
        if outs is None or outs[0] == t:
            rec.add(state0, acc0)
            out_i = 0 if outs is None else 1
        h = self._initial_step(t, Y, f0, t_end) if adaptive else float(self.fixed or 0)
        while t < t_end:
            if self.n_steps >= max_steps:
                raise StepFailure(f"reached max_steps = {max_steps}")
            h = min(h, self.max_step)
            t_target = t_end
            if step_to_outputs and outs is not None and out_i < outs.size:
                t_target = min(t_end, outs[out_i])
            # Land exactly on the target when within a hair of it (no sliver steps); t + h_try
            # may round to a neighbour of t_target, so the step ends at t_target itself.
            landing = t_target - t <= h * (1.0 + 1e-6)
            h_try = t_target - t if landing else h
            if h_try <= 10 * np.finfo(float).eps * max(1.0, abs(t)):
                raise StepFailure(f"step size underflow (h = {h_try:.3g} s)")
            K = m.stages(f, t, Y, h_try, f0)
            Y1 = Y + h_try * (b @ K[:s])
            f1 = f(t + h_try, Y1)  # reused as the next step's first stage
            acc1 = p.acc
            if fsal:
                K[-1] = f1
            if adaptive:
                sc = p.scale(Y, Y1, G0, rtol, atol)
                err = m.error_norm(K, h_try, sc)
                factor = _step_factor(m, err)
                if err > 1.0:
                    self.n_rejected += 1
                    h = h_try * max(m.min_factor, min(m.max_factor_rejected, factor))
                    continue
                h_next = h_try * min(m.max_factor, max(m.min_factor, factor))
            else:
                h_next = h
            t_new = t_target if landing else t + h_try
            if dense and outs is not None:
                hit = outs[out_i:][outs[out_i:] < t_new]
                if hit.size:
                    interp = m.interpolant(f, t, Y, h_try, K, Y1)
                    if adaptive:
                        # Output times inside the step: the continuous extension must meet
                        # the tolerance as well, or the step is retried shorter.
                        err_d = m.interpolant_error(f, interp, sc)
                        factor_d = _step_factor(m, err_d)
                        if err_d > 1.0:
                            self.n_rejected += 1
                            h = h_try * max(m.min_factor, min(m.max_factor_rejected, factor_d))
                            continue
                        h_next = min(h_next, h_try * min(m.max_factor, max(m.min_factor, factor_d)))
                    for tt in hit:
                        st = p.state(float(tt), interp(float(tt)), G0)
                        rec.add(st)
                        out_i += 1
            G1, Y1r = p.advance_base(Y1, G0)
            state1 = p.state(t_new, Y1r, G1)
            assert acc1 is not None
            f0 = p.deriv(Y1r, acc1)  # same accelerations; ξ̇ = V at the new base (ξ = 0)
            if outs is None or (out_i < outs.size and outs[out_i] == t_new):
                rec.add(state1, acc1)
                if outs is not None:
                    out_i += 1
            t, Y, G0, h = t_new, Y1r, G1, h_next
            p.G0 = G0
            self.t = t
            self.n_steps += 1
