"""The Peirce tester's reading (overhang beyond the platform's edge, chord angle to the tip) on
strips of known shape."""
import numpy as np
import pytest

from drape.analyses.platform_reading import centre_line, crossing, reading
from meshes import strip


def _hinged(mesh, edge_x, angle_deg, lift=0.0):
    """The strip flat (at height ``lift``) up to ``edge_x``, straight beyond it and turned down by
    the angle about the point above the edge."""
    X = mesh.p[0]
    theta = np.deg2rad(angle_deg)
    beyond = np.clip(X - edge_x, 0, None)
    u = np.zeros((mesh.p.shape[1], 3))
    u[:, 0] = beyond * (np.cos(theta) - 1)
    u[:, 2] = lift - beyond * np.sin(theta)
    return u


@pytest.mark.parametrize("angle", [20.0, 41.5, 60.0])
def test_reading_of_a_hinged_strip(angle):
    mesh = strip(0.04, 0.025, 16, 2)
    edge = 0.025                                       # on a column of vertices
    r = reading(mesh, _hinged(mesh, edge, angle, lift=1e-4), edge)
    assert r["overhang"] == pytest.approx(0.015, rel=1e-12)
    assert r["chord_angle"] == pytest.approx(angle, rel=1e-12)


def test_reading_between_columns_and_before_the_edge():
    mesh = strip(0.04, 0.025, 16, 2)
    r = reading(mesh, _hinged(mesh, 0.026, 0.0), 0.026)           # flat: the edge between columns
    assert r["overhang"] == pytest.approx(0.014, rel=1e-9) and r["chord_angle"] == pytest.approx(0)
    behind = reading(mesh, np.zeros((mesh.p.shape[1], 3)), 0.05)
    assert behind["overhang"] == 0.0 and np.isnan(behind["chord_angle"])


def test_centre_line_averages_across_the_width():
    mesh = strip(0.04, 0.025, 4, 2)
    u = np.zeros((mesh.p.shape[1], 3))
    u[:, 2] = mesh.p[1] - 0.0125                       # tilted across: the centre stays at 0
    X, position = centre_line(mesh, u)
    assert np.allclose(X, np.linspace(0, 0.04, 5))
    assert np.allclose(position[:, 2], 0) and np.allclose(position[:, 1], 0.0125)


def test_crossing_interpolates_and_says_when_never_reached():
    angle = [np.nan, 10.0, 30.0, 45.0, 50.0]
    overhang = [0.0, 0.010, 0.013, 0.016, 0.017]
    hit = crossing(angle, overhang)
    assert hit["index"] == 3
    assert hit["overhang"] == pytest.approx(0.013 + 0.003 * 11.5 / 15)
    assert crossing([10.0, 20.0], [0.01, 0.02]) is None


# --------------------------------------------------------------------------- the analysis
def _context(edge_of_time, angles):
    """A finished run as the analysis sees it: a strip hinged over a platform whose edge moves."""
    from types import SimpleNamespace

    from constitutive.material import load_material
    from drape.contact import RigidPath, rounded_box

    mesh = strip(0.04, 0.025, 16, 2)
    platform = rounded_box((0.0, 0.0125, -0.005), (0.05, 0.05, 0.01), 0.0, 8)   # front at x = 0.025
    times = np.arange(len(angles), dtype=float)
    path = RigidPath(times, [[edge_of_time(t) - 0.025, 0, 0] for t in times])
    body = SimpleNamespace(name="platform", surface=platform, offset=path.offset, path=path)
    model = SimpleNamespace(contact=SimpleNamespace(scene=SimpleNamespace(bodies=[body])),
                            load_time=0.0)
    case = SimpleNamespace(mesh=SimpleNamespace(kind="strip"))
    ctx = SimpleNamespace(case=case, mesh=mesh, model=model, material=load_material("fabric1"),
                          history=[])
    return ctx, mesh, times


def test_peirce_platform_reads_half_the_overhang_at_the_line():
    from drape.analyses import ANALYSES

    analysis = ANALYSES["peirce_platform"]
    edge = lambda t: 0.03 - 0.0025 * t                  # drawn back a column (2.5 mm) a second
    angles = [20.0, 35.0, 40.0, 44.0]
    ctx, mesh, times = _context(edge, angles)
    for t, angle in zip(times, angles):
        ctx.model.load_time = t
        row = {"t": t, **analysis.probe(ctx, {"displacement": _hinged(mesh, edge(t), angle)})}
        ctx.history.append(row)
    assert [r["overhang_m"] for r in ctx.history] == pytest.approx([0.010, 0.0125, 0.015, 0.0175])
    out = analysis.finish(ctx)
    share = (41.5 - 40) / 4
    assert out["reached"] and out["time_s"] == pytest.approx(2 + share)
    assert out["bending_length_m"] == pytest.approx((0.015 + 0.0025 * share) / 2)
    assert out["flexural_rigidity_Nm"] == pytest.approx(
        ctx.material.areal_mass * 9.80665 * out["bending_length_m"] ** 3)


def test_peirce_platform_says_when_the_line_is_not_reached_and_needs_a_platform():
    from drape.analyses import ANALYSES
    from drape.analyses.base import AnalysisInputError

    analysis = ANALYSES["peirce_platform"]
    ctx, mesh, _ = _context(lambda t: 0.03, [10.0])
    ctx.history.append({"t": 0.0, **analysis.probe(ctx, {"displacement": _hinged(mesh, 0.03, 10.0)})})
    out = analysis.finish(ctx)
    assert out["reached"] is False and out["max_chord_angle_deg"] == pytest.approx(10.0)
    ctx.model.contact.scene.bodies[0].name = "table"
    with pytest.raises(AnalysisInputError, match="named 'platform'"):
        analysis.probe(ctx, {"displacement": _hinged(mesh, 0.03, 10.0)})


def test_grip_study_holds_platform_and_ruler_at_the_given_edge(tmp_path):
    """drape.batch.peirce_grip: the case at rest keeps the platform case's bodies,
    fixed (no path), their front edges at the edge asked for, and the overhang beyond it; with
    another barrier layer the strip still starts in the middle of both layers."""
    from drape.batch.peirce_grip import resting_case
    from drape.case.case import load_case

    path, overhang = resting_case(0.0063, tmp_path)
    case = load_case(path)
    assert overhang == pytest.approx(case.mesh.length - 0.0063)
    assert [b.name for b in case.contact.body] == ["platform", "ruler"]
    for body in case.contact.body:
        assert body.path is None
        assert body.centre[0] + 0.5 * body.size[0] == pytest.approx(0.0063, abs=1e-12)
    thin, _ = resting_case(0.0063, tmp_path, dhat=2e-6)
    thin = load_case(thin)
    platform, ruler = thin.contact.body
    half = case.contact.body[1].centre[2] - 0.5 * case.contact.body[1].size[2] - 0.5 * case.contact.dhat
    assert thin.contact.dhat == 2e-6
    assert platform.centre[2] + 0.5 * platform.size[2] == pytest.approx(-(half + 1e-6), abs=1e-12)
    assert ruler.centre[2] - 0.5 * ruler.size[2] == pytest.approx(half + 1e-6, abs=1e-12)
