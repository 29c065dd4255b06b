"""Boundary-condition dofs (drape/fem/boundary.py), validated by plate solves.

References are independent of the code: Timoshenko & Woinowsky-Krieger's
coefficients for square plates, the closed-form clamped circular plate, and the
closed-form axisymmetric annular plate (Cusick geometry) solved here.
"""
import numpy as np
import pytest
from skfem import (Basis, BilinearForm, ElementTriMorley, ElementVector, LinearForm,
                   MeshTri, condense, solve)
from skfem.helpers import dd, ddot, trace

from drape.fem.argyris import ElementTriArgyrisLocal, interpolate
from drape.fem.boundary import (argyris_element, boundary_dofs, plate_constraints,
                            prescribed_values, rotation_dofs)
from meshes import cusick_annulus, rectangle, strip

SIDES = ("left", "right", "bottom", "top")


def plate_form(nu):
    @BilinearForm
    def plate(u, v, w):          # isotropic Kirchhoff plate, D = 1
        return (1 - nu) * ddot(dd(u), dd(v)) + nu * trace(dd(u)) * trace(dd(v))
    return plate


@LinearForm
def unit_load(v, w):
    return v


def solve_plate(basis, fixed, nu=0.3):
    K = plate_form(nu).assemble(basis)
    return solve(*condense(K, unit_load.assemble(basis), D=fixed))


def all_second_derivatives(basis, names):
    dofs = basis.get_dofs(list(names)).nodal
    return np.concatenate([dofs[k] for k in ("u_xx", "u_xy", "u_yy")])


@pytest.mark.parametrize("n", [4, 8])
def test_clamped_square_plate_and_trap_c(n):
    # centre deflection 0.00126 q a^4 / D (Timoshenko & Woinowsky-Krieger, Table 35)
    mesh = rectangle(1.0, 1.0, n, n)
    conditions = {k: "clamped" for k in SIDES}
    basis = Basis(mesh, argyris_element(mesh, conditions))
    fixed = boundary_dofs(basis, conditions)
    centre = basis.probes(np.array([[0.5], [0.5]]))
    w = (centre @ solve_plate(basis, fixed))[0]
    assert abs(w / 0.00126 - 1) < 0.01
    # clamped plates do not depend on nu when the clamping is exact
    w0 = (centre @ solve_plate(basis, fixed, nu=0.0))[0]
    assert abs(w0 / w - 1) < 1e-9
    # fixing the normal second derivative as well is measurably stiffer
    over = np.union1d(fixed, all_second_derivatives(basis, SIDES))
    w_over = (centre @ solve_plate(basis, over))[0]
    assert w_over < 0.99 * w


def test_simply_supported_square_plate_navier():
    # Navier series, w = 16 q/(pi^6 D) sum_{m,n odd} (-1)^((m+n)/2-1) / (m n (m^2+n^2)^2)
    k = np.arange(1, 400, 2)
    m, n = np.meshgrid(k, k)
    navier = 16 / np.pi**6 * np.sum((-1.0) ** ((m + n) // 2 - 1) / (m * n * (m**2 + n**2) ** 2))
    assert abs(navier / 0.00406 - 1) < 0.001          # T&W's printed coefficient
    mesh = rectangle(1.0, 1.0, 4, 4)
    conditions = {k: "simply_supported" for k in SIDES}
    basis = Basis(mesh, argyris_element(mesh, conditions))
    u = solve_plate(basis, boundary_dofs(basis, conditions))
    w = (basis.probes(np.array([[0.5], [0.5]])) @ u)[0]
    assert abs(w / navier - 1) < 0.005


@pytest.mark.parametrize("kind", ["clamped", "simply_supported"])
def test_rotated_square_plate_matches_axis_aligned(kind):
    # boundary conditions on edges of any orientation (and their corners):
    # a square turned by 30 degrees must give the same plate, to round-off
    base = rectangle(1.0, 1.0, 4, 4)
    a = np.radians(30.0)
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    turned = MeshTri(R @ base.p, base.t).with_boundaries(dict(base.boundaries))
    conditions = {k: kind for k in SIDES}
    w = []
    for mesh, centre in ((base, [0.5, 0.5]), (turned, R @ [0.5, 0.5])):
        pc = plate_constraints(mesh, conditions)
        basis = Basis(mesh, pc.element())
        u = solve_plate(basis, boundary_dofs(basis, conditions))
        w.append((basis.probes(np.array(centre)[:, None]) @ u)[0])
    assert len(pc.frame_nodes) > 0
    assert abs(w[1] / w[0] - 1) < 1e-9


def test_morley_clamped_square_plate():
    conditions = {k: "clamped" for k in SIDES}
    w = []
    for n in (16, 32):
        mesh = rectangle(1.0, 1.0, n, n)
        basis = Basis(mesh, ElementTriMorley())
        u = solve_plate(basis, boundary_dofs(basis, conditions))
        centre = np.argmin(np.hypot(mesh.p[0] - 0.5, mesh.p[1] - 0.5))
        w.append(u[basis.nodal_dofs[0, centre]])
    # nonconforming Morley: O(h^2) from above; Richardson-extrapolate the pair
    assert w[0] > w[1] > 0.00126
    assert abs((4 * w[1] - w[0]) / 3 / 0.00126 - 1) < 0.01


def test_clamped_circular_plate_curved_boundary():
    # w(0) = q a^4 / (64 D) for a clamped circle; boundary nodes lie on the circle
    mesh = MeshTri.init_circle(3)
    mesh = mesh.with_boundaries({"edge": lambda x: np.ones(x.shape[1], bool)})
    conditions = {"edge": "clamped"}
    pc = plate_constraints(mesh, conditions)
    assert len(pc.frame_nodes) > 0                     # curved: dofs re-framed
    basis = Basis(mesh, pc.element())
    origin = basis.probes(np.zeros((2, 1)))
    w = (origin @ solve_plate(basis, boundary_dofs(basis, conditions)))[0]
    assert abs(64 * w - 1) < 0.015          # polygonal boundary, 32 edges
    # all second derivatives fixed instead (the trap on a curved edge)
    cart = Basis(mesh, ElementTriArgyrisLocal())
    over = cart.get_dofs("edge").all()
    w_over = (cart.probes(np.zeros((2, 1))) @ solve_plate(cart, over))[0]
    assert w_over < 0.98 * w


def test_simply_supported_circular_plate_curved_boundary():
    # w(0) = (5 + nu)/(1 + nu) q a^4/(64 D); u_tt is left free at curved nodes
    nu = 0.3
    mesh = MeshTri.init_circle(3)
    mesh = mesh.with_boundaries({"edge": lambda x: np.ones(x.shape[1], bool)})
    conditions = {"edge": "simply_supported"}
    basis = Basis(mesh, argyris_element(mesh, conditions))
    u = solve_plate(basis, boundary_dofs(basis, conditions), nu)
    w = (basis.probes(np.zeros((2, 1))) @ u)[0]
    assert abs(w / ((5 + nu) / (1 + nu) / 64) - 1) < 0.005


def annular_plate_hem_deflection(a, b, nu):
    """Axisymmetric plate, unit load and D: clamped at r = b, free at r = a."""
    # w = r^4/64 + A + B r^2 + C ln r + E r^2 ln r
    L = np.log
    lhs = np.array([
        [1, b**2, L(b), b**2 * L(b)],                                      # w(b) = 0
        [0, 2 * b, 1 / b, 2 * b * L(b) + b],                              # w'(b) = 0
        [0, 2 * (1 + nu), (nu - 1) / a**2, 2 * L(a) + 3 + nu * (2 * L(a) + 1)],  # M_r(a) = 0
        [0, 0, 0, 4 / a],                                                 # Q_r(a) = 0
    ])
    rhs = -np.array([b**4 / 64, b**3 / 16, (3 + nu) * a**2 / 16, a / 2])
    A, B, C, E = np.linalg.solve(lhs, rhs)
    return a**4 / 64 + A + B * a**2 + C * L(a) + E * a**2 * L(a)


def test_cusick_annulus_clamped_on_disc():
    a, b, nu = 0.15, 0.09, 0.3
    exact = annular_plate_hem_deflection(a, b, nu)
    conditions = {"disc": "clamped", "hem": "free"}
    errors = []
    for refine in (1, 2):
        mesh = cusick_annulus(n_radial=2, n_circumferential=16, refine=refine)
        basis = Basis(mesh, argyris_element(mesh, conditions))
        u = solve_plate(basis, boundary_dofs(basis, conditions), nu)
        node = np.argmin(np.hypot(mesh.p[0] - a, mesh.p[1]))        # hem node at (a, 0)
        errors.append(abs(u[basis.nodal_dofs[0, node]] / exact - 1))
    assert errors[1] < 0.005 and errors[1] < errors[0] / 3


def test_imposed_rotation_of_clamped_end_is_rigid():
    # a strip turned at its clamp and otherwise unloaded stays flat: w = theta x
    mesh = strip(0.1, 0.02, 5, 2)
    conditions = {"clamped": "clamped", "free_end": "free"}
    theta = 0.3
    for elem in (argyris_element(mesh, conditions), ElementTriMorley()):
        basis = Basis(mesh, elem)
        fixed = boundary_dofs(basis, conditions)
        dofs, unit = rotation_dofs(basis, "clamped", conditions)
        assert np.array_equal(np.sort(dofs), fixed)
        K = plate_form(0.3).assemble(basis)
        x = np.zeros(basis.N)
        x[dofs] = theta * unit
        u = solve(*condense(K, np.zeros(basis.N), x=x, D=dofs))
        error = basis.interpolate(u - interpolate(
            basis, lambda p: theta * p[0], lambda p: np.array([theta + 0 * p[0], 0 * p[0]])))
        assert np.abs(np.asarray(error)).max() < 1e-10 * theta * 0.1     # w = theta x, x <= 0.1 m
        assert np.abs(error.grad).max() < 1e-9 * theta                   # slope


def test_vector_basis_and_prescribed_values_with_frames():
    mesh = cusick_annulus(n_radial=1, n_circumferential=16)
    conditions = {"disc": "clamped"}
    elem = argyris_element(mesh, conditions)
    scalar = boundary_dofs(Basis(mesh, elem), conditions)
    shell = Basis(mesh, ElementVector(elem, 3))
    assert len(boundary_dofs(shell, conditions)) == 3 * len(scalar)
    assert len(boundary_dofs(shell, conditions, components=[2])) == len(scalar)
    # a rigid translation of the shell: prescribed values equal the translation
    # in the value dofs and vanish in all derivative dofs, also at framed nodes
    dofs = boundary_dofs(shell, conditions)
    shift = np.array([1.0, -2.0, 0.5])
    vals = prescribed_values(shell, dofs, lambda x: shift[:, None] + 0 * x[0])
    value_dofs = shell.nodal_dofs[:3].ravel()
    is_value = np.isin(dofs, value_dofs)
    assert np.allclose(vals[~is_value], 0.0, atol=1e-15)
    assert set(np.round(vals[is_value], 14)) == set(shift)


def test_frames_required_and_bad_input_named():
    mesh = cusick_annulus(n_radial=1, n_circumferential=16)
    with pytest.raises(ValueError, match="node frames do not match"):
        boundary_dofs(Basis(mesh, ElementTriArgyrisLocal()), {"disc": "clamped"})
    with pytest.raises(ValueError, match="boundary 'rim' is not a named boundary"):
        plate_constraints(mesh, {"rim": "clamped"})
    with pytest.raises(ValueError, match="boundary 'disc': condition 'glued'"):
        plate_constraints(mesh, {"disc": "glued"})
