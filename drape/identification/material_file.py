"""The identified fabric as a material file (``cases/materials/*.toml`` format, a ``[kes]`` table).

The file is what ``[material] path = "..."`` of a case, or
:func:`constitutive.material.load_material`, reads: the weight the identification ran at and
the KES values its parameters give there (:func:`drape.identification.parameters.kes_values`).
A drape fixes B/W and 2HB/W, not B: the weight is the case's (or ``--weight``), and B scales
with it.
"""
from __future__ import annotations

from pathlib import Path

import tomli_w

from constitutive.material import MaterialError, load_material
from constitutive.units import to_kes
from drape.identification.parameters import kes_values

__all__ = ["write_material"]


def _law_tables(material) -> dict:
    """``[warp]`` and ``[weft]`` law tables (KES units) of a built material."""
    tables = {}
    for direction in ("warp", "weft"):
        law = getattr(material, direction)
        table = {k: float(f"{to_kes(getattr(law, k), k):.6g}") for k in ("k1", "k3", "d", "m")}
        if law.k1_neg is not None:
            table["k1_neg"] = float(f"{to_kes(law.k1_neg, 'k1_neg'):.6g}")
        if law.friction is not None:
            for k in ("f1", "f2", "eps_f", "eta"):
                table[k] = float(f"{to_kes(getattr(law.friction, k), k):.6g}")
        tables[direction] = table
    return tables


def write_material(path, name: str, point: dict, weight: float, thickness: float | None,
                   intervals: dict, scans: int, built=None) -> Path:
    """Write the material file of a full point and check that it loads; return its path.

    The file gives the fabric's KES values (a ``[kes]`` table) where they lie in a KES sheet's
    plausible range at ``weight``; otherwise (a bending length too short or too long for
    that weight) the laws of ``built``, the material a run of the point builds, as ``[warp]``
    and ``[weft]`` tables.
    """
    kes = {k: float(f"{v:.5g}") for k, v in kes_values(point, weight).items()}
    if point.get("shear_G") is not None:
        kes["G"] = float(f"{point['shear_G']:.4g}")
    data = {"name": name,
            "description": "Identified from its Cusick drapes: bending length c = "
                           f"{point['bending_length']:.3g} cm, 2HB/B = "
                           f"{point.get('hysteresis') or 0.5:.3g} 1/cm",
            "source": f"drape identify from {scans} scanned drapes (B/W and 2HB/W identified; "
                      f"B at W = {weight:g} mg/cm²)",
            "weight": weight}
    if thickness is not None:
        data["thickness"] = thickness
    data["kes"] = kes
    if point.get("face_down") not in (None, 1.0) and built is not None:
        data.pop("kes")          # a [kes] table cannot say it; the law tables can
        data.update(_law_tables(built))
    lines = [f"# {k}: interval {v['low']:.4g} .. {v['high']:.4g} (identified.json says how it "
             f"was computed)" for k, v in intervals.items()]
    path = Path(path)
    path.write_text("\n".join(lines) + "\n" + tomli_w.dumps(data))
    try:
        load_material(path)
    except MaterialError:
        if built is None:
            raise
        data.pop("kes", None)
        data.update(_law_tables(built))
        lines.append("# B outside a KES sheet's plausible range at this weight: the law tables")
        path.write_text("\n".join(lines) + "\n" + tomli_w.dumps(data))
        load_material(path)      # refuse to hand over a file the library cannot read
    return path
