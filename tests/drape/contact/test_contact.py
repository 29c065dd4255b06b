"""Contact of the shell with rigid bodies (IPC): each test against an independent reference.

Bodies are built by a small function (a large two-triangle plane patch, in contact_sheet.py),
so the tests depend on nothing but the contact core. What a case file and bad input give:
test_contact_input.py.
"""
from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp
import pytest
from skfem import MeshTri

import meshes

from constitutive.units import G0
from drape.contact.bodies import ContactInputError, HalfSpace, RigidBody, Scene
from drape.contact.contact import Contact
from drape.contact.stiffness import barrier_stiffness
from drape.models.shell import ElasticMaterial, KirchhoffLoveShell
from drape.solvers.newmark import initial_state
from drape.solvers.static import quasi_static
from drape.solvers.time_stepping import integrate

from contact_sheet import DHAT, FLAT, RHO_A, THICKNESS, flat, in_plane_dofs, pairs_of, plane, sheet


# ---------------------------------------------------------------------------- barrier


@FLAT
def test_sheet_resting_on_a_plane_carries_its_weight_as_the_contact_reaction(kind):
    z0 = -(0.5 * THICKNESS + 0.7 * DHAT)
    table = flat(kind, "table", [0.1, 0.1, z0])
    pairs = pairs_of(kind)
    shell, contact = sheet(bodies=[table], pairs=pairs, fixed_dofs=in_plane_dofs(sheet(bodies=[table], pairs=pairs)[0]))
    state = quasi_static(shell, [1.0], [1.0], rtol=1e-10, du_rtol=1e-10)
    reaction = contact.body_forces(state.u, None, state.t)["table"]
    weight = RHO_A * G0 * 0.2 * 0.2                          # ρ_A g A, the reference
    assert reaction[2] == pytest.approx(-weight, rel=0.01)
    assert np.hypot(*reaction[:2]) < 1e-3 * weight       # frictionless: no tangential force
    gap = shell.nodal_displacement(state.u)[:, 2] - z0
    assert gap.min() > 0.5 * THICKNESS and gap.max() < 0.5 * THICKNESS + DHAT


@FLAT
def test_fast_falling_sheet_does_not_pass_through_the_plane(kind):
    z0 = -0.02
    shell, contact = sheet(bodies=[flat(kind, "floor", [0.1, 0.1, z0])], pairs=pairs_of(kind))
    v0 = np.zeros(shell.ndofs)
    v0[shell.contact_vertices()[2][:, 2]] = -4.0     # vertex values of w: a uniform fall
    dt = 0.02
    assert 4.0 * dt > 2 * abs(z0)                    # one free step would land far below the plane
    gaps = []

    def record(state, info):
        gaps.append(shell.nodal_displacement(state.u)[:, 2].min() - z0)

    integrate(shell, 2 * dt, dt, initial_state(shell, v0=v0), alpha_hht=-0.3, on_step=record, max_cuts=8)
    assert gaps and min(gaps) > 0.5 * THICKNESS       # the mid-surface stays half a thickness off
    assert min(gaps) < 0.5 * THICKNESS + DHAT         # ... and it did land on the plane


@FLAT
def test_step_cap_of_the_newton_problem_limits_a_step_through_the_plane(kind):
    shell, contact = sheet(bodies=[flat(kind, "floor", [0.1, 0.1, -0.01])], pairs=pairs_of(kind))
    u0 = np.zeros(shell.ndofs)
    u1 = u0.copy()
    u1[shell.contact_vertices()[2][:, 2]] = -0.02
    cap = shell.max_step(u0, u1, 0.0)
    # the plane is 1 cm below, the mid-surface stops half a thickness above it: fraction ≤ 0.8 × 0.475
    assert 0.0 < cap <= 0.8 * (0.01 - 0.5 * THICKNESS) / 0.02 + 1e-9
    assert shell.max_step(u0, 0.1 * u1, 0.0) == 1.0


def test_no_contact_evaluates_exactly_as_before():
    mesh = MeshTri.init_tensor(np.linspace(0, 0.2, 4), np.linspace(0, 0.1, 3))
    mat = ElasticMaterial(bending=1e-4, membrane=1e3, areal_mass=RHO_A)
    plain = KirchhoffLoveShell(mesh, mat, clamped=())
    rng = np.random.default_rng(1)
    u, v, a = (1e-3 * rng.standard_normal(plain.ndofs) for _ in range(3))
    far = RigidBody("far", plane([0.0, 0.0, -1.0], [0, 0, 1]))
    touched = KirchhoffLoveShell(mesh, mat, clamped=())
    pts, tris, dofs = touched.contact_vertices()
    touched.attach_contact(Contact(Scene(pts, tris, [far]), dofs, touched.ndofs, dhat=DHAT, stiffness=1.0))
    for shell_b in (KirchhoffLoveShell(mesh, mat, clamped=()), touched):
        e1 = plain.evaluate(u, v, a, 0.3, "consistent", (1.0, 10.0, 100.0))
        e2 = shell_b.evaluate(u, v, a, 0.3, "consistent", (1.0, 10.0, 100.0))
        assert np.array_equal(e1.force, e2.force) and np.array_equal(e1.inertia, e2.inertia)
        assert np.array_equal(e1.J.data, e2.J.data) and np.array_equal(e1.J.indices, e2.J.indices)
    assert plain.max_step is None             # nothing to cap: the step problems skip the CCD
    assert touched.max_step(u, 2 * u, 0.0) == 1.0


def test_contact_state_round_trips():
    shell, contact = sheet(bodies=[RigidBody("floor", plane([0.1, 0.1, -0.0012], [0, 0, 1]), mu=0.3)])
    u = np.zeros(shell.ndofs)
    u[shell.contact_vertices()[2][:, 0]] = 1e-3
    contact.commit(u, u, 0.1)
    state = {k: np.array(v) for k, v in shell.state_dict().items()}
    other, c2 = sheet(bodies=[RigidBody("floor", plane([0.1, 0.1, -0.0012], [0, 0, 1]), mu=0.3)])
    other.load_state_dict(state)
    v = np.ones(shell.ndofs) * 1e-2
    assert np.array_equal(contact.forces(u, v, 0.1)[0], c2.forces(u, v, 0.1)[0])


def test_stiffness_and_damping_are_the_weighted_tangents_parts():
    """One set of pairs gives the force and the barrier's and friction's tangents apart; the
    weighted tangent ``c_K K + c_C C`` is their sum (ipctk adds the pairs in parallel: equal to
    round-off)."""
    floor = plane([0.1, 0.1, -0.0012], [0, 0, 1])
    shell, contact = sheet(bodies=[RigidBody("floor", floor, mu=0.3)])
    u = np.zeros(shell.ndofs)
    u[shell.contact_vertices()[2][:, 2]] = -2e-4
    contact.commit(u, u, 0.1)
    v = np.ones(shell.ndofs) * 1e-2

    def dense(coords):
        rows, cols, values = coords
        return sp.coo_matrix((values, (rows, cols)), shape=(shell.ndofs,) * 2).toarray()

    force, K, C = contact.stiffness_and_damping(u, v, 0.1)
    weighted_force, weighted = contact.forces(u, v, 0.1, (2.0, 0.5))
    K, C = dense(K), dense(C)
    assert np.abs(K).max() > 0 and np.abs(C).max() > 0                # both parts present
    scale = np.abs(2.0 * K + 0.5 * C).max()
    np.testing.assert_allclose(dense(weighted), 2.0 * K + 0.5 * C, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(weighted_force, force, rtol=0, atol=1e-12 * np.abs(force).max())


def test_changing_the_stiffness_is_building_the_contact_with_it():
    """``set_stiffness`` after a commit: barrier and lagged friction forces as a contact built
    with that stiffness from the start and committed at the same state."""
    floor = plane([0.1, 0.1, -0.0012], [0, 0, 1])
    shell, contact = sheet(bodies=[RigidBody("floor", floor, mu=0.3)])
    u = np.zeros(shell.ndofs)
    u[shell.contact_vertices()[2][:, 2]] = -2e-4
    contact.commit(u, u, 0.1)
    _, stiffer = sheet(bodies=[RigidBody("floor", floor, mu=0.3)], force_per_vertex=3 * RHO_A * G0 * 0.04 / 25)
    stiffer.commit(u, u, 0.1)
    contact.set_stiffness(stiffer.kappa)
    v = np.ones(shell.ndofs) * 1e-2
    assert stiffer.kappa == pytest.approx(3 * barrier_stiffness(RHO_A * G0 * 0.04 / 25, DHAT, THICKNESS / 2))
    assert np.abs(contact.forces(u, v, 0.1)[0]).max() > 0
    assert np.allclose(contact.forces(u, v, 0.1)[0], stiffer.forces(u, v, 0.1)[0], rtol=1e-12, atol=0)
    with pytest.raises(ContactInputError, match="must be > 0"):
        contact.set_stiffness(0.0)

# ---------------------------------------------------------------------------- friction


def slide_on_incline(tan_theta, mu, t_end=0.25, dt=0.01, kind="patch"):
    """A strip on a plane inclined by θ (gravity tilted instead: ``g cos θ`` into the plane,
    ``g sin θ`` along x); its centre of mass's x displacement at each step."""
    theta = np.arctan(tan_theta)
    floor = flat(kind, "floor", [0.05, 0.025, -(0.5 * THICKNESS + 0.5 * DHAT)], mu=mu)
    pull = RHO_A * G0 * np.sin(theta)

    def traction(x):
        return np.stack([pull * np.ones_like(x[0]), 0 * x[0], 0 * x[0]])

    shell, _ = sheet(0.1, 0.05, 4, 2, bodies=[floor], gravity=np.cos(theta), surface_load=(traction, 1.0),
                     eps_v=1e-4, pairs=pairs_of(kind))
    times, x = [], []

    def record(state, info):
        times.append(state.t)
        x.append(shell.nodal_displacement(state.u)[:, 0].mean())

    integrate(shell, t_end, dt, initial_state(shell), alpha_hht=-0.3, on_step=record)
    return np.array(times), np.array(x), theta


@FLAT
def test_strip_on_an_incline_slides_with_coulomb_acceleration_above_tan_theta_mu(kind):
    mu = 0.3
    t, x, theta = slide_on_incline(1.3 * mu, mu, kind=kind)
    late = t > 0.05                                        # after the first contact transient
    fit = np.polyfit(t[late], x[late], 2)                  # x = ½ a t² + v t + x0
    expected = G0 * (np.sin(theta) - mu * np.cos(theta))   # Coulomb's sliding block
    assert 2 * fit[0] == pytest.approx(expected, rel=0.02)


@FLAT
def test_strip_on_an_incline_sticks_below_tan_theta_mu(kind):
    mu = 0.3
    t, x, theta = slide_on_incline(0.8 * mu, mu, kind=kind)
    frictionless = 0.5 * G0 * np.sin(theta) * t[-1] ** 2
    assert abs(x[-1]) < 0.01 * frictionless               # IPC's smoothed stick creeps below eps_v only


# ---------------------------------------------------------------------------- self-contact


def two_pieces(self_contact, gap):
    """Two separate squares of one fabric, the second laid ``gap`` over the first (vertex
    positions only: contact sees the vertices)."""
    a = MeshTri.init_tensor(np.linspace(0, 0.05, 3), np.linspace(0, 0.05, 3))
    mesh = MeshTri(np.hstack([a.p, a.p + [[0.1], [0.0]]]), np.hstack([a.t, a.t + a.p.shape[1]]))
    shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-4, membrane=1e3, areal_mass=RHO_A), clamped=())
    points, triangles, dofs = shell.contact_vertices()
    contact = Contact(Scene(points, triangles, [], self_contact=self_contact), dofs, shell.ndofs,
                      dhat=DHAT, thickness=THICKNESS, stiffness=1e3)
    u = np.zeros(shell.ndofs)
    upper = points[:, 0] > 0.075
    u[dofs[upper, 0]] = -0.1 + 0.003                          # over the first, a little aside
    u[dofs[upper, 2]] = gap
    return contact, u, dofs, upper


def test_self_contact_pushes_layers_apart_and_stops_them_passing():
    gap = 0.5 * THICKNESS + 0.5 * DHAT                      # inside the barrier layer
    contact, u, dofs, upper = two_pieces(True, gap)
    force = contact.forces(u, np.zeros_like(u), 0.0)[0]
    # a resisting force (the residual's sign): ∂B/∂z < 0 on the upper layer, > 0 on the lower
    assert force[dofs[upper, 2]].sum() < 0 < force[dofs[~upper, 2]].sum()
    assert force[dofs[:, 2]].sum() == pytest.approx(0.0, abs=1e-9 * abs(force[dofs[upper, 2]].sum()))
    through = u.copy()
    through[dofs[upper, 2]] = -gap                           # the upper layer moved below the lower
    assert contact.max_step(u, through, 0.0) < 0.5
    off, u_off, *_ = two_pieces(False, gap)
    assert not np.any(off.forces(u_off, np.zeros_like(u_off), 0.0)[0])
    assert off.max_step(u_off, through, 0.0) == 1.0


# ---------------------------------------------------------------------------- capstan


def tube(centre, radius, length, facets=64):
    """An open tube along y."""
    a = np.linspace(0, 2 * np.pi, facets, endpoint=False)
    ring = np.column_stack([radius * np.cos(a), np.zeros(facets), radius * np.sin(a)])
    vertices = np.vstack([ring - [0, length / 2, 0], ring + [0, length / 2, 0]]) + centre
    i = np.arange(facets)
    j = (i + 1) % facets
    triangles = np.vstack([np.column_stack([i, j, facets + j]), np.column_stack([i, facets + j, facets + i])])
    return SimpleNamespace(vertices=vertices, triangles=triangles)


def smooth(t, t0, t1):
    s = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)
    return s * s * (3 - 2 * s)


def wrapped(x, L, Rc, phi):
    """The strip laid over the circle of radius Rc (top at z = 0 over x = L/2), leaving it along
    the tangents at ±φ: displacement, its gradient and Hessian (arc length kept)."""
    s = x[0] - L / 2
    a = np.clip(s / Rc, -phi, phi)
    beyond = s - Rc * a
    on = np.abs(s) <= Rc * phi
    px = L / 2 + Rc * np.sin(a) + beyond * np.cos(phi)
    pz = -Rc + Rc * np.cos(a) - np.abs(beyond) * np.sin(phi)
    tx = np.where(on, np.cos(a), np.cos(phi))
    tz = np.where(on, -np.sin(a), -np.sign(s) * np.sin(phi))
    kx = np.where(on, -np.sin(a) / Rc, 0.0)
    kz = np.where(on, -np.cos(a) / Rc, 0.0)
    o = 0 * s
    value = np.stack([px - x[0], o, pz])
    grad = np.stack([np.stack([tx - 1, o]), np.stack([o, o]), np.stack([tz, o])])
    hess = np.stack([np.stack([np.stack([kx, o]), np.stack([o, o])]), np.zeros((2, 2) + s.shape),
                     np.stack([np.stack([kz, o]), np.stack([o, o])])])
    return value, grad, hess


def capstan(ratio, mu, phi, t_end, T1=0.05, L=0.2, W=0.02, nx=20, R=0.04, dt=0.01):
    """A strip laid over a post wrapping 2φ, pulled by T1 and T2 = ratio T1 along its tangents:
    the loaded end's displacement [m] along the pull after T2 has risen (0.1 s), and its last speed."""
    mesh = meshes.strip(L, W, nx, 1)
    Rc = R + 0.5 * THICKNESS + 0.5 * DHAT
    post = RigidBody("post", tube([L / 2, W / 2, -Rc], R, 4 * W), mu=mu)
    a = L / nx
    left = T1 * np.array([-np.cos(phi), 0, -np.sin(phi)]) / (a * W)
    pull = np.array([np.cos(phi), 0, -np.sin(phi)])

    def traction(x):
        return np.where(x[0] < a, 1.0, 0.0) * left[:, None, None] * np.ones_like(x[0])

    def edge(t):
        return T1 * (1 + (ratio - 1) * smooth(t, 0.0, 0.1)) * pull / W

    shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-6, membrane=1e4, areal_mass=0.2), clamped=(),
                               gravity=0.0, surface_load=(traction, 1.0), edge_load=edge,
                               load_boundary="free_end", rayleigh=(100.0, 0.0))
    u0 = shell.interpolate(lambda x: wrapped(x, L, Rc, phi)[0], lambda x: wrapped(x, L, Rc, phi)[1],
                           lambda x: wrapped(x, L, Rc, phi)[2])
    points, triangles, dofs = shell.contact_vertices()
    contact = Contact(Scene(points, triangles, [post]), dofs, shell.ndofs, dhat=DHAT, thickness=THICKNESS,
                      stiffness=barrier_stiffness(T1 * a / (2 * R), DHAT, THICKNESS / 2), eps_v=1e-3)
    contact.check_start(u0)
    contact.commit(u0, None, 0.0)       # friction lagged at the laid strip
    shell.attach_contact(contact)
    end = np.flatnonzero(points[:, 0] > L - 1e-9)
    track = []

    def record(state, info):
        track.append((state.t, shell.nodal_displacement(state.u - u0)[end].mean(axis=0) @ pull))

    integrate(shell, t_end, dt, initial_state(shell, u0=u0), alpha_hht=-0.3, on_step=record, max_cuts=8,
              grow_after=1)
    t, s = np.array(track).T
    after = t >= 0.1
    return s[-1] - np.interp(0.1, t, s), (s[-1] - s[after][0]) / max(t[-1] - t[after][0], 1e-12)


@pytest.mark.slow
def test_capstan_strip_sticks_below_and_slips_above_exp_mu_theta():
    """Euler–Eytelwein: a strip wrapping θ of a post slips once T2/T1 exceeds exp(μθ)."""
    mu, theta = 0.3, np.radians(60.0)
    limit = np.exp(mu * theta)
    _, creep = capstan(0.97 * limit, mu, theta / 2, t_end=0.2)
    moved, slide = capstan(1.03 * limit, mu, theta / 2, t_end=0.2)
    assert abs(creep) < 1e-3                     # smoothed stick: slower than eps_v = 1 mm/s
    assert slide > 5e-3 and moved > 1e-3         # sliding off the post


# ---------------------------------------------------------------------------- moving bodies, pair counts


@pytest.mark.slow
@FLAT
def test_a_rising_plane_lifts_the_sheet_without_passing_through(kind):
    from drape.contact.motion import RigidPath

    z0 = -(0.5 * THICKNESS + 0.7 * DHAT)
    lift = RigidPath([0.0, 0.05], [[0, 0, 0], [0, 0, 0.005]])   # 5 mm up in 0.05 s
    shell, contact = sheet(bodies=[flat(kind, "lift", [0.1, 0.1, z0], path=lift)], pairs=pairs_of(kind))
    gaps = []

    def record(state, info):
        plane_z = z0 + lift.offset(state.t)[2]
        gaps.append(shell.nodal_displacement(state.u)[:, 2].min() - plane_z)

    state = integrate(shell, 0.06, 0.01, initial_state(shell), alpha_hht=-0.3, on_step=record, max_cuts=8)
    assert min(gaps) > 0.5 * THICKNESS                      # never through the moving plane
    assert shell.nodal_displacement(state.u)[:, 2].min() > 0.004    # and carried up with it


def test_resting_multiplicity_counts_one_pair_for_a_vertex_over_one_triangle_and_more_on_a_mesh():
    """One fabric vertex over the middle of one large triangle is one pair: the count is 1.
    A sheet over a plane triangulated as finely as itself gets several pairs per vertex (its
    edges over the plane's edges), and the count is the ratio of the force it gets to one
    pair's at each vertex's distance: scaling κ by it leaves the sheet's weight carried."""
    import ipctk

    from drape.contact import shapes
    from drape.contact.stiffness import resting_multiplicity

    d, dhat, dmin = 6e-4, 1e-3, 1e-4
    x = np.array([[0.0, 0.0, d], [1.0, 0.0, d], [0.0, 1.0, d],      # a fabric triangle
                  [-5.0, -5.0, 0.0], [10.0, -5.0, 0.0], [-5.0, 10.0, 0.0]])
    faces = np.array([[0, 1, 2], [3, 4, 5]])
    mesh = ipctk.CollisionMesh(x, ipctk.edges(faces), faces)
    # the fabric's own triangle spans 1 m: only its vertices are near the body, each one pair
    assert resting_multiplicity(mesh, x, 3, dhat, dmin) == pytest.approx(1.0, abs=1e-12)

    cloth = shapes.plane([0, 0, d], [0, 0, 1], 0.1, 8)
    floor = shapes.plane([0, 0, 0], [0, 0, 1], 0.3, 24)
    x = np.vstack([cloth.vertices, floor.vertices])
    faces = np.vstack([cloth.triangles, floor.triangles + len(cloth.vertices)])
    mesh = ipctk.CollisionMesh(x, ipctk.edges(faces), faces)
    n = len(cloth.vertices)
    count = resting_multiplicity(mesh, x, n, dhat, dmin)
    assert count > 2
    collisions = ipctk.NormalCollisions()
    collisions.build(mesh, x, dhat, dmin)
    kappa = barrier_stiffness(1e-3, dhat, dmin) / count         # 1 mN per vertex
    force = ipctk.BarrierPotential(dhat, kappa).gradient(collisions, mesh, x).reshape(-1, 3)[:n]
    assert np.linalg.norm(force, axis=1).sum() == pytest.approx(n * 1e-3, rel=1e-9)


# ---------------------------------------------------------------------------- half-space


def test_a_half_space_counts_one_pair_per_resting_vertex_where_a_fine_patch_counts_several():
    """The same sheet at mid-layer over a plane triangulated as finely as itself and over the
    exact plane: the half-space pushes each vertex as one pair at its distance (count 1, the
    barrier's own force), the triangulated one several times over."""
    from drape.contact import shapes
    from drape.contact.stiffness import resting_multiplicity

    d = 0.5 * THICKNESS + 0.5 * DHAT
    cloth = shapes.plane([0, 0, 0], [0, 0, 1], 0.1, 8)
    n = len(cloth.vertices)
    dofs = np.arange(3 * n).reshape(n, 3)
    counts = {}
    for kind, body in (("mesh", RigidBody("floor", shapes.plane([0, 0, -d], [0, 0, 1], 0.3, 24))),
                       ("half_space", HalfSpace("floor", [0, 0, -d], [0, 0, 1]))):
        contact = Contact(Scene(cloth.vertices, cloth.triangles, [body]), dofs, 3 * n, dhat=DHAT,
                          stiffness=1.0, thickness=THICKNESS)
        u = np.zeros(3 * n)
        counts[kind] = resting_multiplicity(contact.scene.mesh, contact.positions(u, 0.0), n, DHAT,
                                            0.5 * THICKNESS, collisions=contact.collisions(u, 0.0))
        if kind == "half_space":
            one = barrier_stiffness(1.0, DHAT, 0.5 * THICKNESS)     # κ of one pair pushing 1 N
            contact.set_stiffness(one)
            assert contact.body_forces(u, None, 0.0)["floor"] == pytest.approx([0, 0, -n], rel=1e-9)
    assert counts["half_space"] == pytest.approx(1.0, abs=1e-12)
    assert counts["mesh"] > 2


def test_a_moving_half_space_is_met_where_its_signed_distance_reaches_half_the_thickness():
    """CCD against a plane moving along its normal: the vertex and the plane close at known
    speeds, so the touch is at a fraction computed by hand."""
    from drape.contact.motion import RigidPath

    up = RigidPath([0.0, 1.0], [[0, 0, 0], [0, 0, 0.004]])     # the plane rises 4 mm over the step
    shell, contact = sheet(bodies=[HalfSpace("lift", [0, 0, -0.01], [0, 0, 1], path=up)])
    u0 = np.zeros(shell.ndofs)
    u1 = u0.copy()
    u1[shell.contact_vertices()[2][:, 2]] = -0.004                # the sheet falls 4 mm
    # gap 10 mm - dmin closes at 8 mm per step: first touch at (0.01 - 0.0005) / 0.008 > 1, none
    assert contact.max_step(u0, u1, 1.0, 0.0) == 1.0
    u1[shell.contact_vertices()[2][:, 2]] = -0.008
    # closes at 12 mm per step: touch at 0.0095 / 0.012
    assert contact.max_step(u0, u1, 1.0, 0.0) == pytest.approx(0.8 * 0.0095 / 0.012, rel=1e-12)
