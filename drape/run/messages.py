"""What went wrong, in one line: a run table's or a sweep row's reason, a tool's error.

A schema error lists one problem a line; a results table and a terminal want one line.

>>> describe(FileNotFoundError(2, "No such file or directory", "out/x"))
"No such file or directory: 'out/x'"
>>> describe(KeyError("mesh"))
"KeyError: 'mesh'"
>>> one_line("mesh.length\\n  must be > 0")
'mesh.length; must be > 0'
"""
from __future__ import annotations

__all__ = ["one_line", "describe"]


def one_line(text) -> str:
    """``text`` with its lines joined by ``; `` (a schema error lists one problem a line)."""
    return "; ".join(part.strip() for part in str(text).splitlines() if part.strip())


def describe(exc: BaseException) -> str:
    """What went wrong, in one line: the message, and for an OS error what it was about."""
    if isinstance(exc, OSError) and exc.strerror:
        where = f": {str(exc.filename)!r}" if exc.filename is not None else ""
        return f"{exc.strerror}{where}"
    text = one_line(exc)
    if isinstance(exc, (ValueError, OSError)):
        return text or type(exc).__name__
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
