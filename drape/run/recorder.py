"""What a run keeps of every converged step: the integrator's ``on_step`` callback.

For each converged step :class:`Recorder` appends a history row, writes the VTU when the
output schedule says so, rewrites the checkpoint (:mod:`drape.run.checkpoint`), advances the
progress bar and applies the settling rule. :meth:`Recorder.restore` puts a resumed run back
where its checkpoint left it.
"""
from __future__ import annotations

import dataclasses
import logging
import sys
import time

from drape.analyses import ANALYSES, RunContext
from drape.models.fields import flat_fields
from drape.run.checkpoint import Checkpoint, write_checkpoint
from drape.run.output import OutputSchedule, OutputWriter
from drape.run.probes import DisplacementProbe
from drape.run.run_profile import RunProfile
from drape.run.settling import Settling
from drape.run.termination import sigterm_deferred
from drape.solvers.step_control import StepControl

__all__ = ["Recorder", "progress_bar"]

log = logging.getLogger("drape.run.runner")


class Recorder:
    """The integrator's ``on_step``: history row, VTU when due, checkpoint, progress, settling.

    ``wall0`` is the ``time.perf_counter()`` the run's wall time counts from.
    """

    def __init__(self, case, ctx: RunContext, writer: OutputWriter, bar, wall0: float):
        self.case, self.ctx, self.writer, self.bar = case, ctx, writer, bar
        self.schedule = OutputSchedule(case.output.every, case.output.every_dt)
        self.settled = Settling(case)
        self.analysis = ANALYSES[case.case.analysis]
        self.probe = DisplacementProbe(case, ctx.mesh)
        self.wall0 = wall0
        self.step = 0
        self.last = None
        self.last_written = None
        self.stop_reason = None
        self.control = None        # the integrator's step control after the last step
        self.profile = RunProfile()

    def __call__(self, state, info=None) -> bool:
        t0 = time.perf_counter()
        try:
            with sigterm_deferred():
                return self._record(state, info)
        finally:
            self.profile.output_s += time.perf_counter() - t0

    def _record(self, state, info) -> bool:
        model = self.ctx.model
        if info is not None:
            self.profile.add(info)
        fields = flat_fields(model.fields(state.u, state.v, state.a), self.ctx.mesh)
        energies = {k: float(v) for k, v in model.energies(state.u, state.v, t=state.t).items()}
        settled = self.settled(model, state.u, state.t)
        row = {"step": self.step, "t": float(state.t),
               "dt": float(getattr(info, "dt", 0.0)),
               "iterations": int(getattr(info, "iterations", 0)),
               "evaluations": int(getattr(info, "evaluations", 0)),
               "factorizations": int(getattr(info, "factorizations", 0)),
               "cuts": int(getattr(info, "cuts", 0))}
        row.update(energies)
        if self.settled.active:   # blank until the loads stop changing
            row["out_of_balance"] = self.settled.ratio
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
        self.control = getattr(info, "control", None)
        self.checkpoint()
        self.bar.update(max(0.0, min(float(state.t), self.bar.total) - self.bar.n))
        if settled:
            self.stop_reason = self.settled.reason(state.t)
            return True
        return False

    def checkpoint(self) -> None:
        """Save the last converged step (after the model committed it)."""
        run = {"step": self.step, "datasets": len(self.writer.datasets),
               "last_written": self.last_written, "schedule": self.schedule.state_dict(),
               "settling_count": self.settled.count,
               "step_control": None if self.control is None else dataclasses.asdict(self.control),
               "wall_time_s": time.perf_counter() - self.wall0}
        write_checkpoint(self.writer.directory, self.last, self.ctx.model.state_dict(), run)

    def restore(self, checkpoint: Checkpoint, history: list[dict]):
        """Continue from ``checkpoint``: model state, counters and history; return its state."""
        run = checkpoint.run
        self.ctx.model.load_state_dict(checkpoint.model)
        self.ctx.history[:] = history[:run["step"]]
        self.step, self.last_written = run["step"], run["last_written"]
        self.schedule.load_state_dict(run["schedule"])
        self.settled.count = run["settling_count"]
        control = run["step_control"]
        self.control = None if control is None else StepControl(**control)
        self.wall0 -= run["wall_time_s"]
        self.last = checkpoint.state
        self.bar.update(max(0.0, min(float(self.last.t), self.bar.total) - self.bar.n))
        return checkpoint.state

    def finish(self) -> None:
        """Write the last converged state if the schedule skipped it."""
        if self.last is not None and self.last_written != self.step - 1:
            s = self.last
            self.writer.write_step(s.t, flat_fields(self.ctx.model.fields(s.u, s.v, s.a), self.ctx.mesh))
            self.last_written = self.step - 1


def progress_bar(total: float, quiet: bool):
    """A tqdm bar over simulated time [s] on stderr (disabled when ``quiet``)."""
    from tqdm import tqdm

    return tqdm(total=total, disable=quiet, unit="s", unit_scale=False, desc="simulated time",
                mininterval=0.5,
                bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]",
                file=sys.stderr, leave=False)
