"""A scan set split by specimen: each fabric's training and test halves, and the target they are
judged by.

The scans of a registered scan set (:mod:`drape.analyses.scan_set`) are grouped per fabric:
the scans of its odd samples are the training half, those of its even samples the test half
(:func:`split`). Each half holds every capture of its specimens, face up and face down, as a
Cusick test reads a specimen on both faces and takes the mean (BS 5058), or the face-up
captures only. A prediction of the test half meets the target when its mean DC lies within
5 points of the test scans' and its most frequent node count within ±1 of theirs
(:func:`judged`). :func:`scans_alone` judges each fabric's training scans as the prediction of
its test scans: what a model that reproduced its training specimens exactly would score.
"""
from __future__ import annotations

import csv
from collections import defaultdict
from pathlib import Path

import numpy as np

from drape.analyses.scan_set import SCAN_KEY, write_plys
from drape.identification.target import scan_drapes

__all__ = ["FACES", "split", "measure", "judged", "scans_alone", "judge_scans_alone",
           "scans_alone_markdown", "face_dcs", "creep_lines"]

#: The captures each half may hold: ``both`` faces, or face ``up`` only.
FACES = ("both", "up")


def split(scans: dict, faces: str = "both") -> dict:
    """Per fabric: training (odd samples), test (even samples), face down, creep series.

    Parameters
    ----------
    scans : dict
        Scan key (:data:`drape.analyses.scan_set.SCAN_KEY`) → scan; keys of another form are
        left out.
    faces : {"both", "up"}
        ``"both"``: every capture of a specimen, face up and face down, goes to its half;
        ``"up"``: the face-up captures (1–2, or the single capture) only.

    Returns
    -------
    dict
        Fabric number → ``{"train": [...], "test": [...], "down": [...], "creep": [...]}``, by
        fabric number: the scans of each half, the face-down captures (captures 3–4, listed
        either way) and the creep series as (sample, observation, scan).

    Examples
    --------
    >>> scans = {"fabric04_sample01_capture1": "up", "fabric04_sample01_capture3": "down",
    ...          "fabric04_sample02": "test", "fabric04_sample01_obs2": "creep"}
    >>> halves = split(scans)[4]
    >>> halves["train"], halves["test"], halves["down"], halves["creep"]
    (['up', 'down'], ['test'], ['down'], [(1, 2, 'creep')])
    >>> split(scans, "up")[4]["train"]
    ['up']
    """
    if faces not in FACES:
        raise ValueError(f"faces must be 'both' or 'up', not {faces!r}")
    fabrics = defaultdict(lambda: {"train": [], "test": [], "down": [], "creep": []})
    for key, path in sorted(scans.items()):
        m = SCAN_KEY.match(key)
        if not m:
            continue
        f = fabrics[int(m["fabric"])]
        if m["series"] == "obs":
            f["creep"].append((int(m["sample"]), int(m["n"]), path))
            continue
        half = "train" if int(m["sample"]) % 2 else "test"
        if m["series"] == "capture" and int(m["n"]) > 2:
            f["down"].append(path)
            if faces == "up":
                continue
        f[half].append(path)
    return dict(sorted(fabrics.items()))


def measure(paths):
    """The scans' drapes (:func:`drape.identification.target.scan_drapes`)."""
    return scan_drapes(paths)[0]


def judged(predicted, test) -> dict:
    """The target on a fabric's test specimens.

    Parameters
    ----------
    predicted, test : drape.identification.target.Drapes
        The predicted drapes and the test scans'.

    Returns
    -------
    dict
        ``dDC`` (predicted mean DC less the test scans'), ``DC_within_5`` (within 5 points)
        and ``mode_within_1`` (most frequent node counts within ±1).
    """
    dDC = float(predicted.dc.mean() - test.dc.mean())
    return {"dDC": round(dDC, 2), "DC_within_5": abs(dDC) <= 5.0,
            "mode_within_1": abs(predicted.nodes_mode() - test.nodes_mode()) <= 1}


def scans_alone(fabrics: dict) -> list[dict]:
    """Each fabric's training specimens as their own prediction of its test specimens (their
    mean DC, their most frequent node count), judged by the same target as an identified model;
    fabrics without both halves are left out. Where the two halves differ by more than the
    target, a model that reproduces its training specimens exactly misses it."""
    rows = []
    for number, parts in fabrics.items():
        if not (parts["train"] and parts["test"]):
            continue
        train, test = measure(parts["train"]), measure(parts["test"])
        rows.append({"fabric": number, "train_DC": round(float(train.dc.mean()), 2),
                     "test_DC": round(float(test.dc.mean()), 2),
                     "train_nodes": " ".join(map(str, train.nodes)), "train_mode": train.nodes_mode(),
                     "test_nodes": " ".join(map(str, test.nodes)), "test_mode": test.nodes_mode(),
                     **judged(train, test)})
    return rows


def judge_scans_alone(scans, out, faces: str = "both", numbers=None) -> list[dict]:
    """:func:`scans_alone` of a scan set, written to ``out/scans_alone.csv``.

    Parameters
    ----------
    scans : path
        The registered scan set (``.npz``); its scans are written as PLY to ``out/scans``.
    out : path
        Output folder.
    faces : {"both", "up"}
        The captures of each half (:func:`split`).
    numbers : list of int, optional
        Only these fabrics, in this order (default: every one, by number).
    """
    out = Path(out)
    fabrics = split(write_plys(scans, out / "scans"), faces)
    if numbers:
        fabrics = {k: fabrics[k] for k in numbers if k in fabrics}
    rows = scans_alone(fabrics)
    with open(out / "scans_alone.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, list(rows[0]) if rows else ["fabric"])
        writer.writeheader()
        writer.writerows(rows)
    return rows


def scans_alone_markdown(rows: list[dict]) -> str:
    """The :func:`scans_alone` rows as a markdown table and how many meet the target."""
    lines = ["| fabric | train DC % | test DC % | ΔDC | train nodes (mode) | test nodes (mode) | within 5 / ±1 |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        ok = f"{'✓' if r['DC_within_5'] else '✗'} / {'✓' if r['mode_within_1'] else '✗'}"
        lines.append(f"| {r['fabric']} | {r['train_DC']} | {r['test_DC']} | {r['dDC']:+.2f} | "
                     f"{r['train_nodes']} ({r['train_mode']}) | {r['test_nodes']} ({r['test_mode']}) | {ok} |")
    both = sum(r["DC_within_5"] and r["mode_within_1"] for r in rows)
    lines.append(f"both within target: {both} of {len(rows)}")
    return "\n".join(lines)


def face_dcs(parts: dict, train, test) -> tuple[float, float]:
    """Mean DC of a fabric's face-up and of its face-down captures, each scan measured once.

    Parameters
    ----------
    parts : dict
        The fabric's :func:`split`.
    train, test : drape.identification.target.Drapes
        The drapes of its halves, in the order of ``parts``; face-down captures in neither half
        (``faces="up"``) are measured here.
    """
    dc = dict(zip(parts["train"] + parts["test"], np.concatenate([train.dc, test.dc])))
    missing = [q for q in parts["down"] if q not in dc]
    dc.update(zip(missing, measure(missing).dc) if missing else ())
    up = [v for q, v in dc.items() if q not in parts["down"]]
    return round(float(np.mean(up)), 2), round(float(np.mean([dc[q] for q in parts["down"]])), 2)


def creep_lines(fabrics: dict) -> list[str]:
    """The creep series of the scans: one markdown line per fabric and observation, its DC
    (mean ± standard deviation) and node counts."""
    lines = []
    for number, parts in fabrics.items():
        by_obs = defaultdict(list)
        for _, n, path in parts["creep"]:
            by_obs[n].append(path)
        for n in sorted(by_obs):
            d = measure(by_obs[n])
            lines.append(f"| {number} | {n} | {d.dc.mean():.1f} ± {d.dc_std():.1f} | "
                         f"{' '.join(map(str, d.nodes))} |")
    return lines
