"""Post-processing of a finished run, chosen by ``[case] analysis``.

Every analysis is a module with the same small interface:

``NAME``
    The ``[case] analysis`` value that selects it.
``finish(ctx) -> dict``
    Entries for ``summary["analysis"]`` from the :class:`RunContext` of the finished run.
``probe(ctx, fields) -> dict`` (optional)
    Extra scalar ``history.csv`` columns of every converged step (``fields`` are the flat
    model fields of that step).

:data:`ANALYSES` maps each name to its :class:`Analysis`; the case schema accepts exactly its
keys. A script adds its own with :func:`register` (and removes it with :func:`unregister`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from drape.analyses import cusick, cycle, kes, peirce

__all__ = ["RunContext", "Analysis", "ANALYSES", "register", "unregister", "plain",
           "AnalysisInputError"]


class AnalysisInputError(ValueError):
    """The case does not fit the analysis it asks for (the message names the key)."""


@dataclass
class RunContext:
    """What an analysis sees: the case, the built parts, the final state and the history."""

    case: Any
    mesh: Any
    material: Any
    model: Any
    out_dir: Path
    state: Any = None
    history: list[dict] = field(default_factory=list)

    def fields(self) -> dict:
        """Model output fields of the final state (flat ``name -> array``)."""
        from drape.output import flat_fields

        s = self.state
        return flat_fields(self.model.fields(s.u, s.v, s.a), self.mesh)


@dataclass(frozen=True)
class Analysis:
    """A post-processing hook: ``finish(ctx) -> dict`` and an optional per-step ``probe``."""

    name: str
    finish: Callable[[RunContext], dict]
    probe: Callable[[RunContext, dict], dict] | None = None


def _from_module(module) -> Analysis:
    return Analysis(module.NAME, module.finish, getattr(module, "probe", None))


#: Analyses by ``[case] analysis`` name.
ANALYSES: dict[str, Analysis] = {
    "none": Analysis("none", lambda ctx: {}),
    **{m.NAME: _from_module(m) for m in (peirce, cusick, kes, cycle)},
}


def register(name: str, probe=None):
    """Decorator registering ``finish(ctx) -> dict`` as analysis ``name`` (with an optional probe).

    >>> @register("demo")
    ... def _demo(ctx):
    ...     return {"answer": 42}
    >>> ANALYSES["demo"].finish(None)
    {'answer': 42}
    >>> unregister("demo")
    """

    def wrap(finish):
        ANALYSES[name] = Analysis(name, finish, probe)
        return finish

    return wrap


def unregister(name: str) -> None:
    """Remove analysis ``name`` (registered with :func:`register`)."""
    del ANALYSES[name]


def plain(obj):
    """Summary-friendly copy: dataclasses and mappings to dicts, numpy to Python.

    >>> plain({"a": np.arange(2), "b": (np.float64(1.5),)})
    {'a': [0, 1], 'b': [1.5]}
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        obj = dataclasses.asdict(obj)
    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if hasattr(obj, "_asdict"):
        return plain(obj._asdict())
    return obj
