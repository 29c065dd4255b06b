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

Unit strings from files and the command line (``"5 cm"``, ``"0.5 1/cm/s"``) are read by
:func:`parse_quantity`: a number, then a unit built from the registry's unit names with
``*``, ``/``, ``·`` (or ``.``), parentheses and small integer powers. They are parsed, never evaluated, so no
string can make the reader compute (``"9**9**9 cm"`` is refused at once).
"""
from __future__ import annotations

import math
import re
from functools import lru_cache

import numpy as np
import pint

__all__ = ["ureg", "KES_UNITS", "SI_UNITS", "to_si", "to_kes", "factor", "G0", "parse_quantity",
           "parse_unit"]

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


# --------------------------------------------------------------------------- unit strings
#: A float literal: what a person writes for a magnitude (no expressions, no inf or nan).
_NUMBER = re.compile(r"\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*")
#: The pieces a unit may be written with: a name, a power (an integer of at most two digits,
#: so no power can be large), an operator, parentheses, blanks (a product, as in "N m").
_UNIT_TOKEN = re.compile(r"(?P<name>[^\W\d]\w*)|(?P<power>(?:\*\*|\^)\(?-?\d{1,2}\)?)"
                         r"|(?P<one>1(?=\s*/))|(?P<op>[*/·×.])|(?P<paren>[()])|(?P<blank>\s+)")
_SUPERSCRIPTS = str.maketrans({"²": "**2", "³": "**3", "⁻": None, "¹": None})
_LONGEST = 80


def parse_unit(text: str):
    """The pint unit written in ``text``: unit names of the registry joined by ``*``, ``/``,
    ``·`` or ``.``, blanks and parentheses, each with an optional integer power (``**2``, ``^-1``).

    Raises ``ValueError`` (one line) for anything else.

    >>> str(parse_unit("1/cm/s")), str(parse_unit("g/m^2")), str(parse_unit("gf·cm²/cm"))
    ('1 / centimeter / second', 'gram / meter ** 2', 'centimeter * force_gram')
    >>> parse_unit("cm**9**9")
    Traceback (most recent call last):
    ...
    ValueError: '**9' at 5 is not part of a unit (a unit name, *, /, parentheses, a power of at most two digits)
    """
    text = text.strip().replace("⁻¹", "**-1").translate(_SUPERSCRIPTS).replace("%", "percent")
    if len(text) > _LONGEST:
        raise ValueError(f"a unit of {len(text)} characters is too long (at most {_LONGEST})")
    if not text:
        return ureg.dimensionless
    pos, depth, last = 0, 0, "op"
    while pos < len(text):
        token = _UNIT_TOKEN.match(text, pos)
        kind = token.lastgroup if token else None
        if kind == "power" and last not in ("name", "paren"):
            kind = None
        if kind is None:
            bad = (token.group() if token else text[pos:pos + 3])
            raise ValueError(f"{bad!r} at {pos} is not part of a unit (a unit name, *, /, "
                             f"parentheses, a power of at most two digits)")
        if kind == "name" and not _known(token.group()):
            raise ValueError(f"{token.group()!r} is not a unit name pint knows")
        if kind == "paren":
            depth += 1 if token.group() == "(" else -1
            if depth < 0:
                raise ValueError(f"unbalanced ')' at {pos}")
        if kind != "blank":
            last = "paren" if token.group() == ")" else kind
        pos = token.end()
    if depth:
        raise ValueError("unbalanced '('")
    try:
        return ureg.parse_units(re.sub(r"[·×.]", "*", text).replace("^", "**"))
    except Exception as exc:  # pint raises several unrelated types for malformed units
        raise ValueError(f"{text!r} is not a well-formed unit") from None


def parse_quantity(text: str):
    """The pint quantity written in ``text``: a float literal, then a unit (:func:`parse_unit`).

    Raises ``ValueError`` (one line) for anything else, a magnitude that is not finite
    included.

    >>> parse_quantity("0.5 1/cm/s").to("1/m/s").magnitude
    50.0
    >>> parse_quantity("9**9**9 cm")
    Traceback (most recent call last):
    ...
    ValueError: '9**9**9 cm' is not a number followed by a unit: '**9**9 cm' after the number 9
    """
    number = _NUMBER.match(text)
    if number is None:
        raise ValueError(f"{_short(text)!r} does not start with a number (e.g. '5 cm')")
    rest = text[number.end():]
    if rest[:1] in ("*", "^", "/") and not rest.startswith("/"):
        raise ValueError(f"{_short(text)!r} is not a number followed by a unit: {_short(rest)!r} "
                         f"after the number {number.group(1)}")
    magnitude = float(number.group(1))
    if not math.isfinite(magnitude):
        raise ValueError(f"{_short(text)!r}: the number {number.group(1)} is out of range")
    if rest.startswith("/"):                   # "1/cm": the number is the magnitude
        rest = "1" + rest
    try:
        unit = parse_unit(rest)
    except ValueError as exc:
        raise ValueError(f"{_short(text)!r}: {exc}") from None
    return ureg.Quantity(magnitude, unit)


def _known(name: str) -> bool:
    """Whether ``name`` is a unit of the registry (with a prefix or plural)."""
    try:
        return bool(ureg.parse_unit_name(name))
    except Exception:  # pint's lookups raise assorted errors for odd names
        return False


def _short(text: str, n: int = 40) -> str:
    return text if len(text) <= n else text[:n] + "…"
