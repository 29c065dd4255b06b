"""Convergence rates against analytic solutions: fitted log-log slopes inside a window.

The error of each model on a sequence of meshes is fitted by ``error ≈ C hᵖ``; the test holds
``p`` inside a window around the rate the element gives (as scikit-fem's own H² convergence
tests do), so that a loss of order fails even where the error still decreases.
"""
import numpy as np
import pytest
import skfem

from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial
from drape.models.plate import KirchhoffPlate
from drape.models.shell import ElasticMaterial, KirchhoffLoveShell
from drape.solvers.static import quasi_static


def slope(h, error):
    """Fitted exponent p of ``error ≈ C hᵖ``."""
    return float(np.polyfit(np.log(h), np.log(error), 1)[0])


def navier_centre_deflection(terms: int = 399) -> float:
    """Centre deflection w D / (q a⁴) of a simply supported square plate under uniform load:
    Navier's double sine series 16/π⁶ Σ_{m,n odd} sin(mπ/2) sin(nπ/2) / (m n (m² + n²)²)
    (0.00406 q a⁴/D in Timoshenko & Woinowsky-Krieger's table), the odd terms up to ``terms``."""
    m = np.arange(1, terms + 1, 2)
    M, N = np.meshgrid(m, m)
    s = np.sin(M * np.pi / 2) * np.sin(N * np.pi / 2) / (M * N * (M**2 + N**2) ** 2)
    return float(16 / np.pi**6 * s.sum())


def unit_square(n):
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0), "right": lambda x: np.isclose(x[0], 1),
        "bottom": lambda x: np.isclose(x[1], 0), "top": lambda x: np.isclose(x[1], 1),
    })


def test_navier_series_is_the_tabulated_value():
    assert navier_centre_deflection() == pytest.approx(0.00406235, rel=1e-6)


@pytest.mark.parametrize("element, sizes, window", [
    # quintic Argyris: the nodal deflection converges like h⁶ (fitted 5.9 on 2..16)
    ("argyris", (2, 4, 8), (5.0, 7.0)),
    # Morley's non-conforming quadratic: h² (fitted 2.00)
    ("morley", (8, 16, 32), (1.8, 2.2)),
])
def test_simply_supported_plate_converges_at_the_element_rate(element, sizes, window):
    """Isotropic ν = 0 plate (B = D_t = 1), unit square, all edges simply supported, uniform
    pressure 1: the centre deflection against Navier's series."""
    law = BendingLaw(k1=1.0)
    material = FabricMaterial("isotropic", 1.0, None, law, law, twist_rigidity=1.0)
    exact = navier_centre_deflection()
    errors = []
    for n in sizes:
        mesh = unit_square(n)
        plate = KirchhoffPlate(mesh, material, element=element, gravity=0.0, pressure=1.0,
                               supports={k: "simply_supported" for k in ("left", "right", "bottom", "top")})
        u = quasi_static(plate, [1.0]).u
        centre = np.flatnonzero(np.isclose(mesh.p[0], 0.5) & np.isclose(mesh.p[1], 0.5))
        errors.append(abs(float(u[plate.vertex_dofs][centre][0]) / exact - 1))
    lo, hi = window
    assert lo < slope(1.0 / np.array(sizes), errors) < hi, errors


@pytest.mark.slow
def test_shell_elastica_under_end_moment_converges():
    """A cantilever strip rolled into a half circle by a follower end moment (θ = ML/B = π): the
    elastica is a circular arc of curvature M/B with the tip at u = −L(1 − sin θ/θ),
    w = L(1 − cos θ)/θ. Nearly inextensible (E h L²/B = 1e8), so the
    membrane's own stretch (~1e-8 L) stays below the discretisation error; 1 to 4 elements
    along the strip give a fitted rate of 4.6 (3.2e-2 L down to 5.2e-5 L)."""
    L, b, B = 1.0, 0.1, 1.0
    M = np.pi * B / L
    theta = M * L / B
    exact = np.array([-L * (1 - np.sin(theta) / theta), 0.0, L * (1 - np.cos(theta)) / theta])
    sizes = (1, 2, 3, 4)
    errors = []
    for n in sizes:
        mesh = skfem.MeshTri.init_tensor(np.linspace(0, L, n + 1), np.linspace(0, b, 2))
        mesh = mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-9 * L,
                                     "free": lambda x: x[0] > L * (1 - 1e-9)})
        shell = KirchhoffLoveShell(mesh, ElasticMaterial(bending=B, membrane=1e8), gravity=0.0,
                                   end_moment=M)
        u = quasi_static(shell, np.linspace(0.1, 1.0, 10)).u
        d = shell.nodal_displacement(u)
        tip = d[mesh.p[0] > L * (1 - 1e-9)].mean(axis=0)
        errors.append(float(np.linalg.norm(tip - exact)) / L)
    assert 3.5 < slope(L / np.array(sizes), errors) < 5.5, errors
    assert errors[-1] < 1e-4
