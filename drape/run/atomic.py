"""Files written whole or not at all, with the mode a plain ``open()`` gives.

:func:`atomic_write` has a writer fill a temporary file beside the target, then moves it onto
the target with ``os.replace``: a reader (a resumed run, ParaView, another tool) sees the old
file or the new one, never half of one, whenever the writer dies. The temporary file is
created the way ``open(path, "w")`` creates a file, with mode ``0o666`` less the process's
umask (and the folder's default ACL), so the final file is as readable as every file
written plainly beside it; :func:`tempfile.mkstemp` would make it ``0o600`` whatever the
umask.

Examples
--------
>>> import tempfile
>>> with tempfile.TemporaryDirectory() as d:
...     path = Path(d) / "note.txt"
...     _ = atomic_write(path, lambda tmp: tmp.write_text("whole\\n"))
...     path.read_text(), sorted(p.name for p in Path(d).iterdir())
('whole\\n', ['note.txt'])
"""
from __future__ import annotations

import os
import secrets
from pathlib import Path
from typing import Callable

__all__ = ["atomic_write", "atomic_write_text"]

#: Tries at a free temporary name (a clash of 48 random bits is already next to impossible).
_TRIES = 100


def _new_temporary(path: Path) -> Path:
    """An empty file beside ``path``, created as ``open()`` creates one (0o666 & ~umask)."""
    for _ in range(_TRIES):
        tmp = path.with_name(f".{path.name}.{secrets.token_hex(6)}.tmp")
        try:
            # O_EXCL: never take over a file someone else made; 0o666: the kernel applies the
            # umask (and a default ACL) exactly as for a plain open()
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise FileExistsError(f"{path.parent}: no free temporary name for {path.name}")


def atomic_write(path, write: Callable[[Path], object]) -> Path:
    """Call ``write(tmp)`` on a new temporary file beside ``path``, then move it onto ``path``.

    Parameters
    ----------
    path : str or Path
        The file to (re)write; its folder must exist.
    write : callable
        Fills the temporary file, given its path (it may open it in any mode, or hand the
        path to a library that writes it).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    Whatever ``write`` raises (or OSError from the file system); the temporary file is
    removed and ``path`` is left as it was.
    """
    path = Path(path)
    tmp = _new_temporary(path)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` through :func:`atomic_write`."""
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding=encoding))
