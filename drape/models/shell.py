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

from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import CellBasis

from constitutive.conventions import CURVATURE_SIGN
from constitutive.friction import restored_array
from constitutive.law import BendingLaw, check_friction_tangent
from constitutive.sheet import FRICTION_FRAMES, SheetLaw
from constitutive.units import G0
from drape.fem import shell_kernels as kernels
from drape.fem.argyris import ElementTriArgyrisLocal
from drape.fem.assembly import SparsityPattern
from drape.fem.boundary import argyris_element, clamped_dofs
from drape.fem.kinematics import assumed_strain_operator, basis_arrays
from drape.models.air import NormalDrag
from drape.models.errors import ShellInputError
from drape.models.loads import as_function
from drape.models.protocol import Evaluation, free_dofs
from drape.models.sheet_material import membrane_matrix, sheet_parts
from drape.models.shell_contact import ShellContact
from drape.models.shell_forces import ShellForces
from drape.models.shell_loads import ShellLoads
from drape.models.shell_output import ShellOutput

#: Newton tangents of the rate terms d κ̇ + m κ̈: the symmetric part of K, or the exact one.
VISCOUS_TANGENTS = ("symmetric", "full")

#: Private attributes :meth:`KirchhoffLoveShell.commit` keeps besides the laws' states.
_SHELL_STATE = ("t_last", "friction_work", "damping_work", "u_committed", "v_committed",
                "kappa_committed", "Md_committed")


def default_element(mesh=None, clamped=()):
    """Argyris element with element-local monomials and the node frames the clamps need.

    (:func:`drape.fem.boundary.argyris_element`; frames only where a clamped
    boundary is not parallel to the axes, e.g. the Cusick disc.)
    """
    if mesh is None or not clamped:
        return ElementTriArgyrisLocal()
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
        self._law = BendingLaw(k1=self.bending)

    # the interface of drape.models.sheet_material.sheet_parts: one linear law in both directions
    @property
    def warp(self) -> BendingLaw:
        return self._law

    @property
    def weft(self) -> BendingLaw:
        return self._law

    @property
    def twist_rigidity(self) -> float:
        return self.bending

    def membrane_stiffness(self):
        """Voigt membrane stiffness [N/m]: E h on the diagonal, shear E h / 2 (ν = 0)."""
        Eh = self.membrane
        return np.diag([Eh, Eh, Eh / 2.0])


class KirchhoffLoveShell(ShellForces, ShellLoads, ShellOutput, ShellContact):
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
    rigidity_factor : callable, optional
        ``x -> s(x)``: a factor on the sheet's bending moment (elastic and friction; not the
        laws' viscosity) at reference points ``x`` of shape (2, ...), positive, e.g. a
        specimen's non-uniform rigidity (:class:`drape.models.rigidity.RigidityVariation`).
        Taken at the quadrature points once. None: uniform.
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
                 bending_friction: str = "tensor", rigidity_factor: Optional[Callable] = None):
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
        parts = sheet_parts(material, ShellInputError)
        self.material = material
        self.rho_A = parts.areal_mass
        self.warp_law, self.weft_law = parts.warp, parts.weft
        self.twist = parts.twist
        self.sheet_law = SheetLaw(self.warp_law, self.weft_law, self.twist, bending_friction)
        self.C_m = membrane_matrix(material, ShellInputError)
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
        self.rigidity = self._rigidity(rigidity_factor)
        # what integrates the law's energies and friction work: the factor scales the moments
        self._bending_w = self.w if self.rigidity is None else self.w * self.rigidity
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
    def _rigidity(self, factor):
        """The bending moment's factor at the quadrature points, (E, Q), or None (uniform)."""
        if factor is None:
            return None
        s = np.asarray(factor(np.asarray(self.basis.global_coordinates())[:2]), dtype=float)
        if s.shape != self.w.shape or not np.all(np.isfinite(s) & (s > 0)):
            raise ShellInputError(f"rigidity_factor must give positive finite factors of shape "
                                  f"{self.w.shape} at the quadrature points")
        return s

    def _clamped_dofs(self, names):
        """Clamped dofs of all three components (drape.fem.boundary: u_nn left free, docs/theory.md §4)."""
        if not names:
            return np.zeros(0, dtype=np.int64)
        s = np.asarray(clamped_dofs(self.basis, names), dtype=np.int64)
        return np.sort((3 * s[:, None] + np.arange(3)).ravel())

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

    def mass_products(self, *xs):
        """``M x`` for every ``x``, as one product of ``M_s`` with all their components."""
        X = np.stack([np.reshape(x, (-1, 3)) for x in xs], axis=1)
        Y = (self._M_scalar @ X.reshape(len(X), -1)).reshape(X.shape)
        return [Y[:, i].ravel() for i in range(len(xs))]

    # --------------------------------------------------------------- physics

    # ------------------------------------------------------------- interface

    @property
    def symmetric_tangent(self) -> bool:
        """Symmetric tangents unless the law's viscosity or curvature inertia (their
        configuration dependence, with ``viscous_tangent = "full"``) or a follower end
        moment enter ``K``."""
        return not self._follower_moment() and (not np.any(self._viscosity()) or self._symmetrize_rates())

    def _symmetrize_rates(self) -> bool:
        """Keep the symmetric part of the rate terms' K: asked for, and it makes K symmetric
        (a follower end moment keeps it unsymmetric, and then the exact tangent is free)."""
        return self.viscous_tangent == "symmetric" and not self._follower_moment()

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
        ev = self._structural_evaluation(u, v, a, t, tangent, weights)
        return ev if self.contact is None else self._add_contact(ev, u, v, t, tangent, weights)

    def _structural_evaluation(self, u, v, a, t, tangent, weights):
        """:meth:`evaluate` without contact."""
        self._t_last = t
        u, v, a = (np.asarray(x, dtype=float) for x in (u, v, a))
        fe, Kl = self._edge_terms(u, t)
        lam = self.load_scale
        f_ext = lam * (self._dead_surface_force(t) + fe)
        Ma, Mv = self.mass_products(a, v)
        inertia = Ma + self._law_inertia(u, a)
        force = self.damping_force(v, Mv) + self._drag_force(u, v) - f_ext
        if tangent is None:
            return Evaluation(inertia, force + self.internal_forces(u, v)[0])
        if weights is not None:
            fint, Jd = self._weighted(u, v, a, weights, tangent, Kl)
            if fint is None:
                fint = self.internal_forces(u, v)[0]
            return Evaluation(inertia, force + fint, J=self.pattern.from_data(Jd))
        fint, Kd = self._weighted(u, v, a, (1.0, 0.0, 0.0), tangent, Kl)
        C, M = (self.pattern.from_data(self._weighted(u, v, a, w, tangent, Kl)[1])
                for w in ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
        return Evaluation(inertia, force + fint, self.pattern.from_data(Kd), C, M)

    def residual(self, u, v, a, t):
        """``R = M a + C v + f_int(u) − f_ext(u, t)`` and ``(K, C, M)`` (:meth:`evaluate` with
        the shell's friction tangent)."""
        ev = self.evaluate(u, v, a, t, self.friction_tangent)
        return ev.residual, ev.K, ev.C, ev.M

    def commit(self, u, v=None, a=None):
        """Accept the converged state: commit the friction states, book the dissipated work."""
        u = np.asarray(u, dtype=float)
        _, kappa = self.qp_state(u)
        dk = kappa[..., :2] - self._kappa_committed[..., :2]
        self._friction_work += float(np.sum(self.bending.friction_work(kappa) * self._bending_w))
        if v is not None:
            v = np.asarray(v, dtype=float)
            Md = self.viscous_moments(u, v)
            if self._v_committed is not None:
                du = u - self._u_committed
                vsum = v + self._v_committed
                self._damping_work += float(0.5 * self.damping_force(vsum, *self.mass_products(vsum)) @ du)
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
        self._commit_contact(u, v)
        self._u_committed = u.copy()
        self._kappa_committed = kappa

    def state_dict(self) -> dict:
        """What :meth:`commit` keeps, as named arrays: the law's state at every quadrature
        point (``bending.*``), the committed kinematics and moments the work booking
        starts from, the booked works, the load scale and the load time."""
        out = {f"bending.{k}": v for k, v in self.bending.state_dict().items()}
        out.update({k: np.array(getattr(self, f"_{k}"), dtype=float) for k in _SHELL_STATE})
        out.update(load_scale=np.array(self.load_scale, dtype=float))
        out.update(self._contact_state())
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
        self._load_contact_state(state)

    @property
    def load_time(self):
        """Time [s] of the last :meth:`residual` call; time-dependent loads are read at it."""
        return self._t_last

    def solve_linear(self, K, b):
        """Solve ``K x = b`` with the fixed dofs held at zero."""
        x = np.zeros(self.ndofs)
        free = free_dofs(self.ndofs, self.fixed_dofs)
        x[free] = spla.spsolve(sp.csc_matrix(K[free][:, free]), b[free])
        return x


