"""Validation of ``drape identify`` on real fabrics: identify from some specimens, predict the others.

    python benchmarks/identify_fabrics.py SCANS.npz --out DIR [--fabrics 1 2 ...]
        [--evaluations 6] [--seeds 2] [--workers 2] [--set KEY=VALUE ...]

``SCANS.npz``: registered scans of real Cusick drapes in the format ``scan_descriptors.py``
reads (keys ``fabricNN_sampleSS_captureC``, ``fabricNN_sampleSS``, ``fabricNN_sampleSS_obsK``,
``vertex_unit_m``), e.g. the Leeds Cusick drape dataset (D. Gong, N. Mao, H. Wang, "Bayesian
Differentiable Physics for Cloth Digitalization", CVPR 2024); the scans are external data.

For each fabric, the scans of its odd samples are the training set: ``drape identify`` finds
the bending length and 2HB/B from them (``cases/cusick_kes.toml`` unless ``--case``; all
fabrics share one growing ``--library`` of forward runs, ``DIR/library``). The identified
point's simulated drapes then predict the even samples' scans: mean DC within 5 points and the
most frequent node count within ±1 (the target), beside the measured spread between those
specimens. Each half holds every capture of its specimens, face up and face down, as a Cusick
test reads a specimen on both faces and takes the mean (BS 5058); ``--faces up`` keeps the
face-up captures (1–2, or the single capture) only. The script also reports, from the scans
alone, face up against face down (captures 1–2 against 3–4; the identified law is symmetric
unless ``--set material.face_down_ratio=...``, so it predicts no difference) and the creep
series (``obsK``: the fall of DC at a fixed node count).

``--library-without-own LIB`` gives each fabric a library of its own: LIB's forward runs less
those its folder made in an earlier run of this script (``DIR/fabricNN/library``), but for the
initial design's, which every search runs first whatever its scans. Each fabric is then
identified as a lab would identify a new fabric after the others (or with the package's
bundled runs, made of the others).

``--scans-alone`` runs nothing: it judges each fabric's training scans as the prediction of its
test scans by the same target: what a model that reproduced its training specimens exactly
would score on that split (``DIR/scans_alone.csv``).

Writes, one row per fabric as soon as it is done: ``DIR/fabrics.csv``; at the end
``DIR/identify_fabrics.md`` and ``DIR/nodes_at_matched_dc.png`` (the plot of
``nodes_at_matched_dc.py``, here with the identified fabrics).

The study is :mod:`drape.identification.held_out` (the split and the target:
:mod:`drape.identification.specimen_split`); this script gives it a command line.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from drape.identification.held_out import Budget, identify_fabrics  # noqa: E402
from drape.identification.specimen_split import FACES, judge_scans_alone, scans_alone_markdown  # noqa: E402
from drape.run.termination import sigterm_raises  # noqa: E402
from identifiability import add_forward_options  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scans", type=Path, help="registered scans (.npz)")
    p.add_argument("--out", type=Path, default=Path("out/identify_fabrics"))
    p.add_argument("--fabrics", type=int, nargs="+",
                   help="fabric numbers, run in this order (default: all, in numbers' order)")
    p.add_argument("--evaluations", type=int, default=6,
                   help="points per fabric once the library has some (default 6)")
    p.add_argument("--first-evaluations", type=int, default=12,
                   help="points of a fabric that starts an empty library (default 12)")
    p.add_argument("--converged-within", type=float, default=None, metavar="W",
                   help="drape identify's convergence stop (default: its own; 0: spend every evaluation)")
    p.add_argument("--library-without-own", type=Path, metavar="LIB",
                   help="give each fabric a library of its own, LIB's forward runs less those of "
                        "that fabric's folder (fabricNN) in an earlier run of this script: every "
                        "fabric is new to a lab that has identified the others")
    p.add_argument("--faces", choices=FACES, default="both",
                   help="captures in each half: every capture of a specimen, face up and face down "
                        "(default, as BS 5058 reads a specimen), or the face-up ones only")
    p.add_argument("--scans-alone", action="store_true",
                   help="no identification: each fabric's training scans as the prediction of its "
                        "test scans, by the same target (DIR/scans_alone.csv)")
    add_forward_options(p)
    args = p.parse_args(argv)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    args.out.mkdir(parents=True, exist_ok=True)
    if args.scans_alone:
        print(scans_alone_markdown(judge_scans_alone(args.scans, args.out, args.faces, args.fabrics)))
        return 0
    budget = Budget(args.case, seeds=args.seeds, evaluations=args.evaluations,
                    first_evaluations=args.first_evaluations, converged_within=args.converged_within,
                    workers=args.workers, overrides=tuple(args.overrides))
    with sigterm_raises():         # stopped: the next call continues it
        text = identify_fabrics(args.scans, args.out, budget, numbers=args.fabrics, faces=args.faces,
                                library_without_own=args.library_without_own,
                                echo=lambda line: print(line, flush=True))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
