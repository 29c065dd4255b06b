"""Rigid bodies and the scene: the fabric's vertices and every body's in one collision mesh.

The fabric's vertices come first (their positions follow the shell's vertex-value dofs), the
bodies' after them (prescribed: a body's triangulated surface moved along its rigid path).
The ipctk :class:`ipctk.CollisionMesh` holds all of them; a collision filter keeps bodies from
colliding with one another and, unless self-contact is on, the fabric from colliding with
itself (neighbouring primitives are excluded by ipctk from the topology). Half-spaces
(:class:`drape.contact.half_space.HalfSpace`) have no vertices: the scene hands their
plane–vertex candidates to the collision set (:meth:`Scene.plane_candidates`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import ipctk
import numpy as np

from .errors import ContactInputError
from .half_space import HalfSpace
from .motion import OnPath

__all__ = ["RigidBody", "HalfSpace", "Scene", "ContactInputError"]


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

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> ground = SimpleNamespace(vertices=[[-1, -1, 0], [2, -1, 0], [2, 2, 0], [-1, 2, 0]],
    ...                          triangles=[[0, 1, 2], [0, 2, 3]])
    >>> scene = Scene([[0, 0, 0.1], [1, 0, 0.1], [0, 1, 0.1]], [[0, 1, 2]], [RigidBody("ground", ground)])
    >>> scene.n_fabric, scene.mesh.num_vertices, scene.body_of_vertex.tolist()
    (3, 7, [-1, -1, -1, 0, 0, 0, 0])
    """

    def __init__(self, points, triangles, bodies=(), self_contact: bool = False):
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
