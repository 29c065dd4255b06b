"""Compiled element kernels of the Kirchhoff–Love shell: kinematics, internal force, tangent.

The shell's residual and tangent are sums over triangles of quadrature-point terms
that only involve the element's displacement, the scalar basis gradients ``N_b,α``
and Voigt Hessians ``N_b,v`` (:mod:`drape.fem.kinematics`). Every first variation at a
point has the form

    δ[b, k] = Σ_s φ_s[b] c_s[k],      φ = (N_b,1, N_b,2, N_b,11, N_b,22, 2 N_b,12),

with a (5, 3) coefficient ``c`` (e.g. ``∂κ_v/∂u_bk = N_b,v n_k + N_b,1 (a2 × p_v)_k
+ N_b,2 (p_v × a1)_k``), and every term of the tangent the form
``Σ_st φ_s[b] φ_t[c] Z[s, k, t, l]``. A point's whole contribution to the 63 × 63 element
tangent is therefore a 15 × 15 block ``Z`` (stored (5, 3, 5, 3)) contracted twice with ``φ``:
once per point, then over all points of a triangle in one matrix product, a fraction of the
cost of dense rank updates of the per-dof variations. The per-point contraction runs
innermost over the element's basis functions, contiguous in memory, so that it vectorises
(13–19 % less time per tangent than with the sum over ``t`` innermost, BENCHMARKS.md);
the element matrix then comes out as ``Jf[b, k, l, c]`` and the scatter reads it in that
order. The laws' viscous and curvature-inertia matrices ``∫ ∂κᵀ d ∂κ`` have the same form
as the bending material term, so they join it as one rank-one update per curvature, and the
kernel assembles the one matrix a Newmark step factorises, ``c_K K + c_C C_law + c_M M_law``,
in that same product.

The kernels run in parallel over the triangles of one colour of a colouring in which no
two triangles of a colour share a dof, so each triangle scatters its tangent into the
CSR data of the fixed pattern (:class:`drape.fem.assembly.SparsityPattern`) through a
precomputed element-to-CSR map without write conflicts.

The bending laws stay outside: the kernels take the moments ``M``, their tangents
``D`` and the membrane forces at the quadrature points, which the caller evaluates
from :func:`kinematics`'s strain and curvature.

The kernels are compiled once per install and cached on disk (:mod:`drape.fem.compiled`). They run on
``NUMBA_NUM_THREADS`` threads (default: every core) on meshes of at least
:data:`PARALLEL_MIN_ELEMENTS` elements, on one below; set it to 1 where each core
already runs its own process.
"""
from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp
from numba import prange

from drape.fem.compiled import njit, thread_limit

__all__ = ['element_colours', 'use_threads', 'kinematics', 'curvature_rate', 'internal_force']



#: Below this many elements a kernel runs on one thread: waking the thread pool costs more than
#: the work it would share, and on a busy machine a thread waiting for a core stalls the call.
PARALLEL_MIN_ELEMENTS = 256


def use_threads(n_elements: int) -> None:
    """Let the next kernel calls of this thread use every numba thread, or one for a small mesh."""
    n = numba.config.NUMBA_NUM_THREADS if n_elements >= PARALLEL_MIN_ELEMENTS else 1
    numba.set_num_threads(min(n, thread_limit() or n))


def element_colours(element_dofs):
    """Greedy colouring of elements such that no two of a colour share a dof.

    Parameters
    ----------
    element_dofs : ndarray of int, shape (E, nb)

    Returns
    -------
    order : ndarray of int, shape (E,)
        Elements sorted by colour.
    start : ndarray of int, shape (n_colours + 1,)
        ``order[start[c]:start[c + 1]]`` are the elements of colour ``c``.

    Examples
    --------
    >>> order, start = element_colours(np.array([[0, 1], [1, 2], [3, 4]]))
    >>> [sorted(order[start[c]:start[c + 1]].tolist()) for c in range(len(start) - 1)]
    [[0, 2], [1]]
    """
    element_dofs = np.asarray(element_dofs)
    E = len(element_dofs)
    incidence = sp.csr_matrix((np.ones(element_dofs.size), element_dofs.ravel(),
                               np.arange(0, element_dofs.size + 1, element_dofs.shape[1])))
    adjacency = (incidence @ incidence.T).tocsr()
    colour = np.full(E, -1, dtype=np.int64)
    for e in range(E):
        taken = colour[adjacency.indices[adjacency.indptr[e]:adjacency.indptr[e + 1]]]
        free = np.ones(len(taken) + 1, dtype=bool)
        free[taken[(taken >= 0) & (taken < len(free))]] = False
        colour[e] = int(np.argmax(free))
    order = np.argsort(colour, kind="stable")
    start = np.searchsorted(colour[order], np.arange(colour.max() + 2))
    return order.astype(np.int64), start.astype(np.int64)


@njit(cache=True, inline="always")
def _cross(x, y, out):
    out[0] = x[1] * y[2] - x[2] * y[1]
    out[1] = x[2] * y[0] - x[0] * y[2]
    out[2] = x[0] * y[1] - x[1] * y[0]


@njit(cache=True)
def _point(dN, HN, ue, a, h, n):
    """Base vectors ``a`` (2, 3), Voigt ``u_,v`` + reference ``h`` (3, 3) and unit normal
    ``n`` at one point; returns the area stretch ``j``. ``a`` holds ``g_α = u_,α`` on
    return of the first loop and ``e_α + g_α`` at the end."""
    nb = dN.shape[0]
    a[:] = 0.0
    h[:] = 0.0
    for b in range(nb):
        for k in range(3):
            x = ue[b, k]
            a[0, k] += dN[b, 0] * x
            a[1, k] += dN[b, 1] * x
            h[0, k] += HN[b, 0] * x
            h[1, k] += HN[b, 1] * x
            h[2, k] += HN[b, 2] * x
    a[0, 0] += 1.0
    a[1, 1] += 1.0
    _cross(a[0], a[1], n)
    j = np.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
    for k in range(3):
        n[k] /= j
    return j


@njit(cache=True, parallel=True)
def kinematics(ue, dN, HN, strain, kappa):
    """Membrane strain and curvature (Voigt) at every quadrature point.

    Parameters
    ----------
    ue : (E, nb, 3) element displacement coefficients
    dN : (E, q, nb, 2), HN : (E, q, nb, 3) basis gradients and Voigt Hessians
    strain, kappa : (E, q, 3) outputs, ``(E11, E22, 2 E12)`` and ``(κ11, κ22, 2 κ12)``
    """
    E, nq = dN.shape[0], dN.shape[1]
    for e in prange(E):
        a = np.empty((2, 3))
        h = np.empty((3, 3))
        n = np.empty(3)
        for q in range(nq):
            _point(dN[e, q], HN[e, q], ue[e], a, h, n)
            # from g_α = a_α − e_α: no cancellation in a_α · a_α − 1
            g00, g11 = a[0, 0] - 1.0, a[1, 1] - 1.0
            gg00 = g00 * g00 + a[0, 1] ** 2 + a[0, 2] ** 2
            gg11 = a[1, 0] ** 2 + g11 * g11 + a[1, 2] ** 2
            gg01 = g00 * a[1, 0] + a[0, 1] * g11 + a[0, 2] * a[1, 2]
            strain[e, q, 0] = g00 + 0.5 * gg00
            strain[e, q, 1] = g11 + 0.5 * gg11
            strain[e, q, 2] = a[0, 1] + a[1, 0] + gg01
            for v in range(3):
                kappa[e, q, v] = h[v, 0] * n[0] + h[v, 1] * n[1] + h[v, 2] * n[2]


@njit(cache=True)
def _variations(a, h, n, j, cde, cdk, p, t):
    """Coefficients (5, 3) of ``∂ε_v`` and ``∂κ_v`` (v = 0..2) at a point, and
    ``p_v = (I − n n) h_v / j``; ``t`` is a 3-vector of scratch."""
    cde[:] = 0.0
    cdk[:] = 0.0
    for k in range(3):
        cde[0, 0, k] = a[0, k]
        cde[1, 1, k] = a[1, k]
        cde[2, 0, k] = a[1, k]
        cde[2, 1, k] = a[0, k]
    for v in range(3):
        hn = h[v, 0] * n[0] + h[v, 1] * n[1] + h[v, 2] * n[2]
        for k in range(3):
            p[v, k] = (h[v, k] - hn * n[k]) / j
        _cross(a[1], p[v], t)
        cdk[v, 0] = t
        _cross(p[v], a[0], t)
        cdk[v, 1] = t
        cdk[v, 2 + v] = n


@njit(cache=True)
def _phi(dN, HN, phi):
    for b in range(dN.shape[0]):
        phi[0, b] = dN[b, 0]
        phi[1, b] = dN[b, 1]
        phi[2, b] = HN[b, 0]
        phi[3, b] = HN[b, 1]
        phi[4, b] = HN[b, 2]


@njit(cache=True)
def _add_per_dof(scale, phi, c, out):
    """``out[b, k] += scale Σ_s φ_s[b] c_s[k]``: a (5, 3) coefficient as per-dof values."""
    for b in range(phi.shape[1]):
        for k in range(3):
            acc = 0.0
            for s in range(5):
                acc += phi[s, b] * c[s, k]
            out[b, k] += scale * acc


@njit(cache=True)
def _kappa_rate(dN, HN, x, a, h, n, j, ad, hd, a3d, nd, kdot):
    """Rates at a point of the field ``x`` (E-local coefficients (nb, 3)): ``ȧ_α`` into
    ``ad``, ``ḣ_v`` into ``hd``, ``ȧ3`` into ``a3d``, ``ṅ`` into ``nd`` and the curvature rate
    ``κ̇_v = ḣ_v · n + h_v · ṅ`` into ``kdot``; returns ``n · ȧ3``."""
    nb = dN.shape[0]
    ad[:] = 0.0
    hd[:] = 0.0
    for b in range(nb):
        for k in range(3):
            ad[0, k] += dN[b, 0] * x[b, k]
            ad[1, k] += dN[b, 1] * x[b, k]
            for v in range(3):
                hd[v, k] += HN[b, v] * x[b, k]
    # ȧ3 = ȧ1 × a2 + a1 × ȧ2, built in place from its two cross products
    a3d[0] = ad[0, 1] * a[1, 2] - ad[0, 2] * a[1, 1] + a[0, 1] * ad[1, 2] - a[0, 2] * ad[1, 1]
    a3d[1] = ad[0, 2] * a[1, 0] - ad[0, 0] * a[1, 2] + a[0, 2] * ad[1, 0] - a[0, 0] * ad[1, 2]
    a3d[2] = ad[0, 0] * a[1, 1] - ad[0, 1] * a[1, 0] + a[0, 0] * ad[1, 1] - a[0, 1] * ad[1, 0]
    na3 = n[0] * a3d[0] + n[1] * a3d[1] + n[2] * a3d[2]
    for k in range(3):
        nd[k] = (a3d[k] - na3 * n[k]) / j
    for v in range(3):
        kdot[v] = (hd[v, 0] * n[0] + hd[v, 1] * n[1] + hd[v, 2] * n[2]
                   + h[v, 0] * nd[0] + h[v, 1] * nd[1] + h[v, 2] * nd[2])
    return na3


@njit(cache=True, parallel=True)
def internal_force(ue, xe, dN, HN, w, Nm, M, c, fe):
    """Element internal forces ``∫ ∂εᵀ N + ∂κᵀ (M + c κ̇)``, (E, 3 nb) into ``fe``.

    ``Nm`` (E, q, 3) membrane forces, ``M`` (E, q, 3) moments (Voigt), ``c`` (2,) the
    coefficients (warp, weft) of the curvature rate of the element field ``xe`` (the laws'
    viscosity with the velocity; skipped where both are 0).
    """
    E, nq, nb = dN.shape[0], dN.shape[1], dN.shape[2]
    rates = c[0] != 0.0 or c[1] != 0.0
    for e in prange(E):
        a = np.empty((2, 3))
        h = np.empty((3, 3))
        n = np.empty(3)
        p = np.empty((3, 3))
        cde = np.empty((3, 5, 3))
        cdk = np.empty((3, 5, 3))
        F = np.empty((5, 3))
        phi = np.empty((5, nb))
        t = np.empty(3)
        work = np.empty((8, 3))
        Mq = np.empty(3)
        fe[e] = 0.0
        for q in range(nq):
            j = _point(dN[e, q], HN[e, q], ue[e], a, h, n)
            _variations(a, h, n, j, cde, cdk, p, t)
            _phi(dN[e, q], HN[e, q], phi)
            for v in range(3):
                Mq[v] = M[e, q, v]
            if rates:
                _kappa_rate(dN[e, q], HN[e, q], xe[e], a, h, n, j, work[0:2], work[2:5], work[5],
                            work[6], work[7])
                Mq[0] += c[0] * work[7, 0]
                Mq[1] += c[1] * work[7, 1]
            F[:] = 0.0
            for v in range(3):
                for s in range(5):
                    for k in range(3):
                        F[s, k] += Nm[e, q, v] * cde[v, s, k] + Mq[v] * cdk[v, s, k]
            _add_per_dof(w[e, q], phi, F, fe[e].reshape(nb, 3))



@njit(cache=True, parallel=True)
def curvature_rate(ue, xe, dN, HN, out):
    """Curvature rate ``κ̇ = ∂κ/∂u · ẋ`` (Voigt, (E, q, 3)) of the element rate ``xe``."""
    E, nq = dN.shape[0], dN.shape[1]
    for e in prange(E):
        a = np.empty((2, 3))
        h = np.empty((3, 3))
        n = np.empty(3)
        work = np.empty((7, 3))
        for q in range(nq):
            j = _point(dN[e, q], HN[e, q], ue[e], a, h, n)
            _kappa_rate(dN[e, q], HN[e, q], xe[e], a, h, n, j, work[0:2], work[2:5], work[5], work[6],
                        out[e, q])
