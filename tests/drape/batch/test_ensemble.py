"""Seed ensembles of a sweep: rows per seed, statistics against the statistics module, and a
tiny Cusick ensemble end to end (ensemble.json, the printed lines, the report section)."""
from __future__ import annotations

import json
import statistics
from pathlib import Path

import pytest

from drape.batch import rows as sweep_rows
from drape.cli import sweep as sweep_cli
from drape.case.case import load_case
from drape.batch.ensemble import SEED_KEY, ensemble_stats, seed_rows, seeded

ROOT = Path(__file__).resolve().parents[3]
CUSICK = ROOT / "cases" / "cusick_kes.toml"


def test_each_row_is_repeated_per_seed_and_grouped_by_its_name():
    rows = seed_rows([sweep_rows.SweepRow("wool", {"mesh.refine": "1"}, {"measured.DC": "49.8"})], 3)
    assert [r.name for r in rows] == ["wool.s0", "wool.s1", "wool.s2"]
    assert [r.keys for r in rows] == [{"mesh.refine": "1", SEED_KEY: str(k)} for k in range(3)]
    assert {r.group for r in rows} == {"wool"} and rows[2].measured == {"measured.DC": "49.8"}
    with pytest.raises(sweep_rows.SweepError, match="sets load.perturbation.seed itself"):
        seed_rows([sweep_rows.SweepRow("x", {SEED_KEY: "4"})], 2)
    with pytest.raises(sweep_rows.SweepError, match="--seeds = 0: must be >= 1"):
        seed_rows(None, 0)


def test_a_case_without_a_seeded_perturbation_has_no_ensemble():
    with pytest.raises(sweep_rows.SweepError, match="no seeded \\[load.perturbation\\]"):
        seeded(ROOT / "cases" / "cantilever.toml", [], None, 3)
    with pytest.raises(sweep_rows.SweepError, match="no seeded"):
        seeded(CUSICK, ["load.perturbation.kind='none'"], None, 3)


def test_statistics_over_the_finished_seeds_match_the_statistics_module():
    dc = [61.2, 58.4, 60.1, 57.9, 63.0]
    nodes = [6, 7, 6, 7, 5]
    recs = [{"name": f"w.s{k}", "status": "settled", "DC_percent": repr(d), "nodes": str(n)}
            for k, (d, n) in enumerate(zip(dc, nodes))]
    recs += [{"name": "w.s5", "status": "failed", "DC_percent": "", "nodes": ""},
             {"name": "w.s6", "status": "completed", "DC_percent": "70.0", "nodes": "9"}]
    dc.append(70.0)
    nodes.append(9)
    s = ensemble_stats(recs)
    assert (s["runs"], s["finished"], s["not_finished"]) == (7, 6, {"w.s5": "failed"})
    assert s["DC_percent"]["mean"] == pytest.approx(statistics.fmean(dc), rel=1e-14)
    assert s["DC_percent"]["std"] == pytest.approx(statistics.stdev(dc), rel=1e-14)
    assert (s["DC_percent"]["min"], s["DC_percent"]["max"]) == (57.9, 70.0)
    assert s["nodes"]["mean"] == pytest.approx(statistics.fmean(nodes), rel=1e-14)
    assert s["nodes"]["std"] == pytest.approx(statistics.stdev(nodes), rel=1e-14)
    assert s["nodes"]["histogram"] == {"5": 1, "6": 2, "7": 2, "9": 1}
    # 6 and 7 tie and lie equally near the median 6.5: the smaller count is named
    assert (s["nodes"]["mode"], s["nodes"]["mode_count"]) == (6, 2)
    assert s["nodes"]["agreement"] == "2 of 6 seeds gave 6 nodes"
    # 7 and 9 tie: 7 lies nearer the median, 7.5 (the failed run has no count)
    tied = ensemble_stats([dict(r, nodes=str(n)) for r, n in zip(recs, [7, 9, 7, 9, 5, 0, 8])])
    assert (tied["nodes"]["mode"], tied["nodes"]["mode_count"]) == (7, 2)
    # every seed differs: the median count is named, and the summary says none agree
    spread = ensemble_stats([dict(r, nodes=str(n)) for r, n in zip(recs[:3], [5, 7, 6])])
    assert (spread["nodes"]["mode"], spread["nodes"]["mode_count"]) == (6, 1)
    assert spread["nodes"]["agreement"] == "no two of 3 seeds agree: 5, 6, 7 nodes"
    one = ensemble_stats(recs[:1])
    assert one["DC_percent"]["std"] is None and one["nodes"]["agreement"] == "1 of 1 seeds gave 6 nodes"


@pytest.mark.slow
def test_a_tiny_cusick_ensemble_end_to_end(tmp_path, capsys, tiny_cusick):
    table = tmp_path / "fabrics.csv"
    table.write_text("name,material.bending_scale,measured.DC,measured.nodes\nlimp,1,61.5,6\n"
                     "stiff,4,,\n")
    out = tmp_path / "ens"
    code = sweep_cli.main([str(CUSICK), "--table", str(table), "--seeds", "2", "--out", str(out),
                       "--workers", "1", *sum((["--set", o] for o in tiny_cusick), [])])
    assert code == 0
    printed = capsys.readouterr().out
    records = {r["name"]: r for r in sweep_rows.read_results(out / "results.csv")}
    assert sorted(records) == ["limp.s0", "limp.s1", "stiff.s0", "stiff.s1"]
    for name, rec in records.items():
        assert rec["status"] == "completed"
        case = load_case(out / rec["run_dir"] / "case.resolved.toml")
        assert case.load.perturbation.seed == int(name[-1])
    data = json.loads((out / "ensemble.json").read_text())
    assert data["seed_key"] == SEED_KEY
    by_name = {e["name"]: e for e in data["ensembles"]}
    assert sorted(by_name) == ["limp", "stiff"]
    limp = by_name["limp"]
    dc = [float(records[f"limp.s{k}"]["DC_percent"]) for k in range(2)]
    assert limp["seeds"] == [0, 1] and limp["finished"] == 2
    assert limp["DC_percent"]["mean"] == pytest.approx(statistics.fmean(dc), rel=1e-14)
    assert limp["measured"] == {"DC": "61.5", "nodes": "6"}
    assert limp["keys"] == {"material.bending_scale": "1"}
    assert sum(limp["nodes"]["histogram"].values()) == 2
    assert "limp: 2/2 seeds, DC" in printed and "measured DC 61.5, nodes 6" in printed
    page = (out / "report.html").read_text()
    assert "<h2>Seed ensembles</h2>" in page and limp["nodes"]["agreement"] in page
