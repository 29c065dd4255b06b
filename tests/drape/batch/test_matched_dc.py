"""The matching of B to a fabric's DC (drape.batch.matched_dc), on a made-up DC(B) instead of
forward runs: the secant in log B finds B to within its tolerance in a few sweeps, from any
start, and says nothing for a run that stopped."""
import numpy as np
import pytest

from drape.batch import matched_dc as matched


def dc_of(B):
    """DC % of a model whose DC rises 25 points per unit of ln B (about the Cusick model's)."""
    return 20.0 + 25.0 * np.log(B / 0.01)


def test_secant_step_on_a_log_linear_curve_lands_on_the_target():
    points = [(0.05, dc_of(0.05)), (0.08, dc_of(0.08))]
    B = matched.secant_B(points, 60.0)
    assert dc_of(B) == pytest.approx(60.0, abs=0.01)            # B printed to 4 digits
    # one run: a step along the default slope, 20 points per unit of ln B
    assert matched.secant_B(points[:1], 60.0) == pytest.approx(0.05 * np.exp((60.0 - dc_of(0.05)) / 20.0),
                                                               rel=1e-3)


def test_secant_match_reaches_each_fabric_within_tolerance(monkeypatch, tmp_path):
    sweeps = []

    def fake_sweep(case, rows, out, workers, overrides):
        sweeps.append([r.name for r in rows])
        out.mkdir(parents=True, exist_ok=True)
        (out / "rows").write_text("\n".join(f"{r.name},{r.keys['material.kes.B_warp']}" for r in rows))

    def fake_results(path):
        recs = []
        for line in (path.parent / "rows").read_text().splitlines():
            name, B = line.split(",")
            if name == "fabric9":                       # a run that stops
                recs.append({"name": name, "status": "failed", "DC_percent": ""})
            else:
                recs.append({"name": name, "status": "settled", "DC_percent": f"{dc_of(float(B)):.3f}",
                             "nodes": "7", "material.kes.B_warp": B})
        return recs

    monkeypatch.setattr(matched, "sweep", fake_sweep)
    monkeypatch.setattr(matched, "read_results", fake_results)
    fabrics = [{"fabric": "1", "dc_mean": "46.6"}, {"fabric": "3", "dc_mean": "15.0"},
               {"fabric": "5", "dc_mean": "76.7"}, {"fabric": "9", "dc_mean": "50.0"}]
    best = matched.secant_match(fabrics, "case.toml", {"1": 0.0486}, tmp_path, None, [], 4, 1.5)
    assert set(best) == {"1", "3", "5"}                 # fabric 9 stopped: no B claimed
    for fab in fabrics[:3]:
        B, rec = best[fab["fabric"]]
        assert abs(dc_of(B) - float(fab["dc_mean"])) <= 1.5
        assert float(rec["DC_percent"]) == pytest.approx(dc_of(B), abs=1e-3)
    assert len(sweeps) <= 4 and "fabric1" in sweeps[0]


def test_table_row_counts_the_runs_within_the_measured_range():
    fab = {"fabric": "5", "dc_mean": "76.7", "dc_std": "2.0", "nodes_min": "7", "nodes_max": "8"}
    runs = [{"DC_percent": "75.0", "nodes": "8"}, {"DC_percent": "76.0", "nodes": "9"}]
    row = matched.table_row(fab, "tensor", 0.1377, runs)
    assert row["model_DC"] == pytest.approx(75.5)
    assert (row["model_nodes"], row["within"], row["runs"]) == ("8 9", 1, 2)
    assert matched.table_row(fab, "tensor", None, [])["model_DC"] is None
