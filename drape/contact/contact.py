"""Incremental Potential Contact on the shell's dofs: barrier, lagged friction, safe steps.

Li et al. 2020, "Incremental Potential Contact", ACM Trans. Graph. 39(4) (SIGGRAPH), with the
IPC Toolkit (``ipctk``):

- the barrier potential ``B(x) = κ Σ_k b(d_k² − dmin², 2 dmin d̂ + d̂²)`` over the pairs
  (point–triangle, edge–edge, ...) closer than ``dmin + d̂``; ``dmin`` is half the fabric's
  thickness (the fabric's faces lie that far from its mid-surface, which the shell models),
  so the mid-surface never comes closer than ``dmin`` to a body;
- smoothed Coulomb friction ``D(v) = Σ_k μ_k λ_k f₀(‖T_kᵀ v‖)`` with the normal forces
  ``λ_k`` and tangent bases ``T_k`` lagged at the committed state (rebuilt at every commit),
  a function of the velocity: its gradient is a force like ``C v`` and its Hessian joins the
  velocity part of the step's tangent; below ``eps_v`` a contact sticks elastically;
- continuous collision detection: a Newton step is cut to 0.8 times the largest fraction of
  it that keeps every pair at least ``dmin`` apart, so no iterate passes through.

The fabric's collision vertices are the mesh vertices, or the sub-vertices of a finer
collision mesh (``[contact] subdivision``, :mod:`drape.fem.subdivision`); their positions are
the reference points plus a linear map of the dofs, ``x = X + P u``: a selection of the
vertex-value dofs (the Argyris value dof of each vertex, as in ``nodal_displacement``), or the
shell's field evaluated at the sub-vertices with the element basis. Forces on the dofs are
``Pᵀ g``, tangents ``Pᵀ H P`` (the Hessians projected or exact: :data:`PROJECTIONS`).
"""
from __future__ import annotations

import ipctk
import numpy as np
import scipy.sparse as sp

from drape.contact.bodies import ContactInputError, Scene
from drape.contact.containment import has_inside, inside, one_point_per_piece

__all__ = ["Contact", "CCD_FRACTION", "PROJECTIONS"]

#: Fraction of the step to the first touch that a line search may take (IPC's conservative
#: rescaling, applied by the narrow phase).
CCD_FRACTION = 0.8

#: ``hessian`` of :class:`Contact`: how the barrier's and the friction's Hessians enter the
#: tangent. IPC projects each pair's Hessian on the positive semi-definite cone because its
#: Newton minimises an energy and needs a descent direction; Newton here drives a residual to
#: zero and factorises an indefinite tangent (LDLᵀ), so it can take them exact. The projection
#: drops the negative part of ``κ b′(s) ∇²s`` (``s`` the squared distance), together with the
#: body vertices' rows it mixes in, and so overstates the barrier's stiffness: in a grip, where
#: the fabric is squeezed between two bodies, Newton then converges linearly, the residual
#: halving per iteration (docs/theory.md §7).
PROJECTIONS = {"projected": ipctk.PSDProjectionMethod.CLAMP, "exact": ipctk.PSDProjectionMethod.NONE}


def _coordinates(block):
    """A sparse block as (rows, cols, values) coordinates; empty for None."""
    if block is None:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    block = block.tocoo()
    return block.row.astype(np.int64), block.col.astype(np.int64), block.data


class Contact:
    """Contact of a fabric (its collision vertices) with the bodies of a scene, and with itself.

    Parameters
    ----------
    scene : drape.contact.bodies.Scene
    interpolation : ndarray of int, shape (n_fabric, 3), or sparse matrix (3 n_fabric, ndofs)
        How the fabric vertices (in the scene's order) move with the dofs: the dofs of the x,
        y, z displacement of every vertex, or the matrix ``P`` whose row ``3 k + i`` gives
        component i of vertex k's displacement as ``P u``.
    ndofs : int
        Size of the structural model's dof vector.
    dhat : float
        Barrier activation distance d̂ [m] beyond ``dmin``.
    stiffness : float
        Barrier stiffness κ [N/m³] (:func:`drape.contact.stiffness.barrier_stiffness`).
    thickness : float
        Fabric thickness [m]; ``dmin`` is half of it.
    eps_v : float
        Friction's stick velocity ε_v [m/s]: below it the friction force grows linearly.
    mu_self : float
        Friction coefficient of the fabric on itself (self-contact).
    hessian : {"projected", "exact"}
        The pairs' Hessians in the tangent projected on the positive semi-definite cone, as
        IPC does, or exact (:data:`PROJECTIONS`).
    """

    def __init__(self, scene: Scene, interpolation, ndofs: int, *, dhat: float, stiffness: float,
                 thickness: float = 0.0, eps_v: float = 1e-3, mu_self: float = 0.0,
                 hessian: str = "projected"):
        for name, value, low in (("dhat", dhat, 0.0), ("stiffness", stiffness, 0.0), ("eps_v", eps_v, 0.0)):
            if not (np.isfinite(value) and value > low):
                raise ContactInputError(f"contact.{name} = {value!r} must be > 0")
        if not (np.isfinite(thickness) and thickness >= 0):
            raise ContactInputError(f"contact.thickness = {thickness!r} must be >= 0")
        if not (np.isfinite(mu_self) and mu_self >= 0):
            raise ContactInputError(f"contact.mu_self = {mu_self!r} must be >= 0")
        if hessian not in PROJECTIONS:
            raise ContactInputError(f"contact.hessian = {hessian!r} must be one of {', '.join(PROJECTIONS)}")
        self._projection = PROJECTIONS[hessian]
        self.scene = scene
        self.ndofs = int(ndofs)
        self.P = self._interpolation(interpolation, scene.n_fabric, self.ndofs)
        self._Pt = self.P.T.tocsr()
        self._m = self.P.shape[0]
        self.dhat, self.dmin = float(dhat), 0.5 * float(thickness)
        self.kappa, self.mu_self = float(stiffness), float(mu_self)
        self.barrier = ipctk.BarrierPotential(self.dhat, self.kappa)
        self.friction = ipctk.FrictionPotential(float(eps_v))
        self._mu = np.array([b.mu for b in scene.bodies] + [self.mu_self])
        self._pattern = None
        # additive CCD (Li et al. 2021, codimensional IPC) keeps a minimum distance cheaply
        self._ccd = ipctk.AdditiveCCD(conservative_rescaling=CCD_FRACTION)
        self._u_lag = np.zeros((scene.n_fabric, 3))
        self._t_lag = 0.0
        self._friction_work = 0.0
        self._power = 0.0
        self._lag(self._u_lag, self._t_lag)

    @staticmethod
    def _interpolation(interpolation, n_fabric: int, ndofs: int):
        """``P`` as a CSR matrix (3 n_fabric, ndofs): given, or the selection of vertex dofs."""
        if sp.issparse(interpolation):
            P = sp.csr_matrix(interpolation, dtype=float)
        else:
            dofs = np.asarray(interpolation, dtype=np.int64).reshape(n_fabric, 3).ravel()
            P = sp.csr_matrix((np.ones(dofs.size), (np.arange(dofs.size), dofs)), shape=(dofs.size, ndofs))
        if P.shape != (3 * n_fabric, ndofs):
            raise ContactInputError(f"contact: the interpolation is {P.shape}, not (3 × {n_fabric} vertices, "
                                    f"{ndofs} dofs)")
        return P

    # ------------------------------------------------------------------ kinematics
    def fabric_values(self, u) -> np.ndarray:
        """The fabric vertices' (n_fabric, 3) share of a dof vector (``P u``)."""
        return (self.P @ np.asarray(u, dtype=float)).reshape(-1, 3)

    def positions(self, u, t: float) -> np.ndarray:
        """Positions of every collision vertex: the fabric at ``u``, the bodies at ``t``."""
        return self.scene.positions(self.fabric_values(u), t)

    def _collisions(self, x, t: float, which=None) -> ipctk.NormalCollisions:
        """The pairs closer than ``dmin + dhat`` at ``x`` (bodies at ``t``); ``which``: only
        those of the half-space with that index in the scene's bodies."""
        collisions = ipctk.NormalCollisions()
        if self.scene.per_point:   # weighting first: ipctk warns of the approximator without it
            collisions.use_area_weighting = True
            collisions.collision_set_type = ipctk.NormalCollisions.CollisionSetType.IMPROVED_MAX_APPROX
        if not self.scene.half_spaces:
            collisions.build(self.scene.mesh, x, self.dhat, self.dmin)
            return collisions
        candidates = ipctk.Candidates()
        if which is None:
            # boxes grown by half the reach on every side overlap for every pair within reach
            candidates.build(self.scene.mesh, x, 0.5 * (self.dhat + self.dmin))
        candidates.pv_candidates = self.scene.plane_candidates(x, t, self.dhat + self.dmin, which)
        collisions.build(candidates, self.scene.mesh, x, self.dhat, self.dmin)
        if self.scene.per_point and len(collisions.pv_collisions):
            # ipctk weighs a plane–vertex pair by the whole vertex area (4 here): one pair each
            planes = collisions.pv_collisions
            for pair in planes:
                pair.weight = 1.0
            collisions.pv_collisions = planes
        return collisions

    def collisions(self, u, t: float) -> ipctk.NormalCollisions:
        """The contact pairs (ipctk) of the fabric at ``u`` with the bodies at ``t``, and itself."""
        return self._collisions(self.positions(u, t), t)

    # ------------------------------------------------------------------ forces
    def forces(self, u, v, t: float, weights=None):
        """Contact force on the dofs and, with ``weights = (c_K, c_C)``, its tangent.

        Returns
        -------
        force : ndarray (ndofs,)
            ``Pᵀ (∇B(x) + ∇D(v))``: barrier and lagged friction, as a resisting force (the
            residual's sign, like ``f_int``).
        tangent : (rows, cols, values) or None
            ``c_K Pᵀ ∇²B P + c_C Pᵀ ∇²D P`` as coordinates in the dofs.
        """
        if weights is None:
            return self._terms(u, v, t, False, False)[0], None
        c_K, c_C = weights
        force, barrier, friction = self._terms(u, v, t, c_K != 0.0, c_C != 0.0)
        parts = [c * H for c, H in ((c_K, barrier), (c_C, friction)) if H is not None]
        return force, _coordinates(sum(parts[1:], parts[0]) if parts else None)

    def stiffness_and_damping(self, u, v, t: float):
        """Contact force and its two tangents apart, from one set of pairs: the barrier's
        ``Pᵀ ∇²B P`` (a stiffness) and the friction's ``Pᵀ ∇²D P`` (a damping, in velocity),
        each as coordinates in the dofs."""
        force, barrier, friction = self._terms(u, v, t, True, True)
        return force, _coordinates(barrier), _coordinates(friction)

    def _terms(self, u, v, t: float, barrier_tangent: bool, friction_tangent: bool):
        """The force, and the barrier's and the friction's fabric blocks (CSR; None when not
        asked for or without pairs)."""
        mesh = self.scene.mesh
        x = self.positions(u, t)
        collisions = self._collisions(x, t)
        force = np.zeros(self.ndofs)
        barrier = friction = None
        if len(collisions):
            force += self._Pt @ self.barrier.gradient(collisions, mesh, x)[:self._m]
            if barrier_tangent:
                barrier = self._fabric_block(self.barrier.hessian(collisions, mesh, x, self._projection))
        if not self._lagged.empty():
            w = self.scene.velocities(self.fabric_values(v), t)
            force += self._Pt @ self.friction.gradient(self._lagged, mesh, w)[:self._m]
            if friction_tangent:
                friction = self._fabric_block(self.friction.hessian(self._lagged, mesh, w, self._projection))
        return force, barrier, friction

    def _fabric_block(self, H):
        """``Pᵀ H P`` of the fabric vertices' block of a collision-mesh Hessian (bodies are
        prescribed)."""
        return (self._Pt @ sp.csr_matrix(H)[:self._m, :self._m] @ self.P).tocsr()

    def add_tangent(self, J, tangent):
        """``J`` (CSR) plus the coordinates ``tangent``: scattered into ``J``'s data when every
        entry is in its pattern (contact with bodies: a vertex with itself, a sub-vertex
        with its triangle's dofs), else a sparse sum (self-contact couples distant vertices)."""
        rows, cols, values = tangent
        if values.size == 0:
            return J
        if self._pattern is None or self._pattern[0] is not J.indptr:
            r = np.repeat(np.arange(J.shape[0], dtype=np.int64), np.diff(J.indptr))
            self._pattern = (J.indptr, r * J.shape[1] + J.indices)
        keys = self._pattern[1]
        wanted = rows * J.shape[1] + cols
        pos = np.minimum(np.searchsorted(keys, wanted), keys.size - 1)
        if np.array_equal(keys[pos], wanted):
            data = J.data + np.bincount(pos, weights=values, minlength=J.nnz)
            return sp.csr_matrix((data, J.indices, J.indptr), shape=J.shape)
        return (J + sp.csr_matrix((values, (rows, cols)), shape=J.shape)).tocsr()

    def body_forces(self, u, v, t: float) -> dict:
        """Force [N] the fabric exerts on each body (barrier and friction), by name."""
        x = self.positions(u, t)
        w = None if v is None else self.scene.velocities(self.fabric_values(v), t)
        g = self._gradient(self._collisions(x, t), self._lagged, x, w)
        owner = self.scene.body_of_vertex
        forces = {b.name: -g[owner == k].sum(axis=0) for k, b in self.scene.meshed}
        x_lag = self.scene.positions(self._u_lag, self._t_lag)
        for k, b in self.scene.half_spaces:
            # a half-space has no vertices: what pushes its pairs' fabric vertices pushes it back
            lagged = ipctk.TangentialCollisions()
            if b.mu > 0:
                lagged.build(self.scene.mesh, x_lag, self._collisions(x_lag, self._t_lag, k), self.barrier, b.mu)
            g = self._gradient(self._collisions(x, t, k), lagged, x, w)
            forces[b.name] = g[:self.scene.n_fabric].sum(axis=0)
        return forces

    def _gradient(self, collisions, lagged, x, w) -> np.ndarray:
        """Barrier gradient of ``collisions`` at ``x`` plus friction gradient of ``lagged`` at
        the velocities ``w`` (None: no friction), per collision vertex (n, 3)."""
        g = np.zeros(x.shape)
        if len(collisions):
            g += self.barrier.gradient(collisions, self.scene.mesh, x).reshape(-1, 3)
        if w is not None and not lagged.empty():
            g += self.friction.gradient(lagged, self.scene.mesh, w).reshape(-1, 3)
        return g

    def energy(self, u, t: float) -> float:
        """The barrier potential [J] at ``u``."""
        x = self.positions(u, t)
        collisions = self._collisions(x, t)
        return float(self.barrier(collisions, self.scene.mesh, x)) if len(collisions) else 0.0

    # ------------------------------------------------------------------ steps
    def max_step(self, u0, u1, t: float, t0: float | None = None) -> float:
        """Largest safe fraction in [0, 1] of the straight step from ``u0`` (bodies at ``t0``,
        default ``t``) to ``u1`` (bodies at ``t``): 1 when no pair comes closer than ``dmin``,
        else :data:`CCD_FRACTION` times the fraction at first touch (0 when not even the
        start is safe)."""
        t0 = t if t0 is None else t0
        x0, x1 = self.positions(u0, t0), self.positions(u1, t)
        alpha = min(1.0, float(ipctk.compute_collision_free_stepsize(self.scene.mesh, x0, x1, self.dmin, None,
                                                                     self._ccd)))
        if self.scene.half_spaces:
            # the planes move between t0 and t, which ipctk's static-plane CCD does not know
            touch = self.scene.plane_step(x0, t0, x1, t, self.dmin)
            if touch < 1.0:
                alpha = min(alpha, CCD_FRACTION * touch)
        return alpha

    def check_start(self, u, t: float = 0.0) -> None:
        """Refuse a start where the fabric intersects a body or itself, lies closer than
        ``dmin`` (half its thickness) to a body, or lies inside a closed body."""
        x = self.positions(u, t)
        if ipctk.has_intersections(self.scene.mesh, x):
            raise ContactInputError(f"contact: the fabric starts intersecting {self._intersected(x)}; "
                                    "move the body or the fabric apart")
        for _, b in self.scene.half_spaces:
            d = float(b.signed_distance(x[:self.scene.n_fabric], t).min())
            if d <= self.dmin:
                raise ContactInputError(f"contact: the fabric starts {d:.3g} m from the plane of body {b.name!r}, "
                                        f"{'behind it' if d < 0 else 'closer than half its thickness'} "
                                        f"({self.dmin:.3g} m); move them apart")
        collisions = self._collisions(x, t)
        if len(collisions):
            d = np.sqrt(max(collisions.compute_minimum_distance(self.scene.mesh, x), 0.0))
            if d <= self.dmin:
                raise ContactInputError(f"contact: the fabric starts {d:.3g} m from a body, closer than "
                                        f"half its thickness ({self.dmin:.3g} m); move them apart")
        self._check_outside(x)

    def _check_outside(self, x) -> None:
        """Refuse a fabric inside a closed body. It crosses no body's surface by now (checked
        first), so each of its pieces lies wholly inside or wholly outside each body: one point
        of each piece tells, by the body's winding number."""
        n = self.scene.n_fabric
        fabric_faces = self.scene.faces[np.all(self.scene.faces < n, axis=1)]
        probes = x[one_point_per_piece(n, fabric_faces)]
        for k, body in self.scene.meshed:
            own = x[self.scene.body_of_vertex == k]
            low, high = own.min(axis=0), own.max(axis=0)
            near = probes[np.all((probes >= low) & (probes <= high), axis=1)]
            if len(near) and has_inside(body.surface) and inside(own, body.surface.triangles, near).any():
                raise ContactInputError(f"contact.body[{k}] ({body.name!r}): the fabric starts inside this "
                                        f"closed body, and it must start outside every closed body; "
                                        f"move the body or the fabric")

    def _intersected(self, x) -> str:
        """Which body (or the fabric itself) the fabric intersects at ``x``, in words."""
        n = self.scene.n_fabric
        fabric = x[:n]
        for k, body in self.scene.meshed:
            fabric_faces = self.scene.faces[np.all(self.scene.faces < n, axis=1)]
            alone = Scene(self.scene.rest[:n], fabric_faces, [body])
            if ipctk.has_intersections(alone.mesh, np.vstack([fabric, x[n:][self.scene.body_of_vertex[n:] == k]])):
                return f"body {body.name!r}"
        return "itself"

    def set_stiffness(self, stiffness: float) -> None:
        """Change the barrier stiffness κ [N/m³]; the lagged friction's normal forces follow."""
        if not (np.isfinite(stiffness) and stiffness > 0):
            raise ContactInputError(f"contact.stiffness = {stiffness!r} must be > 0")
        self.kappa = float(stiffness)
        self.barrier = ipctk.BarrierPotential(self.dhat, self.kappa)
        self._lag(self._u_lag, self._t_lag)

    # ------------------------------------------------------------------ state
    def _lag(self, u_fabric, t: float) -> None:
        """Friction's lagged normal forces and tangent bases at a committed state, with each
        pair's μ: the body's for fabric–body pairs, ``mu_self`` for the fabric on itself."""
        mesh = self.scene.mesh
        x = self.scene.positions(u_fabric, t)
        self._lagged = ipctk.TangentialCollisions()
        collisions = self._collisions(x, t)
        if not len(collisions) or not np.any(self._mu > 0):
            return
        self._lagged.build(mesh, x, collisions, self.barrier, 0.0)
        owner = self.scene.body_of_vertex
        for i in range(len(self._lagged)):
            pair = self._lagged[i]
            if isinstance(pair, ipctk.PlaneVertexTangentialCollision):
                pair.mu_s = pair.mu_k = self._mu[self.scene.half_space_of(pair.plane, t)]
                continue
            ids = [j for j in pair.vertex_ids(mesh.edges, mesh.faces) if j >= 0]
            body = owner[ids].max()
            pair.mu_s = pair.mu_k = self._mu[body]   # body -1 (fabric alone): the last, mu_self
        self._lagged.reset_lagged_anisotropic_friction_coefficients()   # the μ the potential reads

    def _friction_power(self, v_fabric, t: float) -> float:
        if self._lagged.empty():
            return 0.0
        w = self.scene.velocities(v_fabric, t)
        return float(self.friction.gradient(self._lagged, self.scene.mesh, w) @ w.ravel())

    def commit(self, u, v, t: float) -> None:
        """A converged step: book the friction work (trapezoidal power over the step, under the
        step's lagged forces), then lag the friction at the new state."""
        uf = self.fabric_values(u)
        vf = None if v is None else self.fabric_values(v)
        if vf is not None:
            end = self._friction_power(vf, t)
            self._friction_work += 0.5 * (self._power + end) * (t - self._t_lag)
        self._u_lag, self._t_lag = uf, float(t)
        self._lag(uf, t)
        self._power = 0.0 if vf is None else self._friction_power(vf, t)

    @property
    def friction_work(self) -> float:
        """Work [J] dissipated by contact friction so far."""
        return self._friction_work

    def state_dict(self) -> dict:
        """What :meth:`commit` keeps: the lagged fabric positions and time, the booked work."""
        return {"contact.u_lag": self._u_lag.copy(), "contact.t_lag": np.array(self._t_lag),
                "contact.friction_work": np.array(self._friction_work),
                "contact.power": np.array(self._power)}

    def load_state_dict(self, state: dict) -> None:
        """Restore a :meth:`state_dict` (the lagged friction is rebuilt from it)."""
        try:
            u_lag = np.asarray(state["contact.u_lag"], dtype=float).reshape(self._u_lag.shape)
            t_lag = float(state["contact.t_lag"])
            work, power = float(state["contact.friction_work"]), float(state["contact.power"])
        except (KeyError, ValueError) as exc:
            raise ValueError(f"contact state: missing or misshapen entry ({exc})") from None
        self._u_lag, self._t_lag, self._friction_work, self._power = u_lag, t_lag, work, power
        self._lag(u_lag, t_lag)
