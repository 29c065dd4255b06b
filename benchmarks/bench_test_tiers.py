"""How long the test tiers take from a fresh clone: README's test command and the slow tier.

    python benchmarks/bench_test_tiers.py [--tiers fast slow] [--workers 2]

Clones the checkout's HEAD into a temporary folder, so the run starts as CI's does: no numba
cache (the first tests compile the shell's kernels), no pytest cache. Runs there, one after
the other, ``python -m pytest -n WORKERS`` (the fast tier, the default selection) and
``python -m pytest -n WORKERS -m slow``, with this interpreter (its environment must have the
project's ``[test]`` extra installed; the clone's own packages come first on the path), and
prints each tier's wall time and pytest's summary line. Timings need a quiet machine.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIERS = {"fast": [], "slow": ["-m", "slow"]}


def run_tier(clone: Path, tier: str, workers: int) -> tuple[float, str, int]:
    """(wall seconds, pytest's last line, exit code) of one tier in ``clone``."""
    cmd = [sys.executable, "-m", "pytest", "-n", str(workers), "-q", "-p", "no:cacheprovider",
           *TIERS[tier]]
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=clone, capture_output=True, text=True)
    wall = time.perf_counter() - start
    lines = [line for line in proc.stdout.splitlines() if line.strip()]
    return wall, (lines[-1] if lines else proc.stderr.strip()[-200:]), proc.returncode


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tiers", nargs="+", choices=list(TIERS), default=list(TIERS))
    ap.add_argument("--workers", type=int, default=2, help="pytest-xdist workers (default 2)")
    args = ap.parse_args(argv)
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                          text=True, check=True).stdout.strip()
    codes = []
    with tempfile.TemporaryDirectory() as tmp:
        clone = Path(tmp) / "clone"
        subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
        print(f"fresh clone of {head}, {args.workers} workers")
        for tier in args.tiers:
            wall, summary, code = run_tier(clone, tier, args.workers)
            codes.append(code)
            print(f"{tier:5s} {wall:7.1f} s  {summary}", flush=True)
    return 0 if all(c == 0 for c in codes) else 1


if __name__ == "__main__":
    sys.exit(main())
