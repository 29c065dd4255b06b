"""Which node count does the model itself prefer? Cusick drapes forced into n folds, compared by energy.

A drape's node count may come from the fabric (the equilibrium of lowest energy) or from the
path that led to it (friction and damping freeze the first folds that form). This study
separates the two. Each run imposes one fold mode ``n`` with a strong transient load
(``load.perturbation.kind = "lobed"``, ``n_lobes = n``, an amplitude of the weight, by default
0.1, five times the default random perturbation's), with the friction of the case and without
it, and lets the specimen settle by the static-balance rule (:func:`fold_rows`). The table
(:func:`energy_table`, :func:`markdown`) gives, for every run, the node count it settled in and
its total potential energy ``Π = U + V`` (strain energy plus the weight's potential, from
``summary.json``):

- without friction, the settled states are equilibria of the elastic fabric alone, so the
  lowest ``Π`` among them is the node count the model prefers. If a forced mode does not
  hold (the run settles in another count), that mode is not even a stable equilibrium;
- with friction, the forced counts that hold show which drapes the hysteresis can freeze.

:func:`run_fold_preference` runs the study as one sweep and writes ``fold_preference.md`` and
``fold_preference.png`` (``Π`` against the settled node count, :func:`energy_figure`).
"""
from __future__ import annotations

import json
import tomllib
from pathlib import Path

from drape.batch.rows import SweepRow, read_results
from drape.batch.sweep import run_sweep

__all__ = ["fold_rows", "energy_table", "markdown", "measured_nodes", "energy_figure",
           "run_fold_preference"]


def fold_rows(lobes, amplitude: float = 0.1) -> list[SweepRow]:
    """One sweep row per imposed fold count and friction setting.

    >>> [r.name for r in fold_rows([4, 6])]
    ['n4_friction', 'n4_frictionless', 'n6_friction', 'n6_frictionless']
    """
    rows = []
    for n in lobes:
        for friction in ("true", "false"):
            keys = {"load.perturbation.kind": "lobed", "load.perturbation.n_lobes": str(n),
                    "load.perturbation.amplitude": repr(amplitude), "material.friction": friction}
            rows.append(SweepRow(f"n{n}_{'friction' if friction == 'true' else 'frictionless'}", keys))
    return rows


def energy_table(out, records) -> list[dict]:
    """The sweep's records with the settled state's energies.

    Parameters
    ----------
    out : path
        The sweep's folder (the records' ``run_dir`` are relative to it).
    records : list of dict
        Its ``results.csv`` rows.

    Returns
    -------
    list of dict
        Per run: imposed count, friction, status, nodes, DC, settling time and, where its
        ``summary.json`` has them, ``U``, ``V`` and ``Pi`` = U + V [J]; friction-on runs first,
        each by imposed count.
    """
    table = []
    for rec in records:
        row = {"name": rec["name"], "imposed": int(rec["load.perturbation.n_lobes"]),
               "friction": rec["material.friction"] == "true", "status": rec["status"],
               "nodes": rec.get("nodes"), "DC": rec.get("DC_percent"),
               "settled_at": rec.get("settling_time_s")}
        summary = Path(out) / rec["run_dir"] / "summary.json"
        if summary.exists():
            final = json.loads(summary.read_text()).get("final") or {}
            if "strain" in final and "external_potential" in final:
                row["U"] = float(final["strain"])
                row["V"] = float(final["external_potential"])
                row["Pi"] = row["U"] + row["V"]
        table.append(row)
    return sorted(table, key=lambda r: (not r["friction"], r["imposed"]))


def _num(x, fmt):
    try:
        return format(float(x), fmt)
    except (TypeError, ValueError):
        return "–"


def markdown(table) -> str:
    """The :func:`energy_table` as a markdown table (energies in mJ), and the sentence naming
    the settled frictionless state of least energy."""
    lines = ["| imposed n | friction | status | settled nodes | DC [%] | settled at [s] | U [mJ] | V [mJ] | Π = U + V [mJ] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in table:
        lines.append(f"| {r['imposed']} | {'on' if r['friction'] else 'off'} | {r['status']} | "
                     f"{r['nodes'] if r['nodes'] not in (None, '') else '–'} | {_num(r['DC'], '.1f')} | "
                     f"{_num(r['settled_at'], '.2f')} | {_num(r.get('U', None) and 1e3 * r['U'], '.4f')} | "
                     f"{_num(r.get('V', None) and 1e3 * r['V'], '.4f')} | "
                     f"{_num(r.get('Pi', None) and 1e3 * r['Pi'], '.4f')} |")
    free = [r for r in table if not r["friction"] and "Pi" in r and r["status"] == "settled"]
    if free:
        best = min(free, key=lambda r: r["Pi"])
        lines.append("")
        lines.append(f"Without friction the lowest energy is the {best['nodes']}-node state "
                     f"(imposed {best['imposed']}, Π = {1e3 * best['Pi']:.4f} mJ).")
    return "\n".join(lines)


def measured_nodes(case_path) -> int | None:
    """``[measured] nodes`` of a validation case file, if it has one."""
    with open(case_path, "rb") as fh:
        nodes = tomllib.load(fh).get("measured", {}).get("nodes")
    return int(nodes) if nodes is not None else None


def energy_figure(table, title: str, measured: int | None = None):
    """``Π`` against the settled node count, friction off and on, each point labelled with its
    imposed count; the measured count as a line.

    Returns a matplotlib ``Figure`` (not attached to pyplot).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4))
    ax = fig.add_subplot()
    for friction, marker, label in ((False, "o", "friction off"), (True, "s", "friction on")):
        pts = [(int(r["nodes"]), 1e3 * r["Pi"], r["imposed"]) for r in table
               if r["friction"] == friction and "Pi" in r and r["nodes"] not in (None, "")]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker, label=label, ms=7, alpha=0.8)
            for x, y, n in pts:
                ax.annotate(f"{n}", (x, y), textcoords="offset points", xytext=(5, 3), fontsize=8)
    if measured is not None:
        ax.axvline(measured, color="k", ls="--", lw=1, label=f"measured ({measured} nodes)")
    ax.set_xlabel("settled node count (labels: imposed n)")
    ax.set_ylabel("total potential energy Π = U + V [mJ]")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    return fig


def run_fold_preference(case, lobes, out, *, amplitude: float = 0.1, overrides=(), workers=None,
                        resume: bool = False) -> str:
    """Run the study on the Cusick case file ``case`` as one sweep into ``out``.

    Parameters
    ----------
    case : path
        A Cusick case file.
    lobes : list of int
        The imposed fold counts.
    out : path
        The sweep's folder; ``fold_preference.md`` and ``fold_preference.png`` are written there.
    amplitude : float
        The lobed perturbation's amplitude, of the weight.
    overrides : sequence of str
        ``--set`` items of every run.
    workers : int, optional
        Worker processes (default: one per core).
    resume : bool
        Keep the finished runs of ``out`` and run the others.

    Returns
    -------
    str
        The markdown (:func:`markdown`).

    Raises
    ------
    drape.batch.rows.SweepError
        The sweep cannot run (a bad case or row, a folder of another sweep).
    """
    out = Path(out)
    run_sweep(case, fold_rows(lobes, amplitude), out, overrides=list(overrides), workers=workers,
              resume=resume)
    table = energy_table(out, read_results(out / "results.csv"))
    text = markdown(table)
    (out / "fold_preference.md").write_text(text + "\n")
    energy_figure(table, Path(case).stem, measured_nodes(case)).savefig(out / "fold_preference.png", dpi=120)
    return text
