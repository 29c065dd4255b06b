"""``njit``: numba's compiler with an on-disk cache wherever one can be written.

Numba caches compiled functions next to their module (``__pycache__``), else in the user's
cache directory, or in ``NUMBA_CACHE_DIR`` when set, so a fresh install compiles each
kernel once. Where no directory is writable (a read-only install without
``NUMBA_CACHE_DIR``) numba refuses ``cache=True``; the kernels are then compiled once per
process instead of failing the import. :func:`cache_is_cold` tells whether the kernels defined so far
still have to be compiled (a fresh install), so that a run can say why its first steps wait.

The material laws' kernels and the finite-element kernels of :mod:`drape.fem` share it.
"""
from __future__ import annotations

from numba import njit as _numba_njit

__all__ = ["njit", "cache_is_cold"]

#: Compiled functions with an on-disk cache, in the order they were defined.
_CACHED = []


def njit(*args, **options):
    """``numba.njit`` with an on-disk cache where numba finds a writable cache directory
    and without one (compiled once per process) where it finds none."""
    def decorate(function):
        try:
            compiled = _numba_njit(**options)(function)
            if options.get("inline") != "always":   # an inlined function has no cache of its own
                _CACHED.append(compiled)
            return compiled
        except RuntimeError:          # "cannot cache function ...: no locator available"
            options.pop("cache", None)
            return _numba_njit(**options)(function)
    return decorate(args[0]) if args else decorate


def cache_is_cold() -> bool:
    """True when most functions defined with a cache have none on disk for their current source
    (a fresh install, or a numba upgrade): their first call compiles them."""
    missing = 0
    for function in _CACHED:
        try:
            missing += not function._cache._cache_file._load_index()
        except Exception:  # numba's cache internals differ between versions: assume cached
            pass
    return missing > len(_CACHED) / 2
