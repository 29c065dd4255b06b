"""Quasi-static load stepping: the static problem at each load factor, solved by Newton.
"""
from __future__ import annotations

import numpy as np

from drape.solvers.linear import DirectSolver
from drape.solvers.newmark import (
    ConvergenceError,
    IntegratorInputError,
    NewmarkState,
    StepInfo,
    _Constraints,
    _describe,
    _Restrictions,
    _tolerances,
    default_solver,
)
from drape.solvers.newton import NewtonPolicy, newton
from drape.solvers.time_stepping import stepping

__all__ = ['quasi_static']


class _StaticProblem:
    """Equilibrium ``f_int(u) − λ f_ext(t) = 0`` (no inertia, no damping) in the free ``u_h``."""

    def __init__(self, model, t: float, u_start, restrict):
        self.model, self.t = model, t
        self.c = _Constraints(model, t)
        self.free = self.c.free
        self.base = self.c.impose(u_start - self.c.lift[0])
        self.zero = np.zeros(model.ndofs)
        self.restrict = restrict
        self.scale = float(model.force_scale(t))

    def u(self, x):
        uh = self.base.copy()
        uh[self.free] = x
        return self.c.lift[0] + uh

    def residual(self, x):
        R = self.model.evaluate(self.u(x), self.zero, self.zero, self.t).force
        return R[self.free], max(float(np.linalg.norm(R)), self.scale)

    def linearize(self, x, tangent):
        ev = self.model.evaluate(self.u(x), self.zero, self.zero, self.t, tangent, (1.0, 0.0, 0.0))
        return ev.force[self.free], self.restrict(self.free, ev.J), max(float(np.linalg.norm(ev.force)),
                                                                        self.scale)

    def norm_reference(self, x):
        return float(np.linalg.norm(self.u(x)))

    def max_step(self, x, dx):
        """The model's safe fraction of the Newton step (contact's CCD; 1 without)."""
        max_step = getattr(self.model, "max_step", None)
        return 1.0 if max_step is None else max_step(self.u(x), self.u(x + dx), self.t)


def quasi_static(model, load_factors, times=None, state: NewmarkState | None = None, *, max_cuts: int = 6,
                 on_step=None, progress: bool = False, policy: NewtonPolicy | None = None,
                 linear_solver: DirectSolver | None = None, **tolerances) -> NewmarkState:
    """Equilibrium path ``f_int(u) = λ f_ext(t)`` (inertia and damping off).

    Parameters
    ----------
    model : drape.models.protocol.StructuralModel
        ``model.load_scale`` is set to each λ in turn (and to a bisected one after a failure).
    load_factors : sequence of float
        Load factors λ_i of the requested equilibrium states, in order.
    times : sequence of float, optional
        Time passed to the model at each step (imposed motions, time-dependent loads);
        default: the load factors themselves.
    state : NewmarkState, optional
        Starting equilibrium (default: at rest, λ = 0, t = 0).
    max_cuts : int
        A failed increment is bisected (in λ and t) up to this depth.
    on_step : callable(state, info), optional
        Called after each requested λ_i is reached and committed; ``True`` stops.
    policy, linear_solver, **tolerances
        As in :func:`newmark_step`.

    Returns
    -------
    NewmarkState
        The last equilibrium (``v = a = 0``).
    """
    lam = np.atleast_1d(np.asarray(load_factors, dtype=float))
    ts = lam.copy() if times is None else np.atleast_1d(np.asarray(times, dtype=float))
    if ts.shape != lam.shape:
        raise IntegratorInputError(f"times must have the same length as load_factors ({lam.size}), got {ts.size}")
    if not np.all(np.isfinite(lam)) or not np.all(np.isfinite(ts)):
        raise IntegratorInputError("load_factors and times must be finite")
    tol = _tolerances(tolerances)
    solver = default_solver(model) if linear_solver is None else linear_solver
    restrict = _Restrictions(solver)
    zero = np.zeros(model.ndofs)
    if state is None:
        state = NewmarkState(0.0, zero.copy(), zero.copy(), zero.copy())
        lam_prev = 0.0
    else:
        lam_prev = float(model.load_scale)

    def solve(lam_k, t_k):
        model.load_scale = lam_k
        problem = _StaticProblem(model, t_k, state.u, restrict)
        info = StepInfo(t=t_k, dt=t_k - state.t)
        result = newton(problem, problem.base[problem.free], tol, policy, solver)
        info.absorb(result)
        if not result.converged:
            where = f"at load factor {lam_k:.6g} (t = {t_k:.6g})"
            raise ConvergenceError(_describe(where, tol, result), info)
        return problem.u(result.x), info

    with stepping(progress, lam.size, "quasi-static") as bar:
        for i, (lam_i, t_i) in enumerate(zip(lam, ts)):
            pending = [(lam_i, t_i, 0)]
            while pending:
                lam_k, t_k, depth = pending[-1]
                try:
                    u, info = solve(lam_k, t_k)
                except ConvergenceError as err:
                    if depth >= max_cuts:
                        model.load_scale = lam_prev
                        raise ConvergenceError(
                            f"quasi-static path stopped at load factor {lam_prev:.6g} (t = {state.t:.6g}): "
                            f"the increment failed after {max_cuts} bisections. Last failure: {err}",
                            err.info) from None
                    pending.append((0.5 * (lam_prev + lam_k), 0.5 * (state.t + t_k), depth + 1))
                    continue
                pending.pop()
                model.commit(u, zero, zero)
                state = NewmarkState(float(t_k), u, zero.copy(), zero.copy())
                lam_prev = lam_k
                info.step, info.cuts = i + 1, depth
            if bar is not None:
                bar.update(1)
            if on_step is not None and on_step(state, info) is True:
                break
    return state
