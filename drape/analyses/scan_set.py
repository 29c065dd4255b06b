"""A set of registered Cusick scans in one file: descriptors per scan and per fabric.

The file is a numpy ``.npz`` with, for each scan, ``KEY/vertices`` (int16; times the scalar
entry ``vertex_unit_m`` gives metres) and ``KEY/faces`` (uint16, 0-based triangles); keys are
``fabricNN_sampleSS_captureC``, ``fabricNN_sampleSS`` or ``fabricNN_sampleSS_obsK`` (one
specimen observed K = 1, 2, ... times in succession while it creeps). The Leeds Cusick drape
dataset comes in this form (D. Gong, N. Mao, H. Wang, "Bayesian Differentiable Physics for
Cloth Digitalization", CVPR 2024); its scans are external data.

Every scan goes through :func:`drape.analyses.scan_measure.measure_surface` (30 cm specimen on
an 18 cm disc, centre from the flat top, the node detection of the simulated drape):
:func:`describe_scans` gives one row per scan, :func:`fabric_tables` the statistics per
fabric (creep series apart), per creep observation and of face down against face up,
:func:`write_tables` writes them as CSV (``scans.csv``, ``fabrics.csv``, ``creep.csv``,
``faces.csv``) and :func:`format_tables` as text.
"""
from __future__ import annotations

import csv
import re
from collections import Counter
from pathlib import Path

import numpy as np

from drape.analyses.outline import N_HARMONICS
from drape.analyses.scan import ScanError
from drape.analyses.scan_measure import DISC_DIAMETER, SPECIMEN_DIAMETER, measure_surface

__all__ = ["SCAN_KEY", "SCAN_COLUMNS", "SUMMARY_COLUMNS", "FACE_COLUMNS", "scan_keys", "describe_scan",
           "describe_scans", "summarise", "group", "face_pairs", "fabric_tables", "write_tables",
           "format_tables", "write_plys"]

#: A scan's key: its fabric, its specimen (sample) and, if any, the series and its number.
SCAN_KEY = re.compile(r"fabric(?P<fabric>\d+)_sample(?P<sample>\d+)"
                      r"(?:_(?P<series>capture|obs)(?P<n>\d+))?$")
#: Columns of ``scans.csv``.
SCAN_COLUMNS = ["key", "fabric", "sample", "series", "number", "dc_percent", "nodes", "depth_mm",
                "irregularity_mm", "centre_x_mm", "centre_y_mm",
                *(f"a{k}_mm" for k in range(N_HARMONICS + 1)), "error", "warning"]
#: Statistics of a group of scans (``fabrics.csv``, ``creep.csv``).
SUMMARY_COLUMNS = ["scans", "dc_mean", "dc_std", "dc_min", "dc_max",
                   "nodes_min", "nodes_max", "nodes_mode", "nodes_mean", "irregularity_mm", "a2_mm"]
#: Columns of ``faces.csv``.
FACE_COLUMNS = ["fabric", "specimens", "dc_up", "dc_down", "down_minus_up", "down_minus_up_std", "repeat"]
#: The tables of :func:`fabric_tables`: file stem, title, leading columns.
_TABLES = (("fabrics", "fabrics (creep series excluded)", ["fabric", *SUMMARY_COLUMNS]),
           ("creep", "creep series", ["fabric", "obs", *SUMMARY_COLUMNS]),
           ("faces", "face down against face up (DC %)", FACE_COLUMNS))


def scan_keys(data) -> list[str]:
    """Keys of the scans in a loaded ``.npz`` file, sorted."""
    return sorted(k[: -len("/vertices")] for k in data.files if k.endswith("/vertices"))


def describe_scan(data, key: str, unit: float) -> dict:
    """One scan's row of ``scans.csv``.

    Parameters
    ----------
    data : numpy.lib.npyio.NpzFile
        The loaded file.
    key : str
        The scan's key.
    unit : float
        Metres per vertex unit (the file's ``vertex_unit_m``).

    Returns
    -------
    dict
        Key, fabric, sample, series and its number, DC %, nodes, mean fold depth, outline
        irregularity (mm), the centre used, the harmonic amplitudes ``a0_mm`` .. and
        ``warning``, what it was measured in spite of (``; ``-separated); or the key's parts
        and ``error``, the reason the scan could not be read as a drape.
    """
    match = SCAN_KEY.match(key)
    row = {"key": key, "fabric": int(match["fabric"]) if match else "",
           "sample": int(match["sample"]) if match else "",
           "series": (match["series"] or "") if match else "",
           "number": int(match["n"]) if match and match["n"] else ""}
    points = data[f"{key}/vertices"].astype(float) * unit
    faces = data[f"{key}/faces"].astype(np.int64)
    try:
        m = measure_surface(points, faces, SPECIMEN_DIAMETER / 2, DISC_DIAMETER / 2, name=key)
    except ScanError as exc:
        return {**row, "error": str(exc), "warning": ""}
    s = m.result.summary()
    row.update(dc_percent=round(s["drape_coefficient_percent"], 3), nodes=s["n_nodes"],
               depth_mm=round(1e3 * s["node_depth_mean_m"], 3),
               irregularity_mm=round(1e3 * s["outline_irregularity_m"], 3),
               centre_x_mm=round(1e3 * m.result.centre[0], 3),
               centre_y_mm=round(1e3 * m.result.centre[1], 3))
    row.update({f"a{k}_mm": round(1e3 * a, 4) for k, a in enumerate(s["outline_harmonics_m"])})
    return {**row, "error": "", "warning": "; ".join(m.warnings)}


def describe_scans(path) -> list[dict]:
    """Every scan of the ``.npz`` file at ``path`` described (:func:`describe_scan`), by key."""
    data = np.load(path)
    unit = float(data["vertex_unit_m"])
    return [describe_scan(data, key, unit) for key in scan_keys(data)]


def summarise(rows) -> dict:
    """DC and node statistics of a group of scan rows (:data:`SUMMARY_COLUMNS`); the most
    frequent node count is the smallest of equally frequent ones."""
    dc = np.array([r["dc_percent"] for r in rows])
    nodes = [r["nodes"] for r in rows]
    counts = Counter(nodes)
    mode = min(n for n, c in counts.items() if c == max(counts.values()))
    return {"scans": len(rows), "dc_mean": round(float(dc.mean()), 2),
            "dc_std": round(float(dc.std(ddof=1)), 2) if len(dc) > 1 else 0.0,
            "dc_min": round(float(dc.min()), 2), "dc_max": round(float(dc.max()), 2),
            "nodes_min": min(nodes), "nodes_max": max(nodes), "nodes_mode": mode,
            "nodes_mean": round(float(np.mean(nodes)), 2),
            "irregularity_mm": round(float(np.mean([r["irregularity_mm"] for r in rows])), 2),
            # the outline's elliptic (two-fold) part: where a fabric's anisotropy shows
            "a2_mm": round(float(np.mean([r.get("a2_mm", np.nan) for r in rows])), 2)}


def group(rows, key) -> list[dict]:
    """Summary rows of ``rows`` grouped by ``key(row)`` (a dict of the group's columns)."""
    groups: dict = {}
    for r in rows:
        groups.setdefault(tuple(key(r).items()), []).append(r)
    return [{**dict(k), **summarise(g)} for k, g in sorted(groups.items())]


def face_pairs(rows) -> list[dict]:
    """Face down against face up, per fabric.

    Over the specimens with all four captures (1–2 one face up, 3–4 the other): mean DC of
    each face, the mean and standard deviation of a specimen's down − up, and the repeat
    scatter of one face's two captures (half their difference, averaged), which that
    difference must exceed to mean anything.

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


def fabric_tables(rows) -> dict[str, list[dict]]:
    """The tables of the scans read (rows without ``error``): ``fabrics`` (per fabric, the
    creep series left out), ``creep`` (per fabric and observation of its creep series) and
    ``faces`` (:func:`face_pairs`)."""
    good = [r for r in rows if not r["error"]]
    return {"fabrics": group([r for r in good if r["series"] != "obs"], lambda r: {"fabric": r["fabric"]}),
            "creep": group([r for r in good if r["series"] == "obs"],
                           lambda r: {"fabric": r["fabric"], "obs": r["number"]}),
            "faces": face_pairs(good)}


def _write_csv(path: Path, rows, columns) -> None:
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)


def write_tables(out, rows, tables) -> None:
    """Write ``scans.csv`` (``rows``) and the :func:`fabric_tables` to the folder ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    _write_csv(out / "scans.csv", rows, SCAN_COLUMNS)
    for name, _, columns in _TABLES:
        _write_csv(out / f"{name}.csv", tables[name], columns)


def format_tables(tables) -> str:
    """The :func:`fabric_tables` as text, each under its title, columns right-aligned."""
    lines = []
    for name, title, columns in _TABLES:
        lines.append(title)
        lines.append("  ".join(f"{c:>10}" for c in columns))
        lines += ["  ".join(f"{r[c]:>10}" for c in columns) for r in tables[name]]
    return "\n".join(lines)


def write_plys(path, folder) -> dict:
    """Every scan of the ``.npz`` file at ``path`` as a PLY surface in metres in ``folder``
    (kept where it exists already), for tools that read scan files.

    Returns
    -------
    dict
        Scan key → PLY path.
    """
    import meshio

    data = np.load(path)
    unit = float(data["vertex_unit_m"])
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    for key in scan_keys(data):
        ply = folder / f"{key}.ply"
        if not ply.exists():
            meshio.write(ply, meshio.Mesh(data[f"{key}/vertices"] * unit,
                                          [("triangle", data[f"{key}/faces"].astype(np.int32))]))
        out[key] = ply
    return out
