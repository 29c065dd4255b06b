"""What every analysis shares: its input (:class:`RunContext`), its record, its errors.

A leaf of :mod:`drape.analyses`: the analysis modules and the registry import it, it imports
none of them.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from drape.models.fields import flat_fields

__all__ = ["AnalysisInputError", "RunContext", "Analysis", "plain"]


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
        s = self.state
        return flat_fields(self.model.fields(s.u, s.v, s.a), self.mesh)


@dataclass(frozen=True)
class Analysis:
    """A post-processing hook: ``finish(ctx) -> dict`` and an optional per-step ``probe``."""

    name: str
    finish: Callable[[RunContext], dict]
    probe: Callable[[RunContext, dict], dict] | None = None


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
