"""Implicit Newmark / HHT-α time stepping and quasi-static load stepping for any structural model.

The integrator knows a model only through the interface of ARCHITECTURE.md::

    model.ndofs, model.fixed_dofs, model.prescribed(t) -> (dofs, values) | None,
    model.residual(u, v, a, t) -> (R, K, C, M),  model.commit(u, v, a),
    model.load_scale (float; multiplies the external loads, used by quasi_static)

optionally ``model.force_scale(t) -> float`` (a typical force norm such as
``|f_ext(t)|``; the relative residual test measures against it, so a step near
rest is not held to the round-off of nearly cancelling forces), and,
optionally, ``model.lifting(t) -> (u_p, v_p, a_p) | None``: a full-size
field carrying the imposed motion *with its exact rates*. The unknown is then
``u = u_p(t) + u_h`` with Newmark applied to ``u_h`` only (zero on imposed
dofs), so rate-dependent terms see the exact imposed velocity and
acceleration. Without a lifting the imposed dofs get Newmark-consistent rates.

Newmark (DESIGN §4)::

    a₁ = (u₁ − u₀ − Δt v₀)/(βΔt²) − (1/(2β) − 1) a₀,   v₁ = v₀ + Δt((1−γ) a₀ + γ a₁)

HHT-α (Hilber, Hughes & Taylor 1977; −⅓ ≤ α ≤ 0) weights the non-inertial
forces ``F = C v + f_int − f_ext``::

    M a₁ + (1 + α) F₁ − α F₀ = 0,   β = (1 − α)²/4,  γ = ½ − α

Newton uses the consistent tangent ``(1 + α)(K + γ/(βΔt) C) + M/(βΔt²)``.

Examples
--------
A single undamped oscillator (mass 1, stiffness 4π², period 1 s) keeps its
energy exactly with the average-acceleration rule:

>>> import numpy as np, scipy.sparse as sp
>>> class Oscillator:
...     ndofs, fixed_dofs, load_scale = 1, np.zeros(0, int), 1.0
...     k = 4 * np.pi**2
...     def prescribed(self, t): return None
...     def residual(self, u, v, a, t):
...         K, M = sp.csr_matrix([[self.k]]), sp.csr_matrix([[1.0]])
...         return M @ a + K @ u, K, sp.csr_matrix((1, 1)), M
...     def commit(self, u, v, a): pass
>>> model = Oscillator()
>>> s = integrate(model, 1.0, 0.01, NewmarkState(0.0, np.array([1.0]), np.zeros(1), np.array([-model.k])))
>>> e = lambda s: 0.5 * s.v[0]**2 + 0.5 * model.k * s.u[0]**2
>>> bool(abs(e(s) / (0.5 * model.k) - 1) < 1e-12)
True
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = [
    "StepControl",
    "NewmarkState",
    "StepInfo",
    "ConvergenceError",
    "IntegratorInputError",
    "LaggedLU",
    "SparseLU",
    "initial_state",
    "newmark_step",
    "integrate",
    "quasi_static",
]


class ConvergenceError(RuntimeError):
    """Newton did not converge; the message gives time, step size and the norm history."""

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
    predictors: tuple = ()         # predictor order: the first is tried first
    iterations: dict = field(default_factory=dict)   # Newton iterations each predictor last took


@dataclass
class StepInfo:
    """Newton record of one converged (or failed) step."""

    t: float
    dt: float
    iterations: int = 0
    residual_norms: list = field(default_factory=list)
    increment_norms: list = field(default_factory=list)
    step: int = 0
    cuts: int = 0
    control: StepControl | None = None


@dataclass(frozen=True)
class _Newton:
    rtol: float = 1e-9
    atol: float = 0.0
    du_rtol: float = 1e-9
    du_atol: float = 0.0
    max_iter: int = 25
    linear_solver: object = None

    def __post_init__(self):
        for name in ("rtol", "atol", "du_rtol", "du_atol"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise IntegratorInputError(f"{name} must be a finite number >= 0, got {value!r}")
        if self.rtol == 0 and self.atol == 0:
            raise IntegratorInputError("rtol and atol cannot both be 0 (the residual test could never pass)")
        if self.linear_solver is not None and not callable(self.linear_solver):
            raise IntegratorInputError(f"linear_solver must be a callable (A, b) -> x, got {self.linear_solver!r}")
        if int(self.max_iter) < 1:
            raise IntegratorInputError(f"max_iter must be >= 1, got {self.max_iter!r}")


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


def _imposed(model, t: float):
    """Lifting ``(u_p, v_p, a_p)`` (zeros without one), imposed dofs and ``u_h`` values on them."""
    n = model.ndofs
    pres = model.prescribed(t)
    if pres is None:
        pdofs, pvals = np.zeros(0, dtype=int), np.zeros(0)
    else:
        pdofs, pvals = np.asarray(pres[0], dtype=int), np.asarray(pres[1], dtype=float)
    lift = getattr(model, "lifting", None)
    lifted = lift(t) if callable(lift) else None
    if lifted is None:
        z = np.zeros(n)
        return (z, z, z), pdofs, pvals
    up, vp, ap = (np.asarray(x, dtype=float) for x in lifted)
    return (up, vp, ap), pdofs, pvals - up[pdofs]


def _force_scale(model, t: float) -> float:
    """Optional ``model.force_scale(t)``: a typical force norm (e.g. |f_ext|) for the residual test."""
    fs = getattr(model, "force_scale", None)
    return float(fs(t)) if callable(fs) else 0.0


def _free_dofs(model, pdofs) -> np.ndarray:
    constrained = np.union1d(np.asarray(model.fixed_dofs, dtype=int), pdofs)
    return np.setdiff1d(np.arange(model.ndofs), constrained)


class _Restriction:
    """``J[free][:, free]`` for a sequence of CSR matrices sharing one sparsity pattern.

    The index map from ``J.data`` to the submatrix data is computed once; a
    matrix with another pattern falls back to plain slicing.
    """

    def __init__(self, free):
        self.free = free
        self._pattern = None

    def __call__(self, J):
        J = sp.csr_matrix(J)
        if self._pattern is not None:
            indptr, indices = self._pattern
            if J.indptr.shape == indptr.shape and J.indices.shape == indices.shape and (
                    (J.indptr is indptr and J.indices is indices)
                    or (np.array_equal(J.indptr, indptr) and np.array_equal(J.indices, indices))):
                return sp.csr_matrix((J.data[self._map], self._sub.indices, self._sub.indptr), shape=self._sub.shape)
        probe = sp.csr_matrix((np.arange(1, J.nnz + 1, dtype=float), J.indices, J.indptr), shape=J.shape)
        sub = probe[self.free][:, self.free]
        sub.sort_indices()
        self._map = sub.data.astype(np.int64) - 1
        self._sub, self._pattern = sub, (J.indptr, J.indices)
        return sp.csr_matrix((J.data[self._map], sub.indices, sub.indptr), shape=sub.shape)


class LaggedLU:
    """Newton linear solver that reuses an earlier factorization (``linear_solver=LaggedLU()``).

    The effective tangent ``K + γ/(βΔt) C + M/(βΔt²)`` changes little from one
    Newton iteration or step to the next (only the nonlinear part of K moves),
    while its sparse LU costs 10–100× an assembly. The LU of an earlier tangent
    preconditions conjugate gradients on the current one; when CG needs more
    than ``max_krylov`` iterations (or the pattern/size changes) the current
    tangent is factorized afresh. Needs a symmetric positive definite tangent
    (plate, shell, friction and cubic laws; Rayleigh damping).

    Parameters
    ----------
    rtol : float
        Relative residual of the linear solve (inexact Newton; keep it well
        below the Newton ``rtol``).
    max_krylov : int
        CG iterations allowed before refactorizing.

    Attributes
    ----------
    factorizations, solves : int
        Counters (for benchmarks).

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> solver = LaggedLU()
    >>> A = sp.csr_matrix(np.diag([2.0, 3.0]))
    >>> solver(A, np.array([2.0, 3.0])), solver(1.01 * A, np.array([2.0, 3.0])).round(6)
    (array([1., 1.]), array([0.990099, 0.990099]))
    >>> solver.factorizations, solver.solves
    (1, 2)
    """

    def __init__(self, rtol: float = 1e-12, max_krylov: int = 40):
        self.rtol, self.max_krylov = float(rtol), int(max_krylov)
        self._lu = None
        self._shape = None
        self.factorizations = 0
        self.solves = 0

    def _factorize(self, A):
        self._lu = SparseLU(A)
        self._shape = A.shape
        self.factorizations += 1

    def __call__(self, A, b):
        self.solves += 1
        if self._lu is None or A.shape != self._shape:
            self._factorize(A)
            return self._lu.solve(b)
        precond = spla.LinearOperator(A.shape, matvec=self._lu.solve, dtype=float)
        x, info = spla.cg(A, b, x0=self._lu.solve(b), rtol=self.rtol, atol=0.0,
                          maxiter=self.max_krylov, M=precond)
        # trust only the true residual (CG updates it recursively; an indefinite tangent may fool it)
        if info != 0 or not np.all(np.isfinite(x)) or (
                np.linalg.norm(b - A @ x) > 100 * self.rtol * np.linalg.norm(b)):
            self._factorize(A)
            return self._lu.solve(b)
        return x


def _combine(terms):
    """``Σ c_i A_i`` for sparse matrices; adds the data arrays directly when the patterns agree."""
    (c0, A0), rest = terms[0], terms[1:]
    A0 = sp.csr_matrix(A0)
    same = all(
        sp.issparse(A) and A.format == "csr" and A.nnz == A0.nnz
        and (A.indices is A0.indices or np.array_equal(A.indices, A0.indices))
        and (A.indptr is A0.indptr or np.array_equal(A.indptr, A0.indptr))
        for _, A in rest
    )
    if same:
        data = c0 * A0.data
        for c, A in rest:
            if c != 0.0:
                data = data + c * A.data
        return sp.csr_matrix((data, A0.indices, A0.indptr), shape=A0.shape)
    out = c0 * A0
    for c, A in rest:
        if c != 0.0:
            out = out + c * A
    return sp.csr_matrix(out)


class SparseLU:
    """LU factors of a structurally symmetric FE matrix, with a safe fallback.

    Finite-element tangents are structurally symmetric and, in dynamics, dominated by
    ``M/(βΔt²)``: a minimum-degree ordering of ``A + Aᵀ`` factorized without pivoting
    (SuperLU's symmetric mode) fills 2.5× less than the default column ordering
    (COLAMD with partial pivoting) and factorizes about 3× faster on the Cusick
    shell (``benchmarks/bench_shell.py``). Should that factorization fail or give a
    poor residual (an indefinite or badly scaled matrix needs pivoting), the default
    SuperLU factorization is used instead.

    Examples
    --------
    >>> A = sp.csc_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    >>> lu = SparseLU(A)
    >>> lu.solve(np.array([5.0, 4.0])).round(12), lu.symmetric_mode
    (array([1., 1.]), True)
    """

    def __init__(self, A):
        self.A = sp.csc_matrix(A)
        self.symmetric_mode = True
        try:
            self._lu = spla.splu(self.A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                 options=dict(SymmetricMode=True))
            b = self.A @ np.ones(self.A.shape[0])
            r = self.A @ self._lu.solve(b) - b
            ok = bool(np.all(np.isfinite(r)) and np.linalg.norm(r) <= 1e-8 * np.linalg.norm(b))
        except RuntimeError:  # exactly singular pivot without pivoting
            ok = False
        if not ok:
            self.symmetric_mode = False
            self._lu = spla.splu(self.A)

    def solve(self, b):
        """``A⁻¹ b``."""
        return self._lu.solve(np.asarray(b, dtype=float))


def _solve(J, rhs, solver=None):
    if solver is not None:
        try:
            return np.asarray(solver(sp.csr_matrix(J), rhs), dtype=float).reshape(rhs.shape)
        except Exception:  # noqa: BLE001 - any solver failure is a failed Newton step
            return np.full_like(rhs, np.nan)
    try:
        return SparseLU(J).solve(rhs)
    except RuntimeError:  # singular for the pivoting factorization too
        return np.full_like(rhs, np.nan)


#: A line search that has halved the Newton update to 1/32 accepts it only if the residual has
#: grown less than this factor (mild growth: a friction point cycling between stick and slip).
_LINE_SEARCH_GROWTH = 10.0
#: The natural-monotonicity test alone never accepts a Newton update longer than
#: ``_UPDATE_GROWTH`` times the step's first one, nor one that raised |R| more than
#: ``_RESIDUAL_GROWTH``-fold: the tangent was near-singular there. (The shell tests accept
#: updates up to 54x the first and residual growth up to 2.8e3; a Cusick drape forming its
#: folds had a 280x update that raised |R| 2e8-fold and sent Newton off.)
_UPDATE_GROWTH = 100.0
_RESIDUAL_GROWTH = 1e5


def _newton(evaluate, x0, free, opts: _Newton, info: StepInfo, what: str, offset=0.0):
    """Newton on the free entries of ``x`` for ``evaluate(x) -> (R, J, scale)``.

    Converged when ``|R_free| <= rtol·ref + atol`` (``ref``: the largest of
    the first free residual and the force scale reported by ``evaluate``:
    all-dof residual incl. reactions, |M a|, ``model.force_scale``) and
    the last increment ``|dx| <= du_rtol·|x + offset| + du_atol`` (``offset``:
    the lifting, so the test measures against the total motion); the increment
    test is waived once the residual is 100× below its tolerance (a linear
    model converges in one solve). An update below the round-off of ``u``
    also ends the iteration: the residual cannot fall below ``‖J‖·ε·‖u‖``.

    A full Newton step is taken when it reduces the residual or when the
    next Newton update is at most half as long as this one (natural
    monotonicity test: a large-rotation shell's first step from the flat state
    raises |R| ~1000x through membrane strain, yet converges quadratically).
    Otherwise a backtracking line search halves the step until the residual
    falls (up to 5 times): the friction tangent jumps where a material point
    reverses (stick vs slip), and plain Newton can cycle between the two sides;
    there the next update is as long as the last and the test above fails.
    The last, 1/32 step is taken even if the residual grew mildly (at most
    ``_LINE_SEARCH_GROWTH``×); a larger growth fails the iteration, so the
    integrator cuts the time step (near a buckling point the tangent can send
    Newton far off, e.g. a Cusick drape forming its folds).
    """
    x = x0.copy()
    ref = 0.0
    last_du = du_next = None
    first_du = None
    restrict = _Restriction(free)
    R, J, scale = evaluate(x)
    r = float(np.linalg.norm(R[free]))
    for k in range(opts.max_iter + 1):
        info.residual_norms.append(r)
        if not np.isfinite(r):
            break
        ref = max(ref, scale, r if k == 0 else 0.0)
        tol = opts.rtol * ref + opts.atol
        du_tol = opts.du_rtol * float(np.linalg.norm(x + offset)) + opts.du_atol
        if r <= tol and (last_du is None or last_du <= du_tol or r <= 1e-2 * tol):
            info.iterations = k
            return x
        if last_du is not None and last_du <= 8 * np.finfo(float).eps * float(np.linalg.norm(x + offset)):
            # the update is below the round-off of u: the residual is at its floor ‖J‖·ε·‖u‖
            info.iterations = k
            return x
        if k == opts.max_iter:
            break
        if du_next is not None:
            du, du_next = du_next, None
        else:
            du = _solve(restrict(J), -R[free], opts.linear_solver) if free.size else np.zeros(0)
        if not np.all(np.isfinite(du)):
            info.increment_norms.append(float("nan"))
            break
        du_norm = float(np.linalg.norm(du))
        first_du = du_norm if first_du is None else first_du
        step = 1.0
        for _ in range(6):
            x_try = x.copy()
            x_try[free] += step * du
            R_try, J_try, scale_try = evaluate(x_try)
            r_try = float(np.linalg.norm(R_try[free]))
            if r_try <= (1.0 - 1e-4 * step) * r:
                break
            if step < 0.05:
                if not r_try <= _LINE_SEARCH_GROWTH * r:
                    # even 1/32 of the update raises |R| tenfold: the tangent does not point
                    # downhill (a near-singular tangent at a buckling point); give up so that
                    # the integrator retries with a shorter step instead of walking off
                    r_try = float("nan")
                break
            if step == 1.0 and np.isfinite(r_try):
                # natural monotonicity (Deuflhard): the full step is good when the next Newton
                # update shrinks, even if |R| grew (a stiff membrane turns the first bending step's
                # tiny stretch into a large force); its solve is reused, so acceptance costs nothing.
                # Not for an update far longer than the step's first one: a near-singular tangent
                # (a Cusick drape forming its folds) sends it far off, where the next update can
                # look small too.
                if du_norm <= _UPDATE_GROWTH * first_du and r_try <= _RESIDUAL_GROWTH * r:
                    cand = _solve(restrict(J_try), -R_try[free], opts.linear_solver)
                    if np.all(np.isfinite(cand)) and float(np.linalg.norm(cand)) <= 0.5 * du_norm:
                        du_next = cand
                        break
            step *= 0.5
        if not np.isfinite(r_try):
            info.residual_norms.append(r_try)
            break
        x, R, J, scale, r = x_try, R_try, J_try, scale_try, r_try
        last_du = step * du_norm
        info.increment_norms.append(last_du)
    info.iterations = len(info.increment_norms)
    fmt = lambda xs: "[" + ", ".join(f"{v:.3e}" for v in xs[-6:]) + "]"  # noqa: E731
    raise ConvergenceError(
        f"Newton did not converge {what} after {info.iterations} iterations "
        f"(max_iter={opts.max_iter}): residual norms {fmt(info.residual_norms)} "
        f"vs tolerance {opts.rtol:g}*{ref:.3e}+{opts.atol:g}; increment norms {fmt(info.increment_norms)}",
        info,
    )


def initial_state(model, u0=None, v0=None, t0: float = 0.0) -> NewmarkState:
    """Consistent start: ``a0`` from ``M a0 = −R(u0, v0, 0, t0)`` on the free dofs.

    Imposed dofs take their imposed values (and the lifting's rates if the model has one).
    If ``M`` is singular on the free dofs, ``a0 = 0`` there.
    """
    n = model.ndofs
    (up, vp, ap), pdofs, ph = _imposed(model, t0)
    u = np.zeros(n) if u0 is None else np.array(u0, dtype=float)
    v = np.zeros(n) if v0 is None else np.array(v0, dtype=float)
    if u.shape != (n,) or v.shape != (n,):
        raise IntegratorInputError(f"u0 and v0 must have shape ({n},)")
    u[pdofs] = up[pdofs] + ph
    v[pdofs] = vp[pdofs]
    a = ap.copy()
    free = _free_dofs(model, pdofs)
    R, _, _, M = model.residual(u, v, a, t0)
    if free.size:
        a_free = _solve(M[free][:, free], -R[free])
        if np.all(np.isfinite(a_free)):
            a[free] += a_free
    return NewmarkState(float(t0), u, v, a)


def newmark_step(model, state: NewmarkState, dt: float, beta=None, gamma=None, alpha_hht: float = 0.0,
                 *, predictor="auto", rtol=1e-9, atol=0.0, du_rtol=1e-9, du_atol=0.0, max_iter=25,
                 linear_solver=None):
    """One implicit step from ``state`` over ``dt``; does NOT commit the model.

    Parameters
    ----------
    model : structural model (ARCHITECTURE.md)
    state : NewmarkState
        Last converged state.
    dt : float
        Step size, > 0.
    beta, gamma : float, optional
        Newmark parameters; default ``β = (1−α)²/4``, ``γ = ½ − α`` (¼, ½ for α = 0).
    alpha_hht : float
        HHT-α parameter in [−⅓, 0]; 0 gives plain Newmark.
    predictor : {"auto", "acceleration", "displacement"}
        Start of the Newton iteration: the constant-acceleration extrapolation
        ``u₀ + Δt v₀ + Δt²/2 a₀`` (fewest iterations for smooth motion) or
        ``u₁ = u₀`` (robust with stiff friction: every point starts on its
        stick tangent and Newton approaches the saturating branch from
        below; on a shell dropped from rest it needs 4 iterations per step
        where the constant-acceleration one needs ~10, and on the Cusick drape
        the latter fails). "auto" tries the first and falls back to the second;
        :func:`integrate` keeps the one that worked (see there).
    rtol, atol, du_rtol, du_atol, max_iter
        Newton tolerances (residual and increment, relative and absolute).
    linear_solver : callable, optional
        ``(A, b) -> x`` for the Newton systems (CSR ``A`` on the free dofs),
        e.g. ``pypardiso.spsolve``; default SciPy's SuperLU (``spsolve``).

    Returns
    -------
    (NewmarkState, StepInfo)

    Raises
    ------
    ConvergenceError
        Newton failed; the state of the model is unchanged (nothing committed).
    """
    if not (np.isfinite(dt) and dt > 0):
        raise IntegratorInputError(f"dt must be > 0, got {dt!r}")
    beta, gamma, alpha = _newmark_coefficients(beta, gamma, alpha_hht)
    opts = _Newton(rtol, atol, du_rtol, du_atol, max_iter, linear_solver)
    if predictor not in ("auto", "displacement", "acceleration"):
        raise IntegratorInputError(f"predictor must be 'auto', 'acceleration' or 'displacement', got {predictor!r}")
    if predictor == "auto":
        kw = dict(rtol=rtol, atol=atol, du_rtol=du_rtol, du_atol=du_atol, max_iter=max_iter,
                  linear_solver=linear_solver)
        return _sticky_step(model, state, dt, beta, gamma, alpha_hht, ["acceleration", "displacement"], kw)
    t0, t1 = state.t, state.t + dt
    (up0, vp0, ap0), _, _ = _imposed(model, t0)
    (up1, vp1, ap1), pdofs, ph1 = _imposed(model, t1)
    free = _free_dofs(model, pdofs)
    uh0, vh0, ah0 = state.u - up0, state.v - vp0, state.a - ap0

    f0 = None
    if alpha != 0.0:
        f0 = state.force
        if f0 is None:
            R, _, _, M = model.residual(state.u, state.v, state.a, t0)
            f0 = R - M @ state.a

    def rates(uh):
        ah = (uh - uh0 - dt * vh0) / (beta * dt * dt) - (0.5 / beta - 1.0) * ah0
        vh = vh0 + dt * ((1.0 - gamma) * ah0 + gamma * ah)
        return vh, ah

    cache = {}
    fscale = _force_scale(model, t1)

    def evaluate(uh):
        vh, ah = rates(uh)
        u, v, a = up1 + uh, vp1 + vh, ap1 + ah
        R, K, C, M = model.residual(u, v, a, t1)
        Ma = M @ a
        if alpha != 0.0:
            force = R - Ma
            R = Ma + (1.0 + alpha) * force - alpha * f0
            cache["force"] = force
        J = _combine([(1.0 + alpha, K), ((1.0 + alpha) * gamma / (beta * dt), C), (1.0 / (beta * dt * dt), M)])
        scale = max(float(np.linalg.norm(R)), float(np.linalg.norm(Ma[free])), fscale)
        return R, J, scale

    if predictor == "displacement":
        # u₁ = u₀ (Δκ = 0): every friction point starts on its stick tangent, the stiffest one, and
        # Newton approaches the saturating (concave) friction branch from below instead of overshooting
        uh = uh0.copy()
    else:
        uh = uh0 + dt * vh0 + 0.5 * dt * dt * ah0  # constant-acceleration predictor
    uh[np.asarray(model.fixed_dofs, dtype=int)] = 0.0
    uh[pdofs] = ph1
    info = StepInfo(t=t1, dt=dt)
    uh = _newton(evaluate, uh, free, opts, info, f"at t = {t1:.6g} s (dt = {dt:.3g} s)", offset=up1)
    vh, ah = rates(uh)
    new = NewmarkState(t1, up1 + uh, vp1 + vh, ap1 + ah, cache.get("force"))
    return new, info


_SLOW_NEWTON = 6  # iterations: a predictor that needs more yields the front to the other one


def _sticky_step(model, state, dt, beta, gamma, alpha_hht, order, newton, counts=None):
    """:func:`newmark_step` with the predictors in ``order`` (a list, reordered in place).

    The predictor that converges stays in front; the other is tried only when
    it fails, or next step when it converged slowly (more than ``_SLOW_NEWTON``
    iterations and more than the other one needed when last used; ``counts``
    holds those numbers). A model on which one predictor never converges (the
    constant-acceleration one on a draping shell) then pays for it once, not
    every step.
    """
    counts = {} if counts is None else counts
    try:
        result = newmark_step(model, state, dt, beta, gamma, alpha_hht, predictor=order[0], **newton)
    except ConvergenceError as first:
        if len(order) == 1:
            raise
        try:
            result = newmark_step(model, state, dt, beta, gamma, alpha_hht, predictor=order[1], **newton)
        except ConvergenceError as second:
            raise ConvergenceError(f"{second} (the {order[0]} predictor failed too: {first})",
                                   second.info) from None
        order.reverse()
        counts[order[0]] = result[1].iterations
        return result
    n = counts[order[0]] = result[1].iterations
    if len(order) > 1 and n > _SLOW_NEWTON and counts.get(order[1], 0) < n:
        order.reverse()
    return result


def integrate(model, t_end: float, dt: float, state: NewmarkState | None = None, *, beta=None, gamma=None,
              alpha_hht: float = 0.0, hit_times=(), max_cuts: int = 6, grow_after: int = 4, on_step=None,
              progress: bool = False, dt_max: float | None = None, control: StepControl | None = None,
              **newton) -> NewmarkState:
    """Integrate from ``state`` (default: :func:`initial_state`) to ``t_end``.

    Each converged step is committed (``model.commit``) and passed to
    ``on_step(state, info)``; a callback returning ``True`` stops the run after
    that step. On a Newton failure the step is halved and retried from the last
    converged state, up to ``max_cuts`` halvings of ``dt``; after ``grow_after``
    consecutive successes the step doubles back towards ``dt``, and on beyond it
    up to ``dt_max`` when that is given (pseudo-transient continuation: a fabric
    creeping into equilibrium under constant loads needs ever fewer, longer steps,
    and as the step grows the update tends to Newton's on the static equilibrium). Steps are
    shortened to land exactly on ``hit_times`` (output times, turning points).
    Newton's linear systems use :class:`LaggedLU` unless ``linear_solver`` is
    given (one factorization serves many steps). With ``predictor="auto"``
    (default) each step starts from the predictor that converged last (first
    the constant-acceleration one) and tries the other only on failure, or
    first when the last one needed more than 6 Newton iterations. Each step's
    ``info.control`` (:class:`StepControl`) is where the step size and the predictor
    choice stand after it; ``control`` starts from there instead of from ``dt``.

    Raises
    ------
    ConvergenceError
        When a step fails at the smallest allowed size ``dt / 2**max_cuts``.
        Every step before it has been committed and passed to ``on_step``.
    """
    if not (np.isfinite(dt) and dt > 0):
        raise IntegratorInputError(f"dt must be > 0, got {dt!r}")
    if int(max_cuts) < 0:
        raise IntegratorInputError(f"max_cuts must be >= 0, got {max_cuts!r}")
    dt_max = dt if dt_max is None else float(dt_max)
    if not dt_max >= dt:
        raise IntegratorInputError(f"dt_max must be >= dt = {dt}, got {dt_max!r}")
    # negative levels are the doublings beyond dt
    min_level = -int(np.ceil(np.log2(dt_max / dt) - 1e-9))
    state = initial_state(model) if state is None else state
    if newton.get("linear_solver") is None:
        newton["linear_solver"] = LaggedLU()
    predictor = newton.pop("predictor", "auto")
    if predictor not in ("auto", "displacement", "acceleration"):
        raise IntegratorInputError(f"predictor must be 'auto', 'acceleration' or 'displacement', got {predictor!r}")
    order = ["acceleration", "displacement"] if predictor == "auto" else [predictor]
    counts = {}
    level, successes = 0, 0
    if control is not None:
        level = min(max(-int(np.ceil(np.log2(control.dt / dt) - 1e-9)), min_level), int(max_cuts))
        successes = int(control.successes)
        if predictor == "auto" and control.predictors:
            order, counts = list(control.predictors), dict(control.iterations)
    if not t_end > state.t:
        raise IntegratorInputError(f"t_end must be > the start time {state.t}, got {t_end!r}")
    eps = 1e-12 * max(abs(t_end), dt)
    hits = sorted(float(t) for t in hit_times if state.t + eps < t <= t_end - eps)
    step = 0
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=float(t_end - state.t), unit="s", unit_scale=False, desc="integrate")
    try:
        while state.t < t_end - eps:
            h = min(dt * 2.0**-level, dt_max)
            while hits and hits[0] <= state.t + eps:
                hits.pop(0)
            limit = min(t_end, hits[0]) if hits else t_end
            h_try = min(h, limit - state.t)
            if limit - (state.t + h_try) < eps:
                h_try = limit - state.t
            try:
                new, info = _sticky_step(model, state, h_try, beta, gamma, alpha_hht, order, newton, counts)
            except ConvergenceError as err:
                if level >= max_cuts:
                    raise ConvergenceError(
                        f"integration stopped at t = {state.t:.6g} s: the step failed at the smallest allowed "
                        f"size dt/2^{max_cuts} = {dt / 2**max_cuts:.3g} s. Last failure: {err}",
                        err.info,
                    ) from None
                level, successes = level + 1, 0
                continue
            model.commit(new.u, new.v, new.a)
            step += 1
            info.step, info.cuts = step, max(level, 0)
            if bar is not None:
                bar.update(new.t - state.t)
            state = new
            successes += 1
            if level > min_level and successes >= grow_after:
                level, successes = level - 1, 0
            info.control = StepControl(min(dt * 2.0**-level, dt_max), successes, tuple(order),
                                       dict(counts))
            if on_step is not None and on_step(state, info) is True:
                break
    finally:
        if bar is not None:
            bar.close()
    return state


def quasi_static(model, load_factors, times=None, state: NewmarkState | None = None, *, max_cuts: int = 6,
                 on_step=None, progress: bool = False, **newton) -> NewmarkState:
    """Equilibrium path ``f_int(u) = λ f_ext(t)`` (inertia and damping off).

    Parameters
    ----------
    model : structural model
        ``model.load_scale`` is set to each λ in turn.
    load_factors : sequence of float
        Load factors λ_i of the requested equilibrium states, in order.
    times : sequence of float, optional
        Time passed to ``residual``/``prescribed`` at each step (imposed
        motions, time-dependent loads); default: the load factors themselves.
    state : NewmarkState, optional
        Starting equilibrium (default: at rest, λ = 0, t = 0).
    max_cuts : int
        A failed increment is bisected (in λ and t) up to this depth.
    on_step : callable(state, info), optional
        Called after each requested λ_i is reached and committed; ``True`` stops.
    **newton
        Newton options as in :func:`newmark_step` (``linear_solver`` defaults to :class:`LaggedLU`).

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
    if newton.get("linear_solver") is None:
        newton["linear_solver"] = LaggedLU()
    opts = _Newton(**newton)
    n = model.ndofs
    zero = np.zeros(n)
    if state is None:
        state = NewmarkState(0.0, zero.copy(), zero.copy(), zero.copy())
        lam_prev = 0.0
    else:
        lam_prev = float(getattr(model, "load_scale", 1.0))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=lam.size, desc="quasi-static")

    def solve(lam_i, t_i, u_start):
        model.load_scale = lam_i
        (up, _, _), pdofs, ph = _imposed(model, t_i)
        free = _free_dofs(model, pdofs)
        uh = u_start - up
        uh[np.asarray(model.fixed_dofs, dtype=int)] = 0.0
        uh[pdofs] = ph

        fscale = _force_scale(model, t_i)

        def evaluate(x):
            R, K, _, _ = model.residual(up + x, zero, zero, t_i)
            return R, K, max(float(np.linalg.norm(R)), fscale)

        info = StepInfo(t=t_i, dt=t_i - state.t)
        x = _newton(evaluate, uh, free, opts, info, f"at load factor {lam_i:.6g} (t = {t_i:.6g})", offset=up)
        return up + x, info

    try:
        for i, (lam_i, t_i) in enumerate(zip(lam, ts)):
            pending = [(lam_i, t_i, 0)]
            while pending:
                lam_k, t_k, depth = pending[-1]
                try:
                    u, info = solve(lam_k, t_k, state.u)
                except ConvergenceError as err:
                    if depth >= max_cuts:
                        model.load_scale = lam_prev
                        raise ConvergenceError(
                            f"quasi-static path stopped at load factor {lam_prev:.6g} (t = {state.t:.6g}): "
                            f"the increment failed after {max_cuts} bisections. Last failure: {err}",
                            err.info,
                        ) from None
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
        if bar is not None:
            bar.close()
    return state
