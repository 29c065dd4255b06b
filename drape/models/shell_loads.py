"""The shell's loads: self-weight, surface tractions, edge loads and end moments, imposed motion.

A part of :class:`drape.models.shell.KirchhoffLoveShell`; every load is a function of time
(:func:`drape.models.loads.as_function`).
"""
from __future__ import annotations

import numpy as np
from skfem import FacetBasis

from drape.fem.assembly import SparsityPattern
from drape.models.errors import ShellInputError

__all__ = ["ShellLoads"]


class ShellLoads:
    """External loads and prescribed motion of :class:`~drape.models.shell.KirchhoffLoveShell`."""

    def _setup_edges(self, name):
        self.edge = None
        if self.edge_load is None and self.end_moment is None:
            return
        bnd = self.mesh.boundaries or {}
        if name not in bnd:
            raise ShellInputError(f"load_boundary '{name}' not in mesh.boundaries ({sorted(bnd)})")
        fb = FacetBasis(self.mesh, self.element, facets=bnd[name],
                        intorder=8)
        fields = [fb.basis[i][0] for i in range(fb.Nbfun)]
        N = np.stack([np.asarray(f) for f in fields], axis=-1)             # (F, q, nb)
        dN = np.stack([np.moveaxis(f.grad, 0, -1) for f in fields], axis=-2)
        nu = np.moveaxis(fb.normals, 0, -1)                        # (F, q, 2)
        sd = fb.element_dofs.T
        self.edge = dict(N=N, dNn=np.einsum("fqba,fqa->fqb", dN, nu), nu=nu, w=fb.dx,
                         edofs=(3 * sd[:, :, None] + np.arange(3)).reshape(len(sd), -1))
        self.edge_pattern = SparsityPattern(self.edge["edofs"].T, self.ndofs)
        # edge element entries -> positions in the cell pattern's CSR data (edge dofs
        # are dofs of the adjacent cell, so every pair is in the cell pattern)
        p = self.pattern
        rows = np.repeat(np.arange(self.ndofs, dtype=np.int64), np.diff(p.indptr))
        keys = rows * self.ndofs + p.indices
        ed = self.edge["edofs"].astype(np.int64)
        ekeys = (ed[:, :, None] * self.ndofs + ed[:, None, :]).ravel()
        pos = np.searchsorted(keys, ekeys)
        assert np.array_equal(keys[pos], ekeys)
        self._edge_scatter = pos

    def _surface_vector(self, traction):
        """Load vector of a force per unit reference area ``traction(x) -> (3, E, q)``."""
        f = np.asarray(traction(np.asarray(self.basis.global_coordinates())), dtype=float)
        fe = np.einsum("ceq,eqb,eq->ebc", f, self.N, self.w)
        return self.pattern.vector(fe.reshape(len(fe), -1))

    def _dead_surface_force(self, t):
        """Gravity and the surface load at time ``t`` (without ``load_scale``)."""
        f = self.gravity(t) * self._f_gravity
        if self._f_surface is not None:
            f = f + self.surface_amplitude(t) * self._f_surface
        return f

    def _edge_terms(self, u, t):
        """External edge force vector and the follower-moment load stiffness."""
        if self.edge is None:
            return 0.0, None
        ed = self.edge
        F = len(ed["edofs"])
        nd = 3 * self.nb
        f = np.zeros((F, self.nb, 3))
        Kl = None
        if self.edge_load is not None:
            f += self._edge_force(t, local=True)
        if self.end_moment is not None:
            m = float(self.end_moment(t))
            ue = u[ed["edofs"]].reshape(F, self.nb, 3)
            anu = np.einsum("fqb,fbk->fqk", ed["dNn"], ue)
            nu3 = np.concatenate([ed["nu"], np.zeros(ed["nu"].shape[:-1] + (1,))], axis=-1)
            anu = anu + nu3
            s = anu[..., 2]
            c = np.einsum("fqk,fqk->fq", anu, nu3)
            r2 = s * s + c * c
            ez = np.zeros(3); ez[2] = 1.0
            # θ = atan2(s, c): rotation of the edge's material normal about the edge
            gvec = (c[..., None] * ez - s[..., None] * nu3) / r2[..., None]
            mw = m * ed["w"]
            f += np.einsum("fqb,fq,fqk->fbk", ed["dNn"], mw, gvec)
            tss = -2 * c * s / r2 ** 2
            tsc = (s * s - c * c) / r2 ** 2
            H = (tss[..., None, None] * (np.outer(ez, ez) - np.einsum("fqk,fql->fqkl", nu3, nu3))
                 + tsc[..., None, None] * (np.einsum("k,fql->fqkl", ez, nu3)
                                           + np.einsum("fqk,l->fqkl", nu3, ez)))
            Ke = np.einsum("fqb,fqc,fq,fqkl->fbkcl", ed["dNn"], ed["dNn"], mw, H,
                           optimize=True).reshape(F, nd, nd)
            Kl = -np.bincount(self._edge_scatter, weights=Ke.ravel(), minlength=self.pattern.nnz)
        return self.edge_pattern.vector(f.reshape(F, -1)), Kl

    def _edge_force(self, t, local=False):
        """Dead edge force: element-local (F, nb, 3) or global vector."""
        ed = self.edge
        q = np.asarray(self.edge_load(t), dtype=float).reshape(3)
        f = np.einsum("fqb,fq,k->fbk", ed["N"], ed["w"], q)
        return f if local else self.edge_pattern.vector(f.reshape(len(f), -1))

    def prescribed(self, t):
        """No imposed motions: returns None."""
        return None

    def external_force(self, u, t):
        """External force ``f_ext(u, t)`` (gravity, edge load, end moment) × ``load_scale``."""
        fe, _ = self._edge_terms(u, t)
        return self.load_scale * (self._dead_surface_force(t) + fe)

    def _follower_moment(self) -> bool:
        return self.edge is not None and self.end_moment is not None

    def lifting(self, t):
        """No imposed motion: None."""
        return None

    def force_scale(self, t):
        """Typical size of the external force (for relative residual tests): the full
        self-weight (independent of the gravity ramp), edge force and end moment."""
        scale = np.linalg.norm(self._f_gravity)
        if self.edge is not None:
            w = self.edge["w"].sum()
            if self.edge_load is not None:
                scale += np.linalg.norm(self.edge_load(t)) * w
            if self.end_moment is not None:
                scale += abs(float(self.end_moment(t))) * np.linalg.norm(
                    np.einsum("fqb,fq->fb", self.edge["dNn"], self.edge["w"]))
        return float(abs(self.load_scale) * scale)
