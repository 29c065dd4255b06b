"""The validation fabrics let down as ``cases/cusick_lowered.toml`` lets its specimen down.

The shipped validation cases (``cases/validation``) lay the specimen on the disc under a gravity
ramp, as ``cases/cusick_kes.toml`` does. This study runs the same fabrics on the tester's
support, lowered away, with the specimen's rigidity varying over it: each case gets the
lowered case's ``[contact]`` (the support placed half the fabric's thickness plus half the
barrier layer below it), its ``[model.rigidity_variation]``, the full weight at once, and,
where the fabric's sheet gives no shear rigidity G, the lowered set-up's. Everything else
(tester, mesh, fabric, damping, solver) stays the validation case's own.

    python benchmarks/validation_lowered.py --out out/validation_lowered --seeds 3
"""
from __future__ import annotations

import argparse
import copy
import sys
import tomllib
from pathlib import Path

import tomli_w

from constitutive.units import parse_quantity

ROOT = Path(__file__).resolve().parents[1]
LOWERED = ROOT / "cases" / "cusick_lowered.toml"


def lowered_case(case: dict, lowered: dict) -> dict:
    """``case`` (a validation case as a TOML dict) worked as ``lowered`` works its specimen."""
    out = copy.deepcopy(case)
    out["model"]["rigidity_variation"] = copy.deepcopy(lowered["model"]["rigidity_variation"])
    out["load"]["gravity"]["ramp_time"] = lowered["load"]["gravity"]["ramp_time"]
    if "G" in lowered["material"]["kes"]:
        out["material"]["kes"].setdefault("G", lowered["material"]["kes"]["G"])
    contact = copy.deepcopy(lowered["contact"])
    dhat_mm = parse_quantity(contact["dhat"]).to("mm").magnitude
    thickness = case["material"]["kes"]["thickness"]     # KES sheets print mm
    thickness_mm = parse_quantity(thickness).to("mm").magnitude if isinstance(thickness, str) else float(thickness)
    for body in contact["body"]:
        if body["name"] == "support":
            body["point"] = [0, 0, f"{-(0.5 * thickness_mm + 0.5 * dhat_mm):.6g} mm"]
    out["contact"] = contact
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=Path("out/validation_lowered"))
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--cases", type=Path, default=ROOT / "cases" / "validation")
    args = p.parse_args(argv)

    lowered = tomllib.loads(LOWERED.read_text())
    folder = args.out / "cases"
    folder.mkdir(parents=True, exist_ok=True)
    for path in sorted(args.cases.glob("*.toml")):
        case = lowered_case(tomllib.loads(path.read_text()), lowered)
        (folder / path.name).write_text(tomli_w.dumps(case))

    from drape.batch.validation_set import main as validate
    workers = [] if args.workers is None else ["--workers", str(args.workers)]
    return validate([str(folder), "--seeds", str(args.seeds), "--out", str(args.out / "runs"),
                     "--resume", *workers])


if __name__ == "__main__":
    sys.exit(main())
