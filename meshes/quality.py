"""Mesh checks run on every mesh this package creates or imports.

A bad mesh fails early with a message naming the offending node, triangle or
boundary instead of surfacing later as a singular stiffness matrix.

Examples
--------
>>> import numpy as np
>>> from skfem import MeshTri
>>> report = check_mesh(MeshTri().with_boundaries({"left": lambda x: x[0] == 0}))
>>> report.n_triangles, round(report.min_angle_deg, 6), report.boundary_facets
(2, 45.0, {'left': 1})
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable

import numpy as np
from numpy import ndarray
from scipy.spatial import cKDTree

__all__ = ["MeshError", "MeshQuality", "check_arrays", "check_mesh",
           "triangle_areas", "triangle_angles"]


class MeshError(ValueError):
    """A mesh violates a validity rule (message names the entity and the rule)."""


@dataclass(frozen=True)
class MeshQuality:
    """Summary of a checked mesh (lengths in metres, angles in degrees)."""

    n_nodes: int
    n_triangles: int
    area: float
    min_angle_deg: float
    h_min: float
    h_max: float
    boundary_facets: dict = field(default_factory=dict)


def triangle_areas(p: ndarray, t: ndarray) -> ndarray:
    """Signed areas of the triangles ``t`` (3, M) on the points ``p`` (2, N).

    >>> triangle_areas(np.array([[0., 1, 0], [0, 0, 1]]), np.array([[0], [1], [2]]))
    array([0.5])
    """
    a, b, c = (p[:, t[k]] for k in range(3))
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def triangle_angles(p: ndarray, t: ndarray) -> ndarray:
    """Interior angles (3, M) in degrees; angle k sits at vertex ``t[k]``.

    >>> triangle_angles(np.array([[0., 1, 0], [0, 0, 1]]), np.array([[0], [1], [2]])).ravel()
    array([90., 45., 45.])
    """
    angles = np.empty(t.shape)
    for k in range(3):
        u = p[:, t[(k + 1) % 3]] - p[:, t[k]]
        v = p[:, t[(k + 2) % 3]] - p[:, t[k]]
        cross = np.abs(u[0] * v[1] - u[1] * v[0])
        angles[k] = np.degrees(np.arctan2(cross, np.sum(u * v, axis=0)))
    return angles


def check_arrays(p: ndarray, t: ndarray, rel_tol: float = 1e-9) -> None:
    """Check raw node and triangle arrays before building a mesh.

    Rules: ``p`` is (2, N) and finite; ``t`` is (3, M) of valid node indices;
    no duplicated nodes (closer than ``rel_tol`` × bounding-box diagonal); every
    node used by a triangle; no triangle of zero area.

    >>> check_arrays(np.array([[0., 1, 2], [0, 0, 0]]), np.array([[0], [1], [2]]))
    Traceback (most recent call last):
    ...
    meshes.quality.MeshError: triangle 0 has zero area (nodes 0, 1, 2)
    """
    p = np.asarray(p, dtype=float)
    t = np.asarray(t)
    if p.ndim != 2 or p.shape[0] != 2 or p.shape[1] < 3:
        raise MeshError(f"node array must have shape (2, N >= 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        bad = int(np.nonzero(~np.all(np.isfinite(p), axis=0))[0][0])
        raise MeshError(f"node {bad} has a non-finite coordinate {p[:, bad]}")
    if t.ndim != 2 or t.shape[0] != 3 or t.shape[1] < 1:
        raise MeshError(f"triangle array must have shape (3, M >= 1), got {t.shape}")
    if not np.issubdtype(t.dtype, np.integer):
        raise MeshError(f"triangle array must hold integer node indices, got {t.dtype}")
    if t.min() < 0 or t.max() >= p.shape[1]:
        j = int(np.nonzero((t.min(axis=0) < 0) | (t.max(axis=0) >= p.shape[1]))[0][0])
        raise MeshError(f"triangle {j} refers to a node outside 0..{p.shape[1] - 1}: {t[:, j]}")
    repeated = (t[0] == t[1]) | (t[1] == t[2]) | (t[0] == t[2])
    if np.any(repeated):
        j = int(np.nonzero(repeated)[0][0])
        raise MeshError(f"triangle {j} repeats a node: {t[:, j]}")
    diag = float(np.linalg.norm(p.max(axis=1) - p.min(axis=1)))
    pairs = cKDTree(p.T).query_pairs(rel_tol * diag, output_type="ndarray")
    if len(pairs):
        i, j = sorted(pairs[0])
        raise MeshError(f"nodes {i} and {j} are duplicated (coincide at {p[:, i]})")
    unused = np.setdiff1d(np.arange(p.shape[1]), t)
    if len(unused):
        raise MeshError(f"node {unused[0]} is not used by any triangle")
    area = triangle_areas(p, t)
    zero = np.abs(area) <= rel_tol * diag**2
    if np.any(zero):
        j = int(np.nonzero(zero)[0][0])
        raise MeshError(f"triangle {j} has zero area (nodes {', '.join(map(str, t[:, j]))})")


def _check_folds(mesh) -> None:
    """Neighbouring triangles must lie on opposite sides of their shared edge."""
    edge_use = np.bincount(mesh.t2f.ravel(), minlength=mesh.facets.shape[1])
    if np.any(edge_use > 2):
        f = int(np.nonzero(edge_use > 2)[0][0])
        raise MeshError(f"edge {mesh.facets[:, f]} is shared by {edge_use[f]} triangles")
    interior = np.nonzero(mesh.f2t[1] >= 0)[0]
    a, b = mesh.p[:, mesh.facets[0, interior]], mesh.p[:, mesh.facets[1, interior]]
    side = []
    for s in range(2):
        centroid = mesh.p[:, mesh.t[:, mesh.f2t[s, interior]]].mean(axis=1)
        side.append((b[0] - a[0]) * (centroid[1] - a[1]) - (b[1] - a[1]) * (centroid[0] - a[0]))
    folded = side[0] * side[1] >= 0
    if np.any(folded):
        f = interior[np.nonzero(folded)[0][0]]
        t0, t1 = mesh.f2t[:, f]
        raise MeshError(f"triangles {t0} and {t1} overlap (inverted/folded at edge "
                        f"{mesh.facets[0, f]}-{mesh.facets[1, f]})")


def check_mesh(mesh, required_boundaries: Iterable[str] = (), min_angle: float = 5.0,
               rel_tol: float = 1e-9) -> MeshQuality:
    """Check a :class:`skfem.MeshTri` and return its :class:`MeshQuality`.

    Parameters
    ----------
    mesh
        The mesh (with optional named boundaries ``mesh.boundaries``).
    required_boundaries
        Names that must exist; every named boundary must be non-empty.
    min_angle
        Smallest admissible interior angle in degrees.
    rel_tol
        Relative tolerance for coincident nodes and zero areas.

    Raises
    ------
    MeshError
        Naming the node, triangle, edge or boundary that breaks a rule.
    """
    p, t = mesh.p, mesh.t
    if p.shape[0] != 2 or t.shape[0] != 3:
        raise MeshError(f"expected a 2-D triangle mesh, got p {p.shape} and t {t.shape}")
    check_arrays(p, t, rel_tol)
    _check_folds(mesh)
    angles = triangle_angles(p, t)
    worst = angles.min(axis=0)
    if worst.min() < min_angle:
        j = int(np.argmin(worst))
        raise MeshError(f"triangle {j} has a {worst[j]:.3g} degree angle "
                        f"(rule: min_angle >= {min_angle} degrees)")
    boundaries = dict(mesh.boundaries or {})
    for name in required_boundaries:
        if name not in boundaries:
            known = ", ".join(sorted(boundaries)) or "none"
            raise MeshError(f"boundary '{name}' is missing (mesh has: {known})")
    for name, facets in boundaries.items():
        if len(facets) == 0:
            raise MeshError(f"boundary '{name}' is empty")
    lengths = np.linalg.norm(p[:, mesh.facets[0]] - p[:, mesh.facets[1]], axis=0)
    return MeshQuality(
        n_nodes=p.shape[1], n_triangles=t.shape[1],
        area=float(np.abs(triangle_areas(p, t)).sum()),
        min_angle_deg=float(worst.min()),
        h_min=float(lengths.min()), h_max=float(lengths.max()),
        boundary_facets={k: len(v) for k, v in boundaries.items()},
    )
