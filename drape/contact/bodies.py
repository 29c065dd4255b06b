"""Rigid bodies and the scene: the fabric's vertices and every body's in one collision mesh.

The fabric's vertices come first (their positions follow the shell's vertex-value dofs), the
bodies' after them (prescribed: a body's triangulated surface moved along its rigid path).
The ipctk :class:`ipctk.CollisionMesh` holds all of them; a collision filter keeps bodies from
colliding with one another and, unless self-contact is on, the fabric from colliding with
itself (neighbouring primitives are excluded by ipctk from the topology). Half-spaces
(:class:`drape.contact.half_space.HalfSpace`) have no vertices: the scene hands their
plane–vertex candidates to the collision set (:meth:`Scene.plane_candidates`).

Which pairs push (:data:`PAIR_SETS`): IPC's own set counts every pair of primitives within
reach in full, so a fabric vertex resting on a triangulated body is pushed once per triangle,
edge and vertex of the body near it (one to five times over on a flat plate, with where it
lies), and up to four times as hard within d̂ of a body's convex edge: a hump in the energy
as steep as the barrier, which a point pushed over the edge has to pass. ``"per_point"``
weighs the pairs (ipctk's area-weighted improved max approximator, Li et al. 2023,
*Convergent Incremental Potential Contact*, with the collision mesh's areas set here): each
fabric contact point is pushed once, by its distance to the body's surface, which falls
smoothly across a body's edges. Where a body's surface folds (its edges and corners), its
edges against the fabric's edges and its vertices against the fabric's faces keep a tenth of
a pair's weight, enough to keep the fold out of the fabric between its points (the barrier
still grows without bound there). Its friction is Coulomb's on a plane, not on a faceted body
(docs/theory.md §7).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import ipctk
import numpy as np

from .errors import ContactInputError
from .half_space import HalfSpace
from .motion import OnPath

__all__ = ["RigidBody", "HalfSpace", "Scene", "ContactInputError", "PAIR_SETS", "BACKSTOP_WEIGHT"]

#: ``pairs`` of :class:`Scene`: IPC's set of primitive pairs, or one pair per fabric point.
PAIR_SETS = ("ipc", "per_point")

#: Weight of an edge–edge pair, and of a body vertex against a fabric face, relative to a
#: fabric point's pair, under ``pairs = "per_point"``.
BACKSTOP_WEIGHT = 0.1


@dataclass(frozen=True)
class RigidBody(OnPath):
    """A rigid obstacle: a triangulated surface, its friction with the fabric and its path.

    Parameters
    ----------
    name : str
        Name in messages and in the reaction output.
    surface : object
        ``vertices`` (n, 3) [m] and ``triangles`` (m, 3) at the body's reference placement
        (a :class:`drape.contact.shapes.Surface`).
    mu : float
        Coulomb friction coefficient of the fabric on this body, >= 0.
    path : object, optional
        Prescribed rigid translation: ``offset(t) -> (3,)`` [m] and ``velocity(t) -> (3,)``
        [m/s] (a :class:`drape.contact.motion.RigidPath`); None: the body stands still.
    """

    name: str
    surface: Any
    mu: float = 0.0
    path: Any = None

    def __post_init__(self):
        vertices = np.asarray(self.surface.vertices, dtype=float)
        triangles = np.asarray(self.surface.triangles)
        if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) < 3:
            raise ContactInputError(f"body {self.name!r}: vertices must be (n >= 3, 3), got {vertices.shape}")
        if not np.all(np.isfinite(vertices)):
            raise ContactInputError(f"body {self.name!r}: the surface has NaN or infinite coordinates")
        if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
            raise ContactInputError(f"body {self.name!r}: the surface has no triangles (not a surface)")
        if triangles.min() < 0 or triangles.max() >= len(vertices):
            raise ContactInputError(f"body {self.name!r}: a triangle names a vertex that does not exist")
        if not (np.isfinite(self.mu) and self.mu >= 0):
            raise ContactInputError(f"body {self.name!r}: mu = {self.mu!r} must be >= 0")


def _fold_edges(vertices, faces, faces_to_edges, n_edges: int, flat: float = 1e-6) -> np.ndarray:
    """Whether each edge is a fold of its surface: on one face only (a border), or between two
    faces whose normals differ by more than ``flat`` radians."""
    normal = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    edge = faces_to_edges.ravel()
    count = np.bincount(edge, minlength=n_edges)
    summed = np.zeros((n_edges, 3))
    np.add.at(summed, edge, np.repeat(normal, 3, axis=0))
    # two unit normals sum to 2 cos(θ/2): shorter than 2 by more than θ²/4 where they part by θ
    return (count != 2) | (np.linalg.norm(summed, axis=1) < 2.0 - 0.25 * flat ** 2)


class Scene:
    """The fabric's vertices and triangles and the bodies' surfaces in one collision mesh.

    Parameters
    ----------
    points : ndarray, shape (n_fabric, 3)
        The fabric's reference vertex positions [m].
    triangles : ndarray of int, shape (m, 3)
        The fabric's triangles.
    bodies : sequence of RigidBody or HalfSpace
    self_contact : bool
        Let the fabric collide with itself (primitives sharing a vertex never do).
    pairs : {"ipc", "per_point"}
        Which pairs push and how hard (:data:`PAIR_SETS`, the module's notes).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> ground = SimpleNamespace(vertices=[[-1, -1, 0], [2, -1, 0], [2, 2, 0], [-1, 2, 0]],
    ...                          triangles=[[0, 1, 2], [0, 2, 3]])
    >>> scene = Scene([[0, 0, 0.1], [1, 0, 0.1], [0, 1, 0.1]], [[0, 1, 2]], [RigidBody("ground", ground)])
    >>> scene.n_fabric, scene.mesh.num_vertices, scene.body_of_vertex.tolist()
    (3, 7, [-1, -1, -1, 0, 0, 0, 0])
    """

    def __init__(self, points, triangles, bodies=(), self_contact: bool = False, pairs: str = "ipc"):
        if pairs not in PAIR_SETS:
            raise ContactInputError(f"contact.pairs = {pairs!r} must be one of {', '.join(PAIR_SETS)}")
        self.per_point = pairs == "per_point"
        points = np.asarray(points, dtype=float)
        triangles = np.asarray(triangles, dtype=np.int32)
        self.bodies = tuple(bodies)
        names = [b.name for b in self.bodies]
        if len(set(names)) != len(names):
            raise ContactInputError(f"body names must be unique, got {names}")
        self.n_fabric = len(points)
        self.self_contact = bool(self_contact)
        vertices, faces, owner = [points], [triangles], [np.full(len(points), -1)]
        start = len(points)
        #: the bodies with a surface, and the half-spaces, each with its index in ``bodies``
        self.meshed = [(k, b) for k, b in enumerate(self.bodies) if not isinstance(b, HalfSpace)]
        self.half_spaces = [(k, b) for k, b in enumerate(self.bodies) if isinstance(b, HalfSpace)]
        for k, body in self.meshed:
            v = np.asarray(body.surface.vertices, dtype=float)
            vertices.append(v)
            faces.append(np.asarray(body.surface.triangles, dtype=np.int32) + start)
            owner.append(np.full(len(v), k))
            start += len(v)
        self.rest = np.ascontiguousarray(np.vstack(vertices))
        self.faces = np.ascontiguousarray(np.vstack(faces), dtype=np.int32)
        self.body_of_vertex = np.concatenate(owner)
        self.edges = ipctk.edges(self.faces)
        self.mesh = ipctk.CollisionMesh(self.rest, self.edges, self.faces)
        if self.per_point:
            self._weigh_per_point()
        # bodies never collide with one another; the fabric with itself only when asked (the
        # components filter is given every face, a vertex outside its faces having no component,
        # and faces tying every fabric vertex to the first: a fabric in pieces is one component)
        self._filters = [ipctk.make_static_obstacle_filter(self.n_fabric)]
        if not self.self_contact:
            tie = np.column_stack([np.zeros(self.n_fabric), np.arange(self.n_fabric),
                                   np.arange(self.n_fabric)]).astype(np.int32)
            self._filters.append(ipctk.make_connected_components_filter(np.vstack([self.faces, tie])))
        self._filters.append(self._filters[0] if len(self._filters) == 1 else self._filters[0] & self._filters[1])
        self.mesh.can_collide = self._filters[-1]   # the filters stay referenced by the scene

    def _weigh_per_point(self) -> None:
        """The collision mesh's areas that make ipctk's area weights one per fabric point.

        ipctk weighs a vertex–face pair by a quarter of the vertex's area, an edge–edge pair by
        a quarter of the two edges' areas summed, and a plane–vertex pair by the vertex's area
        (``Contact`` sets those back to one); a pair of weight zero is dropped. A fabric point
        gets area 4 (its pairs weigh 1); a body's edges where its surface folds, and their
        vertices, get :data:`BACKSTOP_WEIGHT` (× 4): only there can a body meet the fabric
        between its points. The fabric's edges get it too when it collides with itself."""
        n = self.n_fabric
        folds = np.zeros(len(self.edges), dtype=bool)
        folds[self.edges.min(axis=1) >= n] = True
        folds &= _fold_edges(self.rest, self.faces, np.asarray(self.mesh.faces_to_edges), len(self.edges))
        fabric_edge = self.edges.max(axis=1) < n
        backstop = 4.0 * BACKSTOP_WEIGHT
        self.mesh.edge_areas = np.where(folds | (fabric_edge & self.self_contact), backstop, 0.0)
        on_fold = np.zeros(len(self.rest), dtype=bool)
        on_fold[self.edges[folds].ravel()] = True
        self.mesh.vertex_areas = np.where(np.arange(len(self.rest)) < n, 4.0, np.where(on_fold, backstop, 0.0))

    def body_displacements(self, t: float) -> np.ndarray:
        """Displacement (n_body_vertices, 3) of every body vertex at ``t``."""
        rows = [np.broadcast_to(b.offset(t), (len(b.surface.vertices), 3)) for _, b in self.meshed]
        return np.vstack(rows) if rows else np.zeros((0, 3))

    def body_velocities(self, t: float) -> np.ndarray:
        """Velocity (n_body_vertices, 3) of every body vertex at ``t``."""
        rows = [np.broadcast_to(b.velocity(t), (len(b.surface.vertices), 3)) for _, b in self.meshed]
        return np.vstack(rows) if rows else np.zeros((0, 3))

    def positions(self, fabric_displacement, t: float) -> np.ndarray:
        """Positions (n, 3) of all collision-mesh vertices: the fabric displaced by
        ``fabric_displacement`` (n_fabric, 3), the bodies where their paths put them at ``t``."""
        d = np.vstack([np.asarray(fabric_displacement, dtype=float).reshape(-1, 3),
                       self.body_displacements(t)])
        return self.rest + d

    def velocities(self, fabric_velocity, t: float) -> np.ndarray:
        """Velocities (n, 3) of all collision-mesh vertices."""
        return np.vstack([np.asarray(fabric_velocity, dtype=float).reshape(-1, 3),
                          self.body_velocities(t)])

    def plane_candidates(self, x, t: float, reach: float, which=None) -> list:
        """ipctk plane–vertex candidates of the fabric's vertices (rows of ``x``) closer than
        ``reach`` to the half-spaces at ``t`` (``which``: the index in ``bodies`` of one of them)."""
        fabric = np.asarray(x)[:self.n_fabric]
        return [c for k, b in self.half_spaces if which in (None, k) for c in b.candidates(fabric, t, reach)]

    def plane_step(self, x0, t0: float, x1, t1: float, dmin: float) -> float:
        """Fraction of the straight step from ``x0`` to ``x1`` at which a fabric vertex first
        comes within ``dmin`` of a half-space (1: none does)."""
        fractions = [b.first_touch(np.asarray(x0)[:self.n_fabric], t0, np.asarray(x1)[:self.n_fabric], t1, dmin)
                     for _, b in self.half_spaces]
        return float(min((f.min() for f in fractions if f.size), default=1.0))

    def half_space_of(self, plane, t: float) -> int:
        """Index in ``bodies`` of the half-space whose plane at ``t`` is ``plane`` (an
        ``ipctk.Hyperplane`` of a plane–vertex pair)."""
        normal, offset = np.asarray(plane.normal()), float(plane.offset())
        for k, b in self.half_spaces:
            here = b.hyperplane(t)
            if np.allclose(normal, here.normal(), atol=1e-12) and abs(offset - here.offset()) <= 1e-12:
                return k
        raise ValueError("a plane-vertex pair whose plane is no half-space of the scene")
