"""Implicit Newmark / HHT-α time stepping and quasi-static load stepping for any structural model.

The integrator knows a model only through :class:`drape.models.protocol.StructuralModel`:
``ndofs``, ``fixed_dofs``, ``prescribed(t)``, ``lifting(t)``, ``force_scale(t)``,
``symmetric_tangent``, ``evaluate(u, v, a, t, tangent, weights) -> Evaluation`` (a step
asks for the one matrix it factorises, ``J = c_K K + c_C C + c_M M``) and
``commit(u, v, a)`` (``load_scale`` for :func:`quasi_static`).

With a lifting ``(u_p, v_p, a_p)`` (a full-size field carrying the imposed motion
with its exact rates) the unknown is ``u = u_p(t) + u_h`` and Newmark acts on
``u_h`` only (zero on imposed dofs), so rate-dependent terms see the exact imposed
velocity and acceleration; without one the imposed dofs get Newmark-consistent rates.

Newmark (1959)::

    a₁ = (u₁ − u₀ − Δt v₀)/(βΔt²) − (1/(2β) − 1) a₀,   v₁ = v₀ + Δt((1−γ) a₀ + γ a₁)

HHT-α (Hilber, Hughes & Taylor 1977; −⅓ ≤ α ≤ 0) weights the non-inertial
forces ``F = C v + f_int − f_ext``::

    M a₁ + (1 + α) F₁ − α F₀ = 0,   β = (1 − α)²/4,  γ = ½ − α

Each step's equations are solved by :func:`drape.solvers.newton.newton` with the tangent
``(1 + α)(K + γ/(βΔt) C) + M/(βΔt²)`` on the free dofs, factorised by a
:class:`drape.solvers.linear.DirectSolver` (symmetric when the model says so) that
keeps its symbolic analysis from step to step.

The step size either follows Newton (halved on failure, doubled after a run of
successes) or, with ``error_tolerance``, the local error estimate of
Zienkiewicz & Xie (1991), ``e = |β − 1/6| Δt² ‖a₁ − a₀‖``, kept below
``error_tolerance × max‖u‖``.

Examples
--------
A single undamped oscillator (mass 1, stiffness 4π², period 1 s) keeps its
energy exactly with the average-acceleration rule:

>>> import numpy as np, scipy.sparse as sp
>>> from drape.models.protocol import Evaluation
>>> class Oscillator:
...     ndofs, fixed_dofs, load_scale, symmetric_tangent = 1, np.zeros(0, int), 1.0, True
...     k = 4 * np.pi**2
...     def prescribed(self, t): return None
...     def lifting(self, t): return None
...     def force_scale(self, t): return 0.0
...     def evaluate(self, u, v, a, t, tangent=None, weights=None):
...         K, M = sp.csr_matrix([[self.k]]), sp.csr_matrix([[1.0]])
...         return Evaluation(a.copy(), self.k * u, K, sp.csr_matrix((1, 1)), M).weighted(weights)
...     def commit(self, u, v, a): pass
>>> model = Oscillator()
>>> s = integrate(model, 1.0, 0.01, NewmarkState(0.0, np.array([1.0]), np.zeros(1), np.array([-model.k])))
>>> e = lambda s: 0.5 * s.v[0]**2 + 0.5 * model.k * s.u[0]**2
>>> bool(abs(e(s) / (0.5 * model.k) - 1) < 1e-12)
True
"""
from __future__ import annotations

import dataclasses
from contextlib import contextmanager

import numpy as np

from drape.solvers.linear import DirectSolver, blas_threads
from drape.solvers.newmark import (
    ConvergenceError,
    IntegratorInputError,
    NewmarkState,
    _check_step_options,
    _newmark_coefficients,
    _Restrictions,
    _solve_step,
    _StepProblem,
    _tolerances,
    default_solver,
    initial_state,
)
from drape.solvers.newton import NewtonPolicy
from drape.solvers.step_control import StepControl, _StepSize

__all__ = ['integrate', 'stepping']


@contextmanager
def stepping(progress: bool, total: float, desc: str, **bar_options):
    """The context of a loop of steps: one BLAS thread (:func:`drape.solvers.linear.blas_threads`)
    and, with ``progress``, a tqdm bar of ``total`` (yielded, else None), closed however the loop ends."""
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total, desc=desc, **bar_options)
    threads = blas_threads(1)
    try:
        yield bar
    finally:
        threads.unregister()
        if bar is not None:
            bar.close()


def integrate(model, t_end: float, dt: float, state: NewmarkState | None = None, *, beta=None, gamma=None,
              alpha_hht: float = 0.0, hit_times=(), max_cuts: int = 6, grow_after: int = 4, on_step=None,
              progress: bool = False, dt_max: float | None = None, control: StepControl | None = None,
              error_tolerance: float | None = None, predictor: str = "auto",
              policy: NewtonPolicy | None = None, linear_solver: DirectSolver | None = None,
              **tolerances) -> NewmarkState:
    """Integrate from ``state`` (default: :func:`initial_state`) to ``t_end``.

    Each converged step is committed (``model.commit``) and passed to
    ``on_step(state, info)``; a callback returning ``True`` stops the run after
    that step. On a Newton failure the step is halved and retried from the last
    converged state, down to ``dt / 2**max_cuts``; only there does a step try the policy's
    fallback tangents (a cut is the cheaper remedy while one is left). The step then grows back: doubled
    after ``grow_after`` consecutive successes (twice as many after each further failure, until
    a doubled step converges) up to ``dt_max`` (default ``dt``;
    beyond ``dt`` it is pseudo-transient continuation: a fabric creeping into
    equilibrium under constant loads needs ever fewer, longer steps), or, with
    ``error_tolerance``, set from the local error estimate (a step whose estimate
    exceeds it is redone shorter). Steps are shortened to land exactly on
    ``hit_times``. One :class:`drape.solvers.linear.DirectSolver` serves every step. Each step's
    ``info.control`` is where the step control stands after it; ``control``
    starts from there instead of from ``dt``. The policy's kept tangents
    (``reuse_contraction``) serve steps of ``dt`` and longer only: a step cut shorter takes a
    fresh tangent at every iteration, since where steps fail (a skirt folding as it falls) a
    kept tangent contracts too little to save work, and the path through that stretch stays
    Newton's.

    Raises
    ------
    ConvergenceError
        When a step fails at the smallest allowed size. Every step before it has been
        committed and passed to ``on_step``.
    """
    _check_step_options(dt, predictor)
    if int(max_cuts) < 0:
        raise IntegratorInputError(f"max_cuts must be >= 0, got {max_cuts!r}")
    dt_max = dt if dt_max is None else float(dt_max)
    if not dt_max >= dt:
        raise IntegratorInputError(f"dt_max must be >= dt = {dt}, got {dt_max!r}")
    if error_tolerance is not None and not (np.isfinite(error_tolerance) and error_tolerance > 0):
        raise IntegratorInputError(f"error_tolerance must be > 0, got {error_tolerance!r}")
    coefficients = _newmark_coefficients(beta, gamma, alpha_hht)
    tol = _tolerances(tolerances)
    state = initial_state(model) if state is None else state
    if not t_end > state.t:
        raise IntegratorInputError(f"t_end must be > the start time {state.t}, got {t_end!r}")
    solver = default_solver(model) if linear_solver is None else linear_solver
    restrict = _Restrictions(solver)
    policy = NewtonPolicy() if policy is None else policy
    fresh = dataclasses.replace(policy, reuse_contraction=0.0)   # for steps cut below dt
    size = _StepSize(dt, dt_max, max_cuts, grow_after, error_tolerance, control)
    eps = 1e-12 * max(abs(t_end), dt)
    hits = sorted(float(t) for t in hit_times if state.t + eps < t <= t_end - eps)
    step, cuts, rejected = 0, 0, 0
    spent = []      # attempts at the coming step that failed or were refused: their counts join it
    with stepping(progress, float(t_end - state.t), "integrate", unit="s", unit_scale=False) as bar:
        while state.t < t_end - eps:
            while hits and hits[0] <= state.t + eps:
                hits.pop(0)
            limit = min(t_end, hits[0]) if hits else t_end
            h = min(size.h, limit - state.t)
            landed = limit - (state.t + h) < max(eps, 1e-9 * h)
            if landed:
                h = limit - state.t
            problem = _StepProblem(model, state, h, coefficients, restrict)
            try:
                new, info = _solve_step(problem, predictor, tol, fresh if size.h < dt * (1 - 1e-12) else policy,
                                        solver, fallbacks=not size.can_cut())
            except ConvergenceError as err:
                cuts += 1
                spent.append(err.info)
                if not size.failed():
                    raise ConvergenceError(
                        f"integration stopped at t = {state.t:.6g} s: the step failed at the smallest allowed "
                        f"size dt/2^{max_cuts} = {size.h_min:.3g} s (a smaller dt or more max_cuts allow "
                        f"smaller steps). Last failure: {err}", err.info) from None
                continue
            info.error = size.error(state, new, coefficients[0])
            if not size.accept(info.error, h, landed and h < size.h):
                rejected += 1
                spent.append(info)
                continue
            for attempt in spent:
                info.add_counts(attempt)
            model.commit(new.u, new.v, new.a)
            step += 1
            info.step, info.cuts, info.rejected = step, cuts, rejected
            cuts = rejected = 0
            spent = []
            if bar is not None:
                bar.update(new.t - state.t)
            state = new
            info.control = StepControl(size.h, size.successes, size.patience, size.trial)
            if on_step is not None and on_step(state, info) is True:
                break
    return state
