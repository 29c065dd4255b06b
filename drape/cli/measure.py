"""``drape measure`` / ``python -m drape.measure SCAN [SCAN ...] [--specimen 30cm] [--disc 18cm]
[--out DIR] [--json]``: scanned Cusick drapes read like simulated ones
(:func:`drape.analyses.scan_measure.measure_scan`).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from drape.analyses.scan import ScanError
from drape.analyses.scan_measure import (
    DISC_DIAMETER,
    SPECIMEN_DIAMETER,
    TOP_BAND,
    format_table,
    length_m,
    measure_scan,
    unique_names,
    write_outputs,
)
from drape.cli.common import EXIT_BAD_INPUT, EXIT_OK

__all__ = ["main"]


def _arg_length(text: str) -> float:
    try:
        return length_m(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _arg_centre(text: str) -> tuple:
    parts = text.split(",")
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"{text!r}: give the centre as x,y (e.g. 0.002,-0.001)")
    try:
        return tuple(length_m(p, positive=False) for p in parts)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _arg_scale(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (np.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"{text!r}: the scale must be a positive number")
    return value


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m drape.measure",
        description="Read scanned Cusick drapes like simulated ones: drape coefficient, nodes "
                    "and their angles, fold depths, the hem's outline r(theta) and its harmonic "
                    "amplitudes a_k (independent of the drape's orientation), and a top view. "
                    "A scan is any surface mesh meshio reads (PLY, OBJ, STL, VTU, ...) in "
                    "metres, the disc's top near z = 0 and the skirt hanging towards -z; the "
                    "disc centre is found from the flat top unless --centre gives it.",
        epilog="Exit status: 0, or 2 when a scan is missing, unreadable, not a surface, not "
               "finite, not in metres, has no disc top or is larger than the specimen (one "
               "line on stderr per such scan; the others are still measured).")
    p.add_argument("scans", nargs="+", metavar="SCAN", help="surface mesh files")
    p.add_argument("--specimen", type=_arg_length, default=SPECIMEN_DIAMETER, metavar="LENGTH",
                   help="specimen diameter, e.g. 30cm, '300 mm', 0.3 (metres); default 30 cm")
    p.add_argument("--disc", type=_arg_length, default=DISC_DIAMETER, metavar="LENGTH",
                   help="disc diameter; default 18 cm (BS 5058)")
    p.add_argument("--centre", type=_arg_centre, default=None, metavar="X,Y",
                   help="disc centre in metres (or with units, e.g. 2mm,-1mm), instead of the "
                        "estimate from the flat top; write --centre=-2mm,1mm when x is negative")
    p.add_argument("--top-band", type=_arg_length, default=TOP_BAND, metavar="LENGTH",
                   help="height band of the flat disc top the centre is found from; default "
                        "0.3 mm, widen it for a noisy scan")
    p.add_argument("--scale", type=_arg_scale, default=1.0, metavar="FACTOR",
                   help="multiply the coordinates by FACTOR to get metres (0.001 for mm)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="write <name>_top.png per scan and measure.json there")
    p.add_argument("--json", action="store_true",
                   help="print the full descriptors as JSON instead of the table")
    return p


def _measure_all(args) -> tuple[list, list[dict]]:
    """Every scan measured: (measurements, failures); a failure is one line on stderr."""
    measurements, failures = [], []
    for path, name in zip(args.scans, unique_names(args.scans)):
        try:
            measurements.append(measure_scan(path, args.specimen / 2, args.disc / 2, args.centre,
                                             args.scale, name, args.top_band))
        except ScanError as exc:
            print(f"error: {exc}", file=sys.stderr)
            failures.append({"scan": str(path), "error": str(exc)})
    return measurements, failures


def main(argv=None) -> int:
    """Command line: measure every scan, print the table (or JSON), write the outputs."""
    args = _parser().parse_args(argv)
    if args.specimen <= args.disc:
        print(f"error: specimen {args.specimen:g} m must be larger than the disc {args.disc:g} m",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    measurements, failures = _measure_all(args)
    report = {"specimen_diameter_m": args.specimen, "disc_diameter_m": args.disc,
              "scans": [m.descriptors() for m in measurements], "failed": failures}
    if args.out is not None and measurements:
        write_outputs(args.out, measurements, report)
    if args.json:
        print(json.dumps(report, indent=2))
    elif measurements:
        print(format_table(measurements))
    return EXIT_BAD_INPUT if failures else EXIT_OK
