"""A rigid body's surface from a mesh file: anything meshio reads (PLY, OBJ, STL, VTU, ...).

Triangles are kept and quads split in two; vertices no triangle uses are dropped. Every
problem is one :class:`~drape.contact.errors.ContactInputError` line naming the file: it is
missing or unreadable, holds no triangles, has coordinates that are not finite or triangles
of zero area. The file's normals are taken as they are (outwards, counter-clockwise seen from
outside, as STL and most exporters write them).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from constitutive.units import parse_unit, ureg

from meshes.io import read_quietly, surface_triangles

from .errors import ContactInputError
from .surface import Surface

__all__ = ["read_surface", "length_factor"]

#: Triangles whose area is below this fraction of the squared bounding-box diagonal are degenerate.
_DEGENERATE = 1e-14


def length_factor(units: str) -> float:
    """Metres per length unit ``units`` (any length pint knows: "m", "mm", "cm", "inch", ...).

    >>> length_factor("mm")
    0.001
    """
    try:
        unit = parse_unit(str(units))
        return float(ureg.Quantity(1.0, unit).to("m").magnitude)
    except Exception as exc:  # pint's DimensionalityError and parse_unit's ValueError alike
        reason = str(exc) if isinstance(exc, ValueError) and "dimension" not in str(exc).lower() \
            else "not a length"
        raise ContactInputError(f"units {units!r}: {reason} (e.g. 'm', 'cm', 'mm')") from None


def _read(path: Path):
    """The mesh in ``path``; every failure one :class:`ContactInputError` line."""
    return read_quietly(path, ContactInputError)


def _triangles(mesh, path) -> np.ndarray:
    triangles = surface_triangles(mesh)
    if triangles is None:
        kinds = ", ".join(sorted({b.type for b in mesh.cells})) or "none"
        raise ContactInputError(f"{path}: not a surface (no triangles or quads; cells: {kinds})")
    return triangles


def read_surface(path, units: str = "m", scale: float = 1.0) -> Surface:
    """The surface in a mesh file, in metres.

    Parameters
    ----------
    path : str or Path
        Any surface mesh meshio reads.
    units : str
        Length unit of the file's coordinates ("m", "mm", "cm", "inch", ...).
    scale : float
        Further factor (> 0) on the coordinates, after the units.

    Returns
    -------
    Surface

    Raises
    ------
    ContactInputError
        Missing or unreadable file, no triangles, coordinates that are not finite, degenerate
        triangles, bad units or scale.
    """
    path = Path(path)
    factor = length_factor(units)
    if not (np.isfinite(scale) and scale > 0):
        raise ContactInputError(f"scale must be a positive number, not {scale!r}")
    if not path.is_file():
        raise ContactInputError(f"{path}: no such file")
    mesh = _read(path)
    triangles = _triangles(mesh, path)
    points = np.zeros((len(mesh.points), 3))
    points[:, :min(3, mesh.points.shape[1])] = np.asarray(mesh.points, dtype=float)[:, :3]
    if triangles.min() < 0 or triangles.max() >= len(points):
        raise ContactInputError(f"{path}: triangles refer to vertices the file does not have")
    used, triangles = np.unique(triangles, return_inverse=True)
    points, triangles = points[used], triangles.reshape(-1, 3)
    bad = ~np.isfinite(points).all(axis=1)
    if bad.any():
        raise ContactInputError(f"{path}: {int(bad.sum())} of {len(points)} vertices have NaN or "
                                f"infinite coordinates")
    _check_degenerate(points, triangles, path)
    return Surface(factor * scale * points, triangles)


def _check_degenerate(points, triangles, path) -> None:
    a, b, c = (points[triangles[:, k]] for k in range(3))
    doubled = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    diagonal = np.linalg.norm(np.ptp(points, axis=0))
    bad = np.flatnonzero(doubled <= 2 * _DEGENERATE * diagonal ** 2)
    if bad.size:
        raise ContactInputError(f"{path}: {bad.size} degenerate triangle(s) of zero area "
                                f"(first: triangle {bad[0]}, vertices {triangles[bad[0]].tolist()})")
