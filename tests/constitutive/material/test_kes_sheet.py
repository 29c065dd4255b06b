"""A KES-F sheet as input: units as printed, unit slips refused, the membrane built from the
sheet against closed forms, and summary.json saying where each membrane value comes from."""
from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from scipy.integrate import quad

from constitutive.material.kes_sheet import read_sheet_value
from constitutive.material.spec import KesFabricSpec
from constitutive.material import MaterialError, load_material
from drape.case.build import build_material
from drape.case.case import CaseError, load_case

ROOT = Path(__file__).resolve().parents[3]
CUSICK_KES = ROOT / "cases" / "cusick_kes.toml"
GF = 9.80665e-3   # N


# --------------------------------------------------------------------------- units
@pytest.mark.parametrize("given", [12.38, "12.38 mg/cm^2", "123.8 g/m^2", "0.1238 kg/m^2",
                                   "0.01238 gf/cm^2", "1.214 N/m^2"])
def test_weight_is_read_in_mg_per_cm2_or_with_its_units(given):
    """One weight written six ways: the areal mass is 12.38 mg/cm² = 0.1238 kg/m² (the force
    per area ones divided by g0: 0.01238 gf/cm² is 0.01238 g/cm²; 1.214 N/m² is 0.12379 kg/m²)."""
    case = load_case(CUSICK_KES, [f"material.kes.weight={json.dumps(given)}"])
    assert build_material(case).areal_mass == pytest.approx(0.1238, rel=1e-3 if "N" in str(given) else 1e-12)


def test_thickness_is_read_in_mm():
    case = load_case(CUSICK_KES, ["material.kes.thickness=0.497"])
    assert build_material(case).thickness == pytest.approx(4.97e-4, rel=1e-12)
    case = load_case(CUSICK_KES, ['material.kes.thickness="0.0497 cm"'])
    assert build_material(case).thickness == pytest.approx(4.97e-4, rel=1e-12)


@pytest.mark.parametrize("key, value, slip, as_printed", [
    ("weight", 0.01238, "looks like gf/cm² (or g/cm²)", "12.38 mg/cm²"),
    ("weight", 0.1238, "looks like kg/m² (SI)", "12.38 mg/cm²"),
    ("thickness", 0.0497, "looks like cm", "0.497 mm"),
    ("B_warp", 1.157e-5, "looks like N·m (SI)", "0.118 gf·cm²/cm"),
    ("HB2_warp", 1.216e-4, "looks like N·m/m (SI)", "0.0124 gf·cm/cm"),
    ("G", 50.0, "looks like N/m per radian (SI)", "0.8899 gf/(cm·deg)"),
    ("EMT_warp", 0.054, "looks like a fraction", "5.4 %"),
])
def test_a_bare_number_in_the_wrong_unit_names_key_value_and_slip(key, value, slip, as_printed):
    with pytest.raises(CaseError) as err:
        load_case(CUSICK_KES, [f"material.kes.{key}={value}"])
    text = str(err.value)
    assert text.startswith(f"material.kes.{key} = {value}: outside ")
    assert slip in text and f"= {as_printed}" in text and "A KES sheet prints" in text


def test_a_value_out_of_range_with_explicit_units_says_so_without_guessing():
    with pytest.raises(CaseError, match=r"material.kes.weight = '5 g/m\^2': is 0.5 mg/cm²: "
                                        r"outside 1–100 mg/cm² of woven and knitted fabrics$"):
        load_case(CUSICK_KES, ['material.kes.weight="5 g/m^2"'])


def test_a_material_file_reads_weight_and_thickness_as_a_sheet_prints_them():
    """The library's fabrics keep their SI values (Lahey 2002 Table 4.2: 0.01715 gf/cm², 0.0254 cm)."""
    m = load_material("fabric1")
    assert m.areal_mass == pytest.approx(0.1715, rel=1e-12)
    assert m.thickness == pytest.approx(2.54e-4, rel=1e-12)


def test_the_catalogue_and_the_validation_fabrics_are_inside_the_ranges():
    """No real fabric is refused: the eight catalogue fabrics, the two validation fabrics."""
    rows = (ROOT / "cases" / "kes_catalogue.csv").read_text().splitlines()
    keys = [k.split(".")[-1] for k in rows[0].split(",")[1:]]
    for row in rows[1:]:
        values = dict(zip(keys, map(float, row.split(",")[1:])))
        KesFabricSpec(**values)
    for kind, value in (("B", 0.067), ("HB2", 0.033), ("weight", 16.29), ("thickness", 0.407),
                        ("B", 0.118), ("HB2", 0.124), ("weight", 12.38), ("thickness", 0.497)):
        assert read_sheet_value(kind, value) == value


# --------------------------------------------------------------------------- membrane
def membrane(**sheet):
    """The membrane a sheet builds, as the stiffness storing the tensile energy (a Cusick
    case would otherwise take the tangent at its skirt's tension:
    tests/constitutive/test_tensile.py)."""
    over = [f"material.kes.{k}={v}" for k, v in sheet.items()] + ["model.membrane_tension='secant'"]
    return build_material(load_case(CUSICK_KES, over)).describe()["membrane"]


def test_shear_rigidity_per_degree_becomes_g12_per_radian():
    """G = 1 gf/(cm·deg): 9.80665e-3 N per 1e-2 m per (π/180) rad = 56.188 N/m."""
    m = membrane(G=1.0)
    assert m["G12"]["value"] == pytest.approx(GF / 1e-2 * 180.0 / math.pi, rel=1e-12)
    assert m["G12"]["source"].startswith("KES G = 1 gf/(cm·deg)")
    assert m["E11"]["source"] == m["E22"]["source"] == "default"


@pytest.mark.parametrize("given", [("EMT", "WT"), ("EMT", "LT"), ("LT", "WT"), ("EMT", "LT", "WT")])
def test_tensile_stiffness_stores_the_measured_energy_at_the_measured_strain(given):
    """A J-shaped curve F = Fm (ε/εm)^n, εm = 6 %, n = 1.8, measured as KES-FB1 would: EMT,
    WT = ∫F dε (quadrature), LT = WT/(Fm εm/2). Any two of them give the linear stiffness with
    ½ E εm² = WT, i.e. E = 2 Fm/((n + 1) εm) (closed form) per unit width."""
    eps_m, n, fm = 0.06, 1.8, 500.0
    wt = quad(lambda e: fm * (e / eps_m) ** n, 0.0, eps_m)[0]
    sheet = {"EMT": 100 * eps_m, "WT": wt, "LT": wt / (fm * eps_m / 2)}
    m = membrane(**{f"{k}_weft": sheet[k] for k in given})
    assert m["E22"]["value"] == pytest.approx(2 * fm / ((n + 1) * eps_m) * GF / 1e-2, rel=1e-9)
    assert "KES EMT" in m["E22"]["source"] or "KES LT" in m["E22"]["source"]
    assert m["E11"]["source"] == "default"


def test_strain_alone_takes_the_default_linearity_and_a_direct_stiffness_is_taken_as_is():
    m = membrane(EMT_warp=5.0, E_weft=2000.0)
    assert m["E11"]["value"] == pytest.approx(0.65 * 500.0 / 0.05 * GF / 1e-2, rel=1e-12)
    assert "with the default LT = 0.65" in m["E11"]["source"]
    assert m["E22"]["value"] == pytest.approx(2000.0 * GF / 1e-2, rel=1e-12)


@pytest.mark.parametrize("over, message", [
    (["material.kes.LT_warp=0.6"], "material.kes.LT_warp alone does not give a stiffness: add "
                                   "material.kes.EMT_warp"),
    (["material.kes.EMT_warp=5", "material.kes.LT_warp=0.6", "material.kes.WT_warp=12"],
     "material.kes.EMT_warp = 5 %, material.kes.LT_warp = 0.6 and material.kes.WT_warp = 12 disagree"),
    (["material.kes.E_weft=2000", "material.kes.WT_weft=8"], "give material.kes.E_weft or the tensile"),
])
def test_incomplete_or_contradictory_tensile_values_are_refused(over, message):
    with pytest.raises(CaseError, match=message):
        load_case(CUSICK_KES, over)


def test_a_material_file_cannot_give_a_stiffness_twice(tmp_path):
    text = (ROOT / "cases" / "materials" / "kes_example.toml").read_text()
    path = tmp_path / "twice.toml"
    path.write_text(text.replace("eta = 0.5", "eta = 0.5\nG = 0.9"))
    with pytest.raises(MaterialError, match="membrane.G12 and the \\[kes\\] values that build it"):
        load_material(path)


def test_summary_json_says_which_membrane_values_came_from_the_sheet(tmp_path, tiny_cusick):
    """A tiny Cusick run of a sheet with G and the warp tensile values, E22 set by the case:
    the shell is built with them and summary.json names the source of each. E11 is the warp
    curve's tangent at the skirt's mean tension, checked here by differentiating the power
    law numerically at the strain where it carries that tension."""
    from scipy.optimize import brentq

    from drape.analyses.drape_coefficient import skirt_tension

    from drape.run.runner import run_case

    case = load_case(CUSICK_KES, [
        "material.kes.G=0.6", "material.kes.EMT_warp=4", "material.kes.LT_warp=0.65",
        "model.membrane.E22=5000", "material.kes.HG2=0.8", *tiny_cusick, "case.analysis='none'",
        "stop.out_of_balance=0.5"])
    summary = run_case(case, tmp_path / "run", quiet=True)
    on_disk = json.loads((tmp_path / "run" / "summary.json").read_text())
    written = on_disk["material_properties"]
    assert written == json.loads(json.dumps(summary["material_properties"]))
    assert on_disk["damping"] == {"alpha_per_s": pytest.approx(0.3 / written["areal_mass_kg_per_m2"]),
                                  "beta_s": 0.0, "air_drag_N_s_per_m3": 0.3,
                                  "drag_coefficient": 0.0}
    mem = written["membrane"]
    assert mem["G12"]["value"] == pytest.approx(0.6 * GF / 1e-2 * 180 / math.pi, rel=1e-12)
    tension = skirt_tension(written["areal_mass_kg_per_m2"] * 9.80665, 0.15, 0.09)
    assert written["membrane_tension_N_per_m"] == pytest.approx(tension, rel=1e-12)
    fm, eps_m = 500 * GF / 1e-2, 0.04
    curve = lambda e: fm * (e / eps_m) ** (2 / 0.65 - 1)     # noqa: E731
    e = brentq(lambda x: curve(x) - tension, 0.0, eps_m, xtol=1e-16)
    h = 1e-4 * e
    assert mem["E11"]["value"] == pytest.approx((curve(e + h) - curve(e - h)) / (2 * h), rel=1e-6)
    assert (mem["E22"]["source"], mem["nu12"]["source"]) == ("case [model.membrane]", "default")
    assert mem["G12"]["source"].startswith("KES G")
    assert mem["E11"]["source"].startswith("tangent at T = ") and "KES EMT_warp = 4 %" in mem["E11"]["source"]
    assert written["kes_si"]["HG2"] == pytest.approx(0.8 * GF / 1e-2, rel=1e-12)
    assert written["thickness_m"] == pytest.approx(3e-4, rel=1e-12)


def test_f2_ratio_of_a_case_sheet_builds_second_order_friction_with_the_same_B_and_2HB():
    first = build_material(load_case(CUSICK_KES))
    second = build_material(load_case(CUSICK_KES, ["material.kes.f2_ratio=0.5"]))
    assert first.warp.friction.f2 == 0.0
    assert second.warp.friction.f2 == pytest.approx(0.5 * second.warp.friction.f1, rel=1e-14)
    for direction in ("warp", "weft"):
        a, b = first.simulated_kes()[direction], second.simulated_kes()[direction]
        assert (b.B, b.HB2) == pytest.approx((a.B, a.HB2), rel=1e-12)
    with pytest.raises(CaseError, match="material.kes.f2_ratio"):
        load_case(CUSICK_KES, ["material.kes.f2_ratio=1.0"])


# --------------------------------------------------------------------------- bias bending
@pytest.mark.parametrize("theta_deg, B_bias", [(45.0, 0.1), (45.0, 0.06), (30.0, 0.1)])
def test_a_sheets_bias_rigidity_is_the_plates_cylindrical_bending_rigidity(theta_deg, B_bias):
    """A KES-FB2 bias specimen bends cylindrically. The plate's bending energy of the uniform
    curvature field w = ½ κ (n·x)², n at θ to the warp, is ½ B(θ) κ² per area, with
    B(θ) = B₁cos⁴θ + B₂sin⁴θ + 2 D_t sin²θ cos²θ; at 45° it is the sheet's B_bias. Argyris
    elements hold the quadratic exactly (no friction: 2HB = 0, so k1 = B)."""
    from constitutive.units import to_si
    from drape.models.plate import KirchhoffPlate
    from meshes import rectangle

    case = load_case(CUSICK_KES, [f"material.kes.B_bias={B_bias}", "material.kes.HB2_warp=0",
                                  "material.kes.HB2_weft=0"])
    material = build_material(case)
    B1, B2 = to_si(0.085, "B"), to_si(0.062, "B")       # the case's B_warp, B_weft
    assert (material.warp.k1, material.weft.k1) == pytest.approx((B1, B2), rel=1e-12)
    plate = KirchhoffPlate(rectangle(0.02, 0.01, 4, 2), material, element="argyris")
    kappa, c, s = 40.0, math.cos(math.radians(theta_deg)), math.sin(math.radians(theta_deg))
    u = plate.basis.project(lambda x: 0.5 * kappa * (c * x[0] + s * x[1]) ** 2)
    B_theta = B1 * c**4 + B2 * s**4 + 2 * material.twist_rigidity * s**2 * c**2
    assert plate.strain_energy(u) / 2e-4 == pytest.approx(0.5 * B_theta * kappa**2, rel=1e-8)
    if theta_deg == 45.0:
        assert B_theta == pytest.approx(to_si(B_bias, "B"), rel=1e-12)
    assert build_material(case).describe()["twist_rigidity_source"].startswith("KES B_bias")


def test_a_bias_rigidity_below_its_bound_or_given_twice_is_refused(tmp_path):
    with pytest.raises(CaseError, match=r"material.kes.B_bias = 0.03 gf·cm²/cm breaks B_bias > "
                                        r"\(B_warp \+ B_weft\)/4 = 0.03675"):
        load_case(CUSICK_KES, ["material.kes.B_bias=0.03"])
    text = (ROOT / "cases" / "materials" / "kes_example.toml").read_text()
    path = tmp_path / "twice.toml"
    path.write_text(text.replace("eta = 0.5", "eta = 0.5\nB_bias = 0.08").replace(
        'weight = 12.5', 'weight = 12.5\ntwist_rigidity = 0.07'))
    with pytest.raises(MaterialError, match="twist_rigidity and kes.B_bias are both given"):
        load_material(path)
