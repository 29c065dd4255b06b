"""The Peirce tester on its platform against the clamped cantilever: bending lengths side by side.

Runs cases/peirce_platform.toml (the strip moved over the platform's edge to the 41.5° line,
analysis "peirce_platform") and cases/cantilever.toml (the strip clamped at the edge, analysis
"peirce"), and prints the overhang and the bending length of each and their ratio:

    python benchmarks/peirce_platform_check.py --out out/peirce_check
    python benchmarks/peirce_platform_check.py --out out/peirce_check --set mesh.nx=28
    python benchmarks/peirce_platform_check.py --out out/peirce_check --elastic

Beside them, the reference of :mod:`constitutive.elastica` (benchmarks/pushed_elastica.py):
the same law on an inextensible strip pushed quasi-statically over a perfect clamp, where it
meets the line. The overhangs at the line compare the grips alone; the clamped cantilever's
bending length comes from Peirce's relation at its own chord angle (45° for the elastic strip),
which is itself 0.9 % off the relation at 41.5° on an exact elastica.

``--elastic`` runs both strips without the law's friction and viscosity: the two supports are
then compared on the same elastic strip. With the friction moment the two tests load the strip
differently (the clamped strip's curvature only grows; on the platform every section is bent
hardest as it passes the edge and unbends a little as the overhang grows and its lever arm
shortens), so their bending lengths may differ for a physical reason (docs/theory.md §7).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Both strips without the law's friction moment and viscosity: the supports compared alone.
ELASTIC = ["material.friction=false", "material.d=0"]


def run_shipped_case(case: str, out: Path, overrides) -> dict:
    """Run the shipped case ``case`` into ``out`` with ``--set`` overrides; its analysis summary."""
    from drape.cli.run import main as run

    args = [str(ROOT / "cases" / case), "--out", str(out)]
    for item in overrides:
        args += ["--set", item]
    code = run(args)
    if code != 0:
        raise SystemExit(f"{case}: the run ended with exit code {code}")
    return json.loads((out / "summary.json").read_text())["analysis"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "out" / "peirce_check"), help="output folder")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override of the platform case (repeatable), e.g. mesh.nx=28")
    parser.add_argument("--elastic", action="store_true",
                        help="both strips without the law's friction and viscosity "
                             "(material.friction=false, material.d=0)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    both = ELASTIC if args.elastic else []
    platform = run_shipped_case("peirce_platform.toml", out / "platform", both + args.set)
    clamped = run_shipped_case("cantilever.toml", out / "clamped", both)
    if not platform.get("reached"):
        print(f"the platform strip never reached the line (largest chord angle "
              f"{platform['max_chord_angle_deg']:.1f}°)")
        return 1
    rows = [("platform", platform["overhang_m"], platform["chord_angle_deg"] if "chord_angle_deg" in platform
             else platform["line_deg"], platform["bending_length_peirce_m"]),
            ("clamped", clamped["overhang_m"], clamped["chord_angle_deg"], clamped["bending_length_m"])]
    print(f"{'':10s} {'overhang [cm]':>14s} {'chord angle':>12s} {'c, Peirce [mm]':>15s}")
    for name, l, angle, c in rows:
        print(f"{name:10s} {100 * l:14.3f} {angle:11.2f}° {1000 * c:15.3f}")
    print(f"platform / clamped bending length: {platform['bending_length_peirce_m'] / clamped['bending_length_m']:.4f}"
          f" (ASTM's c = l/2 on the platform: {1000 * platform['bending_length_m']:.3f} mm)")
    reference = elastica_overhang(out / "platform", args.elastic)
    print(f"elastica pushed over a perfect clamp meets the line at {100 * reference:.4f} cm; "
          f"platform / elastica overhang: {platform['overhang_m'] / reference:.4f}")
    return 0


def elastica_overhang(run_dir: Path, elastic: bool) -> float:
    """Overhang [m] at which the elastica with the platform run's law (warp), pushed over a
    perfect clamp between the run's first and last overhangs, meets the 41.5° line."""
    import dataclasses
    import tomllib

    from constitutive.elastica import pushed_overhang
    from constitutive.material import load_material
    from constitutive.units import G0

    case = tomllib.loads((run_dir / "case.resolved.toml").read_text())
    material = load_material(case["material"]["name"])
    law = dataclasses.replace(material.warp, friction=None) if elastic else material.warp
    length = case["mesh"]["length"]
    platform = next(b for b in case["contact"]["body"] if b["name"] == "platform")
    edge = platform["centre"][0] + 0.5 * platform["size"][0]
    travel = -platform["path"]["translations"][-1][0]
    return pushed_overhang(law, material.areal_mass * G0, length - edge, length - edge + travel, 1e-4)


if __name__ == "__main__":
    sys.exit(main())
