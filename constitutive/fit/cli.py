"""``python -m constitutive.fit`` / ``drape fit``: fit the thesis's loops or a measured CSV.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time as _time
from pathlib import Path

from constitutive.datasets import DATASET_NAMES, load_dataset
from constitutive.fit.global_fit import fit
from constitutive.fit.residual import evaluate
from constitutive.fit.variants import (
    DEFAULT_ACCEL_TIME,
    DERIVED_UNITS,
    PARAM_UNITS,
    THESIS_RESIDUALS,
    THESIS_VARIANTS,
    VARIANTS,
    thesis_law,
    to_kes,
)

__all__ = ['format_result', 'all_thesis', 'format_all', 'main']


def format_result(r):
    """Human-readable parameter table of a :class:`FitResult` (KES units)."""
    p, der, kv = to_kes(r.params()), r.derived(), r.kes_values()
    lines = [f"dataset {r.dataset}   variant {r.variant} ({VARIANTS[r.variant].label})   "
             f"T = {r.accel_time:g} s   samples {r.loop.kappa.size} (1 ms)",
             f"residual 4.17 = {r.residual:.4e} (gf·cm/cm)²", "",
             f"{'parameter':<10}{'value':>14}  unit", "-" * 36]
    for k, v in p.items():
        lines.append(f"{k:<10}{'—' if v is None else f'{v:14.4e}':>14}  {PARAM_UNITS[k][0]}")
    lines.append("-" * 36)
    for k, v in der.items():
        vv = None if v is None else v / DERIVED_UNITS[k][1]
        lines.append(f"{k:<10}{'—' if vv is None else f'{vv:14.4e}':>14}  {DERIVED_UNITS[k][0]}")
    lines.append("-" * 36)
    lines.append(f"{'B':<10}{kv['model'][0]:14.4e}  gf·cm²/cm   (data {kv['data'][0]:.4e})")
    lines.append(f"{'2HB':<10}{kv['model'][1]:14.4e}  gf·cm/cm    (data {kv['data'][1]:.4e})")
    return "\n".join(lines)


def _fit_cell(args):
    name, variant, accel_time, plot_dir = args
    c0 = _time.process_time()
    r = fit(name, variant, accel_time)
    cpu = _time.process_time() - c0
    if plot_dir is not None:
        from constitutive.fit.plots import plot_fit  # matplotlib: loaded only when a plot is asked for

        Path(plot_dir).mkdir(parents=True, exist_ok=True)
        plot_fit(r, Path(plot_dir) / f"{name}_{variant}.png")
    return name, variant, r.residual, cpu


def all_thesis(accel_time=DEFAULT_ACCEL_TIME, workers=2, variants=THESIS_VARIANTS, progress=True,
               plot_dir=None):
    """Fit every (dataset × variant) cell.

    Returns
    -------
    fitted : dict
        {(dataset, variant): residual 4.17}
    own : dict
        {dataset: residual of the thesis's own full-model parameters, same harness}
    cpu : dict
        {(dataset, variant): CPU seconds of the fit}
    """
    from tqdm import tqdm

    cells = [(n, v, accel_time, plot_dir) for n in DATASET_NAMES for v in variants]
    fitted, times = {}, {}
    if workers > 1:
        import multiprocessing as mp

        with mp.get_context("fork").Pool(workers) as pool:
            it = pool.imap_unordered(_fit_cell, cells)
            for n, v, res, dt in tqdm(it, total=len(cells), disable=not progress, desc="fits"):
                fitted[n, v], times[n, v] = res, dt
    else:
        for c in tqdm(cells, disable=not progress, desc="fits"):
            n, v, res, dt = _fit_cell(c)
            fitted[n, v], times[n, v] = res, dt
    own = {n: evaluate(thesis_law(n), load_dataset(n).sample(accel_time)) for n in DATASET_NAMES}
    return fitted, own, times


def format_all(fitted, own, variants=THESIS_VARIANTS):
    head = f"{'dataset':<14}{'variant':<13}{'fitted R':>11}{'thesis own':>12}{'thesis tbl':>12}"
    lines = [head, "-" * len(head)]
    for n in DATASET_NAMES:
        for v in variants:
            o = f"{own[n]:12.4e}" if v == "full" else " " * 12
            t = THESIS_RESIDUALS[n].get(v)
            t = f"{t:12.4e}" if t is not None else " " * 12
            lines.append(f"{n:<14}{v:<13}{fitted[n, v]:11.4e}{o}{t}")
    return "\n".join(lines)


class _Parser(argparse.ArgumentParser):
    """Errors in one line, exit code 2 (bad input), as drape's tools report them."""

    def error(self, message):
        self.exit(2, f"error: {message} (see {self.prog} --help)\n")


def _parser():
    p = _Parser(
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


#: Exit code of an output file that cannot be written (drape.run.cli's table: 2 is bad input).
EXIT_IO = 4


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


def main(argv=None):
    """Command-line entry point (see ``--help``)."""
    args = _parser().parse_args(argv)
    if args.all_thesis:
        variants = THESIS_VARIANTS + (("asymmetric",) if args.asymmetric else ())
        t0 = _time.perf_counter()
        fitted, own, _ = all_thesis(args.accel_time, args.workers, variants,
                                    plot_dir=args.plot_dir)
        print(f"T = {args.accel_time:g} s; residual 4.17 in (gf·cm/cm)²; 'thesis own' = the "
              "thesis's full-model parameters run through this harness; 'thesis tbl' = as printed")
        print(format_all(fitted, own, variants))
        print(f"total {_time.perf_counter() - t0:.1f} s")
        return 0
    if args.data is None:
        _parser().error("give a dataset name or CSV file (or --all-thesis)")
    try:
        Ts = _accel_times(args.sweep_accel) if args.sweep_accel else None
    except ValueError as err:
        _parser().error(str(err))
    try:
        for path in (args.json, args.plot):     # before the fit: refused at once, not after it
            _writable(path)
    except OSError as err:
        print(f"error: {err}", file=sys.stderr)
        return EXIT_IO
    try:
        curves = load_dataset(args.data, units=args.units)
    except ValueError as err:  # KESDataError: names the file line and the rule
        _parser().error(f"{args.data}: {err}")
    if Ts:
        print(f"{'T [s]':>8}{'fitted R':>12}{'thesis own':>12}")
        for T in Ts:
            r = fit(curves, args.variant, T, fit_mass=args.fit_mass)
            own = (f"{evaluate(thesis_law(curves.name), curves.sample(T)):12.4e}"
                   if curves.name in THESIS_RESIDUALS else "")
            print(f"{T:8.3f}{r.residual:12.4e}{own}")
        return 0
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
        from constitutive.fit.plots import plot_fit  # matplotlib: loaded only when a plot is asked for

        plot_fit(r, args.plot, points=None if curves.points is None else curves.points[:2])
    return 0
