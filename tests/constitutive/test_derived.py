"""Derived friction quantities (3.10–3.15) against the thesis's Tables 4.5, 4.8, 4.11, 4.14.

The thesis prints its inputs rounded (f1, f2 to 4 significant digits, η to 4
decimals, ε_f to 4 digits).  A printed output is reproduced if it lies within
the range our formulas give over the box of all inputs that round to the
printed ones, widened by half a unit in the output's own last printed digit.
That is the stated tolerance; the box is sampled on a 7⁴ grid (corners
included; s_e is monotone in each input, f_s nearly so).
"""
import itertools

import numpy as np
import pytest
from scipy.optimize import brentq

from constitutive.derived import friction_quantities, slope_minus, slope_plus, static_friction, static_peak_path
from constitutive.friction import FrictionParams, closed_form_from_rest

# (table in, printed f1, f2, eps_f, eta, half-units), (table out, printed s_e, s_p, f_k, f_s, half-units) — KES units
TABLES = {
    "fabric1-warp": (("4.4", 0.6184, 0.6164, 0.7302, 0.9998, (5e-5, 5e-5, 5e-5, 5e-5)),
                     ("4.5", 10.92, 2.19, 0.198e-2, 0.198e-2, (5e-3, 5e-3, 5e-6, 5e-6))),
    "fabric1-weft": (("4.7", 0.2173, 0.2161, 0.7316, 0.9876, (5e-5, 5e-5, 5e-5, 5e-5)),
                     ("4.8", 1.07, 2.19, 0.127e-2, 0.189e-2, (5e-3, 5e-3, 5e-6, 5e-6))),
    "fabric2-warp": (("4.10", 0.7836, 0.7810, 0.7207, 0.9949, (5e-5, 5e-5, 5e-5, 5e-5)),
                     ("4.11", 1.17, 2.16, 0.255e-2, 0.334e-2, (5e-3, 5e-3, 5e-6, 5e-6))),
}


def box(f1, f2, eps, eta, half, n=7, f_k=None):
    """FrictionParams arrays over the rounding box (dissipative corners only)."""
    axes = [np.linspace(v - h, v + h, n) for v, h in zip((f1, f2, eps, eta), half)]
    g = np.array(list(itertools.product(*axes))).T
    if f_k is not None:                   # f1 printed equal to f2: pin f1 − f2 to the printed f_k
        g[0] = g[1] + f_k
    ok = g[0] > g[1]
    return FrictionParams(*(x[ok] for x in g))


def within(name, printed, half_out, values, width=0.2):
    """Printed value inside the range over the rounding box, and that range narrow enough
    (``width`` of the printed value) for the check to be able to fail."""
    lo, hi = np.nanmin(values), np.nanmax(values)
    assert hi - lo <= width * abs(printed) + 2 * half_out, f"{name}: box [{lo:.6g}, {hi:.6g}] too wide to test"
    assert lo - half_out <= printed <= hi + half_out, f"{name}: printed {printed} outside [{lo:.6g}, {hi:.6g}]"


#: s_e of Fabric 1 warp spans 9.7 … 17.3 cm⁻¹ over the rounding box of its inputs (η = 0.9998 is
#: within 2e-4 of 1, where 3.12 is singular): the box cannot test it. The η that reproduces the
#: printed value does (test_s_e_sensitivity_to_the_rounding_of_eta_fabric1_warp).
_UNTESTABLE_BY_THE_BOX = {("fabric1-warp", "s_e")}


@pytest.mark.parametrize("fabric", sorted(TABLES))
def test_tables_4_5_4_8_4_11_reproduced_within_rounding(fabric):
    (tin, f1, f2, eps, eta, half), (tout, s_e, s_p, f_k, f_s, hout) = TABLES[fabric]
    q = friction_quantities(box(f1, f2, eps, eta, half))
    for name, printed, h in zip(("s_e", "s_p", "f_k", "f_s"), (s_e, s_p, f_k, f_s), hout):
        if (fabric, name) not in _UNTESTABLE_BY_THE_BOX:
            within(f"Table {tout} {name}", printed, h, q[name])


def test_s_e_sensitivity_to_the_rounding_of_eta_fabric1_warp():
    p = FrictionParams(0.6184, 0.6164, 0.7302, 0.9998)
    central = float(static_peak_path(p))
    assert abs(central - 10.92) / 10.92 > 0.1           # printed inputs: 12.55 cm⁻¹, 15 % off the table
    # η alone, within its rounding interval [0.99975, 0.99985), spans 10.0 … 16.7 cm⁻¹ ...
    lo = float(static_peak_path(FrictionParams(0.6184, 0.6164, 0.7302, 0.99975)))
    hi = float(static_peak_path(FrictionParams(0.6184, 0.6164, 0.7302, 0.99985)))
    assert lo < 10.92 < hi and hi / lo > 1.5
    # ... and the η that gives the printed 10.92 rounds to the printed 0.9998
    eta_star = brentq(lambda e: float(static_peak_path(FrictionParams(0.6184, 0.6164, 0.7302, e))) - 10.92,
                      0.99975, 0.99985)
    assert round(eta_star, 4) == 0.9998


def test_table_4_14_is_100x_table_4_13():
    # Fabric 2 weft: f1 and f2 both print as 0.1600; f_k = 2.120e-6 pins their difference.
    half = (5e-5, 5e-5, 5e-8, 5e-5)
    printed = dict(s_e=7.62e-2, s_p=2.29e-1, f_s=4.045e-2)
    hout = dict(s_e=5e-5, s_p=5e-4, f_s=5e-6)
    as_printed = friction_quantities(box(0.1600, 0.1600, 7.646e-4, 0.9932, half, f_k=2.120e-6))
    for k in printed:
        ratio = printed[k] / np.median(as_printed[k])
        assert 95 < ratio < 105, (k, ratio)          # 100×, not a rounding effect
    # with f1, f2, ε_f scaled by 100 (f1 − f2 kept at the printed f_k) all four entries are reproduced
    scaled = friction_quantities(box(16.00, 16.00, 7.646e-2, 0.9932, (5e-3, 5e-3, 5e-6, 5e-5), f_k=2.120e-6))
    within("Table 4.14 f_k", 2.120e-6, 5e-10, scaled["f_k"])
    for k in printed:
        within(f"Table 4.14 {k}", printed[k], hout[k], scaled[k])


def test_formulas_match_the_closed_form_numerically():
    # independent check of 3.11, 3.12, 3.14, 3.15 by sampling 3.17 on a fine grid
    rng = np.random.default_rng(11)
    for _ in range(5):
        f2 = rng.uniform(0.1, 1.0)
        p = FrictionParams(f2 * rng.uniform(1.01, 1.5), f2, rng.uniform(0.1, 2.0), rng.uniform(0.3, 0.95))
        s = np.linspace(0, 20 * p.eps_f, 400001)
        F = closed_form_from_rest(p, s)
        dF = np.gradient(F, s)
        i = np.argmax(F)
        assert F[i] == pytest.approx(float(static_friction(p)), rel=1e-8)
        assert s[i] == pytest.approx(float(static_peak_path(p)), abs=2 * (s[1] - s[0]))
        assert dF[0] == pytest.approx(float(slope_plus(p)), rel=1e-3)
        assert (-dF).max() == pytest.approx(float(slope_minus(p)), rel=1e-6)


def test_no_static_peak_without_f2():
    p = FrictionParams(1.0, 0.0, 1.0, 0.5)
    q = friction_quantities(p)
    assert q["f_s"] == q["f_k"] == 1.0 and np.isinf(q["s_e"]) and q["k_F_minus"] == 0.0
