"""Large-rotation shell against closed-form and published large-deflection results."""

import numpy as np
import pytest
from skfem import MeshTri

from drape.solvers.static import quasi_static
from constitutive.conventions import CURVATURE_SIGN
from drape.models.shell import ElasticMaterial, KirchhoffLoveShell


def _strip(L, b, nx, ny=1):
    mesh = MeshTri.init_tensor(np.linspace(0, L, nx + 1), np.linspace(0, b, ny + 1))
    return mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9 * L,
                                 "free": lambda x: x[0] > L * (1 - 1e-9)})


#: Membrane strain variants (degree, stabilisation γ): consistent, assumed cubic, and the
#: stabilised linear one of the Cusick cases.
ASSUMED_STRAINS = [(None, 0.0), (3, 0.0), (1, 0.05)]


def _tip(model, u):
    d = model.nodal_displacement(u)
    return d[model.mesh.p[0] > model.mesh.p[0].max() * (1 - 1e-9)].mean(axis=0)


@pytest.mark.parametrize("strain_degree, stabilization", ASSUMED_STRAINS)
def test_rollup_under_follower_end_moment(strain_degree, stabilization):
    """Roll-up (elastica, docs/theory.md §5): θ = ML/B, u = −L(1 − sin θ/θ), w = L(1 − cos θ)/θ.

    Tip within 0.5 % of L at M/M_max = 0.5 and 1.0 (M_max = 2πB/L closes a circle).
    Membrane stiffness E h L²/B = 1e6 (nearly inextensible); also with the assumed strains.
    """
    L, b, B = 1.0, 0.1, 1.0
    Mmax = 2 * np.pi * B / L
    shell = KirchhoffLoveShell(_strip(L, b, 8), ElasticMaterial(bending=B, membrane=1e6),
                               gravity=0.0, end_moment=Mmax, membrane_strain_degree=strain_degree,
                               membrane_stabilization=stabilization)
    checks = {}

    def record(state, info):
        checks[round(shell.load_scale, 6)] = _tip(shell, state.u)

    quasi_static(shell, np.linspace(0.1, 1.0, 10), on_step=record)
    for lam in (0.5, 1.0):
        th = lam * Mmax * L / B
        exact = np.array([-L * (1 - np.sin(th) / th), 0.0, L * (1 - np.cos(th)) / th])
        assert np.linalg.norm(checks[lam] - exact) <= 0.005 * L


def test_assumed_strain_relieves_locking_of_a_coarse_rollup():
    """Three triangles' length rolled into a full circle (M = 2πB/L): the quintic's own
    membrane strain cannot vanish on so coarse an arc (tip error 2.3e-3 L); the stabilised
    linear assumed strain (degree 1, γ = 0.05) must reach the analytic tip within 1e-3 L."""
    L, b, B = 1.0, 0.1, 1.0
    shell = KirchhoffLoveShell(_strip(L, b, 3), ElasticMaterial(bending=B, membrane=1e6),
                               gravity=0.0, end_moment=2 * np.pi * B / L,
                               membrane_strain_degree=1, membrane_stabilization=0.05)
    tip = _tip(shell, quasi_static(shell, np.linspace(0.1, 1.0, 10)).u)
    assert np.linalg.norm(tip - np.array([-L, 0.0, 0.0])) <= 1e-3 * L


@pytest.mark.parametrize("strain_degree, stabilization", ASSUMED_STRAINS)
def test_sze_cantilever_under_end_shear(strain_degree, stabilization):
    """Sze, Liu & Lo (2004) cantilever strip: L = 10, b = 1, h = 0.1, E = 1.2e6, ν = 0,
    P_max = 4 (dead, vertical); published tip (−u, w) = (1.604, 4.933) at P/P_max = 0.5
    and (3.286, 6.698) at 1.0. Tolerance 1 %. Also with the membrane strain projected on
    cubics, and on linears with 5 % of the rest kept (``membrane_strain_degree``,
    ``membrane_stabilization``)."""
    L, b, h, E = 10.0, 1.0, 0.1, 1.2e6
    shell = KirchhoffLoveShell(_strip(L, b, 8), ElasticMaterial(bending=E * h ** 3 / 12, membrane=E * h),
                               gravity=0.0, edge_load=np.array([0.0, 0.0, 4.0 / b]),
                               membrane_strain_degree=strain_degree,
                               membrane_stabilization=stabilization)
    tips = {}
    quasi_static(shell, np.linspace(0.1, 1.0, 10),
                 on_step=lambda s, i: tips.__setitem__(round(shell.load_scale, 6), _tip(shell, s.u)))
    for lam, (mu, w) in {0.5: (1.604, 4.933), 1.0: (3.286, 6.698)}.items():
        assert -tips[lam][0] == pytest.approx(mu, rel=0.01)
        assert tips[lam][2] == pytest.approx(w, rel=0.01)


def test_small_load_limit_agrees_with_small_deflection_plate():
    """Same mesh, element, fabric (cubic + friction law) and a tiny self-weight:
    tip deflection and cell curvatures agree with drape.models.plate.KirchhoffPlate to 1e-3
    (geometric nonlinearity is O((w/L)²) ~ 5e-5 here)."""
    from constitutive.friction import FrictionParams
    from drape.models.plate import KirchhoffPlate, demo_material
    L, b = 0.05, 0.02
    mesh = _strip(L, b, 6, 2)
    mat = demo_material(B=1e-5, areal_mass=0.2, k3=1e-8,
                        friction=FrictionParams(2e-6, 1e-6, 1e-2, 0.5))
    plate = KirchhoffPlate(mesh, mat, element="argyris", supports={"clamped": "clamped"})
    shell = KirchhoffLoveShell(mesh, mat)
    lams = [1e-3, 3e-3]     # tip deflection ~ 0.005 L: friction ~ 30 % of the root moment
    up = quasi_static(plate, lams).u
    # stick friction makes the strip ~1e3x stiffer: |du|/|u| bottoms out near 4e-9 (round-off)
    us = quasi_static(shell, lams, du_rtol=1e-7).u
    wp = plate.fields(up, 0 * up, 0 * up)["point_data"]["displacement"]
    ws = shell.fields(us)["point_data"]["displacement"]
    tip = mesh.p[0] > L * (1 - 1e-9)
    assert ws[tip, 2].mean() == pytest.approx(wp[tip, 2].mean(), rel=1e-3)
    assert abs(ws[tip, 2].mean()) > 1e-3 * L          # not a trivially small answer
    kp = plate.fields(up, 0 * up, 0 * up)["cell_data"]["curvature_xx"]
    ks = shell.fields(us)["cell_data"]["curvature_xx"]
    # one convention (constitutive.conventions): plate κ = s w_,xx, shell κ = s u_,xx · n ≈ s w_,xx
    assert np.linalg.norm(ks - kp) <= 1e-3 * np.linalg.norm(kp)


def test_bad_input_names_the_parameter():
    """Errors name the offending key and the rule."""
    from drape.models.shell import ShellInputError
    mesh = _strip(1.0, 0.1, 2)
    with pytest.raises(ShellInputError, match="clamped boundary 'wall'"):
        KirchhoffLoveShell(mesh, ElasticMaterial(1.0, 1.0), clamped=("wall",))
    with pytest.raises(ShellInputError, match="load_boundary 'tip'"):
        KirchhoffLoveShell(mesh, ElasticMaterial(1.0, 1.0), end_moment=1.0, load_boundary="tip")
    with pytest.raises(ShellInputError, match="rayleigh"):
        KirchhoffLoveShell(mesh, ElasticMaterial(1.0, 1.0), rayleigh=(-1.0, 0.0))
    with pytest.raises(ShellInputError, match="bending must be > 0"):
        ElasticMaterial(bending=0.0, membrane=1.0)


def test_undamped_swing_conserves_energy():
    """Strip released flat under full gravity, no damping or friction, trapezoidal
    Newmark (drape.solvers.time_stepping.integrate): kinetic + strain + gravity potential stays
    at its initial value 0 within 0.5 % of the strain energy at the bottom of the swing."""
    from drape.solvers.time_stepping import integrate
    L, b, B = 1.0, 0.2, 1.0
    shell = KirchhoffLoveShell(_strip(L, b, 4), ElasticMaterial(bending=B, membrane=1e4,
                                                             areal_mass=8.0 / 9.80665))
    hist = []

    def record(state, info):
        hist.append(shell.energies(state.u, state.v))

    integrate(shell, 0.6, 0.01, on_step=record)
    total = np.array([h["total"] for h in hist])
    strain = max(h["strain"] for h in hist)
    assert strain > 0.1                                  # a large swing (α = 8)
    assert np.abs(total).max() <= 0.005 * strain


def test_unloading_leaves_curvature_held_by_friction():
    """Load the Fabric 1 cantilever to full self-weight and unload it quasi-statically.

    Statics of an unloaded cantilever: the bending moment vanishes at every section, so
    the residual curvature must be held by friction alone: k1 κ + k3 κ³ = −M_f. Checked:
    total cell moment ≤ 1e-3 of the friction moment while the tip stays > 1 mm down; the
    same path without friction returns to flat (tip ≤ 1e-9 m)."""
    from constitutive.law import BendingLaw
    from constitutive.material import load_material
    from meshes import strip
    mat = load_material("fabric1")
    path = list(np.linspace(0.1, 1.0, 10)) + list(np.linspace(0.9, 0.0, 10))
    shell = KirchhoffLoveShell(strip(0.0163, 0.025, 3, 1), mat, load_boundary="free_end")
    u = quasi_static(shell, path, du_rtol=1e-7).u
    cells = shell.fields(u)["cell_data"]
    assert shell.nodal_displacement(u)[:, 2].min() < -1e-3
    Mf = np.abs(cells["friction_moment_xx"]).max()
    assert Mf > 0 and np.abs(cells["moment_xx"]).max() <= 1e-3 * Mf

    elastic = mat.replace(warp=BendingLaw(k1=mat.warp.k1, k3=mat.warp.k3),
                          weft=BendingLaw(k1=mat.weft.k1, k3=mat.weft.k3))
    shell = KirchhoffLoveShell(strip(0.0163, 0.025, 3, 1), elastic, load_boundary="free_end")
    u = quasi_static(shell, path, du_rtol=1e-7).u
    assert np.abs(shell.nodal_displacement(u)).max() <= 1e-9


def test_energy_balance_with_friction_viscosity_and_damping():
    """Fabric 1 cantilever dropped under full gravity with Rayleigh damping:
    kinetic + strain + gravity potential + friction work + damping work (Rayleigh and
    the law's d κ̇) stays at 0 within 1 % of the potential released."""
    from constitutive.material import load_material
    from drape.solvers.time_stepping import integrate
    from meshes import strip
    shell = KirchhoffLoveShell(strip(0.0163, 0.025, 3, 1), load_material("fabric1"),
                               load_boundary="free_end", rayleigh=(5.0, 0.0))
    hist = []
    integrate(shell, 0.2, 0.005, on_step=lambda s, i: hist.append(shell.energies(s.u, s.v)))
    last = hist[-1]
    assert last["friction_work"] > 0 and last["damping_work"] > 0
    released = -min(h["external_potential"] for h in hist)
    assert max(abs(h["total"]) for h in hist) <= 0.01 * released


def test_small_amplitude_vibration_frequency():
    """Free vibration from a small tip-loaded shape (no gravity, no damping): the period
    of the tip motion equals the Euler–Bernoulli cantilever's 2π/ω1,
    ω1 = 1.8751² / L² √(B/ρ_A) (docs/theory.md §5), within 1 % (Newmark period error ~0.1 %)."""
    from drape.solvers.newmark import NewmarkState
    from drape.solvers.time_stepping import integrate
    L, b, B, rho = 1.0, 0.1, 1.0, 1.0
    shell = KirchhoffLoveShell(_strip(L, b, 8), ElasticMaterial(bending=B, membrane=1e6,
                                                             areal_mass=rho),
                               gravity=0.0, edge_load=np.array([0.0, 0.0, 1e-4]))
    u0 = quasi_static(shell, [1.0]).u
    shell.load_scale = 0.0                              # release
    T = 2 * np.pi / (1.8751 ** 2 / L ** 2 * np.sqrt(B / rho))
    hist = []
    z = np.zeros_like(u0)
    # atol: round-off floor of the residual (~4e-12 N, stiff membrane) vs tip force 1e-5 N
    integrate(shell, 1.6 * T, T / 60, state=NewmarkState(0.0, u0, z, z), atol=1e-10,
              on_step=lambda s, i: hist.append((s.t, _tip(shell, s.u)[2])))
    t, w = np.array(hist).T
    i = np.nonzero((w[:-1] > 0) & (w[1:] <= 0) | (w[:-1] < 0) & (w[1:] >= 0))[0]
    crossings = t[i] - w[i] * (t[i + 1] - t[i]) / (w[i + 1] - w[i])
    assert len(crossings) >= 3
    assert 2 * np.diff(crossings).mean() == pytest.approx(T, rel=0.01)


def test_deformed_surface_shadow_resolves_curved_triangles():
    """Unit square (2 × 2 cells) stretched by u_x = a x y (1 − y): its exact area is
    1 + a/6. The vertex triangles see y (1 − y) only at y = 0, ½, 1 (area 1 + a/8); the
    surface sampled on 16 sub-triangles per cell (refine = 2) must be ten times closer."""
    from drape.analyses.drape_coefficient import shadow_polygon
    a = 0.6
    mesh = MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    shell = KirchhoffLoveShell(mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9}),
                               ElasticMaterial(bending=1.0, membrane=1.0))
    z = lambda x: 0 * x[0]
    u = shell.interpolate(
        lambda x: np.array([a * x[0] * x[1] * (1 - x[1]), z(x), z(x)]),
        lambda x: np.array([[a * x[1] * (1 - x[1]), a * x[0] * (1 - 2 * x[1])], [z(x), z(x)], [z(x), z(x)]]),
        lambda x: np.array([[[z(x), a * (1 - 2 * x[1])], [a * (1 - 2 * x[1]), -2 * a * x[0]]],
                            [[z(x), z(x)], [z(x), z(x)]], [[z(x), z(x)], [z(x), z(x)]]]))
    exact = 1 + a / 6
    vertices = shell.nodal_displacement(u)[:, :2] + mesh.p.T
    vertex_area = shadow_polygon(vertices, mesh.t.T).area
    assert vertex_area == pytest.approx(1 + a / 8, rel=1e-9)
    pts, tri = shell.deformed_surface(u, refine=2)
    assert tri.shape == (mesh.t.shape[1] * 16, 3)
    assert abs(shadow_polygon(pts, tri).area - exact) <= 0.1 * abs(vertex_area - exact)
