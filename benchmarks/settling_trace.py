"""How a run comes to rest: the static out-of-balance, the kinetic energy and the result per step.

Runs a case through the ordinary runner and, for every converged step once the loads stopped
changing, writes ``OUT/settling_trace.csv``: time, step, Newton iterations, the static
out-of-balance over the weight (:mod:`drape.run.settling`), the kinetic energy, and the result the
run is for (Cusick: drape coefficient of the sampled surface and node count; strip: tip drop).
Then it tells, from that trace, when the static-balance rule would have stopped the run for a
few fractions, and when the former kinetic-energy rule (E_kin < c ρ_A g A L for N steps,
A the fabric's area and L its span) would have.

    python benchmarks/settling_trace.py cases/cusick_fabric1.toml --out out/trace_f1 \\
        --set stop.out_of_balance=1e-14 --set solver.t_end=40
    python benchmarks/settling_trace.py --resume out/trace_f1 --set solver.t_end=80

``stop.out_of_balance`` tiny keeps the run going to ``t_end``; ``--resume`` continues a
finished or stopped trace from its checkpoint with the given ``solver`` keys changed.
"""
from __future__ import annotations

import argparse
import csv
import json
import re
from pathlib import Path

import numpy as np

from constitutive.units import G0
from drape.run import runner
from drape.case.case import load_case
from drape.run.recorder import Recorder

FIELDS = ["t", "step", "dt", "iterations", "out_of_balance", "kinetic", "result", "nodes"]


class TracingRecorder(Recorder):
    """The runner's recorder, plus one trace row per step once the loads are constant."""

    path: Path

    def __call__(self, state, info=None):
        stop = super().__call__(state, info)
        if self.settled.ratio is not None:
            row = self.ctx.history[-1]
            result, nodes = _result(self.case, self.ctx.model, state.u)
            new = not self.path.exists()
            with open(self.path, "a", newline="") as fh:
                out = csv.writer(fh)
                if new:
                    out.writerow(FIELDS)
                out.writerow([state.t, row["step"], row["dt"], row["iterations"], self.settled.ratio,
                              row["kinetic"], result, nodes])
        return stop


def _result(case, model, u):
    """(DC [%], nodes) of a Cusick specimen's sampled surface, or (tip drop [m], '') of a strip."""
    if case.mesh.kind == "cusick":
        from drape.analyses.drape_coefficient import drape_analysis

        pts, tri = model.deformed_surface(u)
        res = drape_analysis(pts, tri, 0.5 * case.mesh.specimen_diameter, 0.5 * case.mesh.disc_diameter)
        return 100.0 * res.drape_coefficient, res.n_nodes
    return -float(model.nodal_displacement(u)[:, 2].min()), ""


def _kinetic_reference(case, mesh, areal_mass) -> float:
    """ρ_A g A L of the former kinetic-energy rule (A: mesh area; L: overhang or strip length)."""
    from meshes.quality import triangle_areas

    spec = case.mesh
    span = (0.5 * (spec.specimen_diameter - spec.disc_diameter) if spec.kind == "cusick"
            else spec.length)
    return areal_mass * G0 * float(np.abs(triangle_areas(mesh.p, mesh.t)).sum()) * span


def fires(rows, key, level, steps):
    """First row at which ``key`` stayed below ``level`` for ``steps`` consecutive rows, or None."""
    count = 0
    for row in rows:
        count = count + 1 if row[key] < level else 0
        if count >= steps:
            return row
    return None


def report(out: Path, fractions, kinetic_fractions, steps: int) -> None:
    rows = [{k: float(v) if v != "" else None for k, v in r.items()}
            for r in csv.DictReader(open(out / "settling_trace.csv"))]
    case = load_case(out / "case.resolved.toml")
    from drape.case.build import build_material, build_mesh

    e_ref = _kinetic_reference(case, build_mesh(case), build_material(case).areal_mass)
    last = rows[-1]
    what = "DC %" if case.mesh.kind == "cusick" else "tip drop m"
    print(f"trace {out}: {len(rows)} steps with constant loads, last t = {last['t']:g} s, "
          f"{what} {last['result']:.6g}, out-of-balance {last['out_of_balance']:.2e}")
    for label, key, levels in (("static out-of-balance <", "out_of_balance", fractions),
                               ("kinetic energy < c rho_A g A L, c =", "kinetic", kinetic_fractions)):
        for c in levels:
            level = c * (e_ref if key == "kinetic" else 1.0)
            hit = fires(rows, key, level, steps)
            if hit is None:
                print(f"  {label} {c:g} for {steps} steps: not reached")
            else:
                nodes = "" if hit["nodes"] is None else f", {int(hit['nodes'])} nodes"
                print(f"  {label} {c:g} for {steps} steps: t = {hit['t']:g} s (step {int(hit['step'])}), "
                      f"{what} {hit['result']:.6g}{nodes}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case", nargs="?")
    p.add_argument("--out", type=Path)
    p.add_argument("--resume", type=Path, help="continue the trace in this folder")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--fractions", type=float, nargs="*", default=[1e-2, 3e-3, 2e-3, 1e-3, 3e-4])
    p.add_argument("--kinetic-fractions", type=float, nargs="*", default=[1e-7, 5e-9])
    p.add_argument("--steps", type=int, default=3, help="consecutive steps of each rule")
    p.add_argument("--report-only", action="store_true")
    args = p.parse_args(argv)
    out = args.resume or args.out
    runner.Recorder = TracingRecorder
    TracingRecorder.path = out / "settling_trace.csv"
    if not args.report_only:
        if args.resume:
            resolved = out / "case.resolved.toml"
            text = resolved.read_text()
            for item in args.set:                 # only solver keys: the rest must not change
                key, value = item.split("=", 1)
                if not key.startswith("solver."):
                    raise SystemExit(f"--resume takes only solver.* keys, got {key}")
                text = re.sub(rf"(?m)^({re.escape(key.split('.', 1)[1])} = ).*$", rf"\g<1>{value}", text)
            resolved.write_text(text)
            (out / "summary.json").unlink(missing_ok=True)
            summary = runner.resume_run(out, quiet=True)
        else:
            summary = runner.run_case(load_case(args.case, args.set), out, quiet=True, source=args.case)
        print(json.dumps({k: summary.get(k) for k in ("status", "reason", "t_final", "steps")}))
    report(out, args.fractions, args.kinetic_fractions, args.steps)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
