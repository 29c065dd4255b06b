"""Running one case: the time loop's wiring and what is recorded.

``python -m drape.run CASE`` (or ``drape run CASE``, :mod:`drape.cli.run`) runs :func:`run_case`.

Modules
-------
runner
    :func:`run_case` and :func:`resume_run`.
recorder
    What is kept of every converged step.
checkpoint
    The last converged step on disk.
settling
    The ``[stop]`` rule: static out-of-balance below a fraction of the weight.
probes
    Displacement columns of ``history.csv``.
output
    VTU/PVD, ``history.csv``, ``summary.json``.
atomic
    Files written whole or not at all, with the mode a plain ``open()`` gives.
run_profile
    :class:`RunProfile`: counts and wall-time split of a run.
pictures
    Pictures of a finished run (``drape inspect``).
termination, lock, messages
    SIGTERM, one writer per output folder, what went wrong in one line.
"""
from drape.run.checkpoint import Checkpoint, read_checkpoint
from drape.run.output import read_history, read_pvd
from drape.run.runner import resume_run, run_case

__all__ = ["run_case", "resume_run", "Checkpoint", "read_checkpoint", "read_history", "read_pvd"]
