"""Where the identification's convergence stop would have ended searches that spent their budget.

    python benchmarks/search_stop_replay.py DIR [--within 0.01 0.02]

``DIR`` holds identifications run with ``--converged-within 0`` (or before the stop existed),
one folder each with ``identify.json`` and ``evaluations.jsonl``, e.g. the fabric folders of
``identify_fabrics.py``. In each, the search's own points are taken in order (the final
``identified`` runs aside); the stop fires at the first point that lies within ``W`` box widths
(log scale, :func:`drape.identification.surrogate.unit_distance`) of an earlier one of the
folder. Library points are left out, so the stop could only come earlier than shown. Until the
stop the search is the same either way (the surrogate sees the same evaluations), so the table
gives the evaluations and forward-run wall time the stop saves, not its effect on the answer.
The stop as ``drape identify`` applies it also needs the surrogate's answer run, which the
stored points do not say; where it was not, the search goes on from the point shown.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drape.identification.store import read_evaluations  # noqa: E402
from drape.identification.surrogate import unit_distance  # noqa: E402


def stop_index(points: list[dict], box: dict, within: float) -> int:
    """Number of points run before the stop fires (all of them if it never does)."""
    for i in range(1, len(points)):
        if min(unit_distance(box, points[i], q) for q in points[:i]) <= within:
            return i
    return len(points)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dir", type=Path, help="folder of identification folders")
    p.add_argument("--within", type=float, nargs="+", default=[0.01, 0.02], metavar="W")
    args = p.parse_args(argv)
    folders = sorted(f.parent for f in args.dir.glob("*/identify.json"))
    if not folders:
        print(f"{args.dir}: no identification folders (*/identify.json)", file=sys.stderr)
        return 2
    head = " | ".join(f"W = {w:g}: points, wall (min)" for w in args.within)
    print(f"| folder | points run | wall (min) | {head} |")
    print("|---|---|---|" + "---|" * len(args.within))
    for folder in folders:
        box = {k: tuple(v) for k, v in json.loads((folder / "identify.json").read_text())["box"].items()}
        own = [e for e in read_evaluations(folder) if not e.name.startswith("identified")]
        if not own:
            continue
        # each evaluation's seeds run side by side: its wall is its longest run
        wall = [max(r.get("wall_time_s") or 0.0 for r in e.runs) / 60 for e in own]
        cells = []
        for w in args.within:
            n = stop_index([e.point for e in own], box, w)
            cells.append(f"{n}, {sum(wall[:n]):.1f}")
        print(f"| {folder.name} | {len(own)} | {sum(wall):.1f} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
