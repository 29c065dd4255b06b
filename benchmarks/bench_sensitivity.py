"""Sensitivity of a Cusick drape: DC and node count, one factor at a time.

The factors and their levels, and why each, are :mod:`drape.batch.cusick_sensitivity`; the
default base is ``cases/validation/wool_tropical.toml`` (Matsudaira et al. 2015), any Cusick
case with ``[material.kes]`` may be given (``--case``).

Usage::

    python benchmarks/bench_sensitivity.py --out out/sensitivity            (the full study:
                                      26 runs of minutes each; --workers N, default one per core)
    python benchmarks/bench_sensitivity.py --factors air_drag,mesh --out out/sens_dm
    python benchmarks/bench_sensitivity.py --seeds 3 --out out/sensitivity_3seeds
    python benchmarks/bench_sensitivity.py --case cases/validation/cotton_broadcloth.toml \
        --out out/sensitivity_cotton                              (the same around the cotton)
    python benchmarks/bench_sensitivity.py --resume --out out/sensitivity    (after a stop)
    python benchmarks/bench_sensitivity.py --tiny                (the plumbing, in seconds)
    python benchmarks/bench_sensitivity.py --list                (factors and levels)

``--tiny`` runs every factor on a very coarse, short case (``mesh.n_radial = 2``,
``mesh.n_circumferential = 24``, ``solver.t_end = 0.05``): its figures mean nothing. The
runs go through :mod:`drape.batch.sweep` (Dask, ``OUT/results.csv``, ``--resume``); the study is
printed as a markdown table and written to ``OUT/sensitivity.md``, ``OUT/sensitivity.json``
and the tornado chart ``OUT/tornado.png`` (:mod:`drape.batch.sensitivity`).

Exit codes: 0 every run finished (whatever its status), 1 bad input, 130 interrupted,
143 terminated: finished runs stay in ``OUT/results.csv`` (continue with ``--resume``).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:            # run as a script from anywhere
    sys.path.insert(0, str(ROOT))

from drape.batch.cusick_sensitivity import BASE_CASE, study_factors  # noqa: E402
from drape.batch.sensitivity import StudyError, run_study  # noqa: E402

#: The coarse, short case of ``--tiny`` (plumbing only).
TINY = ["mesh.n_radial=2", "mesh.n_circumferential=24", "solver.t_end=0.05"]


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code."""
    from drape.batch.sensitivity import markdown_table, factor_sentences
    from drape.batch.rows import SweepError
    from drape.cli.common import add_batch_options
    from drape.run.termination import sigterm_raises, stopped

    p = argparse.ArgumentParser(
        prog="python benchmarks/bench_sensitivity.py",
        description="One-factor-at-a-time sensitivity of a Cusick drape (DC and nodes) around "
                    "a Cusick case (default: the wool of the validation set); table, JSON and "
                    "tornado chart in OUT.")
    p.add_argument("--case", default=str(BASE_CASE), help="base case (default: the wool)")
    p.add_argument("--out", metavar="OUT", help="study folder (default out/sensitivity, "
                   "out/sensitivity_tiny with --tiny)")
    p.add_argument("--factors", metavar="NAME,...", help="only these factors (see --list)")
    p.add_argument("--seeds", type=int, default=1, metavar="N",
                   help="run every level under the perturbation seeds 0..N-1 (default 1)")
    p.add_argument("--tiny", action="store_true",
                   help="coarse, short runs: " + " ".join(TINY) + " (plumbing only)")
    add_batch_options(p, resume="keep the finished runs of OUT")
    p.add_argument("--list", action="store_true", help="print the factors and levels, run nothing")
    args = p.parse_args(argv)
    overrides = (TINY if args.tiny else []) + args.overrides
    out = Path(args.out or ("out/sensitivity_tiny" if args.tiny else "out/sensitivity"))
    try:
        if args.seeds < 1:
            raise StudyError(f"--seeds = {args.seeds}: must be >= 1")
        if args.workers is not None and args.workers < 1:
            raise StudyError(f"--workers = {args.workers}: must be >= 1")
        wanted = [w.strip() for w in (args.factors or "").split(",") if w.strip()]
        chosen = study_factors(args.case, overrides, args.seeds, wanted)
        if args.list:
            for f in chosen:
                levels = "; ".join(f"{lv.label} ({', '.join(f'{k}={v}' for k, v in lv.keys.items())})"
                                   for lv in f.levels)
                print(f"{f.name}: {f.title}, default {f.base_label} -> {levels}")
            return 0
        with sigterm_raises():
            study = run_study(args.case, chosen, out, overrides=overrides, seeds=args.seeds,
                              workers=args.workers, scheduler=args.scheduler,
                              resume=args.resume, quiet=args.quiet)
    except (StudyError, SweepError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2                           # bad input (drape.cli.common.EXIT_BAD_INPUT)
    except KeyboardInterrupt as exc:
        return stopped(exc, "study", f"continue with --resume --out {out}")
    print(markdown_table(study))
    print()
    print("\n".join(factor_sentences(study)))
    files = study["files"]
    print(f"\ntable in {files['md']} and {files['json']}; tornado chart in {files['png']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
