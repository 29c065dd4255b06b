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
