"""Mesh generators, import and checks (meshes/)."""
import math
from pathlib import Path

import meshio
import numpy as np
import pytest
from skfem import MeshTri

from meshes import (MeshError, check_mesh, cusick_annulus, load_mesh, rectangle, save_mesh,
                    strip)
from meshes.quality import triangle_areas


def facet_midpoints(mesh, name):
    return mesh.p[:, mesh.facets[:, mesh.boundaries[name]]].mean(axis=1)


@pytest.mark.parametrize("diagonals", ["alternate", "right", "left"])
def test_rectangle_area_and_boundaries(diagonals):
    lx, ly, x0, y0 = 0.3, 0.2, -0.1, 0.05
    mesh = rectangle(lx, ly, 6, 4, origin=(x0, y0), diagonals=diagonals)
    # exact area to round-off
    assert abs(np.abs(triangle_areas(mesh.p, mesh.t)).sum() - lx * ly) < 1e-14
    expected = {"left": (0, x0, 4), "right": (0, x0 + lx, 4),
                "bottom": (1, y0, 6), "top": (1, y0 + ly, 6)}
    for name, (axis, coord, count) in expected.items():
        mid = facet_midpoints(mesh, name)
        assert mid.shape[1] == count
        assert np.abs(mid[axis] - coord).max() < 1e-15
        # the facets cover the whole side
        assert math.isclose(np.ptp(mid[1 - axis]), (ly if axis == 0 else lx) * (1 - 1 / count))


def test_strip_named_ends():
    mesh = strip(0.2, 0.025, 20, 2)
    assert np.abs(facet_midpoints(mesh, "clamped")[0]).max() < 1e-15
    assert np.abs(facet_midpoints(mesh, "free_end")[0] - 0.2).max() < 1e-15
    assert len(mesh.boundaries["clamped"]) == 2
    assert check_mesh(mesh).min_angle_deg == pytest.approx(math.degrees(math.atan(1.0 / 1.25)), rel=1e-12)


def test_strip_with_a_fine_zone_has_its_cells_and_the_case_builds_it():
    """``[mesh.fine_zone]``: equal cells of (end − start) / nx in the zone, about length / nx
    outside it, the ends and the named boundaries where a uniform strip has them."""
    from drape.case.build import _make_mesh
    from drape.case.case import load_case

    case = load_case(Path(__file__).resolve().parents[2] / "cases" / "peirce_platform.toml",
                     ["mesh.nx=44", "mesh.width='0.05 cm'", "mesh.fine_zone.start='3.5 mm'",
                      "mesh.fine_zone.end='9.5 mm'", "mesh.fine_zone.nx=60"])
    mesh = _make_mesh(case.mesh)
    x = np.unique(mesh.p[0])
    h = np.diff(x)
    inside = (x[:-1] >= 3.5e-3 - 1e-12) & (x[1:] <= 9.5e-3 + 1e-12)
    np.testing.assert_allclose(h[inside], 1e-4, rtol=1e-9)
    assert inside.sum() == 60
    np.testing.assert_allclose(h[~inside], 5e-4, rtol=1e-9)
    assert x[0] == 0.0 and x[-1] == pytest.approx(0.022, rel=1e-15)
    uniform = strip(0.022, 0.0005, 44 + 48)
    assert sorted(mesh.boundaries) == sorted(uniform.boundaries)
    assert len(mesh.boundaries["clamped"]) == 1 and len(mesh.boundaries["top"]) == 92


def test_cusick_annulus_geometry():
    nr, nc = 3, 24
    mesh = cusick_annulus(0.30, 0.18, n_radial=nr, n_circumferential=nc)
    r = np.hypot(*mesh.p)
    R, a = 0.15, 0.09
    for name, radius in (("disc", a), ("hem", R)):
        nodes = np.unique(mesh.facets[:, mesh.boundaries[name]])
        assert len(nodes) == nc and len(mesh.boundaries[name]) == nc
        assert np.abs(r[nodes] - radius).max() < 1e-15       # nodes exactly on the circle
    # area of the annulus between the two inscribed regular nc-gons (independent formula)
    polygon = 0.5 * nc * math.sin(2 * math.pi / nc) * (R**2 - a**2)
    assert abs(np.abs(triangle_areas(mesh.p, mesh.t)).sum() - polygon) < 1e-15
    # the disc region is not meshed
    assert r.min() >= a - 1e-15
    # refinement converges to the circle area at second order
    err = [abs(np.abs(triangle_areas(m.p, m.t)).sum() - math.pi * (R**2 - a**2))
           for m in (cusick_annulus(n_radial=nr, n_circumferential=nc, refine=k) for k in range(3))]
    assert 3.9 < err[0] / err[1] < 4.1 and 3.9 < err[1] / err[2] < 4.1


def test_cusick_annulus_defaults_from_target_size():
    mesh = cusick_annulus(0.24, 0.18, target_size=0.01)
    nc = len(mesh.boundaries["hem"])
    # 66 cells of the mid circumference: the nearest twice a prime is 62 = 2 · 31 (74 is farther)
    assert nc == 62 and abs(nc - math.pi * 0.21 / 0.01) < 6
    assert not any(nc % k == 0 for k in range(3, nc // 2))
    # three rings of cells across the 3 cm overhang
    assert len(np.unique(np.round(np.hypot(*mesh.p), 12))) == 4


def test_cusick_annulus_radial_grading():
    """Ring widths grow geometrically by the given outer/inner ratio; area and boundary
    nodes are those of the uniform mesh; refinement keeps the ratio."""
    nr, nc, ratio = 4, 32, 5.0
    mesh = cusick_annulus(0.30, 0.18, n_radial=nr, n_circumferential=nc, radial_grading=ratio)
    widths = np.diff(np.unique(np.round(np.hypot(*mesh.p), 12)))
    assert widths.sum() == pytest.approx(0.06, abs=1e-14)
    assert widths[-1] / widths[0] == pytest.approx(ratio, rel=1e-9)
    np.testing.assert_allclose(widths[1:] / widths[:-1], ratio ** (1 / (nr - 1)), rtol=1e-9)
    uniform = cusick_annulus(0.30, 0.18, n_radial=nr, n_circumferential=nc)
    assert np.abs(triangle_areas(mesh.p, mesh.t)).sum() == pytest.approx(
        np.abs(triangle_areas(uniform.p, uniform.t)).sum(), rel=1e-13)
    fine = cusick_annulus(0.30, 0.18, n_radial=nr, n_circumferential=nc, radial_grading=ratio,
                          refine=1)
    w2 = np.diff(np.unique(np.round(np.hypot(*fine.p), 12)))
    assert w2.size == 2 * nr and w2[-1] / w2[0] == pytest.approx(ratio, rel=1e-9)
    with pytest.raises(ValueError, match="radial_grading"):
        cusick_annulus(radial_grading=0.5)


def write_square_msh(path, file_format, with_group=True):
    """Unit square in millimetres with a 4-node hole-free fan, and a tagged left edge."""
    points = np.array([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0], [5, 5, 0.]])
    tri = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    cells = [("triangle", tri)]
    cell_data = {"gmsh:physical": [np.full(4, 1)], "gmsh:geometrical": [np.full(4, 1)]}
    field_data = {"fabric": np.array([1, 2])}
    if with_group:
        cells.append(("line", np.array([[3, 0]])))
        cell_data["gmsh:physical"].append(np.array([5]))
        cell_data["gmsh:geometrical"].append(np.array([4]))
        field_data["clamped"] = np.array([5, 1])
    meshio.Mesh(points, cells, cell_data=cell_data, field_data=field_data).write(
        path, file_format=file_format, binary=False)
    return points, tri


# The same square as gmsh 4.1 writes it (entities carry the physical tags;
# meshio's own 4.1 writer does not write them, so this file is typed out).
GMSH41_SQUARE = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 5 "clamped"
2 1 "fabric"
$EndPhysicalNames
$Entities
0 1 1 0
4 0 0 0 0 10 0 1 5 0
1 0 0 0 10 10 0 1 1 1 4
$EndEntities
$Nodes
2 5 1 5
1 4 0 2
1
4
0 0 0
0 10 0
2 1 0 3
2
3
5
10 0 0
10 10 0
5 5 0
$EndNodes
$Elements
2 5 1 5
1 4 1 1
1 4 1
2 1 2 4
2 1 2 5
3 2 3 5
4 3 4 5
5 4 1 5
$EndElements
"""


@pytest.mark.parametrize("file_format", ["gmsh22", "gmsh41-by-gmsh"])
def test_load_gmsh_roundtrip(tmp_path, file_format):
    path = tmp_path / "square.msh"
    if file_format == "gmsh22":
        points, tri = write_square_msh(path, file_format)
    else:
        path.write_text(GMSH41_SQUARE)
        points = np.array([[0, 0, 0], [0, 10, 0], [10, 0, 0], [10, 10, 0], [5, 5, 0.]])
        tri = np.array([[0, 2, 4], [2, 3, 4], [3, 1, 4], [1, 0, 4]])
    mesh = load_mesh(path, scale=1e-3,
                     boundaries={"right": lambda x: np.abs(x[0] - 0.01) < 1e-12},
                     required_boundaries=("clamped",))
    assert np.allclose(mesh.p, 1e-3 * points[:, :2].T, rtol=0, atol=1e-18)
    assert sorted(map(sorted, mesh.t.T.tolist())) == sorted(map(sorted, tri.tolist()))
    assert abs(np.abs(triangle_areas(mesh.p, mesh.t)).sum() - 1e-4) < 1e-18
    left = facet_midpoints(mesh, "clamped")
    assert left.shape == (2, 1) and np.allclose(left[:, 0], [0.0, 0.005], atol=1e-15)
    assert np.allclose(facet_midpoints(mesh, "right")[:, 0], [0.01, 0.005], atol=1e-15)


def test_load_errors(tmp_path):
    path = tmp_path / "square.msh"
    write_square_msh(path, "gmsh22", with_group=False)
    with pytest.raises(MeshError, match="boundary 'clamped' is missing"):
        load_mesh(path, required_boundaries=("clamped",))
    with pytest.raises(MeshError, match="boundary 'clamped' is empty"):
        load_mesh(path, boundaries={"clamped": lambda x: x[0] < -1.0})
    lines = tmp_path / "lines.vtu"
    meshio.Mesh(np.eye(3), [("line", np.array([[0, 1], [1, 2]]))]).write(lines)
    with pytest.raises(MeshError, match="no linear 'triangle' cells"):
        load_mesh(lines)
    with pytest.raises(FileNotFoundError):
        load_mesh(tmp_path / "missing.msh")


def test_quality_errors_name_the_culprit():
    p = np.array([[0., 1, 0, 1, 2], [0, 0, 1, 1, 0]])
    with pytest.raises(MeshError, match="triangle 1 has zero area"):
        check_mesh(MeshTri(p, np.array([[0, 1, 2], [0, 1, 4], [1, 3, 2]]).T))
    with pytest.raises(MeshError, match="nodes 1 and 4 are duplicated"):
        check_mesh(MeshTri(np.array([[0., 1, 0, 1, 1], [0, 0, 1, 1, 0]]),
                           np.array([[0, 1, 2], [4, 3, 2]]).T))
    with pytest.raises(MeshError, match="node 4 is not used"):
        check_mesh(MeshTri(p, np.array([[0, 1, 2], [1, 3, 2]]).T))
    with pytest.raises(MeshError, match="overlap"):       # second triangle folded back
        check_mesh(MeshTri(np.array([[0., 1, 0, 0.5], [0, 0, 1, 0.2]]),
                           np.array([[0, 1, 2], [1, 2, 3]]).T))
    with pytest.raises(MeshError, match="degree angle"):
        check_mesh(MeshTri(np.array([[0., 1, 0.5], [0, 0, 0.01]]), np.array([[0, 1, 2]]).T))


def test_bad_parameters_are_named():
    with pytest.raises(ValueError, match="'nx'"):
        rectangle(1.0, 1.0, 0, 2)
    with pytest.raises(ValueError, match="'ly'"):
        rectangle(1.0, -1.0, 2, 2)
    with pytest.raises(ValueError, match="'specimen_diameter'.*must exceed"):
        cusick_annulus(0.18, 0.18)
    with pytest.raises(ValueError, match="'refine'"):
        cusick_annulus(refine=-1)


def test_save_and_load_keep_geometry_and_boundaries(tmp_path):
    for mesh in (strip(0.2, 0.02, 8, 2), cusick_annulus(n_radial=2, n_circumferential=16)):
        back = load_mesh(save_mesh(mesh, tmp_path / "m.msh"))
        assert np.abs(back.p - mesh.p).max() < 1e-15      # ascii, 17 significant digits
        assert np.array_equal(back.t, mesh.t)
        for name, facets in mesh.boundaries.items():
            assert np.array_equal(np.sort(back.boundaries[name]), np.sort(facets))


def test_circle_is_the_inscribed_polygon_in_good_triangles():
    from meshes import circle
    from meshes.quality import triangle_angles, triangle_areas

    for n in (3, 8):
        mesh = circle(0.30, n_rings=n, centre=(0.1, -0.2))
        sides = 6 * n
        polygon = 0.5 * sides * 0.15 ** 2 * np.sin(2 * np.pi / sides)
        assert np.abs(triangle_areas(mesh.p, mesh.t)).sum() == pytest.approx(polygon, rel=1e-12)
        assert triangle_angles(mesh.p, mesh.t).min() > 40
        hem = np.unique(mesh.facets[:, mesh.boundaries["hem"]])
        assert len(mesh.boundaries["hem"]) == sides
        assert np.allclose(np.hypot(mesh.p[0, hem] - 0.1, mesh.p[1, hem] + 0.2), 0.15)
    assert circle(0.30, target_size=0.05).p.shape[1] == 1 + 6 * (1 + 2 + 3)
