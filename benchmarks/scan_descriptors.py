"""Descriptors of a set of registered Cusick scans, per scan and per fabric.

    python benchmarks/scan_descriptors.py SCANS.npz [--out DIR]

The file is a numpy ``.npz`` with, for each scan, ``KEY/vertices`` (int16; times the scalar
entry ``vertex_unit_m`` gives metres) and ``KEY/faces`` (uint16, 0-based triangles); keys are
``fabricNN_sampleSS_captureC``, ``fabricNN_sampleSS`` or ``fabricNN_sampleSS_obsK`` (one
specimen observed K = 1, 2, ... times in succession while it creeps). The Leeds Cusick drape
dataset comes in this form (D. Gong, N. Mao, H. Wang, "Bayesian Differentiable Physics for Cloth
Digitalization", CVPR 2024); its scans are external data and are not part of this repository.

Every scan goes through :func:`drape.analyses.scan_measure.measure_surface` (30 cm specimen on an 18 cm
disc, centre from the flat top, the node detection of the simulated drape) and the script
writes to DIR (default ``out/scan_descriptors``):

- ``scans.csv``: key, fabric, sample, series (capture / obs) and its number, DC %, nodes,
  mean fold depth, the outline's irregularity (mm: its harmonics outside the fold pattern,
  :func:`drape.analyses.outline.outline_irregularity`), the centre used, the harmonic
  amplitudes a_0 .. a_20 (mm), or the reason a scan could not be read;
- ``fabrics.csv``: per fabric, over its scans other than the creep series: number of scans,
  DC mean, standard deviation, min and max, nodes min, max, most frequent and mean, mean
  irregularity;
- ``creep.csv``: the creep series per fabric and observation: the same columns;
- ``faces.csv``: face up against face down, per fabric over its specimens captured four times
  (captures 1–2 one face up, 3–4 the other): the mean and standard deviation over specimens of
  a specimen's DC face down minus face up, and beside it the repeat scatter (half the
  difference between the two captures of one face, averaged), which that difference must
  exceed to mean anything.

and prints the two tables.
"""
from __future__ import annotations

import argparse
import csv
import re
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from drape.analyses.scan_measure import DISC_DIAMETER, SPECIMEN_DIAMETER, measure_surface
from drape.analyses.outline import N_HARMONICS
from drape.analyses.scan import ScanError

KEY = re.compile(r"fabric(?P<fabric>\d+)_sample(?P<sample>\d+)"
                 r"(?:_(?P<series>capture|obs)(?P<n>\d+))?$")
SUMMARY_COLUMNS = ["scans", "dc_mean", "dc_std", "dc_min", "dc_max",
                   "nodes_min", "nodes_max", "nodes_mode", "nodes_mean", "irregularity_mm"]


def scan_keys(data) -> list[str]:
    """Keys of the scans in the file, sorted."""
    return sorted(k[: -len("/vertices")] for k in data.files if k.endswith("/vertices"))


def describe_scan(data, key: str, unit: float) -> dict:
    """One row of ``scans.csv``."""
    match = KEY.match(key)
    row = {"key": key, "fabric": int(match["fabric"]) if match else "",
           "sample": int(match["sample"]) if match else "",
           "series": (match["series"] or "") if match else "",
           "number": int(match["n"]) if match and match["n"] else ""}
    points = data[f"{key}/vertices"].astype(float) * unit
    faces = data[f"{key}/faces"].astype(np.int64)
    try:
        m = measure_surface(points, faces, SPECIMEN_DIAMETER / 2, DISC_DIAMETER / 2, name=key)
    except ScanError as exc:
        return {**row, "error": str(exc)}
    s = m.result.summary()
    row.update(dc_percent=round(s["drape_coefficient_percent"], 3), nodes=s["n_nodes"],
               depth_mm=round(1e3 * s["node_depth_mean_m"], 3),
               irregularity_mm=round(1e3 * s["outline_irregularity_m"], 3),
               centre_x_mm=round(1e3 * m.result.centre[0], 3),
               centre_y_mm=round(1e3 * m.result.centre[1], 3))
    row.update({f"a{k}_mm": round(1e3 * a, 4) for k, a in enumerate(s["outline_harmonics_m"])})
    return {**row, "error": ""}


def summarise(rows) -> dict:
    """DC and node statistics of a group of rows."""
    dc = np.array([r["dc_percent"] for r in rows])
    nodes = [r["nodes"] for r in rows]
    counts = Counter(nodes)
    mode = min(n for n, c in counts.items() if c == max(counts.values()))
    return {"scans": len(rows), "dc_mean": round(float(dc.mean()), 2),
            "dc_std": round(float(dc.std(ddof=1)), 2) if len(dc) > 1 else 0.0,
            "dc_min": round(float(dc.min()), 2), "dc_max": round(float(dc.max()), 2),
            "nodes_min": min(nodes), "nodes_max": max(nodes), "nodes_mode": mode,
            "nodes_mean": round(float(np.mean(nodes)), 2),
            "irregularity_mm": round(float(np.mean([r["irregularity_mm"] for r in rows])), 2)}


def group(rows, key) -> list[dict]:
    """Summary rows of ``rows`` grouped by ``key(row)`` (a dict of the group's columns)."""
    groups: dict = {}
    for r in rows:
        groups.setdefault(tuple(key(r).items()), []).append(r)
    return [{**dict(k), **summarise(g)} for k, g in sorted(groups.items())]


FACE_COLUMNS = ["fabric", "specimens", "dc_up", "dc_down", "down_minus_up", "down_minus_up_std", "repeat"]


def face_pairs(rows) -> list[dict]:
    """Per fabric, face down against face up over the specimens with all four captures (1–2 one
    face up, 3–4 the other): mean DC of each face, the mean and standard deviation of a
    specimen's down − up, and the repeat scatter of one face's two captures (half their
    difference, averaged).

    >>> rows = [{"fabric": 1, "sample": s, "series": "capture", "number": n, "dc_percent": dc}
    ...         for s, dcs in ((1, (40, 41, 45, 45)), (2, (42, 42, 46, 48))) for n, dc in zip((1, 2, 3, 4), dcs)]
    >>> face_pairs(rows)  # doctest: +NORMALIZE_WHITESPACE
    [{'fabric': 1, 'specimens': 2, 'dc_up': 41.25, 'dc_down': 46.0, 'down_minus_up': 4.75,
      'down_minus_up_std': 0.35, 'repeat': 0.38}]
    """
    captures: dict = {}
    for r in rows:
        if r["series"] == "capture":
            captures.setdefault((r["fabric"], r["sample"]), {})[r["number"]] = r["dc_percent"]
    per_fabric: dict = {}
    for (fabric, _), dc in sorted(captures.items()):
        if all(n in dc for n in (1, 2, 3, 4)):
            per_fabric.setdefault(fabric, []).append(
                (0.5 * (dc[1] + dc[2]), 0.5 * (dc[3] + dc[4]), 0.25 * (abs(dc[1] - dc[2]) + abs(dc[3] - dc[4]))))
    out = []
    for fabric, pairs in per_fabric.items():
        up, down, repeat = (np.array(c, dtype=float) for c in zip(*pairs))
        diff = down - up
        out.append({"fabric": fabric, "specimens": len(pairs), "dc_up": round(float(up.mean()), 2),
                    "dc_down": round(float(down.mean()), 2), "down_minus_up": round(float(diff.mean()), 2),
                    "down_minus_up_std": round(float(diff.std(ddof=1)), 2) if len(diff) > 1 else 0.0,
                    "repeat": round(float(repeat.mean()), 2)})
    return out


def write_csv(path: Path, rows, columns) -> None:
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)


def print_table(title: str, rows, columns) -> None:
    print(title)
    print("  ".join(f"{c:>10}" for c in columns))
    for r in rows:
        print("  ".join(f"{r[c]:>10}" for c in columns))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("npz", type=Path, help="registered scans (.npz)")
    p.add_argument("--out", type=Path, default=Path("out/scan_descriptors"))
    args = p.parse_args(argv)
    data = np.load(args.npz)
    unit = float(data["vertex_unit_m"])
    rows = [describe_scan(data, key, unit) for key in scan_keys(data)]
    good = [r for r in rows if not r["error"]]
    for r in rows:
        if r["error"]:
            print(f"{r['key']}: {r['error']}", file=sys.stderr)
    args.out.mkdir(parents=True, exist_ok=True)
    harmonics = [f"a{k}_mm" for k in range(N_HARMONICS + 1)]
    write_csv(args.out / "scans.csv", rows,
              ["key", "fabric", "sample", "series", "number", "dc_percent", "nodes", "depth_mm",
               "irregularity_mm",
               "centre_x_mm", "centre_y_mm", *harmonics, "error"])
    fabrics = group([r for r in good if r["series"] != "obs"], lambda r: {"fabric": r["fabric"]})
    creep = group([r for r in good if r["series"] == "obs"],
                  lambda r: {"fabric": r["fabric"], "obs": r["number"]})
    write_csv(args.out / "fabrics.csv", fabrics, ["fabric", *SUMMARY_COLUMNS])
    write_csv(args.out / "creep.csv", creep, ["fabric", "obs", *SUMMARY_COLUMNS])
    print_table("fabrics (creep series excluded)", fabrics, ["fabric", *SUMMARY_COLUMNS])
    print_table("creep series", creep, ["fabric", "obs", *SUMMARY_COLUMNS])
    faces = face_pairs(good)
    write_csv(args.out / "faces.csv", faces, FACE_COLUMNS)
    print_table("face down against face up (DC %)", faces, FACE_COLUMNS)
    print(f"{len(good)} of {len(rows)} scans measured; tables in {args.out}")
    return 0 if len(good) == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
