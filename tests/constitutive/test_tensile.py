"""The fabric's tensile curve and the membrane a drape takes on it: the power law against
KES-FB1's definitions (quadrature), its tangent against numerical differentiation, the skirt's
mean tension against a quadrature over the annulus, and the case keys that choose it."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from constitutive.material import DEFAULT_MEMBRANE
from constitutive.tensile import DEFAULT_TENSILE, TensileCurve
from drape.case.build import RunInputError, build_material
from drape.case.case import CaseError, load_case
from drape.analyses.drape_coefficient import skirt_tension

ROOT = Path(__file__).resolve().parents[2]
WOOL = ROOT / "cases" / "validation" / "wool_tropical.toml"
G0 = 9.80665


@pytest.mark.parametrize("lt", [0.45, 0.65, 0.9, 1.0, 1.3])
def test_the_power_law_has_the_linearity_it_is_built_with(lt):
    """LT = WT/(Fm εm/2) with WT = ∫₀^εm F dε by quadrature (the KES-FB1 definitions)."""
    c = TensileCurve(0.05, lt, 490.0)
    wt = quad(c.force, 0.0, 0.05, epsabs=0, epsrel=1e-13)[0]
    assert wt / (490.0 * 0.05 / 2) == pytest.approx(lt, rel=1e-10)
    assert c.energy == pytest.approx(wt, rel=1e-10)
    assert c.secant == pytest.approx(2 * wt / 0.05**2, rel=1e-10)
    assert c.force(0.05) == pytest.approx(490.0, rel=1e-14)


@pytest.mark.parametrize("tension", [1e-3, 0.05, 3.0, 400.0])
def test_the_tangent_is_the_curves_slope_where_it_carries_the_tension(tension):
    c = TensileCurve(0.032, 0.62, 490.0)
    e = brentq(lambda x: c.force(x) - tension, 0.0, 0.032, xtol=1e-18, rtol=1e-15)
    h = 1e-5 * e
    slope = (c.force(e + h) - c.force(e - h)) / (2 * h)
    assert c.tangent(tension) == pytest.approx(slope, rel=1e-7)


def test_a_convex_curve_is_far_softer_at_a_drapes_load_than_its_secant():
    """At 0.05 N/m, 10⁴ times below Fm, the default curve's tangent is some 35 times below the
    stiffness storing its energy (the tangent grows as T^(1 − 1/m), m ≈ 2.08)."""
    assert DEFAULT_TENSILE.linearity == 0.65
    assert DEFAULT_TENSILE.secant == pytest.approx(DEFAULT_MEMBRANE["E11"], rel=1e-12)
    ratio = DEFAULT_TENSILE.tangent(0.05) / DEFAULT_TENSILE.secant
    assert 0.02 < ratio < 0.04
    m = DEFAULT_TENSILE.exponent
    assert DEFAULT_TENSILE.tangent(0.5) / DEFAULT_TENSILE.tangent(0.05) == pytest.approx(10 ** (1 - 1 / m), rel=1e-12)


@pytest.mark.parametrize("lt", [1.0, 1.2])
def test_a_straight_or_concave_curve_gives_the_stiffness_storing_its_energy(lt):
    c = TensileCurve(0.05, lt, 490.0)
    assert c.tangent(0.01) == c.tangent(400.0) == pytest.approx(lt * 490.0 / 0.05, rel=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    (dict(strain_at_max=0.0, linearity=0.6), "εm > 0"),
    (dict(strain_at_max=0.05, linearity=2.0), "0 < LT < 2"),
    (dict(strain_at_max=0.05, linearity=0.6, max_load=-1.0), "Fm > 0"),
])
def test_a_curve_out_of_its_rules_is_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        TensileCurve(**kwargs)
    with pytest.raises(ValueError, match="0 < T <= Fm"):
        DEFAULT_TENSILE.tangent(600.0)


@pytest.mark.parametrize("R, a", [(0.127, 0.0635), (0.15, 0.09), (0.18, 0.09)])
def test_the_skirt_tension_is_the_area_mean_of_the_weight_each_radius_carries(R, a):
    """T(r) = w (R² − r²)/(2r) averaged over the annulus by quadrature."""
    w = 1.6
    mean = quad(lambda r: w * (R**2 - r**2) / (2 * r) * 2 * np.pi * r, a, R)[0] / (np.pi * (R**2 - a**2))
    assert skirt_tension(w, R, a) == pytest.approx(mean, rel=1e-12)


# --------------------------------------------------------------------------- the case keys
def _material(*over):
    return build_material(load_case(WOOL, list(over)))


def test_a_cusick_case_takes_the_membrane_at_its_skirts_tension():
    m = _material()
    tension = skirt_tension(m.areal_mass * G0, 0.127, 0.0635)
    assert m.membrane_tension == pytest.approx(tension, rel=1e-12)
    assert m.E11 == m.E22 == pytest.approx(DEFAULT_TENSILE.tangent(tension), rel=1e-12)
    assert 200.0 < m.E11 < 400.0
    assert m.describe()["membrane"]["E11"]["source"].startswith(f"tangent at T = {tension:.4g} N/m")


def test_the_secant_a_given_tension_and_a_given_stiffness():
    assert _material("model.membrane_tension='secant'").E11 == DEFAULT_MEMBRANE["E11"]
    m = _material("model.membrane_tension='0.5 N/m'")
    assert m.E11 == pytest.approx(DEFAULT_TENSILE.tangent(0.5), rel=1e-12)
    m = _material("model.membrane.E11='3000 N/m'")
    assert m.E11 == 3000.0 and m.E22 == pytest.approx(DEFAULT_TENSILE.tangent(m.membrane_tension))
    assert m.describe()["membrane"]["E11"]["source"] == "case [model.membrane]"


def test_a_strip_keeps_the_secant_and_bad_tensions_name_the_key():
    assert build_material(load_case(ROOT / "cases" / "cantilever.toml")).E11 == DEFAULT_MEMBRANE["E11"]
    with pytest.raises(RunInputError, match=r"model.membrane_tension: tension = 600.0 N/m breaks"):
        _material("model.membrane_tension=600")
    with pytest.raises(CaseError, match="membrane_tension"):
        _material("model.membrane_tension='taut'")
    with pytest.raises(CaseError, match="membrane_tension is only used with"):
        load_case(ROOT / "cases" / "kes_strip.toml", ["model.membrane_tension=0.1"])
