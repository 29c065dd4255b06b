"""The subdivided collision mesh: contact points inside the elements, ``x = X + P u``.

References: the sub-mesh's counts and areas (combinatorics of a triangle split n² times),
skfem's own point evaluation of the field (``probes``: point location and inverse mapping,
not the lattice evaluation ``P`` is built from), the selection of vertex dofs written out
here with ``ipctk`` for subdivision 1, the sheet's weight ρ_A g A, and finite differences.
"""
from types import SimpleNamespace

import ipctk
import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshTri

from constitutive.units import G0
from drape.contact.bodies import RigidBody, Scene
from drape.contact.contact import Contact
from drape.contact.stiffness import barrier_stiffness
from drape.fem.subdivision import subdivide
from drape.models.shell import ElasticMaterial, KirchhoffLoveShell
from drape.solvers.static import quasi_static

RHO_A = 0.2                     # kg/m²
THICKNESS, DHAT = 1e-3, 1e-3
L = W = 0.2


def floor(z):
    """A large two-triangle patch at height ``z`` facing +z, its diagonal off the sheet's grid."""
    v = np.array([[-1.0, -1.1, z], [1.05, -1.0, z], [1.0, 1.0, z], [-1.05, 1.1, z]]) + [0.1, 0.1, 0]
    return SimpleNamespace(vertices=v, triangles=np.array([[0, 1, 2], [0, 2, 3]]))


def sheet(subdivision, bodies=(), nx=4, hessian="projected", **shell_kw):
    """An elastic sheet on [0, L] × [0, W] at z = 0, its contact on the subdivided mesh."""
    mesh = MeshTri.init_tensor(np.linspace(0, L, nx + 1), np.linspace(0, W, nx + 1))
    kw = dict(clamped=(), rayleigh=(0.0, 0.0))
    kw.update(shell_kw)
    shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-4, membrane=1e3, areal_mass=RHO_A), **kw)
    points, triangles, P = shell.contact_vertices(subdivision)
    kappa = barrier_stiffness(RHO_A * G0 * L * W / len(points), DHAT, THICKNESS / 2)
    contact = Contact(Scene(points, triangles, bodies), P, shell.ndofs, dhat=DHAT, thickness=THICKNESS,
                      stiffness=kappa, hessian=hessian)
    shell.attach_contact(contact)
    return shell, contact


@pytest.mark.parametrize("n", [1, 2, 3])
def test_sub_mesh_shares_its_sub_vertices_and_tiles_every_triangle(n):
    mesh = MeshTri.init_tensor(np.linspace(0, 0.3, 4), np.linspace(0, 0.1, 3))
    points, triangles, _ = subdivide(mesh, n)
    n_edges, n_tri = mesh.facets.shape[1], mesh.t.shape[1]
    # one point per vertex, n - 1 per edge, (n - 1)(n - 2)/2 inside each triangle
    assert len(points) == mesh.p.shape[1] + n_edges * (n - 1) + n_tri * (n - 1) * (n - 2) // 2
    assert len(triangles) == n_tri * n * n
    np.testing.assert_array_equal(points[:mesh.p.shape[1]], mesh.p.T)

    def signed_area(p, t):
        a, b, c = (p[t[:, k]] for k in range(3))
        return 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])

    sub = signed_area(points, triangles).reshape(n_tri, n * n)
    parent = signed_area(mesh.p.T, mesh.t.T)
    np.testing.assert_allclose(sub, np.repeat(parent[:, None] / n**2, n * n, axis=1), rtol=1e-12)


@pytest.mark.parametrize("n", [2, 3])
def test_interpolation_reproduces_the_shell_field_at_the_sub_vertices(n):
    mesh = MeshTri.init_tensor(np.linspace(0, 0.2, 4), np.linspace(0, 0.1, 3))
    shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-4, membrane=1e3, areal_mass=RHO_A), clamped=())
    u = np.random.default_rng(3).standard_normal(shell.ndofs)
    points, _, P = shell.contact_vertices(n)
    probes = shell.basis.probes(points[:, :2].T)            # skfem: locate, invert the mapping
    reference = np.column_stack([probes @ u[k::3] for k in range(3)])
    np.testing.assert_allclose((P @ u).reshape(-1, 3), reference, atol=1e-12 * np.abs(reference).max())


def test_subdivision_one_gives_exactly_the_vertex_selection():
    table = RigidBody("table", floor(-(0.5 * THICKNESS + 0.4 * DHAT)))
    shell, contact = sheet(1, [table])
    u = np.zeros(shell.ndofs)
    w = np.random.default_rng(0).uniform(-0.2, 0.2, shell.mesh.p.shape[1]) * DHAT
    dofs = 3 * np.asarray(shell.basis.nodal_dofs[0])[:, None] + np.arange(3)
    u[dofs[:, 2]] = w
    force, (rows, cols, values) = contact.forces(u, u, 0.0, (1.0, 0.0))
    # the selection written out: vertices at X + u[dofs], forces scattered to those dofs
    scene = contact.scene
    x = scene.positions(u[dofs], 0.0)
    collisions = ipctk.NormalCollisions()
    collisions.build(scene.mesh, x, DHAT, 0.5 * THICKNESS)
    assert len(collisions) > 0
    expected = np.zeros(shell.ndofs)
    m = dofs.size
    expected[dofs.ravel()] += contact.barrier.gradient(collisions, scene.mesh, x)[:m]
    # ipctk sums the pairs' gradients and Hessians in parallel threads, so two builds may add in
    # another order: equal to round-off, not bit for bit
    assert np.abs(force - expected).max() <= 1e-12 * np.abs(expected).max()
    H = sp.csr_matrix(contact.barrier.hessian(collisions, scene.mesh, x, ipctk.PSDProjectionMethod.CLAMP))[:m, :m]
    H = H.tocoo()
    old = sp.csr_matrix((H.data, (dofs.ravel()[H.row], dofs.ravel()[H.col])), shape=(shell.ndofs,) * 2)
    new = sp.csr_matrix((values, (rows, cols)), shape=(shell.ndofs,) * 2)
    assert abs(old - new).max() <= 1e-12 * abs(old).max()


def test_sheet_resting_on_a_plane_with_subdivision_two_carries_its_weight():
    z0 = -(0.5 * THICKNESS + 0.7 * DHAT)
    table = RigidBody("table", floor(z0))
    in_plane = np.flatnonzero(np.arange(sheet(2)[0].ndofs) % 3 != 2)   # frictionless: held in its plane
    shell, contact = sheet(2, [table], fixed_dofs=in_plane)
    assert contact.scene.n_fabric > shell.mesh.p.shape[1]
    state = quasi_static(shell, [1.0], [1.0], rtol=1e-10, du_rtol=1e-10)
    reaction = contact.body_forces(state.u, None, state.t)["table"]
    weight = RHO_A * G0 * L * W
    assert reaction[2] == pytest.approx(-weight, rel=0.01)
    gap = contact.fabric_values(state.u)[:, 2] - z0          # every sub-vertex inside the layer
    assert gap.min() > 0.5 * THICKNESS and gap.max() < 0.5 * THICKNESS + DHAT


def test_force_and_tangent_through_the_interpolation_match_finite_differences():
    # the exact Hessian (the projected one is not the derivative)
    table = RigidBody("table", floor(-(0.5 * THICKNESS + 0.5 * DHAT)))
    shell, contact = sheet(3, [table], nx=2, hessian="exact")
    rng = np.random.default_rng(7)
    u = np.zeros(shell.ndofs)
    u[2::3] = 0.05 * DHAT * rng.standard_normal(shell.ndofs // 3)   # w and its derivatives
    d = np.zeros(shell.ndofs)
    d[2::3] = rng.standard_normal(shell.ndofs // 3)
    d *= 1e-3 * DHAT / np.abs(contact.P @ d).max()
    force, (rows, cols, values) = contact.forces(u, u, 0.0, (1.0, 0.0))
    assert np.any(force)
    e_plus, e_minus = contact.energy(u + d, 0.0), contact.energy(u - d, 0.0)
    assert (e_plus - e_minus) / 2 == pytest.approx(force @ d, rel=1e-5)
    K = sp.csr_matrix((values, (rows, cols)), shape=(shell.ndofs,) * 2)
    f_plus, f_minus = contact.forces(u + d, u, 0.0)[0], contact.forces(u - d, u, 0.0)[0]
    np.testing.assert_allclose((f_plus - f_minus) / 2, K @ d, rtol=1e-4, atol=1e-6 * np.abs(K @ d).max())


@pytest.mark.parametrize("value, code, message", [("2", 0, "OK"), ("0", 2, "contact.subdivision = 0: must be >= 1"),
                                                  ("1.5", 2, "contact.subdivision = 1.5: must be an integer")])
def test_case_key_subdivision_is_checked(value, code, message, capsys):
    from pathlib import Path

    from drape.cli.run import main as run

    case = Path(__file__).resolve().parents[3] / "cases" / "peirce_platform.toml"
    assert run([str(case), "--check", "--set", f"contact.subdivision={value}"]) == code
    out, err = capsys.readouterr()
    assert message in out + err
