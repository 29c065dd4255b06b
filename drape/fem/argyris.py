"""Argyris triangle with an element-local, scaled monomial basis.

scikit-fem's :class:`skfem.ElementTriArgyris` inverts a Vandermonde matrix of
*global* monomials ``x**a * y**b``.  On small or offset elements that matrix is
hopelessly ill-conditioned: on a 64×64 unit-square mesh the constant function
is reproduced only to ~5e-5 (Hessian ~1e-2) and on the square [10, 11]² the
error is O(1) (docs/theory.md §4).  This element uses the monomials of the
element-local coordinates ``ξ = (x − c_e)/h_e`` (``c_e`` the centroid, ``h_e``
the largest centroid-to-vertex distance), so the local Vandermonde matrix is
O(1) and identical in conditioning for every element of every mesh; the degrees
of freedom are scaled by ``h_e**k`` (derivative order ``k``) before the
inversion and unscaled exactly afterwards.

The element is a drop-in for ``ElementTriArgyris``: same ``dofnames``
(``u, u_x, u_y, u_xx, u_xy, u_yy`` per vertex, ``u_n`` per edge), same
``doflocs``, usable in :class:`skfem.Basis`, :class:`skfem.ElementVector`,
:class:`skfem.FacetBasis`, ``basis.interpolate`` and ``basis.probes``.  The
inverse Vandermonde and the last evaluated basis are cached *keyed by the mesh
object* (the stock element keeps the first mesh's matrix forever).

Edge normals (the direction of the ``u_n`` dof) follow skfem's convention:
on a boundary edge the outward unit normal; on an interior edge the unit vector
``rot(p_lo − p_hi)`` with ``rot(a, b) = (b, −a)`` and ``lo < hi`` the global
vertex indices (see :func:`facet_normals`).

Examples
--------
>>> import numpy as np
>>> from skfem import Basis, MeshTri
>>> mesh = MeshTri.init_sqsymmetric().refined(2).translated((10.0, 10.0))
>>> basis = Basis(mesh, ElementTriArgyrisLocal())
>>> u = interpolate(basis, lambda x: 1.0 + 0 * x[0])   # the constant 1
>>> field = basis.interpolate(u)
>>> bool(np.abs(field - 1).max() < 1e-12 and np.abs(field.hess).max() < 1e-8)
True
"""
from __future__ import annotations

from typing import Callable, Optional

import numpy as np
from numpy import ndarray
from skfem.element import DiscreteField, ElementTriArgyris, ElementVector

__all__ = ["ElementTriArgyrisLocal", "facet_normals", "interpolate", "same_mesh"]

# exponents (a, b) of the 21 quintic monomials ξ^a η^b
_A, _B = np.array([(a, b) for a in range(6) for b in range(6) if a + b <= 5]).T
# the three local edges of an skfem triangle (order of mesh.t2f rows)
_EDGES = ((0, 1), (1, 2), (0, 2))
# derivative order of each of the 21 dofs (for the h-scaling)
_DOF_ORDER = np.array([0, 1, 1, 2, 2, 2] * 3 + [1, 1, 1])


def _monomials(xi: ndarray, eta: ndarray):
    """Quintic monomials and their ξ-derivatives up to order two.

    Returns ``(P, dP, ddP)`` with shapes ``(21, *s)``, ``(2, 21, *s)`` and
    ``(2, 2, 21, *s)`` where ``s = xi.shape``.
    """
    xp = np.stack([xi**k for k in range(6)])
    ep = np.stack([eta**k for k in range(6)])

    def term(dx: int, dy: int) -> ndarray:
        cx = np.ones(21)
        cy = np.ones(21)
        for k in range(dx):
            cx = cx * (_A - k)
        for k in range(dy):
            cy = cy * (_B - k)
        c = (cx * cy).reshape((21,) + (1,) * xi.ndim)
        return c * xp[np.maximum(_A - dx, 0)] * ep[np.maximum(_B - dy, 0)]

    P = term(0, 0)
    dP = np.stack([term(1, 0), term(0, 1)])
    pxy = term(1, 1)
    ddP = np.stack([np.stack([term(2, 0), pxy]), np.stack([pxy, term(0, 2)])])
    return P, dP, ddP


def _accurate_inverse(A: ndarray) -> ndarray:
    """Batched inverse refined once with residuals in extended precision.

    The Hessian of a sum of basis functions cancels terms of size ~1/h²; an
    inverse correct to the last bit keeps that cancellation at round-off level.
    """
    X = np.linalg.inv(A)
    # only the residual needs the extra bits; the correction is tiny
    R = np.eye(A.shape[-1]) - (A.astype(np.longdouble) @ X.astype(np.longdouble))
    return X + X @ R.astype(float)


def same_mesh(a, b) -> bool:
    """True if two meshes have identical nodes and triangles (copies count)."""
    return a is b or (a.p.shape == b.p.shape and a.t.shape == b.t.shape
                      and np.array_equal(a.p, b.p) and np.array_equal(a.t, b.t))


def facet_normals(mesh) -> ndarray:
    """Unit normals ``(2, nfacets)`` that orient the Argyris ``u_n`` dofs.

    Boundary facets get the outward normal; an interior facet with global
    vertex indices ``lo < hi`` gets ``rot(p_lo − p_hi)``, ``rot(a, b) = (b, −a)``.

    Examples
    --------
    >>> from skfem import MeshTri
    >>> n = facet_normals(MeshTri())        # unit square, two triangles
    >>> n.shape
    (2, 5)
    """
    f = np.sort(mesh.facets, axis=0)
    d = mesh.p[:, f[0]] - mesh.p[:, f[1]]
    n = np.array([d[1], -d[0]]) / np.linalg.norm(d, axis=0)
    bnd = mesh.f2t[1] < 0
    if np.any(bnd):
        fb = np.nonzero(bnd)[0]
        t = mesh.f2t[0, fb]
        mid = 0.5 * (mesh.p[:, f[0, fb]] + mesh.p[:, f[1, fb]])
        centroid = mesh.p[:, mesh.t[:, t]].mean(axis=1)
        flip = np.sum(n[:, fb] * (mid - centroid), axis=0) < 0
        n[:, fb[flip]] *= -1
    return n


class ElementTriArgyrisLocal(ElementTriArgyris):
    """Quintic C¹ Argyris triangle built on element-local scaled monomials.

    Same dofs, names and locations as :class:`skfem.ElementTriArgyris`.
    One instance may be shared by several bases, also on different meshes:
    the cached inverse Vandermonde matrix is keyed by the mesh object.

    Examples
    --------
    >>> from skfem import Basis, ElementVector, MeshTri
    >>> shell = Basis(MeshTri().refined(1), ElementVector(ElementTriArgyrisLocal(), 3))
    >>> int(shell.N)                        # 3 x (6 per vertex x 9 + 1 per edge x 16)
    210
    """

    def __init__(self, node_frames=None):
        """``node_frames``: optional ``(mesh, nodes, M)`` re-combining the six
        vertex dofs of ``nodes`` as ``M[k] @ (u, u_x, u_y, u_xx, u_xy, u_yy)``
        (``M`` of shape (len(nodes), 6, 6), block-diagonal 1 + 2×2 + 3×3).
        Used for boundary conditions along boundaries that are not parallel to
        the axes (see :mod:`drape.fem.boundary`); the element is then tied to
        ``mesh``.
        """
        if node_frames is not None:
            mesh, nodes, M = node_frames
            nodes = np.asarray(nodes, dtype=np.int64).ravel()
            M = np.asarray(M, dtype=float).reshape(len(nodes), 6, 6)
            mask = np.ones((6, 6), bool)
            mask[0, 0] = False
            mask[1:3, 1:3] = False
            mask[3:, 3:] = False
            if np.any(M[:, mask] != 0.0) or np.any(np.abs(np.linalg.det(M)) < 1e-12):
                raise ValueError("node_frames: each M must be invertible and block-diagonal "
                                 "(value, gradient 2x2, Hessian 3x3)")
            node_frames = (mesh, nodes, M)
        self.node_frames = node_frames
        self._coef_mesh = None     # mesh for which _coef holds
        self._coef = None          # (nelems, 21 monomials, 21 basis), x-scaled
        self._h = None             # (nelems,) local length scales
        self._c = None             # (2, nelems) centroids
        self._eval_key = None      # (mesh, X, tind) of the last evaluation
        self._eval = None          # its (value, grad, hess) for all 21 functions

    # -- element geometry -------------------------------------------------
    def _coefficients(self, mesh):
        """Monomial coefficients of the 21 basis functions on every element."""
        if self._coef_mesh is mesh:
            return self._coef, self._c, self._h
        v = mesh.p[:, mesh.t]                                  # (2, 3, ne)
        c = v.mean(axis=1)
        h = np.linalg.norm(v - c[:, None, :], axis=0).max(axis=0)
        xi = (v - c[:, None, :]) / h                           # (2, 3, ne)
        P, dP, ddP = _monomials(xi[0], xi[1])                  # (.., 21, 3, ne)
        n = facet_normals(mesh)[:, mesh.t2f]                   # (2, 3, ne)
        ne = mesh.t.shape[1]
        A = np.empty((ne, 21, 21))                             # dof x monomial
        for k in range(3):
            A[:, 6 * k + 0] = P[:, k].T
            A[:, 6 * k + 1] = dP[0, :, k].T
            A[:, 6 * k + 2] = dP[1, :, k].T
            A[:, 6 * k + 3] = ddP[0, 0, :, k].T
            A[:, 6 * k + 4] = ddP[0, 1, :, k].T
            A[:, 6 * k + 5] = ddP[1, 1, :, k].T
        for j, (a, b) in enumerate(_EDGES):
            mid = 0.5 * (xi[:, a] + xi[:, b])
            _, dPm, _ = _monomials(mid[0], mid[1])             # (2, 21, ne)
            A[:, 18 + j] = (n[0, j] * dPm[0] + n[1, j] * dPm[1]).T
        if self.node_frames is not None:
            fmesh, nodes, M = self.node_frames
            if not same_mesh(fmesh, mesh):
                raise ValueError("ElementTriArgyrisLocal: its node_frames belong to another "
                                 "mesh; build one element per mesh")
            slot = -np.ones(mesh.p.shape[1], dtype=np.int64)
            slot[nodes] = np.arange(len(nodes))
            for k in range(3):
                s_k = slot[mesh.t[k]]
                e = np.nonzero(s_k >= 0)[0]
                # frames mix dofs of one derivative order only, so the h^k
                # scaling of the rows commutes with M
                A[e, 6 * k:6 * k + 6] = M[s_k[e]] @ A[e, 6 * k:6 * k + 6]
        # A holds h^k-scaled dofs of ξ-monomials, O(1) for every element;
        # the true dof matrix is diag(h^-k) A, so its inverse is A^-1 diag(h^k).
        coef = _accurate_inverse(A) * h[:, None, None] ** _DOF_ORDER[None, None, :]
        self._coef_mesh, self._coef, self._c, self._h = mesh, coef, c, h
        self._eval_key = self._eval = None
        return coef, c, h

    # -- skfem element protocol ------------------------------------------
    def _evaluate(self, mapping, X, tind):
        """Values, gradients and Hessians of all 21 functions at X."""
        mesh = mapping.mesh
        key_tind = None if tind is None else np.asarray(tind)
        key = self._eval_key
        if (key is not None and key[0] is mesh and key[1].shape == X.shape
                and np.array_equal(key[1], X)
                and ((key[2] is None and key_tind is None)
                     or (key[2] is not None and key_tind is not None
                         and np.array_equal(key[2], key_tind)))):
            return self._eval
        coef, c, h = self._coefficients(mesh)
        if tind is not None:
            coef, c, h = coef[tind], c[:, tind], h[tind]
        x = mapping.F(X, tind=tind)                            # (2, ne, nq)
        xi = (x - c[:, :, None]) / h[None, :, None]
        P, dP, ddP = _monomials(xi[0], xi[1])                  # (.., 21, ne, nq)
        cT = np.transpose(coef, (0, 2, 1))                     # (ne, 21 fun, 21 mon)
        ne, nq = xi.shape[1:]
        value = np.empty((21, ne, nq))
        grad = np.empty((21, 2, ne, nq))
        hess = np.empty((21, 2, 2, ne, nq))

        def contract(Q, out, scale):                           # sum over monomials
            out[...] = np.transpose(cT @ np.transpose(Q, (1, 0, 2)), (1, 0, 2))
            out /= scale[:, None]

        contract(P, value, np.ones(ne))
        for a in range(2):
            contract(dP[a], grad[:, a], h)
            contract(ddP[a, a], hess[:, a, a], h**2)
        contract(ddP[0, 1], hess[:, 0, 1], h**2)
        hess[:, 1, 0] = hess[:, 0, 1]
        self._eval_key = (mesh, np.array(X, copy=True),
                          None if key_tind is None else key_tind.copy())
        self._eval = (value, grad, hess)
        return self._eval

    def gbasis(self, mapping, X, i, tind=None):
        if not 0 <= i < 21:
            self._index_error()
        value, grad, hess = self._evaluate(mapping, X, tind)
        return (DiscreteField(value=value[i], grad=grad[i], hess=hess[i]),)


def interpolate(basis, value: Callable, grad: Optional[Callable] = None,
                hess: Optional[Callable] = None) -> ndarray:
    """Argyris dof vector of a smooth function given with its derivatives.

    Parameters
    ----------
    basis
        A basis on :class:`ElementTriArgyrisLocal` (or the stock Argyris
        element, or :class:`skfem.ElementTriMorley`: vertex values and edge
        slopes), scalar or wrapped in :class:`skfem.ElementVector`.
    value, grad, hess
        Callables of points ``x`` with shape ``(2, N)`` returning ``(N,)``,
        ``(2, N)``, ``(2, 2, N)`` for a scalar basis, or with a leading
        component axis ``(dim, N)``, ``(dim, 2, N)``, ``(dim, 2, 2, N)`` for a
        vector basis.  ``grad``/``hess`` default to zero (fine for constants).

    Returns
    -------
    ndarray
        The dof vector, exact for quintic polynomials.

    Examples
    --------
    >>> from skfem import Basis, MeshTri
    >>> basis = Basis(MeshTri().refined(2), ElementTriArgyrisLocal())
    >>> u = interpolate(basis, lambda x: x[0] ** 2,
    ...                 lambda x: np.array([2 * x[0], 0 * x[0]]),
    ...                 lambda x: np.array([[2 + 0 * x[0], 0 * x[0]], [0 * x[0], 0 * x[0]]]))
    >>> round(float((basis.probes(np.array([[0.3], [0.7]])) @ u)[0]), 12)
    0.09
    """
    mesh = basis.mesh
    dim = basis.elem.dim if isinstance(basis.elem, ElementVector) else None
    ncomp = 1 if dim is None else dim

    def call(fun, x, shape):
        if fun is None:
            return np.zeros((ncomp,) + shape + (x.shape[1],))
        out = np.asarray(fun(x), dtype=float)
        return out.reshape((ncomp,) + shape + (x.shape[1],))

    out = np.zeros(basis.N)
    p = mesh.p
    u, du, ddu = call(value, p, ()), call(grad, p, (2,)), call(hess, p, (2, 2))
    nodal = np.array([u, du[:, 0], du[:, 1], ddu[:, 0, 0], ddu[:, 0, 1], ddu[:, 1, 1]])
    elem = basis.elem.elem if dim is not None else basis.elem
    frames = getattr(elem, "node_frames", None)
    if frames is not None:                       # dofs re-combined at framed nodes
        _, nodes, M = frames
        nodal[:, :, nodes] = np.einsum("nij,jcn->icn", M, nodal[:, :, nodes])
    n_types = basis.nodal_dofs.shape[0] // ncomp    # 6 for Argyris, 1 for Morley
    for k, field in enumerate(nodal[:n_types]):
        for c in range(ncomp):
            out[basis.nodal_dofs[k * ncomp + c]] = field[c]
    mid = mesh.p[:, mesh.facets].mean(axis=1)
    n = facet_normals(mesh)
    dmid = call(grad, mid, (2,))
    for c in range(ncomp):
        out[basis.facet_dofs[c]] = np.sum(dmid[c] * n, axis=0)
    return out
