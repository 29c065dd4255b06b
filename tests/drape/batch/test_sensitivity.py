"""The one-factor-at-a-time study: ΔDC and Δnodes from a sweep's results against hand values,
the tornado's bars, and the Cusick factors end to end on a tiny case (plumbing only); the fold
preference study's energies, table and plumbing."""
from __future__ import annotations

import csv
import json
import math
import statistics
from pathlib import Path

import pytest

from drape.batch import cusick_sensitivity
from drape.batch import fold_preference as folds
from drape.batch import sensitivity as sens
from drape.batch.rows import read_results

ROOT = Path(__file__).resolve().parents[3]
WOOL = ROOT / "cases" / "validation" / "wool_tropical.toml"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"

FACTORS = [
    sens.Factor("damping", "damping α", "20 1/s", (
        sens.Level("low", "2 1/s", {"model.damping.alpha": "2"}, "low"),
        sens.Level("high", "80 1/s", {"model.damping.alpha": "80"}, "high"))),
    sens.Factor("friction_off", "friction", "from 2HB", (
        sens.Level("off", "off", {"material.friction": "false"}, "low"),)),
    sens.Factor("mesh", "mesh", "6 × 72", (
        sens.Level("coarse", "4 × 48", {"mesh.n_radial": "4", "mesh.n_circumferential": "48"}),
        sens.Level("refine1", "refine 1", {"mesh.refine": "1"}, "high"))),
]


def fake_results(folder: Path, rows: list[tuple]) -> None:
    """A results.csv as drape.batch.sweep writes it, with only the columns the study reads."""
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / "results.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["name", "status", "reason", "DC_percent", "nodes"])
        w.writerows(rows)


def test_study_rows_are_the_base_and_one_per_level_and_names_are_checked():
    rows = sens.study_rows(FACTORS)
    assert [r.name for r in rows] == ["base", "damping.low", "damping.high", "friction_off.off",
                                      "mesh.coarse", "mesh.refine1"]
    assert rows[4].keys == {"mesh.n_radial": "4", "mesh.n_circumferential": "48"}
    seeded = sens.study_rows(FACTORS[:1], seeds=2)
    assert [(r.name, r.group) for r in seeded][:3] == [("base.s0", "base"), ("base.s1", "base"),
                                                        ("damping.low.s0", "damping.low")]
    with pytest.raises(sens.StudyError, match="level tag 'a b'"):
        sens.Level("a b", "x", {"mesh.refine": "1"})
    with pytest.raises(sens.StudyError, match="dotted case keys"):
        sens.Level("a", "x", {"refine": "1"})
    with pytest.raises(sens.StudyError, match="factor name repeated"):
        sens.study_rows([FACTORS[0], FACTORS[0]])


def test_collect_gives_changes_from_the_base_and_marks_runs_without_a_result(tmp_path):
    fake_results(tmp_path, [("base", "settled", "", "60.1", "8"),
                            ("damping.low", "settled", "", "55.6", "6"),
                            ("damping.high", "completed", "", "61.0", "8"),
                            ("friction_off.off", "failed", "Newton did not converge", "", ""),
                            ("mesh.refine1", "settled", "", "58.9", "9")])
    study = sens.collect(tmp_path, WOOL, FACTORS)
    assert study["measured"] == {"DC_percent": 49.8, "nodes": 5}
    assert (study["base"]["DC_percent"], study["base"]["nodes"]) == (60.1, 8)
    levels = {lv["name"]: lv for f in study["factors"] for lv in f["levels"]}
    # hand values: level minus base
    assert levels["damping.low"]["dDC"] == pytest.approx(55.6 - 60.1, abs=1e-12)
    assert levels["damping.low"]["dnodes"] == -2
    assert levels["damping.high"]["dDC"] == pytest.approx(0.9, abs=1e-12)
    assert levels["mesh.refine1"]["dDC"] == pytest.approx(-1.2, abs=1e-12)
    assert levels["mesh.refine1"]["dnodes"] == 1
    failed, missing = levels["friction_off.off"], levels["mesh.coarse"]
    assert failed["dDC"] is None and failed["status"] == "failed"
    assert "Newton did not converge" in failed["reason"]
    assert missing["dDC"] is None and missing["status"] == "not run"

    table = sens.markdown_table(study).splitlines()
    # factors by their largest |ΔDC|: damping (4.5), mesh (1.2), friction (none)
    assert [line.split("|")[1].strip() for line in table[3:]] == [
        "damping α (20 1/s)", "damping α (20 1/s)", "mesh (6 × 72)", "mesh (6 × 72)",
        "friction (from 2HB)"]
    assert "| -4.5 | 6 | -2 |" in table[3] and "failed (failed: Newton did not converge)" in table[-1]


def test_collect_reads_each_level_of_a_seeded_study_as_its_ensemble(tmp_path):
    fake_results(tmp_path, [("base.s0", "settled", "", "60.0", "8"),
                            ("base.s1", "settled", "", "62.0", "7"),
                            ("base.s2", "settled", "", "61.0", "8"),
                            ("damping.low.s0", "settled", "", "55.0", "6"),
                            ("damping.low.s1", "failed", "x", "", ""),
                            ("damping.low.s2", "settled", "", "57.0", "5")])
    study = sens.collect(tmp_path, WOOL, FACTORS[:1], seeds=3)
    base, low = study["base"], study["factors"][0]["levels"][0]
    assert base["DC_percent"] == pytest.approx(61.0, abs=1e-12)
    assert base["DC_std"] == pytest.approx(statistics.stdev([60.0, 62.0, 61.0]), rel=1e-12)
    assert (base["nodes"], base["runs"], base["finished"]) == (8, 3, 3)
    assert low["DC_percent"] == pytest.approx(56.0, abs=1e-12) and low["finished"] == 2
    assert low["dDC"] == pytest.approx(-5.0, abs=1e-12)
    assert low["nodes"] == 5 and low["dnodes"] == -3   # a tie of 5 and 6: the smaller count
    assert low["status"] == "2/3 finished" and "failed: x" in low["reason"]


def test_tornado_bars_are_the_changes_sorted_by_swing_with_the_measured_line(tmp_path):
    fake_results(tmp_path, [("base", "settled", "", "60.0", "8"),
                            ("damping.low", "settled", "", "57.0", "6"),
                            ("damping.high", "settled", "", "61.0", "8"),
                            ("friction_off.off", "settled", "", "52.0", "5"),
                            ("mesh.coarse", "settled", "", "59.5", "9"),
                            ("mesh.refine1", "settled", "", "60.5", "8")])
    study = sens.collect(tmp_path, WOOL, FACTORS)
    fig = sens.tornado_figure(study)
    ax = fig.axes[0]
    bars = [(round(p.get_y() + p.get_height() / 2, 3), p.get_width()) for p in ax.patches
            if p.get_width() != 0 and p.get_height() < 1]
    widths = sorted(w for _, w in bars)
    assert widths == pytest.approx(sorted([-3.0, 1.0, -8.0, -0.5, 0.5]), abs=1e-12)
    # bottom to top by the largest |ΔDC|: mesh (0.5), damping (3), friction (8)
    labels = [t.get_text().split("\n")[0] for t in ax.get_yticklabels()]
    assert labels == ["mesh", "damping α", "friction"]
    y_of = {round(w, 6): y for y, w in bars}
    assert y_of[-8.0] == 2 and 0.5 < y_of[-3.0] < 1.5 and y_of[0.5] < 0.5
    measured = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
    assert len(measured) == 1 and measured[0].get_xdata()[0] == pytest.approx(49.8 - 60.0)
    paths = sens.write_study(tmp_path, study)
    assert paths["png"].read_bytes()[:8] == PNG_MAGIC
    assert json.loads(paths["json"].read_text())["base"]["DC_percent"] == 60.0


def test_cusick_levels_are_valid_cases_of_the_wool():
    from drape.case.case import load_case

    case = load_case(WOOL)
    factors = cusick_sensitivity.factors(case)
    names = [f.name for f in factors]
    for expected in ("friction_length", "friction_order", "friction_off", "membrane_tension",
                     "shear_G12", "perturbation_amplitude", "perturbation_spectrum",
                     "perturbation_duration", "perturbation_seed", "gravity_ramp", "agitation",
                     "air_drag", "air_drag_form",
                     "mesh"):
        assert expected in names
    mesh = {f.name: f for f in factors}["mesh"].levels[0].keys
    assert mesh == {"mesh.n_radial": "4", "mesh.n_circumferential": "46"}   # 2/3 of 74: 2 · 23
    for row in sens.study_rows(factors):
        load_case(WOOL, row.overrides())      # raises for a level that is no valid case


@pytest.mark.slow
def test_cusick_factors_run_tiny_and_write_table_json_and_chart(tmp_path, tiny_cusick):
    out = tmp_path / "sens"
    # a tiny case (12 triangles, two steps) to keep the test short
    factors = cusick_sensitivity.study_factors(WOOL, tiny_cusick, names=["friction_off", "friction_order"])
    assert [f.name for f in factors] == ["friction_order", "friction_off"]

    def run(overrides=tiny_cusick, resume=False):
        return sens.run_study(WOOL, factors, out, overrides=list(overrides), workers=2,
                              resume=resume, quiet=True)

    printed = sens.markdown_table(run())
    study = json.loads((out / "sensitivity.json").read_text())
    assert (out / "tornado.png").read_bytes()[:8] == PNG_MAGIC
    md = (out / "sensitivity.md").read_text()
    assert "| base | (defaults) |" in md and "`material.kes.f2_ratio=0.7`" in md
    assert "| base | (defaults) |" in printed
    results = {r["name"]: r for r in read_results(out / "results.csv")}
    assert sorted(results) == ["base", "friction_off.off", "friction_order.high",
                               "friction_order.low"]
    assert results["friction_off.off"]["material.friction"] == "false"
    base = float(results["base"]["DC_percent"])
    for f in study["factors"]:
        for lv in f["levels"]:
            assert isinstance(lv["dDC"], float) and math.isfinite(lv["dDC"])
            assert lv["dDC"] == pytest.approx(float(results[lv["name"]]["DC_percent"]) - base,
                                              abs=1e-12)
    # the same study again keeps every finished run; another --set is another study
    run(resume=True)
    assert len(read_results(out / "results.csv")) == 4
    with pytest.raises(sens.StudyError, match="use a new --out"):
        run([*tiny_cusick, "model.damping.alpha=5"], resume=True)


def test_fold_preference_names_the_frictionless_state_of_least_energy(tmp_path):
    """Π = U + V from each run's summary.json; the sentence names the lowest frictionless Π,
    whatever friction-on runs reach (hand-made records)."""
    records = []
    for name, n, friction, nodes, U, V in (("a", 4, "false", 8, 0.5e-3, -1.52e-3),
                                           ("b", 6, "false", 6, 0.4e-3, -1.50e-3),
                                           ("c", 6, "true", 6, 0.1e-3, -2.00e-3)):
        run = tmp_path / "runs" / name
        run.mkdir(parents=True)
        (run / "summary.json").write_text(json.dumps({"final": {"strain": U, "external_potential": V}}))
        records.append({"name": name, "load.perturbation.n_lobes": str(n), "material.friction": friction,
                        "status": "settled", "nodes": str(nodes), "DC_percent": "50",
                        "settling_time_s": "1", "run_dir": f"runs/{name}"})
    table = folds.energy_table(tmp_path, records)
    assert [(r["imposed"], r["friction"]) for r in table] == [(6, True), (4, False), (6, False)]
    assert table[1]["Pi"] == pytest.approx(0.5e-3 - 1.52e-3, abs=1e-15)
    text = folds.markdown(table)
    assert "lowest energy is the 6-node state (imposed 6, Π = -1.1000 mJ)" in text
    folds.energy_figure(table, "t", measured=5).savefig(tmp_path / "p.png")
    assert (tmp_path / "p.png").read_bytes()[:8] == PNG_MAGIC
    assert folds.measured_nodes(WOOL) == 5


@pytest.mark.slow
def test_fold_preference_tiny_runs_each_mode_with_and_without_friction(tmp_path, tiny_cusick):
    out = tmp_path / "folds"
    text = folds.run_fold_preference(WOOL, [2, 3], out, overrides=tiny_cusick, workers=2)
    results = {r["name"]: r for r in read_results(out / "results.csv")}
    assert sorted(results) == ["n2_friction", "n2_frictionless", "n3_friction", "n3_frictionless"]
    assert results["n3_frictionless"]["load.perturbation.n_lobes"] == "3"
    assert results["n3_frictionless"]["material.friction"] == "false"
    md = (out / "fold_preference.md").read_text()
    assert md.count("| completed |") == 4 and "Π = U + V" in text and md == text + "\n"
    assert (out / "fold_preference.png").read_bytes()[:8] == PNG_MAGIC
