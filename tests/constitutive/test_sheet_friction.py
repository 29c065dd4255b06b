"""The sheet's tensor friction: the scalar law in a strip, frame invariance, exact update,
tangent and work, and a bias strip that hangs like a warp strip."""

import numpy as np
import pytest

from constitutive.friction import FrictionParams, FrictionState
from constitutive.law import BendingLaw, BendingState
from constitutive.sheet import SheetLaw
from constitutive.sheet_friction import SheetFrictionState, rotate_voigt

WARP = FrictionParams(f1=2.0e-3, f2=0.8e-3, eps_f=40.0, eta=0.3)
WEFT = FrictionParams(f1=1.2e-3, f2=0.3e-3, eps_f=25.0, eta=0.6)


def _kes_cycle(peak=250.0, n=121):
    """0 → +K → −K → 0 (1/m), the KES-FB loop's path."""
    up = np.linspace(0.0, peak, n)
    return np.concatenate([up, up[::-1][1:], -up[1:], -up[::-1][1:]])


def _walk(state, path):
    """Moments along a path of trial-and-commit steps."""
    out = []
    for k in path:
        out.append(state.trial(k)[0])
        state.commit(k)
    return np.array(out)


@pytest.mark.parametrize("axis", [0, 1])
def test_a_strip_bent_along_a_yarn_follows_that_yarns_scalar_law(axis):
    """κ along one yarn only (the KES-FB strip): the tensor law's moment on that yarn is
    the scalar law's to round-off, and it puts no moment on the other components."""
    path = _kes_cycle()
    kappa = np.zeros((path.size, 1, 3))
    kappa[:, 0, axis] = path
    tensor = _walk(SheetFrictionState(WARP, WEFT, (1,)), kappa)[:, 0]
    scalar = _walk(FrictionState((WARP, WEFT)[axis], (1,)), path[:, None])[:, 0]
    assert np.abs(tensor[:, axis] - scalar).max() <= 1e-12 * np.abs(scalar).max()
    assert np.abs(np.delete(tensor, axis, axis=1)).max() == 0.0


def _random_path(rng, n=40, scale=150.0):
    steps = rng.normal(size=(n, 3)) * scale / np.sqrt(n)
    steps[n // 2:] *= -1.3                          # reverse half way: hysteresis branches
    return np.cumsum(steps, axis=0)[:, None, :]


def test_equal_directions_make_the_friction_frame_invariant():
    """Rotating the whole curvature history of a sheet with equal warp and weft rotates its
    friction moment history (to round-off), for every angle; the per-direction law does not."""
    rng = np.random.default_rng(3)
    path = _random_path(rng)
    for angle in (0.3, np.pi / 4, 1.1):
        turned = rotate_voigt(path, angle)
        a = _walk(SheetFrictionState(WARP, WARP, (1,)), path)
        b = _walk(SheetFrictionState(WARP, WARP, (1,)), turned)
        assert np.abs(rotate_voigt(a, angle, moment=True) - b).max() <= 1e-12 * np.abs(a).max()

    law = BendingLaw(k1=1e-9, friction=WARP)
    per_direction = SheetLaw(law, law, twist=1e-9, friction="per_direction")
    a = _walk(per_direction.new_state((1,)), path)
    b = _walk(per_direction.new_state((1,)), rotate_voigt(path, np.pi / 4))
    assert np.abs(rotate_voigt(a, np.pi / 4, moment=True) - b).max() > 0.1 * np.abs(a).max()


def test_twist_meets_the_friction_a_turned_saddle_meets():
    """A pure twist is a saddle turned by 45°: the tensor law resists both alike, the
    per-direction law lets the twist slip free."""
    saddle = np.array([[100.0, -100.0, 0.0]])
    twist = np.array([[0.0, 0.0, 200.0]])
    assert np.allclose(rotate_voigt(saddle, np.pi / 4), twist, rtol=0, atol=1e-12)
    work = [SheetFrictionState(WARP, WARP, (1,)).work(k)[0] for k in (saddle, twist)]
    assert work[0] > 0 and abs(work[1] - work[0]) <= 1e-12 * work[0]
    law = BendingLaw(k1=1e-9, friction=WARP)
    per_direction = SheetLaw(law, law, 1e-9, friction="per_direction").new_state((1,))
    assert per_direction.friction_work(twist)[0] == 0.0 and per_direction.friction_work(saddle)[0] > 0


def test_a_straight_increment_is_exact_whatever_the_substeps():
    """The update over a straight increment is the solution of the rate equations: one
    step and 64 substeps along the same line give the same state and work."""
    rng = np.random.default_rng(5)
    start = _random_path(rng, 10)
    one, many = SheetFrictionState(WARP, WEFT, (1,)), SheetFrictionState(WARP, WEFT, (1,))
    _walk(one, start), _walk(many, start)
    target = start[-1] + np.array([[60.0, -20.0, 45.0]])
    w_one = one.work(target)
    one.commit(target)
    w_many = 0.0
    for s in np.linspace(0, 1, 65)[1:]:
        k = start[-1] + s * (target - start[-1])
        w_many = w_many + many.work(k)
        many.commit(k)
    assert np.allclose(one.y1, many.y1, rtol=0, atol=1e-13)
    assert np.allclose(one.y2, many.y2, rtol=0, atol=1e-13)
    assert abs(w_one[0] - w_many[0]) <= 1e-12 * abs(w_one[0])


def test_work_is_the_integral_of_the_moment():
    """``work`` against the trapezoidal integral of M · dκ along the straight increment."""
    rng = np.random.default_rng(7)
    st = SheetFrictionState(WARP, WEFT, (1,))
    _walk(st, _random_path(rng, 12))
    k0 = st.kappa.copy()
    dk = np.array([[-80.0, 30.0, 50.0]])
    s = np.linspace(0.0, 1.0, 20001)
    M = np.array([st.moment(k0 + si * dk)[0] for si in s])
    integral = np.trapezoid(M @ dk[0], s)
    assert abs(st.work(k0 + dk)[0] - integral) <= 1e-6 * abs(integral)


def test_consistent_tangent_matches_finite_differences():
    """``dM/dκ`` (3 × 3, unsymmetric) against central differences of the moment, away
    from the stick point, after a history that leaves the Dahl states off the new path."""
    rng = np.random.default_rng(11)
    st = SheetFrictionState(WARP, WEFT, (1,))
    _walk(st, _random_path(rng, 15))
    k = st.kappa + np.array([[12.0, -7.0, 9.0]])
    _, D = st.trial(k)
    h = 1e-5
    fd = np.empty((3, 3))
    for j in range(3):
        e = np.zeros((1, 3))
        e[0, j] = h
        fd[:, j] = (st.moment(k + e)[0] - st.moment(k - e)[0]) / (2 * h)
    assert np.abs(D[0] - fd).max() <= 1e-6 * np.abs(fd).max()
    assert np.abs(D[0] - D[0].T).max() > 1e-3 * np.abs(D[0]).max()


def test_per_direction_sheet_is_the_directions_scalar_laws():
    """``friction = "per_direction"`` gives each direction's BendingState moment and tangent
    exactly, and linear twist."""
    rng = np.random.default_rng(2)
    warp = BendingLaw(k1=1e-5, k3=1e-10, friction=WARP)
    weft = BendingLaw(k1=0.7e-5, friction=WEFT)
    sheet = SheetLaw(warp, weft, twist=0.8e-5, friction="per_direction").new_state((4,))
    refs = [BendingState(warp, (4,)), BendingState(weft, (4,))]
    for k in rng.normal(size=(6, 4, 3)) * 80.0:
        M, D = sheet.trial(k)
        for i, ref in enumerate(refs):
            Mi, Di = ref.trial(k[..., i])
            assert np.array_equal(M[..., i], Mi) and np.array_equal(D[..., i, i], Di)
            ref.commit(k[..., i])
        assert np.allclose(M[..., 2], 0.4e-5 * k[..., 2], rtol=1e-14, atol=0)
        sheet.commit(k)


def test_state_dict_round_trip_and_stick_tangent():
    rng = np.random.default_rng(4)
    law = SheetLaw(BendingLaw(1e-5, friction=WARP), BendingLaw(1e-5, friction=WEFT), 1e-5)
    st = law.new_state((2,))
    for k in rng.normal(size=(5, 2, 3)) * 60.0:
        st.commit(k)
    again = law.new_state((2,))
    again.load_state_dict(st.state_dict())
    probe = rng.normal(size=(2, 3)) * 60.0
    for a, b in zip(st.trial(probe), again.trial(probe)):
        assert np.array_equal(a, b)
    # the stick tangent bounds the consistent one at the committed point (PSD difference)
    D_stick = st.trial(st.kappa, "stick")[1]
    D_cons = st.trial(st.kappa + 1e-9, "consistent")[1]
    sym = 0.5 * (D_cons + np.swapaxes(D_cons, -1, -2))
    assert np.all(np.linalg.eigvalsh(D_stick - sym) >= -1e-9 * np.abs(D_stick).max())
    with pytest.raises(ValueError, match="per_direction"):
        SheetLaw(law.warp, law.weft, 1e-5, friction="per_axis")


@pytest.mark.parametrize("frame, same", [("tensor", True), ("per_direction", False)])
def test_a_bias_strip_hangs_like_a_warp_strip_with_tensor_friction(frame, same):
    """A sheet with equal warp and weft (Fabric 1's warp k1 and friction both ways, D_t = k1;
    no cubic or viscous term, which act per direction) is isotropic under the tensor law: a cantilever cut at 45° to the yarns hangs, and after
    unloading keeps, the same tip deflection as one cut along the warp (within 0.5 %).
    With per-direction friction the bias strip twists free of half its friction and
    keeps half the residual deflection after unloading (differs by more than 20 %)."""
    from skfem import MeshTri

    from constitutive.material import load_material
    from drape.solvers.static import quasi_static
    from drape.models.shell import KirchhoffLoveShell

    mat = load_material("fabric1")
    law = BendingLaw(k1=mat.warp.k1, friction=mat.warp.friction)
    mat = mat.replace(warp=law, weft=law)
    L, b = 0.0163, 0.004
    path = list(np.linspace(0.2, 1.0, 5)) + list(np.linspace(0.8, 0.0, 5))
    tips = []
    for angle in (0.0, np.pi / 4):
        base = MeshTri.init_tensor(np.linspace(0, L, 5), np.linspace(-b / 2, b / 2, 2))
        c, s = np.cos(angle), np.sin(angle)
        mesh = MeshTri(np.array([[c, -s], [s, c]]) @ base.p, base.t)
        along = lambda x: c * x[0] + s * x[1]          # the strip's own axis
        mesh = mesh.with_boundaries({"clamped": lambda x: along(x) < 1e-9 * L,
                                     "free": lambda x: along(x) > L * (1 - 1e-9)})
        shell = KirchhoffLoveShell(mesh, mat, bending_friction=frame)
        seen = []
        quasi_static(shell, path, du_rtol=1e-8,
                     on_step=lambda st, info: seen.append(shell.nodal_displacement(st.u)[:, 2].min()))
        tips.append(np.array(seen)[[4, -1]])           # full load, unloaded
    rel = np.abs(tips[1] - tips[0]) / np.abs(tips[0])
    if same:
        assert rel.max() <= 0.001
    else:
        assert rel.max() > 0.2


def _reference(state, kappa, tangent=True):
    """Moment and tangent of the NumPy update (``_DahlTensor.update``), the compiled kernel's
    reference."""
    dk = kappa - state.kappa
    y1, D1 = state._fast.update(state.y1, dk, tangent)
    y2, D2 = state._slow.update(state.y2, dk, tangent)
    return state._fast.sf * y1 - state._slow.sf * y2, (D1 - D2 if tangent else None), y1, y2


@pytest.mark.parametrize("per_point", [False, True])
def test_the_compiled_update_is_the_numpy_reference_to_round_off(per_point):
    """Moment, tangent and new states of the compiled update equal the NumPy formulas' within
    a few ulps, at slipping points and at points whose increment is zero (stick), with the
    laws' parameters the same everywhere or varying from point to point."""
    rng = np.random.default_rng(7)
    shape = (40, 6)
    warp, weft = WARP, WEFT
    if per_point:
        scale = np.exp(rng.normal(0.0, 0.3, shape))
        warp = FrictionParams(f1=WARP.f1 * scale, f2=WARP.f2 * scale, eps_f=WARP.eps_f, eta=WARP.eta)
    state = SheetFrictionState(warp, weft, shape)
    for _ in range(3):                      # a history: states away from zero
        state.commit(state.kappa + rng.normal(0.0, 60.0, shape + (3,)))
    kappa = state.kappa + rng.normal(0.0, 30.0, shape + (3,))
    kappa[:7] = state.kappa[:7]             # points that stick
    kappa[7:9] *= 1.0 + 1e-12               # points that barely slip
    M, D = state.trial(kappa)
    M_ref, D_ref, y1_ref, y2_ref = _reference(state, kappa)
    assert np.abs(M - M_ref).max() <= 1e-13 * np.abs(M_ref).max()
    assert np.abs(D - D_ref).max() <= 1e-13 * np.abs(D_ref).max()
    assert np.abs(state.moment(kappa) - M_ref).max() <= 1e-13 * np.abs(M_ref).max()
    state.commit(kappa)                     # the trial's states, kept from the kernel
    assert np.abs(state.y1 - y1_ref).max() <= 1e-14 and np.abs(state.y2 - y2_ref).max() <= 1e-14


def test_the_compiled_commit_takes_the_reference_states():
    """A commit at a curvature other than the last trial's updates the states as the NumPy
    reference does."""
    rng = np.random.default_rng(3)
    state = SheetFrictionState(WARP, WEFT, (25,))
    state.commit(rng.normal(0.0, 80.0, (25, 3)))
    kappa = state.kappa + rng.normal(0.0, 20.0, (25, 3))
    _, _, y1, y2 = _reference(state, kappa, tangent=False)
    state.commit(kappa)
    assert np.abs(state.y1 - y1).max() <= 1e-14 and np.abs(state.y2 - y2).max() <= 1e-14
