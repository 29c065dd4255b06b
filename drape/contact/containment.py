"""Whether points lie inside a closed rigid body: the generalized winding number.

A body's triangles, counter-clockwise seen from outside, subtend at a point a total solid
angle of 4π when the point is inside a closed surface and 0 outside; divided by 4π that is
the winding number, 1 or 0 (−1 inside a surface oriented inwards). Summed triangle by
triangle (Van Oosterom and Strackee's formula for each triangle's solid angle; Jacobson,
Kavan and Sorkine-Hornung 2013, *Robust inside-outside segmentation using generalized
winding numbers*) it needs no ray and no case analysis of rays through edges or vertices,
and it stays near 0 or 1 away from the surface even where the mesh has small cracks.
Only a closed surface has an inside (:func:`has_inside`): a plane patch has none.

Examples
--------
>>> from drape.contact.shapes import plane, sphere
>>> ball = sphere((0, 0, 0), 0.1, resolution=12)
>>> np.round(winding_number(ball.vertices, ball.triangles, [[0, 0, 0], [0.3, 0, 0]]), 6).tolist()
[1.0, 0.0]
>>> has_inside(ball), has_inside(plane((0, 0, 0), (0, 0, 1), 1.0))
(True, False)
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .surface import Surface

__all__ = ["winding_number", "inside", "has_inside", "one_point_per_piece"]

#: Point–triangle pairs evaluated at once (bounds the memory of a large body).
_CHUNK = 1 << 20


def _solid_angles(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Signed solid angle of each triangle (m, 3, 3) at each point (k, 3), summed: (k,)."""
    a, b, c = (corners[None, :, i, :] - points[:, None, :] for i in range(3))
    la, lb, lc = (np.linalg.norm(v, axis=2) for v in (a, b, c))
    det = np.einsum("kmi,kmi->km", a, np.cross(b, c))
    den = (la * lb * lc + np.einsum("kmi,kmi->km", a, b) * lc
           + np.einsum("kmi,kmi->km", b, c) * la + np.einsum("kmi,kmi->km", c, a) * lb)
    return 2.0 * np.arctan2(det, den).sum(axis=1)


def winding_number(vertices, triangles, points) -> np.ndarray:
    """The generalized winding number of a triangulated surface at ``points``.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
    triangles : array_like of int, shape (m, 3)
        Counter-clockwise seen from outside.
    points : array_like, shape (k, 3)

    Returns
    -------
    ndarray, shape (k,)
        About 1 inside a closed, outward oriented surface, 0 outside it.
    """
    corners = np.asarray(vertices, dtype=float)[np.asarray(triangles)]
    points = np.atleast_2d(np.asarray(points, dtype=float))
    step = max(1, _CHUNK // max(1, len(corners)))
    out = [_solid_angles(corners, points[i:i + step]) for i in range(0, len(points), step)]
    return np.concatenate(out) / (4.0 * np.pi) if out else np.zeros(0)


def inside(vertices, triangles, points) -> np.ndarray:
    """Whether each point lies inside the closed surface (either orientation), shape (k,)."""
    return np.abs(winding_number(vertices, triangles, points)) > 0.5


def has_inside(surface) -> bool:
    """Whether ``surface`` (``vertices``, ``triangles``) encloses a volume: closed
    (:meth:`~drape.contact.surface.Surface.is_closed`) once the vertices that coincide are
    merged, as a mesh file may repeat each vertex for every triangle it belongs to."""
    vertices, merged = np.unique(np.asarray(surface.vertices, dtype=float), axis=0,
                                 return_inverse=True)
    triangles = merged.reshape(-1)[np.asarray(surface.triangles)]
    if (triangles == triangles[:, [1, 2, 0]]).any():
        return False                                  # a triangle the merge collapsed
    return Surface(vertices, triangles).is_closed()


def one_point_per_piece(n_points: int, triangles) -> np.ndarray:
    """Index of one point of each connected piece of a triangulation (a point no triangle
    uses is a piece of its own): a piece that crosses no surface lies wholly on one side."""
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    rows = triangles[:, [0, 1, 2]].ravel()
    cols = triangles[:, [1, 2, 0]].ravel()
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n_points, n_points))
    _, label = connected_components(graph, directed=False)
    _, first = np.unique(label, return_index=True)
    return first
