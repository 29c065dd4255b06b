"""A fabric's anisotropy read from its outline's a2 (drape.batch.outline_anisotropy), on stand-in runs
whose a2 grows with ln(B_warp/B_weft) by a known law."""
from __future__ import annotations

import csv
import json
import math

import pytest

from drape.batch import outline_anisotropy as oa


def a2_law(ratio: float) -> float:
    """The stand-in model's outline a2 (mm) at B_warp/B_weft = ratio."""
    return 2.0 + 3.0 * math.log(ratio)


@pytest.fixture
def swept(monkeypatch):
    """Replace the forward runs by stand-ins; returns the rows each sweep folder was given."""
    given = {}
    failing = ("fabric09.",)    # the isotropic runs of fabric 9 do not finish

    def sweep(case, rows, out, workers, overrides):
        given.setdefault(out.name, []).extend(r.name for r in rows)
        out.mkdir(parents=True, exist_ok=True)
        records = []
        for row in rows:
            ratio = float(row.keys["material.kes.B_warp"]) / float(row.keys["material.kes.B_weft"])
            run = out / "runs" / row.name
            run.mkdir(parents=True)
            harmonics = [0.12, 0.0, 1e-3 * a2_law(ratio)]
            (run / "summary.json").write_text(json.dumps({"analysis": {"outline_harmonics_m": harmonics,
                                                                      "n_nodes": 2 if ratio > 3 else 8}}))
            status = "failed" if row.name.startswith(failing) else "settled"
            records.append({"name": row.name, "status": status, "DC_percent": 50.0,
                            "nodes": 2 if ratio > 3 else 8, "run_dir": f"runs/{row.name}"})
        with open(out / "results.csv", "w", newline="") as fh:
            writer = csv.DictWriter(fh, list(records[0]))
            writer.writeheader()
            writer.writerows(records)

    monkeypatch.setattr(oa, "sweep", sweep)
    return given


def fabric(n: int, a2: float) -> dict:
    return {"fabric": str(n), "dc_mean": "50", "dc_std": "1", "nodes_min": "2", "nodes_max": "3",
            "nodes_mode": "2", "a2_mm": str(a2)}


def test_each_fabric_gets_the_ratio_its_outline_shows(tmp_path, swept):
    fabrics = [fabric(1, 1.5), fabric(2, a2_law(math.e)), fabric(3, 20.0), fabric(4, a2_law(4.0) - 1e-9)]
    table = oa.study(fabrics, {str(n): 0.1 for n in (1, 2, 3, 4)}, "case.toml", 2, tmp_path)
    by = {r["fabric"]: r for r in table}
    assert (by["1"]["anisotropy"], by["1"]["reading"]) == (1.0, "isotropic")
    assert by["2"]["reading"] == "read"
    # linear in ln(ratio) between the runs at 2 and 4, as the stand-in's a2 (to the 6 digits of the
    # run tables' B)
    assert by["2"]["anisotropy"] == pytest.approx(math.e, rel=1e-5)
    assert (by["3"]["anisotropy"], by["3"]["reading"]) == (4.0, "at least")
    # only fabrics more elliptic than their isotropic runs are run at other ratios
    assert sorted(swept["ratios"]) == sorted(f"fabric{n:02d}_r{r}.s{s}" for n in (2, 3, 4)
                                             for r in (2, 4) for s in (0, 1))
    # a ratio between the runs' ratios runs at itself; one at a run's ratio reuses that run
    assert sorted(swept["read"]) == ["fabric02.s0", "fabric02.s1"]
    assert by["4"]["anisotropy"] == pytest.approx(4.0, rel=1e-6) and by["4"]["model_nodes"] == "2 2"
    assert by["1"]["model_nodes"] == "8 8" and by["3"]["model_nodes"] == "2 2"
    assert by["3"]["within"] == 2 and by["1"]["within"] == 0
    assert by["2"]["model_a2_mm"] == " ".join(f"{a2_law(r):.1f}" for r in (1, 2, 4))
    # the runs at the ratio read give back the scans' a2 (the stand-in's law is exact)
    assert by["2"]["a2_at_ratio_mm"] == pytest.approx(a2_law(math.e), rel=1e-5)
    assert by["3"]["isotropic_nodes"] == "8 8" and by["1"]["a2_at_ratio_mm"] == pytest.approx(2.0)
    text = oa.markdown(table)
    assert "| 1 (no sign) |" in text and "| ≥ 4 |" in text and "| 2.72 |" in text


def test_a_fabric_without_a_finished_isotropic_run_is_not_read(tmp_path, swept):
    table = oa.study([fabric(9, 6.0), fabric(2, a2_law(math.e))], {"9": 0.1, "2": 0.1}, "case.toml", 2,
                     tmp_path)
    by = {r["fabric"]: r for r in table}
    assert by["9"]["reading"] == "no runs" and math.isnan(by["9"]["anisotropy"])
    assert by["9"]["runs"] == 0 and by["9"]["model_a2_mm"] == "nan"
    # no run at another ratio, nor at a NaN one
    assert not any(name.startswith("fabric09") for folder in ("ratios", "read") for name in swept.get(folder, []))
    assert by["2"]["reading"] == "read"
    assert "| 9 | 50.0 ± 1.0 | 2–3 | 6.0 | nan | – | – |  | 0 of 0 | nan |  |" in oa.markdown(table)


def test_the_ratio_is_read_on_the_running_maximum():
    ratio, how = oa.ratio_from_a2(4.0, [1, 2, 4], [3.0, 2.5, 5.0])
    # the dip at ratio 2 is read as 3.0: a2 = 4 lies half-way from ratio 2 to 4 in ln(ratio)
    assert how == "read" and ratio == pytest.approx(2 ** 1.5, rel=1e-12)
    assert oa.ratio_from_a2(3.0, [1, 2, 4], [3.0, 5.0, 9.0]) == (1.0, "isotropic")
    # a ratio none of whose runs finished is passed over: read between ratios 1 and 4
    ratio, how = oa.ratio_from_a2(7.0, [1, 2, 4], [3.0, float("nan"), 11.0])
    assert how == "read" and ratio == pytest.approx(2.0, rel=1e-12)


def test_matched_B_is_read_from_either_column(tmp_path):
    (tmp_path / "a.csv").write_text("fabric,B_matched,law\n1,0.05,tensor\n2,,tensor\n")
    (tmp_path / "b.csv").write_text("fabric,B\n3,0.2\n")
    assert oa.read_matched(tmp_path / "a.csv") == {"1": 0.05}
    assert oa.read_matched(tmp_path / "b.csv") == {"3": 0.2}


def test_the_scan_tables_carry_each_fabrics_mean_a2():
    from drape.analyses.scan_set import SUMMARY_COLUMNS, fabric_tables
    rows = [{"fabric": f, "sample": s, "series": "capture", "number": 1, "dc_percent": 50.0, "nodes": 7,
             "irregularity_mm": 9.0, "a2_mm": a2, "error": ""}
            for f, s, a2 in ((1, 1, 4.0), (1, 2, 6.0), (2, 1, 1.0))]
    fabrics = fabric_tables(rows)["fabrics"]
    assert "a2_mm" in SUMMARY_COLUMNS and [f["a2_mm"] for f in fabrics] == [5.0, 1.0]


def test_only_the_fabrics_asked_for_and_none_without_scans(tmp_path, monkeypatch):
    from drape.batch import matched_dc
    monkeypatch.setattr(matched_dc, "read_fabrics", lambda scans, out: [{"fabric": "1"}, {"fabric": "4"}])
    assert matched_dc.select_fabrics("s.npz", tmp_path / "new", None) == [{"fabric": "1"}, {"fabric": "4"}]
    assert (tmp_path / "new").is_dir()
    assert matched_dc.select_fabrics("s.npz", tmp_path, ["4"]) == [{"fabric": "4"}]
    with pytest.raises(ValueError, match="no scans of fabric 7"):
        matched_dc.select_fabrics("s.npz", tmp_path, ["4", "7"])
