"""Bundle forward runs with the package: ``cases/libraries/identification``, the warm start of
``drape.identify``.

    python benchmarks/bundle_library.py LIB [LIB ...] --case cases/cusick_lowered.toml
    python benchmarks/bundle_library.py LIB --case cases/cusick_lowered.toml --from-setup OLD

Takes from each library folder LIB (``drape.identify --library``) the evaluations run in the
set-up of ``--case`` as it loads now (its fingerprint: the resolved case at its own weight, no
``--set``), keeps what the surrogate reads (the point, and per seed the status and the drape's
descriptors; run folders become names), and appends those whose point the bundle lacks.
``--from-setup OLD`` takes instead those stored under an earlier fingerprint of the same case
and stamps them with today's: for runs made before a change that left the forward runs as
they were (a new case key at its default). ``tests/drape/identification/test_identify.py``
checks that every bundled evaluation carries the fingerprint of a bundled case as it loads
now, so a change of the case that would make the runs stale fails there. The bundling is
:mod:`drape.identification.bundle`; this script gives it a command line.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.identification.bundle import bundle

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("libraries", nargs="+", type=Path, help="library folders of drape.identify")
    parser.add_argument("--case", type=Path, required=True, help="the bundled base case the runs were made on")
    parser.add_argument("--from-setup", metavar="OLD", help="take the runs stored under this earlier fingerprint")
    parser.add_argument("--out", type=Path, default=ROOT / "cases" / "libraries" / "identification")
    args = parser.parse_args(argv)
    added, setup = bundle(args.libraries, args.case, args.out, args.from_setup)
    print(f"{added} evaluations added to {args.out} (set-up {setup} of {args.case})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
