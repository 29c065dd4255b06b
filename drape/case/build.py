"""From a validated case to the parts of a run: mesh → material → structural model.

:func:`build` returns the :class:`Parts`; :func:`initial_fields` the start of the integration.
What the case names but cannot be built (a missing mesh file, a material that breaks a rule
after the case's overrides) raises :class:`RunInputError` naming the key.
"""
from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from typing import Any

import meshes
from constitutive.material import MaterialError, load_material, material_from_spec
from constitutive.units import G0
from drape.analyses.drape_coefficient import skirt_tension
from drape.case.case import Case, check_boundaries
from drape.case.contact_build import build_contact
from drape.case.loads import kes_curvature, load_amplitudes
from drape.models.perturbation import FoldPerturbation, StripPerturbation, perturbation_dofs
from drape.models.plate import KirchhoffPlate, pure_bending_rotations
from drape.models.rigidity import RigidityVariation
from drape.models.shell import KirchhoffLoveShell
from drape.solvers.linear import DirectSolver
from drape.solvers.newton import NewtonPolicy

__all__ = ["RunInputError", "Parts", "build", "build_mesh", "build_material", "build_model",
           "face_down", "rayleigh_coefficients", "fold_perturbation", "initial_fields"]

log = logging.getLogger("drape.case.build")


class RunInputError(ValueError):
    """Something the case names cannot be built (material, mesh file, boundary, option)."""


@dataclass
class Parts:
    """The built pieces of a case."""

    mesh: Any
    material: Any
    model: Any


def build(case: Case) -> Parts:
    """Mesh → material → model for ``case`` (raises CaseError / ValueError on bad input)."""
    mesh = build_mesh(case)
    log.info("mesh: %d vertices, %d triangles, boundaries %s", mesh.p.shape[1],
             mesh.t.shape[1], sorted(mesh.boundaries or {}))
    material = build_material(case)
    model = build_model(case, mesh, material)
    log.info("model: %s with %d dofs (%d fixed)", type(model).__name__, model.ndofs,
             len(model.fixed_dofs))
    return Parts(mesh, material, model)


def build_mesh(case: Case):
    """The reference mesh described by ``[mesh]`` (boundaries named by :mod:`meshes`)."""
    try:
        mesh = _make_mesh(case.mesh)
    except RunInputError:
        raise
    except ValueError as err:
        raise RunInputError(f"mesh: {err}") from None
    check_boundaries(case, mesh)
    return mesh


#: Most triangles a case may ask for: seven times the finest mesh of the convergence studies
#: (a shell model takes some 50 kB a triangle), so that a slip of a digit is refused at once
#: instead of filling the memory.
MAX_TRIANGLES = 100_000


def triangles_asked(spec) -> float:
    """How many triangles ``[mesh]`` asks for (before it is built; a file mesh: 0).

    >>> from drape.case.mesh_tables import CusickMesh
    >>> triangles_asked(CusickMesh(kind="cusick", n_radial=6, n_circumferential=72, refine=1))
    3456.0
    """
    if spec.kind == "strip" and spec.fine_zone is not None:
        return 2.0 * (spec.nx + spec.fine_zone.nx) * spec.ny
    if spec.kind in ("strip", "rectangle"):
        return 2.0 * spec.nx * spec.ny
    if spec.kind == "circle":
        rings = spec.n_rings or max(1.0, 0.5 * spec.diameter / spec.target_size)
        return 6.0 * rings ** 2
    if spec.kind != "cusick":
        return 0.0
    overhang = (spec.specimen_diameter - spec.disc_diameter) / 2
    around = math.pi * (spec.specimen_diameter + spec.disc_diameter) / 2
    radial = spec.n_radial or max(1.0, overhang / spec.target_size)
    circumferential = spec.n_circumferential or max(8.0, around / spec.target_size)
    return 2.0 * radial * circumferential * 4.0 ** min(spec.refine, 64)


def _make_mesh(spec):
    asked = triangles_asked(spec)
    if asked > MAX_TRIANGLES:   # before any array is made: the sizes may be absurd
        raise RunInputError(f"mesh: {asked:.3g} triangles asked for, more than {MAX_TRIANGLES:,}; "
                            f"check mesh.nx, mesh.ny, mesh.n_radial, mesh.n_circumferential, "
                            f"mesh.target_size and mesh.refine")

    if spec.kind == "strip":
        return meshes.strip(spec.length, spec.width, spec.nx, spec.ny, x_nodes=spec.x_nodes())
    if spec.kind == "rectangle":
        return meshes.rectangle(spec.length, spec.width, spec.nx, spec.ny)
    if spec.kind == "circle":
        return meshes.circle(spec.diameter, n_rings=spec.n_rings, target_size=spec.target_size)
    if spec.kind == "cusick":
        return meshes.cusick_annulus(spec.specimen_diameter, spec.disc_diameter,
                                     n_radial=spec.n_radial,
                                     n_circumferential=spec.n_circumferential,
                                     target_size=spec.target_size, refine=spec.refine,
                                     radial_grading=spec.radial_grading)
    try:
        return meshes.load_mesh(spec.path, scale=spec.scale)
    except FileNotFoundError:
        raise RunInputError(f"mesh.path = {spec.path!r}: file not found") from None
    except ValueError as err:
        raise RunInputError(f"mesh.path = {spec.path!r}: {err}") from None


def face_down(law, ratio: float):
    """``law`` with face-down (κ < 0) rigidities ``ratio`` times its face-up ones."""
    return dataclasses.replace(law, k1_neg=ratio * law.k1,
                               k3_neg=ratio * law.k3 if law.k3 else None)


def build_material(case: Case):
    """The fabric of ``[material]`` with the case's overrides applied (SI)."""
    spec = case.material
    if spec.kes is not None:
        # the same builder (and KES -> SI conversion) as a material file's [kes] table
        material = material_from_spec(
            spec.kes.material_spec(case.case.name, case.case.description, "case file [material.kes]"),
            where="material.kes")
    else:
        material = load_material(spec.name if spec.name is not None else spec.path)
    membrane = {} if case.model.membrane is None else case.model.membrane.model_dump(exclude_none=True)
    try:
        material = material.with_overrides(
            {d: spec.law_overrides(d) for d in ("warp", "weft")}, friction=spec.friction,
            bending_scale=spec.bending_scale, areal_mass=spec.areal_mass,
            thickness=spec.thickness, twist_rigidity=case.model.twist_rigidity, **membrane)
    except MaterialError as err:
        raise RunInputError(str(err)) from None
    if spec.face_down_ratio != 1.0:
        material = material.replace(warp=face_down(material.warp, spec.face_down_ratio),
                                    weft=face_down(material.weft, spec.face_down_ratio))
    tension = membrane_tension(case, material)
    try:
        return material if tension is None else material.at_tension(tension)
    except ValueError as err:
        raise RunInputError(f"model.membrane_tension: {err}") from None


def membrane_tension(case: Case, material) -> float | None:
    """The tension [N/m] at which the shell's membrane is taken on the fabric's tensile
    curve (``[model] membrane_tension``), or ``None`` for the stiffness storing the KES
    test's energy (the plate has no membrane)."""
    value = case.model.membrane_tension
    if case.model.kinematics != "large" or value == "secant":
        return None
    if value != "auto":
        return float(value)
    gravity = case.load.gravity
    if case.mesh.kind != "cusick" or gravity is None or gravity.factor == 0:
        return None

    return skirt_tension(material.areal_mass * G0 * abs(gravity.factor),
                         case.mesh.specimen_diameter / 2.0, case.mesh.disc_diameter / 2.0)


def rayleigh_coefficients(case: Case, material) -> tuple[float, float]:
    """``(alpha, beta)`` of ``C = alpha M + beta K0``: ``[model.damping] alpha`` plus the air
    drag per unit area over the fabric's areal mass (a drag ``c v`` per area is ``(c/ρ_A) ρ_A v``).
    """
    damping = case.model.damping
    alpha = damping.alpha
    if damping.air_drag > 0.0:
        alpha += damping.air_drag / float(material.areal_mass)
    return alpha, damping.beta


def build_model(case: Case, mesh, material):
    """The structural model for ``[model] kinematics`` with supports, loads and damping, and
    the contact of ``[contact]`` (large kinematics only)."""
    spec = case.model
    rayleigh = rayleigh_coefficients(case, material)
    loads = load_amplitudes(case, mass_damping=rayleigh[0])
    if spec.kinematics == "small":
        rotations = None
        if case.load.kes is not None:
            rotations = pure_bending_rotations(kes_curvature(case), case.mesh.length,
                                               ends=tuple(case.load.kes.ends))
        return KirchhoffPlate(
            mesh, material, element=case.mesh.element, supports=dict(spec.supports),
            rotations=rotations, gravity=loads.get("gravity", 0.0),
            pressure=loads.get("pressure", 0.0), rayleigh=rayleigh,
            translational_inertia=spec.translational_inertia,
            friction_tangent=spec.friction_tangent,
        )

    # what the shell cannot do is rejected by the case schema (drape.case.case.Case._consistent)
    clamped = tuple(b for b, kind in spec.supports.items() if kind == "clamped")
    kwargs = {}
    fold = fold_perturbation(case)
    if fold is not None and fold.target == "force":
        weight = float(material.areal_mass) * G0
        kwargs.update(surface_load=(lambda x: fold.traction(x, weight), fold.time_profile))
    if case.load.end_moment is not None:
        kwargs.update(end_moment=loads["end_moment"], load_boundary=case.load.end_moment.boundary)
    shell = KirchhoffLoveShell(mesh, material, clamped=clamped,
                              gravity=loads.get("gravity", 0.0), rayleigh=rayleigh,
                              membrane_strain_degree=spec.membrane_strain_degree,
                              membrane_stabilization=spec.membrane_stabilization,
                              friction_tangent=spec.friction_tangent,
                              viscous_tangent=spec.viscous_tangent,
                              bending_friction=spec.bending_friction,
                              rigidity_factor=rigidity_variation(case),
                              drag_coefficient=spec.damping.drag_coefficient, **kwargs)
    if case.contact is not None:
        shell.attach_contact(build_contact(case.contact, shell, material))
    return shell


def rigidity_variation(case: Case):
    """The ``[model.rigidity_variation]`` field (``drape.models.rigidity.RigidityVariation``) or
    None; its seed, unless given, the perturbation's (one seed, one specimen)."""
    spec = case.model.rigidity_variation
    if spec is None:
        return None
    seed = spec.seed
    if seed is None:
        fold = fold_perturbation(case)
        seed = 0 if fold is None else fold.seed
    return RigidityVariation(cv=spec.cv, correlation_length=float(spec.correlation_length),
                             seed=seed)


def fold_perturbation(case: Case):
    """The ``[load.perturbation]`` field or None: a ``FoldPerturbation`` round a Cusick disc, a
    ``StripPerturbation`` along a strip or rectangle (``drape.models.perturbation``)."""
    p = case.load.perturbation
    if p is None or p.kind == "none":
        return None
    if case.mesh.kind == "cusick":
        return FoldPerturbation(disc_radius=0.5 * case.mesh.disc_diameter,
                                specimen_radius=0.5 * case.mesh.specimen_diameter, **p.model_dump())
    return StripPerturbation(length=float(case.mesh.length), **p.model_dump())


def initial_fields(case: Case, model):
    """Initial (u0, v0): zero, or the fold perturbation of target displacement / velocity.

    The perturbation (``drape.models.perturbation.FoldPerturbation``) is interpolated on the shell's
    basis (the schema allows it with ``model.kinematics = "large"`` only); target "force" is a
    load (:func:`build_model`), not a start.
    """
    fold = fold_perturbation(case)
    if fold is None or fold.target == "force":
        return None, None

    x0 = perturbation_dofs(model.basis, fold)
    return (x0, None) if fold.target == "displacement" else (None, x0)


def solver_options(case: Case, model) -> dict:
    """Newton tolerances, policy and one linear solver for every phase of a run.

    Newton tries the case's friction tangent first and the law's stick tangent after it, and
    keeps a tangent while it contracts by ``tangent_reuse``
    (:class:`drape.solvers.newton.NewtonPolicy`); the direct solver is symmetric when the model's
    tangents are, and keeps its symbolic analysis for the whole run.
    """
    s = case.solver
    tangents = tuple(dict.fromkeys((case.model.friction_tangent, "stick")))
    return dict(rtol=s.rtol, atol=s.atol, du_rtol=s.du_rtol, du_atol=s.du_atol, max_iter=s.max_iter,
                policy=NewtonPolicy(tangents=tangents, reuse_contraction=s.tangent_reuse),
                linear_solver=DirectSolver(symmetric=model.symmetric_tangent, backend=s.linear_solver))
