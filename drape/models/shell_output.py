"""What the shell reports: energies, fields per point and per cell, the deformed surface.

A part of :class:`drape.models.shell.KirchhoffLoveShell`.
"""
from __future__ import annotations

import numpy as np
from skfem import CellBasis, MeshTri

from drape.fem import shell_kernels as kernels
from drape.fem.argyris import interpolate
from drape.models.errors import ShellInputError

__all__ = ["ShellOutput"]


class ShellOutput:
    """Output of :class:`~drape.models.shell.KirchhoffLoveShell`."""

    def viscous_moments(self, u, v):
        """The laws' viscous moments ``d κ̇`` (warp, weft) at the quadrature points."""
        d = self._viscosity()[0]
        if not np.any(d):
            return np.zeros(self.w.shape + (2,))
        rate = np.empty(self.w.shape + (3,))
        kernels.use_threads(len(self.edofs))
        kernels.curvature_rate(self._element_values(u), self._element_values(v), self.dN, self.HN, rate)
        return d * rate[..., :2]

    def membrane_strain(self, eps):
        """``Q eps`` (e, q, ...), whose forces ``C_m Q eps`` the membrane carries: the
        assumed-strain operator of :func:`drape.fem.kinematics.assumed_strain_operator` when
        ``membrane_strain_degree`` is set, else ``eps`` itself."""
        if self.strain_projection is None:
            return eps
        return np.matmul(self.strain_projection, eps)   # (q, q) @ (e, q, 3), a BLAS call per triangle

    def qp_state(self, u):
        """Membrane strain and curvature (Voigt) at all quadrature points, (e, q, 3) each."""
        return self._kinematics(self._element_values(u))

    def quadrature_fields(self, u, v=None, a=None):
        """Curvatures, moments and friction moments at the quadrature points, (e, q) each.

        Tensor components (``curvature_xy`` = κ12, ``moment_xy`` = M12).
        """
        eps, kap = self.qp_state(u)
        eps = self.membrane_strain(eps)        # the strain whose forces are C_m eps
        out = {}
        M, Mf = self.moments(kap)[0], self.bending.friction_moment(kap)
        if self.rigidity is not None:
            Mf = self.rigidity[..., None] * Mf
        for name, i in (("xx", 0), ("yy", 1), ("xy", 2)):
            out[f"curvature_{name}"] = kap[..., i] * (0.5 if i == 2 else 1.0)
            out[f"moment_{name}"] = M[..., i]
            out[f"friction_moment_{name}"] = Mf[..., i]
        if self.rigidity is not None:
            out["rigidity_factor"] = self.rigidity
        out["membrane_strain_xx"] = eps[..., 0]
        out["membrane_strain_yy"] = eps[..., 1]
        out["membrane_strain_xy"] = 0.5 * eps[..., 2]
        return out

    def energies(self, u, v, t=None):
        """Energies [J]: kinetic, strain (membrane + elastic bending), external potential
        (dead loads: gravity and edge force; not the follower end moment), friction and
        damping work (Rayleigh and the law's d κ̇) dissipated so far, with contact the barrier's
        potential and the contact friction's work, and their total.

        ``t`` evaluates the dead loads' potential (default: :attr:`load_time`)."""
        eps, kap = self.qp_state(u)
        membrane = 0.5 * np.einsum("eqv,vw,eqw,eq->", eps, self.C_m, self.membrane_strain(eps), self.w)
        bend = float(np.sum(self.sheet_law.elastic_energy(kap) * self._bending_w))
        kinetic = 0.5 * float(v @ self.mass_products(v)[0])
        # potential of the dead loads (gravity, surface and edge force)
        t = self._t_last if t is None else t
        f_dead = self._dead_surface_force(t)
        if self.edge_load is not None:
            f_dead = f_dead + self._edge_force(t)
        ext = -float(self.load_scale * f_dead @ u)
        strain = float(membrane + bend)
        out = dict(kinetic=kinetic, strain=strain, membrane=float(membrane), bending=bend,
                   external_potential=ext, friction_work=self._friction_work,
                   damping_work=self._damping_work,
                   total=kinetic + strain + ext + self._friction_work + self._damping_work)
        contact = self._contact_energies(u)
        out.update(contact)
        out["total"] += sum(contact.values())
        return out

    def deformed_surface(self, u, refine: int = 2):
        """The deformed surface sampled inside every triangle, as a triangle soup.

        The vertices alone draw each curved Argyris triangle as its flat chord triangle;
        a fold crest between two vertices is lost, and how much is lost depends on the
        mesh. Sampling every triangle on the reference triangle refined ``refine`` times
        (4^refine sub-triangles) makes what is measured on it (a drape shadow) the
        solution's own.

        Returns
        -------
        points : ndarray, shape (E m, 3)
            Deformed positions (reference x, y, 0 plus displacement) of the m sample
            points of each of the E triangles.
        triangles : ndarray of int, shape (E 4^refine, 3)
        """
        if int(refine) < 0:
            raise ShellInputError(f"refine = {refine!r} must be >= 0")
        ref_tri = MeshTri.init_refdom().refined(int(refine))
        X, local = ref_tri.p, ref_tri.t.T
        sample = CellBasis(self.mesh, self.element, quadrature=(X, np.ones(X.shape[1])))
        ref = sample.mapping.F(X)                                      # (2, E, m)
        disp = np.stack([np.asarray(sample.interpolate(np.asarray(u)[k::3])) for k in range(3)])
        pos = np.concatenate([ref, np.zeros_like(ref[:1])]) + disp    # (3, E, m)
        E, m = pos.shape[1:]
        tris = (np.arange(E)[:, None, None] * m + local[None]).reshape(-1, 3)
        return pos.reshape(3, -1).T, tris

    def nodal_displacement(self, u):
        """Displacement 3-vector at the mesh vertices, shape (n_points, 3)."""
        return np.asarray(u)[3 * self.basis.nodal_dofs[0][:, None] + np.arange(3)]

    def fields(self, u, v=None, a=None):
        """Output data: ``{"point_data": {...}, "cell_data": {...}}``.

        Point data ``displacement`` (and ``velocity``) as (n_points, 3); cell data
        are dx-weighted averages of :meth:`quadrature_fields`.
        """
        q = self.quadrature_fields(u, v, a)
        area = self.w.sum(axis=1)
        cell = {k: np.einsum("eq,eq->e", x, self.w) / area for k, x in q.items()}
        point = {"displacement": self.nodal_displacement(u)}
        if v is not None:
            point["velocity"] = self.nodal_displacement(v)
        return {"point_data": point, "cell_data": cell}

    def interpolate(self, value, grad=None, hess=None):
        """Dof vector of a smooth displacement field given with its derivatives.

        Callables of points ``x`` (2, N) returning (3, N), (3, 2, N), (3, 2, 2, N).
        """
        u = np.zeros(self.ndofs)
        for k in range(3):
            def pick(f, k=k):
                return None if f is None else (lambda x: np.asarray(f(x))[k])
            u[k::3] = interpolate(self.basis, pick(value), pick(grad), pick(hess))
        return u
