"""Verification of the model-agnostic integrator drape/solvers/newmark.py: accuracy, energy
and step control.

References: the discrete energy identity of the average-acceleration rule (exact for
linear models), the closed-form harmonic oscillator (second-order accuracy), HHT-α's
numerical dissipation, and small stand-in models that fail on purpose to exercise
step cutting and the ConvergenceError messages. Tangents, predictors and factorisations
within a step: test_newmark_tangents.py.
"""
import numpy as np
import pytest
import skfem

from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial
from drape.solvers.newmark import ConvergenceError, IntegratorInputError, NewmarkState, newmark_step
from drape.solvers.static import quasi_static
from drape.solvers.time_stepping import integrate
from drape.models.plate import KirchhoffPlate

from newmark_models import B, L, PERIOD, RHO, W, Oscillator, linear_cantilever, released


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


@pytest.mark.slow
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
