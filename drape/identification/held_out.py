"""``drape identify`` checked on real fabrics: identified from some specimens, predicting the others.

For each fabric of a registered scan set (:mod:`drape.analyses.scan_set`), the bending length
and 2HB/B are identified from its training scans (:func:`drape.identification.specimen_split.split`)
on a KES-only Cusick case, as ``drape identify`` does (:func:`drape.identification.identify.identify`);
the identified point's simulated drapes then predict its test scans, judged by the target (mean
DC within 5 points, most frequent node count within ±1:
:func:`drape.identification.specimen_split.judged`), beside the measured spread between those
specimens (:func:`identify_fabric`). All fabrics share one
growing library of forward runs, or each gets one of its own without its own runs
(:func:`without_own`): each fabric is then identified as a lab would identify a new fabric after
the others. :func:`identify_fabrics` runs them all into a folder, one row of ``fabrics.csv`` per
fabric as soon as it is done, and :func:`markdown` and :func:`nodes_figure` give the table and
the node count against DC.
"""
from __future__ import annotations

import csv
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drape.analyses.scan_set import write_plys
from drape.batch.matched_dc import nodes_figure as matched_nodes_figure
from drape.identification.identify import DEFINITION, identify
from drape.identification.objective import misfit
from drape.identification.parameters import DEFAULT_FREE, parse_box
from drape.identification.search import CONVERGED_WITHIN, OutOfReach
from drape.identification.specimen_split import creep_lines, face_dcs, judged, measure, split
from drape.identification.store import append_evaluation, read_evaluations
from drape.identification.surrogate import design

__all__ = ["COLUMNS", "Budget", "without_own", "identify_fabric", "identify_fabrics", "markdown",
           "nodes_figure"]

#: Columns of ``fabrics.csv``.
COLUMNS = ["fabric", "train", "test", "status", "bending_length_cm", "interval_c",
           "hysteresis_per_cm", "interval_h", "train_DC", "test_DC", "test_DC_sd", "model_DC",
           "dDC", "test_nodes", "test_mode", "model_nodes", "model_mode", "DC_within_5",
           "mode_within_1", "J_train", "J_test", "spectrum_test", "matched", "face_up_DC",
           "face_down_DC", "wall_s"]


@dataclass(frozen=True)
class Budget:
    """What each fabric's ``drape identify`` is given.

    Attributes
    ----------
    case : str
        The KES-only Cusick base case.
    seeds : int
        Perturbation seeds per point.
    evaluations : int
        Points per fabric once the library has some.
    first_evaluations : int
        Points of a fabric that starts an empty library.
    converged_within : float or None
        The search's convergence stop (None: the search's default; 0: spend every evaluation).
    workers : int or None
        Dask workers (None: one per core).
    overrides : tuple of str
        ``--set`` items of every forward run.
    """

    case: str
    seeds: int = 2
    evaluations: int = 6
    first_evaluations: int = 12
    converged_within: float | None = None
    workers: int | None = None
    overrides: tuple = ()


def without_own(source, library, folder: str) -> int:
    """Write to ``library`` the evaluations of the library ``source`` that no run of ``folder``
    (a fabric's folder, ``fabricNN``) made, and those at the initial design's points whoever
    made them; return how many.

    The initial design (the box's corners and Latin-hypercube points of a fixed seed,
    :func:`drape.identification.surrogate.design`) is the same for every fabric and does not
    depend on its scans: a library that the other fabrics made holds it whichever fabric ran it
    first.
    """
    initial = design(parse_box([], list(DEFAULT_FREE)), 2 * len(DEFAULT_FREE))

    def at_design(e) -> bool:
        return any(all(k in e.point and np.isclose(e.point[k], q[k], rtol=1e-5, atol=0) for k in q)
                   for q in initial)

    kept = [e for e in read_evaluations(source)
            if at_design(e)
            or not any(Path(r.get("run_dir") or "").parts[-4:-3] == (folder,) for r in e.runs)]
    Path(library).mkdir(parents=True, exist_ok=True)
    for e in kept:
        append_evaluation(library, e)
    return len(kept)


def _definition(parts: dict, folder: Path, budget: Budget, first: bool, library: Path) -> dict:
    """What the fabric's identification is: its training scans on the budget's base case, the
    default free parameters and box, without the bundled forward runs. A fabric begun before
    keeps its definition (its budget among it); only the convergence stop is the budget's."""
    within = CONVERGED_WITHIN if budget.converged_within is None else budget.converged_within
    stored = folder / DEFINITION
    if stored.exists():
        return {**json.loads(stored.read_text()), "converged_within": within}
    box = parse_box([], list(DEFAULT_FREE))
    return {"scans": [str(Path(s).resolve()) for s in parts["train"]],
            "base": str(Path(budget.case).resolve()), "set": list(budget.overrides),
            "free": list(DEFAULT_FREE), "box": {k: list(v) for k, v in box.items()},
            "seeds": budget.seeds, "evaluations": budget.first_evaluations if first else budget.evaluations,
            "converged_within": within, "design": None, "weight": None,
            "library": str(Path(library).resolve()), "bundled_library": False}


def _identified(folder: Path, test) -> dict:
    """The identified point of ``folder``, its intervals, and its drapes judged on ``test``."""
    result = json.loads((folder / "identified.json").read_text())
    final = [e for e in read_evaluations(folder) if e.name.startswith("identified")][-1].drapes
    c, h = result["parameters"]["bending_length"], result["parameters"]["hysteresis"]
    iv = result["intervals"]
    m = misfit(test, final)
    return dict(status="identified", bending_length_cm=round(c, 3), hysteresis_per_cm=round(h, 3),
                interval_c=f"{iv['bending_length']['low']:.3g}-{iv['bending_length']['high']:.3g}",
                interval_h=f"{iv['hysteresis']['low']:.3g}-{iv['hysteresis']['high']:.3g}",
                model_DC=round(float(final.dc.mean()), 2),
                model_nodes=" ".join(map(str, final.nodes)), model_mode=final.nodes_mode(),
                **judged(final, test), J_test=round(m.J, 2), spectrum_test=round(m["spectrum"], 2),
                J_train=round(result["misfit"]["J"], 2), matched=result["matched"])


def identify_fabric(number: int, parts: dict, out, budget: Budget, first: bool, library) -> dict:
    """Identify one fabric from its training scans; compare with its test scans.

    Parameters
    ----------
    number : int
        The fabric; its identification goes to ``out/fabricNN`` (continued where it exists,
        with the budget it started with).
    parts : dict
        Its :func:`drape.identification.specimen_split.split`.
    out : path
        The study's folder.
    budget : Budget
    first : bool
        It starts an empty library (``budget.first_evaluations`` points).
    library : path
        The library of forward runs it reads and adds to.

    Returns
    -------
    dict
        Its row of ``fabrics.csv`` (:data:`COLUMNS`); ``status`` is ``identified`` or ``out of
        reach``.

    Raises
    ------
    KeyboardInterrupt
        The identification was stopped (Ctrl-C, or SIGTERM raised like it): calling again
        continues it.
    """
    folder = Path(out) / f"fabric{number:02d}"
    t0 = time.perf_counter()
    try:
        identify(_definition(parts, folder, budget, first, Path(library)), folder,
                 workers=budget.workers, quiet=True)
        reached = True
    except OutOfReach:
        reached = False
    train, test = measure(parts["train"]), measure(parts["test"])
    row = {"fabric": number, "train": len(train), "test": len(test),
           "train_DC": round(float(train.dc.mean()), 2), "test_DC": round(float(test.dc.mean()), 2),
           "test_DC_sd": round(test.dc_std(), 2), "test_nodes": " ".join(map(str, test.nodes)),
           "test_mode": test.nodes_mode(), "wall_s": round(time.perf_counter() - t0, 1)}
    if parts["down"]:
        row.update(zip(("face_up_DC", "face_down_DC"), face_dcs(parts, train, test)))
    if not reached:
        return {**row, "status": "out of reach"}
    return {**row, **_identified(folder, test)}


def _typed(row: dict) -> dict:
    """A ``fabrics.csv`` row with its numbers and flags read back."""
    out = dict(row)
    for k, v in row.items():
        if v in ("True", "False"):
            out[k] = v == "True"
        elif k not in ("test_nodes", "model_nodes", "interval_c", "interval_h", "status"):
            try:
                out[k] = float(v) if "." in v else int(v)
            except (TypeError, ValueError):
                pass
    return out


def _library_of(number: int, out: Path, library_without_own) -> Path:
    """The library fabric ``number`` reads: the shared one, or its own made from
    ``library_without_own`` (:func:`without_own`) the first time."""
    if library_without_own is None:
        return out / "library"
    library = out / f"fabric{number:02d}" / "library"
    if not library.exists():
        without_own(library_without_own, library, f"fabric{number:02d}")
    return library


def _append_row(table: Path, row: dict) -> None:
    new = not table.exists()
    with open(table, "a", newline="") as fh:
        writer = csv.DictWriter(fh, COLUMNS, extrasaction="ignore")
        if new:
            writer.writeheader()
        writer.writerow(row)


def identify_fabrics(scans, out, budget: Budget, *, numbers=None, faces: str = "both",
                     library_without_own=None, echo=print) -> str:
    """Every fabric of a scan set identified from its training half and judged on its test half.

    Parameters
    ----------
    scans : path
        The registered scan set (``.npz``); its scans are written as PLY to ``out/scans``.
    out : path
        The study's folder: ``fabrics.csv`` (a row per fabric as soon as it is done; the
        fabrics it holds already are not run again), ``identify_fabrics.md``,
        ``nodes_at_matched_dc.png``, the fabrics' identifications ``fabricNN/`` and the shared
        ``library/``.
    budget : Budget
    numbers : list of int, optional
        Only these fabrics, run in this order (default: every one, by number).
    faces : {"both", "up"}
        The captures of each half.
    library_without_own : path, optional
        Give each fabric a library of its own, this library's forward runs less its own
        folder's (:func:`without_own`).
    echo : callable
        Takes a line per fabric done.

    Returns
    -------
    str
        The markdown table (:func:`markdown`), as written to ``identify_fabrics.md``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fabrics = split(write_plys(scans, out / "scans"), faces)
    if numbers:                    # in the order given: the fabrics wanted first run first
        fabrics = {k: fabrics[k] for k in numbers if k in fabrics}
    table = out / "fabrics.csv"
    done = set()
    if table.exists():
        with open(table, newline="") as fh:
            done = {int(r["fabric"]) for r in csv.DictReader(fh)}
    for number, parts in fabrics.items():
        if number in done:
            continue
        library = _library_of(number, out, library_without_own)
        row = identify_fabric(number, parts, out, budget, first=not read_evaluations(library), library=library)
        _append_row(table, row)
        echo(f"fabric {number}: {row['status']}, test DC {row['test_DC']} model "
             f"{row.get('model_DC', '-')}, nodes {row['test_mode']} / {row.get('model_mode', '-')}")
    with open(table, newline="") as fh:
        rows = [_typed(r) for r in csv.DictReader(fh)]
    text = markdown(rows, creep_lines(fabrics))
    (out / "identify_fabrics.md").write_text(text)
    figure = nodes_figure(rows)
    if figure is not None:
        figure.savefig(out / "nodes_at_matched_dc.png", dpi=120)
    return text


def markdown(rows: list[dict], creep: list[str]) -> str:
    """The ``fabrics.csv`` rows (read back by type) as a markdown table, how many meet the
    target, and the creep series' lines (:func:`drape.identification.specimen_split.creep_lines`)."""
    head = ["| fabric | c (cm) [interval] | 2HB/B (1/cm) [interval] | test DC % (sd) | model DC % "
            "| ΔDC | test nodes (mode) | model nodes (mode) | J train / test | ok | face up / down DC % |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        fud = f"{r.get('face_up_DC', '')} / {r.get('face_down_DC', '')}" if r.get("face_down_DC") else "–"
        if r["status"] != "identified":
            head.append(f"| {r['fabric']} | {r['status']} | | {r['test_DC']} ({r['test_DC_sd']}) | "
                        f"| | {r['test_nodes']} ({r['test_mode']}) | | | no | {fud} |")
            continue
        ok = "yes" if r["DC_within_5"] and r["mode_within_1"] else "no"
        head.append(f"| {r['fabric']} | {r['bending_length_cm']} [{r['interval_c']}] | "
                    f"{r['hysteresis_per_cm']} [{r['interval_h']}] | {r['test_DC']} ({r['test_DC_sd']}) | "
                    f"{r['model_DC']} | {r['dDC']:+.1f} | {r['test_nodes']} ({r['test_mode']}) | "
                    f"{r['model_nodes']} ({r['model_mode']}) | {r['J_train']} / {r['J_test']} | "
                    f"{ok} | {fud} |")
    n_ok = sum(1 for r in rows if r.get("DC_within_5") and r.get("mode_within_1"))
    text = "\n".join(head) + f"\n\n{n_ok} of {len(rows)} fabrics within 5 DC points and ±1 node.\n"
    if creep:
        text += ("\nCreep series (scans): | fabric | observation | DC % | nodes |\n|---|---|---|---|\n"
                 + "\n".join(creep) + "\n")
    return text


def nodes_figure(rows: list[dict]):
    """Node count against DC (:func:`drape.batch.matched_dc.nodes_figure`): the identified
    fabrics' measured test ranges and their model's drapes; None if no fabric was identified."""
    table = []
    for r in rows:
        if r["status"] != "identified":
            continue
        nodes = list(map(int, r["test_nodes"].split()))
        table.append({"law": "tensor", "measured_DC": r["test_DC"], "measured_nodes_min": min(nodes),
                      "measured_nodes_max": max(nodes), "model_DC": r["model_DC"],
                      "model_nodes": r["model_nodes"]})
    return matched_nodes_figure(table) if table else None
