"""Cusick drape test: drape coefficient, nodes and top view of a settled specimen."""
from __future__ import annotations

from drape.analyses.base import plain
from drape.analyses.drape_coefficient import cusick_post

NAME = "cusick"


def finish(ctx) -> dict:
    """:func:`drape.analyses.drape_coefficient.cusick_post` of the final state.

    The large-rotation shell's shadow is that of its computed surface sampled inside every
    triangle (:meth:`drape.models.shell.KirchhoffLoveShell.deformed_surface`), not of the flat
    triangles between its vertices.
    """
    spec = ctx.case.mesh
    table = {"specimen_diameter": spec.specimen_diameter, "disc_diameter": spec.disc_diameter}
    u = ctx.state.u
    surface = ctx.model.deformed_surface(u) if ctx.case.model.kinematics == "large" else None
    out = cusick_post(ctx.mesh, ctx.model.nodal_displacement(u), table, ctx.out_dir,
                      name=ctx.case.case.name, surface=surface)
    return plain(out)
