"""Thesis datasets (Tables B.1–B.12) and KES-FB CSV import."""

from pathlib import Path

import numpy as np
import pytest

from constitutive.datasets import (CURVATURE_KES, DATASET_NAMES, MOMENT_KES, THESIS_POLYNOMIALS,
                                   KESDataError, detect_branches, load_dataset, load_kes_csv,
                                   thesis_dataset, turning_points, write_kes_csv)
from constitutive.kes import kes_profile

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data"


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_turning_points_join_the_paths(name):
    # neighbouring path polynomials meet at K+ and K- (to 1e-9 gf·cm/cm), near ±2.5 cm^-1
    polys = THESIS_POLYNOMIALS[name]
    kp, km = turning_points(polys)
    load, unload, rev = polys.paths()
    assert abs(np.polyval(load, kp) - np.polyval(unload, kp)) < 1e-9
    assert abs(np.polyval(unload, km) - np.polyval(rev, km)) < 1e-9
    assert 1.5 < kp < 3.0 and -3.0 < km < -1.5


def test_turning_point_agrees_with_thesis_text():
    # Sec. 4.3.2, fabric 2 warp: "good fit for the region from -2.25 cm^-1 to -1.5 cm^-1 on the
    # reverse unloading portion" -> K- is about -2.25 (tolerance 0.02 cm^-1)
    _, km = turning_points(THESIS_POLYNOMIALS["fabric2-warp"])
    assert km == pytest.approx(-2.25, abs=0.02)


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_sampled_loop_is_continuous_and_follows_the_profile(name):
    data = thesis_dataset(name)
    T = 0.5
    loop = data.sample(T)
    # duration from the profile arithmetic: each phase |dK|/v + T (ramps cover vT/2 each)
    v = 0.5 * CURVATURE_KES
    duration = (2 * data.k_plus - 2 * data.k_minus) / v + 3 * T
    assert loop.time[-1] == pytest.approx(duration, abs=1e-9)
    assert np.all(np.diff(loop.time) <= 1e-3 + 1e-12)
    # the measured moment is continuous across the path switches: at 1 ms and 0.5 cm^-1/s the
    # largest step between samples is tiny against the loop's moment range
    jump = np.abs(np.diff(loop.moment)).max()
    assert jump < 1e-3 * np.ptp(loop.moment)
    # starts at 0 (loading polynomial through the origin), ends at the reverse-unloading
    # polynomial's constant term (the residual moment, Tables B.3/B.6/B.9/B.12)
    assert abs(loop.moment[0]) < 1e-15
    assert loop.moment[-1] / MOMENT_KES == pytest.approx(THESIS_POLYNOMIALS[name].reverse_unloading[-1])


def test_no_deceleration_variant_is_shorter_by_half_a_ramp():
    data = thesis_dataset("fabric1-weft")
    full, nodec = data.sample(0.5), data.sample(0.5, decelerate_at_end=False)
    assert full.time[-1] - nodec.time[-1] == pytest.approx(0.25, abs=1e-9)
    assert nodec.kappa_rate[-1] == pytest.approx(0.5 * CURVATURE_KES)


def test_unknown_dataset_is_named():
    with pytest.raises(KESDataError, match="fabric3-warp"):
        thesis_dataset("fabric3-warp")
    with pytest.raises(KESDataError, match="neither a thesis dataset"):
        load_dataset("nonexistent-thing")


# ---------------------------------------------------------------------------
# CSV import
# ---------------------------------------------------------------------------


def _cycle(n_per_cm=40, noise=0.0, seed=1):
    prof = kes_profile(0.05, accel_time=0.5, include_turning_points=False)
    rng = np.random.default_rng(seed)
    k = prof.kappa + noise * CURVATURE_KES * rng.normal(size=prof.kappa.size)
    m = 5e-3 * MOMENT_KES * k / CURVATURE_KES + 2e-3 * MOMENT_KES * np.sign(prof.kappa_dot)
    return prof, k, m


def test_csv_round_trip_kes_and_si(tmp_path):
    prof, k, m = _cycle()
    write_kes_csv(tmp_path / "a.csv", k, m, prof.t, comment="test")
    write_kes_csv(tmp_path / "b.csv", k, m, prof.t, units="si")
    a, b = load_kes_csv(tmp_path / "a.csv"), load_kes_csv(tmp_path / "b.csv")
    for c in (a, b):
        assert c.k_plus == pytest.approx(250.0, rel=1e-4)
        assert c.k_minus == pytest.approx(-250.0, rel=1e-4)
        assert c.rate == pytest.approx(50.0, rel=1e-3)  # median |dk/dt| = constant test rate
    # moment on the unloading path at kappa = 1 cm^-1: 5e-3*1 - 2e-3 gf·cm/cm
    for c in (a, b):
        assert c.branch_moment(1, np.array([100.0]))[0] / MOMENT_KES == pytest.approx(3e-3, rel=1e-3)


def test_csv_header_units_and_order(tmp_path):
    # columns in another order, curvature in 1/m, moment in N*m/m: same loop as KES defaults
    prof, k, m = _cycle()
    lines = ["# comment", "moment [N*m/m]; time [s]; curvature [1/m]"]
    lines += [f"{mm:.9e}; {t:.3f}; {kk:.6f}" for kk, mm, t in zip(k, m, prof.t)]
    (tmp_path / "c.csv").write_text("\n".join(lines) + "\n")
    c = load_kes_csv(tmp_path / "c.csv")
    assert c.k_plus == pytest.approx(250.0, rel=1e-6)
    assert c.branch_moment(0, np.array([100.0]))[0] == pytest.approx(7e-3 * MOMENT_KES, rel=1e-3)


def test_instrument_style_header(tmp_path):
    # "Curvature(cm-1)  Moment(gf.cm/cm)" as KES-FB software writes it, blank separated
    prof, k, m = _cycle()
    rows = ["Curvature(cm-1)  Moment(gf.cm/cm)"]
    rows += [f"{kk / CURVATURE_KES:.6f}  {mm / MOMENT_KES:.6e}" for kk, mm in zip(k, m)]
    (tmp_path / "e.txt").write_text("\n".join(rows))
    c = load_kes_csv(tmp_path / "e.txt")
    assert c.k_plus == pytest.approx(250.0, rel=1e-6)
    assert c.branch_moment(2, np.array([-100.0]))[0] == pytest.approx(-3e-3 * MOMENT_KES, rel=1e-3)


def test_headerless_csv_with_blanks(tmp_path):
    prof, k, m = _cycle()
    rows = [f"{kk / CURVATURE_KES:.6f} {mm / MOMENT_KES:.6e}" for kk, mm in zip(k, m)]
    (tmp_path / "d.txt").write_text("\n".join(rows))
    c = load_kes_csv(tmp_path / "d.txt")
    assert c.k_minus == pytest.approx(-250.0, rel=1e-6)
    assert c.rate == pytest.approx(50.0)  # no time column: KES standard rate


def _write(tmp_path, body):
    p = tmp_path / "bad.csv"
    p.write_text(body)
    return p


def _good_rows(n=30):
    k = np.concatenate([np.linspace(0, 2.5, n), np.linspace(2.5, -2.5, 2 * n)[1:],
                        np.linspace(-2.5, 0, n)[1:]])
    return [f"{x:.4f},{0.01 * x:.5f}" for x in k]


@pytest.mark.parametrize("bad,line,message", [
    ("0.5,abc", 17, "line 17: moment 'abc' is not a number"),
    ("x1,0.1", 17, "line 17: curvature 'x1' is not a number"),
    ("0.5,0.1,7", 17, "line 17: expected 2 columns (curvature, moment), got 3"),
    ("0.5,nan", 17, "line 17: moment 'nan' is not finite"),
    ("0.5,", 17, "line 17: expected 2 columns"),
])
def test_bad_csv_rows_are_line_numbered(tmp_path, bad, line, message):
    rows = ["# KES-FB export", "curvature,moment"] + _good_rows()
    rows[line - 1] = bad
    with pytest.raises(KESDataError) as err:
        load_kes_csv(_write(tmp_path, "\n".join(rows)))
    assert message in str(err.value)
    assert err.value.line == line


def test_bad_csv_header_and_units(tmp_path):
    rows = _good_rows()
    with pytest.raises(KESDataError, match=r"line 1: unknown column 'curv'"):
        load_kes_csv(_write(tmp_path, "\n".join(["curv,moment"] + rows)))
    with pytest.raises(KESDataError, match=r"line 2: curvature unit 'gf'.*not a curvature unit"):
        load_kes_csv(_write(tmp_path, "\n".join(["#", "curvature [gf],moment"] + rows)))
    with pytest.raises(KESDataError, match="missing column 'moment'"):
        load_kes_csv(_write(tmp_path, "\n".join(["curvature,time"] + rows)))


def test_time_must_increase(tmp_path):
    rows = ["curvature,moment,time"] + [r + f",{0.1 * i:.1f}" for i, r in enumerate(_good_rows())]
    rows[10] = rows[10].rsplit(",", 1)[0] + ",0.0"
    with pytest.raises(KESDataError, match=r"line 11: time 0 s does not increase"):
        load_kes_csv(_write(tmp_path, "\n".join(rows)))


def test_not_a_kes_cycle(tmp_path):
    k = np.linspace(0, 2.5, 50)
    rows = [f"{x},{x}" for x in k]
    with pytest.raises(KESDataError, match="found 0 reversal"):
        load_kes_csv(_write(tmp_path, "\n".join(rows)))
    rows = [f"{-x},{-x}" for x in k]
    with pytest.raises(KESDataError, match="starts with negative curvature"):
        load_kes_csv(_write(tmp_path, "\n".join(rows)))
    with pytest.raises(KESDataError, match="3 data rows"):
        load_kes_csv(_write(tmp_path, "0,0\n1,1\n0,0\n"))


def test_branch_detection_is_robust_to_noise():
    # noise of 0.02 cm^-1 (1 % of the range at 0.025 cm^-1 steps) flips the sign of dk at about
    # a third of the samples; the detected paths must still match the true ones except within
    # 0.1 cm^-1 of the turning points, where noisy samples are ambiguous
    prof, k, _ = _cycle(noise=0.02)
    truth = prof.phase - 1
    flips = np.count_nonzero(np.diff(np.sign(np.diff(k))))
    assert flips > 100
    got = detect_branches(k)
    wrong = got != truth
    near_turn = np.abs(np.abs(prof.kappa) - 250.0) < 10.0
    assert not np.any(wrong & ~near_turn)
    assert np.count_nonzero(wrong) <= 10


def test_example_export_is_flagged_simulated_and_loads():
    path = ROOT / "cases" / "kes" / "example_fabric1_weft.csv"
    assert "SIMULATED" in path.read_text().splitlines()[0]
    c = load_kes_csv(path)
    assert c.k_plus / CURVATURE_KES == pytest.approx(2.5, abs=0.03)
    assert c.k_minus / CURVATURE_KES == pytest.approx(-2.5, abs=0.03)
    assert c.rate / CURVATURE_KES == pytest.approx(0.5, rel=0.05)


def test_fixture_csv_loads():
    c = load_kes_csv(DATA / "kes_small.csv")
    assert c.k_plus > 0 > c.k_minus
