"""Units (KES ↔ SI), material files and building a material from KES summary values."""
import math

import numpy as np
import pytest

from constitutive.kes import kes_profile, kes_values, run_kes
from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial, MaterialError, available_materials, load_material, material_from_kes
from constitutive.units import KES_UNITS, factor, to_kes, to_si, ureg

GF = 9.80665e-3      # N: one gram-force (docs/theory.md §1)


def test_unit_factors_are_design_values():
    assert factor("f1") == pytest.approx(GF, rel=1e-15)              # gf·cm/cm → N·m/m
    assert factor("k1") == pytest.approx(GF * 1e-2, rel=1e-15)       # gf·cm²/cm → N·m
    assert factor("k3") == pytest.approx(GF * 1e-6, rel=1e-15)       # gf·cm⁴/cm → N·m³
    assert factor("d") == pytest.approx(GF * 1e-2, rel=1e-15)        # gf·cm²·s/cm → N·m·s
    assert factor("m") == pytest.approx(GF * 1e-2, rel=1e-15)
    assert factor("eps_f") == 100.0 and factor("curvature") == 100.0
    assert factor("weight") == pytest.approx(0.01, rel=1e-15)        # mg/cm² → kg/m² areal mass
    assert factor("thickness") == 0.001                               # mm → m
    assert to_kes(to_si(0.0123, "k3"), "k3") == pytest.approx(0.0123, rel=1e-15)
    np.testing.assert_allclose(to_si(np.array([1.0, 2.0]), "HB2"), [GF, 2 * GF])
    with pytest.raises(KeyError, match="no KES unit known for 'k2'"):
        factor("k2")


def test_parameter_units_make_every_term_of_the_law_a_moment_per_width():
    # M = m κ̈ + d κ̇ + k1 κ + k3 κ³ + f1 y1 − f2 y2, and s = ∫|κ̇|dt has the unit of κ (a1 = eps_f η)
    M = ureg.Quantity(1, KES_UNITS["moment"])
    kappa = ureg.Quantity(1, KES_UNITS["curvature"])
    sec = ureg.Quantity(1, "s")
    terms = {"k1": kappa, "k3": kappa**3, "d": kappa / sec, "m": kappa / sec**2, "f1": 1, "f2": 1}
    for name, mult in terms.items():
        assert (ureg.Quantity(1, KES_UNITS[name]) * mult).dimensionality == M.dimensionality, name
    assert ureg.Quantity(1, KES_UNITS["eps_f"]).dimensionality == kappa.dimensionality
    assert ureg.Quantity(1, KES_UNITS["B"]).dimensionality == (M / kappa).dimensionality


def test_fabric1_loads_in_si():
    m = load_material("fabric1")
    assert m.areal_mass == pytest.approx(0.1715, rel=1e-12)          # Table 4.2: 0.01715 gf/cm²
    assert m.thickness == pytest.approx(0.0254e-2, rel=1e-12)
    w = m.warp
    assert w.k1 == pytest.approx(6.380e-3 * GF * 1e-2, rel=1e-12)   # Table 4.4
    assert w.k3 == pytest.approx(8.656e-4 * GF * 1e-6, rel=1e-12)
    assert w.d == pytest.approx(5.793e-3 * GF * 1e-2, rel=1e-12)
    assert w.m == 0.0 and w.symmetric
    assert w.friction.f1 == pytest.approx(0.6184 * GF, rel=1e-12)
    assert w.friction.eps_f == pytest.approx(73.02, rel=1e-12) and w.friction.eta == 0.9998
    assert m.weft.k1 == pytest.approx(4.548e-3 * GF * 1e-2, rel=1e-12)   # Table 4.7
    assert m.twist_rigidity == pytest.approx(math.sqrt(m.warp.k1 * m.weft.k1), rel=1e-14)
    assert (m.E11, m.E22, m.nu12, m.G12) == (1.0e4, 1.0e4, 0.0, 50.0)


def test_all_bundled_materials_load():
    names = available_materials()
    assert {"fabric1", "fabric2", "kes_example"} <= set(names)
    for name in names:
        assert isinstance(load_material(name), FabricMaterial)
    f2 = load_material("fabric2")
    assert f2.weft.friction.f1 > f2.weft.friction.f2
    assert f2.warp.k1 == pytest.approx(1.154e-2 * GF * 1e-2, rel=1e-12)   # Table 4.10


def test_kes_example_round_trips_B_and_2HB():
    m = load_material("kes_example")
    prof = kes_profile(dt=1e-3)
    for key, law in (("warp", m.warp), ("weft", m.weft)):
        loop = run_kes(law, prof)
        B, HB2 = kes_values(loop.kappa, loop.moment)
        # the law is calibrated on this very profile: B and 2HB come back to round-off
        assert B == pytest.approx(m.kes[f"B_{key}"], rel=1e-12)
        assert HB2 == pytest.approx(m.kes[f"HB2_{key}"], rel=1e-12)
    assert m.kes["B_warp"] == pytest.approx(0.085 * GF * 1e-2, rel=1e-12)
    assert m.warp.k3 == 0 and m.warp.d == 0 and m.warp.friction.f2 == 0


@pytest.mark.parametrize("B, HB2, T", [(0.02, 0.01, 0.5), (0.3, 0.2, 0.2), (0.05, 0.08, 1.0), (0.1, 0.0, 0.5)])
def test_material_from_kes_round_trip_and_near_coulomb_limit(B, HB2, T):
    Bs, Hs = to_si(B, "B"), to_si(HB2, "HB2")
    m = material_from_kes("t", Bs, 2 * Bs, Hs, 2 * Hs, areal_mass=0.2, accel_time=T)
    loop = run_kes(m.warp, kes_profile(dt=1e-3, accel_time=T))
    v = kes_values(loop.kappa, loop.moment)
    assert v.B == pytest.approx(Bs, rel=0.02) and v.HB2 == pytest.approx(Hs, rel=0.02, abs=1e-15)
    # with a1 = 0.1 cm⁻¹ the friction is nearly Coulomb at |κ| = 1 cm⁻¹: k1 ≈ B, f1 ≈ 2HB/2 (independent estimate)
    assert m.warp.k1 == pytest.approx(Bs, rel=0.01)
    if HB2:
        assert m.warp.friction.f1 == pytest.approx(Hs / 2, rel=0.01)
    else:
        assert m.warp.friction is None


def test_material_from_kes_rejects_bad_values():
    with pytest.raises(MaterialError, match="weft: B = -1.0 breaks B > 0"):
        material_from_kes("x", 1e-5, -1.0, 1e-4, 1e-4, areal_mass=0.1)
    with pytest.raises(MaterialError, match="too large"):
        material_from_kes("x", 1e-7, 1e-7, 1.0, 1e-4, areal_mass=0.1)
    with pytest.raises(MaterialError, match="unknown membrane key"):
        material_from_kes("x", 1e-5, 1e-5, 1e-4, 1e-4, areal_mass=0.1, E33=1.0)


GOOD = """
name = "t"
weight = 20
[warp]
k1 = 0.01
f1 = 0.2
f2 = 0.1
eps_f = 0.5
eta = 0.5
[weft]
k1 = 0.005
k1_neg = 0.004
"""


@pytest.mark.parametrize("edit, message", [
    (("k1 = 0.005\n", "k1 = 0.005\nk2 = 1.0\n"), "unknown key 'weft.k2'"),
    (("k1 = 0.01", 'k1 = "stiff"'), "warp.k1 = 'stiff': must be a number"),
    (("f1 = 0.2", "f1 = 0.1"), "warp: f1 = 0.1 with f2 = 0.1 breaks f1 > f2 >= 0"),
    (("eta = 0.5", "eta = 1.5"), "warp: eta = 1.5 breaks 0 < eta < 1"),
    (("weight = 20", "weight = -20"), "weight = -20: outside 1–100 mg/cm² of woven and knitted fabrics"),
    (("weight = 20", "weight = 0.02"), "weight = 0.02: outside 1–100 mg/cm² of woven and knitted "
                                       "fabrics; looks like gf/cm² (or g/cm²): 0.02 gf/cm² = 20 mg/cm²"),
    (("f2 = 0.1\n", ""), "warp: friction needs all of f1, f2, eps_f, eta (missing f2)"),
    (("[weft]\nk1 = 0.005\nk1_neg = 0.004\n", ""), "give both [warp] and [weft]"),
    (("name = \"t\"", "name = \"t\"\n[membrane]\nnu12 = 2.0"), "membrane.nu12 = 2.0"),
    (("k1 = 0.01", "k1 = 0.01 0.02"), "TOML syntax error"),
])
def test_bad_material_files_name_key_and_rule(tmp_path, edit, message):
    f = tmp_path / "t.toml"
    f.write_text(GOOD.replace(*edit, 1))
    with pytest.raises(MaterialError) as err:
        load_material(f)
    assert message in str(err.value) and "t.toml" in str(err.value)


def test_good_file_asymmetry_and_lookup_errors(tmp_path):
    f = tmp_path / "t.toml"
    f.write_text(GOOD)
    m = load_material(str(f))
    assert m.weft.k1_neg == pytest.approx(0.004 * GF * 1e-2) and m.weft.friction is None
    assert m.weft.elastic(-1.0)[1] == pytest.approx(m.weft.k1_neg)
    with pytest.raises(MaterialError, match="unknown material 'fabric9'; bundled: fabric1"):
        load_material("fabric9")
    with pytest.raises(MaterialError, match="does not exist"):
        load_material(tmp_path / "missing.toml")


def test_fabric_material_validation_and_replace():
    w, f = BendingLaw(k1=4e-6), BendingLaw(k1=1e-6)
    with pytest.raises(MaterialError, match="areal_mass = 0.0 breaks areal_mass > 0"):
        FabricMaterial("x", 0.0, None, w, f)
    with pytest.raises(MaterialError, match="nu12"):
        FabricMaterial("x", 0.1, None, w, f, E11=1.0, E22=100.0, nu12=0.2)
    m = FabricMaterial("x", 0.1, None, w, f)
    assert m.replace(warp=BendingLaw(k1=9e-6)).twist_rigidity == pytest.approx(3e-6)
    assert FabricMaterial("x", 0.1, None, w, f, twist_rigidity=5e-6).replace(warp=w).twist_rigidity == 5e-6


@pytest.mark.parametrize("ratio", [0.3, 0.7])
def test_second_order_friction_from_kes_keeps_B_and_2HB_and_has_a_static_peak(ratio):
    from constitutive.derived import kinetic_friction, static_friction
    from constitutive.friction import friction_path

    Bs, Hs = to_si(0.067, "B"), to_si(0.033, "HB2")
    m = material_from_kes("t", Bs, Bs, Hs, Hs, areal_mass=0.16, f2_ratio=ratio)
    fr = m.warp.friction
    assert fr.f2 == pytest.approx(ratio * fr.f1, rel=1e-14)
    loop = run_kes(m.warp, kes_profile(dt=1e-3))
    v = kes_values(loop.kappa, loop.moment)
    assert v.B == pytest.approx(Bs, rel=1e-12) and v.HB2 == pytest.approx(Hs, rel=1e-12)
    # a1 = 0.1, a2 = 0.2 cm⁻¹ are short against the 1.5 cm⁻¹ from a reversal to |κ| = 1 cm⁻¹:
    # there the loop's half width is the kinetic moment f1 − f2 (independent estimate)
    assert fr.f1 - fr.f2 == pytest.approx(Hs / 2, rel=0.01)
    # from rest the moment peaks at the closed-form static friction (thesis 3.11), above f1 − f2
    kappa = np.linspace(0.0, 250.0, 250_001)
    peak = friction_path(fr, kappa).max()
    assert peak == pytest.approx(static_friction(fr), rel=1e-6)
    assert peak > kinetic_friction(fr) * (1.0 + 0.02)


def test_f2_ratio_must_leave_f1_above_f2():
    with pytest.raises(MaterialError, match="f2_ratio = 1.0 breaks 0 <= f2_ratio < 1"):
        material_from_kes("x", 1e-5, 1e-5, 1e-4, 1e-4, areal_mass=0.1, f2_ratio=1.0)
