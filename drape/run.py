"""Run a case file: ``python -m drape.run CASE.toml [--out DIR] [--set key=value ...]``.

The runner only wires parts together: the case (:mod:`drape.case`) is built into mesh, material
and structural model (:mod:`drape.build`), integrated in time (:func:`drape.newmark.integrate`
or :func:`drape.newmark.quasi_static`, through the phases and landing times of
:mod:`drape.timeline`) until ``t_end`` or until it settles (:mod:`drape.settling`), and written
as it goes (:class:`drape.output.OutputWriter`). Every converged step is appended to
``history.csv``; output steps are written as VTU with the PVD index rewritten each time, so a
run that stops early (no convergence, Ctrl-C) leaves everything up to its last converged step.
After the run the case's analysis (:mod:`drape.analyses`) adds its results to ``summary.json``.

Exit codes: 0 completed or settled, 1 bad input (case file, material, mesh), 2 the integrator
failed to converge (``summary.json`` has ``status = "failed"`` and the reason), 130 interrupted.
Any other error during the integration also leaves ``summary.json`` (``status = "error"``).
"""
from __future__ import annotations

import argparse
import logging
import math
import sys
import time
from pathlib import Path

import numpy as np

from drape.analyses import ANALYSES, RunContext
from drape.build import Parts, RunInputError, build, build_material, build_mesh, initial_fields
from drape.case import Case, CaseError, describe_schema, dump_case, load_case
from drape.output import OutputSchedule, OutputWriter, flat_fields
from drape.probes import DisplacementProbe
from drape.settling import Settling, settling_threshold
from drape.timeline import hit_times, pseudo_times, time_phases

__all__ = ["run_case", "main", "build", "build_mesh", "build_material", "initial_fields", "Parts",
           "RunInputError"]

log = logging.getLogger("drape.run")


def _setup_logging(out_dir: Path) -> logging.Handler:
    handler = logging.FileHandler(out_dir / "run.log", mode="w")
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger("drape")
    root.setLevel(logging.INFO)
    root.addHandler(handler)
    return handler


def run_case(case: Case, out_dir, quiet: bool = False, parts: Parts | None = None,
             source: str = "") -> dict:
    """Run ``case`` writing into ``out_dir``; return the summary (also in ``summary.json``).

    ``parts`` replaces the built mesh/material/model (tests, scripts that build their own);
    ``source`` (where the case came from) heads ``case.resolved.toml`` as a comment.

    Raises
    ------
    CaseError, ValueError
        When the case cannot be built (nothing is integrated then).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    handler = _setup_logging(out_dir)
    try:
        header = "# Resolved case: every key with its value (SI units), as run.\n"
        if source:
            header += "".join(f"# {line}\n" for line in source.splitlines())
        (out_dir / "case.resolved.toml").write_text(header + dump_case(case))
        log.info("case %s: %s", case.case.name, case.case.description)
        wall0 = time.perf_counter()
        parts = build(case) if parts is None else parts
        return _simulate(case, parts, out_dir, quiet, wall0)
    except Exception:
        log.exception("run aborted")
        raise
    finally:
        logging.getLogger("drape").removeHandler(handler)
        handler.close()


class _Recorder:
    """The integrator's ``on_step``: history row, VTU when due, progress, settling check."""

    def __init__(self, case: Case, ctx: RunContext, writer: OutputWriter, bar):
        self.case, self.ctx, self.writer, self.bar = case, ctx, writer, bar
        self.schedule = OutputSchedule(case.output.every, case.output.every_dt)
        self.settled = Settling(case, settling_threshold(case, ctx.mesh, ctx.material))
        self.analysis = ANALYSES[case.case.analysis]
        self.probe = DisplacementProbe(case, ctx.mesh)
        self.step = 0
        self.last = None
        self.last_written = None
        self.stop_reason = None

    def __call__(self, state, info=None) -> bool:
        model = self.ctx.model
        fields = flat_fields(model.fields(state.u, state.v, state.a), self.ctx.mesh)
        energies = {k: float(v) for k, v in model.energies(state.u, state.v, t=state.t).items()}
        row = {"step": self.step, "t": float(state.t),
               "dt": float(getattr(info, "dt", 0.0)),
               "iterations": int(getattr(info, "iterations", 0)),
               "cuts": int(getattr(info, "cuts", 0))}
        row.update(energies)
        row.update(self.probe(fields["displacement"]))
        if self.analysis.probe is not None:
            row.update(self.analysis.probe(self.ctx, fields))
        self.ctx.history.append(row)
        self.writer.append_history(row)
        if info is not None and getattr(info, "cuts", 0):
            log.info("t = %.6g s: step size cut to dt = %.3g s", state.t, info.dt)
        if self.schedule.due(self.step, state.t):
            self.writer.write_step(state.t, fields)
            self.last_written = self.step
        self.last = state
        self.step += 1
        self.bar.update(max(0.0, min(float(state.t), self.bar.total) - self.bar.n))
        if self.settled(state.t, energies.get("kinetic", math.inf)):
            self.stop_reason = (
                f"kinetic energy {energies['kinetic']:.3e} J below "
                f"{self.settled.threshold:.3e} J for {self.settled.needed} steps at t = {state.t:g} s")
            return True
        return False

    def finish(self) -> None:
        """Write the last converged state if the schedule skipped it."""
        if self.last is not None and self.last_written != self.step - 1:
            s = self.last
            self.writer.write_step(s.t, flat_fields(self.ctx.model.fields(s.u, s.v, s.a), self.ctx.mesh))
            self.last_written = self.step - 1


def _simulate(case: Case, parts: Parts, out_dir: Path, quiet: bool, wall0: float) -> dict:
    from drape import newmark

    ctx = RunContext(case, parts.mesh, parts.material, parts.model, out_dir)
    model, solver = parts.model, case.solver
    status, reason = "completed", f"reached t_end = {solver.t_end:g} s"
    error = None
    with OutputWriter(out_dir, case.case.name, parts.mesh, fields=case.output.fields) as writer:
        bar = _progress(solver.t_end, quiet)
        rec = _Recorder(case, ctx, writer, bar)
        u0, v0 = initial_fields(case, model)
        state0 = newmark.initial_state(model, u0, v0)
        rec(state0)
        newton = dict(rtol=solver.rtol, atol=solver.atol, du_rtol=solver.du_rtol,
                      du_atol=solver.du_atol, max_iter=solver.max_iter)
        try:
            if solver.quasi_static:
                times = np.union1d(pseudo_times(solver.dt, solver.t_end), hit_times(case))
                newmark.quasi_static(model, np.ones_like(times), times=times, state=state0,
                                     max_cuts=solver.max_cuts, on_step=rec, **newton)
            else:
                state = state0
                for t_stop, dt_max, settling in time_phases(case):
                    # the settling phase starts at dt and lands on no output marks: its step grows
                    state = newmark.integrate(model, t_stop, solver.dt, state=state, dt_max=dt_max,
                                              beta=solver.newmark_beta, gamma=solver.newmark_gamma,
                                              alpha_hht=solver.alpha_hht, max_cuts=solver.max_cuts,
                                              hit_times=() if settling else hit_times(case),
                                              on_step=rec, **newton)
                    if rec.stop_reason is not None:
                        break
            if rec.stop_reason is not None:
                status, reason = "settled", rec.stop_reason
        except newmark.ConvergenceError as exc:
            status, reason = "failed", f"no convergence: {exc}"
            log.error("stopped: %s", exc)
        except KeyboardInterrupt:
            status, reason = "interrupted", "interrupted by the user (Ctrl-C)"
            log.warning("interrupted")
        except Exception as exc:  # keep what was written, say why, then let it propagate
            status, reason = "error", f"{type(exc).__name__}: {exc}"
            error = exc
            log.exception("run stopped by an error")
        finally:
            bar.close()
        rec.finish()
        ctx.state = rec.last
        summary = {
            "case": case.case.name, "description": case.case.description,
            "material": getattr(parts.material, "name", None), "model": type(model).__name__,
            "status": status, "reason": reason, "t_final": float(rec.last.t),
            "settling_time": float(rec.last.t) if status == "settled" else None,
            "steps": rec.step - 1, "vtu_files": len(writer.datasets), "pvd": writer.pvd_path.name,
            "final": {k: v for k, v in ctx.history[-1].items() if k != "step"},
        }
        if status in ("completed", "settled") and case.case.analysis != "none":
            analysis = ANALYSES[case.case.analysis]
            try:
                summary["analysis"] = {"name": analysis.name, **analysis.finish(ctx)}
            except Exception as exc:  # a failing analysis must not lose the run
                log.exception("analysis %s failed", analysis.name)
                summary["analysis"] = {"name": analysis.name,
                                       "error": f"{type(exc).__name__}: {exc}"}
        wall = time.perf_counter() - wall0
        summary["wall_time_s"] = wall
        summary["simulated_per_wall"] = float(rec.last.t) / wall if wall > 0 else None
        writer.write_summary(summary)
    log.info("%s: %s (%d steps, %.1f s wall)", status, reason, summary["steps"], wall)
    if error is not None:
        raise error
    return summary


def _progress(total: float, quiet: bool):
    from tqdm import tqdm

    return tqdm(total=total, disable=quiet, unit="s", unit_scale=False, desc="simulated time",
                mininterval=0.5,
                bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]",
                file=sys.stderr, leave=False)


# --------------------------------------------------------------------------- CLI
_EXAMPLES = """\
example:
  python -m drape.run cases/cantilever.toml --out out/cantilever \\
      --set solver.t_end=0.5 --set mesh.nx=10 --set "mesh.length=3 cm"
  python -m drape.inspect out/cantilever      (pictures of the result)

outputs in DIR: <name>_NNNN.vtu + <name>.pvd (ParaView, pyvista), history.csv,
summary.json, case.resolved.toml, run.log

exit codes: 0 completed or settled, 1 bad input, 2 no convergence (every converged
step stays on disk; summary.json says why), 130 interrupted"""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m drape.run", epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Run a fabric bending / drape case file (TOML) and write VTU/PVD, "
                    "history.csv and summary.json.")
    p.add_argument("case", nargs="?", help="case file (TOML)")
    p.add_argument("--out", metavar="DIR",
                   help="output directory (default: out/<case name>)")
    p.add_argument("--set", metavar="KEY=VALUE", action="append", default=[], dest="overrides",
                   help="override any case key by its dotted name; the value is read as TOML "
                        "(numbers, true/false, arrays, \"strings\"), a bare word as a string: "
                        "--set solver.dt=1e-3 --set model.kinematics=small; "
                        "repeatable, applied before validation")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no final message")
    p.add_argument("--check", action="store_true",
                   help="validate the case and build mesh, material and model, then stop "
                        "(prints what would run; writes nothing)")
    p.add_argument("--help-case", action="store_true",
                   help="print every case-file table and key with its meaning, and exit")
    return p


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code."""
    parser = _parser()
    args = parser.parse_args(argv)
    if args.help_case:
        print(describe_schema())
        return 0
    if args.case is None:
        parser.error("the case file is required (or --help-case)")
    try:
        case = load_case(args.case, args.overrides)
        if args.check:
            parts = build(case)
            print(f"{case.case.name}: OK — {type(parts.model).__name__}, {parts.model.ndofs} dofs "
                  f"({len(parts.model.fixed_dofs)} fixed), {parts.mesh.t.shape[1]} triangles, "
                  f"material {getattr(parts.material, 'name', '?')}, "
                  f"t_end = {case.solver.t_end:g} s, dt = {case.solver.dt:g} s, "
                  f"analysis {case.case.analysis}")
            return 0
        out = Path(args.out) if args.out else Path("out") / case.case.name
        source = f"from {args.case}" + "".join(f" --set {o}" for o in args.overrides)
        summary = run_case(case, out, quiet=args.quiet, source=source)
    except (CaseError, RunInputError) as exc:
        print(f"error in {args.case}:\n  " + str(exc).replace("\n", "\n  "), file=sys.stderr)
        return 1
    except ValueError as exc:  # bad input caught by a lower layer (material, mesh, model)
        print(f"error in {args.case}: {exc}", file=sys.stderr)
        return 1
    if summary["status"] == "failed":
        print(f"{case.case.name}: FAILED at t = {summary['t_final']:g} s: {summary['reason']}\n"
              f"  every converged step is kept in {out} ({summary['vtu_files']} VTU files, "
              f"{summary['pvd']})", file=sys.stderr)
        return 2
    if summary["status"] == "interrupted":
        print(f"{case.case.name}: interrupted at t = {summary['t_final']:g} s; output kept in {out}",
              file=sys.stderr)
        return 130
    if not args.quiet:
        print(f"{case.case.name}: {summary['status']} ({summary['reason']}); "
              f"{summary['steps']} steps in {summary['wall_time_s']:.1f} s; output in {out}")
        if "analysis" in summary:
            for key, value in summary["analysis"].items():
                if isinstance(value, (int, float, str)):
                    print(f"  {key}: {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
