"""Small-deflection Kirchhoff plate of fabric with the hysteretic bending law (thesis ch. 5).

Scalar deflection ``w`` discretised with ``ElementTriMorley`` or an Argyris
element. Curvatures (docs/theory.md §1, face-up positive): ``κ_xx = w_,xx``, ``κ_yy = w_,yy``,
``κ_xy = w_,xy`` (tensor component). Bending energy density of the linear part
``½ B1 κ_xx² + ½ B2 κ_yy² + D_t κ_xy²``; the warp law (material.warp) acts on
``κ_xx``, the weft law on ``κ_yy`` and the twist is linear with rigidity
``D_t``. The cubic and friction parts enter through one
:class:`constitutive.law.BendingState` per direction holding every quadrature
point (shape ``(n_elements, n_qp)``); the law's ``d κ̇`` and ``m κ̈`` terms
are linear and become the matrices ``d ∫ B_dir B_dirᵀ`` (thesis 5.45) and
``m ∫ B_dir B_dirᵀ``.

The model implements the structural-model interface of ARCHITECTURE.md and
is driven by :mod:`drape.solvers.newmark`.

Examples
--------
A clamped-free strip of a linear fabric under its own weight (ν = 0 plate, so
the strip is an Euler–Bernoulli beam and the tip deflection is ρ_A g L⁴/(8B)):

>>> import numpy as np, skfem
>>> from drape.models.plate import KirchhoffPlate, demo_material
>>> mesh = skfem.MeshTri.init_tensor(np.linspace(0, 0.02, 17), np.linspace(0, 0.005, 5))
>>> mesh = mesh.with_boundaries({"clamped": lambda x: np.isclose(x[0], 0.0)})
>>> mat = demo_material(B=1e-5, areal_mass=0.2)
>>> plate = KirchhoffPlate(mesh, mat, supports={"clamped": "clamped"})
>>> from drape.solvers.static import quasi_static
>>> state = quasi_static(plate, [1.0])
>>> tip = state.u[plate.vertex_dofs][np.isclose(mesh.p[0], 0.02)].mean()
>>> exact = -0.2 * 9.80665 * 0.02**4 / (8 * 1e-5)        # 3.9 mm
>>> bool(abs(tip / exact - 1) < 0.01)
True
"""
from __future__ import annotations

import time
from typing import Callable, Mapping

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import skfem

from constitutive.conventions import CURVATURE_SIGN, twisting_moment
from constitutive.friction import restored_array
from constitutive.law import BendingLaw, check_friction_tangent
from constitutive.units import G0
from drape.fem.assembly import (
    SparsityPattern,
    at_quadrature,
    basis_hessians,
    basis_values,
    element_matrix,
    element_vector,
)
from drape.fem.boundary import plate_constraints, prescribed_values, pure_bending_rotations, straight_edge
from drape.models.errors import PlateInputError
from drape.models.loads import as_function
from drape.models.protocol import Evaluation, free_dofs
from drape.models.sheet_material import sheet_parts

__all__ = ["KirchhoffPlate", "PlateInputError", "pure_bending_rotations", "demo_material"]

SUPPORT_KINDS = ("clamped", "simply_supported", "free")
_DEFAULT_INTORDER = {"morley": 4, "argyris": 10}


def _make_element(element, constraints):
    """A fresh element instance (the Argyris element caches its inverse Vandermonde per instance).

    "argyris" is the element-local Argyris (:mod:`drape.fem.argyris`) with the node frames that
    the boundary conditions need (curved or tilted clamped edges, e.g. the Cusick disc).
    """
    if isinstance(element, skfem.Element):
        return element, ("argyris" if getattr(element, "maxdeg", 2) >= 5 else "morley")
    if element == "morley":
        return skfem.ElementTriMorley(), "morley"
    if element == "argyris":
        return constraints.element(), "argyris"
    raise PlateInputError(f"element must be 'morley' or 'argyris', got {element!r}")


def _coef(law, name: str) -> float:
    value = getattr(law, name, 0.0)
    return 0.0 if value is None else float(value)


class KirchhoffPlate:
    """Small-deflection orthotropic Kirchhoff plate with hysteretic bending.

    Parameters
    ----------
    mesh : skfem.MeshTri
        Reference mesh (x–y plane, metres) with named boundaries.
    material : FabricMaterial
        Provides ``areal_mass`` (kg/m²), ``warp`` and ``weft``
        (:class:`constitutive.law.BendingLaw`) and ``twist_rigidity`` (N·m).
    element : {"morley", "argyris"} or skfem.Element
        Plate element; "argyris" uses the element-local Argyris of :mod:`drape.fem.argyris`.
    supports : dict, optional
        ``{boundary_name: "clamped" | "simply_supported" | "free"}``.
    rotations : dict, optional
        ``{boundary_name: callable t -> slope}``: the edge is clamped and
        rotated rigidly so that its outward normal slope ``∂w/∂n`` equals the
        given value (radians, small). A callable returning
        ``(slope, rate, acceleration)`` also gives the exact rates
        (:meth:`lifting`). See :func:`pure_bending_rotations`.
    gravity : float, bool or callable
        Load factor λ(t) of the weight ``−λ ρ_A g`` (along −z).
    pressure : float or callable
        Extra uniform load q(t) in Pa, positive along +z.
    rayleigh : (float, float)
        ``(α, β)``: adds ``α M_ρ + β K0`` to the damping matrix, with ``M_ρ``
        the translational mass and ``K0`` the linear stiffness (k1 and twist).
    law_damping, law_inertia : bool
        Include the law's ``d κ̇`` (thesis 5.45) and ``m κ̈`` per direction.
    translational_inertia : bool
        Include ``ρ_A ∫ N Nᵀ``. ``False`` gives pure bending (KES strip).
    intorder : int, optional
        Quadrature order (default 4 for Morley, 10 for Argyris).
    friction_tangent : {"consistent", "nonnegative"}
        Newton's tangent of the friction moment (:meth:`constitutive.law.BendingState.trial`):
        ``"nonnegative"`` floors it at zero where a law softens (Fabric 2's weft); the
        residual, hence the solution, is unchanged.

    Attributes
    ----------
    load_scale : float
        Multiplies all external loads (set by :func:`drape.solvers.static.quasi_static`).
    rayleigh : (float, float)
        The damping ``(alpha, beta)`` as given.
    """

    def __init__(
        self,
        mesh,
        material,
        *,
        element="morley",
        supports: Mapping[str, str] | None = None,
        rotations: Mapping[str, Callable[[float], float]] | None = None,
        gravity=1.0,
        pressure=0.0,
        rayleigh=(0.0, 0.0),
        law_damping: bool = True,
        law_inertia: bool = True,
        translational_inertia: bool = True,
        intorder: int | None = None,
        friction_tangent: str = "consistent",
    ):
        self.mesh = mesh
        try:
            self.friction_tangent = check_friction_tangent(friction_tangent)
        except ValueError as exc:
            raise PlateInputError(str(exc)) from None
        supports, rotations = dict(supports or {}), dict(rotations or {})
        self._constraints = self._plate_constraints(supports, rotations)
        self.elem, self.kind = _make_element(element, self._constraints)
        self.areal_mass, self.warp, self.weft, self.twist_rigidity = sheet_parts(material, PlateInputError)
        self.material = material
        self._gravity = as_function(gravity, "gravity", PlateInputError)
        self._pressure = as_function(pressure, "pressure", PlateInputError)
        try:
            alpha, beta = (float(c) for c in rayleigh)
        except (TypeError, ValueError):
            raise PlateInputError(f"rayleigh must be a pair (alpha, beta), got {rayleigh!r}") from None
        if alpha < 0 or beta < 0:
            raise PlateInputError(f"rayleigh coefficients must be >= 0, got {(alpha, beta)}")
        self.rayleigh = (alpha, beta)
        self.load_scale = 1.0

        order = _DEFAULT_INTORDER[self.kind] if intorder is None else int(intorder)
        self.basis = skfem.Basis(mesh, self.elem, intorder=order)
        self.ndofs = self.basis.N
        self.pattern = SparsityPattern(self.basis.element_dofs, self.ndofs)
        self.vertex_dofs = self.basis.nodal_dofs[0]
        self._dx = self.basis.dx
        self._N = basis_values(self.basis)
        H = basis_hessians(self.basis)
        sign, nq = CURVATURE_SIGN, self._dx.shape[1]
        # both law directions in one batched contraction: (n_elements, 2 n_qp, n_basis); xx, yy are views
        self._B_dirs = sign * np.concatenate([H[0, 0], H[1, 1]], axis=1)
        self._B = {"xx": self._B_dirs[:, :nq], "yy": self._B_dirs[:, nq:], "xy": sign * H[0, 1]}
        del H
        self._dx_dirs = np.concatenate([self._dx, self._dx], axis=1)

        # linear matrices, once, all on the one sparsity pattern (the integrator adds their data arrays)
        pat = self.pattern
        unit = {d: pat.data(element_matrix(self._B[d], self._B[d], self._dx)) for d in ("xx", "yy")}
        twist = pat.data(element_matrix(self._B["xy"], self._B["xy"], self._dx)) * 2.0 * self.twist_rigidity
        mass = pat.data(element_matrix(self._N, self._N, self._dx)) * self.areal_mass
        self._twist_data = twist
        self.K_twist = pat.from_data(twist)
        k0 = _coef(self.warp, "k1") * unit["xx"] + _coef(self.weft, "k1") * unit["yy"] + twist
        self.K0 = pat.from_data(k0)
        m_data = mass if translational_inertia else np.zeros_like(mass)
        c_data = alpha * mass + beta * k0
        if law_inertia:
            m_data = m_data + _coef(self.warp, "m") * unit["xx"] + _coef(self.weft, "m") * unit["yy"]
        if law_damping:
            c_data = c_data + _coef(self.warp, "d") * unit["xx"] + _coef(self.weft, "d") * unit["yy"]
        self.M = pat.from_data(m_data)
        self.C = pat.from_data(c_data)
        self._f_unit = self.pattern.vector(element_vector(self._N, np.ones_like(self._dx), self._dx))

        shape = self._dx.shape
        self.states = {"xx": self.warp.new_state(shape), "yy": self.weft.new_state(shape)}
        self._laws = {"xx": self.warp, "yy": self.weft}
        self._committed = {"u": np.zeros(self.ndofs), "v": np.zeros(self.ndofs)}
        self.friction_work = 0.0
        self.damping_work = 0.0
        self._t_last = 0.0
        self.seconds = {"law": 0.0, "assembly": 0.0}

        self._setup_boundaries(supports, rotations)
        self._liftings = self._build_liftings()

    # ------------------------------------------------------------------ boundaries
    def _boundary_facets(self, name: str, key: str):
        boundaries = getattr(self.mesh, "boundaries", None) or {}
        if name not in boundaries:
            raise PlateInputError(
                f"{key}: boundary {name!r} is not a named boundary of the mesh (known: {sorted(boundaries)})"
            )
        return np.asarray(boundaries[name])

    def _plate_constraints(self, supports, rotations):
        """Validate the boundary conditions and work out their dofs (:mod:`drape.fem.boundary`)."""

        conditions = {}
        for name, kind in supports.items():
            if kind not in SUPPORT_KINDS:
                raise PlateInputError(f"supports[{name!r}] must be one of {SUPPORT_KINDS}, got {kind!r}")
            self._boundary_facets(name, f"supports[{name!r}]")
            conditions[name] = kind
        for name, slope in rotations.items():
            if not callable(slope):
                raise PlateInputError(f"rotations[{name!r}] must be a callable t -> slope")
            self._boundary_facets(name, f"rotations[{name!r}]")
            if conditions.get(name, "clamped") != "clamped":
                raise PlateInputError(f"rotations[{name!r}]: a rotated edge is clamped, but supports says {supports[name]!r}")
            conditions[name] = "clamped"
        try:
            return plate_constraints(self.mesh, conditions)
        except (ValueError, KeyError) as err:
            raise PlateInputError(f"supports/rotations: {err}") from None

    def _setup_boundaries(self, supports, rotations):

        pc = self._constraints
        held = [name for name, kind in supports.items() if kind != "free" and name not in rotations]
        fixed = pc.fixed_dofs(self.basis, names=held) if held else np.zeros(0, dtype=int)
        self._rotations = []
        for name, slope in rotations.items():
            edge = straight_edge(self.mesh, name, self._boundary_facets(name, f"rotations[{name!r}]"), PlateInputError)
            dofs = pc.fixed_dofs(self.basis, names=[name])
            n, x0 = edge.normal, edge.origin
            unit = prescribed_values(
                self.basis, dofs,
                lambda x, n=n, x0=x0: np.einsum("i,i...->...", n, x - x0[:, None]),
                lambda x, n=n: np.broadcast_to(n[:, None], (2, x.shape[1])),
            )
            self._rotations.append((edge, dofs, np.asarray(unit, dtype=float), slope))
        presc = np.concatenate([r[1] for r in self._rotations]) if self._rotations else np.zeros(0, dtype=int)
        if presc.size != np.unique(presc).size:
            raise PlateInputError("rotations: two rotated boundaries share dofs (a common corner)")
        self.fixed_dofs = np.setdiff1d(fixed, presc).astype(int)
        self._prescribed_dofs = presc.astype(int)

    def _slopes(self, t: float):
        """Slopes of the rotated edges at ``t`` and, if every callable gives them, their rates."""
        out = []
        for *_, slope in self._rotations:
            value = slope(t)
            out.append(tuple(float(x) for x in value) if np.ndim(value) else (float(value),))
        return out

    def prescribed(self, t: float):
        """Imposed edge rotations at time ``t`` as ``(dofs, values)``, or ``None``."""
        if not self._rotations:
            return None
        slopes = self._slopes(t)
        values = np.concatenate([rot[2] * s[0] for rot, s in zip(self._rotations, slopes)])
        return self._prescribed_dofs, values

    def _build_liftings(self):
        """Static extension of each rotated edge's unit motion into the free dofs (K0 solve)."""
        if not self._rotations:
            return None
        free = free_dofs(self.ndofs, self.fixed_dofs, self._prescribed_dofs)
        K = sp.csr_matrix(self.K0)
        Kff = K[free][:, free].tocsc()
        lifts = []
        for _, dofs, unit, _ in self._rotations:
            psi = np.zeros(self.ndofs)
            psi[dofs] = unit
            if free.size:
                psi[free] = spla.spsolve(Kff, -(K[free][:, dofs] @ unit))
            if not np.all(np.isfinite(psi)):
                return None
            lifts.append(psi)
        return lifts

    def lifting(self, t: float):
        """Imposed motion with exact rates, ``(u_p, v_p, a_p)``, or ``None``.

        Available when every rotation callable returns ``(slope, rate, acceleration)``.
        ``u_p = Σ_e θ_e(t) ψ_e`` with ``ψ_e`` the linear static response to a
        unit slope of edge ``e``; for a strip in pure bending it is exactly the
        uniform-curvature field, so the integrator's unknown ``u − u_p`` stays
        zero and the law's ``d κ̇``, ``m κ̈`` see the exact imposed rates.
        """
        if self._liftings is None:
            return None
        slopes = self._slopes(t)
        if any(len(s) != 3 for s in slopes):
            return None
        return tuple(sum(psi * s[k] for psi, s in zip(self._liftings, slopes)) for k in range(3))

    def edge_moment(self, R, name: str) -> float:
        """Bending moment per unit width transmitted through a rotated edge.

        ``R`` is the residual vector (reactions on the prescribed dofs). The
        moment is the generalized force conjugate to the edge's outward slope,
        divided by the edge length, with the sign of a moment producing positive
        curvature (``M = k1 κ`` for a linear strip in pure bending).
        """
        for edge, dofs, unit, _ in self._rotations:
            if edge.name == name:
                # the slope dofs carry s·κ (s = CURVATURE_SIGN), so their generalized force is s·M
                return CURVATURE_SIGN * float(R[dofs] @ unit) / edge.length
        raise PlateInputError(f"edge_moment: {name!r} is not a rotated boundary")

    # ------------------------------------------------------------------ physics
    def external_force(self, t: float) -> np.ndarray:
        """``f_ext(t) = load_scale (q(t) − λ(t) ρ_A g) ∫ N``."""
        q = self._pressure(t) - self._gravity(t) * self.areal_mass * G0
        return self.load_scale * q * self._f_unit

    def force_scale(self, t: float) -> float:
        """Typical force norm for the integrator's residual test: ``|f_ext(t)|`` at full load."""
        q = abs(self._pressure(t)) + abs(self._gravity(t)) * self.areal_mass * G0
        return float(q * np.linalg.norm(self._f_unit))

    def curvatures(self, u) -> dict:
        """Curvatures ``κ_xx, κ_yy, κ_xy`` at the quadrature points, each (n_elements, n_qp)."""
        ue = self.pattern.gather(u)
        return {d: at_quadrature(B, ue) for d, B in self._B.items()}

    symmetric_tangent = True   # bending, twist, Rayleigh damping and mass are all symmetric

    def evaluate(self, u, v, a, t: float, tangent: str | None = None, weights=None) -> Evaluation:
        """``M a`` and ``C v + f_int(u) − f_ext(t)``; with a friction ``tangent`` name also
        ``(K, C, M)`` (one CSR pattern), or with ``weights`` their sum ``J``."""
        self._t_last = float(t)
        t0 = time.perf_counter()
        ue = self.pattern.gather(u)
        nq = self._dx.shape[1]
        kappa = at_quadrature(self._B_dirs, ue)  # κ_xx and κ_yy stacked along the quadrature axis
        t1 = time.perf_counter()
        moment, dmoment = np.empty_like(kappa), np.empty_like(kappa)
        for j, d in enumerate(("xx", "yy")):
            sl = slice(j * nq, (j + 1) * nq)
            moment[:, sl], dmoment[:, sl] = self.states[d].trial(kappa[:, sl], tangent or self.friction_tangent)
        t2 = time.perf_counter()
        f_int = self.pattern.vector(element_vector(self._B_dirs, moment, self._dx_dirs)) + self.K_twist @ u
        force = self.C @ v + f_int - self.external_force(t)
        K = None
        if tangent is not None:
            K = self.pattern.matrix(element_matrix(self._B_dirs, self._B_dirs, self._dx_dirs, dmoment))
            K.data += self._twist_data
        self.seconds["law"] += t2 - t1
        self.seconds["assembly"] += time.perf_counter() - t2 + t1 - t0
        if K is None:
            return Evaluation(self.M @ a, force)
        return Evaluation(self.M @ a, force, K, self.C, self.M).weighted(weights)

    def residual(self, u, v, a, t: float):
        """``R = M a + C v + f_int(u) − f_ext(t)`` and its derivatives ``(K, C, M)`` w.r.t. u, v, a."""
        ev = self.evaluate(u, v, a, t, self.friction_tangent)
        return ev.residual, ev.K, ev.C, ev.M

    def commit(self, u, v, a) -> None:
        """Accept the converged step: commit the friction states and book the dissipated work."""
        kappa = self.curvatures(u)
        for d in ("xx", "yy"):
            self.friction_work += float(np.sum(self.states[d].friction_work(kappa[d]) * self._dx))
            self.states[d].commit(kappa[d])
        du = np.asarray(u) - self._committed["u"]
        vbar = 0.5 * (np.asarray(v) + self._committed["v"])
        # trapezoidal rule: Δu = Δt v̄ exactly, so this is Δt v̄ᵀ C v̄
        self.damping_work += float((self.C @ vbar) @ du)
        self._committed = {"u": np.array(u, dtype=float), "v": np.array(v, dtype=float)}

    def state_dict(self) -> dict:
        """What :meth:`commit` keeps, as named arrays: the laws' states at every quadrature
        point (``xx.*``, ``yy.*``), the committed ``u`` and ``v`` the work booking starts from,
        the booked works, the load scale and the load time."""
        out = {f"{d}.{k}": v for d in ("xx", "yy") for k, v in self.states[d].state_dict().items()}
        out.update({f"committed_{k}": v.copy() for k, v in self._committed.items()})
        out.update(friction_work=np.array(self.friction_work), damping_work=np.array(self.damping_work),
                   load_scale=np.array(self.load_scale, dtype=float), t_last=np.array(self._t_last))
        return out

    def load_state_dict(self, state: dict) -> None:
        """Restore a :meth:`state_dict` of a plate built from the same case."""
        for d in ("xx", "yy"):
            self.states[d].load_state_dict({k[3:]: v for k, v in state.items() if k.startswith(f"{d}.")})
        self._committed = {k: restored_array(f"plate state committed_{k}", state, f"committed_{k}",
                                             (self.ndofs,)) for k in ("u", "v")}
        scalar = {k: float(restored_array(f"plate state {k}", state, k, ()))
                  for k in ("friction_work", "damping_work", "load_scale", "t_last")}
        self.friction_work, self.damping_work = scalar["friction_work"], scalar["damping_work"]
        self.load_scale, self._t_last = scalar["load_scale"], scalar["t_last"]

    def strain_energy(self, u) -> float:
        """Elastic bending energy (cubic law per direction + linear twist); friction excluded."""
        kappa = self.curvatures(u)
        e = sum(np.sum(self._laws[d].elastic_energy(kappa[d]) * self._dx) for d in ("xx", "yy"))
        return float(e + 0.5 * u @ (self.K_twist @ u))

    @property
    def load_time(self) -> float:
        """Time [s] of the last :meth:`residual` call; time-dependent loads are read at it."""
        return self._t_last

    def nodal_displacement(self, u) -> np.ndarray:
        """Displacement 3-vectors ``(0, 0, w)`` at the mesh vertices, shape (n_points, 3)."""
        disp = np.zeros((self.mesh.p.shape[1], 3))
        disp[:, 2] = np.asarray(u)[self.vertex_dofs]
        return disp

    def energies(self, u, v, t: float | None = None) -> dict:
        """Kinetic, elastic, load potential and cumulative dissipated works (J).

        ``total`` = kinetic + strain + external_potential + friction_work +
        damping_work stays constant for a model without imposed motions
        (energy balance; exactly so for linear models under the trapezoidal rule).
        ``t`` evaluates time-dependent loads (default: the time of the last
        ``residual`` call); with loads that vary in time ``total`` is not conserved.
        """
        kinetic = 0.5 * float(v @ (self.M @ v))
        strain = self.strain_energy(u)
        potential = -float(self.external_force(self._t_last if t is None else t) @ u)
        out = dict(
            kinetic=kinetic,
            strain=strain,
            external_potential=potential,
            friction_work=self.friction_work,
            damping_work=self.damping_work,
        )
        out["total"] = kinetic + strain + potential + self.friction_work + self.damping_work
        return out

    def quadrature_fields(self, u, v, a) -> dict:
        """Curvatures, total moments (law + d κ̇ + m κ̈) and friction moments at the quadrature points."""
        kappa, rate, accel = self.curvatures(u), self.curvatures(v), self.curvatures(a)
        out = {}
        for d in ("xx", "yy"):
            law = self._laws[d]
            moment, _ = self.states[d].trial(kappa[d])
            out[f"curvature_{d}"] = kappa[d]
            out[f"moment_{d}"] = moment + _coef(law, "d") * rate[d] + _coef(law, "m") * accel[d]
            out[f"friction_moment_{d}"] = np.asarray(self.states[d].friction_moment(kappa[d]))
        out["curvature_xy"] = kappa["xy"]
        out["moment_xy"] = twisting_moment(self.twist_rigidity, kappa["xy"])
        return out

    def fields(self, u, v, a) -> dict:
        """Output fields: point data (displacement, velocity as 3-vectors) and cell averages."""
        disp, vel = self.nodal_displacement(u), self.nodal_displacement(v)
        area = self._dx.sum(axis=1)
        cells = {k: (f * self._dx).sum(axis=1) / area for k, f in self.quadrature_fields(u, v, a).items()}
        return {"point_data": {"displacement": disp, "velocity": vel}, "cell_data": cells}


def demo_material(B: float = 1e-5, areal_mass: float = 0.2, k3: float = 0.0, d: float = 0.0, m: float = 0.0,
                  friction=None, twist_rigidity: float | None = None):
    """A small isotropic :class:`constitutive.material.FabricMaterial` for examples (same law warp and weft).

    ``twist_rigidity`` defaults to ``B`` (the isotropic ν = 0 plate).
    """
    # not at the top: the material package reads material files (pydantic), the plate does not
    from constitutive.material import FabricMaterial

    law = BendingLaw(k1=B, k3=k3, d=d, m=m, friction=friction)
    return FabricMaterial(name="demo", areal_mass=areal_mass, thickness=None, warp=law, weft=law,
                          twist_rigidity=B if twist_rigidity is None else twist_rigidity)
