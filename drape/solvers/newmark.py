"""One Newmark / HHT-α step: the state, the step's nonlinear problem, the predictors.

The method and the step's tangent are described in :mod:`drape.solvers.time_stepping`.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from drape.models.protocol import free_dofs
from drape.solvers.linear import DirectSolver, FreeRestriction, LinearSolverError
from drape.solvers.newton import NewtonPolicy, NewtonTolerances, newton
from drape.solvers.step_control import StepControl

__all__ = ['NewmarkState', 'StepInfo', 'ConvergenceError', 'IntegratorInputError', 'default_solver', 'initial_state', 'newmark_step']


PREDICTORS = ("auto", "acceleration", "velocity", "displacement")
#: "auto" starts from ``u₁ = u₀`` and falls back to constant acceleration. ``u₁ = u₀`` is the
#: return-mapping trial state (every friction point on its stick branch), and the one that
#: starts closer to balance in the Cusick drapes: as a fold forms, the constant-acceleration
#: extrapolation carries the high-frequency (membrane) content of ``a`` that HHT-α damps only
#: slowly (residual 200-fold larger). Ranking both starts by their residual first chose
#: ``u₁ = u₀`` at 111 of Fabric 1's 111 steps and at 69 of the limp polyester's 71, for two
#: force evaluations a step (BENCHMARKS.md); constant velocity failed more often than either.
AUTO_ORDER = ("displacement", "acceleration")
#: "auto" falls back to the other start only if its residual is at most this many times the
#: first's: one farther from balance than the start that failed does not converge either
#: (the Cusick drapes of BENCHMARKS.md: no step was saved by such a start, and each try cost a
#: full Newton run per tangent).
FALLBACK_RATIO = 100.0


class ConvergenceError(RuntimeError):
    """Newton did not converge; the message gives time, step size, tolerances and norm history."""

    def __init__(self, message: str, info: "StepInfo | None" = None):
        super().__init__(message)
        self.info = info


class IntegratorInputError(ValueError):
    """Invalid integrator parameter; the message names the parameter and the rule it breaks."""


@dataclass
class NewmarkState:
    """Time ``t`` and the full displacement, velocity and acceleration vectors."""

    t: float
    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    force: np.ndarray | None = field(default=None, repr=False)  # C v + f_int − f_ext at t (HHT cache)


@dataclass
class StepInfo:
    """Record of one converged (or failed) step.

    ``iterations``, ``evaluations`` (force evaluations, with or without tangent) and
    ``factorizations`` count every Newton attempt of the step, failed ones included (also
    those at the longer sizes cut or refused before it);
    ``cuts`` is the number of failed attempts at shorter or retried sizes, ``rejected``
    the number of sizes the error estimate refused; ``error`` the estimate of the step;
    ``rescued`` is True when it converged only from the fallback start or with a fallback
    tangent (:data:`AUTO_ORDER`, ``NewtonPolicy.tangents``).
    """

    t: float
    dt: float
    iterations: int = 0
    evaluations: int = 0
    factorizations: int = 0
    tangent: str = ""
    predictor: str = ""
    residual_norms: list = field(default_factory=list)
    increment_norms: list = field(default_factory=list)
    step: int = 0
    cuts: int = 0
    rejected: int = 0
    error: float = float("nan")
    rescued: bool = False
    control: StepControl | None = None

    def absorb(self, result) -> None:
        """Add a :class:`drape.solvers.newton.NewtonResult`'s counts and keep its norms and tangent."""
        self.add_counts(result)
        self.tangent = result.tangent
        self.residual_norms, self.increment_norms = result.residual_norms, result.increment_norms

    def add_counts(self, other) -> None:
        """Add the iterations, evaluations and factorizations of ``other`` (a Newton result, or
        the info of an attempt at this step that failed or was refused before)."""
        self.iterations += other.iterations
        self.evaluations += other.evaluations
        self.factorizations += other.factorizations


def _newmark_coefficients(beta, gamma, alpha_hht):
    alpha = float(alpha_hht)
    if not -1.0 / 3.0 <= alpha <= 0.0:
        raise IntegratorInputError(f"alpha_hht must lie in [-1/3, 0], got {alpha}")
    beta = 0.25 * (1.0 - alpha) ** 2 if beta is None else float(beta)
    gamma = 0.5 - alpha if gamma is None else float(gamma)
    if not beta > 0:
        raise IntegratorInputError(f"beta must be > 0, got {beta}")
    if not gamma >= 0.5:
        raise IntegratorInputError(f"gamma must be >= 1/2 (else the scheme amplifies), got {gamma}")
    return beta, gamma, alpha


def _tolerances(kw) -> NewtonTolerances:
    try:
        return NewtonTolerances(**kw)
    except (TypeError, ValueError) as exc:
        raise IntegratorInputError(str(exc)) from None


def default_solver(model) -> DirectSolver:
    """A :class:`DirectSolver` for the model's tangents: symmetric when they are."""
    return DirectSolver(symmetric=bool(model.symmetric_tangent))


class _Constraints:
    """Imposed motion at one time: lifting, free dofs and the start of ``u_h``."""

    def __init__(self, model, t: float):
        n = model.ndofs
        pres = model.prescribed(t)
        if pres is None:
            pdofs, pvals = np.zeros(0, dtype=int), np.zeros(0)
        else:
            pdofs, pvals = np.asarray(pres[0], dtype=int), np.asarray(pres[1], dtype=float)
        lifted = model.lifting(t)
        if lifted is None:
            z = np.zeros(n)
            self.lift = (z, z, z)
        else:
            self.lift = tuple(np.asarray(x, dtype=float) for x in lifted)
            pvals = pvals - self.lift[0][pdofs]
        self.fixed = np.asarray(model.fixed_dofs, dtype=int)
        self.pdofs, self.pvals = pdofs, pvals
        self.free = free_dofs(n, self.fixed, pdofs)

    def impose(self, uh):
        """``uh`` with the fixed dofs zero and the imposed ones at their values."""
        uh = np.array(uh, dtype=float)
        uh[self.fixed] = 0.0
        uh[self.pdofs] = self.pvals
        return uh


class _StepProblem:
    """One Newmark/HHT step as a :class:`drape.solvers.newton.NonlinearProblem` in the free ``u_h``."""

    def __init__(self, model, state: NewmarkState, dt: float, coefficients, restrict):
        self.model, self.dt = model, dt
        self.beta, self.gamma, self.alpha = coefficients
        self.t1 = state.t + dt
        c0, self.c1 = _Constraints(model, state.t), _Constraints(model, self.t1)
        self.t0, self.c0_lift = state.t, c0.lift[0]
        self.uh0, self.vh0, self.ah0 = (x - l for x, l in zip((state.u, state.v, state.a), c0.lift))
        self.u0_norm = float(np.linalg.norm(state.u))
        self.free = self.c1.free
        self.restrict = restrict
        self.scale = float(model.force_scale(self.t1))
        self.f0 = None
        if self.alpha != 0.0:
            self.f0 = state.force if state.force is not None else model.evaluate(
                state.u, state.v, state.a, state.t).force
        self._last = None

    def start(self, predictor: str):
        """Free part of the predictor: constant acceleration, constant velocity, or ``u₁ = u₀``
        (every friction point starts on its stick branch and approaches the saturating one
        from below)."""
        uh = self.uh0.copy()
        if predictor == "acceleration":
            uh += self.dt * self.vh0 + 0.5 * self.dt ** 2 * self.ah0
        elif predictor == "velocity":
            uh += self.dt * self.vh0
        self.base = self.c1.impose(uh)
        if predictor != "displacement" and self._unsafe_start():
            return self.start("displacement")   # the extrapolation passes through a body
        if predictor == "displacement" and self._unsafe_start():
            raise ConvergenceError(f"at t = {self.t1:.6g} s (dt = {self.dt:.3g} s): a body moves "
                                   "through the fabric's last position within the step", StepInfo(t=self.t1, dt=self.dt))
        return self.base[self.free]

    def _unsafe_start(self) -> bool:
        """The start is not reached collision-free from the last state (bodies moving from
        ``t₀`` to ``t₁``): :meth:`max_step` of the model below 1."""
        max_step = getattr(self.model, "max_step", None)
        if max_step is None:
            return False
        u1 = self.c1.lift[0] + self.base
        return max_step(self.uh0 + self.c0_lift, u1, self.t1, self.t0) < 1.0

    def max_step(self, x, dx) -> float:
        """The model's safe fraction of the Newton step ``x → x + dx`` (contact's CCD)."""
        max_step = getattr(self.model, "max_step", None)
        if max_step is None:
            return 1.0
        return max_step(self._fields(x)[0], self._fields(x + dx)[0], self.t1)

    def _fields(self, x):
        uh = self.base.copy()
        uh[self.free] = x
        ah = (uh - self.uh0 - self.dt * self.vh0) / (self.beta * self.dt ** 2) - (0.5 / self.beta - 1.0) * self.ah0
        vh = self.vh0 + self.dt * ((1.0 - self.gamma) * self.ah0 + self.gamma * ah)
        up, vp, ap = self.c1.lift
        return up + uh, vp + vh, ap + ah

    def _evaluate(self, x, tangent, weights=None):
        u, v, a = self._fields(x)
        ev = self.model.evaluate(u, v, a, self.t1, tangent, weights)
        R = ev.inertia + ev.force if self.alpha == 0.0 else (
            ev.inertia + (1.0 + self.alpha) * ev.force - self.alpha * self.f0)
        self._last = (x.copy(), ev.force)
        scale = max(float(np.linalg.norm(R)), float(np.linalg.norm(ev.inertia[self.free])), self.scale)
        return ev, R, scale

    def residual(self, x):
        _, R, scale = self._evaluate(x, None)
        return R[self.free], scale

    def linearize(self, x, tangent):
        b, g, dt, al = self.beta, self.gamma, self.dt, self.alpha
        ev, R, scale = self._evaluate(x, tangent, (1.0 + al, (1.0 + al) * g / (b * dt), 1.0 / (b * dt * dt)))
        return R[self.free], self.restrict(self.free, ev.J), scale

    def tangent_key(self):
        """What this step's tangents share with another step's: the weights of ``K``, ``C`` and
        ``M`` (the step size and the scheme's coefficients) and the free dofs."""
        return ("newmark", float(f"{self.dt:.12g}"), self.beta, self.gamma, self.alpha, self.free.size,
                hash(self.free.tobytes()))

    def norm_reference(self, x):
        # the step's round-off comes from u₀ and Δt v₀ as much as from u (which may pass zero)
        u, _, _ = self._fields(x)
        return max(float(np.linalg.norm(u)), self.u0_norm)

    def state(self, x) -> NewmarkState:
        u, v, a = self._fields(x)
        force = None
        if self.alpha != 0.0:
            if self._last is not None and np.array_equal(self._last[0], x):
                force = self._last[1]
            else:
                force = self.model.evaluate(u, v, a, self.t1).force
        return NewmarkState(self.t1, u, v, a, force)


class _Restrictions:
    """:class:`FreeRestriction` per free-dof set, upper triangles for a symmetric solver."""

    def __init__(self, solver: DirectSolver):
        self.upper = solver.symmetric
        self._cache = {}

    def __call__(self, free, J):
        """``J`` restricted to ``free``."""
        key = (free.size, hash(free.tobytes()))
        if key not in self._cache:
            self._cache = {key: FreeRestriction(free, upper=self.upper)}
        return self._cache[key](J)


def initial_state(model, u0=None, v0=None, t0: float = 0.0) -> NewmarkState:
    """Consistent start: ``a0`` from ``M a0 = −R(u0, v0, 0, t0)`` on the free dofs.

    Imposed dofs take their imposed values (and the lifting's rates if the model has one).
    If ``M`` is singular on the free dofs, ``a0 = 0`` there.
    """
    n = model.ndofs
    c = _Constraints(model, t0)
    up, vp, ap = c.lift
    u = np.zeros(n) if u0 is None else np.array(u0, dtype=float)
    v = np.zeros(n) if v0 is None else np.array(v0, dtype=float)
    if u.shape != (n,) or v.shape != (n,):
        raise IntegratorInputError(f"u0 and v0 must have shape ({n},)")
    u[c.pdofs] = up[c.pdofs] + c.pvals
    v[c.pdofs] = vp[c.pdofs]
    a = ap.copy()
    if c.free.size:
        ev = model.evaluate(u, v, a, t0, "consistent", (0.0, 0.0, 1.0))
        solver = DirectSolver(symmetric=True, backend="superlu")
        try:
            solver.factorize(FreeRestriction(c.free, upper=True)(ev.J))
            a[c.free] += solver.solve(-ev.residual[c.free])
        except LinearSolverError:
            pass  # massless free dofs: start from a = 0 there
    return NewmarkState(float(t0), u, v, a)


def _check_step_options(dt, predictor):
    if not (np.isfinite(dt) and dt > 0):
        raise IntegratorInputError(f"dt must be > 0, got {dt!r}")
    if predictor not in PREDICTORS:
        raise IntegratorInputError(f"predictor must be one of {PREDICTORS}, got {predictor!r}")


def _describe(where, tol: NewtonTolerances, result) -> str:
    return (f"Newton did not converge {where} after {result.iterations} iterations "
            f"(max_iter={tol.max_iter}, rtol={tol.rtol:g}, du_rtol={tol.du_rtol:g}): {result.reason}")


def newmark_step(model, state: NewmarkState, dt: float, beta=None, gamma=None, alpha_hht: float = 0.0,
                 *, predictor="auto", policy: NewtonPolicy | None = None,
                 linear_solver: DirectSolver | None = None, **tolerances):
    """One implicit step from ``state`` over ``dt``; does NOT commit the model.

    Parameters
    ----------
    model : drape.models.protocol.StructuralModel
    state : NewmarkState
        Last converged state.
    dt : float
        Step size, > 0.
    beta, gamma : float, optional
        Newmark parameters; default ``β = (1−α)²/4``, ``γ = ½ − α`` (¼, ½ for α = 0).
    alpha_hht : float
        HHT-α parameter in [−⅓, 0]; 0 gives plain Newmark.
    predictor : {"auto", "acceleration", "velocity", "displacement"}
        Start of Newton: ``u₀ + Δt v₀ + Δt²/2 a₀``, ``u₀ + Δt v₀`` or ``u₀`` (every
        friction point then starts on its stick branch); "auto" tries :data:`AUTO_ORDER`
        in turn, the second only near balance (:data:`FALLBACK_RATIO`).
    policy : drape.solvers.newton.NewtonPolicy, optional
        Damping and the material tangents to try (default: consistent).
    linear_solver : drape.solvers.linear.DirectSolver, optional
        Default :func:`default_solver`; pass one to keep its analysis across steps.
    **tolerances
        ``rtol, atol, du_rtol, du_atol, max_iter`` of :class:`drape.solvers.newton.NewtonTolerances`.

    Returns
    -------
    (NewmarkState, StepInfo)

    Raises
    ------
    ConvergenceError
        Newton failed; the model is unchanged (nothing committed).
    """
    _check_step_options(dt, predictor)
    coefficients = _newmark_coefficients(beta, gamma, alpha_hht)
    tol = _tolerances(tolerances)
    solver = default_solver(model) if linear_solver is None else linear_solver
    problem = _StepProblem(model, state, dt, coefficients, _Restrictions(solver))
    return _solve_step(problem, predictor, tol, policy, solver)


def _solve_step(problem: _StepProblem, predictor, tol, policy, solver, fallbacks: bool = True):
    """Newton from the chosen start(s), with the policy's tangents in turn. Without
    ``fallbacks`` only the policy's first tangent is tried: the fallback tangents (the friction
    law's stick tangent) converge slowly, and while the caller can still cut the step, half a
    step costs less than the long runs they add. The other start is always tried (when near
    balance): a full Newton run that lands where the first one stalls, e.g. at the residual's
    round-off floor, which a shorter step only raises (``M a`` grows as 1/Δt²)."""
    info = StepInfo(t=problem.t1, dt=problem.dt)
    if not fallbacks:
        policy = NewtonPolicy() if policy is None else policy
        policy = dataclasses.replace(policy, tangents=policy.tangents[:1])
    order = list(AUTO_ORDER) if predictor == "auto" else [predictor]
    reasons, near, first = [], np.inf, None
    for name in order:
        x0 = problem.start(name)
        if first is None:
            first = x0
        elif np.array_equal(x0, first):   # at rest (v₀ = a₀ = 0) both starts are u₀
            reasons.append(f"{name} predictor: not tried, the same start as {order[0]}'s")
            continue
        else:
            # the fallback start only near balance: one farther off than a failed start fails too
            size = float(np.linalg.norm(problem.residual(x0)[0]))
            info.evaluations += 1
            if not size <= FALLBACK_RATIO * near:
                reasons.append(f"{name} predictor: not tried, its residual {size:.3e} is more than "
                               f"{FALLBACK_RATIO:g} times the first start's")
                continue
        result = newton(problem, x0, tol, policy, solver)
        info.absorb(result)
        if result.converged:
            info.predictor = name
            info.rescued = name != order[0] or result.fallback
            return problem.state(result.x), info
        reasons.append(f"{name} predictor: {result.reason}")
        if name == order[0] and result.residual_norms and np.isfinite(result.residual_norms[0]):
            near = result.residual_norms[0]
    where = f"at t = {problem.t1:.6g} s (dt = {problem.dt:.3g} s)"
    result.reason = "; ".join(reasons)
    raise ConvergenceError(_describe(where, tol, result), info)
