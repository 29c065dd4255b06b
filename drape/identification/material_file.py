"""The identified fabric as a material file (``cases/materials/*.toml`` format).

The file is what ``[material] path = "..."`` of a case, or
:func:`constitutive.material.load_material`, reads: the weight the identification ran at and
the KES values its parameters give there (:func:`drape.identification.parameters.kes_values`).
A drape fixes B/W and 2HB/W, not B: the weight is the case's (or ``--weight``), and B scales
with it.

**The whole fabric of the runs travels.** An identification's forward runs build their
material from the base case's ``[material.kes]`` table, the definition's ``--set`` items and
the point's overrides (:func:`drape.identification.parameters.overrides`); the point sets B
and 2HB (and, if freed, the anisotropy, the face-down ratio and G), the rest is the base's:
its shear rigidity G, thickness, 2HG, tensile values, friction lengths, ... The file carries
all of it, so that the file given as the whole ``[material]`` table of the base case,

.. code-block:: toml

    [material]
    path = "out/identify/material.toml"

builds the same material as the runs of the point did (laws, areal mass, thickness, twist
rigidity and membrane; the set-up's own ``[model]`` keys, such as ``membrane_tension``,
act on it as they did on the runs). Two forms:

* a ``[kes]`` table (with ``[membrane]`` for membrane stiffnesses the runs took from
  ``[model.membrane]``), where the point's KES values lie in a KES sheet's plausible range
  at the weight and the runs' material is the sheet's (no face-down ratio, no law overrides);
* otherwise the runs' laws as ``[warp]`` and ``[weft]`` tables, with the membrane in
  ``[membrane]`` (N/m: G12 always, so the shear travels; ν12 where it is not 0; E11, E22
  as numbers where the runs had numbers, as ``[membrane.tensile_warp]`` /
  ``[membrane.tensile_weft]`` curves where the runs took them on a sheet's tensile curve,
  nothing where on the default curve: :class:`constitutive.material.spec.MembraneSpec`) and
  ``twist_rigidity`` where it is not the default √(k1_warp k1_weft).

Given the base case, :func:`write_material` builds the file on it and compares with the runs'
material; the ``[kes]`` form that does not build the same material gives way to the law
tables, and law tables that do not (a ``--set`` of the set-up, not of the material, that no
material file can carry) are written with a comment naming each difference, and a warning.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import tomli_w

from constitutive.material import DEFAULT_MEMBRANE, MaterialError, load_material
from constitutive.tensile import DEFAULT_TENSILE
from constitutive.units import to_kes
from drape.case.build import build_material
from drape.case.case import parse_case, read_case_data
from drape.identification.parameters import kes_values

__all__ = ["write_material", "material_differences", "built_on_base"]

#: Relative difference up to which two built values count as the same (they differ by the
#: rounding of the file's numbers to :data:`DIGITS` digits and by KES ↔ SI round-off).
SAME = 1e-9
#: Significant digits of the values the runs' material gives the file.
DIGITS = 12

_BENDING = ("B_warp", "B_weft", "HB2_warp", "HB2_weft")
#: The ``[kes]`` keys that build each membrane stiffness.
_SHEET_MEMBRANE = {"G12": ("G",),
                   "E11": ("EMT_warp", "LT_warp", "WT_warp", "E_warp"),
                   "E22": ("EMT_weft", "LT_weft", "WT_weft", "E_weft")}


def _exact(x) -> float:
    return float(f"{float(x):.{DIGITS}g}")


def _law_tables(material) -> dict:
    """``[warp]`` and ``[weft]`` law tables (KES units) of a built material."""
    tables = {}
    for direction in ("warp", "weft"):
        law = getattr(material, direction)
        table = {k: _exact(to_kes(getattr(law, k), k)) for k in ("k1", "k3", "d", "m")}
        for k in ("k1_neg", "k3_neg"):
            if getattr(law, k) is not None:
                table[k] = _exact(to_kes(getattr(law, k), k))
        if law.friction is not None:
            for k in ("f1", "f2", "eps_f", "eta"):
                table[k] = _exact(to_kes(getattr(law.friction, k), k))
        tables[direction] = table
    return tables


def _twist_given(material) -> bool:
    return not material.describe()["twist_rigidity_source"].startswith("default")


def _membrane_table(material) -> dict:
    """``[membrane]`` (N/m) of a built material for the law-table form: G12, ν12 where not 0,
    and E11, E22 as numbers or, where the runs took them on a tensile curve other than the
    default, that curve (``[membrane.tensile_warp]``, ``[membrane.tensile_weft]``)."""
    table = {"G12": _exact(material.G12)}
    if material.nu12 != DEFAULT_MEMBRANE["nu12"]:
        table["nu12"] = _exact(material.nu12)
    for key, direction in (("E11", "warp"), ("E22", "weft")):
        curve = material.tensile.get(key)
        if curve is None:
            table[key] = _exact(getattr(material, key))
        elif curve != DEFAULT_TENSILE:          # the default curve is built again from nothing
            table[f"tensile_{direction}"] = {"strain_at_max": float(curve.strain_at_max),
                                             "linearity": float(curve.linearity),
                                             "max_load": float(curve.max_load)}
    return table


def _sheet_form(case, point: dict, weight: float) -> tuple[dict, dict] | None:
    """``(top-level keys, [kes] table)`` of the runs' material, or ``None`` where a ``[kes]``
    table cannot say it (a face-down ratio, law overrides, friction dropped)."""
    if point.get("face_down") not in (None, 1.0):
        return None
    if case is None:                      # the point alone (no run's case at hand)
        kes = {k: float(f"{v:.5g}") for k, v in kes_values(point, weight).items()}
        if point.get("shear_G") is not None:
            kes["G"] = float(f"{point['shear_G']:.4g}")
        return {}, kes
    spec = case.material
    if (spec.face_down_ratio != 1.0 or not spec.friction
            or any(spec.law_overrides(d) for d in ("warp", "weft"))):
        return None
    kes = spec.kes.model_dump(exclude_none=True, exclude_defaults=True)
    for key in _BENDING:   # a run's KES values are a reference fabric's, times bending_scale
        kes[key] = _exact(getattr(spec.kes, key) * spec.bending_scale)
    top = {"weight": kes.pop("weight")}
    kes.pop("thickness", None)
    if spec.areal_mass is not None:
        top["weight"] = _exact(to_kes(spec.areal_mass, "weight"))
    membrane = {} if case.model.membrane is None else case.model.membrane.model_dump(exclude_none=True)
    for key in membrane:
        for sheet_key in _SHEET_MEMBRANE.get(key, ()):
            kes.pop(sheet_key, None)       # [membrane] wins over the sheet, as in the runs
    if membrane:
        top["membrane"] = {k: float(v) for k, v in membrane.items()}
    return top, kes


def built_on_base(path, base):
    """The material (SI) the base case builds with its ``[material]`` table replaced by
    ``path = <path>``."""
    base = Path(base)
    data = read_case_data(base)
    data["material"] = {"path": str(Path(path).resolve())}
    return build_material(parse_case(data, base_dir=base.parent))


def material_differences(a, b, rel: float = SAME) -> list[str]:
    """What differs between two built materials (SI): areal mass, thickness, twist rigidity,
    membrane (E11, E22, ν12, G12, and the tensile curves behind E11 and E22) and each law's
    parameters, as ``"key: a against b"``."""
    def values(m):
        out = {k: getattr(m, k) for k in ("areal_mass", "thickness", "twist_rigidity",
                                           *DEFAULT_MEMBRANE)}
        for d in ("warp", "weft"):
            law = getattr(m, d)
            out.update({f"{d}.{k}": getattr(law, k) for k in ("k1", "k3", "d", "m", "k1_neg", "k3_neg")})
            fr = law.friction
            out.update({f"{d}.{k}": None if fr is None else getattr(fr, k)
                        for k in ("f1", "f2", "eps_f", "eta")})
        for key in ("E11", "E22"):
            curve = m.tensile.get(key)
            out.update({f"{key} curve {k}": None if curve is None else getattr(curve, k)
                        for k in ("strain_at_max", "linearity", "max_load")})
        return out

    va, vb = values(a), values(b)
    out = []
    for key, x in va.items():
        y = vb[key]
        if (x is None) != (y is None) or (x is not None and not math.isclose(
                float(x), float(y), rel_tol=rel, abs_tol=0.0)):
            out.append(f"{key}: {x!r} against {y!r}")
    return out


def write_material(path, name: str, point: dict, weight: float, thickness: float | None,
                   intervals: dict, scans: int, built=None, case=None, base=None) -> Path:
    """Write the material file of a full point and check that it loads; return its path.

    Parameters
    ----------
    path : str or Path
    name : str
        The material's name.
    point : dict
        The full point (:func:`drape.identification.parameters.full_point`).
    weight : float
        W [mg/cm²] the identification ran at.
    thickness : float or None
        T [mm]; where ``case`` is given, the case's own is written instead.
    intervals : dict
        ``{parameter: {"low", "high"}}``, written as comments.
    scans : int
        How many scanned drapes the identification matched.
    built : FabricMaterial, optional
        The material a run of the point builds (SI); needed for the law-table form.
    case : drape.case.case.Case, optional
        The case a run of the point loads (base case, the definition's ``--set`` items, the
        weight and the point's overrides): what its material takes from the base beyond the
        point (G, thickness, 2HG, ...) goes into the file. Without it the file holds the
        point's KES values only.
    base : str or Path, optional
        The base case file: the file is built on it (:func:`built_on_base`) and compared with
        ``built`` (see the module docstring).

    The file gives the fabric's KES values (a ``[kes]`` table) where they lie in a KES sheet's
    plausible range at ``weight`` and say the runs' material; otherwise (a bending length too
    short or too long for that weight, a face-down ratio) the laws of ``built``, with its
    membrane, as ``[warp]``, ``[weft]`` and ``[membrane]`` tables.
    """
    if case is not None:
        spec = case.material
        thickness = (_exact(to_kes(spec.thickness, "thickness")) if spec.thickness is not None
                     else spec.kes.thickness)
    data = {"name": name,
            "description": "Identified from its Cusick drapes: bending length c = "
                           f"{point['bending_length']:.3g} cm, 2HB/B = "
                           f"{point.get('hysteresis') or 0.5:.3g} 1/cm",
            "source": f"drape identify from {scans} scanned drapes (B/W and 2HB/W identified; "
                      f"B at W = {weight:g} mg/cm²)",
            "weight": weight}
    if thickness is not None:
        data["thickness"] = thickness
    lines = [f"# {k}: interval {v['low']:.4g} .. {v['high']:.4g} (identified.json says how it "
             f"was computed)" for k, v in intervals.items()]
    path = Path(path)

    def write(body: dict, notes=()):
        path.write_text("\n".join([*lines, *notes]) + "\n" + tomli_w.dumps(body))

    def laws(why: str):
        body = dict(data)
        body["weight"] = _exact(to_kes(built.areal_mass, "weight"))
        if _twist_given(built):
            body["twist_rigidity"] = _exact(to_kes(built.twist_rigidity, "twist_rigidity"))
        body.update(_law_tables(built))
        body["membrane"] = _membrane_table(built)
        write(body, [why])
        load_material(path)      # refuse to hand over a file the library cannot read

    def differences_on_base() -> list[str]:
        """What the written file, on the base case, builds otherwise than the runs did."""
        if base is None or built is None:
            return []
        return material_differences(built_on_base(path, base), built)

    sheet = _sheet_form(case, point, weight)
    if sheet is None:
        if built is None:
            raise ValueError("the point's material needs law tables: give built")
        laws("# a [kes] table cannot say the runs' material (face-down ratio or law "
             "overrides): the laws of the runs")
    else:
        top, kes = sheet
        body = {**data, **{k: v for k, v in top.items() if k != "membrane"}}
        if built is not None and "B_bias" in kes:
            kes.pop("B_bias")    # the runs' twist came from it at the reference B: keep theirs
        if built is not None and _twist_given(built):
            body["twist_rigidity"] = _exact(to_kes(built.twist_rigidity, "twist_rigidity"))
        body["kes"] = kes
        if "membrane" in top:
            body["membrane"] = top["membrane"]
        write(body)
        try:
            load_material(path)
            differ = differences_on_base()
            ok = not differ
        except MaterialError:
            if built is None:
                raise
            ok = False
        if not ok:
            laws("# B outside a KES sheet's plausible range at this weight, or a [kes] table "
                 "that does not build the runs' material: the law tables")
    if base is not None and built is not None:
        if sheet is None or not ok:
            differ = differences_on_base()
        if differ:
            text = path.read_text()
            path.write_text("# on the base case this file does not build the runs' material "
                            "(what differs, here against the runs):\n"
                            + "".join(f"#   {d}\n" for d in differ) + text)
            warnings.warn(f"{path}: on the base case it builds another material than the "
                          f"identification's runs: {'; '.join(differ)}", stacklevel=2)
    return path
