"""Seed ensembles: the same Cusick run under N perturbation seeds, summarised.

A Cusick drape is a buckling problem: which folds form depends on the imperfection, and the
real test is reported as a mean over several specimens (BS 5058 asks for at least two
specimens, each way up). ``python -m drape.sweep CASE --seeds N --out DIR`` runs every row of
the sweep (or the case alone) with ``load.perturbation.seed = 0 .. N-1``; the rows of one base
row form an ensemble. ``DIR/ensemble.json`` gives, per ensemble, over the runs that finished
(status completed or settled) with a drape coefficient:

* DC [%]: mean, sample standard deviation (n − 1; none for one run), minimum, maximum and the
  value of each seed;
* nodes: mean, sample standard deviation, the histogram (node count → number of seeds), the
  most frequent count and how many seeds agreed on it (ties: the count nearest the median,
  then the smaller; where no two seeds agree the summary says so);
* the measured values of the base row (``measured.*`` columns), the runs that did not finish.
"""
from __future__ import annotations

import json
import math
import statistics
from collections import Counter
from pathlib import Path

from drape.batch.rows import MEASURED, SweepError, SweepRow, read_results
from drape.case.case import CaseError, load_case
from drape.run.atomic import atomic_write_text

__all__ = ["SEED_KEY", "seed_rows", "seeded", "ensemble_stats", "ensembles", "write_ensembles",
           "describe_ensemble"]

#: The case key of the perturbation seed (:class:`drape.case.loads.Perturbation`).
SEED_KEY = "load.perturbation.seed"
GOOD = ("completed", "settled")


def seed_rows(rows, n: int, base_name: str = "base"):
    """Each row of ``rows`` (or one row named ``base_name`` if ``rows`` is None) ``n`` times,
    with the seed key set to 0 .. n-1, named ``<row>.s<seed>`` and grouped by the row's name.

    >>> [(r.name, r.keys, r.group) for r in seed_rows(None, 2)]
    [('base.s0', {'load.perturbation.seed': '0'}, 'base'), ('base.s1', {'load.perturbation.seed': '1'}, 'base')]
    """
    if n < 1:
        raise SweepError(f"--seeds = {n}: must be >= 1")
    rows = rows if rows is not None else [SweepRow(base_name)]
    out = []
    for row in rows:
        if SEED_KEY in row.keys:
            raise SweepError(f"run {row.name!r} sets {SEED_KEY} itself; --seeds sets it")
        out += [SweepRow(f"{row.name}.s{k}", {**row.keys, SEED_KEY: str(k)}, dict(row.measured),
                         group=row.name) for k in range(n)]
    return out


def seeded(case_path, overrides: list[str], rows, n: int):
    """:func:`seed_rows` of ``rows`` (or of the case alone, named after its file) after checking
    that the case has a seeded ``[load.perturbation]``."""
    try:
        perturbation = load_case(case_path, overrides).load.perturbation
    except CaseError as exc:
        raise SweepError(f"case {case_path}: {' '.join(str(exc).split())}") from None
    if perturbation is None or perturbation.kind == "none":
        raise SweepError(f"--seeds: case {case_path} has no seeded [load.perturbation] ({SEED_KEY})")
    return seed_rows(rows, n, Path(case_path).stem)


def _number(text):
    try:
        x = float(text)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _spread(values):
    n = len(values)
    if n == 0:
        return None, None
    mean = sum(values) / n
    std = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1)) if n > 1 else None
    return mean, std


def ensemble_stats(records: list[dict]) -> dict:
    """Statistics of one ensemble from its results.csv records (see the module docstring).

    >>> recs = [{"name": f"a.s{k}", "status": "settled", "DC_percent": dc, "nodes": n}
    ...         for k, (dc, n) in enumerate([(50.0, 5), (52.0, 5), (54.0, 6)])]
    >>> s = ensemble_stats(recs)
    >>> s["DC_percent"]["mean"], s["DC_percent"]["std"], s["nodes"]["histogram"], s["nodes"]["agreement"]
    (52.0, 2.0, {'5': 2, '6': 1}, '2 of 3 seeds gave 5 nodes')

    A run that finished without a drape to measure (``analysis = "none"``) counts as finished:

    >>> s = ensemble_stats([{"name": "drop.s0", "status": "completed", "DC_percent": ""},
    ...                     {"name": "drop.s1", "status": "failed", "DC_percent": ""}])
    >>> s["finished"], s["not_finished"], s["DC_percent"]["mean"]
    (1, {'drop.s1': 'failed'}, None)
    """
    done = [r for r in records if r.get("status") in GOOD]
    measured = [r for r in done if _number(r.get("DC_percent")) is not None]
    dc = [_number(r["DC_percent"]) for r in measured]
    nodes = [int(_number(r["nodes"])) for r in measured if _number(r.get("nodes")) is not None]
    dc_mean, dc_std = _spread(dc)
    n_mean, n_std = _spread(nodes)
    hist = Counter(nodes)
    mode, mode_count = None, 0
    if hist:  # the commonest count; among tied ones the nearest the median, then the smaller
        middle = statistics.median(nodes)
        mode = min(hist, key=lambda k: (-hist[k], abs(k - middle), k))
        mode_count = hist[mode]
    if not nodes:
        agreement = "no run gave a node count"
    elif mode_count == 1 and len(nodes) > 1:
        agreement = f"no two of {len(nodes)} seeds agree: {', '.join(map(str, sorted(nodes)))} nodes"
    else:
        agreement = f"{mode_count} of {len(nodes)} seeds gave {mode} nodes"
    return {
        "runs": len(records), "finished": len(done),
        "not_finished": {r["name"]: r.get("status", "") for r in records if r not in done},
        "DC_percent": {"mean": dc_mean, "std": dc_std, "min": min(dc, default=None),
                       "max": max(dc, default=None),
                       "values": {r["name"]: _number(r["DC_percent"]) for r in measured}},
        "nodes": {"mean": n_mean, "std": n_std,
                  "histogram": {str(k): hist[k] for k in sorted(hist)},
                  "mode": mode, "mode_count": mode_count, "agreement": agreement},
    }


def ensembles(out_dir) -> list[dict]:
    """The ensembles of a sweep folder (``sweep.json`` groups, ``results.csv`` records)."""
    out_dir = Path(out_dir)
    definition = json.loads((out_dir / "sweep.json").read_text())
    records = {r["name"]: r for r in read_results(out_dir / "results.csv")}
    groups: dict[str, list[dict]] = {}
    for row in definition["rows"]:
        if row.get("group"):
            groups.setdefault(row["group"], []).append(row)
    out = []
    for name, rows in groups.items():
        keys = {k: v for k, v in rows[0]["keys"].items() if k != SEED_KEY}
        measured = {k[len(MEASURED):]: v for k, v in rows[0]["measured"].items()}
        got = [records.get(r["name"], {"name": r["name"], "status": "not run"}) for r in rows]
        out.append({"name": name, "keys": keys, "measured": measured,
                    "seeds": [int(r["keys"][SEED_KEY]) for r in rows], **ensemble_stats(got)})
    return out


def write_ensembles(out_dir) -> Path | None:
    """Write ``out_dir/ensemble.json`` if the sweep has seed ensembles; return its path."""
    out_dir = Path(out_dir)
    found = ensembles(out_dir)
    if not found:
        return None
    path = out_dir / "ensemble.json"
    return atomic_write_text(path, json.dumps({"seed_key": SEED_KEY, "ensembles": found}, indent=1))


def _pm(stats: dict, digits: int) -> str:
    if stats["mean"] is None:
        return "-"
    std = "" if stats["std"] is None else f" ± {stats['std']:.{digits}f}"
    return f"{stats['mean']:.{digits}f}{std}"


def describe_ensemble(e: dict) -> str:
    """One line: DC mean ± sd, nodes mean ± sd, histogram and agreement (and measured values).

    >>> e = {"name": "wool", "finished": 3, "runs": 3, "measured": {"DC": "49.8"},
    ...      "DC_percent": {"mean": 52.0, "std": 2.0}, "nodes": {"mean": 5.33, "std": 0.58,
    ...      "histogram": {"5": 2, "6": 1}, "agreement": "2 of 3 seeds gave 5 nodes"}}
    >>> describe_ensemble(e)
    'wool: 3/3 seeds, DC 52.0 ± 2.0 %, nodes 5.3 ± 0.6 (5:2 6:1; 2 of 3 seeds gave 5 nodes); measured DC 49.8'
    """
    hist = " ".join(f"{k}:{v}" for k, v in e["nodes"]["histogram"].items())
    measured = ", ".join(f"{k} {v}" for k, v in e.get("measured", {}).items())
    return (f"{e['name']}: {e['finished']}/{e['runs']} seeds, DC {_pm(e['DC_percent'], 1)} %, "
            f"nodes {_pm(e['nodes'], 1)} ({hist}; {e['nodes']['agreement']})"
            + (f"; measured {measured}" if measured else ""))
