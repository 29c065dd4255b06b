"""Bliman–Sorine friction state: validation, exactness, tangent, passivity."""
import numpy as np
import pytest

from constitutive.friction import (FrictionParams, FrictionState, ParameterError, closed_form_from_rest,
                                   dahl_path, friction_path)
from constitutive.friction_switching import SwitchCounter

P = FrictionParams(f1=2.0e-3, f2=1.5e-3, eps_f=40.0, eta=0.3)


def random_path(rng, n=400, scale=150.0):
    """A path with many reversals and some repeated samples (zero increments)."""
    steps = rng.normal(0.0, scale / 20, n)
    steps[rng.random(n) < 0.05] = 0.0
    return np.concatenate(([0.0], np.cumsum(steps)))


@pytest.mark.parametrize("kw, name, rule", [
    (dict(f1=1.0, f2=1.0, eps_f=1.0, eta=0.5), "f1 = 1 with f2 = 1", "f1 > f2 >= 0"),
    (dict(f1=1.0, f2=-0.1, eps_f=1.0, eta=0.5), "f2 = -0.1", "f1 > f2 >= 0"),
    (dict(f1=1.0, f2=0.0, eps_f=0.0, eta=0.5), "eps_f = 0", "eps_f > 0"),
    (dict(f1=1.0, f2=0.0, eps_f=1.0, eta=1.2), "eta = 1.2", "0 < eta < 1 (dissipativity, thesis 3.19)"),
    (dict(f1=1.0, f2=0.0, eps_f=1.0, eta=0.0), "eta = 0", "0 < eta < 1"),
    (dict(f1=1.0, f2=0.0, eps_f=np.nan, eta=0.5), "eps_f", "finite"),
    (dict(f1=1.0, f2=0.0, eps_f=1e-300, eta=1e-10), "eps_f * eta = 1e-310", "the fast Dahl length a1"),
])
def test_invalid_parameters_name_parameter_and_rule(kw, name, rule):
    with pytest.raises(ParameterError) as err:
        FrictionParams(**kw)
    assert name in str(err.value) and rule in str(err.value)
    assert isinstance(err.value, ValueError)


def test_array_parameters_validated_elementwise_and_broadcast():
    with pytest.raises(ParameterError, match=r"eta = 1 \(at index \(2, 0\)"):
        FrictionParams(1.0, 0.5, 1.0, np.array([[0.2], [0.5], [1.0]]))
    p = FrictionParams(np.array([[1.0], [2.0]]), 0.5, np.array([[1.0], [3.0]]), 0.5)
    assert p.shape == (2, 1)
    FrictionState(p, (2, 7))
    with pytest.raises(ParameterError, match="do not broadcast"):
        FrictionState(p, (3,))


def test_state_form_equals_closed_form_3_17_on_monotone_path_from_rest():
    s = np.linspace(0.0, 300.0, 301)
    for sigma in (1.0, -1.0):
        Mf = friction_path(P, sigma * s)
        np.testing.assert_allclose(Mf, closed_form_from_rest(P, s, sigma), rtol=0, atol=1e-15)
    # and stepping the state object gives the same, whatever the step size
    st = FrictionState(P, ())
    for k in s[1:]:
        st.commit(k)
    np.testing.assert_allclose(st.trial(s[-1])[0], closed_form_from_rest(P, s[-1]), rtol=1e-13)
    big = FrictionState(P, ())
    big.commit(s[-1])
    np.testing.assert_allclose([big.y1, big.y2], [st.y1, st.y2], rtol=1e-13)


def test_closed_form_is_wrong_after_a_reversal_state_form_right():
    # 0 -> K -> 0: closed form 4.2 (s total, sign at start) vs stepping the ODE with a fine RK scheme
    K = 60.0
    kappa = np.concatenate((np.linspace(0, K, 601), np.linspace(K, 0, 601)[1:]))
    Mf = friction_path(P, kappa)
    s = np.concatenate(([0.0], np.cumsum(np.abs(np.diff(kappa)))))
    naive = np.sign(np.gradient(kappa)) * (P.f1 - P.f2) + (P.f2 * np.exp(-s / P.eps_f) - P.f1 * np.exp(-s / P.a1))
    # independent reference: explicit midpoint integration of dy/ds = (σ − y)/a with tiny steps
    y = np.zeros(2)
    a = np.array([P.a1, P.a2])
    h = 0.005
    for sigma, length in ((1.0, K), (-1.0, K)):
        for _ in range(int(round(length / h))):
            ym = y + 0.5 * h * (sigma - y) / a
            y = y + h * (sigma - ym) / a
    ref = P.f1 * y[0] - P.f2 * y[1]
    assert abs(Mf[-1] - ref) < 1e-8
    assert abs(naive[-1] - ref) > 1e-4


def test_dahl_path_equals_stepping_state_sample_by_sample():
    rng = np.random.default_rng(1)
    kappa = random_path(rng)
    a = np.array([[5.0], [40.0], [300.0]])
    y = dahl_path(kappa, a, y0=np.array([[0.3], [-0.2], [0.0]]))
    p = FrictionParams(f1=1.0, f2=0.5, eps_f=a[:, 0], eta=0.5)   # a2 = eps_f = a
    st = FrictionState(p, (3,))
    st.y2 = np.array([0.3, -0.2, 0.0])
    ys = [st.y2.copy()]
    for k in kappa[1:]:
        st.commit(np.full(3, k))
        ys.append(st.y2.copy())
    np.testing.assert_allclose(y, np.array(ys).T, rtol=0, atol=1e-12)
    # moment along the path: friction_path equals the state's trial moments
    M = friction_path(P, kappa)
    st = FrictionState(P, ())
    Ms = []
    for k in kappa:
        Ms.append(st.trial(k)[0])
        st.commit(k)
    np.testing.assert_allclose(M, Ms, rtol=0, atol=1e-15)


def test_trial_does_not_mutate_and_commit_accepts():
    st = FrictionState(P, (4,))
    st.commit(np.array([10.0, -5.0, 0.0, 30.0]))
    before = (st.kappa.copy(), st.y1.copy(), st.y2.copy())
    k = np.array([12.0, -20.0, 1.0, 29.0])
    first = st.trial(k)
    st.trial(k + 7.0)
    second = st.trial(k)
    for x, y in zip(before, (st.kappa, st.y1, st.y2)):
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(first[0], second[0])
    st.commit(k)
    np.testing.assert_array_equal(st.trial(k)[0], first[0])


def test_consistent_tangent_matches_finite_differences_away_from_reversals():
    rng = np.random.default_rng(2)
    n = 50
    st = FrictionState(P, (n,))
    for _ in range(5):                       # some history with reversals
        st.commit(st.kappa + rng.normal(0, 40.0, n))
    dk = rng.choice([-1, 1], n) * rng.uniform(0.5, 60.0, n)   # |Δκ| >= 0.5: away from the reversal
    k = st.kappa + dk
    h = 1e-4
    _, dM = st.trial(k)
    fd = (st.trial(k + h)[0] - st.trial(k - h)[0]) / (2 * h)
    np.testing.assert_allclose(dM, fd, rtol=1e-6, atol=1e-12)


def test_stick_tangent_is_larger_one_sided_derivative_per_state():
    # with y1, y2 of the same sign the stick tangent is the one-sided derivative towards −sign(y)
    st = FrictionState(P, ())
    st.commit(25.0)
    assert st.y1 > 0 and st.y2 > 0
    _, dM0 = st.trial(25.0)
    h = 1e-7
    back = (st.trial(25.0 - h)[0] - st.trial(25.0)[0]) / (-h)
    fwd = (st.trial(25.0 + h)[0] - st.trial(25.0)[0]) / h
    np.testing.assert_allclose(dM0, back, rtol=1e-5)
    assert back > fwd
    # at rest: f1/a1 − f2/a2 (the initial slope k_F+ of Eq. 3.15)
    np.testing.assert_allclose(FrictionState(P, ()).trial(0.0)[1], P.f1 / P.a1 - P.f2 / P.a2, rtol=1e-14)


def exact_work(f1, f2, a1, a2, kappa):
    """Cumulative work ∫ M_f dκ, integrated exactly over each monotone increment.

    Written with raw numbers (no validation) so it can also show a non-dissipative set.
    """
    dk = np.diff(kappa)
    sig, adk = np.sign(dk), np.abs(dk)
    work = np.zeros(dk.size)
    for f, a, sgn in ((f1, a1, 1.0), (f2, a2, -1.0)):
        y, w = 0.0, np.empty(dk.size)
        for i in range(dk.size):
            e = np.exp(-adk[i] / a)
            w[i] = f * (adk[i] + sig[i] * (y - sig[i]) * a * (1 - e))
            y = sig[i] + (y - sig[i]) * e
        work += sgn * w
    return np.cumsum(work)


def test_friction_never_adds_energy_on_random_paths():
    # 3.18–3.19 make the operator passive: the work done on it from rest is never negative
    rng = np.random.default_rng(3)
    for _ in range(30):
        f2 = rng.uniform(0, 1e-2)
        f1 = f2 * rng.uniform(1.0001, 3.0)
        eps, eta = rng.uniform(1.0, 200.0), rng.uniform(0.01, 0.999)
        kappa = random_path(rng, n=200)
        W = exact_work(f1, f2, eps * eta, eps, kappa)
        assert W.min() >= -1e-12 * f1 * 200
        # the exact work agrees with the trapezoid rule on the state's moments (refined path)
    fine = np.interp(np.linspace(0, 200, 20001), np.arange(201), kappa)
    p = FrictionParams(f1, f2, eps, eta)
    Mf = friction_path(p, fine)
    trap = np.sum(0.5 * (Mf[1:] + Mf[:-1]) * np.diff(fine))
    np.testing.assert_allclose(exact_work(f1, f2, eps * eta, eps, fine)[-1], trap, rtol=1e-4)
    # the check is not vacuous: f2 > f1 (breaking 3.18) does give negative work
    assert exact_work(1e-3, 2e-3, 10.0, 20.0, np.linspace(0, 100, 11)).min() < 0


def test_vectorised_over_points_and_parameter_sets():
    p = FrictionParams(np.array([[2e-3], [3e-3]]), 1e-3, np.array([[20.0], [50.0]]), np.array([[0.5], [0.9]]))
    kappa = np.linspace(0, 120, 13)
    M = friction_path(p, kappa)
    assert M.shape == (2, 13)
    for i in range(2):
        pi = FrictionParams(float(p.f1[i, 0]), 1e-3, float(p.eps_f[i, 0]), float(p.eta[i, 0]))
        np.testing.assert_allclose(M[i], friction_path(pi, kappa), rtol=1e-14)


def test_switch_counter_counts_sign_changes_between_distinct_trial_points():
    """A repeated trial point is counted once, and each new point counts the points whose Δκ
    changed sign since the previous one."""
    class Counted(FrictionState):   # the counter patches this class, not FrictionState
        pass

    counter = SwitchCounter(Counted)
    counter.install()
    state = Counted(FrictionParams(1.0, 0.0, 0.5, 0.5), shape=(3,))
    for kappa in ([0.0, 0.0, 0.0], [1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, -1.0]):
        state.trial(np.array(kappa))
    state.commit(np.array([1.0, 1.0, -1.0]))
    assert counter.take() == [2, 2]
    assert counter.take() == []
    assert FrictionState.trial is not Counted.trial
