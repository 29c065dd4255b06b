"""Kirchhoff–Love kinematics of a flat reference surface, vectorised over points.

Total-Lagrangian description of a plate whose reference configuration is the
x–y plane: the displacement ``u`` (3 components) gives the deformed surface
``r = X + u``, with

* covariant base vectors ``a_α = e_α + u_,α``,
* unit normal ``n = a1 × a2 / |a1 × a2|``,
* Green–Lagrange membrane strain ``E_αβ = ½ (a_α · a_β − δ_αβ)``,
* curvature ``κ_αβ = u_,αβ · n`` (positive: concave towards +n, i.e. face-up).

Everything is stored in Voigt order ``(11, 22, 12)`` with the engineering
factor 2 on the shear/twist entry: ``ε = (E11, E22, 2 E12)``,
``κ = (κ11, κ22, 2 κ12)``; the conjugate stress resultants are
``N = (N11, N22, N12)`` and ``M = (M11, M22, M12)``.

Arrays carry the material points in their leading axes ``(e, q)`` (element,
quadrature point). Derivatives with respect to the element's displacement
coefficients use a flat local dof index ``I = 3 b + k`` (scalar basis function
``b``, displacement component ``k``), the layout of
``skfem.ElementVector(element, 3)``.

Examples
--------
A rigid rotation of the plane about the x axis leaves strain and curvature zero:

>>> import numpy as np
>>> c, s = np.cos(0.3), np.sin(0.3)
>>> a = np.array([[[1.0, 0.0, 0.0], [0.0, c, s]]])   # (points, α, xyz)
>>> np.allclose(membrane_strain(a), 0.0)
True
>>> n, j = unit_normal(a)
>>> np.round(n, 6).tolist()
[[0.0, -0.29552, 0.955336]]
"""

from __future__ import annotations

import numpy as np

#: Permutation (Levi-Civita) symbol ε_ijk.
LEVI_CIVITA = np.zeros((3, 3, 3))
LEVI_CIVITA[0, 1, 2] = LEVI_CIVITA[1, 2, 0] = LEVI_CIVITA[2, 0, 1] = 1.0
LEVI_CIVITA[0, 2, 1] = LEVI_CIVITA[2, 1, 0] = LEVI_CIVITA[1, 0, 2] = -1.0


def basis_arrays(basis):
    """Gradients and Voigt Hessians of a scalar C¹ basis, points first.

    Parameters
    ----------
    basis : skfem.CellBasis
        Scalar basis (e.g. Argyris) with Hessians.

    Returns
    -------
    dN : ndarray, shape (e, q, nb, 2)
        ``N_b,α`` at every quadrature point.
    HN : ndarray, shape (e, q, nb, 3)
        ``(N_b,11, N_b,22, 2 N_b,12)`` (Voigt, factor 2 on the mixed entry).
    N : ndarray, shape (e, q, nb)
        Basis values.
    """
    fields = [basis.basis[i][0] for i in range(basis.Nbfun)]
    N = np.stack([np.asarray(f) for f in fields], axis=-1)
    dN = np.stack([np.moveaxis(f.grad, 0, -1) for f in fields], axis=-2)
    hess = [f.hess for f in fields]
    HN = np.stack([np.stack([h[0, 0], h[1, 1], 2.0 * h[0, 1]], axis=-1)
                   for h in hess], axis=-2)
    return dN, HN, N


def covariant_basis(dN, ue):
    """Deformed covariant base vectors ``a_α = e_α + Σ_b N_b,α u_b``.

    Parameters
    ----------
    dN : ndarray, shape (e, q, nb, 2)
    ue : ndarray, shape (e, nb, 3)
        Element displacement coefficients.

    Returns
    -------
    ndarray, shape (e, q, 2, 3)
    """
    a = np.einsum("eqba,ebk->eqak", dN, ue)
    a[..., 0, 0] += 1.0
    a[..., 1, 1] += 1.0
    return a


def second_derivatives(HN, ue):
    """Voigt second derivatives ``(u_,11, u_,22, 2 u_,12)``, shape (e, q, 3, 3)."""
    return np.einsum("eqbv,ebk->eqvk", HN, ue)


def unit_normal(a):
    """Unit normal ``n = a1 × a2 / j`` and area stretch ``j = |a1 × a2|``."""
    a3 = np.cross(a[..., 0, :], a[..., 1, :])
    j = np.linalg.norm(a3, axis=-1)
    return a3 / j[..., None], j


def membrane_strain(a):
    """Green–Lagrange strain in Voigt form ``(E11, E22, 2 E12)``.

    Computed from the displacement gradient ``g_α = a_α − e_α`` as
    ``E_αβ = ½ (g_αβ + g_βα + g_α · g_β)``, which avoids the cancellation in
    ``a_α · a_α − 1`` (the membrane is 1e9× stiffer than the bending of fabric,
    so that round-off would set the residual floor).
    """
    g = a.copy()
    g[..., 0, 0] -= 1.0
    g[..., 1, 1] -= 1.0
    gg = np.einsum("...ak,...bk->...ab", g, g)
    return np.stack([
        g[..., 0, 0] + 0.5 * gg[..., 0, 0],
        g[..., 1, 1] + 0.5 * gg[..., 1, 1],
        g[..., 0, 1] + g[..., 1, 0] + gg[..., 0, 1],
    ], axis=-1)


def curvature(h, n):
    """Voigt curvature ``(κ11, κ22, 2 κ12)`` with ``κ_αβ = u_,αβ · n``."""
    return np.einsum("...vk,...k->...v", h, n)


class KLPoint:
    """Kinematic state and its variations at an array of material points.

    Parameters
    ----------
    dN, HN : ndarray
        From :func:`basis_arrays`.
    ue : ndarray, shape (e, nb, 3)
        Element displacement coefficients.

    Attributes
    ----------
    a : (e, q, 2, 3) covariant base vectors
    n : (e, q, 3) unit normal; j : (e, q) area stretch
    h : (e, q, 3, 3) Voigt second derivatives of the position
    strain : (e, q, 3) Voigt membrane strain
    kappa : (e, q, 3) Voigt curvature
    """

    def __init__(self, dN, HN, ue):
        self.dN, self.HN = dN, HN
        self.a = covariant_basis(dN, ue)
        self.h = second_derivatives(HN, ue)
        self.n, self.j = unit_normal(self.a)
        self.strain = membrane_strain(self.a)
        self.kappa = curvature(self.h, self.n)
        self._da3 = self._de = self._dk = None

    @property
    def nb(self):
        return self.dN.shape[2]

    def strain_variation(self):
        """``∂ε_v/∂u_I``, shape (e, q, 3, 3 nb)."""
        if self._de is None:
            self._de = self._strain_variation()
        return self._de

    def _strain_variation(self):
        dN, a = self.dN, self.a
        d = np.stack([
            np.einsum("eqb,eqk->eqbk", dN[..., 0], a[..., 0, :]),
            np.einsum("eqb,eqk->eqbk", dN[..., 1], a[..., 1, :]),
            np.einsum("eqb,eqk->eqbk", dN[..., 0], a[..., 1, :])
            + np.einsum("eqb,eqk->eqbk", dN[..., 1], a[..., 0, :]),
        ], axis=2)
        return d.reshape(d.shape[:3] + (-1,))

    def normal_variation(self):
        """``∂a3/∂u_I`` and ``∂n/∂u_I``, both shape (e, q, 3 nb, 3)."""
        if self._da3 is None:
            dN, a = self.dN, self.a
            # e_k × a2 = -[a2]_x e_k, a1 × e_k = [a1]_x e_k; skew[..., i, k] = ([v]_x)_ik
            sk1 = np.einsum("ijm,eqj->eqim", LEVI_CIVITA, a[..., 0, :])
            sk2 = np.einsum("ijm,eqj->eqim", LEVI_CIVITA, a[..., 1, :])
            # da3[e, q, b, k, i] = -N_b,1 ([a2]_x)_ik + N_b,2 ([a1]_x)_ik
            da3 = (dN[..., 1, None, None] * np.swapaxes(sk1, 2, 3)[:, :, None]
                   - dN[..., 0, None, None] * np.swapaxes(sk2, 2, 3)[:, :, None])
            da3 = da3.reshape(da3.shape[:2] + (-1, 3))
            # dn = (I - n n^T) da3 / j
            self._An = np.matmul(da3, self.n[..., None])[..., 0]     # da3 · n
            dn = da3 - self._An[..., None] * self.n[:, :, None, :]
            dn /= self.j[..., None, None]
            self._da3, self._dn = da3, dn
        return self._da3, self._dn

    def curvature_variation(self):
        """``∂κ_v/∂u_I``, shape (e, q, 3, 3 nb)."""
        if self._dk is None:
            self._dk = self._curvature_variation()
        return self._dk

    def _curvature_variation(self):
        _, dn = self.normal_variation()
        e, q, nb, _ = self.HN.shape
        first = (np.swapaxes(self.HN, 2, 3)[..., None] * self.n[:, :, None, None, :])
        return first.reshape(e, q, 3, 3 * nb) + np.matmul(self.h, np.swapaxes(dn, 2, 3))

    def rate_variation(self, xe):
        """Curvature rate ``κ̇ = ∂κ/∂u · x`` and its derivative ``∂κ̇/∂u`` for a fixed rate.

        Parameters
        ----------
        xe : ndarray, shape (e, nb, 3)
            Element coefficients of the rate field ``x`` (velocity or acceleration).

        Returns
        -------
        kdot : (e, q, 3) Voigt curvature rate.
        g : (e, q, 3, 3 nb) ``∂κ̇_v/∂u_I = (∂²κ_v/∂u∂u) x`` (enters the tangent of
        viscous bending moments ``d κ̇``).
        """
        da3, dn = self.normal_variation()
        a, n, j, h = self.a, self.n, self.j, self.h
        e, q, nb, _ = self.HN.shape
        adot = np.einsum("eqba,ebk->eqak", self.dN, xe)
        hdot = np.einsum("eqbv,ebk->eqvk", self.HN, xe)
        a3dot = np.cross(adot[..., 0, :], a[..., 1, :]) + np.cross(a[..., 0, :], adot[..., 1, :])
        na3 = np.einsum("eqk,eqk->eq", n, a3dot)
        ndot = (a3dot - na3[..., None] * n) / j[..., None]
        kdot = np.einsum("eqvk,eqk->eqv", hdot, n) + np.einsum("eqvk,eqk->eqv", h, ndot)
        # ḣ_v · ∂n/∂u_I + N_b,v ṅ_k
        g = np.matmul(hdot, np.swapaxes(dn, 2, 3))
        g += (np.swapaxes(self.HN, 2, 3)[..., None] * ndot[:, :, None, None, :]).reshape(e, q, 3, -1)
        # h_v · ∂²n/∂a3² [∂a3/∂u_I, ȧ3]
        hn = np.einsum("eqvk,eqk->eqv", h, n)
        ha3 = np.einsum("eqvk,eqk->eqv", h, a3dot)
        Dh = np.matmul(h, np.swapaxes(da3, 2, 3))                      # (e, q, v, I)
        An = self._An[:, :, None, :]
        Da = np.matmul(da3, a3dot[..., None])[..., 0][:, :, None, :]
        j2 = (j ** 2)[..., None, None]
        g += (-Dh * na3[..., None, None] - ha3[..., None] * An - Da * hn[..., None]
              + 3.0 * (hn * na3[..., None])[..., None] * An) / j2
        # (P h_v / j) · ∂ȧ3/∂u_I = N_b,2 (p × ȧ1)_k + N_b,1 (ȧ2 × p)_k
        p = (h - hn[..., None] * n[:, :, None, :]) / j[..., None, None]
        c1 = np.cross(p, adot[:, :, None, 0, :])
        c2 = np.cross(adot[:, :, None, 1, :], p)
        g += (self.dN[:, :, None, :, 1, None] * c1[:, :, :, None, :]
              + self.dN[:, :, None, :, 0, None] * c2[:, :, :, None, :]).reshape(e, q, 3, -1)
        return kdot, g

    def tangent(self, C_m, N, M, D, w, strain_projection=None):
        """Element tangent ``Σ_q w (∂²W/∂u_I∂u_J)``, shape (e, 3 nb, 3 nb).

        Material parts ``∂εᵀ C_m ∂ε`` and ``∂κᵀ D ∂κ`` plus the geometric parts
        ``N_v ∂²ε_v`` and ``M_v ∂²κ_v`` (second variation of the normal included);
        the dense rank terms are stacked into one batched matmul.

        Parameters
        ----------
        C_m : (3, 3) membrane stiffness; N : (e, q, 3) membrane forces;
        M : (e, q, 3) moments; D : (e, q, 3) moment tangents dM_v/dκ_v;
        w : (e, q) quadrature weights; strain_projection : (q, q), optional
        self-adjoint operator ``Q`` of an assumed membrane strain
        (:func:`assumed_strain_operator`, energy ``½ ∫ εᵀ C_m Q ε``); then ``N`` must be
        ``C_m Q ε``.
        """
        da3, dn = self.normal_variation()
        de = self.strain_variation()
        dk = self.curvature_variation()
        n, j, nb = self.n, self.j, self.nb
        e, nq = w.shape
        nd = 3 * nb
        Mw = M * w[..., None]
        m = np.einsum("eqv,eqvk->eqk", Mw, self.h)
        mn = np.einsum("eqk,eqk->eq", m, n)
        s = mn / j ** 2
        Am = np.matmul(da3, m[..., None])[..., 0] / j[..., None] ** 2
        An = self._An
        A = np.empty((e, nq, 12, nd))
        B = np.empty((e, nq, 12, nd))
        A[:, :, 0:3] = de
        # assumed strain: the second variation of ½ ∫ εᵀ C Q ε is ∫ ∂εᵀ C (Q ∂ε) (Q self-adjoint)
        dep = de if strain_projection is None else np.einsum("pq,eqvI->epvI", strain_projection, de)
        B[:, :, 0:3] = np.matmul(C_m, dep) * w[..., None, None]
        A[:, :, 3:6] = dk
        B[:, :, 3:6] = dk * (D * w[..., None])[..., None]
        A[:, :, 6:9] = np.swapaxes(da3, 2, 3)
        B[:, :, 6:9] = A[:, :, 6:9] * -s[..., None, None]
        A[:, :, 9], B[:, :, 9] = An, 3.0 * s[..., None] * An
        A[:, :, 10], B[:, :, 10] = Am, -An
        A[:, :, 11], B[:, :, 11] = An, -Am
        K = gram(A, B)
        # N_b,v (∂n/∂u_J)_k M_v and its transpose
        Mh = np.matmul(self.HN, Mw[..., None])[..., 0]
        X = gram(Mh, dn.reshape(e, nq, nd * 3)).reshape(e, nb, nd, 3)
        X = np.swapaxes(X, 2, 3).reshape(e, nd, nd)
        K += X + np.swapaxes(X, 1, 2)
        # (P m / j) · ∂²a3/∂u_I∂u_J = -(N_b,1 N_c,2 - N_b,2 N_c,1) [p]_x[k, l]
        p = (m - mn[..., None] * n) / j[..., None]
        S = np.einsum("kil,eqi->eqkl", LEVI_CIVITA, p)
        Bt = np.einsum("eqc,eqkl->eqckl", self.dN[..., 1], S).reshape(e, nq, -1)
        T = gram(self.dN[..., 0], Bt).reshape(e, nb, nb, 3, 3)   # [b, c, k, l]
        T = T - np.swapaxes(T, 1, 2)
        # membrane geometric term N_v ∂²ε_v (identity in the components) on the diagonal blocks
        Sn = np.empty(N.shape[:2] + (2, 2))
        Sn[..., 0, 0], Sn[..., 1, 1] = N[..., 0], N[..., 1]
        Sn[..., 0, 1] = Sn[..., 1, 0] = N[..., 2]
        SdN = np.einsum("eqac,eqdc->eqad", Sn * w[..., None, None], self.dN)
        G = gram(np.swapaxes(self.dN, 2, 3), SdN)                # (e, nb, nb)
        T = -T
        for k in range(3):
            T[:, :, :, k, k] += G
        K += np.transpose(T, (0, 1, 3, 2, 4)).reshape(e, nd, nd)
        return K


def polynomial_projection(X, W, degree: int):
    """L²(W) projection of quadrature-point values onto polynomials of total ``degree``.

    Parameters
    ----------
    X : ndarray, shape (2, q)
        Quadrature points on the reference triangle.
    W : ndarray, shape (q,)
        Their weights.
    degree : int
        Polynomial degree (>= 0).

    Returns
    -------
    ndarray, shape (q, q)
        ``P`` with ``(P f)_p = Σ_q P_pq f_q``; on affine elements the same for every element
        (the weights scale by the constant Jacobian). Self-adjoint in the weighted inner
        product: ``Σ w a (P b) = Σ w (P a) b``.

    Examples
    --------
    A quadratic is its own projection onto degree 2, not onto degree 1:

    >>> from skfem.quadrature import get_quadrature
    >>> from skfem.refdom import RefTri
    >>> X, W = get_quadrature(RefTri, 6)
    >>> f = X[0] ** 2 - X[0] * X[1]
    >>> bool(np.allclose(polynomial_projection(X, W, 2) @ f, f))
    True
    >>> bool(np.allclose(polynomial_projection(X, W, 1) @ f, f))
    False
    """
    if degree < 0:
        raise ValueError(f"degree = {degree!r} must be >= 0")
    powers = [(i, k - i) for k in range(degree + 1) for i in range(k + 1)]
    V = np.stack([X[0] ** a * X[1] ** b for a, b in powers], axis=1)      # (q, m)
    if V.shape[1] > V.shape[0]:
        raise ValueError(f"degree {degree} needs {V.shape[1]} quadrature points, the rule has {V.shape[0]}")
    G = V.T @ (W[:, None] * V)
    return V @ np.linalg.solve(G, V.T * W)


def gram(A, B):
    """``Σ AᵢBⱼ`` over all middle axes: (e, ..., I), (e, ..., J) -> (e, I, J) by batched matmul."""
    e = A.shape[0]
    A2 = A.reshape(e, -1, A.shape[-1])
    B2 = B.reshape(e, -1, B.shape[-1])
    return np.matmul(np.swapaxes(A2, 1, 2), B2)


def assumed_strain_operator(X, W, degree: int, stabilization: float = 0.0):
    """Quadrature-point operator ``Q = (1 − γ) P + γ I`` of a stabilised assumed strain.

    With ``P`` the :func:`polynomial_projection` onto ``degree`` and a membrane stiffness
    ``C`` constant on the element, the energy ``½ ∫ εᵀ C Q ε`` splits into the assumed
    strain's part and a penalty ``γ`` on the rest,

        ½ ∫ (P ε)ᵀ C (P ε) + γ ½ ∫ ((I − P) ε)ᵀ C ((I − P) ε),

    (the cross terms vanish: ``P`` is the L² projection). ``γ = 0`` is the pure assumed
    strain, whose low degrees (0–2) leave spurious zero-energy in-plane modes; a small
    ``γ`` (0.01–0.1) removes them while it still relieves most of the locking; ``γ = 1`` is
    the consistent strain. ``Q`` is self-adjoint in the weighted inner product, so
    internal force ``∫ ∂εᵀ C Q ε`` and tangent ``∫ ∂εᵀ C Q ∂ε + (C Q ε)·∂²ε`` follow from
    the energy as they do for the consistent strain.

    Examples
    --------
    >>> from skfem.quadrature import get_quadrature
    >>> from skfem.refdom import RefTri
    >>> X, W = get_quadrature(RefTri, 6)
    >>> Q = assumed_strain_operator(X, W, 1, 0.05)
    >>> f = X[0] ** 2                          # not linear: only 5 % of its remainder stays
    >>> P = polynomial_projection(X, W, 1)
    >>> bool(np.allclose(Q @ f, P @ f + 0.05 * (f - P @ f)))
    True
    >>> bool(np.allclose(W * (Q @ f) @ X[1], W * f @ (Q @ X[1])))   # self-adjoint
    True
    """
    if not 0.0 <= stabilization <= 1.0:
        raise ValueError(f"stabilization = {stabilization!r} must be in [0, 1]")
    P = polynomial_projection(X, W, degree)
    return (1.0 - stabilization) * P + stabilization * np.eye(len(W))
