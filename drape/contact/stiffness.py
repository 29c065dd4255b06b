"""The barrier stiffness κ: a physical choice from the force a vertex carries.

IPC's adaptive stiffness (Li et al. 2020, §4.3; ``ipctk.initial_barrier_stiffness``) balances
the barrier's gradient against the elastic energy's at the start and grows κ while distances
shrink; it serves a stiffness that need not mean anything. For a fabric the force a contact
vertex carries is known beforehand (its share of the weight, or of the edge loads that press it
on a body), so κ is chosen such that one vertex pressed by that force rests at ``dmin + dhat/2``,
in the middle of the barrier's layer: heavier loads sink deeper, where the barrier stiffens
without bound, and the fabric never touches the body. A vertex resting on a triangulated
body is in several pairs at once (:func:`resting_multiplicity`); for a fabric laid on a body the
stiffness is divided by their count, so that it starts at rest.
"""
from __future__ import annotations

import ipctk
import numpy as np

__all__ = ["resting_distance", "barrier_stiffness", "resting_multiplicity"]


def resting_distance(dhat: float, dmin: float = 0.0) -> float:
    """Where a vertex carrying its share of the weight rests from a body: in the middle of the
    barrier layer, ``dmin + dhat/2`` (:func:`barrier_stiffness` is chosen for it).

    >>> resting_distance(1e-3, dmin=1.5e-4)
    0.00065
    """
    return dmin + 0.5 * dhat


def barrier_stiffness(force_per_vertex: float, dhat: float, dmin: float = 0.0) -> float:
    """κ [N/m³] of ipctk's clamped-log barrier (on squared distances) such that a single vertex
    at distance ``dmin + dhat/2`` from a body is pushed off by ``force_per_vertex`` [N].

    Examples
    --------
    >>> import ipctk
    >>> kappa = barrier_stiffness(1e-3, dhat=1e-3, dmin=2e-4)
    >>> round(ipctk.barrier_force_magnitude((2e-4 + 5e-4) ** 2, ipctk.ClampedLogBarrier(), 1e-3, kappa, 2e-4), 12)
    0.001
    """
    if not (np.isfinite(force_per_vertex) and force_per_vertex > 0):
        raise ValueError(f"force_per_vertex must be > 0, got {force_per_vertex!r}")
    if not (np.isfinite(dhat) and dhat > 0) or not dmin >= 0:
        raise ValueError(f"dhat must be > 0 and dmin >= 0, got dhat = {dhat!r}, dmin = {dmin!r}")
    d = resting_distance(dhat, dmin)
    unit = ipctk.barrier_force_magnitude(d * d, ipctk.ClampedLogBarrier(), dhat, 1.0, dmin)
    return float(force_per_vertex / abs(unit))


def resting_multiplicity(mesh, x, n_fabric: int, dhat: float, dmin: float = 0.0,
                         min_share: float = 0.1, collisions=None) -> float:
    """How many times over IPC's barrier counts a fabric vertex resting on a body's mesh.

    A vertex lying over a triangulated surface is one point–triangle pair closer than
    ``dmin + dhat``, but also the edge–edge pairs of its edges with the body's edges beneath,
    and the pairs with the neighbouring triangles: on the flat top of a triangulated disc or
    box a resting vertex is pushed ten to fifteen times as hard as one pair at its distance
    would push it. This is the ratio, over the fabric vertices resting on a body at ``x``, of
    the barrier force on them (κ = 1) to the force of one pair at each vertex's own distance to
    the bodies; 1 when fewer than ``min_share`` of the fabric's vertices rest on a body (a
    fabric whose corner touches a body is not laid on it: the few pairs there say little of
    the contacts to come, and the start's balance hardly matters).

    Parameters
    ----------
    mesh : ipctk.CollisionMesh
        The scene's collision mesh, fabric vertices first.
    x : ndarray (n_vertices, 3)
        Positions of every collision vertex.
    n_fabric : int
        Number of fabric vertices (the first ``n_fabric`` rows of ``x``).
    dhat, dmin : float
        Barrier layer and minimum distance [m].
    min_share : float
        Share of the fabric's vertices that must rest on a body for a count.
    collisions : ipctk.NormalCollisions, optional
        The pairs at ``x`` (with the plane–vertex pairs of half-spaces, which count one each);
        default: built from ``mesh``.

    Examples
    --------
    A square of fabric at mid-layer over a plane triangulated as coarsely:

    >>> import ipctk, numpy as np
    >>> from drape.contact import shapes
    >>> cloth = shapes.plane([0, 0, 6e-4], [0, 0, 1], 0.1, 8)
    >>> floor = shapes.plane([0, 0, 0], [0, 0, 1], 0.3, 8)
    >>> x = np.vstack([cloth.vertices, floor.vertices])
    >>> faces = np.vstack([cloth.triangles, floor.triangles + len(cloth.vertices)])
    >>> mesh = ipctk.CollisionMesh(x, ipctk.edges(faces), faces)
    >>> resting_multiplicity(mesh, x, len(cloth.vertices), dhat=1e-3, dmin=1e-4) > 2
    True
    """
    if collisions is None:
        collisions = ipctk.NormalCollisions()
        collisions.build(mesh, x, dhat, dmin)
    edges, faces = mesh.edges, mesh.faces
    d2 = np.full(n_fabric, np.inf)
    # a vertex's own distance to a body: to a triangle, or to an edge or a vertex it lies over
    points = ([(p, p.vertex_id, faces[p.face_id]) for p in collisions.fv_collisions]
              + [(p, p.vertex_id, edges[p.edge_id]) for p in collisions.ev_collisions]
              + [(p, min(p.vertex0_id, p.vertex1_id), [max(p.vertex0_id, p.vertex1_id)])
                 for p in collisions.vv_collisions]
              + [(p, p.vertex_id, [n_fabric]) for p in collisions.pv_collisions])
    for pair, v, other in points:
        if v < n_fabric and min(other) >= n_fabric:
            d2[v] = min(d2[v], pair.compute_distance(pair.dof(x, edges, faces)))
    resting = np.flatnonzero(np.isfinite(d2))
    if resting.size == 0 or resting.size < min_share * n_fabric:
        return 1.0
    one_pair = sum(abs(ipctk.barrier_force_magnitude(d, ipctk.ClampedLogBarrier(), dhat, 1.0, dmin))
                   for d in d2[resting])
    if not one_pair > 0:
        return 1.0
    force = ipctk.BarrierPotential(dhat, 1.0).gradient(collisions, mesh, x).reshape(-1, 3)
    return float(max(1.0, np.linalg.norm(force[resting], axis=1).sum() / one_pair))
