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
from dataclasses import dataclass, field

import numpy as np

from drape.solvers.linear import DirectSolver, FreeRestriction, LinearSolverError, blas_threads
from drape.models.protocol import free_dofs
from drape.solvers.newton import NewtonPolicy, NewtonTolerances, newton

__all__ = [
    "StepControl",
    "NewmarkState",
    "StepInfo",
    "ConvergenceError",
    "IntegratorInputError",
    "default_solver",
    "initial_state",
    "newmark_step",
    "integrate",
    "quasi_static",
]

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
class StepControl:
    """Where :func:`integrate`'s step control stands after a converged step.

    Given back to :func:`integrate` (``control=``), the step sequence continues as if the
    integration had never stopped (a run resumed from its checkpoint).
    """

    dt: float                      # size of the next step, before landing on hit times
    successes: int = 0             # converged steps since the size last changed
    patience: int | None = None    # converged steps the size must wait before it doubles
    trial: bool = False            # the size was just doubled and has not converged yet


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
        return self.base[self.free]

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


class _StepSize:
    """Step size of :func:`integrate`: halved on failure; then doubled after ``patience``
    successes up to ``dt_max``, or set by the local error estimate.

    ``patience`` starts at ``grow_after`` and doubles with every failure (up to
    ``MAX_BACKOFF × grow_after``); once a doubled size has converged it is ``grow_after``
    again. Where a size keeps failing for a while, as where a limp fabric folds, the step
    stays short longer each time instead of being cut again after every few steps."""

    MAX_BACKOFF = 16

    def __init__(self, dt, dt_max, max_cuts, grow_after, error_tolerance, control):
        self.dt, self.dt_max, self.grow_after = dt, dt_max, int(grow_after)
        self.h_min = dt / 2.0 ** int(max_cuts)
        self.error_tolerance = error_tolerance
        self.h, self.successes, self.patience = dt, 0, self.grow_after
        self.trial = False          # the size was just doubled and has not converged yet
        if control is not None:
            self.h = float(np.clip(control.dt, self.h_min, dt_max))
            self.successes = int(control.successes)
            if control.patience is not None:
                self.patience = max(int(control.patience), self.grow_after)
            self.trial = bool(control.trial)

    def can_cut(self) -> bool:
        """Whether a failed step can still be halved."""
        return self.h > self.h_min * (1 + 1e-12)

    def failed(self) -> bool:
        """Halve after a Newton failure; False when already at the smallest size."""
        if not self.can_cut():
            return False
        self.h, self.successes = max(0.5 * self.h, self.h_min), 0
        self.patience = min(2 * self.patience, self.MAX_BACKOFF * self.grow_after)
        self.trial = False
        return True

    def error(self, old: NewmarkState, new: NewmarkState, beta: float) -> float:
        """Zienkiewicz-Xie estimate relative to the tolerance (NaN without one)."""
        if self.error_tolerance is None:
            return float("nan")
        h = new.t - old.t
        e = abs(beta - 1.0 / 6.0) * h * h * float(np.linalg.norm(new.a - old.a))
        ref = max(float(np.linalg.norm(new.u)), float(np.linalg.norm(old.u)), np.finfo(float).tiny)
        return e / (self.error_tolerance * ref)

    def accept(self, eta: float, h_taken: float, landed: bool) -> bool:
        """Next size after a converged step of size ``h_taken``; False: redo with the new size."""
        if self.error_tolerance is None:
            self.successes += 1
            if self.trial:
                self.patience, self.trial = self.grow_after, False
            if self.successes >= self.patience and self.h < self.dt_max:
                self.h, self.successes, self.trial = min(2.0 * self.h, self.dt_max), 0, True
            return True
        factor = float(np.clip(0.9 * max(eta, 1e-12) ** (-1.0 / 3.0), 0.5, 2.0))
        if eta > 1.0 and h_taken > self.h_min * (1 + 1e-12):
            self.h, self.successes = max(factor * h_taken, self.h_min), 0
            return False
        if not landed:  # a step shortened to land on a mark says nothing about the size
            self.h = float(np.clip(factor * h_taken, self.h_min, self.dt_max))
        self.successes += 1
        return True


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
    starts from there instead of from ``dt``.

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
    size = _StepSize(dt, dt_max, max_cuts, grow_after, error_tolerance, control)
    eps = 1e-12 * max(abs(t_end), dt)
    hits = sorted(float(t) for t in hit_times if state.t + eps < t <= t_end - eps)
    step, cuts, rejected = 0, 0, 0
    spent = []      # attempts at the coming step that failed or were refused: their counts join it
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=float(t_end - state.t), unit="s", unit_scale=False, desc="integrate")
    threads = blas_threads(1)
    try:
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
                new, info = _solve_step(problem, predictor, tol, policy, solver, fallbacks=not size.can_cut())
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
    finally:
        threads.unregister()
        if bar is not None:
            bar.close()
    return state


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
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=lam.size, desc="quasi-static")
    threads = blas_threads(1)

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

    try:
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
    finally:
        threads.unregister()
        if bar is not None:
            bar.close()
    return state
