"""``drape fit`` / ``python -m constitutive.fit``: fit the thesis's loops or a measured CSV
(:func:`constitutive.fit.fit`), print the parameters (:mod:`constitutive.fit.tables`).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

from constitutive.datasets import DATASET_NAMES, load_dataset
from constitutive.fit.global_fit import fit
from constitutive.fit.plots import plot_fit
from constitutive.fit.tables import accel_sweep_lines, all_thesis, format_all, format_result
from constitutive.fit.variants import DEFAULT_ACCEL_TIME, THESIS_RESIDUALS, THESIS_VARIANTS, VARIANTS
from drape.cli.common import EXIT_IO, EXIT_OK, Parser

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="python -m constitutive.fit",
        description="Fit the hysteretic bending law (m κ̈ + d κ̇ + k1 κ + k3 κ³ + M_f) to a KES-FB "
                    "loop: a thesis dataset (" + ", ".join(DATASET_NAMES) + ") or a CSV export "
                    "(curvature, moment[, time]). Global fit: variable projection over (ε_f, η), "
                    "no initial guess. Residual = thesis Eq. 4.17 in KES units, 1 ms samples.")
    p.add_argument("data", nargs="?", help="dataset name or CSV file")
    p.add_argument("--variant", default="full", choices=list(VARIANTS),
                   help="model variant (Tables 4.6/4.9/4.12/4.15, plus 'asymmetric'); default full")
    p.add_argument("--accel-time", type=float, default=DEFAULT_ACCEL_TIME, metavar="T",
                   help=f"machine acceleration time per ramp [s] (default {DEFAULT_ACCEL_TIME})")
    p.add_argument("--units", choices=("kes", "si"), default="kes",
                   help="units of CSV columns without a unit in the header (default kes)")
    p.add_argument("--fit-mass", action="store_true", help="also fit the curvature inertia m >= 0")
    p.add_argument("--json", metavar="OUT.json", help="write the result as JSON")
    p.add_argument("--plot", metavar="OUT.png", help="write a 3-panel plot (loop, friction, "
                   "visco-elastic part)")
    p.add_argument("--sweep-accel", metavar="T1,T2,...",
                   help="refit for each acceleration time and print the residuals")
    p.add_argument("--all-thesis", action="store_true",
                   help="fit all 20 (dataset x variant) cells and compare with the thesis")
    p.add_argument("--asymmetric", action="store_true",
                   help="with --all-thesis: also fit the face-up/face-down variant")
    p.add_argument("--plot-dir", metavar="DIR", help="with --all-thesis: write one PNG per cell "
                   "(like the thesis's Figs 4.8-4.34)")
    p.add_argument("--workers", type=int, default=2, help="processes for --all-thesis (default 2)")
    return p


def _accel_times(text: str) -> list[float]:
    """``--sweep-accel T1,T2,...`` as positive, finite numbers (ValueError naming the option)."""
    try:
        times = [float(item) for item in text.split(",")]
    except ValueError:
        raise ValueError(f"--sweep-accel {text!r}: expected numbers T1,T2,... in seconds") from None
    if not all(math.isfinite(t) and t > 0 for t in times):
        raise ValueError(f"--sweep-accel {text!r}: every time must be a number > 0")
    return times


def _writable(path) -> None:
    """OSError when ``path`` (if given) could not be created: its folder is missing or a file."""
    if path is None:
        return
    folder = Path(path).resolve().parent
    if not folder.is_dir():
        raise OSError(f"cannot write {path}: its folder {folder} does not exist")


def _all_thesis(args) -> int:
    """``--all-thesis``: every (dataset x variant) cell fitted, beside the thesis."""
    variants = THESIS_VARIANTS + (("asymmetric",) if args.asymmetric else ())
    t0 = time.perf_counter()
    fitted, own, _ = all_thesis(args.accel_time, args.workers, variants, plot_dir=args.plot_dir)
    print(f"T = {args.accel_time:g} s; residual 4.17 in (gf·cm/cm)²; 'thesis own' = the "
          "thesis's full-model parameters run through this harness; 'thesis tbl' = as printed")
    print(format_all(fitted, own, variants))
    print(f"total {time.perf_counter() - t0:.1f} s")
    return EXIT_OK


def _one_fit(args, curves) -> int:
    """One fit of ``curves``: its table, and the JSON and plot asked for."""
    r = fit(curves, args.variant, args.accel_time, fit_mass=args.fit_mass)
    print(format_result(r))
    if curves.name in THESIS_RESIDUALS and args.variant in THESIS_RESIDUALS[curves.name]:
        print(f"thesis Table {THESIS_RESIDUALS[curves.name]['table']}: residual "
              f"{THESIS_RESIDUALS[curves.name][args.variant]:.4e}")
    if args.json:
        try:
            with open(args.json, "w") as fh:
                json.dump(r.to_json(), fh, indent=2)
        except OSError as err:
            print(f"error: cannot write {args.json}: {err.strerror or err}", file=sys.stderr)
            return EXIT_IO
    if args.plot:
        plot_fit(r, args.plot, points=None if curves.points is None else curves.points[:2])
    return EXIT_OK


def main(argv=None) -> int:
    """Command-line entry point (see ``--help``)."""
    parser = _parser()
    args = parser.parse_args(argv)
    if args.all_thesis:
        return _all_thesis(args)
    if args.data is None:
        parser.error("give a dataset name or CSV file (or --all-thesis)")
    try:
        times = _accel_times(args.sweep_accel) if args.sweep_accel else None
    except ValueError as err:
        parser.error(str(err))
    try:
        for path in (args.json, args.plot):     # before the fit: refused at once, not after it
            _writable(path)
    except OSError as err:
        print(f"error: {err}", file=sys.stderr)
        return EXIT_IO
    try:
        curves = load_dataset(args.data, units=args.units)
    except ValueError as err:  # KESDataError: names the file line and the rule
        parser.error(f"{args.data}: {err}")
    if times:
        for line in accel_sweep_lines(curves, args.variant, times, args.fit_mass):
            print(line)
        return EXIT_OK
    return _one_fit(args, curves)
