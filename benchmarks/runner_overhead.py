"""Share of wall time the case runner itself takes (history row, fields, VTU/PVD writes, settling check).

Runs a case through ``drape.run.runner.run_case`` under cProfile and prints the time spent in the runner's
per-step callback (``_Recorder.__call__``) against the whole integration.

    python benchmarks/runner_overhead.py [CASE.toml] [--set key=value ...]

Default: cases/kes_strip.toml with solver.dt = 0.05 (a cheap model, so the overhead shows).
"""
from __future__ import annotations

import cProfile
import pstats
import sys
import tempfile
import time
from pathlib import Path

from drape.case.case import load_case
from drape.run.runner import run_case

ROOT = Path(__file__).resolve().parents[1]


def main(argv):
    case_file = argv[0] if argv and not argv[0].startswith("--") else str(ROOT / "cases" / "kes_strip.toml")
    overrides = [a.split("=", 1)[0] + "=" + a.split("=", 1)[1] for a in argv[1:] if "=" in a]
    if not overrides and case_file.endswith("kes_strip.toml"):
        overrides = ["solver.dt=0.05"]
    case = load_case(case_file, overrides)
    with tempfile.TemporaryDirectory() as out:
        prof = cProfile.Profile()
        t0 = time.perf_counter()
        prof.enable()
        summary = run_case(case, out, quiet=True)
        prof.disable()
        wall = time.perf_counter() - t0
    stats = pstats.Stats(prof)
    rows = {}
    for k, v in stats.stats.items():   # keep the largest cumulative time per file:function
        key = f"{Path(k[0]).name}:{k[2]}"
        rows[key] = max(rows.get(key, 0.0), v[3])
    callback = rows.get("run.py:__call__", float("nan"))   # _Recorder.__call__ (the biggest)
    write = rows.get("output.py:write_step", float("nan"))
    integrate = rows.get("newmark.py:integrate", float("nan"))
    steps = summary["steps"]
    print(f"case {case.case.name}: {steps} steps, {summary['vtu_files']} VTU files, wall {wall:.2f} s")
    print(f"  integrate (incl. callback): {integrate:.2f} s")
    print(f"  runner callback per step:   {1e3 * callback / max(steps, 1):.2f} ms "
          f"({100 * callback / integrate:.1f} % of integrate)")
    print(f"  VTU + PVD write per file:   {1e3 * write / max(summary['vtu_files'], 1):.2f} ms")


if __name__ == "__main__":
    main(sys.argv[1:])
