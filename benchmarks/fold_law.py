"""Fold number of the Cusick drape against the law of Cerda, Mahadevan & Pasini, over c.

Runs a Cusick case (by default ``cases/cusick_lowered.toml``, 30 cm on 18 cm) over a grid of
bending rigidities B, warp = weft, 2HB = 0.5 B, at one weight W (the fabric of
``benchmarks/nodes_at_matched_dc.py``, ``drape.batch.matched_dc.fabric_keys``), each under
``--seeds`` perturbation seeds, and compares each B's node counts with the fold-number law of
*The elements of draping* (PNAS 101, 2004),

    n = C · 2π R_D / (c³ (R − R_D))^{1/4},   c = (B/W)^{1/3} (Peirce's bending length),

whose prefactor C the paper does not give: it is fitted on the even-indexed B (in increasing
B) and the law is checked on the others (``drape.batch.fold_law``; docs/theory.md §6).

Usage::

    python benchmarks/fold_law.py --case cases/cusick_lowered.toml \\
        --B 0.003 0.006 0.012 0.025 0.05 0.1 0.2 0.4 0.8 --weight 15 --seeds 1 --workers 2 \\
        --out out/fold_law

Writes ``fold_law.csv`` (one row per B: c, L/c, DC and nodes per seed, the law's n, the
difference, the half it belongs to), ``fold_law.md``, ``fold_law.png`` (nodes against c, the
simulated points and the law's curve) and the sweep it ran (``runs/``, continued where it
exists already).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.fold_law import study

ROOT = Path(__file__).resolve().parents[1]
GRID = [0.003, 0.006, 0.012, 0.025, 0.05, 0.1, 0.2, 0.4, 0.8]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--case", default=str(ROOT / "cases" / "cusick_lowered.toml"))
    p.add_argument("--B", nargs="+", type=float, default=GRID, metavar="B",
                   help="bending rigidities, gf·cm²/cm (warp = weft)")
    p.add_argument("--weight", type=float, default=15.0, help="W, mg/cm²")
    p.add_argument("--seeds", type=int, default=1, help="perturbation seeds per B")
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--out", default="out/fold_law")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides",
                   help="override a case key in every run (e.g. load.gravity.ramp_time=0.5)")
    args = p.parse_args(argv)
    if len(set(args.B)) < 2:
        p.error("--B: at least two values (the law's prefactor is fitted on half of them)")
    text = study(args.case, args.B, args.weight, args.seeds, args.out, args.workers, args.overrides)
    if text is None:
        print("no run finished: nothing to compare", file=sys.stderr)
        return 3
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
