"""``drape measure`` / ``python -m drape.measure SCAN [SCAN ...] [--specimen 30cm] [--disc 18cm]
[--out DIR] [--json]``: scanned Cusick drapes read like simulated ones
(:func:`drape.analyses.scan_measure.measure_scan`).

Every option is checked before a scan is read (one line, exit 2), ``--out`` before a scan is
measured (exit 4); a scan that is no drape is refused in one line and the others are still
measured; a scan measured in spite of a flaw gets a warning line.
"""
from __future__ import annotations

import argparse
import json
import sys
import textwrap
from pathlib import Path

import numpy as np

from drape.analyses.scan import EXTENT_REFUSED, EXTENT_SILENT, ScanError
from drape.analyses.scan_checks import (
    DISC_LARGER,
    DISC_SMALLER,
    HOLE_REFUSED,
    HOLE_WARNED,
    MIN_AREA,
    MISSING_REFUSED,
)
from drape.analyses.scan_measure import (
    DISC_DIAMETER,
    SIZE_RANGES,
    SPECIMEN_DIAMETER,
    TOP_BAND,
    format_table,
    length_m,
    measure_scan,
    plausible_size,
    unique_names,
    write_outputs,
)
from drape.cli.common import (
    EXIT_BAD_INPUT,
    EXIT_IO,
    EXIT_OK,
    Parser,
    fail,
    guarded,
    writable_folder,
)

__all__ = ["main"]

def _epilog() -> str:
    """The rules a scan is measured by, and the exit codes."""
    def block(text):
        return textwrap.fill(" ".join(text.split()), 88, initial_indent="  ",
                             subsequent_indent="  ")
    refused = block(f"""
        a surface mesh (triangles or quads) in metres, finite, the size of a drape (its extent
        neither ten specimens nor a few stray vertices); triangles covering at least
        {100 * MIN_AREA:g} % of the hanging annulus; a flat disc top at most
        {100 * DISC_SMALLER:g} % smaller and {100 * DISC_LARGER:g} % larger than the stated disc
        (unless the scan is flat to its edge); skirt in all but {360 * MISSING_REFUSED:g}° of
        the directions round the disc; holes in its shadow under {HOLE_REFUSED:g} DC point; a
        reach at most {100 * EXTENT_REFUSED:g} % past the stated specimen radius.""")
    warned = block(f"""
        skirt missing in a few directions; holes of {HOLE_WARNED:g} to {HOLE_REFUSED:g} DC
        point (the DC with them filled is given); a reach {100 * EXTENT_SILENT:g} to
        {100 * EXTENT_REFUSED:g} % past the specimen radius; a scan upside down (its flat disc
        top at the bottom), measured turned over.""")
    return f"""\
what a scan must be (else it is refused in one line; the other scans are still measured):
{refused}
measured with a warning line on stderr:
{warned}

exit codes:
  {EXIT_OK}    every scan measured
  {EXIT_BAD_INPUT}    bad input: an option, or a scan refused (one line on stderr per scan)
  {EXIT_IO}    --out cannot be written (a file in the way, read-only), checked before measuring"""


def _arg_size(kind: str):
    """An argparse type: a length (m, or with units) plausible as ``kind``."""
    def parse(text: str) -> float:
        try:
            return plausible_size(kind, length_m(text))
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return parse


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


def _range(kind: str) -> str:
    low, high = SIZE_RANGES[kind]
    return f"{low:g} to {high:g} m"


def _parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="python -m drape.measure",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Read scanned Cusick drapes like simulated ones: drape coefficient, nodes "
                    "and their angles, fold depths, the hem's outline r(theta) and its harmonic "
                    "amplitudes a_k (independent of the drape's orientation), and a top view. "
                    "A scan is any surface mesh meshio reads (PLY, OBJ, STL, VTU, ...) in "
                    "metres, the disc's top near z = 0 and the skirt hanging towards -z; the "
                    "disc centre is found from the flat top unless --centre gives it. A length "
                    "is a number with a unit (30cm, '300 mm') or a bare number in metres.",
        epilog=_epilog())
    p.add_argument("scans", nargs="+", metavar="SCAN", help="surface mesh files")
    p.add_argument("--specimen", type=_arg_size("specimen diameter"), default=SPECIMEN_DIAMETER,
                   metavar="LENGTH", help="specimen diameter, e.g. 30cm, '300 mm', 0.3 (a bare "
                   f"number is metres; {_range('specimen diameter')}); default 30 cm")
    p.add_argument("--disc", type=_arg_size("disc diameter"), default=DISC_DIAMETER,
                   metavar="LENGTH", help="disc diameter (a bare number is metres; "
                   f"{_range('disc diameter')}); default 18 cm (BS 5058)")
    p.add_argument("--centre", type=_arg_centre, default=None, metavar="X,Y",
                   help="disc centre in metres (or with units, e.g. 2mm,-1mm), instead of the "
                        "estimate from the flat top; write --centre=-2mm,1mm when x is negative")
    p.add_argument("--top-band", type=_arg_size("top band"), default=TOP_BAND, metavar="LENGTH",
                   help="height band of the flat disc top the centre is found from (a bare "
                        f"number is metres; up to {SIZE_RANGES['top band'][1]:g} m); default "
                        "0.3 mm, widen it for a noisy scan")
    p.add_argument("--scale", type=_arg_scale, default=1.0, metavar="FACTOR",
                   help="multiply the coordinates by FACTOR to get metres (0.001 for mm)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="write <name>_top.png per scan and measure.json there")
    p.add_argument("--json", action="store_true",
                   help="print the full descriptors as JSON instead of the table")
    return p


def _measure_all(args) -> tuple[list, list[dict]]:
    """Every scan measured: (measurements, failures); a failure or a warning is one line on
    stderr."""
    measurements, failures = [], []
    for path, name in zip(args.scans, unique_names(args.scans)):
        try:
            m = measure_scan(path, args.specimen / 2, args.disc / 2, args.centre, args.scale,
                             name, args.top_band)
        except ScanError as exc:
            print(f"error: {exc}", file=sys.stderr)
            failures.append({"scan": str(path), "error": str(exc)})
            continue
        for warning in m.warnings:
            print(f"warning: {warning}", file=sys.stderr)
        measurements.append(m)
    return measurements, failures


def _measure(args) -> int:
    """The checked options' scans measured, printed, then written to ``--out``."""
    if args.specimen <= args.disc:
        return fail(f"--specimen {args.specimen:g} m must be larger than --disc {args.disc:g} m")
    if args.out is not None:
        writable_folder(args.out, "--out")
    measurements, failures = _measure_all(args)
    report = {"specimen_diameter_m": args.specimen, "disc_diameter_m": args.disc,
              "scans": [m.descriptors() for m in measurements], "failed": failures}
    if args.json:
        print(json.dumps(report, indent=2))
    elif measurements:
        print(format_table(measurements))
    sys.stdout.flush()      # the results stand before a failure to write them
    if args.out is not None and measurements:
        write_outputs(args.out, measurements, report)
    return EXIT_BAD_INPUT if failures else EXIT_OK


def main(argv=None) -> int:
    """Command line: measure every scan, print the table (or JSON), write the outputs."""
    args = _parser().parse_args(argv)
    return guarded(_measure, args)
