"""``drape datasets`` / ``python -m constitutive.datasets``: list the thesis datasets, write the
example export (:func:`constitutive.datasets.example.write_example_export`).
"""
from __future__ import annotations

import argparse

from constitutive.datasets.example import write_example_export
from constitutive.datasets.thesis import DATASET_NAMES, THESIS_POLYNOMIALS, turning_points
from drape.cli.common import EXIT_OK

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m constitutive.datasets",
        description="Thesis datasets (K± and tables) and a simulated example KES-FB CSV export.")
    sub = p.add_subparsers(dest="cmd", required=True)
    sub.add_parser("list", help="list the thesis datasets with their turning points")
    ex = sub.add_parser("example", help="write a simulated, noisy KES-FB export (Fabric 1 weft, "
                        "thesis Table 4.7 parameters)")
    ex.add_argument("out", help="CSV file to write")
    ex.add_argument("--seed", type=int, default=0)
    return p


def _list() -> int:
    """``list``: each thesis dataset with its turning points and tables."""
    for n in DATASET_NAMES:
        kp, km = turning_points(THESIS_POLYNOMIALS[n])
        print(f"{n:14s} K+ = {kp:6.3f}  K- = {km:6.3f} cm^-1   "
              f"Tables {', '.join(THESIS_POLYNOMIALS[n].tables)}")
    return EXIT_OK


def main(argv=None) -> int:
    """Command-line entry point (see ``--help``)."""
    args = _parser().parse_args(argv)
    if args.cmd == "list":
        return _list()
    rows = write_example_export(args.out, args.seed)
    print(f"wrote {args.out} ({rows} rows)")
    return EXIT_OK
