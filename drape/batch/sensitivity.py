"""One-factor-at-a-time sensitivity of a Cusick drape: DC and node count around a base case.

A study is a base case and a list of :class:`Factor` s, each with one or two
:class:`Level` s: case keys set away from the base (``--set`` style dotted keys, values as
text). Every level is one row of a :mod:`drape.batch.sweep` (run name ``<factor>.<tag>``, the
base case alone is ``base``), so the runs go to Dask in parallel, land in ``OUT/results.csv``
as they finish, and a stopped study continues with ``resume`` (the finished rows are kept).
With ``seeds > 1`` every row runs under the perturbation seeds 0..N-1 (:mod:`drape.batch.ensemble`)
and each level is read as its ensemble: the mean DC and the most frequent node count.

:func:`collect` reads the finished study into one record (``OUT/sensitivity.json``): per
level its DC, node count, status, and their changes from the base, ΔDC (points) and Δnodes.
:func:`markdown_table` prints it, :func:`tornado_figure` draws ΔDC per factor and level
(low and high level side by side, the node count at each bar, the measured DC of the case's
``[measured]`` table as a line), and :func:`write_study` writes ``sensitivity.md``,
``sensitivity.json`` and ``tornado.png``.

A level whose run did not finish (status other than completed or settled, or no DC) gets
no ΔDC; the table gives its status and reason, and the chart marks it.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

from drape.batch.ensemble import ensemble_stats, seed_rows
from drape.batch.rows import SweepRow, _checked, read_results
from drape.batch.sweep import run_sweep
from drape.case.case import CaseError, load_case

__all__ = ["Level", "Factor", "BASE", "StudyError", "study_rows", "collect", "markdown_table",
           "factor_sentences", "tornado_figure", "write_study", "run_study"]

#: Run name of the base case.
BASE = "base"
_TAG = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*$")
SIDES = ("low", "high")


class StudyError(ValueError):
    """A study definition or folder breaks a rule (the message names it)."""


@dataclass(frozen=True)
class Level:
    """One level of a factor: the case keys it sets and how it is shown.

    Parameters
    ----------
    tag : str
        Names the run ``<factor>.<tag>`` (letters, digits, ``_``, ``-``).
    label : str
        The level as a reader sees it, e.g. ``"ε_f = 0.05 cm⁻¹"``.
    keys : dict
        Dotted case key → value text (read as a ``--set`` value).
    side : {"low", "high"}
        Where the level sits against the base (the chart's colour).
    """

    tag: str
    label: str
    keys: dict
    side: str = "low"

    def __post_init__(self):
        if not _TAG.match(self.tag):
            raise StudyError(f"level tag {self.tag!r}: letters, digits, '_' or '-' (it names a run)")
        if self.side not in SIDES:
            raise StudyError(f"level {self.tag!r}: side = {self.side!r} must be 'low' or 'high'")
        if not self.keys or any("." not in k for k in self.keys):
            raise StudyError(f"level {self.tag!r}: keys must be dotted case keys, at least one "
                             f"(got {list(self.keys)})")


@dataclass(frozen=True)
class Factor:
    """A factor of the study: its levels around the base value ``base_label``."""

    name: str
    title: str
    base_label: str
    levels: tuple = field(default_factory=tuple)

    def __post_init__(self):
        if not _TAG.match(self.name):
            raise StudyError(f"factor name {self.name!r}: letters, digits, '_' or '-' "
                             "(it names its runs)")
        if not self.levels:
            raise StudyError(f"factor {self.name!r}: no levels")
        tags = [lv.tag for lv in self.levels]
        if len(set(tags)) != len(tags):
            raise StudyError(f"factor {self.name!r}: level tag repeated in {tags}")


def _run_name(factor: Factor, level: Level) -> str:
    return f"{factor.name}.{level.tag}"


def study_rows(factors, seeds: int = 1):
    """The sweep rows of a study: ``base`` and one per level (each ``seeds`` times).

    >>> f = Factor("damping", "damping α", "20 1/s",
    ...            (Level("low", "5 1/s", {"model.damping.alpha": "5"}),))
    >>> [(r.name, r.keys) for r in study_rows([f])]
    [('base', {}), ('damping.low', {'model.damping.alpha': '5'})]
    """
    names = [f.name for f in factors]
    if len(set(names)) != len(names):
        raise StudyError(f"factor name repeated in {names}")
    rows = [SweepRow(BASE)] + [SweepRow(_run_name(f, lv), dict(lv.keys))
                               for f in factors for lv in f.levels]
    if seeds > 1:
        rows = seed_rows(rows, seeds)
    return _checked(rows, "sensitivity study")


# --------------------------------------------------------------------------- results
def _level_record(records: list[dict]) -> dict:
    """DC and nodes of one level from its results.csv records (one per seed)."""
    stats = ensemble_stats(records)
    dc, nodes = stats["DC_percent"], stats["nodes"]
    reasons = sorted({f"{r.get('status', '')}: {r.get('reason', '')}".rstrip(": ")
                      for r in records if r["name"] in stats["not_finished"]})
    single = len(records) == 1
    return {
        "runs": stats["runs"], "finished": stats["finished"],
        "status": (records[0].get("status", "") if single else
                   f"{stats['finished']}/{stats['runs']} finished"),
        "reason": "; ".join(reasons),
        "DC_percent": dc["mean"], "DC_std": dc["std"],
        "nodes": nodes["mode"], "nodes_mean": nodes["mean"],
        "nodes_histogram": nodes["histogram"],
    }


def _diff(a, b):
    return None if a is None or b is None else a - b


def collect(out, case_path, factors, *, overrides: list[str] | None = None,
            seeds: int = 1) -> dict:
    """The study record of the sweep folder ``out`` (see the module docstring).

    Levels missing from ``results.csv`` (not run yet) are recorded with status ``not run``.
    """
    out = Path(out)
    path = out / "results.csv"
    records = read_results(path) if path.exists() else []
    group_of = {r.name: r.group or r.name for r in study_rows(factors, seeds)}
    by_group: dict[str, list[dict]] = {}
    for rec in records:
        if rec["name"] in group_of:
            by_group.setdefault(group_of[rec["name"]], []).append(rec)

    def level(name):
        recs = by_group.get(name)
        if not recs:
            return {"runs": 0, "finished": 0, "status": "not run", "reason": "",
                    "DC_percent": None, "DC_std": None, "nodes": None, "nodes_mean": None,
                    "nodes_histogram": {}}
        return _level_record(recs)

    try:
        measured = load_case(case_path, overrides).measured
    except CaseError as exc:
        raise StudyError(f"case {case_path}: {' '.join(str(exc).split())}") from None
    base = {"name": BASE, **level(BASE)}
    study = {"case": str(case_path), "set": list(overrides or []), "seeds": seeds,
             "measured": None if measured is None else {"DC_percent": measured.DC_percent,
                                                         "nodes": measured.nodes},
             "base": base, "factors": []}
    for f in factors:
        levels = []
        for lv in f.levels:
            rec = level(_run_name(f, lv))
            rec.update({"name": _run_name(f, lv), "tag": lv.tag, "label": lv.label,
                        "side": lv.side, "keys": dict(lv.keys),
                        "dDC": _diff(rec["DC_percent"], base["DC_percent"]),
                        "dnodes": _diff(rec["nodes"], base["nodes"])})
            levels.append(rec)
        study["factors"].append({"name": f.name, "title": f.title, "base_label": f.base_label,
                                 "levels": levels})
    return study


def _f(x, fmt=".1f", none="–"):
    text = none if x is None else format(x, fmt)
    # a change that rounds to zero is shown without a sign of its own
    return "0" + text[2:] if text[:2] in ("-0", "+0") and not text[2:].strip("0.") else text


def _swing(factor: dict) -> float:
    """The largest |ΔDC| of a factor's levels (0 when none finished)."""
    return max((abs(lv["dDC"]) for lv in factor["levels"] if lv["dDC"] is not None), default=0.0)


def _dc_text(rec: dict) -> str:
    return _f(rec["DC_percent"]) + ("" if rec["DC_std"] is None else f" ± {rec['DC_std']:.1f}")


def _nodes_text(rec: dict) -> str:
    if rec["nodes"] is None:
        return "–"
    if rec["runs"] > 1:
        return f"{rec['nodes']} (mean {_f(rec['nodes_mean'])})"
    return str(rec["nodes"])


def markdown_table(study: dict) -> str:
    """The study as a markdown table: the base, then each factor's levels, factors by their
    largest |ΔDC| (the tornado's order).

    >>> lv = {"label": "α = 5 1/s", "keys": {"model.damping.alpha": "5"}, "DC_percent": 58.0,
    ...       "DC_std": None, "nodes": 9, "nodes_mean": 9.0, "runs": 1, "status": "settled",
    ...       "reason": "", "dDC": -2.1, "dnodes": 1}
    >>> base = {**lv, "DC_percent": 60.1, "nodes": 8, "dDC": 0.0, "dnodes": 0}
    >>> study = {"base": base, "factors": [{"title": "damping", "base_label": "α = 20 1/s",
    ...                                      "levels": [lv]}]}
    >>> print(markdown_table(study))
    | factor | level | keys | DC [%] | ΔDC [points] | nodes | Δnodes | status |
    |---|---|---|---|---|---|---|---|
    | base | (defaults) |  | 60.1 | 0.0 | 8 | 0 | settled |
    | damping (α = 20 1/s) | α = 5 1/s | `model.damping.alpha=5` | 58.0 | -2.1 | 9 | +1 | settled |
    """
    lines = ["| factor | level | keys | DC [%] | ΔDC [points] | nodes | Δnodes | status |",
             "|---|---|---|---|---|---|---|---|"]

    def status(rec):
        return rec["status"] + (f" ({rec['reason']})" if rec["reason"] else "")

    base = study["base"]
    lines.append(f"| base | (defaults) |  | {_dc_text(base)} | "
                 f"{'0.0' if base['DC_percent'] is not None else '–'} | {_nodes_text(base)} | "
                 f"{'0' if base['nodes'] is not None else '–'} | {status(base)} |")
    for f in sorted(study["factors"], key=_swing, reverse=True):
        for lv in f["levels"]:
            keys = ", ".join(f"`{k}={v}`" for k, v in lv["keys"].items())
            lines.append(f"| {f['title']} ({f['base_label']}) | {lv['label']} | {keys} | "
                         f"{_dc_text(lv)} | {_f(lv['dDC'], '+.1f')} | {_nodes_text(lv)} | "
                         f"{_f(lv['dnodes'], '+d')} | {status(lv)} |")
    return "\n".join(lines)


def factor_sentences(study: dict) -> list[str]:
    """One line per factor stating what each level does to DC and nodes (the figures only;
    what they mean is the reader's)."""
    base = study["base"]
    out = []
    for f in sorted(study["factors"], key=_swing, reverse=True):
        parts = []
        for lv in f["levels"]:
            if lv["dDC"] is None:
                parts.append(f"{lv['label']}: no result ({lv['status']})")
            else:
                parts.append(f"{lv['label']}: DC {_f(lv['dDC'], '+.1f')} points, nodes "
                             f"{_f(base['nodes'], 'd')} → {_f(lv['nodes'], 'd')}")
        out.append(f"- **{f['title']}** (default {f['base_label']}): " + "; ".join(parts) + ".")
    return out


# --------------------------------------------------------------------------- the chart
_COLOURS = {"low": "#4477aa", "high": "#ee6677"}


def tornado_figure(study: dict, title: str | None = None):
    """Tornado chart of ΔDC per factor and level, node counts at the bars.

    Factors run top to bottom by their largest |ΔDC|; each factor's levels are side by side
    (bar ``i`` of ``n`` at ``y + (n - 1)/2·h − i·h``), coloured by side. A dashed line marks
    the measured DC (relative to the base) when the study has one; a band marks the base's
    seed spread (±1 sample standard deviation) when it ran as an ensemble.

    Returns a matplotlib ``Figure`` (not attached to pyplot).
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    factors = sorted(study["factors"], key=_swing)          # bottom (y = 0) is the smallest
    base, measured = study["base"], study.get("measured")
    fig = Figure(figsize=(9.5, 1.2 + 0.62 * max(len(factors), 1)), layout="constrained")
    ax = fig.add_subplot()
    height = 0.36
    extent = [0.0]
    for y, f in enumerate(factors):
        n = len(f["levels"])
        for i, lv in enumerate(f["levels"]):
            yy = y + (n - 1) / 2 * height - i * height
            if lv["dDC"] is None:
                ax.text(0, yy, f"  {lv['label']}: {lv['status']}", va="center", fontsize=7,
                        color="0.4")
                continue
            dx = lv["dDC"]
            ax.barh(yy, dx, height=height * 0.92, color=_COLOURS[lv["side"]])
            extent.append(dx)
            ax.text(dx, yy, f" {lv['label']}, {_f(lv['nodes'], 'd')} nodes ",
                    ha="left" if dx >= 0 else "right", va="center", fontsize=7)
    ax.set_yticks(range(len(factors)),
                  [f"{f['title']}\n(default {f['base_label']})" for f in factors], fontsize=8)
    ax.axvline(0.0, color="k", lw=0.8)
    handles = [Patch(color=_COLOURS[s], label=f"{s} level") for s in SIDES]
    if base["DC_std"] is not None:
        ax.axvspan(-base["DC_std"], base["DC_std"], color="0.85", zorder=0)
        handles.append(Patch(color="0.85", label="base ±1 s.d. over seeds"))
    if measured and measured.get("DC_percent") is not None and base["DC_percent"] is not None:
        x = measured["DC_percent"] - base["DC_percent"]
        extent.append(x)
        line = ax.axvline(x, color="k", ls="--", lw=1.0,
                          label=f"measured: {measured['DC_percent']:.1f} %"
                                + (f", {measured['nodes']} nodes" if measured.get("nodes") else ""))
        handles.append(line)
    span = max(max(abs(v) for v in extent), 1.0)
    ax.set_xlim(-1.9 * span, 1.9 * span)       # room for the labels beyond the bars
    ax.set_ylim(-0.6, len(factors) - 0.4)
    ax.set_xlabel("ΔDC from the base [points]")
    ax.legend(handles=handles, fontsize=7, loc="lower right")
    ax.grid(axis="x", color="0.9", lw=0.6)
    ax.set_axisbelow(True)
    head = title or Path(study.get("case", "")).stem
    ax.set_title(f"{head}: one factor at a time around DC {_f(base['DC_percent'])} %, "
                 f"{_f(base['nodes'], 'd')} nodes", fontsize=10)
    return fig


# --------------------------------------------------------------------------- files
def write_study(out, study: dict) -> dict:
    """``sensitivity.json``, ``sensitivity.md`` and ``tornado.png`` in ``out``; returns their
    paths."""
    out = Path(out)
    paths = {"json": out / "sensitivity.json", "md": out / "sensitivity.md",
             "png": out / "tornado.png"}
    paths["json"].write_text(json.dumps(study, indent=1))
    base, measured = study["base"], study.get("measured")
    head = [f"# Sensitivity of {Path(study['case']).name}", "",
            f"Base: `{study['case']}`" + "".join(f" `--set {s}`" for s in study["set"]) +
            f"; {study['seeds']} seed(s) per level. Base DC {_dc_text(base)} %, "
            f"{_nodes_text(base)} nodes ({base['status']})."]
    if measured:
        head.append(f"Measured: DC {_f(measured['DC_percent'])} %, "
                    f"{_f(measured['nodes'], 'd')} nodes.")
    text = "\n".join(head + ["", markdown_table(study), "", *factor_sentences(study), "",
                             f"![tornado]({paths['png'].name})", ""])
    paths["md"].write_text(text)
    tornado_figure(study).savefig(paths["png"], dpi=110)
    return paths


def run_study(case_path, factors, out, *, overrides: list[str] | None = None, seeds: int = 1,
              workers: int | None = None, scheduler: str | None = None, resume: bool = False,
              quiet: bool = False) -> dict:
    """Run the study as one sweep into ``out`` and write its files; return the study record.

    ``overrides`` apply to every run (before each level's keys). ``resume`` keeps the finished
    runs of ``out`` and runs the others; the study must then have the same ``overrides``
    (``StudyError`` otherwise: a different study needs a new folder).
    """
    out = Path(out)
    if seeds < 1:
        raise StudyError(f"seeds = {seeds}: must be >= 1")
    rows = study_rows(factors, seeds)
    overrides = list(overrides or [])
    definition = out / "sweep.json"
    if resume and definition.exists():
        before = json.loads(definition.read_text())
        if before.get("set") != overrides:
            raise StudyError(f"--resume: {out} ran with --set {before.get('set')}, this study "
                             f"gives {overrides}; use a new --out for a different study")

    for row in rows:      # a level that cannot be a case is a bad study, not a failed run
        try:
            load_case(case_path, overrides + row.overrides())
        except CaseError as exc:
            raise StudyError(f"run {row.name}: {' '.join(str(exc).split())}") from None
    run_sweep(case_path, rows, out, overrides=overrides, scheduler=scheduler, workers=workers,
              resume=resume, quiet=quiet)
    study = collect(out, case_path, factors, overrides=overrides, seeds=seeds)
    study["files"] = {k: str(v) for k, v in write_study(out, study).items()}
    return study
