"""drape.solvers.newton: convergence rate, damping, tangent fallback, failure reports, bad input.

References: the exact roots of small algebraic systems; Newton's quadratic convergence
(e_{k+1} ≤ C e_k²) near a simple root; the classical divergence of undamped Newton on arctan
from |x0| > 1.39.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from constitutive.friction import FrictionParams
from constitutive.law import BendingLaw
from drape.solvers.linear import DirectSolver
from drape.solvers.newton import NewtonPolicy, NewtonTolerances, newton


class Problem:
    """``R(x) = f(x) − b`` with a Jacobian per tangent name (and a count of the tangents used)."""

    def __init__(self, f, jac, b=0.0, jacobians=None):
        self.f, self.jac, self.b = f, jac, b
        self.jacobians = jacobians or {}
        self.used = []

    def residual(self, x):
        return self.f(x) - self.b, 1.0

    def linearize(self, x, tangent):
        self.used.append(tangent)
        J = self.jacobians.get(tangent, self.jac)(x)
        return self.f(x) - self.b, sp.csr_matrix(np.atleast_2d(J)), 1.0

    def norm_reference(self, x):
        return float(np.linalg.norm(x))


def test_quadratic_convergence_on_a_smooth_system():
    """x² + y² = 4, x y = 1: the errors of successive iterates square (ratio e_{k+1}/e_k² bounded)."""
    f = lambda x: np.array([x[0] ** 2 + x[1] ** 2 - 4.0, x[0] * x[1] - 1.0])  # noqa: E731
    jac = lambda x: np.array([[2 * x[0], 2 * x[1]], [x[1], x[0]]])  # noqa: E731
    exact = np.array([np.sqrt(2 + np.sqrt(3)), np.sqrt(2 - np.sqrt(3))])
    res = newton(Problem(f, jac), np.array([2.0, 0.3]), NewtonTolerances(rtol=1e-14, du_rtol=1e-14))
    # the root is confirmed by the simplified correction: no tangent is assembled there
    assert res.converged and res.factorizations == res.iterations
    np.testing.assert_allclose(res.x, exact, rtol=1e-13)
    errs = np.array(res.increment_norms)  # ≈ the error of the iterate before each step
    ratios = errs[1:] / errs[:-1] ** 2
    assert np.all(ratios[-3:] < 2.0)   # quadratic: bounded ratio of e_{k+1} to e_k²


def test_the_trial_tangent_saves_evaluations_and_changes_no_iterate():
    """Evaluating a full step's trial with its tangent gives the same iterates, bit for bit, as
    evaluating the residual and then the tangent apart, with fewer evaluations of the problem."""
    f = lambda x: np.array([x[0] ** 2 + x[1] ** 2 - 4.0, x[0] * x[1] - 1.0])  # noqa: E731
    jac = lambda x: np.array([[2 * x[0], 2 * x[1]], [x[1], x[0]]])  # noqa: E731
    tol = NewtonTolerances(rtol=1e-14, du_rtol=1e-14)
    apart = newton(Problem(f, jac), np.array([4.0, 0.1]), tol, NewtonPolicy(trial_tangent=False))
    problem = Problem(f, jac)
    fused = newton(problem, np.array([4.0, 0.1]), tol)
    assert fused.converged and apart.converged
    np.testing.assert_array_equal(fused.x, apart.x)
    assert fused.increment_norms == apart.increment_norms
    assert fused.evaluations < apart.evaluations
    # at most the last tangent goes unused (the step expected not to converge, and did)
    assert len(problem.used) <= fused.factorizations + 1


def test_damping_brings_arctan_home_where_plain_newton_diverges():
    """Undamped Newton on arctan(x) = 0 diverges from |x0| > 1.3917; the damped one converges."""
    f = lambda x: np.arctan(x)  # noqa: E731
    jac = lambda x: np.diag(1.0 / (1.0 + x ** 2))  # noqa: E731
    x = np.array([3.0])
    for _ in range(3):  # plain Newton: |x| grows
        x = x - f(x) / jac(x).diagonal()
    assert abs(x[0]) > 1e3
    res = newton(Problem(f, jac), np.array([3.0]), NewtonTolerances(rtol=1e-12, atol=1e-14, du_rtol=1e-12))
    assert res.converged and abs(res.x[0]) < 1e-10


def test_stick_tangent_fallback_and_the_reason_of_each_failure():
    """A tangent that points the wrong way fails; the policy's next tangent converges from x0."""
    f = lambda x: x ** 3 + x  # noqa: E731
    good = lambda x: np.diag(3 * x ** 2 + 1)  # noqa: E731
    wrong = lambda x: -np.diag(3 * x ** 2 + 1)  # noqa: E731
    prob = Problem(f, good, b=2.0, jacobians={"consistent": wrong, "stick": good})
    res = newton(prob, np.array([0.5]), NewtonTolerances(rtol=1e-12, du_rtol=1e-12),
                 NewtonPolicy(tangents=("consistent", "stick")))
    assert res.converged and res.tangent == "stick" and res.x[0] == pytest.approx(1.0, rel=1e-12)
    assert res.fallback
    assert prob.used[0] == "consistent" and "stick" in prob.used
    alone = newton(Problem(f, good, b=2.0, jacobians={"consistent": wrong}), np.array([0.5]),
                   NewtonTolerances(rtol=1e-12, du_rtol=1e-12))
    assert not alone.converged and "consistent tangent" in alone.reason and "residual norms" in alone.reason
    assert not alone.fallback


def test_newton_passes_the_stick_slip_kink_of_the_friction_law():
    """A friction point loaded from rest past its stick range: M(κ) = M_target is solved to
    round-off with the consistent tangent (kink at the committed curvature)."""
    law = BendingLaw(k1=1e-6, friction=FrictionParams(2e-6, 1e-6, 50.0, 0.5))
    state = law.new_state((1,))
    target = state.trial(np.array([0.08]))[0]

    f = lambda x: state.trial(x)[0]  # noqa: E731
    jac = lambda x: np.diag(state.trial(x)[1])  # noqa: E731
    res = newton(Problem(f, jac, b=target), np.zeros(1), NewtonTolerances(rtol=1e-12, atol=1e-20, du_rtol=1e-10))
    assert res.converged and res.x[0] == pytest.approx(0.08, rel=1e-8)


@pytest.mark.parametrize("kwargs, match", [
    (dict(rtol=-1.0), "rtol"), (dict(rtol=0.0, atol=0.0), "both be 0"), (dict(max_iter=0), "max_iter"),
])
def test_bad_tolerances_name_themselves(kwargs, match):
    with pytest.raises(ValueError, match=match):
        NewtonTolerances(**kwargs)


@pytest.mark.parametrize("kwargs, match", [
    (dict(tangents=()), "tangents"), (dict(lambda_min=0.0), "lambda_min"),
    (dict(stall_iterations=-1), "stall_iterations"),
])
def test_bad_policy_names_itself(kwargs, match):
    with pytest.raises(ValueError, match=match):
        NewtonPolicy(**kwargs)


def test_an_attempt_that_stalls_on_full_steps_gives_up():
    """R = x with a tangent 0.52 (the slope of a kink's other side, as at a friction point that
    switches): every full step is accepted (‖R‖ and the simplified correction fall), yet ‖R‖
    shrinks by only 0.923 per step. The attempt ends after ``stall_iterations`` = 8 full steps
    that do not halve ‖R‖ (9 iterations) with a reason that says so; without the rule it
    runs to max_iter."""
    problem = Problem(lambda x: x.copy(), lambda x: np.diag(0.52 * np.ones_like(x)))
    tol = NewtonTolerances(rtol=1e-10, du_rtol=1e-10)
    res = newton(problem, np.array([1.0]), tol)
    assert not res.converged and res.iterations == 9
    assert "did not halve in 8 iterations (8 of them undamped)" in res.reason
    r = np.array(res.residual_norms)
    np.testing.assert_allclose(r[1:] / r[:-1], 1 / 0.52 - 1, rtol=1e-12)   # every step full
    res = newton(problem, np.array([1.0]), tol, NewtonPolicy(stall_iterations=0))
    assert not res.converged and res.iterations == tol.max_iter and "max_iter" in res.reason


class KeyedProblem(Problem):
    """A :class:`Problem` that names its tangents (``tangent_key``), as a time step does by its size."""

    def __init__(self, f, jac, b=0.0, key="step"):
        super().__init__(f, jac, b)
        self.key = key

    def tangent_key(self):
        return self.key


def _mildly_nonlinear(n=40):
    """``A x + 0.05 x³ = b`` with A a tridiagonal stiffness: a tangent that changes little."""
    A = sp.diags([-1.0, 2.5, -1.0], [-1, 0, 1], shape=(n, n)).toarray()
    f = lambda x: A @ x + 0.05 * x ** 3  # noqa: E731
    jac = lambda x: A + np.diag(0.15 * x ** 2)  # noqa: E731
    return f, jac, np.linspace(0.5, 1.5, n)


def test_a_kept_tangent_converges_to_the_same_root_with_fewer_factorisations():
    """Modified Newton (the tangent kept while it contracts) meets the same tests at the same
    root, factorising fewer tangents than Newton in more, cheaper iterations."""
    f, jac, b = _mildly_nonlinear()
    tol = NewtonTolerances(rtol=1e-12, du_rtol=1e-12)
    plain = newton(Problem(f, jac, b), np.zeros(b.size), tol)
    kept = newton(Problem(f, jac, b), np.zeros(b.size), tol, NewtonPolicy(reuse_contraction=0.5))
    assert plain.converged and kept.converged
    np.testing.assert_allclose(kept.x, plain.x, rtol=1e-10)
    assert np.linalg.norm(f(kept.x) - b) <= 1e-12 * np.linalg.norm(b) * 10
    assert kept.factorizations < plain.factorizations
    assert kept.iterations >= plain.iterations


def test_the_next_problem_of_the_same_key_starts_from_the_kept_tangent():
    """A second solve whose problem has the same tangent key (a nearby load) starts from the
    factorisation the first left and converges without factorising; one with another key
    factorises its own."""
    f, jac, b = _mildly_nonlinear()
    solver = DirectSolver(symmetric=False, backend="superlu")
    tol = NewtonTolerances(rtol=1e-10, du_rtol=1e-10)
    policy = NewtonPolicy(reuse_contraction=0.5)
    first = newton(KeyedProblem(f, jac, b), np.zeros(b.size), tol, policy, solver)
    again = newton(KeyedProblem(f, jac, 1.01 * b), first.x, tol, policy, solver)
    other = newton(KeyedProblem(f, jac, 1.02 * b, key="other"), again.x, tol, policy, solver)
    assert first.converged and again.converged and other.converged
    assert again.factorizations == 0 and other.factorizations >= 1
    np.testing.assert_allclose(f(again.x), 1.01 * b, rtol=1e-9)


def test_a_kept_tangent_that_no_longer_contracts_is_replaced():
    """A factorisation kept under the same key but of a very different problem (the tangent
    changed by a factor of 50) is refused at the first step and replaced by a fresh tangent: the
    solve converges, as Newton does."""
    f, jac, b = _mildly_nonlinear()
    solver = DirectSolver(symmetric=False, backend="superlu")
    tol = NewtonTolerances(rtol=1e-10, du_rtol=1e-10)
    policy = NewtonPolicy(reuse_contraction=0.5)
    newton(KeyedProblem(f, jac, b), np.zeros(b.size), tol, policy, solver)
    stiff = lambda x: 50.0 * f(x)  # noqa: E731
    stiff_jac = lambda x: 50.0 * jac(x)  # noqa: E731
    res = newton(KeyedProblem(stiff, stiff_jac, 50.0 * b), np.zeros(b.size), tol, policy, solver)
    assert res.converged and res.factorizations >= 1
    np.testing.assert_allclose(f(res.x), b, rtol=1e-8)


def test_without_tangent_reuse_no_factorisation_is_taken_over():
    """The default policy factorises its own tangent even where the solver holds one of the same key."""
    f, jac, b = _mildly_nonlinear()
    solver = DirectSolver(symmetric=False, backend="superlu")
    tol = NewtonTolerances(rtol=1e-10, du_rtol=1e-10)
    newton(KeyedProblem(f, jac, b), np.zeros(b.size), tol, None, solver)
    res = newton(KeyedProblem(f, jac, 1.01 * b), np.zeros(b.size), tol, None, solver)
    assert res.converged and res.factorizations >= 1
    assert solver.tag == ("step", "consistent")
