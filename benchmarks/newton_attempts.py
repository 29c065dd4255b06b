"""Where a drape run's Newton work goes: converged steps against failed (cut) attempts.

Runs a case through the case runner with :func:`drape.solvers.newton.newton` wrapped by a timer, and
prints the wall time of the whole run, of the Newton runs of steps that converged and of
those that failed (the integrator then halves the step), each failed step's attempts (start,
iterations, tangent, seconds), and how often the fallback start rescued a step::

    python benchmarks/newton_attempts.py cases/cusick_fabric1.toml
    python benchmarks/newton_attempts.py cases/cusick_kes.toml --set material.kes.B_warp=0.019 ...
    python benchmarks/newton_attempts.py cases/cusick_fabric1.toml --stall 0   # without the stall rule

Counts are deterministic; times only mean something on an otherwise idle machine.
"""
from __future__ import annotations

import argparse
import collections
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("case", help="case file (TOML)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="case override")
    p.add_argument("--stall", type=int, default=None,
                   help="NewtonPolicy.stall_iterations for this run (default: the shipped one)")
    p.add_argument("--out", default=None, help="output directory (default: a temporary one)")
    args = p.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from drape.solvers import newmark
    from drape.run import runner
    from drape.case.case import load_case

    calls = []
    newton = newmark.newton

    def timed(problem, x0, tolerances, policy, solver):
        if args.stall is not None:
            policy = dataclasses.replace(policy, stall_iterations=args.stall)
        t0 = time.perf_counter()
        result = newton(problem, x0, tolerances, policy, solver)
        calls.append((round(problem.t1, 9), problem.dt, result.converged, result.iterations,
                      result.tangent, time.perf_counter() - t0, policy.tangents[0]))
        return result

    newmark.newton = timed  # the integrator looks the name up at each step
    case = load_case(args.case, args.set)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        summary = runner.run_case(case, args.out or tmp, quiet=True)
        wall = time.perf_counter() - t0
    steps = collections.defaultdict(list)
    for call in calls:
        steps[call[:2]].append(call)
    ok = [c for c in calls if c[2]]
    failed = [c for c in calls if not c[2]]
    rescued = sum(1 for v in steps.values() if len(v) > 1 and v[-1][2])
    by_fallback_tangent = sum(1 for c in ok if c[4] != c[6])
    print(f"{case.case.name}: {summary['status']} ({summary['reason'][:80]})")
    print(f"wall {wall:.1f} s; converged Newton runs {len(ok)}: {sum(c[5] for c in ok):.1f} s, "
          f"{sum(c[3] for c in ok)} iterations; failed Newton runs {len(failed)}: "
          f"{sum(c[5] for c in failed):.1f} s, {sum(c[3] for c in failed)} iterations; "
          f"steps rescued by the fallback start: {rescued}; by a fallback tangent: {by_fallback_tangent}")
    for (t, dt), runs in steps.items():
        if any(not c[2] for c in runs):
            attempts = ", ".join(f"{'ok' if c[2] else 'failed'} {c[3]} it {c[5]:.1f} s" for c in runs)
            print(f"  t = {t:.4g} s, dt = {dt:.3g} s: {attempts}")
    analysis = summary.get("analysis") or {}
    if "drape_coefficient_percent" in analysis:
        print(f"DC {analysis['drape_coefficient_percent']:.4f} %, {analysis.get('n_nodes')} nodes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
