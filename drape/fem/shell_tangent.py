"""The compiled step matrix of the shell: ``c_K K + c_C C_law + c_M M_law`` scattered into CSR data.

The laws' viscous and curvature-inertia matrices join the bending term point by point; the
elements of one colour (:func:`drape.fem.shell_kernels.element_colours`) share no dof, so each
colour is scattered in parallel without races. Compiled and cached like the other kernels
(:mod:`drape.fem.compiled`).
"""
from __future__ import annotations

import numpy as np
from numba import prange

from drape.fem.compiled import njit
from drape.fem.shell_kernels import _add_per_dof, _cross, _kappa_rate, _phi, _point, _variations

__all__ = ['tangent']



@njit(cache=True)
def _rate(dN, HN, x, a, h, n, j, p, visc_v, wq, cdk, Mg, Z, work):
    """Curvature rate of the field ``x`` and, with ``visc_v`` = (c_warp, c_weft), the
    moments ``c κ̇`` added to ``Mg`` and ``w c ∂κ ⊗ ∂κ̇/∂u`` added to ``Z``; ``work`` is
    (16, 3) scratch."""
    ad, hd, a3d, nd, kd, y, t1, t2, cg = (work[0:2], work[2:5], work[5], work[6], work[7], work[8],
                                          work[9], work[10], work[11:16])
    na3 = _kappa_rate(dN, HN, x, a, h, n, j, ad, hd, a3d, nd, kd)
    for v in range(2):
        if visc_v[v] == 0.0:
            continue
        hn = h[v, 0] * n[0] + h[v, 1] * n[1] + h[v, 2] * n[2]
        ha3 = h[v, 0] * a3d[0] + h[v, 1] * a3d[1] + h[v, 2] * a3d[2]
        hdn = hd[v, 0] * n[0] + hd[v, 1] * n[1] + hd[v, 2] * n[2]
        Mg[v] += visc_v[v] * kd[v]
        # ∂κ̇_v/∂u = h_v · ∂²n [∂u, ẋ] + ḣ_v · ∂n + ∂h_v · ṅ: every ∂a3 term is one vector y
        for k in range(3):
            y[k] = ((-na3 * h[v, k] - ha3 * n[k] - hn * a3d[k] + 3.0 * hn * na3 * n[k]) / (j * j)
                    + (hd[v, k] - hdn * n[k]) / j)
        cg[:] = 0.0
        _cross(a[1], y, t1)
        _cross(ad[1], p[v], t2)
        for k in range(3):
            cg[0, k] = t1[k] + t2[k]
        _cross(y, a[0], t1)
        _cross(p[v], ad[0], t2)
        for k in range(3):
            cg[1, k] = t1[k] + t2[k]
            cg[2 + v, k] = nd[k]
        _outer_add(wq * visc_v[v], cdk[v], cg, Z)


@njit(cache=True)
def _half(Z, phi, Wrow):
    """``Wrow[s, k, l, c] = Σ_t Z[s, k, t, l] φ_t[c]``, contiguous in ``c`` (it vectorises)."""
    nb = phi.shape[1]
    for s in range(5):
        for k in range(3):
            for l in range(3):
                z0, z1, z2 = Z[s, k, 0, l], Z[s, k, 1, l], Z[s, k, 2, l]
                z3, z4 = Z[s, k, 3, l], Z[s, k, 4, l]
                for c in range(nb):
                    Wrow[s, k, l, c] = (z0 * phi[0, c] + z1 * phi[1, c] + z2 * phi[2, c]
                                        + z3 * phi[3, c] + z4 * phi[4, c])


@njit(cache=True)
def _outer_add(scale, x, y, Z):
    """``Z[s, k, t, l] += scale x[s, k] y[t, l]``, on ``Z`` as a 15 × 15 matrix."""
    for s in range(5):
        for k in range(3):
            xs = scale * x[s, k]
            if xs == 0.0:
                continue
            for t in range(5):
                for l in range(3):
                    Z[s, k, t, l] += xs * y[t, l]


@njit(cache=True, parallel=True)
def tangent(ue, ve, ae, dN, HN, w, Q, C_m, Nm, M, D, visc, weights, order, start, csr_map,
            fe, Jd, symmetrize=False):
    """Element internal force and the weighted tangent ``c_K K + c_C C_law + c_M M_law``,
    scattered into CSR data.

    A Newmark step needs only this sum, so the laws' viscous and curvature-inertia matrices
    ``∫ ∂κᵀ (c_C d + c_M m) ∂κ`` join the bending material term ``∫ ∂κᵀ D ∂κ`` point by
    point: they cost no element matrix product of their own and no scatter.

    Parameters
    ----------
    ue, ve, ae : (E, nb, 3)
        Element displacement, velocity and acceleration coefficients.
    dN, HN, w : basis gradients (E, q, nb, 2), Voigt Hessians (E, q, nb, 3), weights (E, q).
    Q : (q, q)
        Assumed-strain operator (identity for the consistent strain).
    C_m : (3, 3) membrane stiffness.
    Nm, M : (E, q, 3)
        Membrane forces ``C_m Q ε`` and the law's Voigt moments.
    D : (E, q, 3, 3)
        The law's tangent ``dM_v/dκ_x`` (Voigt).
    visc : (2, 2)
        ``[[d_warp, d_weft], [m_warp, m_weft]]``: the laws' viscosity and curvature inertia.
    weights : (3,)
        ``(c_K, c_C, c_M)``.
    order, start : element colouring (:func:`drape.fem.shell_kernels.element_colours`).
    csr_map : (E, 3 nb, 3 nb) int
        Position of every element-matrix entry in the CSR data.
    fe : (E, 3 nb) output
        Element forces ``∫ ∂εᵀ N + ∂κᵀ (M + d κ̇)``: the laws' viscous moment is a force,
        their curvature inertia ``m κ̈`` is not (it belongs to the inertia).
    Jd : (nnz,)
        CSR data the weighted tangent is added to. ``K = ∂f/∂u`` is material + geometric +
        the configuration dependence of ``d κ̇ + m κ̈``; ``C_law = d ∫ ∂κᵀ∂κ``,
        ``M_law = m ∫ ∂κᵀ∂κ``.
    symmetrize : bool
        Scatter the symmetric part of each element's matrix (only K's rate terms are
        unsymmetric).
    """
    nq, nb = dN.shape[1], dN.shape[2]
    cK, cC, cM = weights[0], weights[1], weights[2]
    has_c = visc[0, 0] != 0.0 or visc[0, 1] != 0.0
    has_m = visc[1, 0] != 0.0 or visc[1, 1] != 0.0
    for colour in range(len(start) - 1):
        for i in prange(start[colour], start[colour + 1]):
            e = order[i]
            a = np.empty((nq, 2, 3))
            h = np.empty((nq, 3, 3))
            n = np.empty((nq, 3))
            jq = np.empty(nq)
            # membrane: ∂ε at every point first, the assumed strain couples the points
            de = np.zeros((nq, 3, nb, 3))
            for q in range(nq):
                jq[q] = _point(dN[e, q], HN[e, q], ue[e], a[q], h[q], n[q])
                for b in range(nb):
                    for k in range(3):
                        de[q, 0, b, k] = dN[e, q, b, 0] * a[q, 0, k]
                        de[q, 1, b, k] = dN[e, q, b, 1] * a[q, 1, k]
                        de[q, 2, b, k] = dN[e, q, b, 0] * a[q, 1, k] + dN[e, q, b, 1] * a[q, 0, k]
            # the assumed strain Σ_r Q_qr ∂ε_r at every point, as one matrix product
            Qde = np.dot(Q, de.reshape(nq, 9 * nb)).reshape(nq, 3, nb, 3)
            # Σ_q Σ_s φ_qs[b] W_q[s, k, l, c] as one matrix product over (q, s)
            Phi = np.empty((nb, 5 * nq))
            Wall = np.empty((5 * nq, 3, 3, nb))   # every entry set by _half
            Z = np.empty((5, 3, 5, 3))
            p = np.empty((3, 3))
            cde = np.empty((3, 5, 3))
            cdk = np.empty((3, 5, 3))
            phi = np.empty((5, nb))
            CQde = np.empty((3, 3, nb))
            E0 = np.empty((3, 3))
            E1 = np.empty((3, 3))
            Pm = np.empty((3, 3))
            cAn = np.zeros((5, 3))
            cAm = np.zeros((5, 3))
            ca3 = np.zeros((3, 5, 3))
            ek = np.empty(3)
            t = np.empty(3)
            m = np.empty(3)
            pm = np.empty(3)
            Mg = np.empty(3)
            Mf = np.empty(3)
            F = np.empty((5, 3))
            t3 = np.empty(3)
            work = np.empty((16, 3))
            fe[e] = 0.0
            for q in range(nq):
                j = jq[q]
                wq = w[e, q]
                _variations(a[q], h[q], n[q], j, cde, cdk, p, t3)
                _phi(dN[e, q], HN[e, q], phi)
                Wrow = Wall[5 * q:5 * q + 5]
                for s in range(5):
                    for b in range(nb):
                        Phi[b, 5 * q + s] = phi[s, b]
                # ---- moments: the law's, + d κ̇ (the force's), + m κ̈ (the geometric term's);
                # with them ∂κ ⊗ ∂(d κ̇ + m κ̈)/∂u into Z
                Z[:] = 0.0
                for v in range(3):
                    Mg[v] = M[e, q, v]
                if has_c:
                    _rate(dN[e, q], HN[e, q], ve[e], a[q], h[q], n[q], j, p,
                          visc[0], wq, cdk, Mg, Z, work)
                for v in range(3):
                    Mf[v] = Mg[v]
                if has_m:
                    _rate(dN[e, q], HN[e, q], ae[e], a[q], h[q], n[q], j, p,
                          visc[1], wq, cdk, Mg, Z, work)
                # ---- force
                F[:] = 0.0
                for v in range(3):
                    for s in range(5):
                        for k in range(3):
                            F[s, k] += Nm[e, q, v] * cde[v, s, k] + Mf[v] * cdk[v, s, k]
                _add_per_dof(wq, phi, F, fe[e].reshape(nb, 3))
                # ---- membrane geometric part N_v ∂²ε_v (identity in k, l)
                S00, S11, S01 = wq * Nm[e, q, 0], wq * Nm[e, q, 1], wq * Nm[e, q, 2]
                for k in range(3):
                    Z[0, k, 0, k] += S00
                    Z[1, k, 1, k] += S11
                    Z[0, k, 1, k] += S01
                    Z[1, k, 0, k] += S01
                # ---- bending geometric part Σ_v M_v ∂²κ_v
                for k in range(3):
                    m[k] = wq * (Mg[0] * h[q, 0, k] + Mg[1] * h[q, 1, k] + Mg[2] * h[q, 2, k])
                nq_ = n[q]
                mn = m[0] * nq_[0] + m[1] * nq_[1] + m[2] * nq_[2]
                sg = mn / (j * j)
                for k in range(3):
                    pm[k] = (m[k] - mn * nq_[k]) / j
                # ∂a3_i/∂u_bk = N_b,1 (e_k × a2)_i + N_b,2 (a1 × e_k)_i
                for k in range(3):
                    ek[:] = 0.0
                    ek[k] = 1.0
                    _cross(ek, a[q, 1], t)
                    E0[k] = t
                    _cross(a[q, 0], ek, t)
                    E1[k] = t
                for i3 in range(3):
                    for k in range(3):
                        ca3[i3, 0, k] = E0[k, i3]
                        ca3[i3, 1, k] = E1[k, i3]
                for k in range(3):
                    cAn[0, k] = E0[k, 0] * nq_[0] + E0[k, 1] * nq_[1] + E0[k, 2] * nq_[2]
                    cAn[1, k] = E1[k, 0] * nq_[0] + E1[k, 1] * nq_[1] + E1[k, 2] * nq_[2]
                    cAm[0, k] = (E0[k, 0] * m[0] + E0[k, 1] * m[1] + E0[k, 2] * m[2]) / (j * j)
                    cAm[1, k] = (E1[k, 0] * m[0] + E1[k, 1] * m[1] + E1[k, 2] * m[2]) / (j * j)
                # m · ∂²(a3/j) [∂a3, ∂a3]
                for i3 in range(3):
                    _outer_add(-sg, ca3[i3], ca3[i3], Z)
                _outer_add(3.0 * sg, cAn, cAn, Z)
                _outer_add(-1.0, cAm, cAn, Z)
                _outer_add(-1.0, cAn, cAm, Z)
                # (P m / j) · ∂²a3 = (N_b,1 N_c,2 − N_b,2 N_c,1) pm · (e_k × e_l)
                for kl in range(3):
                    k, l, i3 = kl, (kl + 1) % 3, (kl + 2) % 3
                    Z[0, k, 1, l] += pm[i3]
                    Z[0, l, 1, k] -= pm[i3]
                    Z[1, k, 0, l] -= pm[i3]
                    Z[1, l, 0, k] += pm[i3]
                # N_b,v M_v (∂n/∂u_cl)_k and its transpose, ∂n = (I − n n) ∂a3 / j
                for k in range(3):
                    for i3 in range(3):
                        Pm[k, i3] = ((1.0 if k == i3 else 0.0) - nq_[k] * nq_[i3]) / j
                for v in range(3):
                    mv = wq * Mg[v]
                    if mv == 0.0:
                        continue
                    for k in range(3):
                        for l in range(3):
                            x0 = mv * (Pm[k, 0] * E0[l, 0] + Pm[k, 1] * E0[l, 1] + Pm[k, 2] * E0[l, 2])
                            x1 = mv * (Pm[k, 0] * E1[l, 0] + Pm[k, 1] * E1[l, 1] + Pm[k, 2] * E1[l, 2])
                            Z[2 + v, k, 0, l] += x0
                            Z[2 + v, k, 1, l] += x1
                            Z[0, l, 2 + v, k] += x0
                            Z[1, l, 2 + v, k] += x1
                # ---- weighted: c_K K, where the bending material part c_K D joins the laws'
                # c_C d + c_M m on the warp and weft curvatures (one rank-one update per
                # non-zero entry of D: three where the law is diagonal)
                if cK != 1.0:
                    Z *= cK
                for v in range(3):
                    for x in range(3):
                        law = cK * D[e, q, v, x]
                        if v == x and v < 2:
                            law += cC * visc[0, v] + cM * visc[1, v]
                        if law != 0.0:
                            _outer_add(wq * law, cdk[v], cdk[x], Z)
                _half(Z, phi, Wrow)
                # ---- membrane material part: w_p ∂ε_pᵀ C_m Σ_q Q_pq ∂ε_q, as rows s = α
                CQde[:] = 0.0
                for v in range(3):
                    for x in range(3):
                        cvx = cK * wq * C_m[v, x]
                        if cvx == 0.0:
                            continue
                        for b in range(nb):
                            for k in range(3):
                                CQde[v, k, b] += cvx * Qde[q, x, b, k]
                for v in range(3):
                    for s in range(2):
                        for k in range(3):
                            c = cde[v, s, k]
                            if c == 0.0:
                                continue
                            for l in range(3):
                                for b in range(nb):
                                    Wrow[s, k, l, b] += c * CQde[v, l, b]
            # Jf[b, k, l, c]: the element matrix's entry (3 b + k, 3 c + l)
            Jf = np.dot(Phi, Wall.reshape(5 * nq, 9 * nb)).reshape(nb, 3, 3, nb)
            for b in range(nb):
                for k in range(3):
                    I = 3 * b + k
                    for c in range(nb):
                        for l in range(3):
                            x = Jf[b, k, l, c]
                            if symmetrize:
                                x = 0.5 * (x + Jf[c, l, k, b])
                            Jd[csr_map[e, I, 3 * c + l]] += x
