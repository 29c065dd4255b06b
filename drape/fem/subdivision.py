"""A triangle mesh split into n² sub-triangles per triangle, and a field's values at its vertices.

The fabric's contact sees its surface as flat triangles between collision vertices. With the
mesh vertices alone these are the chords of the curved (quintic Argyris) elements; splitting
every triangle into ``n²`` sub-triangles, with sub-vertices at the reference points
``(i/n, j/n)``, and placing every sub-vertex where the element's own field puts it, lets the
contact follow the field inside the elements.

The sub-vertices are shared: a point on a mesh edge (or at a mesh vertex) is one sub-vertex,
whichever triangle names it. A point is identified by its integer barycentric weights on the
mesh vertices it lies between, which both neighbours of an edge compute alike.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import CellBasis

__all__ = ["reference_lattice", "subdivide", "interpolation_matrix"]


def reference_lattice(n: int):
    """Lattice points ``(i/n, j/n)``, ``i + j <= n``, of the reference triangle and its
    ``n²`` sub-triangles (counter-clockwise, like the reference triangle).

    Returns
    -------
    ij : ndarray of int, shape (m, 2)
        The integer coordinates ``(i, j)`` of the m = (n + 1)(n + 2)/2 points.
    triangles : ndarray of int, shape (n², 3)
        Indices into ``ij``.
    """
    n = int(n)
    ij = np.array([(i, j) for j in range(n + 1) for i in range(n + 1 - j)], dtype=np.int64)
    index = {(int(i), int(j)): k for k, (i, j) in enumerate(ij)}
    triangles = []
    for j in range(n):
        for i in range(n - j):
            triangles.append((index[i, j], index[i + 1, j], index[i, j + 1]))
            if i + j + 2 <= n:
                triangles.append((index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]))
    return ij, np.array(triangles, dtype=np.int64)


def subdivide(mesh, n: int):
    """The sub-mesh of ``mesh`` (a skfem ``MeshTri``) with ``n²`` sub-triangles per triangle.

    The mesh vertices come first, in their order, so ``n = 1`` gives the mesh itself.

    Returns
    -------
    points : ndarray, shape (N, 2)
        Reference (undeformed) positions of the sub-vertices.
    triangles : ndarray of int, shape (E n², 3)
    owner : ndarray of int, shape (N, 2)
        For every sub-vertex one triangle that holds it and its index in
        :func:`reference_lattice` (where the field is evaluated).
    """
    n = int(n)
    if n < 1:
        raise ValueError(f"subdivision = {n!r} must be an integer >= 1")
    ij, local = reference_lattice(n)
    weights = np.column_stack([n - ij.sum(axis=1), ij[:, 0], ij[:, 1]])    # on vertices 0, 1, 2
    t = np.asarray(mesh.t)
    n_vertices = mesh.p.shape[1]
    ids = {((int(v), n),): int(v) for v in range(n_vertices)}
    owner = [None] * n_vertices
    weights_of = [None] * n_vertices
    numbering = np.empty((t.shape[1], len(ij)), dtype=np.int64)
    for e in range(t.shape[1]):
        for q, w in enumerate(weights):
            key = tuple(sorted((int(t[a, e]), int(w[a])) for a in range(3) if w[a] > 0))
            k = ids.get(key)
            if k is None:
                k = ids[key] = len(owner)
                owner.append(None)
                weights_of.append(None)
            if owner[k] is None:
                owner[k], weights_of[k] = (e, q), w
            numbering[e, q] = k
    owner = np.array(owner, dtype=np.int64)
    corners = mesh.p[:, t[:, owner[:, 0]]]                                   # (2, 3, N)
    w = weights[owner[:, 1]] / n                                             # (N, 3)
    points = np.einsum("dan,na->nd", corners, w)
    points[:n_vertices] = mesh.p.T                                           # exactly the mesh's
    triangles = np.take_along_axis(numbering, np.broadcast_to(local.ravel(), (t.shape[1], local.size)), axis=1)
    return points, triangles.reshape(-1, 3), owner


def interpolation_matrix(mesh, element, owner, n: int, components: int = 3):
    """Sparse ``P`` with ``(P u)[c k + i]`` the i-th component of the field ``u`` at sub-vertex k.

    The field is the scalar ``element`` on ``mesh`` in each of ``components`` components, its
    dofs interleaved (``u[c j + i]``: dof j of component i), as the shell stores them. Each
    row holds the element's basis functions evaluated at the sub-vertex in its ``owner``
    triangle (skfem's ``CellBasis`` at the lattice points, the element's own mapping).
    """
    ij, _ = reference_lattice(n)
    X = (ij / float(n)).T                                                    # (2, m)
    sample = CellBasis(mesh, element, quadrature=(X, np.ones(X.shape[1])))
    e, q = owner[:, 0], owner[:, 1]
    values = np.stack([np.asarray(phi[0])[e, q] for phi in sample.basis], axis=1)   # (N, nbf)
    dofs = np.asarray(sample.element_dofs)[:, e].T                                       # (N, nbf)
    keep = values != 0.0
    rows, cols, data = [], [], []
    k = np.broadcast_to(np.arange(len(owner))[:, None], values.shape)[keep]
    for i in range(components):
        rows.append(components * k + i)
        cols.append(components * dofs[keep] + i)
        data.append(values[keep])
    shape = (components * len(owner), components * sample.N)
    return sp.csr_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))), shape=shape)
