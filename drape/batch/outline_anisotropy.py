"""A fabric's anisotropy read from its drapes' outlines, and its node count at matched DC with it.

A sheet stiffer one way than the other hangs farther out along its stiff direction: its outline
gains an elliptic, two-fold part, the amplitude ``a2`` of its second harmonic. An isotropic
model specimen has an ``a2`` too, from its varying rigidity and its folds' irregularity, so a
fabric's scans say nothing of its anisotropy until their ``a2`` exceeds the isotropic model's at
the fabric's matched B. For each fabric of a scan set (``fabrics.csv`` of
:mod:`drape.analyses.scan_set`, with its mean ``a2_mm``) and its matched B:

1. the model runs isotropic at B under ``seeds`` seeds (``out/isotropic``);
2. a fabric whose scans' mean ``a2`` exceeds those runs' is run at each B_warp/B_weft of
   ``ratios`` with the same geometric mean B (``out/ratios``), and its ratio is read off the
   model's ``a2`` against ln(ratio) (:func:`ratio_from_a2`); the others keep ratio 1;
3. a ratio read between the runs' ratios runs at itself (``out/read``), and the fabric's node
   counts at its ratio are compared with its measured range (:func:`study`).

The orientation of warp and weft in the scans is not known, so only the amplitude is read.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from drape.batch.ensemble import seed_rows
from drape.batch.matched_dc import fabric_keys, finished_runs, node_counts, sweep, sweep_row, table_row

__all__ = ["RATIOS", "read_matched", "run_a2_mm", "ratio_from_a2", "study", "markdown"]

#: B_warp/B_weft the model runs at for a fabric whose outline is more elliptic than its
#: isotropic runs': wovens' KES B differ between warp and weft by up to about 4 (Kawabata 1980).
RATIOS = (2.0, 4.0)


def read_matched(path) -> dict[str, float]:
    """Fabric → matched B (gf·cm²/cm) from a CSV with columns ``fabric`` and ``B_matched`` (the
    ``matched.csv`` of ``benchmarks/nodes_at_matched_dc.py``) or ``B``; rows without a B are
    left out."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    column = "B_matched" if rows and "B_matched" in rows[0] else "B"
    return {r["fabric"]: float(r[column]) for r in rows if r.get(column)}


def run_a2_mm(record: dict) -> float | None:
    """The ``a2`` (mm) of a finished run's outline, from its ``summary.json`` (None if absent)."""
    path = Path(record.get("run_dir") or "") / "summary.json"
    if not record.get("run_dir") or not path.exists():
        return None
    return 1e3 * float(json.loads(path.read_text())["analysis"]["outline_harmonics_m"][2])


def ratio_from_a2(a2: float, ratios, model_a2) -> tuple[float, str]:
    """B_warp/B_weft at which the model's mean ``a2`` is ``a2``, and how it was read.

    ``ratios`` starts at 1 (isotropic) and grows; ``model_a2`` are the model's mean ``a2`` at
    them. Linear in ln(ratio) on the running maximum of ``model_a2``: at or below the isotropic
    runs' ``a2`` the ratio is 1 (``"isotropic"``: the outline shows no anisotropy), beyond the
    largest ratio's it is that ratio (``"at least"``), else ``"read"``. A ratio whose ``a2`` is
    NaN (none of its runs finished) is passed over; without the isotropic runs' ``a2`` nothing
    is read: NaN, ``"no runs"``.

    >>> ratio_from_a2(2.0, [1, 2, 4], [3.0, 5.0, 9.0])
    (1.0, 'isotropic')
    >>> r, how = ratio_from_a2(7.0, [1, 2, 4], [3.0, 5.0, 9.0]); round(r, 6), how
    (2.828427, 'read')
    >>> ratio_from_a2(12.0, [1, 2, 4], [3.0, 5.0, 9.0])
    (4.0, 'at least')
    >>> ratio_from_a2(7.0, [1], [float("nan")])
    (nan, 'no runs')
    """
    a2_model = np.asarray(model_a2, dtype=float)
    if not np.isfinite(a2_model[0]):
        return float("nan"), "no runs"
    known = np.isfinite(a2_model)   # a ratio none of whose runs finished is passed over
    r = np.asarray(ratios, dtype=float)[known]
    mono = np.maximum.accumulate(a2_model[known])
    if a2 <= mono[0]:
        return 1.0, "isotropic"
    if a2 >= mono[-1]:
        return float(r[-1]), "at least"
    return float(np.exp(np.interp(a2, mono, np.log(r)))), "read"


def _name(fabric) -> str:
    return f"fabric{int(fabric):02d}"


def _by_row(folder: Path) -> dict[str, list[dict]]:
    """The finished runs of a seeded sweep, by row (``<row>.s<seed>``)."""
    runs: dict[str, list[dict]] = {}
    for rec in finished_runs(folder):
        runs.setdefault(rec["name"].rsplit(".s", 1)[0], []).append(rec)
    return runs


def _mean_a2(records) -> float:
    values = [a for a in map(run_a2_mm, records) if a is not None]
    return float(np.mean(values)) if values else float("nan")


def _run(case, rows, seeds: int, folder: Path, workers, overrides) -> dict[str, list[dict]]:
    if rows:
        sweep(case, seed_rows(rows, seeds), folder, workers, list(overrides))
    return _by_row(folder) if (folder / "results.csv").exists() else {}


def study(fabrics, matched: dict, case, seeds: int, out, workers=None, overrides=(),
          ratios=RATIOS) -> list[dict]:
    """Each fabric's ratio read from its outline and its runs at it (steps 1–3 above).

    Parameters
    ----------
    fabrics : list of dict
        Rows of ``fabrics.csv`` (``fabric``, ``dc_mean``, ``nodes_min``, ``nodes_max``,
        ``a2_mm``, ...); fabrics without a matched B are left out.
    matched : dict
        Fabric → matched B (gf·cm²/cm), :func:`read_matched`.
    case : str or Path
        The KES-only Cusick case the fabrics are run on.
    seeds : int
        Perturbation seeds per fabric and ratio.
    out : Path
        Folder of the three sweeps.

    Returns
    -------
    list of dict
        :func:`drape.batch.matched_dc.table_row` at the fabric's ratio, with ``anisotropy``,
        ``reading``, ``measured_a2_mm``, ``model_a2_mm`` (the model's at each ratio run),
        ``a2_at_ratio_mm`` (its runs' at the fabric's ratio: a check of the reading where they
        ran at the ratio read) and ``isotropic_nodes`` (the node counts at warp = weft).
    """
    out = Path(out)
    fabrics = [f for f in fabrics if f["fabric"] in matched]
    B = {f["fabric"]: matched[f["fabric"]] for f in fabrics}
    iso = _run(case, [sweep_row(_name(f), fabric_keys(b)) for f, b in B.items()], seeds,
               out / "isotropic", workers, overrides)
    # a fabric without a finished isotropic run compares False with its NaN and is not calibrated
    elliptic = {f["fabric"] for f in fabrics if float(f["a2_mm"]) > _mean_a2(iso.get(_name(f["fabric"]), []))}
    calibration = _run(case, [sweep_row(f"{_name(f)}_r{r:g}", fabric_keys(B[f], anisotropy=r))
                              for f in B if f in elliptic for r in ratios], seeds, out / "ratios", workers,
                       overrides)
    read = {}
    for f in fabrics:
        name = _name(f["fabric"])
        curve = [_mean_a2(iso.get(name, []))]
        if f["fabric"] in elliptic:
            curve += [_mean_a2(calibration.get(f"{name}_r{r:g}", [])) for r in ratios]
        read[f["fabric"]] = (*ratio_from_a2(float(f["a2_mm"]), [1.0, *ratios][:len(curve)], curve), curve)
    between = [sweep_row(_name(f), fabric_keys(B[f], anisotropy=r)) for f, (r, how, _) in read.items()
               if how == "read" and not any(np.isclose(r, x) for x in ratios)]
    at_read = _run(case, between, seeds, out / "read", workers, overrides)
    table = []
    for fab in fabrics:
        r, how, curve = read[fab["fabric"]]
        name = _name(fab["fabric"])
        if how in ("isotropic", "no runs"):
            runs = iso.get(name, [])
        else:
            runs = at_read.get(name) or calibration.get(f"{name}_r{min(ratios, key=lambda x: abs(x - r)):g}", [])
        table.append({**table_row(fab, "tensor", B[fab["fabric"]], runs), "anisotropy": r, "reading": how,
                      "measured_a2_mm": float(fab["a2_mm"]), "model_a2_mm": " ".join(f"{a:.1f}" for a in curve),
                      "a2_at_ratio_mm": _mean_a2(runs),
                      "isotropic_nodes": " ".join(map(str, node_counts(iso.get(name, []))))})
    return table


def markdown(table: list[dict], ratios=RATIOS) -> str:
    """The study as a markdown table, one line per fabric."""
    head = " / ".join(f"{r:g}" for r in (1.0, *ratios))
    lines = [f"| fabric | measured DC % | nodes measured | a2 mm, scans | a2 mm, model at {head} | "
             "B_warp/B_weft | model DC % | model nodes | in range | a2 mm at the ratio | nodes, warp = weft |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in table:
        dc = "–" if r["model_DC"] is None else f"{r['model_DC']:.1f}"
        ratio = {"isotropic": "1 (no sign)", "at least": f"≥ {r['anisotropy']:g}", "no runs": "–"}.get(
            r["reading"], f"{r['anisotropy']:.2f}")
        lines.append(f"| {r['fabric']} | {r['measured_DC']:.1f} ± {r['measured_DC_std']:.1f} | "
                     f"{r['measured_nodes_min']}–{r['measured_nodes_max']} | {r['measured_a2_mm']:.1f} | "
                     f"{r['model_a2_mm']} | {ratio} | {dc} | {r['model_nodes']} | {r['within']} of {r['runs']} | "
                     f"{r['a2_at_ratio_mm']:.1f} | {r['isotropic_nodes']} |")
    return "\n".join(lines)
