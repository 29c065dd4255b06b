"""``drape identify`` / ``python -m drape.identify``: the bending law from scanned drapes.

``python -m drape.identify SCAN [SCAN ...] [--base CASE] --out DIR [--free KEY ...] [--box KEY=LO,HI]
[--seeds N] [--evaluations N] [--library LIB] [--no-bundled-library] [--weight W] [--resume]``

The options make the identification's definition; :func:`drape.identification.identify.identify`
runs it. Writes to DIR: ``identified.json`` (parameters, intervals and how they were computed, the
scans' and the identified point's descriptors, the time spent where), ``material.toml`` (a
material file ``load_material`` reads), ``report.html``, the forward runs (``runs/``) and the
evaluation store (``evaluations.jsonl``, ``evaluations.csv``).
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path

from drape.cli.common import (
    EXIT_CODES,
    EXIT_OK,
    Parser,
    add_batch_options,
    code_of,
    fail,
    writable_folder,
)
from drape.identification.definition import (
    BUDGET,
    COUNTS,
    DEFINITION,
    check_definition,
    read_definition,
)
from drape.identification.identify import identify
from drape.identification.parameters import DEFAULT_FREE, PARAMETERS, parse_box
from drape.identification.search import CONVERGED_WITHIN, OutOfReach
from drape.identification.store import BUNDLED_LIBRARY, TABLE
from drape.run.messages import describe
from drape.run.termination import sigterm_raises, stopped

__all__ = ["EXIT_OUT_OF_REACH", "WORKERS", "main"]

#: The scans lie beyond what the model reaches over the parameter box.
EXIT_OUT_OF_REACH = 5
#: The stated range of --workers (processes of the local cluster).
WORKERS = (1, 256)


def _arg_weight(text: str):
    """A weight: a bare number (mg/cm²) or one with units (checked with the definition)."""
    try:
        return float(text)
    except ValueError:
        return text


def _ranges() -> str:
    counts = "; ".join(f"--{k} {lo}..{hi}" for k, (lo, hi) in COUNTS.items())
    return (f"option ranges: {counts}; --converged-within 0 <= W < 1; --weight 1..100 mg/cm²; "
            f"--scale > 0; --workers {WORKERS[0]}..{WORKERS[1]}; --box within each parameter's "
            "limits (below)")


def _parser() -> argparse.ArgumentParser:
    free = ", ".join(f"{p.name} ({p.what}; {p.unit}; box {p.low:g}..{p.high:g}, limits "
                     f"{p.limits[0]:g}..{p.limits[1]:g})" for p in PARAMETERS.values())
    p = Parser(
        prog="python -m drape.identify",
        description="Identify the bending law's parameters from scanned Cusick drapes: "
                    "Bayesian optimisation (Gaussian-process surrogate) of forward runs of a "
                    "KES-only Cusick case, each point a seed ensemble, on Dask. Every option, "
                    "the scans and the base case are checked before DIR is made or written.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=f"{_ranges()}\n\nfree parameters: {free}\n\nexamples:\n"
               "  python -m drape.identify scans/*.ply --out out/id\n"
               "  python -m drape.identify s1.ply s2.ply --base my_tester.toml "
               "--free bending_length hysteresis anisotropy --out out/id3\n"
               "  python -m drape.identify --resume --out out/id\n\n"
               + EXIT_CODES + f"\n  {EXIT_OUT_OF_REACH}    the scans are out of the model's "
               "reach over the parameter box")
    p.add_argument("scans", nargs="*", metavar="SCAN", help="scanned drapes (PLY, OBJ, STL, VTU, "
                   "...), measured as drape measure measures them (30 cm specimen, 18 cm disc)")
    p.add_argument("--scale", type=float, default=None, metavar="FACTOR",
                   help="multiply the scans' coordinates by FACTOR to get metres (0.001 for mm)")
    p.add_argument("--base", metavar="CASE", help="KES-only Cusick case the forward runs are "
                   "made on (default: cases/cusick_lowered.toml, the one Cusick set-up, on which "
                   "the bundled library of forward runs was made)")
    p.add_argument("--out", metavar="DIR", required=True, help="output folder")
    p.add_argument("--free", nargs="+", choices=list(PARAMETERS), metavar="KEY",
                   help=f"parameters to identify (default: {' '.join(DEFAULT_FREE)})")
    p.add_argument("--box", action="append", default=[], metavar="KEY=LOW,HIGH",
                   help="search range of a free parameter (default: the ranges listed below)")
    p.add_argument("--seeds", type=int, default=None, metavar="N",
                   help="perturbation seeds per point (default 2)")
    p.add_argument("--evaluations", type=int, default=None, metavar="N",
                   help="points run in DIR besides the final one (default 14; a resumed "
                        "identification may be given more)")
    p.add_argument("--converged-within", type=float, default=None, metavar="W",
                   help="end the search once the surrogate asks for a point within W box widths "
                        "(log scale) of one already run and its answer lies as close to one (an "
                        f"answer not yet run is run first; default {CONVERGED_WITHIN:g}; 0: spend "
                        "every evaluation)")
    p.add_argument("--design", type=int, default=None, metavar="N",
                   help="Latin-hypercube points after the two corners (default 2 per parameter)")
    p.add_argument("--library", metavar="LIB", help="folder of earlier forward runs in the same "
                   "set-up: they warm-start the surrogate, and this run's are added to it")
    p.add_argument("--no-bundled-library", action="store_true", default=None,
                   help="do not warm-start from the forward runs shipped with the package "
                        "(cases/libraries/identification; used where their set-up is the base case's)")
    p.add_argument("--weight", type=_arg_weight, metavar="MG_PER_CM2",
                   help="fabric weight W (mg/cm², or with units, e.g. '124 g/m^2') the material "
                        "file's B is given at (default: the base case's)")
    add_batch_options(p, resume="continue the identification in DIR (its stored evaluations "
                                "are registered again); options given with it may raise the "
                                "budget, or correct a definition stored with values now refused")
    return p


def _given(args) -> dict:
    """The definition's keys the command line gives (an option left out gives none)."""
    given = {"scans": list(args.scans) or None, "scale": args.scale, "base": args.base,
             "set": args.overrides or None, "free": args.free, "seeds": args.seeds,
             "evaluations": args.evaluations, "converged_within": args.converged_within,
             "design": args.design, "weight": args.weight, "library": args.library,
             "bundled_library": False if args.no_bundled_library else None}
    given = {k: v for k, v in given.items() if v is not None}
    if args.box or "free" in given:
        given["box"] = args.box
    return given


def _checked(definition: dict, box_items) -> dict:
    """``definition`` checked, its box from ``--box`` items over the free parameters'
    defaults when they are given (checked after the keys before it: the scans, the base)."""
    if box_items is None:
        return check_definition(definition)
    checked = check_definition({k: v for k, v in definition.items() if k != "box"})
    box = parse_box(box_items, checked["free"])
    return check_definition({**checked, "box": {k: list(v) for k, v in box.items()}})


def _fresh(given: dict) -> dict:
    """A new identification's definition from the options."""
    if "scans" not in given:
        raise ValueError("give the scans to identify from (SCAN ...)")
    box = given.pop("box", None)
    return _checked({"bundled_library": True, **given}, box)


def _resumed(given: dict, out: Path) -> dict:
    """The stored definition of ``out``, with the options given: the budget, or corrections of
    a definition that cannot be used as stored."""
    stored, problem = read_definition(out)
    if problem is None:
        problem = _folder_problem(stored, out)
    path = out / DEFINITION
    box = given.pop("box", None)
    if problem is None:
        merged = _checked({**stored, **given}, box)
        if {**merged, **dict.fromkeys(BUDGET)} != {**stored, **dict.fromkeys(BUDGET)}:
            raise ValueError(f"--resume: {path} defines another identification (only "
                             f"--evaluations and --converged-within may change); use a new --out")
        return merged
    what = problem if stored is None else "holds a value now refused"
    try:
        return _checked({**(stored or {}), **given}, box)
    except ValueError as exc:
        raise ValueError(f"--resume: {path} {what}: {exc}; give the corrected options with "
                         "--resume") from None


def _definition(args, out: Path) -> dict:
    """What the identification is: from the options, or (``--resume``) from DIR with them."""
    given = _given(args)
    exists = (out / DEFINITION).exists()
    if exists and args.resume:
        return _resumed(given, out)
    if exists:
        raise ValueError(f"{out / DEFINITION} exists: continue it with --resume, or use a new --out")
    if args.resume and "scans" not in given:
        raise ValueError(f"--resume: {out} holds no identification (no {DEFINITION}); start one "
                         f"with SCAN ... --out {out}")
    return _fresh(given)


def _check_folders(definition: dict, out: Path) -> None:
    """The output folder and the library writable, the library neither of the others."""
    writable_folder(out, "--out")
    library = definition["library"]
    if library is None:
        return
    if Path(library) == out.resolve():
        raise ValueError(f"--library {library}: must not be the output folder --out")
    if Path(library) == Path(BUNDLED_LIBRARY).resolve():
        raise ValueError(f"--library {library}: the bundled library is read only")
    writable_folder(library, "--library")


def _folder_problem(definition: dict, out: Path) -> str | None:
    """What :func:`_check_folders` finds wrong with a stored definition's folders (a library
    that has become a file can be given anew with --resume), or None."""
    try:
        _check_folders(definition, out)
    except (OSError, ValueError) as exc:
        return describe(exc)
    return None


def _identify(args, out: Path) -> int:
    """The identification the options define, checked, run; its summary printed."""
    if args.workers is not None and not WORKERS[0] <= args.workers <= WORKERS[1]:
        raise ValueError(f"--workers = {args.workers}: must be from {WORKERS[0]} to {WORKERS[1]}")
    definition = _definition(args, out)
    _check_folders(definition, out)
    result = identify(definition, out, scheduler=args.scheduler, workers=args.workers,
                      quiet=args.quiet)
    if not args.quiet:
        print(result["summary_line"])
        print(f"report in {out / 'report.html'}")
    return EXIT_OK


def _stopped_hint(out: Path) -> str:
    """What a stopped identification left, and how to go on."""
    if not (out / DEFINITION).exists():
        return "nothing was written"
    if (out / TABLE).exists():
        return f"finished evaluations are in {out / TABLE} (continue with --resume)"
    return f"no evaluation had finished (continue with --resume --out {out})"


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (see ``--help``)."""
    args = _parser().parse_args(argv)
    out = Path(args.out)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    with sigterm_raises():
        try:
            return _identify(args, out)
        except KeyboardInterrupt as exc:
            return stopped(exc, "identification", _stopped_hint(out))
        except OutOfReach as exc:
            return fail(str(exc), EXIT_OUT_OF_REACH)
        except Exception as exc:    # every problem is one line, with the code of its kind
            return fail(describe(exc), code_of(exc))
