"""The case file: its tables (pydantic schema), the whole case, and what is built from it.

The only layer that knows the case file's keys; the models and solvers below it take plain
numbers, arrays and functions of time.

Modules
-------
schema
    The case file's tables other than ``[load]``, with units.
loads
    The ``[load]`` tables.
case
    :class:`Case`, :func:`load_case`, ``--set`` overrides, cross-table rules.
setup
    A case on a set-up (``setup = "cusick"``): the set-up's tables under the case's own.
help
    ``--help-case`` text from the JSON schema.
build
    Case → mesh, material, model, solver settings; initial fields.
timeline
    Time-step phases, times to land on, quasi-static pseudo-times.
"""
from drape.case.build import Parts, RunInputError, build
from drape.case.case import (Case, CaseError, apply_overrides, dump_case, load_case, parse_case,
                             read_case_data)
from drape.case.setup import merge_setup

__all__ = ["Case", "CaseError", "load_case", "parse_case", "read_case_data", "merge_setup",
           "apply_overrides", "dump_case", "Parts", "RunInputError", "build"]
