"""Friction points that switch branch between Newton iterates, per time step of a case.

A Bliman–Sorine friction point's tangent jumps where its curvature increment over the step
changes sign (stick ↔ slip; ``constitutive.friction``). Newton converges quadratically only
once no point switches any more. This script runs a case through the runner and counts, for
every step, the points of each direction (warp, weft) whose increment κ − κ_committed has
another sign than at the previous evaluation point (Newton iterates and line-search trials;
repeated evaluations at one point are counted once; :mod:`constitutive.friction_switching`)::

    python benchmarks/friction_switching.py cases/cusick_fabric1.toml --set solver.t_end=12.48

It prints one line per step: time, step size, Newton iterations, and the switches at each
new evaluation point (warp + weft), the first being the start's move off Δκ = 0.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("case", help="case file, e.g. cases/cusick_fabric1.toml")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="case override")
    args = p.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from constitutive.friction import FrictionState
    from constitutive.friction_switching import SwitchCounter
    from drape.cli.run import main as run
    from drape.run.recorder import Recorder

    counter = SwitchCounter(FrictionState).install()
    rows = []
    record = Recorder.__call__

    def recorded(rec, state, info=None):
        if info is not None:
            rows.append((state.t, info.dt, info.iterations, counter.take()))
        return record(rec, state, info)

    Recorder.__call__ = recorded
    with tempfile.TemporaryDirectory() as out:
        overrides = [a for key in args.set for a in ("--set", key)]
        run([args.case, "--out", out, "--quiet", *overrides])
    print(f"{'t [s]':>8s} {'dt [s]':>7s} {'iter':>4s}  switches at each new evaluation point")
    for t, dt, iterations, switches in rows:
        print(f"{t:8.3f} {dt:7.3f} {iterations:4d}  {switches}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
