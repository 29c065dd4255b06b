"""Physical quantities of the friction operator (thesis Eqs. 3.10–3.15).

For a monotone path from rest the friction moment (3.17) rises with slope
``k_F+`` to the static peak ``f_s`` at path length ``s_e`` and then decays
(steepest fall ``k_F−``) to the kinetic level ``f_k``, which it reaches to
within 5 % after about ``s_p = 3 ε_f``::

    f_k  = f1 − f2                                                (3.10)
    f_s  = f_k + f2 (η f2/f1)^(η/(1−η)) (1 − η)                   (3.11)
    s_e  = ε_f η/(1−η) · ln(f1/(η f2))                            (3.12)
    s_p  = 3 ε_f                                                  (3.13)
    k_F− = f2/ε_f · (η² f2/f1)^(η/(1−η)) (1 − η)                  (3.14)
    k_F+ = (f1 − η f2)/(η ε_f)                                    (3.15)

Good fits drift to f1 ≈ f2 → large with η → 1 (the raw parameters are poorly
identified); these bounded quantities are what to report beside them.

Rounding.  The thesis prints f1, f2 to four digits and η to four decimals,
so ``f1/f2`` and ``1 − η`` carry only one or two significant digits when
f1 ≈ f2 and η ≈ 1.  s_e is then very sensitive: for Fabric 1 warp
(Table 4.4) the printed inputs give s_e = 12.6 cm⁻¹, but η = 0.99977 — which
also prints as 0.9998 — gives the printed 10.92 cm⁻¹ (see
``tests/constitutive/test_derived.py``).  Table 4.14 (Fabric 2 weft) prints s_e, s_p and
f_s each 100× what Table 4.13 gives (s_p = 3 ε_f = 2.29e-3, printed 2.29e-1;
f_s = 4.0e-4, printed 4.045e-2): all four of its entries follow, within
rounding, from f1 ≈ f2 ≈ 16.00, f1 − f2 = 2.12e-6, ε_f = 7.646e-2 — i.e. it was
evaluated with f1, f2, ε_f a hundred times those printed.  We keep Table 4.13 as printed: Table 4.15 shows the
friction term hardly changes that fit (residual 4.479e-2 with, 4.482e-2
without), which fits a peak of 4e-4 gf·cm/cm beside loop moments of ~2e-2,
not a peak of 4e-2 that would double them.

>>> from constitutive.friction import FrictionParams
>>> q = friction_quantities(FrictionParams(f1=0.2173, f2=0.2161, eps_f=0.7316, eta=0.9876))
>>> {k: round(float(v), 4) for k, v in q.items()}
{'f_k': 0.0012, 'f_s': 0.0018, 's_e': 1.0497, 's_p': 2.1948, 'k_F_minus': 0.0003, 'k_F_plus': 0.0054}
"""
from __future__ import annotations

import numpy as np

from constitutive.friction import FrictionParams

__all__ = ["kinetic_friction", "static_friction", "static_peak_path", "kinetic_path",
           "slope_minus", "slope_plus", "friction_quantities"]


def kinetic_friction(p: FrictionParams):
    """``f_k = f1 − f2`` (3.10): the sliding level [N·m/m]."""
    return p.f1 - p.f2


def static_friction(p: FrictionParams):
    """``f_s`` (3.11): the peak of the moment from rest [N·m/m]."""
    f1, f2, eta = np.asarray(p.f1), np.asarray(p.f2), np.asarray(p.eta)
    return f1 - f2 + f2 * (eta * f2 / f1) ** (eta / (1 - eta)) * (1 - eta)


def static_peak_path(p: FrictionParams):
    """``s_e`` (3.12): path length from rest to the static peak [1/m] (∞ if f2 = 0)."""
    f1, f2, eta = np.asarray(p.f1), np.asarray(p.f2), np.asarray(p.eta)
    with np.errstate(divide="ignore"):
        return p.eps_f * eta / (1 - eta) * np.log(f1 / (eta * f2))


def kinetic_path(p: FrictionParams):
    """``s_p = 3 ε_f`` (3.13): path after which the slow state is within 5 % (e⁻³) of saturation [1/m]."""
    return 3.0 * p.eps_f


def slope_minus(p: FrictionParams):
    """``k_F−`` (3.14): steepest decay of the moment after the static peak [N·m]."""
    f1, f2, eta = np.asarray(p.f1), np.asarray(p.f2), np.asarray(p.eta)
    return f2 / p.eps_f * (eta**2 * f2 / f1) ** (eta / (1 - eta)) * (1 - eta)


def slope_plus(p: FrictionParams):
    """``k_F+`` (3.15): initial slope of the moment from rest, ``f1/a1 − f2/a2`` [N·m]."""
    return (p.f1 - p.eta * p.f2) / (p.eta * p.eps_f)


def friction_quantities(p: FrictionParams) -> dict:
    """All of 3.10–3.15 as a dict (keys f_k, f_s, s_e, s_p, k_F_minus, k_F_plus), SI or KES alike.

    The formulas are homogeneous: parameters in KES units give results in KES
    units (f in gf·cm/cm, s in cm⁻¹, k_F in gf·cm²/cm).
    """
    return {"f_k": kinetic_friction(p), "f_s": static_friction(p), "s_e": static_peak_path(p),
            "s_p": kinetic_path(p), "k_F_minus": slope_minus(p), "k_F_plus": slope_plus(p)}
