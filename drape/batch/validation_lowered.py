"""The validation fabrics let down as ``cases/cusick_lowered.toml`` lets its specimen down.

The shipped validation cases (``cases/validation``) lay the specimen on the disc under a gravity
ramp, as ``cases/cusick_kes.toml`` does. :func:`lowered_case` works a validation case as the
lowered case works its specimen: on the tester's support, lowered away, with the specimen's
rigidity varying over it. The case gets the lowered case's ``[contact]`` (the support placed
half the fabric's thickness plus half the barrier layer below it), its
``[model.rigidity_variation]``, the full weight at once, and, where the fabric's sheet gives no
shear rigidity G, the lowered set-up's. Everything else (tester, mesh, fabric, damping, solver)
stays the validation case's own. :func:`write_lowered_cases` writes a folder of them, which
runs as a validation set (:mod:`drape.batch.validation_set`).
"""
from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import tomli_w

from constitutive.bundled import cases_dir
from constitutive.units import parse_quantity

__all__ = ["LOWERED", "lowered_case", "write_lowered_cases"]

#: The case whose set-up the validation fabrics are given.
LOWERED = cases_dir("cusick_lowered.toml")


def _thickness_mm(value) -> float:
    """A sheet's thickness in mm: a quantity string, or a number in mm (as KES sheets print)."""
    return parse_quantity(value).to("mm").magnitude if isinstance(value, str) else float(value)


def lowered_case(case: dict, lowered: dict) -> dict:
    """``case`` (a validation case as a TOML dict) worked as ``lowered`` works its specimen.

    Parameters
    ----------
    case : dict
        A validation case with ``[material.kes]``, as read from its TOML file.
    lowered : dict
        The lowered case (``cases/cusick_lowered.toml``), as read from its TOML file.

    Returns
    -------
    dict
        A new case: ``case`` with the lowered case's contact (its ``support`` placed half the
        fabric's thickness plus half the barrier layer ``dhat`` below the specimen), rigidity
        variation and gravity ramp time, and its sheet's G where ``case`` gives none.
    """
    out = copy.deepcopy(case)
    out["model"]["rigidity_variation"] = copy.deepcopy(lowered["model"]["rigidity_variation"])
    out["load"]["gravity"]["ramp_time"] = lowered["load"]["gravity"]["ramp_time"]
    if "G" in lowered["material"]["kes"]:
        out["material"]["kes"].setdefault("G", lowered["material"]["kes"]["G"])
    contact = copy.deepcopy(lowered["contact"])
    dhat_mm = parse_quantity(contact["dhat"]).to("mm").magnitude
    below = 0.5 * _thickness_mm(case["material"]["kes"]["thickness"]) + 0.5 * dhat_mm
    for body in contact["body"]:
        if body["name"] == "support":
            body["point"] = [0, 0, f"{-below:.6g} mm"]
    out["contact"] = contact
    return out


def write_lowered_cases(directory, folder, lowered=LOWERED) -> Path:
    """Every case file of ``directory`` worked by :func:`lowered_case`, written under its own
    name to ``folder`` (created); returns ``folder``."""
    set_up = tomllib.loads(Path(lowered).read_text())
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for path in sorted(Path(directory).glob("*.toml")):
        case = lowered_case(tomllib.loads(path.read_text()), set_up)
        (folder / path.name).write_text(tomli_w.dumps(case))
    return folder
