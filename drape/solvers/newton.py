"""Damped Newton for ``R(x) = 0`` with an error-oriented line search and tangent fallbacks.

The problem (a Newmark step, a quasi-static load step) is injected as a
:class:`NonlinearProblem` on the free dofs; the linear solver as a
:class:`drape.solvers.linear.DirectSolver`; the strategy as a :class:`NewtonPolicy`.
:func:`newton` returns a :class:`NewtonResult` whether it converged or not.

Strategy (Deuflhard 2004, *Newton Methods for Nonlinear Problems*, §3.3, the
error-oriented NLEQ-ERR damping):

- From ``x`` with Newton correction ``Δx = −J⁻¹R(x)``, a trial ``x + λΔx`` is
  judged by its *simplified* correction ``Δx̄ = −J⁻¹R(x + λΔx)`` (same
  factorisation, one back-substitution): it is accepted when
  ``‖Δx̄‖ ≤ (1 − λ/4)‖Δx‖`` (natural monotonicity), or when both ``‖R‖`` and
  ``‖Δx̄‖`` fell. Contrary to ``‖R‖``, ``‖Δx̄‖`` is invariant to the scaling of
  the equations, so the stiff membrane of a shell does not veto a good bending
  step.
- A full step's trial is evaluated with its tangent (one evaluation of the model
  gives both): if accepted, that tangent is the next iteration's and is only
  factorised; the residual alone is evaluated where the step is expected to
  converge (its predicted next correction, the last contraction times this one,
  is within the increment tolerance), since the last tangent would go unused.
- A rejected full step first gets a new tangent at the trial point: where the
  tangent jumps (a friction point switching between stick and slip) the old
  one judges the step wrongly; the trial is accepted if the new correction is
  at most half the old one. Otherwise λ shrinks to Deuflhard's estimate
  ``λ' = min(λ/2, ‖Δx‖ λ² / (2‖Δx̄ − (1 − λ)Δx‖))`` (at least ``λ/10``).
- At ``λ < lambda_min`` the step is taken at ``lambda_min`` if ``‖R‖`` has not
  grown more than ``kink_growth``-fold: the residual has a kink where a point
  leaves stick (the tangent there is one-sided), which no damping of the same
  direction passes smoothly; at most ``kink_steps`` such steps.
- Converged when ``‖R‖ ≤ rtol·ref + atol`` and the error estimate (the next
  simplified correction) ``‖Δx̄‖ ≤ du_rtol·‖x‖ + du_atol`` (``ref``: the larger
  of the first residual and the problem's force scale); the correction test is
  waived when ``‖R‖`` is 100× below its tolerance (a linear problem converges in
  one solve), and a correction below the round-off of ``x`` ends the iteration.
- An attempt that takes ``stall_iterations`` full steps (or three times as many
  steps of any kind) without halving its residual norm (below the best since
  the first step, which may overshoot) is given up: it cycles, typically with
  friction points switching between stick and slip, and a shorter step (the
  caller's remedy) is cheaper than more iterations. Damped steps count less:
  they descend, if slowly.
- A problem with ``max_step(x, dx)`` (contact: continuous collision detection) caps λ and
  its floor at the safe fraction of the step it returns, so no iterate passes through a body.
- If the first tangent of ``policy.tangents`` fails, Newton restarts from
  ``x0`` with the next (e.g. the friction law's *stick* tangent, which is
  positive and constant in the step: slower, but it cannot point uphill).
- With ``policy.reuse_contraction`` > 0 the factorised tangent is kept while it
  contracts (modified Newton, Deuflhard §2.3.3): after a full step whose
  contraction ``‖Δx̄‖/‖Δx‖`` is at most that value, the simplified correction
  ``Δx̄`` is the next correction, and a problem that names its tangents
  (``tangent_key``, e.g. a time step's size) starts from the last one factorised
  for the same key. A kept tangent's full step is accepted only at that
  contraction; otherwise a fresh tangent is factorised at the iterate. An
  iteration then costs one residual and one back-substitution instead of a
  tangent's assembly and factorisation, about a sixth, where the tangent changes
  little from iteration to iteration and step to step (a drape creeping into
  equilibrium); the converged iterate meets the same tests.

Examples
--------
``x³ = 8`` from ``x = 1``:

>>> import numpy as np, scipy.sparse as sp
>>> class Cube:
...     def residual(self, x): return x**3 - 8.0, 8.0
...     def linearize(self, x, tangent):
...         return x**3 - 8.0, sp.csr_matrix(3 * np.diag(x**2)), 8.0
...     def norm_reference(self, x): return float(np.linalg.norm(x))
>>> result = newton(Cube(), np.array([1.0]), NewtonTolerances(rtol=1e-12, du_rtol=1e-12))
>>> result.converged, result.x.round(12), result.iterations
(True, array([2.]), 7)
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from drape.solvers.linear import DirectSolver, LinearSolverError

__all__ = ["NonlinearProblem", "NewtonTolerances", "NewtonPolicy", "NewtonResult", "newton"]


class NonlinearProblem(Protocol):
    """``R(x) = 0`` on the free dofs."""

    def residual(self, x) -> tuple:
        """``(R, scale)``: the residual and a typical force norm (no tangent)."""

    def linearize(self, x, tangent: str) -> tuple:
        """``(R, J, scale)``: residual, tangent ``∂R/∂x`` (CSR) with the material tangent
        ``tangent``, and the force norm. ``J`` must stay as returned: Newton may factorise it
        again after later calls."""

    def norm_reference(self, x) -> float:
        """Norm of the whole unknown at ``x`` (e.g. including imposed motion) for the increment test."""

    # optional: max_step(x, dx) -> float in (0, 1], the largest safe fraction of the step
    # x -> x + dx (continuous collision detection); a problem without it allows every step.
    # optional: tangent_key() -> hashable, equal for problems whose tangents are alike (a
    # modified Newton may start from the last tangent factorised for the same key).


@dataclass(frozen=True)
class NewtonTolerances:
    """Convergence tolerances: residual ``rtol``/``atol`` [force], increment ``du_rtol``/``du_atol``."""

    rtol: float = 1e-9
    atol: float = 0.0
    du_rtol: float = 1e-9
    du_atol: float = 0.0
    max_iter: int = 25

    def __post_init__(self):
        for name in ("rtol", "atol", "du_rtol", "du_atol"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        if self.rtol == 0 and self.atol == 0:
            raise ValueError("rtol and atol cannot both be 0 (the residual test could never pass)")
        if int(self.max_iter) < 1:
            raise ValueError(f"max_iter must be >= 1, got {self.max_iter!r}")


@dataclass(frozen=True)
class NewtonPolicy:
    """How Newton damps and which material tangents it tries, in order.

    Parameters
    ----------
    tangents : tuple of str
        Material tangents passed to ``problem.linearize``, tried in turn from ``x0``.
    lambda_min : float
        Smallest damping factor of the line search.
    jump_ratio : float
        A full correction longer than ``jump_ratio`` × the first one is not re-linearised
        at its trial point (a near-singular tangent sends it far off; shrink instead).
    kink_steps : int
        Steps at ``lambda_min`` allowed per attempt when no damping reduces the error.
    kink_growth : float
        Largest growth of ``‖R‖`` such a step may cause.
    stall_iterations : int
        An attempt ends after this many full (undamped) steps, or three times as many
        steps of any kind, without halving ``‖R‖`` (the first step's residual
        excluded); 0: never (only ``max_iter`` ends it).
    trial_tangent : bool
        Evaluate a full step's trial with its tangent (the next iteration's if the trial is
        accepted), unless the step is expected to converge or to keep its tangent; False: the
        residual alone, and the tangent in an evaluation of its own.
    reuse_contraction : float
        Keep the factorised tangent after a full step that contracted at least this much
        (``‖Δx̄‖ ≤ reuse_contraction ‖Δx‖``), and start from the last one factorised for the
        problem's ``tangent_key`` (modified Newton); 0: a fresh tangent at every iteration.
    """

    tangents: tuple = ("consistent",)
    lambda_min: float = 1.0 / 64.0
    jump_ratio: float = 100.0
    kink_steps: int = 3
    kink_growth: float = 10.0
    stall_iterations: int = 8
    trial_tangent: bool = True
    reuse_contraction: float = 0.0

    def __post_init__(self):
        if not self.tangents or not all(isinstance(t, str) for t in self.tangents):
            raise ValueError(f"tangents must be a non-empty tuple of names, got {self.tangents!r}")
        if not 0 < self.lambda_min <= 1:
            raise ValueError(f"lambda_min must lie in (0, 1], got {self.lambda_min!r}")
        if not self.jump_ratio >= 1 or not self.kink_growth >= 1 or int(self.kink_steps) < 0:
            raise ValueError("jump_ratio and kink_growth must be >= 1 and kink_steps >= 0")
        if int(self.stall_iterations) < 0:
            raise ValueError(f"stall_iterations must be >= 0, got {self.stall_iterations!r}")
        if not 0 <= self.reuse_contraction < 1:
            raise ValueError(f"reuse_contraction must lie in [0, 1), got {self.reuse_contraction!r}")


@dataclass
class NewtonResult:
    """What :func:`newton` did: the last iterate, whether it converged, and its history."""

    x: np.ndarray
    converged: bool
    iterations: int = 0
    evaluations: int = 0
    factorizations: int = 0
    tangent: str = ""
    fallback: bool = False      # converged (or ended) with a tangent after the policy's first
    residual_norms: list = field(default_factory=list)
    increment_norms: list = field(default_factory=list)
    reason: str = ""


def _norms(xs) -> str:
    return "[" + ", ".join(f"{v:.3e}" for v in xs[-6:]) + "]"


#: :meth:`_Attempt._damped_step`'s answer when a kept tangent's full step is refused: a fresh
#: tangent at the iterate is due, no damping of the old direction.
_REFRESH = "refresh"


class _Attempt:
    """One Newton run from ``x0`` with one material tangent."""

    def __init__(self, problem, tol: NewtonTolerances, policy: NewtonPolicy, solver: DirectSolver,
                 tangent: str):
        self.problem, self.tol, self.policy, self.solver, self.tangent = problem, tol, policy, solver, tangent
        self.result = NewtonResult(x=None, converged=False, tangent=tangent)
        self.ref = 0.0
        self.J = None          # the factorised tangent
        self.contraction = np.inf   # ‖Δx̄‖/(λ‖Δx‖) of the last accepted step
        self.stale = False     # the factorised tangent is not the current iterate's (kept)
        self.refused_start = False   # a kept tangent was refused at the first step
        key = getattr(problem, "tangent_key", None)
        self.key = None if key is None else (key(), tangent)

    # -- the problem's evaluations, counted
    def _residual(self, x):
        self.result.evaluations += 1
        R, scale = self.problem.residual(x)
        self.ref = max(self.ref, float(scale))
        return R, float(np.linalg.norm(R))

    def _assemble(self, x):
        """``(R, ‖R‖, J)``: residual and tangent at ``x``, the tangent not yet factorised."""
        self.result.evaluations += 1
        R, J, scale = self.problem.linearize(x, self.tangent)
        self.ref = max(self.ref, float(scale))
        return R, float(np.linalg.norm(R)), J

    def _factorize(self, J):
        self.solver.factorize(J, tag=self.key)
        self.result.factorizations += 1
        self.J = J
        self.stale = False

    def _linearize(self, x):
        R, r, J = self._assemble(x)
        self._factorize(J)
        return R, r

    def _start(self, x):
        """Residual at ``x`` with a factorised tangent: the last one of this problem's
        ``tangent_key`` when the policy keeps tangents, else a fresh one."""
        if self.policy.reuse_contraction and self.key is not None and self.solver.tag == self.key:
            self.stale = True
            return self._residual(x)
        return self._linearize(x)

    def _tolerances(self, x):
        return (self.tol.rtol * self.ref + self.tol.atol,
                self.tol.du_rtol * self.problem.norm_reference(x) + self.tol.du_atol)

    def _converged(self, x, r, dx_next) -> bool:
        r_tol, du_tol = self._tolerances(x)
        if r <= r_tol and (dx_next <= du_tol or r <= 1e-2 * r_tol):
            return True
        # below the round-off of x the residual sits at its floor ‖J‖·ε·‖x‖
        return dx_next <= 8 * np.finfo(float).eps * self.problem.norm_reference(x)

    def _fail(self, x, why: str):
        res = self.result
        r_tol, _ = self._tolerances(x)
        res.x, res.converged = x, False
        res.reason = (f"{why} with the {self.tangent} tangent: residual norms {_norms(res.residual_norms)} vs "
                      f"tolerance {r_tol:.3e}, increment norms {_norms(res.increment_norms)}")
        return res

    def run(self, x0) -> NewtonResult:
        res = self.result
        x = np.array(x0, dtype=float)
        R, r = self._start(x)
        self.ref = max(self.ref, r)
        res.residual_norms.append(r)
        if not np.isfinite(r):
            return self._fail(x, "the residual is not finite")
        dx = self.solver.solve(-R)
        dx_norm = float(np.linalg.norm(dx))
        if self._converged(x, r, dx_norm):
            res.x, res.converged = x, True
            return res
        result = self._iterate(x, R, r, dx, dx_norm)
        if self.refused_start and self.solver.tag == self.key:
            # the last step's tangent did not serve this one's start: the next step starts fresh
            self.solver.tag = None
        return result

    def _iterate(self, x, R, r, dx, dx_norm) -> NewtonResult:
        """The iterations of :meth:`run` from the first correction ``dx`` at ``x``."""
        res, pol = self.result, self.policy
        first, lam, kinks = dx_norm, 1.0, 0
        best, stalled, slow = np.inf, 0, 0
        while res.iterations < self.tol.max_iter:
            kept = self.stale
            step = self._damped_step(x, dx, dx_norm, r, first, lam)
            if step is _REFRESH:   # the kept tangent no longer contracts: a fresh one here
                self.refused_start = self.refused_start or not res.iterations
                R, r = self._linearize(x)
                dx = self.solver.solve(-R)
                dx_norm, lam, self.contraction = float(np.linalg.norm(dx)), 1.0, np.inf
                if not res.iterations:
                    first = dx_norm
                continue
            if step is None:
                if kinks >= pol.kink_steps:
                    return self._fail(x, "no damping factor reduced the error")
                step = self._kink_step(x, dx, r)
                if step is None:
                    return self._fail(x, f"no damping factor down to {pol.lambda_min:g} reduced the error")
                kinks += 1
            x, R, r, lam_used, dx_next, fresh, J_next = step
            res.iterations += 1
            res.residual_norms.append(r)
            res.increment_norms.append(lam_used * dx_norm)
            next_norm = float(np.linalg.norm(dx_next))
            if self._converged(x, r, next_norm):
                res.x, res.converged = x, True
                return res
            if r < 0.5 * best:
                best, stalled, slow = r, 0, 0
            elif not kept:  # full steps that do not halve it cycle; damped ones descend, if slowly
                stalled, slow = stalled + (lam_used == 1.0), slow + 1
            limit = pol.stall_iterations
            if limit and (stalled >= limit or slow >= 3 * limit):
                return self._fail(x, f"the residual did not halve in {slow} iterations "
                                     f"({stalled} of them undamped)")
            self.contraction = next_norm / max(lam_used * dx_norm, 1e-300)
            if fresh:
                self.stale = False
            elif lam_used == 1.0 and self._keeps(x, r, next_norm):
                self.stale = True   # the simplified correction is the next correction
            else:  # the simplified correction served the test; now a new tangent
                if J_next is None:
                    R, r = self._linearize(x)
                else:
                    self._factorize(J_next)
                dx_next = self.solver.solve(-R)
            dx, dx_norm = dx_next, float(np.linalg.norm(dx_next))
            lam = min(1.0, 2.0 * lam_used)
        return self._fail(x, f"max_iter = {self.tol.max_iter} reached")

    def _keeps(self, x, r, next_norm) -> bool:
        """Whether the factorised tangent serves the next iteration too: the last full step
        contracted by ``reuse_contraction`` or more, and at that rate both tests are expected to
        pass with two iterations to spare (for a fresh tangent, should the rate not hold)."""
        rate = self.policy.reuse_contraction
        if not rate or self.contraction > rate:
            return False
        r_tol, du_tol = self._tolerances(x)
        per_iteration = np.log(max(self.contraction, 1e-12))
        needed = max(np.log(min(du_tol / next_norm, 1.0)), np.log(min(r_tol / max(r, 1e-300), 1.0)))
        return needed / per_iteration <= self.tol.max_iter - self.result.iterations - 2

    def _step_cap(self, x, dx) -> float:
        """The problem's safe fraction of ``dx`` (1 if it has no ``max_step``)."""
        max_step = getattr(self.problem, "max_step", None)
        return 1.0 if max_step is None else float(max_step(x, dx))

    def _expects_convergence(self, x, dx_norm) -> bool:
        """Whether the full step is expected to pass the increment test (its tangent unused)."""
        _, du_tol = self._tolerances(x)
        return self.contraction * dx_norm <= du_tol

    def _expects_reuse(self) -> bool:
        """Whether the next step is expected to keep the factorised tangent (its trial's own
        tangent unused): it is kept now, or the last step contracted enough (or was the first)."""
        rate = self.policy.reuse_contraction
        return bool(rate) and (self.stale or self.contraction <= rate or self.contraction == np.inf)

    def _damped_step(self, x, dx, dx_norm, r, first, lam):
        """Accepted ``(x, R, ‖R‖, λ, next correction, fresh tangent?, tangent to factorise)``,
        None, or :data:`_REFRESH` when a kept tangent's full step is refused.

        λ never exceeds the problem's safe fraction (:meth:`_step_cap`), nor does its floor."""
        pol = self.policy
        cap = self._step_cap(x, dx)
        if self.stale and cap < 1.0:
            return _REFRESH   # a kept tangent is not damped: a fresh one leads
        lam, floor = min(lam, cap), min(pol.lambda_min, cap)
        if floor <= 0.0:
            return None
        while lam >= floor:
            x_try = x + lam * dx
            J_try = None
            if (lam == 1.0 and pol.trial_tangent and not self._expects_reuse()
                    and not self._expects_convergence(x, dx_norm)):
                R_try, r_try, J_try = self._assemble(x_try)
            else:
                R_try, r_try = self._residual(x_try)
            if not np.isfinite(r_try):
                if self.stale:
                    return _REFRESH
                lam *= 0.25
                continue
            dxbar = self.solver.solve(-R_try)
            bar = float(np.linalg.norm(dxbar))
            if self.stale:   # a kept tangent's step stands only where it contracts as required
                if bar <= pol.reuse_contraction * dx_norm:
                    return x_try, R_try, r_try, lam, dxbar, False, None
                return _REFRESH
            if bar <= (1.0 - 0.25 * lam) * dx_norm or (r_try < r and bar < dx_norm):
                return x_try, R_try, r_try, lam, dxbar, False, J_try
            if lam == 1.0 and dx_norm <= pol.jump_ratio * first:
                # the tangent may have jumped (stick <-> slip): judge the trial with its own tangent
                J_here = self.J
                if J_try is None:
                    R_new, r_new = self._linearize(x_try)
                else:
                    R_new, r_new = R_try, r_try
                    self._factorize(J_try)
                dx_new = self.solver.solve(-R_new)
                if float(np.linalg.norm(dx_new)) <= 0.5 * dx_norm:
                    return x_try, R_new, r_new, lam, dx_new, True, None
                self._factorize(J_here)  # back to the tangent at x for the damped trials
            mu = dx_norm * lam * lam / (2.0 * max(float(np.linalg.norm(dxbar - (1.0 - lam) * dx)), 1e-300))
            lam = float(np.clip(mu, 0.1 * lam, 0.5 * lam))
        return None

    def _kink_step(self, x, dx, r):
        lam = min(self.policy.lambda_min, self._step_cap(x, dx))
        if lam <= 0.0:
            return None
        x_try = x + lam * dx
        R_try, r_try = self._residual(x_try)
        if not r_try <= self.policy.kink_growth * r:
            return None
        return x_try, R_try, r_try, lam, self.solver.solve(-R_try), False, None


def newton(problem: NonlinearProblem, x0, tolerances: NewtonTolerances | None = None,
           policy: NewtonPolicy | None = None, solver: DirectSolver | None = None) -> NewtonResult:
    """Solve ``problem`` from ``x0``; each tangent of ``policy.tangents`` in turn until one converges.

    Only the linear solver's own failures (:class:`drape.solvers.linear.LinearSolverError`)
    end an attempt early; any other exception is a defect and propagates.

    Returns
    -------
    NewtonResult
        The converged attempt, or the last one with ``reason`` naming every attempt's failure.
        Iterations, evaluations and factorizations count all attempts.
    """
    tolerances = NewtonTolerances() if tolerances is None else tolerances
    policy = NewtonPolicy() if policy is None else policy
    solver = DirectSolver() if solver is None else solver
    reasons, totals = [], np.zeros(3, dtype=int)
    result = None
    for tangent in policy.tangents:
        attempt = _Attempt(problem, tolerances, policy, solver, tangent)
        try:
            result = attempt.run(x0)
        except LinearSolverError as exc:
            result = attempt._fail(np.array(x0, dtype=float), f"linear solver failed ({exc})")
        totals += (result.iterations, result.evaluations, result.factorizations)
        result.fallback = tangent != policy.tangents[0]
        if result.converged:
            break
        reasons.append(result.reason)
    result.iterations, result.evaluations, result.factorizations = (int(v) for v in totals)
    if not result.converged:
        result.reason = "; ".join(reasons)
    return result
