"""From ``[contact]`` to the shell's contact: the bodies' surfaces, paths and the IPC parameters.

:func:`build_contact` builds every ``[[contact.body]]`` surface (:mod:`drape.contact.shapes`),
places it, gives it its path (:mod:`drape.contact.motion`), puts it in one scene with the
fabric and checks that the fabric starts clear of every body (and of itself).
"""
from __future__ import annotations

import logging

import numpy as np

from constitutive.units import G0
from drape.contact import shapes
from drape.contact.bodies import ContactInputError, HalfSpace, RigidBody, Scene
from drape.contact.contact import Contact
from drape.contact.motion import RigidPath
from drape.contact.stiffness import barrier_stiffness, resting_distance, resting_multiplicity

log = logging.getLogger(__name__)

__all__ = ["build_contact", "body_surface", "half_space", "body_triangles_asked", "MAX_CONTACT_TRIANGLES"]

#: Most triangles a body, or the fabric's collision mesh, may have: as for ``[mesh]``
#: (:data:`drape.case.build.MAX_TRIANGLES`), a slip of a digit is refused before any array is made.
MAX_CONTACT_TRIANGLES = 100_000

#: Triangles per resolution² of each built shape (upper bounds of the builders' counts).
_TRIANGLES_PER_RESOLUTION2 = {"plane": 2.0, "sphere": 4.0, "cylinder": 1.0, "box": 14.0, "disc": 2.0}


def body_triangles_asked(spec) -> float:
    """About how many triangles a ``[[contact.body]]`` table asks for (a mesh file: 0).

    >>> from drape.case.contact_tables import SphereBody
    >>> body_triangles_asked(SphereBody(name="ball", shape="sphere", centre=[0, 0, 0], radius=0.1))
    2304.0
    """
    factor = _TRIANGLES_PER_RESOLUTION2.get(spec.shape)
    return 0.0 if factor is None else factor * float(spec.resolution) ** 2


def _check_size(what: str, asked: float, key: str) -> None:
    if asked > MAX_CONTACT_TRIANGLES:
        raise ContactInputError(f"{what}: about {asked:.3g} triangles asked for, more than "
                                f"{MAX_CONTACT_TRIANGLES:,}; check {key}")


def body_surface(spec):
    """The placed surface of one ``[[contact.body]]`` table (metres)."""
    kind = spec.shape
    if kind == "plane":
        surface = shapes.plane(spec.point, spec.normal, spec.size, spec.resolution)
    elif kind == "sphere":
        surface = shapes.sphere(spec.centre, spec.radius, spec.resolution)
    elif kind == "cylinder":
        surface = shapes.cylinder(spec.centre, spec.axis, spec.radius, spec.length, spec.resolution)
    elif kind == "box":
        surface = shapes.rounded_box(spec.centre, spec.size, spec.edge_radius, spec.resolution)
    elif kind == "disc":
        surface = shapes.disc(spec.centre, spec.radius, spec.thickness, spec.edge_radius, spec.resolution)
    else:
        surface = shapes.read_surface(spec.file, units=spec.units)
    return surface.placed(translation=spec.translation, rotation_deg=spec.rotation_deg, scale=spec.scale)


def half_space(spec, path=None, resting: float = 0.0) -> HalfSpace:
    """The placed :class:`drape.contact.half_space.HalfSpace` of a ``shape = "half_space"`` table;
    ``point = "resting"`` puts the plane ``resting`` [m] below z = 0 (before placement)."""
    linear, shift = shapes.placement(spec.translation, spec.rotation_deg, spec.scale)
    point = [0.0, 0.0, -resting] if spec.point == "resting" else spec.point
    return HalfSpace(spec.name, linear @ np.asarray(point, dtype=float) + shift,
                     linear @ np.asarray(spec.normal, dtype=float), spec.mu, path)


def _body(spec, resting: float):
    _check_size(f"contact.body {spec.name!r}", body_triangles_asked(spec), "its resolution")
    try:
        path = None if spec.path is None else RigidPath(spec.path.times, spec.path.translations)
        if spec.shape == "half_space":
            return half_space(spec, path, resting)
        return RigidBody(spec.name, body_surface(spec), spec.mu, path)
    except (ContactInputError, OSError, ValueError) as err:     # OSError: a file missing or not a surface
        said = str(err).removeprefix(f"body {spec.name!r}: ")     # the body's own checks name it too
        raise ContactInputError(f"contact.body {spec.name!r}: {said}") from None


def build_contact(spec, shell, material, u0=None) -> Contact:
    """The :class:`drape.contact.contact.Contact` of ``[contact]`` on ``shell``.

    The barrier stiffness is the table's, or the one that rests a vertex carrying its share of
    the fabric's weight in the middle of the barrier layer
    (:func:`drape.contact.stiffness.barrier_stiffness`), divided by the number of pairs' worth
    of force a vertex resting on a body at the start gets from the body's mesh
    (:func:`drape.contact.stiffness.resting_multiplicity`): a fabric laid on a table starts at
    rest instead of being thrown off it. Raises ContactInputError (one line)
    for a body that cannot be built or a fabric that starts inside a body.
    """
    thickness = spec.thickness if spec.thickness is not None else getattr(material, "thickness", None)
    if thickness is None:
        raise ContactInputError("contact.thickness: the material has no thickness; give contact.thickness")
    _check_size("contact", float(len(shell.w)) * float(spec.subdivision) ** 2, "contact.subdivision")
    points, triangles, dofs = shell.contact_vertices(spec.subdivision)
    resting = resting_distance(spec.dhat, 0.5 * thickness)     # where a flat specimen rests on a plane
    scene = Scene(points, triangles, [_body(b, resting) for b in spec.body], spec.self_contact, spec.pairs)
    kappa = spec.barrier_stiffness
    if kappa is None:
        area = float(shell.w.sum())
        kappa = barrier_stiffness(float(material.areal_mass) * G0 * area / len(points), spec.dhat,
                                  0.5 * thickness)
    u0 = np.zeros(shell.ndofs) if u0 is None else u0
    contact = Contact(scene, dofs, shell.ndofs, dhat=spec.dhat, stiffness=kappa, thickness=thickness,
                      eps_v=spec.eps_v, mu_self=spec.mu_self, hessian=spec.hessian)
    contact.check_start(u0)
    if spec.barrier_stiffness is None:
        # the share is carried by every pair a resting vertex makes with the body's mesh
        count = resting_multiplicity(scene.mesh, contact.positions(u0, 0.0), scene.n_fabric,
                                     spec.dhat, 0.5 * thickness, collisions=contact.collisions(u0, 0.0))
        if count > 1.0:
            log.info("contact: a resting vertex makes %.3g pairs' worth of barrier force; "
                     "barrier stiffness %.4g N/m³", count, kappa / count)
            contact.set_stiffness(kappa / count)
    return contact
