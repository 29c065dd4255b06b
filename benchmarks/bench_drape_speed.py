"""How long a drape takes: the let-down Cusick case, Fabric 1's Cusick case and a limp fabric.

Each case runs alone, one after another, as ``python -m drape.run`` in a fresh process of the
code tree given with ``--code`` (its own ``drape`` package first on ``PYTHONPATH``, its own case
files), so one benchmark run can time two checkouts side by side: with several ``--code`` trees the
runs of one case follow each other, tree by tree, and a case's rows were taken under the same
conditions. Per run the script prints the process's wall time (imports, build, integration,
analysis and output), the run's own wall time (``summary.json``, from the build on), steps,
Newton iterations, factorisations, the drape coefficient and the node count, and it writes
``results.json``.

Cases (``--cases``):

* ``lowered``  ``cases/cusick_lowered.toml``: a cotton shirting let down on the tester's support.
* ``fabric1``  ``cases/cusick_fabric1.toml``: Fabric 1 under a gravity ramp, no contact.
* ``limp``     the let-down set-up with a limp fabric: B = 0.005 gf·cm²/cm, 2HB = 0.0025 gf·cm/cm
  both ways, W = 15 mg/cm² (DC about 15 %).

Usage::

    python benchmarks/bench_drape_speed.py --code /path/to/old --code . --out out/drape_speed
    python benchmarks/bench_drape_speed.py --cases lowered fabric1 --threads 1

Timings need a quiet machine: run nothing else meanwhile. The counts (steps, iterations,
factorisations) do not depend on the load.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: The limp fabric: the let-down set-up's cotton made limp (KES units, as a sheet prints them).
LIMP = ("material.kes.B_warp=0.005", "material.kes.B_weft=0.005", "material.kes.HB2_warp=0.0025",
        "material.kes.HB2_weft=0.0025", "material.kes.weight=15")

#: name: (case file in the code tree, overrides)
CASES = {"lowered": ("cases/cusick_lowered.toml", ()),
         "fabric1": ("cases/cusick_fabric1.toml", ()),
         "limp": ("cases/cusick_lowered.toml", LIMP)}

COLUMNS = ("case", "code", "wall_s", "run_wall_s", "steps", "iterations", "factorizations", "dc", "nodes",
           "status")


def _environment(code: Path, threads: int | None) -> dict:
    env = {**os.environ, "PYTHONPATH": str(code)}
    if threads:
        for name in ("NUMBA_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
            env[name] = str(threads)
    return env


def package_of(code: Path, threads: int | None = None) -> str:
    """Where ``import drape`` leads in a process of this code tree (to show which code runs)."""
    proc = subprocess.run([sys.executable, "-c", "import drape; print(drape.__file__)"], cwd=code,
                          env=_environment(code, threads), capture_output=True, text=True)
    return proc.stdout.strip() or proc.stderr.strip().splitlines()[-1]


def run_case(name: str, code: Path, out: Path, threads: int | None, extra=()) -> dict:
    """One case in a fresh process of ``code``; its row of the table."""
    case_file, overrides = CASES[name]
    cmd = [sys.executable, "-m", "drape.run", str(code / case_file), "--out", str(out), "--quiet"]
    for override in (*overrides, *extra):
        cmd += ["--set", override]
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=code, env=_environment(code, threads), capture_output=True, text=True)
    wall = time.perf_counter() - start
    row = {"case": name, "code": str(code), "wall_s": wall, "status": f"exit {proc.returncode}"}
    summary_path = out / "summary.json"
    if summary_path.exists():
        summary = json.loads(summary_path.read_text())
        profile = summary.get("profile", {})
        analysis = summary.get("analysis", {})
        row.update(status=summary.get("status"), run_wall_s=summary.get("wall_time_s"),
                   steps=summary.get("steps"), iterations=profile.get("newton_iterations"),
                   factorizations=profile.get("factorizations"),
                   dc=analysis.get("drape_coefficient_percent"), nodes=analysis.get("n_nodes"))
    if proc.returncode != 0:
        row["error"] = proc.stderr.strip().splitlines()[-1:] or [""]
    return row


def _cell(value) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:.1f}"
    return str(value)


def table(rows) -> str:
    """The rows as a Markdown table."""
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(_cell(row.get(c)) for c in COLUMNS) + " |" for row in rows]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--code", action="append", default=None, metavar="DIR",
                    help="code tree to run (repeatable; default: this checkout)")
    ap.add_argument("--cases", nargs="+", choices=sorted(CASES), default=list(CASES))
    ap.add_argument("--out", default="out/drape_speed", help="folder of the runs and results.json")
    ap.add_argument("--threads", type=int, default=None,
                    help="NUMBA_NUM_THREADS, MKL_NUM_THREADS and OMP_NUM_THREADS of the runs")
    ap.add_argument("--set", action="append", default=[], dest="overrides", metavar="KEY=VALUE",
                    help="an override for every run (as python -m drape.run --set)")
    args = ap.parse_args(argv)
    codes = [Path(c).resolve() for c in (args.code or [ROOT])]
    out = Path(args.out).resolve()
    for i, code in enumerate(codes):
        print(f"code {i}: {code} (drape from {package_of(code, args.threads)})", flush=True)
    rows = []
    for name in args.cases:
        for i, code in enumerate(codes):
            row = run_case(name, code, out / f"{name}_code{i}", args.threads, args.overrides)
            rows.append(row)
            print(" | ".join(f"{c} {_cell(row.get(c))}" for c in COLUMNS), flush=True)
    print(table(rows))
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(rows, indent=2) + "\n")
    return 0 if all(row.get("status") in ("settled", "completed") for row in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
