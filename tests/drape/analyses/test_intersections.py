"""The independent intersection check against constructed cases and a brute-force test by
another algorithm (an edge of one triangle through the other)."""
import numpy as np
import pytest

from drape.analyses.intersections import intersections, self_intersections, triangles_intersect
from drape.contact import rounded_box, sphere

TRI = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)


def _pair(q):
    return bool(triangles_intersect(TRI[None], np.asarray(q, float)[None])[0])


def test_crossing_separated_and_touching_triangles():
    assert _pair([[0.2, 0.2, -0.5], [0.2, 0.2, 0.5], [0.3, 0.3, 0.0]])          # pierces
    assert not _pair([[0.2, 0.2, 0.1], [0.2, 0.2, 0.5], [0.3, 0.3, 0.3]])       # above
    assert not _pair([[0.8, 0.8, -0.5], [0.8, 0.8, 0.5], [0.9, 0.9, 0.0]])      # beside
    assert _pair([[0.0, 0.0, 0.0], [-1, 0, 1], [0, -1, 1]])                      # one corner shared
    assert _pair([[0.3, 0.3, 0.0], [0.3, 0.3, 1.0], [0.4, 0.2, 1.0]])           # a corner on the face


def test_coplanar_triangles():
    assert _pair([[0.2, 0.2, 0], [0.6, 0.2, 0], [0.2, 0.6, 0]])                 # inside
    assert _pair([[0.5, -0.5, 0], [0.5, 1.5, 0], [2, 0.5, 0]])                  # edges cross
    assert _pair([[-1, -1, 0], [3, -1, 0], [-1, 3, 0]])                          # holds it
    assert not _pair([[1, 1, 0], [2, 1, 0], [1, 2, 0]])                          # beyond the hypotenuse
    assert _pair([[0.5, 0.5, 0], [2, 0.5, 0], [0.5, 2, 0]])                      # touches it


def _strip(n=24, width=0.1):
    """A flat strip, x in [0, 1], as a structured grid: points on the x axis to map, triangles."""
    s = np.linspace(0, 1, n + 1)
    y = np.linspace(0, width, 3)
    u, v = (a.ravel() for a in np.meshgrid(s, y, indexing="ij"))
    a = (np.arange(n)[:, None] * 3 + np.arange(2)[None, :]).ravel()
    tris = np.concatenate([np.stack([a, a + 3, a + 4], 1), np.stack([a, a + 4, a + 1], 1)])
    return u, v, tris


def _folded(gap, dip=0.0):
    """The strip folded back on itself round a half circle of diameter ``gap`` at x = 0.5; the
    upper layer sinks by ``dip`` towards its free end."""
    u, v, tris = _strip()
    r, bend = gap / 2, np.pi * gap / 2
    fold_end = 0.5 + bend
    x = np.where(u < 0.5, u, np.where(u < fold_end, 0.5 + r * np.sin((u - 0.5) / r),
                                      0.5 - (u - fold_end)))
    z = np.where(u < 0.5, 0.0, np.where(u < fold_end, r - r * np.cos((u - 0.5) / r),
                                        gap - dip * (u - fold_end) / (1 - fold_end)))
    # the straight strip is 1 long; stretch the parameter so the layers fit beside the fold
    return np.stack([x, v, z], axis=1), tris


def test_folded_sheet_that_touches_and_one_that_crosses():
    points, tris = _folded(gap=0.02)
    assert len(self_intersections(points, tris)) == 0
    near, _ = _folded(gap=1e-4)
    assert len(self_intersections(near, tris)) == 0              # close, not crossing
    crossing, _ = _folded(gap=0.02, dip=0.06)
    pairs = self_intersections(crossing, tris)
    assert len(pairs) > 0
    # the crossing is where the sinking layer passes z = 0, above the lower layer
    hit = crossing[tris[pairs.ravel()]].mean(axis=1)
    assert (np.abs(hit[:, 2]) < 0.02).all()


def _torus(R=0.3, r=0.1, n=40, m=20):
    import pyvista as pv

    ring = pv.ParametricTorus(ringradius=R, crosssectionradius=r, u_res=n, v_res=m, w_res=1)
    ring = ring.triangulate().clean()
    return np.asarray(ring.points), ring.faces.reshape(-1, 4)[:, 1:]


def test_torus_and_bodies():
    points, tris = _torus()
    assert len(self_intersections(points, tris)) == 0
    in_hole = sphere((0, 0, 0), 0.15, 24)
    assert len(intersections(points, tris, in_hole.vertices, in_hole.triangles)) == 0
    through_tube = sphere((0.3, 0, 0), 0.15, 24)
    assert len(intersections(points, tris, through_tube.vertices, through_tube.triangles)) > 0
    inside_tube = sphere((0.3, 0, 0), 0.05, 24)                 # wholly inside: no surface crosses
    assert len(intersections(points, tris, inside_tube.vertices, inside_tube.triangles)) == 0
    box = rounded_box((0, 0, 0), (0.2, 0.2, 0.2), 0.02, 8)
    assert len(self_intersections(box.vertices, box.triangles)) == 0


# --------------------------------------------------------------------------- brute force
def _det(a, b, c, d):
    return np.einsum("...i,...i->...", np.cross(b - a, c - a), d - a)


def _edge_through(p, q):
    """Whether an edge of p passes through triangle q: its ends on either side of q's plane and
    the line through it inside q's three edges (general position: no zeros)."""
    hit = np.zeros(len(p), dtype=bool)
    a, b, c = q[:, 0], q[:, 1], q[:, 2]
    for k in range(3):
        s, e = p[:, k], p[:, (k + 1) % 3]
        sides = _det(a, b, c, s) * _det(a, b, c, e) < 0
        around = np.stack([_det(s, e, a, b), _det(s, e, b, c), _det(s, e, c, a)], 1)
        inside = (around > 0).all(1) | (around < 0).all(1)
        hit |= sides & inside
    return hit


def _brute(corners_a, corners_b, same):
    i, j = np.meshgrid(np.arange(len(corners_a)), np.arange(len(corners_b)), indexing="ij")
    i, j = i.ravel(), j.ravel()
    if same:
        i, j = i[i < j], j[i < j]
    p, q = corners_a[i], corners_b[j]
    hit = _edge_through(p, q) | _edge_through(q, p)
    return {(a, b) for a, b in zip(i[hit], j[hit])}


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_triangles_against_brute_force(seed):
    rng = np.random.default_rng(seed)
    n = 150
    centres = rng.uniform(0, 1, (n, 1, 3))
    corners = centres + rng.normal(0, 0.08, (n, 3, 3))
    points, tris = corners.reshape(-1, 3), np.arange(3 * n).reshape(n, 3)
    found = {tuple(p) for p in self_intersections(points, tris)}
    expected = _brute(corners, corners, same=True)
    assert expected and found == expected
    other = rng.uniform(0, 1, (80, 1, 3)) + rng.normal(0, 0.1, (80, 3, 3))
    found = {tuple(p) for p in intersections(points, tris, other.reshape(-1, 3),
                                             np.arange(240).reshape(80, 3))}
    assert found == _brute(corners, other, same=False)


def test_neighbours_sharing_a_vertex_are_left_out():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, 0.5], [0.3, 0.2, -0.5]])
    tris = np.array([[0, 1, 2], [0, 3, 4]])       # the second pierces the first, sharing vertex 0
    assert len(self_intersections(points, tris)) == 0
    apart = np.vstack([points, points[[0]] + [0.0, 0.0, 0.0]])
    assert self_intersections(apart, [[0, 1, 2], [5, 3, 4]]).tolist() == [[0, 1]]
