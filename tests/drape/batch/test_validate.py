"""The validation command's plumbing on the real validation cases made tiny (12 triangles, two
time steps): ensembles per fabric, the side-by-side table, validation.json and the PNG."""
from __future__ import annotations

import json
import shutil
import statistics
from pathlib import Path

import pytest

from drape.batch import validation_set as validate
from drape.cli import validate as validate_cli
from drape.case.case import load_case
from drape.batch.rows import read_results, read_table

ROOT = Path(__file__).resolve().parents[3]
CASES = ROOT / "cases" / "validation"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_the_validation_cases_are_the_published_fabrics():
    """Matsudaira et al. (2015) Tables 1-2 as the secondary copy gives them."""
    cases = {p.stem: c for p, c in validate.validation_cases(CASES)}
    assert sorted(cases) == ["cotton_broadcloth", "wool_tropical"]
    expected = {"cotton_broadcloth": (0.118, 0.124, 12.38, 0.497, 82.9, 2),
                "wool_tropical": (0.067, 0.033, 16.29, 0.407, 49.8, 5)}
    for name, (B, HB2, W, T, DC, nodes) in expected.items():
        kes, measured = cases[name].material.kes, cases[name].measured
        assert (kes.B_warp, kes.B_weft, kes.HB2_warp, kes.HB2_weft) == (B, B, HB2, HB2)
        assert (kes.weight, kes.thickness) == (W, T)
        assert (measured.DC_percent, measured.nodes) == (DC, nodes)
        assert "Matsudaira" in measured.source
        assert (cases[name].mesh.specimen_diameter, cases[name].mesh.disc_diameter) == (0.254, 0.127)


def test_the_cotton_anisotropy_table_splits_the_sheet_about_the_mean_each_row_names():
    """cases/cotton_anisotropy.csv: each row a valid case, its B and 2HB split warp : weft as its
    name says, about the geometric or the arithmetic mean of the printed 0.118 and 0.124."""
    rows = read_table(ROOT / "cases" / "cotton_anisotropy.csv")
    assert len(rows) == 10
    for row in rows:
        kes = load_case(CASES / "cotton_broadcloth.toml", row.overrides()).material.kes
        for warp, weft, printed in ((kes.B_warp, kes.B_weft, 0.118), (kes.HB2_warp, kes.HB2_weft, 0.124)):
            if row.name == "unsplit" or (row.name.endswith("_B_only") and printed == 0.124):
                assert warp == weft == printed
                continue
            ratio = float(row.name.split("_")[1].split("to")[0])
            assert warp / weft == pytest.approx(ratio, rel=1e-4), row.name
            mean = (warp * weft) ** 0.5 if row.name.startswith("geometric") else (warp + weft) / 2
            assert mean == pytest.approx(printed, rel=1e-4), row.name


@pytest.mark.slow
def test_validate_runs_every_case_as_an_ensemble_and_compares(tmp_path, capsys, tiny_cusick):
    out = tmp_path / "validation"
    code = validate_cli.main([str(CASES), "--seeds", "2", "--out", str(out), "--workers", "1",
                          "--quiet", *sum((["--set", o] for o in tiny_cusick), [])])
    assert code == 0
    printed = capsys.readouterr().out.splitlines()
    records = json.loads((out / "validation.json").read_text())
    assert [r["name"] for r in records] == ["cotton_broadcloth", "wool_tropical"]
    for r, line in zip(records, printed[1:3]):
        case = load_case(r["case"])
        assert r["measured"] == case.measured.model_dump()
        results = read_results(out / r["name"] / "results.csv")
        assert sorted(x["name"] for x in results) == [f"{r['name']}.s0", f"{r['name']}.s1"]
        dc = [float(x["DC_percent"]) for x in results]
        sim = r["simulated"]
        assert sim["DC_percent"]["mean"] == pytest.approx(statistics.fmean(dc), rel=1e-14)
        assert sim["DC_percent"]["std"] == pytest.approx(statistics.stdev(dc), rel=1e-12, abs=1e-12)
        assert r["setup"] == "25.4 cm on 12.7 cm" and Path(r["top_view_vtu"]).exists()
        # the printed line: name, simulated mean, measured DC and the difference
        delta = sim["DC_percent"]["mean"] - case.measured.DC_percent
        assert line.split()[0] == r["name"] and f"{sim['DC_percent']['mean']:.1f}" in line
        assert f"{case.measured.DC_percent:.1f}" in line and f"{delta:+.1f}" in line
    assert printed[0].split()[:3] == ["fabric", "setup", "seeds"]
    png = (out / "validation.png").read_bytes()
    assert png.startswith(PNG_MAGIC)
    width = int.from_bytes(png[16:20], "big")
    height = int.from_bytes(png[20:24], "big")
    assert width > 1.5 * height            # two panels side by side


def test_a_folder_without_validation_cases_is_refused(tmp_path, capsys):
    assert validate_cli.main([str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    assert "no case files" in capsys.readouterr().err
    shutil.copy(ROOT / "cases" / "cusick_kes.toml", tmp_path / "plain.toml")
    assert validate_cli.main([str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    assert "plain.toml: a validation case needs case.analysis = 'cusick' and a [measured] table" \
        in capsys.readouterr().err
