"""``drape inspect`` / ``python -m drape.inspect DIR``: pictures of a finished (or stopped) run.

Writes, into the run directory unless ``--out`` says otherwise (:mod:`drape.run.pictures`),
the deformed fabric coloured by a field, ``history.png`` and, for a KES-FB run,
``kes_loop.png``; prints the files written.
"""
from __future__ import annotations

import argparse
import os
import sys

from drape.cli.common import EXIT_BAD_INPUT, EXIT_OK
from drape.run.pictures import (
    InspectError,
    available,
    contact_bodies,
    plot_history,
    plot_kes_loop,
    render_step,
)

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m drape.inspect",
        description="PNG pictures of a drape.run.runner output directory: the deformed fabric coloured "
                    "by a field (pyvista, off-screen) and plots of history.csv (matplotlib).",
        epilog="Example: python -m drape.inspect out/cantilever --field moment_xx --step -1",
    )
    p.add_argument("directory", help="run output directory (holds <name>.pvd and history.csv)")
    p.add_argument("--field", help="point or cell field to colour by (default: curvature_xx); "
                                   "vectors are shown by magnitude")
    p.add_argument("--step", type=int, default=-1,
                   help="output step index in the PVD (default -1: the last one)")
    p.add_argument("--out", metavar="PNG", help="file for the 3-D picture (default: in DIRECTORY)")
    p.add_argument("--list", action="store_true", help="print the fields and output times, and exit")
    p.add_argument("--no-history", action="store_true", help="skip the history plots")
    return p


def _list(directory) -> int:
    """``--list``: the fields and the output times."""
    names, times = available(directory)
    print("fields: " + ", ".join(names))
    print(f"{len(times)} output steps, t = " + ", ".join(f"{t:.4g}" for t in times))
    return EXIT_OK


def _pictures(args) -> list:
    """The pictures the options ask for, written; their paths."""
    written = [render_step(args.directory, args.field, args.step, args.out,
                           bodies=contact_bodies(args.directory))]
    if not args.no_history:
        written.append(plot_history(args.directory))
        loop = plot_kes_loop(args.directory)
        if loop is not None:
            written.append(loop)
    return written


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code (:data:`drape.cli.common.EXIT_CODES`)."""
    args = _parser().parse_args(argv)
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    try:
        if args.list:
            return _list(args.directory)
        written = _pictures(args)
    except InspectError as err:
        print(f"error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    for path in written:
        print(path)
    return EXIT_OK
