"""Sweep benchmark: the same catalogue of 8 KES fabrics on 1 and on 2 Dask workers, back to back.

Both sweeps run ``python -m drape.sweep cases/cusick_kes.toml --table cases/kes_catalogue.csv``
(each on a fresh ``LocalCluster`` of single-threaded worker processes), one right after the
other, so that they see the same machine. The script prints the wall time of each sweep, the
speed-up and each fabric's DC and wall time, and writes ``bench_sweep.json``. With 8 runs of
similar length on 2 free cores the speed-up is bounded by 2; what it loses below 2 is cluster
start-up and the unequal run lengths at the end of the sweep.

Run it on an otherwise idle machine (timings of a shared machine mean nothing)::

    python benchmarks/bench_sweep.py --out out/bench_sweep            # full Cusick runs, long
    python benchmarks/bench_sweep.py --out out/bench_sweep_tiny --tiny  # seconds: checks the script

``--tiny`` drapes a coarse specimen for a few steps: it checks that the benchmark works, its
timings measure start-up rather than the sweep.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "cusick_kes.toml"
CATALOGUE = ROOT / "cases" / "kes_catalogue.csv"
#: A coarse annulus for a few steps: enough to run every part of the sweep.
TINY = ["mesh.n_radial=1", "mesh.n_circumferential=12", "solver.t_end=0.03"]


def sweep(out: Path, workers: int, overrides: list[str]) -> tuple[float, list[dict]]:
    """Run the catalogue on ``workers`` worker processes into ``out``; return (wall, records)."""
    sys.path.insert(0, str(ROOT))
    from drape.batch import sweep as drape_sweep

    if out.exists():
        shutil.rmtree(out)
    args = [str(CASE), "--table", str(CATALOGUE), "--out", str(out), "--workers", str(workers),
            "--quiet", *sum((["--set", o] for o in overrides), [])]
    t0 = time.perf_counter()
    code = drape_sweep.main(args)
    wall = time.perf_counter() - t0
    if code != 0:
        raise SystemExit(f"sweep on {workers} worker(s) exited with {code}")
    return wall, drape_sweep.read_results(out / "results.csv")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="out/bench_sweep", help="folder of both sweeps")
    p.add_argument("--tiny", action="store_true", help="coarse, short runs: checks the script")
    p.add_argument("--set", action="append", default=[], dest="overrides", metavar="KEY=VALUE",
                   help="override a case key in every run")
    args = p.parse_args(argv)
    out = Path(args.out)
    overrides = (TINY if args.tiny else []) + args.overrides
    results = {}
    for workers in (1, 2):
        wall, records = sweep(out / f"workers_{workers}", workers, overrides)
        results[workers] = {"wall_s": wall, "runs": records}
        print(f"{workers} worker(s): {len(records)} runs in {wall:.1f} s")
    speedup = results[1]["wall_s"] / results[2]["wall_s"]
    print(f"speed-up 2 vs 1 worker: {speedup:.2f}x")
    print(f"{'fabric':12s} {'status':10s} {'DC [%]':>7s} {'nodes':>5s} {'c [cm]':>7s} "
          f"{'wall 1 [s]':>10s} {'wall 2 [s]':>10s}")
    second = {r["name"]: r for r in results[2]["runs"]}
    for r in results[1]["runs"]:
        dc = f"{float(r['DC_percent']):7.2f}" if r["DC_percent"] else f"{'':7s}"
        c = f"{100 * float(r['bending_length_m']):7.3f}" if r["bending_length_m"] else f"{'':7s}"
        print(f"{r['name']:12s} {r['status']:10s} {dc} {r['nodes']:>5s} {c} "
              f"{float(r['wall_time_s'] or 'nan'):10.1f} "
              f"{float(second[r['name']]['wall_time_s'] or 'nan'):10.1f}")
    summary = {"case": str(CASE.relative_to(ROOT)), "table": str(CATALOGUE.relative_to(ROOT)),
               "overrides": overrides, "wall_1_worker_s": results[1]["wall_s"],
               "wall_2_workers_s": results[2]["wall_s"], "speedup": speedup,
               "runs_1_worker": results[1]["runs"], "runs_2_workers": results[2]["runs"]}
    (out / "bench_sweep.json").write_text(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
