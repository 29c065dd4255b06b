"""A fabric wholly inside a closed body crosses none of its triangles, yet cannot be draped:
it is refused at the start, in one line naming the body's key, like a fabric that crosses one."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest

from drape.case.build import build
from drape.case.case import load_case
from drape.contact import shapes
from drape.contact.containment import has_inside, inside, one_point_per_piece, winding_number
from drape.contact.errors import ContactInputError
from drape.contact.surface import Surface

ROOT = Path(__file__).resolve().parents[3]
CUSICK = ROOT / "cases" / "cusick_kes.toml"
#: Bodies round the 30 cm Cusick specimen, centred on its disc at the origin.
AROUND = {
    "sphere": '{name = "ball", shape = "sphere", centre = [0, 0, 0], radius = "20 cm"}',
    "box": '{name = "crate", shape = "box", centre = [0, 0, 0], size = ["1 m", "1 m", "1 m"]}',
    "cylinder": '{name = "can", shape = "cylinder", centre = [0, 0, 0], axis = [0, 0, 1], '
                'radius = "20 cm", length = "20 cm"}',
    "disc": '{name = "puck", shape = "disc", centre = [0, 0, "5 cm"], radius = "20 cm", '
            'thickness = "10 cm"}',
}
BESIDE = '{name = "stool", shape = "sphere", centre = ["50 cm", 0, 0], radius = "10 cm"}'
#: An open body: a patch has no inside, whatever lies below or above it.
PATCH = '{name = "floor", shape = "plane", point = [0, 0, "-20 cm"], normal = [0, 0, 1], size = "1 m"}'


def with_bodies(tiny_cusick, *bodies) -> list[str]:
    return [*tiny_cusick, f"contact.body=[{', '.join(bodies)}]"]


def check_command(overrides) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "drape.run", str(CUSICK), "--check",
                           *sum((["--set", o] for o in overrides), [])],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["sphere", "box"])
def test_check_refuses_a_fabric_inside_a_closed_body_in_one_line(tiny_cusick, kind):
    done = check_command(with_bodies(tiny_cusick, AROUND[kind]))
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert "contact.body[0]" in lines[0] and "inside" in lines[0] and "closed body" in lines[0]


def test_check_accepts_a_body_beside_the_fabric(tiny_cusick):
    done = check_command(with_bodies(tiny_cusick, BESIDE))
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("kind", sorted(AROUND))
def test_the_builder_refuses_every_closed_shape_around_the_fabric(tiny_cusick, kind):
    with pytest.raises(ContactInputError, match=r"^contact\.body\[1\] .*starts inside this closed body"):
        build(load_case(CUSICK, with_bodies(tiny_cusick, BESIDE, AROUND[kind])))


def test_the_builder_accepts_a_body_beside_and_an_open_patch_below(tiny_cusick):
    parts = build(load_case(CUSICK, with_bodies(tiny_cusick, BESIDE, PATCH)))
    assert parts.model is not None


def write_stl(path: Path, surface: Surface, soup: bool) -> Path:
    """``surface`` as an STL file; ``soup``: every triangle with vertices of its own, as many
    exporters write them."""
    vertices, triangles = surface.vertices, surface.triangles
    if soup:
        vertices, triangles = vertices[triangles].reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3)
    meshio.write(path, meshio.Mesh(vertices, [("triangle", triangles)]), file_format="stl")
    return path


def test_a_closed_mesh_file_around_the_fabric_is_refused_an_open_one_is_not(tiny_cusick, tmp_path):
    ball = shapes.sphere((0, 0, 0), 0.2, resolution=16)
    closed = write_stl(tmp_path / "closed.stl", ball, soup=True)
    with pytest.raises(ContactInputError, match=r"contact\.body\[0\] \('shell'\).*inside"):
        build(load_case(CUSICK, with_bodies(tiny_cusick, f'{{name = "shell", shape = "mesh", file = "{closed}"}}')))
    # the same sphere with one triangle cut out: no inside, nothing refused
    cut = write_stl(tmp_path / "cut.stl", Surface(ball.vertices, ball.triangles[1:]), soup=False)
    build(load_case(CUSICK, with_bodies(tiny_cusick, f'{{name = "shell", shape = "mesh", file = "{cut}"}}')))


# --------------------------------------------------------------------------- the inside test
def test_winding_number_is_one_inside_zero_outside_and_minus_one_turned_inside_out():
    cube = shapes.rounded_box((0, 0, 0), (1.0, 1.0, 1.0), 0.0, resolution=8)
    points = [[0, 0, 0], [0.49, 0.49, -0.49], [0.51, 0, 0], [3, 2, 1]]
    np.testing.assert_allclose(winding_number(cube.vertices, cube.triangles, points), [1, 1, 0, 0],
                               atol=1e-9)
    inverted = cube.triangles[:, ::-1]
    np.testing.assert_allclose(winding_number(cube.vertices, inverted, points), [-1, -1, 0, 0],
                               atol=1e-9)
    assert inside(cube.vertices, inverted, points).tolist() == [True, True, False, False]


def test_only_a_closed_surface_has_an_inside():
    ball = shapes.sphere((0, 0, 0), 1.0, resolution=12)
    soup = Surface(ball.vertices[ball.triangles].reshape(-1, 3), np.arange(3 * len(ball.triangles)).reshape(-1, 3))
    assert has_inside(ball) and has_inside(soup)
    assert not has_inside(Surface(ball.vertices, ball.triangles[1:]))          # a hole
    assert not has_inside(shapes.plane((0, 0, 0), (0, 0, 1), 1.0))
    mixed = ball.triangles.copy()
    mixed[0] = mixed[0, ::-1]                                                    # one flipped
    assert not has_inside(Surface(ball.vertices, mixed))


def test_one_point_per_piece_of_a_triangulation():
    triangles = [[0, 1, 2], [2, 3, 0], [4, 5, 6]]                  # two pieces, and point 7 alone
    first = one_point_per_piece(8, triangles)
    assert sorted(first.tolist()) == [0, 4, 7]
