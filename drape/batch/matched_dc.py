"""Node count at matched drape coefficient: a fabric's B matched to its DC, the nodes compared.

A drape at rest depends on the fabric's weight only through B/W and 2HB/W, so a scanned fabric
of unknown KES values can be matched by its bending length alone. For each fabric of a scan set
(its mean DC and range of node counts over its specimens and captures, ``fabrics.csv`` of
:mod:`drape.analyses.scan_set`, read by :func:`read_fabrics`):

1. a KES-only Cusick case (warp = weft, 2HB/B = 0.5 cm⁻¹, W = 15 mg/cm²: :func:`fabric_keys`)
   runs over a grid of B for each friction law, and log B is interpolated against DC to the B
   at which the model's DC is the fabric's (:func:`compare`); or, per fabric, secant steps in
   log B from a first B until its run's DC is within a tolerance of the fabric's
   (:func:`compare_secant`, for a case whose DC is not monotonic enough in B to interpolate
   across fabrics);
2. the model runs at that B under several perturbation seeds, and its node counts are compared
   with the fabric's measured range (:func:`table_row`, :func:`markdown`, :func:`nodes_figure`).

Every set of runs is a :func:`drape.batch.sweep.run_sweep` into a folder of its own, continued
where it exists already.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from drape.analyses.outline import outline_irregularity
from drape.analyses.scan_set import describe_scans, fabric_tables, write_tables
from drape.batch.rows import SweepRow, read_results
from drape.batch.sweep import run_sweep

__all__ = ["LAWS", "GRIDS", "START_B", "SLOPE", "fabric_keys", "sweep_row", "read_fabrics",
           "select_fabrics", "read_start", "sweep", "finished_runs", "node_counts", "dc_curve",
           "matched_B", "compare", "secant_B", "secant_match", "compare_secant", "table_row",
           "mode_within", "markdown", "nodes_figure", "write_rows", "write_table"]

#: Friction law → its case overrides.
LAWS = {"tensor": [], "per_direction": ["model.bending_friction=per_direction"]}
#: Friction law → the grid of B (gf·cm²/cm) its DC curve is run on.
GRIDS = {"tensor": [0.005 * 2 ** (k / 2) for k in range(13)],            # 0.005 … 0.32
         "per_direction": [0.005 * 2 ** k for k in range(8)]}             # 0.005 … 0.64
GOOD = ("settled", "completed")
#: Secant matching: the first B without a start table, and the first step's DC points per
#: unit of ln B (about 20 between DC 20 and 75 %).
START_B = 0.05
SLOPE = 20.0


def fabric_keys(B: float, hb_ratio: float = 0.5, weight: float = 15.0, anisotropy: float = 1.0) -> list[str]:
    """``--set`` items of a fabric, in KES units: warp and weft of geometric mean ``B`` and
    ratio ``anisotropy`` = B_warp/B_weft, each with 2HB = ``hb_ratio`` B.

    >>> fabric_keys(0.1)   # doctest: +NORMALIZE_WHITESPACE
    ['material.kes.B_warp=0.1', 'material.kes.B_weft=0.1', 'material.kes.HB2_warp=0.05',
     'material.kes.HB2_weft=0.05', 'material.kes.weight=15']
    >>> fabric_keys(0.1, anisotropy=4)   # doctest: +NORMALIZE_WHITESPACE
    ['material.kes.B_warp=0.2', 'material.kes.B_weft=0.05', 'material.kes.HB2_warp=0.1',
     'material.kes.HB2_weft=0.025', 'material.kes.weight=15']
    """
    warp, weft = B * anisotropy ** 0.5, B / anisotropy ** 0.5
    return [f"material.kes.B_warp={warp:g}", f"material.kes.B_weft={weft:g}",
            f"material.kes.HB2_warp={hb_ratio * warp:g}", f"material.kes.HB2_weft={hb_ratio * weft:g}",
            f"material.kes.weight={weight:g}"]


def sweep_row(name: str, items) -> SweepRow:
    """A run table's row ``name`` of ``KEY=VALUE`` items (:func:`fabric_keys`)."""
    return SweepRow(name, dict(o.split("=", 1) for o in items))


def read_fabrics(scans, out) -> list[dict]:
    """Per-fabric measured DC and node counts of the scan set ``scans`` (``.npz``), as text.

    The scans are described once, into ``out/scans`` (:mod:`drape.analyses.scan_set`), and its
    ``fabrics.csv`` is read back (columns ``fabric``, ``dc_mean``, ``dc_std``, ``nodes_min``,
    ``nodes_max``, ...).
    """
    folder = Path(out) / "scans"
    if not (folder / "fabrics.csv").exists():
        rows = describe_scans(scans)
        write_tables(folder, rows, fabric_tables(rows))
    with open(folder / "fabrics.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def select_fabrics(scans, out, wanted=None) -> list[dict]:
    """:func:`read_fabrics` into ``out`` (made if missing), only the fabrics named in
    ``wanted`` (every one when it is empty or None).

    Raises
    ------
    ValueError
        When ``wanted`` names a fabric without scans.
    """
    Path(out).mkdir(parents=True, exist_ok=True)
    fabrics = read_fabrics(scans, out)
    if not wanted:
        return fabrics
    unknown = sorted(set(wanted) - {f["fabric"] for f in fabrics})
    if unknown:
        raise ValueError(f"--fabrics: no scans of fabric {', '.join(unknown)}")
    return [f for f in fabrics if f["fabric"] in wanted]


def read_start(path) -> dict:
    """Fabric → first B from a CSV with columns ``fabric`` and ``B`` (gf·cm²/cm)."""
    with open(path, newline="") as fh:
        return {r["fabric"]: float(r["B"]) for r in csv.DictReader(fh)}


def sweep(case, rows, out: Path, workers, overrides) -> None:
    """Run ``rows`` into ``out`` (``overrides`` in every run), continuing a sweep already there."""
    run_sweep(case, rows, out, overrides=overrides, workers=workers,
              resume=(out / "results.csv").exists(), quiet=False)


def finished_runs(folder: Path):
    """The finished runs of the sweep in ``folder``, their ``run_dir`` made absolute."""
    records = read_results(folder / "results.csv")
    return [{**r, "run_dir": str(folder / r["run_dir"]) if r.get("run_dir") else ""}
            for r in records if r.get("status") in GOOD and r.get("DC_percent")]


def dc_curve(case, law: str, out: Path, workers, overrides) -> tuple[np.ndarray, np.ndarray]:
    """(B, DC %) of the law's grid (seed 0), sorted by B; the runs go to ``out``."""
    rows = [sweep_row(f"B{B:.5g}", fabric_keys(B) + LAWS[law]) for B in GRIDS[law]]
    sweep(case, rows, out, workers, overrides)
    recs = finished_runs(out)
    B = np.array([float(r["material.kes.B_warp"]) for r in recs])
    dc = np.array([float(r["DC_percent"]) for r in recs])
    order = np.argsort(B)
    return B[order], dc[order]


def matched_B(B, dc, target: float) -> float | None:
    """B at which a grid's DC reaches ``target``.

    Linear in log B between the two grid points around it, on the grid's running maximum (DC
    grows with B); None off the grid.

    >>> round(matched_B([0.01, 0.1], [20.0, 40.0], 30.0), 5)
    0.03162
    """
    B, dc = np.asarray(B, dtype=float), np.asarray(dc, dtype=float)
    mono = np.maximum.accumulate(dc)
    if not (mono[0] <= target <= mono[-1]):
        return None
    logB = np.log(B)
    i = int(np.searchsorted(mono, target))
    i = min(max(i, 1), len(B) - 1)
    lo, hi = mono[i - 1], mono[i]
    s = 0.0 if hi == lo else (target - lo) / (hi - lo)
    return float(np.exp(logB[i - 1] + s * (logB[i] - logB[i - 1])))


def _runs_of(recs, fabric) -> list[dict]:
    """The records of ``fabric``'s seeds (rows named ``fabric<id>_s<seed>``)."""
    return [r for r in recs if r["name"].rsplit("_s", 1)[0] == f"fabric{fabric}"]


def compare(fabrics, case, laws, seeds: int, out: Path, workers, overrides=()) -> list[dict]:
    """B matched on each law's grid, then the model's runs at it: one :func:`table_row` per
    (fabric, law). The first law runs ``seeds`` seeds, the others one; the grids go to
    ``out/grid_<law>``, the matched runs to ``out/matched_<law>``."""
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
                rows.append(sweep_row(f"fabric{fab['fabric']}_s{seed}", keys + [f"load.perturbation.seed={seed}"]))
        sweep(case, rows, out / f"matched_{law}", workers, list(overrides))
        recs = finished_runs(out / f"matched_{law}")
        table += [table_row(fab, law, target[fab["fabric"]], _runs_of(recs, fab["fabric"]))
                  for fab in fabrics]
    return table


def secant_B(points, target: float, slope: float = SLOPE) -> float:
    """Next B towards ``target`` from the runs so far.

    Parameters
    ----------
    points : list of (float, float)
        (B, DC %) of the runs so far, in order.
    target : float
        The DC % to reach.
    slope : float
        DC points per unit of ln B of the step from a single run.

    Returns
    -------
    float
        B (4 significant digits) along the secant through the last two runs in log B, its
        slope kept within [SLOPE/4, 4 SLOPE], or the single run moved along ``slope``.

    >>> secant_B([(0.05, 40.0)], 60.0)
    0.1359
    """
    (B1, d1) = points[-1]
    if len(points) > 1:
        (B0, d0) = points[-2]
        if B0 != B1:
            slope = float(np.clip((d1 - d0) / np.log(B1 / B0), SLOPE / 4, 4 * SLOPE))
    return float(f"{B1 * np.exp((target - d1) / slope):.4g}")


def secant_match(fabrics, case, start: dict, out: Path, workers, overrides, iterations: int,
                 tol: float) -> dict:
    """Per fabric, the B whose run (seed 0) reaches the fabric's mean DC within ``tol`` points.

    Runs at ``start`` (fabric → B; :data:`START_B` for a fabric it lacks), then secant steps in
    log B (:func:`secant_B`), ``iterations`` sweeps at most (``out/secant_<k>/``); a fabric whose
    run stops takes no further step.

    Returns
    -------
    dict
        Fabric → (B, that run's record) of its run nearest the target (no entry for a fabric
        none of whose runs finished).
    """
    points = {f["fabric"]: [] for f in fabrics}
    best, B = {}, {f["fabric"]: float(start.get(f["fabric"], START_B)) for f in fabrics}
    target = {f["fabric"]: float(f["dc_mean"]) for f in fabrics}
    todo = list(B)
    for k in range(iterations):
        if not todo:
            break
        sweep(case, [sweep_row(f"fabric{f}", fabric_keys(B[f])) for f in todo], out / f"secant_{k}",
              workers, list(overrides))
        recs = {r["name"]: r for r in finished_runs(out / f"secant_{k}")}
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
    """As :func:`compare` for the tensor law, B matched by :func:`secant_match`; the matched
    run is seed 0, seeds 1 … seeds-1 run at the same B (``out/seeds/``)."""
    best = secant_match(fabrics, case, start, out, workers, overrides, iterations, tol)
    rows = [sweep_row(f"fabric{f}_s{seed}", fabric_keys(Bm) + [f"load.perturbation.seed={seed}"])
            for f, (Bm, _) in best.items() for seed in range(1, seeds)]
    if rows:
        sweep(case, rows, out / "seeds", workers, list(overrides))
    recs = finished_runs(out / "seeds") if rows else []
    table = []
    for fab in fabrics:
        B, matched = best.get(fab["fabric"], (None, None))
        mine = ([matched] if matched else []) + _runs_of(recs, fab["fabric"])
        table.append(table_row(fab, "tensor", B, mine))
    return table


def _irregularity_mm(recs) -> float | None:
    """Mean outline irregularity (mm) of the runs, from their summary.json (None if absent)."""
    values = []
    for r in recs:
        path = Path(r.get("run_dir") or "") / "summary.json"
        if r.get("run_dir") and path.exists():
            a = json.loads(path.read_text())["analysis"]
            values.append(outline_irregularity(a["outline_harmonics_m"], a["n_nodes"]))
    return round(1e3 * float(np.mean(values)), 2) if values else None


def node_counts(records) -> list[int]:
    """The node counts of the sweep records that have one, in increasing order."""
    return sorted(int(float(r["nodes"])) for r in records if r.get("nodes"))


def table_row(fab: dict, law: str, B, mine: list[dict]) -> dict:
    """One fabric's row of the comparison.

    Parameters
    ----------
    fab : dict
        The fabric's row of ``fabrics.csv`` (:func:`read_fabrics`).
    law : str
        The friction law.
    B : float or None
        The matched B (gf·cm²/cm), None where none was found.
    mine : list of dict
        The sweep records of the model's runs at B.

    Returns
    -------
    dict
        Its measured DC, node range and outline irregularity, the matched B, the model's mean
        DC, node counts, how many of them lie in the measured range, and its irregularity.
    """
    nodes = node_counts(mine)
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


def mode_within(row: dict) -> bool:
    """Whether the model's most frequent node count (the smallest of equally frequent ones)
    lies in the row's measured range; False without runs."""
    nodes = list(map(int, row["model_nodes"].split()))
    if not nodes:
        return False
    mode = max(set(nodes), key=lambda n: (nodes.count(n), -n))
    return row["measured_nodes_min"] <= mode <= row["measured_nodes_max"]


def markdown(table: list[dict]) -> str:
    """The comparison as a markdown table, one line per row."""
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


def nodes_figure(table: list[dict]):
    """Node count against DC: the measured ranges as bars (those of the first law's rows), the
    model's runs as markers per law. Rows need ``law``, ``measured_DC``, ``measured_nodes_min``,
    ``measured_nodes_max``, ``model_DC`` and ``model_nodes``.

    Returns a matplotlib ``Figure`` (not attached to pyplot).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 4.5))
    ax = fig.add_subplot()
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
    return fig


def write_rows(table: list[dict], text: str, out, stem: str) -> None:
    """Write a study's rows as ``<stem>.csv`` and its markdown ``text`` as ``<stem>.md`` in
    ``out``."""
    out = Path(out)
    with open(out / f"{stem}.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, list(table[0]))
        writer.writeheader()
        writer.writerows(table)
    (out / f"{stem}.md").write_text(text + "\n")


def write_table(table: list[dict], out) -> str:
    """Write ``matched.csv``, ``matched.md`` and ``nodes_at_matched_dc.png`` to ``out``; return
    the markdown."""
    text = markdown(table)
    write_rows(table, text, out, "matched")
    nodes_figure(table).savefig(Path(out) / "nodes_at_matched_dc.png", dpi=120)
    return text
