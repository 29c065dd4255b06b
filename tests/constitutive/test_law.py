"""Bending law M = m κ̈ + d κ̇ + k1 κ + k3 κ³ + M_f: validation, tangent, energy balance."""
import numpy as np
import pytest

from constitutive.friction import FrictionParams, ParameterError
from constitutive.law import BendingLaw

FRIC = FrictionParams(f1=3.0e-3, f2=2.0e-3, eps_f=30.0, eta=0.4)
LAW = BendingLaw(k1=6e-5, k3=8e-9, d=5e-6, m=1e-8, friction=FRIC, k1_neg=4e-5, k3_neg=2e-9)


@pytest.mark.parametrize("kw, msg", [
    (dict(k1=-1.0), "k1 = -1 breaks k1 > 0"),
    (dict(k1=1.0, k3=-1.0), "k3 = -1 breaks k3 >= 0"),
    (dict(k1=1.0, d=-1e-3), "d = -0.001 breaks d >= 0"),
    (dict(k1=1.0, m=-1.0), "m = -1 breaks m >= 0"),
    (dict(k1=1.0, k1_neg=0.0), "k1_neg = 0 breaks k1_neg > 0"),
    (dict(k1=1.0, k3_neg=-2.0), "k3_neg = -2 breaks k3_neg >= 0"),
    (dict(k1=1.0, friction=(1.0, 0.5, 1.0, 0.5)), "friction ="),
])
def test_invalid_parameters_name_parameter_and_rule(kw, msg):
    with pytest.raises(ParameterError, match=msg.replace("(", r"\(").replace(")", r"\)")):
        BendingLaw(**kw)


def test_asymmetric_elastic_branches():
    k = np.array([-200.0, -1e-9, 0.0, 1e-9, 200.0])
    M, dM = LAW.elastic(k)
    np.testing.assert_allclose(M[[0, 4]], [-4e-5 * 200 - 2e-9 * 200**3, 6e-5 * 200 + 8e-9 * 200**3], rtol=1e-14)
    assert abs(M[1]) < 1e-13 and M[2] == 0 and abs(M[3]) < 1e-13      # continuous through κ = 0
    np.testing.assert_allclose(dM[[0, 4]], [4e-5 + 3 * 2e-9 * 200**2, 6e-5 + 3 * 8e-9 * 200**2], rtol=1e-14)
    sym = BendingLaw(k1=6e-5, k3=8e-9)
    np.testing.assert_allclose(sym.elastic(-k)[0], -sym.elastic(k)[0], rtol=0, atol=0)


def test_consistent_tangent_matches_finite_differences_away_from_reversals():
    rng = np.random.default_rng(5)
    n = 40
    st = LAW.new_state((n,))
    for _ in range(4):
        st.commit(st.kappa + rng.normal(0, 60.0, n))
    dk = rng.choice([-1, 1], n) * rng.uniform(1.0, 80.0, n)
    k = st.kappa + dk
    k[np.abs(k) < 1.0] += 2.0                  # also away from the κ = 0 kink of the asymmetric elastic law
    h = 1e-4
    _, dM = st.trial(k)
    fd = (st.trial(k + h)[0] - st.trial(k - h)[0]) / (2 * h)
    np.testing.assert_allclose(dM, fd, rtol=1e-6)


def cycle(K, n_cycles, n_per_cycle, omega):
    """κ = K sin(ωt) sampled so both turning points are samples."""
    t = np.arange(n_cycles * n_per_cycle + 1) * (2 * np.pi / omega) / n_per_cycle
    return t, K * np.sin(omega * t + 0.0), K * omega * np.cos(omega * t), -K * omega**2 * np.sin(omega * t)


def run_state(law, kappa, kdot, kddot):
    st = law.new_state()
    M, Mf = np.empty_like(kappa), np.empty_like(kappa)
    for i, (k, kd, kdd) in enumerate(zip(kappa, kdot, kddot)):
        M[i] = law.moment(k, kd, kdd, st)
        Mf[i] = st.friction_moment(k)
        st.commit(k)
    return M, Mf


def periodic_friction_dissipation(p, K):
    """Analytic work per cycle of the friction between ±K in the periodic state.

    One Dahl element cycling between ±K settles at y(±K) = ±tanh(K/a); the work
    per cycle is 4 f (K − a tanh(K/a)).  M_f = f1 y1 − f2 y2.
    """
    w = lambda f, a: 4 * f * (K - a * np.tanh(K / a))
    return w(p.f1, p.a1) - w(p.f2, p.a2)


def test_closed_cycle_loop_area_equals_dissipation_and_is_positive():
    # sinusoid between ±K from rest at 0: after 2 cycles the state is periodic to ~exp(-4 K/a2) = 2e-9
    K, omega, n = 150.0, 2 * np.pi / 20.0, 2000
    t, k, kd, kdd = cycle(K, 3, n, omega)
    M, Mf = run_state(LAW, k, kd, kdd)
    last = slice(2 * n, 3 * n + 1)
    area = np.sum(0.5 * (M[last][1:] + M[last][:-1]) * np.diff(k[last]))          # ∮ M dκ
    friction_area = np.sum(0.5 * (Mf[last][1:] + Mf[last][:-1]) * np.diff(k[last]))
    viscous = np.pi * LAW.d * K**2 * omega                                          # ∮ d κ̇ dκ (exact)
    expected_friction = periodic_friction_dissipation(FRIC, K)
    assert expected_friction > 0 and area > 0
    np.testing.assert_allclose(friction_area, expected_friction, rtol=1e-5)
    # elastic (a potential, also when asymmetric) and inertial (κ̇ periodic) parts add nothing
    np.testing.assert_allclose(area, expected_friction + viscous, rtol=1e-5)


def test_loop_area_with_d_zero_is_the_friction_dissipation():
    law = BendingLaw(k1=6e-5, k3=8e-9, friction=FRIC)
    K, omega, n = 100.0, 1.0, 2000
    t, k, kd, kdd = cycle(K, 3, n, omega)
    M, _ = run_state(law, k, kd, kdd)
    last = slice(2 * n, 3 * n + 1)
    area = np.sum(0.5 * (M[last][1:] + M[last][:-1]) * np.diff(k[last]))
    np.testing.assert_allclose(area, periodic_friction_dissipation(FRIC, K), rtol=1e-5)


def test_moment_helper_adds_inertial_and_viscous_terms():
    st = LAW.new_state((3,))
    k = np.array([10.0, -20.0, 30.0])
    M = LAW.moment(k, np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0]), st)
    Mt, _ = st.trial(k)
    np.testing.assert_allclose(M, Mt + LAW.d * np.array([1.0, 2.0, 3.0]) + LAW.m * np.array([4.0, 5.0, 6.0]))
    np.testing.assert_allclose(st.friction_moment(k) + LAW.elastic(k)[0], Mt, rtol=1e-14)
    np.testing.assert_array_equal(st.kappa, 0.0)               # helper did not commit


def test_state_shapes_and_copy():
    law = BendingLaw(k1=1e-4)
    st = law.new_state((3, 4))
    M, dM = st.trial(np.zeros((3, 4)))
    assert M.shape == dM.shape == (3, 4) and M.flags.writeable
    assert np.all(st.friction_moment(np.ones((3, 4))) == 0)
    fst = LAW.new_state((2,))
    fst.commit(np.array([50.0, -50.0]))
    c = fst.copy()
    c.commit(np.array([0.0, 0.0]))
    assert not np.allclose(fst.friction.y1, c.friction.y1)


def test_fabric2_weft_softens_and_the_nonnegative_friction_tangent_keeps_the_moment():
    """Table 4.13's Fabric 2 weft: the slow Dahl term overtakes the fast one within
    ~1e-3 cm⁻¹ of a reversal, so dM/dκ < 0 there. Independent check: the moment's own finite
    difference along a monotone load from rest."""
    from constitutive.material import load_material

    law = load_material("fabric2").weft
    kappa = np.linspace(0.0, 1.0, 20001)          # 1/m, i.e. up to 0.01 cm⁻¹
    st = law.new_state(kappa.shape)
    M, dM = st.trial(kappa)
    fd = np.gradient(M, kappa)
    assert np.allclose(dM[1:-1], fd[1:-1], rtol=1e-3, atol=1e-3 * law.k1)
    assert dM.min() < -50 * law.k1                # softening: −51 k1
    M2, dM2 = st.trial(kappa, friction_tangent="nonnegative")
    np.testing.assert_array_equal(M2, M)          # the moment is untouched
    elastic = law.k1 + 3 * law.k3 * kappa**2
    assert np.all(dM2 >= elastic * (1 - 1e-12)) and np.allclose(dM2[dM > elastic], dM[dM > elastic])
    with pytest.raises(ValueError, match="friction_tangent"):
        st.trial(kappa, friction_tangent="secant")


def test_commit_and_restore_give_kappa_a_new_array():
    """A holder of the state (the shell keeps the last trial it took) tells by the identity of
    ``kappa`` whether the committed state changed: commit and restore replace the array."""
    st = BendingLaw(k1=1.0, friction=FrictionParams(1.0, 0.5, 1.0, 0.5)).new_state((3,))
    before = st.kappa
    st.commit(np.zeros(3))
    assert st.kappa is not before
    saved, committed = st.state_dict(), st.kappa
    st.load_state_dict(saved)
    assert st.kappa is not committed and np.array_equal(st.kappa, committed)
