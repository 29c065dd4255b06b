"""Rigid bodies as triangulated surfaces: plane patch, sphere, cylinder, rounded box, disc.

Each builder returns a :class:`~drape.contact.surface.Surface` in metres, its triangles
oriented outwards; every body but the plane patch is closed. ``resolution`` is, for every
round shape, the number of segments along a full circle of it (the sphere's great circles,
the cylinder's and the disc's rims, the box's rounded edges seen end on): area and volume
approach the smooth body's as it grows, with an error of order ``resolution⁻²``. A surface
from a file is read by :func:`read_surface`.

Examples
--------
>>> import math
>>> ball = sphere((0, 0, 0), 0.1, resolution=24)
>>> ball.is_closed(), round(ball.area() / (4 * math.pi * 0.1 ** 2), 3)
(True, 0.995)
>>> table = disc((0, 0, 0.7), radius=0.4, thickness=0.03, edge_radius=0.01)
>>> float(table.bounds()[1, 2])          # its top face is at the centre's height
0.7
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import ContactInputError
from .surface import Surface, placement
from .surface_file import read_surface

__all__ = ["Surface", "plane", "sphere", "cylinder", "rounded_box", "disc", "read_surface",
           "placement"]

#: Segments of a great circle of the icosahedron (edge angle 63.43°), doubled at each subdivision.
_ICOSAHEDRON_SEGMENTS = 360.0 / math.degrees(math.acos(1 / math.sqrt(5)))


# --------------------------------------------------------------------------- checks
def _vector(name, value) -> np.ndarray:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.isfinite(v).all():
        raise ContactInputError(f"{name} must be three finite numbers, not {value!r}")
    return v


def _direction(name, value) -> np.ndarray:
    v = _vector(name, value)
    length = np.linalg.norm(v)
    if length == 0:
        raise ContactInputError(f"{name} must not be the zero vector")
    return v / length


def _positive(name, value) -> float:
    if not (isinstance(value, (int, float, np.number)) and math.isfinite(value) and value > 0):
        raise ContactInputError(f"{name} must be a positive number, not {value!r}")
    return float(value)


def _segments(resolution, least=3) -> int:
    if not (isinstance(resolution, (int, np.integer)) and resolution >= least):
        raise ContactInputError(f"resolution must be an integer >= {least}, not {resolution!r}")
    return int(resolution)


# --------------------------------------------------------------------------- plane patch
def plane(point, normal, size, resolution: int = 4) -> Surface:
    """A square patch of side ``size`` centred at ``point``, facing ``normal``.

    Parameters
    ----------
    point : array_like, shape (3,)
        Centre of the patch (m).
    normal : array_like, shape (3,)
        Direction the patch faces (the fabric's side); need not be unit.
    size : float
        Side of the square (m). One in-plane side runs along the projection of x (of y when
        the normal is near x).
    resolution : int
        Divisions per side: ``2 resolution²`` triangles, so a fabric bent over the patch
        meets many triangles rather than one long diagonal.
    """
    centre, n = _vector("point", point), _direction("normal", normal)
    size, k = _positive("size", size), _segments(resolution, least=1)
    guide = np.eye(3)[0] if abs(n[0]) < 0.9 else np.eye(3)[1]
    e1 = guide - (guide @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    s = np.linspace(-0.5 * size, 0.5 * size, k + 1)
    u, v = (a.ravel() for a in np.meshgrid(s, s, indexing="ij"))
    vertices = centre + u[:, None] * e1 + v[:, None] * e2
    return Surface(vertices, _grid_triangles(k, k))


def _grid_triangles(nu: int, nv: int) -> np.ndarray:
    """Triangles of an (nu+1) × (nv+1) grid numbered ``i (nv+1) + j``, counter-clockwise in (u, v)."""
    i, j = (a.ravel() for a in np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij"))
    a = i * (nv + 1) + j
    b, c, d = a + nv + 1, a + nv + 2, a + 1          # (i+1, j), (i+1, j+1), (i, j+1)
    return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


# --------------------------------------------------------------------------- sphere
def sphere(centre, radius, resolution: int = 24) -> Surface:
    """A sphere as an icosphere: the least subdivided one with ``resolution`` segments or more
    along a great circle (pyvista's ``Icosphere``; vertices on the sphere, triangles nearly equal).
    """
    import pyvista as pv

    centre, radius = _vector("centre", centre), _positive("radius", radius)
    k = _segments(resolution)
    level = max(0, math.ceil(math.log2(k / _ICOSAHEDRON_SEGMENTS)))
    ball = pv.Icosphere(radius=radius, center=centre, nsub=level)
    return Surface(np.asarray(ball.points, dtype=float), ball.faces.reshape(-1, 4)[:, 1:])


# --------------------------------------------------------------------------- bodies of revolution
def _revolve(profile: np.ndarray, segments: int) -> Surface:
    """The closed surface swept by a profile (r, z) about the z axis.

    ``profile`` runs from a point on the axis (r = 0, the top pole) outwards and down to
    another point on the axis (the bottom pole), so that the body lies to its right; rings are
    numbered after the top pole, the bottom pole last.
    """
    keep = np.ones(len(profile), dtype=bool)
    keep[1:] = np.linalg.norm(np.diff(profile, axis=0), axis=1) > 1e-12 * np.ptp(profile)
    rings = profile[keep][1:-1]
    theta = 2 * np.pi * np.arange(segments) / segments
    ring_points = np.stack([rings[:, :1] * np.cos(theta), rings[:, :1] * np.sin(theta),
                            np.repeat(rings[:, 1:], segments, axis=1)], axis=-1).reshape(-1, 3)
    top, bottom = [0.0, 0.0, profile[0, 1]], [0.0, 0.0, profile[-1, 1]]
    vertices = np.vstack([top, ring_points, bottom])
    j, jn = np.arange(segments), (np.arange(segments) + 1) % segments
    first, last = 1, 1 + (len(rings) - 1) * segments
    parts = [np.stack([np.zeros(segments, int), first + j, first + jn], 1)]
    for r in range(len(rings) - 1):
        a, b = 1 + r * segments + j, 1 + r * segments + jn      # this ring at θ_j, θ_j+1
        d, c = a + segments, b + segments                      # the next ring outwards/down
        parts += [np.stack([b, a, d], 1), np.stack([b, d, c], 1)]
    parts.append(np.stack([np.full(segments, len(vertices) - 1), last + jn, last + j], 1))
    return Surface(vertices, np.concatenate(parts))


def _arc(centre, radius, start, stop, pieces) -> np.ndarray:
    angle = np.linspace(start, stop, pieces + 1)
    return np.stack([centre[0] + radius * np.cos(angle), centre[1] + radius * np.sin(angle)], 1)


def _segment(a, b, pieces) -> np.ndarray:
    return np.linspace(a, b, max(1, pieces) + 1)


def _rounded_profile(radius, thickness, edge_radius, segments) -> np.ndarray:
    """Profile (r, z) of a disc with its top at z = 0 and rounded rim edges, pole to pole."""
    e, flat = edge_radius, radius - edge_radius
    spacing = 2 * np.pi * radius / segments
    quarter = max(1, math.ceil(segments / 4)) if e > 0 else 1
    pieces = [_segment([0.0, 0.0], [flat, 0.0], round(flat / spacing)),
              _arc([flat, -e], e, np.pi / 2, 0.0, quarter),
              _segment([radius, -e], [radius, e - thickness], round((thickness - 2 * e) / spacing)),
              _arc([flat, e - thickness], e, 0.0, -np.pi / 2, quarter),
              _segment([flat, -thickness], [0.0, -thickness], round(flat / spacing))]
    return np.vstack(pieces)


def _oriented(surface: Surface, centre, axis) -> Surface:
    """``surface`` built about +z at the origin, turned so +z becomes ``axis``, then moved."""
    turn = Rotation.align_vectors([axis], [[0.0, 0.0, 1.0]])[0].as_matrix()
    return Surface(surface.vertices @ turn.T + centre, surface.triangles)


def cylinder(centre, axis, radius, length, resolution: int = 24) -> Surface:
    """A closed circular cylinder (flat end caps).

    Parameters
    ----------
    centre : array_like, shape (3,)
        Midpoint of its axis (m).
    axis : array_like, shape (3,)
        Direction of its axis.
    radius, length : float
        Radius and length (m).
    resolution : int
        Segments round the rim; the side and caps are divided into triangles of about the
        same size.
    """
    centre, axis = _vector("centre", centre), _direction("axis", axis)
    radius, length = _positive("radius", radius), _positive("length", length)
    k = _segments(resolution)
    body = _revolve(_rounded_profile(radius, length, 0.0, k) + [0.0, 0.5 * length], k)
    return _oriented(body, centre, axis)


def disc(centre, radius, thickness, edge_radius=0.0, resolution: int = 48) -> Surface:
    """A flat round body with axis z whose top face is at the centre's height: a Cusick disc or
    a round table top, its rim edges rounded.

    Parameters
    ----------
    centre : array_like, shape (3,)
        Centre of the top face (m).
    radius, thickness : float
        Radius and thickness (m); the bottom face is at ``centre z − thickness``.
    edge_radius : float
        Radius of the rounded rim edges (m), ``0 <= edge_radius <= thickness / 2`` and below
        ``radius``; 0 leaves sharp edges.
    resolution : int
        Segments round the rim; each rounded edge takes a quarter of them.
    """
    centre = _vector("centre", centre)
    radius, thickness = _positive("radius", radius), _positive("thickness", thickness)
    e = float(edge_radius)
    if not (math.isfinite(e) and 0 <= e <= 0.5 * thickness and e < radius):
        raise ContactInputError(f"edge_radius must be between 0 and half the thickness "
                                f"({0.5 * thickness:g} m), not {edge_radius!r}")
    k = _segments(resolution)
    body = _revolve(_rounded_profile(radius, thickness, e, k), k)
    return Surface(body.vertices + centre, body.triangles)


# --------------------------------------------------------------------------- rounded box
def rounded_box(centre, size, edge_radius=0.0, resolution: int = 24) -> Surface:
    """A box with rounded edges and corners: the points within ``edge_radius`` of a smaller box.

    Parameters
    ----------
    centre : array_like, shape (3,)
        Centre of the box (m).
    size : array_like, shape (3,)
        Full extents along x, y, z (m).
    edge_radius : float
        Radius of the rounded edges and corners (m), at most half the smallest extent;
        0 gives a sharp box.
    resolution : int
        Segments a rounded edge would have round a full circle, rounded up to a multiple of
        8 (a quarter on each edge, half of that from each face it joins); flat faces get triangles of about the size of the edge's, but no finer than
        ``max(size) / resolution``.

    Notes
    -----
    Built by mapping grids on the faces of the outer box onto the rounded box: a point q goes
    to ``c + e (q − c)/|q − c|`` with c the nearest point of the inner box.
    """
    centre, size = _vector("centre", centre), _vector("size", size)
    for extent in size:
        _positive("size", extent)
    half, e, k = 0.5 * size, float(edge_radius), _segments(resolution, least=4)
    if not (math.isfinite(e) and 0 <= e <= half.min()):
        raise ContactInputError(f"edge_radius must be between 0 and half the smallest extent "
                                f"({half.min():g} m), not {edge_radius!r}")
    inner = half - e
    quarter = max(1, math.ceil(k / 8)) if e > 0 else 0
    band = e * np.tan(np.linspace(0.0, np.pi / 4, quarter + 1)) if e > 0 else np.zeros(1)
    coarsest = size.max() / k
    axes = []
    for h, i in zip(half, inner):
        spacing = max(band[1] - band[0] if quarter else 0.0, coarsest)
        flat = np.linspace(-i, i, max(1, math.ceil(2 * i / spacing)) + 1) if i > 0 else np.zeros(1)
        axes.append(np.unique(np.concatenate([-(i + band[::-1]), flat, i + band])))
    vertices, triangles = _box_faces(axes, half)
    if e > 0:
        nearest = np.clip(vertices, -inner, inner)
        offset = vertices - nearest
        vertices = nearest + e * offset / np.linalg.norm(offset, axis=1, keepdims=True)
    return Surface(vertices + centre, triangles)


def _box_faces(axes, half):
    """The six faces of the box ``[-half, half]`` as grids on ``axes``, merged at the edges."""
    points, triangles, count = [], [], 0
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3              # e_i × e_j = e_k
        u, v = np.meshgrid(axes[i], axes[j], indexing="ij")
        grid = _grid_triangles(len(axes[i]) - 1, len(axes[j]) - 1)
        for side in (1.0, -1.0):
            p = np.empty((u.size, 3))
            p[:, i], p[:, j], p[:, k] = u.ravel(), v.ravel(), side * half[k]
            points.append(p)
            triangles.append(count + (grid if side > 0 else grid[:, ::-1]))
            count += len(p)
    points, triangles = np.vstack(points), np.vstack(triangles)
    # the same edge point of two faces is one vertex: merge on coordinates rounded far below the grid
    key = np.round(points / half.max(), 9)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return points[first], inverse.ravel()[triangles]
