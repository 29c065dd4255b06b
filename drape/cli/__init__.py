"""The command line: the ``drape`` command, one module per subcommand.

``drape run CASE`` is ``python -m drape.run CASE``: each subcommand hands the rest of the
command line to its module's ``main(argv)`` (:mod:`drape.cli.run`, :mod:`drape.cli.sweep`, ...),
so its ``--help`` and its exit codes (:data:`drape.cli.common.EXIT_CODES`) are the tool's.

Examples
--------
>>> main(["--help"])  # doctest: +ELLIPSIS
usage: drape COMMAND [ARGS...]
...
0
>>> main(["--version"])  # doctest: +ELLIPSIS
drape ...
0
>>> main(["frobnicate"])   # the error is one line on stderr
2
>>> main([])               # the usage, on stderr
2
"""
from __future__ import annotations

import importlib
import importlib.metadata
import sys

import drape

__all__ = ["COMMANDS", "DISTRIBUTION", "main", "version"]

#: Subcommand -> (module with ``main(argv)``, what it does).
COMMANDS: dict[str, tuple[str, str]] = {
    "run": ("drape.cli.run", "run one case file (python -m drape.run)"),
    "sweep": ("drape.cli.sweep", "a case over a run table, a grid or seeds (python -m drape.sweep)"),
    "report": ("drape.cli.report", "report.html of a sweep or a run (python -m drape.report)"),
    "validate": ("drape.cli.validate",
                 "the validation cases against their measurements (python -m drape.validate)"),
    "predict": ("drape.cli.predict", "a Cusick drape from a KES sheet, with the interval its "
                                     "missing values leave (python -m drape.predict)"),
    "inspect": ("drape.cli.inspect", "pictures of a finished run (python -m drape.inspect)"),
    "measure": ("drape.cli.measure", "a scanned drape measured like a simulated one "
                                     "(python -m drape.measure)"),
    "identify": ("drape.cli.identify", "the bending law from scanned drapes "
                                       "(python -m drape.identify)"),
    "fit": ("drape.cli.fit", "fit the bending law to KES-FB loops (python -m constitutive.fit)"),
    "datasets": ("drape.cli.datasets", "the thesis's KES-FB loops, an example CSV export "
                                       "(python -m constitutive.datasets)"),
}

#: The distribution whose version ``drape --version`` prints.
DISTRIBUTION = "fabric-drape"

# drape.cli.common.EXIT_BAD_INPUT, not imported: common loads drape.run, and with it the runner
_EXIT_BAD_INPUT = 2


def version() -> str:
    """The installed distribution's version, else the package's own (a source tree on the path)."""
    try:
        return importlib.metadata.version(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        return drape.__version__


def _usage() -> str:
    width = max(map(len, COMMANDS))
    rows = "\n".join(f"  {name:<{width}}  {what}" for name, (_, what) in COMMANDS.items())
    return (f"usage: drape COMMAND [ARGS...]\n\ncommands:\n{rows}\n\n"
            "drape COMMAND --help shows a command's options; drape --version the version.")


def main(argv: list[str] | None = None) -> int:
    """Run ``drape COMMAND ARGS...``; returns the command's exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv:
        print(_usage(), file=sys.stderr)
        return _EXIT_BAD_INPUT
    if argv[0] in ("-h", "--help"):
        print(_usage())
        return 0
    if argv[0] == "--version":
        print(f"drape {version()}")
        return 0
    name, rest = argv[0], argv[1:]
    if name not in COMMANDS:
        print(f"error: unknown command {name!r} (see drape --help)", file=sys.stderr)
        return _EXIT_BAD_INPUT
    # The one import kept out of the module top: only the chosen command's module is loaded,
    # so that ``drape --help`` does not wait for the solver, Dask and the plotting libraries.
    module = importlib.import_module(COMMANDS[name][0])
    return module.main(rest)
