"""KES-FB profile, driver and characteristic values."""
import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from constitutive.friction import FrictionParams, ParameterError
from constitutive.kes import kes_profile, kes_values, run_kes
from constitutive.law import BendingLaw

V, T = 50.0, 0.8


def boundaries(p):
    """Times where the regions meet, and the end (9 regions, 3 per phase; 8 without the last slow-down)."""
    out = []
    for i in range(3):
        t0, t1 = p.phase_times[i], p.phase_times[i + 1]
        out += [t0, t0 + T] + ([t1 - T] if (i < 2 or p.decelerate_at_end) else [])
    return np.array(out[1:] + [p.phase_times[-1]])


@pytest.mark.parametrize("decel", [True, False])
def test_profile_kappa_and_rate_continuous_acceleration_as_designed(decel):
    p = kes_profile(dt=0.01, rate=V, accel_time=T, k_max=240.0, k_min=-200.0, decelerate_at_end=decel)
    tb = boundaries(p)[:-1]
    assert tb.size == (8 if decel else 7)
    eps = 1e-7
    L = kes_profile(t=tb - eps, rate=V, accel_time=T, k_max=240.0, k_min=-200.0, decelerate_at_end=decel)
    R = kes_profile(t=tb + eps, rate=V, accel_time=T, k_max=240.0, k_min=-200.0, decelerate_at_end=decel)
    amax = 1.5 * V / T                                     # peak of 6 v τ(T−τ)/T³
    assert np.all(np.abs(R.kappa - L.kappa) <= 2 * eps * V * (1 + 1e-6))
    assert np.all(np.abs(R.kappa_dot - L.kappa_dot) <= 2 * eps * amax * (1 + 1e-6))
    # κ̈ vanishes at both ends of every region: within eps of a boundary |κ̈| <= 6 v eps / T² (its slope there)
    assert np.all(np.abs(L.kappa_ddot) <= 6 * V * eps / T**2 * 1.001)
    assert np.all(np.abs(R.kappa_ddot) <= 6 * V * eps / T**2 * 1.001)
    # κ̈ is a quadratic in t within each region (exactly: the cubic coefficient of a fit is 0)
    fine = kes_profile(dt=1e-3, rate=V, accel_time=T, k_max=240.0, k_min=-200.0, decelerate_at_end=decel)
    for r in np.unique(fine.region):
        sel = fine.region == r
        tt, aa = fine.t[sel], fine.kappa_ddot[sel]
        c = np.polyfit(tt - tt.mean(), aa, 3)
        assert abs(c[0]) * np.ptp(tt) ** 3 < 1e-8 * amax
        assert np.max(np.abs(np.polyval(c, tt - tt.mean()) - aa)) < 1e-9 * amax
    assert np.isclose(np.abs(fine.kappa_ddot).max(), amax, rtol=1e-5)
    # an independent check: integrating κ̈ gives κ̇ and integrating κ̇ gives κ (trapezoid error O(dt²))
    kd = cumulative_trapezoid(fine.kappa_ddot, fine.t, initial=0.0)
    k = cumulative_trapezoid(fine.kappa_dot, fine.t, initial=0.0)
    np.testing.assert_allclose(kd, fine.kappa_dot, atol=1e-4)
    np.testing.assert_allclose(k, fine.kappa, atol=1e-4)


def test_each_ramp_covers_half_v_T_and_turning_points_are_hit():
    p = kes_profile(dt=0.005, rate=V, accel_time=T, k_max=240.0, k_min=-200.0)
    tb = np.concatenate(([0.0], boundaries(p)))
    q = kes_profile(t=tb, rate=V, accel_time=T, k_max=240.0, k_min=-200.0)
    moves = np.diff(q.kappa)
    ramps = moves[[0, 2, 3, 5, 6, 8]]
    np.testing.assert_allclose(np.abs(ramps), V * T / 2, rtol=1e-12)
    np.testing.assert_allclose(q.kappa[[3, 6, 9]], [240.0, -200.0, 0.0], atol=1e-10)
    np.testing.assert_allclose(q.kappa_dot[[0, 3, 6, 9]], 0.0, atol=1e-12)
    np.testing.assert_allclose(np.abs(q.kappa_dot[[1, 2, 4, 5, 7, 8]]), V, rtol=1e-12)
    assert p.kappa.max() == pytest.approx(240.0, abs=1e-9) and p.kappa.min() == pytest.approx(-200.0, abs=1e-9)
    # duration: each phase |ΔK|/v + T
    assert p.t[-1] == pytest.approx((240 + 440 + 200) / V + 3 * T, rel=1e-12)
    assert list(np.unique(p.region)) == list(range(1, 10))


def test_no_deceleration_at_end_keeps_the_rate():
    p = kes_profile(dt=0.005, rate=V, accel_time=T, decelerate_at_end=False)
    assert p.kappa[-1] == pytest.approx(0.0, abs=1e-9) and p.kappa_dot[-1] == pytest.approx(V, rel=1e-12)
    assert p.region.max() == 8
    full = kes_profile(dt=0.005, rate=V, accel_time=T)
    assert full.t[-1] - p.t[-1] == pytest.approx(T / 2, rel=1e-9)
    same = p.t <= full.phase_times[2] + 1e-12
    np.testing.assert_allclose(p.kappa[same], full.kappa[: same.sum()], atol=1e-12)


@pytest.mark.parametrize("kw, msg", [
    (dict(rate=0.0), "rate = 0.0 breaks rate > 0"),
    (dict(accel_time=-1.0), "accel_time = -1.0 breaks accel_time > 0"),
    (dict(k_max=-1.0), "k_max = -1.0 breaks k_max > 0"),
    (dict(k_min=10.0), "k_min = 10.0 breaks k_min < 0"),
    (dict(k_max=20.0, accel_time=1.0), "k_max = 20 1/m breaks k_max >= v T = 50 1/m"),
    (dict(t=[0.0, 1e6]), "t must lie within"),
])
def test_bad_profile_arguments(kw, msg):
    with pytest.raises(ParameterError, match=msg):
        kes_profile(**kw)


ASYM = BendingLaw(k1=6e-5, k3=8e-9, d=5e-6, m=2e-6, k1_neg=4e-5, k3_neg=3e-9,
                  friction=FrictionParams(f1=3e-3, f2=2.5e-3, eps_f=60.0, eta=0.7))


@pytest.mark.parametrize("decel", [True, False])
def test_run_kes_equals_stepping_the_state(decel):
    p = kes_profile(dt=0.01, accel_time=T, decelerate_at_end=decel)
    loop = run_kes(ASYM, p)
    st = ASYM.new_state()
    ref, fr = [], []
    for k, kd, kdd in zip(p.kappa, p.kappa_dot, p.kappa_ddot):
        ref.append(ASYM.moment(k, kd, kdd, st))
        fr.append(st.friction_moment(k))
        st.commit(k)
    np.testing.assert_allclose(loop.moment, ref, rtol=0, atol=1e-15)
    np.testing.assert_allclose(loop.friction, fr, rtol=0, atol=1e-15)
    np.testing.assert_allclose(loop.viscous, ASYM.d * p.kappa_dot, rtol=1e-15)
    np.testing.assert_allclose(loop.inertial, ASYM.m * p.kappa_ddot, rtol=1e-15)
    np.testing.assert_allclose(loop.elastic + loop.friction + loop.viscous + loop.inertial, loop.moment, rtol=1e-15)


def test_run_kes_batches_parameter_sets():
    fp = FrictionParams(np.array([[3e-3], [4e-3]]), 2.5e-3, np.array([[60.0], [10.0]]), np.array([[0.7], [0.2]]))
    law = BendingLaw(k1=np.array([[6e-5], [7e-5]]), d=5e-6, friction=fp)
    p = kes_profile(dt=0.01)
    loop = run_kes(law, p)
    assert loop.moment.shape == (2, p.t.size)
    for i in range(2):
        one = BendingLaw(k1=float(law.k1[i, 0]), d=5e-6,
                         friction=FrictionParams(float(fp.f1[i, 0]), 2.5e-3, float(fp.eps_f[i, 0]), float(fp.eta[i, 0])))
        np.testing.assert_allclose(loop.moment[i], run_kes(one, p).moment, rtol=1e-14)


def test_kes_values_on_synthetic_linear_coulomb_loop():
    p = kes_profile(dt=0.002)
    k1, k1n, fc = 2.0e-4, 1.5e-4, 3.0e-3
    M = np.where(p.kappa >= 0, k1, k1n) * p.kappa + fc * np.sign(p.kappa_dot)
    v = kes_values(p.kappa, M)
    assert v.B_pos == pytest.approx(k1, rel=1e-9) and v.B_neg == pytest.approx(k1n, rel=1e-9)
    assert v.B == pytest.approx(0.5 * (k1 + k1n), rel=1e-9)
    assert v.HB2 == pytest.approx(2 * fc, rel=1e-9)
    B, HB2 = v
    assert (B, HB2) == (v.B, v.HB2)
    # a viscous law at constant rate: width 2 d v
    loop = run_kes(BendingLaw(k1=1e-4, d=2e-5), p)
    assert kes_values(loop.kappa, loop.moment).HB2 == pytest.approx(2 * 2e-5 * 50.0, rel=1e-9)


def test_kes_values_on_a_measured_like_loop():
    # irregular sampling, noise, starts mid-cycle: still recovers slope and width
    rng = np.random.default_rng(7)
    p = kes_profile(t=np.sort(rng.uniform(0, 21.5, 6000)))
    M = 1.2e-4 * p.kappa + 2e-3 * np.sign(p.kappa_dot) + rng.normal(0, 2e-5, p.t.size)
    v = kes_values(p.kappa, M)
    assert v.B == pytest.approx(1.2e-4, rel=0.01)
    assert v.HB2 == pytest.approx(4e-3, rel=0.02)


def test_kes_values_reports_missing_branch():
    k = np.linspace(0, 250, 100)
    with pytest.raises(ValueError, match="decreasing-κ branch"):
        kes_values(k, 1e-4 * k)
    assert np.isnan(kes_values(np.concatenate((k, k[::-1])), np.concatenate((k, k[::-1] - 1)) * 1e-4,
                               sides="positive").B_neg)
