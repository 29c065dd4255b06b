"""A validation set: simulated drape against measured drape, side by side.

``python -m drape.validate [DIR] [--seeds N] [--out OUT] [--set KEY=VALUE ...]``

Every case file in ``DIR`` (default ``cases/validation``) is a Cusick case with a
``[measured]`` table (the real test's drape coefficient and nodes, their source and setup).
Each runs as a seed ensemble through :mod:`drape.batch.sweep` (``--seeds N``, default 1) into
``OUT/<case file stem>/`` (``results.csv``, ``ensemble.json``, ``report.html``, the runs);
``--set`` applies to every case and run. Then the command prints one line per fabric, the
simulated DC (mean ± sample standard deviation over the seeds) and node count (the most frequent
count, how many seeds agreed, the mean) beside the measured ones and their differences, and
writes ``OUT/validation.json`` (the same, with every seed's value) and ``OUT/validation.png``
(the top view of each fabric, from the first seed giving the most frequent node count, titled
with its simulated and measured values). ``--resume`` continues a stopped validation.

Exit codes: 0 every case ran (whatever each run's status), 1 bad input, 130 interrupted,
143 terminated.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from constitutive.bundled import cases_dir
from drape.batch.ensemble import ensembles, seed_rows, write_ensembles
from drape.batch.report import draw_top_view, write_report
from drape.batch.rows import SweepError, read_results
from drape.batch.sweep import run_sweep
from drape.batch.sweep_cli import add_batch_options
from drape.case.case import CaseError, load_case
from drape.run.cli import EXIT_BAD_INPUT, EXIT_IO, describe
from drape.run.output import read_pvd
from drape.run.termination import sigterm_raises, stopped

__all__ = ["ValidationSetError", "validation_cases", "run_validation", "comparison_table",
           "validation_figure", "main"]

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


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (:data:`drape.run.cli.EXIT_CODES`)."""
    p = argparse.ArgumentParser(prog="python -m drape.validate", description=(
        "Run the validation cases (Cusick cases with a [measured] table) as seed ensembles and "
        "print simulated against measured drape; writes OUT/validation.json and validation.png."))
    p.add_argument("directory", nargs="?", default=str(DEFAULT_DIR),
                   help="folder of validation case files (default: cases/validation)")
    p.add_argument("--seeds", type=int, default=1, metavar="N",
                   help="perturbation seeds per case, 0..N-1 (default 1)")
    p.add_argument("--out", default="out/validation", metavar="OUT", help="output folder")
    add_batch_options(p, resume="continue a stopped validation in OUT")
    args = p.parse_args(argv)
    out = Path(args.out)
    try:
        if args.seeds < 1:
            raise ValidationSetError(f"--seeds = {args.seeds}: must be >= 1")
        out.mkdir(parents=True, exist_ok=True)
        with sigterm_raises():
            records = run_validation(args.directory, out, seeds=args.seeds,
                                     overrides=args.overrides, workers=args.workers,
                                     scheduler=args.scheduler, resume=args.resume,
                                     quiet=args.quiet)
    except (ValidationSetError, SweepError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:                 # the folder cannot be written, or is in use
        print(f"error: {describe(exc)}", file=sys.stderr)
        return EXIT_IO
    except KeyboardInterrupt as exc:
        return stopped(exc, "validation", f"continue with --resume --out {out}")
    print(comparison_table(records))
    png = out / "validation.png"
    validation_figure(records).savefig(png, dpi=110)
    print(f"top views in {png}; details in {out / 'validation.json'} and {out}/*/report.html")
    return 0


if __name__ == "__main__":
    from drape.batch.validation_set import (
        main as _main,  # the imported module's main: its classes are the ones raised
    )

    sys.exit(_main())
