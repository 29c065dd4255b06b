"""How firmly does contact grip the strip at the Peirce platform's edge? A study at rest.

The platform and the ruler of cases/peirce_platform.toml are fixed with their front edges at
``--edge`` (no motion), the strip settles under its weight, and its chord angle at rest is
compared with that of the clamped strip of the same overhang (cases/cantilever.toml with its
length set to the overhang). Both strips are elastic (no friction moment, no viscosity), so
the difference is the grip's alone: a clamp turns the strip by nothing at the edge, the
barrier's grip by the couple it builds over a zone behind the edge. The variants change the
barrier stiffness, the barrier layer's width, the cells and the contact points inside them
(``contact.subdivision``; :mod:`drape.batch.peirce_grip`):

    python benchmarks/peirce_platform_grip.py --out out/peirce_grip
    python benchmarks/peirce_platform_grip.py --out out/peirce_grip --only h0.8-n1 h0.4-n3-k2.4e8
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.peirce_grip import VARIANTS, grip_study, grip_table

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "out" / "peirce_grip"), help="output folder")
    parser.add_argument("--edge", type=float, default=0.0063,
                        help="front edge of platform and ruler [m] (default 0.0063: 1.57 cm overhang)")
    parser.add_argument("--only", nargs="+", choices=list(VARIANTS), help="run these variants only")
    args = parser.parse_args(argv)
    print(grip_table(*grip_study(args.edge, Path(args.out), args.only)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
