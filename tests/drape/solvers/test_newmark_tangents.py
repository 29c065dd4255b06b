"""The Newmark step's tangents, predictors and factorisations (drape/solvers/newmark.py,
drape/solvers/linear.py): the symmetric and general factorisations, kept tangents, fresh
tangents on cut steps, the automatic predictor, fallbacks, and the direct solvers against
SciPy. References are paths computed another way (plain Newton, the other factorisation)
and SciPy's spsolve.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial
from drape.solvers.linear import DirectSolver, pardiso_available
from drape.solvers.newmark import ConvergenceError, NewmarkState, newmark_step
from drape.solvers.time_stepping import integrate

from newmark_models import PERIOD, Oscillator, linear_cantilever, released


BACKENDS = ["superlu"] + (["pardiso"] if pardiso_available() else [])


@pytest.mark.parametrize("backend", BACKENDS)
def test_symmetric_and_general_factorizations_give_the_same_path_with_one_analysis(backend):
    """Friction and cubic terms change the tangent every step: the symmetric (upper-triangle)
    and the general factorization follow the same path to 1e-9, each analysing the pattern once."""
    from constitutive.friction import FrictionParams

    runs = []
    for symmetric in (True, False):
        plate = linear_cantilever(law={"k3": 1e-8, "friction": FrictionParams(2e-4, 1e-4, 50.0, 0.5)})
        solver = DirectSolver(symmetric=symmetric, backend=backend)
        s = integrate(plate, PERIOD, PERIOD / 20, linear_solver=solver)
        runs.append((s.u, solver))
    np.testing.assert_allclose(runs[0][0], runs[1][0], rtol=1e-9, atol=1e-9 * np.abs(runs[1][0]).max())
    for _, solver in runs:
        assert solver.analyses == 1 and solver.factorizations >= 20 and solver.solves > solver.factorizations


def test_kept_tangents_follow_the_same_path_with_fewer_factorisations():
    """Modified Newton across steps (``NewtonPolicy.reuse_contraction``): a friction plate's
    free vibration takes the same path within Newton's tolerance, factorising under half as
    many tangents as Newton (a kept tangent serves several iterations, and the next step)."""
    from constitutive.friction import FrictionParams
    from drape.solvers.newton import NewtonPolicy

    runs = []
    for policy in (NewtonPolicy(), NewtonPolicy(reuse_contraction=0.5)):
        plate = linear_cantilever(law={"k3": 1e-8, "friction": FrictionParams(2e-4, 1e-4, 50.0, 0.5)})
        solver = DirectSolver(symmetric=True, backend="superlu")
        steps = []
        s = integrate(plate, PERIOD, PERIOD / 20, released(plate), linear_solver=solver, policy=policy,
                      rtol=1e-10, du_rtol=1e-10, on_step=lambda s, i: steps.append(i))
        runs.append((s.u, solver.factorizations, len(steps)))
    (u_newton, f_newton, n), (u_kept, f_kept, n_kept) = runs
    assert n == n_kept == 20
    np.testing.assert_allclose(u_kept, u_newton, rtol=1e-7, atol=1e-7 * np.abs(u_newton).max())
    assert f_kept < 0.5 * f_newton


class ShortStepsOnly:
    """A model whose steps longer than ``longest`` fail (a NaN force), wrapping another."""

    def __init__(self, model, longest):
        self.model, self.longest, self.t_last = model, longest, 0.0

    def __getattr__(self, name):
        return getattr(self.model, name)

    def evaluate(self, u, v, a, t, tangent=None, weights=None):
        ev = self.model.evaluate(u, v, a, t, tangent, weights)
        if t - self.t_last > self.longest * (1 + 1e-9):
            ev.force[:] = np.nan
        return ev

    def commit(self, u, v, a):
        self.model.commit(u, v, a)
        self.t_last = self.model.load_time


@pytest.mark.parametrize("longest, same", [(0.6, True), (2.0, False)])
def test_cut_steps_take_a_fresh_tangent_every_iteration(longest, same):
    """Kept tangents serve steps of ``dt`` only: where every step is cut below ``dt`` the run
    with ``reuse_contraction`` follows plain Newton's path to the bit; where steps of ``dt``
    converge, it does not (it keeps tangents there)."""
    from constitutive.friction import FrictionParams
    from drape.solvers.newton import NewtonPolicy

    dt = PERIOD / 20
    runs = []
    for policy in (NewtonPolicy(), NewtonPolicy(reuse_contraction=0.5)):
        plate = linear_cantilever(law={"k3": 1e-8, "friction": FrictionParams(2e-4, 1e-4, 50.0, 0.5)})
        state = released(plate)
        model = ShortStepsOnly(plate, longest * dt)
        steps = []
        s = integrate(model, PERIOD / 2, dt, state, policy=policy, rtol=1e-10, du_rtol=1e-10,
                      on_step=lambda s, i: steps.append(i.dt))
        runs.append((s.u, steps))
    assert all(h < dt for h in runs[0][1]) == same
    assert np.array_equal(runs[0][0], runs[1][0]) == same


def test_auto_predictor_falls_back_only_to_a_start_near_balance():
    """A Newton budget of one iteration fails every start of a stiff cubic oscillator; "auto"
    starts from u₁ = u₀ and tries constant acceleration after it only when that start's
    residual is at most 100 times u₁ = u₀'s. Swinging through u = 0 (v = 6, Δt = 0.01) the
    second start is far closer, released from u = 1 at rest (Δt = 0.2) comparable: both are
    tried. Released at Δt = 2 it overshoots to u ≈ −100, and is not tried."""
    from drape.solvers.newmark import FALLBACK_RATIO, _Restrictions, _StepProblem, _newmark_coefficients

    tried, ratio = {}, {}
    for label, (u, v, dt) in {"swing": (0.0, 6.0, 0.01), "release": (1.0, 0.0, 0.2),
                              "overshoot": (1.0, 0.0, 2.0)}.items():
        model = Oscillator(k3=50.0)
        a = -(model.k * u + model.k3 * u ** 3)
        state = NewmarkState(0.0, np.array([u]), np.array([v]), np.array([a]))
        problem = _StepProblem(model, state, dt, _newmark_coefficients(None, None, 0.0),
                               _Restrictions(DirectSolver()))
        size = {name: np.linalg.norm(problem.residual(problem.start(name))[0])
                for name in ("displacement", "acceleration")}
        ratio[label] = size["acceleration"] / size["displacement"]
        with pytest.raises(ConvergenceError) as err:
            newmark_step(model, state, dt, max_iter=1, rtol=1e-14, du_rtol=1e-14)
        message = str(err.value)
        tried[label] = [name for name in ("displacement", "acceleration")
                        if f"{name} predictor: not tried" not in message and f"{name} predictor" in message]
    assert ratio["swing"] < 1e-2 and 1e-2 < ratio["release"] < 1e2 and ratio["overshoot"] > 1e2
    assert FALLBACK_RATIO == 100.0
    assert tried == {"swing": ["displacement", "acceleration"], "release": ["displacement", "acceleration"],
                     "overshoot": ["displacement"]}


class WrongConsistentTangent(Oscillator):
    """The oscillator with a "consistent" tangent that makes the step's Jacobian negative (its
    corrections point uphill): only "stick" converges."""

    def evaluate(self, u, v, a, t, tangent=None, weights=None):
        ev = super().evaluate(u, v, a, t, tangent)
        if tangent == "consistent":
            ev.K = -1e7 * ev.K
        return ev.weighted(weights)


def test_a_step_converged_only_by_a_fallback_is_marked_rescued():
    """A step converged with the first start and tangent is not rescued; one that needed the
    stick tangent is, and the run profile counts it."""
    from types import SimpleNamespace

    from drape.solvers.newton import NewtonPolicy
    from drape.run.run_profile import RunProfile

    state = NewmarkState(0.0, np.array([0.3]), np.array([0.0]), np.array([-4 * np.pi**2 * 0.3]))
    policy = NewtonPolicy(tangents=("consistent", "stick"))
    _, plain = newmark_step(Oscillator(k3=5.0), state, 0.01, policy=policy)
    _, saved = newmark_step(WrongConsistentTangent(k3=5.0), state, 0.01, policy=policy)
    assert (plain.rescued, plain.tangent) == (False, "consistent")
    assert (saved.rescued, saved.tangent) == (True, "stick")
    profile = RunProfile()
    for info in (plain, saved, plain):
        profile.add(info)
    model = SimpleNamespace(seconds={"law": 0.0, "assembly": 0.0})
    summary = profile.summary(model, DirectSolver(), wall=1.0)
    assert summary["rescued_steps"] == 1 and summary["ldlt_factorizations"] == 0


def test_cut_before_fallbacks_and_every_attempt_counted():
    """A step whose attempts from both starts fail is cut, not retried with the stick tangent
    (the cut is the cheaper remedy while one is left), and the converged half step carries
    the failed attempts' counts: the steps' factorizations add up to the solver's own count."""
    from drape.solvers.newton import NewtonPolicy

    failed_calls = []

    def once(model, t):                     # the fifth step, 0.08 -> 0.10 s, fails
        failing = len(model.committed) == 5 and t > 0.1 - 1e-9
        failed_calls.extend([t] if failing else [])
        return failing

    model = Oscillator(k3=5.0, fail=once)
    solver = DirectSolver(symmetric=True)
    infos = []
    state = NewmarkState(0.0, np.array([0.3]), np.array([0.0]), np.array([-model.k * 0.3 - 5.0 * 0.027]))
    integrate(model, 0.12, 0.02, state, linear_solver=solver, policy=NewtonPolicy(tangents=("consistent", "stick")),
              on_step=lambda s, info: infos.append(info))
    cut = [info for info in infos if info.cuts]
    assert len(cut) == 1 and cut[0].t == pytest.approx(0.09) and cut[0].dt == pytest.approx(0.01)
    assert not any(info.rescued for info in infos)
    # a Newton attempt from u₁ = u₀, then the other start's residual: not finite, so not tried
    assert len(failed_calls) == 2
    assert sum(info.factorizations for info in infos) == solver.factorizations


def test_symmetric_viscous_tangent_gives_the_same_path():
    """A hanging strip with a viscous law (d/k1 = 1 s) in large rotation: Newton on the
    symmetric part of K (LDLᵀ) and on the exact, unsymmetric K (LU) reach the same states to
    the Newton tolerance. The symmetric part converges linearly, not quadratically: at this
    tight tolerance and a swing far faster than a drape's creep it takes 96 iterations
    against 78 (bounded here by 1.5 times)."""
    from skfem import MeshTri

    from drape.models.shell import KirchhoffLoveShell

    law = BendingLaw(k1=2e-6, d=2e-6)
    mat = FabricMaterial("viscous", 0.2, None, law, law, twist_rigidity=2e-6)
    mesh = MeshTri.init_tensor(np.linspace(0, 0.03, 5), np.linspace(0, 0.01, 2))
    mesh = mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9})
    runs = {}
    for mode in ("full", "symmetric"):
        shell = KirchhoffLoveShell(mesh, mat, rayleigh=(5.0, 0.0), viscous_tangent=mode,
                                   gravity=lambda t: min(t / 0.05, 1.0))
        iterations = []
        s = integrate(shell, 0.2, 0.01, rtol=1e-10, du_rtol=1e-10, alpha_hht=-0.1,
                      on_step=lambda st, info: iterations.append(info.iterations))
        runs[mode] = (s.u, sum(iterations), shell.symmetric_tangent)
    (u_full, it_full, sym_full), (u_sym, it_sym, sym_sym) = runs["full"], runs["symmetric"]
    assert sym_sym and not sym_full
    assert np.abs(u_sym).max() > 0.1 * 0.03        # a large deflection, not a linear problem
    np.testing.assert_allclose(u_sym, u_full, rtol=0, atol=1e-7 * np.abs(u_full).max())
    assert it_sym <= 1.5 * it_full


@pytest.mark.parametrize("backend", BACKENDS)
def test_direct_solver_on_a_shell_tangent_and_an_indefinite_matrix(backend):
    """The Newmark tangent of the large-rotation shell and a symmetric indefinite matrix
    (zero diagonal: no factorization without pivoting exists) against SciPy's spsolve."""
    import scipy.sparse.linalg as spla
    from skfem import MeshTri

    from drape.solvers.linear import FreeRestriction
    from drape.models.shell import ElasticMaterial, KirchhoffLoveShell

    mesh = MeshTri.init_tensor(np.linspace(0, 0.1, 7), np.linspace(0, 0.05, 4))
    mesh = mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9})
    shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-6, membrane=1e4, areal_mass=0.2))
    u = np.zeros(shell.ndofs)
    u[2::3] = 1e-3 * np.random.default_rng(0).standard_normal(shell.basis.N)
    u[shell.fixed_dofs] = 0.0
    ev = shell.evaluate(u, 0 * u, 0 * u, 0.0, "consistent")
    free = np.setdiff1d(np.arange(shell.ndofs), shell.fixed_dofs)
    J = (ev.K + 200.0 * ev.C + 3.3e4 * ev.M).tocsr()
    b = np.random.default_rng(1).standard_normal(free.size)
    ref = spla.spsolve(sp.csc_matrix(J[free][:, free]), b)
    solver = DirectSolver(symmetric=True, backend=backend)
    restrict = FreeRestriction(free, upper=True)
    solver.factorize(restrict(J))
    np.testing.assert_allclose(solver.solve(b), ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())
    # the restriction keeps the upper triangle of J's free block
    expected = sp.triu(J[free][:, free], format="csr")
    assert abs(restrict(J) - expected).max() == 0.0
    P = sp.csr_matrix(np.array([[0.0, 2.0, 0.0], [2.0, 0.0, 1.0], [0.0, 1.0, 3.0]]))
    for symmetric in (True, False):
        solver = DirectSolver(symmetric=symmetric, backend=backend)
        solver.factorize(P)
        np.testing.assert_allclose(solver.solve(P @ np.ones(3)), np.ones(3), rtol=1e-12)


@pytest.mark.skipif(not pardiso_available(), reason="MKL PARDISO not available")
def test_pardiso_factorises_by_cholesky_until_a_matrix_is_indefinite():
    """Positive definite matrices take Cholesky; an indefinite one (two negative eigenvalues)
    makes Cholesky stop at a negative pivot and is factorised by LDLᵀ, as are the next
    RETRY_AFTER; then Cholesky is tried again. Every solve matches SciPy's spsolve."""
    import scipy.sparse.linalg as spla

    from drape.solvers.linear import _PardisoSymmetric

    n = 400
    lap = sp.diags([-np.ones(n - 1), 2.5 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    shift = np.zeros(n)
    shift[[100, 300]] = -3.0
    definite, indefinite = lap, (lap + sp.diags(shift)).tocsr()
    assert np.sum(np.linalg.eigvalsh(indefinite.toarray()) < 0) == 2
    solver = DirectSolver(symmetric=True, backend="pardiso")
    retry = _PardisoSymmetric.RETRY_AFTER
    b = np.random.default_rng(0).standard_normal(n)
    by_ldlt = []
    for A in [definite, indefinite] + [definite] * 10:
        before = solver.ldlt_factorizations
        solver.factorize(A)
        by_ldlt.append(solver.ldlt_factorizations > before)
        np.testing.assert_allclose(solver.solve(b), spla.spsolve(A.tocsc(), b), rtol=1e-10)
    assert by_ldlt == [False] + [True] * (retry + 1) + [False] * (11 - retry - 1)
    assert solver.analyses == 1
