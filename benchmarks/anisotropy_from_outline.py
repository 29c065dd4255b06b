"""Each fabric's anisotropy read from its scans' outlines, and its node count at matched DC with it.

    python benchmarks/anisotropy_from_outline.py SCANS.npz --matched MATCHED.csv --out out/outline_anisotropy
    python benchmarks/anisotropy_from_outline.py SCANS.npz --matched MATCHED.csv --out DIR --seeds 2 \
        --ratios 2 4 --workers 2

The study is :mod:`drape.batch.outline_anisotropy`: the model's outline ``a2`` (the elliptic,
two-fold harmonic) at each fabric's matched B, isotropic and at B_warp/B_weft = ``--ratios``
for a fabric whose scans are more elliptic than its isotropic runs; the fabric's ratio read off
the model's ``a2``; its node counts at that ratio against its measured range.

``SCANS.npz``: registered Cusick scans (the format ``scan_descriptors.py`` reads; described once
into ``DIR/scans``). ``MATCHED.csv``: columns ``fabric`` and ``B_matched`` (or ``B``), in
gf·cm²/cm, e.g. the ``matched.csv`` of ``nodes_at_matched_dc.py --match secant``. Runs on
``cases/cusick_lowered.toml`` (the Cusick set-up's KES-only case) unless ``--case``. Writes
``outline_anisotropy.csv``, ``.md`` and ``nodes_at_matched_dc.png`` to DIR, and the sweeps
(``isotropic/``, ``ratios/``, ``read/``), continued where they exist.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.matched_dc import mode_within, nodes_figure, select_fabrics, write_rows
from drape.batch.outline_anisotropy import RATIOS, markdown, read_matched, study

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scans", help="registered scans of real Cusick drapes (.npz)")
    p.add_argument("--matched", required=True, metavar="CSV", help="matched B per fabric (fabric, B_matched)")
    p.add_argument("--out", default="out/outline_anisotropy")
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--ratios", type=float, nargs="+", default=list(RATIOS),
                   help="B_warp/B_weft run for an elliptic fabric, increasing, each > 1")
    p.add_argument("--case", default=str(ROOT / "cases" / "cusick_lowered.toml"))
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--fabrics", nargs="+", metavar="N", help="only these fabrics (default: every one)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides")
    args = p.parse_args(argv)
    if not (all(r > 1 for r in args.ratios) and args.ratios == sorted(set(args.ratios))):
        p.error(f"--ratios {args.ratios}: increasing, each > 1")
    out = Path(args.out)
    try:
        fabrics = select_fabrics(args.scans, out, args.fabrics)
    except ValueError as exc:
        p.error(str(exc))
    table = study(fabrics, read_matched(args.matched), args.case, args.seeds, out, args.workers,
                  args.overrides, tuple(args.ratios))
    text = markdown(table, tuple(args.ratios))
    write_rows(table, text, out, "outline_anisotropy")
    nodes_figure(table).savefig(out / "nodes_at_matched_dc.png", dpi=120)
    print(text)
    print(f"most frequent model node count within the measured range for "
          f"{sum(mode_within(r) for r in table)} of {len(table)} fabrics; runs in range "
          f"{sum(r['within'] for r in table)} of {sum(r['runs'] for r in table)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
