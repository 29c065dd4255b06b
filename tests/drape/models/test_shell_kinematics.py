"""Kirchhoff–Love kinematics and the consistency of the shell's residual and tangent."""

import numpy as np
import pytest
from skfem import MeshTri

from constitutive.friction import FrictionParams
from constitutive.law import BendingLaw
from constitutive.conventions import CURVATURE_SIGN
from drape.models.shell import KirchhoffLoveShell


class _Material:
    """Anisotropic fabric with cubic, friction and face-down terms (all code paths)."""

    areal_mass = 0.3
    warp = BendingLaw(k1=1.0, k3=0.5, d=0.05, m=0.01,
                      friction=FrictionParams(0.3, 0.1, 0.5, 0.5))
    weft = BendingLaw(k1=0.7, k3=0.2, k1_neg=0.5, d=0.02)
    twist_rigidity = 0.8
    E1, E2, nu12, G12 = 100.0, 80.0, 0.2, 10.0


def _strip(nx=3, ny=2, L=1.0, b=0.5, x0=0.0):
    mesh = MeshTri.init_tensor(np.linspace(x0, x0 + L, nx + 1), np.linspace(0, b, ny + 1))
    return mesh.with_boundaries({"clamped": lambda x: x[0] < x0 + 1e-9,
                                 "free": lambda x: x[0] > x0 + L - 1e-9})


@pytest.fixture(scope="module")
def shell():
    return KirchhoffLoveShell(_strip(), _Material(), gravity=lambda t: 0.7 * t,
                              edge_load=lambda t: np.array([0.1, 0.2, 0.3]),
                              end_moment=lambda t: 0.9, rayleigh=(0.1, 0.01))


def _random_state(shell, seed=0, scale=0.3):
    rng = np.random.default_rng(seed)
    u = scale * rng.standard_normal(shell.ndofs)
    u[shell.fixed_dofs] = 0.0
    return u, rng


def _rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.cross(np.eye(3), axis)
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def test_rigid_body_motion_gives_zero_strain_and_curvature():
    """Finite rotation + translation: ε = κ = 0 to round-off (tolerance 1e-10)."""
    sh = KirchhoffLoveShell(_strip(nx=2, ny=2, x0=3.0), _Material(), gravity=0.0)
    Q = _rotation([0.3, -0.5, 0.8], 2.1)
    A = Q - np.eye(3)
    c = np.array([0.4, -1.0, 2.0])
    u = sh.interpolate(lambda x: A[:, :2] @ x + c[:, None],
                       lambda x: np.broadcast_to(A[:, :2, None], (3, 2, x.shape[1])))
    eps, kap = sh.qp_state(u)
    assert np.abs(eps).max() < 1e-10
    assert np.abs(kap).max() < 1e-10
    # and no internal force
    fint = sh.residual(u, 0 * u, 0 * u, 0.0)[0]
    assert np.abs(fint).max() < 1e-9


@pytest.mark.parametrize("phi", [0.0, np.pi / 2, 0.6])
def test_cylinder_of_radius_R_gives_curvature_one_over_R(phi):
    """Plate rolled onto a cylinder whose axis makes the angle φ + 90° with x.

    Exact: E = 0, κ_αβ = t_α t_β / R with t = (cos φ, sin φ) (face-up, concave +z).
    Tolerance 1e-6 · (1/R) (interpolation of the cylinder by quintics, h = 1/8, R = 1).
    """
    R = 1.0
    mesh = MeshTri.init_tensor(np.linspace(0, 1, 9), np.linspace(0, 1, 9))
    sh = KirchhoffLoveShell(mesh, _Material(), clamped=(), gravity=0.0)
    t = np.array([np.cos(phi), np.sin(phi)])
    tt = np.array([-t[1], t[0]])

    def split(x):
        s = t @ x
        return s, np.sin(s / R), np.cos(s / R)

    def value(x):
        s, sn, cs = split(x)
        r = R * sn[None] * np.append(t, 0)[:, None] + (tt @ x)[None] * np.append(tt, 0)[:, None]
        r[2] = R * (1 - cs)
        return r - np.vstack([x, 0 * x[0]])

    def grad(x):                                    # (3, 2, N)
        s, sn, cs = split(x)
        dr = np.einsum("i,a,n->ian", np.append(t, 0), t, cs) \
            + np.einsum("i,a->ia", np.append(tt, 0), tt)[..., None]
        dr[2] = np.einsum("a,n->an", t, sn)
        return dr - np.vstack([np.eye(2), np.zeros((1, 2))])[..., None]

    def hess(x):                                    # (3, 2, 2, N)
        s, sn, cs = split(x)
        h = -np.einsum("i,a,b,n->iabn", np.append(t, 0), t, t, sn / R)
        h[2] = np.einsum("a,b,n->abn", t, t, cs / R)
        return h

    u = sh.interpolate(value, grad, hess)
    eps, kap = sh.qp_state(u)
    expected = CURVATURE_SIGN * np.array([t[0] ** 2, t[1] ** 2, 2 * t[0] * t[1]]) / R
    assert np.abs(kap - expected).max() < 1e-6 / R
    assert np.abs(eps).max() < 1e-6


def test_first_variations_match_finite_differences(shell):
    """∂ε/∂u and ∂κ/∂u against central differences (relative error ≤ 1e-6)."""
    u, rng = _random_state(shell, seed=1)
    du = rng.standard_normal(shell.ndofs)
    sl = slice(0, len(shell.edofs))
    kp = shell.points(u, sl)
    due = du[shell.edofs].reshape(len(shell.edofs), -1)
    lin_e = np.einsum("eqvI,eI->eqv", kp.strain_variation(), due)
    lin_k = np.einsum("eqvI,eI->eqv", kp.curvature_variation(), due)
    h = 1e-6
    ep, kpp = shell.qp_state(u + h * du)
    em, kpm = shell.qp_state(u - h * du)
    for lin, fd in ((lin_e, (ep - em) / (2 * h)), (lin_k, (kpp - kpm) / (2 * h))):
        assert np.linalg.norm(lin - fd) <= 1e-6 * np.linalg.norm(fd)


@pytest.fixture(scope="module")
def assumed_strain_shell():
    return KirchhoffLoveShell(_strip(), _Material(), gravity=lambda t: 0.7 * t,
                              edge_load=lambda t: np.array([0.1, 0.2, 0.3]),
                              membrane_strain_degree=1, membrane_stabilization=0.05,
                              viscous_tangent="full")


@pytest.mark.parametrize("model", ["shell", "assumed_strain_shell"])
@pytest.mark.parametrize("moving", [False, True])
def test_tangent_matches_finite_differences_of_residual(model, moving, request):
    """K = ∂R/∂u (membrane, bending with friction and face-down stiffness, twist,
    follower end moment; moving: the law's viscous d κ̇ and inertia m κ̈ at random
    v, a) at a random non-trivial state after a committed step; relative error of
    K·du against central differences ≤ 1e-6. Also with the stabilised assumed membrane
    strain (degree 1, γ = 0.05)."""
    shell = request.getfixturevalue(model)
    u0, rng = _random_state(shell, seed=2, scale=0.1)
    shell.commit(u0, 0 * u0)
    u = u0 + 0.3 * rng.standard_normal(shell.ndofs)
    u[shell.fixed_dofs] = 0.0
    v, a = (rng.standard_normal(shell.ndofs) * moving for _ in range(2))
    _, K, _, _ = shell.residual(u, v, a, 1.0)
    for _ in range(2):
        du = rng.standard_normal(shell.ndofs)
        h = 1e-6
        fd = (shell.residual(u + h * du, v, a, 1.0)[0]
              - shell.residual(u - h * du, v, a, 1.0)[0]) / (2 * h)
        assert np.linalg.norm(K @ du - fd) <= 1e-6 * np.linalg.norm(fd)


def test_damping_and_mass_matrices_are_derivatives_of_residual(shell):
    """C = ∂R/∂v, M = ∂R/∂a (Rayleigh + law viscosity + curvature inertia), rel. ≤ 1e-9."""
    u, rng = _random_state(shell, seed=3)
    v, a, dv = (rng.standard_normal(shell.ndofs) for _ in range(3))
    R0, _, C, M = shell.residual(u, v, a, 0.5)
    Rv = shell.residual(u, v + dv, a, 0.5)[0]
    Ra = shell.residual(u, v, a + dv, 0.5)[0]
    assert np.linalg.norm(C @ dv - (Rv - R0)) <= 1e-9 * np.linalg.norm(Rv - R0)
    assert np.linalg.norm(M @ dv - (Ra - R0)) <= 1e-9 * np.linalg.norm(Ra - R0)


@pytest.mark.parametrize("assumed", [None, (1, 0.05), (2, 0.0)])
def test_internal_force_is_gradient_of_strain_energy(assumed):
    """Without friction, f_int = ∂(strain energy)/∂u (relative error ≤ 1e-6); also with a
    (stabilised) assumed membrane strain of degree 1 or 2."""
    class Elastic(_Material):
        warp = BendingLaw(k1=1.0, k3=0.5)
    kw = {} if assumed is None else dict(membrane_strain_degree=assumed[0],
                                         membrane_stabilization=assumed[1])
    sh = KirchhoffLoveShell(_strip(), Elastic(), gravity=0.0, **kw)
    u, rng = _random_state(sh, seed=4)
    z = np.zeros_like(u)
    fint = sh.residual(u, z, z, 0.0)[0]
    du = rng.standard_normal(sh.ndofs)
    h = 1e-6
    fd = (sh.energies(u + h * du, z)["strain"] - sh.energies(u - h * du, z)["strain"]) / (2 * h)
    assert abs(fint @ du - fd) <= 1e-6 * abs(fd)
