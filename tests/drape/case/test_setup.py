"""One Cusick set-up: every Cusick case is built on cases/setups/cusick.toml, and differs from the
others only by what is its own (the fabric, the measurement, a tester's diameters)."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

from drape.case.build import build
from drape.case.case import CaseError, dump_case, load_case
from drape.identification.definition import DEFAULT_BASE

ROOT = Path(__file__).resolve().parents[3]
CASES = ROOT / "cases"
SETUP = CASES / "setups" / "cusick.toml"

#: Every Cusick drape a user runs from a sheet, a scan or a catalogue.
CUSICK_CASES = sorted([CASES / "cusick_kes.toml", CASES / "cusick_lowered.toml", DEFAULT_BASE,
                       *(CASES / "validation").glob("*.toml")])

#: What a case on the set-up may give of its own.
OWN = ("case", "material", "measured")
TESTER = ("specimen_diameter", "disc_diameter")


def _set_up_of(path) -> dict:
    """The loaded case without what is the case's own (fabric, measurement, tester diameters)."""
    case = tomllib.loads(dump_case(load_case(path)))
    for key in OWN:
        case.pop(key, None)
    for key in TESTER:
        case["mesh"].pop(key)
    return case


def test_every_cusick_case_is_the_one_set_up_up_to_its_own_values():
    reference = _set_up_of(CASES / "cusick_kes.toml")
    assert reference["contact"]["body"][0]["point"] == "resting"
    for path in CUSICK_CASES:
        assert tomllib.loads(Path(path).read_text())["setup"] == "cusick", path
        assert _set_up_of(path) == reference, path


def test_the_thesis_fabrics_are_the_set_up_with_its_stand_in_shear_written_out():
    """A law table takes nothing from the set-up's sheet, so its case writes out the set-up's G."""
    reference = _set_up_of(CASES / "cusick_kes.toml")
    G = load_case(CASES / "cusick_kes.toml").material.kes.G           # gf/(cm·deg)
    G12 = G * 9.80665e-3 / 1e-2 * 180 / math.pi                      # N/m per radian
    for name in ("cusick_fabric1.toml", "cusick_fabric2.toml"):
        case = _set_up_of(CASES / name)
        assert case["model"].pop("membrane") == {"G12": pytest.approx(G12, rel=1e-3)}
        case["model"]["friction_tangent"] = reference["model"]["friction_tangent"]   # the weft law's
        assert case == reference, name


def test_every_cusick_case_file_in_the_cases_folder_names_the_set_up():
    """No second Cusick set-up hides among the shipped cases (the thesis fabrics included)."""
    for path in sorted(CASES.rglob("*.toml")):
        data = tomllib.loads(path.read_text())
        if data.get("mesh", {}).get("kind") == "cusick" and "setups" not in path.parts:
            assert "setup" in data, f"{path.relative_to(ROOT)} is a Cusick case off the set-up"


def test_a_sheet_without_G_takes_the_set_ups_and_one_with_G_keeps_its_own(tmp_path):
    setup_G = tomllib.loads(SETUP.read_text())["material"]["kes"]["G"]
    assert load_case(CASES / "cusick_kes.toml").material.kes.G == setup_G
    own = tmp_path / "own.toml"
    own.write_text((CASES / "cusick_kes.toml").read_text() + "G = 1.2\n")   # a copy keeps its set-up
    assert load_case(own).material.kes.G == 1.2


def test_a_named_material_takes_nothing_from_the_set_ups_sheet(tmp_path):
    case = tmp_path / "named.toml"
    case.write_text(f'setup = "{SETUP.as_posix()}"\n[case]\nname = "n"\nanalysis = "cusick"\n'
                    '[material]\nname = "fabric1"\n')
    loaded = load_case(case)
    assert loaded.material.name == "fabric1" and loaded.material.kes is None
    assert loaded.contact is not None and loaded.load.gravity.ramp_time == 0.0


@pytest.mark.parametrize("path", [p for p in CUSICK_CASES if "validation" in Path(p).parts])
def test_the_support_lies_where_this_fabric_rests(path):
    """``point = "resting"``: half the fabric's own thickness plus half the barrier layer below
    the flat specimen, computed here from the case's values, not the set-up's."""
    case = load_case(path, ["mesh.n_radial=2", "mesh.n_circumferential=16"])
    support = {b.name: b for b in build(case).model.contact.scene.bodies}["support"]
    expected = 0.5 * case.material.kes.thickness * 1e-3 + 0.5 * case.contact.dhat
    assert support.point == pytest.approx([0.0, 0.0, -expected], abs=1e-15)


@pytest.mark.parametrize("text, words", [
    ('setup = 3\n', "setup = 3: must be a bundled set-up's name"),
    ('setup = "missing.toml"\n', "set-up file .*missing.toml' does not exist"),
    ('setup = "nosuch"\n', "set-up file .*setups/nosuch.toml' does not exist"),
    ('setup = "inner.toml"\n', "names a set-up of its own"),
])
def test_a_bad_set_up_is_one_clear_error(tmp_path, text, words):
    (tmp_path / "inner.toml").write_text('setup = "other.toml"\n')
    case = tmp_path / "case.toml"
    case.write_text(text + '[case]\nname = "x"\n')
    with pytest.raises(CaseError, match=words):
        load_case(case)


def test_a_resting_support_must_face_up(tmp_path):
    case = tmp_path / "case.toml"
    case.write_text((CASES / "cusick_kes.toml").read_text()
        + '[[contact.body]]\nname = "support"\nshape = "half_space"\npoint = "resting"\n'
          'normal = [0, 1, 0]\n')
    with pytest.raises(CaseError, match="normal must be"):
        load_case(case)
