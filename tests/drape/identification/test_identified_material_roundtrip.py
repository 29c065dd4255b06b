"""The identified fabric's material.toml, given as the base case's ``[material] path``, builds
the material the identification's runs of the point built: the base case's G (the set-up's
G12 = 25 N/m of cases/cusick_lowered.toml, not the membrane's default 50 N/m), thickness and
the rest travel with it, in the ``[kes]`` form and in the law-table form."""
from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from constitutive.units import to_si
from drape.case.build import build_material
from drape.case.case import load_case
from drape.identification.outputs import _built, material_file
from drape.identification.parameters import full_point, overrides

ROOT = Path(__file__).resolve().parents[3]
BASE = ROOT / "cases" / "cusick_lowered.toml"
W = 12.5                       # mg/cm², the base case's own weight
G_BASE = 0.45                  # gf/(cm·deg), the base case's [material.kes] G
INTERVALS = {"bending_length": {"low": 1.6, "high": 2.0}}


def point_of(**free):
    return full_point(free, list(free))


def write(tmp_path, point, sets=()):
    """material.toml of ``point`` as ``finish`` writes it, and the definition it came from."""
    definition = {"base": str(BASE), "set": list(sets)}
    path = material_file(tmp_path / "material.toml", definition, point, W, 0.3, INTERVALS, 3)
    return path, definition


def base_with_file(tmp_path, path) -> Path:
    """The base case with its whole [material] table replaced by ``path = <path>``."""
    data = tomllib.loads(BASE.read_text())
    data["material"] = {"path": str(path)}
    case = tmp_path / "on_base.toml"
    case.write_text(tomli_w.dumps(data))
    return case


def assert_same_material(a, b, rtol=1e-9):
    """Laws, membrane, areal mass, thickness and twist of two built materials (SI) agree."""
    def fields(m):
        out = {k: getattr(m, k) for k in ("areal_mass", "thickness", "twist_rigidity",
                                           "E11", "E22", "nu12", "G12")}
        for d in ("warp", "weft"):
            law = getattr(m, d)
            for k in ("k1", "k3", "d", "m", "k1_neg", "k3_neg"):
                out[f"{d}.{k}"] = getattr(law, k)
            for k in ("f1", "f2", "eps_f", "eta"):
                out[f"{d}.{k}"] = None if law.friction is None else getattr(law.friction, k)
        return out

    fa, fb = fields(a), fields(b)
    assert [k for k in fa if fa[k] is None] == [k for k in fb if fb[k] is None]
    keys = [k for k in fa if fa[k] is not None]
    np.testing.assert_allclose(np.array([fa[k] for k in keys], dtype=float),
                               np.array([fb[k] for k in keys], dtype=float), rtol=rtol, atol=0.0,
                               err_msg=f"fields: {keys}")
    assert a.tensile == b.tensile
    np.testing.assert_allclose(a.membrane_tension, b.membrane_tension, rtol=rtol)


def test_the_base_cases_shear_travels_in_the_kes_table(tmp_path):
    """(a) shear_G not freed: the file carries the base's G, so G12 = 25 N/m on the base case."""
    point = point_of(bending_length=1.8, hysteresis=0.6)
    path, definition = write(tmp_path, point)
    data = tomllib.loads(path.read_text())
    assert "kes" in data and "warp" not in data
    assert data["kes"]["G"] == G_BASE and data["thickness"] == 0.3
    built = _built(definition, point, W)
    on_base = build_material(load_case(base_with_file(tmp_path, path)))
    assert_same_material(on_base, built)
    assert on_base.G12 == pytest.approx(to_si(G_BASE, "G")) and on_base.G12 == pytest.approx(25.28, abs=0.01)
    assert on_base.thickness == pytest.approx(3e-4)


def test_a_freed_shear_rigidity_is_the_points(tmp_path):
    """(b) shear_G freed: the point's G, not the base's."""
    point = point_of(bending_length=1.8, hysteresis=0.6, shear_G=1.2)
    path, definition = write(tmp_path, point)
    assert tomllib.loads(path.read_text())["kes"]["G"] == 1.2
    on_base = build_material(load_case(base_with_file(tmp_path, path)))
    assert_same_material(on_base, _built(definition, point, W))
    assert on_base.G12 == pytest.approx(to_si(1.2, "G"))


@pytest.mark.parametrize("free", [
    {"bending_length": 1.8, "face_down": 1.3},            # (c) a face-down ratio: no [kes] form
    {"bending_length": 0.4},                               # B below a KES sheet's range at W
    {"bending_length": 0.4, "face_down": 0.7, "shear_G": 2.0},
])
def test_law_tables_carry_the_membrane(tmp_path, free):
    """(c) the law-table form: [warp]/[weft] and the shear in [membrane] (G12 in N/m)."""
    point = point_of(**free)
    path, definition = write(tmp_path, point)
    data = tomllib.loads(path.read_text())
    assert "warp" in data and "weft" in data and "kes" not in data
    g = free.get("shear_G", G_BASE)
    assert data["membrane"]["G12"] == pytest.approx(to_si(g, "G"), rel=1e-9)
    on_base = build_material(load_case(base_with_file(tmp_path, path)))
    assert_same_material(on_base, _built(definition, point, W))
    if "face_down" in free:
        assert on_base.warp.k1_neg == pytest.approx(free["face_down"] * on_base.warp.k1)


@pytest.mark.parametrize("free", [{"bending_length": 1.8}, {"bending_length": 1.8, "face_down": 1.3}])
def test_the_definitions_settings_of_the_material_travel(tmp_path, free):
    """``--set`` items of the identification on the material (a friction length, a tensile
    strain, a membrane stiffness of [model.membrane], a bias rigidity) are in the file too."""
    sets = ["material.kes.eps_f=0.3", "material.kes.EMT_warp=5.0", "model.membrane.E22=3000",
            "material.kes.B_bias=0.06"]
    point = point_of(**free)
    path, definition = write(tmp_path, point, sets)
    on_base = build_material(load_case(base_with_file(tmp_path, path)))
    assert_same_material(on_base, _built(definition, point, W))
    assert on_base.E22 == 3000.0 and on_base.warp.friction.eps_f == pytest.approx(30.0)


#: The base case shrunk to a short, coarse run (as the other Cusick tests shrink it).
SMALL = ["mesh.n_radial=2", "mesh.n_circumferential=16", "solver.t_end=0.8", "solver.dt=0.1",
         "load.perturbation.duration=0.5", "output.every_dt=0.8"]


@pytest.mark.slow
def test_the_file_drapes_as_the_runs_did(tmp_path):
    """End to end: the written file on the shrunk base case gives the drape coefficient of the
    shrunk base case with the point's overrides (what a forward run of the point loads). About
    12 s; at G12 = 50 N/m the runs' DC is 1.3 points higher."""
    from drape.run.runner import run_case

    point = point_of(bending_length=1.8, hysteresis=0.6)
    path, _ = write(tmp_path, point)
    runs = load_case(BASE, SMALL + [f"material.kes.weight={W:g}"] + overrides(point, W))
    on_base = load_case(base_with_file(tmp_path, path), SMALL)
    dc = [run_case(case, tmp_path / name, quiet=True)["analysis"]["drape_coefficient_percent"]
          for name, case in (("runs", runs), ("file", on_base))]
    assert dc[0] == pytest.approx(dc[1], abs=1e-6)
    assert 0 < dc[0] < 100


# ------------------------------------------------ a law-table file's membrane ([membrane] tables)
LAWS = """name = "x"
weight = 12.5
[warp]
k1 = 0.08
[weft]
k1 = 0.06
"""


def test_a_law_table_file_gives_its_tensile_curve_and_shear(tmp_path):
    """[membrane.tensile_warp] builds E11 as a tensile curve (its secant as the number, its
    tangent at a drape's tension), G12 the shear; the weft keeps the default curve."""
    from constitutive.material import load_material
    from constitutive.tensile import DEFAULT_TENSILE, TensileCurve

    path = tmp_path / "m.toml"
    path.write_text(LAWS + "[membrane]\nG12 = 25.0\n[membrane.tensile_warp]\n"
                           "strain_at_max = 0.05\nlinearity = 0.7\nmax_load = 490\n")
    m = load_material(path)
    curve = TensileCurve(0.05, 0.7, 490.0)
    assert m.tensile == {"E11": curve, "E22": DEFAULT_TENSILE}
    assert m.E11 == pytest.approx(curve.secant) and m.G12 == 25.0
    assert "tensile curve" in m.membrane_source["E11"]
    assert m.at_tension(0.05).E11 == pytest.approx(curve.tangent(0.05))


@pytest.mark.parametrize("extra, words", [
    ("[membrane]\nE11 = 5000.0\n[membrane.tensile_warp]\nstrain_at_max = 0.05\nlinearity = 0.7\n",
     "membrane.E11 and [membrane.tensile_warp] both give E11"),
    ("[membrane.tensile_weft]\nstrain_at_max = 0.05\nlinearity = 2.5\n", "linearity"),
    ("[membrane.tensile_weft]\nstrain_at_max = -0.05\nlinearity = 0.7\n", "strain_at_max"),
    ("[membrane.tensile_weft]\nlinearity = 0.7\n", "strain_at_max"),
    ("[membrane.tensile_weft]\nstrain_at_max = 0.05\nlinearity = 0.7\nEMT = 5\n", "EMT"),
    ("[kes]\nB_warp = 0.08\nB_weft = 0.06\nHB2_warp = 0.04\nHB2_weft = 0.03\nEMT_weft = 5.0\n"
     "[membrane.tensile_weft]\nstrain_at_max = 0.05\nlinearity = 0.7\n",
     "[membrane.tensile_weft] and the [kes] values that build it are both given"),
])
def test_a_membrane_table_that_breaks_a_rule_is_refused(tmp_path, extra, words):
    from constitutive.material import MaterialError, load_material

    path = tmp_path / "m.toml"
    path.write_text(LAWS + extra)
    with pytest.raises(MaterialError, match=None) as err:
        load_material(path)
    assert words in str(err.value)
