"""drape predict: the unknowns a sheet leaves, their Latin-hypercube samples, the interval and
the unknown that explains the spread; the command on a stand-in sweep and, slow, on real runs."""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from drape.batch import prediction as pred
from drape.batch.ensemble import SEED_KEY
from drape.cli import predict as predict_cli

ROOT = Path(__file__).resolve().parents[3]
SHEET = {"B_warp": 0.1, "B_weft": 0.1, "HB2_warp": 0.05, "HB2_weft": 0.05, "weight": 15}


@pytest.mark.parametrize("extra, missing", [
    ({}, ["shear_G", "anisotropy", "thickness"]),
    ({"G": 0.8, "thickness": 0.4}, ["anisotropy"]),
    ({"B_weft": 0.06, "HB2_weft": 0.03, "G": 0.8, "thickness": 0.4}, []),
    ({"B_weft": 0.06, "thickness": 0.4}, ["shear_G"]),
])
def test_the_unknowns_are_what_the_sheet_omits(extra, missing):
    assert pred.missing_unknowns({**SHEET, **extra}) == missing


def test_the_samples_stratify_each_unknown_and_keep_the_sheets_mean_bending():
    n = 10
    unknowns = ["shear_G", "anisotropy", "thickness"]
    rows = pred.sample_rows(SHEET, unknowns, n, seed=3)
    assert [r.keys[SEED_KEY] for r in rows] == [str(i) for i in range(n)]
    assert [r.name for r in rows] == [f"p{i:03d}" for i in range(n)]
    for name in unknowns:
        u = pred.UNKNOWNS[name]
        x = np.array([float(r.measured[f"unknown.{name}"]) for r in rows])
        strata = np.floor(n * np.log(x / u.low) / math.log(u.high / u.low)).astype(int)
        assert sorted(strata) == list(range(n))          # one sample in each of n equal log-strata
    for r in rows:
        a = float(r.measured["unknown.anisotropy"])
        bw, bf = float(r.keys["material.kes.B_warp"]), float(r.keys["material.kes.B_weft"])
        hw, hf = float(r.keys["material.kes.HB2_warp"]), float(r.keys["material.kes.HB2_weft"])
        assert bw / bf == pytest.approx(a, rel=1e-5) and math.sqrt(bw * bf) == pytest.approx(0.1, rel=1e-5)
        assert hw / bw == pytest.approx(0.5, rel=1e-5) and hf / bf == pytest.approx(0.5, rel=1e-5)
        assert float(r.keys["material.kes.G"]) == pytest.approx(float(r.measured["unknown.shear_G"]), rel=1e-5)
    assert [r.keys for r in pred.sample_rows(SHEET, unknowns, n, seed=3)] == [r.keys for r in rows]
    with pytest.raises(ValueError, match="--samples = 1"):
        pred.sample_rows(SHEET, unknowns, 1)


def _records(rows, dc_of, status="settled"):
    return [{"name": r.name, "status": status, "DC_percent": f"{dc_of(r):.6g}",
             "nodes": str(6 + int(r.keys[SEED_KEY]) % 2)} for r in rows]


def test_the_interval_is_the_samples_percentiles_and_G_is_named_when_it_drives_the_DC():
    """DC = 60 + 8 ln(G / 0.7) + a seed scatter of ±0.5: G explains nearly all the variance."""
    unknowns = ["shear_G", "anisotropy"]
    rows = pred.sample_rows(SHEET, unknowns, 16, seed=1)
    rng = np.random.default_rng(0)
    noise = {r.name: rng.uniform(-0.5, 0.5) for r in rows}
    records = _records(rows, lambda r: 60 + 8 * math.log(float(r.measured["unknown.shear_G"]) / 0.7)
                       + noise[r.name])
    records.append({"name": "p999", "status": "failed", "DC_percent": "", "nodes": ""})
    p = pred.summarise(records, rows, unknowns)
    dc = np.array([float(r["DC_percent"]) for r in records[:-1]])
    assert (p["DC_percent"]["low"], p["DC_percent"]["high"]) == pytest.approx(tuple(np.percentile(dc, [5, 95])))
    assert p["nodes"] == {"low": 6, "high": 7, "values": p["nodes"]["values"]}
    assert p["runs"] == {"used": 16, "of": 17}
    assert p["most_informative"] == "shear_G"
    assert p["unknowns"]["shear_G"]["variance_share"] > 0.95
    assert p["unknowns"]["anisotropy"]["variance_share"] < 0.02
    assert "measuring the shear rigidity G (KES-FB1) would narrow it most" in pred.describe_prediction(p)


def test_an_unknown_that_explains_little_is_not_advised():
    rows = pred.sample_rows(SHEET, ["shear_G"], 12, seed=2)
    rng = np.random.default_rng(1)
    p = pred.summarise(_records(rows, lambda r: 50 + rng.normal()), rows, ["shear_G"])
    assert p["unknowns"]["shear_G"]["variance_share"] < pred.MATTERS
    assert "the seed's scatter is the interval" in pred.describe_prediction(p)


def test_too_few_runs_give_no_interval_and_too_few_to_rank_say_so():
    rows = pred.sample_rows(SHEET, ["shear_G", "anisotropy"], 3)
    with pytest.raises(ValueError, match="1 of 3 runs finished"):
        pred.summarise(_records(rows[:1], lambda r: 50) + _records(rows[1:], lambda r: 50, "failed"),
                       rows, ["shear_G", "anisotropy"])
    p = pred.summarise(_records(rows, lambda r: 50 + float(r.keys[SEED_KEY])), rows, ["shear_G", "anisotropy"])
    assert p["most_informative"] is None and "too few to tell" in pred.describe_prediction(p)


def _stand_in_sweep(dc_of):
    """``run_sweep`` replaced: writes results.csv from ``dc_of(row)`` without running anything."""
    def run_sweep(case_path, rows, out, **kwargs):
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        records = _records(rows, dc_of)
        with open(out / "results.csv", "w", newline="") as fh:
            writer = csv.DictWriter(fh, list(records[0]))
            writer.writeheader()
            writer.writerows(records)
        return records
    return run_sweep


def test_the_command_prints_the_interval_and_where_the_measurement_lies(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(predict_cli, "run_sweep", _stand_in_sweep(
        lambda r: 80 + 5 * math.log(float(r.measured["unknown.anisotropy"]))))
    case = ROOT / "cases" / "validation" / "cotton_broadcloth.toml"       # measured 82.9 %, 2 nodes
    code = predict_cli.main([str(case), "--samples", "8", "--out", str(tmp_path / "p")])
    out = capsys.readouterr().out
    assert code == 0, out
    p = json.loads((tmp_path / "p" / "prediction.json").read_text())
    assert sorted(p["unknowns"]) == ["anisotropy", "shear_G"]            # the sheet gives T
    assert p["most_informative"] == "anisotropy"
    assert p["measured"]["DC_inside"] == (p["DC_percent"]["low"] <= 82.9 <= p["DC_percent"]["high"])
    assert p["measured"]["nodes_inside"] is False
    assert "measuring B and 2HB of warp and weft apart (KES-FB2) would narrow it most" in out
    assert "measured: DC 82.9 %" in out and "2 nodes outside" in out
    assert (tmp_path / "p" / "prediction.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_sheet_in_other_units_is_sampled_in_kes_units_and_a_resume_keeps_its_samples(
        tmp_path, monkeypatch, capsys):
    """B as a string with units is read as the loaded case holds it; a resume with another
    --samples is refused before anything runs."""
    seen = []

    def stand_in(case_path, rows, out, **kwargs):
        seen.append(rows)
        from drape.batch.sweep import _write_definition
        Path(out).mkdir(parents=True, exist_ok=True)
        _write_definition(Path(out), str(case_path), rows, [])
        return _stand_in_sweep(lambda r: 60.0 + int(r.keys[SEED_KEY]))(case_path, rows, out)

    monkeypatch.setattr(predict_cli, "run_sweep", stand_in)
    case = ROOT / "cases" / "validation" / "wool_tropical.toml"
    out = tmp_path / "p"
    unit_b = "material.kes.B_warp=\"6.5704555e-6 N*m\""             # 0.067 gf·cm²/cm
    assert predict_cli.main([str(case), "--samples", "4", "--set", unit_b, "--out", str(out)]) == 0
    warp = [float(r.keys["material.kes.B_warp"]) / math.sqrt(float(r.measured["unknown.anisotropy"]))
            for r in seen[0]]
    assert warp == pytest.approx([0.067] * 4, rel=1e-4)
    capsys.readouterr()
    assert predict_cli.main([str(case), "--samples", "5", "--set", unit_b, "--resume",
                             "--out", str(out)]) == 2
    assert "holds other samples" in capsys.readouterr().err and len(seen) == 1


def test_the_command_takes_only_the_unknowns_it_is_given(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(predict_cli, "run_sweep", _stand_in_sweep(lambda r: 50.0 + int(r.keys[SEED_KEY])))
    case = ROOT / "cases" / "cusick_kes.toml"
    assert predict_cli.main([str(case), "--samples", "4", "--unknowns", "--out", str(tmp_path / "p")]) == 0
    assert "the interval is the seed's scatter alone" in capsys.readouterr().out
    assert json.loads((tmp_path / "p" / "prediction.json").read_text())["unknowns"] == {}


@pytest.mark.parametrize("argv, words", [
    (["cases/cantilever.toml"], "needs a Cusick case"),
    (["cases/cusick_kes.toml", "--samples", "1"], "--samples = 1: must be >= 2"),
    (["cases/nosuch.toml"], "does not exist"),
])
def test_bad_input_is_one_line_and_exit_2(argv, words, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert predict_cli.main([*argv, "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_prediction_runs_end_to_end_on_a_tiny_cusick_case(tmp_path, capsys):
    """Three real forward runs (a 2 × 16 mesh, 0.3 s): the interval holds their DCs."""
    case = ROOT / "cases" / "validation" / "wool_tropical.toml"
    shrink = ["--set", "mesh.n_radial=2", "--set", "mesh.n_circumferential=16", "--set", "solver.t_end=0.3"]
    assert predict_cli.main([str(case), "--samples", "3", *shrink, "--workers", "1", "--quiet",
                             "--out", str(tmp_path / "p")]) == 0
    p = json.loads((tmp_path / "p" / "prediction.json").read_text())
    assert p["runs"] == {"used": 3, "of": 3}
    assert min(p["DC_percent"]["values"]) <= p["DC_percent"]["low"] <= p["DC_percent"]["high"] \
        <= max(p["DC_percent"]["values"])
    assert "too few to tell" in capsys.readouterr().out
