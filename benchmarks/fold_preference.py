"""Which node count does the model itself prefer? Cusick drapes forced into n folds, compared by energy.

A drape's node count may come from the fabric (the equilibrium of lowest energy) or from the
path that led to it (friction and damping freeze the first folds that form). This study
separates the two. Each run imposes one fold mode ``n`` with a strong transient load
(``load.perturbation.kind = "lobed"``, ``n_lobes = n``, amplitude ``--amplitude`` of the
weight, default 0.1, five times the default random perturbation's), with the friction of the
case and without it, and lets the specimen settle by the static-balance rule. The table
gives, for every run, the node count it settled in and its total potential energy
``Π = U + V`` (strain energy plus the weight's potential, from ``summary.json``):

- without friction, the settled states are equilibria of the elastic fabric alone, so the
  lowest ``Π`` among them is the node count the model prefers. If a forced mode does not
  hold (the run settles in another count), that mode is not even a stable equilibrium;
- with friction, the forced counts that hold show which drapes the hysteresis can freeze.

Usage::

    python benchmarks/fold_preference.py cases/validation/wool_tropical.toml --lobes 4,5,6,8,10 \\
        --out out/folds_wool
    python benchmarks/fold_preference.py cases/validation/cotton_broadcloth.toml --lobes 2,3,4,6 \\
        --out out/folds_cotton
    python benchmarks/fold_preference.py CASE --tiny --out /tmp/folds   (the plumbing, in seconds)

The runs go through :mod:`drape.batch.sweep` (Dask, ``--workers``, ``--resume``); the table is
printed and written to ``OUT/fold_preference.md``, and ``Π`` against the settled node count
to ``OUT/fold_preference.png``.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: A coarse, short version of any Cusick case: checks the plumbing, its figures mean nothing.
TINY = ["mesh.n_radial=2", "mesh.n_circumferential=24", "solver.t_end=0.05"]


def rows_for(lobes, amplitude):
    """One sweep row per imposed fold count and friction setting."""
    from drape.batch.rows import SweepRow

    rows = []
    for n in lobes:
        for friction in ("true", "false"):
            keys = {"load.perturbation.kind": "lobed", "load.perturbation.n_lobes": str(n),
                    "load.perturbation.amplitude": repr(amplitude), "material.friction": friction}
            rows.append(SweepRow(f"n{n}_{'friction' if friction == 'true' else 'frictionless'}", keys))
    return rows


def energy_table(out: Path, records) -> list[dict]:
    """The sweep's records with the settled state's energies from each run's summary.json."""
    table = []
    for rec in records:
        row = {"name": rec["name"], "imposed": int(rec["load.perturbation.n_lobes"]),
               "friction": rec["material.friction"] == "true", "status": rec["status"],
               "nodes": rec.get("nodes"), "DC": rec.get("DC_percent"),
               "settled_at": rec.get("settling_time_s")}
        summary = out / rec["run_dir"] / "summary.json"
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
    """``[measured] nodes`` of a validation case, if it has one."""
    import tomllib

    with open(case_path, "rb") as fh:
        nodes = tomllib.load(fh).get("measured", {}).get("nodes")
    return int(nodes) if nodes is not None else None


def plot(table, path: Path, title: str, measured: int | None = None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
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
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("case", help="a Cusick case file (TOML)")
    p.add_argument("--lobes", default="4,5,6,8,10", help="imposed fold counts, comma-separated")
    p.add_argument("--amplitude", type=float, default=0.1, help="perturbation amplitude (of the weight)")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides",
                   help="override a case key in every run")
    p.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    p.add_argument("--resume", action="store_true", help="keep finished runs of OUT and run the others")
    p.add_argument("--tiny", action="store_true", help="coarse and short: checks the plumbing only")
    args = p.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from drape.batch.rows import SweepError, read_results
    from drape.batch.sweep import run_sweep

    try:
        lobes = [int(v) for v in args.lobes.split(",")]
    except ValueError:
        p.error(f"--lobes {args.lobes!r}: expected integers such as 4,5,6")
    if not lobes or min(lobes) < 1:
        p.error("--lobes: every fold count must be >= 1")
    out = Path(args.out).resolve()
    overrides = (TINY if args.tiny else []) + args.overrides
    try:
        run_sweep(args.case, rows_for(lobes, args.amplitude), out, overrides=overrides,
                  workers=args.workers, resume=args.resume)
    except SweepError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    table = energy_table(out, read_results(out / "results.csv"))
    text = markdown(table)
    print(text)
    (out / "fold_preference.md").write_text(text + "\n")
    plot(table, out / "fold_preference.png", Path(args.case).stem, measured_nodes(args.case))
    print(f"\nwritten: {out / 'fold_preference.md'}, {out / 'fold_preference.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
