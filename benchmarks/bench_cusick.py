"""Cusick drape benchmark: mesh, perturbation and stop studies run through the case runner.

Studies (each a set of runs of cases/cusick_*.toml with dotted overrides):

* ``fabrics``      Fabric 1, Fabric 2 and the KES-only material (cases/cusick_*.toml as they are):
                   DC, nodes, node depths, settling time, wall time.
* ``friction``     Fabric 1 with and without the dry-friction (hysteresis) moment.
* ``sweep``        Fabric 1 with every bending moment scaled ([material] bending_scale = s:
                   k1, k3, d, f1, f2 x s), s = 100, 30, 10, 3, 1, i.e. warp bending length
                   c = (k1/(rho_A g))^(1/3) = 3.3 ... 0.72 cm, plus s = 1000 (c = 7.2 cm, more
                   than the 6 cm overhang): DC must fall monotonically as s falls, and the stiff
                   one must stay near 100 %.
* ``convergence``  Fabric 1 on the default mesh (6 x 72, radial_grading 4), on 8 x 96 (x4/3) and
                   on one uniform refinement (mesh.refine = 1, 12 x 144; about 35 minutes): DC change
                   (points) and node counts. Add e.g. ``--set material.bending_scale=10`` for a
                   stiffer member of the sweep.

Usage::

    python benchmarks/bench_cusick.py --study fabrics --out out/bench_cusick
    python benchmarks/bench_cusick.py --study all --jobs 2        (long: several runs of minutes)

Every run writes its own directory (VTU series, summary.json, top-view PNG); the script prints a
table and writes ``results.json`` and, for the sweep, ``dc_vs_bending_length.png``.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
G = 9.80665
#: Bending-moment scales of Fabric 1 in the sweep, stiff to limp, and the one stiffer than
#: its weight (bending length > overhang).
SWEEP_SCALES = (100, 30, 10, 3, 1)
STIFF_SCALE = 1000
#: Finer meshes of the convergence study (the default is 6 x 72, radial_grading 4): 4/3 of
#: its density, and one uniform refinement (every triangle split in four).
CONVERGENCE_MESHES = {"fabric1_8x96": ["mesh.n_radial=8", "mesh.n_circumferential=96"],
                      "fabric1_refine1": ["mesh.refine=1"]}


def _run(args):
    """Run one case with overrides in a fresh process; return a compact record."""
    label, case_file, overrides, out = args
    sys.path.insert(0, str(ROOT))
    from drape.case import load_case
    from drape.run import run_case

    case = load_case(ROOT / case_file, overrides)
    t0 = time.perf_counter()
    try:
        s = run_case(case, out, quiet=True)
    except Exception as err:  # noqa: BLE001 - report and go on with the other runs
        return dict(label=label, error=f"{type(err).__name__}: {err}", wall_s=time.perf_counter() - t0)
    a = s.get("analysis", {})
    return dict(label=label, case=case_file, overrides=overrides, status=s.get("status"),
                reason=s.get("reason"), dc_percent=a.get("drape_coefficient_percent"),
                dc_vertices_percent=a.get("drape_coefficient_vertices_percent"),
                n_nodes=a.get("n_nodes"), node_depths_mm=[1e3 * d for d in a.get("node_depths_m", [])],
                settling_time_s=s.get("settling_time"), t_final_s=s.get("t_final"),
                steps=s.get("steps"), wall_s=time.perf_counter() - t0, out=str(out))


def bending_length(scale: float, direction: str = "warp") -> float:
    """Bending length c = (k1/(rho_A g))^(1/3) [m] of Fabric 1 with its moments times ``scale``."""
    from constitutive.material import load_material

    m = load_material("fabric1")
    return (scale * getattr(m, direction).k1 / (m.areal_mass * G)) ** (1 / 3)


def studies(which: list[str], extra: list[str]):
    """Runs ``(label, case file, overrides)`` of the chosen studies; a run that two studies
    share (Fabric 1 as it is: fabrics, friction, sweep s = 1, convergence) is made once."""
    runs = {}

    def add(label, case, overrides=()):
        runs.setdefault(label, (label, case, list(overrides) + list(extra)))

    if "fabrics" in which:
        for name in ("cusick_fabric1", "cusick_fabric2", "cusick_kes"):
            add(name, f"cases/{name}.toml")
    if "friction" in which:
        for name, label in (("cusick_fabric1", "fabric1"), ("cusick_kes", "kes")):
            add(name, f"cases/{name}.toml")
            add(f"{label}_no_friction", f"cases/{name}.toml", ["material.friction=false"])
    if "sweep" in which:
        for scale in SWEEP_SCALES + (STIFF_SCALE,):
            if scale == 1:
                add("cusick_fabric1", "cases/cusick_fabric1.toml")
            else:
                add(f"sweep_s{scale:g}", "cases/cusick_fabric1.toml", [f"material.bending_scale={scale!r}"])
    if "convergence" in which:
        add("cusick_fabric1", "cases/cusick_fabric1.toml")
        for label, overrides in CONVERGENCE_MESHES.items():
            add(label, "cases/cusick_fabric1.toml", overrides)
    return list(runs.values())


def _table(records):
    head = f"{'run':22s} {'status':9s} {'DC %':>6s} {'nodes':>5s} {'depth mm (mean)':>15s} " \
           f"{'settle s':>8s} {'steps':>5s} {'wall s':>7s}"
    lines = [head, "-" * len(head)]
    for r in records:
        if "error" in r:
            lines.append(f"{r['label']:22s} ERROR {r['error']}")
            continue
        d = r["node_depths_mm"]
        depth = f"{sum(d) / len(d):.1f}" if d else "-"
        st = r["settling_time_s"]
        lines.append(f"{r['label']:22s} {str(r['status']):9s} {r['dc_percent']:6.1f} {r['n_nodes']:5d} "
                     f"{depth:>15s} {('%.2f' % st) if st is not None else '-':>8s} "
                     f"{r['steps']:5d} {r['wall_s']:7.0f}")
    return "\n".join(lines)


def _checks(records):
    by = {r["label"]: r for r in records if "error" not in r}
    out = []
    sweep = [by.get("cusick_fabric1" if s == 1 else f"sweep_s{s:g}") for s in SWEEP_SCALES]
    if all(sweep):
        dcs = [r["dc_percent"] for r in sweep]
        mono = all(a > b for a, b in zip(dcs, dcs[1:]))
        cs = ", ".join(f"{100 * bending_length(s):.2f}" for s in SWEEP_SCALES)
        out.append(f"sweep DC (bending_scale {', '.join(f'{s:g}' for s in SWEEP_SCALES)}; warp c = {cs} cm): "
                   f"{', '.join(f'{d:.1f}' for d in dcs)} % -> monotonic decrease: {mono}")
    stiff = by.get(f"sweep_s{STIFF_SCALE:g}")
    if stiff:
        out.append(f"stiff (bending_scale {STIFF_SCALE:g}, warp c = {100 * bending_length(STIFF_SCALE):.1f} cm "
                   f">= 6 cm overhang): DC = {stiff['dc_percent']:.1f} %")
    for name in ("fabric1", "kes"):
        a, b = by.get(f"cusick_{name}"), by.get(f"{name}_no_friction")
        if a and b:
            out.append(f"friction ({name}): DC {a['dc_percent']:.2f} % vs friction-free {b['dc_percent']:.2f} % "
                       f"(difference {a['dc_percent'] - b['dc_percent']:+.2f} points; nodes {a['n_nodes']} vs "
                       f"{b['n_nodes']})")
    for fine in CONVERGENCE_MESHES:
        if "cusick_fabric1" in by and fine in by:
            a, b = by["cusick_fabric1"], by[fine]
            out.append(f"convergence ({fine}): DC {a['dc_percent']:.2f} -> {b['dc_percent']:.2f} % "
                       f"(|change| {abs(a['dc_percent'] - b['dc_percent']):.2f} points, rule < 2); "
                       f"nodes {a['n_nodes']} -> {b['n_nodes']}")
    return out


def _plot_sweep(records, out_dir: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pts = []
    for r in records:
        scale = 1.0 if r["label"] == "cusick_fabric1" else None
        if r["label"].startswith("sweep_s"):
            scale = float(r["label"].removeprefix("sweep_s"))
        if scale is not None and "error" not in r:
            pts.append((100 * bending_length(scale), r["dc_percent"]))
    if not pts:
        return None
    pts.sort()
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot(*zip(*pts), "o-")
    ax.axvline(6.0, ls="--", color="0.5", label="overhang 6 cm")
    ax.set_xscale("log")
    ax.set_xlabel("warp bending length c = (k1 / rho_A g)^(1/3) [cm] (Fabric 1 x bending_scale)")
    ax.set_ylabel("drape coefficient [%]")
    ax.set_ylim(0, 105)
    ax.legend()
    fig.tight_layout()
    path = out_dir / "dc_vs_bending_length.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--study", nargs="+", default=["fabrics"],
                    choices=["fabrics", "friction", "sweep", "convergence", "all"],
                    help="which studies to run (default: fabrics)")
    ap.add_argument("--out", default="out/bench_cusick", help="output directory")
    ap.add_argument("--jobs", type=int, default=1, help="runs in parallel (processes)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="extra override for every run, e.g. --set solver.t_end=1.0")
    ap.add_argument("--only", nargs="*", default=None, help="run only these labels")
    args = ap.parse_args(argv)
    which = ["fabrics", "friction", "sweep", "convergence"] if "all" in args.study else args.study
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = studies(which, args.set)
    if args.only:
        runs = [r for r in runs if r[0] in args.only]
    todo = [(label, case, over, out / label) for label, case, over in runs]
    print(f"{len(todo)} runs, {args.jobs} at a time, {os.cpu_count()} cpus", flush=True)
    t0 = time.perf_counter()
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            records = list(pool.map(_run, todo))
    else:
        records = [_run(t) for t in todo]
    print(_table(records))
    for line in _checks(records):
        print(line)
    fig = _plot_sweep(records, out)
    if fig:
        print(f"figure: {fig}")
    (out / "results.json").write_text(json.dumps(records, indent=2))
    print(f"total wall {time.perf_counter() - t0:.0f} s; results in {out / 'results.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
