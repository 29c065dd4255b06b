"""The ``drape`` command: one entry point, a subcommand per tool.

``drape run CASE`` is ``python -m drape.run CASE``: each subcommand hands the rest of the
command line to the tool's own ``main(argv)``, so its ``--help`` and its exit codes
(:data:`drape.run.cli.EXIT_CODES`) are the tool's. The tool's module is imported only when its
subcommand is chosen, so ``drape --help`` stays quick.

Examples
--------
>>> main(["--help"])  # doctest: +ELLIPSIS
usage: drape COMMAND [ARGS...]
...
0
>>> main(["frobnicate"])
error: unknown command 'frobnicate' (see drape --help)
2
"""
from __future__ import annotations

import importlib
import sys

__all__ = ["COMMANDS", "main"]

#: Subcommand -> (module with ``main(argv)``, what it does).
COMMANDS: dict[str, tuple[str, str]] = {
    "run": ("drape.run.runner", "run one case file (python -m drape.run)"),
    "sweep": ("drape.batch.sweep_cli", "a case over a run table, a grid or seeds (python -m drape.sweep)"),
    "report": ("drape.batch.report", "report.html of a sweep or a run (python -m drape.report)"),
    "validate": ("drape.batch.validation_set",
                 "the validation cases against their measurements (python -m drape.validate)"),
    "inspect": ("drape.run.pictures", "pictures of a finished run (python -m drape.inspect)"),
    "measure": ("drape.analyses.scan_measure", "a scanned drape measured like a simulated one "
                                                "(python -m drape.measure)"),
    "identify": ("drape.identification.cli", "the bending law from scanned drapes "
                                              "(python -m drape.identify)"),
    "fit": ("constitutive.fit.cli", "fit the bending law to KES-FB loops (python -m constitutive.fit)"),
}

_EXIT_BAD_INPUT = 2   # drape.run.cli.EXIT_BAD_INPUT, not imported: it would load the runner


def _usage() -> str:
    width = max(map(len, COMMANDS))
    rows = "\n".join(f"  {name:<{width}}  {what}" for name, (_, what) in COMMANDS.items())
    return (f"usage: drape COMMAND [ARGS...]\n\ncommands:\n{rows}\n\n"
            "drape COMMAND --help shows a command's options.")


def main(argv: list[str] | None = None) -> int:
    """Run ``drape COMMAND ARGS...``; returns the command's exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] in ("-h", "--help"):
        print(_usage())
        return 0 if argv else _EXIT_BAD_INPUT
    name, rest = argv[0], argv[1:]
    if name not in COMMANDS:
        print(f"error: unknown command {name!r} (see drape --help)", file=sys.stdout)
        return _EXIT_BAD_INPUT
    module = importlib.import_module(COMMANDS[name][0])
    return module.main(rest)
