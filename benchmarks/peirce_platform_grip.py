"""How firmly does contact grip the strip at the Peirce platform's edge? A study at rest.

The platform and the ruler of cases/peirce_platform.toml are fixed with their front edges at
``--edge`` (no motion), the strip settles under its weight, and its chord angle at rest is
compared with that of the clamped strip of the same overhang (cases/cantilever.toml with its
length set to the overhang). Both strips are elastic (no friction moment, no viscosity), so
the difference is the grip's alone: a clamp turns the strip by nothing at the edge, the
barrier's grip by the couple it builds over a zone behind the edge. The variants change the
barrier stiffness, the barrier layer's width, the cells and the contact points inside them
(``contact.subdivision``):

    python benchmarks/peirce_platform_grip.py --out out/peirce_grip
    python benchmarks/peirce_platform_grip.py --out out/peirce_grip --only h0.8-n1 h0.4-n3-k2.4e8
"""
from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path

import numpy as np
import tomli_w

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from peirce_platform_check import ELASTIC, run_shipped_case  # noqa: E402

# name: (cells along the strip, strip width, cells across, subdivision, barrier stiffness
# [N/m³] or None for the case's own: one vertex's weight share at mid-layer, 2.43e6 with 0.8 mm
# cells, barrier layer dhat [m] or None for the case's 10 µm)
VARIANTS = {
    "h0.8-n1": (28, "0.5cm", 2, 1, None, None),
    "h0.8-n1-k2.4e8": (28, "0.5cm", 2, 1, 2.4e8, None),
    "h0.4-n3-k2.4e8": (56, "0.2cm", 1, 3, 2.4e8, None),
    "h0.2-n1": (112, "0.1cm", 1, 1, None, None),
    "h0.2-n1-k2.4e7": (112, "0.1cm", 1, 1, 2.4e7, None),
    "h0.2-n1-k2.4e8": (112, "0.1cm", 1, 1, 2.4e8, None),
    "h0.2-n1-d2um": (112, "0.1cm", 1, 1, None, 2e-6),
    "h0.2-n1-d2um-k2.4e8": (112, "0.1cm", 1, 1, 2.4e8, 2e-6),
}


def _resting_case(edge: float, out: Path, dhat: float | None = None) -> tuple[Path, float]:
    """The platform case with its bodies fixed, their front edges at ``edge``; its overhang.

    With ``dhat`` the barrier layer changes and platform and ruler move apart or together by
    the change, so the strip still starts in the middle of both layers."""
    from drape.case.case import dump_case, load_case

    data = tomllib.loads(dump_case(load_case(ROOT / "cases" / "peirce_platform.toml")))
    shift = 0.0 if dhat is None else 0.5 * (dhat - data["contact"]["dhat"])
    for body in data["contact"]["body"]:
        body["centre"][0] += edge - (body["centre"][0] + 0.5 * body["size"][0])
        # the platform lies below the strip, the ruler above it
        body["centre"][2] += float(np.sign(body["centre"][2])) * shift
        body.pop("path", None)
    if dhat is not None:
        data["contact"]["dhat"] = dhat
    data["solver"]["t_end"] = 1.5                    # at rest by then (the [stop] rule is off)
    data["case"]["name"] = "peirce_platform_at_rest"
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"peirce_platform_at_rest{'' if dhat is None else f'_dhat{dhat:g}'}.toml"
    path.write_text(tomli_w.dumps(data))
    return path, data["mesh"]["length"] - edge


def _chord_at_rest(out: Path, edge: float) -> float:
    """Chord angle [deg] from the strip's point above the edge to its tip at the last step."""
    import meshio
    from skfem import MeshTri

    from drape.analyses.platform_reading import reading

    mesh = meshio.read(sorted(out.glob("*.vtu"))[-1])
    strip = MeshTri(np.ascontiguousarray(mesh.points[:, :2].T),
                    np.ascontiguousarray(mesh.cells_dict["triangle"].T))
    return reading(strip, mesh.point_data["displacement"], edge)["chord_angle"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "out" / "peirce_grip"), help="output folder")
    parser.add_argument("--edge", type=float, default=0.0063,
                        help="front edge of platform and ruler [m] (default 0.0063: 1.57 cm overhang)")
    parser.add_argument("--only", nargs="+", choices=list(VARIANTS), help="run these variants only")
    args = parser.parse_args(argv)
    out = Path(args.out)
    _, overhang = _resting_case(args.edge, out)
    clamped = run_shipped_case("cantilever.toml", out / "clamped",
                   ELASTIC + [f"mesh.length={overhang!r}"])["chord_angle_deg"]
    rows = []
    for name in args.only or VARIANTS:
        nx, width, ny, n, kappa, dhat = VARIANTS[name]
        case, _ = _resting_case(args.edge, out, dhat)
        overrides = ELASTIC + [f"mesh.nx={nx}", f"mesh.width={width}", f"mesh.ny={ny}",
                               f"contact.subdivision={n}"]
        overrides += [] if kappa is None else [f"contact.barrier_stiffness={kappa:g}"]
        run_shipped_case(str(case), out / name, overrides)          # an absolute path: not under cases/
        rows.append((name, _chord_at_rest(out / name, args.edge)))
    print(f"overhang {100 * overhang:.2f} cm; clamped strip at rest: chord angle {clamped:.3f}°")
    print(f"{'variant':16s} {'chord angle':>12s} {'excess':>8s}")
    for name, chord in rows:
        print(f"{name:16s} {chord:11.3f}° {chord - clamped:7.3f}°")
    return 0


if __name__ == "__main__":
    sys.exit(main())
