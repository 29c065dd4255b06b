"""A scanned Cusick drape as a surface: reading it, checking it, finding its disc.

A scan is any triangle (or quad) surface meshio reads (PLY, OBJ, STL, VTU, ...) of a specimen
hanging in a Cusick tester, in the drape meter's frame: metres, the disc's top near z = 0, the
skirt hanging towards -z, the disc centre near (0, 0) but not exactly on it.  A VTU written
by :mod:`drape.run.runner` holds the flat reference mesh and its ``displacement``; it is read as the
deformed surface ``points + displacement``.

Each check here raises :class:`ScanError` with one line that says what is wrong and what to
do about it: coordinates that are not finite, a scan in other units than metres (its extent a
hundred or a thousand times the specimen's) or of no plausible size in any unit (a stray
vertex), no flat disc top, a scan that reaches beyond the stated specimen by more than
:data:`EXTENT_REFUSED`. What a scan must be besides to be read as a drape (its area, its
disc, its coverage of the annulus, its holes) is checked in :mod:`drape.analyses.scan_checks`.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely

from meshes.io import read_quietly, surface_triangles

__all__ = ["ScanError", "DiscTop", "EXTENT_SILENT", "EXTENT_REFUSED", "read_scan", "check_finite",
           "check_units", "find_disc_top", "check_extent"]

#: Unit slips recognised by their factor to metres: (name, scale factor that converts them).
_UNIT_SLIPS = (("centimetres", 1e-2), ("millimetres", 1e-3), ("micrometres", 1e-6))
#: How far (decades) a scan's size in a slipped unit may lie from a drape's to be named as it.
_SLIP_DECADES = 0.5
#: A scan's reach past the stated specimen radius (fraction of it): up to EXTENT_SILENT it is
#: the scanner's noise and the fabric's thickness; up to EXTENT_REFUSED a stretched fabric or
#: an offset registration, measured with a warning; beyond, another specimen size.
EXTENT_SILENT = 0.01
EXTENT_REFUSED = 0.05


class ScanError(ValueError):
    """A scan that cannot be read as a Cusick drape (message: one line)."""


@dataclass(frozen=True)
class DiscTop:
    """The flat top of a draped specimen: where it lies on the disc.

    Attributes
    ----------
    centre : tuple of float
        Centre (x, y) of the circle fitted to the flat region's outline (m).
    radius : float
        Radius of that circle (m): about the disc radius.
    level : float
        Height z of the top (m).
    n_vertices : int
        Scan vertices within the tolerance of that height.
    """

    centre: tuple
    radius: float
    level: float
    n_vertices: int


def _triangles(mesh) -> np.ndarray:
    """The mesh's triangles; quads are split in two, other cells ignored."""
    triangles = surface_triangles(mesh)
    if triangles is None:
        kinds = ", ".join(sorted({b.type for b in mesh.cells})) or "none"
        raise ScanError(f"no triangles: not a surface mesh (cells: {kinds})")
    return triangles


def _read_mesh(path: Path):
    """The mesh in ``path``; every failure one :class:`ScanError` line."""
    return read_quietly(path, ScanError)


def read_scan(path, scale: float = 1.0):
    """Vertices and triangles of a scanned (or simulated) drape, in metres.

    Parameters
    ----------
    path : str or Path
        Any surface mesh meshio reads.
    scale : float
        Factor taking the file's coordinates to metres (0.001 for millimetres).

    Returns
    -------
    points : ndarray, shape (N, 3)
    triangles : ndarray of int, shape (T, 3)

    Raises
    ------
    ScanError
        Missing or unreadable file, or no triangles in it.
    """
    path = Path(path)
    if path.is_dir():
        raise ScanError(f"{path}: is a folder, not a mesh file")
    if not path.is_file():
        raise ScanError(f"{path}: no such file")
    mesh = _read_mesh(path)
    triangles = _triangles(mesh)
    points = np.zeros((len(mesh.points), 3))
    dim = min(3, mesh.points.shape[1]) if mesh.points.ndim == 2 else 0
    points[:, :dim] = mesh.points[:, :dim]
    u = mesh.point_data.get("displacement")
    if u is not None and np.shape(u) == points.shape:
        points = points + u
    if triangles.size and (triangles.min() < 0 or triangles.max() >= len(points)):
        raise ScanError(f"{path}: triangles refer to vertices the file does not have")
    return scale * points, triangles


def check_finite(points) -> None:
    """Refuse NaN or infinite coordinates."""
    bad = ~np.all(np.isfinite(points), axis=1)
    if bad.any():
        raise ScanError(f"{int(bad.sum())} of {len(bad)} vertices have NaN or infinite coordinates")


def check_units(points, specimen_radius: float, disc_radius: float) -> None:
    """Refuse a scan whose size says it is not in metres, or is no drape in any unit.

    The projected extent of a drape lies between the disc's and the specimen's diameter; one
    ten times the specimen or more, or under half the disc, is in other units. Vertices that
    lie that far from all the others are stray ones, and a size no unit slip explains is
    refused with the extent it has.
    """
    xy = points[:, :2]
    span = float(np.ptp(xy, axis=0).max()) if len(points) else 0.0
    diameter = 2.0 * specimen_radius
    stated = f"a {_cm(diameter)} specimen"
    if span > 10.0 * diameter:
        _check_stray(xy, diameter, stated)
        ratio = span / diameter
        name, factor = min(_UNIT_SLIPS, key=lambda u: abs(np.log10(ratio * u[1])))
        if abs(np.log10(ratio * factor)) > _SLIP_DECADES:
            raise ScanError(f"scan spans {span:.4g} across, {ratio:.3g} times {stated}: not a "
                            f"drape in metres, centimetres, millimetres or micrometres")
        raise ScanError(f"scan spans {span:.4g} across for {stated}: looks like {name}, convert to "
                        f"metres or pass --scale {factor:g}")
    if span < disc_radius:
        raise ScanError(f"scan spans {span:.4g} across, less than the {_cm(2 * disc_radius)} disc: "
                        f"not in metres? convert or pass --scale")


def _check_stray(xy, diameter: float, stated: str) -> None:
    """Refuse a scan of which a few vertices lie ten specimens or more from the rest."""
    dist = np.hypot(*(xy - np.median(xy, axis=0)).T)
    far = dist > 10.0 * diameter
    if 0 < far.sum() <= 0.01 * len(xy):
        rest = float(np.ptp(xy[~far], axis=0).max())
        raise ScanError(f"{int(far.sum())} of {len(xy)} vertices lie up to {dist.max():.4g} from "
                        f"the others, which span {rest:.4g} across for {stated}: stray vertices, "
                        f"remove them")


def _cm(length: float) -> str:
    return f"{100.0 * length:.4g} cm"


def _fit_circle(xy) -> tuple[np.ndarray, float]:
    """Least-squares (algebraic) circle through points: centre and radius."""
    a = np.column_stack([2.0 * xy, np.ones(len(xy))])
    sol, *_ = np.linalg.lstsq(a, np.sum(xy**2, axis=1), rcond=None)
    centre = sol[:2]
    return centre, float(np.sqrt(max(sol[2] + centre @ centre, 0.0)))


def find_disc_top(points, disc_radius: float, tolerance: float = 3e-4,
                  n_outline: int = 360) -> DiscTop:
    """Where the specimen lies flat on the disc: its height, centre and radius.

    The top level is a high percentile of z (a stray point above it does not count), the flat
    region every vertex within ``tolerance`` of it.  A circle is fitted to the outline of that
    region (its convex hull, sampled evenly along its length, so that dense and sparse parts of
    the scan weigh alike): a specimen lying on the disc makes a flat disc, a simulated one
    clamped on the disc's edge a ring of that radius; either way the circle is the disc's.

    Parameters
    ----------
    points : ndarray, shape (N, 3)
        Vertices in metres.
    disc_radius : float
        Stated disc radius (m): the region found must reach at least half of it.
    tolerance : float
        Height band of the flat region (m).
    n_outline : int
        Points the hull's outline is sampled at.

    Returns
    -------
    DiscTop

    Raises
    ------
    ScanError
        No flat top, or one far smaller than the disc.
    """
    z = points[:, 2]
    level = float(np.percentile(z, 99.5))
    top = points[z >= level - tolerance, :2]
    hull = shapely.MultiPoint(top).convex_hull
    if hull.geom_type != "Polygon":
        raise ScanError(f"disc top not found: no flat region at the top level z = {level:.4g} m")
    ring = hull.exterior
    xy = shapely.get_coordinates(
        shapely.line_interpolate_point(ring, np.linspace(0.0, 1.0, n_outline, endpoint=False),
                                       normalized=True))
    centre, radius = _fit_circle(xy)
    if radius < 0.5 * disc_radius:
        raise ScanError(f"disc top not found: the flat region at z = {level:.4g} m reaches only "
                        f"r = {_cm(radius)}, the disc's radius is {_cm(disc_radius)}")
    return DiscTop((float(centre[0]), float(centre[1])), radius, level, len(top))


def check_extent(points, centre, specimen_radius: float) -> str | None:
    """Refuse a scan that reaches farther from the disc centre than the stated specimen.

    A hanging specimen's shadow lies within its flat radius. A reach past it up to
    :data:`EXTENT_SILENT` of it is the scanner's noise; up to :data:`EXTENT_REFUSED`, a
    stretched fabric or an offset registration, which is measured: the warning is returned.

    Returns
    -------
    str or None
        The warning, one line, or None.

    Raises
    ------
    ScanError
        Beyond :data:`EXTENT_REFUSED` of the stated radius.
    """
    reach = float(np.max(np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1])))
    past = reach / specimen_radius - 1.0
    if past > EXTENT_REFUSED:
        raise ScanError(f"scan reaches r = {_cm(reach)} from the disc centre, beyond the stated "
                        f"specimen radius {_cm(specimen_radius)} by more than "
                        f"{100 * EXTENT_REFUSED:g} %: pass --specimen")
    if past > EXTENT_SILENT:
        return (f"scan reaches r = {_cm(reach)} from the disc centre, {100 * past:.1f} % past the "
                f"stated specimen radius {_cm(specimen_radius)} (a stretched fabric or an offset "
                f"registration?); measured")
    return None
