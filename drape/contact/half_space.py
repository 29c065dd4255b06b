"""A rigid half-space: an exact plane the fabric's vertices meet one pair each.

A flat body triangulated for IPC is met by a resting vertex many times over: its triangle,
the neighbours' within the barrier layer, its edges against the edges beneath
(:func:`drape.contact.stiffness.resting_multiplicity`). How many depends on where the vertex
lies against the body's edges, so a fabric resting on a triangulated plate is pushed harder in
some places than in others, with the beat of the two meshes: round a Cusick support's fan of m
triangles, a fabric of n sectors is pushed in a ripple of |n − m| waves, and the skirt can take
that as its folds (docs/theory.md §6). The IPC Toolkit also knows planes exactly (point–plane
pairs, ``ipctk.PlaneVertexCandidate``): every vertex within the layer makes one pair, pushed
along the plane's normal, the same everywhere. That is what a support plate, a floor or a
table top larger than the fabric is.

The plane bounds the solid ``{x : n·(x − p(t)) < 0}``; it may move along its normal on a
prescribed path (ipctk's plane–vertex friction takes the plane as still in its own plane, which
a motion along the normal leaves exact), and the continuous collision detection of a vertex
against it is exact: the signed distance is linear along a straight step.

Examples
--------
>>> import numpy as np
>>> floor = HalfSpace("floor", point=[0, 0, 0], normal=[0, 0, 2])
>>> floor.signed_distance(np.array([[0.3, 0.1, 0.002]]), 0.0).tolist()
[0.002]
>>> floor.first_touch(np.array([[0, 0, 0.002]]), 0.0, np.array([[0, 0, -0.002]]), 0.0, dmin=0.001).tolist()
[0.25]
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import ipctk
import numpy as np

from .errors import ContactInputError
from .motion import OnPath

__all__ = ["HalfSpace"]


@dataclass(frozen=True, eq=False)
class HalfSpace(OnPath):
    """The solid below the plane through ``point`` facing ``normal``, still or moving along it.

    Parameters
    ----------
    name : str
        Name in messages and in the reaction output.
    point : array_like, shape (3,)
        A point of the plane at the body's reference placement [m].
    normal : array_like, shape (3,)
        Direction the plane faces (the fabric's side); need not be unit.
    mu : float
        Coulomb friction coefficient of the fabric on the plane, >= 0.
    path : object, optional
        Prescribed translation (:class:`drape.contact.motion.RigidPath`), along the normal only.
    """

    name: str
    point: Any
    normal: Any
    mu: float = 0.0
    path: Any = None

    def __post_init__(self):
        point = np.asarray(self.point, dtype=float)
        normal = np.asarray(self.normal, dtype=float)
        if point.shape != (3,) or normal.shape != (3,):
            raise ContactInputError(f"body {self.name!r}: point and normal must be three numbers each")
        if not (np.isfinite(point).all() and np.isfinite(normal).all()):
            raise ContactInputError(f"body {self.name!r}: point or normal has NaN or infinite coordinates")
        length = float(np.linalg.norm(normal))
        if length == 0.0:
            raise ContactInputError(f"body {self.name!r}: normal must not be the zero vector")
        if not (np.isfinite(self.mu) and self.mu >= 0):
            raise ContactInputError(f"body {self.name!r}: mu = {self.mu!r} must be >= 0")
        object.__setattr__(self, "point", point)
        object.__setattr__(self, "normal", normal / length)
        if self.path is not None:
            moves = np.asarray(self.path.translations, dtype=float)
            sideways = np.cross(moves - moves[0], self.normal)
            if np.abs(sideways).max() > 1e-9 * max(1.0, np.abs(moves).max()):
                raise ContactInputError(f"body {self.name!r}: a half-space moves along its normal only "
                                        "(path.translations must be multiples of the normal)")


    def signed_distance(self, x, t: float) -> np.ndarray:
        """Signed distance [m] of the points ``x`` (n, 3) from the plane at ``t`` (> 0 on the
        fabric's side)."""
        return (np.asarray(x, dtype=float) - (self.point + self.offset(t))) @ self.normal

    def hyperplane(self, t: float) -> ipctk.Hyperplane:
        """The plane at ``t`` as ipctk holds it."""
        return ipctk.Hyperplane(self.normal, self.point + self.offset(t))

    def candidates(self, x, t: float, reach: float) -> list:
        """ipctk plane–vertex candidates of the points ``x`` (n, 3) closer than ``reach`` to the
        plane at ``t`` (either side: ipctk's point–plane distance is unsigned)."""
        near = np.flatnonzero(np.abs(self.signed_distance(x, t)) < reach)
        plane = self.hyperplane(t)
        return [ipctk.PlaneVertexCandidate(plane, int(i)) for i in near]

    def first_touch(self, x0, t0: float, x1, t1: float, dmin: float) -> np.ndarray:
        """Per point, the fraction in [0, 1] of the straight step from ``x0`` (plane at ``t0``) to
        ``x1`` (plane at ``t1``) at which it first comes within ``dmin`` of the plane: 1 if it
        does not, 0 if it starts there. Exact: a point's signed distance is linear in the step."""
        s0 = self.signed_distance(x0, t0) - dmin
        s1 = self.signed_distance(x1, t1) - dmin
        alpha = np.ones(s0.shape)
        closing = s1 < 0.0
        alpha[closing] = np.clip(s0[closing] / (s0[closing] - s1[closing]), 0.0, 1.0)
        alpha[s0 <= 0.0] = 0.0
        return alpha
