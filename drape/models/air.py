"""Still air's drag on a moving fabric: quadratic in the speed, normal to the surface.

A plate moving broadside through still air at a speed v_n along its normal n is held back by
the pressure drag ``½ ρ_air C_d |v_n| v_n`` per unit area (C_d ≈ 1.2 for a flat plate
broadside; Hoerner, *Fluid-Dynamic Drag*, 1965); moving in its own plane it meets only the
skin friction, orders of magnitude less, which is left out. The force per unit reference area
on the fabric is ``f = −k |v·n| (v·n) n``, ``k = ½ ρ_air C_d``, with n the deformed surface's
unit normal. Unlike the linear drag ``[model.damping] air_drag`` it needs no reference speed:
a fold falling fast meets much drag, a creeping fabric almost none.
"""
from __future__ import annotations

import numpy as np

__all__ = ["AIR_DENSITY", "NormalDrag"]

AIR_DENSITY = 1.204
"""Density of dry air at 20 °C and 101.325 kPa [kg/m³]."""


class NormalDrag:
    """Quadratic normal drag on a Kirchhoff–Love surface discretised by a scalar C¹ basis.

    Parameters
    ----------
    drag_coefficient : float
        C_d of the fabric moving broadside (dimensionless).
    dN, N : ndarray
        Basis gradients (e, q, nb, 2) and values (e, q, nb) at the quadrature points
        (:func:`drape.fem.kinematics.basis_arrays`) of a mesh flat in the x-y plane.
    w : ndarray
        Quadrature weights times the reference area element, shape (e, q).
    edofs : ndarray
        Element dofs (e, 3 nb), components of each basis function together.
    air_density : float
        ρ_air [kg/m³].
    """

    def __init__(self, drag_coefficient: float, dN, N, w, edofs, air_density: float = AIR_DENSITY):
        if not drag_coefficient >= 0.0:
            raise ValueError(f"drag_coefficient must be >= 0, got {drag_coefficient!r}")
        self.k = 0.5 * float(air_density) * float(drag_coefficient)
        self.N, self.w, self.edofs = N, w, edofs
        e, q, nb, _ = dN.shape
        # (e, 2q, nb): rows N_b,α at each point, so that u,α of all points is one matmul
        self._dN_rows = np.ascontiguousarray(np.moveaxis(dN, 3, 2)).reshape(e, 2 * q, nb)

    def normal_velocity(self, u, v):
        """Unit normal ``n`` (e, q, 3) of the deformed surface and ``v·n`` (e, q)."""
        e, q, nb = self.N.shape
        ue = np.asarray(u)[self.edofs].reshape(e, nb, 3)
        ve = np.asarray(v)[self.edofs].reshape(e, nb, 3)
        tangents = np.matmul(self._dN_rows, ue).reshape(e, q, 2, 3)     # u,α
        tangents[..., 0, 0] += 1.0                                      # x,α = e_α + u,α
        tangents[..., 1, 1] += 1.0
        n = np.cross(tangents[..., 0, :], tangents[..., 1, :])
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        vn = np.sum(np.matmul(self.N, ve) * n, axis=-1)
        return n, vn

    def element_forces(self, u, v):
        """``−∫ N_b f`` per element, (e, 3 nb): the drag as it enters the residual
        (it resists the motion, like ``C v``)."""
        n, vn = self.normal_velocity(u, v)
        traction = (self.k * np.abs(vn) * vn * self.w)[..., None] * n              # (e, q, 3)
        return np.matmul(self.N.transpose(0, 2, 1), traction).reshape(len(n), -1)

    def element_tangents(self, u, v):
        """``∂(−∫ N f)/∂v`` per element, (e, 3 nb, 3 nb): ``∫ N_a N_b 2 k |v·n| n ⊗ n``.

        The turning of n with the configuration is left out of Newton's tangent (the
        residual keeps it): the drag is a small force whose direction changes slowly, and
        that part, ``N_a ∂n/∂u_b``, is unsymmetric, where this one keeps the shell's
        symmetric factorisation."""
        n, vn = self.normal_velocity(u, v)
        weight = 2.0 * self.k * np.abs(vn) * self.w
        e, q, nb = self.N.shape
        Nn = (self.N[..., :, None] * n[..., None, :]).reshape(e, q, 3 * nb)    # N_a n_c
        return np.matmul(Nn.transpose(0, 2, 1), Nn * weight[..., None])
