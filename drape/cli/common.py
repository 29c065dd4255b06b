"""What every command-line tool shares: the exit codes, one-line errors, common options.

Each exit code means one thing (:data:`EXIT_CODES` is the table ``--help`` prints). A tool
reports a problem as one line on stderr, ``error: ...``, never as a traceback:
:func:`guarded` runs a tool's body and turns what it raises into that line and the code.

>>> code_of(ValueError("mesh.length = -1.0: must be > 0"))
2
>>> code_of(FileNotFoundError(2, "No such file or directory", "out/x"))
4
>>> code_of(KeyError("mesh"))
1
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from drape.run.messages import describe, one_line
from drape.run.termination import EXIT_TERMINATED, Terminated

__all__ = ["EXIT_OK", "EXIT_UNEXPECTED", "EXIT_BAD_INPUT", "EXIT_NOT_CONVERGED", "EXIT_IO",
           "EXIT_INTERRUPTED", "EXIT_TERMINATED", "EXIT_CODES", "Parser", "code_of", "fail",
           "guarded", "add_batch_options", "writable_folder"]

EXIT_OK = 0
#: An error nobody foresaw (a bug): still one line; a run's run.log has the traceback.
EXIT_UNEXPECTED = 1
#: Bad input: the case file, a --set value, a mesh or material file, a run table, the options.
EXIT_BAD_INPUT = 2
#: The solver did not converge (every converged step stays on disk; summary.json says why).
EXIT_NOT_CONVERGED = 3
#: The file system refused: a file where a folder should be, read-only, full, or the output
#: folder held by another run.
EXIT_IO = 4
#: Ctrl-C (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130

#: The exit-code table, as ``--help`` and README.md print it.
EXIT_CODES = f"""\
exit codes:
  {EXIT_OK}    finished (a run completed or settled; a sweep ran every row, whatever its status)
  {EXIT_BAD_INPUT}    bad input: case file, --set value, mesh or material file, run table, options
  {EXIT_NOT_CONVERGED}    the solver did not converge (every converged step stays on disk)
  {EXIT_IO}    I/O error: the output folder cannot be written (a file in the way, read-only,
       full) or another run or sweep is writing into it
  {EXIT_INTERRUPTED}  interrupted (Ctrl-C); continue with --resume
  {EXIT_TERMINATED}  terminated (SIGTERM); continue with --resume
  {EXIT_UNEXPECTED}    an unexpected error (a bug): one line here, the traceback in run.log"""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit with :data:`EXIT_BAD_INPUT`."""

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"error: {message} (see {self.prog} --help)\n")


def code_of(exc: BaseException) -> int:
    """The exit code of an exception that ends a tool."""
    if isinstance(exc, Terminated):
        return EXIT_TERMINATED
    if isinstance(exc, KeyboardInterrupt):
        return EXIT_INTERRUPTED
    if isinstance(exc, OSError):
        return EXIT_IO
    if isinstance(exc, ValueError):     # CaseError, RunInputError, SweepError, a material rule
        return EXIT_BAD_INPUT
    return EXIT_UNEXPECTED


def fail(message, code: int = EXIT_BAD_INPUT) -> int:
    """Print ``error: message`` as one line on stderr; return ``code``."""
    print(f"error: {one_line(message)}", file=sys.stderr)
    return code


def guarded(body, *args, what: str = "", **kwargs) -> int:
    """``body(*args, **kwargs)``'s exit code, or the one-line report of what it raised.

    ``what`` prefixes the message of bad input (e.g. ``"in cases/x.toml"``); an I/O error
    names its file itself. Ctrl-C and SIGTERM print ``interrupted`` or ``terminated``.
    """
    try:
        return body(*args, **kwargs)
    except (Exception, KeyboardInterrupt) as exc:
        code = code_of(exc)
        if isinstance(exc, KeyboardInterrupt):
            print("terminated" if code == EXIT_TERMINATED else "interrupted", file=sys.stderr)
            return code
        prefix = f"{what}: " if what and code == EXIT_BAD_INPUT else ""
        if code == EXIT_UNEXPECTED:
            prefix = "unexpected "
        return fail(prefix + describe(exc), code)


def add_batch_options(p: argparse.ArgumentParser, resume: str, quiet: str = "no progress bars") -> None:
    """The options every batch of runs on Dask shares (sweep, validation set, sensitivity study,
    identification): ``--set``, ``--scheduler``, ``--workers``, ``--resume`` and ``--quiet``
    (their help: ``resume``, ``quiet``)."""
    p.add_argument("--set", metavar="KEY=VALUE", action="append", default=[], dest="overrides",
                   help="override a case key in every run (as in drape.run.runner)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler of an existing cluster, e.g. tcp://HOST:8786 "
                        "(default: DASK_SCHEDULER_ADDRESS, else a local cluster)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--resume", action="store_true", help=resume)
    p.add_argument("--quiet", action="store_true", help=quiet)


def writable_folder(path, option: str) -> Path:
    """``path`` as a folder a tool can write into, checked before anything is written.

    The folder need not exist yet: its nearest existing parent must be a folder in which a
    (temporary, removed at once) folder can be made. Nothing is left behind.

    Raises
    ------
    OSError
        One line naming ``option`` (exit code :data:`EXIT_IO`): a file in the way, or a place
        that cannot be written.
    """
    path = Path(path)
    existing = next(p for p in (path, *path.parents) if p.exists())
    if not existing.is_dir():
        where = "a file is in the way" if existing == path else f"{existing} is a file"
        raise OSError(f"{option} {path}: {where}, not a folder")
    try:
        with tempfile.TemporaryDirectory(dir=existing, prefix=".drape-probe-"):
            pass
    except OSError as exc:
        raise OSError(f"{option} {path}: cannot write in {existing} "
                      f"({exc.strerror or describe(exc)})") from None
    return path
