"""Descriptors of a set of registered Cusick scans, per scan and per fabric.

    python benchmarks/scan_descriptors.py SCANS.npz [--out DIR]

The file is a numpy ``.npz`` with, for each scan, ``KEY/vertices`` (int16; times the scalar
entry ``vertex_unit_m`` gives metres) and ``KEY/faces`` (uint16, 0-based triangles); keys are
``fabricNN_sampleSS_captureC``, ``fabricNN_sampleSS`` or ``fabricNN_sampleSS_obsK`` (one
specimen observed K = 1, 2, ... times in succession while it creeps). The Leeds Cusick drape
dataset comes in this form (D. Gong, N. Mao, H. Wang, "Bayesian Differentiable Physics for Cloth
Digitalization", CVPR 2024); its scans are external data and are not part of this repository.

Every scan goes through :func:`drape.analyses.scan_measure.measure_surface` (30 cm specimen on an 18 cm
disc, centre from the flat top, the node detection of the simulated drape;
:mod:`drape.analyses.scan_set`) and the script writes to DIR (default ``out/scan_descriptors``):

- ``scans.csv``: key, fabric, sample, series (capture / obs) and its number, DC %, nodes,
  mean fold depth, the outline's irregularity (mm: its harmonics outside the fold pattern,
  :func:`drape.analyses.outline.outline_irregularity`), the centre used, the harmonic
  amplitudes a_0 .. a_20 (mm), or the reason a scan could not be read;
- ``fabrics.csv``: per fabric, over its scans other than the creep series: number of scans,
  DC mean, standard deviation, min and max, nodes min, max, most frequent and mean, mean
  irregularity;
- ``creep.csv``: the creep series per fabric and observation: the same columns;
- ``faces.csv``: face up against face down, per fabric over its specimens captured four times
  (captures 1–2 one face up, 3–4 the other): the mean and standard deviation over specimens of
  a specimen's DC face down minus face up, and beside it the repeat scatter (half the
  difference between the two captures of one face, averaged), which that difference must
  exceed to mean anything.

and prints the tables.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.analyses.scan_set import describe_scans, fabric_tables, format_tables, write_tables


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("npz", type=Path, help="registered scans (.npz)")
    p.add_argument("--out", type=Path, default=Path("out/scan_descriptors"))
    args = p.parse_args(argv)
    rows = describe_scans(args.npz)
    for r in rows:
        if r["error"] or r["warning"]:
            print(f"{r['key']}: {r['error'] or 'warning: ' + r['warning']}", file=sys.stderr)
    tables = fabric_tables(rows)
    write_tables(args.out, rows, tables)
    print(format_tables(tables))
    good = sum(not r["error"] for r in rows)
    print(f"{good} of {len(rows)} scans measured; tables in {args.out}")
    return 0 if good == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
