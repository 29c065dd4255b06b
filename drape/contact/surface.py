"""A rigid body's surface: a triangle mesh in metres, outward oriented, placed in the scene.

A :class:`Surface` is a frozen pair of arrays.  Its triangles are ordered counter-clockwise
seen from outside, so their right-hand normals point out of the body (into the space the
fabric may occupy); a closed body's signed volume (:meth:`Surface.volume`, by the divergence
theorem) is then positive.

Examples
--------
>>> import numpy as np
>>> square = Surface([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
>>> square.area()
1.0
>>> moved = square.placed(translation=(0, 0, 2), rotation_deg=(90, 0, 0))
>>> np.round(moved.vertices[2], 12).tolist()   # (1, 1, 0) turned about x, then lifted
[1.0, 0.0, 3.0]
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import ContactInputError

__all__ = ["Surface", "placement"]


def _frozen(array) -> np.ndarray:
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Surface:
    """A triangulated rigid surface.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
        Vertex coordinates (m), all finite.
    triangles : array_like of int, shape (m, 3)
        Vertex indices of each triangle, counter-clockwise seen from outside the body.

    Raises
    ------
    ContactInputError
        Arrays of the wrong shape, coordinates that are not finite, indices out of range.
    """

    vertices: np.ndarray
    triangles: np.ndarray

    def __post_init__(self):
        vertices = np.array(self.vertices, dtype=float)
        triangles = np.array(self.triangles)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ContactInputError(f"surface vertices must be an (n, 3) array, not {vertices.shape}")
        if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
            raise ContactInputError(f"surface triangles must be a non-empty (m, 3) array, "
                                    f"not {triangles.shape}")
        if not np.issubdtype(triangles.dtype, np.integer):
            raise ContactInputError("surface triangles must hold integer vertex indices")
        triangles = triangles.astype(np.int64)
        if triangles.min() < 0 or triangles.max() >= len(vertices):
            raise ContactInputError(f"surface triangles refer to vertices outside 0..{len(vertices) - 1}")
        bad = ~np.isfinite(vertices).all(axis=1)
        if bad.any():
            raise ContactInputError(f"{int(bad.sum())} of {len(vertices)} surface vertices have "
                                    f"NaN or infinite coordinates")
        object.__setattr__(self, "vertices", _frozen(vertices))
        object.__setattr__(self, "triangles", _frozen(triangles))

    # ----------------------------------------------------------------------- geometry
    def _corners(self):
        v = self.vertices[self.triangles]
        return v[:, 0], v[:, 1], v[:, 2]

    def triangle_areas(self) -> np.ndarray:
        """Area of every triangle (m²), shape (m,)."""
        a, b, c = self._corners()
        return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)

    def area(self) -> float:
        """Total area (m²)."""
        return float(self.triangle_areas().sum())

    def volume(self) -> float:
        """Signed enclosed volume (m³) by the divergence theorem, ``Σ a·(b×c)/6``.

        Positive for a closed surface whose normals point outwards; meaningless for an
        open one (a plane patch).
        """
        a, b, c = self._corners()
        return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)

    def normals(self) -> np.ndarray:
        """Unit outward normal of every triangle, shape (m, 3)."""
        a, b, c = self._corners()
        n = np.cross(b - a, c - a)
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    def edges(self) -> np.ndarray:
        """The distinct undirected edges, shape (e, 2), each as (low, high) vertex index."""
        directed = self.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        return np.unique(np.sort(directed, axis=1), axis=0)

    def is_closed(self) -> bool:
        """Whether the surface is closed, edge-manifold and consistently oriented.

        True when every directed edge of a triangle appears exactly once and its reverse
        exactly once, in a neighbouring triangle: no border, no edge shared by three
        triangles, no neighbours of opposite orientation.
        """
        directed = self.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        forward, count = np.unique(directed, axis=0, return_counts=True)
        if (count != 1).any():
            return False
        keys = forward[:, 0] * len(self.vertices) + forward[:, 1]
        reverse = forward[:, 1] * len(self.vertices) + forward[:, 0]
        return bool(np.isin(reverse, keys).all())

    def bounds(self) -> np.ndarray:
        """Lower and upper corner of the bounding box, shape (2, 3)."""
        return np.array([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    # ----------------------------------------------------------------------- placement
    def placed(self, translation=(0.0, 0.0, 0.0), rotation_deg=(0.0, 0.0, 0.0),
               scale: float = 1.0) -> "Surface":
        """The surface scaled, turned and moved: ``x ↦ t + R (s x)``.

        Parameters
        ----------
        translation : array_like, shape (3,)
            Translation t (m), applied last.
        rotation_deg : array_like, shape (3,)
            Angles (degrees) of rotations about the fixed x, then y, then z axis through
            the origin: ``R = R_z R_y R_x``.
        scale : float
            Uniform scale s about the origin (> 0), applied first.

        Returns
        -------
        Surface
            A new surface; the triangles (and so the orientation) are unchanged.
        """
        matrix, shift = placement(translation, rotation_deg, scale)
        return Surface(self.vertices @ matrix.T + shift, self.triangles)

    def to_polydata(self):
        """The surface as a :class:`pyvista.PolyData` (for pictures and VTK files)."""
        import pyvista as pv

        faces = np.hstack([np.full((len(self.triangles), 1), 3), self.triangles]).ravel()
        return pv.PolyData(np.array(self.vertices), faces)


def placement(translation=(0.0, 0.0, 0.0), rotation_deg=(0.0, 0.0, 0.0), scale: float = 1.0):
    """The linear part ``s R`` and shift ``t`` of :meth:`Surface.placed`.

    >>> m, t = placement(rotation_deg=(0, 0, 90))
    >>> np.round(m @ [1, 0, 0], 12).tolist()
    [0.0, 1.0, 0.0]
    """
    shift = np.asarray(translation, dtype=float)
    angles = np.asarray(rotation_deg, dtype=float)
    if shift.shape != (3,) or angles.shape != (3,):
        raise ContactInputError("translation and rotation_deg must each be three numbers")
    if not (np.isfinite(shift).all() and np.isfinite(angles).all()):
        raise ContactInputError("translation and rotation_deg must be finite")
    if not (np.isfinite(scale) and scale > 0):
        raise ContactInputError(f"scale must be a positive number, not {scale}")
    # lower-case "xyz": extrinsic rotations about the fixed axes, x first
    rotation = Rotation.from_euler("xyz", angles, degrees=True).as_matrix()
    return float(scale) * rotation, shift
