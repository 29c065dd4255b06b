"""Cusick drape: the seeded fold perturbation and the wiring of the simulated drape test.

Full-resolution drapes (node counts, mesh convergence, material sweep, friction) take minutes
and live in benchmarks/bench_cusick.py. Here: the perturbation field against finite
differences and the clamp, and an end-to-end runner case on a coarse annulus whose settled
shape is checked against the closed-form axisymmetric annular-plate solution.
"""
import json
import math

import numpy as np
import pytest

from drape.models.perturbation import FoldPerturbation, PerturbationError, perturbation_dofs

R, RD = 0.15, 0.09


def ring_points(radius, n=720):
    phi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return phi, radius * np.array([np.cos(phi), np.sin(phi)])


def test_same_seed_same_field_other_seed_other_field():
    x = np.random.default_rng(5).uniform(-R, R, (2, 200))
    a = FoldPerturbation(RD, R, seed=3).value(x)
    b = FoldPerturbation(RD, R, seed=3).value(x)
    c = FoldPerturbation(RD, R, seed=4).value(x)
    assert np.array_equal(a, b)
    assert np.abs(a - c).max() > 1e-4


@pytest.mark.parametrize("n", [3, 7, 10])
def test_lobed_field_has_n_lobes_and_amplitude_on_hem(n):
    from drape.analyses.drape_coefficient import find_nodes

    p = FoldPerturbation(RD, R, kind="lobed", n_lobes=n, amplitude=2e-3, seed=11)
    phi, x = ring_points(R)
    w = p.value(x)
    # 720 samples miss the crest by at most half a sample: relative error <= 1 - cos(n pi / 720)
    assert np.abs(w).max() == pytest.approx(2e-3, rel=1 - np.cos(n * np.pi / 720) + 1e-12)
    assert len(find_nodes(w)[0]) == n
    # quadratic growth from the disc: at mid-overhang a quarter of the hem value
    _, xm = ring_points(0.5 * (R + RD))
    np.testing.assert_allclose(p.value(xm), 0.25 * w, atol=1e-15)


def test_random_field_is_normalised_and_multimodal():
    p = FoldPerturbation(RD, R, kind="random", amplitude=1e-3, k_min=2, k_max=12, seed=0)
    k, c, _ = p.modes()
    assert k.tolist() == list(range(2, 13)) and np.count_nonzero(c) == 11
    _, x = ring_points(R, 4096)
    assert np.abs(p.value(x)).max() == pytest.approx(1e-3, rel=1e-3)


@pytest.mark.parametrize("kind", ["lobed", "random"])
def test_gradient_and_hessian_match_finite_differences(kind):
    p = FoldPerturbation(RD, R, kind=kind, n_lobes=5, amplitude=1e-3, seed=2)
    x = np.random.default_rng(1).uniform(-R, R, (2, 50))
    x = x[:, (np.hypot(*x) > RD + 0.005) & (np.hypot(*x) < R)]
    h = 1e-6
    e = np.eye(2)[:, :, None] * h
    grad_fd = np.array([(p.value(x + e[i]) - p.value(x - e[i])) / (2 * h) for i in range(2)])
    hess_fd = np.array([(p.grad(x + e[i]) - p.grad(x - e[i])) / (2 * h) for i in range(2)])
    scale = 1e-3 / (R - RD)
    np.testing.assert_allclose(p.grad(x), grad_fd, atol=1e-7 * scale)
    np.testing.assert_allclose(p.hess(x), hess_fd, atol=1e-5 * scale / (R - RD))


def test_bad_parameters_name_the_key():
    with pytest.raises(PerturbationError, match="perturbation.kind"):
        FoldPerturbation(RD, R, kind="wavy")
    with pytest.raises(PerturbationError, match="perturbation.target"):
        FoldPerturbation(RD, R, target="wind")
    with pytest.raises(PerturbationError, match="perturbation.duration"):
        FoldPerturbation(RD, R, target="force", duration=0.0)
    with pytest.raises(PerturbationError, match="k_min"):
        FoldPerturbation(RD, R, k_min=5, k_max=3)
    with pytest.raises(PerturbationError, match="disc_radius"):
        FoldPerturbation(R, RD)


def test_dofs_respect_the_disc_clamp_and_reproduce_the_field():
    """Interpolated on the framed Argyris basis of a Cusick annulus, the field has zero
    clamped dofs (w, grad w, w_tt, w_tn vanish on the disc edge) and matches w inside."""
    from skfem import Basis
    from skfem.element import ElementVector

    import meshes
    from drape.fem.argyris import interpolate  # noqa: F401  (frame-aware interpolation used inside)
    from drape.fem.boundary import argyris_element, clamped_dofs

    mesh = meshes.cusick_annulus(0.30, 0.18, n_radial=3, n_circumferential=48)
    elem = argyris_element(mesh, {"disc": "clamped"})
    basis = Basis(mesh, elem)
    fixed = clamped_dofs(Basis(mesh, ElementVector(elem, 3)), ["disc"])
    p = FoldPerturbation(RD, R, kind="lobed", n_lobes=6, amplitude=1e-3, seed=0)
    x0 = perturbation_dofs(basis, p)
    assert np.abs(x0[fixed]).max() < 1e-15
    assert np.abs(x0[0::3]).max() == 0 and np.abs(x0[1::3]).max() == 0
    w_h = basis.interpolate(x0[2::3])
    w = p.value(np.asarray(basis.global_coordinates()))
    # quintic interpolation of cos(6 phi) on 48 sectors: well under 1 % of the amplitude
    assert np.abs(np.asarray(w_h) - w).max() < 1e-2 * 1e-3


def test_force_perturbation_load_vector_does_the_analytic_work():
    """The shell's load vector of the "force" target, dotted with the interpolated field w
    with unit amplitude, is int f_z w dA = A rho_A g pi int_rd^R s^2 rho drho for one lobe
    cos(k phi + phi0) (int cos^2 = pi), with s = xi^2, xi = (rho - r_d)/L:
    int xi^4 rho drho = L (r_d/5 + L/6)."""
    from drape.models.shell import ElasticMaterial, KirchhoffLoveShell

    import meshes

    mesh = meshes.cusick_annulus(0.30, 0.18, n_radial=3, n_circumferential=48)
    rho_g = 2.0
    p = FoldPerturbation(RD, R, kind="lobed", n_lobes=4, amplitude=0.05, seed=1, target="force")
    shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-6, membrane=1e3, areal_mass=1.0),
                               clamped=("disc",), gravity=0.0,
                               surface_load=(lambda x: p.traction(x, rho_g), p.time_profile))
    w_dofs = perturbation_dofs(shell.basis, FoldPerturbation(RD, R, kind="lobed", n_lobes=4,
                                                               amplitude=1.0, seed=1))
    L = R - RD
    radial = L * (RD / 5 + L / 6)
    expected = p.amplitude * rho_g * np.pi * radial
    work = shell.external_force(np.zeros(shell.ndofs), 0.5 * p.duration) @ w_dofs
    # the same integral of the exact fields over the mesh's (polygonal) annulus
    from skfem import Basis, ElementTriP1, Functional

    on_mesh = Functional(lambda w: p.traction(w.x, rho_g)[2] * p.value(w.x) / p.amplitude
                         ).assemble(Basis(mesh, ElementTriP1(), intorder=10))
    assert work == pytest.approx(on_mesh, rel=1e-3)       # quintic interpolant of w
    # the 48-gon hem misses 1.9 % of the xi^4-weighted annulus (O(n^-2): 0.48 % at 96)
    assert on_mesh == pytest.approx(expected, rel=0.025)
    # the load is transient: gone at t = 0 and after the duration
    for t in (0.0, p.duration, 2 * p.duration):
        assert np.abs(shell.external_force(np.zeros(shell.ndofs), t)).max() == 0.0


def test_uniform_surface_load_equals_gravity():
    """A uniform traction -rho_A g e_z through ``surface_load`` is the self-weight vector."""
    from skfem import MeshTri

    from drape.models.shell import ElasticMaterial, KirchhoffLoveShell

    mesh = MeshTri.init_tensor(np.linspace(0, 0.1, 4), np.linspace(0, 0.05, 3))
    mesh = mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9})
    mat = ElasticMaterial(bending=1e-6, membrane=1e3, areal_mass=0.2)
    weight = lambda x: np.stack([0 * x[0], 0 * x[0], -0.2 * 9.80665 + 0 * x[0]])  # noqa: E731
    a = KirchhoffLoveShell(mesh, mat, gravity=1.0)
    b = KirchhoffLoveShell(mesh, mat, gravity=0.0, surface_load=(weight, 1.0))
    u = np.zeros(a.ndofs)
    np.testing.assert_allclose(b.external_force(u, 0.3), a.external_force(u, 0.3), atol=1e-15)
    # total weight: the z components against a unit rigid translation
    tz = np.zeros(a.ndofs)
    tz[2::3][a.basis.nodal_dofs[0]] = 1.0
    assert a.external_force(u, 0.0) @ tz == pytest.approx(-0.2 * 9.80665 * 0.1 * 0.05, rel=1e-12)


def test_force_target_starts_at_rest_with_a_transient_load(tmp_path):
    """target = "force": no initial displacement or velocity; the shell carries the load and
    the settling rule waits until the load is gone (LoadSpec.end_time)."""
    from drape.case.case import parse_case
    from drape.run.runner import build, initial_fields

    case = parse_case({
        "case": {"name": "cusick_force", "analysis": "cusick"},
        "mesh": {"kind": "cusick", "specimen_diameter": 0.30, "disc_diameter": 0.18,
                 "n_radial": 2, "n_circumferential": 24},
        "material": {"name": "fabric1"},
        "model": {"kinematics": "large", "supports": {"disc": "clamped"}},
        "load": {"gravity": {"ramp_time": 0.2},
                 "perturbation": {"target": "force", "amplitude": 0.05, "duration": 0.5}},
        "solver": {"dt": 0.01, "t_end": 1.0},
    })
    assert case.load.end_time() == pytest.approx(0.5)
    parts = build(case)
    assert initial_fields(case, parts.model) == (None, None)
    model = parts.model
    f = model.external_force(np.zeros(model.ndofs), 0.25)
    g = model.external_force(np.zeros(model.ndofs), 0.75)   # gravity alone
    # the perturbation's work on the virtual displacement (0, 0, x²) (exact in the Argyris
    # space) against an independent quadrature of ρ_A g w(x) h(t) x² over the mesh triangles
    from skfem import Basis, ElementTriP1

    from drape.case.build import fold_perturbation

    zero = lambda x: np.zeros(x.shape[1:])      # noqa: E731
    psi = model.interpolate(
        lambda x: np.stack([zero(x), zero(x), x[0] ** 2]),
        lambda x: np.stack([np.zeros((2,) + x.shape[1:])] * 2 + [np.stack([2 * x[0], zero(x)])]),
        lambda x: np.stack([np.zeros((2, 2) + x.shape[1:])] * 2
                           + [np.array([[zero(x) + 2, zero(x)], [zero(x), zero(x)]])]))
    fold = fold_perturbation(case)
    quad = Basis(parts.mesh, ElementTriP1(), intorder=12)
    x = np.asarray(quad.global_coordinates())
    weight = parts.material.areal_mass * 9.80665
    expected = fold.time_profile(0.25) * np.sum(fold.traction(x, weight)[2] * x[0] ** 2 * quad.dx)
    assert abs(expected) > 0
    assert (f - g) @ psi == pytest.approx(expected, rel=1e-4)


# ------------------------------------------------------------------ end-to-end (runner)
def annular_plate_deflection(r, q, D, a=R, b=RD, nu=0.0):
    """Closed-form axisymmetric Kirchhoff plate: clamped at r = b, free at r = a, load q (+z).

    w = C1 + C2 ln r + C3 r^2 + C4 r^2 ln r + q r^4 / (64 D); w(b) = w'(b) = 0,
    M_r(a) = 0, Q_r(a) = 0.
    """
    def parts(x):  # columns: C1..C4 and the particular solution; rows: w, w', w'', w'''
        ln = math.log(x)
        return np.array([
            [1, ln, x**2, x**2 * ln, q * x**4 / (64 * D)],
            [0, 1 / x, 2 * x, 2 * x * ln + x, q * x**3 / (16 * D)],
            [0, -1 / x**2, 2, 2 * ln + 3, 3 * q * x**2 / (16 * D)],
            [0, 2 / x**3, 0, 2 / x, 6 * q * x / (16 * D)],
        ])
    pb, pa = parts(b), parts(a)
    rows = [pb[0], pb[1], pa[2] + nu * pa[1] / a, pa[3] + pa[2] / a - pa[1] / a**2]
    A = np.array([row[:4] for row in rows])
    rhs = -np.array([row[4] for row in rows])
    c = np.linalg.solve(A, rhs)
    return np.array([np.dot(parts(x)[0, :4], c) + parts(x)[0, 4] for x in np.atleast_1d(r)])


def stiff_case(tmp_path, k1):
    from drape.case.case import parse_case

    return parse_case({
        "case": {"name": "cusick_stiff", "analysis": "cusick"},
        "mesh": {"kind": "cusick", "specimen_diameter": 0.30, "disc_diameter": 0.18,
                 "n_radial": 2, "n_circumferential": 24},
        "material": {"name": "fabric1", "friction": False, "k1": k1, "k3": 0.0, "d": 0.0},
        "model": {"kinematics": "large", "supports": {"disc": "clamped"}},
        "load": {"gravity": {"ramp_time": 1.0}},
        "solver": {"dt": 0.5, "t_end": 1.0, "quasi_static": True},
        "output": {"every": 100},
    })


def test_stiff_fabric_hangs_like_the_annular_plate_and_keeps_dc_near_one(tmp_path):
    """Bending length (k1/(rho_A g))^(1/3) = 18 cm >> 6 cm overhang: small deflection, so the
    settled hem deflection equals the closed-form plate value (isotropic, nu = 0: the shell's
    default twist rigidity sqrt(k1 k1) is the nu = 0 plate), and DC stays ~100 %."""
    from drape.run.runner import run_case

    k1 = 1e-2
    case = stiff_case(tmp_path, k1)
    summary = run_case(case, tmp_path, quiet=True)
    assert summary["status"] == "completed"
    import meshio

    from constitutive.material import load_material
    from drape.run.output import read_pvd

    last = read_pvd(tmp_path / "cusick_stiff.pvd")[-1][1]
    m = meshio.read(last)
    disp = m.point_data["displacement"]
    rho = np.hypot(m.points[:, 0], m.points[:, 1])
    hem = rho > R - 1e-9
    rho_A = load_material("fabric1").areal_mass
    w_ref = annular_plate_deflection(R, -rho_A * 9.80665, k1)[0]
    # coarse 2 x 24 annulus: the polygonal disc edge and hem cost ~2 % (C: 1.4 % at refine=1)
    np.testing.assert_allclose(disp[hem, 2], w_ref, rtol=0.04)
    a = summary["analysis"]
    assert a["n_nodes"] == 0
    # DC of the flat 24-gon hem (the mesh's own 100 %), minus what a 0.3 mm sag can take away
    dc_flat = (0.5 * 24 * R**2 * np.sin(2 * np.pi / 24) - np.pi * RD**2) / (np.pi * (R**2 - RD**2))
    assert a["drape_coefficient"] == pytest.approx(dc_flat, abs=1e-3)
    # measured on the sampled Argyris surface; the vertex triangles agree for so flat a sag
    assert a["drape_coefficient_vertices_percent"] == pytest.approx(100 * dc_flat, abs=0.1)
    assert (tmp_path / "cusick_stiff_top_view.png").exists()
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert saved["analysis"]["drape_coefficient"] == pytest.approx(a["drape_coefficient"])
