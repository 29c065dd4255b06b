"""Compiled kernels' set-up: ``njit`` and how many threads a parallel kernel may use.

``njit`` and :func:`cache_is_cold` are :mod:`constitutive.compiled`'s (numba's compiler with
its on-disk cache where one can be written), shared with the material laws' kernels.
"""
from __future__ import annotations

from constitutive.compiled import cache_is_cold, njit

__all__ = ["njit", "cache_is_cold", "limit_threads", "thread_limit"]

#: The most threads a parallel kernel of this process may use (None: numba's pool size).
_THREAD_LIMIT = None


def limit_threads(n: int | None) -> None:
    """Let parallel kernels of this process use at most ``n`` threads (None: every thread).

    A sweep's worker runs on one core. The cap is kept here, not in ``NUMBA_NUM_THREADS``:
    numba re-reads that variable whenever it compiles, and refuses a value other than the
    one its thread pool was launched with (a worker that had already run a kernel would
    fail at its next compilation).
    """
    global _THREAD_LIMIT
    _THREAD_LIMIT = None if n is None else max(1, int(n))


def thread_limit() -> int | None:
    """The cap of :func:`limit_threads` (None: none)."""
    return _THREAD_LIMIT
