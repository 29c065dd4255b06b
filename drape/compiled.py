"""``njit``: numba's compiler with an on-disk cache wherever one can be written.

Numba caches compiled functions next to their module (``__pycache__``), else in the user's
cache directory, or in ``NUMBA_CACHE_DIR`` when set, so a fresh install compiles each
kernel once. Where no directory is writable (a read-only install without
``NUMBA_CACHE_DIR``) numba refuses ``cache=True``; the kernels are then compiled once per
process instead of failing the import.
"""
from __future__ import annotations

from numba import njit as _numba_njit

__all__ = ["njit"]


def njit(*args, **options):
    """``numba.njit`` with an on-disk cache where numba finds a writable cache directory
    and without one (compiled once per process) where it finds none."""
    def decorate(function):
        try:
            return _numba_njit(**options)(function)
        except RuntimeError:          # "cannot cache function ...: no locator available"
            options.pop("cache", None)
            return _numba_njit(**options)(function)
    return decorate(args[0]) if args else decorate
