"""A drape predicted from a KES sheet, with the interval its missing values and the seed leave.

A KES sheet seldom gives everything a Cusick drape depends on. What it omits is sampled over the
range that values of woven apparel fabrics span (:data:`UNKNOWNS`), together with the
perturbation seed (one seed, one specimen):

* ``shear_G``: the shear rigidity G, when the sheet gives none (the set-up's stand-in otherwise
  applies), log-uniform over the wovens' KES-FB1 range 0.3–2 gf/(cm·deg) (Kawabata 1980);
* ``anisotropy``: B_warp / B_weft, when the sheet gives one B and one 2HB for both directions,
  log-uniform over 0.5–2, keeping √(B_warp B_weft) and 2HB/B per direction (woven apparel
  fabrics are stiffer along the warp by up to about twice, and some the other way; Kawabata &
  Niwa 1989);
* ``thickness``: T, when the sheet gives none, log-uniform over 0.2–1 mm (it places the fabric
  on the tester's support).

:func:`sample_rows` draws the samples as a Latin hypercube in the logarithms (each sample its
own seed), run on Dask as a sweep (:func:`drape.batch.sweep.run_sweep`). :func:`summarise`
gives the DC's median and its interval (the 5th and 95th percentiles of the samples, linear
interpolation between order statistics: with 12 samples the ends are themselves uncertain by a
few points), the node counts over the same percentiles, and which missing measurement would
narrow the interval most: the unknown whose spread explains the largest share of the DC's
variance, by a least-squares fit of DC on the unknowns' standardised logarithms
(Saltelli et al., *Global Sensitivity Analysis: The Primer*, 2008, §1.2.5: standardised
regression coefficients, β_j² = the share of the variance explained by input j for a nearly
linear response and independent inputs, which a Latin hypercube keeps nearly so). What the
fit does not explain is the seed's scatter and the response's curvature.

Examples
--------
>>> sheet = {"B_warp": 0.1, "B_weft": 0.1, "HB2_warp": 0.05, "HB2_weft": 0.05, "weight": 15}
>>> missing_unknowns(sheet)
['shear_G', 'anisotropy', 'thickness']
>>> rows = sample_rows(sheet, missing_unknowns(sheet), 4, seed=0)
>>> len(rows), sorted(rows[0].keys)[:3]
(4, ['load.perturbation.seed', 'material.kes.B_warp', 'material.kes.B_weft'])
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drape.batch.ensemble import SEED_KEY
from drape.batch.rows import SweepRow

__all__ = ["Unknown", "UNKNOWNS", "missing_unknowns", "sample_rows", "interval", "interval_line", "summarise",
           "describe_prediction", "prediction_figure", "LEVEL"]

#: The interval's probability: from the 5th to the 95th percentile of the samples.
LEVEL = 0.90

#: The least share of the DC's variance for which measuring an unknown is advised.
MATTERS = 0.10


@dataclass(frozen=True)
class Unknown:
    """A value a sheet may omit, and the range woven apparel fabrics span."""

    name: str
    what: str
    unit: str
    low: float
    high: float


UNKNOWNS: dict[str, Unknown] = {u.name: u for u in (
    Unknown("shear_G", "the shear rigidity G (KES-FB1)", "gf/(cm·deg)", 0.3, 2.0),
    Unknown("anisotropy", "B and 2HB of warp and weft apart (KES-FB2)", "B_warp/B_weft", 0.5, 2.0),
    Unknown("thickness", "the thickness T (KES-FB3)", "mm", 0.2, 1.0),
)}


def _same(a, b) -> bool:
    """One value printed for both directions (the same to 6 digits: a value given in other
    units converts with round-off)."""
    return a is None or b is None or math.isclose(float(a), float(b), rel_tol=1e-6)


def missing_unknowns(sheet: dict) -> list[str]:
    """The :data:`UNKNOWNS` the sheet (the case's own ``[material.kes]`` table, without what a
    set-up stands in) leaves open: no G, one B and one 2HB for both directions, no thickness."""
    out = []
    if "G" not in sheet:
        out.append("shear_G")
    if all(_same(sheet.get(f"{k}_warp"), sheet.get(f"{k}_weft")) for k in ("B", "HB2")):
        out.append("anisotropy")
    if "thickness" not in sheet:
        out.append("thickness")
    return out


def _keys(sheet: dict, values: dict) -> dict:
    """The case keys of one sample."""
    keys = {}
    if "shear_G" in values:
        keys["material.kes.G"] = f"{values['shear_G']:.6g}"
    if "anisotropy" in values:
        root = math.sqrt(values["anisotropy"])
        for name, factor in (("warp", root), ("weft", 1.0 / root)):
            keys[f"material.kes.B_{name}"] = f"{float(sheet[f'B_{name}']) * factor:.6g}"
            keys[f"material.kes.HB2_{name}"] = f"{float(sheet[f'HB2_{name}']) * factor:.6g}"
    if "thickness" in values:
        keys["material.kes.thickness"] = f"{values['thickness']:.6g}"
    return keys


def sample_rows(sheet: dict, unknowns: list[str], n: int, seed: int = 0) -> list[SweepRow]:
    """``n`` runs: the unknowns drawn as a Latin hypercube in their logarithms (scipy's
    ``qmc.LatinHypercube``, seeded), sample ``i`` under perturbation seed ``i``; named
    ``p000``, ``p001``, ... with the sampled values as ``unknown.<name>`` in ``measured``."""
    from scipy.stats import qmc

    if n < 2:
        raise ValueError(f"--samples = {n}: must be >= 2 (an interval needs samples)")
    unit = qmc.LatinHypercube(d=max(len(unknowns), 1), seed=seed).random(n)
    rows = []
    for i in range(n):
        values = {}
        for j, name in enumerate(unknowns):
            u = UNKNOWNS[name]
            values[name] = math.exp(math.log(u.low) + unit[i, j] * math.log(u.high / u.low))
        keys = {**_keys(sheet, values), SEED_KEY: str(i)}
        rows.append(SweepRow(f"p{i:03d}", keys, {f"unknown.{k}": f"{v:.6g}" for k, v in values.items()}))
    return rows


def _shares(dc: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Each column's share of the variance of ``dc`` (squared standardised regression
    coefficients of a least-squares fit); empty without columns."""
    if x.shape[1] == 0 or dc.size <= x.shape[1] + 1 or np.std(dc) == 0:
        return np.full(x.shape[1], np.nan)
    z = (x - x.mean(0)) / np.where(x.std(0) > 0, x.std(0), 1.0)
    beta, *_ = np.linalg.lstsq(np.column_stack([np.ones(len(dc)), z]), dc, rcond=None)
    return beta[1:] ** 2 / np.var(dc)


def interval(dc, nodes) -> dict:
    """DC median and :data:`LEVEL` interval (its percentiles) and node range of a set of drapes.

    >>> p = interval([60.0, 62.0, 64.0], [6, 7, 7])
    >>> p["DC_percent"]["median"], round(p["DC_percent"]["low"], 2), (p["nodes"]["low"], p["nodes"]["high"])
    (62.0, 60.2, (6, 7))
    """
    dc, nodes = np.asarray(dc, dtype=float), np.asarray(nodes, dtype=float)
    tail = 50.0 * (1.0 - LEVEL)
    low, mid, high = np.percentile(dc, [tail, 50.0, 100.0 - tail])
    n_low, n_high = np.percentile(nodes, [tail, 100.0 - tail])
    return {"DC_percent": {"median": float(mid), "low": float(low), "high": float(high),
                           "level": LEVEL, "values": dc.tolist()},
            "nodes": {"low": int(math.floor(n_low + 1e-9)), "high": int(math.ceil(n_high - 1e-9)),
                      "values": nodes.astype(int).tolist()}}


def interval_line(p: dict) -> str:
    """``DC 63 % (57–68 %, 90 %), nodes 6–7`` of :func:`interval`'s entries."""
    dc, nodes = p["DC_percent"], p["nodes"]
    count = f"{nodes['low']}" if nodes["low"] == nodes["high"] else f"{nodes['low']}–{nodes['high']}"
    return (f"DC {dc['median']:.0f} % ({dc['low']:.0f}–{dc['high']:.0f} %, {100 * dc['level']:.0f} %), "
            f"nodes {count}")


def summarise(records: list[dict], rows: list[SweepRow], unknowns: list[str]) -> dict:
    """The prediction from the sweep's ``results.csv`` records: DC median and interval, node
    counts, the unknowns' shares of the DC's variance and the one that would narrow it most.

    Runs that did not finish (status other than completed or settled) are counted, not used.
    """
    by_name = {r.name: r for r in rows}
    good = [r for r in records if r.get("status") in ("completed", "settled")
            and r.get("DC_percent") not in (None, "") and r["name"] in by_name]
    if len(good) < 2:
        raise ValueError(f"{len(good)} of {len(records)} runs finished with a drape: too few for "
                         "an interval")
    dc = np.array([float(r["DC_percent"]) for r in good])
    nodes = np.array([float(r["nodes"]) for r in good])
    x = np.array([[math.log(float(by_name[r["name"]].measured[f"unknown.{u}"])) for u in unknowns]
                  for r in good]).reshape(len(good), len(unknowns))
    shares = _shares(dc, x)
    ranked = sorted(((float(s), u) for s, u in zip(shares, unknowns) if np.isfinite(s)), reverse=True)
    return {
        **interval(dc, nodes),
        "runs": {"used": len(good), "of": len(records)},
        "unknowns": {u: {"range": [UNKNOWNS[u].low, UNKNOWNS[u].high], "unit": UNKNOWNS[u].unit,
                         "variance_share": float(s) if np.isfinite(s) else None}
                     for u, s in zip(unknowns, shares)},
        "most_informative": ranked[0][1] if ranked else None,
        "unexplained_share": float(max(0.0, 1.0 - sum(s for s, _ in ranked))) if ranked else 1.0,
    }


def describe_prediction(p: dict) -> str:
    """The prediction in one line, and which measurement would narrow it most.

    >>> print(describe_prediction({"DC_percent": {"median": 63.2, "low": 57.1, "high": 68.4,
    ...     "level": 0.9}, "nodes": {"low": 6, "high": 7}, "runs": {"used": 12, "of": 12},
    ...     "unknowns": {"shear_G": {"variance_share": 0.6}}, "most_informative": "shear_G",
    ...     "unexplained_share": 0.4}))
    DC 63 % (57–68 %, 90 %), nodes 6–7 (12 of 12 runs)
    measuring the shear rigidity G (KES-FB1) would narrow it most: 60 % of the DC's variance; the seed and the rest 40 %
    """
    line = f"{interval_line(p)} ({p['runs']['used']} of {p['runs']['of']} runs)"
    best = p["most_informative"]
    if not p["unknowns"]:
        return line + "\nthe sheet leaves nothing open: the interval is the seed's scatter alone"
    if best is None:
        return line + (f"\n{p['runs']['used']} runs are too few to tell which missing value matters "
                       f"most (more than {len(p['unknowns']) + 1} are needed)")
    share = p["unknowns"][best]["variance_share"]
    if share < MATTERS:
        return line + (f"\nnone of the missing values explains much of it (the most, {UNKNOWNS[best].what}, "
                       f"{100 * share:.0f} %): the seed's scatter is the interval")
    return (line + f"\nmeasuring {UNKNOWNS[best].what} would narrow it most: {100 * share:.0f} % of "
            f"the DC's variance; the seed and the rest {100 * p['unexplained_share']:.0f} %")


def prediction_figure(prediction: dict, rows: list[SweepRow], records: dict):
    """The DC of each run against each sampled unknown (log scale; against the seed where none
    was sampled), the interval shaded and the measured DC drawn where there is one.
    ``records`` maps run names to their results.csv records. Returns a matplotlib ``Figure``
    (not attached to pyplot)."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    names = list(prediction["unknowns"]) or ["seed"]
    fig = Figure(figsize=(3.6 * len(names), 3.2), layout="constrained")
    dc = prediction["DC_percent"]
    for k, name in enumerate(names):
        ax = fig.add_subplot(1, len(names), k + 1)
        pts = [(i if name == "seed" else float(r.measured[f"unknown.{name}"]),
                float(records[r.name]["DC_percent"])) for i, r in enumerate(rows)
               if records.get(r.name, {}).get("DC_percent") not in (None, "")]
        ax.scatter(*zip(*pts), s=18, color="C0")
        ax.axhspan(dc["low"], dc["high"], color="C0", alpha=0.12,
                   label=f"{100 * dc['level']:.0f} % interval")
        if "measured" in prediction:
            ax.axhline(prediction["measured"]["DC_percent"], color="C3", label="measured")
        if name != "seed":
            ax.set_xscale("log")
            u = UNKNOWNS[name]
            ax.set_xticks([v for v in (0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0) if u.low <= v <= u.high])
            ax.xaxis.set_major_formatter(ScalarFormatter())
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(name if name == "seed" else f"{name} [{UNKNOWNS[name].unit}]")
        ax.set_ylabel("DC [%]")
        if k == 0:
            ax.legend(fontsize=8)
    return fig
