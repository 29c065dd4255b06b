"""``drape predict`` / ``python -m drape.predict CASE [--samples N] [--unknowns NAME ...] --out OUT``.

A Cusick case with a KES sheet (``[material.kes]``, as in ``cases/cusick_kes.toml``) predicted
with an interval: what the sheet omits is sampled over its range for woven apparel fabrics,
each sample under its own perturbation seed, on Dask (:mod:`drape.batch.prediction`). Prints
the DC's median and 90 % interval, the node counts, and which missing measurement would narrow
the interval most; with a ``[measured]`` table, whether the measured drape lies inside. Writes
``OUT/prediction.json``, ``OUT/prediction.png`` (DC against each unknown) and the sweep's
``OUT/results.csv`` with its runs. ``--resume`` continues a stopped prediction.
"""
from __future__ import annotations

import argparse
import json
import tomllib
from pathlib import Path

from drape.batch.prediction import (UNKNOWNS, describe_prediction, missing_unknowns,
                                    prediction_figure, sample_rows, summarise)
from drape.batch.rows import SweepError, read_results
from drape.batch.sweep import _read_definition, run_sweep
from drape.case.case import CaseError, apply_overrides, load_case
from drape.case.setup import SETUP_KEY
from drape.cli.common import EXIT_CODES, EXIT_OK, Parser, add_batch_options, code_of, fail
from drape.run.atomic import atomic_write_text
from drape.run.messages import describe
from drape.run.termination import sigterm_raises, stopped

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    names = ", ".join(f"{u.name} ({u.what}; {u.low:g}–{u.high:g} {u.unit})" for u in UNKNOWNS.values())
    p = Parser(
        prog="python -m drape.predict",
        description="Predict a Cusick drape from a KES sheet with an interval: the values the "
                    "sheet omits are sampled over their range for woven fabrics, each sample "
                    "under its own seed, on Dask.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=f"unknowns: {names}\n\nexamples:\n"
               "  python -m drape.predict my_fabric.toml --out out/predict\n"
               "  python -m drape.predict cases/validation/cotton_broadcloth.toml --samples 16 "
               "--out out/cotton\n\n" + EXIT_CODES)
    p.add_argument("case", help="Cusick case with a [material.kes] sheet (copy cases/cusick_kes.toml)")
    p.add_argument("--samples", type=int, default=12, metavar="N",
                   help="runs, each with its own values of the unknowns and its own seed (default 12)")
    p.add_argument("--unknowns", nargs="*", choices=list(UNKNOWNS), metavar="NAME",
                   help="the values to sample (default: those the sheet omits); none: the seed alone")
    p.add_argument("--out", metavar="OUT", required=True, help="output folder")
    add_batch_options(p, resume="continue a stopped prediction in OUT", quiet="no progress bar")
    return p


def _sheet(case_path: Path, overrides: list[str], case) -> dict:
    """The values the case's own ``[material.kes]`` gives, with ``--set`` (not those its set-up
    stands in), in KES units as the loaded case holds them (a string with units converted)."""
    data = tomllib.loads(case_path.read_text())
    data.pop(SETUP_KEY, None)
    apply_overrides(data, overrides)
    given = data.get("material", {}).get("kes", {})
    return {k: v for k, v in case.material.kes.model_dump().items() if k in given}


def _same_samples(out: Path, rows) -> None:
    """A resumed prediction must draw the samples it began with (the same sheet and --samples)."""
    _, stored, _ = _read_definition(out)
    if [(r.name, r.keys) for r in stored] != [(r.name, r.keys) for r in rows]:
        raise SweepError(f"--resume: {out / 'sweep.json'} holds other samples (another sheet, "
                         "--set, --unknowns or --samples); give the same options, or a new --out")


def _predict(args, out: Path) -> tuple[dict, object]:
    case_path = Path(args.case)
    if args.samples < 2:
        raise SweepError(f"--samples = {args.samples}: must be >= 2 (an interval needs samples)")
    if args.workers is not None and args.workers < 1:
        raise SweepError(f"--workers = {args.workers}: must be >= 1")
    case = load_case(case_path, args.overrides)
    if case.case.analysis != "cusick" or case.material.kes is None:
        raise CaseError(f"{case_path}: drape predict needs a Cusick case (case.analysis = 'cusick') "
                        "whose fabric is a KES sheet ([material.kes])")
    sheet = _sheet(case_path, args.overrides, case)
    unknowns = missing_unknowns(sheet) if args.unknowns is None else list(dict.fromkeys(args.unknowns))
    rows = sample_rows(sheet, unknowns, args.samples)
    if args.resume:
        _same_samples(out, rows)
    run_sweep(case_path, rows, out, overrides=args.overrides, scheduler=args.scheduler,
              workers=args.workers, resume=args.resume, quiet=args.quiet)
    prediction = summarise(read_results(out / "results.csv"), rows, unknowns)
    if case.measured is not None and case.measured.DC_percent is not None:
        dc, nodes = prediction["DC_percent"], prediction["nodes"]
        prediction["measured"] = {
            "DC_percent": case.measured.DC_percent, "nodes": case.measured.nodes,
            "DC_inside": dc["low"] <= case.measured.DC_percent <= dc["high"],
            "nodes_inside": None if case.measured.nodes is None
            else nodes["low"] <= case.measured.nodes <= nodes["high"]}
    prediction["case"], prediction["samples"] = str(case_path), args.samples
    atomic_write_text(out / "prediction.json", json.dumps(prediction, indent=1))
    return prediction, rows


def _figure(prediction: dict, rows, out: Path) -> Path:
    records = {r["name"]: r for r in read_results(out / "results.csv")}
    path = out / "prediction.png"
    prediction_figure(prediction, rows, records).savefig(path, dpi=110)
    return path


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (:data:`drape.cli.common.EXIT_CODES`)."""
    args = _parser().parse_args(argv)
    out = Path(args.out)
    with sigterm_raises():
        try:
            prediction, rows = _predict(args, out)
        except KeyboardInterrupt as exc:
            return stopped(exc, "prediction", f"continue with --resume --out {out}")
        except Exception as exc:    # every problem is one line, with the code of its kind
            return fail(describe(exc), code_of(exc))
    print(describe_prediction(prediction))
    if "measured" in prediction:
        m = prediction["measured"]
        where = lambda inside: "inside" if inside else "outside"   # noqa: E731
        nodes = "" if m["nodes"] is None else f", {m['nodes']} nodes {where(m['nodes_inside'])}"
        print(f"measured: DC {m['DC_percent']:g} % {where(m['DC_inside'])} the interval{nodes}")
    print(f"details in {out / 'prediction.json'}, {_figure(prediction, rows, out)} and {out / 'results.csv'}")
    return EXIT_OK
