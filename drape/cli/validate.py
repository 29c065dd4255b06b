"""``drape validate`` / ``python -m drape.validate [DIR] [--seeds N] [--out OUT] [--set KEY=VALUE ...]``.

Runs every validation case of ``DIR`` (default ``cases/validation``) as a seed ensemble
(:func:`drape.batch.validation_set.run_validation`, ``--seeds N``, default 1) into
``OUT/<case file stem>/``; ``--set`` applies to every case and run. Then prints one line per
fabric, simulated against measured DC and nodes (:func:`~drape.batch.validation_set.comparison_table`),
and writes ``OUT/validation.png`` (the top views). ``--resume`` continues a stopped validation.

Exit codes: 0 every case ran (whatever each run's status), 2 bad input, 4 the output folder
cannot be written, 130 interrupted, 143 terminated.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.rows import SweepError
from drape.batch.validation_set import (
    DEFAULT_DIR,
    ValidationSetError,
    comparison_table,
    run_validation,
    validation_figure,
)
from drape.cli.common import EXIT_BAD_INPUT, EXIT_IO, EXIT_OK, add_batch_options
from drape.run.messages import describe
from drape.run.termination import sigterm_raises, stopped

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m drape.validate", description=(
        "Run the validation cases (Cusick cases with a [measured] table) as seed ensembles and "
        "print simulated against measured drape; writes OUT/validation.json and validation.png."))
    p.add_argument("directory", nargs="?", default=str(DEFAULT_DIR),
                   help="folder of validation case files (default: cases/validation)")
    p.add_argument("--seeds", type=int, default=1, metavar="N",
                   help="perturbation seeds per case, 0..N-1 (default 1)")
    p.add_argument("--out", default="out/validation", metavar="OUT", help="output folder")
    add_batch_options(p, resume="continue a stopped validation in OUT")
    return p


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (:data:`drape.cli.common.EXIT_CODES`)."""
    args = _parser().parse_args(argv)
    out = Path(args.out)
    try:
        if args.seeds < 1:
            raise ValidationSetError(f"--seeds = {args.seeds}: must be >= 1")
        out.mkdir(parents=True, exist_ok=True)
        with sigterm_raises():
            records = run_validation(args.directory, out, seeds=args.seeds,
                                     overrides=args.overrides, workers=args.workers,
                                     scheduler=args.scheduler, resume=args.resume,
                                     quiet=args.quiet)
    except (ValidationSetError, SweepError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:                 # the folder cannot be written, or is in use
        print(f"error: {describe(exc)}", file=sys.stderr)
        return EXIT_IO
    except KeyboardInterrupt as exc:
        return stopped(exc, "validation", f"continue with --resume --out {out}")
    print(comparison_table(records))
    png = out / "validation.png"
    validation_figure(records).savefig(png, dpi=110)
    print(f"top views in {png}; details in {out / 'validation.json'} and {out}/*/report.html")
    return EXIT_OK
