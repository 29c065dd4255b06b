"""``drape report`` / ``python -m drape.report OUTDIR``: ``OUTDIR/report.html`` of a sweep or a
run folder (:func:`drape.batch.report.write_report`).
"""
from __future__ import annotations

import argparse
import sys

from drape.batch.report import write_report
from drape.cli.common import EXIT_BAD_INPUT, EXIT_OK, Parser

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = Parser(prog="python -m drape.report",
               description="Write OUTDIR/report.html for a sweep or a run folder "
                           "(self-contained: opens offline).")
    p.add_argument("out_dir", metavar="OUTDIR", help="a sweep folder or a run folder")
    return p


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (:data:`drape.cli.common.EXIT_CODES`)."""
    args = _parser().parse_args(argv)
    try:
        path = write_report(args.out_dir)
    except FileNotFoundError as exc:       # a folder that holds neither a sweep nor a run
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    print(path)
    return EXIT_OK
