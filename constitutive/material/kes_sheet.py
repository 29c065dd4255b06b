"""A KES-F sheet as input: its values in the units it prints, their plausible ranges, and the
membrane built from them.

The Kawabata Evaluation System for Fabrics (Kawabata, *The standardization and analysis of
hand evaluation*, 2nd ed., Textile Machinery Society of Japan, 1980) prints, per fabric:

======================  ==================  =====================================================
key                     unit (bare number)  meaning
======================  ==================  =====================================================
``weight``              mg/cm²              W, mass per area
``thickness``           mm                  T, thickness at 0.5 gf/cm² (KES-FB3)
``B_warp``, ``B_weft``  gf·cm²/cm           bending rigidity, slope of M(κ) over 0.5–1.5 cm⁻¹
``HB2_warp``, …         gf·cm/cm            2HB, bending hysteresis width at |κ| = 1 cm⁻¹
``B_bias``              gf·cm²/cm           bending rigidity of a bias specimen (45° to warp and
                                            weft, KES-FB2): gives the twist rigidity
``G``                   gf/(cm·degree)      shear rigidity, slope of the shear force per length
                                            against the shear angle over 0.5–5° (KES-FB1, under
                                            10 gf/cm tension; the mean of the two directions)
``HG2``, ``HG2_5``      gf/cm               2HG, 2HG5: shear hysteresis width at 0.5° and 5°
``EMT_warp``, …         %                   tensile strain at the maximum load Fm (KES-FB1)
``LT_warp``, …          1                   linearity of the tensile curve, WT / (Fm·EMT/2)
``WT_warp``, …          gf·cm/cm²           tensile energy ∫₀^εm F dε per area, up to Fm
``Fm``                  gf/cm               the maximum tensile load (standard 500 gf/cm)
``E_warp``, ``E_weft``  gf/cm               a linear tensile stiffness measured otherwise
                                            (force per width per unit strain)
======================  ==================  =====================================================

A bare number is read in the unit the sheet prints; a string is read with its units by pint
(``weight = "124 g/m^2"``, ``B_warp = "1.16e-5 N*m"``; a weight given as a force per area,
``"0.0124 gf/cm^2"``, is divided by standard gravity).

**Plausible ranges.** Woven and knitted apparel fabrics span roughly W 3–50 mg/cm², T 0.1–3 mm,
B 0.005–1 gf·cm²/cm, 2HB 0.002–1 gf·cm/cm, G 0.2–5 gf/(cm·deg), 2HG 0.1–10 gf/cm,
EMT 1–50 %, LT 0.4–1, WT 2–50 gf·cm/cm² (Kawabata 1980; Kawabata & Niwa, *Fabric performance
in clothing and clothing manufacture*, J. Text. Inst. 80, 1989; Matsudaira, Kawabata & Niwa,
*The effect of fibre cross-sectional shape on fabric mechanical properties and handle*,
J. Text. Inst. 75, 1984, for thin dress fabrics at the tester's high sensitivity). The bounds
below are wider, by a factor of about 3 to 10 at each end, so that no real woven or knitted
fabric is refused; they are there to catch unit slips of a factor 100 or 1000 (gf/cm² for
mg/cm², SI for KES), which a bare number out of range names. Slips of a factor 10 inside the
bounds (e.g. a weight in g/m² below 100) cannot be told from a real fabric.

**The membrane from the sheet** (per unit width, N/m; engineering shear strain):

* ``G12 = G · (g₀·10⁻³ N / 10⁻² m) · (180/π)`` — KES G is per degree of shear angle; the
  membrane's is per radian: 1 gf/(cm·deg) = 56.19 N/m.
* Tensile curve per direction from the KES-FB1 values up to Fm: the power law of
  :mod:`constitutive.tensile`, with strain εm = EMT/100 at Fm and linearity LT. Any two of
  EMT, LT, WT give it (all three must agree within 10 %: a sheet rounds them); EMT alone
  takes the default LT = 0.65. Its linear stiffness storing the energy,
  ``E = 2 WT / εm² = LT · Fm / εm``, is E11 or E22 of the material; a drape case linearises
  the curve at the tension its specimen carries instead (``[model] membrane_tension``).
  ``E_warp`` / ``E_weft`` give a linear stiffness directly instead.
* ``B_bias`` gives the twist rigidity (see :meth:`KesSpec.twist_rigidity`).
* 2HG and 2HG5 are kept with the material (and in summary.json) but not used: the membrane
  is elastic.

Where the sheet is silent the membrane keeps the project's defaults
(:data:`constitutive.material.DEFAULT_MEMBRANE`: E11 = E22 = 1e4 N/m, G12 = 50 N/m, ν12 = 0;
in sheet terms G ≈ 0.89 gf/(cm·deg), and the tensile curve
:data:`constitutive.tensile.DEFAULT_TENSILE`, EMT ≈ 3.2 % at LT = 0.65: mid-range apparel
values).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from typing import Annotated

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, model_validator

from constitutive.tensile import DEFAULT_LINEARITY, MAX_LOAD_KES, TensileCurve
from constitutive.units import G0, parse_quantity, to_si, ureg

__all__ = ["SHEET", "SheetKey", "read_sheet_value", "sheet_field", "KesSpec",
           "TENSILE_LOAD", "LT_TOLERANCE"]

#: KES-FB1 standard maximum tensile load Fm [gf/cm].
TENSILE_LOAD = MAX_LOAD_KES
#: Relative disagreement allowed between WT and LT·Fm·εm/2 when all three are given.
LT_TOLERANCE = 0.10


@dataclass(frozen=True)
class SheetKey:
    """One value of a KES sheet: the unit a bare number is in, its plausible range, and the
    units a bare number out of range was likely written in (tried in order)."""

    unit: str              # pint unit of a bare number (what the sheet prints)
    label: str             # the unit as written in messages
    low: float             # plausible range, in ``unit``
    high: float
    below: tuple = ()      # (pint unit, what it is, its symbol) of slips giving too small a number
    above: tuple = ()      # ... too large a number
    zero_ok: bool = False  # 0 is a real value (no hysteresis)
    mass_per_area: bool = False   # a force per area given as a string is divided by g0


_SI_B = ("N*m", "N·m (SI)", "N·m")
SHEET = {
    "weight": SheetKey("mg/cm**2", "mg/cm²", 1.0, 100.0,
                       below=(("gf/cm**2", "gf/cm² (or g/cm²)", "gf/cm²"),
                              ("kg/m**2", "kg/m² (SI)", "kg/m²")),
                       above=(("g/m**2", "g/m²", "g/m²"),), mass_per_area=True),
    "thickness": SheetKey("mm", "mm", 0.05, 10.0, below=(("cm", "cm", "cm"), ("m", "m (SI)", "m")),
                          above=(("um", "µm", "µm"),)),
    "B": SheetKey("gf*cm**2/cm", "gf·cm²/cm", 1e-3, 30.0, below=(_SI_B,)),
    "HB2": SheetKey("gf*cm/cm", "gf·cm/cm", 1e-3, 20.0, below=(("N*m/m", "N·m/m (SI)", "N"),),
                    zero_ok=True),
    "G": SheetKey("gf/cm/degree", "gf/(cm·deg)", 0.02, 30.0,
                  above=(("N/m/radian", "N/m per radian (SI)", "N/m"),
                         ("gf/cm/radian", "gf/cm per radian", "gf/(cm·rad)"))),
    "HG2": SheetKey("gf/cm", "gf/cm", 1e-3, 50.0, zero_ok=True),
    "EMT": SheetKey("percent", "%", 0.3, 300.0, below=(("dimensionless", "a fraction", ""),)),
    "LT": SheetKey("dimensionless", "", 0.1, 1.5, above=(("percent", "a percentage", "%"),)),
    "WT": SheetKey("gf*cm/cm**2", "gf·cm/cm²", 0.1, 300.0),
    "E": SheetKey("gf/cm", "gf/cm", 50.0, 1e6),
    "Fm": SheetKey("gf/cm", "gf/cm", 10.0, 5000.0),
}


def _fmt(x: float) -> str:
    return f"{x:.4g}"


def _with_unit(x: float, spec: SheetKey) -> str:
    return f"{_fmt(x)} {spec.label}".rstrip()


def _span(spec: SheetKey) -> str:
    return f"{_fmt(spec.low)}–{_with_unit(spec.high, spec)}"


def _in_range(spec: SheetKey, x: float) -> bool:
    return (spec.zero_ok and x == 0.0) or spec.low <= x <= spec.high


def _to_sheet_unit(spec: SheetKey, q) -> float:
    """Magnitude of the pint quantity ``q`` in the sheet unit of ``spec`` (a weight given as a
    force per area is divided by standard gravity)."""
    if spec.mass_per_area and q.check("[force]/[area]"):
        q = q / ureg.Quantity(G0, "m/s**2")
    return float(q.to(spec.unit).magnitude)


def read_sheet_value(kind: str, value) -> float:
    """A sheet value in the unit the sheet prints, from a bare number or a unit string.

    Raises ``ValueError`` (worded for a schema error: the caller names the key) when it is
    not a number, has the wrong dimension, or lies outside the plausible range; a bare
    number out of range names the unit it was likely written in.

    >>> read_sheet_value("weight", 12.38), read_sheet_value("weight", "124 g/m^2")
    (12.38, 12.4)
    >>> read_sheet_value("weight", 0.01238)
    Traceback (most recent call last):
    ...
    ValueError: outside 1–100 mg/cm² of woven and knitted fabrics; looks like gf/cm² (or g/cm²): 0.01238 gf/cm² = 12.38 mg/cm². A KES sheet prints mg/cm²; write it so, or as a string with its units
    """
    spec = SHEET[kind]
    if isinstance(value, str):
        try:
            x = _to_sheet_unit(spec, parse_quantity(value))
        except Exception as exc:  # pint's errors, or text that is no quantity at all
            raise ValueError(f"cannot read {value!r} as a quantity in {spec.label} ({exc})") from None
        if not _in_range(spec, x):
            raise ValueError(f"is {_with_unit(x, spec)}: outside {_span(spec)} of woven and knitted "
                             "fabrics")
        return x
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"must be a number ({spec.label or 'a ratio'}) or a string with units")
    x = float(value)
    if _in_range(spec, x):
        return x
    where = f"outside {_span(spec)} of woven and knitted fabrics"
    if math.isfinite(x) and x > 0:
        for unit, what, symbol in spec.below if x < spec.low else spec.above:
            y = _to_sheet_unit(spec, ureg.Quantity(x, unit))
            if spec.low <= y <= spec.high:
                raise ValueError(f"{where}; looks like {what}: {_fmt(x)}{symbol and ' ' + symbol} = "
                                 f"{_with_unit(y, spec)}. A KES sheet prints {spec.label or 'a ratio'}; "
                                 f"write it so, or as a string with its units")
    raise ValueError(f"{where}; check the unit (a bare number is read in {spec.label or 'a ratio'})")


def sheet_field(kind: str, default=..., description: str = ""):
    """A pydantic field holding a sheet value of ``kind`` (see :data:`SHEET`) in its sheet unit."""
    spec = SHEET[kind]
    rng = f" Plausible: {_span(spec)}" + (" or 0." if spec.zero_ok else ".")
    ann = Annotated[float, BeforeValidator(partial(read_sheet_value, kind))]
    if default is None:
        ann = Annotated[ann | None, Field(None, description=description + rng)]
    elif default is ...:
        ann = Annotated[ann, Field(description=description + rng)]
    else:
        ann = Annotated[ann, Field(default, description=description + rng)]
    return ann


# --------------------------------------------------------------------------- the tables
class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


_DIRS = ("warp", "weft")
_TENSILE = ("EMT", "LT", "WT")


class KesSpec(_Strict):
    """A ``[kes]`` table of a material file: KES-F summary values, each a bare number in the
    unit the sheet prints or a string with units."""

    B_warp: sheet_field("B", description="Bending rigidity B, warp direction [gf·cm²/cm].")
    B_weft: sheet_field("B", description="Bending rigidity B, weft direction [gf·cm²/cm].")
    HB2_warp: sheet_field("HB2", description="Hysteresis width 2HB at |κ| = 1 cm⁻¹, warp "
                                             "[gf·cm/cm].")
    HB2_weft: sheet_field("HB2", description="Hysteresis width 2HB, weft [gf·cm/cm].")
    eps_f: float = Field(0.2, gt=0, description="Friction length ε_f [cm⁻¹] of the calibrated "
                                                 "friction (a1 = ε_f η).")
    eta: float = Field(0.5, gt=0, lt=1, description="Ratio η of the friction lengths.")
    f2_ratio: float = Field(0.0, ge=0, lt=1, description="f2/f1 of the calibrated friction: 0 "
                                                        "first order (Dahl, no static peak); "
                                                        "0 < f2/f1 < 1 second order (a static "
                                                        "peak after a reversal), with the same "
                                                        "B and 2HB.")
    accel_time: float | None = Field(None, gt=0, description="Acceleration time of the simulated "
                                                            "KES-FB test [s] (default: the tester's).")
    B_bias: sheet_field("B", None, "Bending rigidity of a bias specimen, 45° to warp and weft "
                                   "(KES-FB2) [gf·cm²/cm]; gives the twist rigidity "
                                   "D_t = 2 B_bias − (B_warp + B_weft)/2 (default √(B_warp B_weft)).")
    G: sheet_field("G", None, "Shear rigidity G [gf/(cm·deg)], mean of warp and weft; builds the "
                              "membrane's G12 = 56.19 G N/m (default G12 = 50 N/m).")
    HG2: sheet_field("HG2", None, "Shear hysteresis 2HG at 0.5° [gf/cm]; recorded, not used (the "
                                  "membrane is elastic).")
    HG2_5: sheet_field("HG2", None, "Shear hysteresis 2HG5 at 5° [gf/cm]; recorded, not used.")
    EMT_warp: sheet_field("EMT", None, "Tensile strain at Fm, warp [%]; with LT or WT (alone: "
                                       "LT = 0.65) builds the warp's tensile curve and E11.")
    EMT_weft: sheet_field("EMT", None, "Tensile strain at Fm, weft [%]; builds E22.")
    LT_warp: sheet_field("LT", None, "Linearity of the tensile curve, warp [1].")
    LT_weft: sheet_field("LT", None, "Linearity of the tensile curve, weft [1].")
    WT_warp: sheet_field("WT", None, "Tensile energy, warp [gf·cm/cm²]; E11 = 2 WT/εm².")
    WT_weft: sheet_field("WT", None, "Tensile energy, weft [gf·cm/cm²]; E22 = 2 WT/εm².")
    Fm: sheet_field("Fm", TENSILE_LOAD, "Maximum load of the tensile test [gf/cm].")
    E_warp: sheet_field("E", None, "Linear tensile stiffness per width, warp [gf/cm], instead of "
                                   "EMT/LT/WT.")
    E_weft: sheet_field("E", None, "Linear tensile stiffness per width, weft [gf/cm].")

    @model_validator(mode="after")
    def _bias_above_its_bound(self):
        if self.B_bias is not None and not self.B_bias > (self.B_warp + self.B_weft) / 4.0:
            raise ValueError(f"@.B_bias = {self.B_bias:g} gf·cm²/cm breaks B_bias > (B_warp + B_weft)/4 = "
                             f"{(self.B_warp + self.B_weft) / 4.0:.4g}: a bias specimen bent without "
                             "twisting is at least that stiff (the twist rigidity must be > 0)")
        return self

    def twist_rigidity(self) -> float | None:
        """D_t [gf·cm²/cm] from ``B_bias``, or ``None``.

        The KES-FB2 specimen is 20 cm wide and bent over a 1 cm gap between chucks that hold
        its whole width, so it bends cylindrically: curvature κ along the specimen's length
        n = (cos θ, sin θ), none across it, no twist. With the bending energy
        ½B₁κ₁₁² + ½B₂κ₂₂² + D_t κ₁₂² (docs/theory.md) its rigidity is
        B(θ) = B₁cos⁴θ + B₂sin⁴θ + 2 D_t sin²θ cos²θ, and at 45°
        ``D_t = 2 B_bias − (B_warp + B_weft)/2``. (A narrow strip free to twist, as in a
        cantilever test, would give the compliance form instead, 4/B₄₅ = 1/B₁ + 1/B₂ + 2/D_t.)

        >>> KesSpec(B_warp=0.1, B_weft=0.1, HB2_warp=0.05, HB2_weft=0.05, B_bias=0.1).twist_rigidity()
        0.1
        """
        if self.B_bias is None:
            return None
        return 2.0 * self.B_bias - (self.B_warp + self.B_weft) / 2.0

    @model_validator(mode="after")
    def _tensile_complete(self):
        for d in _DIRS:
            given = [k for k in _TENSILE if getattr(self, f"{k}_{d}") is not None]
            if getattr(self, f"E_{d}") is not None and given:
                raise ValueError(f"give @.E_{d} or the tensile values ({', '.join(f'@.{k}_{d}' for k in given)}), "
                                 "not both")
            if given in (["LT"], ["WT"]):
                raise ValueError(f"@.{given[0]}_{d} alone does not give a stiffness: add @.EMT_{d}")
            if len(given) == 3:
                emt, lt, wt = (getattr(self, f"{k}_{d}") for k in _TENSILE)
                expected = lt * self.Fm * emt / 200.0
                if abs(wt - expected) > LT_TOLERANCE * wt:
                    raise ValueError(
                        f"@.EMT_{d} = {emt:g} %, @.LT_{d} = {lt:g} and @.WT_{d} = {wt:g} disagree: "
                        f"LT·Fm·EMT/2 = {expected:.4g} gf·cm/cm² should be WT (LT is defined so) "
                        f"within {LT_TOLERANCE:.0%}")
        return self

    def tensile_curves(self) -> dict:
        """``{key: (TensileCurve, source text)}`` for E11 (warp) and E22 (weft) where the sheet
        gives tensile values (see the module docstring); a missing LT is the default."""
        out = {}
        for d, key in zip(_DIRS, ("E11", "E22")):
            emt, lt, wt = (getattr(self, f"{k}_{d}") for k in _TENSILE)
            fm = self.Fm
            if emt is not None:
                eps = emt / 100.0
                if lt is not None:
                    how = f"EMT_{d} = {emt:g} %, LT_{d} = {lt:g}"
                elif wt is not None:
                    lt = 2.0 * wt / (fm * eps)
                    how = f"EMT_{d} = {emt:g} %, WT_{d} = {wt:g} gf·cm/cm² (LT = {lt:.3g})"
                else:
                    lt = DEFAULT_LINEARITY
                    how = f"EMT_{d} = {emt:g} % with the default LT = {lt:g}"
            elif lt is not None and wt is not None:
                eps = 2.0 * wt / (lt * fm)
                how = f"LT_{d} = {lt:g}, WT_{d} = {wt:g} gf·cm/cm² (EMT = {100 * eps:.3g} %)"
            else:
                continue
            out[key] = (TensileCurve(eps, lt, to_si(fm, "E_tensile")), f"KES {how}, Fm = {fm:g} gf/cm")
        return out

    def membrane(self) -> tuple[dict, dict]:
        """The membrane stiffnesses this sheet determines: ``({key: N/m}, {key: source text})``
        for the keys among E11, E22, G12 it gives (see the module docstring). E11 and E22 are
        the linear stiffnesses storing the tensile energy, 2 WT/εm², or ``E_warp``/``E_weft``."""
        values, sources = {}, {}
        if self.G is not None:
            values["G12"] = to_si(self.G, "G")
            sources["G12"] = f"KES G = {self.G:g} gf/(cm·deg) × 56.19 (per degree → per radian)"
        curves = self.tensile_curves()
        for d, key in zip(_DIRS, ("E11", "E22")):
            direct = getattr(self, f"E_{d}")
            if direct is not None:
                values[key], sources[key] = to_si(direct, "E_tensile"), f"KES E_{d} = {direct:g} gf/cm"
            elif key in curves:
                curve, how = curves[key]
                values[key], sources[key] = curve.secant, f"2 WT/εm² of the {how}"
        return values, sources

    def extras_si(self) -> dict:
        """The sheet's values other than B and 2HB that were given, in SI (N/m, strain, J/m²)."""
        names = {"B_bias": "B", "G": "G", "HG2": "HG2", "HG2_5": "HG2", "Fm": "E_tensile"}
        names.update({f"{k}_{d}": k if k != "E" else "E_tensile" for k in (*_TENSILE, "E") for d in _DIRS})
        out = {}
        for key, kind in names.items():
            value = getattr(self, key)
            if value is not None and (key != "Fm" or any(getattr(self, f"{k}_{d}") is not None
                                                         for k in _TENSILE for d in _DIRS)):
                out[key] = to_si(value, kind)
        return out
