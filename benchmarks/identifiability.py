"""Identifiability of the bending law from Cusick drapes: the model's own drapes identified back.

    python benchmarks/identifiability.py --out out/identifiability
    python benchmarks/identifiability.py --out DIR --truth 1.5,0.5 2.5,0.8 --specimens 4 \
        --evaluations 14 --seeds 2 [--set KEY=VALUE ...]

For each true point (bending length c in cm, 2HB/B in 1/cm), the KES-only Cusick case
(``cases/cusick_kes.toml``, 30 cm on 18 cm) is run under perturbation seeds 100, 101, ... (the
"specimens"; the identification's own runs use seeds 0 .. N-1), their last VTU files are read as
scans, and ``drape identify`` (bending length and 2HB/B free, default box) finds the point
back. The points share one ``--library``. Writes ``DIR/identifiability.md`` and ``.csv``: the
truth, the identified point, its interval (the surrogate's misfit within 1 of its minimum),
whether the truth lies in it, the relative error, and the scans' and identified point's DC and
nodes. A parameter the drape hardly sees shows as a wide interval, not as a wrong answer.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drape.case.case import load_case  # noqa: E402
from drape.cli.identify import main as identify  # noqa: E402
from drape.identification.parameters import full_point, overrides  # noqa: E402
from drape.run.output import read_pvd  # noqa: E402
from drape.run.runner import run_case  # noqa: E402

FREE = ["bending_length", "hysteresis"]


def specimens(case: str, point: dict, weight: float, n: int, sets, folder: Path) -> list[Path]:
    """The model's drapes at ``point`` under seeds 100 .. 100+n-1: their last VTU files."""
    out = []
    for k in range(n):
        run_dir = folder / f"seed{100 + k}"
        summary_file = run_dir / "summary.json"
        if summary_file.exists():
            summary = json.loads(summary_file.read_text())
        else:
            items = list(sets) + overrides(point, weight) + [f"load.perturbation.seed={100 + k}"]
            summary = run_case(load_case(case, items), run_dir, quiet=True)
        if summary["status"] in ("settled", "completed"):
            out.append(read_pvd(run_dir / summary["pvd"])[-1][1])
    return out


def add_forward_options(parser) -> None:
    """The options an identification benchmark passes on to its forward runs."""
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--case", default=str(ROOT / "cases" / "cusick_kes.toml"))
    parser.add_argument("--set", action="append", default=[], dest="overrides", metavar="KEY=VALUE")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=Path("out/identifiability"))
    p.add_argument("--truth", nargs="+", default=["1.4,0.5", "2.2,0.8"], metavar="C,H",
                   help="true points: bending length (cm), 2HB/B (1/cm)")
    p.add_argument("--specimens", type=int, default=3)
    p.add_argument("--evaluations", type=int, default=14)
    add_forward_options(p)
    args = p.parse_args(argv)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    weight = float(load_case(args.case, args.overrides).material.kes.weight)
    rows = []
    for text in args.truth:
        c, h = (float(v) for v in text.split(","))
        point = full_point({"bending_length": c, "hysteresis": h}, FREE)
        folder = args.out / f"c{c:g}_h{h:g}"
        scans = specimens(args.case, point, weight, args.specimens, args.overrides,
                          folder / "specimens")
        argv = [*map(str, scans), "--base", args.case, "--out", str(folder / "identify"),
                "--evaluations", str(args.evaluations), "--seeds", str(args.seeds),
                "--library", str(args.out / "library"), "--no-bundled-library", "--quiet"]
        argv += sum((["--set", s] for s in args.overrides), [])
        argv += ["--workers", str(args.workers)] if args.workers else []
        if (folder / "identify" / "identify.json").exists():
            argv.append("--resume")
        code = identify(argv)
        row = {"truth_c_cm": c, "truth_h_per_cm": h, "exit": code}
        if code == 0:
            r = json.loads((folder / "identify" / "identified.json").read_text())
            for key, truth, col in (("bending_length", c, "c"), ("hysteresis", h, "h")):
                v, iv = r["parameters"][key], r["intervals"][key]
                row.update({f"{col}": round(v, 4), f"{col}_low": round(iv["low"], 4),
                            f"{col}_high": round(iv["high"], 4),
                            f"{col}_in_interval": iv["low"] <= truth <= iv["high"],
                            f"{col}_rel_error": round(v / truth - 1.0, 4)})
            row.update(scan_DC=round(r["target"]["DC_mean_percent"], 2),
                       scan_nodes=r["target"]["nodes_histogram"],
                       model_DC=round(r["simulated"]["DC_mean_percent"], 2),
                       model_nodes=r["simulated"]["nodes_histogram"], J=round(r["misfit"]["J"], 2),
                       evaluations=r["evaluations"], seconds=r["seconds"])
        rows.append(row)
        print(row, flush=True)
    with open(args.out / "identifiability.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, list(dict.fromkeys(k for r in rows for k in r)))
        writer.writeheader()
        writer.writerows(rows)
    lines = ["| truth c, 2HB/B | identified c [interval] | error | identified 2HB/B [interval] | "
             "error | scans DC / model DC | J |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["exit"] != 0:
            lines.append(f"| {r['truth_c_cm']}, {r['truth_h_per_cm']} | exit {r['exit']} | | | | | |")
            continue
        lines.append(f"| {r['truth_c_cm']}, {r['truth_h_per_cm']} | {r['c']} [{r['c_low']}, "
                     f"{r['c_high']}] | {100 * r['c_rel_error']:+.1f} % | {r['h']} [{r['h_low']}, "
                     f"{r['h_high']}] | {100 * r['h_rel_error']:+.1f} % | {r['scan_DC']} / "
                     f"{r['model_DC']} | {r['J']} |")
    (args.out / "identifiability.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
