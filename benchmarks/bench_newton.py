"""Newton and step-size choices on a window of the Cusick drape, counted and timed.

Integrates ``cases/cusick_fabric1.toml`` to ``--start`` once, then the window up to ``--end``
once per variant, from the same state, and prints steps, Newton iterations, force evaluations,
factorisations, failed attempts and wall time. A variant is a comma-separated list of
``key=value`` for :func:`drape.solvers.time_stepping.integrate` (``predictor``, ``error_tolerance``) or
:class:`drape.solvers.newton.NewtonPolicy` (``lambda_min``, ``jump_ratio``, ``kink_steps``, ``reuse_contraction``,
``kink_growth``)::

    python benchmarks/bench_newton.py --start 0.1 --end 0.2 \\
        "predictor='auto'" "predictor='velocity'" "kink_steps=0" \\
        "error_tolerance=1e-2"

Counts are deterministic; wall times only mean something on an otherwise idle machine.
"""
from __future__ import annotations

import argparse
import ast
import copy
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
POLICY_KEYS = ("lambda_min", "jump_ratio", "kink_steps", "kink_growth", "trial_tangent", "reuse_contraction")


def parse_variant(text: str) -> dict:
    """``"a=1,b='x'"`` -> ``{"a": 1, "b": "x"}`` (values are Python literals)."""
    out = {}
    for item in filter(None, (p.strip() for p in text.split(","))):
        key, _, value = item.partition("=")
        out[key.strip()] = ast.literal_eval(value.strip())
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("variants", nargs="+", help="e.g. \"predictor='displacement'\"")
    p.add_argument("--case", default=str(ROOT / "cases" / "cusick_fabric1.toml"))
    p.add_argument("--start", type=float, default=0.1, help="start of the window [s]")
    p.add_argument("--end", type=float, default=0.2, help="end of the window [s]")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="case override")
    args = p.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from drape.solvers import newmark, time_stepping
    from drape.case.build import build, initial_fields, solver_options
    from drape.case.case import load_case

    case = load_case(args.case, args.set)
    model = build(case).model
    s = case.solver
    steps = dict(beta=s.newmark_beta, gamma=s.newmark_gamma, alpha_hht=s.alpha_hht)
    start = newmark.initial_state(model, *initial_fields(case, model))
    start = time_stepping.integrate(model, args.start, s.dt, state=start, **steps, **solver_options(case, model))
    saved = model.state_dict()
    for text in args.variants:
        kw = parse_variant(text)
        model.load_state_dict(saved)
        options = solver_options(case, model)
        policy = {k: kw.pop(k) for k in list(kw) if k in POLICY_KEYS}
        options["policy"] = dataclasses.replace(options["policy"], **policy)
        rows = []
        t0 = time.perf_counter()
        time_stepping.integrate(model, args.end, s.dt, state=copy.deepcopy(start), **steps, **options, **kw,
                          on_step=lambda st, i: rows.append((i.iterations, i.evaluations, i.factorizations, i.cuts)))
        wall = time.perf_counter() - t0
        it, ev, fa, cuts = np.sum(rows, axis=0)
        print(f"{text:50s} steps {len(rows):4d}  iterations {it:4d}  evaluations {ev:4d}  "
              f"factorisations {fa:4d}  failed attempts {cuts:3d}  wall {wall:6.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
