"""``drape run`` / ``python -m drape.run CASE.toml [--out DIR] [--set key=value ...]``.

Runs a case file (:func:`drape.run.runner.run_case`) or continues a stopped run
(:func:`drape.run.runner.resume_run`, ``--resume OUTDIR``); ``--check`` builds it without
running, ``--help-case`` prints every case-file key.

Exit codes (:data:`drape.cli.common.EXIT_CODES`): 0 completed or settled, 2 bad input (case
file, material, mesh), 3 the integrator failed to converge (``summary.json`` has
``status = "failed"`` and the reason), 4 an I/O error (the output folder cannot be written, or
another run writes into it), 130 interrupted (Ctrl-C), 143 terminated (SIGTERM, handled like
Ctrl-C), 1 an unexpected error. Each is reported as one line on stderr.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drape.case.build import Parts, build
from drape.case.case import Case, describe_schema, load_case
from drape.cli.common import (
    EXIT_CODES,
    EXIT_INTERRUPTED,
    EXIT_NOT_CONVERGED,
    EXIT_OK,
    EXIT_TERMINATED,
    Parser,
    fail,
    guarded,
)
from drape.run.runner import announce_compiling, resume_run, run_case
from drape.run.termination import sigterm_raises

__all__ = ["main"]

_EXAMPLES = f"""\
example:
  python -m drape.run cases/cantilever.toml --out out/cantilever \\
      --set solver.t_end=0.5 --set mesh.nx=10 --set "mesh.length=3 cm"
  python -m drape.inspect out/cantilever      (pictures of the result)

outputs in DIR: <name>_NNNN.vtu + <name>.pvd (ParaView, pyvista), history.csv,
summary.json, case.resolved.toml, run.log, checkpoint.npz; one run at a time writes
into DIR; continue a stopped run with --resume DIR

{EXIT_CODES}"""


_OPTIONS = {
    "--resume": dict(metavar="OUTDIR", help="continue the stopped run in OUTDIR from its checkpoint "
                                            "(its last converged step)"),
    "--out": dict(metavar="DIR", help="output directory (default: out/<case name>)"),
    "--set": dict(metavar="KEY=VALUE", action="append", default=[], dest="overrides",
                  help="override any case key by its dotted name; the value is read as TOML "
                       "(numbers, true/false, arrays, \"strings\"), a bare word as a string: "
                       "--set solver.dt=1e-3 --set model.kinematics=small; "
                       "repeatable, applied before validation"),
    "--quiet": dict(action="store_true", help="no progress bar, no final message"),
    "--check": dict(action="store_true", help="validate the case and build mesh, material and model, "
                                              "then stop (prints what would run; writes nothing)"),
    "--help-case": dict(action="store_true",
                        help="print every case-file table and key with its meaning, and exit"),
}


def _parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="python -m drape.run", epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Run a fabric bending / drape case file (TOML) and write VTU/PVD, "
                    "history.csv and summary.json.")
    p.add_argument("case", nargs="?", help="case file (TOML)")
    for flag, options in _OPTIONS.items():
        p.add_argument(flag, **options)
    return p


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (:data:`drape.cli.common.EXIT_CODES`).

    Every problem is one line on stderr; Ctrl-C and SIGTERM stop it at any point with 130 and
    143 (a run stopped during its build leaves a summary.json that says so).
    """
    parser = _parser()
    args = parser.parse_args(argv)
    if args.help_case:
        print(describe_schema())
        return EXIT_OK
    if args.resume is not None:
        return _resume(args)
    if args.case is None:
        parser.error("the case file is required (or --help-case, --resume OUTDIR)")
    with sigterm_raises():
        return guarded(_run, args, what=f"in {args.case}")


def _run(args) -> int:
    case = load_case(args.case, args.overrides)
    if args.check:
        announce_compiling(case, args.quiet)
        _print_check(case, build(case))
        return EXIT_OK
    out = Path(args.out) if args.out else Path("out") / case.case.name
    source = f"from {args.case}" + "".join(f" --set {o}" for o in args.overrides)
    summary = run_case(case, out, quiet=args.quiet, source=source)
    return _report(summary, out, args.quiet)


def _print_check(case: Case, parts: Parts) -> None:
    """What ``--check`` found: the model, its size, the material and the loads."""
    print(f"{case.case.name}: OK — {type(parts.model).__name__}, {parts.model.ndofs} dofs "
          f"({len(parts.model.fixed_dofs)} fixed), {parts.mesh.t.shape[1]} triangles, "
          f"material {getattr(parts.material, 'name', '?')}, "
          f"t_end = {case.solver.t_end:g} s, dt = {case.solver.dt:g} s, "
          f"analysis {case.case.analysis}")
    tension = getattr(parts.material, "membrane_tension", None)
    if tension is not None:
        m = parts.material
        print(f"  membrane taken at T = {tension:.3g} N/m: E11 = {m.E11:.4g} N/m, "
              f"E22 = {m.E22:.4g} N/m, G12 = {m.G12:.4g} N/m")
    alpha, beta = parts.model.rayleigh
    if alpha or beta:
        print(f"  damping C = {alpha:.3g} 1/s M + {beta:.3g} s K0")
    if case.model.damping.drag_coefficient:
        print(f"  air drag ½ ρ_air C_d |v·n| v·n normal to the fabric, C_d = "
              f"{case.model.damping.drag_coefficient:g}")
    if case.load.agitation is not None:
        shake = case.load.agitation.describe()
        print(f"  supports shaken {shake['cycles']} cycles at {shake['frequency_Hz']:g} Hz "
              f"from t = {shake['start_s']:g} s to {shake['end_s']:g} s, peak "
              f"{shake['peak_acceleration_g']:g} g, stroke {1e3 * shake['stroke_m']:.3g} mm")


def _resume(args) -> int:
    if args.case is not None or args.overrides or args.out or args.check:
        return fail("--resume OUTDIR runs OUTDIR/case.resolved.toml: no case, --set, --out, --check")
    with sigterm_raises():
        return guarded(_resumed, args, what=f"cannot resume {args.resume}")


def _resumed(args) -> int:
    summary = resume_run(args.resume, quiet=args.quiet)
    return _report(summary, Path(args.resume), args.quiet)


def _report(summary: dict, out: Path, quiet: bool) -> int:
    """Print the outcome of a run; return its exit code."""
    name = summary["case"]
    if summary["status"] == "failed":
        print(f"{name}: FAILED at t = {summary['t_final']:g} s: {summary['reason']}; "
              f"every converged step is kept in {out} ({summary['vtu_files']} VTU files, "
              f"{summary['pvd']})", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    if summary["status"] in ("interrupted", "terminated"):
        print(f"{name}: {summary['status']} at t = {summary['t_final']:g} s; output kept in {out}; "
              f"continue with: python -m drape.run --resume {out}", file=sys.stderr)
        return EXIT_INTERRUPTED if summary["status"] == "interrupted" else EXIT_TERMINATED
    if not quiet:
        print(f"{name}: {summary['status']} ({summary['reason']}); "
              f"{summary['steps']} steps in {summary['wall_time_s']:.1f} s; output in {out}")
        if "analysis" in summary:
            for key, value in summary["analysis"].items():
                if isinstance(value, (int, float, str)):
                    print(f"  {key}: {value}")
    return EXIT_OK

