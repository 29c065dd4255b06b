"""Running one case: the time loop's wiring, what is recorded, and the command line.

``python -m drape.run CASE`` (or ``drape run CASE``) runs :func:`run_case`.

Modules
-------
runner
    :func:`run_case`, :func:`resume_run` and the command line.
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
termination, lock, cli
    SIGTERM, one writer per output folder, exit codes and one-line errors.
"""
from drape.run.checkpoint import Checkpoint, read_checkpoint
from drape.run.cli import EXIT_CODES
from drape.run.output import read_history, read_pvd
from drape.run.runner import resume_run, run_case

__all__ = ["run_case", "resume_run", "Checkpoint", "read_checkpoint", "read_history", "read_pvd",
           "EXIT_CODES"]
