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
    """Kinematic state and its first variations at an array of material points.

    A vectorised reference for the compiled kernels of :mod:`drape.fem.shell_kernels`,
    which assemble the shell's force and tangent.

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
