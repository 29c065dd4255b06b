"""The parameters an identification looks for, their box, and the case keys they set.

A drape at rest depends on the fabric's weight W only through B/W and 2HB/W (the weight
scales every load, the laws every moment), so the parameters are ratios: the bending length
``c = (B/W)^(1/3)`` (Peirce 1930; B the geometric mean of warp and weft) and the hysteresis
``2HB/B`` (KES-FB, Kawabata 1980). They set the ``[material.kes]`` values of a KES-only
Cusick case (``cases/cusick_kes.toml``) at the case's own weight:

    B = W c³,   B_warp = B √a,   B_weft = B / √a,   2HB_dir = (2HB/B) B_dir

with ``a = B_warp / B_weft`` the anisotropy (1 unless freed). A run gets them as the KES
values of a reference fabric (B = :data:`REFERENCE_B`, the same 2HB/B and anisotropy) scaled
by ``material.bending_scale = W c³ / REFERENCE_B``: the law's moments all scale with it, so the
run's B and 2HB are exactly the point's, and a bending length whose B would lie outside the
KES sheet's plausible range at the case's weight can still be run (only the ratios matter). Optional parameters: the
anisotropy, the face-down asymmetry ``k1_neg / k1`` (:class:`drape.case.material_tables.CaseMaterial`
``face_down_ratio``) and the KES shear rigidity G. Every parameter is searched on a log scale
(they are positive ratios spanning a decade or more).

KES units throughout (the material file's): W in mg/cm² (weight 10⁻³ gf/cm²), B in gf·cm²/cm,
2HB in gf·cm/cm, c in cm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Parameter", "PARAMETERS", "REFERENCE_B", "DEFAULT_FREE", "parse_box", "check_box",
           "full_point", "kes_values", "overrides"]


@dataclass(frozen=True)
class Parameter:
    """One identifiable parameter.

    Attributes
    ----------
    name : str
        The ``--free`` key.
    unit : str
        Its unit, as reports print it.
    low, high : float
        The default search box.
    fixed : float or None
        Its value when not freed (None: the base case's own).
    what : str
    limits : tuple of float
        The widest box ``--box`` may give it: past them no fabric hangs in a Cusick tester
        (or the KES sheet's plausible range ends).
    """

    name: str
    unit: str
    low: float
    high: float
    fixed: float | None
    what: str
    limits: tuple = (0.0, math.inf)


#: The parameters by ``--free`` key. The default box of c spans drape coefficients of about
#: 12 to 95 % (apparel fabrics hang between); 2HB/B spans typical woven fabrics. Their limits
#: lie a decade or so beyond (G's are the KES sheet's plausible range).
PARAMETERS: dict[str, Parameter] = {p.name: p for p in (
    Parameter("bending_length", "cm", 0.6, 3.0, None, "c = (B/W)^(1/3), B = √(B_warp B_weft)",
              (0.1, 20.0)),
    Parameter("hysteresis", "1/cm", 0.25, 1.5, 0.5, "2HB/B, the bending hysteresis per rigidity",
              (0.01, 20.0)),
    Parameter("anisotropy", "1", 0.4, 2.5, 1.0, "B_warp / B_weft", (0.05, 20.0)),
    Parameter("face_down", "1", 0.5, 2.0, 1.0, "k1_neg / k1, face-down against face-up rigidity",
              (0.1, 10.0)),
    Parameter("shear_G", "gf/(cm·deg)", 0.3, 3.0, None, "KES shear rigidity G", (0.02, 30.0)),
)}

#: B (gf·cm²/cm) of the reference fabric a run's KES values describe before bending_scale.
REFERENCE_B = 0.1

#: Freed when ``--free`` is not given.
DEFAULT_FREE = ("bending_length", "hysteresis")


def parse_box(items, free) -> dict[str, tuple[float, float]]:
    """The search box of the free parameters: the defaults, with ``KEY=LOW,HIGH`` items.

    >>> parse_box(["bending_length=1,3"], ["bending_length", "hysteresis"])
    {'bending_length': (1.0, 3.0), 'hysteresis': (0.25, 1.5)}
    >>> parse_box(["hysteresis=2,1"], ["hysteresis"])
    Traceback (most recent call last):
    ...
    ValueError: --box hysteresis=2,1: need 0 < LOW < HIGH
    >>> parse_box(["bending_length=0.01,3"], ["bending_length"])
    Traceback (most recent call last):
    ...
    ValueError: --box bending_length=0.01,3: bending_length must lie within 0.1..20 cm
    """
    box = {k: (PARAMETERS[k].low, PARAMETERS[k].high) for k in free}
    for item in items or []:
        key, _, text = item.partition("=")
        if key not in box:
            raise ValueError(f"--box {item}: {key!r} is not a free parameter (free: {', '.join(free)})")
        try:
            low, high = (float(v) for v in text.split(","))
        except ValueError:
            raise ValueError(f"--box {item}: give KEY=LOW,HIGH (two numbers)") from None
        box[key] = _checked_range(key, low, high, f"--box {item}")
    return box


def _checked_range(key: str, low: float, high: float, what: str) -> tuple[float, float]:
    """``(low, high)`` if it is a range within the parameter's limits; else ValueError."""
    p = PARAMETERS[key]
    if not 0 < low < high:
        raise ValueError(f"{what}: need 0 < LOW < HIGH")
    if not p.limits[0] <= low < high <= p.limits[1]:
        raise ValueError(f"{what}: {key} must lie within {p.limits[0]:g}..{p.limits[1]:g} {p.unit}")
    return low, high


def check_box(box, free) -> dict[str, tuple[float, float]]:
    """A stored box checked: a range within its limits for every free parameter, no other.

    >>> check_box({"bending_length": [1, 3]}, ["bending_length"])
    {'bending_length': (1.0, 3.0)}
    """
    if not isinstance(box, dict) or set(box) != set(free):
        raise ValueError(f"--box: a range for each free parameter ({', '.join(free)}), no other")
    checked = {}
    for key in free:
        value = box[key]
        try:
            if not isinstance(value, (list, tuple)) or len(value) != 2:
                raise TypeError
            low, high = (float(v) for v in value)
        except (TypeError, ValueError):
            raise ValueError(f"--box {key}={value!r}: give KEY=LOW,HIGH (two numbers)") from None
        checked[key] = _checked_range(key, low, high, f"--box {key}={low:g},{high:g}")
    return checked


def full_point(point: dict, free) -> dict:
    """Every parameter's value at ``point`` (the free ones) and the fixed values (the others;
    None where the base case keeps its own)."""
    return {k: (point[k] if k in free else p.fixed) for k, p in PARAMETERS.items()}


def kes_values(point: dict, weight: float) -> dict:
    """KES values (gf·cm²/cm, gf·cm/cm) of a full point at weight W (mg/cm²).

    >>> v = kes_values({"bending_length": 2.0, "hysteresis": 0.5, "anisotropy": 4.0}, 12.5)
    >>> round(v["B_warp"], 6), round(v["B_weft"], 6), round(v["HB2_warp"], 6)
    (0.2, 0.05, 0.1)
    """
    b = weight * 1e-3 * point["bending_length"] ** 3
    a = math.sqrt(point.get("anisotropy") or 1.0)
    h = point.get("hysteresis") or PARAMETERS["hysteresis"].fixed
    return {"B_warp": b * a, "B_weft": b / a, "HB2_warp": h * b * a, "HB2_weft": h * b / a}


def overrides(point: dict, weight: float) -> list[str]:
    """The ``--set`` items of a full point for a KES-only case at weight W (mg/cm²).

    >>> overrides({"bending_length": 1.0, "hysteresis": 0.5, "anisotropy": 1.0,
    ...            "face_down": 1.0, "shear_G": None}, 12.5)  # doctest: +NORMALIZE_WHITESPACE
    ['material.kes.B_warp=0.1', 'material.kes.B_weft=0.1', 'material.kes.HB2_warp=0.05',
     'material.kes.HB2_weft=0.05', 'material.bending_scale=0.125']
    """
    values = kes_values(point, weight)
    scale = math.sqrt(values["B_warp"] * values["B_weft"]) / REFERENCE_B
    items = [f"material.kes.{k}={v / scale:.6g}" for k, v in values.items()]
    items.append(f"material.bending_scale={scale:.6g}")
    if point.get("face_down") not in (None, 1.0):
        items.append(f"material.face_down_ratio={point['face_down']:.6g}")
    if point.get("shear_G") is not None:
        items.append(f"material.kes.G={point['shear_G']:.6g}")
    return items
