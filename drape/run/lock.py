"""One writer per output folder: a lock held for as long as a run or a sweep writes into it.

Two processes writing into one folder would mix their files (one run's summary beside the
other's history, a PVD listing the VTU files of both). A run, a resumed run and a sweep each
hold the folder's lock file (:data:`LOCK`, an OS-level lock through :mod:`filelock`, released
by the OS when the holder dies) while they write; a second writer is refused at once.
"""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

from filelock import FileLock, Timeout

__all__ = ["LOCK", "FolderInUse", "folder_lock"]

#: Name of the lock file in an output folder.
LOCK = ".drape.lock"


class FolderInUse(OSError):
    """Another process holds the folder's lock (the message names the folder)."""


@contextmanager
def folder_lock(folder):
    """Hold ``folder``'s lock for the block; raise :class:`FolderInUse` if another holds it.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d, folder_lock(d):
    ...     try:
    ...         with folder_lock(d):
    ...             pass
    ...     except FolderInUse as exc:
    ...         print("refused")
    refused
    """
    folder = Path(folder)
    # not thread-local and not shared: a second holder in the same process is refused too
    lock = FileLock(folder / LOCK, blocking=False, thread_local=False)
    try:
        lock.acquire()
    except Timeout:
        raise FolderInUse(f"{folder} is in use by another run or sweep (it holds {LOCK}); wait "
                          f"for it to end or choose another output folder") from None
    try:
        yield folder
    finally:
        lock.release()
