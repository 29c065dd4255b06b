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
they were (a new case key at its default). ``tests/test_identify.py`` checks that every bundled
evaluation carries the fingerprint of a bundled case as it loads now, so a change of the case
that would make the runs stale fails there.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def setup_of(case: Path) -> str:
    """Fingerprint of ``case`` as ``drape.identify --base case`` computes it (no --set, its weight)."""
    from drape.case.case import dump_case, load_case
    from drape.identification.store import fingerprint

    loaded = load_case(case, [])
    return fingerprint(dump_case(loaded), [], float(loaded.material.kes.weight))


def bundled(evaluation, setup: str, index: int):
    """``evaluation`` as the bundle keeps it, its ``index``-th: stamped ``setup``, named
    ``bNNN``, its run folders made names."""
    from drape.identification.store import Evaluation

    name = f"b{index:03d}"
    runs = [{"seed": r["seed"], "status": r["status"], "run_dir": f"bundled/{setup}/{name}/s{r['seed']}",
             "wall_time_s": r.get("wall_time_s", 0.0), "reason": r.get("reason", ""), "drape": r.get("drape")}
            for r in evaluation.runs]
    return Evaluation(evaluation.point, setup, runs, name)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("libraries", nargs="+", type=Path, help="library folders of drape.identify")
    parser.add_argument("--case", type=Path, required=True, help="the bundled base case the runs were made on")
    parser.add_argument("--from-setup", metavar="OLD", help="take the runs stored under this earlier fingerprint")
    parser.add_argument("--out", type=Path, default=ROOT / "cases" / "libraries" / "identification")
    args = parser.parse_args(argv)
    from drape.identification.store import append_evaluation, read_evaluations

    setup = setup_of(args.case)
    wanted = args.from_setup or setup
    stored = read_evaluations(args.out)
    have = {(e.setup, tuple(sorted(e.point.items(), key=str))) for e in stored}
    added = 0
    for library in args.libraries:
        for e in read_evaluations(library):
            key = (setup, tuple(sorted(e.point.items(), key=str)))
            if e.setup != wanted or key in have or not e.drapes.dc.size:
                continue
            append_evaluation(args.out, bundled(e, setup, len(stored) + added))
            have.add(key)
            added += 1
    print(f"{added} evaluations added to {args.out} (set-up {setup} of {args.case})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
