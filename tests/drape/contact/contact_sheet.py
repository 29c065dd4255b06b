"""The sheet and the flat bodies the contact tests share: a free elastic sheet with contact
to given bodies, and a large two-triangle plane patch, so that the tests depend on nothing but
the contact core."""
from types import SimpleNamespace

import numpy as np
import pytest
from skfem import MeshTri

from constitutive.units import G0
from drape.contact.bodies import HalfSpace, RigidBody, Scene
from drape.contact.contact import Contact
from drape.contact.stiffness import barrier_stiffness
from drape.models.shell import ElasticMaterial, KirchhoffLoveShell

RHO_A = 0.2            # kg/m²
THICKNESS, DHAT = 1e-3, 1e-3


def plane(point, normal, size=3.0):
    """A square two-triangle patch through ``point`` with ``normal``, ``size`` wide; its
    diagonal is turned off the sheet's grid lines so no vertex sits over an edge."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    e1 = np.cross(n, [0.3, 1.0, 0.1] if abs(n[1]) < 0.9 else [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    corners = [(-1, -1.1), (1.05, -1), (1, 1), (-1.05, 1.1)]
    vertices = np.array([np.asarray(point, float) + 0.5 * size * (a * e1 + b * e2) for a, b in corners])
    triangles = np.array([[0, 1, 2], [0, 2, 3]])
    if np.dot(np.cross(vertices[1] - vertices[0], vertices[2] - vertices[0]), n) < 0:
        triangles = triangles[:, ::-1]
    return SimpleNamespace(vertices=vertices, triangles=triangles)


def flat(kind, name, point, normal=(0, 0, 1), **kw):
    """A flat body: the two-triangle patch of :func:`plane` (``patch``, and ``per_point``, the
    patch with one pair per fabric point) or the exact plane of a half-space."""
    if kind in ("patch", "per_point"):
        return RigidBody(name, plane(point, normal), **kw)
    return HalfSpace(name, point, normal, **kw)


FLAT = pytest.mark.parametrize("kind", ["patch", "half_space", "per_point"])


def pairs_of(kind) -> str:
    """The scene's ``pairs`` for a :data:`FLAT` kind."""
    return "per_point" if kind == "per_point" else "ipc"


def sheet(L=0.2, W=0.2, nx=4, ny=4, bodies=(), *, mu_self=0.0, eps_v=1e-3, force_per_vertex=None, pairs="ipc",
          **shell_kw):
    """A free elastic sheet on [0, L] × [0, W] at z = 0 with contact to ``bodies``."""
    mesh = MeshTri.init_tensor(np.linspace(0, L, nx + 1), np.linspace(0, W, ny + 1))
    kw = dict(clamped=(), rayleigh=(0.0, 0.0))
    kw.update(shell_kw)
    shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-4, membrane=1e3, areal_mass=RHO_A), **kw)
    points, triangles, dofs = shell.contact_vertices()
    if force_per_vertex is None:
        force_per_vertex = RHO_A * G0 * L * W / len(points)
    contact = Contact(Scene(points, triangles, bodies, pairs=pairs), dofs, shell.ndofs, dhat=DHAT,
                      thickness=THICKNESS, stiffness=barrier_stiffness(force_per_vertex, DHAT, THICKNESS / 2),
                      eps_v=eps_v, mu_self=mu_self)
    contact.check_start(np.zeros(shell.ndofs))
    shell.attach_contact(contact)
    return shell, contact


def in_plane_dofs(shell):
    """Every x and y dof: the sheet held in its plane (frictionless contact leaves it free)."""
    return np.flatnonzero(np.arange(shell.ndofs) % 3 != 2)
