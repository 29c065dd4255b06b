"""What is fitted: the model variants, parameter units, and the thesis's own parameters.
"""
from __future__ import annotations

from dataclasses import dataclass

from constitutive import units as _units
from constitutive.kes import DEFAULT_ACCEL_TIME as KES_DEFAULT_ACCEL_TIME
from constitutive.material import load_material

__all__ = ['DEFAULT_ACCEL_TIME', 'PARAM_UNITS', 'DERIVED_UNITS', 'to_kes', 'from_kes', 'THESIS_RESIDUALS', 'thesis_law', 'Variant', 'VARIANTS', 'THESIS_VARIANTS']


DEFAULT_ACCEL_TIME = KES_DEFAULT_ACCEL_TIME  # s, the project's one equipment constant (0.5 s)

# ---------------------------------------------------------------------------
# KES <-> SI factors of the parameters (the I/O boundary)
# ---------------------------------------------------------------------------
_SHOW = {"gf*cm**2/cm": "gf·cm²/cm", "gf*cm**4/cm": "gf·cm⁴/cm", "gf*cm**2*s/cm": "gf·cm²·s/cm",
         "gf*cm**2*s**2/cm": "gf·cm²·s²/cm", "gf*cm/cm": "gf·cm/cm", "1/cm": "cm⁻¹",
         "dimensionless": "-"}
PARAM_UNITS = {n: (_SHOW[_units.KES_UNITS[n]], _units.factor(n))  # name: (KES unit, SI per KES unit)
               for n in ("m", "d", "k1", "k3", "k1_neg", "k3_neg", "f1", "f2", "eps_f", "eta")}
DERIVED_UNITS = {n: (_SHOW[_units.KES_UNITS[n]], _units.factor(n))
                 for n in ("f_k", "f_s", "s_e", "s_p")}


def to_kes(params):
    """SI parameter dict -> KES units (see :data:`PARAM_UNITS`)."""
    return {k: (None if v is None else v / PARAM_UNITS[k][1]) for k, v in params.items()}


def from_kes(params):
    """KES parameter dict -> SI."""
    return {k: (None if v is None else v * PARAM_UNITS[k][1]) for k, v in params.items()}


# ---------------------------------------------------------------------------
# Thesis reference values
# ---------------------------------------------------------------------------
# Residuals the thesis reports for its own fits (Tables 4.6, 4.9, 4.12, 4.15).
THESIS_RESIDUALS = {
    "fabric1-warp": dict(table="4.6", full=1.104e-2, **{"no-decel": 1.545e-2}, **{
        "no-friction": 2.523e-2, "no-cubic": 5.792e-2, "linear": 8.977e-2}),
    "fabric1-weft": dict(table="4.9", full=1.974e-2, **{"no-decel": 2.250e-2}, **{
        "no-friction": 3.879e-2, "no-cubic": 2.138e-2, "linear": 4.474e-2}),
    "fabric2-warp": dict(table="4.12", full=1.067e-1, **{"no-decel": 1.200e-1}, **{
        "no-friction": 1.663e-1, "no-cubic": 1.780e-1, "linear": 2.791e-1}),
    "fabric2-weft": dict(table="4.15", full=4.479e-2, **{"no-decel": 4.486e-2}, **{
        "no-friction": 4.482e-2, "no-cubic": 5.367e-2, "linear": 6.683e-2}),
}


def thesis_law(name):
    """The thesis's published full-model law for a dataset (SI), m = 0.

    Taken from the material library (``cases/materials/fabric1.toml``,
    ``fabric2.toml``: Tables 4.4, 4.7, 4.10, 4.13 as printed; the Fabric 2
    weft tie f1 = f2 is resolved there with Table 4.14's f_k).

    >>> law = thesis_law("fabric1-warp")
    >>> round(_units.to_kes(law.k1, "k1"), 6), law.m
    (0.00638, 0.0)
    """
    if name not in THESIS_RESIDUALS:
        raise ValueError(f"no published parameters for {name!r}; known: {', '.join(THESIS_RESIDUALS)}")
    fabric, direction = name.split("-")
    return getattr(load_material(fabric), direction)


# ---------------------------------------------------------------------------
# Variants
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Variant:
    """One model variant of Tables 4.6/4.9/4.12/4.15 (or the asymmetric one)."""

    name: str
    label: str
    friction: bool = True
    cubic: bool = True
    decelerate_at_end: bool = True
    asymmetric: bool = False


VARIANTS = {v.name: v for v in (
    Variant("full", "Full model"),
    Variant("no-decel", "No deceleration at end", decelerate_at_end=False),
    Variant("no-friction", "No friction term", friction=False),
    Variant("no-cubic", "No cubic term", cubic=False),
    Variant("linear", "No friction or cubic term", friction=False, cubic=False),
    Variant("asymmetric", "Full, face-down k1/k3", asymmetric=True),
)}
THESIS_VARIANTS = ("full", "no-decel", "no-friction", "no-cubic", "linear")


def _variant(v):
    if isinstance(v, Variant):
        return v
    if v not in VARIANTS:
        raise ValueError(f"variant {v!r} is not one of {', '.join(VARIANTS)}")
    return VARIANTS[v]


# ---------------------------------------------------------------------------
# Model evaluation
# ---------------------------------------------------------------------------
