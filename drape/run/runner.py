"""Run a case file: :func:`run_case`, and :func:`resume_run` for a stopped one.

The runner only wires parts together: the case (:mod:`drape.case.case`) is built into mesh, material
and structural model (:mod:`drape.case.build`), integrated in time (:func:`drape.solvers.time_stepping.integrate`
or :func:`drape.solvers.static.quasi_static`, through the phases and landing times of
:mod:`drape.case.timeline`) until ``t_end`` or until it settles (:mod:`drape.run.settling`), and written
as it goes (:class:`drape.run.output.OutputWriter`). Every converged step is appended to
``history.csv``; output steps are written as VTU with the PVD index rewritten each time, so a
run that stops early (no convergence, Ctrl-C) leaves everything up to its last converged step.
After the run the case's analysis (:mod:`drape.analyses`) adds its results to ``summary.json``.

``summary.json`` says how the run ended: ``status`` completed or settled, failed (the integrator
did not converge; ``reason`` says why), interrupted (Ctrl-C), terminated (SIGTERM, handled like
Ctrl-C) or error (any other error during the integration, which is raised again). Every
converged step is checkpointed (:mod:`drape.run.checkpoint`); :func:`resume_run` continues a
stopped run. One process at a time writes into an output folder (:mod:`drape.run.lock`). The
command line, ``python -m drape.run`` and its exit codes, is :mod:`drape.cli.run`.
"""
from __future__ import annotations

import json
import logging
import sys
import time
from pathlib import Path

import numpy as np

import drape.fem.shell_kernels  # noqa: F401  (define the kernels, so that cache_is_cold sees them;
import drape.fem.shell_tangent  # noqa: F401   nothing is compiled yet)
from drape.analyses import ANALYSES, RunContext
from drape.case.build import (
    Parts,
    RunInputError,
    build,
    build_material,
    build_mesh,
    initial_fields,
    solver_options,
)
from drape.case.case import Case, dump_case, load_case
from drape.case.timeline import hit_times, pseudo_times, time_phases
from drape.fem import compiled  # compiled.cache_is_cold read at call time (tests replace it)
from drape.run.atomic import atomic_write_text
from drape.run.checkpoint import CHECKPOINT, Checkpoint, read_checkpoint
from drape.run.lock import folder_lock
from drape.run.output import OutputWriter, read_history
from drape.run.recorder import Recorder, progress_bar
from drape.run.termination import Terminated
from drape.solvers.newmark import ConvergenceError, initial_state
from drape.solvers.static import quasi_static
from drape.solvers.time_stepping import integrate

__all__ = ["run_case", "resume_run", "read_summary", "ResumeError", "announce_compiling", "build",
           "build_mesh", "build_material", "initial_fields", "Parts", "RunInputError"]

log = logging.getLogger("drape.run.runner")


def _setup_logging(out_dir: Path, mode: str = "w") -> logging.Handler:
    handler = logging.FileHandler(out_dir / "run.log", mode=mode)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger("drape")
    root.setLevel(logging.INFO)
    root.addHandler(handler)
    return handler


def run_case(case: Case, out_dir, quiet: bool = False, parts: Parts | None = None,
             source: str = "", resume: Checkpoint | None = None) -> dict:
    """Run ``case`` writing into ``out_dir``; return the summary (also in ``summary.json``).

    ``parts`` replaces the built mesh/material/model (tests, scripts that build their own);
    ``source`` (where the case came from) heads ``case.resolved.toml`` as a comment;
    ``resume`` continues the run in ``out_dir`` from its checkpoint (see :func:`resume_run`).

    Raises
    ------
    CaseError, ValueError
        When the case cannot be built (nothing is integrated then).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with folder_lock(out_dir):
        return _run_locked(case, out_dir, quiet, parts, source, resume)


def _run_locked(case: Case, out_dir: Path, quiet: bool, parts: Parts | None, source: str,
                resume: Checkpoint | None) -> dict:
    """:func:`run_case` once ``out_dir`` is locked."""
    if resume is None:      # a summary left by an earlier run in this folder is not this run's
        (out_dir / "summary.json").unlink(missing_ok=True)
    handler = _setup_logging(out_dir, "w" if resume is None else "a")
    wall0 = time.perf_counter()
    try:
        try:
            header = "# Resolved case: every key with its value (SI units), as run.\n"
            if source:
                header += "".join(f"# {line}\n" for line in source.splitlines())
            if resume is None:
                (out_dir / "case.resolved.toml").write_text(header + dump_case(case))
            log.info("case %s: %s", case.case.name, case.case.description)
            if parts is None:
                announce_compiling(case, quiet)
                parts = build(case)
        except KeyboardInterrupt as exc:   # stopped before its first step: say so on disk
            return _stopped_while_building(case, out_dir, exc, wall0)
        return _simulate(case, parts, out_dir, quiet, wall0, resume)
    except Exception:
        log.exception("run aborted")
        raise
    finally:
        logging.getLogger("drape").removeHandler(handler)
        handler.close()


def announce_compiling(case: Case, quiet: bool = False) -> None:
    """Say so on stderr when the shell's kernels are about to be compiled (a cold numba cache):
    the first run of an install waits for them, with nothing else on screen."""
    if quiet or case.model.kinematics != "large":
        return
    if compiled.cache_is_cold():
        print("compiling the shell's kernels (first run only, about a minute)…", file=sys.stderr,
              flush=True)


def _stopped_while_building(case: Case, out_dir: Path, exc: KeyboardInterrupt, wall0: float):
    """The summary of a run stopped (Ctrl-C, SIGTERM) before its first step."""
    status, signal = (("terminated", "SIGTERM") if isinstance(exc, Terminated)
                      else ("interrupted", "the user (Ctrl-C)"))
    summary = {"case": case.case.name, "description": case.case.description, "status": status,
               "reason": f"{status} by {signal} while the case was being built",
               "t_final": 0.0, "settling_time": None, "steps": 0, "vtu_files": 0,
               "pvd": f"{case.case.name}.pvd", "wall_time_s": time.perf_counter() - wall0}
    log.warning("%s; start it again with python -m drape.run --resume %s", summary["reason"], out_dir)
    atomic_write_text(out_dir / "summary.json", json.dumps(summary, indent=2) + "\n")
    return summary


class ResumeError(ValueError):
    """A folder that holds no run to continue (the message says what is missing)."""


def resume_run(out_dir, quiet: bool = False) -> dict:
    """Continue the run in ``out_dir`` from its checkpoint (``python -m drape.run --resume``): the
    case read back from ``case.resolved.toml``, what was written after the checkpoint dropped.

    A run stopped before its first converged step (no checkpoint) starts again from the
    beginning. A finished run (``summary.json`` says completed or settled) runs nothing.

    Raises
    ------
    ResumeError
        When ``out_dir`` holds no run, or its summary or checkpoint cannot be read.
    """
    out_dir = Path(out_dir)
    resolved = out_dir / "case.resolved.toml"
    if not out_dir.is_dir():
        raise ResumeError(f"{out_dir} is not a folder")
    with folder_lock(out_dir):
        summary = read_summary(out_dir)
        if summary.get("status") in ("completed", "settled"):
            return summary                        # nothing left to run
        if not resolved.exists():
            raise ResumeError(f"{out_dir} holds no run to continue: no case.resolved.toml, no "
                              f"checkpoint")
        checkpoint = None
        if (out_dir / CHECKPOINT).exists() or summary.get("steps", 0) > 0:
            checkpoint = read_checkpoint(out_dir)
        source = "" if checkpoint is not None else "\n".join(
            line[2:] for line in resolved.read_text().splitlines()[1:] if line.startswith("# "))
        return _run_locked(load_case(resolved), out_dir, quiet, None, source, checkpoint)


def read_summary(out_dir: Path) -> dict:
    """``out_dir/summary.json`` ({} when there is none); :class:`ResumeError` if unreadable."""
    path = Path(out_dir) / "summary.json"
    if not path.exists():
        return {}
    try:
        summary = json.loads(path.read_bytes())
    except (ValueError, UnicodeDecodeError):
        raise ResumeError(f"{path} is not a run's summary (not JSON)") from None
    if not isinstance(summary, dict):
        raise ResumeError(f"{path} is not a run's summary")
    return summary


def _simulate(case: Case, parts: Parts, out_dir: Path, quiet: bool, wall0: float,
              resume: Checkpoint | None) -> dict:
    ctx = RunContext(case, parts.mesh, parts.material, parts.model, out_dir)
    model, solver = parts.model, case.solver
    status, reason = "completed", f"reached t_end = {solver.t_end:g} s"
    error = None
    keep = None if resume is None else (resume.run["datasets"], resume.run["step"])
    with OutputWriter(out_dir, case.case.name, parts.mesh, fields=case.output.fields,
                      keep=keep) as writer:
        bar = progress_bar(solver.t_end, quiet)
        rec = Recorder(case, ctx, writer, bar, wall0)
        if resume is None:
            state0 = initial_state(model, *initial_fields(case, model))
            rec(state0)
        else:
            state0 = rec.restore(resume, read_history(writer.history_path))
            log.info("resumed at t = %.6g s (step %d)", state0.t, rec.step - 1)
        t_eps = 1e-12 * max(solver.t_end, solver.dt)
        newton = solver_options(case, model)
        try:
            if solver.quasi_static:
                times = np.union1d(pseudo_times(solver.dt, solver.t_end), hit_times(case))
                times = times[times > state0.t + t_eps]
                if times.size:
                    quasi_static(model, np.ones_like(times), times=times, state=state0,
                                         max_cuts=solver.max_cuts, on_step=rec, **newton)
            else:
                state, t_start = state0, 0.0
                for t_stop, dt_max, settling in time_phases(case):
                    if t_stop > state.t + t_eps and rec.stop_reason is None:
                        # settling: the step grows, no output marks; resumed: the phase's control
                        state = integrate(model, t_stop, solver.dt, state=state, dt_max=dt_max,
                                                  beta=solver.newmark_beta, gamma=solver.newmark_gamma,
                                                  alpha_hht=solver.alpha_hht, max_cuts=solver.max_cuts,
                                                  error_tolerance=solver.error_tolerance,
                                                  hit_times=() if settling else hit_times(case),
                                                  control=rec.control if state.t > t_start + t_eps else None,
                                                  on_step=rec, **newton)
                    t_start = t_stop
            if rec.stop_reason is not None:
                status, reason = "settled", rec.stop_reason
        except ConvergenceError as exc:
            status, reason = "failed", f"no convergence: {exc}"
            log.error("stopped: %s", exc)
        except KeyboardInterrupt as exc:
            status, reason = (("terminated", "terminated by SIGTERM") if isinstance(exc, Terminated)
                              else ("interrupted", "interrupted by the user (Ctrl-C)"))
            log.warning("%s; continue with python -m drape.run --resume %s", reason, out_dir)
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
        if hasattr(parts.material, "describe"):   # SI values, membrane sources, KES sheet given
            summary["material_properties"] = parts.material.describe()
        alpha, beta = parts.model.rayleigh
        summary["damping"] = {"alpha_per_s": alpha, "beta_s": beta,
                              "air_drag_N_s_per_m3": case.model.damping.air_drag,
                              "drag_coefficient": case.model.damping.drag_coefficient}
        if case.load.agitation is not None:
            summary["agitation"] = case.load.agitation.describe()
        if case.measured is not None:
            summary["measured"] = case.measured.model_dump()
        if status in ("completed", "settled") and case.case.analysis != "none":
            analysis = ANALYSES[case.case.analysis]
            try:
                summary["analysis"] = {"name": analysis.name, **analysis.finish(ctx)}
            except Exception as exc:  # a failing analysis must not lose the run
                log.exception("analysis %s failed", analysis.name)
                summary["analysis"] = {"name": analysis.name,
                                       "error": f"{type(exc).__name__}: {exc}"}
        wall = time.perf_counter() - rec.wall0      # a resumed run counts its earlier time too
        summary["wall_time_s"] = wall
        summary["profile"] = rec.profile.summary(model, newton["linear_solver"], wall)
        summary["simulated_per_wall"] = float(rec.last.t) / wall if wall > 0 else None
        writer.write_summary(summary)
    log.info("%s: %s (%d steps, %.1f s wall)", status, reason, summary["steps"], wall)
    if error is not None:
        raise error
    return summary
