"""Do triangles of a deformed surface cross each other or a body? An independent check.

The contact solver keeps surfaces apart by a barrier on their distances; this module checks
its result by another route: Möller's triangle–triangle test (T. Möller, "A fast
triangle-triangle intersection test", Journal of Graphics Tools 2(2), 25–30, 1997), exact up
to floating point, vectorised over candidate pairs, after a broad phase on the triangles'
bounding spheres (:class:`scipy.spatial.cKDTree`) and boxes.

Triangles are closed sets: two that only touch (a shared point, an edge lying on a face)
count as intersecting. :func:`self_intersections` leaves out pairs that share a vertex, which
touch by construction.

Examples
--------
>>> import numpy as np
>>> flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
>>> upright = np.array([[0.2, 0.2, -0.5], [0.2, 0.2, 0.5], [0.3, 0.3, 0]], float)
>>> intersections(flat, [[0, 1, 2]], upright, [[0, 1, 2]]).tolist()
[[0, 0]]
>>> intersections(flat, [[0, 1, 2]], upright + [0, 0, 0.6], [[0, 1, 2]]).tolist()
[]
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["self_intersections", "intersections", "triangles_intersect"]

#: Relative size below which a vertex's distance to the other triangle's plane counts as zero.
_PLANE_TOL = 1e-12
#: Candidate pairs tested at once (bounds the narrow phase's memory).
_CHUNK = 100_000


# --------------------------------------------------------------------------- public
def self_intersections(points, triangles) -> np.ndarray:
    """Pairs of triangles of one surface that intersect, leaving out pairs sharing a vertex.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Vertex positions (deformed).
    triangles : array_like of int, shape (m, 3)

    Returns
    -------
    ndarray of int, shape (k, 2)
        Triangle index pairs ``(i, j)`` with ``i < j``, sorted.
    """
    points, triangles = _arrays(points, triangles)
    boxes = _boxes(points[triangles])
    i, j = _candidates(boxes, boxes)
    keep = i < j
    i, j = i[keep], j[keep]
    shared = (triangles[i][:, :, None] == triangles[j][:, None, :]).any(axis=(1, 2))
    return _narrow(points[triangles], points[triangles], i[~shared], j[~shared])


def intersections(points_a, triangles_a, points_b, triangles_b) -> np.ndarray:
    """Pairs ``(triangle of a, triangle of b)`` of two surfaces that intersect.

    Returns
    -------
    ndarray of int, shape (k, 2)
        Sorted index pairs, the first into ``triangles_a``, the second into ``triangles_b``.
    """
    pa, ta = _arrays(points_a, triangles_a)
    pb, tb = _arrays(points_b, triangles_b)
    i, j = _candidates(_boxes(pa[ta]), _boxes(pb[tb]))
    return _narrow(pa[ta], pb[tb], i, j)


def triangles_intersect(p, q) -> np.ndarray:
    """Möller's test on pairs of triangles.

    Parameters
    ----------
    p, q : array_like, shape (k, 3, 3)
        Corners of the k first and k second triangles.

    Returns
    -------
    ndarray of bool, shape (k,)
        Whether each pair shares at least one point.
    """
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    n1, dq = _plane_distances(p, q)
    n2, dp = _plane_distances(q, p)
    apart = _one_side(dq) | _one_side(dp)
    coplanar = (dp == 0).all(axis=1)
    result = np.zeros(len(p), dtype=bool)
    crossing = ~apart & ~coplanar
    if crossing.any():
        result[crossing] = _intervals_overlap(p[crossing], q[crossing], n1[crossing],
                                              n2[crossing], dp[crossing], dq[crossing])
    flat = ~apart & coplanar
    if flat.any():
        result[flat] = _coplanar_intersect(p[flat], q[flat], n1[flat])
    return result


# --------------------------------------------------------------------------- broad phase
def _arrays(points, triangles):
    points = np.asarray(points, dtype=float)
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must be an (n, 3) array, not {points.shape}")
    return points, triangles


def _boxes(corners):
    """Axis-aligned bounding boxes (lower, upper), each (m, 3)."""
    return corners.min(axis=1), corners.max(axis=1)


def _candidates(boxes_a, boxes_b):
    """Index pairs whose bounding boxes overlap, found through their bounding spheres."""
    (lo_a, hi_a), (lo_b, hi_b) = boxes_a, boxes_b
    if len(lo_a) == 0 or len(lo_b) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    centre_a, centre_b = 0.5 * (lo_a + hi_a), 0.5 * (lo_b + hi_b)
    radius_a = 0.5 * np.linalg.norm(hi_a - lo_a, axis=1)
    radius_b = 0.5 * np.linalg.norm(hi_b - lo_b, axis=1)
    # a sphere of b within r_a + r_b of a's centre has its centre within r_a + max r_b
    near = cKDTree(centre_b).query_ball_point(centre_a, radius_a + radius_b.max() * (1 + 1e-12))
    counts = np.fromiter((len(n) for n in near), dtype=np.int64, count=len(near))
    i = np.repeat(np.arange(len(near)), counts)
    j = np.fromiter((k for n in near for k in n), dtype=np.int64, count=int(counts.sum()))
    overlap = ((lo_a[i] <= hi_b[j]) & (lo_b[j] <= hi_a[i])).all(axis=1)
    return i[overlap], j[overlap]


def _narrow(corners_a, corners_b, i, j) -> np.ndarray:
    hits = [np.zeros((0, 2), dtype=np.int64)]
    for start in range(0, len(i), _CHUNK):
        a, b = i[start:start + _CHUNK], j[start:start + _CHUNK]
        touch = triangles_intersect(corners_a[a], corners_b[b])
        hits.append(np.stack([a[touch], b[touch]], axis=1))
    pairs = np.concatenate(hits)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


# --------------------------------------------------------------------------- Möller's test
def _plane_distances(tri, other):
    """Normal of ``tri``'s plane and the (scaled) signed distances of ``other``'s corners from
    it, those within round-off of the plane set to exactly zero."""
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    distance = np.einsum("kij,kj->ki", other - tri[:, :1], normal)
    size = np.abs(np.concatenate([tri, other], axis=1) - tri[:, :1]).max(axis=(1, 2))
    tolerance = _PLANE_TOL * np.linalg.norm(normal, axis=1) * size
    distance[np.abs(distance) <= tolerance[:, None]] = 0.0
    return normal, distance


def _one_side(d):
    return (d > 0).all(axis=1) | (d < 0).all(axis=1)


def _interval(projection, d):
    """Where the line of the two planes runs through a triangle: its interval (lo, hi) on
    that line, from the corner alone on its side of the other plane (Möller's cases)."""
    d0, d1, d2 = d.T
    alone = np.select([d0 * d1 > 0, d0 * d2 > 0, (d1 * d2 > 0) | (d0 != 0), d1 != 0],
                      [2, 1, 0, 1], default=2)
    rows = np.arange(len(d))
    first, second = (alone + 1) % 3, (alone + 2) % 3
    p_alone, d_alone = projection[rows, alone], d[rows, alone]
    ends = []
    for k in (first, second):
        p_k, d_k = projection[rows, k], d[rows, k]
        ends.append(p_k + (p_alone - p_k) * d_k / (d_k - d_alone))
    return np.minimum(*ends), np.maximum(*ends)


def _intervals_overlap(p, q, n1, n2, dp, dq):
    direction = np.cross(n1, n2)
    axis = np.abs(direction).argmax(axis=1)          # project onto the largest component
    rows = np.arange(len(p))
    lo_p, hi_p = _interval(p[rows, :, axis], dp)
    lo_q, hi_q = _interval(q[rows, :, axis], dq)
    return np.maximum(lo_p, lo_q) <= np.minimum(hi_p, hi_q)


# --------------------------------------------------------------------------- coplanar pairs
def _orient(a, b, c):
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def _segments_meet(a, b, c, d):
    o1, o2, o3, o4 = _orient(a, b, c), _orient(a, b, d), _orient(c, d, a), _orient(c, d, b)
    collinear = (o1 == 0) & (o2 == 0) & (o3 == 0) & (o4 == 0)
    boxes = ((np.minimum(a, b) <= np.maximum(c, d)) & (np.minimum(c, d) <= np.maximum(a, b))).all(1)
    return np.where(collinear, boxes, (o1 * o2 <= 0) & (o3 * o4 <= 0))


def _inside(point, tri):
    s = np.stack([_orient(tri[:, k], tri[:, (k + 1) % 3], point) for k in range(3)], axis=1)
    return (s >= 0).all(axis=1) | (s <= 0).all(axis=1)


def _coplanar_intersect(p, q, normal):
    """Triangles in one plane, seen along the normal's largest component: an edge of one
    crosses an edge of the other, or one holds a corner of the other."""
    drop = np.abs(normal).argmax(axis=1)
    keep = np.stack([(drop + 1) % 3, (drop + 2) % 3], axis=1)
    rows = np.arange(len(p))[:, None, None]
    p2 = p[rows, np.arange(3)[None, :, None], keep[:, None, :]]
    q2 = q[rows, np.arange(3)[None, :, None], keep[:, None, :]]
    meet = np.zeros(len(p), dtype=bool)
    for a in range(3):
        for c in range(3):
            meet |= _segments_meet(p2[:, a], p2[:, (a + 1) % 3], q2[:, c], q2[:, (c + 1) % 3])
    return meet | _inside(p2[:, 0], q2) | _inside(q2[:, 0], p2)
