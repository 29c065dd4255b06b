"""Boundary-condition dofs on named boundaries for Morley and Argyris plates.

Conditions per named boundary (``mesh.boundaries``): ``"clamped"``,
``"simply_supported"`` or ``"free"``.

Morley (vertex values ``u``, edge normal slopes ``u_n``): clamped fixes both on
the boundary, simply supported fixes the vertex values.

Argyris (per vertex ``u, u_x, u_y, u_xx, u_xy, u_yy``, per edge ``u_n``).  With
``t`` the boundary tangent and ``n`` its normal at a boundary vertex:

* clamped (``u = ∂u/∂n = 0`` on the edge): ``u, ∇u`` and, because ``u`` and
  ``∂u/∂n`` vanish *along* the edge, ``u_tt = u_tn = 0``; the edge-midpoint
  slopes ``u_n`` are fixed too.  ``u_nn`` stays free — fixing it (i.e. all
  second derivatives) makes the plate ~2.5 % too stiff (docs/theory.md §4).
  At a clamped corner (two clamped edges turning by ``corner_angle`` or more)
  ``H t1 = H t2 = 0`` forces the whole Hessian to zero.
* simply supported (``u = 0`` on the edge): ``u`` and ``u_t``; on a straight
  edge also ``u_tt``; at a corner ``∇u`` and ``u_t1t1, u_t2t2``.  On a curved
  boundary (a polygon through nodes on a curve) ``u_tt = −κ u_n ≠ 0``, so it is
  left free there (fixing it reproduces the polygonal-plate paradox).
* free: nothing.

On a smooth curved boundary (e.g. the Cusick disc) the nodal frame ``(t, n)``
is not aligned with x, y; the vertex dofs there are re-combined into
``(u, u_t, u_n, u_tt, u_tn, u_nn)`` by giving the element *node frames*
(:func:`argyris_element`), so every condition is a plain dof fix and
``fixed_dofs`` stays an index array (ARCHITECTURE.md).  On edges parallel to
the axes no frame is needed and the dofs keep their Cartesian meaning.

Examples
--------
>>> from skfem import Basis
>>> from meshes import strip
>>> mesh = strip(0.1, 0.02, 4, 1)
>>> basis = Basis(mesh, argyris_element(mesh, {"clamped": "clamped"}))
>>> fixed = boundary_dofs(basis, {"clamped": "clamped", "free_end": "free"})
>>> len(fixed)            # 2 nodes x (u, u_x, u_y, u_yy, u_xy) + 1 edge slope
11
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
from numpy import ndarray
from skfem import ElementTriMorley, ElementVector
from skfem.element import ElementTriArgyris

from constitutive.conventions import CURVATURE_SIGN
from drape.fem.argyris import ElementTriArgyrisLocal, facet_normals, interpolate, same_mesh

__all__ = ["StraightEdge", "straight_edge", "pure_bending_rotations", "CONDITIONS", "PlateConstraints", "plate_constraints", "argyris_element",
           "boundary_dofs", "clamped_dofs", "rotation_dofs", "prescribed_values"]

CONDITIONS = ("clamped", "simply_supported", "free")
_ALIASES = {"simply-supported": "simply_supported", "simply supported": "simply_supported",
            "pinned": "simply_supported"}
_STRAIGHT = 1e-9        # turning angle (rad) below which two edges are collinear
_AXIS = 1e-12           # |n_x| or |n_y| below which a normal is axis-parallel


def _hessian_row(a: ndarray, b: ndarray) -> ndarray:
    """Weights on (u_xx, u_xy, u_yy) of the functional ``aᵀ H b``."""
    return np.array([a[0] * b[0], a[0] * b[1] + a[1] * b[0], a[1] * b[1]])


def _frame(g1, g2, h1, h2, h3) -> ndarray:
    """6×6 dof re-combination: value, gradient rows g1, g2, Hessian rows h*."""
    M = np.zeros((6, 6))
    M[0, 0] = 1.0
    M[1, 1:3], M[2, 1:3] = g1, g2
    M[3, 3:], M[4, 3:], M[5, 3:] = h1, h2, h3
    return M


def _tn_slots(n: ndarray):
    """Frame for the tangent/normal pair ``(t, n)``: (M or None, slots dict)."""
    t = np.array([-n[1], n[0]])
    if abs(n[0]) < _AXIS:        # edge along x: t = ±e_x
        return None, dict(t=1, n=2, tt=3, tn=4, nn=5)
    if abs(n[1]) < _AXIS:        # edge along y
        return None, dict(t=2, n=1, tt=5, tn=4, nn=3)
    M = _frame(t, n, _hessian_row(t, t), _hessian_row(t, n), _hessian_row(n, n))
    return M, dict(t=1, n=2, tt=3, tn=4, nn=5)


@dataclass
class PlateConstraints:
    """Node frames and constrained slots of the Argyris / Morley dofs of a mesh.

    Build with :func:`plate_constraints`.  ``node_slots[k]`` lists the local
    vertex dof slots (0..5 = u, u_x, u_y, u_xx, u_xy, u_yy, re-combined where
    ``k`` has a frame) fixed at node ``nodes[k]``; ``facets`` are the edges
    whose midpoint slope ``u_n`` is fixed (clamped boundaries); ``frames`` the
    6×6 dof re-combinations at ``frame_nodes``; ``by_boundary[name]`` holds
    ``(nodes, slots, clamped facets, Morley value nodes)`` per named boundary.
    """

    mesh: object
    conditions: dict
    nodes: ndarray
    node_slots: list
    frame_nodes: ndarray
    frames: ndarray
    facets: ndarray
    by_boundary: dict

    @property
    def node_frames(self):
        """``(mesh, nodes, M)`` for :class:`ElementTriArgyrisLocal`, or None."""
        if len(self.frame_nodes) == 0:
            return None
        return (self.mesh, self.frame_nodes, self.frames)

    def element(self) -> ElementTriArgyrisLocal:
        """An Argyris element whose vertex dofs follow the boundary frames."""
        return ElementTriArgyrisLocal(node_frames=self.node_frames)

    def fixed_dofs(self, basis, components=None, names=None) -> ndarray:
        """Global dofs fixed by the conditions (optionally only ``names``)."""
        _check_basis(self, basis)
        names = list(self.conditions) if names is None else list(names)
        out = [self._dofs_of(basis, name, components) for name in names]
        return np.unique(np.concatenate(out)) if out else np.zeros(0, dtype=np.int64)

    def _dofs_of(self, basis, name, components):
        if name not in self.by_boundary:
            raise KeyError(f"boundary '{name}' has no condition (have: {sorted(self.by_boundary)})")
        nodes, slots, facets, morley_nodes = self.by_boundary[name]
        elem = basis.elem
        ncomp = elem.dim if isinstance(elem, ElementVector) else 1
        comps = range(ncomp) if components is None else list(components)
        base = elem.elem if isinstance(elem, ElementVector) else elem
        out = []
        for c in comps:
            if not 0 <= c < ncomp:
                raise ValueError(f"component {c} out of range 0..{ncomp - 1}")
            if isinstance(base, ElementTriMorley):
                out.append(basis.nodal_dofs[c, morley_nodes])
            else:
                for node, sl in zip(nodes, slots):
                    out.append(basis.nodal_dofs[np.asarray(sl, dtype=np.int64) * ncomp + c, node])
            out.append(basis.facet_dofs[c, facets])
        return np.concatenate(out).astype(np.int64) if out else np.zeros(0, dtype=np.int64)


def _normalise(conditions: Mapping[str, str], mesh) -> dict:
    known = dict(mesh.boundaries or {})
    out = {}
    for name, kind in conditions.items():
        kind = _ALIASES.get(str(kind).lower(), str(kind).lower())
        if kind not in CONDITIONS:
            raise ValueError(f"boundary '{name}': condition {kind!r} is not one of {CONDITIONS}")
        if name not in known:
            raise ValueError(f"boundary '{name}' is not a named boundary of the mesh "
                             f"(have: {', '.join(sorted(known)) or 'none'})")
        if len(known[name]) == 0:
            raise ValueError(f"boundary '{name}' is empty")
        out[name] = kind
    return out


def plate_constraints(mesh, conditions: Mapping[str, str],
                      corner_angle: float = 30.0) -> PlateConstraints:
    """Work out frames and fixed dof slots for named-boundary conditions.

    Parameters
    ----------
    mesh
        :class:`skfem.MeshTri` with named boundaries.
    conditions
        ``{boundary name: "clamped" | "simply_supported" | "free"}``.
    corner_angle
        Degrees: where two constrained boundary edges meet at a node with
        normals turning by this much or more, the node is a corner; below it a
        smooth (possibly curved) boundary.

    Examples
    --------
    >>> from meshes import cusick_annulus
    >>> mesh = cusick_annulus(n_radial=2, n_circumferential=16)
    >>> pc = plate_constraints(mesh, {"disc": "clamped", "hem": "free"})
    >>> len(pc.frame_nodes)            # disc nodes off the axes need a frame
    12
    """
    conditions = _normalise(conditions, mesh)
    normals = facet_normals(mesh)
    constrained = {n: k for n, k in conditions.items() if k != "free"}
    # incident constrained edges per node: (facet, kind)
    incident: dict[int, list] = {}
    for name, kind in constrained.items():
        for f in np.asarray(mesh.boundaries[name]):
            for v in mesh.facets[:, f]:
                incident.setdefault(int(v), []).append((int(f), kind))
    node_ids, node_slots, frame_nodes, frames = [], [], [], []
    slots_of = {}
    cos_corner = np.cos(np.radians(corner_angle))
    for v, edges in sorted(incident.items()):
        edges = list({f: k for f, k in edges}.items())        # a facet may be in 2 names
        clamped = [f for f, k in edges if k == "clamped"]
        ss = [f for f, k in edges if k == "simply_supported"]
        M, fixed = None, []
        if clamped:
            ns = [normals[:, f] for f in clamped + ss]
            if len(ns) == 1 or (len(ns) == 2 and ns[0] @ ns[1] > cos_corner):
                n = ns[0] + ns[-1]
                M, sl = _tn_slots(n / np.linalg.norm(n))
                fixed = [0, 1, 2, sl["tt"], sl["tn"]]
            else:                                  # clamped corner: H = 0
                fixed = [0, 1, 2, 3, 4, 5]
        else:
            ns = [normals[:, f] for f in ss]
            if len(ns) == 1 or (len(ns) == 2 and ns[0] @ ns[1] > cos_corner):
                n = ns[0] + ns[-1]
                M, sl = _tn_slots(n / np.linalg.norm(n))
                # sin of the turning angle (arccos is blind near 1)
                straight = len(ns) == 1 or abs(ns[0][0] * ns[1][1] - ns[0][1] * ns[1][0]) < _STRAIGHT
                fixed = [0, sl["t"]] + ([sl["tt"]] if straight else [])
            elif len(ns) == 2:                     # corner: both tangents
                t1, t2 = (np.array([-m[1], m[0]]) for m in ns)
                if min(abs(ns[0][0]), abs(ns[0][1])) < _AXIS and abs(ns[0] @ ns[1]) < _AXIS:
                    fixed = [0, 1, 2, 3, 5]        # axis-parallel right-angle corner
                else:
                    M = _frame(t1, t2, _hessian_row(t1, t1), _hessian_row(t2, t2),
                               _hessian_row(t1, t2))
                    fixed = [0, 1, 2, 3, 4]
            else:                                  # >2 edges meet: pin value and slope
                fixed = [0, 1, 2]
        node_ids.append(v)
        node_slots.append(fixed)
        slots_of[v] = fixed
        if M is not None:
            frame_nodes.append(v)
            frames.append(M)
    by_boundary = {}
    for name, kind in conditions.items():
        facets = np.asarray(mesh.boundaries[name], dtype=np.int64)
        nodes = np.unique(mesh.facets[:, facets])
        if kind == "free":
            by_boundary[name] = (nodes[:0], [], facets[:0], nodes[:0])
            continue
        # a node shared with another constrained boundary carries the
        # combined slots; each boundary reports all dofs fixed at its nodes
        by_boundary[name] = (nodes, [slots_of[int(v)] for v in nodes],
                             facets if kind == "clamped" else facets[:0], nodes)
    clamped_facets = [np.asarray(mesh.boundaries[n]) for n, k in conditions.items() if k == "clamped"]
    return PlateConstraints(
        mesh=mesh, conditions=conditions, nodes=np.array(node_ids, dtype=np.int64),
        node_slots=node_slots, frame_nodes=np.array(frame_nodes, dtype=np.int64),
        frames=np.array(frames).reshape(-1, 6, 6),
        facets=np.unique(np.concatenate(clamped_facets)) if clamped_facets else np.zeros(0, np.int64),
        by_boundary=by_boundary)


def argyris_element(mesh, conditions: Mapping[str, str],
                    corner_angle: float = 30.0) -> ElementTriArgyrisLocal:
    """Argyris element for ``mesh`` with the node frames these conditions need.

    For a scalar plate use ``Basis(mesh, elem)``, for the shell
    ``Basis(mesh, ElementVector(elem, 3))``.
    """
    return plate_constraints(mesh, conditions, corner_angle).element()


def _check_basis(pc: PlateConstraints, basis) -> None:
    elem = basis.elem.elem if isinstance(basis.elem, ElementVector) else basis.elem
    if not same_mesh(basis.mesh, pc.mesh):
        raise ValueError("basis and boundary conditions are on different meshes")
    if isinstance(elem, ElementTriMorley):
        return
    if not isinstance(elem, ElementTriArgyris):
        raise TypeError(f"boundary dofs support Morley and Argyris elements, got {type(elem).__name__}")
    have = getattr(elem, "node_frames", None)
    need = pc.node_frames
    if need is None and have is None:
        return
    if (need is None) != (have is None) or not (
            np.array_equal(have[1], need[1]) and np.allclose(have[2], need[2], atol=1e-14)):
        raise ValueError("the Argyris element's node frames do not match these boundary "
                         "conditions; build it with drape.fem.boundary.argyris_element(mesh, conditions)")


def boundary_dofs(basis, conditions: Mapping[str, str], corner_angle: float = 30.0,
                  components=None) -> ndarray:
    """Dofs fixed by ``conditions`` in ``basis`` (Morley, Argyris, or their ElementVector).

    Parameters
    ----------
    basis
        :class:`skfem.Basis`; an Argyris basis must be built on
        :func:`argyris_element` for the same conditions when any constrained
        boundary is not parallel to the axes (checked).
    conditions
        ``{boundary name: "clamped" | "simply_supported" | "free"}``.
    corner_angle
        See :func:`plate_constraints`.
    components
        For a vector basis, the components to constrain (default: all).

    Examples
    --------
    >>> from skfem import Basis, ElementTriMorley
    >>> from meshes import rectangle
    >>> mesh = rectangle(1.0, 1.0, 2, 2)
    >>> len(boundary_dofs(Basis(mesh, ElementTriMorley()), {"left": "clamped"}))   # 3 u + 2 u_n
    5
    """
    pc = plate_constraints(basis.mesh, conditions, corner_angle)
    return pc.fixed_dofs(basis, components)


def clamped_dofs(basis, names, corner_angle: float = 30.0, components=None) -> ndarray:
    """Dofs of the boundaries ``names`` (a name or a list) all clamped.

    Shorthand for ``boundary_dofs(basis, {name: "clamped" for name in names})``.

    >>> from skfem import Basis, ElementVector
    >>> from meshes import strip
    >>> mesh = strip(0.1, 0.02, 4, 1)
    >>> shell = Basis(mesh, ElementVector(argyris_element(mesh, {"clamped": "clamped"}), 3))
    >>> len(clamped_dofs(shell, "clamped"))          # 3 components x 11
    33
    """
    names = [names] if isinstance(names, str) else list(names)
    return boundary_dofs(basis, {n: "clamped" for n in names}, corner_angle, components)


def rotation_dofs(basis, name: str, conditions: Mapping[str, str] | None = None,
                  corner_angle: float = 30.0):
    """Dofs of a straight clamped boundary and their values per unit rotation.

    The boundary ``name`` is turned rigidly about its own line by a small
    angle θ: ``w = θ s`` with ``s`` the distance from the line measured
    *into* the specimen, so θ > 0 lifts the specimen next to the boundary (for
    a strip clamped at x = 0: ``w_x = θ``).  Impose ``u[dofs] = θ(t) * unit``.

    Returns
    -------
    dofs, unit : ndarray
        The clamped dofs of ``name`` (all components of a vector basis — use
        :func:`prescribed_values` for large rotations) and values for θ = 1.

    Examples
    --------
    >>> from skfem import Basis
    >>> from meshes import strip
    >>> mesh = strip(0.1, 0.02, 4, 1)
    >>> dofs, unit = rotation_dofs(Basis(mesh, argyris_element(mesh, {"clamped": "clamped"})), "clamped")
    >>> [float(v) for v in sorted(set(np.round(unit, 12)))]   # w_x = 1 at nodes, u_n = -1 on the edge
    [-1.0, 0.0, 1.0]
    """
    conditions = dict(conditions or {name: "clamped"})
    if conditions.get(name) != "clamped":
        raise ValueError(f"rotation_dofs: boundary '{name}' must be 'clamped' in conditions")
    mesh = basis.mesh
    facets = np.asarray(mesh.boundaries[name])
    n = facet_normals(mesh)[:, facets]
    if np.abs(n - n[:, :1]).max() > 1e-9:
        raise ValueError(f"rotation_dofs: boundary '{name}' is not straight")
    inward = -n[:, 0]
    x0 = mesh.p[:, mesh.facets[0, facets[0]]]
    pc = plate_constraints(mesh, conditions, corner_angle)
    dofs = pc.fixed_dofs(basis, names=[name])
    unit = prescribed_values(basis, dofs, lambda x: np.einsum("i,i...->...", inward, x - x0[:, None]),
                             lambda x: np.broadcast_to(inward[:, None], (2, x.shape[1])))
    return dofs, unit


def prescribed_values(basis, dofs: ndarray, value, grad=None, hess=None) -> ndarray:
    """Values at ``dofs`` of the Argyris interpolant of a field (see
    :func:`drape.fem.argyris.interpolate` for the callables' shapes); node frames
    are taken into account.  Use it for imposed motions of any boundary, e.g.
    the rigid rotation ``u = (R(θ) − I)(X − X0)`` of a clamped shell edge.
    """
    return interpolate(basis, value, grad, hess)[np.asarray(dofs)]


@dataclass
class StraightEdge:
    """A straight named boundary: facets, outward unit normal and a point on it."""

    name: str
    facets: np.ndarray
    normal: np.ndarray
    origin: np.ndarray
    length: float


def straight_edge(mesh, name: str, facets, error: type[Exception] = ValueError) -> StraightEdge:
    """The named boundary ``facets`` as one straight edge (``error`` if it is not one)."""
    p = mesh.p[:, mesh.facets[:, facets]]  # (2, 2, nf)
    tangent = p[:, 1] - p[:, 0]
    lengths = np.linalg.norm(tangent, axis=0)
    normal = np.array([tangent[1], -tangent[0]]) / lengths
    # orient outwards: away from the centroid of the element owning the facet
    centroid = mesh.p[:, mesh.t[:, mesh.f2t[0, facets]]].mean(axis=1)
    flip = np.einsum("ij,ij->j", normal, 0.5 * (p[:, 0] + p[:, 1]) - centroid) < 0
    normal[:, flip] *= -1
    n0 = normal[:, 0]
    offsets = np.einsum("i,ij->j", n0, p[:, 0] - p[:, 0, :1])
    if np.any(n0 @ normal < 1 - 1e-9) or np.any(np.abs(offsets) > 1e-9 * max(lengths.sum(), 1e-300)):
        raise error(f"boundary {name!r} must be a single straight edge for this support")
    return StraightEdge(name, np.asarray(facets), n0, p[:, 0, 0].copy(), float(lengths.sum()))


def pure_bending_rotations(kappa, length: float, ends=("left", "right")):
    """Edge rotations that impose the uniform curvature ``κ(t)`` on a strip of ``length``.

    With both ends clamped at ``w = 0`` and outward normal slopes
    ``∂w/∂n = s κ L/2`` (``s`` = :data:`CURVATURE_SIGN`) the deflection is
    ``w = s κ x (x − L)/2``: exactly uniform ``κ_xx = κ`` (pure bending, as in
    the KES-FB tester). If ``kappa`` returns ``(κ, κ̇, κ̈)`` the slopes carry
    their rates too (exact lifting).

    >>> rot = pure_bending_rotations(lambda t: 2.0 * t, 0.01)
    >>> rot["left"](1.0), rot["right"](1.0)
    (0.01, 0.01)
    """
    if not length > 0:
        raise ValueError(f"length must be > 0, got {length}")

    def slope(t):
        value = kappa(t)
        if np.ndim(value):
            return tuple(0.5 * CURVATURE_SIGN * length * float(x) for x in value)
        return 0.5 * CURVATURE_SIGN * length * float(value)

    return {end: slope for end in ends}
