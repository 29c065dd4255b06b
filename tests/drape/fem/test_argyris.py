"""Element-local Argyris triangle: conditioning on small and offset elements, one matrix per mesh
(docs/theory.md §4)."""
import numpy as np
import pytest
from skfem import (Basis, ElementTriArgyris, ElementVector, InteriorFacetBasis,
                   MeshTri)

from drape.fem.argyris import ElementTriArgyrisLocal, facet_normals, interpolate


def unit_square(n, offset=0.0):
    x = np.linspace(0.0, 1.0, n + 1) + offset
    return MeshTri.init_tensor(x, x)


def constant_errors(basis):
    u = interpolate(basis, lambda x: 1.0 + 0.0 * x[0])
    f = basis.interpolate(u)
    return (np.abs(np.asarray(f) - 1.0).max(), np.abs(f.grad).max(),
            np.abs(f.hess).max())


@pytest.mark.parametrize("offset", [0.0, 10.0])
def test_constant_and_its_hessian_on_fine_mesh(offset):
    # constant function and its Hessian to <= 1e-10 on a 64x64 mesh of the unit square and
    # of [10, 11]^2 (the stock element: 5e-5 / O(1), docs/theory.md §4)
    basis = Basis(unit_square(64, offset), ElementTriArgyrisLocal(), intorder=4)
    err_value, err_grad, err_hess = constant_errors(basis)
    assert err_value <= 1e-10
    assert err_grad <= 1e-10
    assert err_hess <= 1e-10


def test_stock_element_fails_offset_square():
    # the same check must fail for skfem's global-monomial element, so that the
    # test above is able to detect the trap
    basis = Basis(unit_square(16, 10.0), ElementTriArgyris(), intorder=4)
    err_value, _, err_hess = constant_errors(basis)
    assert err_value > 1e-4 and err_hess > 1e-3


EXPONENTS = [(a, b) for a in range(6) for b in range(6) if a + b <= 5]


def quintic(coef, centre=(0.0, 0.0)):
    """Value, gradient and Hessian callables of sum_k coef_k (x-cx)^a_k (y-cy)^b_k."""
    def mono(x, a, b, dx, dy):
        if a < dx or b < dy:
            return 0.0 * x[0]
        ca = np.prod(np.arange(a - dx + 1, a + 1)) if dx else 1.0
        cb = np.prod(np.arange(b - dy + 1, b + 1)) if dy else 1.0
        return ca * cb * (x[0] - centre[0]) ** (a - dx) * (x[1] - centre[1]) ** (b - dy)

    def d(dx, dy):
        return lambda x: sum(c * mono(x, a, b, dx, dy) for c, (a, b) in zip(coef, EXPONENTS))

    value = d(0, 0)
    grad = lambda x: np.array([d(1, 0)(x), d(0, 1)(x)])
    hess = lambda x: np.array([[d(2, 0)(x), d(1, 1)(x)], [d(1, 1)(x), d(0, 2)(x)]])
    return value, grad, hess


def random_quintic(rng):
    return quintic(rng.uniform(-1.0, 1.0, len(EXPONENTS)))


def distorted_mesh(rng, n=5, offset=0.3):
    mesh = unit_square(n, offset)
    p = mesh.p.copy()
    interior = np.setdiff1d(np.arange(p.shape[1]), mesh.boundary_nodes())
    p[:, interior] += rng.uniform(-0.25, 0.25, (2, len(interior))) / n
    return MeshTri(p, mesh.t)


def test_quintics_reproduced_exactly_on_distorted_mesh():
    rng = np.random.default_rng(1)
    mesh = distorted_mesh(rng)
    element = ElementTriArgyrisLocal()
    basis = Basis(mesh, element)
    x = np.asarray(basis.global_coordinates())
    # each of the 21 monomials (hence every quintic), then random combinations
    cases = [quintic(np.eye(len(EXPONENTS))[k], centre=(0.8, 0.8)) for k in range(len(EXPONENTS))]
    cases += [random_quintic(rng) for _ in range(3)]
    for value, grad, hess in cases:
        f = basis.interpolate(interpolate(basis, value, grad, hess))
        # all terms O(1..100) on [0.3, 1.3]^2: round-off level relative to that
        assert np.abs(np.asarray(f) - value(x)).max() < 1e-11
        assert np.abs(f.grad - grad(x)).max() < 1e-10
        assert np.abs(f.hess - hess(x)).max() < 1e-8
    # point evaluation through probes (element search + inverse mapping)
    pts = rng.uniform(0.35, 1.25, (2, 7))
    assert np.allclose(basis.probes(pts) @ interpolate(basis, value, grad, hess),
                       value(pts), atol=1e-11, rtol=0)


def test_c1_continuity_across_interior_edges():
    # a random dof vector: value and full gradient agree from both sides of
    # every interior edge (checks the edge-normal orientation bookkeeping)
    rng = np.random.default_rng(2)
    mesh = distorted_mesh(rng, n=4)
    element = ElementTriArgyrisLocal()
    basis = Basis(mesh, element)
    u = rng.uniform(-1, 1, basis.N)
    sides = [InteriorFacetBasis(mesh, element, side=s) for s in (0, 1)]
    f0, f1 = (b.interpolate(u) for b in sides)
    scale = np.abs(f0.grad).max()
    assert np.abs(np.asarray(f0) - np.asarray(f1)).max() < 1e-11 * scale
    assert np.abs(f0.grad - f1.grad).max() < 1e-11 * scale
    # the second derivatives do jump (only C1): guards against a vacuous test
    assert np.abs(f0.hess - f1.hess).max() > 1e-3 * scale


def test_one_element_instance_on_two_meshes():
    # the stock element caches the first mesh's Vandermonde matrix
    element = ElementTriArgyrisLocal()
    for offset in (0.0, 10.0, 0.0):
        basis = Basis(unit_square(4, offset), element, intorder=4)
        assert max(constant_errors(basis)) < 1e-10


def test_vector_element_components_and_boundary_normals():
    rng = np.random.default_rng(3)
    mesh = distorted_mesh(rng, n=3)
    basis = Basis(mesh, ElementVector(ElementTriArgyrisLocal(), 3))
    funcs = [random_quintic(rng) for _ in range(3)]
    u = interpolate(basis, lambda x: np.array([f[0](x) for f in funcs]),
                    lambda x: np.array([f[1](x) for f in funcs]),
                    lambda x: np.array([f[2](x) for f in funcs]))
    f = basis.interpolate(u)
    x = np.asarray(basis.global_coordinates())
    for c in range(3):
        assert np.abs(np.asarray(f)[c] - funcs[c][0](x)).max() < 1e-11
        assert np.abs(f.hess[c] - funcs[c][2](x)).max() < 1e-8
    # outward normals on the boundary of the square [0.3, 1.3]^2
    n = facet_normals(mesh)
    fb = mesh.boundary_facets()
    mid = mesh.p[:, mesh.facets[:, fb]].mean(axis=1)
    assert np.all(np.sum(n[:, fb] * (mid - 0.8), axis=0) > 0)
    assert np.allclose(np.linalg.norm(n, axis=0), 1.0, atol=1e-14)
