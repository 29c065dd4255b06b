"""Rigid contact bodies: their surfaces against the smooth bodies' analytic area and volume,
orientation, closedness, placement, and surfaces read from files (units, bad files)."""
import math

import meshio
import numpy as np
import pytest

from drape.contact import (ContactInputError, Surface, cylinder, disc, plane, read_surface,
                           rounded_box, sphere)


# --------------------------------------------------------------------------- analytic bodies
def _disc_exact(R, t, e):
    """Area and volume of a disc with rounded rim edges, by Pappus's theorems: the profile is a
    rectangle R × t less two corner spandrels, each of area e²(1 − π/4) and centroid
    e (10 − 3π)/(3 (4 − π)) in from the rim; the rounded edges are quarter arcs of centroid 2e/π
    out from their centres."""
    spandrel_in = e * (10 - 3 * math.pi) / (3 * (4 - math.pi))
    volume = math.pi * R ** 2 * t - 2 * 2 * math.pi * (R - spandrel_in) * e ** 2 * (1 - math.pi / 4)
    arc = 2 * math.pi * (R - e + 2 * e / math.pi) * (math.pi * e / 2)
    area = 2 * math.pi * (R - e) ** 2 + 2 * math.pi * R * (t - 2 * e) + 2 * arc
    return area, volume


def _box_exact(a, b, c, e):
    """Area and volume of the points within e of a box (a−2e) × (b−2e) × (c−2e) (Steiner)."""
    x, y, z = a - 2 * e, b - 2 * e, c - 2 * e
    volume = x * y * z + 2 * e * (x * y + y * z + z * x) + math.pi * e ** 2 * (x + y + z) \
        + 4 / 3 * math.pi * e ** 3
    area = 2 * (x * y + y * z + z * x) + 2 * math.pi * e * (x + y + z) + 4 * math.pi * e ** 2
    return area, volume


BODIES = {
    "sphere": (lambda n: sphere((0.1, -0.2, 0.3), 0.1, n),
               (4 * math.pi * 0.1 ** 2, 4 / 3 * math.pi * 0.1 ** 3), (0.1, -0.2, 0.3)),
    "cylinder": (lambda n: cylinder((0, 0, 0.5), (1, 1, 0), 0.05, 0.3, n),
                 (2 * math.pi * 0.05 * (0.05 + 0.3), math.pi * 0.05 ** 2 * 0.3), (0, 0, 0.5)),
    "disc": (lambda n: disc((0, 0, 0.1), 0.09, 0.02, 0.005, n), _disc_exact(0.09, 0.02, 0.005),
             (0, 0, 0.09)),
    "rounded_box": (lambda n: rounded_box((0.2, 0, 0), (0.3, 0.2, 0.1), 0.02, n),
                    _box_exact(0.3, 0.2, 0.1, 0.02), (0.2, 0, 0)),
}


def _errors(name, n):
    build, (area, volume), _ = BODIES[name]
    body = build(n)
    return body.area() / area - 1, body.volume() / volume - 1


@pytest.mark.parametrize("name", BODIES)
def test_area_and_volume_converge_to_the_smooth_body(name):
    """Vertices on a convex body: the polyhedron lies inside, so it falls short, by an error
    bounded by (2π/resolution)²/4 that at least a third at each doubling (second order)."""
    last = None
    for n in (16, 32, 64):
        errors = np.array(_errors(name, n))
        assert (errors < 0).all(), (n, errors)
        assert (-errors <= (2 * math.pi / n) ** 2 / 4).all(), (n, errors)
        if last is not None:
            assert (-errors < -last / 3).all(), (n, errors, last)
        last = errors


@pytest.mark.parametrize("name", BODIES)
def test_closed_manifold_and_outward(name):
    import pyvista as pv

    build, _, inside = BODIES[name]
    body = build(16)
    assert body.is_closed() and body.volume() > 0
    poly = body.to_polydata()
    bad_edges = poly.extract_feature_edges(boundary_edges=True, non_manifold_edges=True,
                                           feature_edges=False, manifold_edges=False)
    assert bad_edges.n_cells == 0
    assert isinstance(poly, pv.PolyData) and poly.n_cells == len(body.triangles)
    # convex: every triangle faces away from a point inside
    centroids = body.vertices[body.triangles].mean(axis=1)
    assert (np.einsum("ij,ij->i", body.normals(), centroids - inside) > 0).all()
    assert body.triangle_areas().min() > 1e-6 * body.area() / len(body.triangles)


def test_is_closed_sees_a_hole_and_a_flipped_triangle():
    ball = sphere((0, 0, 0), 1.0, 12)
    assert ball.is_closed()
    assert not Surface(ball.vertices, ball.triangles[1:]).is_closed()
    flipped = ball.triangles.copy()
    flipped[0] = flipped[0, ::-1]
    assert not Surface(ball.vertices, flipped).is_closed()


def test_plane_patch_faces_its_normal():
    patch = plane((1.0, 2.0, 3.0), (0, 0, 2), 0.5, resolution=5)
    assert len(patch.triangles) == 50 and not patch.is_closed()
    assert patch.area() == pytest.approx(0.25, rel=1e-12)
    assert np.allclose(patch.normals(), [0, 0, 1])
    assert np.allclose(patch.bounds(), [[0.75, 1.75, 3.0], [1.25, 2.25, 3.0]])
    tilted = plane((0, 0, 0), (1, 1, 1), 2.0)
    assert np.allclose(tilted.normals(), np.ones(3) / math.sqrt(3))
    assert np.allclose(tilted.vertices @ np.ones(3), 0) and tilted.area() == pytest.approx(4.0)


def test_disc_top_face_at_the_centre_and_sharp_edges():
    top = disc((0.1, 0.2, 0.7), radius=0.4, thickness=0.03, edge_radius=0.01, resolution=32)
    lo, hi = top.bounds()
    assert hi[2] == pytest.approx(0.7) and lo[2] == pytest.approx(0.67)
    assert np.allclose([hi[0] - 0.1, 0.1 - lo[0]], 0.4)
    sharp = disc((0, 0, 0), 0.1, 0.01, 0.0, 64)
    assert sharp.volume() == pytest.approx(math.pi * 0.01 * 0.1 ** 2 * np.sinc(2 / 64), rel=1e-9)
    with pytest.raises(ContactInputError, match="edge_radius"):
        disc((0, 0, 0), 0.1, 0.01, 0.006)


def test_sharp_box_is_exact_and_cylinder_follows_its_axis():
    box = rounded_box((1, 2, 3), (0.3, 0.2, 0.1), 0.0, 8)
    assert box.is_closed()
    assert box.volume() == pytest.approx(0.006, rel=1e-12)
    assert box.area() == pytest.approx(2 * (0.06 + 0.02 + 0.03), rel=1e-12)
    assert np.allclose(box.bounds(), [[0.85, 1.9, 2.95], [1.15, 2.1, 3.05]])
    rod = cylinder((0, 0, 1), (1, 0, 0), 0.05, 0.4, 24)
    lo, hi = rod.bounds()
    assert np.allclose([lo[0], hi[0]], [-0.2, 0.2]) and np.allclose([lo[2], hi[2]], [0.95, 1.05])


# --------------------------------------------------------------------------- placement
def _rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_placed_rotates_about_x_then_y_then_z_then_translates():
    box = rounded_box((0.1, 0.0, 0.0), (0.3, 0.2, 0.1), 0.02, 8)
    angles = (30.0, -50.0, 110.0)
    moved = box.placed(translation=(1, 2, 3), rotation_deg=angles, scale=2.0)
    matrix = _rz(math.radians(110)) @ _ry(math.radians(-50)) @ _rx(math.radians(30))
    assert np.allclose(moved.vertices, 2.0 * box.vertices @ matrix.T + [1, 2, 3])
    assert moved.volume() == pytest.approx(8 * box.volume(), rel=1e-12)
    assert moved.area() == pytest.approx(4 * box.area(), rel=1e-12)
    # the order matters: x then y takes the x axis to −z, y then x would take it to +y
    axis = Surface([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]).placed(rotation_deg=(90, 90, 0))
    assert np.allclose(axis.vertices[1], [0, 0, -1])


@pytest.mark.parametrize("bad", [dict(scale=0.0), dict(translation=(0, 1)),
                                 dict(rotation_deg=(0, float("nan"), 0))])
def test_placed_refuses_bad_placements(bad):
    with pytest.raises(ContactInputError):
        plane((0, 0, 0), (0, 0, 1), 1.0).placed(**bad)


# --------------------------------------------------------------------------- files
@pytest.mark.parametrize("suffix", [".stl", ".ply", ".obj", ".vtu"])
def test_read_surface_round_trips_each_format(tmp_path, suffix):
    ball = sphere((0, 0, 0), 0.1, 12)
    path = tmp_path / f"ball{suffix}"
    meshio.write(path, meshio.Mesh(ball.vertices, [("triangle", ball.triangles)]))
    read = read_surface(path)
    assert read.is_closed()
    assert read.volume() == pytest.approx(ball.volume(), rel=1e-6)   # STL stores float32


def test_units_and_scale(tmp_path):
    ball = sphere((0, 0, 0), 100.0, 12)                 # drawn in millimetres
    path = tmp_path / "ball.ply"
    meshio.write(path, meshio.Mesh(ball.vertices, [("triangle", ball.triangles)]))
    in_m = read_surface(path, units="mm")
    assert np.allclose(in_m.vertices, 1e-3 * ball.vertices)
    assert np.allclose(read_surface(path, units="cm", scale=0.5).vertices, 5e-3 * ball.vertices)
    assert np.allclose(read_surface(path, units="inch").vertices, 0.0254 * ball.vertices)
    for bad in ("kg", "parsec!"):
        with pytest.raises(ContactInputError, match="units"):
            read_surface(path, units=bad)


def test_quads_are_split(tmp_path):
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 3)], float)
    quads = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4],
                      [1, 5, 7, 3]])
    path = tmp_path / "cube.obj"
    meshio.write(path, meshio.Mesh(corners, [("quad", quads)]))
    block = read_surface(path)
    assert len(block.triangles) == 12 and block.is_closed()
    assert block.volume() == pytest.approx(6.0) and block.area() == pytest.approx(22.0)


def _one_line(error):
    message = str(error.value)
    assert "\n" not in message and "Traceback" not in message
    return message


def test_bad_files_one_line_each(tmp_path):
    with pytest.raises(ContactInputError) as missing:
        read_surface(tmp_path / "nowhere.stl")
    assert "no such file" in _one_line(missing)

    garbage = tmp_path / "garbage.ply"
    garbage.write_text("this is not a mesh\n")
    with pytest.raises(ContactInputError) as unreadable:
        read_surface(garbage)
    assert "cannot read" in _one_line(unreadable)

    lines = tmp_path / "lines.vtu"
    meshio.write(lines, meshio.Mesh(np.eye(3), [("line", np.array([[0, 1], [1, 2]]))]))
    with pytest.raises(ContactInputError) as not_surface:
        read_surface(lines)
    assert "not a surface" in _one_line(not_surface)

    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [np.nan, 0, 1]], float)
    nan = tmp_path / "nan.vtu"
    meshio.write(nan, meshio.Mesh(points, [("triangle", np.array([[0, 1, 2], [0, 1, 3]]))]))
    with pytest.raises(ContactInputError) as not_finite:
        read_surface(nan)
    assert "NaN" in _one_line(not_finite)

    flat = tmp_path / "degenerate.vtu"
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], float)
    meshio.write(flat, meshio.Mesh(points, [("triangle", np.array([[0, 1, 2], [0, 1, 3]]))]))
    with pytest.raises(ContactInputError) as degenerate:
        read_surface(flat)
    assert "degenerate triangle" in _one_line(degenerate) and "triangle 1" in str(degenerate.value)


def test_surface_refuses_bad_arrays():
    with pytest.raises(ContactInputError, match="NaN"):
        Surface([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]], [[0, 1, 2]])
    with pytest.raises(ContactInputError, match="outside"):
        Surface([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])
    with pytest.raises(ContactInputError, match=r"\(n, 3\)"):
        Surface([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    with pytest.raises(ContactInputError, match="resolution"):
        sphere((0, 0, 0), 1.0, resolution=2)
    with pytest.raises(ContactInputError, match="radius"):
        sphere((0, 0, 0), -1.0)
