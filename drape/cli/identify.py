"""``drape identify`` / ``python -m drape.identify``: the bending law from scanned drapes.

``python -m drape.identify SCAN [SCAN ...] --base CASE --out DIR [--free KEY ...] [--box KEY=LO,HI]
[--seeds N] [--evaluations N] [--library LIB] [--no-bundled-library] [--weight W] [--resume]``

The options make the identification's definition; :func:`drape.identification.identify.identify`
runs it. Writes to DIR: ``identified.json`` (parameters, intervals and how they were computed, the
scans' and the identified point's descriptors, the time spent where), ``material.toml`` (a
material file ``load_material`` reads), ``report.html``, the forward runs (``runs/``) and the
evaluation store (``evaluations.jsonl``, ``evaluations.csv``).
"""
from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path

from drape.cli.common import EXIT_CODES, EXIT_OK, Parser, add_batch_options, code_of, fail
from drape.identification.identify import DEFINITION, identify
from drape.identification.parameters import DEFAULT_FREE, PARAMETERS, parse_box
from drape.identification.search import CONVERGED_WITHIN, OutOfReach
from drape.run.messages import describe
from drape.run.termination import sigterm_raises, stopped

__all__ = ["EXIT_OUT_OF_REACH", "main"]

#: The scans lie beyond what the model reaches over the parameter box.
EXIT_OUT_OF_REACH = 5


def _parser() -> argparse.ArgumentParser:
    free = ", ".join(f"{p.name} ({p.what}; {p.unit}; box {p.low:g}..{p.high:g})"
                     for p in PARAMETERS.values())
    p = Parser(
        prog="python -m drape.identify",
        description="Identify the bending law's parameters from scanned Cusick drapes: "
                    "Bayesian optimisation (Gaussian-process surrogate) of forward runs of a "
                    "KES-only Cusick case, each point a seed ensemble, on Dask.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=f"free parameters: {free}\n\nexamples:\n"
               "  python -m drape.identify scans/*.ply --base cases/cusick_kes.toml --out out/id\n"
               "  python -m drape.identify s1.ply s2.ply --base cases/cusick_kes.toml "
               "--free bending_length hysteresis anisotropy --out out/id3\n"
               "  python -m drape.identify --resume --out out/id\n\n"
               + EXIT_CODES + f"\n  {EXIT_OUT_OF_REACH}    the scans are out of the model's "
               "reach over the parameter box")
    p.add_argument("scans", nargs="*", metavar="SCAN", help="scanned drapes (PLY, OBJ, STL, VTU, ...)")
    p.add_argument("--base", metavar="CASE", help="KES-only Cusick case (e.g. cases/cusick_kes.toml)")
    p.add_argument("--out", metavar="DIR", required=True, help="output folder")
    p.add_argument("--free", nargs="+", choices=list(PARAMETERS), metavar="KEY",
                   help=f"parameters to identify (default: {' '.join(DEFAULT_FREE)})")
    p.add_argument("--box", action="append", default=[], metavar="KEY=LOW,HIGH",
                   help="search range of a free parameter (default: the ranges listed below)")
    p.add_argument("--seeds", type=int, default=2, metavar="N",
                   help="perturbation seeds per point (default 2)")
    p.add_argument("--evaluations", type=int, default=14, metavar="N",
                   help="points run in DIR besides the final one (default 14; a resumed "
                        "identification may be given more)")
    p.add_argument("--converged-within", type=float, default=CONVERGED_WITHIN, metavar="W",
                   help="end the search once the surrogate asks for a point within W box widths "
                        "(log scale) of one already run and its answer lies as close to one (an "
                        f"answer not yet run is run first; default {CONVERGED_WITHIN:g}; 0: spend "
                        "every evaluation)")
    p.add_argument("--design", type=int, default=None, metavar="N",
                   help="Latin-hypercube points after the two corners (default 2 per parameter)")
    p.add_argument("--library", metavar="LIB", help="folder of earlier forward runs in the same "
                   "set-up: they warm-start the surrogate, and this run's are added to it")
    p.add_argument("--no-bundled-library", action="store_true",
                   help="do not warm-start from the forward runs shipped with the package "
                        "(cases/libraries/identification; used where their set-up is the base case's)")
    p.add_argument("--weight", type=float, metavar="MG_PER_CM2",
                   help="fabric weight W (mg/cm²) the material file's B is given at "
                        "(default: the base case's)")
    add_batch_options(p, resume="continue the identification in DIR (its stored evaluations "
                                "are registered again)")
    return p


def _definition(args, out: Path) -> dict:
    """What the identification is, from the options or (``--resume`` alone) from DIR."""
    stored = out / DEFINITION
    if args.base is None:
        if not (args.resume and stored.exists()):
            raise ValueError("--base CASE is required (or --resume --out DIR of an identification)")
        return json.loads(stored.read_text())
    if not args.scans:
        raise ValueError("give the scans to identify from (SCAN ...)")
    for path in [args.base, *args.scans]:
        if not Path(path).is_file():
            raise ValueError(f"{path}: no such file")
    for key, n in (("--seeds", args.seeds), ("--evaluations", args.evaluations)):
        if n < 1:
            raise ValueError(f"{key} = {n}: must be >= 1")
    if not (math.isfinite(args.converged_within) and 0 <= args.converged_within < 1):
        raise ValueError(f"--converged-within = {args.converged_within!r}: must lie in [0, 1)")
    free = list(dict.fromkeys(args.free or DEFAULT_FREE))
    if "bending_length" not in free:
        raise ValueError("--free must include bending_length (the drape's first parameter)")
    definition = {"scans": [str(Path(s).resolve()) for s in args.scans],
                  "base": str(Path(args.base).resolve()), "set": args.overrides, "free": free,
                  "box": parse_box(args.box, free), "seeds": args.seeds,
                  "evaluations": args.evaluations, "converged_within": args.converged_within,
                  "design": args.design,
                  "weight": args.weight,
                  "library": str(Path(args.library).resolve()) if args.library else None,
                  "bundled_library": not args.no_bundled_library}
    definition["box"] = {k: list(v) for k, v in definition["box"].items()}
    if stored.exists():
        if not args.resume:
            raise ValueError(f"{stored} exists: continue it with --resume, or use a new --out")
        before = json.loads(stored.read_text())
        before.setdefault("bundled_library", definition["bundled_library"])   # begun before there was one
        budget = {"evaluations": None, "converged_within": None}
        if {**before, **budget} != {**definition, **budget}:
            raise ValueError(f"--resume: {stored} defines another identification (only "
                             f"--evaluations and --converged-within may change); use a new --out")
    return definition


def _identify(args, out: Path) -> int:
    """The identification the options define, run; its summary printed."""
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers = {args.workers}: must be >= 1")
    result = identify(_definition(args, out), out, scheduler=args.scheduler, workers=args.workers,
                      quiet=args.quiet)
    if not args.quiet:
        print(result["summary_line"])
        print(f"report in {out / 'report.html'}")
    return EXIT_OK


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (see ``--help``)."""
    args = _parser().parse_args(argv)
    out = Path(args.out)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    with sigterm_raises():
        try:
            return _identify(args, out)
        except KeyboardInterrupt as exc:
            return stopped(exc, "identification", f"finished evaluations are in "
                                                  f"{out / 'evaluations.csv'} (continue with --resume)")
        except OutOfReach as exc:
            return fail(str(exc), EXIT_OUT_OF_REACH)
        except Exception as exc:    # every problem is one line, with the code of its kind
            return fail(describe(exc), code_of(exc))

