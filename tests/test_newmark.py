"""Verification of the model-agnostic integrator drape/solvers/newmark.py.

References: the discrete energy identity of the average-acceleration rule (exact for
linear models), the closed-form harmonic oscillator (second-order accuracy), HHT-α's
numerical dissipation, and small stand-in models that fail on purpose to exercise
step cutting and the ConvergenceError messages.
"""
import numpy as np
import pytest
import scipy.sparse as sp
import skfem

from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial
from drape.solvers.linear import DirectSolver, pardiso_available
from drape.models.protocol import Evaluation
from drape.solvers.newmark import ConvergenceError, IntegratorInputError, NewmarkState, initial_state, newmark_step
from drape.solvers.static import quasi_static
from drape.solvers.time_stepping import integrate
from drape.models.plate import KirchhoffPlate

B, RHO, L, W = 2.0e-5, 0.2, 0.1, 0.02
OMEGA1 = 1.8751**2 / L**2 * np.sqrt(B / RHO)
PERIOD = 2 * np.pi / OMEGA1


def linear_cantilever(**kw):
    law = BendingLaw(k1=B, **kw.pop("law", {}))
    mat = FabricMaterial("test", RHO, None, law, law, twist_rigidity=B)
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, L, 9), np.linspace(0, W, 2))
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0)})
    return KirchhoffPlate(mesh, mat, supports={"left": "clamped"}, **kw)


def released(plate):
    """Deflect under the weight, then switch the load off: free vibration from rest."""
    u0 = quasi_static(plate, [1.0]).u
    plate.load_scale = 0.0
    return initial_state(plate, u0=u0)


class Oscillator:
    """Stand-in model: m ü + c u̇ + k u + k3 u³ = 0 (one dof), optionally failing on purpose."""

    ndofs, fixed_dofs, load_scale, symmetric_tangent = 1, np.zeros(0, dtype=int), 1.0, True

    def __init__(self, k=4 * np.pi**2, c=0.0, k3=0.0, fail=None):
        self.k, self.c, self.k3, self.fail = k, c, k3, fail
        self.committed = [0.0]

    def prescribed(self, t):
        return None

    def lifting(self, t):
        return None

    def force_scale(self, t):
        return 0.0

    def forces(self, u, v, t):
        """Non-inertial force ``c v + k u + k3 u³`` and its u-derivative."""
        return self.c * v + self.k * u + self.k3 * u**3, self.k + 3 * self.k3 * u[0] ** 2

    def evaluate(self, u, v, a, t, tangent=None, weights=None):
        force, k = self.forces(u, v, t)
        if self.fail is not None and self.fail(self, t):
            force = np.full(1, np.nan)
        if tangent is None:
            return Evaluation(a.copy(), force)
        return Evaluation(a.copy(), force, sp.csr_matrix([[k]]), sp.csr_matrix([[self.c]]),
                          sp.csr_matrix([[1.0]])).weighted(weights)

    def commit(self, u, v, a):
        self.committed.append(float(u[0]))


def energy(plate, s):
    return 0.5 * s.v @ (plate.M @ s.v) + 0.5 * s.u @ (plate.K0 @ s.u)


# --------------------------------------------------------------------------- accuracy, energy
def test_average_acceleration_conserves_energy():
    """Undamped frictionless linear plate: ½vᵀMv + ½uᵀKu constant to 1e-8 relative over 5 periods."""
    plate = linear_cantilever()
    s0 = released(plate)
    e0 = energy(plate, s0)
    errs = []
    integrate(plate, 5 * PERIOD, PERIOD / 20, s0, rtol=1e-12,
              on_step=lambda s, i: errs.append(abs(energy(plate, s) / e0 - 1)))
    assert len(errs) == 100
    assert max(errs) < 1e-8


def test_free_vibration_period_is_euler_bernoulli():
    """Released Argyris cantilever: the tip crosses zero with the period 2π/ω1 of Euler–Bernoulli
    (ω1 = 1.8751²/L² √(B/ρ_A)) within 1 % (Δt = T/100: trapezoidal elongation 0.3 %)."""
    law = BendingLaw(k1=B)
    mat = FabricMaterial("test", RHO, None, law, law, twist_rigidity=B)
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, L, 7), np.linspace(0, W, 2))
    plate = KirchhoffPlate(mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0)}), mat,
                           element="argyris", supports={"left": "clamped"})
    tip = np.flatnonzero(np.isclose(plate.mesh.p[0], L))
    rec = []
    integrate(plate, 3 * PERIOD, PERIOD / 100, released(plate),
              on_step=lambda s, i: rec.append((s.t, s.u[plate.vertex_dofs][tip].mean())))
    t, w = np.array(rec).T
    for sign in (1, -1):
        i = np.flatnonzero((sign * w[:-1] < 0) & (sign * w[1:] >= 0))
        crossings = t[i] - w[i] * (t[i + 1] - t[i]) / (w[i + 1] - w[i])
        assert len(crossings) >= 2
        np.testing.assert_allclose(np.diff(crossings), PERIOD, rtol=0.01)


def test_energy_balance_with_rayleigh_and_law_damping():
    """With C = αM + βK0 + d∫BBᵀ the booked damping work closes the balance to 1e-8."""
    plate = linear_cantilever(rayleigh=(2.0, 1e-4), law={"d": 1e-7})
    s0 = released(plate)
    e0 = energy(plate, s0)
    out = []
    integrate(plate, 2 * PERIOD, PERIOD / 20, s0, rtol=1e-12,
              on_step=lambda s, i: out.append((energy(plate, s), plate.damping_work)))
    balance = np.array([e + w for e, w in out])
    assert np.max(np.abs(balance / e0 - 1)) < 1e-8
    assert out[-1][1] > 0.1 * e0     # the damping really worked


def test_second_order_accuracy_and_hht_dissipation():
    """Harmonic oscillator, period 1: the trapezoidal rule's discrete solution is cos(ω̃ t) with
    ω̃ = (2/Δt) arctan(ωΔt/2) (to 1e-9), so the error at the zero crossing t = 1.25 falls 4× per
    halving of Δt; HHT-α (α = −0.1) loses energy from period to period (mildly at ωΔt = 0.3) while α = 0 keeps it."""
    errors = []
    omega = 2 * np.pi
    for dt in (0.025, 0.0125, 0.00625):
        model = Oscillator()
        s = integrate(model, 1.25, dt, NewmarkState(0.0, np.ones(1), np.zeros(1), -model.k * np.ones(1)),
                      rtol=1e-13)
        omega_h = 2 / dt * np.arctan(omega * dt / 2)
        assert abs(s.u[0] - np.cos(omega_h * 1.25)) < 1e-9
        errors.append(abs(s.u[0] - np.cos(omega * 1.25)))
    assert 3.9 < errors[0] / errors[1] < 4.1 and 3.9 < errors[1] / errors[2] < 4.1

    for alpha in (0.0, -0.1):
        model = Oscillator()
        e = []
        integrate(model, 3.0, 0.05, NewmarkState(0.0, np.ones(1), np.zeros(1), -model.k * np.ones(1)),
                  alpha_hht=alpha, rtol=1e-12,
                  on_step=lambda s, i: e.append(0.5 * s.v[0] ** 2 + 0.5 * model.k * s.u[0] ** 2))
        e = np.array(e) / (0.5 * model.k)
        if alpha == 0.0:
            assert np.max(np.abs(e - 1)) < 1e-10
        else:
            per_period = e[19::20]                      # energy at t = 1, 2, 3
            assert np.all(np.diff(per_period) < 0) and 0.95 < per_period[-1] < 0.995


def test_hht_high_frequency_spectral_radius():
    """HHT-α damps unresolved modes (ωΔt = 1e4) at the textbook rate ρ∞ = (1 + α)/(1 − α)
    per step (Hilber, Hughes & Taylor 1977); measured over steps 100–200 within 1 %
    (the double eigenvalue adds a factor (200/100)^(1/100) = 1.007)."""
    model = Oscillator(k=1e10)
    amp = []
    integrate(model, 20.0, 0.1, NewmarkState(0.0, np.ones(1), np.zeros(1), -model.k * np.ones(1)),
              alpha_hht=-0.1, rtol=1e-13,
              on_step=lambda s, i: amp.append(np.hypot(np.sqrt(model.k) * s.u[0], s.v[0])))
    rate = (amp[199] / amp[99]) ** (1 / 100)
    assert abs(rate / (0.9 / 1.1) - 1) < 0.01


def test_hht_on_plate_matches_newmark_for_zero_alpha():
    plate_a, plate_b = linear_cantilever(), linear_cantilever()
    sa, sb = released(plate_a), released(plate_b)
    for _ in range(5):
        sa, _ = newmark_step(plate_a, sa, PERIOD / 20, alpha_hht=0.0)
        sb, _ = newmark_step(plate_b, sb, PERIOD / 20, beta=0.25, gamma=0.5)
    np.testing.assert_allclose(sa.u, sb.u, rtol=1e-12, atol=1e-15)


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


# --------------------------------------------------------------------------- robustness
def _steps_with_long_steps_failing(window, t_end):
    """Integrate an oscillator with dt = 0.05, grow_after = 2, where steps longer than 0.013 s
    fail inside ``window``; the model and ``(t, dt, cuts, patience)`` of each converged step."""
    last = {"t": 0.0}

    def fail(model, t):
        return t - last["t"] > 0.013 and window[0] < t < window[1]

    model = Oscillator(fail=fail)
    infos = []

    def on_step(s, info):
        last["t"] = s.t
        infos.append((s.t, info.dt, info.cuts, info.control.patience))

    integrate(model, t_end, 0.05, NewmarkState(0.0, np.ones(1), np.zeros(1), -model.k * np.ones(1)),
              grow_after=2, on_step=on_step)
    return model, infos


def test_step_cutting_and_regrowth():
    """A model that cannot take steps longer than 0.013 s: dt = 0.05 is cut to 0.0125, then grows back."""
    model, infos = _steps_with_long_steps_failing((0.2, 0.4), 1.0)
    dts = np.array([d for _, d, *_ in infos])
    assert np.isclose(infos[-1][0], 1.0)
    assert dts.min() == pytest.approx(0.0125) and max(c for _, _, c, _ in infos) == 2
    assert dts[-3] == pytest.approx(0.05)          # grew back
    assert len(model.committed) == len(infos) + 1  # one commit per converged step, none for failures


def test_a_size_that_keeps_failing_is_retried_ever_later():
    """Where steps over 0.013 s fail for a long stretch (0.2 < t < 1.2 s), each failure doubles
    the successes the size must wait before it doubles (2, then 8, 16, 32 at most for
    grow_after = 2): 0.025 s is retried 3 times in the stretch, not after every second step
    (about 40 cuts); once it converges the wait is 2 again and the step grows back to dt."""
    _, infos = _steps_with_long_steps_failing((0.2, 1.2), 3.0)
    in_stretch = [(dt, c) for t, dt, c, _ in infos if 0.2 < t < 1.2]
    assert min(dt for dt, _ in in_stretch) == pytest.approx(0.0125)
    assert sum(c for _, c in in_stretch) == 5      # 0.05 and 0.025 at entry, then 0.025 thrice
    assert max(p for *_, p in infos) == 32
    assert infos[-1][1] == pytest.approx(0.05) and infos[-1][3] == 2    # grown back, patience too


def test_step_grows_beyond_dt_up_to_dt_max_and_follows_an_overdamped_creep():
    """Pseudo-transient continuation: an overdamped oscillator (slow root -1.01/s) creeping home.

    From dt = 0.01 the step doubles every 4 steps to dt_max = 0.5: 36 steps instead of 800, within
    1 % of the exact solution at t = 2 and 5 % at t = 4 (where 2 % of the motion is left).
    """
    k, c = 4 * np.pi**2, 40.0
    r1, r2 = np.roots([1.0, c, k])
    A = np.linalg.solve([[1.0, 1.0], [r1, r2]], [1.0, 0.0])
    exact = lambda t: A[0] * np.exp(r1 * t) + A[1] * np.exp(r2 * t)  # noqa: E731
    rec = []
    integrate(Oscillator(k=k, c=c), 8.0, 0.01, NewmarkState(0.0, np.ones(1), np.zeros(1), -k * np.ones(1)),
              dt_max=0.5, alpha_hht=-0.1, hit_times=[2.0, 4.0],
              on_step=lambda s, i: rec.append((s.t, i.dt, s.u[0], i.cuts)))
    t, dts, u, cuts = map(np.array, zip(*rec))
    assert len(rec) < 40 and dts.max() == pytest.approx(0.5) and np.all(cuts == 0)
    np.testing.assert_allclose(dts[:12], [0.01] * 4 + [0.02] * 4 + [0.04] * 4)
    assert u[np.isclose(t, 2.0)][0] == pytest.approx(exact(2.0), rel=0.01)
    assert u[np.isclose(t, 4.0)][0] == pytest.approx(exact(4.0), rel=0.05)
    with pytest.raises(IntegratorInputError, match="dt_max"):
        integrate(Oscillator(), 1.0, 0.1, dt_max=0.05)


def test_nonconvergence_raises_clear_error_after_converged_steps():
    model = Oscillator(fail=lambda m, t: t > 0.5)
    seen = []
    with pytest.raises(ConvergenceError) as err:
        integrate(model, 1.0, 0.1, NewmarkState(0.0, np.ones(1), np.zeros(1), -model.k * np.ones(1)),
                  max_cuts=2, on_step=lambda s, i: seen.append(s.t))
    msg = str(err.value)
    assert "t = 0.5" in msg and "dt/2^2" in msg and "residual norms" in msg
    np.testing.assert_allclose(seen, [0.1, 0.2, 0.3, 0.4, 0.5])   # everything before is delivered

    # a hard cubic spring in one huge step with one Newton iteration allowed
    with pytest.raises(ConvergenceError, match=r"after \d+ iterations \(max_iter=1,.*residual norms"):
        newmark_step(Oscillator(k3=1e6), NewmarkState(0.0, np.ones(1), np.zeros(1), np.zeros(1)), 0.5, max_iter=1)


def test_callback_can_stop_and_hit_times_are_exact():
    model = Oscillator()
    times = []
    s = integrate(model, 1.0, 0.03, NewmarkState(0.0, np.ones(1), np.zeros(1), -model.k * np.ones(1)),
                  hit_times=[0.1, 0.25], on_step=lambda s, i: times.append(s.t) or s.t >= 0.25)
    assert 0.1 in times and times[-1] == pytest.approx(0.25) and s.t == pytest.approx(0.25)


def test_quasi_static_bisects_failed_increments():
    """Load steps larger than 0.3 fail on purpose: the path 0 → 1 is reached by bisection."""
    state = {"lam": 0.0}

    class Spring(Oscillator):
        def forces(self, u, v, t):
            force, k = super().forces(u, v, t)
            if abs(self.load_scale - state["lam"]) > 0.3:
                force = np.full(1, np.nan)
            return force - self.load_scale, k

        def commit(self, u, v, a):
            state["lam"] = self.load_scale
            super().commit(u, v, a)

    model = Spring(k=2.0, k3=1.0)
    s = quasi_static(model, [1.0])
    assert 2 * s.u[0] + s.u[0] ** 3 == pytest.approx(1.0, rel=1e-9)
    assert len(model.committed) > 2   # intermediate equilibria were committed


@pytest.mark.parametrize("call, match", [
    (lambda m, s: newmark_step(m, s, -0.1), "dt"),
    (lambda m, s: newmark_step(m, s, 0.1, alpha_hht=0.5), "alpha_hht"),
    (lambda m, s: newmark_step(m, s, 0.1, gamma=0.4), "gamma"),
    (lambda m, s: newmark_step(m, s, 0.1, rtol=-1.0), "rtol"),
    (lambda m, s: integrate(m, 0.0, 0.1, s), "t_end"),
    (lambda m, s: quasi_static(m, [0.5, 1.0], times=[1.0]), "times"),
])
def test_bad_parameters_name_themselves(call, match):
    model = Oscillator()
    with pytest.raises(IntegratorInputError, match=match):
        call(model, NewmarkState(0.0, np.ones(1), np.zeros(1), np.zeros(1)))


def test_auto_predictor_does_not_repeat_a_failed_run_from_the_same_start():
    """Released at rest with a₀ = 0 (as a run starts), constant acceleration gives u₁ = u₀ again:
    after Newton fails from u₁ = u₀ it is not run a second time from the same point."""
    model = Oscillator(k3=50.0)
    state = NewmarkState(0.0, np.array([1.0]), np.array([0.0]), np.array([0.0]))
    with pytest.raises(ConvergenceError) as err:
        newmark_step(model, state, 0.2, max_iter=1, rtol=1e-14, du_rtol=1e-14)
    assert "acceleration predictor: not tried, the same start as displacement's" in str(err.value)
    with pytest.raises(ConvergenceError) as alone:   # the run from u₁ = u₀ alone
        newmark_step(model, state, 0.2, predictor="displacement", max_iter=1, rtol=1e-14, du_rtol=1e-14)
    counts = [(e.value.info.iterations, e.value.info.evaluations, e.value.info.factorizations)
              for e in (err, alone)]
    assert counts[0] == counts[1]
