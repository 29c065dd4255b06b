"""The shell's compiled element kernels and its quadrature rule."""

from math import factorial

import numpy as np
import pytest
from skfem import MeshTri
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from constitutive.friction import FrictionParams
from constitutive.law import BendingLaw
from drape.models.shell import ElasticMaterial, KirchhoffLoveShell, ShellInputError
from drape.fem.shell_kernels import element_colours


class _Viscous:
    """Anisotropic fabric with cubic stiffness, face-down stiffness, viscosity and
    curvature inertia, no friction."""

    areal_mass = 0.3
    warp = BendingLaw(k1=1.0, k3=0.5, d=0.05, m=0.01)
    weft = BendingLaw(k1=0.7, k3=0.2, k1_neg=0.5, d=0.02)
    twist_rigidity = 0.8
    E1, E2, nu12, G12 = 100.0, 80.0, 0.2, 10.0


class _Elastic(_Viscous):
    """Elastic (k3 = 0, no friction, no viscosity): the force derives from an energy."""

    warp = BendingLaw(k1=1.0)
    weft = BendingLaw(k1=0.7)


K_ONLY = (1.0, 0.0, 0.0)


def _parts(shell, u, v=None, a=None):
    """Force (with the viscous moments of ``v``) and the data of K, C_law and M_law, each
    from its own weighted pass of the tangent kernel."""
    f, Kd = shell.internal_forces(u, v, a, K_ONLY)
    Cd, Md = (shell.internal_forces(u, v, a, w)[1] for w in ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
    return f, Kd, Cd, Md

def _strip(nx=3, ny=2, L=1.0, b=0.5):
    mesh = MeshTri.init_tensor(np.linspace(0, L, nx + 1), np.linspace(0, b, ny + 1))
    return mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9,
                                 "free": lambda x: x[0] > L - 1e-9})


def _large_rotation_state(shell, seed=0, angle=1.3, scale=0.05):
    """A strip rolled about the y axis through ``angle`` over its length (rotations up to
    75°), plus a random perturbation; free of the clamp (not needed for the kernels)."""
    R = 1.0 / angle

    def value(x):
        s = x[0]
        return np.stack([R * np.sin(s / R) - s, 0 * s, R * (1 - np.cos(s / R))])

    def grad(x):
        s = x[0]
        g = np.zeros((3, 2) + s.shape)
        g[0, 0] = np.cos(s / R) - 1
        g[2, 0] = np.sin(s / R)
        return g

    def hess(x):
        s = x[0]
        h = np.zeros((3, 2, 2) + s.shape)
        h[0, 0, 0] = -np.sin(s / R) / R
        h[2, 0, 0] = np.cos(s / R) / R
        return h

    rng = np.random.default_rng(seed)
    u = shell.interpolate(value, grad, hess) + scale * rng.standard_normal(shell.ndofs)
    return u, rng


@pytest.fixture(scope="module", params=[None, (1, 0.05)], ids=["consistent", "assumed-strain"])
def viscous_shell(request):
    kw = {} if request.param is None else dict(membrane_strain_degree=request.param[0],
                                               membrane_stabilization=request.param[1])
    return KirchhoffLoveShell(_strip(), _Viscous(), gravity=0.0, viscous_tangent="full", **kw)


def test_element_colours_share_no_dof():
    """Within a colour no two elements share a dof; every element has one colour."""
    shell = KirchhoffLoveShell(_strip(4, 3), ElasticMaterial(1.0, 1e3), gravity=0.0)
    sdofs = shell.basis.element_dofs.T
    order, start = element_colours(sdofs)
    assert np.array_equal(np.sort(order), np.arange(len(sdofs)))
    for c in range(len(start) - 1):
        dofs = sdofs[order[start[c]:start[c + 1]]].ravel()
        assert len(np.unique(dofs)) == len(dofs)


@pytest.mark.parametrize("assumed", [None, (1, 0.05)])
def test_force_is_gradient_of_elastic_energy(assumed):
    """k3 = 0, no friction, no viscosity, a large-rotation state: f_int · du equals the
    central difference of the strain energy (relative error ≤ 1e-6), in the force-only and
    in the tangent pass, which agree to 1e-13."""
    kw = {} if assumed is None else dict(membrane_strain_degree=assumed[0],
                                         membrane_stabilization=assumed[1])
    shell = KirchhoffLoveShell(_strip(), _Elastic(), gravity=0.0, **kw)
    u, rng = _large_rotation_state(shell)
    f_only, J = shell.internal_forces(u)
    assert J is None
    f_tan = shell.internal_forces(u, weights=K_ONLY)[0]
    assert np.linalg.norm(f_tan - f_only) <= 1e-13 * np.linalg.norm(f_only)
    z = np.zeros_like(u)
    h = 1e-7          # the third derivative along a random direction is large: h² O(1e3)
    for _ in range(3):
        du = rng.standard_normal(shell.ndofs)
        fd = (shell.energies(u + h * du, z)["strain"] - shell.energies(u - h * du, z)["strain"]) / (2 * h)
        assert abs(f_only @ du - fd) <= 1e-6 * abs(fd)


def test_tangent_is_derivative_of_force(viscous_shell):
    """K = ∂/∂u (f_int + d κ̇ + M_law a) at a large-rotation state with v, a ≠ 0 (the
    viscous and curvature-inertia terms, unsymmetric), and C_law, M_law = ∂/∂v, ∂/∂a;
    relative error of the directional derivative against central differences ≤ 1e-6. The
    weighted pass c_K K + c_C C_law + c_M M_law equals the sum of the three (1e-13)."""
    shell = viscous_shell
    u, rng = _large_rotation_state(shell, seed=1)
    v, a = rng.standard_normal(shell.ndofs), rng.standard_normal(shell.ndofs)
    P = shell.pattern

    def force(x, v=v, a=a):
        f, _, _, Md = _parts(shell, x, v, a)
        return f + P.from_data(Md) @ a

    f, Kd, Cd, Md = _parts(shell, u, v, a)
    weights = (1.3, 250.0, 4.0e4)
    f_w, Jd = shell.internal_forces(u, v, a, weights)
    expected = weights[0] * Kd + weights[1] * Cd + weights[2] * Md
    assert np.abs(Jd - expected).max() <= 1e-13 * np.abs(expected).max()
    assert np.array_equal(f_w, f)
    K = P.from_data(Kd)
    assert abs(K - K.T).max() > 1e-6 * abs(K).max()          # the viscous terms are unsymmetric
    h = 1e-6
    for _ in range(2):
        du = rng.standard_normal(shell.ndofs)
        fd = (force(u + h * du) - force(u - h * du)) / (2 * h)
        assert np.linalg.norm(K @ du - fd) <= 1e-6 * np.linalg.norm(fd)
    dv = rng.standard_normal(shell.ndofs)
    assert np.linalg.norm(P.from_data(Cd) @ dv - (force(u, v + dv) - force(u))) <= \
        1e-10 * np.linalg.norm(P.from_data(Cd) @ dv)
    assert np.linalg.norm(P.from_data(Md) @ dv - (force(u, v, a + dv) - force(u))) <= \
        1e-10 * np.linalg.norm(P.from_data(Md) @ dv)


def test_symmetric_viscous_tangent_is_the_symmetric_part(viscous_shell):
    """``viscous_tangent = "symmetric"``: K is (K + Kᵀ)/2 of the exact tangent (1e-13), the
    force, C_law and M_law are unchanged, and the shell says its tangent is symmetric."""
    full = viscous_shell
    kw = {}
    if full.strain_projection is not None:
        kw = dict(membrane_strain_degree=1, membrane_stabilization=0.05)
    sym = KirchhoffLoveShell(_strip(), _Viscous(), gravity=0.0, **kw)
    assert sym.viscous_tangent == "symmetric" and sym.symmetric_tangent and not full.symmetric_tangent
    u, rng = _large_rotation_state(full, seed=4)
    v, a = rng.standard_normal(full.ndofs), rng.standard_normal(full.ndofs)
    f, Kd, Cd, Md = _parts(full, u, v, a)
    f_s, Kd_s, Cd_s, Md_s = _parts(sym, u, v, a)
    K = full.pattern.from_data(Kd)
    K_s = sym.pattern.from_data(Kd_s)
    assert abs(K_s - 0.5 * (K + K.T)).max() <= 1e-13 * abs(K).max()
    assert abs(K_s - K).max() > 1e-6 * abs(K).max()
    assert np.array_equal(f_s, f)
    for new, ref in ((Cd_s, Cd), (Md_s, Md)):   # symmetric already: the same to round-off
        assert np.abs(new - ref).max() <= 1e-13 * np.abs(ref).max()


def test_viscous_tangent_choice_is_checked():
    with pytest.raises(ShellInputError, match="viscous_tangent"):
        KirchhoffLoveShell(_strip(), _Viscous(), gravity=0.0, viscous_tangent="exact")


def test_elastic_tangent_is_symmetric(viscous_shell):
    """Without rates the tangent is the Hessian of an energy: symmetric to 1e-12."""
    shell = viscous_shell
    u, _ = _large_rotation_state(shell, seed=2)
    K = shell.pattern.from_data(shell.internal_forces(u, weights=K_ONLY)[1])
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()


def test_kernels_match_vectorised_first_variations(viscous_shell):
    """Force, viscous and inertia matrices, strain, curvature and curvature rate against the
    einsum evaluation of :class:`drape.fem.kinematics.KLPoint` (relative 1e-12)."""
    shell = viscous_shell
    u, rng = _large_rotation_state(shell, seed=3, scale=0.3)
    v = rng.standard_normal(shell.ndofs)
    kp = shell.points(u, slice(None))
    eps, kappa = shell.qp_state(u)
    for new, ref in ((eps, kp.strain), (kappa, kp.kappa)):
        assert np.abs(new - ref).max() <= 1e-12 * np.abs(ref).max()
    M, _ = shell.moments(kp.kappa)
    Nm = np.einsum("vw,eqw->eqv", shell.C_m, shell.membrane_strain(kp.strain))
    de, dk = kp.strain_variation(), kp.curvature_variation()
    fe = np.einsum("eqvI,eqv,eq->eI", de, Nm, shell.w) + np.einsum("eqvI,eqv,eq->eI", dk, M, shell.w)
    f_ref = shell.pattern.vector(fe)
    f, _, Cd, Md = _parts(shell, u)
    assert np.linalg.norm(f - f_ref) <= 1e-12 * np.linalg.norm(f_ref)
    for data, k in ((Cd, 0), (Md, 1)):
        coef = shell.sheet_law.viscosity[k]
        Ke = np.einsum("eqvI,eqv,eqvJ->eIJ", dk[:, :, :2], coef * shell.w[..., None], dk[:, :, :2])
        ref = shell.pattern.matrix(Ke).data
        assert np.abs(data - ref).max() <= 1e-12 * np.abs(ref).max()
    ve = v[shell.edofs]
    kdot = np.einsum("eqvI,eI->eqv", dk[:, :, :2], ve) * shell.sheet_law.viscosity[0]
    assert np.abs(shell.viscous_moments(u, v) - kdot).max() <= 1e-12 * np.abs(kdot).max()


def test_linear_stiffness_is_tangent_at_rest(viscous_shell):
    """The flat state's stiffness is the tangent at u = 0 with the laws' k1 (1e-13)."""
    shell = viscous_shell
    K0 = shell.linear_stiffness()
    Kd = shell.internal_forces(np.zeros(shell.ndofs), weights=K_ONLY, elastic_tangent=True)[1]
    assert np.abs(K0.data - Kd).max() <= 1e-13 * np.abs(Kd).max()


def test_friction_tangent_choice_is_checked():
    shell = KirchhoffLoveShell(_strip(), ElasticMaterial(1.0, 1e3), gravity=0.0)
    u = np.zeros(shell.ndofs)
    with pytest.raises(ShellInputError, match="friction_tangent"):
        shell.internal_forces(u, weights=K_ONLY, friction_tangent="secant")
    K1 = shell.internal_forces(u, weights=K_ONLY, friction_tangent="nonnegative")[1]
    assert np.array_equal(K1, shell.internal_forces(u, weights=K_ONLY)[1])     # elastic law: the same tangent


# ---------------------------------------------------------------- quadrature
def _monomial_integral(i, j):
    """∫ x^i y^j over the reference triangle (0,0), (1,0), (0,1)."""
    return factorial(i) * factorial(j) / factorial(i + j + 2)


def test_default_rule_integrates_degree_six_exactly():
    """The shell's default rule (12 points) integrates every monomial of degree ≤ 6 on the
    reference triangle to 1e-14 and not all of degree 7: the bending stiffness of the
    quintic Argyris basis on straight triangles, ∫ ∇∇N · ∇∇N, is of degree 3 + 3 = 6."""
    shell = KirchhoffLoveShell(_strip(), ElasticMaterial(1.0, 1e3), gravity=0.0)
    X, W = shell.basis.quadrature
    assert len(W) == 12
    for d in range(7):
        for i in range(d + 1):
            exact = _monomial_integral(i, d - i)
            assert abs(W @ (X[0] ** i * X[1] ** (d - i)) - exact) <= 1e-14
    errors = [abs(W @ (X[0] ** i * X[1] ** (7 - i)) - _monomial_integral(i, 7 - i)) for i in range(8)]
    assert max(errors) > 1e-8
    # the rule of the next lower degree (7 points) does not integrate degree 6
    X5, W5 = get_quadrature(RefTri, 5)
    assert max(abs(W5 @ (X5[0] ** i * X5[1] ** (6 - i)) - _monomial_integral(i, 6 - i))
               for i in range(7)) > 1e-8


def _bending_stiffness(intorder):
    shell = KirchhoffLoveShell(_strip(), ElasticMaterial(1.0, 1e-9), gravity=0.0, intorder=intorder)
    return shell.linear_stiffness()


def test_bending_stiffness_needs_and_gets_degree_six():
    """The flat-state bending stiffness (membrane negligible) with the default rule equals
    a degree-10 rule's to 1e-12; a degree-5 rule misses it by more than 1e-6."""
    K6, K10, K5 = (_bending_stiffness(o) for o in (6, 10, 5))
    scale = abs(K10).max()
    assert abs(K6 - K10).max() <= 1e-12 * scale
    assert abs(K5 - K10).max() >= 1e-6 * scale


def test_large_deflection_does_not_move_with_a_finer_rule():
    """A cantilever under an end load with a tip rotation of ~40°: the tip deflection with
    the default rule and with a degree-8 rule agree to 1e-4 relative."""
    def tip(intorder):
        mesh = _strip(8, 1, L=1.0, b=0.1)
        shell = KirchhoffLoveShell(mesh, ElasticMaterial(1.0, 1e4), gravity=0.0,
                                   edge_load=lambda t: np.array([0.0, 0.0, 1.0]),
                                   intorder=intorder)
        u = np.zeros(shell.ndofs)
        z = np.zeros_like(u)
        for lam in np.linspace(0.25, 1.0, 4):
            shell.load_scale = lam
            for _ in range(30):
                R, K, _, _ = shell.residual(u, z, z, 1.0)
                du = shell.solve_linear(K, -R)
                u += du
                if np.linalg.norm(du) < 1e-12 * max(1.0, np.linalg.norm(u)):
                    break
        return shell.nodal_displacement(u)[:, 2].max()

    w6, w8 = tip(6), tip(8)
    assert 0.1 < w6 < 0.4                       # PL³/3B = 0.33 linear: a large deflection
    assert abs(w6 - w8) <= 1e-4 * abs(w8)


def test_force_only_evaluation_equals_the_tangent_pass(viscous_shell):
    """evaluate(..., tangent=None) gives the same inertia and force as the tangent pass
    (law viscosity d κ̇ and curvature inertia m κ̈ included, Rayleigh damping on), to 1e-12."""
    shell = viscous_shell
    shell.rayleigh = (3.0, 1e-3)
    u, rng = _large_rotation_state(shell, seed=2)
    v, a = rng.standard_normal(shell.ndofs), rng.standard_normal(shell.ndofs)
    try:
        fast = shell.evaluate(u, v, a, 0.3)
        full = shell.evaluate(u, v, a, 0.3, "consistent")
    finally:
        shell.rayleigh = (0.0, 0.0)
    assert fast.K is None and full.K is not None
    for name in ("inertia", "force"):
        x, y = getattr(fast, name), getattr(full, name)
        assert np.linalg.norm(x - y) <= 1e-12 * np.linalg.norm(y), name
    assert not shell.symmetric_tangent          # viscous terms make K unsymmetric


def test_step_matrix_is_the_weighted_sum_of_K_C_and_M(viscous_shell):
    """evaluate(..., weights) assembles c_K K + c_C C + c_M M in one pass: the same matrix as
    the sum of the separately assembled K, C (Rayleigh damping + the law's viscosity) and M
    (mass + curvature inertia) to 1e-13, with the same forces; weights without K (the start's
    M) skip the kernel where no law term needs it."""
    shell = viscous_shell
    shell.rayleigh = (3.0, 1e-3)
    u, rng = _large_rotation_state(shell, seed=5)
    v, a = rng.standard_normal(shell.ndofs), rng.standard_normal(shell.ndofs)
    try:
        apart = shell.evaluate(u, v, a, 0.3, "consistent")
        for w in ((1.1, 210.0, 3.3e4), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)):
            ev = shell.evaluate(u, v, a, 0.3, "consistent", w)
            assert ev.K is None and ev.C is None and ev.M is None
            expected = w[0] * apart.K + w[1] * apart.C + w[2] * apart.M
            assert abs(ev.J - expected).max() <= 1e-13 * abs(expected).max(), w
            for name in ("inertia", "force"):
                x, y = getattr(ev, name), getattr(apart, name)
                assert np.linalg.norm(x - y) <= 1e-13 * np.linalg.norm(y), (w, name)
    finally:
        shell.rayleigh = (0.0, 0.0)


def test_mass_and_damping_products_match_the_assembled_matrices(viscous_shell):
    """``M a`` and ``C₀ v`` from the scalar mass (applied to the three components at once)
    equal the products with the assembled ``M`` and ``C₀ = αM + βK₀`` on the shared pattern."""
    shell = viscous_shell
    rng = np.random.default_rng(4)
    a, v = rng.standard_normal((2, shell.ndofs))
    assert shell._M_scalar.nnz == np.count_nonzero(shell._M.data) // 3
    Ma, Mv = shell.mass_products(a, v)
    assert np.allclose(Ma, shell._M @ a, rtol=0, atol=1e-15 * np.abs(shell._M @ a).max())
    for alpha, beta in ((3.0, 0.0), (3.0, 0.02)):
        shell.rayleigh = (alpha, beta)
        try:
            C0v = (alpha * shell._M + beta * shell._K0) @ v
            assert np.allclose(shell.damping_force(v, Mv), C0v, rtol=0, atol=1e-14 * np.abs(C0v).max())
        finally:
            shell.rayleigh = (0.0, 0.0)


class _Frictional(_Viscous):
    """Dry friction in both directions (Bliman–Sorine), whose moment depends on the
    committed state."""

    warp = BendingLaw(k1=1.0, friction=FrictionParams(0.3, 0.1, 0.05, 0.5))
    weft = BendingLaw(k1=0.7, friction=FrictionParams(0.2, 0.05, 0.05, 0.5))


def test_point_state_is_kept_for_one_committed_state():
    """The force pass and the tangent pass at one ``u`` share the laws' trial (the kept
    result gives the same numbers as a fresh one); after a commit the trial at that ``u``
    starts from the new committed state, and friction makes its force differ."""
    shell = KirchhoffLoveShell(_strip(), _Frictional(), gravity=0.0)
    u, _ = _large_rotation_state(shell)

    def fresh(*args):
        shell._kept_point = None
        return shell.internal_forces(u, *args)

    f_start = shell.internal_forces(u)[0]
    kept = shell._kept_point
    f, Kd = shell.internal_forces(u, None, None, K_ONLY)
    assert shell._kept_point is kept
    f_fresh, Kd_fresh = fresh(None, None, K_ONLY)
    assert np.array_equal(f, f_fresh) and np.array_equal(Kd, Kd_fresh)

    shell.commit(0.5 * u)
    f_after = shell.internal_forces(u)[0]
    assert np.array_equal(f_after, fresh()[0])
    assert np.linalg.norm(f_after - f_start) > 1e-3 * np.linalg.norm(f_start)
