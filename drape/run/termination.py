"""SIGTERM handled like Ctrl-C: a batch scheduler's kill stops a run the way a user's does.

Inside :func:`sigterm_raises`, SIGTERM raises :class:`Terminated`, a ``KeyboardInterrupt``, so
every ``except KeyboardInterrupt`` that keeps a run's output valid also keeps it on SIGTERM.
Exit code :data:`EXIT_TERMINATED` = 143 = 128 + 15, the shell's code for a process ended by
SIGTERM.
"""
from __future__ import annotations

import signal
import sys
import threading
from contextlib import contextmanager

__all__ = ["Terminated", "EXIT_TERMINATED", "sigterm_raises", "sigterm_deferred", "stopped"]

#: Exit code of a run or sweep stopped by SIGTERM (128 + signal number, as a shell reports it).
EXIT_TERMINATED = 128 + int(signal.SIGTERM)


class Terminated(KeyboardInterrupt):
    """SIGTERM received (raised in the main thread, like Ctrl-C's KeyboardInterrupt)."""


#: Depth of :func:`sigterm_deferred` blocks, and whether a SIGTERM arrived inside one.
_DEFERRED = {"depth": 0, "pending": False}


def _raise(signum, frame):
    if _DEFERRED["depth"]:
        _DEFERRED["pending"] = True
        return
    raise Terminated()


@contextmanager
def sigterm_deferred():
    """Within the block a SIGTERM waits; :class:`Terminated` is raised when the block ends.

    A converged step is then recorded whole (history row, VTU, checkpoint) or not at all, so
    the checkpoint a resumed run starts from is the step ``summary.json`` reports last.
    """
    _DEFERRED["depth"] += 1
    try:
        yield
    finally:
        _DEFERRED["depth"] -= 1
    if not _DEFERRED["depth"] and _DEFERRED["pending"]:
        _DEFERRED["pending"] = False
        raise Terminated()


@contextmanager
def sigterm_raises():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread.

    Signal handlers can only be set from the main thread; elsewhere (a run inside a Dask
    worker's thread) the block runs unchanged and the worker's own handling applies.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def stopped(exc: KeyboardInterrupt, what: str, hint: str) -> int:
    """Say that a batch (sweep, study, validation set) was stopped and how to go on; return
    its exit code (:data:`EXIT_TERMINATED` for SIGTERM, 130 for Ctrl-C).

    >>> stopped(Terminated(), "sweep", "continue with --resume")
    143
    """
    terminated = isinstance(exc, Terminated)
    print(f"{what} {'terminated' if terminated else 'interrupted'}; {hint}", file=sys.stderr)
    return EXIT_TERMINATED if terminated else 130
