"""FE and law agree: a plate strip driven through the KES-FB profile by imposed end rotations
reproduces the material-point moment history of constitutive.kes.run_kes (same law, same profile).

Why the FE curvature is exactly uniform here (so 1e-6 is a fair tolerance):
- pure bending: both ends clamped at w = 0 and rotated to outward slopes −κ(t) L/2; the
  field w = −κ x (x − L)/2 is quadratic, inside the Morley and Argyris spaces, and its
  constant moment is in equilibrium (both elements pass the constant-moment patch test);
- no translational inertia and no gravity (ρ_A ẅ and ρ_A g would be distributed loads and
  bend the strip non-uniformly: the KES tester measures moment, not drape);
- the law's d κ̇ and m κ̈ are curvature terms, uniform for a uniform κ; the rotation
  callables return (slope, rate, acceleration), so the integrator's lifting carries the
  exact imposed rates and Newmark only integrates the (zero) deviation from it.
The moment compared is the FE reaction at the rotated edge (edge_moment of the residual),
not the law evaluated at the FE curvature.
"""
import numpy as np
import pytest
import skfem

from constitutive.friction import FrictionParams
from constitutive.kes import kes_profile, run_kes
from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial
from drape.solvers.static import quasi_static
from drape.solvers.time_stepping import integrate
from drape.models.plate import KirchhoffPlate, pure_bending_rotations

L, W = 0.01, 0.01          # m: the KES-FB clamp gap is 1 cm
DT = 0.05                  # s: profile sampling (turning points are added by kes_profile)


def strip(nx, ny):
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, L, nx + 1), np.linspace(0, W, ny + 1))
    return mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0), "right": lambda x: np.isclose(x[0], L)})


def fabric(**kw):
    law = BendingLaw(k1=2e-5, k3=3e-10, friction=FrictionParams(f1=3e-3, f2=1.5e-3, eps_f=30.0, eta=0.4), **kw)
    return law, FabricMaterial("test", 0.2, None, law, law, twist_rigidity=2e-5)


def profile_kappa(t):
    p = kes_profile(t=[t])
    return p.kappa[0], p.kappa_dot[0], p.kappa_ddot[0]


@pytest.mark.slow
@pytest.mark.parametrize("element, n", [("morley", (4, 2)), ("argyris", (2, 1))])
def test_dynamic_kes_strip_matches_run_kes(element, n):
    """Newmark run with m, d, cubic and friction: edge moment = run_kes moment to 1e-6 relative."""
    law, mat = fabric(d=2e-6, m=1e-6)
    prof = kes_profile(dt=DT)
    plate = KirchhoffPlate(strip(*n), mat, element=element, gravity=0.0, translational_inertia=False,
                           rotations=pure_bending_rotations(profile_kappa, L))
    rec = {"t": [0.0], "left": [0.0], "right": [0.0], "spread": 0.0}

    def on_step(s, info):
        R = plate.residual(s.u, s.v, s.a, s.t)[0]
        rec["t"].append(s.t)
        rec["left"].append(plate.edge_moment(R, "left"))
        rec["right"].append(plate.edge_moment(R, "right"))
        kxx = plate.curvatures(s.u)["xx"]
        rec["spread"] = max(rec["spread"], float(np.ptp(kxx)))

    integrate(plate, prof.t[-1], DT, hit_times=prof.t, on_step=on_step)
    np.testing.assert_allclose(rec["t"], prof.t, rtol=0, atol=1e-9)
    ref = run_kes(law, prof)
    scale = np.max(np.abs(ref.moment))
    for side in ("left", "right"):
        assert np.max(np.abs(np.array(rec[side]) - ref.moment)) < 1e-6 * scale
    assert rec["spread"] < 1e-6 * np.max(np.abs(prof.kappa))     # curvature uniform along the strip
    # the rate terms are really in the comparison (a few % of the moment), and so is friction
    assert np.max(np.abs(ref.inertial + ref.viscous)) > 0.01 * scale
    assert np.max(np.abs(ref.friction)) > 0.1 * scale


@pytest.mark.slow
def test_quasi_static_kes_strip_rate_free_law():
    """Quasi-static path (no rates): a law without m, d is reproduced to 1e-6 relative."""
    law, mat = fabric()
    prof = kes_profile(dt=DT)
    plate = KirchhoffPlate(strip(4, 2), mat, gravity=0.0,
                           rotations=pure_bending_rotations(lambda t: kes_profile(t=[t]).kappa[0], L))
    moments = [0.0]
    quasi_static(plate, np.zeros(prof.t.size - 1), prof.t[1:],
                 on_step=lambda s, i: moments.append(plate.edge_moment(plate.residual(s.u, s.v, s.a, s.t)[0], "right")))
    ref = run_kes(law, prof).moment
    assert np.max(np.abs(np.array(moments) - ref)) < 1e-6 * np.max(np.abs(ref))


def test_unconvergeable_kes_run_stops_with_clear_error_and_commits_nothing():
    """One-second steps through friction with 2 Newton iterations allowed cannot converge:
    a ConvergenceError names t, the smallest dt tried and the norms; no state was committed."""
    from drape.solvers.newmark import ConvergenceError

    _, mat = fabric(d=2e-6)
    plate = KirchhoffPlate(strip(4, 2), mat, gravity=0.0, translational_inertia=False,
                           rotations=pure_bending_rotations(lambda t: kes_profile(t=[t]).kappa[0], L))
    with pytest.raises(ConvergenceError) as err:
        integrate(plate, 21.5, 1.0, max_iter=2, max_cuts=1)
    msg = str(err.value)
    assert "integration stopped at t = 0 s" in msg and "dt/2^1 = 0.5 s" in msg
    assert "max_iter=2" in msg and "residual norms" in msg and "increment norms" in msg
    assert plate.friction_work == 0.0
    assert np.all(plate.states["xx"].kappa == 0.0) and np.all(plate.states["xx"].friction.y1 == 0.0)
