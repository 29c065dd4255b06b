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

from constitutive.material import load_material
from drape.identification.parameters import kes_values

__all__ = ["write_material"]


def write_material(path, name: str, point: dict, weight: float, thickness: float | None,
                   intervals: dict, scans: int) -> Path:
    """Write the material file of a full point and check that it loads; return its path."""
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
    lines = [f"# {k}: interval {v['low']:.4g} .. {v['high']:.4g} (identified.json says how it "
             f"was computed)" for k, v in intervals.items()]
    if point.get("face_down") not in (None, 1.0):
        lines.append(f"# face-down asymmetry: run it with [material] face_down_ratio = "
                     f"{point['face_down']:.4g}")
    path = Path(path)
    path.write_text("\n".join(lines) + "\n" + tomli_w.dumps(data))
    load_material(path)          # refuse to hand over a file the library cannot read
    return path
