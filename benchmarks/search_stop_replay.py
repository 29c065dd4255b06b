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
The replay is :mod:`drape.identification.stop_replay`; this script gives it a command line.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.identification.stop_replay import replay_table


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dir", type=Path, help="folder of identification folders")
    p.add_argument("--within", type=float, nargs="+", default=[0.01, 0.02], metavar="W")
    args = p.parse_args(argv)
    try:
        print(replay_table(args.dir, args.within))
    except ValueError as exc:
        print(exc, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
