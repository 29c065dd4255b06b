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

Modules
-------
base
    :class:`RunContext`, :class:`Analysis`, :func:`plain`.
peirce, cusick, kes, cycle, peirce_platform
    The analyses (``NAME``, ``finish``, ``probe``).
bending_length
    Peirce / ASTM D1388: bending length and flexural rigidity of a cantilever.
platform_reading
    The Peirce tester's reading: overhang beyond a platform's edge, chord angle, the 41.5° line.
drape_coefficient
    Cusick: drape coefficient, nodes, shadow and top view.
outline
    The drape outline's harmonic amplitudes.
scan, scan_measure
    A scanned drape read and measured like a simulated one (``drape measure``).
intersections
    Whether triangles of a deformed surface cross each other or a body (Möller's test), a
    check of the contact solver by another route.
"""
from __future__ import annotations

from drape.analyses import cusick, cycle, kes, peirce, peirce_platform
from drape.analyses.base import Analysis, AnalysisInputError, RunContext, plain

__all__ = ["RunContext", "Analysis", "ANALYSES", "register", "unregister", "plain",
           "AnalysisInputError"]


def _from_module(module) -> Analysis:
    return Analysis(module.NAME, module.finish, getattr(module, "probe", None))


#: Analyses by ``[case] analysis`` name.
ANALYSES: dict[str, Analysis] = {
    "none": Analysis("none", lambda ctx: {}),
    **{m.NAME: _from_module(m) for m in (peirce, cusick, kes, cycle, peirce_platform)},
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
