"""Which node count does the model itself prefer? Cusick drapes forced into n folds, compared by energy.

A drape's node count may come from the fabric (the equilibrium of lowest energy) or from the
path that led to it (friction and damping freeze the first folds that form). This study
separates the two. Each run imposes one fold mode ``n`` with a strong transient load
(``load.perturbation.kind = "lobed"``, ``n_lobes = n``, amplitude ``--amplitude`` of the
weight, default 0.1, five times the default random perturbation's), with the friction of the
case and without it, and lets the specimen settle by the static-balance rule. The table
gives, for every run, the node count it settled in and its total potential energy
``Π = U + V`` (strain energy plus the weight's potential, from ``summary.json``):

- without friction, the settled states are equilibria of the elastic fabric alone, so the
  lowest ``Π`` among them is the node count the model prefers. If a forced mode does not
  hold (the run settles in another count), that mode is not even a stable equilibrium;
- with friction, the forced counts that hold show which drapes the hysteresis can freeze.

Usage::

    python benchmarks/fold_preference.py cases/validation/wool_tropical.toml --lobes 4,5,6,8,10 \\
        --out out/folds_wool
    python benchmarks/fold_preference.py cases/validation/cotton_broadcloth.toml --lobes 2,3,4,6 \\
        --out out/folds_cotton
    python benchmarks/fold_preference.py CASE --tiny --out /tmp/folds   (the plumbing, in seconds)

The runs go through :mod:`drape.batch.sweep` (Dask, ``--workers``, ``--resume``); the table is
printed and written to ``OUT/fold_preference.md``, and ``Π`` against the settled node count
to ``OUT/fold_preference.png``. The study is :mod:`drape.batch.fold_preference`; this script
gives it a command line.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.fold_preference import run_fold_preference
from drape.batch.rows import SweepError

#: A coarse, short version of any Cusick case: checks the plumbing, its figures mean nothing.
TINY = ["mesh.n_radial=2", "mesh.n_circumferential=24", "solver.t_end=0.05"]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("case", help="a Cusick case file (TOML)")
    p.add_argument("--lobes", default="4,5,6,8,10", help="imposed fold counts, comma-separated")
    p.add_argument("--amplitude", type=float, default=0.1, help="perturbation amplitude (of the weight)")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides",
                   help="override a case key in every run")
    p.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    p.add_argument("--resume", action="store_true", help="keep finished runs of OUT and run the others")
    p.add_argument("--tiny", action="store_true", help="coarse and short: checks the plumbing only")
    args = p.parse_args(argv)
    try:
        lobes = [int(v) for v in args.lobes.split(",")]
    except ValueError:
        p.error(f"--lobes {args.lobes!r}: expected integers such as 4,5,6")
    if not lobes or min(lobes) < 1:
        p.error("--lobes: every fold count must be >= 1")
    out = Path(args.out).resolve()
    try:
        text = run_fold_preference(args.case, lobes, out, amplitude=args.amplitude,
                                   overrides=(TINY if args.tiny else []) + args.overrides,
                                   workers=args.workers, resume=args.resume)
    except SweepError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(text)
    print(f"\nwritten: {out / 'fold_preference.md'}, {out / 'fold_preference.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
