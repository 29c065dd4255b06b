"""Large-rotation Kirchhoff–Love fabric: total-Lagrangian plate on a flat reference.

The displacement ``u ∈ [Argyris]³`` (``skfem.ElementVector`` layout, global dof
``3 s + k`` for scalar dof ``s`` and component ``k``) carries the fabric from
the flat x–y reference to its deformed surface.  The strain energy per unit
reference area is

    W = ½ εᵀ C_m ε + W_b(κ11; warp law) + W_b(κ22; weft law) + D_t κ12²

with ``ε`` the Green–Lagrange membrane strain and ``κ_αβ = s u_,αβ · n`` the
curvature (:mod:`drape.fem.kinematics`; ``s`` = :data:`CURVATURE_SIGN`, the same
convention as the small-deflection plate), plus the dry friction of the bending law.
The moments come from the sheet's hysteretic law through ``SheetState.trial/commit``
at every quadrature point (:mod:`constitutive.sheet`): elastic per direction, linear
twist, and the friction on the curvature tensor (default) or per direction.  External loads: gravity ``−λ(t) ρ_A g e_z``,
a force per unit length on an edge and a follower end moment per unit width.

Force and tangent come from compiled per-element kernels (:mod:`drape.fem.shell_kernels`)
that work on the basis arrays and scatter straight into the CSR data of a precomputed
sparsity pattern (:class:`drape.fem.assembly.SparsityPattern`), not on per-basis-pair form
calls (docs/theory.md §4); K, C and M share one CSR pattern.

Examples
--------
A clamped unit strip under a small edge load, solved with plain Newton:

>>> import numpy as np
>>> from skfem import MeshTri
>>> from drape.models.shell import KirchhoffLoveShell, ElasticMaterial
>>> mesh = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 0.25, 2))
>>> mesh = mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9,
...                              "free": lambda x: x[0] > 1 - 1e-9})
>>> mat = ElasticMaterial(bending=1.0, membrane=1e3, areal_mass=1.0)
>>> shell = KirchhoffLoveShell(mesh, mat, gravity=0.0,
...                            edge_load=lambda t: np.array([0.0, 0.0, 1e-3]))
>>> u = np.zeros(shell.ndofs)
>>> for _ in range(3):
...     R, K, C, M = shell.residual(u, 0 * u, 0 * u, 1.0)
...     u += shell.solve_linear(K, -R)
>>> tip = shell.fields(u)["point_data"]["displacement"][:, 2].max()
>>> bool(abs(tip - 1e-3 / 3) < 1e-6)    # P L³ / (3 B) with P per unit width
True
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import CellBasis, FacetBasis, MeshTri

from constitutive.friction import restored_array
from constitutive.law import BendingLaw, check_friction_tangent
from constitutive.conventions import CURVATURE_SIGN
from constitutive.sheet import FRICTION_FRAMES, SheetLaw
from constitutive.units import G0
from drape.models.air import NormalDrag
from drape.fem.assembly import SparsityPattern
from drape.fem import shell_kernels as kernels
from drape.fem.kinematics import KLPoint, assumed_strain_operator, basis_arrays
from drape.models.loads import as_function
from drape.models.protocol import Evaluation, free_dofs

#: Newton tangents of the rate terms d κ̇ + m κ̈: the symmetric part of K, or the exact one.
VISCOUS_TANGENTS = ("symmetric", "full")

#: Private attributes :meth:`KirchhoffLoveShell.commit` keeps besides the laws' states.
_SHELL_STATE = ("t_last", "friction_work", "damping_work", "u_committed", "v_committed",
                "kappa_committed", "Md_committed")


class ShellInputError(ValueError):
    """Invalid input to the large-rotation shell model."""


def default_element(mesh=None, clamped=()):
    """Argyris element with element-local monomials and the node frames the clamps need.

    (:func:`drape.fem.boundary.argyris_element`; frames only where a clamped
    boundary is not parallel to the axes, e.g. the Cusick disc.)
    """
    if mesh is None or not clamped:
        from drape.fem.argyris import ElementTriArgyrisLocal
        return ElementTriArgyrisLocal()
    from drape.fem.boundary import argyris_element
    return argyris_element(mesh, {name: "clamped" for name in clamped})


@dataclass
class ElasticMaterial:
    """Isotropic linear-elastic stand-in material for verification problems.

    Parameters
    ----------
    bending : float
        Bending rigidity B [N·m], both directions; twist rigidity D_t = B
        (the isotropic ν = 0 plate: W = ½B(κ11² + κ22²) + B κ12²).
    membrane : float
        Membrane stiffness E h [N/m] (ν = 0, shear stiffness E h / 2).
    areal_mass : float
        ρ_A [kg/m²].
    """

    bending: float
    membrane: float
    areal_mass: float = 0.0

    def __post_init__(self):
        for name in ("bending", "membrane"):
            if not getattr(self, name) > 0:
                raise ShellInputError(f"ElasticMaterial.{name} must be > 0, got {getattr(self, name)}")
        if not self.areal_mass >= 0:
            raise ShellInputError(f"ElasticMaterial.areal_mass must be >= 0, got {self.areal_mass}")


def material_parts(material):
    """Extract what the shell needs from a material object.

    Returns
    -------
    dict with ``areal_mass`` [kg/m²], ``warp``/``weft`` laws, ``twist`` D_t [N·m]
    and ``membrane`` (3, 3) Voigt stiffness [N/m].
    """
    if isinstance(material, ElasticMaterial):
        Eh = material.membrane
        law = BendingLaw(k1=material.bending)
        return dict(areal_mass=material.areal_mass, warp=law, weft=law, twist=material.bending,
                    membrane=np.diag([Eh, Eh, Eh / 2.0]))
    try:
        warp, weft = material.warp, material.weft
        rho = float(material.areal_mass)
    except AttributeError as err:
        raise ShellInputError(f"material lacks {err}: need areal_mass, warp, weft") from None
    twist = getattr(material, "twist_rigidity", None)
    if twist is None:
        twist = np.sqrt(warp.k1 * weft.k1)
    return dict(areal_mass=rho, warp=warp, weft=weft, twist=float(twist),
                membrane=membrane_matrix(material))


def membrane_matrix(material):
    """Orthotropic plane-stress membrane stiffness (Voigt, N/m) of a material.

    Uses ``material.membrane_stiffness()`` if the material provides it, else the
    attributes ``E11, E22, nu12, G12`` (N/m; FabricMaterial), else the project default
    E1 = E2 = 1.0e4 N/m, ν12 = 0, G12 = 50 N/m (docs/theory.md §1).

    >>> membrane_matrix(object()).diagonal().tolist()
    [10000.0, 10000.0, 50.0]
    """
    if hasattr(material, "membrane_stiffness"):
        C = np.asarray(material.membrane_stiffness() if callable(material.membrane_stiffness)
                       else material.membrane_stiffness, dtype=float)
        if C.shape == (3, 3):
            return C
    def get(names, default):
        for n in names:
            value = getattr(material, n, None)
            if value is not None:
                return float(value)
        return default

    E1 = get(("E11", "E1"), 1.0e4)
    E2 = get(("E22", "E2"), 1.0e4)
    nu12 = get(("nu12",), 0.0)
    G12 = get(("G12",), 50.0)
    nu21 = nu12 * E2 / E1
    den = 1.0 - nu12 * nu21
    if den <= 0 or min(E1, E2, G12) <= 0:
        raise ShellInputError("membrane stiffness must be positive definite "
                              f"(E1={E1}, E2={E2}, nu12={nu12}, G12={G12})")
    return np.array([[E1 / den, nu21 * E1 / den, 0.0],
                     [nu12 * E2 / den, E2 / den, 0.0],
                     [0.0, 0.0, G12]])


class KirchhoffLoveShell:
    """Total-Lagrangian Kirchhoff–Love fabric with hysteretic bending.

    Parameters
    ----------
    mesh : skfem.MeshTri
        Flat reference configuration (x–y plane, metres).
    material : FabricMaterial or ElasticMaterial
        Areal mass, warp/weft bending laws, twist rigidity, membrane stiffness.
    clamped : sequence of str
        Boundary names whose edges are clamped.
    fixed_dofs : array_like, optional
        Explicit homogeneous Dirichlet dofs (replaces ``clamped``).
    element : skfem element, optional
        Scalar C¹ element (default: :func:`drape.fem.boundary.argyris_element` for the
        clamps, an :class:`drape.fem.argyris.ElementTriArgyrisLocal`).
    gravity : float or callable
        Load factor λ(t) on the self-weight ``−ρ_A g e_z``.
    edge_load : callable, optional
        ``t -> (3,)`` dead force per unit reference length [N/m] on ``load_boundary``.
    surface_load : (callable, float or callable), optional
        ``(traction, amplitude)``: a dead force per unit reference area
        ``amplitude(t) * traction(x)`` [N/m²], ``traction`` mapping points ``x`` of shape
        (2, ...) to (3, ...) (e.g. the transient fold perturbation of a Cusick drape,
        :meth:`drape.models.perturbation.FoldPerturbation.traction`).
    end_moment : callable or float, optional
        Follower moment per unit width [N] on ``load_boundary``; positive curls
        the edge towards +z (face-up).
    load_boundary : str
        Boundary name for the edge load and the end moment.
    rayleigh : (float, float)
        ``C = α M + β K0`` with ``K0`` the tangent of the undeformed state.
    drag_coefficient : float
        C_d of still air's quadratic drag normal to the surface (:class:`drape.models.air.NormalDrag`);
        0: none.
    intorder : int
        Degree of the quadrature rule (default 6, 12 points): the bending stiffness of the
        quintic Argyris basis on straight triangles, ``∫ ∇∇N · ∇∇N``, is a polynomial of
        degree 6, which this rule integrates exactly (the 7-point rule of degree 5 does
        not).
    g : float
        Gravitational acceleration [m/s²].
    membrane_strain_degree : int, optional
        Project the membrane strain on each triangle onto polynomials of this degree
        before it enters the energy (an assumed-strain remedy of membrane locking: a
        fabric's membrane is ~10⁹× stiffer than its bending, and the full quintic strain
        cannot vanish in the folds a coarse mesh must represent). None: the consistent
        strain.
    membrane_stabilization : float
        With ``membrane_strain_degree``: the weight γ ∈ [0, 1] kept on the part of the
        strain the projection removes (:func:`drape.fem.kinematics.assumed_strain_operator`);
        0.01–0.1 suppresses the spurious in-plane modes of degrees 0–2.
    bending_friction : {"tensor", "per_direction"}
        How the bending law's dry friction sees the curvature (:mod:`constitutive.sheet`):
        one frame-invariant law on the curvature tensor, or each direction's law on its own
        curvature with frictionless twist (square-symmetric; docs/theory.md §2).
    friction_tangent : {"consistent", "nonnegative"}
        Newton's tangent of the friction moment (:meth:`constitutive.law.BendingState.trial`):
        ``"nonnegative"`` floors it at zero where a law softens (Fabric 2's weft); the
        residual, hence the solution, is unchanged.
    viscous_tangent : {"symmetric", "full"}
        Newton's tangent of the rate terms ``d κ̇ + m κ̈``. Their dependence on the
        configuration (the curvature rate rotates with the surface) makes ``K``
        unsymmetric; ``"symmetric"`` keeps the symmetric part of each element's ``K``,
        so a symmetric factorisation serves (Fabric 1's Cusick drape spends half
        the time in linear solves); the residual is exact, hence the solution is
        unchanged, and the dropped part is of the order of the viscous moments against
        the elastic ones (that drape: 498 Newton iterations against 497,
        BENCHMARKS.md). ``"full"``: the exact derivative (quadratic convergence), also
        used under a follower end moment, whose tangent is unsymmetric anyway.
    """

    def __init__(self, mesh, material, *, clamped: Sequence[str] = ("clamped",),
                 fixed_dofs=None, element=None, gravity=1.0,
                 edge_load: Optional[Callable] = None, end_moment=None,
                 surface_load=None, load_boundary: str = "free", rayleigh=(0.0, 0.0), intorder: int = 6,
                 g: float = G0, membrane_strain_degree=None,
                 membrane_stabilization: float = 0.0, friction_tangent: str = "consistent",
                 viscous_tangent: str = "symmetric", drag_coefficient: float = 0.0,
                 bending_friction: str = "tensor"):
        self.mesh = mesh
        if bending_friction not in FRICTION_FRAMES:
            raise ShellInputError(f"bending_friction must be one of {FRICTION_FRAMES}, "
                                  f"got {bending_friction!r}")
        try:
            self.friction_tangent = check_friction_tangent(friction_tangent)
        except ValueError as exc:
            raise ShellInputError(str(exc)) from None
        if viscous_tangent not in VISCOUS_TANGENTS:
            raise ShellInputError(f"viscous_tangent must be one of {VISCOUS_TANGENTS}, "
                                  f"got {viscous_tangent!r}")
        self.viscous_tangent = viscous_tangent
        names = [clamped] if isinstance(clamped, str) else list(clamped)
        bnd = mesh.boundaries or {}
        for name in names:
            if name not in bnd:
                raise ShellInputError(f"clamped boundary '{name}' not in mesh.boundaries ({sorted(bnd)})")
        self.element = default_element(mesh, names) if element is None else element
        self.basis = CellBasis(mesh, self.element, intorder=intorder)
        parts = material_parts(material)
        self.material = material
        self.rho_A = parts["areal_mass"]
        self.warp_law, self.weft_law = parts["warp"], parts["weft"]
        self.twist = parts["twist"]
        self.sheet_law = SheetLaw(self.warp_law, self.weft_law, self.twist, bending_friction)
        self.C_m = parts["membrane"]
        self.g = float(g)
        self.gravity = as_function(gravity, "gravity", ShellInputError)
        self.edge_load = as_function(edge_load, "edge_load", ShellInputError)
        self.end_moment = as_function(end_moment, "end_moment", ShellInputError)
        if len(rayleigh) != 2 or min(rayleigh) < 0:
            raise ShellInputError(f"rayleigh must be (alpha >= 0, beta >= 0), got {rayleigh}")
        self.rayleigh = tuple(float(r) for r in rayleigh)

        self.strain_projection = None
        if membrane_strain_degree is not None:
            X, W = self.basis.quadrature
            self.strain_projection = assumed_strain_operator(X, W, int(membrane_strain_degree),
                                                             membrane_stabilization)
        self.dN, self.HN, self.N = basis_arrays(self.basis)
        # every curvature quantity is linear in HN: the sign convention is one factor
        self.HN *= CURVATURE_SIGN
        self.w = self.basis.dx
        sdofs = self.basis.element_dofs.T                   # (E, nb)
        self.nb = sdofs.shape[1]
        self.edofs = (3 * sdofs[:, :, None] + np.arange(3)).reshape(len(sdofs), -1)
        self.ndofs = 3 * self.basis.N
        self.pattern = SparsityPattern(self.edofs.T, self.ndofs)
        self._csr_map = self.pattern.element_positions()
        self._colours = kernels.element_colours(sdofs)
        self.drag = None
        if drag_coefficient:
            try:
                self.drag = NormalDrag(drag_coefficient, self.dN, self.N, self.w, self.edofs)
            except ValueError as exc:
                raise ShellInputError(str(exc)) from None

        if fixed_dofs is not None:
            self.fixed_dofs = np.unique(np.asarray(fixed_dofs, dtype=np.int64))
        else:
            self.fixed_dofs = self._clamped_dofs(names)

        self._state_shape = self.w.shape
        self.bending = self.sheet_law.new_state(self._state_shape)

        self._setup_edges(load_boundary)
        self._M, self._M_scalar = self._mass()
        weight = np.array([0.0, 0.0, -self.rho_A * self.g])
        self._f_gravity = self._surface_vector(lambda x: weight[:, None, None] * np.ones_like(x[0]))
        self._f_surface, self.surface_amplitude = None, None
        if surface_load is not None:
            traction, amplitude = surface_load
            self._f_surface = self._surface_vector(traction)
            self.surface_amplitude = as_function(amplitude, "surface_load amplitude", ShellInputError)
        zero = np.zeros(self.ndofs)
        self.load_scale = 1.0
        self._t_last = 0.0
        self.seconds = {"law": 0.0, "assembly": 0.0}
        self._K0 = self.linear_stiffness()
        self._friction_work = self._damping_work = 0.0
        self._kept_point = None     # the last point state (_point_state)
        self._u_committed, self._v_committed = zero.copy(), zero.copy()   # at rest
        self._kappa_committed = np.zeros(self.w.shape + (3,))
        self._Md_committed = np.zeros(self.w.shape + (2,))

    # ------------------------------------------------------------------ setup
    def _clamped_dofs(self, names):
        """Clamped dofs of all three components (drape.fem.boundary: u_nn left free, docs/theory.md §4)."""
        if not names:
            return np.zeros(0, dtype=np.int64)
        from drape.fem.boundary import clamped_dofs
        s = np.asarray(clamped_dofs(self.basis, names), dtype=np.int64)
        return np.sort((3 * s[:, None] + np.arange(3)).ravel())

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

    def _mass(self):
        """The mass ``M = M_s ⊗ I₃`` on the shared pattern (it joins the step matrix) and the
        scalar ``M_s`` (for products: the components do not couple, so ``M a`` is ``M_s``
        applied to the three components at once, reading a ninth of the stored entries)."""
        Me = np.einsum("eqb,eq,eqc->ebc", self.N, self.w, self.N, optimize=True) * self.rho_A
        Ke = np.einsum("ebc,kl->ebkcl", Me, np.eye(3))
        M = self.pattern.matrix(Ke.reshape(len(Me), 3 * self.nb, 3 * self.nb))
        M_scalar = SparsityPattern(self.edofs[:, 0::3].T // 3, self.ndofs // 3).matrix(Me)
        M_scalar.eliminate_zeros()
        return M, M_scalar

    def _mass_products(self, *xs):
        """``M x`` for every ``x``, as one product of ``M_s`` with all their components."""
        X = np.stack([np.reshape(x, (-1, 3)) for x in xs], axis=1)
        Y = (self._M_scalar @ X.reshape(len(X), -1)).reshape(X.shape)
        return [Y[:, i].ravel() for i in range(len(xs))]

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

    # --------------------------------------------------------------- physics
    def _points(self, u, sl):
        """:class:`drape.fem.kinematics.KLPoint` of the elements ``sl`` (an independent,
        vectorised check of the compiled kernels)."""
        ue = u[self.edofs[sl]].reshape(-1, self.nb, 3)
        return KLPoint(self.dN[sl], self.HN[sl], ue)

    def _element_values(self, x):
        """Element coefficients (E, nb, 3) of a global dof vector."""
        return np.ascontiguousarray(np.asarray(x, dtype=float)[self.edofs].reshape(-1, self.nb, 3))

    def _moments(self, kappa, elastic=False, friction_tangent=None):
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
        return M, D

    def _viscosity(self):
        """``[[d_warp, d_weft], [m_warp, m_weft]]``: the laws' viscosity and curvature inertia."""
        return self.sheet_law.viscosity

    def _internal(self, u, v=None, a=None, weights=None, elastic_tangent=False, *,
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
        M, D = self._moments(kappa, elastic=elastic, friction_tangent=friction_tangent)
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
        kernels.tangent(ue, ve, ae, self.dN, self.HN, self.w, np.ascontiguousarray(Q),
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
        return np.ascontiguousarray(self._membrane_strain(eps) @ self.C_m.T)

    def linear_stiffness(self):
        """Tangent stiffness of the flat, unstressed state (membrane + elastic bending).

        At ``u = 0`` the strain variation is ``sym ∇u_in-plane`` and the curvature
        variation ``±∇∇u_z``; the geometric terms vanish.
        """
        ue = np.zeros((len(self.edofs), self.nb, 3))
        zero = np.zeros(self.w.shape + (3,))
        D = np.ascontiguousarray(self._moments(zero, elastic=True)[1])
        fe = np.empty((len(ue), 3 * self.nb))
        Kd = self._tangent(ue, ue, ue, zero, zero, D, np.zeros((2, 2)), (1.0, 0.0, 0.0), fe)
        return self.pattern.from_data(Kd)

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

    # ------------------------------------------------------------- interface
    def prescribed(self, t):
        """No imposed motions: returns None."""
        return None

    def external_force(self, u, t):
        """External force ``f_ext(u, t)`` (gravity, edge load, end moment) × ``load_scale``."""
        fe, _ = self._edge_terms(u, t)
        return self.load_scale * (self._dead_surface_force(t) + fe)

    @property
    def symmetric_tangent(self) -> bool:
        """Symmetric tangents unless the law's viscosity or curvature inertia (their
        configuration dependence, with ``viscous_tangent = "full"``) or a follower end
        moment enter ``K``."""
        return not self._follower_moment() and (not np.any(self._viscosity()) or self._symmetrize_rates())

    def _follower_moment(self) -> bool:
        return self.edge is not None and self.end_moment is not None

    def _symmetrize_rates(self) -> bool:
        """Keep the symmetric part of the rate terms' K: asked for, and it makes K symmetric
        (a follower end moment keeps it unsymmetric, and then the exact tangent is free)."""
        return self.viscous_tangent == "symmetric" and not self._follower_moment()

    def lifting(self, t):
        """No imposed motion: None."""
        return None

    def evaluate(self, u, v, a, t, tangent=None, weights=None):
        """Forces ``M a`` and ``C v + f_int(u) − f_ext(u, t)`` at a state, and with a tangent name
        their derivatives.

        ``C = α M + β K0`` plus the law's viscous term ``d κ̇``; ``M`` includes the law's
        curvature inertia ``m κ̈``; both are linearised about the current configuration.

        Parameters
        ----------
        tangent : {"consistent", "nonnegative", "stick"}, optional
            Friction tangent of ``K``; None: forces only (no tangent is assembled).
        weights : (c_K, c_C, c_M), optional
            Return only ``J = c_K K + c_C C + c_M M``, assembled in one pass (what a Newmark
            step factorises); None: ``K``, ``C`` and ``M`` apart.

        Returns
        -------
        drape.models.protocol.Evaluation
            ``K`` (consistent, including the configuration dependence of the law's
            viscous and curvature-inertia terms), ``C`` and ``M`` on one CSR pattern, or ``J``.
        """
        self._t_last = t
        u, v, a = (np.asarray(x, dtype=float) for x in (u, v, a))
        fe, Kl = self._edge_terms(u, t)
        lam = self.load_scale
        f_ext = lam * (self._dead_surface_force(t) + fe)
        Ma, Mv = self._mass_products(a, v)
        inertia = Ma + self._law_inertia(u, a)
        force = self._damping_force(v, Mv) + self._drag_force(u, v) - f_ext
        if tangent is None:
            return Evaluation(inertia, force + self._internal(u, v)[0])
        if weights is not None:
            fint, Jd = self._weighted(u, v, a, weights, tangent, Kl)
            if fint is None:
                fint = self._internal(u, v)[0]
            return Evaluation(inertia, force + fint, J=self.pattern.from_data(Jd))
        fint, Kd = self._weighted(u, v, a, (1.0, 0.0, 0.0), tangent, Kl)
        C, M = (self.pattern.from_data(self._weighted(u, v, a, w, tangent, Kl)[1])
                for w in ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
        return Evaluation(inertia, force + fint, self.pattern.from_data(Kd), C, M)

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
        fint, Jd = self._internal(u, v, a, (cK, cC, cM), friction_tangent=tangent, base=base)
        if Kl is not None and cK != 0.0:
            Jd += cK * self.load_scale * Kl
        return fint, Jd

    def _damping_force(self, v, Mv):
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

    def residual(self, u, v, a, t):
        """``R = M a + C v + f_int(u) − f_ext(u, t)`` and ``(K, C, M)`` (:meth:`evaluate` with
        the shell's friction tangent)."""
        ev = self.evaluate(u, v, a, t, self.friction_tangent)
        return ev.residual, ev.K, ev.C, ev.M

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

    def commit(self, u, v=None, a=None):
        """Accept the converged state: commit the friction states, book the dissipated work."""
        u = np.asarray(u, dtype=float)
        _, kappa = self.qp_state(u)
        dk = kappa[..., :2] - self._kappa_committed[..., :2]
        self._friction_work += float(np.sum(self.bending.friction_work(kappa) * self.w))
        if v is not None:
            v = np.asarray(v, dtype=float)
            Md = self._viscous_moments(u, v)
            if self._v_committed is not None:
                du = u - self._u_committed
                vsum = v + self._v_committed
                self._damping_work += float(0.5 * self._damping_force(vsum, *self._mass_products(vsum)) @ du)
                if self.drag is not None:       # ∫ ½ (f_old + f_new) · Δu, as for C v
                    self._damping_work += float(0.5 * (
                        self._drag_force(u, v)
                        + self._drag_force(self._u_committed, self._v_committed)) @ du)
                # the law's own viscosity: ∫ ½ (d κ̇_old + d κ̇_new) Δκ
                self._damping_work += float(np.einsum(
                    "eqv,eq->", 0.5 * (Md + self._Md_committed) * dk, self.w))
            self._v_committed = v.copy()
            self._Md_committed = Md
        self.bending.commit(kappa)
        self._u_committed = u.copy()
        self._kappa_committed = kappa

    def state_dict(self) -> dict:
        """What :meth:`commit` keeps, as named arrays: the law's state at every quadrature
        point (``bending.*``), the committed kinematics and moments the work booking
        starts from, the booked works, the load scale and the load time."""
        out = {f"bending.{k}": v for k, v in self.bending.state_dict().items()}
        out.update({k: np.array(getattr(self, f"_{k}"), dtype=float) for k in _SHELL_STATE})
        out.update(load_scale=np.array(self.load_scale, dtype=float))
        return out

    def load_state_dict(self, state: dict) -> None:
        """Restore a :meth:`state_dict` of a shell built from the same case."""
        self.bending.load_state_dict({k[len("bending."):]: v for k, v in state.items()
                                      if k.startswith("bending.")})
        for key in _SHELL_STATE:
            shape = np.shape(getattr(self, f"_{key}"))
            value = restored_array(f"shell state {key}", state, key, shape)
            setattr(self, f"_{key}", value if shape else float(value))
        self.load_scale = float(restored_array("shell state load_scale", state, "load_scale", ()))

    def _viscous_moments(self, u, v):
        """The laws' viscous moments ``d κ̇`` (warp, weft) at the quadrature points."""
        d = self._viscosity()[0]
        if not np.any(d):
            return np.zeros(self.w.shape + (2,))
        rate = np.empty(self.w.shape + (3,))
        kernels.use_threads(len(self.edofs))
        kernels.curvature_rate(self._element_values(u), self._element_values(v), self.dN, self.HN, rate)
        return d * rate[..., :2]

    def _membrane_strain(self, eps):
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
        eps = self._membrane_strain(eps)        # the strain whose forces are C_m eps
        out = {}
        M, Mf = self.bending.trial(kap)[0], self.bending.friction_moment(kap)
        for name, i in (("xx", 0), ("yy", 1), ("xy", 2)):
            out[f"curvature_{name}"] = kap[..., i] * (0.5 if i == 2 else 1.0)
            out[f"moment_{name}"] = M[..., i]
            out[f"friction_moment_{name}"] = Mf[..., i]
        out["membrane_strain_xx"] = eps[..., 0]
        out["membrane_strain_yy"] = eps[..., 1]
        out["membrane_strain_xy"] = 0.5 * eps[..., 2]
        return out

    @property
    def load_time(self):
        """Time [s] of the last :meth:`residual` call; time-dependent loads are read at it."""
        return self._t_last

    def energies(self, u, v, t=None):
        """Energies [J]: kinetic, strain (membrane + elastic bending), external potential
        (dead loads: gravity and edge force; not the follower end moment), friction and
        damping work (Rayleigh and the law's d κ̇) dissipated so far, and their total.

        ``t`` evaluates the dead loads' potential (default: :attr:`load_time`)."""
        eps, kap = self.qp_state(u)
        membrane = 0.5 * np.einsum("eqv,vw,eqw,eq->", eps, self.C_m, self._membrane_strain(eps), self.w)
        bend = float(np.sum(self.sheet_law.elastic_energy(kap) * self.w))
        kinetic = 0.5 * float(v @ self._mass_products(v)[0])
        # potential of the dead loads (gravity, surface and edge force)
        t = self._t_last if t is None else t
        f_dead = self._dead_surface_force(t)
        if self.edge_load is not None:
            f_dead = f_dead + self._edge_force(t)
        ext = -float(self.load_scale * f_dead @ u)
        strain = float(membrane + bend)
        return dict(kinetic=kinetic, strain=strain, membrane=float(membrane), bending=bend,
                    external_potential=ext, friction_work=self._friction_work,
                    damping_work=self._damping_work,
                    total=kinetic + strain + ext + self._friction_work + self._damping_work)

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

    def solve_linear(self, K, b):
        """Solve ``K x = b`` with the fixed dofs held at zero."""
        x = np.zeros(self.ndofs)
        free = free_dofs(self.ndofs, self.fixed_dofs)
        x[free] = spla.spsolve(sp.csc_matrix(K[free][:, free]), b[free])
        return x

    def interpolate(self, value, grad=None, hess=None):
        """Dof vector of a smooth displacement field given with its derivatives.

        Callables of points ``x`` (2, N) returning (3, N), (3, 2, N), (3, 2, 2, N).
        """
        from drape.fem.argyris import interpolate
        u = np.zeros(self.ndofs)
        for k in range(3):
            def pick(f, k=k):
                return None if f is None else (lambda x: np.asarray(f(x))[k])
            u[k::3] = interpolate(self.basis, pick(value), pick(grad), pick(hess))
        return u

