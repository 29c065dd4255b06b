"""The validation fabrics let down as ``cases/cusick_lowered.toml`` lets its specimen down.

The shipped validation cases (``cases/validation``) lay the specimen on the disc under a gravity
ramp, as ``cases/cusick_kes.toml`` does. This study runs the same fabrics on the tester's
support, lowered away, with the specimen's rigidity varying over it: each case gets the
lowered case's ``[contact]`` (the support placed half the fabric's thickness plus half the
barrier layer below it), its ``[model.rigidity_variation]``, the full weight at once, and,
where the fabric's sheet gives no shear rigidity G, the lowered set-up's. Everything else
(tester, mesh, fabric, damping, solver) stays the validation case's own
(:mod:`drape.batch.validation_lowered`).

    python benchmarks/validation_lowered.py --out out/validation_lowered --seeds 3
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.batch.validation_lowered import write_lowered_cases

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=Path("out/validation_lowered"))
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--cases", type=Path, default=ROOT / "cases" / "validation")
    args = p.parse_args(argv)

    folder = write_lowered_cases(args.cases, args.out / "cases")

    from drape.cli.validate import main as validate
    workers = [] if args.workers is None else ["--workers", str(args.workers)]
    return validate([str(folder), "--seeds", str(args.seeds), "--out", str(args.out / "runs"),
                     "--resume", *workers])


if __name__ == "__main__":
    sys.exit(main())
