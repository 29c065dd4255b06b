"""The fold-number law of Cerda, Mahadevan & Pasini (drape.batch.fold_law) against values worked
by hand from its formula, its rows against those of the matched-DC study, and the comparison
and figure on made-up sweep records (no drape runs)."""
import csv
import math
from pathlib import Path

import numpy as np
import pytest

from drape.batch import fold_law
from drape.batch.matched_dc import fabric_keys

ROOT = Path(__file__).resolve().parents[3]
CASE = ROOT / "cases" / "cusick_lowered.toml"


def test_law_against_hand_values():
    # n = 2π R_D / (c³ (R − R_D))^{1/4}: R_D = 9, R = 15 (overhang 6), c = 1 → 2π·9 / 6^{1/4}
    assert fold_law.cerda_folds(1.0, 9.0, 15.0) == pytest.approx(56.548668 / 1.565085, rel=1e-6)
    # c = 2, overhang 6: (8·6)^{1/4} = 48^{1/4} = 2.632148
    assert fold_law.cerda_folds(2.0, 9.0, 15.0) == pytest.approx(56.548668 / 2.632148, rel=1e-6)
    # a JIS set-up, 12.7 cm specimen radius on a 6.35 cm disc, c = 1.5, C = 0.3:
    # 0.3 · 2π · 6.35 / (3.375 · 6.35)^{1/4} = 11.969468 / 21.43125^{1/4} = 11.969468 / 2.151604
    assert fold_law.cerda_folds(1.5, 6.35, 12.7, prefactor=0.3) == pytest.approx(
        0.3 * 2 * math.pi * 6.35 / (3.375 * 6.35) ** 0.25, rel=1e-12)
    assert fold_law.cerda_folds(1.5, 6.35, 12.7, prefactor=0.3) == pytest.approx(5.5630, abs=1e-3)


def test_bending_length_in_kes_units():
    # B = 0.1 gf·cm²/cm, W = 15 mg/cm² = 0.015 gf/cm² → c³ = 6.667 cm³, c = 1.882 cm
    assert fold_law.bending_length_cm(0.1, 15.0) == pytest.approx((0.1 / 0.015) ** (1 / 3))
    assert fold_law.bending_length_cm(0.1, 15.0) == pytest.approx(1.8821, abs=1e-4)


def test_law_falls_with_c_as_its_power():
    c = np.geomspace(0.3, 6.0, 40)
    n = fold_law.cerda_folds(c, 9.0, 15.0)
    assert np.all(np.diff(n) < 0)
    assert n[-1] / n[0] == pytest.approx((c[-1] / c[0]) ** -0.75)


def test_law_needs_an_overhang():
    with pytest.raises(ValueError):
        fold_law.cerda_folds(1.0, 9.0, 9.0)


def test_rows_are_those_matched_dc_runs_at_the_same_B():
    rows = fold_law.fold_law_rows(CASE, [0.05, 0.2], weight=15.0, seeds=2)
    assert [r.name for r in rows] == ["B0.05_s0", "B0.05_s1", "B0.2_s0", "B0.2_s1"]
    for row in rows:
        B, seed = row.name[1:].split("_s")
        expected = fabric_keys(float(B)) + [f"load.perturbation.seed={seed}"]
        assert row.overrides() == expected
        assert row.keys["material.kes.HB2_warp"] == f"{0.5 * float(B):g}"


def test_rows_refuse_a_case_that_is_not_cusick():
    with pytest.raises(ValueError):
        fold_law.fold_law_rows(ROOT / "cases" / "cantilever.toml", [0.1])


def test_case_radii_of_the_lowered_case():
    assert fold_law.case_radii(CASE) == pytest.approx((9.0, 15.0))


def records(C=0.25, B_values=(0.003, 0.012, 0.05, 0.2, 0.8), seeds=2, weight=15.0):
    """Made-up results.csv records whose node counts follow the law with prefactor C, the
    odd seeds one node more; a failed run at the end."""
    recs = []
    for B in B_values:
        c = fold_law.bending_length_cm(B, weight)
        n = round(fold_law.cerda_folds(c, 9.0, 15.0, C))
        for s in range(seeds):
            recs.append({"name": f"B{B:g}_s{s}", "material.kes.B_warp": f"{B:g}",
                         "material.kes.weight": f"{weight:g}", "load.perturbation.seed": str(s),
                         "status": "settled", "DC_percent": f"{40 + 10 * math.log10(B):.3f}",
                         "nodes": str(n + s)})
    recs.append({"name": "B1.6_s0", "material.kes.B_warp": "1.6", "material.kes.weight": "15",
                 "load.perturbation.seed": "0", "status": "failed", "DC_percent": "", "nodes": ""})
    return recs


def test_compare_on_synthetic_records():
    table = fold_law.compare(records())
    assert [r["B"] for r in table] == [0.003, 0.012, 0.05, 0.2, 0.8]          # the failed run left out
    assert [r["half"] for r in table] == ["fit", "check", "fit", "check", "fit"]
    first = table[0]
    assert first["c_cm"] == pytest.approx(fold_law.bending_length_cm(0.003, 15.0), abs=1e-4)
    assert first["overhang_over_c"] == pytest.approx(6.0 / first["c_cm"], abs=1e-2)
    assert first["seeds"] == "0 1"
    n0 = round(fold_law.cerda_folds(first["c_cm"], 9.0, 15.0, 0.25))
    assert first["nodes"] == f"{n0} {n0 + 1}" and first["nodes_mean"] == n0 + 0.5
    assert len(first["DC"].split()) == 2
    # prefactor from the fit half only: the geometric mean of nodes / n(C = 1) over its seeds
    fit = [r for r in table if r["half"] == "fit"]
    ratios = [int(n) / fold_law.cerda_folds(fold_law.bending_length_cm(r["B"], 15.0), 9.0, 15.0)
              for r in fit for n in r["nodes"].split()]
    C = math.exp(np.mean(np.log(ratios)))
    assert all(r["prefactor"] == pytest.approx(C, abs=1e-4) for r in table)
    assert C == pytest.approx(0.25, rel=0.15)
    for r in table:
        n = fold_law.cerda_folds(fold_law.bending_length_cm(r["B"], 15.0), 9.0, 15.0, C)
        assert r["n_law"] == pytest.approx(n, abs=0.01)
        assert r["difference"] == pytest.approx(r["nodes_mean"] - n, abs=0.02)
    halves = fold_law.agreement(table)
    assert halves["fit"]["points"] == 3 and halves["check"]["points"] == 2
    assert halves["check"]["rms"] < 1.5                       # the records follow the law
    text = fold_law.markdown(table)
    assert text.count("\n| ") == len(table) and "fitted on the even-indexed B" in text


def test_compare_without_finished_runs_is_empty():
    assert fold_law.compare([r for r in records() if r["status"] == "failed"]) == []


def test_plot_and_tables_are_written(tmp_path):
    table = fold_law.compare(records())
    png = fold_law.write_plot(table, tmp_path / "fold.png")
    assert png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = fold_law.write_table(table, tmp_path / "out")
    for name in ("fold_law.csv", "fold_law.md", "fold_law.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    assert (tmp_path / "out" / "fold_law.md").read_text().strip() == text


def test_the_study_runs_the_rows_and_writes_its_tables(monkeypatch, tmp_path):
    swept = []

    def fake_sweep(case, rows, out, workers, overrides):       # no drape runs: the law's records
        swept.append([r.name for r in rows])
        recs = [r for r in records(seeds=1) if r["name"] in {row.name for row in rows}]
        out.mkdir(parents=True, exist_ok=True)
        with open(out / "results.csv", "w", newline="") as fh:
            writer = csv.DictWriter(fh, list(recs[0]))
            writer.writeheader()
            writer.writerows(recs)

    monkeypatch.setattr(fold_law, "sweep", fake_sweep)
    out = tmp_path / "study"
    text = fold_law.study(CASE, [0.8, 0.003, 0.05, 0.012, 0.2], 15.0, 1, out)
    assert swept == [["B0.003_s0", "B0.012_s0", "B0.05_s0", "B0.2_s0", "B0.8_s0"]]
    for name in ("fold_law.csv", "fold_law.md", "fold_law.png"):
        assert (out / name).exists()
    assert (out / "fold_law.md").read_text().strip() == text
    with open(out / "fold_law.csv", newline="") as fh:
        assert len(list(csv.DictReader(fh))) == 5
