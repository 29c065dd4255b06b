"""``drape identify`` checks every option, the scans and the base case before anything is
written or started: a problem is one line on stderr naming the option (exit 2 for bad input,
4 for a folder that cannot be written), and leaves nothing behind; what it saves for
``--resume`` is what it checked, and a definition saved with values now refused can be
corrected with ``--resume`` and the options.

The forward runs are not started: the cluster is a stand-in and the search is stopped as
Ctrl-C stops it, once the definition is saved (exit 130).
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from drape.cli.identify import main
from drape.identification import identify as identify_module
from drape.identification.definition import DEFINITION

ROOT = Path(__file__).resolve().parents[3]
CASE = ROOT / "cases" / "cusick_kes.toml"


def _interrupted(*args, **kwargs):
    raise KeyboardInterrupt


def _run(argv, capsys) -> tuple[int, list[str]]:
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:       # an option the parser refuses
        code = exc.code
    return code, capsys.readouterr().err.splitlines()


def _start(scan, out, *extra) -> list:
    return [scan, "--base", CASE, "--out", out, *extra]


@pytest.mark.parametrize("extra, code, words", [
    (["--design", "-1"], 2, "--design = -1: must be a whole number from 0 to 100"),
    (["--design", "1000000000"], 2, "--design = 1000000000: must be a whole number from 0 to 100"),
    (["--weight", "0"], 2, "--weight 0.0: outside 1–100 mg/cm²"),
    (["--weight", "-3"], 2, "--weight -3.0: outside 1–100 mg/cm²"),
    (["--seeds", "0"], 2, "--seeds = 0: must be a whole number from 1 to 100"),
    (["--evaluations", "x"], 2, "argument --evaluations: invalid int value: 'x'"),
    (["--converged-within", "nan"], 2, "--converged-within = nan: must lie in [0, 1)"),
    (["--box", "bending_length=1,inf"], 2, "--box bending_length=1,inf: bending_length must lie "
                                          "within 0.1..20 cm"),
    (["--scale", "0"], 2, "--scale = 0.0: must be a positive number"),
    (["--workers", "0"], 2, "--workers = 0: must be from 1 to 256"),
    (["--set", "mesh.n_radial=-1"], 2, "mesh.n_radial = -1"),
    (["--library", "{tmp}/taken"], 4, "--library {tmp}/taken: a file is in the way, not a folder"),
    (["--library", "{tmp}/id"], 2, "--library {tmp}/id: must not be the output folder --out"),
])
def test_a_bad_option_is_one_line_and_writes_nothing(scan, tmp_path, capsys, no_runs, extra,
                                                     code, words):
    (tmp_path / "taken").write_text("x")
    extra = [e.format(tmp=tmp_path) for e in extra]
    got, err = _run(_start(scan, tmp_path / "id", *extra), capsys)
    assert (got, len(err)) == (code, 1), err
    assert err[0].startswith("error: ") and words.format(tmp=tmp_path) in err[0]
    assert not (tmp_path / "id").exists()


def test_an_output_folder_in_a_file_is_exit_4(scan, tmp_path, capsys, no_runs):
    (tmp_path / "taken").write_text("x")
    code, err = _run(_start(scan, tmp_path / "taken" / "id"), capsys)
    assert code == 4 and err == [f"error: --out {tmp_path / 'taken' / 'id'}: {tmp_path / 'taken'} "
                                 "is a file, not a folder"]


def test_a_scan_in_millimetres_is_told_the_option_identify_has(tmp_path, capsys, no_runs,
                                                                 drape_surface):
    scan = drape_surface(n_folds=5, n_sectors=120, n_rings=3).write(tmp_path / "mm.ply", 1000.0)
    code, err = _run(_start(scan, tmp_path / "id"), capsys)
    assert code == 2 and len(err) == 1 and "pass --scale 0.001" in err[0]
    assert not (tmp_path / "id").exists()
    code, err = _run(_start(scan, tmp_path / "id", "--scale", "0.001"), capsys)
    assert code == 130, err
    assert json.loads((tmp_path / "id" / DEFINITION).read_text())["scale"] == 0.001


def test_resume_of_a_folder_without_an_identification_says_so(tmp_path, capsys):
    code, err = _run(["--resume", "--out", tmp_path], capsys)
    assert code == 2 and err == [f"error: --resume: {tmp_path} holds no identification (no "
                                 f"{DEFINITION}); start one with SCAN ... --out "
                                 f"{tmp_path}"]


def test_ctrl_c_names_only_what_exists(scan, tmp_path, capsys, no_runs, monkeypatch):
    out = tmp_path / "id"
    code, err = _run(_start(scan, out), capsys)
    assert code == 130 and err[-1] == (f"identification interrupted; no evaluation had finished "
                                       f"(continue with --resume --out {out})")
    (out / "evaluations.csv").write_text("name\n")
    code, err = _run(["--resume", "--out", out], capsys)
    assert code == 130 and err[-1] == (f"identification interrupted; finished evaluations are in "
                                       f"{out / 'evaluations.csv'} (continue with --resume)")
    monkeypatch.setattr(identify_module, "scan_drapes", _interrupted)
    code, err = _run(_start(scan, tmp_path / "new"), capsys)
    assert code == 130 and err[-1] == "identification interrupted; nothing was written"
    assert not (tmp_path / "new").exists()


def test_what_is_saved_is_what_was_checked(scan, tmp_path, capsys, no_runs):
    out = tmp_path / "id"
    code, _ = _run(_start(scan, out, "--weight", "124 g/m^2", "--free", "bending_length",
                          "bending_length", "--design", "0"), capsys)
    assert code == 130
    saved = json.loads((out / DEFINITION).read_text())
    assert saved["weight"] == pytest.approx(12.4) and saved["free"] == ["bending_length"]
    assert saved["box"] == {"bending_length": [0.6, 3.0]} and saved["design"] == 0
    assert saved["scans"] == [str(scan.resolve())] and saved["bundled_library"] is True


def test_resume_changes_the_budget_only(scan, tmp_path, capsys, no_runs):
    out = tmp_path / "id"
    assert _run(_start(scan, out), capsys)[0] == 130
    code, _ = _run(["--resume", "--out", out, "--evaluations", "20"], capsys)
    assert code == 130 and json.loads((out / DEFINITION).read_text())["evaluations"] == 20
    code, err = _run(["--resume", "--out", out, "--seeds", "3"], capsys)
    assert code == 2 and "defines another identification" in err[0]
    assert json.loads((out / DEFINITION).read_text())["seeds"] == 2


@pytest.mark.parametrize("key, bad, option, good", [
    ("design", -1, "--design", "2"), ("weight", 0, "--weight", "12.5"),
    ("design", 1000000000, "--design", "1"),
])
def test_a_definition_saved_with_a_value_now_refused_is_corrected_by_resume(
        scan, tmp_path, capsys, no_runs, key, bad, option, good):
    out = tmp_path / "id"
    assert _run(_start(scan, out), capsys)[0] == 130
    saved = json.loads((out / DEFINITION).read_text())
    (out / DEFINITION).write_text(json.dumps({**saved, key: bad}))
    code, err = _run(["--resume", "--out", out], capsys)
    assert code == 2 and len(err) == 1
    assert f"holds a value now refused: {option}" in err[0] and "give the corrected options" in err[0]
    code, err = _run(["--resume", "--out", out, option, good], capsys)
    assert code == 130, err
    assert json.loads((out / DEFINITION).read_text())[key] == pytest.approx(float(good))


def test_an_unreadable_definition_is_replaced_by_the_options(scan, tmp_path, capsys, no_runs):
    out = tmp_path / "id"
    out.mkdir()
    (out / DEFINITION).write_text("{cut")
    code, err = _run(["--resume", "--out", out], capsys)
    assert code == 2 and "cannot be read" in err[0]
    code, err = _run(["--resume", *_start(scan, out)], capsys)
    assert code == 130, err
    assert json.loads((out / DEFINITION).read_text())["base"] == str(CASE.resolve())


def test_a_library_that_became_a_file_is_given_anew_with_resume(scan, tmp_path, capsys, no_runs):
    out, library = tmp_path / "id", tmp_path / "lib"
    assert _run(_start(scan, out, "--library", library), capsys)[0] == 130
    assert not library.exists()        # made when the first evaluation is added to it
    library.write_text("x")
    code, err = _run(["--resume", "--out", out], capsys)
    assert code == 4 and err == [f"error: --library {library}: a file is in the way, not a folder"]
    code, err = _run(["--resume", "--out", out, "--library", tmp_path / "lib2"], capsys)
    assert code == 130, err
    assert json.loads((out / DEFINITION).read_text())["library"] == str(tmp_path / "lib2")
