"""Node count at matched drape coefficient: simulated against measured, fabric by fabric.

A drape at rest depends on the fabric's weight only through B/W and 2HB/W, so a scanned
fabric of unknown KES values can be matched by its bending length alone. For each
fabric of a scan set, this script

1. reads every scan through ``drape.analyses.scan_measure`` (the Cusick analysis of a simulated drape)
   and takes the fabric's mean DC and the range of node counts over its specimens and
   captures (:mod:`drape.analyses.scan_set`, as ``benchmarks/scan_descriptors.py``);
2. runs the KES-only Cusick case (``cases/cusick_kes.toml`` at the scans' 30 cm on 18 cm,
   warp = weft, 2HB/B = 0.5 cm⁻¹, W = 15 mg/cm²) over a grid of B for each friction law,
   and interpolates log B against DC to the B at which the model's DC is the fabric's
   (``--match grid``), or, per fabric, takes secant steps in log B from a first B until its
   run's DC is within ``--tol`` points of the fabric's (``--match secant``, for a case whose
   DC is not monotonic enough in B to interpolate across fabrics, e.g. the lowered support);
3. runs the model at that B under several perturbation seeds and compares its node count
   with the fabric's measured range.

The study is :mod:`drape.batch.matched_dc`; this script gives it a command line.

Usage::

    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/matched
    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/matched --laws tensor --seeds 3
    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/lowered --case cases/cusick_lowered.toml \
        --match secant --seeds 2
    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/matched_drop --laws tensor \
        --set load.gravity.ramp_time=0.5 --set load.perturbation.duration=0.5

``SCANS.npz``: registered scans of real Cusick drapes (the format ``scan_descriptors.py``
reads). Writes ``matched.csv`` and ``matched.md`` (one row per fabric and law),
``nodes_at_matched_dc.png`` and the sweeps it ran (``grid_<law>/``, ``matched_<law>/``; with
``--match secant``: ``secant_<k>/`` and ``seeds/``).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.matched_dc import (LAWS, START_B, compare, compare_secant, mode_within, read_start,
                                    select_fabrics, write_table)

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scans", help="registered scans of real Cusick drapes (.npz)")
    p.add_argument("--out", default="out/matched")
    p.add_argument("--laws", nargs="+", choices=list(LAWS), default=list(LAWS),
                   help="friction laws; the first gets --seeds seeds, the others one")
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--case", default=str(ROOT / "cases" / "cusick_kes.toml"))
    p.add_argument("--match", choices=["grid", "secant"], default="grid",
                   help="grid: interpolate a grid of B (every law); secant: secant steps in log B "
                        "per fabric until its run's DC is within --tol of the scans' (first law)")
    p.add_argument("--start", metavar="CSV", help="secant: first B per fabric (columns fabric, B); "
                   f"default {START_B} for every fabric")
    p.add_argument("--iterations", type=int, default=4, help="secant: sweeps at most")
    p.add_argument("--tol", type=float, default=1.5, help="secant: DC points")
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--fabrics", nargs="+", metavar="N", help="only these fabrics (default: every one)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides",
                   help="override a case key in every run (e.g. load.gravity.ramp_time=0.5)")
    args = p.parse_args(argv)
    out = Path(args.out)
    try:
        fabrics = select_fabrics(args.scans, out, args.fabrics)
    except ValueError as exc:
        p.error(str(exc))
    if args.match == "secant":
        start = read_start(args.start) if args.start else {}
        table = compare_secant(fabrics, args.case, start, args.seeds, out, args.workers,
                               args.overrides, args.iterations, args.tol)
        args.laws = args.laws[:1]
    else:
        table = compare(fabrics, args.case, args.laws, args.seeds, out, args.workers, args.overrides)
    print(write_table(table, out))
    for law in args.laws:
        rows = [r for r in table if r["law"] == law]
        print(f"{law}: most frequent model node count within the measured range for "
              f"{sum(mode_within(r) for r in rows)} of {len(rows)} fabrics")
    return 0


if __name__ == "__main__":
    sys.exit(main())
