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
* ``speed``        the solver's figures, each run alone: Fabric 1 as it is, four fabrics from
                   their KES sheets (cotton, wool, polyester, limp polyester; B and 2HB both
                   directions, W), the wool without friction, Fabric 1 on one uniform
                   refinement, and the cantilever: wall time, steps, Newton iterations, force
                   evaluations, factorisations and the split between assembly, law, linear
                   solve and output (``summary.json`` ``profile``). ``--code DIR`` runs the
                   same cases with another checkout (e.g. an older commit; its own case files)
                   for a side-by-side.
* ``robustness``   KES fabrics B = 0.01, 0.03, 0.1, 0.3 gf·cm²/cm, W = 8, 25 mg/cm², 2HB = 0.4 B
                   and 1.2 B (per cm), with friction, and each (B, W) without: every run must settle.
* ``timestep``     the two validation fabrics (cases/validation/, seed 0) with the step of the
                   lowering (``solver.dt``, the cases' own and 0.025 and 0.01 s): DC change
                   (points) and node counts against the finest step.
* ``convergence``  Fabric 1 on the default mesh (6 x 72, radial_grading 4), on 8 x 96 (x4/3) and
                   on one uniform refinement (mesh.refine = 1, 12 x 144; about 35 minutes): DC change
                   (points) and node counts. Add e.g. ``--set material.bending_scale=10`` for a
                   stiffer member of the sweep.

Usage::

    python benchmarks/bench_cusick.py --study fabrics --out out/bench_cusick
    python benchmarks/bench_cusick.py --study all --jobs 2        (long: several runs of minutes)
    python benchmarks/bench_cusick.py --study speed --only cusick_fabric1 --set solver.t_end=0.3 --code ../old

Every run writes its own directory (VTU series, summary.json, top-view PNG); the script prints a
table and writes ``results.json`` and, for the sweep, ``dc_vs_bending_length.png``.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
import subprocess
from concurrent.futures import ThreadPoolExecutor
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


#: Steps of the lowering tried against the validation cases' own ``solver.dt``.
TIMESTEP_DTS = (0.025, 0.01)
#: The cases of the time-step study.
TIMESTEP_CASES = ("wool_tropical", "cotton_broadcloth")

#: KES sheets (B gf·cm²/cm, 2HB gf·cm/cm, W mg/cm²) of the speed study, both directions alike.
KES_FABRICS = {"cotton": (0.118, 0.124, 12.38), "wool": (0.067, 0.033, 16.29),
               "polyester": (0.077, 0.029, 11.65), "limp_polyester": (0.019, 0.007, 10.43)}
#: The robustness grid.
ROBUST_B, ROBUST_W, ROBUST_HB = (0.01, 0.03, 0.1, 0.3), (8.0, 25.0), (0.4, 1.2)


def kes_overrides(B, HB2, W, friction=True):
    keys = [f"material.kes.B_warp={B!r}", f"material.kes.B_weft={B!r}", f"material.kes.HB2_warp={HB2!r}",
            f"material.kes.HB2_weft={HB2!r}", f"material.kes.weight={W!r}"]
    return keys + ([] if friction else ["material.friction=false"])


def _run(args):
    """Run one case with overrides in a fresh ``python -m drape.run`` of checkout ``code``;
    return a compact record from its summary.json."""
    label, case_file, overrides, out, code = args
    code = Path(code or ROOT)
    cmd = [sys.executable, "-m", "drape.run", str(code / case_file), "--out", str(Path(out).resolve()), "--quiet"]
    for o in overrides:
        cmd += ["--set", o]
    env = {**os.environ, "PYTHONPATH": str(code)}
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=code, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    try:
        s = json.loads((Path(out) / "summary.json").read_text())
    except (OSError, ValueError):
        return dict(label=label, error=(proc.stderr.strip().splitlines() or ["no summary"])[-1], wall_s=wall)
    a = s.get("analysis", {})
    return dict(label=label, case=case_file, overrides=overrides, status=s.get("status"),
                reason=s.get("reason"), dc_percent=a.get("drape_coefficient_percent"),
                dc_vertices_percent=a.get("drape_coefficient_vertices_percent"),
                n_nodes=a.get("n_nodes"), node_depths_mm=[1e3 * d for d in a.get("node_depths_m", [])],
                settling_time_s=s.get("settling_time"), t_final_s=s.get("t_final"),
                steps=s.get("steps"), wall_s=wall, run_wall_s=s.get("wall_time_s"),
                simulated_per_wall=s.get("simulated_per_wall"), profile=s.get("profile"),
                tip_drop_m=a.get("tip_drop_m"), out=str(out))


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
    if "speed" in which:
        add("cusick_fabric1", "cases/cusick_fabric1.toml")
        for name, (B, HB2, W) in KES_FABRICS.items():
            add(name, "cases/cusick_kes.toml", kes_overrides(B, HB2, W))
        add("wool_no_friction", "cases/cusick_kes.toml", kes_overrides(*KES_FABRICS["wool"], friction=False))
        add("fabric1_refine1", "cases/cusick_fabric1.toml", ["mesh.refine=1"])
        add("cantilever", "cases/cantilever.toml")
    if "robustness" in which:
        for B in ROBUST_B:
            for W in ROBUST_W:
                for f in ROBUST_HB:
                    add(f"B{B:g}_W{W:g}_2HB{f:g}B", "cases/cusick_kes.toml", kes_overrides(B, f * B, W))
                add(f"B{B:g}_W{W:g}_no_friction", "cases/cusick_kes.toml",
                    kes_overrides(B, 0.4 * B, W, friction=False))
    if "timestep" in which:
        for name in TIMESTEP_CASES:
            add(name, f"cases/validation/{name}.toml")
            for dt in TIMESTEP_DTS:
                add(f"{name}_dt{dt:g}", f"cases/validation/{name}.toml", [f"solver.dt={dt!r}"])
    if "convergence" in which:
        add("cusick_fabric1", "cases/cusick_fabric1.toml")
        for label, overrides in CONVERGENCE_MESHES.items():
            add(label, "cases/cusick_fabric1.toml", overrides)
    return list(runs.values())


def _speed_table(records):
    """Solver figures per run: steps, iterations, evaluations, factorisations (of which by LDLᵀ,
    where a step matrix was not positive definite), steps only a fallback start or tangent
    converged, and the time split."""
    head = (f"{'run':18s} {'status':9s} {'wall s':>7s} {'sim/wall':>8s} {'steps':>5s} {'iter':>5s} {'evals':>5s} "
            f"{'facts':>5s} {'LDLt':>5s} {'resc':>4s} {'assembly':>8s} {'law':>6s} {'linear':>7s} {'output':>7s} {'other':>6s}")
    lines = [head, "-" * len(head)]
    for r in records:
        p = r.get("profile") or {}
        sec = p.get("seconds", {})
        cells = [f"{sec.get(k, float('nan')):8.1f}" for k in ("assembly", "law", "linear_solve", "output", "other")]
        lines.append(f"{r['label']:18s} {str(r.get('status')):9s} {r.get('run_wall_s') or r['wall_s']:7.1f} "
                     f"{r.get('simulated_per_wall') or float('nan'):8.3f} {r.get('steps') or 0:5d} "
                     f"{p.get('newton_iterations', 0):5d} {p.get('evaluations', 0):5d} "
                     f"{p.get('factorizations', 0):5d} {p.get('ldlt_factorizations', 0):5d} "
                     f"{p.get('rescued_steps', 0):4d} "
                     + " ".join(cells))
    return "\n".join(lines)


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
        dc = "-" if r["dc_percent"] is None else f"{r['dc_percent']:.1f}"
        nodes = "-" if r["n_nodes"] is None else str(r["n_nodes"])
        lines.append(f"{r['label']:22s} {str(r['status']):9s} {dc:>6s} {nodes:>5s} "
                     f"{depth:>15s} {('%.2f' % st) if st is not None else '-':>8s} "
                     f"{r['steps'] or 0:5d} {r['wall_s']:7.0f}")
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
    from drape.case.case import load_case

    for name in TIMESTEP_CASES:
        finest = by.get(f"{name}_dt{min(TIMESTEP_DTS):g}")
        if finest is None or name not in by:
            continue
        case_dt = load_case(ROOT / "cases" / "validation" / f"{name}.toml").solver.dt
        steps = [(case_dt, by[name])] + [(dt, by[f"{name}_dt{dt:g}"]) for dt in TIMESTEP_DTS
                                      if f"{name}_dt{dt:g}" in by]
        out.append(f"time step ({name}): " + "; ".join(
            f"dt {dt:g} s: DC {r['dc_percent']:.2f} % ({r['dc_percent'] - finest['dc_percent']:+.2f}), "
            f"{r['n_nodes']} nodes" for dt, r in steps))
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
                    choices=["fabrics", "friction", "sweep", "convergence", "speed", "robustness", "timestep",
                             "all"],
                    help="which studies to run (default: fabrics)")
    ap.add_argument("--out", default="out/bench_cusick", help="output directory")
    ap.add_argument("--jobs", type=int, default=1, help="runs in parallel (processes)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="extra override for every run, e.g. --set solver.t_end=1.0")
    ap.add_argument("--only", nargs="*", default=None, help="run only these labels")
    ap.add_argument("--code", default=None, metavar="DIR",
                    help="run the cases with the checkout in DIR (default: this one)")
    args = ap.parse_args(argv)
    which = ["fabrics", "friction", "sweep", "convergence"] if "all" in args.study else args.study
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = studies(which, args.set)
    if args.only:
        runs = [r for r in runs if r[0] in args.only]
    todo = [(label, case, over, out / label, args.code) for label, case, over in runs]
    print(f"{len(todo)} runs, {args.jobs} at a time, {os.cpu_count()} cpus", flush=True)
    t0 = time.perf_counter()
    if args.jobs > 1:
        from drape.batch.sweep import SINGLE_THREADED

        # one core per run (each a fresh process, so numba's pool size may be set): kernels and PARDISO don't fight
        os.environ.update(SINGLE_THREADED, NUMBA_NUM_THREADS="1")
        with ThreadPoolExecutor(args.jobs) as pool:
            records = list(pool.map(_run, todo))
    else:
        records = [_run(t) for t in todo]
    print(_table(records))
    if "speed" in which or args.code:
        print(_speed_table(records))
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
