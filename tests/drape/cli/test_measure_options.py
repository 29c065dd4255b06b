"""``drape measure``'s options and output folder: each problem one line on stderr naming the
option or the scan, exit 2 for bad input and 4 for a folder that cannot be written, checked
before any scan is measured; a flaw a scan is measured in spite of, one warning line."""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from drape.cli import measure as measure_cli
from drape.cli.measure import main


@pytest.fixture
def scan(tmp_path, drape_surface):
    return drape_surface(centre=(0.004, -0.003)).write(tmp_path / "drape.ply")


def _run(argv, capsys) -> tuple[int, str, list[str]]:
    """Exit code (an option error exits from the parser, as under ``python -m``), stdout and
    the lines of stderr."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:
        code = exc.code
    captured = capsys.readouterr()
    return code, captured.out, captured.err.splitlines()


@pytest.mark.parametrize("option, words", [
    (["--specimen", "30"], "argument --specimen: 30 m is no specimen diameter: 10 cm to 1 m "
                           "(a bare number is metres: write 30cm)"),
    (["--disc", "1cm"], "argument --disc: 0.01 m is no disc diameter"),
    (["--top-band", "0.3"], "argument --top-band: 0.3 m is no top band: 1 µm to 2 cm (a bare "
                            "number is metres: write 0.3cm or 0.3mm)"),
    (["--scale", "-1"], "argument --scale: '-1': the scale must be a positive number"),
    (["--centre", "1"], "argument --centre: '1': give the centre as x,y"),
    (["--frobnicate"], "unrecognized arguments: --frobnicate"),
    (["--specimen", "20cm", "--disc", "20cm"], "--specimen 0.2 m must be larger than --disc 0.2 m"),
])
def test_an_option_error_is_one_line_and_exit_2(scan, capsys, option, words):
    code, out, err = _run([scan, *option], capsys)
    assert (code, out, len(err)) == (2, "", 1), err
    assert err[0].startswith("error: ") and words in err[0]


def test_the_help_says_what_a_bare_number_is(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "a bare number is metres; 0.1 to 1 m" in text
    assert "4 --out cannot be written" in text


@pytest.mark.parametrize("where", ["file", "under a file", "proc"])
def test_an_output_folder_that_cannot_be_written_is_exit_4_before_measuring(
        scan, tmp_path, capsys, monkeypatch, where):
    measured = []
    monkeypatch.setattr(measure_cli, "measure_scan", lambda *a, **k: measured.append(a))
    (tmp_path / "taken").write_text("x")
    out = {"file": tmp_path / "taken", "under a file": tmp_path / "taken" / "out",
           "proc": Path("/proc/drape-measure-out")}[where]
    if where == "proc" and not Path("/proc/self").is_dir():
        pytest.skip("no /proc")
    before = sorted(os.listdir(tmp_path))
    code, out_text, err = _run([scan, "--out", out], capsys)
    assert (code, out_text, len(err), measured) == (4, "", 1, []), err
    assert err[0].startswith(f"error: --out {out}: ")
    assert sorted(os.listdir(tmp_path)) == before


def test_a_failure_to_write_comes_after_the_table(scan, tmp_path, capsys, monkeypatch):
    def full(*args):
        raise OSError(28, "No space left on device", str(tmp_path / "out" / "measure.json"))

    monkeypatch.setattr(measure_cli, "write_outputs", full)
    code, out, err = _run([scan, "--out", tmp_path / "out"], capsys)
    assert code == 4 and out.splitlines()[2].split()[0] == "drape"
    assert err == [f"error: No space left on device: '{tmp_path / 'out' / 'measure.json'}'"]


def test_a_folder_given_as_a_scan_is_called_a_folder(scan, tmp_path, capsys):
    code, out, err = _run([tmp_path, scan], capsys)
    assert code == 2 and err == [f"error: {tmp_path}: is a folder, not a mesh file"]
    assert out.splitlines()[-1].split()[0] == "drape"


def test_the_stated_disc_against_the_flat_top_names_both(scan, capsys):
    code, out, err = _run([scan, "--disc", "12cm"], capsys)
    assert (code, out, len(err)) == (2, "", 1)
    assert "flat disc top found is 18 cm across, the stated disc 12 cm" in err[0]


def test_a_warning_is_one_line_and_in_the_json(tmp_path, drape_surface, capsys):
    d = drape_surface()
    d.points[:, 2] *= -1.0
    path = d.write(tmp_path / "upside.ply")
    code, out, err = _run([path, "--json"], capsys)
    assert code == 0 and len(err) == 1 and err[0].startswith(f"warning: {path}: upside down")
    (scan,) = json.loads(out)["scans"]
    assert scan["warnings"] == [err[0][len("warning: "):]]
    assert scan["drape_coefficient_percent"] == pytest.approx(d.dc_percent, abs=0.2)
