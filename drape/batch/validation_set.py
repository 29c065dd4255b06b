"""A validation set: simulated drape against measured drape, side by side.

Every case file in a folder (default :data:`DEFAULT_DIR`, ``cases/validation``) is a Cusick
case with a ``[measured]`` table (the real test's drape coefficient and nodes, their source and
setup). :func:`run_validation` runs each as a seed ensemble through :mod:`drape.batch.sweep`
into ``OUT/<case file stem>/`` (``results.csv``, ``ensemble.json``, ``report.html``, the runs)
and writes ``OUT/validation.json``: the simulated DC (mean ± sample standard deviation over
the seeds) and node count (the most frequent count, how many seeds agreed, the mean) beside
the measured ones, with every seed's value. :func:`comparison_table` prints them one line per
fabric, :func:`validation_figure` draws the top view of each fabric (from the first seed giving
the most frequent node count). The command line is ``python -m drape.validate``
(:mod:`drape.cli.validate`).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from constitutive.bundled import cases_dir
from drape.batch.ensemble import ensembles, seed_rows, write_ensembles
from drape.batch.report import draw_top_view, write_report
from drape.batch.rows import read_results
from drape.batch.sweep import run_sweep
from drape.case.case import CaseError, load_case
from drape.run.output import read_pvd

__all__ = ["DEFAULT_DIR", "ValidationSetError", "validation_cases", "run_validation",
           "comparison_table", "validation_figure"]

DEFAULT_DIR = cases_dir("validation")


class ValidationSetError(ValueError):
    """A validation folder or case breaks a rule (the message names it)."""


def validation_cases(directory, overrides: list[str] | None = None) -> list[tuple[Path, object]]:
    """The case files of ``directory`` with their validated cases (each a Cusick case with a
    ``[measured]`` table), sorted by file name."""
    directory = Path(directory)
    paths = sorted(directory.glob("*.toml")) if directory.is_dir() else []
    if not paths:
        raise ValidationSetError(f"{directory}: no case files (*.toml)")
    out = []
    for path in paths:
        try:
            case = load_case(path, overrides)
        except CaseError as exc:
            raise ValidationSetError(f"{path}: {exc}") from None
        if case.measured is None or case.case.analysis != "cusick":
            raise ValidationSetError(f"{path}: a validation case needs case.analysis = 'cusick' "
                                     "and a [measured] table")
        out.append((path, case))
    return out


def _representative_vtu(out: Path, ensemble: dict) -> str | None:
    """The last VTU of the first seed whose node count is the ensemble's most frequent."""
    for rec in read_results(out / "results.csv"):
        if rec["name"] in ensemble["DC_percent"]["values"] and rec.get("nodes") not in (None, "") \
                and int(float(rec["nodes"])) == ensemble["nodes"]["mode"] and rec.get("pvd"):
            pvd = out / rec["run_dir"] / rec["pvd"]
            steps = read_pvd(pvd) if pvd.exists() else []
            if steps:
                return str(steps[-1][1])
    return None


def run_validation(directory, out, *, seeds: int = 1, overrides: list[str] | None = None,
                   workers: int | None = None, scheduler: str | None = None,
                   resume: bool = False, quiet: bool = False) -> list[dict]:
    """Run every case of ``directory`` as a seed ensemble into ``out/<stem>``; return one
    comparison record per case (also written to ``out/validation.json``)."""
    out = Path(out)
    records = []
    for path, case in validation_cases(directory, overrides):
        folder = out / path.stem
        rows = seed_rows(None, seeds, path.stem)
        if not quiet:
            print(f"{path.stem}: {seeds} seed(s) into {folder}", file=sys.stderr)
        run_sweep(path, rows, folder, overrides=overrides, scheduler=scheduler, workers=workers,
                  resume=resume, quiet=quiet)
        write_ensembles(folder)
        write_report(folder)
        (ensemble,) = ensembles(folder)
        mesh = case.mesh
        records.append({
            "case": str(path), "name": path.stem, "description": case.case.description,
            "setup": f"{100 * mesh.specimen_diameter:.1f} cm on {100 * mesh.disc_diameter:.1f} cm",
            "measured": case.measured.model_dump(), "simulated": ensemble,
            "top_view_vtu": _representative_vtu(folder, ensemble), "folder": str(folder)})
    (out / "validation.json").write_text(json.dumps(records, indent=1))
    return records


def _f(x, fmt=".1f", none="-"):
    return none if x is None else format(x, fmt)


def comparison_table(records: list[dict]) -> str:
    """The side-by-side table printed by the command (one line per fabric).

    >>> rec = {"name": "wool", "setup": "25.4 cm on 12.7 cm",
    ...        "measured": {"DC_percent": 49.8, "nodes": 5},
    ...        "simulated": {"finished": 3, "runs": 3,
    ...                      "DC_percent": {"mean": 55.0, "std": 1.5},
    ...                      "nodes": {"mode": 6, "mode_count": 2, "mean": 6.3}}}
    >>> print(comparison_table([rec]))  # doctest: +NORMALIZE_WHITESPACE
    fabric  setup               seeds  DC sim [%]   DC meas [%]  ΔDC    nodes sim (agree, mean)  nodes meas  Δnodes
    wool    25.4 cm on 12.7 cm  3/3    55.0 ± 1.5   49.8         +5.2   6 (2/3, 6.3)             5           +1
    """
    head = ["fabric", "setup", "seeds", "DC sim [%]", "DC meas [%]", "ΔDC",
            "nodes sim (agree, mean)", "nodes meas", "Δnodes"]
    lines = [head]
    for r in records:
        sim, meas = r["simulated"], r["measured"]
        dc, nodes = sim["DC_percent"], sim["nodes"]
        dc_sim = _f(dc["mean"]) + ("" if dc["std"] is None else f" ± {dc['std']:.1f}")
        d_dc = (None if dc["mean"] is None or meas["DC_percent"] is None
                else dc["mean"] - meas["DC_percent"])
        d_n = (None if nodes["mode"] is None or meas["nodes"] is None
               else nodes["mode"] - meas["nodes"])
        n_sim = ("-" if nodes["mode"] is None else
                 f"{nodes['mode']} ({nodes['mode_count']}/{sim['finished']}, {_f(nodes['mean'])})")
        lines.append([r["name"], r["setup"], f"{sim['finished']}/{sim['runs']}", dc_sim,
                      _f(meas["DC_percent"]), _f(d_dc, "+.1f"), n_sim, _f(meas["nodes"], "d"),
                      _f(d_n, "+d")])
    widths = [max(len(str(row[i])) for row in lines) for i in range(len(head))]
    return "\n".join("  ".join(str(c).ljust(w) for c, w in zip(row, widths)).rstrip()
                     for row in lines)


def validation_figure(records: list[dict], size: float = 3.6):
    """One top view per fabric (simulated), titled with the simulated and measured values.

    Returns a matplotlib ``Figure`` (not attached to pyplot).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(size * len(records), size + 0.8), layout="constrained")
    for i, r in enumerate(records):
        ax = fig.add_subplot(1, len(records), i + 1)
        sim, meas = r["simulated"], r["measured"]
        if r.get("top_view_vtu"):
            draw_top_view(ax, r["top_view_vtu"])
        else:
            ax.text(0.5, 0.5, "no finished run", ha="center", transform=ax.transAxes)
            ax.set_axis_off()
        ax.set_title(f"{r['name']} ({r['setup']})\n"
                     f"simulated DC {_f(sim['DC_percent']['mean'])} %, {_f(sim['nodes']['mode'], 'd')} nodes\n"
                     f"measured DC {_f(meas['DC_percent'])} %, {_f(meas['nodes'], 'd')} nodes",
                     fontsize=9)
    return fig
