"""Still air's quadratic normal drag (drape.models.air.NormalDrag) on the large-rotation shell."""
import numpy as np
import pytest
from skfem import MeshTri

from drape.models.air import AIR_DENSITY
from drape.fem.argyris import interpolate
from drape.solvers.newmark import initial_state
from drape.solvers.time_stepping import integrate
from drape.models.shell import ElasticMaterial, KirchhoffLoveShell, ShellInputError

CD = 1.2
K = 0.5 * AIR_DENSITY * CD


def sheet(nx=3, ny=2, length=0.2, width=0.1, **kw):
    mesh = MeshTri.init_tensor(np.linspace(0, length, nx + 1), np.linspace(0, width, ny + 1))
    mesh = mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9,
                                 "free": lambda x: x[0] > length * (1 - 1e-9)})
    material = ElasticMaterial(bending=1e-5, membrane=1e3, areal_mass=0.15)
    return KirchhoffLoveShell(mesh, material, gravity=0.0, drag_coefficient=CD, **kw)


def vector_field(shell, components):
    """Shell dofs (3 s + c) of a field linear in x, y: ``components[c] = (a, b)`` is a x + b y."""
    out = np.zeros(shell.ndofs)
    for c, (a, b) in enumerate(components):
        out[c::3] = interpolate(shell.basis, lambda x: a * x[0] + b * x[1],
                                lambda x: np.array([a + 0 * x[0], b + 0 * x[0]]))
    return out


def constant_field(shell, vector):
    out = np.zeros(shell.ndofs)
    for c, value in enumerate(vector):
        out[c::3] = interpolate(shell.basis, lambda x: value + 0 * x[0])
    return out


def total_drag(shell, u, v):
    """Resultant of the drag on the sheet [N] (its residual contribution, sign reversed)."""
    f = -shell.pattern.vector(shell.drag.element_forces(u, v))
    return np.array([f[c::3][shell.basis.nodal_dofs[0]].sum() for c in range(3)])


@pytest.mark.parametrize("theta", [0.0, 0.4, 1.1])
def test_a_tilted_sheet_falling_meets_the_broadside_drag_of_its_normal_speed(theta):
    """A flat sheet rotated by θ about x, moving down at V: the drag is ½ ρ C_d |V cos θ|
    V cos θ times its area, along its normal n = (0, −sin θ, cos θ). Moving in its own plane it
    meets none."""
    shell = sheet()
    c, s = np.cos(theta), np.sin(theta)
    u = vector_field(shell, [(0.0, 0.0), (0.0, c - 1.0), (0.0, s)])   # y → (y cos θ, y sin θ)
    V = -0.4
    area = 0.2 * 0.1
    n = np.array([0.0, -s, c])
    expected = -K * abs(V * c) * (V * c) * area * n
    assert np.allclose(total_drag(shell, u, constant_field(shell, [0.0, 0.0, V])), expected,
                       rtol=1e-10, atol=1e-14)
    in_plane = constant_field(shell, [0.3, 0.2 * c, 0.2 * s])            # along the sheet
    assert np.allclose(total_drag(shell, u, in_plane), 0.0, atol=1e-14)


def test_drag_tangent_is_the_velocity_derivative_of_the_drag():
    rng = np.random.default_rng(3)
    shell = sheet()
    u = 1e-3 * rng.normal(size=shell.ndofs)
    v = 0.3 * rng.normal(size=shell.ndofs)
    dv = rng.normal(size=shell.ndofs)
    C = shell.pattern.matrix(shell.drag.element_tangents(u, v))
    force = lambda x: shell.pattern.vector(shell.drag.element_forces(u, x))   # noqa: E731
    h = 1e-6
    fd = (force(v + h * dv) - force(v - h * dv)) / (2 * h)
    assert np.linalg.norm(C @ dv - fd) < 1e-6 * np.linalg.norm(fd)


def test_drag_dissipates_what_the_free_fabric_loses():
    """A cantilever set swinging in its first mode (tip 1.4 cm against 20 cm), no other
    damping. The mechanical energy it loses over a cycle equals the drag's booked work within
    2 % (it is 0.7 %: trapezoidal work against the Newmark step). And it loses what the
    averaged modal equation of quadratic damping predicts, within 2 % (it is 0.04 %): the
    amplitude obeys dA/dn = −(8/3) c₂ A² per cycle n, c₂ = k ∫|φ|³ / (ρ_A ∫φ²) with φ the
    Euler–Bernoulli mode, so A₁ = A₀ / (1 + (8/3) c₂ A₀) and E ∝ A²."""
    length = 0.2
    shell = sheet(nx=6, ny=1, length=length, width=0.02, membrane_strain_degree=0,
                  membrane_stabilization=0.5)
    beta = 1.8751 / length
    mode = lambda x: (np.cosh(beta * x) - np.cos(beta * x)                # noqa: E731
                      - 0.7341 * (np.sinh(beta * x) - np.sin(beta * x))) / 2.0
    dmode = lambda x: beta * (np.sinh(beta * x) + np.sin(beta * x)         # noqa: E731
                              - 0.7341 * (np.cosh(beta * x) - np.cos(beta * x))) / 2.0
    ddmode = lambda x: beta ** 2 * (np.cosh(beta * x) + np.cos(beta * x)   # noqa: E731
                                    - 0.7341 * (np.sinh(beta * x) + np.sin(beta * x))) / 2.0
    v0 = np.zeros(shell.ndofs)
    V0 = 0.01                                                             # tip speed [m/s]
    v0[2::3] = V0 * interpolate(shell.basis, lambda x: mode(x[0]),
                                lambda x: np.array([dmode(x[0]), 0 * x[0]]),
                                lambda x: np.array([[ddmode(x[0]), 0 * x[0]],
                                                    [0 * x[0], 0 * x[0]]]))
    v0[shell.fixed_dofs] = 0.0
    omega = 1.8751 ** 2 / length ** 2 * np.sqrt(1e-5 / 0.15)
    period = 2 * np.pi / omega
    rec = []
    state = initial_state(shell, v0=v0)
    e0 = shell.energies(state.u, state.v)
    integrate(shell, 1.0 * period, period / 200, state,
              on_step=lambda s, i: rec.append((s.t, shell.energies(s.u, s.v))))
    mech = np.array([e["kinetic"] + e["strain"] for _, e in rec])
    work = np.array([e["damping_work"] for _, e in rec])
    mech0 = e0["kinetic"] + e0["strain"]
    assert work[-1] > 0.01 * mech0                                        # the air took something
    assert abs((mech0 - mech[-1]) - work[-1]) < 0.02 * work[-1]
    # the modal amplitude A (tip swing V0/ω) after one cycle
    x = np.linspace(0, length, 2001)
    phi = mode(x) / mode(length)
    c2 = K * np.trapezoid(np.abs(phi) ** 3, x) / (0.15 * np.trapezoid(phi ** 2, x))
    A0 = V0 / omega
    predicted = mech0 / (1 + (8 / 3) * c2 * A0) ** 2
    assert abs((mech0 - mech[-1]) / (mech0 - predicted) - 1) < 0.02


def test_a_negative_drag_coefficient_is_refused():
    mesh = sheet().mesh
    with pytest.raises(ShellInputError, match="drag_coefficient must be >= 0"):
        KirchhoffLoveShell(mesh, ElasticMaterial(bending=1e-5, membrane=1e3, areal_mass=0.15),
                           drag_coefficient=-1.0)
