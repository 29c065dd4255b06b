"""Shaken supports ([load.agitation]): the burst, its rules, and the cantilever it shakes
against the same cantilever computed in the fixed (inertial) frame."""
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid, quad
from scipy.linalg import lu_factor, lu_solve

from constitutive.units import G0
from drape.case.build import build
from drape.case.case import CaseError, parse_case
from drape.case.loads import Agitation
from drape.solvers.newmark import initial_state
from drape.solvers.time_stepping import integrate

LENGTH, A_G, FREQ, CYCLES = 0.05, 0.02, 1.0, 3


def burst(t):
    """The supports' vertical acceleration, written out here from its definition."""
    T = CYCLES / FREQ
    inside = (t > 0) & (t < T)
    return np.where(inside, A_G * G0 * np.sin(2 * np.pi * FREQ * t) * np.sin(np.pi * t / T) ** 2, 0.0)


def test_support_velocity_is_the_integral_of_the_acceleration_and_ends_at_rest():
    shake = Agitation(acceleration=A_G, frequency=FREQ, cycles=CYCLES, start=0.5)
    for t in (0.6, 1.3, 2.2, 3.4):
        a, v = shake.support_motion(t)
        assert a == pytest.approx(float(burst(t - 0.5)), rel=1e-12)
        assert v == pytest.approx(quad(lambda s: burst(s - 0.5), 0.5, t, limit=200)[0], abs=1e-12)
    assert shake.support_motion(0.4) == (0.0, 0.0)
    assert abs(shake.support_motion(3.5 - 1e-9)[1]) < 1e-9


def shaken_case(**solver):
    return parse_case({
        "case": {"name": "shaken"},
        "material": {"name": "fabric1", "friction": False, "warp": {"k3": 0}, "weft": {"k3": 0}},
        "mesh": {"kind": "strip", "length": LENGTH, "width": 0.01, "nx": 6, "ny": 1,
                 "element": "argyris"},
        "model": {"supports": {"clamped": "clamped"}, "damping": {"air_drag": "0.2 N*s/m^3"}},
        "load": {"agitation": {"acceleration": A_G, "frequency": f"{FREQ} Hz", "cycles": CYCLES}},
        "solver": {"dt": 0.01, "t_end": 4.0, **solver}})


def inertial_frame_tip(plate, times, substeps=10):
    """Tip deflection relative to the clamp, from the cantilever's own matrices in the fixed
    frame: the clamp's value dofs follow the support's travel z(t) (integrated here from its
    acceleration), the air drag acts on absolute velocities (``C`` carries it as α M).
    Trapezoidal Newmark on a grid ``substeps`` times finer than ``times``, dense algebra."""
    n = plate.ndofs
    rigid = np.zeros(n)
    rigid[plate.vertex_dofs] = 1.0                       # w = 1 everywhere: a lift of the strip
    fixed = plate.fixed_dofs
    free = np.setdiff1d(np.arange(n), fixed)
    M, C, K = (A.toarray() for A in (plate.M, plate.C, plate.K0))
    Mff, Cff, Kff = (A[np.ix_(free, free)] for A in (M, C, K))
    Mfc, Cfc, Kfc = (A[np.ix_(free, fixed)] @ rigid[fixed] for A in (M, C, K))
    grid = np.linspace(0.0, times[-1], substeps * (len(times) - 1) + 1)
    h = grid[1] - grid[0]
    a_s = burst(grid)
    v_s = cumulative_trapezoid(a_s, grid, initial=0.0)
    z_s = cumulative_trapezoid(v_s, grid, initial=0.0)
    force = -(np.outer(Mfc, a_s) + np.outer(Cfc, v_s) + np.outer(Kfc, z_s))
    lu = lu_factor(Mff + 0.5 * h * Cff + 0.25 * h * h * Kff)
    u, v, a = np.zeros(len(free)), np.zeros(len(free)), np.zeros(len(free))
    tip = plate.vertex_dofs[np.isclose(plate.mesh.p[0], LENGTH)]
    at_tip = np.isin(free, tip)
    out = [0.0]
    for i in range(1, len(grid)):
        u_pred, v_pred = u + h * v + 0.25 * h * h * a, v + 0.5 * h * a
        a = lu_solve(lu, force[:, i] - Cff @ v_pred - Kff @ u_pred)
        u, v = u_pred + 0.25 * h * h * a, v_pred + 0.5 * h * a
        if i % substeps == 0:
            out.append(u[at_tip].mean() - z_s[i])
    return np.array(out)


def test_shaken_cantilever_matches_the_fixed_frame_solution():
    """A cantilever shaken at its clamp (0.02 g, 1 Hz, 3 cycles, between its modes 1 and 2 at
    0.43 and 2.7 Hz; air drag α = 1.2 1/s): the run in the clamp's frame, where the shaking is
    a weight (a + α v)/g, follows the fixed-frame solution of the same matrices with the clamp
    moving, within 1 % of the largest deflection (it is 0.05 %; without the drag term α v it
    would miss by 28 %)."""
    plate = build(shaken_case()).model
    tip = plate.vertex_dofs[np.isclose(plate.mesh.p[0], LENGTH)]
    tips = [0.0]
    integrate(plate, 4.0, 0.01, initial_state(plate),
              on_step=lambda state, info: tips.append(state.u[tip].mean()))
    tips = np.array(tips)
    reference = inertial_frame_tip(plate, np.linspace(0.0, 4.0, len(tips)))
    peak = np.abs(reference).max()
    assert peak > 3e-3                                   # a real swing: millimetres at the tip
    assert np.abs(tips - reference).max() < 0.01 * peak


@pytest.mark.parametrize("overrides, message", [
    ({"solver": {"dt": 0.2, "t_end": 4.0}}, "solver.dt = 0.2 s is too long for load.agitation"),
    ({"solver": {"dt": 0.01, "t_end": 4.0, "quasi_static": True}},
     "load.agitation needs a dynamic run"),
])
def test_agitation_rules_name_the_key(overrides, message):
    with pytest.raises(CaseError, match=message):
        shaken_case(**overrides["solver"])


def test_agitation_starts_when_the_other_loads_stop_and_ends_the_loading():
    case = parse_case({
        "case": {"name": "lowered"}, "material": {"name": "fabric1"},
        "mesh": {"kind": "strip", "length": LENGTH, "width": 0.01, "nx": 2, "ny": 1},
        "model": {"supports": {"clamped": "clamped"}},
        "load": {"gravity": {"ramp_time": 2.0}, "agitation": {"acceleration": 0.3}},
        "solver": {"dt": 0.01, "t_end": 10.0}})
    assert case.load.agitation.start == 2.0 == case.load.end_time(agitation=False)
    assert case.load.end_time() == pytest.approx(2.0 + 3 / 2.0)


def test_check_and_summary_state_the_shaking(tmp_path, capsys, monkeypatch, tiny_cusick):
    """``--check`` prints the burst, summary.json records it; the stroke is the support's
    peak-to-peak travel, here integrated twice from the acceleration on a fine grid."""
    from drape.case.case import load_case
    from drape.cli.run import main as run
    from drape.run.runner import run_case

    wool = Path(__file__).parents[3] / "cases" / "validation" / "wool_tropical.toml"
    monkeypatch.chdir(tmp_path)
    shake = ["--set", "load.agitation.acceleration=0.3"]
    assert run([str(wool), "--check", *shake]) == 0
    t = np.linspace(0.0, 1.5, 30001)
    a = 0.3 * G0 * np.sin(4 * np.pi * t) * np.sin(np.pi * t / 1.5) ** 2
    z = cumulative_trapezoid(cumulative_trapezoid(a, t, initial=0.0), t, initial=0.0)
    line = capsys.readouterr().out.splitlines()[3]
    assert line == ("  supports shaken 3 cycles at 2 Hz from t = 2 s to 3.5 s, peak 0.3 g, "
                    f"stroke {1e3 * (z.max() - z.min()):.3g} mm")
    case = load_case(wool, ["load.agitation.acceleration=0.3", *tiny_cusick])
    summary = run_case(case, tmp_path / "run", quiet=True)
    assert summary["agitation"]["start_s"] == 2.0 and summary["agitation"]["end_s"] == 3.5
    assert summary["agitation"]["stroke_m"] == pytest.approx(z.max() - z.min(), rel=1e-3)
