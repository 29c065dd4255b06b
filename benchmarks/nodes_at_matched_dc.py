"""Node count at matched drape coefficient: simulated against measured, fabric by fabric.

A drape at rest depends on the fabric's weight only through B/W and 2HB/W, so a scanned
fabric of unknown KES values can be matched by its bending length alone. For each
fabric of a scan set, this script

1. reads every scan through ``drape.analyses.scan_measure`` (the Cusick analysis of a simulated drape)
   and takes the fabric's mean DC and the range of node counts over its specimens and
   captures (``benchmarks/scan_descriptors.py``);
2. runs the KES-only Cusick case (``cases/cusick_kes.toml`` at the scans' 30 cm on 18 cm,
   warp = weft, 2HB/B = 0.5 cm⁻¹, W = 15 mg/cm²) over a grid of B for each friction law,
   and interpolates log B against DC to the B at which the model's DC is the fabric's
   (``--match grid``), or, per fabric, takes secant steps in log B from a first B until its
   run's DC is within ``--tol`` points of the fabric's (``--match secant``, for a case whose
   DC is not monotonic enough in B to interpolate across fabrics, e.g. the lowered support);
3. runs the model at that B under several perturbation seeds and compares its node count
   with the fabric's measured range.

Usage::

    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/matched
    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/matched --laws tensor --seeds 3
    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/lowered --case cases/cusick_lowered.toml \
        --match secant --seeds 2
    python benchmarks/nodes_at_matched_dc.py SCANS.npz --out out/matched_drop --laws tensor \
        --set load.gravity.ramp_time=0.5 --set load.perturbation.duration=0.5

``SCANS.npz``: registered scans of real Cusick drapes (the format ``scan_descriptors.py``
reads). Writes ``matched.csv`` and ``matched.md`` (one row per fabric and law),
``nodes_at_matched_dc.png`` and the sweeps it ran (``grid_<law>/``, ``matched_<law>/``; with
``--match secant``: ``secant_<k>/`` and ``seeds/``).
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from drape.batch.rows import SweepRow, read_results
from drape.batch.sweep import run_sweep  # noqa: E402
from fold_causes import fabric_keys  # noqa: E402

LAWS = {"tensor": [], "per_direction": ["model.bending_friction=per_direction"]}
GRIDS = {"tensor": [0.005 * 2 ** (k / 2) for k in range(13)],            # 0.005 … 0.32
         "per_direction": [0.005 * 2 ** k for k in range(8)]}             # 0.005 … 0.64
GOOD = ("settled", "completed")
#: Secant matching: the first B without a start table, and the first step's DC points per
#: unit of ln B (about 20 between DC 20 and 75 %, BENCHMARKS.md "Folds of real fabrics").
START_B = 0.05
SLOPE = 20.0


def _finished(folder: Path):
    """The finished runs of the sweep in ``folder``, their ``run_dir`` made absolute."""
    records = read_results(folder / "results.csv")
    return [{**r, "run_dir": str(folder / r["run_dir"]) if r.get("run_dir") else ""}
            for r in records if r.get("status") in GOOD and r.get("DC_percent")]


def dc_curve(case, law: str, out: Path, workers, overrides) -> tuple[np.ndarray, np.ndarray]:
    """(B, DC %) of the law's grid (seed 0), sorted by B."""
    rows = [SweepRow(f"B{B:.5g}", {**dict(o.split("=", 1) for o in fabric_keys(B) + LAWS[law])})
            for B in GRIDS[law]]
    sweep(case, rows, out, workers, overrides)
    recs = _finished(out)
    B = np.array([float(r["material.kes.B_warp"]) for r in recs])
    dc = np.array([float(r["DC_percent"]) for r in recs])
    order = np.argsort(B)
    return B[order], dc[order]


def sweep(case, rows, out: Path, workers, overrides) -> None:
    """Run ``rows`` into ``out`` (``overrides`` in every run), continuing a sweep already there."""
    run_sweep(case, rows, out, overrides=overrides, workers=workers,
              resume=(out / "results.csv").exists(), quiet=False)


def matched_B(B, dc, target: float) -> float | None:
    """B at which the grid's DC reaches ``target``: linear in log B between the two grid
    points around it, on the grid's running maximum (DC grows with B); None off the grid."""
    mono = np.maximum.accumulate(dc)
    if not (mono[0] <= target <= mono[-1]):
        return None
    logB = np.log(B)
    i = int(np.searchsorted(mono, target))
    i = min(max(i, 1), len(B) - 1)
    lo, hi = mono[i - 1], mono[i]
    s = 0.0 if hi == lo else (target - lo) / (hi - lo)
    return float(np.exp(logB[i - 1] + s * (logB[i] - logB[i - 1])))


def read_fabrics(scans: str, out: Path) -> list[dict]:
    """Per-fabric measured DC and node counts (``scan_descriptors.py``'s fabrics.csv)."""
    import scan_descriptors
    folder = out / "scans"
    if not (folder / "fabrics.csv").exists():
        scan_descriptors.main([scans, "--out", str(folder)])
    with open(folder / "fabrics.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _nodes(recs) -> list[int]:
    return sorted(int(float(r["nodes"])) for r in recs if r.get("nodes"))


def compare(fabrics, case, laws, seeds: int, out: Path, workers, overrides=()) -> list[dict]:
    """One row per (fabric, law): matched B, the model's DCs and node counts."""
    table = []
    for law in laws:
        B, dc = dc_curve(case, law, out / f"grid_{law}", workers, list(overrides))
        rows, target = [], {}
        for fab in fabrics:
            Bm = matched_B(B, dc, float(fab["dc_mean"]))
            target[fab["fabric"]] = Bm
            if Bm is None:
                continue
            keys = fabric_keys(float(f"{Bm:.4g}")) + LAWS[law]
            for seed in range(seeds if law == laws[0] else 1):
                rows.append(SweepRow(f"fabric{fab['fabric']}_s{seed}",
                                     dict(o.split("=", 1) for o in keys
                                          + [f"load.perturbation.seed={seed}"])))
        sweep(case, rows, out / f"matched_{law}", workers, list(overrides))
        recs = _finished(out / f"matched_{law}")
        table += [table_row(fab, law, target[fab["fabric"]], _runs_of(recs, fab["fabric"]))
                  for fab in fabrics]
    return table


def _runs_of(recs, fabric) -> list[dict]:
    """The records of ``fabric``'s seeds (rows named ``fabric<id>_s<seed>``)."""
    return [r for r in recs if r["name"].rsplit("_s", 1)[0] == f"fabric{fabric}"]


def _irregularity_mm(recs) -> float | None:
    """Mean outline irregularity (mm) of the runs, from their summary.json (None if absent)."""
    from drape.analyses.outline import outline_irregularity

    values = []
    for r in recs:
        path = Path(r.get("run_dir") or "") / "summary.json"
        if r.get("run_dir") and path.exists():
            a = json.loads(path.read_text())["analysis"]
            values.append(outline_irregularity(a["outline_harmonics_m"], a["n_nodes"]))
    return round(1e3 * float(np.mean(values)), 2) if values else None


def table_row(fab: dict, law: str, B, mine: list[dict]) -> dict:
    """One fabric's row: its measured DC, node range and outline irregularity, the matched B
    and the model's runs."""
    nodes = _nodes(mine)
    lo, hi = int(float(fab["nodes_min"])), int(float(fab["nodes_max"]))
    measured_irregularity = fab.get("irregularity_mm")
    return {"fabric": fab["fabric"], "law": law, "measured_DC": float(fab["dc_mean"]),
            "measured_DC_std": float(fab["dc_std"]), "measured_nodes_min": lo,
            "measured_nodes_max": hi, "measured_nodes_mode": fab.get("nodes_mode", ""),
            "B_matched": B,
            "model_DC": float(np.mean([float(r["DC_percent"]) for r in mine])) if mine else None,
            "model_nodes": " ".join(map(str, nodes)),
            "within": sum(lo <= n <= hi for n in nodes), "runs": len(nodes),
            "measured_irregularity_mm": float(measured_irregularity) if measured_irregularity else None,
            "model_irregularity_mm": _irregularity_mm(mine)}


def secant_B(points, target: float, slope: float = SLOPE) -> float:
    """Next B towards ``target`` from the runs so far, ``points`` = [(B, DC %), ...]: the secant
    through the last two in log B (its slope kept within [SLOPE/4, 4 SLOPE]), or the first run
    moved along ``slope`` (DC points per unit of ln B)."""
    (B1, d1) = points[-1]
    if len(points) > 1:
        (B0, d0) = points[-2]
        if B0 != B1:
            slope = float(np.clip((d1 - d0) / np.log(B1 / B0), SLOPE / 4, 4 * SLOPE))
    return float(f"{B1 * np.exp((target - d1) / slope):.4g}")


def secant_match(fabrics, case, start: dict, out: Path, workers, overrides, iterations: int,
                 tol: float) -> dict:
    """Per fabric, B whose run (seed 0) reaches the fabric's mean DC within ``tol`` points:
    runs at ``start`` (fabric → B), then secant steps in log B, ``iterations`` sweeps at most
    (``out/secant_<k>/``). Returns fabric → (B, that run's record) of the run nearest the target."""
    points = {f["fabric"]: [] for f in fabrics}
    best, B = {}, {f["fabric"]: float(start.get(f["fabric"], START_B)) for f in fabrics}
    target = {f["fabric"]: float(f["dc_mean"]) for f in fabrics}
    todo = list(B)
    for k in range(iterations):
        if not todo:
            break
        rows = [SweepRow(f"fabric{f}", dict(o.split("=", 1) for o in fabric_keys(B[f]))) for f in todo]
        sweep(case, rows, out / f"secant_{k}", workers, list(overrides))
        recs = {r["name"]: r for r in _finished(out / f"secant_{k}")}
        for f in list(todo):
            rec = recs.get(f"fabric{f}")
            if rec is None:                    # stopped: no step from here
                todo.remove(f)
                continue
            dc = float(rec["DC_percent"])
            points[f].append((B[f], dc))
            if f not in best or abs(dc - target[f]) < abs(float(best[f][1]["DC_percent"]) - target[f]):
                best[f] = (B[f], rec)
            if abs(dc - target[f]) <= tol:
                todo.remove(f)
            else:
                B[f] = secant_B(points[f], target[f])
    return best


def compare_secant(fabrics, case, start: dict, seeds: int, out: Path, workers, overrides=(),
                   iterations: int = 4, tol: float = 1.5) -> list[dict]:
    """As :func:`compare` for the first law, B matched by :func:`secant_match`; the matched
    run is seed 0, seeds 1 … seeds-1 run at the same B (``out/seeds/``)."""
    best = secant_match(fabrics, case, start, out, workers, overrides, iterations, tol)
    rows = [SweepRow(f"fabric{f}_s{seed}", dict(o.split("=", 1) for o in fabric_keys(Bm)
                                                + [f"load.perturbation.seed={seed}"]))
            for f, (Bm, _) in best.items() for seed in range(1, seeds)]
    if rows:
        sweep(case, rows, out / "seeds", workers, list(overrides))
    recs = _finished(out / "seeds") if rows else []
    table = []
    for fab in fabrics:
        B, matched = best.get(fab["fabric"], (None, None))
        mine = ([matched] if matched else []) + _runs_of(recs, fab["fabric"])
        table.append(table_row(fab, "tensor", B, mine))
    return table


def read_start(path) -> dict:
    """fabric → first B from a CSV with columns ``fabric`` and ``B`` (gf·cm²/cm)."""
    with open(path, newline="") as fh:
        return {r["fabric"]: float(r["B"]) for r in csv.DictReader(fh)}


def markdown(table: list[dict]) -> str:
    lines = ["| fabric | measured DC % | measured nodes | law | B matched (gf·cm²/cm) | "
             "model DC % | model nodes | in range | irregularity mm, measured / model |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in table:
        B = "off grid" if r["B_matched"] is None else f"{r['B_matched']:.4g}"
        dc = "–" if r["model_DC"] is None else f"{r['model_DC']:.1f}"
        irregular = " / ".join("–" if r.get(k) is None else f"{r[k]:.1f}"
                               for k in ("measured_irregularity_mm", "model_irregularity_mm"))
        lines.append(f"| {r['fabric']} | {r['measured_DC']:.1f} ± {r['measured_DC_std']:.1f} | "
                     f"{r['measured_nodes_min']}–{r['measured_nodes_max']} | {r['law']} | {B} | "
                     f"{dc} | {r['model_nodes']} | {r['within']} of {r['runs']} | {irregular} |")
    return "\n".join(lines)


def plot(table: list[dict], path: Path) -> None:
    """Node count against DC: the measured ranges as bars, the model's runs as markers."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    seen = set()
    for r in table:
        if r["law"] == table[0]["law"]:
            ax.vlines(r["measured_DC"], r["measured_nodes_min"], r["measured_nodes_max"],
                      color="0.5", lw=6, alpha=0.5,
                      label=None if "m" in seen else "measured range (scans)")
            seen.add("m")
        style = {"tensor": ("o", "C0"), "per_direction": ("x", "C3")}[r["law"]]
        for n in map(int, r["model_nodes"].split()):
            ax.plot(r["model_DC"], n, style[0], color=style[1], ms=6,
                    label=None if r["law"] in seen else f"model, {r['law']} friction")
            seen.add(r["law"])
    ax.set_xlabel("drape coefficient (%)")
    ax.set_ylabel("nodes")
    ax.set_title("Node count at matched DC (30 cm on 18 cm)")
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scans", help="registered scans of real Cusick drapes (.npz)")
    p.add_argument("--out", default="out/matched")
    p.add_argument("--laws", nargs="+", choices=list(LAWS), default=list(LAWS),
                   help="friction laws; the first gets --seeds seeds, the others one")
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--case", default=str(ROOT / "cases" / "cusick_kes.toml"))
    p.add_argument("--match", choices=["grid", "secant"], default="grid",
                   help="grid: interpolate a grid of B (every law); secant: secant steps in log B "
                        "per fabric until its run's DC is within --tol of the scans' (first law)")
    p.add_argument("--start", metavar="CSV", help="secant: first B per fabric (columns fabric, B); "
                   f"default {START_B} for every fabric")
    p.add_argument("--iterations", type=int, default=4, help="secant: sweeps at most")
    p.add_argument("--tol", type=float, default=1.5, help="secant: DC points")
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--fabrics", nargs="+", metavar="N", help="only these fabrics (default: every one)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides",
                   help="override a case key in every run (e.g. load.gravity.ramp_time=0.5)")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fabrics = read_fabrics(args.scans, out)
    if args.fabrics:
        unknown = sorted(set(args.fabrics) - {f["fabric"] for f in fabrics})
        if unknown:
            p.error(f"--fabrics: no scans of fabric {', '.join(unknown)}")
        fabrics = [f for f in fabrics if f["fabric"] in args.fabrics]
    if args.match == "secant":
        start = read_start(args.start) if args.start else {}
        table = compare_secant(fabrics, args.case, start, args.seeds, out, args.workers,
                               args.overrides, args.iterations, args.tol)
        args.laws = args.laws[:1]
    else:
        table = compare(fabrics, args.case, args.laws, args.seeds, out, args.workers, args.overrides)
    with open(out / "matched.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, list(table[0]))
        writer.writeheader()
        writer.writerows(table)
    text = markdown(table)
    (out / "matched.md").write_text(text + "\n")
    plot(table, out / "nodes_at_matched_dc.png")
    print(text)
    for law in args.laws:
        rows = [r for r in table if r["law"] == law]
        print(f"{law}: most frequent model node count within the measured range for "
              f"{sum(_mode_within(r) for r in rows)} of {len(rows)} fabrics")
    return 0


def _mode_within(r) -> bool:
    nodes = list(map(int, r["model_nodes"].split()))
    if not nodes:
        return False
    mode = max(set(nodes), key=lambda n: (nodes.count(n), -n))
    return r["measured_nodes_min"] <= mode <= r["measured_nodes_max"]


if __name__ == "__main__":
    sys.exit(main())
