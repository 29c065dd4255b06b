"""Benchmark: all 20 (dataset x variant) global fits of ``--all-thesis``.

Target: <= 30 s total on 2 cores.  Prints the 20-cell residual table,
the wall time with 1 and 2 worker processes, and the CPU time per fit.

    python benchmarks/bench_fit.py [--accel-time T] [--workers 1,2]
"""

import argparse
import os
import time

from constitutive.fit import DEFAULT_ACCEL_TIME
from constitutive.fit.tables import all_thesis, format_all


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--accel-time", type=float, default=DEFAULT_ACCEL_TIME)
    ap.add_argument("--workers", default="1,2", help="comma-separated worker counts to time")
    args = ap.parse_args()
    print(f"cores available: {os.cpu_count()}; load average {os.getloadavg()[0]:.2f}")
    for w in [int(x) for x in args.workers.split(",")]:
        t0 = time.perf_counter()
        fitted, own, times = all_thesis(args.accel_time, workers=w, progress=False)
        wall = time.perf_counter() - t0
        cpu = sum(times.values())
        print(f"workers={w}: 20 fits + 4 thesis-parameter evaluations in {wall:.1f} s wall; "
              f"fits' CPU time {cpu:.1f} s (slowest fit {max(times.values()):.2f} s CPU); "
              f"load average now {os.getloadavg()[0]:.2f}")
    print()
    print(format_all(fitted, own))


if __name__ == "__main__":
    main()
