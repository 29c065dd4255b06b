"""KES ↔ SI units at the I/O boundary (pint).

The code works in SI; KES-FB data and the thesis's tables use gram-force and
centimetres.  Moments are per unit specimen width: "gf·cm/cm" is a moment per
width, N·m/m (= N) in SI.

Parameter units, derived from the equation each parameter sits in
(``M = m κ̈ + d κ̇ + k1 κ + k3 κ³ + M_f`` with M in gf·cm/cm and κ in cm⁻¹,
``M_f = f1 y1 − f2 y2`` with dimensionless y, ``dy/ds = (σ − y)/a``,
``s = ∫|κ̇| dt``, ``a1 = ε_f η``, ``a2 = ε_f``):

============  ==================  ==================  =====================================
name          KES unit            SI unit             thesis prints (Tables 4.4–4.13)
============  ==================  ==================  =====================================
k1, B         gf·cm²/cm           N·m                 "gmf-cm"      (drops the per-width cm)
k3            gf·cm⁴/cm           N·m³                "gmf-cm³"     (same)
d             gf·cm²·s/cm         N·m·s               "gmf-cm/s"    (inverted s, and per-width)
m             gf·cm²·s²/cm        N·m·s²              (not printed: m was not fitted)
f1, f2, 2HB   gf·cm/cm            N·m/m = N           "gmf-cm"      (per width)
eps_f         cm⁻¹                1/m                 "gmf-cm/cm"   (wrong: a path length in κ)
eta           1                   1                   1
weight        mg/cm²              (areal mass kg/m²)  "gmf/cm²"     (as a KES sheet: 1 mg/cm² = 0.01 kg/m²)
thickness     mm                  m                   cm            (as a KES sheet)
G             gf/(cm·degree)      N/m (per radian)    –             (KES-FB1 shear rigidity)
HG2           gf/cm               N/m                 –             (2HG, 2HG5 shear hysteresis)
EMT           %                   1                   –             (tensile strain at Fm)
LT            1                   1                   –
WT            gf·cm/cm²           N/m (J/m²)          –             (tensile energy)
E_tensile     gf/cm               N/m                 –             (tensile stiffness, Fm)
curvature     cm⁻¹                1/m                 cm⁻¹
============  ==================  ==================  =====================================

Conclusion: the thesis's printed units are per-width-sloppy throughout and
wrong for ε_f and d; the values are consistent with the units in the KES
column (e.g. Fabric 1 warp ``k1 = 6.38e-3`` against the loading polynomial
slope ``1.21e-2 gf·cm²/cm`` of Table B.1, ``s_p = 3 ε_f`` printed in cm⁻¹).

>>> round(to_si(1.0, "k1"), 12)
9.80665e-05
>>> round(to_kes(9.80665e-3, "f1"), 12)
1.0
>>> round(to_si(17.15, "weight"), 12)
0.1715
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pint

__all__ = ["ureg", "KES_UNITS", "SI_UNITS", "to_si", "to_kes", "factor", "G0"]

ureg = pint.UnitRegistry()
ureg.define("gmf = gram_force")   # the thesis writes "gmf"

G0 = 9.80665  # m/s², standard gravity (defines the gram-force)

#: KES (file) unit of each quantity, by parameter name.
KES_UNITS = {
    "k1": "gf*cm**2/cm", "k1_neg": "gf*cm**2/cm", "B": "gf*cm**2/cm", "twist_rigidity": "gf*cm**2/cm",
    "k3": "gf*cm**4/cm", "k3_neg": "gf*cm**4/cm",
    "d": "gf*cm**2*s/cm",
    "m": "gf*cm**2*s**2/cm",
    "f1": "gf*cm/cm", "f2": "gf*cm/cm", "HB2": "gf*cm/cm", "moment": "gf*cm/cm",
    "f_k": "gf*cm/cm", "f_s": "gf*cm/cm",
    "eps_f": "1/cm", "s_e": "1/cm", "s_p": "1/cm", "curvature": "1/cm",
    "k_F": "gf*cm**2/cm",
    "eta": "dimensionless",
    "weight": "mg/cm**2",     # as a KES sheet prints it (the thesis's gf/cm² × 1000)
    "thickness": "mm",
    "G": "gf/cm/degree", "HG2": "gf/cm", "EMT": "percent", "LT": "dimensionless",
    "WT": "gf*cm/cm**2", "E_tensile": "gf/cm",
    "rate": "1/cm/s",
    "time": "s",
}

#: SI unit each quantity is held in inside the code.
SI_UNITS = {
    "k1": "N*m", "k1_neg": "N*m", "B": "N*m", "twist_rigidity": "N*m", "k_F": "N*m",
    "k3": "N*m**3", "k3_neg": "N*m**3",
    "d": "N*m*s",
    "m": "N*m*s**2",
    "f1": "N", "f2": "N", "HB2": "N", "moment": "N", "f_k": "N", "f_s": "N",
    "eps_f": "1/m", "s_e": "1/m", "s_p": "1/m", "curvature": "1/m",
    "eta": "dimensionless",
    "weight": "kg/m**2",      # areal mass
    "thickness": "m",
    "G": "N/m", "HG2": "N/m", "EMT": "dimensionless", "LT": "dimensionless", "WT": "N/m",
    "E_tensile": "N/m",
    "rate": "1/m/s",
    "time": "s",
}


@lru_cache(maxsize=None)
def factor(name: str) -> float:
    """Multiplier taking quantity ``name`` from its KES unit to its SI unit.

    >>> factor("k3")
    9.80665e-09
    """
    if name not in KES_UNITS:
        raise KeyError(f"no KES unit known for {name!r}; known: {', '.join(sorted(KES_UNITS))}")
    q = ureg.Quantity(1.0, KES_UNITS[name])
    return float(f"{q.to(SI_UNITS[name]).magnitude:.15g}")   # drop pint round-off in the 16th digit


def to_si(value, name: str):
    """Convert ``value`` of quantity ``name`` from KES to SI units."""
    return np.asarray(value, dtype=float) * factor(name) if np.ndim(value) else float(value) * factor(name)


def to_kes(value, name: str):
    """Convert ``value`` of quantity ``name`` from SI to KES units."""
    return np.asarray(value, dtype=float) / factor(name) if np.ndim(value) else float(value) / factor(name)
