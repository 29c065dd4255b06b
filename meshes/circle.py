"""A whole circular specimen (SI, metres): rings of nearly equilateral triangles.

Ring k of n carries 6k vertices at radius ``k R / n`` (the centre is ring 0), each ring
turned half a step from the one inside it; the Delaunay triangulation of these points
(scipy) has no angle much below 40° and its hem vertices lie exactly on the circle.

Examples
--------
>>> mesh = circle(0.3, n_rings=6)
>>> sorted(mesh.boundaries), mesh.p.shape[1], mesh.t.shape[1]
(['hem'], 127, 216)
>>> round(float(np.hypot(*mesh.p).max()), 12)
0.15
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial import Delaunay
from skfem import MeshTri

from .quality import check_mesh
from .rectangle import positive, positive_int

__all__ = ["circle"]


def circle(diameter: float = 0.30, n_rings: int | None = None, target_size: float = 0.01,
           centre=(0.0, 0.0)) -> MeshTri:
    """Triangle mesh of a whole circular specimen.

    Parameters
    ----------
    diameter : float
        Specimen diameter [m].
    n_rings : int, optional
        Rings of triangles from the centre to the hem; default ``ceil(radius / target_size)``.
    target_size : float
        Nominal element size [m] for the default.
    centre : tuple of float
        Centre of the specimen.

    Returns
    -------
    skfem.MeshTri
        With the boundary ``hem`` (the whole outline).
    """
    radius = 0.5 * positive("diameter", diameter)
    h = positive("target_size", target_size)
    n = positive_int("n_rings", n_rings if n_rings is not None
                     else max(1, math.ceil(radius / h - 1e-9)))
    points = [np.zeros((1, 2))]
    for k in range(1, n + 1):
        angle = 2 * np.pi * (np.arange(6 * k) + 0.5 * (k % 2)) / (6 * k)
        points.append(k * radius / n * np.column_stack([np.cos(angle), np.sin(angle)]))
    p = np.vstack(points)
    t = Delaunay(p).simplices
    mesh = MeshTri(np.ascontiguousarray((p + np.asarray(centre, dtype=float)).T),
                   np.ascontiguousarray(t.T))
    cx, cy = (float(v) for v in centre)
    inner = radius * (1 - 0.5 / n)          # boundary facet midpoints lie beyond this
    mesh = mesh.with_boundaries({"hem": lambda x: np.hypot(x[0] - cx, x[1] - cy) > inner})
    check_mesh(mesh, ("hem",))
    return mesh
