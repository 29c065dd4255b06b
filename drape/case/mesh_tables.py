"""The ``[mesh]`` table of a case: a strip, a rectangle, a Cusick annulus, a circle or a mesh file.
"""
from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import (
    Field,
    model_validator,
)

from drape.case.quantities import Q, _rule, _Section
from meshes import graded_nodes

__all__ = ['FineZone', 'StripMesh', 'RectangleMesh', 'CusickMesh', 'CircleMesh', 'FileMesh', 'MeshSpec']


class _MeshBase(_Section):
    element: Literal["morley", "argyris"] = "argyris"
    """Finite element: ``morley`` (quadratic, small deflection only) or ``argyris`` (quintic)."""


class FineZone(_Section):
    """[mesh.fine_zone] of a strip: finer cells on a stretch of its length, e.g. where it passes
    a tester's edge and bends sharply (``meshes.graded_nodes``)."""

    start: Q("m", ge=0)
    """Where the zone begins along x [m]."""
    end: Q("m", gt=0)
    """Where it ends [m]; outside it, cells of about length / nx."""
    nx: int = Field(ge=1)
    """Divisions of the zone."""

    @model_validator(mode="after")
    def _ordered(self):
        if self.start >= self.end:
            raise _rule(f"@.start = {self.start:g} m must be below @.end = {self.end:g} m")
        return self


class StripMesh(_MeshBase):
    """[mesh] kind = "strip": [0, length] x [0, width]; boundaries ``clamped`` (= ``left``, x = 0),
    ``free_end`` (= ``right``), ``bottom``, ``top``."""

    kind: Literal["strip"]
    length: Q("m", gt=0)
    """Strip length along x (warp) [m]."""
    width: Q("m", gt=0)
    """Strip width along y [m]."""
    nx: int = Field(ge=1)
    """Divisions along the length."""
    ny: int = Field(1, ge=1)
    """Divisions across the width."""
    fine_zone: FineZone | None = None
    """Finer cells on a stretch of the length (none by default)."""

    @model_validator(mode="after")
    def _zone_inside(self):
        if self.fine_zone is not None and self.fine_zone.end > self.length:
            raise _rule(f"@.fine_zone.end = {self.fine_zone.end:g} m lies beyond the strip's "
                        f"length {self.length:g} m")
        return self

    def x_nodes(self):
        """Node abscissae along the length, or None for nx equal cells."""
        if self.fine_zone is None:
            return None
        z = self.fine_zone
        return graded_nodes(self.length, self.nx, z.start, z.end, z.nx)


class RectangleMesh(_MeshBase):
    """[mesh] kind = "rectangle": [0, length] x [0, width]; boundaries ``left``, ``right``,
    ``bottom``, ``top``."""

    kind: Literal["rectangle"]
    length: Q("m", gt=0)
    """Side along x (warp) [m]."""
    width: Q("m", gt=0)
    """Side along y (weft) [m]."""
    nx: int = Field(ge=1)
    """Divisions along x."""
    ny: int = Field(ge=1)
    """Divisions along y."""


class CusickMesh(_MeshBase):
    """[mesh] kind = "cusick": the overhanging annulus, centred at 0; boundaries ``disc``, ``hem``."""

    kind: Literal["cusick"]
    specimen_diameter: Q("m", gt=0) = 0.30
    """Specimen diameter [m] (standard: 0.24, 0.30 or 0.36)."""
    disc_diameter: Q("m", gt=0) = 0.18
    """Support disc diameter [m]."""
    target_size: Q("m", gt=0) = 0.01
    """Nominal element size [m]; sets the divisions not given explicitly."""
    n_radial: int | None = Field(None, ge=1)
    """Element rings across the overhang (default: overhang / target_size)."""
    n_circumferential: int | None = Field(None, ge=8)
    """Divisions around the circumference, even (default: twice the prime nearest to half of
    mid circumference / target_size, a grid that favours no fold count)."""
    refine: int = Field(0, ge=0)
    """Uniform refinements (divisions × 2**refine) for convergence studies."""
    radial_grading: float = Field(1.0, ge=1.0)
    """Outermost over innermost ring width (1: uniform); finer rings at the clamped disc edge,
    where a limp fabric turns down within about one bending length."""

    @model_validator(mode="after")
    def _disc_inside(self):
        if self.disc_diameter >= self.specimen_diameter:
            raise _rule(
                f"@.disc_diameter = {self.disc_diameter} must be smaller than "
                f"@.specimen_diameter = {self.specimen_diameter}"
            )
        return self


class CircleMesh(_MeshBase):
    """[mesh] kind = "circle": a whole circular specimen centred at 0 (a drape over a body);
    boundary ``hem``."""

    kind: Literal["circle"]
    diameter: Q("m", gt=0)
    """Specimen diameter [m]."""
    target_size: Q("m", gt=0) = 0.01
    """Nominal element size [m]; sets the rings when ``n_rings`` is not given."""
    n_rings: int | None = Field(None, ge=1)
    """Rings of triangles from the centre to the hem (6 n_rings² triangles)."""


class FileMesh(_MeshBase):
    """[mesh] kind = "file": an external triangle mesh read with meshio (gmsh .msh, .vtu, ...);
    boundaries are the file's named line groups."""

    kind: Literal["file"]
    path: str
    """Mesh file; relative paths are taken from the case file's directory."""
    scale: float = Field(1.0, gt=0)
    """Factor taking the file's coordinates to metres (0.01 for a file in cm)."""


MeshSpec = Annotated[
    Union[StripMesh, RectangleMesh, CusickMesh, CircleMesh, FileMesh], Field(discriminator="kind")
]


# --------------------------------------------------------------------------- [material]
