"""Verification of the small-deflection Kirchhoff plate (drape/models/plate.py) against independent references.

References: Euler–Bernoulli beam (tip qL⁴/(8B), first frequency 1.8751²/L² √(B/ρ_A)),
clamped square plate centre deflection 0.00126 q a⁴/D (Timoshenko & Woinowsky-Krieger,
Table 35; 0.00126532 to six digits, Taylor & Govindjee 2004), the statically
determinate cantilever with the cubic + friction law solved by quadrature, and
finite differences for the consistent tangent.
"""
import numpy as np
import pytest
import scipy.sparse.linalg as spla
import skfem
from scipy.integrate import quad
from scipy.optimize import brentq

from constitutive.friction import FrictionParams, closed_form_from_rest
from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial
from drape.solvers.newmark import initial_state
from drape.solvers.static import quasi_static
from drape.solvers.time_stepping import integrate
from constitutive.units import G0
from drape.models.plate import KirchhoffPlate, PlateInputError, pure_bending_rotations

B = 2.0e-5        # N·m, bending rigidity (a mid-weight fabric)
RHO = 0.2         # kg/m²
L, W = 0.02, 0.005  # m, strip length and width (tip deflection ~1 mm: small)


def material(k1=B, rho=RHO, **law_kw):
    law = BendingLaw(k1=k1, **law_kw)
    return FabricMaterial("test", rho, None, law, law, twist_rigidity=k1)


def strip(nx, ny, length=L, width=W):
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, length, nx + 1), np.linspace(0, width, ny + 1))
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0.0),
        "right": lambda x: np.isclose(x[0], length),
    })


def tip_deflection(plate, u, length=L):
    mesh = plate.mesh
    return float(np.mean(u[plate.vertex_dofs][np.isclose(mesh.p[0], length)]))


# --------------------------------------------------------------------------- statics
def test_cantilever_morley_tip_and_convergence():
    """Tip w = ρ_A g L⁴/(8B) within 1 %; the error falls under uniform refinement (O(h²))."""
    exact = -RHO * G0 * L**4 / (8 * B)
    errors = []
    for nx, ny in [(8, 2), (16, 4), (32, 8)]:
        plate = KirchhoffPlate(strip(nx, ny), material(), supports={"left": "clamped"})
        u = quasi_static(plate, [1.0]).u
        errors.append(abs(tip_deflection(plate, u) / exact - 1))
    assert errors[-1] < 0.01
    assert errors[0] > errors[1] > errors[2]
    assert errors[1] / errors[2] > 3.0  # second order


def test_cantilever_argyris_tip_exact():
    """The beam solution is a quartic, inside the quintic Argyris space: tip exact to 1e-8."""
    exact = -RHO * G0 * L**4 / (8 * B)
    plate = KirchhoffPlate(strip(4, 1), material(), element="argyris", supports={"left": "clamped"})
    u = quasi_static(plate, [1.0]).u
    assert abs(tip_deflection(plate, u) / exact - 1) < 1e-8


def square(n, a=1.0):
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, a, n + 1), np.linspace(0, a, n + 1))
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0), "right": lambda x: np.isclose(x[0], a),
        "bottom": lambda x: np.isclose(x[1], 0), "top": lambda x: np.isclose(x[1], a),
    })


@pytest.mark.parametrize("element, sizes", [("morley", (16, 32, 64)), ("argyris", (2, 4, 8))])
def test_clamped_square_plate(element, sizes):
    """Centre 0.00126 q a⁴/D within 1 % on the finest mesh; error vs 0.00126532 falls with refinement."""
    a, q, D = 1.0, 1.0, 1.0
    errors = []
    for n in sizes:
        mesh = square(n, a)
        plate = KirchhoffPlate(mesh, material(k1=D), element=element, gravity=0.0, pressure=q,
                               supports={k: "clamped" for k in ("left", "right", "bottom", "top")})
        u = quasi_static(plate, [1.0]).u
        centre = np.flatnonzero(np.isclose(mesh.p[0], a / 2) & np.isclose(mesh.p[1], a / 2))
        w = float(u[plate.vertex_dofs][centre][0]) * D / (q * a**4)
        errors.append(abs(w / 0.00126532 - 1))
    assert abs(w / 0.00126 - 1) < 0.01
    assert errors[0] > errors[1] > errors[2]


def test_cubic_friction_cantilever_against_quadrature():
    """Monotone loading from rest: κ(x) from k1 κ + k3 κ³ + M_f(κ) = ρ_A g (L−x)²/2, tip by quadrature.

    The moment is statically determinate, the friction moment along a monotone
    path from rest is the closed form 3.17 (constitutive.friction), so
    w_tip = −∫ κ(x) (L − x) dx. Argyris, one load step; within 0.5 %.
    """
    fp = FrictionParams(f1=2e-3, f2=1e-3, eps_f=5.0, eta=0.5)
    law_kw = dict(k3=2e-8, friction=fp)
    plate = KirchhoffPlate(strip(12, 1), material(**law_kw), element="argyris", supports={"left": "clamped"})
    u = quasi_static(plate, [1.0]).u
    law = BendingLaw(k1=B, **law_kw)

    def kappa(x):
        M = RHO * G0 * (L - x) ** 2 / 2
        f = lambda k: law.elastic(k)[0] + closed_form_from_rest(fp, k) - M  # noqa: E731
        return brentq(f, 0.0, 1e4) if M > 0 else 0.0

    exact = -quad(lambda x: kappa(x) * (L - x), 0, L, limit=200)[0]
    assert abs(tip_deflection(plate, u) / exact - 1) < 5e-3
    # the nonlinear terms matter here: the linear answer is far off
    assert abs(-RHO * G0 * L**4 / (8 * B) / exact - 1) > 0.05


def test_consistent_tangent_matches_finite_differences():
    """K from residual() equals dR/du by central differences (cubic + friction after a reversal)."""
    fp = FrictionParams(f1=1e-3, f2=4e-4, eps_f=2.0, eta=0.3)
    plate = KirchhoffPlate(strip(4, 2), material(k3=1e-7, friction=fp), element="argyris",
                           supports={"left": "clamped"})
    rng = np.random.default_rng(0)
    u1 = 1e-3 * rng.standard_normal(plate.ndofs)
    plate.commit(u1, 0 * u1, 0 * u1)          # some history
    u = 0.5 * u1 + 2e-4 * rng.standard_normal(plate.ndofs)
    z = np.zeros(plate.ndofs)
    _, K, _, _ = plate.residual(u, z, z, 0.0)
    du = rng.standard_normal(plate.ndofs)
    h = 1e-9
    fd = (plate.residual(u + h * du, z, z, 0.0)[0] - plate.residual(u - h * du, z, z, 0.0)[0]) / (2 * h)
    assert np.linalg.norm(K @ du - fd) < 1e-5 * np.linalg.norm(fd)


# --------------------------------------------------------------------------- dynamics
@pytest.mark.parametrize("element, mesh_n", [("morley", (24, 2)), ("argyris", (6, 1))])
def test_first_frequency_cantilever(element, mesh_n):
    """Lowest eigenvalue of (K, M) on the free dofs: ω1 = 1.8751²/L² √(B/ρ_A) within 1 %."""
    plate = KirchhoffPlate(strip(*mesh_n), material(), element=element, supports={"left": "clamped"})
    free = np.setdiff1d(np.arange(plate.ndofs), plate.fixed_dofs)
    K = plate.K0[free][:, free]
    M = plate.M[free][:, free]
    lam = spla.eigsh(K.tocsc(), k=1, M=M.tocsc(), sigma=0, which="LM", return_eigenvectors=False)
    omega = float(np.sqrt(lam[0]))
    exact = 1.8751**2 / L**2 * np.sqrt(B / RHO)
    assert abs(omega / exact - 1) < 0.01


@pytest.mark.parametrize("law_d, rayleigh", [(3e-7, (0.0, 0.0)), (0.0, (0.0, 2e-3)), (0.0, (4.0, 0.0))])
def test_damping_matrices_give_the_beam_modal_damping(law_d, rayleigh):
    """Modal damping ratio of mode 1, ζ = φᵀCφ / (2 √(φᵀKφ φᵀMφ)), against the beam values:
    law d (thesis 5.45, C = d ∫ B_xx B_xxᵀ): ζ = d ω1 / (2 B); Rayleigh β K0: ζ = β ω1 / 2;
    Rayleigh α M: ζ = α / (2 ω1); within 1 % (ω1 from Euler–Bernoulli)."""
    plate = KirchhoffPlate(strip(6, 1), material(d=law_d), element="argyris", supports={"left": "clamped"},
                           rayleigh=rayleigh)
    free = np.setdiff1d(np.arange(plate.ndofs), plate.fixed_dofs)
    K, M, C = (A[free][:, free].tocsc() for A in (plate.K0, plate.M, plate.C))
    _, phi = spla.eigsh(K, k=1, M=M, sigma=0, which="LM")
    phi = phi[:, 0]
    zeta = (phi @ C @ phi) / (2 * np.sqrt((phi @ K @ phi) * (phi @ M @ phi)))
    omega = 1.8751**2 / L**2 * np.sqrt(B / RHO)
    alpha, beta = rayleigh
    expected = law_d * omega / (2 * B) + beta * omega / 2 + alpha / (2 * omega)
    assert abs(zeta / expected - 1) < 0.01


def test_air_drag_is_mass_damping_over_the_areal_mass():
    """``[model.damping] air_drag = c`` (a drag c v per unit area) gives mode 1 of a cantilever
    the damping ratio ζ = c / (2 ρ_A ω1) + d ω1 / (2 k1) (drag plus the law's viscosity), within
    1 %, through the case path (ω1 of the Euler–Bernoulli beam)."""
    from drape.case.build import build
    from drape.case.case import parse_case

    c, length = 0.3, 0.1      # long: the drag term dominates the law's
    case = parse_case({
        "case": {"name": "drag"}, "material": {"name": "fabric1", "friction": False},
        "mesh": {"kind": "strip", "length": length, "width": 0.01, "nx": 6, "ny": 1,
                 "element": "argyris"},
        "model": {"supports": {"clamped": "clamped"}, "damping": {"air_drag": f"{c} N*s/m^3"}},
        "solver": {"dt": 0.01, "t_end": 0.1}})
    parts = build(case)
    plate = parts.model
    free = np.setdiff1d(np.arange(plate.ndofs), plate.fixed_dofs)
    K, M, C = (A[free][:, free].tocsc() for A in (plate.K0, plate.M, plate.C))
    _, phi = spla.eigsh(K, k=1, M=M, sigma=0, which="LM")
    phi = phi[:, 0]
    zeta = (phi @ C @ phi) / (2 * np.sqrt((phi @ K @ phi) * (phi @ M @ phi)))
    rho, law = parts.material.areal_mass, parts.material.warp
    omega = 1.8751**2 / length**2 * np.sqrt(law.k1 / rho)
    assert abs(zeta / (c / (2 * rho * omega) + law.d * omega / (2 * law.k1)) - 1) < 0.01


def test_friction_never_adds_energy_free_vibration():
    """Friction work from the virgin state stays >= 0 and the energy balance holds.

    Load a cantilever quasi-statically under its weight, then release it (no
    damping). T + U + (W_f − W_f,release) = E_release holds up to the Newmark
    error; W_f >= 0 (passivity: the friction operator gives back at most what it
    stored) then means the mechanical energy never exceeds E_release + W_f,release.
    """
    fp = FrictionParams(f1=4e-4, f2=1e-4, eps_f=1.0, eta=0.5)
    plate = KirchhoffPlate(strip(8, 1), material(friction=fp), supports={"left": "clamped"})
    state = quasi_static(plate, [0.5, 1.0])
    work_loading = plate.friction_work
    assert work_loading > 0
    plate.load_scale = 0.0
    state = initial_state(plate, u0=state.u)
    e0 = plate.energies(state.u, state.v)
    mech0 = e0["kinetic"] + e0["strain"]
    period = 2 * np.pi / (1.8751**2 / L**2 * np.sqrt(B / RHO))
    rec = []
    integrate(plate, 2 * period, period / 120, state,
              on_step=lambda s, i: rec.append((plate.energies(s.u, s.v), plate.friction_work)))
    mech = np.array([e["kinetic"] + e["strain"] for e, _ in rec])
    work = np.array([w for _, w in rec])
    assert mech.max() > 1.05 * mech0          # released friction energy shows up as motion (not a bug)
    assert np.all(work >= -1e-12 * mech0)                           # never negative from virgin
    assert np.all(mech <= (mech0 + work_loading) * (1 + 1e-9))      # never more than was put in
    balance = mech + (work - work_loading)
    assert np.max(np.abs(balance - mech0)) < 0.02 * mech0           # energy balance (Newmark error O(Δt²))
    assert mech[-1] < 0.5 * mech0 and work[-1] > work_loading       # and friction did dissipate


def test_friction_work_over_cycle_equals_loop_area():
    """Closed curvature cycle imposed on a strip: dissipated work = area × loop area ∮ M dκ.

    The loop area is computed independently from the law at one material point
    (BendingState stepped through the same κ samples, trapezoid on M dκ); the
    plate's friction work is the exact path integral booked at each commit, and
    the reaction work ∮ M_edge dθ is measured at the rotated edges. Agreement 1e-3
    (trapezoid error of the loop integral at 400 samples).
    """
    fp = FrictionParams(f1=3e-3, f2=1e-3, eps_f=20.0, eta=0.4)
    law = BendingLaw(k1=B, k3=1e-9, friction=fp)
    mat = FabricMaterial("test", RHO, None, law, law, twist_rigidity=B)
    amp = 200.0
    kap = lambda t: amp * np.sin(2 * np.pi * t)  # noqa: E731
    plate = KirchhoffPlate(strip(4, 1), mat, rotations=pure_bending_rotations(kap, L), gravity=0.0)
    times = np.linspace(0, 1, 401)
    moments = []
    quasi_static(plate, np.zeros_like(times[1:]), times[1:],
                 on_step=lambda s, i: moments.append(plate.edge_moment(plate.residual(s.u, s.u * 0, s.u * 0, s.t)[0], "right")))
    # material point
    st = law.new_state(())
    m_point = [0.0]
    for t in times[1:]:
        m_point.append(float(st.trial(kap(t))[0]))
        st.commit(kap(t))
    k = kap(times)
    loop_area = float(np.sum(0.5 * (np.array(m_point[1:]) + m_point[:-1]) * np.diff(k)))
    fe_moment = np.concatenate(([0.0], moments))
    reaction_work = float(np.sum(0.5 * (fe_moment[1:] + fe_moment[:-1]) * np.diff(k)))
    area = L * W
    assert loop_area > 0
    assert abs(plate.friction_work / (area * loop_area) - 1) < 1e-3
    assert abs(reaction_work / loop_area - 1) < 1e-9


def test_library_fabric_drape_strip_converges_and_friction_stiffens():
    """fabric1 (thesis Table 4.4 fit: cubic + friction + d) as a hanging cantilever: quasi-static in
    4 steps; monotone loading from rest, so cubic and friction can only stiffen: |tip| below the
    linear k1 answer ρ_A g L⁴/(8 k1_warp), and above the answer with the stick stiffness k1 + f1/a1."""
    from constitutive.material import load_material

    mat = load_material("fabric1")
    length = 0.02
    plate = KirchhoffPlate(strip(8, 1, length=length, width=0.01), mat, supports={"left": "clamped"})
    u = quasi_static(plate, [0.25, 0.5, 0.75, 1.0]).u
    tip = -tip_deflection(plate, u, length)
    q = mat.areal_mass * G0
    w = mat.warp
    stick = w.k1 + (w.friction.f1 / w.friction.a1 - w.friction.f2 / w.friction.a2)
    assert q * length**4 / (8 * stick) < tip < q * length**4 / (8 * w.k1)


# --------------------------------------------------------------------------- conventions, input
def test_sign_convention_positive_curvature():
    """κ_xx = +w_,xx (docs/theory.md §1, face-up positive): a sagging cantilever has κ_xx < 0 and M_xx < 0;
    an imposed positive κ on a strip gives the trough w = κ x (x − L)/2 (midspan down, ends up)."""
    plate = KirchhoffPlate(strip(8, 2), material(), supports={"left": "clamped"})
    s = quasi_static(plate, [1.0])
    cells = plate.fields(s.u, s.v, s.a)["cell_data"]
    assert tip_deflection(plate, s.u) < 0
    root = plate.mesh.p[0, plate.mesh.t].mean(axis=0) < 0.75 * L   # Morley's tip cells are ~0 either sign
    assert np.all(cells["curvature_xx"][root] < 0) and np.all(cells["moment_xx"][root] < 0)

    kappa = 30.0
    plate = KirchhoffPlate(strip(8, 2), material(), rotations=pure_bending_rotations(lambda t: kappa * t, L),
                           gravity=0.0)
    s = quasi_static(plate, [0.0], times=[1.0])
    cells = plate.fields(s.u, s.v, s.a)["cell_data"]
    np.testing.assert_allclose(cells["curvature_xx"], kappa, rtol=1e-9)
    x = plate.mesh.p[0]
    np.testing.assert_allclose(s.u[plate.vertex_dofs], kappa * x * (x - L) / 2, atol=1e-12)


def test_fields_shapes_and_units():
    plate = KirchhoffPlate(strip(4, 1), material(), supports={"left": "clamped"})
    s = quasi_static(plate, [1.0])
    f = plate.fields(s.u, s.v, s.a)
    nv, ne = plate.mesh.p.shape[1], plate.mesh.t.shape[1]
    assert f["point_data"]["displacement"].shape == (nv, 3)
    assert np.all(f["point_data"]["displacement"][:, :2] == 0)
    assert all(v.shape == (ne,) for v in f["cell_data"].values())
    e = plate.energies(s.u, s.v)
    # static equilibrium of a linear model: U = −V_ext / 2 (Clapeyron)
    assert abs(e["strain"] / (-0.5 * e["external_potential"]) - 1) < 1e-9


@pytest.mark.parametrize("kwargs, match", [
    (dict(supports={"nowhere": "clamped"}), "nowhere"),
    (dict(supports={"left": "glued"}), "supports\\['left'\\]"),
    (dict(element="bogner"), "element"),
    (dict(rayleigh=(-1.0, 0.0)), "rayleigh"),
    (dict(gravity="heavy"), "gravity"),
    (dict(rotations={"left": 1.0}), "rotations"),
])
def test_bad_input_names_the_parameter(kwargs, match):
    with pytest.raises(PlateInputError, match=match):
        KirchhoffPlate(strip(2, 1), material(), **kwargs)
