"""Contact benchmark: wall time, Newton iterations and the contact's share of each iteration.

Runs every given case file (each with ``[[contact.body]]`` tables) as an ordinary run and
prints one row per case: wall time, steps, Newton iterations, the seconds spent in the contact
(barrier and friction forces and tangents, continuous collision detection; ``drape.contact``)
and that share of the time of an iteration. Time it alone on the machine.

    python benchmarks/bench_contact.py CASE.toml [CASE.toml ...] [--out DIR] [--set key=value ...]
"""
import argparse
import tempfile
import time
from pathlib import Path

from drape.case.build import build
from drape.case.case import load_case
from drape.run.runner import run_case


def bench(path, out_dir, overrides):
    """One run of the case at ``path``: its row of figures."""
    case = load_case(path, overrides)
    parts = build(case)
    if getattr(parts.model, "contact", None) is None:
        raise SystemExit(f"{path}: no [contact] table")
    start = time.perf_counter()
    summary = run_case(case, out_dir, quiet=True, parts=parts)
    wall = time.perf_counter() - start
    profile = summary["profile"]
    iterations = max(1, profile["newton_iterations"])
    contact = float(parts.model.seconds.get("contact", 0.0))
    return dict(case=Path(path).name, status=summary.get("status", ""), wall_s=wall, steps=profile["steps"],
                newton_iterations=profile["newton_iterations"], contact_s=contact,
                ms_per_iteration=1e3 * wall / iterations, contact_share=contact / wall if wall else 0.0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cases", nargs="+", help="case files with [[contact.body]] tables")
    ap.add_argument("--out", default=None, help="output folder (default: a temporary one)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="case override, e.g. --set solver.t_end=0.1 (a short check)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.out or tmp)
        rows = [bench(c, root / Path(c).stem, args.set) for c in args.cases]
    print(f"{'case':28s} {'status':10s} {'wall s':>8s} {'steps':>6s} {'Newton':>7s} {'ms/iter':>8s} "
          f"{'contact s':>10s} {'contact %':>9s}")
    for r in rows:
        print(f"{r['case']:28s} {r['status']:10s} {r['wall_s']:8.2f} {r['steps']:6d} {r['newton_iterations']:7d} "
              f"{r['ms_per_iteration']:8.2f} {r['contact_s']:10.2f} {100 * r['contact_share']:8.1f}%")


if __name__ == "__main__":
    main()
