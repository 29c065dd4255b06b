"""``drape sweep`` / ``python -m drape.sweep``: a base case over a run table, a grid or seeds.

The rows the options give are run by :func:`drape.batch.sweep.run_sweep`; then
``ensemble.json`` (:mod:`drape.batch.ensemble`, with ``--seeds``) and ``report.html``
(:func:`drape.batch.report.write_report`) are written.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.ensemble import describe_ensemble, ensembles, seeded, write_ensembles
from drape.batch.report import write_report
from drape.batch.rows import SweepError, _checked, grid_rows, read_table
from drape.batch.sweep import _one_line, _read_definition, run_sweep
from drape.cli.common import EXIT_CODES, EXIT_OK, Parser, add_batch_options, code_of, fail
from drape.run.messages import describe
from drape.run.termination import sigterm_raises, stopped

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="python -m drape.sweep",
        description="Run a base case over a run table or a grid of case keys, on Dask; "
                    "results.csv gets one row per finished run.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
               "  python -m drape.sweep cases/cusick_kes.toml --table cases/kes_catalogue.csv "
               "--out out/catalogue\n"
               "  python -m drape.sweep cases/cantilever.toml --grid material.bending_scale=0.5,1,2 "
               "--out out/scale\n"
               "  python -m drape.sweep cases/cusick_kes.toml --seeds 5 --out out/seeds\n"
               "  python -m drape.sweep --resume --out out/catalogue\n"
               "  python -m drape.sweep ... --scheduler tcp://10.0.0.5:8786   (an existing "
               "cluster)\n\n" + EXIT_CODES,
    )
    p.add_argument("case", nargs="?", help="base case file (TOML)")
    rows = p.add_mutually_exclusive_group()
    rows.add_argument("--table", metavar="CSV", help="run table: name, case keys, measured.*")
    rows.add_argument("--grid", metavar="KEY=V1,V2", action="append",
                      help="values of one case key; repeat for a product of several keys")
    p.add_argument("--seeds", type=int, metavar="N", help="run every row (or the case alone) under "
                   "the perturbation seeds 0..N-1; DIR/ensemble.json summarises each row's seeds")
    p.add_argument("--out", metavar="DIR", required=True, help="sweep folder")
    add_batch_options(p, resume="keep the finished rows of DIR/results.csv and run the others",
                      quiet="no progress bar, no final table")
    p.add_argument("--dashboard", action="store_true",
                   help="serve the local cluster's Dask dashboard on 127.0.0.1 (it has no "
                        "authentication; off by default)")
    return p


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (:data:`drape.cli.common.EXIT_CODES`)."""
    args = _parser().parse_args(argv)
    out = Path(args.out)
    with sigterm_raises():
        try:
            records = _sweep(args, out)
        except KeyboardInterrupt as exc:
            return stopped(exc, "sweep", f"finished runs are in {out / 'results.csv'} "
                                         f"(continue with --resume)")
        except Exception as exc:    # every problem is one line, with the code of its kind
            return fail(describe(exc), code_of(exc))
    _print_records(records, out, args.quiet)
    return _finish(out, args.quiet)


def _sweep(args, out: Path) -> list[dict]:
    """The rows the options give, run (:func:`run_sweep`)."""
    if args.workers is not None and args.workers < 1:
        raise SweepError(f"--workers = {args.workers}: must be >= 1")
    if args.seeds is not None and args.seeds < 1:
        raise SweepError(f"--seeds = {args.seeds}: must be >= 1")
    if args.case is None:
        if not args.resume:
            raise SweepError("the base case file is required (or --resume --out DIR)")
        case_path, rows, overrides = _read_definition(out)
    else:
        if not (args.table or args.grid or args.seeds):
            raise SweepError("give the runs: --table CSV, --grid KEY=V1,V2,... or --seeds N")
        rows = read_table(args.table) if args.table else grid_rows(args.grid) if args.grid else None
        case_path, overrides = args.case, args.overrides
        if not Path(case_path).is_file():
            raise SweepError(f"case file {case_path!r} does not exist")
        if args.seeds is not None:
            rows = _checked(seeded(case_path, overrides, rows, args.seeds), "--seeds")
    return run_sweep(case_path, rows, out, overrides=overrides, scheduler=args.scheduler,
                     workers=args.workers, resume=args.resume, quiet=args.quiet,
                     dashboard=args.dashboard)


def _print_records(records: list[dict], out: Path, quiet: bool) -> None:
    if quiet:
        return
    for rec in records:
        dc = f", DC {float(rec['DC_percent']):.1f} %" if rec["DC_percent"] != "" else ""
        why = f": {rec['reason']}" if rec["reason"] else ""
        print(f"{rec['name']}: {rec['status']}{dc}{why}")
    print(f"results in {out / 'results.csv'}")


def _finish(out: Path, quiet: bool) -> int:
    """ensemble.json and report.html of the finished sweep; the exit code."""
    try:
        if write_ensembles(out) is not None and not quiet:
            print("\n".join(describe_ensemble(e) for e in ensembles(out)))
        report = write_report(out)
    except Exception as exc:  # the runs and results.csv are done; the page can be made again
        print(f"report.html not written ({_one_line(exc)}); try python -m drape.report {out}",
              file=sys.stderr)
        return EXIT_OK
    if not quiet:
        print(f"report in {report}")
    return EXIT_OK

