"""Peirce / ASTM D1388 cantilever: bending length and rigidity of a settled strip.

The strip overhangs from its one clamped boundary to ``free_end`` (:mod:`drape.analyses.bending_length`).
"""
from __future__ import annotations

from constitutive.units import G0
from drape.analyses import bending_length as peirce
from drape.analyses.base import AnalysisInputError, plain

NAME = "peirce"


def finish(ctx) -> dict:
    """Tip drop and angles, Peirce c, G and G/B_KES (:func:`drape.analyses.bending_length.peirce_summary`).

    The large-rotation shell reads the tip slope from its gradient dofs and picks the warp or
    weft B from the strip's direction (:func:`drape.analyses.bending_length.shell_peirce_summary`); the plate's
    strips run along x, so B_KES is the slope of the warp law's simulated KES-FB loop.
    """
    if ctx.case.mesh.kind != "strip":
        raise AnalysisInputError("case.analysis = 'peirce' needs mesh.kind = 'strip'")
    clamped = [b for b, kind in ctx.case.model.supports.items() if kind == "clamped"]
    if len(clamped) != 1:
        raise AnalysisInputError("case.analysis = 'peirce' needs exactly one clamped boundary")
    s = ctx.state
    if ctx.case.model.kinematics == "large":
        out = peirce.shell_peirce_summary(ctx.model, s.u, clamped=clamped[0], free="free_end")
    else:
        B_kes = float(ctx.material.simulated_kes()["warp"].B)
        gravity = ctx.case.load.gravity
        W = ctx.material.areal_mass * G0 * (
            0.0 if gravity is None else gravity.factor * gravity.amplitude(s.t))
        out = peirce.peirce_summary(ctx.mesh, ctx.model.nodal_displacement(s.u), W, B_kes=B_kes,
                                    clamped=clamped[0], free="free_end")
    return plain(out)
