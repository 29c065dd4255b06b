"""Driving the shell's compiled kernels: strains, moments, internal force and step matrix.

A part of :class:`drape.models.shell.KirchhoffLoveShell`: the kernels of
:mod:`drape.fem.shell_kernels` evaluated on the shell's quadrature points, the bending state
(:class:`constitutive.sheet.SheetState`) asked for its moments and tangents.
"""
from __future__ import annotations

import time

import numpy as np

from constitutive.law import BendingLaw, check_friction_tangent
from constitutive.sheet import SheetLaw
from drape.fem import shell_kernels as kernels
from drape.fem import shell_tangent
from drape.fem.kinematics import KLPoint
from drape.models.errors import ShellInputError

__all__ = ["ShellForces"]


class ShellForces:
    """Internal forces and tangents of :class:`~drape.models.shell.KirchhoffLoveShell`."""

    def points(self, u, sl):
        """:class:`drape.fem.kinematics.KLPoint` of the elements ``sl`` (an independent,
        vectorised check of the compiled kernels)."""
        ue = u[self.edofs[sl]].reshape(-1, self.nb, 3)
        return KLPoint(self.dN[sl], self.HN[sl], ue)

    def _element_values(self, x):
        """Element coefficients (E, nb, 3) of a global dof vector."""
        return np.ascontiguousarray(np.asarray(x, dtype=float)[self.edofs].reshape(-1, self.nb, 3))

    def moments(self, kappa, elastic=False, friction_tangent=None):
        """Voigt moments (…, 3) and their tangents (…, 3, 3) from the law at Voigt curvature
        (``elastic``: the linear elastic law alone). The tangent is symmetrised where the
        solver factorises symmetrically: the residual, hence the solution, is unchanged."""
        if elastic:
            M, D = SheetLaw(BendingLaw(self.warp_law.k1), BendingLaw(self.weft_law.k1),
                            self.twist).elastic(kappa)
        else:
            mode = self.friction_tangent if friction_tangent is None else friction_tangent
            M, D = self.bending.trial(kappa, mode)
            if self.symmetric_tangent:
                D = 0.5 * (D + np.swapaxes(D, -1, -2))
        if self.rigidity is not None:
            M, D = self.rigidity[..., None] * M, self.rigidity[..., None, None] * D
        return M, D

    def _viscosity(self):
        """``[[d_warp, d_weft], [m_warp, m_weft]]``: the laws' viscosity and curvature inertia."""
        return self.sheet_law.viscosity

    def internal_forces(self, u, v=None, a=None, weights=None, elastic_tangent=False, *,
                  friction_tangent=None, base=None):
        """Internal force ``∫ ∂εᵀ N + ∂κᵀ (M + d κ̇)`` and, with ``weights``, the data of the
        weighted tangent on the cell pattern.

        Parameters
        ----------
        v, a : ndarray, optional
            Velocity (its curvature rate gives the laws' viscous moment ``d κ̇``, a force) and
            acceleration (its ``m κ̈`` enters the tangent only: it is inertia,
            :meth:`_law_inertia`). None: zero.
        weights : (c_K, c_C, c_M), optional
            Also return ``c_K K + c_C C_law + c_M M_law``: K the derivative of the force and of
            ``M_law a`` with respect to u, ``C_law``/``M_law`` the laws' viscous ``d ∫ ∂κᵀ∂κ``
            and curvature inertia ``m ∫ ∂κᵀ∂κ`` in the current configuration. None: the
            force only.
        friction_tangent : {"consistent", "nonnegative", "stick"}, optional
            Tangent of the friction moment passed to the laws' ``trial``; None: the
            shell's ``friction_tangent``.
        base : ndarray, optional
            CSR data the weighted tangent is added to, in place (default: zeros).

        Returns
        -------
        fint : ndarray; Jd : ndarray or None
        """
        if friction_tangent is not None:
            try:
                friction_tangent = check_friction_tangent(friction_tangent)
            except ValueError as exc:
                raise ShellInputError(str(exc)) from None
        ue, M, D, Nm = self._point_state(u, elastic_tangent, friction_tangent)
        t2 = time.perf_counter()
        fe = np.empty((len(ue), 3 * self.nb))
        visc = self._viscosity()
        Jd = None
        if weights is None:
            d = visc[0] if v is not None else np.zeros(2)
            ve = self._element_values(v) if np.any(d) else ue
            kernels.internal_force(ue, ve, self.dN, self.HN, self.w, Nm, np.ascontiguousarray(M), d, fe)
        else:
            ve = ue * 0.0 if v is None else self._element_values(v)
            ae = ue * 0.0 if a is None else self._element_values(a)
            Jd = self._tangent(ue, ve, ae, Nm, M, D, visc, weights, fe, base)
        fint = self.pattern.vector(fe)
        self.seconds["assembly"] += time.perf_counter() - t2
        return fint, Jd

    def _point_state(self, u, elastic, friction_tangent):
        """Element coefficients of ``u``, the laws' moments and tangents and the membrane
        forces at the quadrature points.

        The last result is kept: Newton's line search takes the force at the point where the
        next tangent is taken. It is reused while its inputs are the same objects: the same
        ``u``, tangent, laws and membrane, and the same committed states (every commit and
        restore gives a state a new curvature array, so a kept result never outlives one).
        """
        mode = (elastic, self.friction_tangent if friction_tangent is None else friction_tangent,
                float(self.twist))
        inputs = (self.sheet_law, self.bending, self.bending.kappa, self.C_m,
                  self.strain_projection)
        kept = self._kept_point
        if (kept is not None and kept[0] == mode and all(x is y for x, y in zip(kept[1], inputs))
                and np.array_equal(kept[2], u)):
            return kept[3]
        t0 = time.perf_counter()
        ue = self._element_values(u)
        eps, kappa = self._kinematics(ue)
        t1 = time.perf_counter()
        M, D = self.moments(kappa, elastic=elastic, friction_tangent=friction_tangent)
        t2 = time.perf_counter()
        point = (ue, M, D, self._membrane_force(eps))
        self._kept_point = (mode, inputs, np.array(u, dtype=float), point)
        self.seconds["law"] += t2 - t1
        self.seconds["assembly"] += time.perf_counter() - t2 + t1 - t0
        return point

    def _tangent(self, ue, ve, ae, Nm, M, D, visc, weights, fe, base=None):
        """Run the tangent kernel: element forces into ``fe``; the data of
        ``c_K K + c_C C_law + c_M M_law`` (added to ``base`` in place) returned."""
        Jd = np.zeros(self.pattern.nnz) if base is None else base
        Q = np.eye(self.w.shape[1]) if self.strain_projection is None else self.strain_projection
        order, start = self._colours
        kernels.use_threads(len(ue))
        shell_tangent.tangent(ue, ve, ae, self.dN, self.HN, self.w, np.ascontiguousarray(Q),
                        np.ascontiguousarray(self.C_m, dtype=float), np.ascontiguousarray(Nm),
                        np.ascontiguousarray(M), np.ascontiguousarray(D), visc,
                        np.asarray(weights, dtype=float), order, start, self._csr_map, fe, Jd,
                        bool(np.any(visc)) and self._symmetrize_rates())
        return Jd

    def _law_inertia(self, u, a):
        """The laws' curvature-inertia force ``M_law a = ∫ ∂κᵀ m κ̈`` (0.0 without it)."""
        m = self._viscosity()[1]
        if not np.any(m):
            return 0.0
        t0 = time.perf_counter()
        ue = self._element_values(u)
        zero = np.zeros(self.w.shape + (3,))
        fe = np.empty((len(ue), 3 * self.nb))
        kernels.use_threads(len(ue))
        kernels.internal_force(ue, self._element_values(a), self.dN, self.HN, self.w, zero, zero, m, fe)
        self.seconds["assembly"] += time.perf_counter() - t0
        return self.pattern.vector(fe)

    def _kinematics(self, ue):
        """Membrane strain and curvature (Voigt), (E, q, 3) each, of element coefficients."""
        eps, kappa = np.empty(self.w.shape + (3,)), np.empty(self.w.shape + (3,))
        kernels.use_threads(len(ue))
        kernels.kinematics(ue, self.dN, self.HN, eps, kappa)
        return eps, kappa

    def _membrane_force(self, eps):
        """Membrane forces ``C_m Q ε`` at the quadrature points, (E, q, 3)."""
        return np.ascontiguousarray(self.membrane_strain(eps) @ self.C_m.T)

    def linear_stiffness(self):
        """Tangent stiffness of the flat, unstressed state (membrane + elastic bending).

        At ``u = 0`` the strain variation is ``sym ∇u_in-plane`` and the curvature
        variation ``±∇∇u_z``; the geometric terms vanish.
        """
        ue = np.zeros((len(self.edofs), self.nb, 3))
        zero = np.zeros(self.w.shape + (3,))
        D = np.ascontiguousarray(self.moments(zero, elastic=True)[1])
        fe = np.empty((len(ue), 3 * self.nb))
        Kd = self._tangent(ue, ue, ue, zero, zero, D, np.zeros((2, 2)), (1.0, 0.0, 0.0), fe)
        return self.pattern.from_data(Kd)

    def _weighted(self, u, v, a, weights, tangent, Kl):
        """Internal force (None when the pass is skipped) and the data of
        ``c_K K + c_C C + c_M M``: the kernel's weighted tangent added to the constant part
        ``c_C (α M + β K0) + c_M M``. Without a K or law term no kernel runs."""
        cK, cC, cM = (float(c) for c in weights)
        alpha, beta = self.rayleigh
        base = (cC * alpha + cM) * self._M.data      # a new array, which the kernel adds to
        if cC * beta != 0.0:
            base += cC * beta * self._K0.data
        if cC != 0.0 and self.drag is not None:
            base += cC * self.pattern.data(self.drag.element_tangents(u, v))
        visc = self._viscosity()
        if cK == 0.0 and not np.any(cC * visc[0] + cM * visc[1]):
            return None, base
        fint, Jd = self.internal_forces(u, v, a, (cK, cC, cM), friction_tangent=tangent, base=base)
        if Kl is not None and cK != 0.0:
            Jd += cK * self.load_scale * Kl
        return fint, Jd

    def damping_force(self, v, Mv):
        """``C0 v = α M v + β K0 v`` from ``M v``."""
        alpha, beta = self.rayleigh
        f = alpha * Mv
        if beta != 0.0:
            f += beta * (self._K0 @ v)
        return f

    def _drag_force(self, u, v):
        """Still air's quadratic drag as it enters the residual, like ``C v`` (0 without it)."""
        if self.drag is None:
            return 0.0
        return self.pattern.vector(self.drag.element_forces(u, v))
